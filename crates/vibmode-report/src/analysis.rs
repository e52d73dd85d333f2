//! The report of an analysis (`vibmode analyze`, `vibmode demo`): functions from results to
//! figures, tables, text and files. The binary only calls [`write_analysis_report`] and prints
//! [`modes_table_text`].

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use vibmode_analysis::{
    first_record_spectra, AnalysisResults, FirstRecord, FirstRecordSpectra, RecordInput,
};
use vibmode_core::{InvariantMode, ModeClass, Recording, Robust, SweepModel};

use crate::error::ReportError;
use crate::html::HtmlReport;
use crate::model::{Figure, Panel, Scale, Series, SeriesStyle};
use crate::panels::{damping_panel, grid, mode_marks, positive_freq, stabilisation_panel};

pub use vibmode_core::TruthRow;

/// Files written by [`write_analysis_report`].
#[derive(Clone, Debug, PartialEq)]
pub struct ReportFiles {
    /// `DIR/index.html`.
    pub html: PathBuf,
    /// `DIR/results.json`.
    pub results_json: PathBuf,
    /// `DIR/modes.csv`.
    pub modes_csv: PathBuf,
    /// `DIR/figures/*.svg|png`.
    pub figures: Vec<PathBuf>,
}

/// The axis label of a quantity in `unit`; an unknown unit is said so, never faked.
fn unit_label(unit: &str) -> String {
    if unit.is_empty() {
        "input units".into()
    } else {
        unit.to_string()
    }
}

/// `PSD [(m/s^2)^2/Hz]`, or `PSD [(input units)^2/Hz]` for an unknown unit.
fn psd_label(unit: &str) -> String {
    format!("PSD [({})^2/Hz]", unit_label(unit))
}

fn class_name(c: &ModeClass) -> &'static str {
    match c {
        ModeClass::Structural => "structural mode",
        ModeClass::PeriodicDisturbance => "periodic disturbance",
        ModeClass::Spurious => "spurious",
    }
}

fn shown(modes: &[InvariantMode]) -> impl Iterator<Item = &InvariantMode> {
    modes.iter().filter(|m| m.class != ModeClass::Spurious)
}

fn freqs_of(modes: &[InvariantMode], class: ModeClass) -> Vec<f64> {
    modes
        .iter()
        .filter(|m| m.class == class)
        .map(|m| m.frequency_hz)
        .collect()
}

/// A group of channels whose poles were clustered together: a role pool, or one channel without
/// a role (analysed alone, never pooled).
struct Pool<'a> {
    /// "sprung channels (FR_sprung, ...)" or "channel z (no role: analysed alone)".
    title: String,
    /// "the sprung channels" or "channel z".
    subject: String,
    modes: &'a [InvariantMode],
    matches: &'a [vibmode_core::ModeMatch],
    channels: Vec<&'a vibmode_analysis::ChannelAnalysis>,
    lines: &'a [vibmode_analysis::LineTrack],
    /// What to know before reading the pool's modes (printed under its table).
    note: Option<String>,
}

fn pools(r: &AnalysisResults) -> Vec<Pool<'_>> {
    let mut out: Vec<Pool<'_>> = r
        .roles
        .iter()
        .map(|role| Pool {
            title: format!("{} channels ({})", role.role, role.channels.join(", ")),
            subject: format!("the {} channels", role.role),
            modes: &role.invariant_modes,
            matches: &role.matches,
            channels: r.channels.iter().filter(|c| c.role == role.role).collect(),
            lines: &role.lines,
            note: None,
        })
        .collect();
    for ch in r
        .channels
        .iter()
        .filter(|c| c.role == vibmode_core::Role::Other)
    {
        out.push(Pool {
            title: format!("channel {} (no role: analysed alone, not pooled)", ch.name),
            subject: format!("channel {}", ch.name),
            modes: &ch.invariant_modes,
            matches: &[],
            channels: vec![ch],
            lines: &ch.lines,
            note: None,
        });
    }
    if let Some(ssi) = &r.ssi {
        let how = if r.config.ssi.pool_records {
            "correlations pooled over the records"
        } else {
            "each record alone"
        };
        out.push(Pool {
            title: format!(
                "all channels together (SSI-cov, {how}, {} block rows: {})",
                r.config.ssi.block_rows,
                ssi.channels.join(", ")
            ),
            subject: "the multichannel identification (SSI-cov)".into(),
            modes: &ssi.invariant_modes,
            matches: &ssi.matches,
            channels: r.channels.iter().collect(),
            lines: &ssi.lines,
            note: None,
        });
    }
    if let Some(b) = &r.body_ssi {
        let used: Vec<f64> = b.delays.iter().filter_map(|d| d.delay_s).collect();
        let (lo, hi) = used
            .iter()
            .fold((f64::INFINITY, 0.0f64), |(l, h), &d| (l.min(d), h.max(d)));
        out.push(Pool {
            title: format!(
                "body band, all channels together (SSI-cov at {} Hz, each of {} records from beyond its own wheelbase delay, {:.2}-{:.2} s measured on {}; {} of records)",
                b.fs_hz,
                b.n_records,
                lo,
                hi,
                b.delay_pairs
                    .iter()
                    .map(|p| format!("{}/{}", p[0], p[1]))
                    .collect::<Vec<_>>()
                    .join(" and "),
                if b.duration_s >= 3600.0 {
                    format!("{:.1} h", b.duration_s / 3600.0)
                } else {
                    format!("{:.1} min", b.duration_s / 60.0)
                }
            ),
            subject: "the body-band SSI-cov".into(),
            modes: &b.analysis.invariant_modes,
            matches: &b.analysis.matches,
            channels: r.channels.iter().collect(),
            lines: &[],
            note: Some(format!(
                "Body heave and pitch come apart here only with hours of records driven at different speeds (within 3 % from 5.8 h at 20-45 km/h on the demo bus; docs/ssi.md); {} record(s) left out.",
                b.delays.iter().filter(|d| d.left_out.is_some()).count()
            )),
        });
    }
    out
}

/// The records with a clipped or a held channel, one sentence each (none when no record has
/// one): such a channel is analysed, but the clipping's harmonics or the dropouts are in its
/// spectra and modes.
pub fn sensor_notes(r: &AnalysisResults) -> Vec<String> {
    let mut out = Vec::new();
    let clipped = records_sentence(r, |rec| {
        rec.clipped
            .iter()
            .map(|c| {
                format!(
                    "channel '{}' {:.1} % of the samples at {}",
                    vibmode_core::quoted(&c.channel),
                    100.0 * c.share,
                    vibmode_core::Num(c.value)
                )
            })
            .collect()
    });
    if let Some((n, list)) = clipped {
        out.push(format!(
            "Clipped: {n} of {} records hold a channel at its extreme for 1 % of the samples or more (a saturated sensor or amplifier; analysed, but its spectra and modes hold the clipping's harmonics): {list}.",
            r.records.len()
        ));
    }
    let held = records_sentence(r, |rec| {
        rec.held
            .iter()
            .map(|h| {
                format!(
                    "channel '{}' {:.1} % of the samples in {} stretch(es), the longest {:.3} s",
                    vibmode_core::quoted(&h.channel),
                    100.0 * h.share,
                    h.stretches,
                    h.longest_s
                )
            })
            .collect()
    });
    if let Some((n, list)) = held {
        out.push(format!(
            "Held: {n} of {} records hold one value of a channel over stretches of {} s or more (a data logger's dropouts, filled with the last value or 0? a live sensor's reading changes from sample to sample; analysed, but the stretches are in its spectra and modes): {list}.",
            r.records.len(),
            vibmode_analysis::HELD_MIN_S
        ));
    }
    out
}

