//! Hand-checkable cases and seeded-random identity checks for the numeric helpers.

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use vibmode_report::axes::{
    auto_range, clip_segment, decimate_minmax, format_tick, log_ticks, nice_ticks, rescale_to,
};
use vibmode_report::Scale;

// ---------- hand cases ----------

#[test]
fn decimate_small_case_by_hand() {
    // 10 points on [0, 10) with 2 columns: column 0 holds i = 0..4, column 1 holds i = 5..9.
    let x: Vec<f64> = (0..10).map(f64::from).collect();
    let y = [0.0, 5.0, -3.0, 1.0, 2.0, 2.0, 2.0, 9.0, 2.0, 2.0];
    // Column 0: first 0, max 1, min 2, last 4. Column 1: first 5 (also min, first tie), max 7, last 9.
    assert_eq!(
        decimate_minmax(&x, &y, 0.0, 10.0, 2),
        vec![0, 1, 2, 4, 5, 7, 9]
    );
    // A NaN breaks the run and is kept.
    let y2 = [0.0, 5.0, f64::NAN, 1.0, 2.0, 2.0, 2.0, 9.0, 2.0, 2.0];
    assert_eq!(
        decimate_minmax(&x, &y2, 0.0, 10.0, 2),
        vec![0, 1, 2, 3, 4, 5, 7, 9]
    );
    // Degenerate arguments return everything.
    assert_eq!(decimate_minmax(&x, &y, 1.0, 1.0, 2).len(), 10);
    assert_eq!(decimate_minmax(&x, &y, 0.0, 10.0, 0).len(), 10);
    assert_eq!(decimate_minmax(&x, &y[..3], 0.0, 10.0, 2).len(), 10);
}

#[test]
fn clip_segment_by_hand() {
    let b = (0.0, 10.0, 0.0, 10.0);
    // Fully inside: unchanged.
    assert_eq!(
        clip_segment((1.0, 1.0), (2.0, 3.0), b),
        Some(((1.0, 1.0), (2.0, 3.0)))
    );
    // Horizontal line crossing the box: cut at x = 0 and x = 10.
    assert_eq!(
        clip_segment((-5.0, 5.0), (15.0, 5.0), b),
        Some(((0.0, 5.0), (10.0, 5.0)))
    );
    // Diagonal from (-10,-10) to (20,20): enters at (0,0), leaves at (10,10).
    assert_eq!(
        clip_segment((-10.0, -10.0), (20.0, 20.0), b),
        Some(((0.0, 0.0), (10.0, 10.0)))
    );
    // Entirely above the box.
    assert_eq!(clip_segment((0.0, 11.0), (10.0, 12.0), b), None);
    // Passing the corner outside.
    assert_eq!(clip_segment((-1.0, 9.0), (1.0, 12.0), b), None);
}

#[test]
fn nice_ticks_by_hand() {
    assert_eq!(
        nice_ticks(0.0, 10.0, 6),
        vec![0.0, 2.0, 4.0, 6.0, 8.0, 10.0]
    );
    assert_eq!(nice_ticks(-1.0, 1.0, 5), vec![-1.0, -0.5, 0.0, 0.5, 1.0]);
    assert_eq!(
        nice_ticks(0.0, 25.0, 6),
        vec![0.0, 5.0, 10.0, 15.0, 20.0, 25.0]
    );
    assert!(nice_ticks(1.0, 1.0, 5).is_empty());
    assert!(nice_ticks(f64::NAN, 1.0, 5).is_empty());
    // 0.1 + 0.2 style noise must not leak: ticks are exact multiples.
    let t = nice_ticks(0.0, 0.35, 4);
    assert_eq!(t, vec![0.0, 0.1, 0.2, 0.30000000000000004]);
    assert_eq!(format_tick(t[3]), "0.3");
}

