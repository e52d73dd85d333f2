//! `vibmode analyze` and `vibmode demo`: the paper's whole analysis and its report.

use anyhow::{bail, Context, Result};
use clap::Args;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use vibmode_analysis::{
    analyze, AnalysisConfig, AnalysisResults, ChainedRecords, Preset, RecordInput, StreamRecords,
};
use vibmode_modal::ReferenceMode;
use vibmode_report::TruthRow;

/// Arguments of `vibmode analyze`.
#[derive(Args, Debug)]
pub struct AnalyzeArgs {
    /// Record files (one record each), or long recordings cut into records of
    /// `record_length_s` (10.24 s by default).
    #[arg(required = true)]
    pub inputs: Vec<PathBuf>,
    /// Analysis settings (TOML); see docs/analysis.md. Keys not given take the preset's values.
    #[arg(long)]
    pub config: Option<PathBuf>,
    /// Preset for the defaults: vibmode (50 Hz analysis rate, p = 2..30) or paper (200 Hz, p = 2..60).
    #[arg(long)]
    pub preset: Option<String>,
    /// Full-car parameter file: its modes are drawn and matched to the invariant modes, and its
    /// suspension is fitted to the records (the model update: the measured bus's body modes,
    /// model_update.json, updated_vehicle.toml; settings in the config's `[model_update]`).
    #[arg(long)]
    pub vehicle: Option<PathBuf>,
    #[command(flatten)]
    pub channel: crate::input::ChannelArgs,
    #[command(flatten)]
    pub read: crate::input::ReadArgs,
    /// Output folder for index.html, results.json and figures/.
    #[arg(short = 'o', long = "output", default_value = "vibmode-report")]
    pub output: PathBuf,
    /// No progress bar.
    #[arg(long, short = 'q')]
    pub quiet: bool,
    /// Role of a channel, `NAME=sprung|unsprung|other` (repeat for several); overrides the
    /// config's `[[channels]]` and the guess from the name.
    #[arg(long = "role", value_name = "NAME=ROLE")]
    pub roles: Vec<String>,
    /// Corner of a channel, `NAME=FL|FR|RL|RR` (repeat for several).
    #[arg(long = "corner", value_name = "NAME=CORNER")]
    pub corners: Vec<String>,
    /// Identification: both (the default), arma (per channel) or ssi-cov (all channels at once,
    /// with mode shapes); overrides the config's `method`.
    #[arg(long)]
    pub method: Option<String>,
    /// Records of this length in seconds from long files (overrides the config's
    /// `record_length_s`).
    #[arg(long = "record-length-s")]
    pub record_length_s: Option<f64>,
    #[command(flatten)]
    pub seg: crate::cmd_segment::SegmentOptions,
}

/// `NAME=VALUE` of `--role` / `--corner`.
fn split_assignment<'a>(flag: &str, text: &'a str) -> Result<(&'a str, &'a str)> {
    match text.rsplit_once('=') {
        Some((name, value)) if !name.is_empty() && !value.is_empty() => Ok((name, value)),
        _ => bail!("{flag} '{text}' must be NAME=VALUE, e.g. {flag} FL_wheel=unsprung"),
    }
}

/// Adds the `--role` and `--corner` assignments to the config's channel table.
fn apply_placements(cfg: &mut AnalysisConfig, roles: &[String], corners: &[String]) -> Result<()> {
    use vibmode_analysis::{ChannelRole, Corner, Role};
    fn entry<'c>(cfg: &'c mut AnalysisConfig, name: &str) -> &'c mut ChannelRole {
        let i = match cfg.channels.iter().position(|c| c.name == name) {
            Some(i) => i,
            None => {
                cfg.channels.push(ChannelRole {
                    name: name.to_string(),
                    role: None,
                    corner: None,
                });
                cfg.channels.len() - 1
            }
        };
        &mut cfg.channels[i]
    }
    for r in roles {
        let (name, value) = split_assignment("--role", r)?;
        entry(cfg, name).role = Some(value.parse::<Role>()?);
    }
    for c in corners {
        let (name, value) = split_assignment("--corner", c)?;
        entry(cfg, name).corner = Some(value.parse::<Corner>()?);
    }
    Ok(())
}