/// How many records `of` names channels for, and the first [`NOTED_RECORDS_SHOWN`] of them as
/// `name: item, item; name: ...` (and how many more).
fn records_sentence(
    r: &AnalysisResults,
    of: impl Fn(&vibmode_analysis::RecordSummary) -> Vec<String>,
) -> Option<(usize, String)> {
    let mut parts = Vec::new();
    let mut n_records: usize = 0;
    for rec in &r.records {
        let items = of(rec);
        if items.is_empty() {
            continue;
        }
        n_records += 1;
        if parts.len() < NOTED_RECORDS_SHOWN {
            parts.push(format!("{}: {}", rec.name, items.join(", ")));
        }
    }
    let more = n_records.saturating_sub(NOTED_RECORDS_SHOWN);
    (n_records > 0).then(|| {
        let mut list = parts.join("; ");
        if more > 0 {
            list.push_str(&format!("; and {more} more"));
        }
        (n_records, list)
    })
}

/// Most records [`sensor_notes`] names per sentence (the JSON lists them all).
const NOTED_RECORDS_SHOWN: usize = 5;

/// The first line of the terminal summary: counts, rate, cutoff, orders and run time.
pub fn run_summary_line(r: &AnalysisResults) -> String {
    format!(
        "{} records, {} channels, {} fits ({} not converged, {} failed) in {:.1} s; analysis at {} Hz, cutoff {} Hz, orders {}..{}",
        r.records.len(),
        r.channels.len(),
        r.n_fits,
        r.n_not_converged,
        r.n_failed,
        r.timing.elapsed_s,
        r.config.preprocess.analysis_fs_hz,
        r.config.preprocess.cutoff_hz,
        r.config.sweep.order_min,
        r.config.sweep.order_max
    )
}

/// What the support tests rejected, for a pool without any invariant mode: the densest
/// candidates (most poles) with the tests each failed.
fn candidates_text(r: &AnalysisResults, pool: &Pool<'_>, indent: &str) -> String {
    let modes = pool.modes;
    let n_active = r.records.len() - r.n_stationary;
    let fits: Vec<&vibmode_core::FitSummary> =
        pool.channels.iter().flat_map(|c| c.fits.iter()).collect();
    let failed: Vec<&vibmode_core::FitSummary> =
        fits.iter().copied().filter(|f| f.failed).collect();
    if !fits.is_empty() && failed.len() == fits.len() {
        let why = failed
            .iter()
            .find_map(|f| f.error.as_deref())
            .unwrap_or("no reason recorded");
        return format!(
            "{indent}every one of the {} fits failed, so there are no poles; the first failure: {why}\n",
            fits.len()
        );
    }
    let mut cands: Vec<&InvariantMode> = modes
        .iter()
        .filter(|m| m.class == ModeClass::Spurious)
        .collect();
    cands.sort_by_key(|m| std::cmp::Reverse(m.n_poles));
    if cands.is_empty() {
        return format!(
            "{indent}no cluster of poles at all: every pole was isolated or outside the band\n"
        );
    }
    let mut s = format!("{indent}no cluster passed the support tests; the best candidates:\n");
    for m in cands.iter().take(3) {
        let why: Vec<String> = m
            .support_failures(&r.config.cluster, n_active)
            .iter()
            .map(|f| f.to_string())
            .collect();
        let _ = writeln!(
            s,
            "{indent}  {:.2} Hz, damping {:.2}: {}",
            m.frequency_hz,
            m.damping_ratio,
            why.join("; ")
        );
    }
    s
}

/// The invariant-mode table per role, as printed by the command line; with `truth`, the true
/// modes beside it. A pool without invariant modes says so and lists the best candidates with
/// the support test each failed.
pub fn modes_table_text(r: &AnalysisResults, truth: Option<&[TruthRow]>) -> String {
    let mut s = run_summary_line(r);
    s.push('\n');
    if r.n_stationary > 0 {
        let stops: Vec<&str> = r
            .records
            .iter()
            .filter(|rec| rec.stationary)
            .map(|rec| rec.name.as_str())
            .collect();
        let _ = writeln!(
            s,
            "{} of {} records were stops and are left out of the mode statistics: {}",
            r.n_stationary,
            r.records.len(),
            stops.join(", ")
        );
    }
    for line in sensor_notes(r) {
        let _ = writeln!(s, "{line}");
    }
    for pool in pools(r) {
        let _ = writeln!(s, "\nInvariant modes, {}:", pool.title);
        let _ = writeln!(
            s,
            "  {:>9} {:>8} {:>9} {:>7} {:>7}  class",
            "freq_hz", "std_hz", "damping", "orders", "records"
        );
        let mut any = false;
        for m in shown(pool.modes) {
            any = true;
            let _ = writeln!(
                s,
                "  {:>9.3} {:>8.3} {:>9.4} {:>6.0}% {:>6.0}%  {}{}",
                m.frequency_hz,
                m.frequency_std_hz,
                m.damping_ratio,
                100.0 * m.order_share,
                100.0 * m.record_share,
                class_name(&m.class),
                uncertainty_text(m).map_or(String::new(), |u| format!(" ({u})"))
            );
        }
        if !any {
            s.push_str(&candidates_text(r, &pool, "  "));
        }
        if pool.note.is_none() {
            // (the body band's pool has no lines of its own: they are the other pools')
            s.push_str(&lines_text(r, pool.lines, "  "));
        }
        s.push_str(&matches_text(pool.matches, pool.modes, "  "));
        if let Some(n) = &pool.note {
            let _ = writeln!(s, "  {n}");
        }
    }
    if let Some(why) = &r.body_ssi_not_run {
        let _ = writeln!(
            s,
            "\nBody-band SSI-cov beyond each record's wheelbase delay: not run: {why}"
        );
    }
    if let Some(t) = truth {
        s.push_str("\nTrue values (simulation):\n");
        let _ = writeln!(s, "  {:>9} {:>9}  what", "freq_hz", "damping");
        for (label, f, z) in t {
            let _ = writeln!(s, "  {f:>9.3} {z:>9.4}  {label}");
        }
    }
    s
}

/// The physical-model modes and the identified mode each was matched to (with the MAC of their
/// shapes when both have one), or nothing when there is no model.
fn matches_text(
    matches: &[vibmode_core::ModeMatch],
    modes: &[InvariantMode],
    indent: &str,
) -> String {
    let mut s = String::new();
    if matches.is_empty() {
        return s;
    }
    let _ = writeln!(s, "{indent}Model modes matched:");
    for m in matches {
        let found = m.invariant.and_then(|i| modes.get(i));
        match found {
            Some(inv) => {
                let mac = m.mac.map_or(String::new(), |v| format!(", MAC {v:.2}"));
                let _ = writeln!(
                    s,
                    "{indent}  {:<20} {:>7.3} Hz -> {:>7.3} Hz ({:+.1} %), damping {:.3} -> {:.3}{mac}",
                    m.reference.label,
                    m.reference.frequency_hz,
                    inv.frequency_hz,
                    100.0 * m.freq_diff_rel,
                    m.reference.damping_ratio,
                    inv.damping_ratio
                );
            }
            None => {
                // The nearest structural mode, and where it went: matching is one to one.
                let tol = vibmode_modal::MATCH_MAX_FREQ_DIFF_REL;
                let why = if m.freq_diff_rel.is_finite() && m.freq_diff_rel.abs() > tol {
                    format!(" (none within {:.0} %)", 100.0 * tol)
                } else if m.freq_diff_rel.is_finite() {
                    let near = m.reference.frequency_hz * (1.0 + m.freq_diff_rel);
                    let owner = matches
                        .iter()
                        .filter_map(|o| {
                            let inv = modes.get(o.invariant?)?;
                            ((inv.frequency_hz - near).abs() <= 1e-9 * near.max(1.0))
                                .then_some(o.reference.label.as_str())
                        })
                        .next();
                    match owner {
                        Some(label) => format!(
                            " (nearest {near:.3} Hz, {:+.1} %, is {label}'s)",
                            100.0 * m.freq_diff_rel
                        ),
                        None => {
                            format!(" (nearest {near:.3} Hz, {:+.1} %)", 100.0 * m.freq_diff_rel)
                        }
                    }
                } else {
                    String::new()
                };
                let _ = writeln!(
                    s,
                    "{indent}  {:<20} {:>7.3} Hz -> not found{why}",
                    m.reference.label, m.reference.frequency_hz
                );
            }
        }
    }
    s
}