#[test]
fn log_ticks_by_hand() {
    let (major, minor) = log_ticks(0.5, 2000.0, 10);
    assert_eq!(major, vec![1.0, 10.0, 100.0, 1000.0]);
    assert!(minor.contains(&0.6) && minor.contains(&2000.0) && minor.contains(&20.0));
    assert!(!minor.contains(&0.4));
    // 31 whole decades, at most 7 ticks: step ceil(31/7) = 5 decades.
    let (major, minor) = log_ticks(1e-30, 1.0, 7);
    assert_eq!(major, vec![1e-30, 1e-25, 1e-20, 1e-15, 1e-10, 1e-5, 1.0]);
    assert_eq!(minor.len(), 31 - 7);
    let (major, _) = log_ticks(1e-30, 1.0, 6);
    assert_eq!(
        major,
        vec![1e-30, 1e-20, 1e-10, 1.0],
        "ceil(31/6) = 6 rounds up to 10"
    );
    let (major, _) = log_ticks(1e-200, 1.0, 2);
    assert_eq!(
        major,
        vec![1e-200, 1.0],
        "ceil(201/2) = 101 rounds up to 200"
    );
    // Less than two decades: 1-2-5 series.
    let (major, minor) = log_ticks(0.013, 0.25, 8);
    assert_eq!(major, vec![0.02, 0.05, 0.1, 0.2]);
    assert!(minor.contains(&0.03) && minor.contains(&0.09));
    // Within one decade, too few 1-2-5 values: every mantissa.
    let (major, _) = log_ticks(2.5, 8.5, 10);
    assert_eq!(major, vec![3.0, 4.0, 5.0, 6.0, 7.0, 8.0]);
    assert_eq!(log_ticks(0.0, 1.0, 5), (vec![], vec![]));
}

#[test]
fn format_tick_by_hand() {
    assert_eq!(format_tick(0.0), "0");
    assert_eq!(format_tick(-0.0), "0");
    assert_eq!(format_tick(2.0), "2");
    assert_eq!(format_tick(-0.5), "-0.5");
    assert_eq!(format_tick(1234.5), "1234.5");
    assert_eq!(format_tick(0.001), "0.001");
    assert_eq!(format_tick(2.5e-5), "2.5e-5");
    assert_eq!(format_tick(1e-30), "1e-30");
    assert_eq!(format_tick(100000.0), "1e5");
    assert_eq!(format_tick(9.9999e6), "1e7");
    assert_eq!(format_tick(f64::NAN), "NaN");
    assert_eq!(format_tick(f64::NEG_INFINITY), "-inf");
}

#[test]
fn auto_range_by_hand() {
    assert_eq!(auto_range(&[0.0, 10.0], Scale::Linear), (-0.5, 10.5));
    assert_eq!(auto_range(&[], Scale::Linear), (0.0, 1.0));
    assert_eq!(auto_range(&[0.0, -1.0], Scale::Log), (1.0, 10.0));
    let (lo, hi) = auto_range(&[1.0, 1e4, -5.0, 0.0, f64::NAN], Scale::Log);
    assert!((lo - 10f64.powf(-0.2)).abs() < 1e-12 && (hi - 10f64.powf(4.2)).abs() < 1e-9);
    assert_eq!(
        rescale_to(&[1.0, 10.0, 100.0], Scale::Log, (0.0, 2.0)),
        vec![0.0, 1.0, 2.0]
    );
}

// ---------- seeded random identity checks ----------

#[test]
fn decimation_preserves_column_extremes_and_bounds_count() {
    let mut rng = ChaCha8Rng::seed_from_u64(11);
    for _ in 0..20 {
        let n = rng.gen_range(100..30_000);
        let ncol = rng.gen_range(1..600);
        let mut x: Vec<f64> = (0..n).map(|_| rng.gen_range(0.0..100.0)).collect();
        x.sort_by(f64::total_cmp);
        let y: Vec<f64> = (0..n)
            .map(|_| rng.gen_range(-1.0..1.0) * rng.gen_range(0.0..50.0))
            .collect();
        let (lo, hi) = (0.0, 100.0);
        let kept = decimate_minmax(&x, &y, lo, hi, ncol);
        assert!(
            kept.windows(2).all(|w| w[0] < w[1]),
            "indices sorted and unique"
        );
        assert!(
            kept.len() <= 4 * (ncol + 2),
            "{} > 4·{}",
            kept.len(),
            ncol + 2
        );
        assert_eq!(kept[0], 0);
        assert_eq!(*kept.last().unwrap(), n - 1);
        // Per column, the extremes of the kept points equal those of all points.
        let col = |v: f64| ((v - lo) / (hi - lo) * ncol as f64).floor() as i64;
        let mut all = std::collections::HashMap::<i64, (f64, f64)>::new();
        for i in 0..n {
            let e = all
                .entry(col(x[i]))
                .or_insert((f64::INFINITY, f64::NEG_INFINITY));
            *e = (e.0.min(y[i]), e.1.max(y[i]));
        }
        let mut sub = std::collections::HashMap::<i64, (f64, f64)>::new();
        for &i in &kept {
            let e = sub
                .entry(col(x[i]))
                .or_insert((f64::INFINITY, f64::NEG_INFINITY));
            *e = (e.0.min(y[i]), e.1.max(y[i]));
        }
        assert_eq!(all, sub);
    }
}

