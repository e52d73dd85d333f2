//! Profiling aid: the paper's hard setting (ideal 25 Hz low-pass, 200 Hz), ARMA(p,p) sweep.
//! `cargo run --release -p vibmode-ident --example hard_sweep -- [N] [pmax] [robust]`
use num_complex::Complex64;
use vibmode_ident::sim::{ar_from_modes, poly_mul, simulate_arma};
use vibmode_ident::{fit_arma, fit_arma_warm, ArmaParams, Robust};

fn ideal_lowpass(x: &[f64], fs_hz: f64, cutoff_hz: f64) -> Vec<f64> {
    let n = x.len();
    let mut planner = realfft::RealFftPlanner::<f64>::new();
    let fwd = planner.plan_fft_forward(n);
    let inv = planner.plan_fft_inverse(n);
    let mut input = x.to_vec();
    let mut spec = fwd.make_output_vec();
    fwd.process(&mut input, &mut spec).unwrap();
    for (k, v) in spec.iter_mut().enumerate() {
        if k as f64 * fs_hz / n as f64 > cutoff_hz {
            *v = Complex64::new(0.0, 0.0);
        }
    }
    spec[0].im = 0.0;
    let last = spec.len() - 1;
    spec[last].im = 0.0;
    let mut out = inv.make_output_vec();
    inv.process(&mut spec, &mut out).unwrap();
    out.iter().map(|v| v / n as f64).collect()
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let n: usize = args.get(1).and_then(|s| s.parse().ok()).unwrap_or(2048);
    let pmax: usize = args.get(2).and_then(|s| s.parse().ok()).unwrap_or(60);
    let robust = args.get(3).map(|s| s != "off").unwrap_or(true);
    let fs_raw = 1000.0;
    let truth = [(1.1, 0.08), (4.0, 0.1), (9.0, 0.04), (11.5, 0.03)];
    let a = ar_from_modes(&truth, fs_raw);
    let c = poly_mul(&[1.0, -1.9975, 0.9975 * 0.9975 + 1e-6], &[1.0, 0.3]);
    let mut raw = simulate_arma(&a, &c, 1.0, 5 * n, 21).unwrap();
    // Sensor noise: white, std = noise_rel x std of the signal (0 = none).
    let noise_rel: f64 = std::env::var("NOISE")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(0.0);
    if noise_rel > 0.0 {
        let sd = (raw.iter().map(|v| v * v).sum::<f64>() / raw.len() as f64).sqrt();
        let w = simulate_arma(&[1.0], &[1.0], 1.0, raw.len(), 99).unwrap();
        for (r, wi) in raw.iter_mut().zip(&w) {
            *r += noise_rel * sd * wi;
        }
    }
    let filtered = ideal_lowpass(&raw, fs_raw, 25.0);
    let mut y: Vec<f64> = filtered.iter().step_by(5).copied().collect();
    // DATA=file.f64 (interleaved little-endian f64, NCH channels) CH=k: use that channel instead.
    if let Ok(path) = std::env::var("DATA") {
        let nch: usize = std::env::var("NCH")
            .ok()
            .and_then(|s| s.parse().ok())
            .unwrap_or(7);
        let ch: usize = std::env::var("CH")
            .ok()
            .and_then(|s| s.parse().ok())
            .unwrap_or(0);
        let bytes = std::fs::read(path).unwrap();
        let all: Vec<f64> = bytes
            .chunks_exact(8)
            .map(|b| f64::from_le_bytes(b.try_into().unwrap()))
            .collect();
        y = all.iter().skip(ch).step_by(nch).copied().collect();
    }
    // DITHER=eps: add white noise of variance eps x mean square (relative floor).
    if let Some(eps) = std::env::var("DITHER")
        .ok()
        .and_then(|s| s.parse::<f64>().ok())
    {
        let m = y.iter().sum::<f64>() / y.len() as f64;
        let ms = y.iter().map(|v| (v - m) * (v - m)).sum::<f64>() / y.len() as f64;
        let w = simulate_arma(&[1.0], &[1.0], 1.0, y.len(), 7).unwrap();
        for (v, wi) in y.iter_mut().zip(&w) {
            *v += (eps * ms).sqrt() * wi;
        }
    }
    let mut params = ArmaParams::default();
    if !robust {
        params.robust = Robust::Off;
    }
    if let Some(f) = std::env::var("TOL").ok().and_then(|s| s.parse().ok()) {
        params.tol = f;
    }
    if let Some(f) = std::env::var("MAXIT").ok().and_then(|s| s.parse().ok()) {
        params.max_iter = f;
    }
    let t_all = std::time::Instant::now();
    let mut prev = None;
    let mut total_it = 0;
    for p in 2..=pmax {
        let t = std::time::Instant::now();
        let m = match &prev {
            Some(pm) => fit_arma_warm(&y, p, p, pm, &params),
            None => fit_arma(&y, p, p, &params),
        }
        .unwrap();
        let dt = t.elapsed().as_secs_f64() * 1e3;
        total_it += m.iterations;
        let ms = m.modes(200.0);
        let low: Vec<String> = ms
            .modes
            .iter()
            .filter(|x| x.frequency_hz < 25.0 && x.damping_ratio < 0.3)
            .map(|x| format!("{:.2}/{:.3}", x.frequency_hz, x.damping_ratio))
            .collect();
        println!(
            "p={p:2} {dt:8.1} ms it={:3} {:?} loss={:.4e} unstable={} low=[{}]",
            m.iterations,
            m.stop_reason,
            m.loss,
            ms.unstable_poles.len(),
            low.join(" ")
        );
        prev = Some(m);
    }
    println!(
        "total {:.2} s, {} iterations",
        t_all.elapsed().as_secs_f64(),
        total_it
    );
}