/// A track's entry in record `r`: its steady frequency (`7.00`), its sweep from start to end
/// (`7.04>5.19`), or `-` where it was not found.
fn record_entry(t: &vibmode_analysis::LineTrack, r: usize) -> String {
    if let Some(f) = t.record_hz.get(r).copied().flatten() {
        return format!("{f:.2}");
    }
    match t.record_sweep.get(r).and_then(Option::as_ref) {
        Some(s) => format!("{:.2}>{:.2}", s.start_hz, s.end_hz),
        None => "-".to_string(),
    }
}

/// The swept entries of `lines`, one sentence each: record (1-based), start, end, range,
/// kurtosis along the ridge and the time the ridge spans.
fn sweep_sentences(lines: &[vibmode_analysis::LineTrack]) -> Vec<String> {
    let mut out = Vec::new();
    for t in lines {
        for (r, s) in t.record_sweep.iter().enumerate() {
            let Some(s) = s else { continue };
            let (t0, t1) = (
                s.time_s.first().copied().unwrap_or(0.0),
                s.time_s.last().copied().unwrap_or(0.0),
            );
            out.push(format!(
                "record {}: {:.2} -> {:.2} Hz from {:.1} to {:.1} s (range {:.2}-{:.2} Hz, kurtosis along the ridge {:.2})",
                r + 1,
                s.start_hz,
                s.end_hz,
                t0,
                t1,
                s.range_hz.0,
                s.range_hz.1,
                s.kurtosis
            ));
        }
    }
    out
}

/// The periodic lines of a pool, one per row with its frequency in each record (`-` where it was
/// not found, `start>end` where it swept within the record), then the swept entries one per
/// line; or a sentence saying none was found.
pub fn lines_text(
    r: &AnalysisResults,
    lines: &[vibmode_analysis::LineTrack],
    indent: &str,
) -> String {
    let mut s = String::new();
    if r.config.lines.max_kurtosis <= 0.0 {
        return s;
    }
    if lines.is_empty() {
        let _ = writeln!(
            s,
            "{indent}No periodic lines (no harmonic F-test peak at p < {:e} per record and channel in two records or more, none over the pooled records at a false-alarm rate of {} for the band, no prominent peak with a narrow-band kurtosis below {} in {:.0} % of the records and two at least, no swept ridge).",
            r.config.lines.f_test_alpha,
            r.config.lines.f_test_combined_alpha,
            r.config.lines.max_kurtosis,
            100.0 * r.config.lines.min_record_share
        );
        return s;
    }
    let _ = writeln!(
        s,
        "{indent}Periodic lines (engine/gear orders: Thomson's harmonic F-test, or a narrow-band kurtosis near 1.5 for a line that drifts), frequency per record, Hz (a>b: swept from a to b within the record):"
    );
    for t in lines {
        let per: Vec<String> = (0..t.record_hz.len().max(t.record_sweep.len()))
            .map(|i| record_entry(t, i))
            .collect();
        let _ = writeln!(
            s,
            "{indent}  {:>7.2} Hz ({:.2}-{:.2}, {:.0} % of records, kurtosis {:.2}): {}",
            t.frequency_hz,
            t.frequency_range_hz.0,
            t.frequency_range_hz.1,
            100.0 * t.record_share,
            t.kurtosis,
            per.join(" ")
        );
    }
    let sweeps = sweep_sentences(lines);
    if !sweeps.is_empty() {
        let _ = writeln!(
            s,
            "{indent}Swept lines (a ridge of the short-time spectra, periodic along it):"
        );
        for l in sweeps {
            let _ = writeln!(s, "{indent}  {l}");
        }
    }
    s
}

/// The invariant modes of every role pool and every channel as CSV (one row per mode, spurious
/// clusters left out): `pool,channels,frequency_hz,frequency_std_hz,damping_ratio,
/// damping_iqr_lo,damping_iqr_hi,order_share,record_share,n_poles,class`.
pub fn modes_csv(r: &AnalysisResults) -> String {
    let mut s = String::from(
        "pool,channels,frequency_hz,frequency_std_hz,damping_ratio,damping_iqr_lo,damping_iqr_hi,order_share,record_share,n_poles,class\n",
    );
    let mut row = |pool: String, channels: String, m: &InvariantMode| {
        let _ = writeln!(
            s,
            "{},{},{},{},{},{},{},{},{},{},{}",
            csv_cell(&pool),
            csv_cell(&channels),
            m.frequency_hz,
            m.frequency_std_hz,
            m.damping_ratio,
            m.damping_iqr.0,
            m.damping_iqr.1,
            m.order_share,
            m.record_share,
            m.n_poles,
            m.class
        );
    };
    for role in &r.roles {
        for m in shown(&role.invariant_modes) {
            row(format!("role:{}", role.role), role.channels.join(" "), m);
        }
    }
    for ch in &r.channels {
        for m in shown(&ch.invariant_modes) {
            row(format!("channel:{}", ch.name), ch.name.clone(), m);
        }
    }
    if let Some(ssi) = &r.ssi {
        for m in shown(&ssi.invariant_modes) {
            row("ssi-cov".into(), ssi.channels.join(" "), m);
        }
    }
    s
}

fn csv_cell(text: &str) -> String {
    if text.contains([',', '"', '\n']) {
        format!("\"{}\"", text.replace('"', "\"\""))
    } else {
        text.to_string()
    }
}

/// The standard deviations of a mode, e.g. "jackknife sd 0.012 Hz, damping 0.010".
fn uncertainty_text(m: &InvariantMode) -> Option<String> {
    m.uncertainty.as_ref().map(|u| {
        let how = match u.method {
            vibmode_core::UncertaintyMethod::FirstOrder => "first-order",
            _ => "jackknife",
        };
        format!(
            "{how} sd {:.3} Hz, damping {:.3}",
            u.frequency_std_hz, u.damping_std
        )
    })
}

fn mode_row(m: &InvariantMode) -> Vec<String> {
    vec![
        format!("{:.3}", m.frequency_hz),
        format!("{:.3}", m.frequency_std_hz),
        format!("{:.4}", m.damping_ratio),
        format!("{:.4}-{:.4}", m.damping_iqr.0, m.damping_iqr.1),
        format!("{:.0} %", 100.0 * m.order_share),
        format!("{:.0} %", 100.0 * m.record_share),
        m.n_poles.to_string(),
        match uncertainty_text(m) {
            Some(u) => format!("{} ({u})", class_name(&m.class)),
            None => class_name(&m.class).to_string(),
        },
    ]
}

