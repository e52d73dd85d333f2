//! Numeric helpers behind the figures: automatic ranges, tick positions, tick labels, peak-preserving
//! decimation, clipping and rescaling. They are public so that callers (and tests) can rely on
//! exactly what the renderer does.

use crate::model::Scale;

/// Fraction of the data span added on each side by [`auto_range`] (5 %; on log axes the span is
/// measured in decades).
pub const PAD_FRACTION: f64 = 0.05;

/// Largest magnitude drawn on a linear axis; beyond it values are skipped like NaN (so that
/// spans and paddings stay finite).
pub const MAX_LINEAR_ABS: f64 = 1e300;

/// Is `v` drawable on an axis of this scale (finite with `|v| <= 1e300` on linear axes; finite
/// and > 0 on log axes)?
pub fn is_valid(v: f64, scale: Scale) -> bool {
    match scale {
        Scale::Linear => v.is_finite() && v.abs() <= MAX_LINEAR_ABS,
        Scale::Log => v.is_finite() && v > 0.0,
    }
}

/// Axis coordinate of a data value: `v` (linear) or `log10(v)` (log). Caller checks [`is_valid`].
pub fn to_axis(v: f64, scale: Scale) -> f64 {
    match scale {
        Scale::Linear => v,
        Scale::Log => v.log10(),
    }
}

/// Inverse of [`to_axis`].
pub fn from_axis(t: f64, scale: Scale) -> f64 {
    match scale {
        Scale::Linear => t,
        Scale::Log => 10f64.powf(t),
    }
}

/// Automatic axis range `(lo, hi)` in data units for `values` (invalid values for the scale are
/// skipped).
///
/// * Linear: `[min - 5 % span, max + 5 % span]`; a single value `v` gives `v ± 0.1|v|`
///   (`±1` if `v == 0`).
/// * Log: the same in decades (`log10`), a single value gives `v / √10 .. v · √10`.
/// * No valid value: `(0, 1)` (linear) or `(1, 10)` (log).
pub fn auto_range(values: &[f64], scale: Scale) -> (f64, f64) {
    let mut lo = f64::INFINITY;
    let mut hi = f64::NEG_INFINITY;
    for &v in values {
        if is_valid(v, scale) {
            let t = to_axis(v, scale);
            lo = lo.min(t);
            hi = hi.max(t);
        }
    }
    let (tlo, thi) = padded_axis_range(lo, hi, scale);
    (from_axis(tlo, scale), from_axis(thi, scale))
}

/// Padding of an axis-space range `[lo, hi]` (infinite bounds mean "no data"), see [`auto_range`].
pub(crate) fn padded_axis_range(lo: f64, hi: f64, scale: Scale) -> (f64, f64) {
    if !(lo.is_finite() && hi.is_finite()) {
        return match scale {
            Scale::Linear => (0.0, 1.0),
            Scale::Log => (0.0, 1.0),
        };
    }
    let span = hi - lo;
    let tiny = 1e-12 * lo.abs().max(hi.abs());
    if span <= tiny {
        let mid = 0.5 * (lo + hi);
        let d = match scale {
            Scale::Linear => {
                if mid == 0.0 {
                    1.0
                } else {
                    0.1 * mid.abs()
                }
            }
            Scale::Log => 0.5,
        };
        return (mid - d, mid + d);
    }
    (lo - PAD_FRACTION * span, hi + PAD_FRACTION * span)
}

/// "Nice" linear tick positions in `[lo, hi]`: multiples of the smallest step `s ∈ {1, 2, 5}·10^k`
/// that yields at most `max_ticks` ticks (`max_ticks` is raised to at least 2). Returns an empty
/// vector if the bounds are not finite or `hi <= lo`.
pub fn nice_ticks(lo: f64, hi: f64, max_ticks: usize) -> Vec<f64> {
    let max_ticks = max_ticks.max(2);
    if !(lo.is_finite() && hi.is_finite()) || hi <= lo {
        return Vec::new();
    }
    let span = hi - lo;
    let eps = 1e-9;
    let k0 = (span / max_ticks as f64).log10().floor() as i32 - 1;
    for k in k0..k0 + 40 {
        for m in [1.0, 2.0, 5.0] {
            let s = m * 10f64.powi(k);
            let first = (lo / s - eps).ceil();
            let last = (hi / s + eps).floor();
            let count = last - first + 1.0;
            if count <= max_ticks as f64 {
                let n = count.max(0.0) as i64;
                return (0..n)
                    .map(|i| {
                        let v = (first + i as f64) * s;
                        if v.abs() < 1e-12 * s {
                            0.0
                        } else {
                            v
                        }
                    })
                    .collect();
            }
        }
    }
    Vec::new()
}

