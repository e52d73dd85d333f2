//! The body's response to the wheel motions: the cross-spectra of a record in the body band,
//! the frequency response `H(f)` (sprung channels over unsprung channels) fitted by pooling the
//! cross-spectra of the nominal records, and the feature that compares a record's measured
//! body power with the power `H S_uu H^H` its own wheel motions predict. See docs/fleet.md
//! ("Body response to wheel motion").
//!
//! The body is a linear system driven by the four suspension forces, which depend only on the
//! wheel (unsprung) and body motions; so the body's motion is `y = H(f) u` with `u` the wheel
//! motions, whatever the road and the speed. Within one record the four wheel inputs are nearly
//! coherent (the rear wheel sees the front wheel's road a wheelbase later, the left and right
//! tracks are alike at long wavelengths), but the delay changes with speed, so the cross-spectra
//! pooled over nominal records at different speeds determine `H`.

use nalgebra::DMatrix;
use serde::{Deserialize, Serialize};
use vibmode_spectra::{Complex64, SpectraError, WelchParams, WelchPlan, Window};

use crate::error::{FleetError, Result};

/// Cross-spectra of one file's sprung and unsprung channels in the body band, averaged over its
/// records (Welch, Hann, at the analysis rate). `S_uu[j][k] = E[u_j conj(u_k)]`,
/// `S_yu[i][j] = E[y_i conj(u_j)]` (units^2/Hz).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct BodySpectra {
    /// Bin frequencies, Hz.
    pub freq_hz: Vec<f64>,
    /// The unsprung (input) channels, in corner order.
    pub unsprung: Vec<String>,
    /// The sprung (output) channels, in corner order.
    pub sprung: Vec<String>,
    /// Per bin, `S_uu` row-major (`n_u x n_u`).
    pub s_uu: Vec<Vec<Complex64>>,
    /// Per bin, `S_yu` row-major (`n_y x n_u`).
    pub s_yu: Vec<Vec<Complex64>>,
    /// Per bin, the auto-spectra of the sprung channels (`n_y`).
    pub s_yy: Vec<Vec<f64>>,
}

impl BodySpectra {
    /// Zero spectra for the channels and bins given.
    pub fn zeros(freq_hz: Vec<f64>, unsprung: Vec<String>, sprung: Vec<String>) -> Self {
        let (nb, nu, ny) = (freq_hz.len(), unsprung.len(), sprung.len());
        BodySpectra {
            freq_hz,
            unsprung,
            sprung,
            s_uu: vec![vec![Complex64::new(0.0, 0.0); nu * nu]; nb],
            s_yu: vec![vec![Complex64::new(0.0, 0.0); ny * nu]; nb],
            s_yy: vec![vec![0.0; ny]; nb],
        }
    }

    /// These spectra with white noise of one-sided density `densities[j]` (the unsprung
    /// sensors' floors, in the order of `unsprung`) taken out of each input's auto-spectrum: the
    /// sensors' noise is independent of everything else, so it sits on the diagonal of `S_uu`
    /// alone. `None` if `densities` does not match the inputs or is not finite.
    pub fn without_input_noise(&self, densities: &[f64]) -> Option<Self> {
        let nu = self.unsprung.len();
        if densities.len() != nu || !densities.iter().all(|d| d.is_finite()) || !self.consistent() {
            return None;
        }
        let mut out = self.clone();
        for bin in &mut out.s_uu {
            for (j, d) in densities.iter().enumerate() {
                bin[j * nu + j] -= d.max(0.0);
            }
        }
        Some(out)
    }