/// Reads the config: --config file (with its own preset key) or --preset, else defaults.
fn load_config(config: Option<&Path>, preset: Option<&str>) -> Result<AnalysisConfig> {
    let cfg = match (config, preset) {
        (Some(path), None) => AnalysisConfig::from_path(path)?,
        (Some(path), Some(p)) => {
            let text = vibmode_core::files::read_text_capped(path)
                .with_context(|| format!("cannot read config {}", path.display()))?;
            let p: Preset = p.parse()?;
            let name = match p {
                Preset::Paper => "paper",
                Preset::Vibmode => "vibmode",
            };
            AnalysisConfig::from_toml_str(&format!("preset = \"{name}\"\n{text}"))
                .with_context(|| format!("config {}", path.display()))?
        }
        (None, Some(p)) => AnalysisConfig::preset(p.parse()?),
        (None, None) => AnalysisConfig::default(),
    };
    cfg.validate()?;
    Ok(cfg)
}

/// Runs `vibmode analyze`.
pub fn run(a: &AnalyzeArgs) -> Result<()> {
    let mut cfg = load_config(a.config.as_deref(), a.preset.as_deref())?;
    // The output folder is checked and locked before any work, and written as a whole.
    let mut inputs = a.inputs.clone();
    inputs.extend(a.seg.gps.iter().cloned());
    let out = crate::output::StagedDir::begin(&a.output, &inputs)?;
    apply_placements(&mut cfg, &a.roles, &a.corners)?;
    if let Some(m) = &a.method {
        cfg.method = m.parse()?;
    }
    let opts = a.read.options()?;
    let sel = a.channel.selectors()?;
    let reference = match &a.vehicle {
        Some(p) => vehicle_reference(p)?,
        None => Vec::new(),
    };
    // Each file is read as a stream and cut into records as it is read; each record is brought
    // to the analysis rate as it arrives, so memory does not grow with the file.
    if let Some(l) = a.record_length_s {
        cfg.record_length_s = l;
        cfg.validate()?;
    }
    let record_length_s = cfg.record_length_s;
    // With --gps / --by-vibration each file is segmented first (a pass over it), then its
    // records are cut where the segmentation says.
    let plans = if a.seg.active() {
        if a.seg.gps.is_some() && a.inputs.len() > 1 {
            bail!("--gps TRACK goes with one recording; give one input file");
        }
        let mut plans = Vec::new();
        for path in &a.inputs {
            let plan = crate::cmd_segment::plan(path, &opts, &sel, &a.seg, record_length_s)?;
            eprintln!("{}", crate::cmd_segment::summary(&plan));
            if plan.records.is_empty() {
                bail!(
                    "no steady stretch of {record_length_s} s in {}; see the reasons above, or analyse without segmentation",
                    path.display()
                );
            }
            plans.push(plan);
        }
        Some(plans)
    } else {
        None
    };
    let mut source = ChainedRecords::new(a.inputs.len(), |i| {
        let path = &a.inputs[i];
        let mut stream = vibmode_signal::open_stream(path, &opts)?;
        stream.select(&sel)?;
        Ok(match &plans {
            Some(p) => StreamRecords::windows(&display_name(path), stream, p[i].windows()),
            None => StreamRecords::cut(&display_name(path), stream, record_length_s),
        })
    });
    // With --vehicle, every record also feeds the fit of the vehicle's suspension.
    let mut update = ModelUpdate::new(a.vehicle.as_deref(), &cfg)?;
    let mut tee = FeedUpdate {
        source: &mut source,
        update: &mut update,
    };
    let (mut results, first) = run_stream_analysis(&mut tee, &cfg, &reference, a.quiet)?;
    let update = update.finish();
    if let Some([plan]) = plans.as_deref() {
        if let Some(g) = &plan.gps {
            results.drive_speed_trace = g.speed_trace.clone();
        }
    }
    check_some_fit(&results)?;
    write_report(
        out.path(),
        std::slice::from_ref(&first),
        &results,
        None,
        &update.sections(&results),
    )?;
    if let Some(plans) = &plans {
        let path = out.path().join("segments.json");
        let text = if plans.len() == 1 {
            serde_json::to_string_pretty(&plans[0])?
        } else {
            serde_json::to_string_pretty(plans)?
        };
        std::fs::write(&path, text + "\n")
            .with_context(|| format!("writing {}", path.display()))?;
    }
    let update_text = update.write(out.path(), &a.output)?;
    out.commit()?;
    print_modes(&results, None)?;
    if let Some(t) = update_text {
        crate::output::print_stdout(&t)?;
    }
    eprintln!("report: {}", a.output.join("index.html").display());
    Ok(())
}

/// The fit of the vehicle file's suspension to the records (`vibmode_vehicle::update`).
pub struct ModelUpdate {
    cfg: AnalysisConfig,
    state: UpdateState,
}

