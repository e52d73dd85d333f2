//! The one median every layer uses (spectra, identification, clustering, lines, segmentation,
//! fleet): mean of the two middle values for an even count, NaN for no value; and the high
//! median (the larger middle value) where the level must be an observed value; and the dot
//! product the fits' inner loops share ([`dot`]).
//!
//! Values are ordered by [`f64::total_cmp`]; callers pass NaN-free values (every input is checked
//! to be finite where it is read) or filter them first.

/// Median of `v`, reordering `v` in place (O(n): `select_nth_unstable`). NaN when `v` is empty.
pub fn median_in_place(v: &mut [f64]) -> f64 {
    let n = v.len();
    if n == 0 {
        return f64::NAN;
    }
    let mid = n / 2;
    let (lower, m, _) = v.select_nth_unstable_by(mid, f64::total_cmp);
    let upper = *m;
    if n % 2 == 1 {
        upper
    } else {
        let below = lower.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        (below + upper) / 2.0
    }
}

/// Median of `values` (copied). NaN when `values` is empty.
pub fn median(values: &[f64]) -> f64 {
    median_in_place(&mut values.to_vec())
}

/// The high median of `v` (Python's `statistics.median_high`): the middle value for an odd
/// count, the larger of the two middle values for an even count, always one of the values.
/// Reorders `v` in place (O(n)). NaN when `v` is empty. For a level that must be one of the
/// observed values (a peak's surrounding level, a noise density).
pub fn median_high_in_place(v: &mut [f64]) -> f64 {
    let n = v.len();
    if n == 0 {
        return f64::NAN;
    }
    *v.select_nth_unstable_by(n / 2, f64::total_cmp).1
}

/// Dot product of the common length of `x` and `z`, with four accumulators (accumulator k sums
/// the products at indices `4 i + k`; the chunks of four share SIMD registers): about 4x faster
/// than one running sum, whose every addition waits for the previous one, and no less accurate.
/// The ARMA fits' filters and SSI-cov's lag sums use it.
#[inline]
pub fn dot(x: &[f64], z: &[f64]) -> f64 {
    let n = x.len().min(z.len());
    let (xc, zc) = (x[..n].chunks_exact(4), z[..n].chunks_exact(4));
    let (xr, zr) = (xc.remainder(), zc.remainder());
    let mut s = [0.0f64; 4];
    for (a, b) in xc.zip(zc) {
        for k in 0..4 {
            s[k] += a[k] * b[k];
        }
    }
    let mut tail = 0.0;
    for (a, b) in xr.iter().zip(zr) {
        tail += a * b;
    }
    (s[0] + s[1]) + (s[2] + s[3]) + tail
}

/// The smallest and largest of `x` (no NaN), in four lanes (`<` and `>` compare as SIMD
/// instructions where `f64::min` and `max`, which mind NaN, do not).
///
/// # Panics
/// When `x` is empty.
pub fn extremes(x: &[f64]) -> (f64, f64) {
    let (mut lo, mut hi) = ([x[0]; 4], [x[0]; 4]);
    let chunks = x.chunks_exact(4);
    let rest = chunks.remainder();
    for c in chunks {
        for k in 0..4 {
            lo[k] = if c[k] < lo[k] { c[k] } else { lo[k] };
            hi[k] = if c[k] > hi[k] { c[k] } else { hi[k] };
        }
    }
    let mut min = lo.iter().copied().fold(lo[0], f64::min);
    let mut max = hi.iter().copied().fold(hi[0], f64::max);
    for &v in rest {
        min = min.min(v);
        max = max.max(v);
    }
    (min, max)
}

/// The value of a channel that carries no vibration: `Some(0.0)` when every sample is 0 (a dead
/// sensor: its peak magnitude at most [`crate::limits::SAMPLE_PEAK_MIN`]), `Some(v)` when every
/// sample is `v` to within 1e-9 of the peak (a stuck sensor; rounding of a resampled constant
/// stays far inside this), `None` otherwise (and for an empty slice). The analysis refuses such
/// a channel, the fleet calls it `dead` or `flat`. `None` for fewer than 2 samples (too short
/// is another fault).
pub fn constant_value(x: &[f64]) -> Option<f64> {
    if x.len() < 2 {
        return None;
    }
    let (min, max) = extremes(x);
    constant_from_extremes(min, max)
}

