//! Periodic window functions, numerically following scipy.signal.get_window(fftbins=True).

use crate::{SpectraError, Window};
use std::f64::consts::PI;
use std::sync::Arc;

/// The taper applied to each segment: a named [`Window`], computed for the segment length in
/// force, or custom coefficients (scipy's `window=` given as an array), which fix the segment
/// length to their own.
///
/// Custom coefficients are dimensionless weights, multiplied sample by sample into each
/// detrended segment; they need no normalisation. The spectra are scaled, exactly as scipy, by
/// `1 / (fs_hz * sum(w^2))` ([`crate::Scaling::Density`], units^2/Hz) or `1 / sum(w)^2`
/// ([`crate::Scaling::Spectrum`], units^2), so a window and any non-zero multiple of it give the
/// same spectra. Give periodic windows (scipy `get_window(name, n)`) to match scipy's named
/// windows: the custom coefficients of [`window_values`] give bit-for-bit the spectra of the named
/// window.
///
/// Checked by [`WindowSpec::validate`] (and by every spectral function): at least one
/// coefficient, all finite, not all zero.
///
/// ```
/// use vibmode_spectra::{window_values, WelchParams, WelchPlan, Window, WindowSpec};
/// let x: Vec<f64> = (0..1000).map(|i| (i as f64 * 0.37).sin()).collect();
/// let hann = WindowSpec::custom(window_values(&Window::Hann, 128))?;
/// let mut plan = WelchPlan::with_window(x.len(), 50.0, &WelchParams::default(), &hann)?;
/// assert_eq!(plan.nperseg(), 128); // the window's length
/// let named = WelchParams { nperseg: Some(128), ..WelchParams::default() };
/// assert_eq!(plan.welch(&x)?, vibmode_spectra::welch(&x, 50.0, &named)?);
/// # Ok::<(), vibmode_spectra::SpectraError>(())
/// ```
#[derive(Clone, Debug, PartialEq)]
pub enum WindowSpec {
    /// A named window, computed for the segment length in force.
    Named(Window),
    /// Custom coefficients (dimensionless); their length is the segment length.
    Custom(Arc<[f64]>),
}

impl From<Window> for WindowSpec {
    fn from(w: Window) -> Self {
        WindowSpec::Named(w)
    }
}

impl WindowSpec {
    /// Custom coefficients, checked ([`WindowSpec::validate`]).
    pub fn custom(coefficients: impl Into<Arc<[f64]>>) -> Result<Self, SpectraError> {
        let w = WindowSpec::Custom(coefficients.into());
        w.validate()?;
        Ok(w)
    }

    /// Checks the window: a named one's parameters ([`Window::validate`]); custom coefficients
    /// non-empty, finite and not all zero.
    pub fn validate(&self) -> Result<(), SpectraError> {
        match self {
            WindowSpec::Named(w) => w.validate(),
            WindowSpec::Custom(c) => {
                if c.is_empty() {
                    return Err(SpectraError::EmptyWindow);
                }
                if let Some(index) = c.iter().position(|v| !v.is_finite()) {
                    return Err(SpectraError::NonFiniteWindow {
                        index,
                        value: c[index],
                    });
                }
                if c.iter().all(|&v| v == 0.0) {
                    return Err(SpectraError::ZeroWindow { len: c.len() });
                }
                Ok(())
            }
        }
    }

    /// The number of custom coefficients (the segment length they impose); `None` for a named
    /// window.
    pub fn fixed_len(&self) -> Option<usize> {
        match self {
            WindowSpec::Named(_) => None,
            WindowSpec::Custom(c) => Some(c.len()),
        }
    }

    /// The coefficients for a segment of `n` samples: a named window's [`window_values`], or
    /// the custom coefficients (whose length the caller has checked to be `n`).
    pub(crate) fn values(&self, n: usize) -> Vec<f64> {
        match self {
            WindowSpec::Named(w) => window_values(w, n),
            WindowSpec::Custom(c) => c.to_vec(),
        }
    }
}

/// Cosine-sum coefficients `a_k` of `w = sum_k (-1)^k a_k cos(2 pi k j / n)`, as scipy.signal.windows
/// defines them. Hann.
const HANN: [f64; 2] = [0.5, 0.5];
/// Hamming (0.54, 0.46: the classic rounded values, as scipy).
const HAMMING: [f64; 2] = [0.54, 0.46];
/// Blackman (0.42, 0.5, 0.08: the classic rounded values, as scipy).
const BLACKMAN: [f64; 3] = [0.42, 0.50, 0.08];
/// Flat top (scipy's coefficients).
const FLATTOP: [f64; 5] = [
    0.21557895,
    0.41663158,
    0.277263158,
    0.083578947,
    0.006947368,
];