/// A record source that also feeds each record to the model update.
pub struct FeedUpdate<'a> {
    source: &'a mut dyn vibmode_analysis::RecordSource,
    update: &'a mut ModelUpdate,
}

/// Where the model update stands.
pub enum UpdateState {
    /// No vehicle file: nothing to update.
    Off,
    /// Records are being added.
    Fitting(
        Box<(
            vibmode_vehicle::VehicleParams,
            vibmode_vehicle::update::BodyFit,
        )>,
    ),
    /// A record could not be used (the reason), so the update was stopped.
    Skipped(String),
}

impl UpdateState {
    /// A fit of `v`'s suspension with the analysis' `[model_update]` settings.
    pub fn start(v: vibmode_vehicle::VehicleParams, cfg: &AnalysisConfig) -> Result<Self> {
        let fit = vibmode_vehicle::update::BodyFit::new(&v, cfg.model_update.clone())?;
        Ok(UpdateState::Fitting(Box::new((v, fit))))
    }
}

impl ModelUpdate {
    /// With a vehicle file, a fit of its suspension; without, nothing.
    pub fn new(vehicle: Option<&Path>, cfg: &AnalysisConfig) -> Result<Self> {
        let v = vehicle
            .map(vibmode_vehicle::VehicleParams::from_path)
            .transpose()?;
        Self::for_vehicle(v, cfg)
    }

    /// As [`ModelUpdate::new`], with the vehicle's parameters already read.
    pub fn for_vehicle(
        vehicle: Option<vibmode_vehicle::VehicleParams>,
        cfg: &AnalysisConfig,
    ) -> Result<Self> {
        let state = match vehicle {
            Some(v) => UpdateState::start(v, cfg)?,
            None => UpdateState::Off,
        };
        Ok(ModelUpdate {
            cfg: cfg.clone(),
            state,
        })
    }

    /// Adds one record (its channels placed as the analysis places them).
    pub fn add(&mut self, r: &RecordInput) {
        if let UpdateState::Fitting(b) = &mut self.state {
            let cfg = &self.cfg;
            if let Err(e) =
                b.1.add_record_placed(&r.recording, |c| cfg.placement_for_update(c))
            {
                self.state = UpdateState::Skipped(format!("{}: {e}", r.name));
            }
        }
    }

    /// Solves the fit.
    pub fn finish(&mut self) -> UpdateOutcome {
        let state = std::mem::replace(&mut self.state, UpdateState::Off);
        match state {
            UpdateState::Off => UpdateOutcome::Off,
            UpdateState::Skipped(why) => UpdateOutcome::Skipped(why),
            UpdateState::Fitting(b) => match b.1.solve() {
                Ok(r) => UpdateOutcome::Done(Box::new((b.0, r))),
                Err(e) => UpdateOutcome::Skipped(e.to_string()),
            },
        }
    }
}

impl vibmode_analysis::RecordSource for FeedUpdate<'_> {
    fn next_record(&mut self) -> Option<Result<RecordInput, vibmode_analysis::AnalysisError>> {
        let r = self.source.next_record();
        if let Some(Ok(rec)) = &r {
            self.update.add(rec);
        }
        r
    }

    fn meta(&self) -> Option<vibmode_core::RecordMeta> {
        self.source.meta()
    }
}

/// The model update's result.
pub enum UpdateOutcome {
    /// No vehicle file.
    Off,
    /// Not possible, and why.
    Skipped(String),
    /// The vehicle file and the fit.
    Done(
        Box<(
            vibmode_vehicle::VehicleParams,
            vibmode_vehicle::update::BodyFitResult,
        )>,
    ),
}

impl UpdateOutcome {
    /// The report's section on the model update (none without a vehicle file), with the
    /// analysis' SSI-cov modes in its figure.
    pub fn sections(&self, results: &AnalysisResults) -> Vec<vibmode_report::ReportSection> {
        use vibmode_report::ReportSection;
        let identified = results
            .ssi
            .as_ref()
            .map_or(&[][..], |s| &s.invariant_modes[..]);
        match self {
            UpdateOutcome::Off => Vec::new(),
            UpdateOutcome::Skipped(why) => vec![ReportSection::model_update_skipped(why)],
            UpdateOutcome::Done(b) => match unsupported(&b.1) {
                Some(why) => vec![ReportSection::model_update_skipped(&why)],
                None => vec![ReportSection::model_update(&b.0, &b.1, identified)],
            },
        }
    }

