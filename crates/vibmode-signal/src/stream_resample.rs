//! Block-by-block anti-alias filtering and resampling of recordings of any length: a linear-phase
//! polyphase FIR (Kaiser-windowed sinc) evaluated only at the output samples.
//!
//! # Filter
//! Let `nyq = min(fs_in, fs_out) / 2` (the lower Nyquist frequency). The filter passes
//! `0..=pass_hz` and stops `stop_hz..`:
//! - `pass_hz` = the cutoff given, default `0.8 nyq` (80 Hz when decimating to 200 Hz);
//! - `stop_hz = min(nyq, pass_hz + 0.2 nyq)` (100 Hz there; 45 Hz with the paper's cutoff of
//!   25 Hz at 200 Hz): nothing that can alias into the output, at any frequency, is left above
//!   the stop-band attenuation;
//! - Kaiser window for `attenuation_db` (default 110 dB, so the stop band is below -100 dB with
//!   margin; the pass-band ripple of a Kaiser design is the same `10^(-A/20)`, 3.2e-6 for 110 dB),
//!   length `N = (A - 7.95) / (2.285 * 2 pi (stop - pass) / (L fs_in)) + 1` (odd) at the up-sampled
//!   rate, sinc cut at `(pass + stop) / 2`, taps normalised to a DC gain of exactly 1.
//!
//! The rate ratio must be a ratio `L / M` of integers with `L <= 1024` (`fs_out / fs_in` within
//! 1e-9 relative): 20 kHz -> 200 Hz is 1/100, 44.1 kHz -> 200 Hz is 2/441. The output sample `m`
//! sits at time `m / fs_out` exactly (the filter's delay is compensated; zero phase), as with the
//! whole-record ideal filter of [`crate::resample()`]. The input is taken as zero before its
//! first and after its last sample, so the first and last `N / (2 L fs_in)` seconds carry edge
//! effects (the ideal filter has its own there: it treats the record as periodic). Output length:
//! `ceil(n_in L / M)`, the same as [`crate::resample()`] for integer ratios.
//!
//! Cost: `N / L` multiply-adds per output sample and channel (7 109 for 20 kHz -> 200 Hz), the
//! channels in parallel; memory: `N / L` input samples per channel besides the block.

use crate::error::{Result, SignalError};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

/// Parameters of [`FirDecimator`].
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct StreamResampleParams {
    /// The rate to resample to, Hz (as [`crate::ResampleParams::fs_out_hz`]; the older key
    /// `to_hz` is still read). Default 200.
    #[serde(alias = "to_hz")]
    pub fs_out_hz: f64,
    /// Pass-band edge, Hz. Default `None` = 0.8 x the lower Nyquist frequency.
    pub cutoff_hz: Option<f64>,
    /// Stop-band attenuation (and pass-band ripple, `10^(-A/20)`) of the Kaiser design, dB.
    /// Default 110.
    pub attenuation_db: f64,
}

impl Default for StreamResampleParams {
    fn default() -> Self {
        StreamResampleParams {
            fs_out_hz: 200.0,
            cutoff_hz: None,
            attenuation_db: 110.0,
        }
    }
}

/// Which resampler a file goes through (`vibmode resample --resampler`): the paper's ideal DFT
/// filter over the whole record in memory ([`crate::Resampler`]), the streamed FIR
/// ([`FirDecimator`], any length in bounded memory), or `Auto` (the default): ideal for input
/// files up to [`ResamplerKind::AUTO_IDEAL_MAX_BYTES`], FIR above.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum ResamplerKind {
    /// Ideal up to [`ResamplerKind::AUTO_IDEAL_MAX_BYTES`] of input file, streamed FIR above
    /// (ideal whenever no anti-alias filter is asked for).
    #[default]
    Auto,
    /// The ideal DFT low-pass over the whole record.
    Ideal,
    /// The streamed linear-phase FIR.
    Fir,
}

