//! Stabilisation labels: each mode at each order compared with the modes of the previous order.

pub use vibmode_core::Stability;
use vibmode_core::StabilityParams;

use crate::cov::{SsiMode, SsiResult};
use crate::shape::mac;

fn label(mode: &SsiMode, previous: &[SsiMode], p: &StabilityParams) -> Stability {
    let mut best = Stability::New;
    for q in previous {
        if (mode.frequency_hz - q.frequency_hz).abs() > p.freq_tol_rel * q.frequency_hz {
            continue;
        }
        let this =
            if (mode.damping_ratio - q.damping_ratio).abs() > p.damping_tol_rel * q.damping_ratio {
                Stability::Frequency
            } else if mac(&mode.shape, &q.shape) < p.mac_min {
                Stability::FrequencyDamping
            } else {
                Stability::Stable
            };
        best = best.max(this);
    }
    best
}

/// Labels every mode of `result` (same nesting as `result.orders[o].modes[m]`) against the
/// modes of the previous entry of `result.orders`: the best label over all of its modes, where a
/// mode `q` of the previous order matches in frequency when `|f - f_q| <= freq_tol_rel f_q`, in
/// damping when `|z - z_q| <= damping_tol_rel z_q`, and in shape when
/// `MAC(shape, shape_q) >= mac_min`. Every mode of the first order is [`Stability::New`].
pub fn stabilisation(result: &SsiResult, params: &StabilityParams) -> Vec<Vec<Stability>> {
    let mut out = Vec::with_capacity(result.orders.len());
    let mut previous: &[SsiMode] = &[];
    for order in &result.orders {
        out.push(
            order
                .modes
                .iter()
                .map(|m| label(m, previous, params))
                .collect(),
        );
        previous = &order.modes;
    }
    out
}