/// Share of the samples at one extreme of a channel above which it counts as clipped (a
/// continuous signal reaches its extreme once or, quantised, a few times).
pub const CLIPPED_SHARE: f64 = 0.01;
/// Fewest samples at one extreme that count as clipped, however short the record.
pub const CLIPPED_MIN_SAMPLES: usize = 10;

/// Shortest stretch of one repeated value that counts as held, s (and at least
/// [`HELD_MIN_SAMPLES`]): a live sensor's noise changes its reading from sample to sample.
pub const HELD_MIN_S: f64 = 0.01;
/// Fewest samples in a stretch that counts as held, however high the rate.
pub const HELD_MIN_SAMPLES: usize = 10;
/// Share of a record's samples in held stretches from which the channel is named.
pub const HELD_SHARE_MIN: f64 = 0.01;

/// Share of a channel's samples that repeat a value (at a clipped extreme, or in held
/// stretches) from which it carries no vibration to identify: a dead or stuck sensor with
/// glitches (a spike, a step), or a logger that held its values through most of the record.
/// The analysis refuses such a channel as it refuses a constant one ([`constant_value`]); a
/// saturated sensor clips a few per cent of its samples, a logger's dropouts a few more.
pub const REPEATED_SHARE_MAX: f64 = 0.9;

/// The shortest held stretch at `fs_hz`, samples: [`HELD_MIN_S`], at least
/// [`HELD_MIN_SAMPLES`].
pub fn held_min_run(fs_hz: f64) -> usize {
    ((HELD_MIN_S * fs_hz).ceil() as usize).max(HELD_MIN_SAMPLES)
}

/// What a channel's samples say about its sensor, from one look at them ([`channel_health`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ChannelHealth {
    /// Number of samples.
    pub n: usize,
    /// The channel's value when it carries no vibration ([`constant_value`]).
    pub constant: Option<f64>,
    /// `(count, value)` when clipped ([`clipped`]).
    pub clipped: Option<(usize, f64)>,
    /// `(samples, stretches, longest)` of the stretches that hold one value: runs of at least
    /// `min_run` (>= 2) consecutive samples that are exactly equal, leaving out a clipped
    /// channel's runs at its extremes (clipping, reported as such). A live sensor's signal,
    /// dithered by its own noise, changes from sample to sample (the longest run in the shipped
    /// real recordings is 4 samples at 500 Hz); a data logger's dropout, filled with the last
    /// value or with 0, holds it.
    pub held: (usize, usize, usize),
}

impl ChannelHealth {
    /// Share of the samples in held stretches (0-1).
    pub fn held_share(&self) -> f64 {
        self.held.0 as f64 / self.n.max(1) as f64
    }

    /// Whether the held stretches cover [`HELD_SHARE_MIN`] of the samples or more.
    pub fn is_held(&self) -> bool {
        self.held.0 > 0 && self.held_share() >= HELD_SHARE_MIN
    }

    /// Share of the samples that repeat a value (0-1): those at the clipped extreme and those
    /// in held stretches (which leave the clipped extremes out: no sample counts twice).
    pub fn repeated_share(&self) -> f64 {
        (self.clipped.map_or(0, |c| c.0) + self.held.0) as f64 / self.n.max(1) as f64
    }

    /// Whether the channel repeats a value over [`REPEATED_SHARE_MAX`] of its samples or more:
    /// no vibration to identify, as a constant channel.
    pub fn is_mostly_repeated(&self) -> bool {
        self.constant.is_none() && self.repeated_share() >= REPEATED_SHARE_MAX
    }
}

/// [`constant_value`], [`clipped`] and the held stretches ([`ChannelHealth::held`]: runs of
/// `min_run` samples or more, see [`held_min_run`]) of one channel: what the analysis notes and
/// the fleet calls a sensor fault. The [`HealthScan`] of the whole channel, its extremes found
/// first: one rule for a channel in memory and one read in blocks.
pub fn channel_health(x: &[f64], min_run: usize) -> ChannelHealth {
    let (min, max) = if x.is_empty() {
        (0.0, 0.0)
    } else {
        extremes(x)
    };
    let mut scan = HealthScan::new(x.len(), min, max, min_run);
    scan.push(x);
    scan.finish()
}

