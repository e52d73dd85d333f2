//! Classic stabilisation diagram: is a pole of order p also present at the previous order?

use std::collections::{BTreeMap, HashMap};
use std::fmt;
use std::str::FromStr;

use serde::{Deserialize, Serialize};

use crate::{ModalError, PoleObservation, StabilisationParams};

/// Stability status of one pole in a stabilisation diagram.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Stability {
    /// No pole of the previous order (same record and channel) within the frequency tolerance,
    /// or no previous order at all. Plot symbol `o`.
    New,
    /// A pole of the previous order is within the frequency tolerance, but none is also within the
    /// damping tolerance. Plot symbol `f`.
    Frequency,
    /// A pole of the previous order is within both the frequency and damping tolerances.
    /// Plot symbol `s`.
    FrequencyAndDamping,
}

impl Stability {
    /// The usual one-letter plot symbol: `o`, `f` or `s`.
    pub fn symbol(&self) -> char {
        match self {
            Stability::New => 'o',
            Stability::Frequency => 'f',
            Stability::FrequencyAndDamping => 's',
        }
    }
}

impl fmt::Display for Stability {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Stability::New => "new",
            Stability::Frequency => "frequency",
            Stability::FrequencyAndDamping => "frequency-and-damping",
        })
    }
}

impl FromStr for Stability {
    type Err = ModalError;
    /// Case-insensitive names (`new`, `frequency`, `frequency-and-damping`) or symbols (`o`, `f`, `s`).
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s.trim().to_ascii_lowercase().replace('_', "-").as_str() {
            "new" | "o" => Ok(Stability::New),
            "frequency" | "f" => Ok(Stability::Frequency),
            "frequency-and-damping" | "stable" | "s" => Ok(Stability::FrequencyAndDamping),
            _ => Err(ModalError::UnknownName {
                what: "stability",
                value: s.to_string(),
                valid: "new (o), frequency (f), frequency-and-damping (s)",
            }),
        }
    }
}

/// Stability of every pole (same order as the input) against the poles of the previous order of the
/// same (record, channel) sweep. "Previous order" is the largest order below the pole's own
/// order that produced at least one pole in that sweep. A pole is frequency-stable when some
/// previous-order pole has `|f - f_prev| / f_prev <= freq_tol_rel`, and stable in both when some
/// previous-order pole also has `|zeta - zeta_prev| / zeta_prev <= damping_tol_rel`.
///
/// Errors: non-finite frequency or damping (with the pole index), invalid params. Never panics.
pub fn stabilisation(
    poles: &[PoleObservation],
    p: &StabilisationParams,
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
                        if df <= p.freq_tol_rel {
                            let dz =
                                (a.damping_ratio - b.damping_ratio).abs() / b.damping_ratio.abs();
                            if dz <= p.damping_tol_rel {
                                status = Stability::FrequencyAndDamping;
                                break;
                            }
                            status = Stability::Frequency;
                        }
                    }
                    out[i] = status;
                }
            }
            prev = Some(current);
        }
    }
    Ok(out)
}