/// Tick positions (data units) for a log axis over `[lo, hi]` (both > 0): `(major, minor)`.
///
/// * At least two whole decades inside: majors at `10^d` for every `step`-th decade, where
///   `step` is the smallest of 1, 2, 3, 5, 10, 20, 25, 50, 100, ... that is at least
///   `ceil(decades / max_ticks)` (decades = number of whole decades inside); minors at `m·10^d`, m = 2..9, when `step == 1` and the
///   range spans at most 10 decades, otherwise at the skipped decades.
/// * Fewer: majors at the 1-2-5 values `{1, 2, 5}·10^d` inside the range if that gives 3 to
///   `max_ticks` ticks (minors at the other mantissas 3, 4, 6..9); else at every mantissa 1..9 if
///   that gives 2 to `max_ticks` ticks; else from [`nice_ticks`] on the raw values; no minors.
pub fn log_ticks(lo: f64, hi: f64, max_ticks: usize) -> (Vec<f64>, Vec<f64>) {
    let max_ticks = max_ticks.max(2);
    if !(lo.is_finite() && hi.is_finite()) || lo <= 0.0 || hi <= lo {
        return (Vec::new(), Vec::new());
    }
    let a = lo.log10();
    let b = hi.log10();
    let d0 = (a - 1e-9).ceil() as i64;
    let d1 = (b + 1e-9).floor() as i64;
    let n = d1 - d0 + 1;
    if n < 2 {
        // Less than two whole decades: try the 1-2-5 series, then every mantissa 1..9, then
        // plain linear ticks.
        let series = |mantissas: &[f64]| -> Vec<f64> {
            let mut v = Vec::new();
            for d in (d0 - 1)..=d1 {
                for &m in mantissas {
                    let t = mantissa_pow10(m, d);
                    if t >= lo * (1.0 - 1e-12) && t <= hi * (1.0 + 1e-12) {
                        v.push(t);
                    }
                }
            }
            v
        };
        let all: Vec<f64> = series(&[1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 9.0]);
        let one_two_five = series(&[1.0, 2.0, 5.0]);
        if one_two_five.len() >= 3 && one_two_five.len() <= max_ticks {
            let minor = all
                .into_iter()
                .filter(|t| !one_two_five.contains(t))
                .collect();
            return (one_two_five, minor);
        }
        if all.len() >= 2 && all.len() <= max_ticks {
            return (all, Vec::new());
        }
        let major = nice_ticks(lo, hi, max_ticks)
            .into_iter()
            .filter(|&v| v > 0.0)
            .collect();
        return (major, Vec::new());
    }
    let needed = (n as usize).div_ceil(max_ticks).max(1) as i64;
    let step = nice_decade_step(needed);
    let mut major = Vec::new();
    let mut minor = Vec::new();
    for d in d0..=d1 {
        if d.rem_euclid(step) == 0 {
            major.push(mantissa_pow10(1.0, d));
        } else if n <= 400 {
            minor.push(mantissa_pow10(1.0, d));
        }
    }
    if step == 1 && b - a <= 10.0 {
        for d in (d0 - 1)..=d1 {
            for m in 2..=9 {
                let v = mantissa_pow10(f64::from(m), d);
                if v >= lo * (1.0 - 1e-12) && v <= hi * (1.0 + 1e-12) {
                    minor.push(v);
                }
            }
        }
    }
    (major, minor)
}

/// Smallest decade step in 1, 2, 3, 5, 10, 20, 25, 50, 100, 200, 250, 500, ... that is ≥ `needed`.
fn nice_decade_step(needed: i64) -> i64 {
    for c in [1, 2, 3, 5] {
        if c >= needed {
            return c;
        }
    }
    let mut scale = 10i64;
    while scale < 1_000_000 {
        for c in [scale, 2 * scale, 5 * scale / 2, 5 * scale] {
            if c >= needed {
                return c;
            }
        }
        scale *= 10;
    }
    needed
}

