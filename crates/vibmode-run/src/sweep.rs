//! `vibmode sweep` as a library: every model order of every channel fitted, each fit's modes
//! through the analysis' pole filters (kept, or left out with the reason), the Welch spectrum
//! behind the stabilisation diagram; how the sweep is summarised and drawn.

use serde::Serialize;
use vibmode_core::{
    BandLimit, ClusterParams, InvariantMode, ModeClass, PoleFilterParams, PoleObservation,
    SweepModel,
};
use vibmode_ident::{ArMethod, ArmaModel, ArmaParams, IdentError, PoleRejection};
use vibmode_signal::Recording;

use crate::RunError;

/// One pole pair of the sweep.
#[derive(Serialize, Clone, Copy, Debug, PartialEq)]
pub struct SweepMode {
    /// Model order p.
    pub order: usize,
    /// Natural frequency, Hz.
    pub frequency_hz: f64,
    /// Damping ratio.
    pub damping_ratio: f64,
}

/// A pole pair the pole filters left out, and why.
#[derive(Serialize, Clone, Copy, Debug, PartialEq)]
pub struct FilteredMode {
    /// Model order p.
    pub order: usize,
    /// Natural frequency, Hz.
    pub frequency_hz: f64,
    /// Damping ratio.
    pub damping_ratio: f64,
    /// Why it is no mode.
    pub reason: PoleRejection,
}

/// The sweep of one channel: per order (in `orders`' order) the loss, convergence and error,
/// and all modes kept or left out.
#[derive(Serialize, Clone, Debug)]
pub struct SweepChannel {
    /// Channel name.
    pub name: String,
    /// Unit of the samples.
    pub unit: String,
    /// The orders fitted.
    pub orders: Vec<usize>,
    /// Each fit's criterion (NaN where it failed).
    pub loss: Vec<f64>,
    /// Whether each fit converged.
    pub converged: Vec<bool>,
    /// Why a fit failed.
    pub errors: Vec<Option<String>>,
    /// The pole pairs that passed the pole filters.
    pub modes: Vec<SweepMode>,
    /// The pole pairs the filters left out.
    pub filtered_out: Vec<FilteredMode>,
    /// The kept poles clustered over the orders (the analysis' clustering of one record,
    /// `ClusterParams` defaults in the signal's band): the modes that stay over the orders,
    /// structural and periodic ones first (`class`), with `order_share` the share of the orders
    /// each is found at.
    pub clusters: Vec<InvariantMode>,
    /// Welch frequencies (Hann, 256 samples), Hz.
    pub welch_freq_hz: Vec<f64>,
    /// Welch PSD.
    pub welch_psd: Vec<f64>,
}

/// The sweep of a recording (`vibmode sweep --json`).
#[derive(Serialize, Clone, Debug)]
pub struct SweepOutput {
    /// The file.
    pub source: String,
    /// Sampling rate, Hz.
    pub fs_hz: f64,
    /// Samples per channel.
    pub n_samples: usize,
    /// Model structure.
    pub model: SweepModel,
    /// One entry per channel.
    pub channels: Vec<SweepChannel>,
}

impl SweepChannel {
    /// An empty sweep of `orders` for a channel.
    pub fn new(name: &str, unit: &str, orders: &[usize]) -> Self {
        SweepChannel {
            name: name.to_string(),
            unit: unit.to_string(),
            orders: orders.to_vec(),
            loss: Vec::new(),
            converged: Vec::new(),
            errors: Vec::new(),
            modes: Vec::new(),
            filtered_out: Vec::new(),
            clusters: Vec::new(),
            welch_freq_hz: Vec::new(),
            welch_psd: Vec::new(),
        }
    }

    /// Adds every fit (`fits[i]` of order `orders[i]`): its loss, convergence or error, and its
    /// modes split by the pole filters.
    pub fn add_fits(
        &mut self,
        fits: &[Result<ArmaModel, IdentError>],
        band: &BandLimit,
        filters: &PoleFilterParams,
    ) {
        for (&order, f) in self.orders.iter().zip(fits) {
            match f {
                Ok(m) => {
                    self.loss.push(m.loss);
                    self.converged.push(m.converged);
                    self.errors.push(None);
                    for fm in vibmode_ident::filter_modes(m, band, filters) {
                        let (frequency_hz, damping_ratio) =
                            (fm.mode.frequency_hz, fm.mode.damping_ratio);
                        match fm.rejected {
                            None => self.modes.push(SweepMode {
                                order,
                                frequency_hz,
                                damping_ratio,
                            }),
                            Some(reason) => self.filtered_out.push(FilteredMode {
                                order,
                                frequency_hz,
                                damping_ratio,
                                reason,
                            }),
                        }
                    }
                }
                Err(e) => {
                    self.loss.push(f64::NAN);
                    self.converged.push(false);
                    self.errors.push(Some(e.to_string()));
                }
            }
        }
    }
}