/// The summary paragraph: what was analysed, how, and what was found per role.
pub fn summary_text(r: &AnalysisResults) -> String {
    let cfg = &r.config;
    let mut s = format!(
        "{} record(s) of {} channel(s) were analysed at {} Hz after an ideal DFT low-pass at {} Hz; {} {} models (orders {} to {}) were fitted to each record and channel, {} fits in all ({} did not converge, {} failed) in {:.1} s. ",
        r.records.len(),
        r.channels.len(),
        cfg.preprocess.analysis_fs_hz,
        cfg.preprocess.cutoff_hz,
        match cfg.sweep.model {
            SweepModel::Arma => "ARMA(p,p)",
            SweepModel::Ar => "AR(p)",
        },
        if cfg.sweep.robust == Robust::Off { "quadratic-criterion" } else { "robust" },
        cfg.sweep.order_min,
        cfg.sweep.order_max,
        r.n_fits,
        r.n_not_converged,
        r.n_failed,
        r.timing.elapsed_s
    );
    for pool in pools(r) {
        s.push_str(&pool_sentence(&pool, cfg.cluster.disturbance_damping_max));
    }
    if r.n_stationary > 0 {
        let stops: Vec<String> = r
            .records
            .iter()
            .filter(|rec| rec.stationary)
            .map(|rec| {
                format!(
                    "{} (activity {:.2} of the median record)",
                    rec.name, rec.activity_ratio
                )
            })
            .collect();
        let _ = write!(
            s,
            "{} of {} records were stops (acceleration RMS in {}-{} Hz below {} of the median record) and were left out of the mode statistics: {}. ",
            r.n_stationary,
            r.records.len(),
            cfg.stops.activity_min_hz,
            cfg.preprocess.cutoff_hz,
            cfg.stops.stop_rms_ratio,
            stops.join(", ")
        );
    }
    for line in sensor_notes(r) {
        s.push_str(&line);
        s.push(' ');
    }
    if cfg.preset == vibmode_analysis::Preset::Paper {
        s.push_str("These are the paper's settings. At 200 Hz with a 25 Hz cutoff the band 25-100 Hz is empty: three quarters of the poles of every model are spent on it, the prediction-error criterion has no minimum without the -30 dB numerical noise floor vibmode adds to such signals, the ideal filter's edge draws lightly damped poles of its own (poles above 0.8 x the cutoff are left out by the pole filters), and every fit has four times the samples. On the simulated bus this costs about 14 times the default preset's time, spreads the wheel hop over 1.5 Hz and merges the 11 and 12 Hz engine lines into one cluster taken for a structural mode; the default preset analyses at 50 Hz (twice the cutoff, the same information) instead. ");
    }
    s
}

fn pool_sentence(pool: &Pool<'_>, disturbance_damping_max: f64) -> String {
    let st: Vec<String> = pool
        .modes
        .iter()
        .filter(|m| m.class == ModeClass::Structural)
        .map(|m| format!("{:.2} Hz (damping {:.3})", m.frequency_hz, m.damping_ratio))
        .collect();
    let di: Vec<String> = freqs_of(pool.modes, ModeClass::PeriodicDisturbance)
        .iter()
        .map(|f| format!("{f:.2} Hz"))
        .collect();
    let structural = if st.is_empty() {
        format!(
            "On {} no invariant structural mode was found (see the table for the candidates the support tests rejected)",
            pool.subject
        )
    } else {
        format!(
            "On {} the invariant structural modes are {}",
            pool.subject,
            st.join(", ")
        )
    };
    let lines = if di.is_empty() {
        "no periodic disturbance (line with damping below {}) was found"
            .replace("{}", &disturbance_damping_max.to_string())
    } else {
        format!(
            "periodic disturbances (lines with damping below {disturbance_damping_max}) lie at {}",
            di.join(", ")
        )
    };
    format!("{structural}; {lines}. ")
}

/// Builds figures, numbers them once (heading and caption agree) and saves each as SVG and PNG.
struct FigureWriter<'a> {
    dir: &'a Path,
    html: HtmlReport,
    files: Vec<PathBuf>,
}

impl FigureWriter<'_> {
    fn add(
        &mut self,
        file: &str,
        title: &str,
        fig: &Figure,
        caption: &str,
    ) -> Result<(), ReportError> {
        let n = self.html.figure_count() + 1;
        for ext in ["svg", "png"] {
            let path = self.dir.join(format!("fig{n:02}_{file}.{ext}"));
            fig.save(&path)?;
            self.files.push(path);
        }
        self.html.heading(2, &format!("Figure {n}: {title}"));
        let folder = self
            .dir
            .file_name()
            .map(|f| f.to_string_lossy().into_owned())
            .unwrap_or_default();
        self.html.figure_or_image(
            fig,
            caption,
            &format!("{folder}/fig{n:02}_{file}.png"),
            crate::html::INLINE_SVG_MAX_BYTES,
        )
    }
}

fn line(label: &str, x: Vec<f64>, y: Vec<f64>, width: u32, alpha: f64) -> Series {
    Series::line(x, y)
        .with_label(label)
        .with_style(SeriesStyle::Line {
            width,
            dashed: false,
        })
        .with_alpha(alpha)
}

/// Most samples drawn per channel in the time-record figure.
const TIME_FIGURE_MAX_POINTS: usize = 20_000;

fn time_records_figure(name: &str, rec: &Recording) -> Figure {
    let panels = rec
        .channels
        .iter()
        .map(|ch| {
            let n = ch.samples.len();
            let step = (n / TIME_FIGURE_MAX_POINTS).max(1);
            let x: Vec<f64> = (0..n).step_by(step).map(|i| i as f64 / rec.fs_hz).collect();
            let y: Vec<f64> = ch.samples.iter().step_by(step).copied().collect();
            Panel::new(
                format!("{name}: {}", ch.name),
                "Time [s]",
                format!("Acceleration [{}]", unit_label(&ch.unit)),
            )
            .with_series(line(&ch.name, x, y, 1, 1.0))
            .without_legend()
        })
        .collect();
    grid(panels, 2, 600, 260)
}

/// The vehicle's speed over the recording from its GPS track (thin line) with each record cut
/// by GPS marked at its mean speed (thick segments); `None` when no record has a speed.
fn drive_figure(r: &AnalysisResults) -> Option<Figure> {
    let segs: Vec<&vibmode_core::RecordMeta> = r
        .records
        .iter()
        .filter_map(|x| x.segment.as_ref())
        .collect();
    if !segs.iter().any(|m| m.mean_speed_kmh.is_some()) {
        return None;
    }
    let mut panel = Panel::new(
        "speed over the drive, records marked",
        "Time in the recording [s]",
        "Speed [km/h]",
    );
    if !r.drive_speed_trace.is_empty() {
        let (t, v): (Vec<f64>, Vec<f64>) = r.drive_speed_trace.iter().map(|p| (p[0], p[1])).unzip();
        panel = panel.with_series(line("GPS speed", t, v, 1, 0.6));
    }
    // One series, the records' segments separated by NaN (which breaks a polyline).
    let (mut x, mut y) = (Vec::new(), Vec::new());
    for m in segs {
        if let Some(v) = m.mean_speed_kmh {
            x.extend([m.start_s, m.start_s + m.duration_s, f64::NAN]);
            y.extend([v, v, f64::NAN]);
        }
    }
    panel = panel.with_series(line("record (mean speed)", x, y, 4, 1.0));
    Some(grid(vec![panel], 1, 900, 300))
}

