//! `ingest_files` reads and analyses the files in parallel: the results keep the order of the
//! paths, the same bytes given twice are analysed once, a bad file anywhere stores nothing and
//! the error names the first bad file in the given order.
use crate::common;

use std::path::{Path, PathBuf};
use vibmode_fleet::{ingest_files, Condition, IngestLabels, Store};
use vibmode_signal::ReadOptions;
use vibmode_vehicle::{Disturbances, RoadClass, VehicleParams};

fn labels() -> IngestLabels<'static> {
    IngestLabels {
        vehicle: "bus-1",
        condition: Condition::Nominal,
        road: None,
    }
}

/// Five simulated records as CSV files in `dir`.
fn files(dir: &Path) -> Vec<PathBuf> {
    let recs = common::records(
        &VehicleParams::city_bus(),
        RoadClass::B,
        30.0,
        5,
        5,
        Disturbances::default(),
    );
    recs.iter()
        .enumerate()
        .map(|(i, r)| {
            let p = dir.join(format!("rec_{i}.csv"));
            vibmode_signal::write_path(&p, r).unwrap();
            p
        })
        .collect()
}

/// On pools of 1 to 4 threads: the files go in chunks of that many, so a repeat and a bad file
/// fall in the same chunk as the first copy or the good files before them, or in a later one.
#[test]
fn order_duplicates_and_the_first_error_in_order() {
    let dir = tempfile::tempdir().unwrap();
    let f = files(dir.path());
    for threads in 1..=4 {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        let run = dir.path().join(format!("t{threads}"));
        std::fs::create_dir(&run).unwrap();
        pool.install(|| ingest_in(&run, &f));
    }
}

fn ingest_in(dir: &Path, f: &[PathBuf]) {
    let cfg = common::config();
    let (mut store, _) = Store::init(&dir.join("f.db")).unwrap();
    store.set_config(&cfg).unwrap();
    // A bad file third and another last: the third is named, nothing is stored.
    let bad1 = dir.join("bad_1.csv");
    let bad2 = dir.join("bad_2.csv");
    std::fs::write(&bad1, "a,b\n1,x\n").unwrap();
    std::fs::write(&bad2, "nonsense").unwrap();
    let given: Vec<&Path> = vec![&f[0], &f[1], &bad1, &f[2], &bad2];
    let e = ingest_files(&mut store, &labels(), &given, &ReadOptions::default(), &cfg)
        .unwrap_err()
        .to_string();
    assert!(e.contains("bad_1.csv"), "{e}");
    assert!(
        store.vehicles().unwrap().is_empty(),
        "a failed ingest stored something"
    );
    // Good files, one given twice: one result per path, in the given order, the repeat marked
    // as already stored with the first one's record.
    let given: Vec<&Path> = vec![&f[3], &f[0], &f[4], &f[0], &f[1], &f[2]];
    let out = ingest_files(&mut store, &labels(), &given, &ReadOptions::default(), &cfg).unwrap();
    // Named by the path as given.
    let names: Vec<&str> = out.iter().map(|r| r.file.as_str()).collect();
    let want: Vec<String> = given.iter().map(|p| p.display().to_string()).collect();
    assert_eq!(names, want);
    assert!(names[0].ends_with("rec_3.csv"), "{}", names[0]);
    let flags: Vec<bool> = out.iter().map(|r| r.already_stored).collect();
    assert_eq!(flags, [false, false, false, true, false, false]);
    assert_eq!(out[1].record_id, out[3].record_id);
    let mut ids: Vec<i64> = out.iter().map(|r| r.record_id).collect();
    ids.sort_unstable();
    ids.dedup();
    assert_eq!(ids.len(), 5);
    // Each record's stored features are its own file's: the same as ingesting it alone.
    let (mut alone, _) = Store::init(&dir.join("g.db")).unwrap();
    alone.set_config(&cfg).unwrap();
    for (k, p) in given.iter().enumerate() {
        let one = ingest_files(&mut alone, &labels(), &[p], &ReadOptions::default(), &cfg)
            .unwrap()
            .remove(0);
        assert_eq!(
            serde_json::to_value(store.features(out[k].record_id).unwrap()).unwrap(),
            serde_json::to_value(alone.features(one.record_id).unwrap()).unwrap(),
            "{}",
            names[k]
        );
    }
}