impl SweepChannel {
    /// Clusters the kept poles over the orders into [`Self::clusters`] (one record, this
    /// channel; `params` as the analysis' `[cluster]`, its upper frequency from `band` where
    /// unset).
    pub fn cluster(&mut self, band: &BandLimit, params: &ClusterParams) -> Result<(), RunError> {
        let obs: Vec<PoleObservation> = self
            .modes
            .iter()
            .map(|m| PoleObservation::new(m.frequency_hz, m.damping_ratio, m.order, 0, &*self.name))
            .collect();
        self.clusters =
            vibmode_modal::find_invariant_modes(&obs, 1, &self.orders, &params.for_band(band))
                .map_err(vibmode_analysis::AnalysisError::from)?;
        Ok(())
    }
}

/// A channel's Welch PSD drawn behind the poles of a stabilisation diagram: segments of 256
/// samples (the whole record when shorter), the other settings scipy's defaults.
pub(crate) fn figure_welch(
    ch: &vibmode_signal::Channel,
    fs_hz: f64,
) -> Result<vibmode_spectra::Spectrum, RunError> {
    let wp = vibmode_spectra::WelchParams {
        nperseg: Some(256.min(ch.samples.len())),
        ..Default::default()
    };
    vibmode_spectra::welch(&ch.samples, fs_hz, &wp).map_err(|source| RunError::Spectrum {
        channel: ch.name.clone(),
        source,
    })
}

/// The sweep of every channel of `rec` (read from `source`). `band`: what the signal carries
/// (the pole filters' band). A channel whose every fit fails is an error with the highest
/// order's reason.
pub fn sweep(
    rec: &Recording,
    source: &str,
    model: SweepModel,
    ar_method: ArMethod,
    orders: &[usize],
    params: &ArmaParams,
    band: &BandLimit,
) -> Result<SweepOutput, RunError> {
    let filters = PoleFilterParams::default();
    let max_order = orders.iter().copied().max().unwrap_or(1);
    let mut channels = Vec::new();
    for ch in &rec.channels {
        let fits = vibmode_ident::sweep_fits(&ch.samples, model, ar_method, orders, params);
        if fits.iter().all(|f| f.is_err()) {
            if let Some(Err(e)) = fits.into_iter().last() {
                return Err(RunError::SweepFailed {
                    channel: ch.name.clone(),
                    order: max_order,
                    source: e,
                });
            }
            return Err(RunError::NoChannels);
        }
        let mut out = SweepChannel::new(&ch.name, &ch.unit, orders);
        out.add_fits(&fits, band, &filters);
        out.cluster(band, &ClusterParams::default())?;
        let w = figure_welch(ch, rec.fs_hz)?;
        out.welch_freq_hz = w.freq_hz;
        out.welch_psd = w.psd;
        channels.push(out);
    }
    Ok(SweepOutput {
        source: source.to_string(),
        fs_hz: rec.fs_hz,
        n_samples: rec.len(),
        model,
        channels,
    })
}

impl SweepOutput {
    /// Per channel: orders, pole pairs kept and left out, fits not converged and failed; then
    /// the modes that stay over the orders (structural and periodic clusters), or why none is
    /// listed.
    pub fn summary_text(&self) -> String {
        let mut text = String::new();
        for c in &self.channels {
            let nc = c.converged.iter().filter(|x| !**x).count();
            text += &format!(
                "{}: {} orders, {} pole pairs ({} more left out by the pole filters: cancelled by a zero of C or above the valid band), {} fits not converged, {} failed\n",
                c.name,
                c.orders.len(),
                c.modes.len(),
                c.filtered_out.len(),
                nc,
                c.errors.iter().filter(|e| e.is_some()).count()
            );
            let stay: Vec<&InvariantMode> = c
                .clusters
                .iter()
                .filter(|m| m.class != ModeClass::Spurious)
                .collect();
            if stay.is_empty() {
                text += "  no mode stays over half the orders (poles scattered); try other orders, more samples or a longer record\n";
            }
            for m in stay {
                text += &format!(
                    "  {:>8.3} Hz  damping {:.4}  in {:.0} % of orders{}\n",
                    m.frequency_hz,
                    m.damping_ratio,
                    100.0 * m.order_share,
                    if m.class == ModeClass::PeriodicDisturbance {
                        "  periodic (damping below the disturbance limit)"
                    } else {
                        ""
                    }
                );
            }
        }
        text
    }

    /// The stabilisation diagrams (one panel per channel, over its Welch spectrum) and the
    /// frequency-damping plots.
    #[cfg(feature = "report")]
    pub fn figures(&self) -> (vibmode_report::Figure, vibmode_report::Figure) {
        use vibmode_report::panels as figures;
        let mut stab = Vec::new();
        let mut damp = Vec::new();
        for c in &self.channels {
            let pts: Vec<(usize, f64, f64)> = c
                .modes
                .iter()
                .map(|m| (m.order, m.frequency_hz, m.damping_ratio))
                .collect();
            stab.push(figures::stabilisation_panel(
                &format!("{}: stabilisation diagram", c.name),
                &pts,
                &c.welch_freq_hz,
                &c.welch_psd,
                self.fs_hz / 2.0,
            ));
            damp.push(figures::damping_panel(
                &format!("{}: frequency vs damping", c.name),
                &pts,
                &[],
                self.fs_hz / 2.0,
            ));
        }
        (
            figures::grid(stab, 1, 1000, 520),
            figures::grid(damp, 1, 1000, 520),
        )
    }
}
