//! `vibmode ssi` as a library: multichannel SSI-cov of one record with the stabilisation
//! diagram's poles and the modes that stay over the orders (frequency, damping, shape); how it
//! is summarised and drawn.

use serde::Serialize;
use std::fmt::Write as _;
use vibmode_core::{InvariantMode, ModeClass, SsiParams};
use vibmode_signal::Recording;
use vibmode_ssi::{RecordSsi, RecordSsiOptions};

use crate::RunError;

/// SSI-cov of a record (`vibmode ssi --json`).
#[derive(Serialize, Clone, Debug)]
pub struct SsiOutput {
    /// The file.
    pub source: String,
    /// The channels, in the order of the shapes.
    pub channels: Vec<String>,
    /// Parameters, every order's modes and labels, and the clusters (structural ones first).
    #[serde(flatten)]
    pub found: RecordSsi,
}

/// SSI-cov of every channel of `rec` (read from `source`) at once.
pub fn ssi(
    rec: &Recording,
    source: &str,
    params: &SsiParams,
    options: &RecordSsiOptions,
) -> Result<SsiOutput, RunError> {
    let chans: Vec<&[f64]> = rec.channels.iter().map(|c| c.samples.as_slice()).collect();
    let found = vibmode_ssi::identify_record(&chans, rec.fs_hz, params, options).map_err(|e| {
        match e {
            // Named as the analysis names it: the record and the channel by name.
            vibmode_ssi::SsiError::ConstantChannel { channel, value } => {
                RunError::Analysis(vibmode_analysis::AnalysisError::ChannelConstant {
                    record: source.to_string(),
                    channel: rec
                        .channels
                        .get(channel)
                        .map_or_else(|| channel.to_string(), |c| c.name.clone()),
                    value,
                })
            }
            e => e.into(),
        }
    })?;
    Ok(SsiOutput {
        source: source.to_string(),
        channels: rec.channels.iter().map(|c| c.name.clone()).collect(),
        found,
    })
}

/// What the Toeplitz matrix's lags reach: their span in seconds (the largest lag over `fs_hz`)
/// and the frequency whose period it is. A mode below that frequency completes less than one
/// period within the lags; in noise SSI-cov seldom identifies it (docs/ssi.md: 20 block rows at
/// 50 Hz miss a bus's 1.17 Hz heave, 40 find it), so the text says where the record's band
/// of interest lies below it.
pub fn lag_span_note(params: &SsiParams, fs_hz: f64) -> String {
    let span_s = params.lag_span_s(fs_hz);
    format!(
        "the lags span {span_s:.3} s (lag {} at {fs_hz} Hz): a mode below about {:.3} Hz completes less than one period within them and is seldom identified (a lower rate or more block rows reach lower)",
        params.last_lag(),
        1.0 / span_s
    )
}

impl SsiOutput {
    /// The modes that stay over the orders, with their shapes (modulus and phase per channel).
    pub fn summary_text(&self) -> String {
        let out = self;
        let mut s = format!(
            "{}: SSI-cov of {} channels ({} samples at {} Hz), {} block rows (lags {}..{}), orders {}..{}\n",
            out.source,
            out.channels.len(),
            out.found.n_samples,
            out.found.fs_hz,
            out.found.params.block_rows,
            out.found.params.first_lag,
            out.found.params.last_lag(),
            out.found.result.orders.first().map_or(0, |o| o.order),
            out.found.result.orders.last().map_or(0, |o| o.order),
        );
        let _ = writeln!(s, "  {}", lag_span_note(&out.found.params, out.found.fs_hz));
        let structural: Vec<&InvariantMode> = out
            .found
            .modes
            .iter()
            .filter(|m| m.class == ModeClass::Structural)
            .collect();
        if structural.is_empty() {
            s.push_str(
                "No mode stays over half the orders (poles scattered); try more block rows, more samples or a longer record.\n",
            );
        }
        for m in structural {
            let _ = write!(
                s,
                "  {:>8.3} Hz  damping {:.4}  in {:.0} % of orders",
                m.frequency_hz,
                m.damping_ratio,
                100.0 * m.order_share
            );
            if let Some((med, _)) = m.shape_mac {
                let _ = write!(s, ", shape MAC {med:.2}");
            }
            if let Some(u) = &m.uncertainty {
                let _ = write!(
                    s,
                    ", sd {:.4} Hz / damping {:.4} (first order, {} blocks)",
                    u.frequency_std_hz,
                    u.damping_std,
                    out.found.uncertainty_blocks.unwrap_or(0)
                );
            }
            s.push('\n');
            if let Some(shape) = &m.shape {
                let parts: Vec<String> = out
                    .channels
                    .iter()
                    .zip(shape)
                    .map(|(c, v)| {
                        format!(
                            "{c} {:.2}/{:+.0}deg",
                            v[0].hypot(v[1]),
                            v[1].atan2(v[0]).to_degrees()
                        )
                    })
                    .collect();
                let _ = writeln!(s, "      shape: {}", parts.join(", "));
            }
        }
        s
    }

    /// The stabilisation diagram up to `f_max_hz` over the Welch PSD of `rec` summed over its
    /// channels.
    #[cfg(feature = "report")]
    pub fn figure(
        &self,
        rec: &Recording,
        f_max_hz: f64,
    ) -> Result<vibmode_report::Figure, RunError> {
        use vibmode_report::panels as figures;
        let out = self;
        let pts: Vec<(usize, f64, f64)> = out
            .found
            .result
            .orders
            .iter()
            .flat_map(|o| {
                o.modes
                    .iter()
                    .map(move |m| (o.order, m.frequency_hz, m.damping_ratio))
            })
            .collect();
        // The Welch PSD summed over the channels, drawn behind the poles.
        let mut freq = Vec::new();
        let mut psd: Vec<f64> = Vec::new();
        for ch in &rec.channels {
            let w = crate::sweep::figure_welch(ch, rec.fs_hz)?;
            if psd.is_empty() {
                psd = vec![0.0; w.psd.len()];
                freq = w.freq_hz;
            }
            for (a, b) in psd.iter_mut().zip(&w.psd) {
                *a += b;
            }
        }
        let panel = figures::stabilisation_panel(
            &format!(
                "SSI-cov stabilisation diagram ({} channels)",
                out.channels.len()
            ),
            &pts,
            &freq,
            &psd,
            f_max_hz,
        );
        Ok(figures::grid(vec![panel], 1, 1000, 520))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_lag_span_is_the_largest_lag_over_the_rate() {
        // 20 block rows from lag 1: lags 1..39; at 500 Hz 0.078 s, whose period is 12.8 Hz.
        let p = SsiParams::default();
        assert_eq!((p.block_rows, p.first_lag), (20, 1));
        let t = lag_span_note(&p, 500.0);
        assert!(
            t.starts_with("the lags span 0.078 s (lag 39 at 500 Hz): a mode below about 12.821 Hz"),
            "{t}"
        );
        // 40 block rows from lag 11 at 50 Hz: lags 11..89, 1.78 s, 0.562 Hz.
        let p = SsiParams {
            block_rows: 40,
            first_lag: 11,
            ..SsiParams::default()
        };
        assert!(
            lag_span_note(&p, 50.0).starts_with(
                "the lags span 1.780 s (lag 89 at 50 Hz): a mode below about 0.562 Hz"
            ),
            "{}",
            lag_span_note(&p, 50.0)
        );
    }
}
