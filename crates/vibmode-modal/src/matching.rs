//! Matching invariant modes to the modes of a physical reference model.

use crate::{InvariantMode, ModeClass, ModeMatch, ReferenceMode};

/// For every reference mode, find the nearest-in-frequency **structural** invariant mode
/// (`class == Structural`; periodic disturbances and spurious clusters are never matched).
///
/// Nearness is the relative difference `|f_inv - f_ref| / f_ref`; the match is accepted when it is
/// `<= max_freq_diff_rel` (e.g. 0.1 for 10 %). Several reference modes may match the same invariant
/// mode (the full-car model has four nearly equal wheel-hop modes); the output has one entry per
/// reference mode, in input order. Unmatched references have `invariant: None` and still carry the
/// differences to the nearest structural mode (NaN when there is none). A NaN or negative
/// `max_freq_diff_rel`, or a reference with a non-finite or non-positive frequency, matches nothing.
/// Never panics.
pub fn match_reference(
    modes: &[InvariantMode],
    reference: &[ReferenceMode],
    max_freq_diff_rel: f64,
) -> Vec<ModeMatch> {
    reference
        .iter()
        .map(|r| {
            let mut nearest: Option<(f64, usize)> = None;
            if r.frequency_hz.is_finite() && r.frequency_hz > 0.0 {
                for (k, m) in modes.iter().enumerate() {
                    if m.class != ModeClass::Structural || !m.frequency_hz.is_finite() {
                        continue;
                    }
                    let d = (m.frequency_hz - r.frequency_hz).abs() / r.frequency_hz;
                    if nearest.map_or(true, |(bd, _)| d < bd) {
                        nearest = Some((d, k));
                    }
                }
            }
            match nearest {
                Some((d, k)) => ModeMatch {
                    reference: r.clone(),
                    invariant: (d <= max_freq_diff_rel).then_some(k),
                    freq_diff_rel: (modes[k].frequency_hz - r.frequency_hz) / r.frequency_hz,
                    damping_diff: modes[k].damping_ratio - r.damping_ratio,
                },
                None => ModeMatch {
                    reference: r.clone(),
                    invariant: None,
                    freq_diff_rel: f64::NAN,
                    damping_diff: f64::NAN,
                },
            }
        })
        .collect()
}
