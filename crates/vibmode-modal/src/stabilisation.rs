//! Classic stabilisation diagram: is a pole of order p also present at the previous order?

use std::collections::{BTreeMap, HashMap};

pub use vibmode_core::Stability;

use crate::shapes::mac;
use crate::{ModalError, PoleObservation, StabilityParams};

/// Stability of every pole (same order as the input) against the poles of the previous order of the
/// same (record, channel) sweep. "Previous order" is the largest order below the pole's own
/// order that produced at least one pole in that sweep. A pole is frequency-stable when some
/// previous-order pole has `|f - f_prev| / f_prev <= freq_tol_rel`, and stable when some
/// previous-order pole also has `|zeta - zeta_prev| / zeta_prev <= damping_tol_rel` and, if both
/// poles have shapes, `MAC >= mac_min` ([`Stability::FrequencyDamping`] when only the MAC fails).
/// The best label over the previous order's poles.
///
/// Errors: non-finite frequency or damping (with the pole index), invalid params. Never panics.
pub fn stabilisation(
    poles: &[PoleObservation],
    p: &StabilityParams,
) -> Result<Vec<Stability>, ModalError> {
    p.validate()?;
    for (index, pole) in poles.iter().enumerate() {
        crate::types::check_finite(pole, index)?;
    }
    let mut sweeps: HashMap<(usize, &str), BTreeMap<usize, Vec<usize>>> = HashMap::new();
    for (i, pole) in poles.iter().enumerate() {
        sweeps
            .entry((pole.record, pole.channel.as_str()))
            .or_default()
            .entry(pole.order)
            .or_default()
            .push(i);
    }
    let mut out = vec![Stability::New; poles.len()];
    for by_order in sweeps.values() {
        let mut prev: Option<&Vec<usize>> = None;
        for current in by_order.values() {
            if let Some(prev) = prev {
                for &i in current {
                    let a = &poles[i];
                    let mut status = Stability::New;
                    for &j in prev {
                        let b = &poles[j];
                        let df = (a.frequency_hz - b.frequency_hz).abs() / b.frequency_hz.abs();
                        if df > p.freq_tol_rel {
                            continue;
                        }
                        let dz = (a.damping_ratio - b.damping_ratio).abs() / b.damping_ratio.abs();
                        let this = if dz > p.damping_tol_rel {
                            Stability::Frequency
                        } else {
                            match (&a.shape, &b.shape) {
                                (Some(sa), Some(sb)) if mac(sa, sb) < p.mac_min => {
                                    Stability::FrequencyDamping
                                }
                                _ => Stability::Stable,
                            }
                        };
                        status = status.max(this);
                    }
                    out[i] = status;
                }
            }
            prev = Some(current);
        }
    }
    Ok(out)
}