    /// The largest share of an input's power in `[lo, hi)` Hz that is its sensor's noise of
    /// density `densities[j]` (the bins' count times the density over the bins' sum of `S_uu`);
    /// `None` without such a bin or if `densities` does not match the inputs.
    pub fn input_noise_share(&self, densities: &[f64], band_hz: [f64; 2]) -> Option<f64> {
        let nu = self.unsprung.len();
        if densities.len() != nu || !self.consistent() {
            return None;
        }
        let bins: Vec<usize> = (0..self.freq_hz.len())
            .filter(|&b| self.freq_hz[b] >= band_hz[0] && self.freq_hz[b] < band_hz[1])
            .collect();
        if bins.is_empty() {
            return None;
        }
        let mut worst: f64 = 0.0;
        for (j, d) in densities.iter().enumerate() {
            let power: f64 = bins.iter().map(|&b| self.s_uu[b][j * nu + j].re).sum();
            let noise = d.max(0.0) * bins.len() as f64;
            worst = worst.max(if power > 0.0 {
                noise / power
            } else {
                f64::INFINITY
            });
        }
        Some(worst)
    }

    /// These spectra times `w`.
    pub fn scaled(mut self, w: f64) -> Self {
        self.s_uu.iter_mut().flatten().for_each(|z| *z *= w);
        self.s_yu.iter_mut().flatten().for_each(|z| *z *= w);
        self.s_yy.iter_mut().flatten().for_each(|z| *z *= w);
        self
    }

    /// These spectra plus `w` times `other`; `None` if their channels or bins differ.
    pub fn add_scaled(mut self, other: &BodySpectra, w: f64) -> Option<Self> {
        if self.freq_hz != other.freq_hz
            || self.unsprung != other.unsprung
            || self.sprung != other.sprung
            || !self.consistent()
            || !other.consistent()
        {
            return None;
        }
        for (a, b) in self
            .s_uu
            .iter_mut()
            .flatten()
            .zip(other.s_uu.iter().flatten())
        {
            *a += b * w;
        }
        for (a, b) in self
            .s_yu
            .iter_mut()
            .flatten()
            .zip(other.s_yu.iter().flatten())
        {
            *a += b * w;
        }
        for (a, b) in self
            .s_yy
            .iter_mut()
            .flatten()
            .zip(other.s_yy.iter().flatten())
        {
            *a += b * w;
        }
        Some(self)
    }

    fn consistent(&self) -> bool {
        let (nb, nu, ny) = (self.freq_hz.len(), self.unsprung.len(), self.sprung.len());
        self.s_uu.len() == nb
            && self.s_yu.len() == nb
            && self.s_yy.len() == nb
            && self.s_uu.iter().all(|m| m.len() == nu * nu)
            && self.s_yu.iter().all(|m| m.len() == ny * nu)
            && self.s_yy.iter().all(|m| m.len() == ny)
    }
}

/// Cross-spectra of `inputs` (unsprung, named `unsprung`) and `outputs` (sprung, named
/// `sprung`), all of one length, sampled at `fs_hz`, in the bins of `band_hz` (inclusive): one
/// Hann-windowed periodogram over the whole record (the body's impulse response lasts about a
/// second, so shorter Welch segments would leave part of each segment's body motion to inputs
/// before the segment and bias `H`).
///
/// Errors: those of the spectra (empty, non-finite or unequal records, bad rate).
pub fn body_spectra(
    inputs: &[&[f64]],
    outputs: &[&[f64]],
    unsprung: Vec<String>,
    sprung: Vec<String>,
    fs_hz: f64,
    band_hz: [f64; 2],
) -> std::result::Result<BodySpectra, SpectraError> {
    let n = inputs.first().map_or(0, |x| x.len());
    let wp = WelchParams {
        window: Window::Hann,
        nperseg: Some(n.max(1)),
        ..WelchParams::default()
    };
    let mut plan = WelchPlan::new(n, fs_hz, &wp)?;
    let bins: Vec<usize> = plan
        .freq_hz()
        .iter()
        .enumerate()
        .filter(|(_, f)| **f >= band_hz[0] && **f <= band_hz[1])
        .map(|(k, _)| k)
        .collect();
    let freq: Vec<f64> = bins.iter().map(|&k| plan.freq_hz()[k]).collect();
    let mut out = BodySpectra::zeros(freq, unsprung, sprung);
    let nu = inputs.len();
    // csd(x, y) = E[conj(x) y]: S_uu[j][k] = csd(u_k, u_j), S_yu[i][j] = csd(u_j, y_i).
    for (k, uk) in inputs.iter().enumerate() {
        for (j, uj) in inputs.iter().enumerate() {
            let s = plan.csd(uk, uj)?;
            for (b, &bin) in bins.iter().enumerate() {
                out.s_uu[b][j * nu + k] = s.csd[bin];
            }
        }
        for (i, y) in outputs.iter().enumerate() {
            let s = plan.csd(uk, y)?;
            for (b, &bin) in bins.iter().enumerate() {
                out.s_yu[b][i * nu + k] = s.csd[bin];
            }
        }
    }
    for (i, y) in outputs.iter().enumerate() {
        let s = plan.welch(y)?;
        for (b, &bin) in bins.iter().enumerate() {
            out.s_yy[b][i] = s.psd[bin];
        }
    }
    Ok(out)
}