impl ResamplerKind {
    /// The names [`ResamplerKind::from_str`](std::str::FromStr) accepts.
    pub const NAMES: [&'static str; 3] = ["auto", "ideal", "fir"];

    /// Input files up to this size are resampled whole with the ideal filter by `Auto` (64 MiB).
    pub const AUTO_IDEAL_MAX_BYTES: u64 = 64 << 20;

    /// Whether a file of `input_bytes` (`None`: size unknown) goes through the streamed FIR;
    /// `filter = false` (plain decimation, which only the ideal resampler does) keeps `Auto`
    /// on the ideal resampler.
    pub fn streams(self, input_bytes: Option<u64>, filter: bool) -> bool {
        match self {
            ResamplerKind::Fir => true,
            ResamplerKind::Ideal => false,
            ResamplerKind::Auto => {
                filter && input_bytes.is_some_and(|n| n > Self::AUTO_IDEAL_MAX_BYTES)
            }
        }
    }
}

impl std::str::FromStr for ResamplerKind {
    type Err = vibmode_core::ParamError;
    /// Accepts the [`ResamplerKind::NAMES`] (case-insensitive).
    fn from_str(s: &str) -> std::result::Result<Self, Self::Err> {
        match s.trim().to_ascii_lowercase().as_str() {
            "auto" => Ok(ResamplerKind::Auto),
            "ideal" => Ok(ResamplerKind::Ideal),
            "fir" => Ok(ResamplerKind::Fir),
            _ => Err(vibmode_core::ParamError::UnknownName {
                what: "resampler",
                value: s.to_string(),
                valid: "auto, ideal, fir",
            }),
        }
    }
}

/// The designed filter, as used (for messages and documentation of a run).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct FirDesign {
    /// Input rate, Hz.
    pub fs_in_hz: f64,
    /// Output rate, Hz (`fs_in_hz * up / down`).
    pub fs_out_hz: f64,
    /// Up-sampling factor L.
    pub up: usize,
    /// Down-sampling factor M.
    pub down: usize,
    /// Pass-band edge, Hz.
    pub pass_hz: f64,
    /// Stop-band edge, Hz.
    pub stop_hz: f64,
    /// Design attenuation, dB.
    pub attenuation_db: f64,
    /// Kaiser window beta.
    pub kaiser_beta: f64,
    /// Taps at the up-sampled rate (odd).
    pub n_taps: usize,
}

/// `L / M` with `L <= max_up` equal to `x` within 1e-9 relative (continued fractions).
pub fn rational_ratio(x: f64, max_up: usize) -> Option<(usize, usize)> {
    if !(x.is_finite() && x > 0.0) {
        return None;
    }
    // Convergents of 1/x = M/L.
    let y = 1.0 / x;
    let (mut h0, mut h1) = (0u128, 1u128); // numerators (M)
    let (mut k0, mut k1) = (1u128, 0u128); // denominators (L)
    let mut r = y;
    for _ in 0..64 {
        let a = r.floor();
        if a > 1e12 {
            return None;
        }
        let a = a as u128;
        let (h2, k2) = (a * h1 + h0, a * k1 + k0);
        (h0, h1, k0, k1) = (h1, h2, k1, k2);
        if k1 as usize > max_up {
            return None;
        }
        let approx = k1 as f64 / h1 as f64;
        if (approx - x).abs() <= 1e-9 * x {
            return Some((k1 as usize, h1 as usize));
        }
        let frac = r - r.floor();
        if frac < 1e-15 {
            return None;
        }
        r = 1.0 / frac;
    }
    None
}

/// Modified Bessel function of the first kind, order 0 (power series; converges for the betas
/// used, below 20).
pub fn bessel_i0(x: f64) -> f64 {
    let mut sum = 1.0;
    let mut term = 1.0;
    let q = x * x / 4.0;
    for k in 1..200 {
        term *= q / (k as f64 * k as f64);
        sum += term;
        if term < 1e-17 * sum {
            break;
        }
    }
    sum
}

/// Kaiser's beta for a stop-band attenuation of `a_db` dB.
pub fn kaiser_beta(a_db: f64) -> f64 {
    if a_db > 50.0 {
        0.1102 * (a_db - 8.7)
    } else if a_db >= 21.0 {
        0.5842 * (a_db - 21.0).powf(0.4) + 0.07886 * (a_db - 21.0)
    } else {
        0.0
    }
}

