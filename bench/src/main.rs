//! `vibmode-bench`: times vibmode's kernels on inputs shared with the Python peers.
//!
//! `vibmode-bench gen DIR` writes the inputs; `vibmode-bench run DIR [--quick]` prints a JSON
//! object `{case: {implementation: median_seconds}}`. Driven by `bench/run.py`, which times
//! scipy / numpy / pandas / statsmodels on the same files in the same run.

use anyhow::{bail, Context, Result};
use serde_json::{json, Map, Value};
use std::io::Write;
use std::path::Path;
use std::time::Instant;
use vibmode_signal::ResampleRecording;

const ARMA_ORDERS: [usize; 3] = [4, 10, 20];

/// Deterministic pseudo-random numbers (xorshift64*), so that inputs need no RNG crate.
struct Rng(u64);
impl Rng {
    fn uniform(&mut self) -> f64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        (self.0.wrapping_mul(0x2545F4914F6CDD1D) >> 11) as f64 / (1u64 << 53) as f64
    }
    fn normal(&mut self) -> f64 {
        let u1 = self.uniform().max(1e-300);
        let u2 = self.uniform();
        (-2.0 * u1.ln()).sqrt() * (2.0 * std::f64::consts::PI * u2).cos()
    }
}

fn write_f64(path: &Path, x: &[f64]) -> Result<()> {
    let mut b = Vec::with_capacity(x.len() * 8);
    for v in x {
        b.extend_from_slice(&v.to_le_bytes());
    }
    std::fs::write(path, b).with_context(|| format!("writing {}", path.display()))
}

/// A lightly damped ARMA(p,p) test signal: poles at several modes, MA zeros inside the circle.
fn arma_signal(p: usize, n: usize, rng: &mut Rng) -> Vec<f64> {
    // AR part: p/2 pole pairs spread over 0.5-40 Hz at fs = 200 Hz, radii 0.97-0.995.
    let fs = 200.0;
    let mut a = vec![1.0];
    for k in 0..p / 2 {
        let f = 0.5 + 39.5 * (k as f64 + 0.5) / (p / 2) as f64;
        let r: f64 = 0.97 + 0.025 * ((k * 7) % 5) as f64 / 4.0;
        let w = 2.0 * std::f64::consts::PI * f / fs;
        let quad = [1.0, -2.0 * r * w.cos(), r * r];
        let mut na = vec![0.0; a.len() + 2];
        for (i, ai) in a.iter().enumerate() {
            for (j, qj) in quad.iter().enumerate() {
                na[i + j] += ai * qj;
            }
        }
        a = na;
    }
    let c: Vec<f64> = (0..=p)
        .map(|i| {
            if i == 0 {
                1.0
            } else {
                0.5f64.powi(i as i32) * if i % 2 == 0 { 1.0 } else { -1.0 }
            }
        })
        .collect();
    let burn = 2000;
    let e: Vec<f64> = (0..n + burn).map(|_| rng.normal()).collect();
    let mut y = vec![0.0; n + burn];
    for t in 0..n + burn {
        let mut v = 0.0;
        for (j, cj) in c.iter().enumerate() {
            if t >= j {
                v += cj * e[t - j];
            }
        }
        for (j, aj) in a.iter().enumerate().skip(1) {
            if t >= j {
                v -= aj * y[t - j];
            }
        }
        y[t] = v;
    }
    y[burn..].to_vec()
}

