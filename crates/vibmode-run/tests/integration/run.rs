//! The run entry point: the same records give the same results.json whether they come from
//! files (streamed, as `vibmode analyze` and Python's `analyze` of paths read them) or from
//! memory (as `vibmode demo` and Python's `analyze` of arrays give them); the output folder's
//! results.json is `to_json`; errors name the layer that failed.

use std::path::PathBuf;

use vibmode_analysis::{AnalysisConfig, RecordInput};
use vibmode_run::{Progress, Run, RunError, RunInput};
use vibmode_signal::ReadOptions;
use vibmode_vehicle::{SimParams, VehicleParams};

/// Three simulated records of the flexible city bus at 2 kHz, written as 32-bit float WAV
/// (exact samples) and kept in memory under the same names.
fn records(dir: &std::path::Path) -> (Vec<PathBuf>, Vec<RecordInput>) {
    let vehicle = VehicleParams::city_bus_flexible();
    let mut p = SimParams::demo(3, 7);
    p.fs_hz = 2000.0;
    let sim = vibmode_vehicle::simulate(&vehicle, &p).unwrap_or_else(|e| panic!("{e}"));
    let mut paths = Vec::new();
    let mut mem = Vec::new();
    for (i, r) in sim.records.iter().enumerate() {
        let path = dir.join(format!("rec{i}.f64"));
        vibmode_signal::write_path(&path, &r.recording).unwrap_or_else(|e| panic!("{e}"));
        // What the reader gives back (units and placements as the file keeps them).
        let back = vibmode_signal::read_path(&path, &ReadOptions::default())
            .unwrap_or_else(|e| panic!("{e}"));
        mem.push(RecordInput {
            name: vibmode_run::record_name(&path),
            recording: back,
        });
        paths.push(path);
    }
    (paths, mem)
}

/// The JSON paths where `a` and `b` differ (at most `max`).
fn differences(
    a: &serde_json::Value,
    b: &serde_json::Value,
    path: &str,
    out: &mut Vec<String>,
    max: usize,
) {
    use serde_json::Value;
    if out.len() >= max {
        return;
    }
    match (a, b) {
        (Value::Object(x), Value::Object(y)) => {
            for k in x.keys().chain(y.keys().filter(|k| !x.contains_key(*k))) {
                match (x.get(k), y.get(k)) {
                    (Some(u), Some(v)) => differences(u, v, &format!("{path}.{k}"), out, max),
                    _ => out.push(format!("{path}.{k}: only on one side")),
                }
            }
        }
        (Value::Array(x), Value::Array(y)) if x.len() == y.len() => {
            for (i, (u, v)) in x.iter().zip(y).enumerate() {
                differences(u, v, &format!("{path}[{i}]"), out, max);
            }
        }
        _ if a != b => {
            let short = |v: &Value| v.to_string().chars().take(80).collect::<String>();
            out.push(format!("{path}: {} vs {}", short(a), short(b)));
        }
        _ => {}
    }
}

fn without_timing(mut v: serde_json::Value) -> serde_json::Value {
    if let serde_json::Value::Object(m) = &mut v {
        m.remove("timing");
    }
    v
}

#[test]
fn files_and_memory_give_the_same_results_json() {
    let dir = tempfile::tempdir().unwrap_or_else(|e| panic!("{e}"));
    let (paths, mem) = records(dir.path());
    let run = Run::new(AnalysisConfig::default())
        .vehicle(VehicleParams::city_bus_flexible())
        .unwrap_or_else(|e| panic!("{e}"));
    let read = ReadOptions::default();
    let streamed = run
        .run(RunInput::files(&paths, &read, &[]), &Progress::none())
        .unwrap_or_else(|e| panic!("{e}"));
    let in_memory = run
        .run(RunInput::Records(mem), &Progress::none())
        .unwrap_or_else(|e| panic!("{e}"));
    let (a, b) = (
        without_timing(streamed.to_json().unwrap_or_else(|e| panic!("{e}"))),
        without_timing(in_memory.to_json().unwrap_or_else(|e| panic!("{e}"))),
    );
    assert!(
        a.get("model_update").is_some(),
        "a vehicle gives a model_update key"
    );
    let mut diff = Vec::new();
    differences(&a, &b, "", &mut diff, 10);
    assert!(
        diff.is_empty(),
        "streamed and in-memory results.json differ: {diff:#?}"
    );

    // The folder's results.json is to_json.
    let out = dir.path().join("out");
    std::fs::create_dir(&out).unwrap_or_else(|e| panic!("{e}"));
    streamed.write(&out, None).unwrap_or_else(|e| panic!("{e}"));
    // Compared as text: serde_json reads floats back only to within an ulp.
    let text = std::fs::read_to_string(out.join("results.json")).unwrap_or_else(|e| panic!("{e}"));
    let want = serde_json::to_string_pretty(&streamed.to_json().unwrap_or_else(|e| panic!("{e}")))
        .unwrap_or_else(|e| panic!("{e}"));
    assert!(text == want + "\n", "results.json is not to_json");
    for f in ["index.html", "modes.csv"] {
        assert!(out.join(f).is_file(), "{f} missing");
    }
}