fn spectra_figures(
    r: &AnalysisResults,
    spectra: &[FirstRecordSpectra],
    fmax: f64,
) -> (Figure, Figure) {
    let mut p5 = Vec::new();
    let mut p67 = Vec::new();
    for (ch, sp) in r.channels.iter().zip(spectra) {
        let (px, py) = positive_freq(&sp.periodogram_freq_hz, &sp.periodogram_psd);
        let (wx, wy) = positive_freq(&sp.welch_freq_hz, &sp.welch_psd);
        p5.push(
            Panel::new(
                format!("{} ({})", ch.name, ch.role),
                "Frequency [Hz]",
                psd_label(&ch.unit),
            )
            .with_scales(Scale::Linear, Scale::Log)
            .with_x_range(0.0, fmax)
            .with_series(line("periodogram", px, py, 1, 0.4))
            .with_series(line("Welch", wx.clone(), wy.clone(), 2, 1.0)),
        );
        let mut panel = Panel::new(
            format!("{}: model PSD over Welch", ch.name),
            "Frequency [Hz]",
            psd_label(&ch.unit),
        )
        .with_scales(Scale::Linear, Scale::Log)
        .with_x_range(0.0, fmax)
        .with_series(line("Welch", wx, wy, 2, 0.7));
        for m in &sp.models {
            panel = panel.with_series(line(
                &format!("ARMA({},{})", m.order, m.order),
                sp.model_freq_hz.clone(),
                m.psd.clone(),
                2,
                1.0,
            ));
        }
        p67.push(panel);
    }
    (grid(p5, 2, 600, 340), grid(p67, 2, 600, 340))
}

fn stabilisation_figure(r: &AnalysisResults, fmax: f64) -> Figure {
    let panels = r
        .channels
        .iter()
        .map(|ch| {
            let pts: Vec<(usize, f64, f64)> = ch
                .poles
                .iter()
                .map(|p| (p.order, p.frequency_hz, p.damping_ratio))
                .collect();
            let mut panel = stabilisation_panel(
                &format!("{}: all records", ch.name),
                &pts,
                &ch.welch_freq_hz,
                &ch.welch_psd,
                fmax,
            );
            panel.series.extend(mode_marks(
                &freqs_of(&ch.invariant_modes, ModeClass::Structural),
                &freqs_of(&ch.invariant_modes, ModeClass::PeriodicDisturbance),
            ));
            panel
        })
        .collect();
    grid(panels, 2, 600, 400)
}

fn damping_figure(r: &AnalysisResults, fmax: f64) -> Figure {
    let refs: Vec<(f64, f64, String)> = r
        .reference_modes
        .iter()
        .map(|m| (m.frequency_hz, m.damping_ratio, m.label.clone()))
        .collect();
    let panels = pools(r)
        .iter()
        .map(|pool| {
            let pts: Vec<(usize, f64, f64)> = pool
                .channels
                .iter()
                .flat_map(|c| {
                    c.poles
                        .iter()
                        .map(|p| (p.order, p.frequency_hz, p.damping_ratio))
                })
                .collect();
            let mut panel = damping_panel(
                &format!("{}: frequency vs damping", pool.subject),
                &pts,
                &refs,
                fmax,
            );
            panel.series.extend(mode_marks(
                &freqs_of(pool.modes, ModeClass::Structural),
                &freqs_of(pool.modes, ModeClass::PeriodicDisturbance),
            ));
            panel
        })
        .collect();
    grid(panels, 1, 1000, 450)
}

fn inputs_table(html: &mut HtmlReport, r: &AnalysisResults) {
    html.heading(2, "Inputs");
    let units: Vec<String> = r
        .channels
        .iter()
        .map(|c| format!("{} [{}]", c.name, unit_label(&c.unit)))
        .collect();
    html.paragraph(&format!("Channels: {}.", units.join(", ")));
    let rows: Vec<Vec<String>> = r
        .records
        .iter()
        .map(|rec| {
            vec![
                rec.name.clone(),
                format!("{}", rec.fs_hz),
                rec.n_samples.to_string(),
                format!("{:.2}", rec.duration_s),
                format!("{:.3}", rec.band.fs_hz),
                format!("{:.2}", rec.activity_ratio),
                rec.segment.as_ref().map_or("-".into(), |m| {
                    let mut t = format!("{:.1} s", m.start_s);
                    if let Some(v) = m.mean_speed_kmh {
                        t.push_str(&format!(", {v:.1} km/h"));
                    }
                    if let (Some(la), Some(lo)) = (m.lat_deg, m.lon_deg) {
                        t.push_str(&format!(", {la:.5} {lo:.5}"));
                    }
                    t
                }),
                rec.excluded_reason.clone().unwrap_or_else(|| "used".into()),
            ]
        })
        .collect();
    html.table(
        &[
            "record",
            "rate [Hz]",
            "samples",
            "duration [s]",
            "analysis rate [Hz]",
            "activity",
            "start, speed, position",
            "status",
        ],
        &rows,
    );
}

/// The mode shapes of the multichannel structural modes (modulus and phase per channel) and, with
/// a physical model, the MAC matrix between the model's modes and the identified ones.
fn shape_tables(
    html: &mut HtmlReport,
    ssi: &vibmode_analysis::SsiAnalysis,
    reference: &[vibmode_core::ReferenceMode],
) {
    let modes: Vec<&InvariantMode> = ssi
        .invariant_modes
        .iter()
        .filter(|m| m.class == vibmode_core::ModeClass::Structural && m.shape.is_some())
        .collect();
    if modes.is_empty() {
        return;
    }
    html.paragraph(
        "Mode shapes of the structural modes (all channels identified together): modulus / phase in degrees per channel, the largest entry 1 / 0; the shape's spread is the median and lowest MAC of the cluster's poles with the mean shape.",
    );
    let mut headers: Vec<String> =
        vec!["frequency [Hz]".into(), "shape MAC (median, lowest)".into()];
    headers.extend(ssi.channels.iter().cloned());
    let rows: Vec<Vec<String>> = modes
        .iter()
        .map(|m| {
            let mut row = vec![
                format!("{:.3}", m.frequency_hz),
                m.shape_mac
                    .map_or("-".into(), |(a, b)| format!("{a:.2}, {b:.2}")),
            ];
            if let Some(shape) = &m.shape {
                row.extend(shape.iter().map(|v| {
                    format!(
                        "{:.2} / {:+.0}",
                        v[0].hypot(v[1]),
                        v[1].atan2(v[0]).to_degrees()
                    )
                }));
            }
            row
        })
        .collect();
    let h: Vec<&str> = headers.iter().map(String::as_str).collect();
    html.table(&h, &rows);
    let with_shape: Vec<(&vibmode_core::ReferenceMode, Vec<[f64; 2]>)> = reference
        .iter()
        .filter_map(|r| r.shape_for(&ssi.channels).map(|s| (r, s)))
        .collect();
    if with_shape.is_empty() {
        return;
    }
    html.paragraph(
        "MAC between the physical model's modes (rows, their shapes at the sensors) and the identified structural modes (columns); 1 = the same shape.",
    );
    let mut headers: Vec<String> = vec!["model mode".into(), "model f [Hz]".into()];
    headers.extend(modes.iter().map(|m| format!("{:.2} Hz", m.frequency_hz)));
    let rows: Vec<Vec<String>> = with_shape
        .iter()
        .map(|(r, rs)| {
            let mut row = vec![r.label.clone(), format!("{:.3}", r.frequency_hz)];
            row.extend(modes.iter().map(|m| {
                m.shape.as_ref().map_or("-".into(), |ms| {
                    format!("{:.2}", vibmode_modal::shapes::mac(rs, ms))
                })
            }));
            row
        })
        .collect();
    let h: Vec<&str> = headers.iter().map(String::as_str).collect();
    html.table(&h, &rows);
}