/// The paper-size pole cloud: 8 records x 7 channels x orders 2..=60, each fit with the four
/// structural modes and two lines of the brief (jittered, present with probability 0.85) and
/// 0..=50 spurious poles (uniform 0.5-20 Hz, log-uniform damping 1e-3..0.6): about 100 000 poles,
/// clustered with the reference script's settings (fixed radius) by both implementations.
fn write_pole_cloud(dir: &Path, rng: &mut Rng) -> Result<()> {
    let modes = [
        (1.1, 0.25, 0.015),
        (1.5, 0.2, 0.015),
        (9.5, 0.15, 0.015),
        (11.0, 0.12, 0.015),
        (7.0, 0.001, 0.0005),
        (11.8, 0.001, 0.0005),
    ];
    let channels = ["FL", "FR", "RL", "RR", "sFR", "sRL", "sRR"];
    let orders: Vec<usize> = (2..=60).collect();
    let mut poles = Vec::new();
    for record in 0..8usize {
        for ch in channels {
            for &order in &orders {
                for &(f0, z0, fj) in &modes {
                    if rng.uniform() < 0.85 {
                        poles.push(json!({"frequency_hz": f0 * (1.0 + fj * rng.normal()),
                            "damping_ratio": z0 * (0.35 * rng.normal()).exp(),
                            "order": order, "record": record, "channel": ch}));
                    }
                }
                for _ in 0..(rng.uniform() * 51.0) as usize {
                    poles.push(json!({"frequency_hz": 0.5 + 19.5 * rng.uniform(),
                        "damping_ratio": 10f64.powf(-3.0 + rng.uniform() * (0.6f64.log10() + 3.0)),
                        "order": order, "record": record, "channel": ch}));
                }
            }
        }
    }
    let params = script_cluster_params();
    std::fs::write(
        dir.join("poles.json"),
        json!({"n_records": 8, "orders": orders, "params": params, "poles": poles}).to_string(),
    )?;
    Ok(())
}

/// SSI input of the demo's size: 8 records x 7 channels x 512 samples at 50 Hz (record-major,
/// then channel, then sample). Four modes of the brief (1.1, 1.5, 9.5, 11 Hz; damping 0.25, 0.2,
/// 0.15, 0.12), each a noise-driven AR(2), mixed into the 7 channels with fixed real shapes,
/// plus 10 % white noise.
fn write_ssi_input(dir: &Path, rng: &mut Rng) -> Result<()> {
    let fs = SSI_FS_HZ;
    let modes = [(1.1, 0.25), (1.5, 0.2), (9.5, 0.15), (11.0, 0.12)];
    let shapes = [
        [1.0, 0.9, 0.8, 0.7, 0.3, 0.2, 0.2],
        [1.0, -0.9, 0.8, -0.7, 0.3, -0.2, 0.2],
        [0.2, 0.3, -0.2, -0.3, 1.0, 0.8, -0.9],
        [0.1, -0.2, 0.3, -0.1, -0.8, 1.0, 0.9],
    ];
    let mut out = Vec::with_capacity(SSI_RECORDS * SSI_CHANNELS * SSI_SAMPLES);
    for _ in 0..SSI_RECORDS {
        let burn = 500;
        let mut q = vec![vec![0.0f64; SSI_SAMPLES + burn]; modes.len()];
        for (m, &(f, z)) in modes.iter().enumerate() {
            let w = 2.0 * std::f64::consts::PI * f;
            let r = (-z * w / fs).exp();
            let a1 = 2.0 * r * (w * (1.0f64 - z * z).sqrt() / fs).cos();
            let a2 = -r * r;
            for t in 2..SSI_SAMPLES + burn {
                q[m][t] = a1 * q[m][t - 1] + a2 * q[m][t - 2] + rng.normal();
            }
        }
        for shape in (0..SSI_CHANNELS).map(|c| shapes.map(|s| s[c])) {
            for t in burn..SSI_SAMPLES + burn {
                let v: f64 = q.iter().zip(&shape).map(|(qm, s)| s * qm[t]).sum();
                out.push(v + 0.1 * rng.normal());
            }
        }
    }
    write_f64(&dir.join("ssi_8x7x512.f64"), &out)
}

/// The SSI case: the demo's size, block rows 20, orders 2..=60 step 2.
const SSI_RECORDS: usize = 8;
const SSI_CHANNELS: usize = 7;
const SSI_SAMPLES: usize = 512;
const SSI_FS_HZ: f64 = 50.0;
const SSI_BLOCK_ROWS: usize = 20;
const SSI_ORDER_MAX: usize = 60;

/// The settings of tools/reference/modal.py (vibmode-modal 0.1's defaults, fixed radius).
fn script_cluster_params() -> vibmode_core::ClusterParams {
    vibmode_core::ClusterParams {
        freq_tol_per_damping: 0.0,
        min_order_share: 0.25,
        disturbance_freq_spread_max: 0.01,
        freq_min_hz: 0.1,
        freq_max_hz: Some(30.0),
        ..Default::default()
    }
}