/// Linear-phase low-pass taps: Kaiser-windowed sinc with cutoff `fc_rel` (cycles per sample),
/// `n` taps (odd), DC gain 1.
pub fn kaiser_lowpass(n: usize, fc_rel: f64, beta: f64) -> Vec<f64> {
    let d = (n as f64 - 1.0) / 2.0;
    let i0b = bessel_i0(beta);
    let mut h: Vec<f64> = (0..n)
        .map(|k| {
            let x = k as f64 - d;
            let s = if x == 0.0 {
                2.0 * fc_rel
            } else {
                (2.0 * std::f64::consts::PI * fc_rel * x).sin() / (std::f64::consts::PI * x)
            };
            let r = if d > 0.0 { x / d } else { 0.0 };
            let w = bessel_i0(beta * (1.0 - r * r).max(0.0).sqrt()) / i0b;
            s * w
        })
        .collect();
    let sum: f64 = h.iter().sum();
    for v in &mut h {
        *v /= sum;
    }
    h
}

fn invalid(name: &'static str, value: f64, fix: String) -> SignalError {
    SignalError::InvalidParam {
        name,
        value: value.to_string(),
        fix,
    }
}

impl FirDesign {
    /// Designs the filter for input rate `fs_in_hz` (see the module documentation).
    pub fn new(fs_in_hz: f64, p: &StreamResampleParams) -> Result<FirDesign> {
        if !(fs_in_hz.is_finite() && fs_in_hz > 0.0) {
            return Err(invalid(
                "fs_in_hz",
                fs_in_hz,
                "must be a positive rate in Hz".into(),
            ));
        }
        if !(p.fs_out_hz.is_finite() && p.fs_out_hz > 0.0) {
            return Err(invalid(
                "fs_out_hz",
                p.fs_out_hz,
                "must be a positive rate in Hz, e.g. 200".into(),
            ));
        }
        if !(p.attenuation_db.is_finite() && (40.0..=200.0).contains(&p.attenuation_db)) {
            return Err(invalid(
                "attenuation_db",
                p.attenuation_db,
                "must lie in 40..200 dB, e.g. 110".into(),
            ));
        }
        let (up, down) = rational_ratio(p.fs_out_hz / fs_in_hz, 1024).ok_or_else(|| {
            invalid(
                "fs_out_hz",
                p.fs_out_hz,
                format!(
                    "{} / {fs_in_hz} Hz is not a ratio of whole numbers L/M with L <= 1024; the streaming filter needs one (e.g. 20000 -> 200 Hz); resample the whole record instead",
                    p.fs_out_hz
                ),
            )
        })?;
        let fs_out = fs_in_hz * up as f64 / down as f64;
        let nyq = fs_in_hz.min(fs_out) / 2.0;
        let pass = p.cutoff_hz.unwrap_or(0.8 * nyq);
        if !(pass.is_finite() && pass > 0.0 && pass < nyq) {
            return Err(invalid(
                "cutoff_hz",
                pass,
                format!(
                    "the pass-band edge must lie between 0 and the Nyquist frequency {nyq} Hz (exclusive) so that a transition band fits; e.g. {}",
                    0.8 * nyq
                ),
            ));
        }
        let stop = nyq.min(pass + 0.2 * nyq);
        let fs_up = fs_in_hz * up as f64;
        let dw = 2.0 * std::f64::consts::PI * (stop - pass) / fs_up;
        let mut n = ((p.attenuation_db - 7.95) / (2.285 * dw)).ceil() as usize + 1;
        n = n.max(3);
        if n % 2 == 0 {
            n += 1;
        }
        Ok(FirDesign {
            fs_in_hz,
            fs_out_hz: fs_out,
            up,
            down,
            pass_hz: pass,
            stop_hz: stop,
            attenuation_db: p.attenuation_db,
            kaiser_beta: kaiser_beta(p.attenuation_db),
            n_taps: n,
        })
    }

