//! Matching invariant modes to the modes of a physical reference model.

use crate::{InvariantMode, ModeClass, ModeMatch, ReferenceMode};

/// A physical-model mode is matched to a structural mode within this relative
/// frequency difference (25 %: body modes of a bus sit 15-25 % apart, wheel hop near 10 Hz).
pub const MATCH_MAX_FREQ_DIFF_REL: f64 = 0.25;

/// A physical-model mode is matched to an identified mode whose shape has at least this MAC with
/// the model's shape at the sensors (and whose frequency is within
/// [`MATCH_MAX_FREQ_DIFF_REL`]).
pub const MATCH_MAC_MIN: f64 = 0.5;

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
                    mac: None,
                },
                None => ModeMatch {
                    reference: r.clone(),
                    invariant: None,
                    freq_diff_rel: f64::NAN,
                    damping_diff: f64::NAN,
                    mac: None,
                },
            }
        })
        .collect()
}

/// Matching by frequency **and** shape, one to one: every (reference, structural mode) pair
/// whose relative frequency difference is at most `max_freq_diff_rel` and whose shapes have
/// MAC at least `mac_min` is a candidate (the reference's shape is taken at `channels`, the
/// channels of the identified shapes, by name); candidates are accepted by decreasing MAC (then
/// increasing frequency difference), each reference and each identified mode at most once.
/// References or modes without a shape fall back to frequency only, after the shape matches,
/// and only onto modes still free, the pairs closest in relative frequency first (so with no
/// shapes at all, e.g. single-channel ARMA modes, this is a one-to-one nearest-frequency match). The output has one entry per reference mode, in input order,
/// with the MAC of the match. Never panics.
pub fn match_reference_shapes(
    modes: &[InvariantMode],
    reference: &[ReferenceMode],
    channels: &[String],
    max_freq_diff_rel: f64,
    mac_min: f64,
) -> Vec<ModeMatch> {
    let ok = |r: &ReferenceMode, m: &InvariantMode| {
        m.class == ModeClass::Structural
            && m.frequency_hz.is_finite()
            && r.frequency_hz.is_finite()
            && r.frequency_hz > 0.0
            && ((m.frequency_hz - r.frequency_hz).abs() / r.frequency_hz) <= max_freq_diff_rel
    };
    let ref_shapes: Vec<Option<Vec<[f64; 2]>>> =
        reference.iter().map(|r| r.shape_for(channels)).collect();
    let mut pairs: Vec<(usize, usize, f64, f64)> = Vec::new();
    for (i, r) in reference.iter().enumerate() {
        let Some(rs) = &ref_shapes[i] else { continue };
        for (k, m) in modes.iter().enumerate() {
            let Some(ms) = &m.shape else { continue };
            if !ok(r, m) {
                continue;
            }
            let mac = crate::shapes::mac(rs, ms);
            if mac >= mac_min {
                let d = (m.frequency_hz - r.frequency_hz).abs() / r.frequency_hz;
                pairs.push((i, k, mac, d));
            }
        }
    }
    pairs.sort_by(|a, b| b.2.total_cmp(&a.2).then(a.3.total_cmp(&b.3)));
    let mut of_ref: Vec<Option<(usize, Option<f64>)>> = vec![None; reference.len()];
    let mut taken = vec![false; modes.len()];
    for (i, k, mac, _) in pairs {
        if of_ref[i].is_none() && !taken[k] {
            of_ref[i] = Some((k, Some(mac)));
            taken[k] = true;
        }
    }
    // Frequency only, for what has no shape: the closest free pairs first (relative difference),
    // so a reference earlier in the list cannot take a mode that is nearer to a later one.
    let mut by_freq: Vec<(usize, usize, f64)> = Vec::new();
    for (i, r) in reference.iter().enumerate() {
        if of_ref[i].is_some() {
            continue;
        }
        for (k, m) in modes.iter().enumerate() {
            if !taken[k] && ok(r, m) && (ref_shapes[i].is_none() || m.shape.is_none()) {
                let d = (m.frequency_hz - r.frequency_hz).abs() / r.frequency_hz;
                by_freq.push((i, k, d));
            }
        }
    }
    by_freq.sort_by(|a, b| a.2.total_cmp(&b.2));
    for (i, k, _) in by_freq {
        if of_ref[i].is_none() && !taken[k] {
            of_ref[i] = Some((k, None));
            taken[k] = true;
        }
    }
    let nearest = match_reference(modes, reference, f64::INFINITY);
    reference
        .iter()
        .zip(nearest)
        .zip(of_ref)
        .map(|((r, near), m)| match m {
            Some((k, mac)) => ModeMatch {
                reference: r.clone(),
                invariant: Some(k),
                freq_diff_rel: (modes[k].frequency_hz - r.frequency_hz) / r.frequency_hz,
                damping_diff: modes[k].damping_ratio - r.damping_ratio,
                mac,
            },
            None => ModeMatch {
                invariant: None,
                ..near
            },
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn mode(f: f64, shape: Vec<[f64; 2]>) -> InvariantMode {
        InvariantMode {
            frequency_hz: f,
            frequency_std_hz: 0.0,
            damping_ratio: 0.2,
            damping_iqr: (0.2, 0.2),
            order_share: 1.0,
            record_share: 1.0,
            n_poles: 10,
            channels: vec!["ssi".into()],
            roles: vec![],
            min_order: 2,
            class: ModeClass::Structural,
            line_kurtosis: None,
            shape: Some(shape),
            shape_mac: None,
            uncertainty: None,
        }
    }

    #[test]
    fn shapes_decide_between_modes_close_in_frequency_one_to_one() {
        let chans: Vec<String> = ["a", "b"].iter().map(|s| s.to_string()).collect();
        // identified: 1.05 Hz in phase, 1.10 Hz out of phase
        let modes = vec![
            mode(1.05, vec![[1.0, 0.0], [1.0, 0.0]]),
            mode(1.10, vec![[1.0, 0.0], [-1.0, 0.0]]),
        ];
        // model: pitch 1.03 out of phase, heave 1.17 in phase (channels given in reverse order)
        let r = |f: f64, label: &str, s: Vec<[f64; 2]>| ReferenceMode {
            shape: Some(s),
            shape_channels: vec!["b".into(), "a".into()],
            ..ReferenceMode::new(f, 0.2, label)
        };
        let reference = vec![
            r(1.03, "pitch", vec![[-1.0, 0.0], [1.0, 0.0]]),
            r(1.17, "heave", vec![[1.0, 0.0], [1.0, 0.0]]),
            r(1.08, "no shape twin", vec![[0.0, 0.0], [0.0, 0.0]]),
        ];
        let m = match_reference_shapes(&modes, &reference, &chans, 0.25, 0.5);
        assert_eq!(
            m[0].invariant,
            Some(1),
            "pitch goes to the out-of-phase mode"
        );
        assert_eq!(m[1].invariant, Some(0), "heave to the in-phase one");
        assert!((m[0].mac.unwrap() - 1.0).abs() < 1e-12);
        // both identified modes are taken: the third reference stays unmatched
        assert_eq!(m[2].invariant, None);
        assert!(m[2].freq_diff_rel.is_finite());
    }

    #[test]
    fn without_shapes_the_closest_pairs_are_matched_first_one_to_one() {
        // One identified body mode at 1.236 Hz and one wheel-hop mode at 9.255 Hz, no shapes
        // (single-channel ARMA pools): heave (5.4 % away) takes the body mode before pitch
        // (20 %) or roll (7.2 %) can, though pitch comes first in the list; of the wheel modes,
        // the front tramp (0.1 %) takes 9.255 Hz.
        let m = |f: f64| InvariantMode {
            shape: None,
            ..mode(f, vec![])
        };
        let modes = vec![m(1.236), m(9.255)];
        let reference: Vec<ReferenceMode> = [
            (1.030, "pitch"),
            (1.173, "heave"),
            (1.332, "roll"),
            (8.672, "front bounce"),
            (9.243, "front tramp"),
            (9.873, "rear tramp"),
        ]
        .iter()
        .map(|&(f, l)| ReferenceMode::new(f, 0.2, l))
        .collect();
        let got = match_reference_shapes(&modes, &reference, &[], 0.25, 0.5);
        let taken: Vec<Option<usize>> = got.iter().map(|g| g.invariant).collect();
        assert_eq!(taken, [None, Some(0), None, None, Some(1), None]);
        // the unmatched still carry the difference to the nearest structural mode
        assert!((got[0].freq_diff_rel - (1.236 / 1.030 - 1.0)).abs() < 1e-12);
        assert!((got[5].freq_diff_rel - (9.255 / 9.873 - 1.0)).abs() < 1e-12);
        assert!(got.iter().all(|g| g.mac.is_none()));
    }
}