    /// Writes `model_update.json` and `updated_vehicle.toml` into `dir` and returns the text for
    /// the terminal (a one-line reason when the update was not possible).
    /// `shown` is the folder's final path, for the message.
    pub fn write(&self, dir: &Path, shown: &Path) -> Result<Option<String>> {
        match self {
            UpdateOutcome::Off => Ok(None),
            UpdateOutcome::Skipped(why) => Ok(Some(format!("Full-car model not updated: {why}\n"))),
            UpdateOutcome::Done(b) => {
                let (file, r) = (&b.0, &b.1);
                let json = dir.join("model_update.json");
                std::fs::write(&json, serde_json::to_string_pretty(r)? + "\n")
                    .with_context(|| format!("writing {}", json.display()))?;
                // A fit the records do not support is not written as a vehicle file; its
                // figures stay in model_update.json.
                if let Some(why) = unsupported(r) {
                    return Ok(Some(format!(
                        "Full-car model not updated: {why} (the fit's figures: {})\n",
                        shown.join("model_update.json").display()
                    )));
                }
                let toml_path = dir.join("updated_vehicle.toml");
                let mut v = r.vehicle.clone();
                v.name = format!("{} (updated from the records)", file.name);
                // The fit's standard deviations as comments (jackknife over the records).
                let mut head = format!(
                    "# Fitted to {} records by vibmode's model update (docs/model_update.md).\n",
                    r.records
                );
                for p in r.parameters.iter().filter(|p| p.sd.is_some()) {
                    head.push_str(&format!(
                        "# {}: {:.6e} {}, standard deviation {:.2e}\n",
                        p.name,
                        p.value,
                        p.unit,
                        p.sd.unwrap_or(f64::NAN)
                    ));
                }
                std::fs::write(&toml_path, head + &v.to_toml_string()?)
                    .with_context(|| format!("writing {}", toml_path.display()))?;
                Ok(Some(format!(
                    "{}  the updated vehicle file: {}\n",
                    r.summary_text(file),
                    shown.join("updated_vehicle.toml").display()
                )))
            }
        }
    }
}

/// Why the records do not support a model update's fit, as the one line the terminal and the
/// report give; `None` when they do.
fn unsupported(r: &vibmode_vehicle::update::BodyFitResult) -> Option<String> {
    (!r.supported).then(|| {
        format!(
            "the records do not support the fit: {}",
            r.not_supported.as_deref().unwrap_or("no reason recorded")
        )
    })
}

/// An analysis in which every fit failed has nothing to report: an error, with the first
/// failure's reason (not an empty table and exit 0).
fn check_some_fit(r: &AnalysisResults) -> Result<()> {
    if r.n_fits > 0 && r.n_failed == r.n_fits {
        let why = r
            .channels
            .iter()
            .flat_map(|c| c.fits.iter())
            .find_map(|f| f.error.clone())
            .unwrap_or_else(|| "no reason recorded".into());
        bail!(
            "every one of the {} fits failed, so nothing was identified; the first failure: {why}",
            r.n_fits
        );
    }
    Ok(())
}

/// The full-car model's modes as reference modes.
pub fn vehicle_reference(path: &Path) -> Result<Vec<ReferenceMode>> {
    let params = vibmode_vehicle::VehicleParams::from_path(path)?;
    let car = vibmode_vehicle::FullCar::new(&params)?;
    Ok(reference_modes(&car.modes()?))
}

/// Physical-model modes as the reference modes the clustering is matched to.
fn reference_modes(modes: &[vibmode_vehicle::ModeInfo]) -> Vec<ReferenceMode> {
    modes.iter().map(|m| m.to_reference()).collect()
}

/// Runs the analysis with a progress bar on a terminal (records identified, per second, the
/// time left).
pub fn run_analysis(
    records: &[RecordInput],
    cfg: &AnalysisConfig,
    reference: &[ReferenceMode],
    quiet: bool,
) -> Result<AnalysisResults> {
    if records.is_empty() {
        bail!("no records to analyse");
    }
    let n_ch = AtomicUsize::new(records[0].recording.channels.len());
    let pb = crate::progress::records_bar(quiet, None, "records identified", "records");
    let progress = sweeps_as_records(&pb, &n_ch);
    let res = analyze(records, cfg, reference, &progress)?;
    pb.finish_and_clear();
    Ok(res)
}

