//! Times `read_path` on one file: `cargo run --release -p vibmode-signal --example read_time -- FILE [FS_HZ] [REPEATS]`.
//! Prints the median and the minimum wall-clock time in ms.
use vibmode_signal::{read_path, ReadOptions};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    let path = std::path::PathBuf::from(
        args.get(1)
            .ok_or("usage: read_time FILE [FS_HZ] [REPEATS]")?,
    );
    let fs_hz = args.get(2).map(|s| s.parse::<f64>()).transpose()?;
    let reps = args
        .get(3)
        .map(|s| s.parse::<usize>())
        .transpose()?
        .unwrap_or(15);
    let opts = ReadOptions {
        fs_hz,
        ..Default::default()
    };
    let mut t = Vec::new();
    for _ in 0..reps {
        let t0 = std::time::Instant::now();
        let rec = read_path(&path, &opts)?;
        t.push(t0.elapsed().as_secs_f64() * 1e3);
        std::hint::black_box(rec);
    }
    t.sort_by(|a, b| a.total_cmp(b));
    println!(
        "read_path: median {:.1} ms, min {:.1} ms ({} runs)",
        t[t.len() / 2],
        t[0],
        reps
    );
    Ok(())
}