    /// The taps at the up-sampled rate `up * fs_in_hz`.
    pub fn taps(&self) -> Vec<f64> {
        let fs_up = self.fs_in_hz * self.up as f64;
        let fc = (self.pass_hz + self.stop_hz) / 2.0 / fs_up;
        kaiser_lowpass(self.n_taps, fc, self.kaiser_beta)
    }

    /// Seconds at each end of a recording where the output feels the zeros outside it.
    pub fn edge_s(&self) -> f64 {
        (self.n_taps as f64 - 1.0) / 2.0 / (self.fs_in_hz * self.up as f64)
    }
}

/// Dot product with four accumulators (vectorises without reassociation).
#[inline]
fn dot(a: &[f64], b: &[f64]) -> f64 {
    let n = a.len().min(b.len());
    let (a, b) = (&a[..n], &b[..n]);
    let mut s = [0.0f64; 8];
    let ca = a.chunks_exact(8);
    let cb = b.chunks_exact(8);
    let (ra, rb) = (ca.remainder(), cb.remainder());
    for (x, y) in ca.zip(cb) {
        for k in 0..8 {
            s[k] += x[k] * y[k];
        }
    }
    let mut tail = 0.0;
    for (x, y) in ra.iter().zip(rb) {
        tail += x * y;
    }
    (s[0] + s[4]) + (s[1] + s[5]) + (s[2] + s[6]) + (s[3] + s[7]) + tail
}

/// A streaming polyphase FIR resampler for several channels; feed blocks with
/// [`FirDecimator::process`], then call [`FirDecimator::finish`].
#[derive(Debug)]
pub struct FirDecimator {
    design: FirDesign,
    /// Per phase p, the taps `h[p + i L]` reversed and times L.
    phases: Vec<Vec<f64>>,
    k_max: usize,
    /// Half the filter length at the up-sampled rate (the delay compensated).
    delay: u64,
    /// Per channel: input samples from absolute index `buf_start` on.
    bufs: Vec<Vec<f64>>,
    buf_start: i64,
    n_in: u64,
    n_out: u64,
}

impl FirDecimator {
    /// A resampler from `fs_in_hz` for `n_channels` channels.
    pub fn new(fs_in_hz: f64, n_channels: usize, p: &StreamResampleParams) -> Result<Self> {
        let design = FirDesign::new(fs_in_hz, p)?;
        let h = design.taps();
        let l = design.up;
        let phases: Vec<Vec<f64>> = (0..l)
            .map(|ph| {
                let mut g: Vec<f64> = (ph..h.len()).step_by(l).map(|k| h[k] * l as f64).collect();
                g.reverse();
                g
            })
            .collect();
        let k_max = phases.iter().map(Vec::len).max().unwrap_or(1);
        Ok(FirDecimator {
            delay: ((design.n_taps - 1) / 2) as u64,
            design,
            phases,
            k_max,
            bufs: vec![vec![0.0; k_max]; n_channels],
            buf_start: -(k_max as i64),
            n_in: 0,
            n_out: 0,
        })
    }

    /// The filter in use.
    pub fn design(&self) -> &FirDesign {
        &self.design
    }

    /// Output rate, Hz.
    pub fn fs_out_hz(&self) -> f64 {
        self.design.fs_out_hz
    }

    /// Input samples per channel consumed so far.
    pub fn n_in(&self) -> u64 {
        self.n_in
    }

    /// (last input index needed, phase, first-tap input index) of output `m`.
    fn locate(&self, m: u64) -> (i64, usize) {
        let t = m * self.design.down as u64 + self.delay;
        let l = self.design.up as u64;
        ((t / l) as i64, (t % l) as usize)
    }