/// The pool's periodic lines: one row per track with its frequency in every record.
fn lines_table(html: &mut HtmlReport, r: &AnalysisResults, lines: &[vibmode_analysis::LineTrack]) {
    if r.config.lines.max_kurtosis <= 0.0 {
        return;
    }
    if lines.is_empty() {
        html.paragraph(lines_text(r, lines, "").trim());
        return;
    }
    html.paragraph(
        "Periodic lines (engine/gear orders), tracked over the records: a sinusoid found by Thomson's multitaper harmonic F-test at a stated false-alarm rate (docs/analysis.md), or, for a line that drifts within a record, a prominent peak whose narrow-band signal has the kurtosis of a sine (1.5) rather than of a randomly excited mode (3). Frequency in each record, Hz (- = not found there or a stop; a>b = swept from a to b Hz within the record: a ridge of the short-time spectra along which the signal has the kurtosis of a sine).",
    );
    let mut headers: Vec<String> = vec![
        "frequency [Hz]".into(),
        "range [Hz]".into(),
        "records".into(),
        "kurtosis".into(),
    ];
    headers.extend((1..=r.records.len()).map(|i| format!("r{i}")));
    let rows: Vec<Vec<String>> = lines
        .iter()
        .map(|t| {
            let mut row = vec![
                format!("{:.2}", t.frequency_hz),
                format!(
                    "{:.2}-{:.2}",
                    t.frequency_range_hz.0, t.frequency_range_hz.1
                ),
                format!("{:.0} %", 100.0 * t.record_share),
                format!("{:.2}", t.kurtosis),
            ];
            row.extend((0..r.records.len()).map(|i| record_entry(t, i)));
            row
        })
        .collect();
    let h: Vec<&str> = headers.iter().map(String::as_str).collect();
    html.table(&h, &rows);
    let sweeps = sweep_sentences(lines);
    if !sweeps.is_empty() {
        html.paragraph(&format!(
            "Swept lines (a ridge of the short-time spectra, periodic along it; the frequency per slice is in results.json): {}.",
            sweeps.join("; ")
        ));
    }
}

fn modes_tables(html: &mut HtmlReport, r: &AnalysisResults) {
    html.heading(2, "Invariant modes");
    let headers = [
        "frequency [Hz]",
        "std [Hz]",
        "damping ratio (median)",
        "damping IQR",
        "orders",
        "records",
        "poles",
        "class",
    ];
    for pool in pools(r) {
        html.heading(3, &pool.title);
        let rows: Vec<Vec<String>> = shown(pool.modes).map(mode_row).collect();
        if rows.is_empty() {
            html.paragraph(&candidates_text(r, &pool, ""));
        } else {
            html.table(&headers, &rows);
        }
        if pool.note.is_none() {
            lines_table(html, r, pool.lines);
        }
        if let Some(n) = &pool.note {
            html.paragraph(n);
        }
        if let Some(ssi) = r
            .ssi
            .as_ref()
            .filter(|ssi| std::ptr::eq(pool.modes, ssi.invariant_modes.as_slice()))
        {
            shape_tables(html, ssi, &r.reference_modes);
        }
        if !pool.matches.is_empty() {
            html.paragraph("Physical model modes matched to the invariant structural modes:");
            let rows: Vec<Vec<String>> = pool
                .matches
                .iter()
                .map(|m| {
                    let inv = m.invariant.and_then(|i| pool.modes.get(i));
                    let or_dash = |v: Option<String>| v.unwrap_or_else(|| "-".into());
                    vec![
                        m.reference.label.clone(),
                        format!("{:.3}", m.reference.frequency_hz),
                        format!("{:.3}", m.reference.damping_ratio),
                        or_dash(inv.map(|i| format!("{:.3}", i.frequency_hz))),
                        or_dash(inv.map(|i| format!("{:.3}", i.damping_ratio))),
                        or_dash(inv.map(|_| format!("{:+.1} %", 100.0 * m.freq_diff_rel))),
                        or_dash(inv.map(|_| format!("{:+.3}", m.damping_diff))),
                        or_dash(m.mac.map(|v| format!("{v:.2}"))),
                    ]
                })
                .collect();
            html.table(
                &[
                    "model mode",
                    "model f [Hz]",
                    "model damping",
                    "identified f [Hz]",
                    "identified damping",
                    "f difference",
                    "damping difference",
                    "MAC",
                ],
                &rows,
            );
        }
    }
    if let Some(why) = &r.body_ssi_not_run {
        html.paragraph(&format!(
            "Body-band SSI-cov beyond each record's wheelbase delay: not run: {why}"
        ));
    }
}

fn write_text(path: &Path, text: &str) -> Result<(), ReportError> {
    std::fs::write(path, text).map_err(|e| ReportError::Write {
        path: path.to_path_buf(),
        message: e.to_string(),
    })
}

/// The figures of the report, in the paper's order.
fn add_figures(
    w: &mut FigureWriter<'_>,
    first: &RecordInput,
    r: &AnalysisResults,
    spectra: &[FirstRecordSpectra],
) -> Result<(), ReportError> {
    let cfg = &r.config;
    let fmax = cfg.preprocess.analysis_fs_hz / 2.0;
    let fig = time_records_figure(&first.name, &first.recording);
    w.add(
        "time_records",
        "time records",
        &fig,
        "Acceleration of the first record, every channel.",
    )?;
    if first.recording.fs_hz > cfg.preprocess.analysis_fs_hz * 1.0001 {
        let band = r.records.first().map(|x| x.band);
        let cutoff = band.map_or(cfg.preprocess.cutoff_hz, |b| b.cutoff_hz);
        let fig = crate::signal_figures::antialias_figure(
            &first.recording,
            cfg.preprocess.analysis_fs_hz,
            Some(cutoff),
            0.5,
        )?;
        w.add(
            "antialias",
            "anti-aliasing and resampling",
            &fig,
            &format!(
                "First channel: raw at {} Hz, resampled to {} Hz without filter (aliased), and with the ideal DFT low-pass at {} Hz.",
                first.recording.fs_hz, cfg.preprocess.analysis_fs_hz, cutoff
            ),
        )?;
    }
    if let Some(fig) = drive_figure(r) {
        w.add(
            "drive",
            "speed over the drive, records marked",
            &fig,
            "The vehicle's speed from the GPS track (thin line) over the time in the recording, and each record cut from it at its mean speed (a bar from its start to its end); the gaps are what the segmentation skipped (stops, braking, turns; segments.json says why).",
        )?;
    }
    let (fig5, fig67) = spectra_figures(r, spectra, fmax);
    w.add(
        "periodogram_welch",
        "periodogram and Welch spectra",
        &fig5,
        "First record of each channel: periodogram (boxcar) and Welch (Hann).",
    )?;
    w.add(
        "model_psd",
        "model spectra",
        &fig67,
        &format!(
            "ARMA model PSD of the first record at orders {:?}, over its Welch estimate.",
            cfg.report.model_psd_orders
        ),
    )?;
    w.add(
        "stabilisation",
        "stabilisation diagrams",
        &stabilisation_figure(r, fmax),
        "Frequency of every complex pole pair that passed the pole filters against model order, all records; the Welch PSD (log) drawn behind; the channel's invariant structural modes (green) and periodic disturbances (orange, dotted) marked.",
    )?;
    let with_model = if r.reference_modes.is_empty() {
        ""
    } else {
        "; red diamonds: the physical model's modes"
    };
    w.add(
        "frequency_damping",
        "frequency and damping",
        &damping_figure(r, fmax),
        &format!("Every pole pair of every order and record, pooled per role; the pool's invariant structural modes (green) and periodic disturbances (orange, dotted) marked{with_model}."),
    )?;
    if let Some(ssi) = &r.ssi {
        shape_figures(w, r, ssi)?;
    }
    Ok(())
}

