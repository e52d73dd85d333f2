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
    // Its two parts: reading the file, and parsing it from memory (all threads).
    let mut tr = Vec::new();
    let mut tp = Vec::new();
    for _ in 0..reps {
        let t0 = std::time::Instant::now();
        let bytes = std::fs::read(&path)?;
        tr.push(t0.elapsed().as_secs_f64() * 1e3);
        let t0 = std::time::Instant::now();
        let rec = vibmode_signal::read_delimited_bytes(&bytes, "file", &opts)?;
        tp.push(t0.elapsed().as_secs_f64() * 1e3);
        std::hint::black_box(rec);
    }
    tr.sort_by(|a, b| a.total_cmp(b));
    tp.sort_by(|a, b| a.total_cmp(b));
    println!(
        "  of which std::fs::read: median {:.1} ms; read_delimited_bytes: median {:.1} ms",
        tr[tr.len() / 2],
        tp[tp.len() / 2]
    );
    // The parser alone on one thread (file already in memory): CPU cost per cell.
    let bytes = std::fs::read(&path)?;
    let mut t1 = Vec::new();
    let mut cells = 0;
    for _ in 0..reps {
        let t0 = std::time::Instant::now();
        let mut r = vibmode_signal::DelimitedReader::new(bytes.as_slice(), "file")?;
        let b = r.read_all_parallel(1)?;
        t1.push(t0.elapsed().as_secs_f64() * 1e3);
        cells = b.map_or(0, |b| b.n_rows() * b.columns.len());
    }
    t1.sort_by(|a, b| a.total_cmp(b));
    println!(
        "parse only, 1 thread: median {:.1} ms, min {:.1} ms = {:.1} ns per cell ({} cells)",
        t1[t1.len() / 2],
        t1[0],
        t1[0] * 1e6 / cells as f64,
        cells
    );
    Ok(())
}
