//! Periodic window functions, numerically following scipy.signal.get_window(fftbins=True).

use crate::Window;
use std::f64::consts::PI;

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
/// a NaN alpha gives a boxcar. [`Window::validate`] rejects such alphas, and the spectral
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
    }
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