fn gen(dir: &Path) -> Result<()> {
    std::fs::create_dir_all(dir)?;
    let mut rng = Rng(0x9E3779B97F4A7C15);
    let n = 204_800;
    // Welch input: noise plus two tones.
    let x: Vec<f64> = (0..n)
        .map(|i| {
            let t = i as f64 / 20000.0;
            (2.0 * std::f64::consts::PI * 9.0 * t).sin()
                + 0.5 * (2.0 * std::f64::consts::PI * 1.1 * t).sin()
                + rng.normal()
        })
        .collect();
    write_f64(&dir.join("welch.f64"), &x)?;
    // 7 channels at 20 kHz, interleaved, and the same as a CSV with a header.
    let raw: Vec<f64> = (0..n * 7).map(|_| rng.normal()).collect();
    write_f64(&dir.join("raw7.f64"), &raw)?;
    let mut csv = std::io::BufWriter::new(std::fs::File::create(dir.join("seven_channels.csv"))?);
    writeln!(csv, "FL,FR,RL,RR,FR_body,RL_body,RR_body")?;
    for row in raw.chunks(7) {
        let cells: Vec<String> = row.iter().map(|v| format!("{v:.6}")).collect();
        writeln!(csv, "{}", cells.join(","))?;
    }
    csv.flush()?;
    // The same samples as NumPy's `.npy` of shape (n, 7), C order: NumPy's header (version 1.0,
    // padded to 64 bytes) before the interleaved values; `bench/run.py` checks that `numpy.load`
    // gives back `raw`.
    let mut header = format!("{{'descr': '<f8', 'fortran_order': False, 'shape': ({n}, 7), }}");
    while (10 + header.len() + 1) % 64 != 0 {
        header.push(' ');
    }
    header.push('\n');
    let mut npy = b"\x93NUMPY\x01\x00".to_vec();
    npy.extend((header.len() as u16).to_le_bytes());
    npy.extend(header.as_bytes());
    npy.extend(raw.iter().flat_map(|v| v.to_le_bytes()));
    std::fs::write(dir.join("seven_channels.npy"), npy)?;
    for p in ARMA_ORDERS {
        write_f64(
            &dir.join(format!("arma{p}.f64")),
            &arma_signal(p, 2048, &mut rng),
        )?;
    }
    write_pole_cloud(dir, &mut rng)?;
    write_ssi_input(dir, &mut rng)?;
    std::fs::write(
        dir.join("meta.json"),
        json!({"arma_orders": ARMA_ORDERS, "n": n, "fs_hz": 20000.0,
            "ssi": {"records": SSI_RECORDS, "channels": SSI_CHANNELS, "samples": SSI_SAMPLES,
                "fs_hz": SSI_FS_HZ, "block_rows": SSI_BLOCK_ROWS, "order_max": SSI_ORDER_MAX,
                "order_step": 2}})
        .to_string(),
    )?;
    Ok(())
}

fn read_f64(path: &Path) -> Result<Vec<f64>> {
    let b = std::fs::read(path).with_context(|| format!("reading {}", path.display()))?;
    Ok(b.chunks_exact(8)
        .map(|c| f64::from_le_bytes([c[0], c[1], c[2], c[3], c[4], c[5], c[6], c[7]]))
        .collect())
}

fn median_time<F: FnMut() -> Result<()>>(repeat: usize, mut f: F) -> Result<f64> {
    let mut t = Vec::with_capacity(repeat);
    for _ in 0..repeat {
        let t0 = Instant::now();
        f()?;
        t.push(t0.elapsed().as_secs_f64());
    }
    Ok(vibmode_core::stats::median_high_in_place(&mut t))
}

/// The SSI inputs (file in the data folder, case name): the generated one (always written by
/// `gen`), then the demo's 8 records at 50 Hz (written by `bench/run.py --ssi-demo` only).
const SSI_CASES: [(&str, &str); 2] = [
    ("ssi_8x7x512.f64", "ssi_cov_8x7x512_br20_orders2-60"),
    (
        "ssi_demo50_8x7x512.f64",
        "ssi_cov_demo50_8x7x512_br20_orders2-60",
    ),
];