/// [`constant_value`] from a channel's extremes (for a channel read in blocks): `Some(0.0)`
/// when its peak magnitude is at most [`crate::limits::SAMPLE_PEAK_MIN`], `Some(max)` when
/// `max - min` is within 1e-9 of the peak, else `None`.
pub fn constant_from_extremes(min: f64, max: f64) -> Option<f64> {
    let peak = max.abs().max(min.abs());
    if peak <= crate::limits::SAMPLE_PEAK_MIN {
        return Some(0.0);
    }
    (max - min <= 1e-9 * peak).then_some(max)
}

/// Whether a channel is clipped: more than [`CLIPPED_SHARE`] of its samples (and at least
/// [`CLIPPED_MIN_SAMPLES`]) at its largest or its smallest value, to within 1e-9 of its range,
/// in stretches of two or more consecutive samples (a saturated sensor or amplifier holds its
/// extreme; a pure tone whose period is a whole number of samples touches it once per period).
/// `Some((count, value))` of the extreme held more often, `count` every sample at it (held or
/// not); `None` for a channel that is not clipped or is constant ([`constant_value`]).
pub fn clipped(x: &[f64]) -> Option<(usize, f64)> {
    channel_health(x, HELD_MIN_SAMPLES).clipped
}

/// A seeded xorshift generator of `u64`s for the crate's tests (Marsaglia's 13/7/17 shifts).
#[cfg(test)]
pub(crate) fn xorshift(seed: u64) -> impl FnMut() -> u64 {
    let mut state = seed;
    move || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        state
    }
}

/// The rules of [`channel_health`] (constant, clipped, held) applied in one pass over a channel
/// whose extremes are known, so that a channel read in blocks is judged as a whole one is (the
/// first pass: `min`, `max` and the number of samples `n`). Feed every block in order with
/// [`HealthScan::push`]; [`HealthScan::finish`] gives the same for any cut into blocks (runs
/// are carried across them). `channel_health` is this scan of the whole channel.
#[derive(Clone, Debug)]
pub struct HealthScan {
    n: usize,
    min: f64,
    max: f64,
    hi: f64,
    lo: f64,
    min_run: usize,
    constant: Option<f64>,
    at: [usize; 2],
    held_at: [usize; 2],
    run_at: [usize; 2],
    /// The current run of one value: its value and length.
    run: Option<(f64, usize)>,
    /// `(samples, stretches, longest)` of held runs at another value than an extreme, and at
    /// an extreme (left out when the channel is clipped).
    held_other: (usize, usize, usize),
    held_extreme: (usize, usize, usize),
}

impl HealthScan {
    /// A scan of a channel of `n` samples between `min` and `max`, held runs of `min_run`
    /// samples or more ([`held_min_run`]).
    pub fn new(n: usize, min: f64, max: f64, min_run: usize) -> HealthScan {
        let tol = 1e-9 * (max - min);
        HealthScan {
            n,
            min,
            max,
            hi: max - tol,
            lo: min + tol,
            min_run: min_run.max(2),
            constant: if n < 2 {
                None
            } else {
                constant_from_extremes(min, max)
            },
            at: [0; 2],
            held_at: [0; 2],
            run_at: [0; 2],
            run: None,
            held_other: (0, 0, 0),
            held_extreme: (0, 0, 0),
        }
    }

    fn end_run(&mut self) {
        if let Some((v, len)) = self.run.take() {
            self.count_run(v, len);
        }
    }

    /// Counts a run of `len` samples of `v` that has ended, when it is long enough.
    fn count_run(&mut self, v: f64, len: usize) {
        if len >= self.min_run {
            let h = if v == self.min || v == self.max {
                &mut self.held_extreme
            } else {
                &mut self.held_other
            };
            h.0 += len;
            h.1 += 1;
            h.2 = h.2.max(len);
        }
    }

    fn end_extreme_run(&mut self, k: usize) {
        if self.run_at[k] >= 2 {
            self.held_at[k] += self.run_at[k];
        }
        self.run_at[k] = 0;
    }