/// The multichannel modes' shapes on the sensor layout, and the MAC matrix against the model.
fn shape_figures(
    w: &mut FigureWriter<'_>,
    r: &AnalysisResults,
    ssi: &vibmode_analysis::SsiAnalysis,
) -> Result<(), ReportError> {
    use crate::shape_figures::{
        layout_position, mac_matrix, mac_matrix_figure, mode_shapes_figure, shaped_structural,
    };
    let modes = shaped_structural(&ssi.invariant_modes);
    let positions: Vec<Option<(f64, f64)>> = ssi
        .channels
        .iter()
        .map(|name| {
            r.channels
                .iter()
                .find(|c| &c.name == name)
                .and_then(|c| layout_position(c.role, c.placement.corner))
        })
        .collect();
    let labels: Vec<Option<String>> = modes
        .iter()
        .map(|m| {
            ssi.matches.iter().find_map(|mm| {
                let k = mm.invariant?;
                std::ptr::eq(ssi.invariant_modes.get(k)?, *m).then(|| {
                    format!(
                        "{}, MAC {}",
                        mm.reference.label,
                        mm.mac.map_or("-".into(), |v| format!("{v:.2}"))
                    )
                })
            })
        })
        .collect();
    let unplaced: Vec<&str> = ssi
        .channels
        .iter()
        .zip(&positions)
        .filter(|(_, p)| p.is_none())
        .map(|(c, _)| c.as_str())
        .collect();
    if let Some(fig) = mode_shapes_figure(&modes, &labels, &positions) {
        let left_out = if unplaced.is_empty() {
            String::new()
        } else {
            format!(
                " Channels without a corner are not drawn: {}.",
                unplaced.join(", ")
            )
        };
        w.add(
            "mode_shapes",
            "mode shapes on the sensor layout",
            &fig,
            &format!("Each structural mode of all channels identified together, seen from above (front to the right, left up; schematic positions from the channels' corners: wheels outside the body outline, body sensors inside): a circle per sensor whose area grows with the modulus of its shape entry (the largest 1), blue in phase with the largest entry (within 90 degrees), red opposite. The matched model mode and its MAC are in the title.{left_out} Moduli and phases are in the mode-shape table."),
        )?;
    }
    let (rows, mac) = mac_matrix(&r.reference_modes, &ssi.channels, &modes);
    if let Some(fig) = mac_matrix_figure(&mac) {
        let cols: Vec<String> = modes
            .iter()
            .enumerate()
            .map(|(j, m)| format!("{} = {:.3} Hz", j + 1, m.frequency_hz))
            .collect();
        let rows: Vec<String> = rows
            .iter()
            .enumerate()
            .map(|(i, l)| format!("{} = {l}", i + 1))
            .collect();
        w.add(
            "mac_matrix",
            "MAC matrix, model against identified modes",
            &fig,
            &format!(
                "MAC between the physical model's mode shapes at the sensors and the identified structural modes' shapes; 1 = the same shape. Columns: {}. Rows, from the bottom: {}.",
                cols.join(", "),
                rows.join(", ")
            ),
        )?;
    }
    Ok(())
}

/// The line of the top-level `channels` key in the pretty-printed results when it holds no
/// channel: [`write_results_json`] writes the channels there, one at a time.
const EMPTY_CHANNELS_LINE: &str = "\n  \"channels\": [],\n";

/// Writes `path` (`results.json`): `r`, with each of `extra`'s JSON values under its key, as
/// `serde_json::to_string_pretty` of the whole value writes it (keys sorted, two-space indent)
/// plus a newline, byte for byte; but only one channel's results are held as a JSON value at a
/// time (the channels' fits and poles are nearly all of it: an hour of records makes 56 MB of
/// text and several times that as one value), and the text goes to the file as it is made.
fn write_results_json(
    path: &Path,
    r: &AnalysisResults,
    extra: &[crate::ReportSection],
) -> Result<(), ReportError> {
    use std::io::Write;
    let err = |message: String| ReportError::Write {
        path: path.to_path_buf(),
        message,
    };
    let json_err = |e: serde_json::Error| err(e.to_string());
    let io_err = |e: std::io::Error| err(e.to_string());
    let with_extra = |mut value: serde_json::Value| {
        if let serde_json::Value::Object(map) = &mut value {
            for (key, v) in extra.iter().filter_map(|s| s.json.as_ref()) {
                map.insert(key.clone(), v.clone());
            }
        }
        value
    };
    let rest = AnalysisResults {
        schema_version: r.schema_version,
        drive_speed_trace: r.drive_speed_trace.clone(),
        config: r.config.clone(),
        records: r.records.clone(),
        channels: Vec::new(),
        roles: r.roles.clone(),
        ssi: r.ssi.clone(),
        body_ssi: r.body_ssi.clone(),
        body_ssi_not_run: r.body_ssi_not_run.clone(),
        reference_modes: r.reference_modes.clone(),
        n_stationary: r.n_stationary,
        n_fits: r.n_fits,
        n_not_converged: r.n_not_converged,
        n_failed: r.n_failed,
        timing: r.timing.clone(),
    };
    let text =
        serde_json::to_string_pretty(&with_extra(serde_json::to_value(&rest).map_err(json_err)?))
            .map_err(json_err)?;
    let file = std::fs::File::create(path).map_err(io_err)?;
    let mut w = std::io::BufWriter::new(file);
    match text.find(EMPTY_CHANNELS_LINE) {
        Some(at) if !r.channels.is_empty() => {
            w.write_all(&text.as_bytes()[..at]).map_err(io_err)?;
            w.write_all(b"\n  \"channels\": [\n").map_err(io_err)?;
            for (k, ch) in r.channels.iter().enumerate() {
                // Through a value, as before: its maps' keys sorted.
                let one = serde_json::to_value(ch).map_err(json_err)?;
                let one = serde_json::to_string_pretty(&one).map_err(json_err)?;
                // An array element two levels deep: every line indented by four spaces (a
                // JSON string holds no raw line break).
                for (j, line) in one.split('\n').enumerate() {
                    if j > 0 {
                        w.write_all(b"\n").map_err(io_err)?;
                    }
                    w.write_all(b"    ").map_err(io_err)?;
                    w.write_all(line.as_bytes()).map_err(io_err)?;
                }
                let end: &[u8] = if k + 1 < r.channels.len() {
                    b",\n"
                } else {
                    b"\n"
                };
                w.write_all(end).map_err(io_err)?;
            }
            w.write_all(b"  ],\n").map_err(io_err)?;
            w.write_all(&text.as_bytes()[at + EMPTY_CHANNELS_LINE.len()..])
                .map_err(io_err)?;
        }
        Some(_) => w.write_all(text.as_bytes()).map_err(io_err)?,
        // Not where expected (never with today's keys): the whole value at once.
        None => {
            let all = with_extra(serde_json::to_value(r).map_err(json_err)?);
            let all = serde_json::to_string_pretty(&all).map_err(json_err)?;
            w.write_all(all.as_bytes()).map_err(io_err)?;
        }
    }
    w.write_all(b"\n").map_err(io_err)?;
    w.flush().map_err(io_err)
}