    /// Computes every output whose inputs up to `avail` (exclusive, absolute) are present, up to
    /// `limit` outputs in all.
    fn run(&mut self, avail: i64, limit: u64) -> Vec<Vec<f64>> {
        let mut ms = Vec::new();
        let mut m = self.n_out;
        while m < limit {
            let (j0, ph) = self.locate(m);
            if j0 >= avail {
                break;
            }
            ms.push((j0, ph));
            m += 1;
        }
        self.n_out = m;
        let phases = &self.phases;
        let start = self.buf_start;
        let outs: Vec<Vec<f64>> = self
            .bufs
            .par_iter()
            .map(|buf| {
                ms.iter()
                    .map(|&(j0, ph)| {
                        let g = &phases[ph];
                        let hi = (j0 - start) as usize + 1;
                        let lo = hi - g.len();
                        dot(g, &buf[lo..hi])
                    })
                    .collect()
            })
            .collect();
        // Drop the input no later output needs.
        let (next_j0, _) = self.locate(self.n_out);
        let keep_from = next_j0 - self.k_max as i64 + 1;
        let drop = (keep_from - self.buf_start).max(0) as usize;
        let drop = drop.min(self.bufs.first().map_or(0, Vec::len));
        if drop > 0 {
            for b in &mut self.bufs {
                b.drain(..drop);
            }
            self.buf_start += drop as i64;
        }
        outs
    }

    /// Feeds one block (`block[c]` = channel c, all the same length) and returns the output
    /// samples now complete, per channel.
    pub fn process(&mut self, block: &[Vec<f64>]) -> Result<Vec<Vec<f64>>> {
        if block.len() != self.bufs.len() {
            return Err(invalid(
                "channels",
                block.len() as f64,
                format!(
                    "the resampler was made for {} channels; feed blocks with that many",
                    self.bufs.len()
                ),
            ));
        }
        let n = block.first().map_or(0, Vec::len);
        if block.iter().any(|c| c.len() != n) {
            return Err(invalid(
                "block length",
                n as f64,
                "every channel of a block must have the same number of samples".into(),
            ));
        }
        for (b, c) in self.bufs.iter_mut().zip(block) {
            b.extend_from_slice(c);
        }
        self.n_in += n as u64;
        Ok(self.run(self.n_in as i64, u64::MAX))
    }

    /// The last output samples (the input taken as zero past its end): in all
    /// `ceil(n_in L / M)` samples per channel have been returned.
    pub fn finish(&mut self) -> Vec<Vec<f64>> {
        let (l, m) = (self.design.up as u64, self.design.down as u64);
        let total = (self.n_in * l).div_ceil(m);
        if self.n_out >= total || total == 0 {
            return vec![Vec::new(); self.bufs.len()];
        }
        let (j_last, _) = self.locate(total - 1);
        let have = self.buf_start + self.bufs.first().map_or(0, Vec::len) as i64;
        let pad = (j_last + 1 - have).max(0) as usize;
        for b in &mut self.bufs {
            b.resize(b.len() + pad, 0.0);
        }
        self.run(j_last + 1, total)
    }
}

/// What [`resample_stream`] did.
#[derive(Clone, Debug, PartialEq)]
pub struct StreamResampleSummary {
    /// The filter.
    pub design: FirDesign,
    /// Input frames read.
    pub frames_in: u64,
    /// Output frames written.
    pub frames_out: u64,
}

/// Reads `stream` block by block, filters and resamples it with a [`FirDecimator`] and writes
/// the result to `out` as it goes ([`crate::StreamWriter`]: nothing is left at `out` if anything
/// fails). `progress(frames_read)` is called after every block.
pub fn resample_stream(
    stream: &mut crate::FrameStream,
    out: &std::path::Path,
    p: &StreamResampleParams,
    progress: &mut dyn FnMut(u64),
) -> Result<StreamResampleSummary> {
    let info = stream.info().clone();
    let mut fir = FirDecimator::new(info.fs_hz, info.n_channels(), p)?;
    let mut w =
        crate::StreamWriter::create(out, &info.names, &info.units, fir.fs_out_hz(), info.start_s)?;
    while let Some(b) = stream.next_block(crate::DEFAULT_BLOCK_FRAMES)? {
        let y = fir.process(&b.channels)?;
        w.write_block(&y)?;
        progress(fir.n_in());
    }
    let y = fir.finish();
    w.write_block(&y)?;
    let frames_out = w.frames_written();
    w.finish()?;
    Ok(StreamResampleSummary {
        design: fir.design().clone(),
        frames_in: fir.n_in(),
        frames_out,
    })
}