/// The analysis' progress (`done` of `total` record x channel fits) shown as records: a record
/// counts when all its `n_ch` channels are fitted (the total is the records fitted: stops are
/// not). `n_ch` is read at the first call (a streamed source knows it once read).
fn sweeps_as_records<'a>(
    pb: &'a indicatif::ProgressBar,
    n_ch: &'a AtomicUsize,
) -> impl Fn(usize, usize) + Sync + 'a {
    let started = AtomicBool::new(false);
    move |done: usize, total: usize| {
        let n = n_ch.load(Ordering::SeqCst).max(1);
        if !started.swap(true, Ordering::SeqCst) {
            crate::progress::set_phase(
                pb,
                Some(total.div_ceil(n) as u64),
                "records identified",
                "records",
            );
        }
        pb.set_position((done / n) as u64);
    }
}

/// The name a record file is reported under: the path as the user gave it (relative stays
/// relative), not its base name, so that `run1/record_01.wav` and `run2/record_01.wav` stay
/// apart. The same rule as the fleet's ([`vibmode_fleet::record_file_name`]) and the Python
/// package's.
pub fn display_name(path: &Path) -> String {
    vibmode_fleet::record_file_name(path)
}

/// Runs the streamed analysis of `source` with a progress display on a terminal; returns the
/// results and the first record (for the report's figures).
pub fn run_stream_analysis(
    source: &mut dyn vibmode_analysis::RecordSource,
    cfg: &AnalysisConfig,
    reference: &[ReferenceMode],
    quiet: bool,
) -> Result<(AnalysisResults, RecordInput)> {
    // Records are counted as they are read (and brought to the analysis rate), then as they
    // are identified; the number of channels is the first record's (all must have its layout).
    let pb = crate::progress::records_bar(quiet, None, "records read", "records");
    let n_ch = AtomicUsize::new(0);
    let mut counted = CountChannels {
        source,
        n_ch: &n_ch,
    };
    let on_record = |n: usize| pb.set_position(n as u64);
    let sweeps = sweeps_as_records(&pb, &n_ch);
    let identifier = vibmode_analysis::SweepIdentifier {
        sweep: cfg.sweep.clone(),
        poles: cfg.poles.clone(),
    };
    let out = vibmode_analysis::analyze_source(
        &mut counted,
        cfg,
        &identifier,
        reference,
        &on_record,
        &sweeps,
    )?;
    pb.finish_and_clear();
    Ok(out)
}

/// A record source that notes the number of channels of the first record (for the progress in
/// records).
struct CountChannels<'a> {
    source: &'a mut dyn vibmode_analysis::RecordSource,
    n_ch: &'a AtomicUsize,
}

impl vibmode_analysis::RecordSource for CountChannels<'_> {
    fn next_record(&mut self) -> Option<Result<RecordInput, vibmode_analysis::AnalysisError>> {
        let r = self.source.next_record();
        if let Some(Ok(rec)) = &r {
            let _ = self.n_ch.compare_exchange(
                0,
                rec.recording.channels.len(),
                Ordering::SeqCst,
                Ordering::SeqCst,
            );
        }
        r
    }

    fn meta(&self) -> Option<vibmode_core::RecordMeta> {
        self.source.meta()
    }
}

/// Prints the invariant-mode table per role; with `truth`, the true modes beside it.
pub fn print_modes(r: &AnalysisResults, truth: Option<&[TruthRow]>) -> Result<()> {
    crate::output::print_stdout(&vibmode_report::modes_table_text(r, truth))
}

/// Writes `DIR/index.html`, `DIR/results.json`, `DIR/modes.csv` and `DIR/figures/*`.
pub fn write_report(
    dir: &Path,
    records: &[RecordInput],
    r: &AnalysisResults,
    intro: Option<&str>,
    extra: &[vibmode_report::ReportSection],
) -> Result<()> {
    vibmode_report::write_analysis_report(dir, records, r, intro, extra)
        .with_context(|| format!("writing the report in {}", dir.display()))?;
    Ok(())
}

/// Arguments of `vibmode demo`.
#[derive(Args, Debug)]
pub struct DemoArgs {
    /// Output folder for the report (and the simulated records in `records/`).
    #[arg(short = 'o', long = "output", default_value = "vibmode-demo")]
    pub output: PathBuf,
    /// Preset of the analysis: vibmode or paper.
    #[arg(long)]
    pub preset: Option<String>,
    /// Number of simulated records.
    #[arg(long, default_value_t = 8)]
    pub records: usize,
    /// Random seed of the simulation.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Also write the simulated records (WAV) and truth.json into `OUTPUT/records/`.
    #[arg(long)]
    pub keep_records: bool,
    /// No progress bar.
    #[arg(long, short = 'q')]
    pub quiet: bool,
    /// Identification: both (the default), arma or ssi-cov.
    #[arg(long)]
    pub method: Option<String>,
}