/// Median time of `vibmode_ssi::ssi_cov` over the 8 records of `ssi` (record-major, each
/// channel-major, 7 x 512 at 50 Hz), block rows 20, orders 2..=60 step 2; and the modes found.
fn time_ssi(ssi: &[f64], quick: bool) -> Result<(f64, usize)> {
    if ssi.len() != SSI_RECORDS * SSI_CHANNELS * SSI_SAMPLES {
        bail!(
            "SSI input has {} values, expected {SSI_RECORDS} x {SSI_CHANNELS} x {SSI_SAMPLES}",
            ssi.len()
        );
    }
    let ssi_params = vibmode_ssi::SsiParams {
        block_rows: SSI_BLOCK_ROWS,
        order_min: 2,
        order_max: SSI_ORDER_MAX,
        order_step: 2,
        reference_channels: None,
        pool_records: false,
        first_lag: 1,
    };
    let mut n_ssi_modes = 0;
    let t_ssi = median_time(if quick { 3 } else { 11 }, || {
        n_ssi_modes = 0;
        for record in ssi.chunks_exact(SSI_CHANNELS * SSI_SAMPLES) {
            let ch: Vec<&[f64]> = record.chunks_exact(SSI_SAMPLES).collect();
            let res = vibmode_ssi::ssi_cov(&ch, SSI_FS_HZ, &ssi_params)?;
            n_ssi_modes += res.orders.iter().map(|o| o.modes.len()).sum::<usize>();
        }
        Ok(())
    })?;
    Ok((t_ssi, n_ssi_modes))
}