    /// The next block of the channel's samples.
    pub fn push(&mut self, x: &[f64]) {
        if self.constant.is_some() || self.n < 2 {
            return;
        }
        // The current run in locals (NaN equals no sample: a first sample starts a run).
        let (mut value, mut len) = self.run.take().unwrap_or((f64::NAN, 0));
        // Most blocks of samples lie strictly between the extremes with no two neighbours
        // equal: such a block only ends the runs before it (the extremes' and the current one)
        // and starts a run of its last sample; its runs of one sample are never counted
        // (`min_run` >= 2). That is tested without a branch per sample; any other block is
        // taken sample by sample.
        const BLOCK: usize = 8;
        let mut blocks = x.chunks_exact(BLOCK);
        for block in blocks.by_ref() {
            let (hi, lo) = (self.hi, self.lo);
            let inside = block.iter().fold(true, |ok, &v| ok & (v < hi) & (v > lo));
            let distinct = block[1..]
                .iter()
                .zip(block)
                .fold(block[0] != value, |ok, (&v, &before)| ok & (v != before));
            let plain = inside & distinct;
            if plain {
                if self.run_at != [0, 0] {
                    self.end_extreme_run(0);
                    self.end_extreme_run(1);
                }
                self.count_run(value, len);
                (value, len) = (block[BLOCK - 1], 1);
            } else {
                for &v in block {
                    self.step(v, &mut value, &mut len);
                }
            }
        }
        for &v in blocks.remainder() {
            self.step(v, &mut value, &mut len);
        }
        self.run = (len > 0).then_some((value, len));
    }

    /// One sample `v` of [`HealthScan::push`], the current run (`value`, `len`) in the caller's
    /// locals.
    #[inline(always)]
    fn step(&mut self, v: f64, value: &mut f64, len: &mut usize) {
        // Most samples lie strictly between the extremes: one test, and the extremes' runs (if
        // any) end.
        if v < self.hi && v > self.lo {
            if self.run_at != [0, 0] {
                self.end_extreme_run(0);
                self.end_extreme_run(1);
            }
        } else {
            for (k, at) in [v >= self.hi, v <= self.lo].into_iter().enumerate() {
                if at {
                    self.at[k] += 1;
                    self.run_at[k] += 1;
                } else {
                    self.end_extreme_run(k);
                }
            }
        }
        if v == *value {
            *len += 1;
        } else {
            self.count_run(*value, *len);
            (*value, *len) = (v, 1);
        }
    }

    /// What [`channel_health`] gives for the channel fed.
    pub fn finish(mut self) -> ChannelHealth {
        let mut h = ChannelHealth {
            n: self.n,
            constant: self.constant,
            clipped: None,
            held: (0, 0, 0),
        };
        if self.n < 2 || h.constant.is_some() {
            return h;
        }
        self.end_run();
        self.end_extreme_run(0);
        self.end_extreme_run(1);
        let need = CLIPPED_MIN_SAMPLES.max((CLIPPED_SHARE * self.n as f64).ceil() as usize);
        if self.at[0].max(self.at[1]) >= need {
            let (held, count, value) = if self.held_at[0] >= self.held_at[1] {
                (self.held_at[0], self.at[0], self.max)
            } else {
                (self.held_at[1], self.at[1], self.min)
            };
            h.clipped = (held >= need).then_some((count, value));
        }
        let (o, e) = (self.held_other, self.held_extreme);
        h.held = if h.clipped.is_some() {
            o
        } else {
            (o.0 + e.0, o.1 + e.1, o.2.max(e.2))
        };
        h
    }
}