/// Runs `vibmode demo`: simulate the shipped city bus and analyse it.
pub fn run_demo(a: &DemoArgs) -> Result<()> {
    use crate::cmd_vehicle::{write_simulation, RecordFormat};
    if a.records == 0 {
        bail!("--records 0: give at least one record");
    }
    let mut cfg = load_config(None, a.preset.as_deref())?;
    if let Some(m) = &a.method {
        cfg.method = m.parse()?;
    }
    let out = crate::output::StagedDir::begin(&a.output, &[])?;
    let vehicle = vibmode_vehicle::VehicleParams::city_bus_flexible();
    let p = vibmode_vehicle::SimParams::demo(a.records, a.seed);
    p.validate()?;
    eprintln!(
        "simulating {} records of 10.24 s at 20 kHz: 12 m city bus with a flexible body, ISO 8608 class B road, ~30 km/h, wandering engine/gear lines, sensor noise and misalignment, braking, a turn, tones up to 6 kHz ...",
        a.records
    );
    let sim = vibmode_vehicle::simulate(&vehicle, &p)?;
    if a.keep_records {
        let dir = out.path().join("records");
        std::fs::create_dir(&dir).with_context(|| format!("cannot create {}", dir.display()))?;
        write_simulation(&dir, &sim, RecordFormat::Wav)?;
    }
    let records: Vec<RecordInput> = sim
        .records
        .iter()
        .enumerate()
        .map(|(i, r)| RecordInput {
            name: format!("record {:02} ({:.1} km/h)", i + 1, r.mean_speed_kmh),
            recording: r.recording.clone(),
        })
        .collect();
    let reference = reference_modes(&sim.truth.modes);
    let results = run_analysis(&records, &cfg, &reference, a.quiet)?;
    let mut update = ModelUpdate::for_vehicle(Some(vehicle.clone()), &cfg)?;
    records.iter().for_each(|r| update.add(r));
    let update = update.finish();
    let update_text = update.write(out.path(), &a.output)?;
    let lines: Vec<String> = sim
        .truth
        .disturbance_lines_hz
        .iter()
        .map(|f| format!("{f} Hz"))
        .collect();
    let intro = format!(
        "Demo: {} simulated record(s) of {} s of a 12 m city bus with a flexible body (vibmode's full-car simulator, examples/city_bus_flexible.toml: a body bending mode at 9 Hz between the axle modes) on an ISO 8608 class {} road at about {} km/h (the speed varies by 3 %), seed {}, with engine/gear lines at nominally {} (their frequency wanders by 0.1 %, their amplitude by 10 %, the engine speed differs by 2 % from record to record and the 7 Hz driveline line follows the vehicle speed), sensor noise, bias and misalignment up to 3 deg, braking, acceleration and a turn, and tones at {} Hz that alias without the anti-alias filter. The true modes are the full-car model's (red diamonds in the frequency-damping figure).",
        records.len(),
        p.duration_s,
        sim.truth.road_class,
        sim.truth.speed_kmh,
        a.seed,
        lines.join(", "),
        sim.truth
            .hf_tones_hz
            .iter()
            .map(|f| f.to_string())
            .collect::<Vec<_>>()
            .join(", "),
    );
    write_report(
        out.path(),
        &records,
        &results,
        Some(&intro),
        &update.sections(&results),
    )?;
    out.commit()?;
    let mut truth: Vec<TruthRow> = sim
        .truth
        .modes
        .iter()
        .map(|m| (m.label.to_string(), m.frequency_hz, m.damping_ratio))
        .collect();
    for line in &sim.truth.lines {
        let lo = line
            .record_min_hz
            .iter()
            .copied()
            .fold(f64::INFINITY, f64::min);
        let hi = line
            .record_max_hz
            .iter()
            .copied()
            .fold(f64::NEG_INFINITY, f64::max);
        truth.push((
            format!("engine/gear line, {lo:.2}-{hi:.2} Hz over the records"),
            line.nominal_hz,
            0.0,
        ));
    }
    truth.sort_by(|x, y| x.1.total_cmp(&y.1));
    print_modes(&results, Some(&truth))?;
    if let Some(t) = update_text {
        crate::output::print_stdout(&t)?;
    }
    eprintln!("report: {}", a.output.join("index.html").display());
    Ok(())
}