#[test]
fn clipped_segments_lie_in_box_and_on_the_original_line() {
    let mut rng = ChaCha8Rng::seed_from_u64(5);
    let b = (-1.0, 2.0, 0.5, 3.0);
    let inside = |p: (f64, f64)| {
        p.0 >= b.0 - 1e-9 && p.0 <= b.1 + 1e-9 && p.1 >= b.2 - 1e-9 && p.1 <= b.3 + 1e-9
    };
    let mut hits = 0;
    for _ in 0..5000 {
        let p0 = (rng.gen_range(-5.0..5.0), rng.gen_range(-5.0..5.0));
        let p1 = (rng.gen_range(-5.0..5.0), rng.gen_range(-5.0..5.0));
        let cross = |a: (f64, f64), c: (f64, f64)| {
            (p1.0 - p0.0) * (c.1 - a.1) - (p1.1 - p0.1) * (c.0 - a.0)
        };
        match clip_segment(p0, p1, b) {
            Some((a, c)) => {
                hits += 1;
                assert!(inside(a) && inside(c), "{a:?} {c:?}");
                assert!(
                    cross(p0, a).abs() < 1e-9 && cross(p0, c).abs() < 1e-9,
                    "collinear"
                );
                if inside(p0) {
                    assert_eq!(a, p0);
                }
                if inside(p1) {
                    assert_eq!(c, p1);
                }
            }
            None => {
                // No sample of the segment may fall inside the box.
                for k in 0..=200 {
                    let t = k as f64 / 200.0;
                    let p = (p0.0 + t * (p1.0 - p0.0), p0.1 + t * (p1.1 - p0.1));
                    assert!(
                        !(p.0 > b.0 + 1e-6
                            && p.0 < b.1 - 1e-6
                            && p.1 > b.2 + 1e-6
                            && p.1 < b.3 - 1e-6)
                    );
                }
            }
        }
    }
    assert!(hits > 500 && hits < 4900);
}

#[test]
fn random_nice_ticks_are_uniform_125_steps_inside_range() {
    let mut rng = ChaCha8Rng::seed_from_u64(3);
    for _ in 0..2000 {
        // Centres up to 1000 half-widths away (beyond that the tick differences lose digits).
        let w = 10f64.powf(rng.gen_range(-6.0..6.0));
        let c = rng.gen_range(-1.0..1.0) * w * 10f64.powf(rng.gen_range(0.0..3.0));
        let (lo, hi) = (c - w, c + w * rng.gen_range(0.01..2.0));
        let m = rng.gen_range(2..12);
        let t = nice_ticks(lo, hi, m);
        assert!(!t.is_empty() && t.len() <= m, "{lo} {hi} {m}: {t:?}");
        let step = if t.len() > 1 { t[1] - t[0] } else { continue };
        let e = step.log10().floor();
        let mant = (step / 10f64.powf(e) * 1e6).round() / 1e6;
        assert!([1.0, 2.0, 5.0, 10.0].contains(&mant), "step {step}");
        for w in t.windows(2) {
            assert!(((w[1] - w[0]) - step).abs() <= 1e-9 * step);
        }
        let tol = 1e-9 * step;
        assert!(t[0] >= lo - tol && *t.last().unwrap() <= hi + tol);
        // A finer 1-2-5 step would exceed max_ticks: the next smaller step fits more ticks than m.
        assert!(t[0] - step < lo + tol || *t.last().unwrap() + step > hi - tol);
    }
}

#[test]
fn rescale_maps_extremes_to_target_and_keeps_order() {
    let mut rng = ChaCha8Rng::seed_from_u64(9);
    for scale in [Scale::Linear, Scale::Log] {
        let v: Vec<f64> = (0..500)
            .map(|_| 10f64.powf(rng.gen_range(-10.0..3.0)))
            .collect();
        let r = rescale_to(&v, scale, (2.0, 30.0));
        let (imin, imax) = (0..v.len()).fold((0, 0), |(a, b), i| {
            (
                if v[i] < v[a] { i } else { a },
                if v[i] > v[b] { i } else { b },
            )
        });
        assert!((r[imin] - 2.0).abs() < 1e-12 && (r[imax] - 30.0).abs() < 1e-12);
        for i in 0..v.len() {
            for j in 0..v.len() {
                if v[i] < v[j] {
                    assert!(r[i] <= r[j]);
                }
            }
        }
    }
}
