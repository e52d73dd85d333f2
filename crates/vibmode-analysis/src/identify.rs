//! Stage 3, identification: the ARMA/AR order sweep per channel ([`SweepIdentifier`]), an
//! implementation of the [`Identifier`] contract of `vibmode-core`.

use vibmode_core::{
    BandLimit, FitSummary, Identifier, ModelCoefficients, PoleFilterParams, PoleOut, SignalFits,
    SweepParams,
};
use vibmode_ident::{ArMethod, ArmaModel, ArmaParams, IdentError};

/// The paper's method: an order sweep of ARMA(p,p) (or AR(p)) models, warm-started order to
/// order, each fit's modes through the shared pole filters.
#[derive(Clone, Debug, PartialEq)]
pub struct SweepIdentifier {
    /// The sweep's settings.
    pub sweep: SweepParams,
    /// The pole filters.
    pub poles: PoleFilterParams,
}

impl SweepIdentifier {
    /// The prediction-error settings of each fit of the sweep.
    pub fn arma_params(&self, band: &BandLimit) -> ArmaParams {
        ArmaParams {
            robust: self.sweep.robust,
            max_iterations: self.sweep.max_iterations,
            tolerance: self.sweep.tolerance,
            starts: self.sweep.starts,
            band: Some(*band),
            ..ArmaParams::default()
        }
    }

    fn fits(&self, y: &[f64], band: &BandLimit) -> Vec<Result<ArmaModel, IdentError>> {
        vibmode_ident::sweep_fits(
            y,
            self.sweep.model,
            ArMethod::Burg,
            &self.sweep.orders(),
            &self.arma_params(band),
        )
    }
}

impl Identifier for SweepIdentifier {
    fn identify(
        &self,
        y: &[f64],
        band: &BandLimit,
        record: usize,
        keep_orders: &[usize],
    ) -> SignalFits {
        let mut out = SignalFits::default();
        for (order, fit) in self.sweep.orders().into_iter().zip(self.fits(y, band)) {
            match fit {
                Ok(m) => {
                    let set = m.modes(band.fs_hz);
                    let modes = vibmode_ident::filter_mode_set(&m, &set, band, &self.poles);
                    out.poles
                        .extend(
                            modes
                                .iter()
                                .filter(|f| f.rejected.is_none())
                                .map(|f| PoleOut {
                                    record,
                                    order,
                                    frequency_hz: f.mode.frequency_hz,
                                    damping_ratio: f.mode.damping_ratio,
                                }),
                        );
                    if keep_orders.contains(&order) {
                        out.models.push(ModelCoefficients {
                            order,
                            fs_hz: band.fs_hz,
                            a: m.a.clone(),
                            c: m.c.clone(),
                            noise_variance: m.noise_variance,
                        });
                    }
                    out.fits.push(FitSummary {
                        record,
                        order,
                        loss: m.loss,
                        noise_variance: m.noise_variance,
                        converged: m.converged,
                        n_unstable: set.unstable_poles.len(),
                        failed: false,
                        error: None,
                    });
                }
                Err(e) => out.fits.push(FitSummary {
                    record,
                    order,
                    loss: f64::NAN,
                    noise_variance: f64::NAN,
                    converged: false,
                    n_unstable: 0,
                    failed: true,
                    error: Some(e.to_string()),
                }),
            }
        }
        out
    }
}
