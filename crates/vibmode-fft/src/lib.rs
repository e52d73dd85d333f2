//! The workspace's real FFT: one planner for `f64`, shared by every thread, behind two plain
//! functions.
//!
//! Every crate of vibmode that transforms a signal asks this crate for its plans: from the
//! process's shared cache ([`forward`], [`inverse`]: for the few lengths a run repeats, such as a
//! resampler's) or from a [`Planner`] of its own (plans kept while it lives: for lengths that
//! change with the input, which a process-wide cache would keep for ever). The reason is
//! build cost as much as run cost: RustFFT's planner is generic, and each crate that calls
//! `RealFftPlanner::<f64>::plan_fft_forward` itself compiles the planner and every FFT algorithm
//! again (about half a minute of optimised compilation per crate and per test binary). Here it is
//! compiled once; the plans come back as trait objects, whose `process` needs nothing more.
//!
//! Normalisation is RustFFT's: neither direction scales, so `inverse(n)` after `forward(n)` gives
//! `n` times the input.
//!
//! ```
//! let fwd = vibmode_fft::forward(8);
//! let mut x = vec![1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0];
//! let mut spec = fwd.make_output_vec();
//! fwd.process(&mut x, &mut spec).unwrap();
//! // An impulse has a flat spectrum: n / 2 + 1 bins of 1 + 0i.
//! assert_eq!(spec.len(), 5);
//! assert!(spec.iter().all(|c| (c.re - 1.0).abs() < 1e-12 && c.im.abs() < 1e-12));
//! ```

use std::sync::{Arc, LazyLock, Mutex, MutexGuard};

pub use realfft::num_complex::Complex;
pub use realfft::{ComplexToReal, FftError, RealToComplex};

/// The process's planner. A plan's twiddle factors cost about one transform of its length and
/// the records of a run have few lengths, so plans are kept; the same length always gets the same
/// algorithm, hence the same bits.
static PLANNER: LazyLock<Mutex<realfft::RealFftPlanner<f64>>> =
    LazyLock::new(|| Mutex::new(realfft::RealFftPlanner::new()));

fn planner() -> MutexGuard<'static, realfft::RealFftPlanner<f64>> {
    // A poisoned lock only means another thread panicked while planning; the planner's cache is
    // still a valid cache.
    PLANNER.lock().unwrap_or_else(|e| e.into_inner())
}

/// The forward real FFT of length `n` (`n` real samples to `n / 2 + 1` complex bins), unscaled,
/// from the process's shared planner.
///
/// The plan is cached for the life of the process: asking again for the same `n` is cheap, and
/// its twiddle factors (about `n` complex numbers) stay in memory. `n = 0` gives a plan that
/// transforms nothing.
pub fn forward(n: usize) -> Arc<dyn RealToComplex<f64>> {
    planner().plan_fft_forward(n)
}

/// The inverse real FFT of length `n` (`n / 2 + 1` complex bins to `n` real samples), unscaled,
/// from the process's shared planner (cached for the life of the process, as [`forward`]).
///
/// The imaginary parts of the first bin, and of the last when `n` is even, must be zero; the
/// plan's `process` returns an error otherwise.
pub fn inverse(n: usize) -> Arc<dyn ComplexToReal<f64>> {
    planner().plan_fft_inverse(n)
}

/// A planner of one's own: RustFFT's `RealFftPlanner<f64>` (compiled in this crate), whose plans
/// are kept while it lives and freed with it.
///
/// The same length gives the same algorithm as the shared planner, so the same bits.
#[derive(Default)]
pub struct Planner(realfft::RealFftPlanner<f64>);

impl Planner {
    /// An empty planner.
    pub fn new() -> Planner {
        Planner(realfft::RealFftPlanner::new())
    }

    /// The forward real FFT of length `n`, unscaled (as [`forward`]), kept by this planner.
    pub fn forward(&mut self, n: usize) -> Arc<dyn RealToComplex<f64>> {
        self.0.plan_fft_forward(n)
    }

    /// The inverse real FFT of length `n`, unscaled (as [`inverse`]), kept by this planner.
    pub fn inverse(&mut self, n: usize) -> Arc<dyn ComplexToReal<f64>> {
        self.0.plan_fft_inverse(n)
    }
}