/// `m · 10^d`, correctly rounded (so 6·10⁻¹ is exactly the double nearest 0.6).
fn mantissa_pow10(m: f64, d: i64) -> f64 {
    format!("{m}e{d}").parse().unwrap_or(f64::NAN)
}

/// Tick label text: plain decimal with up to 6 significant digits and no trailing zeros
/// (`0.30000000000000004` → `"0.3"`), scientific (`"2.5e-5"`, `"1e6"`) when `|v| < 1e-3` or
/// `|v| ≥ 1e5`. Non-finite values print as `"NaN"`, `"inf"`, `"-inf"`.
pub fn format_tick(v: f64) -> String {
    if v.is_nan() {
        return "NaN".into();
    }
    if v.is_infinite() {
        return if v > 0.0 { "inf".into() } else { "-inf".into() };
    }
    if v == 0.0 {
        return "0".into();
    }
    let mag = v.abs().log10().floor() as i32;
    if !(-3..5).contains(&mag) {
        let mut mant = v / 10f64.powi(mag);
        let mut exp = mag;
        // Round the mantissa to 3 decimals; renormalise 9.9996 → 10 → 1e(exp+1).
        mant = (mant * 1000.0).round() / 1000.0;
        if mant.abs() >= 10.0 {
            mant /= 10.0;
            exp += 1;
        }
        let m = trim_zeros(format!("{mant:.3}"));
        return format!("{m}e{exp}");
    }
    let prec = (5 - mag).clamp(0, 9) as usize;
    let s = trim_zeros(format!("{v:.prec$}"));
    if s == "-0" {
        "0".into()
    } else {
        s
    }
}

fn trim_zeros(s: String) -> String {
    if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        s
    }
}

/// Pixel column of `x` for [`decimate_minmax`]: `floor((x - lo) / (hi - lo) · n)`, clamped to
/// `[-1, n]` (everything left/right of the range shares one column). Caller ensures hi > lo.
fn column_of(x: f64, lo: f64, hi: f64, n: usize) -> i64 {
    let c = ((x - lo) / (hi - lo) * n as f64).floor();
    c.clamp(-1.0, n as f64) as i64
}

/// Peak-preserving decimation of a polyline for drawing ("M4": min/max per pixel column).
///
/// The x range `[x_lo, x_hi]` is divided into `n_columns` equal columns. For every run of
/// *consecutive* points that fall into the same column, the first, last, lowest-y and highest-y
/// points are kept (first occurrence on ties). Points with a non-finite x or y are always kept
/// (they break the line and form their own run). Returns the kept indices in increasing order;
/// at most `4 · (n_columns + 2)` for x sorted, so the drawn shape and all peaks are preserved.
/// If `x_hi <= x_lo`, bounds are not finite, `n_columns == 0` or lengths differ, all indices are
/// returned.
pub fn decimate_minmax(x: &[f64], y: &[f64], x_lo: f64, x_hi: f64, n_columns: usize) -> Vec<usize> {
    let n = x.len();
    if n_columns == 0 || y.len() != n || !(x_lo.is_finite() && x_hi.is_finite()) || x_hi <= x_lo {
        return (0..n).collect();
    }
    let mut keep = Vec::with_capacity(n.min(4 * (n_columns + 2)));
    let mut i = 0;
    while i < n {
        if !(x[i].is_finite() && y[i].is_finite()) {
            keep.push(i);
            i += 1;
            continue;
        }
        let col = column_of(x[i], x_lo, x_hi, n_columns);
        let start = i;
        let (mut imin, mut imax) = (i, i);
        let mut j = i + 1;
        while j < n
            && x[j].is_finite()
            && y[j].is_finite()
            && column_of(x[j], x_lo, x_hi, n_columns) == col
        {
            if y[j] < y[imin] {
                imin = j;
            }
            if y[j] > y[imax] {
                imax = j;
            }
            j += 1;
        }
        let last = j - 1;
        let mut run = [start, imin, imax, last];
        run.sort_unstable();
        for (k, &idx) in run.iter().enumerate() {
            if k == 0 || idx != run[k - 1] {
                keep.push(idx);
            }
        }
        i = j;
    }
    keep
}

