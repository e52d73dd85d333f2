//! Prints every mode SSI-cov finds in the benchmark's layout of records (`vibmode-bench gen DIR`
//! writes `DIR/ssi_8x7x512.f64`; `bench/run.py --ssi-demo` the demo's records at 50 Hz): raw
//! little-endian f64, record-major, each record channel-major. Block rows 20, orders 2..60
//! step 2. One line per mode: record, order, frequency (Hz), damping ratio, shape
//! (`[re, im]` per channel), all digits, so that two builds can be compared with
//! `tools/compare/ssi_modes.py`:
//!
//! `cargo run --release -p vibmode-ssi --example ssi_dump -- FILE.f64 [CHANNELS SAMPLES FS_HZ] > modes.txt`
//! (defaults 7 channels, 512 samples, 50 Hz)

use vibmode_ssi::{SsiCov, SsiParams};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    let path = args
        .get(1)
        .ok_or("usage: ssi_dump FILE.f64 [CHANNELS SAMPLES FS_HZ]")?;
    let n_ch: usize = args.get(2).map_or(Ok(7), |s| s.parse())?;
    let n: usize = args.get(3).map_or(Ok(512), |s| s.parse())?;
    let fs_hz: f64 = args.get(4).map_or(Ok(50.0), |s| s.parse())?;
    let bytes = std::fs::read(path)?;
    let data: Vec<f64> = bytes
        .chunks_exact(8)
        .map(|b| f64::from_le_bytes([b[0], b[1], b[2], b[3], b[4], b[5], b[6], b[7]]))
        .collect();
    let params = SsiParams {
        block_rows: 20,
        order_min: 2,
        order_max: 60,
        order_step: 2,
        ..SsiParams::default()
    };
    for (r, record) in data.chunks_exact(n_ch * n).enumerate() {
        let ch: Vec<&[f64]> = record.chunks_exact(n).collect();
        let res = SsiCov::new(&ch, fs_hz, &params)?.sweep(&params.orders())?;
        for o in res.orders {
            for m in o.modes {
                println!(
                    "{r} {} {:.17e} {:.17e} {:?}",
                    o.order, m.frequency_hz, m.damping_ratio, m.shape
                );
            }
        }
    }
    Ok(())
}