fn run(dir: &Path, quick: bool) -> Result<Value> {
    let r = if quick { 3 } else { 15 };
    let mut out = Map::new();
    let x = read_f64(&dir.join("welch.f64"))?;
    for nperseg in [256usize, 4096] {
        let wp = vibmode_spectra::WelchParams {
            nperseg: Some(nperseg),
            ..Default::default()
        };
        let simple = median_time(r, || {
            vibmode_spectra::welch(&x, 20000.0, &wp)?;
            Ok(())
        })?;
        let mut plan = vibmode_spectra::WelchPlan::new(x.len(), 20000.0, &wp)?;
        let planned = median_time(r, || {
            plan.welch(&x)?;
            Ok(())
        })?;
        out.insert(
            format!("welch_204800_nperseg{nperseg}"),
            json!({"vibmode_spectra::welch": simple, "WelchPlan::welch (reused plan)": planned}),
        );
    }
    // Resampling 7 x 204 800 from 20 kHz to 200 Hz with the ideal filter.
    let raw = read_f64(&dir.join("raw7.f64"))?;
    let chans: Vec<Vec<f64>> = (0..7)
        .map(|c| raw.iter().skip(c).step_by(7).copied().collect())
        .collect();
    let rec = vibmode_signal::Recording {
        fs_hz: 20000.0,
        channels: chans
            .iter()
            .enumerate()
            .map(|(i, s)| vibmode_signal::Channel {
                name: format!("ch{i}"),
                unit: "m/s^2".into(),
                samples: s.clone(),
                placement: Default::default(),
            })
            .collect(),
        time_axis: None,
    };
    let rp = vibmode_signal::ResampleParams {
        fs_out_hz: 200.0,
        cutoff_hz: None,
        filter: true,
    };
    let t_res = median_time(r, || {
        rec.resample(&rp)?;
        Ok(())
    })?;
    out.insert(
        "resample_7x204800_20k_to_200".into(),
        json!({"Recording::resample (ideal DFT filter)": t_res}),
    );
    // Reading the CSV, and the same samples as a NumPy array.
    let opts = vibmode_signal::ReadOptions {
        fs_hz: Some(20000.0),
        ..Default::default()
    };
    for (case, file, repeat) in [
        (
            "read_csv_7x204800",
            "seven_channels.csv",
            if quick { 2 } else { 7 },
        ),
        (
            "read_npy_7x204800",
            "seven_channels.npy",
            if quick { 3 } else { 11 },
        ),
    ] {
        let path = dir.join(file);
        let t = median_time(repeat, || {
            let rec = vibmode_signal::read_path(&path, &opts)?;
            if rec.channels.len() != 7 || rec.len() != 204_800 {
                bail!("read {} channels x {} rows", rec.channels.len(), rec.len());
            }
            Ok(())
        })?;
        out.insert(case.into(), json!({"vibmode_signal::read_path": t}));
    }
    // What `vibmode info` computes: each channel's statistics and sensor checks, streamed.
    for (case, file) in [
        ("summarize_csv_7x204800", "seven_channels.csv"),
        ("summarize_npy_7x204800", "seven_channels.npy"),
    ] {
        let path = dir.join(file);
        let t = median_time(if quick { 3 } else { 11 }, || {
            let s = vibmode_signal::summarize(&path, &opts)?;
            if s.channels.len() != 7 || s.frames != 204_800 {
                bail!(
                    "summarised {} channels x {} frames",
                    s.channels.len(),
                    s.frames
                );
            }
            Ok(())
        })?;
        out.insert(
            case.into(),
            json!({"vibmode_signal::summarize (vibmode info)": t}),
        );
    }
    // Clustering the paper-size pole cloud.
    let cloud: Value = serde_json::from_str(&std::fs::read_to_string(dir.join("poles.json"))?)?;
    let poles: Vec<vibmode_core::PoleObservation> = serde_json::from_value(cloud["poles"].clone())?;
    let orders: Vec<usize> = serde_json::from_value(cloud["orders"].clone())?;
    let params = script_cluster_params();
    let mut n_modes = 0;
    let t_cl = median_time(if quick { 2 } else { 7 }, || {
        let a = vibmode_modal::analyse_poles(&poles, 8, &orders, &params)?;
        n_modes = a.modes.iter().filter(|m| m.is_invariant()).count();
        Ok(())
    })?;
    out.insert(
        "cluster_poles".into(),
        json!({"vibmode_modal::analyse_poles": t_cl, "_n_poles": poles.len(), "_invariant_modes": n_modes}),
    );
    // SSI-cov of 8 records x 7 channels x 512 samples, block rows 20, orders 2..=60 step 2: the
    // generated case, and the demo's records brought to 50 Hz when `bench/run.py --ssi-demo`
    // has written them.
    for (file, case) in SSI_CASES {
        let path = dir.join(file);
        if case != SSI_CASES[0].1 && !path.exists() {
            continue;
        }
        let (t_ssi, n_ssi_modes) = time_ssi(&read_f64(&path)?, quick)?;
        out.insert(
            case.into(),
            json!({"vibmode_ssi::ssi_cov": t_ssi, "_n_modes": n_ssi_modes}),
        );
    }
    // ARMA fits, quadratic criterion (as statsmodels), N = 2048.
    for p in ARMA_ORDERS {
        let y = read_f64(&dir.join(format!("arma{p}.f64")))?;
        let params = vibmode_ident::ArmaParams {
            robust: vibmode_ident::Robust::Off,
            ..Default::default()
        };
        let mut lambda = f64::NAN;
        let t = median_time(if quick { 3 } else { 11 }, || {
            let m = vibmode_ident::fit_arma(&y, p, p, &params)?;
            lambda = m.noise_variance;
            Ok(())
        })?;
        out.insert(
            format!("arma_{p}_{p}_n2048"),
            json!({"vibmode_ident::fit_arma (quadratic)": t, "_lambda_vibmode": lambda}),
        );
    }
    Ok(Value::Object(out))
}

fn main() -> Result<()> {
    let args: Vec<String> = std::env::args().collect();
    match args.get(1).map(String::as_str) {
        Some("gen") => gen(Path::new(
            args.get(2).context("usage: vibmode-bench gen DIR")?,
        )),
        Some("run") => {
            let dir = args
                .get(2)
                .context("usage: vibmode-bench run DIR [--quick]")?;
            let quick = args.iter().any(|a| a == "--quick");
            println!("{}", run(Path::new(dir), quick)?);
            Ok(())
        }
        _ => bail!("usage: vibmode-bench gen DIR | vibmode-bench run DIR [--quick]"),
    }
}