/// Clip the segment `p0 → p1` to the box `[x_lo, x_hi] × [y_lo, y_hi]` (Liang–Barsky).
/// Returns the visible part, or `None` if the segment misses the box. Coordinates must be finite.
pub fn clip_segment(
    p0: (f64, f64),
    p1: (f64, f64),
    (x_lo, x_hi, y_lo, y_hi): (f64, f64, f64, f64),
) -> Option<((f64, f64), (f64, f64))> {
    let dx = p1.0 - p0.0;
    let dy = p1.1 - p0.1;
    let mut t0 = 0.0f64;
    let mut t1 = 1.0f64;
    for (p, q) in [
        (-dx, p0.0 - x_lo),
        (dx, x_hi - p0.0),
        (-dy, p0.1 - y_lo),
        (dy, y_hi - p0.1),
    ] {
        if p == 0.0 {
            if q < 0.0 {
                return None;
            }
        } else {
            let r = q / p;
            if p < 0.0 {
                if r > t1 {
                    return None;
                }
                t0 = t0.max(r);
            } else {
                if r < t0 {
                    return None;
                }
                t1 = t1.min(r);
            }
        }
    }
    let a = if t0 > 0.0 {
        (p0.0 + t0 * dx, p0.1 + t0 * dy)
    } else {
        p0
    };
    let b = if t1 < 1.0 {
        (p0.0 + t1 * dx, p0.1 + t1 * dy)
    } else {
        p1
    };
    Some((a, b))
}

/// Clip a polyline (axis coordinates; `None` = break) to a box, returning the visible pieces,
/// each with at least two points.
pub(crate) fn clip_polyline(
    pts: &[Option<(f64, f64)>],
    bounds: (f64, f64, f64, f64),
) -> Vec<Vec<(f64, f64)>> {
    let mut out = Vec::new();
    let mut cur: Vec<(f64, f64)> = Vec::new();
    for w in pts.windows(2) {
        match (w[0], w[1]) {
            (Some(a), Some(b)) => match clip_segment(a, b, bounds) {
                Some((c, d)) => {
                    if cur.last() != Some(&c) {
                        if cur.len() >= 2 {
                            out.push(std::mem::take(&mut cur));
                        }
                        cur.clear();
                        cur.push(c);
                    }
                    cur.push(d);
                }
                None => {
                    if cur.len() >= 2 {
                        out.push(std::mem::take(&mut cur));
                    }
                    cur.clear();
                }
            },
            _ => {
                if cur.len() >= 2 {
                    out.push(std::mem::take(&mut cur));
                }
                cur.clear();
            }
        }
    }
    if cur.len() >= 2 {
        out.push(cur);
    }
    out
}

/// Map `values` affinely onto `target = (lo, hi)` (data units of the destination axis), e.g. to
/// draw a faint PSD behind a stabilisation diagram whose y axis is the model order.
///
/// With `scale == Scale::Log` the mapping is affine in `log10(value)` (so a PSD spanning decades
/// keeps its shape); the smallest valid value goes to `lo` and the largest to `hi`. Invalid
/// values (NaN/Inf, and ≤ 0 for `Log`) become NaN, which the renderer skips. If all valid values
/// are equal they map to the middle of the target.
pub fn rescale_to(values: &[f64], scale: Scale, target: (f64, f64)) -> Vec<f64> {
    let mut lo = f64::INFINITY;
    let mut hi = f64::NEG_INFINITY;
    for &v in values {
        if is_valid(v, scale) {
            let t = to_axis(v, scale);
            lo = lo.min(t);
            hi = hi.max(t);
        }
    }
    values
        .iter()
        .map(|&v| {
            if !is_valid(v, scale) {
                return f64::NAN;
            }
            let t = to_axis(v, scale);
            if hi > lo {
                target.0 + (t - lo) / (hi - lo) * (target.1 - target.0)
            } else {
                0.5 * (target.0 + target.1)
            }
        })
        .collect()
}