/// The jackknife standard deviation of an estimate from its leave-one-out values `theta`
/// (`m >= 2` of them): `sqrt((m - 1) / m * sum (theta_s - mean)^2)`. 0 for fewer than two.
/// SSI-cov's modes, the model update's parameters and the fleet's suspension scores use it.
pub fn jackknife_std(theta: &[f64]) -> f64 {
    let m = theta.len();
    if m < 2 {
        return 0.0;
    }
    let mean = theta.iter().sum::<f64>() / m as f64;
    let ss: f64 = theta.iter().map(|t| (t - mean) * (t - mean)).sum();
    ((m as f64 - 1.0) / m as f64 * ss).sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Oracle: stretches of a channel that hold one value: `(samples, stretches, longest)` over the runs of
    /// at least `min_run` (>= 2) consecutive samples that are exactly equal, skipping runs at
    /// `skip` (the extremes of a clipped channel, which [`clipped`] reports). A live sensor's
    /// signal, dithered by its own noise, changes from sample to sample (the longest run in the
    /// shipped real recordings is 4 samples at 500 Hz); a data logger's dropout, filled with the
    /// last value or with 0, holds it.
    fn held_runs(x: &[f64], min_run: usize, skip: &[f64]) -> (usize, usize, usize) {
        let min_run = min_run.max(2);
        let (mut samples, mut stretches, mut longest) = (0, 0, 0);
        let mut i = 0;
        while i < x.len() {
            let mut j = i + 1;
            while j < x.len() && x[j] == x[i] {
                j += 1;
            }
            let run = j - i;
            if run >= min_run && !skip.contains(&x[i]) {
                samples += run;
                stretches += 1;
                longest = longest.max(run);
            }
            i = j;
        }
        (samples, stretches, longest)
    }

    /// Oracle of the clipped rule, written from its definition ([`clipped`]): the samples at
    /// each extreme, those with a neighbour there too, judged by the held ones.
    fn clipped_by_definition(x: &[f64]) -> Option<(usize, f64)> {
        if x.len() < 2 {
            return None;
        }
        let min = x.iter().copied().fold(f64::INFINITY, f64::min);
        let max = x.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        if constant_value(x).is_some() {
            return None;
        }
        let tol = 1e-9 * (max - min);
        let need = CLIPPED_MIN_SAMPLES.max((CLIPPED_SHARE * x.len() as f64).ceil() as usize);
        let count = |at: &dyn Fn(f64) -> bool| {
            let all = x.iter().filter(|&&v| at(v)).count();
            let held = (0..x.len())
                .filter(|&i| {
                    at(x[i]) && ((i > 0 && at(x[i - 1])) || (i + 1 < x.len() && at(x[i + 1])))
                })
                .count();
            (held, all)
        };
        let (held_hi, at_hi) = count(&|v| v >= max - tol);
        let (held_lo, at_lo) = count(&|v| v <= min + tol);
        let (held, all, value) = if held_hi >= held_lo {
            (held_hi, at_hi, max)
        } else {
            (held_lo, at_lo, min)
        };
        (held >= need).then_some((all, value))
    }

    #[test]
    fn a_scan_in_blocks_is_the_scan_of_the_whole_and_each_rule() {
        // Channels that are live, clipped at either extreme or both, held (dropouts filled with
        // the last value or with an extreme), constant, dead, or of 0-3 samples, cut into blocks
        // at every split of a seeded generator: the scan equals `channel_health` of the whole, and
        // that equals each rule written out from its definition (the oracles above).
        let mut next = xorshift(0x9e37_79b9_7f4a_7c15);
        let mut kinds = [0usize; 3];
        for case in 0..400 {
            let n = match case % 10 {
                0 => (next() % 4) as usize,
                _ => 20 + (next() % 3000) as usize,
            };
            let mut x: Vec<f64> = (0..n)
                .map(|_| (next() % 2001) as f64 / 1000.0 - 1.0)
                .collect();
            match case % 7 {
                1 => x.iter_mut().for_each(|v| *v = v.clamp(-2.0, 0.8)),
                2 => x.iter_mut().for_each(|v| *v = v.clamp(-0.7, 0.7)),
                3 if n > 0 => {
                    let (a, len) = ((next() as usize) % n, (next() % 400) as usize);
                    let v = x[a];
                    x.iter_mut().skip(a).take(len).for_each(|s| *s = v);
                }
                4 => x.iter_mut().for_each(|v| *v = 0.25),
                5 => x.iter_mut().for_each(|v| *v = 0.0),
                6 if n > 0 => {
                    let top = x.iter().cloned().fold(f64::NEG_INFINITY, f64::max);
                    let (a, len) = ((next() as usize) % n, (next() % 200) as usize);
                    x.iter_mut().skip(a).take(len).for_each(|s| *s = top);
                }
                _ => {}
            }
            let min_run = 2 + (next() % 12) as usize;
            let whole = channel_health(&x, min_run);
            let (min, max) = if x.is_empty() {
                (f64::INFINITY, f64::NEG_INFINITY)
            } else {
                extremes(&x)
            };
            let mut scan = HealthScan::new(x.len(), min, max, min_run);
            let mut i = 0;
            while i < x.len() {
                let len = 1 + (next() % 700) as usize;
                let j = (i + len).min(x.len());
                scan.push(&x[i..j]);
                i = j;
            }
            assert_eq!(
                scan.finish(),
                whole,
                "case {case}: n {n}, min_run {min_run}"
            );
            // And the whole is each rule written from its definition.
            assert_eq!(whole.constant, constant_value(&x), "case {case}");
            assert_eq!(whole.clipped, clipped_by_definition(&x), "case {case}");
            let skip = match whole.clipped {
                Some(_) => vec![min, max],
                None => Vec::new(),
            };
            let held = if whole.constant.is_some() {
                (0, 0, 0)
            } else {
                held_runs(&x, min_run, &skip)
            };
            assert_eq!(whole.held, held, "case {case}");
            kinds[0] += usize::from(whole.constant.is_some());
            kinds[1] += usize::from(whole.clipped.is_some());
            kinds[2] += usize::from(whole.held.1 > 0);
        }
        // Every kind was there to compare: constant, clipped, held.
        assert!(kinds.iter().all(|&k| k >= 20), "{kinds:?}");
    }

    #[test]
    fn held_stretches_are_counted() {
        // 0, 1, 1, 1, 2, 0, 0, 0, 0, 3 with runs of 3 and 4.
        let x = [0.0, 1.0, 1.0, 1.0, 2.0, 0.0, 0.0, 0.0, 0.0, 3.0];
        assert_eq!(held_runs(&x, 3, &[]), (7, 2, 4));
        assert_eq!(held_runs(&x, 4, &[]), (4, 1, 4));
        assert_eq!(held_runs(&x, 5, &[]), (0, 0, 0));
        assert_eq!(held_runs(&x, 3, &[0.0]), (3, 1, 3));
        // A run at the end counts; min_run below 2 is 2.
        assert_eq!(held_runs(&[1.0, 2.0, 2.0], 0, &[]), (2, 1, 2));
        assert_eq!(held_runs(&[], 2, &[]), (0, 0, 0));
    }

    #[test]
    fn a_channel_held_at_an_extreme_is_clipped() {
        // A sine of 1000 samples cut at 0.9: about 29 % of its samples at each extreme.
        let sine: Vec<f64> = (0..1000)
            .map(|i| (2.0 * std::f64::consts::PI * i as f64 / 100.0).sin())
            .collect();
        assert_eq!(clipped(&sine), None);
        let cut: Vec<f64> = sine.iter().map(|v| v.clamp(-2.0, 0.9)).collect();
        let (n, value) = clipped(&cut).unwrap();
        assert_eq!(value, 0.9);
        assert_eq!(n, sine.iter().filter(|&&v| v >= 0.9).count());
        // Ten samples held at the top of 1000 (1 %) are clipped; nine are not; ten at the top
        // but never two in a row are a tone's peaks, not clipping.
        let mut x: Vec<f64> = (0..1000).map(|i| ((i * 37) % 101) as f64 / 200.0).collect();
        for v in x.iter_mut().skip(1).take(10) {
            *v = 1.0;
        }
        assert_eq!(clipped(&x), Some((10, 1.0)));
        x[10] = 0.4;
        assert_eq!(clipped(&x), None);
        let mut y: Vec<f64> = (0..1000).map(|i| ((i * 37) % 101) as f64 / 200.0).collect();
        for i in 0..10 {
            y[1 + 50 * i] = 1.0;
        }
        assert_eq!(clipped(&y), None);
        // Held ten times in a row as well: clipped, and every sample at the top is counted.
        for v in y.iter_mut().skip(700).take(10) {
            *v = 1.0;
        }
        assert_eq!(clipped(&y), Some((20, 1.0)));
        // A constant channel is not "clipped" (it is dead or stuck).
        assert_eq!(clipped(&[2.0; 50]), None);
    }

    #[test]
    fn extremes_in_lanes_are_the_fold() {
        assert_eq!(extremes(&[3.0]), (3.0, 3.0));
        assert_eq!(extremes(&[1.0, -2.0, 5.0, 0.0, 4.0, -7.0]), (-7.0, 5.0));
        for n in 1..40 {
            for shift in 0..n {
                // The extremes at every position, in the lanes and in the remainder.
                let x: Vec<f64> = (0..n)
                    .map(|i| (((i + shift) * 7) % n) as f64 - 3.0)
                    .collect();
                let want = x
                    .iter()
                    .fold((x[0], x[0]), |(a, b), &v| (a.min(v), b.max(v)));
                assert_eq!(extremes(&x), want, "n {n} shift {shift}");
            }
        }
    }

    #[test]
    fn a_channel_that_repeats_a_value_most_of_the_time_carries_no_vibration() {
        // The fault above: 12 clipped + 30 held of 1000 samples, 4.2 %: a live sensor.
        let mut x: Vec<f64> = (0..1000).map(|i| ((i * 37) % 101) as f64 / 200.0).collect();
        for v in x.iter_mut().skip(100).take(30) {
            *v = 0.25;
        }
        for v in x.iter_mut().skip(500).take(12) {
            *v = 1.0;
        }
        let h = channel_health(&x, 10);
        assert!((h.repeated_share() - 0.042).abs() < 1e-12);
        assert!(!h.is_mostly_repeated());
        // A dead sensor with one spike: 999 of 1000 samples at its lower extreme, 0.
        let mut spike = vec![0.0; 1000];
        spike[400] = 3.0;
        let h = channel_health(&spike, 10);
        assert_eq!(h.clipped, Some((999, 0.0)));
        assert!((h.repeated_share() - 0.999).abs() < 1e-12 && h.is_mostly_repeated());
        // Spikes both ways: 0 is no extreme, the zeros are held stretches (998 samples).
        spike[700] = -3.0;
        let h = channel_health(&spike, 10);
        assert_eq!(h.clipped, None);
        assert_eq!(h.held.0, 998);
        assert!(h.is_mostly_repeated());
        // At the bound: 900 of 1000 samples held, the rest varying.
        let mut edge: Vec<f64> = (0..1000).map(|i| ((i * 37) % 101) as f64).collect();
        edge.iter_mut().take(900).for_each(|v| *v = 50.5);
        let h = channel_health(&edge, 10);
        assert!((h.repeated_share() - 0.9).abs() < 1e-12 && h.is_mostly_repeated());
        edge[0] = 0.25;
        assert!(!channel_health(&edge, 10).is_mostly_repeated());
        // A constant channel is constant, not "mostly repeated".
        assert!(!channel_health(&[2.0; 50], 10).is_mostly_repeated());
    }

    #[test]
    fn one_look_at_a_channel_gives_each_fault() {
        // A channel with a dropout of 30 samples held at 0.25 and a top clipped at 1.0 over
        // 12 samples, at 1000 Hz (held runs of 10 samples or more count).
        let mut x: Vec<f64> = (0..1000).map(|i| ((i * 37) % 101) as f64 / 200.0).collect();
        for v in x.iter_mut().skip(100).take(30) {
            *v = 0.25;
        }
        for v in x.iter_mut().skip(500).take(12) {
            *v = 1.0;
        }
        let h = channel_health(&x, held_min_run(1000.0));
        assert_eq!(held_min_run(1000.0), 10);
        assert_eq!(held_min_run(20_000.0), 200);
        assert_eq!(h.constant, None);
        assert_eq!(h.clipped, Some((12, 1.0)));
        // The clipped top is clipping, not a held stretch.
        assert_eq!(h.held, (30, 1, 30));
        assert!((h.held_share() - 0.03).abs() < 1e-12 && h.is_held());
        let dead = channel_health(&[0.0; 40], 10);
        assert_eq!(
            (dead.constant, dead.clipped, dead.held),
            (Some(0.0), None, (0, 0, 0))
        );
        assert!(!dead.is_held());
        let short = channel_health(&[1.0], 10);
        assert_eq!((short.constant, short.clipped), (None, None));
        // The same as each rule alone, over seeded random channels with held and clipped parts.
        let mut state = 0x9E37_79B9_7F4A_7C15u64;
        let mut next = || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        for seed in 0..200 {
            let n = 20 + (next() * 2000.0) as usize;
            let mut y: Vec<f64> = (0..n).map(|_| (next() * 8.0).round() / 8.0 - 0.5).collect();
            if seed % 3 == 0 {
                let c = next() * 0.4;
                y.iter_mut().for_each(|v| *v = v.clamp(-0.5, c));
            }
            if seed % 5 == 0 {
                let at = (next() * n as f64) as usize;
                let v = y[at];
                y.iter_mut().skip(at).take(15).for_each(|s| *s = v);
            }
            let h = channel_health(&y, 4);
            assert_eq!(h.constant, constant_value(&y), "seed {seed}");
            assert_eq!(h.clipped, clipped_by_definition(&y), "seed {seed}");
            let skip = match h.clipped {
                Some(_) => vec![
                    y.iter().copied().fold(f64::INFINITY, f64::min),
                    y.iter().copied().fold(f64::NEG_INFINITY, f64::max),
                ],
                None => Vec::new(),
            };
            let expect = if h.constant.is_some() {
                (0, 0, 0)
            } else {
                held_runs(&y, 4, &skip)
            };
            assert_eq!(h.held, expect, "seed {seed}");
        }
    }

    #[test]
    fn a_dead_or_stuck_channel_has_a_constant_value_and_a_moving_one_none() {
        assert_eq!(constant_value(&[]), None);
        assert_eq!(constant_value(&[1.0]), None);
        assert_eq!(constant_value(&[0.0; 5]), Some(0.0));
        assert_eq!(constant_value(&[1e-70, -1e-70]), Some(0.0));
        assert_eq!(constant_value(&[9.81; 4]), Some(9.81));
        // Rounding-level wobble of a resampled constant is still constant...
        assert_eq!(
            constant_value(&[1.0, 1.0 + 1e-15, 1.0 - 1e-15]),
            Some(1.0 + 1e-15)
        );
        // ...a micro-g vibration on gravity is not, nor is one sign change.
        assert_eq!(constant_value(&[9.81, 9.81 + 1e-6, 9.81]), None);
        assert_eq!(constant_value(&[1.0, -1.0]), None);
        assert_eq!(constant_value(&[0.0, 0.0, 1e-3]), None);
    }

    #[test]
    fn by_hand() {
        assert_eq!(median(&[3.0, 1.0, 2.0]), 2.0);
        assert_eq!(median(&[4.0, 1.0, 2.0, 3.0]), 2.5);
        assert_eq!(median(&[-1.0]), -1.0);
        assert_eq!(median(&[5.0, 5.0, 1.0, 9.0]), 5.0);
        assert!(median(&[]).is_nan());
        assert_eq!(median_high_in_place(&mut [4.0, 1.0, 2.0, 3.0]), 3.0);
        assert_eq!(median_high_in_place(&mut [3.0, 1.0, 2.0]), 2.0);
        assert!(median_high_in_place(&mut []).is_nan());
    }

    /// Against the definition (sort, take the middle) on seeded random inputs of every length
    /// up to 64, with ties.
    #[test]
    fn equals_the_sorted_middle_over_seeds() {
        let mut state: u64 = 0x9E37_79B9_7F4A_7C15;
        for n in 1..=64usize {
            for _ in 0..20 {
                let v: Vec<f64> = (0..n)
                    .map(|_| {
                        state = state
                            .wrapping_mul(6_364_136_223_846_793_005)
                            .wrapping_add(1_442_695_040_888_963_407);
                        ((state >> 33) % 17) as f64 - 8.0
                    })
                    .collect();
                let mut s = v.clone();
                s.sort_by(f64::total_cmp);
                let want = if n % 2 == 1 {
                    s[n / 2]
                } else {
                    (s[n / 2 - 1] + s[n / 2]) / 2.0
                };
                assert_eq!(median(&v), want, "{v:?}");
                assert_eq!(median_high_in_place(&mut v.clone()), s[n / 2], "{v:?}");
            }
        }
    }

    #[test]
    fn dot_by_hand_and_against_one_running_sum() {
        // 1 + 2 + 3 + 4 + 5 * 2 = 20; the shorter length counts.
        assert_eq!(
            dot(&[1.0, 2.0, 3.0, 4.0, 5.0], &[1.0, 1.0, 1.0, 1.0, 2.0, 9.0]),
            20.0
        );
        assert_eq!(dot(&[], &[1.0]), 0.0);
        let mut state = 12345u64;
        for n in 0..40 {
            let mut next = || {
                state = state
                    .wrapping_mul(6364136223846793005)
                    .wrapping_add(1442695040888963407);
                (state >> 11) as f64 / (1u64 << 53) as f64 - 0.5
            };
            let x: Vec<f64> = (0..n).map(|_| next()).collect();
            let z: Vec<f64> = (0..n).map(|_| next()).collect();
            let naive: f64 = x.iter().zip(&z).map(|(a, b)| a * b).sum();
            let scale: f64 = x.iter().zip(&z).map(|(a, b)| (a * b).abs()).sum();
            assert!((dot(&x, &z) - naive).abs() <= 1e-15 * scale.max(1e-300) * n as f64);
        }
    }
}