/// The periodic window `w` of length `n` (dimensionless), as scipy's
/// `get_window(w, n)` (`fftbins=True`): the symmetric window of length `n + 1` without
/// its last sample. `n = 0` gives an empty vector, `n = 1` gives `[1.0]`.
///
/// A Tukey alpha outside [0, 1] is clamped as scipy does (<= 0: boxcar, >= 1: Hann);
/// a NaN alpha gives a boxcar; a Kaiser |beta| beyond about 713 gives NaN coefficients.
/// [`Window::validate`] rejects such parameters, and the spectral
/// functions call it, so only direct callers of this function see the clamping.
/// Never panics.
pub fn window_values(w: &Window, n: usize) -> Vec<f64> {
    if n <= 1 {
        return vec![1.0; n];
    }
    match *w {
        Window::Hann => general_cosine(n, &HANN),
        Window::Hamming => general_cosine(n, &HAMMING),
        Window::Blackman => general_cosine(n, &BLACKMAN),
        Window::Boxcar => vec![1.0; n],
        Window::Flattop => general_cosine(n, &FLATTOP),
        Window::Tukey { alpha } => tukey(n, alpha),
        Window::Kaiser { beta } => kaiser(n, beta),
    }
}

/// Periodic Kaiser window of length n (symmetric length n + 1, last point dropped):
/// `I0(beta sqrt(1 - r^2)) / I0(beta)` with `r = 2 j / n - 1`. A |beta| beyond about 713
/// overflows I0 (NaN coefficients); [`Window::validate`] rejects |beta| > 700.
fn kaiser(n: usize, beta: f64) -> Vec<f64> {
    let den = bessel_i0(beta);
    let m1 = n as f64;
    (0..n)
        .map(|j| {
            let r = 2.0 * j as f64 / m1 - 1.0;
            bessel_i0(beta * (1.0 - r * r).max(0.0).sqrt()) / den
        })
        .collect()
}

/// Modified Bessel function of the first kind, order 0: `sum_k ((x/2)^k / k!)^2`. All terms are
/// positive (no cancellation): relative error a few ulps times the number of terms (about
/// |x| + 40).
fn bessel_i0(x: f64) -> f64 {
    let q = x * x / 4.0;
    let mut term = 1.0;
    let mut sum = 1.0;
    let mut k = 1.0;
    while k < 2000.0 {
        term *= q / (k * k);
        sum += term;
        if term <= sum * 1e-17 {
            break;
        }
        k += 1.0;
    }
    sum
}

/// Periodic generalized cosine window: sum_k a_k cos(k * phi_j), phi_j running from -pi in
/// steps of 2 pi / n (the symmetric grid of n + 1 points on [-pi, pi], last one dropped).
fn general_cosine(n: usize, a: &[f64]) -> Vec<f64> {
    let step = 2.0 * PI / n as f64;
    (0..n)
        .map(|j| {
            let phi = j as f64 * step - PI;
            a.iter()
                .enumerate()
                .map(|(k, &ak)| ak * (k as f64 * phi).cos())
                .sum()
        })
        .collect()
}

/// Periodic Tukey window of length n (symmetric length n + 1, last point dropped).
fn tukey(n: usize, alpha: f64) -> Vec<f64> {
    if alpha.is_nan() || alpha <= 0.0 {
        return vec![1.0; n];
    }
    if alpha >= 1.0 {
        return general_cosine(n, &HANN);
    }
    // Symmetric length m = n + 1, so m - 1 = n.
    let m1 = n as f64;
    let width = (alpha * m1 / 2.0).floor() as usize;
    (0..n)
        .map(|j| {
            let jf = j as f64;
            if j <= width {
                0.5 * (1.0 + (PI * (-1.0 + 2.0 * jf / alpha / m1)).cos())
            } else if j >= n - width {
                0.5 * (1.0 + (PI * (-2.0 / alpha + 1.0 + 2.0 * jf / alpha / m1)).cos())
            } else {
                1.0
            }
        })
        .collect()
}
