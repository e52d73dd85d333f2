//! Times SSI-cov on the benchmark's input (`vibmode-bench gen DIR` writes
//! `DIR/ssi_8x7x512.f64`: 8 records x 7 channels x 512 samples at 50 Hz), block rows 20,
//! orders 2..60 step 2, `REPS` times over the 8 records, split into the plan (correlations,
//! Toeplitz, SVD, QR) and the orders (least squares, eigenpairs, shapes):
//!
//! `cargo run --release -p vibmode-ssi --example ssi_time -- DIR/ssi_8x7x512.f64 [REPS]`

use std::time::Instant;

use vibmode_ssi::{SsiCov, SsiParams};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    let path = args.get(1).ok_or("usage: ssi_time FILE.f64 [REPS]")?;
    let reps: usize = args.get(2).map_or(Ok(20), |s| s.parse())?;
    let bytes = std::fs::read(path)?;
    let data: Vec<f64> = bytes
        .chunks_exact(8)
        .map(|b| f64::from_le_bytes([b[0], b[1], b[2], b[3], b[4], b[5], b[6], b[7]]))
        .collect();
    let (n_ch, n) = (7, 512);
    let params = SsiParams {
        block_rows: 20,
        order_min: 2,
        order_max: 60,
        order_step: 2,
        ..SsiParams::default()
    };
    let orders = params.orders();
    let (mut t_plan, mut t_orders, mut n_modes) = (0.0, 0.0, 0);
    for _ in 0..reps {
        for record in data.chunks_exact(n_ch * n) {
            let ch: Vec<&[f64]> = record.chunks_exact(n).collect();
            let t0 = Instant::now();
            let plan = SsiCov::new(&ch, 50.0, &params)?;
            let t1 = Instant::now();
            let res = plan.sweep(&orders)?;
            t_plan += (t1 - t0).as_secs_f64();
            t_orders += t1.elapsed().as_secs_f64();
            n_modes += res.orders.iter().map(|o| o.modes.len()).sum::<usize>();
        }
    }
    let per = reps as f64;
    println!(
        "8 records: plan {:.4} s, orders {:.4} s, total {:.4} s; {} modes per pass",
        t_plan / per,
        t_orders / per,
        (t_plan + t_orders) / per,
        n_modes / reps
    );
    Ok(())
}