/// The body's frequency response to the wheel motions, fitted on nominal records.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct BodyModel {
    /// Bin frequencies, Hz.
    pub freq_hz: Vec<f64>,
    /// The unsprung (input) channels.
    pub unsprung: Vec<String>,
    /// The sprung (output) channels.
    pub sprung: Vec<String>,
    /// Per bin, `H = (sum S_yu) (sum S_uu)^-1` row-major (`n_y x n_u`).
    pub h: Vec<Vec<Complex64>>,
    /// Per bin, the condition number of the pooled `S_uu` (largest over smallest eigenvalue;
    /// `f64::MAX` where it is not positive definite).
    pub condition: Vec<f64>,
}

/// Largest condition number of the pooled wheel cross-spectral matrix at which `H` is fitted;
/// beyond it the nominal records do not tell the wheels' contributions apart (e.g. all at one
/// speed) and the bin is left out.
pub const MAX_CONDITION: f64 = 1e8;

fn matrix(n: usize, m: usize, v: &[Complex64]) -> DMatrix<Complex64> {
    DMatrix::from_row_slice(n, m, v)
}

/// Fits `H(f) = (sum S_yu)(sum S_uu)^-1` per bin over `spectra` (the nominal records' body
/// spectra, which must have the same channels and bins). Bins whose pooled `S_uu` is singular or
/// has a condition number above [`MAX_CONDITION`] get no `H` (an empty row); if no bin is left,
/// an error says so.
///
/// Errors: no spectra; spectra of different channels or bins; no bin with a well-conditioned
/// pooled `S_uu`.
pub fn fit_body_model(spectra: &[&BodySpectra]) -> Result<BodyModel> {
    let Some(first) = spectra.first() else {
        return Err(FleetError::NoBodySpectra);
    };
    for s in spectra {
        if !s.consistent()
            || s.freq_hz != first.freq_hz
            || s.unsprung != first.unsprung
            || s.sprung != first.sprung
        {
            return Err(FleetError::BodySpectraDiffer {
                sprung: s.sprung.clone(),
                unsprung: s.unsprung.clone(),
                bins: s.freq_hz.len(),
                first_sprung: first.sprung.clone(),
                first_unsprung: first.unsprung.clone(),
                first_bins: first.freq_hz.len(),
            });
        }
    }
    let (nu, ny) = (first.unsprung.len(), first.sprung.len());
    let mut h = Vec::with_capacity(first.freq_hz.len());
    let mut condition = Vec::with_capacity(first.freq_hz.len());
    for b in 0..first.freq_hz.len() {
        let mut suu = DMatrix::<Complex64>::zeros(nu, nu);
        let mut syu = DMatrix::<Complex64>::zeros(ny, nu);
        for s in spectra {
            suu += matrix(nu, nu, &s.s_uu[b]);
            syu += matrix(ny, nu, &s.s_yu[b]);
        }
        // Hermitian by construction up to rounding.
        let suu = (&suu + suu.adjoint()) * Complex64::new(0.5, 0.0);
        let eig = suu.clone().symmetric_eigen().eigenvalues;
        let (lo, hi) = eig.iter().fold((f64::INFINITY, 0.0f64), |(lo, hi), &e| {
            (lo.min(e), hi.max(e))
        });
        // Not positive definite (the wheels' noise taken out where their motion is below it,
        // or no power at all): no H, and the largest finite number as the condition (an
        // infinity would not be stored).
        let cond = if lo > 0.0 { hi / lo } else { f64::MAX };
        condition.push(cond);
        // H S_uu = S_yu  =>  S_uu H^H = S_yu^H.
        let solved = (cond <= MAX_CONDITION)
            .then(|| suu.cholesky())
            .flatten()
            .map(|c| c.solve(&syu.adjoint()).adjoint());
        h.push(match solved {
            Some(hb) if hb.iter().all(|z| z.re.is_finite() && z.im.is_finite()) => {
                // Row-major.
                (0..ny)
                    .flat_map(|i| (0..nu).map(move |j| (i, j)))
                    .map(|(i, j)| hb[(i, j)])
                    .collect()
            }
            _ => Vec::new(),
        });
    }
    if h.iter().all(Vec::is_empty) {
        let best = condition.iter().copied().fold(f64::INFINITY, f64::min);
        return Err(FleetError::BodySpectraSingular {
            best_condition: best,
            max_condition: MAX_CONDITION,
        });
    }
    Ok(BodyModel {
        freq_hz: first.freq_hz.clone(),
        unsprung: first.unsprung.clone(),
        sprung: first.sprung.clone(),
        h,
        condition,
    })
}