/// Writes `DIR/index.html`, `DIR/results.json`, `DIR/modes.csv` and `DIR/figures/*.svg|png` for
/// the analysis `r` whose first record is `first` (as read and as the analysis pre-processed it);
/// `intro` is a first paragraph (e.g. what was simulated), `extra`
/// are sections after the modes' tables (e.g. the model update).
pub fn write_analysis_report(
    dir: &Path,
    first: &FirstRecord,
    r: &AnalysisResults,
    intro: Option<&str>,
    extra: &[crate::ReportSection],
) -> Result<ReportFiles, ReportError> {
    let figdir = dir.join("figures");
    std::fs::create_dir_all(&figdir).map_err(|e| ReportError::Write {
        path: figdir.clone(),
        message: e.to_string(),
    })?;
    let results_json = dir.join("results.json");
    write_results_json(&results_json, r, extra)?;
    let modes_csv_path = dir.join("modes.csv");
    write_text(&modes_csv_path, &modes_csv(r))?;
    let spectra = first_record_spectra(&first.prepared, r)
        .map_err(|e| ReportError::Analysis(e.to_string()))?;
    let first = &first.record;
    let mut html = HtmlReport::new("vibmode: vibration modes from in-service accelerations");
    if let Some(t) = intro {
        html.paragraph(t);
    }
    html.paragraph(&summary_text(r));
    inputs_table(&mut html, r);
    let mut w = FigureWriter {
        dir: &figdir,
        html,
        files: Vec::new(),
    };
    add_figures(&mut w, first, r, &spectra)?;
    modes_tables(&mut w.html, r);
    w.html.paragraph("The same modes, per role and per channel, are in modes.csv beside this page; every number of the analysis is in results.json.");
    for section in extra {
        w.html.heading(2, &section.title);
        for p in &section.paragraphs {
            w.html.paragraph(p);
        }
        for t in &section.tables {
            let headers: Vec<&str> = t.headers.iter().map(String::as_str).collect();
            w.html.table(&headers, &t.rows);
        }
        for f in &section.figures {
            w.add(&f.file, &f.title, &f.figure, &f.caption)?;
        }
    }
    let FigureWriter {
        mut html, files, ..
    } = w;
    html.heading(2, "Settings");
    html.preformatted(&toml::to_string(&r.config).unwrap_or_default());
    let html_path = dir.join("index.html");
    html.save(&html_path)?;
    Ok(ReportFiles {
        html: html_path,
        results_json,
        modes_csv: modes_csv_path,
        figures: files,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use vibmode_analysis::{LineSweep, LineTrack};

    /// Three channels (two with roles, so both pools are reported) of filtered noise, two
    /// records, analysed with low orders: results with every kind of entry.
    fn small_results() -> AnalysisResults {
        use rand::{Rng, SeedableRng};
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(3);
        let fs = 200.0;
        let n = 4096;
        let names = ["FL_unsprung", "FR_sprung", "acc_z"];
        let record = |k: usize, rng: &mut rand_chacha::ChaCha8Rng| {
            let channels = names
                .iter()
                .map(|name| {
                    let (mut y1, mut y2) = (0.0, 0.0);
                    let samples = (0..n)
                        .map(|_| {
                            let y = 1.8 * y1 - 0.9 * y2 + rng.gen_range(-1.0..1.0);
                            y2 = y1;
                            y1 = y;
                            y
                        })
                        .collect();
                    vibmode_signal::Channel::new(name.to_string(), "m/s^2".to_string(), samples)
                })
                .collect();
            RecordInput {
                name: format!("record_{k}"),
                recording: vibmode_signal::Recording {
                    fs_hz: fs,
                    channels,
                    time_axis: None,
                },
            }
        };
        let records: Vec<RecordInput> = (0..2).map(|k| record(k, &mut rng)).collect();
        let mut cfg = vibmode_analysis::AnalysisConfig::default();
        cfg.sweep.order_max = 6;
        vibmode_analysis::analyze(&records, &cfg, &[], &|_, _| {}).unwrap()
    }

    #[test]
    fn results_json_is_the_whole_value_pretty_printed_byte_for_byte() {
        let mut r = small_results();
        r.timing.elapsed_s = 1.25;
        assert_eq!(r.channels.len(), 3);
        assert!(r.channels.iter().all(|c| !c.fits.is_empty()));
        let extra = crate::ReportSection {
            title: "extra".into(),
            paragraphs: Vec::new(),
            tables: Vec::new(),
            figures: Vec::new(),
            json: Some((
                "model_update".into(),
                serde_json::json!({"b": [1.5, null], "a": 2}),
            )),
        };
        let dir = tempfile::tempdir().unwrap();
        for (k, extra) in [vec![], vec![extra]].iter().enumerate() {
            for channels in [r.channels.len(), 1, 0] {
                let mut r = r.clone();
                r.channels.truncate(channels);
                let mut whole = serde_json::to_value(&r).unwrap();
                if let serde_json::Value::Object(map) = &mut whole {
                    for (key, v) in extra.iter().filter_map(|s| s.json.as_ref()) {
                        map.insert(key.clone(), v.clone());
                    }
                }
                let expected = serde_json::to_string_pretty(&whole).unwrap() + "\n";
                let path = dir.path().join(format!("results_{k}_{channels}.json"));
                write_results_json(&path, &r, extra).unwrap();
                let written = std::fs::read_to_string(&path).unwrap();
                assert_eq!(written, expected, "{} channels, extra {k}", channels);
            }
        }
    }

    #[test]
    fn a_swept_entry_shows_start_and_end_and_is_listed() {
        let sweep = LineSweep {
            start_hz: 7.04,
            end_hz: 5.19,
            range_hz: (5.19, 7.05),
            mean_hz: 5.9,
            kurtosis: 1.53,
            time_s: vec![0.96, 1.28, 9.28],
            freq_hz: vec![7.04, 6.9, 5.19],
        };
        let t = LineTrack {
            frequency_hz: 7.0,
            frequency_range_hz: (7.0, 7.0),
            record_hz: vec![Some(7.0), None, None],
            record_share: 2.0 / 3.0,
            kurtosis: 1.6,
            record_sweep: vec![None, Some(sweep), None],
        };
        let entries: Vec<String> = (0..3).map(|r| record_entry(&t, r)).collect();
        assert_eq!(entries, vec!["7.00", "7.04>5.19", "-"]);
        let s = sweep_sentences(std::slice::from_ref(&t));
        assert_eq!(
            s,
            vec![
                "record 2: 7.04 -> 5.19 Hz from 1.0 to 9.3 s (range 5.19-7.05 Hz, kurtosis along the ridge 1.53)"
            ]
        );
        // A track read from an older results.json (no sweeps) shows its steady entries only.
        let old = LineTrack {
            record_sweep: Vec::new(),
            ..t
        };
        assert_eq!(record_entry(&old, 1), "-");
        assert!(sweep_sentences(&[old]).is_empty());
    }
}