#[test]
fn errors_name_the_layer_and_the_value() {
    let dir = tempfile::tempdir().unwrap_or_else(|e| panic!("{e}"));
    let missing = vec![dir.path().join("nope.csv")];
    let read = ReadOptions::default();
    let run = Run::new(AnalysisConfig::default());
    let err = run
        .run(RunInput::files(&missing, &read, &[]), &Progress::none())
        .err();
    let msg = err.as_ref().map(|e| e.to_string()).unwrap_or_default();
    assert!(
        matches!(err, Some(RunError::Analysis(_)) | Some(RunError::Signal(_))),
        "{err:?}"
    );
    assert!(msg.contains("nope.csv") && !msg.contains('\n'), "{msg}");
    // One list of windows per file.
    let (paths, _) = records(dir.path());
    let err = run
        .run(
            RunInput::Files {
                paths: &paths,
                read: &read,
                channels: &[],
                windows: Some(vec![Vec::new()]),
            },
            &Progress::none(),
        )
        .err();
    assert!(
        matches!(
            err,
            Some(RunError::WindowsMismatch {
                n_windows: 1,
                n_files: 3
            })
        ),
        "{err:?}"
    );
    // No records in memory.
    let err = run
        .run(RunInput::Records(Vec::new()), &Progress::none())
        .err();
    assert!(matches!(err, Some(RunError::Analysis(_))), "{err:?}");
}

/// A segmented run: one segmentation per recording in the output and in `segments.json`, its
/// summary among the notes, the records cut where it says (here consecutive: the same modes as
/// the unsegmented run); a GPS track with several recordings and a segmentation that leaves no
/// record are errors naming the value.
#[test]
fn segmented_runs_keep_their_segmentations() {
    use vibmode_run::Segmenting;
    use vibmode_segment::SegmentParams;
    let dir = tempfile::tempdir().unwrap_or_else(|e| panic!("{e}"));
    let (paths, _) = records(dir.path());
    let read = ReadOptions::default();
    let run = Run::new(AnalysisConfig::default());
    let plain = run
        .run(RunInput::files(&paths, &read, &[]), &Progress::none())
        .unwrap_or_else(|e| panic!("{e}"));
    assert!(plain.segments.is_empty() && plain.notes.is_empty());
    let consecutive = Segmenting::Consecutive {
        params: SegmentParams::default(),
    };
    let seg = run
        .run(
            RunInput::Segmented {
                paths: &paths,
                read: &read,
                channels: &[],
                segmenting: &consecutive,
            },
            &Progress::none(),
        )
        .unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(seg.segments.len(), 3);
    for (s, p) in seg.segments.iter().zip(&paths) {
        assert_eq!(s.records.len(), 1, "{}", s.summary());
        assert!(
            seg.notes.iter().any(|n| n == &s.summary()),
            "{:?}",
            seg.notes
        );
        assert!(s.source.contains(&*p.to_string_lossy()), "{}", s.source);
    }
    let freqs = |o: &vibmode_run::RunOutput| -> Vec<f64> {
        o.results
            .roles
            .iter()
            .flat_map(|r| r.invariant_modes.iter().map(|m| m.frequency_hz))
            .collect()
    };
    assert_eq!(freqs(&plain), freqs(&seg));
    let out = dir.path().join("out");
    std::fs::create_dir(&out).unwrap_or_else(|e| panic!("{e}"));
    seg.write(&out, None).unwrap_or_else(|e| panic!("{e}"));
    let text = std::fs::read_to_string(out.join("segments.json")).unwrap_or_else(|e| panic!("{e}"));
    let v: serde_json::Value = serde_json::from_str(&text).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(v.as_array().map(Vec::len), Some(3), "{text}");

    let gps = Segmenting::Gps {
        track: dir.path().join("track.gpx"),
        offset_s: 0.0,
        params: SegmentParams::default(),
    };
    let err = run
        .run(
            RunInput::Segmented {
                paths: &paths,
                read: &read,
                channels: &[],
                segmenting: &gps,
            },
            &Progress::none(),
        )
        .err();
    assert!(
        matches!(err, Some(RunError::GpsWithManyFiles { n_files: 3 })),
        "{err:?}"
    );
    // Every window below the stop threshold: no record left.
    let all_stops = Segmenting::Vibration {
        params: SegmentParams {
            stop_activity_ratio: 5.0,
            ..SegmentParams::default()
        },
    };
    let err = run
        .run(
            RunInput::Segmented {
                paths: &paths[..1],
                read: &read,
                channels: &[],
                segmenting: &all_stops,
            },
            &Progress::none(),
        )
        .err();
    let msg = err.as_ref().map(|e| e.to_string()).unwrap_or_default();
    assert!(
        matches!(err, Some(RunError::NoSteadyStretch { .. }))
            && msg.contains("rec0.f64")
            && !msg.contains('\n'),
        "{err:?}"
    );
}