/// Per bin of the model (`None` where it has no `H`), per sprung channel: the power the
/// record's own wheel motions predict, `diag(H S_uu H^H)` (units^2/Hz). `None` if the record's
/// channels or bins differ from the model's.
pub fn predicted_psd(model: &BodyModel, s: &BodySpectra) -> Option<Vec<Option<Vec<f64>>>> {
    if !s.consistent()
        || s.freq_hz != model.freq_hz
        || s.unsprung != model.unsprung
        || s.sprung != model.sprung
    {
        return None;
    }
    let (nu, ny) = (model.unsprung.len(), model.sprung.len());
    Some(
        model
            .h
            .iter()
            .zip(&s.s_uu)
            .map(|(hb, suu)| {
                if hb.len() != ny * nu {
                    return None;
                }
                let hm = matrix(ny, nu, hb);
                let p = &hm * matrix(nu, nu, suu) * hm.adjoint();
                Some((0..ny).map(|i| p[(i, i)].re).collect())
            })
            .collect(),
    )
}

/// Per sprung channel of the model: `ln(sum_band S_yy / sum_band diag(H S_uu H^H))` over the
/// bins in `[lo, hi)` Hz where the model has `H` (`None` where the band has no such bin or no
/// power). `None` if the record's channels or bins differ from the model's.
pub fn body_response(
    bm: &BodyModel,
    s: &BodySpectra,
    band_hz: [f64; 2],
) -> Option<Vec<Option<f64>>> {
    let pred = predicted_psd(bm, s)?;
    let ny = bm.sprung.len();
    let mut meas = vec![0.0; ny];
    let mut want = vec![0.0; ny];
    let mut any = false;
    for (b, f) in bm.freq_hz.iter().enumerate() {
        let (Some(p), true) = (&pred[b], *f >= band_hz[0] && *f < band_hz[1]) else {
            continue;
        };
        any = true;
        for i in 0..ny {
            meas[i] += s.s_yy[b][i];
            want[i] += p[i];
        }
    }
    Some(
        (0..ny)
            .map(|i| {
                let x = (meas[i] / want[i]).ln();
                (any && x.is_finite()).then_some(x)
            })
            .collect(),
    )
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    fn c(re: f64, im: f64) -> Complex64 {
        Complex64::new(re, im)
    }

    /// One bin at 1 Hz with the given spectra.
    fn one_bin(
        nu: usize,
        ny: usize,
        suu: Vec<Complex64>,
        syu: Vec<Complex64>,
        syy: Vec<f64>,
    ) -> BodySpectra {
        BodySpectra {
            freq_hz: vec![1.0],
            unsprung: (0..nu).map(|j| format!("u{j}")).collect(),
            sprung: (0..ny).map(|i| format!("y{i}")).collect(),
            s_uu: vec![suu],
            s_yu: vec![syu],
            s_yy: vec![syy],
        }
    }

    /// By hand: S_uu = [[2, 0.5], [0.5, 5]] at 1 Hz with noise densities 1 and 1: the diagonal
    /// becomes 1 and 4, the cross term and the outputs stay; the noise shares are 1/2 and 1/5
    /// (the largest 0.5); a band without a bin, or a density per input missing: none.
    #[test]
    fn input_noise_comes_off_the_diagonal_by_hand() {
        let s = one_bin(
            2,
            1,
            vec![c(2.0, 0.0), c(0.5, 0.0), c(0.5, 0.0), c(5.0, 0.0)],
            vec![c(2.0, 0.0), c(0.0, 4.0)],
            vec![9.0],
        );
        let out = s.without_input_noise(&[1.0, 1.0]).expect("two densities");
        assert_eq!(
            out.s_uu[0],
            vec![c(1.0, 0.0), c(0.5, 0.0), c(0.5, 0.0), c(4.0, 0.0)]
        );
        assert_eq!((out.s_yu, out.s_yy), (s.s_yu.clone(), s.s_yy.clone()));
        assert_eq!(s.input_noise_share(&[1.0, 1.0], [0.5, 2.0]), Some(0.5));
        assert_eq!(s.input_noise_share(&[0.2, 1.0], [0.5, 2.0]), Some(0.2));
        assert_eq!(s.input_noise_share(&[1.0, 1.0], [2.0, 4.0]), None);
        assert!(s.without_input_noise(&[1.0]).is_none());
        assert!(s.without_input_noise(&[1.0, f64::NAN]).is_none());
    }

    /// Spectra whose wheels' noise leaves `S_uu` not positive definite in a bin give no `H` there
    /// and a finite condition number (an infinity would make the model set unstorable).
    #[test]
    fn a_bin_that_is_not_positive_definite_has_a_finite_condition() {
        let s = one_bin(
            2,
            1,
            vec![c(1.0, 0.0), c(1.0, 0.0), c(1.0, 0.0), c(1.0, 0.0)],
            vec![c(1.0, 0.0), c(1.0, 0.0)],
            vec![1.0],
        );
        let err = fit_body_model(&[&s]);
        assert!(err.is_err());
        let two = BodySpectra {
            freq_hz: vec![1.0, 2.0],
            s_uu: vec![
                s.s_uu[0].clone(),
                vec![c(2.0, 0.0), c(0.0, 0.0), c(0.0, 0.0), c(2.0, 0.0)],
            ],
            s_yu: vec![s.s_yu[0].clone(); 2],
            s_yy: vec![s.s_yy[0].clone(); 2],
            ..s.clone()
        };
        let m = fit_body_model(&[&two]).expect("one good bin");
        assert!(m.h[0].is_empty() && !m.h[1].is_empty());
        assert_eq!(m.condition[0], f64::MAX);
        let json = serde_json::to_string(&m).unwrap();
        assert!(serde_json::from_str::<BodyModel>(&json).is_ok());
    }

    #[test]
    fn response_and_prediction_by_hand() {
        // Two wheels, one body channel: S_uu = diag(1, 4), S_yu = [2, 4i] => H = [2, i];
        // predicted power |2|^2 1 + |i|^2 4 = 8.
        let s = one_bin(
            2,
            1,
            vec![c(1.0, 0.0), c(0.0, 0.0), c(0.0, 0.0), c(4.0, 0.0)],
            vec![c(2.0, 0.0), c(0.0, 4.0)],
            vec![8.0],
        );
        let m = fit_body_model(&[&s]).expect("fit");
        assert!((m.h[0][0] - c(2.0, 0.0)).norm() < 1e-12, "{:?}", m.h);
        assert!((m.h[0][1] - c(0.0, 1.0)).norm() < 1e-12, "{:?}", m.h);
        assert!((m.condition[0] - 4.0).abs() < 1e-12);
        let p = predicted_psd(&m, &s).expect("same layout");
        assert!((p[0].as_ref().expect("bin")[0] - 8.0).abs() < 1e-12);
        assert_eq!(body_response(&m, &s, [0.5, 2.0]), Some(vec![Some(0.0)]));
        // Half the measured power: ln(4 / 8).
        let mut weak = s.clone();
        weak.s_yy[0][0] = 4.0;
        let r = body_response(&m, &weak, [0.5, 2.0]).expect("layout")[0].expect("value");
        assert!((r - 0.5f64.ln()).abs() < 1e-12);
        // No bin in the band: no value; other channels: None.
        assert_eq!(body_response(&m, &s, [2.0, 3.0]), Some(vec![None]));
        let mut other = s.clone();
        other.sprung = vec!["z".into()];
        assert_eq!(body_response(&m, &other, [0.5, 2.0]), None);
    }

    #[test]
    fn coherent_wheels_are_a_one_line_error() {
        // Both records drive the two wheels identically (u1 = u0): the pooled S_uu is singular.
        let s = one_bin(
            2,
            1,
            vec![c(1.0, 0.0), c(1.0, 0.0), c(1.0, 0.0), c(1.0, 0.0)],
            vec![c(1.0, 0.0), c(1.0, 0.0)],
            vec![4.0],
        );
        let e = fit_body_model(&[&s, &s]).expect_err("singular");
        assert!(
            matches!(e, FleetError::BodySpectraSingular { best_condition, max_condition }
                if best_condition > max_condition),
            "{e:?}"
        );
        let msg = e.to_string();
        assert!(msg.contains("singular in every body bin"), "{msg}");
        assert!(
            msg.contains("several speeds") && !msg.contains('\n'),
            "{msg}"
        );
        let e = fit_body_model(&[]).expect_err("none");
        assert!(matches!(e, FleetError::NoBodySpectra), "{e:?}");
        assert!(
            e.to_string().contains("no nominal record has body spectra"),
            "{e}"
        );
    }

    /// xorshift64* uniform in (0, 1) and Box-Muller normals: no dependency for a test.
    pub(crate) struct Rng(pub(crate) u64);
    impl Rng {
        pub(crate) fn uniform(&mut self) -> f64 {
            self.0 ^= self.0 >> 12;
            self.0 ^= self.0 << 25;
            self.0 ^= self.0 >> 27;
            ((self.0.wrapping_mul(0x2545_f491_4f6c_dd1d) >> 11) as f64 + 0.5) / (1u64 << 53) as f64
        }
        pub(crate) fn normal(&mut self) -> f64 {
            let (a, b) = (self.uniform(), self.uniform());
            (-2.0 * a.ln()).sqrt() * (std::f64::consts::TAU * b).cos()
        }
    }

    pub(crate) const FS: f64 = 50.0;
    pub(crate) const N: usize = 512;
    pub(crate) const NU: usize = 3;
    pub(crate) const NY: usize = 2;
    pub(crate) const TAPS: usize = 4;

    /// A record of a known MIMO FIR system `y_i[n] = sum_j sum_k b[i][j][k] u_j[n - k]`: the
    /// wheels share a common input, delayed by a record-specific lag (as the rear wheel sees
    /// the front wheel's road), plus their own.
    pub(crate) fn fir_record(
        rng: &mut Rng,
        b: &[[[f64; TAPS]; NU]; NY],
        lag: usize,
    ) -> BodySpectra {
        let warm = 64;
        let common: Vec<f64> = (0..N + warm + lag).map(|_| rng.normal()).collect();
        let u: Vec<Vec<f64>> = (0..NU)
            .map(|j| {
                (0..N + warm)
                    .map(|n| common[n + lag * j / (NU - 1)] + 0.5 * rng.normal())
                    .collect()
            })
            .collect();
        let y: Vec<Vec<f64>> = (0..NY)
            .map(|i| {
                (warm..N + warm)
                    .map(|n| {
                        (0..NU)
                            .map(|j| (0..TAPS).map(|k| b[i][j][k] * u[j][n - k]).sum::<f64>())
                            .sum()
                    })
                    .collect()
            })
            .collect();
        let ui: Vec<&[f64]> = u.iter().map(|x| &x[warm..]).collect();
        let yi: Vec<&[f64]> = y.iter().map(Vec::as_slice).collect();
        body_spectra(
            &ui,
            &yi,
            (0..NU).map(|j| format!("u{j}")).collect(),
            (0..NY).map(|i| format!("y{i}")).collect(),
            FS,
            [1.0, 10.0],
        )
        .expect("spectra")
    }

    #[test]
    fn a_known_mimo_system_is_recovered_over_ten_seeds() {
        for seed in 1..=10u64 {
            let mut rng = Rng(0x9e37_79b9_7f4a_7c15 ^ seed);
            let mut b = [[[0.0; TAPS]; NU]; NY];
            b.iter_mut()
                .flatten()
                .flatten()
                .for_each(|x| *x = rng.normal());
            let nominal: Vec<BodySpectra> = (0..8)
                .map(|r| fir_record(&mut rng, &b, 3 + 2 * r))
                .collect();
            let refs: Vec<&BodySpectra> = nominal.iter().collect();
            let m = fit_body_model(&refs).expect("fit");
            // H against the analytic FIR response, per bin, relative to the largest |H_ij|.
            // The error is the leakage of the memory of the system across the record's edges,
            // amplified where the pooled S_uu is ill-conditioned: median 0.5 %, largest 8.7 %
            // over the 10 seeds.
            let mut errors = Vec::new();
            for (k, f) in m.freq_hz.iter().enumerate() {
                for (i, bi) in b.iter().enumerate() {
                    for (j, taps) in bi.iter().enumerate() {
                        let want: Complex64 = taps
                            .iter()
                            .enumerate()
                            .map(|(t, &bt)| {
                                Complex64::from_polar(
                                    bt,
                                    -std::f64::consts::TAU * f * t as f64 / FS,
                                )
                            })
                            .sum();
                        let scale: f64 = taps.iter().map(|x| x.abs()).sum();
                        let got = m.h[k][i * NU + j];
                        let e = (got - want).norm() / scale;
                        assert!(e < 0.15, "seed {seed} {f} Hz H[{i}][{j}] {got} vs {want}");
                        errors.push(e);
                    }
                }
            }
            let med = crate::stats::median(&errors).unwrap_or(f64::NAN);
            assert!(med < 0.015, "seed {seed}: median relative error {med}");
            // A new record of the same system: measured = predicted within a few %.
            let same = fir_record(&mut rng, &b, 6);
            for v in body_response(&m, &same, [2.0, 8.0]).expect("layout") {
                let v = v.expect("value");
                assert!(v.abs() < 0.05, "seed {seed}: {v}");
            }
            // The first body channel's response 20 % weaker: ln(0.64) there, 0 in the other.
            let mut weak = b;
            weak[0].iter_mut().flatten().for_each(|x| *x *= 0.8);
            let moved = fir_record(&mut rng, &weak, 6);
            let r = body_response(&m, &moved, [2.0, 8.0]).expect("layout");
            let (r0, r1) = (r[0].expect("y0"), r[1].expect("y1"));
            assert!((r0 - 0.64f64.ln()).abs() < 0.05, "seed {seed}: {r0}");
            assert!(r1.abs() < 0.05, "seed {seed}: {r1}");
        }
    }
}
