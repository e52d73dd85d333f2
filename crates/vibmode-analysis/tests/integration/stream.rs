//! The streamed analysis (records read, cut and pre-processed as they arrive) gives the same
//! results as the analysis of the recording held in memory.

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use vibmode_analysis::{
    analyze, analyze_source, cut_records, AnalysisConfig, ChainedRecords, RecordSource,
    StreamRecords, SweepIdentifier,
};
use vibmode_signal::{open_stream, write_path, Channel, ReadOptions, Recording};

/// A two-channel recording: AR(2) resonances at 2 and 6 Hz driven by white noise, at 500 Hz.
fn recording(seed: u64, seconds: f64) -> Recording {
    let fs = 500.0;
    let n = (fs * seconds) as usize;
    let mut r = ChaCha8Rng::seed_from_u64(seed);
    let chans = [(2.0, 0.05), (6.0, 0.03)]
        .iter()
        .enumerate()
        .map(|(c, &(f, z))| {
            let w = 2.0 * std::f64::consts::PI * f / fs;
            let rad = (-z * w).exp();
            let (a1, a2) = (2.0 * rad * w.cos(), -rad * rad);
            let (mut y1, mut y2) = (0.0, 0.0);
            let samples = (0..n)
                .map(|_| {
                    let y = a1 * y1 + a2 * y2 + r.gen_range(-1.0..1.0);
                    y2 = y1;
                    y1 = y;
                    y
                })
                .collect();
            Channel::new(format!("c{c}"), "m/s^2".to_string(), samples)
        })
        .collect();
    Recording {
        fs_hz: fs,
        channels: chans,
        time_axis: None,
    }
}

#[test]
fn streamed_and_in_memory_analyses_agree_over_seeds() {
    let dir = tempfile::tempdir().unwrap();
    let mut cfg = AnalysisConfig::default();
    cfg.sweep.order_max = 8;
    let id = SweepIdentifier {
        sweep: cfg.sweep.clone(),
        poles: cfg.poles.clone(),
    };
    for seed in 0..3u64 {
        let rec = recording(seed, 33.0 + seed as f64 * 5.0);
        let p = dir.path().join(format!("r{seed}.f64"));
        write_path(&p, &rec).unwrap();
        let mem = analyze(
            &cut_records("r", &rec, cfg.record_length_s),
            &cfg,
            &[],
            &|_, _| {},
        )
        .unwrap();
        let mut src = ChainedRecords::new(1, |_| {
            Ok(StreamRecords::cut(
                "r",
                open_stream(&p, &ReadOptions::default())?,
                cfg.record_length_s,
            ))
        });
        let (st, first) = analyze_source(&mut src, &cfg, &id, &[], &|_| {}, &|_, _| {}).unwrap();
        assert_eq!(first.record.recording.len(), 5120);
        // the first record at the analysis rate, as the in-memory analysis pre-processes it
        let pre = vibmode_signal::preprocess(&first.record.recording, &cfg.preprocess).unwrap();
        assert_eq!(first.prepared, pre);
        assert_eq!(st.records.len(), mem.records.len());
        for (a, b) in st.records.iter().zip(&mem.records) {
            assert_eq!(a.name, b.name);
            assert_eq!(a.n_samples, b.n_samples);
            assert_eq!(a.activity_rms, b.activity_rms);
        }
        let js = |r: &vibmode_analysis::AnalysisResults| {
            serde_json::to_string(&(&r.channels, &r.roles)).unwrap()
        };
        assert_eq!(js(&st), js(&mem), "seed {seed}");
        // Each streamed record knows where it starts.
        let starts: Vec<f64> = st
            .records
            .iter()
            .map(|r| r.segment.as_ref().unwrap().start_s)
            .collect();
        assert_eq!(starts[1], 10.24);
    }
}

#[test]
fn a_short_file_is_one_record_and_channels_must_agree() {
    let dir = tempfile::tempdir().unwrap();
    let rec = recording(9, 15.0);
    let p = dir.path().join("short.f32");
    write_path(&p, &rec).unwrap();
    let mut s = StreamRecords::cut(
        "short",
        open_stream(&p, &ReadOptions::default()).unwrap(),
        10.24,
    );
    let one = s.next_record().unwrap().unwrap();
    assert_eq!(one.recording.len(), 7500);
    assert!(s.next_record().is_none());
    // A second file with other channels is refused, naming both.
    let mut other = recording(10, 25.0);
    other.channels[1].name = "zz".into();
    let q = dir.path().join("other.f32");
    write_path(&q, &other).unwrap();
    let files = [p.clone(), q.clone()];
    let cfg = AnalysisConfig::default();
    let id = SweepIdentifier {
        sweep: cfg.sweep.clone(),
        poles: cfg.poles.clone(),
    };
    let mut src = ChainedRecords::new(2, |i| {
        Ok(StreamRecords::cut(
            "f",
            open_stream(&files[i], &ReadOptions::default())?,
            10.24,
        ))
    });
    let e = analyze_source(&mut src, &cfg, &id, &[], &|_| {}, &|_, _| {})
        .unwrap_err()
        .to_string();
    assert!(e.contains("zz") && e.contains("c1"), "{e}");
}

/// Four channels with roles (two unsprung, front and rear of one side: the body stage runs;
/// two sprung: both role pools are clustered) and a line at 9 Hz on every channel (a track on
/// the unsprung ones): AR(2) resonances driven by white noise, at 500 Hz, quiet (a stop)
/// during the third record.
fn recording_with_roles(seed: u64, seconds: f64) -> Recording {
    let fs = 500.0;
    let n = (fs * seconds) as usize;
    let mut r = ChaCha8Rng::seed_from_u64(seed);
    let names = ["FL_unsprung", "RL_unsprung", "FR_sprung", "RL_sprung"];
    let modes = [(1.3, 0.15), (1.3, 0.15), (8.0, 0.1), (8.0, 0.1)];
    let stop = (2.0 * 10.24 * fs) as usize..(3.0 * 10.24 * fs) as usize;
    let chans = names
        .iter()
        .zip(modes)
        .enumerate()
        .map(|(c, (name, (f, z)))| {
            let w = 2.0 * std::f64::consts::PI * f / fs;
            let rad = (-z * w).exp();
            let (a1, a2) = (2.0 * rad * w.cos(), -rad * rad);
            let (mut y1, mut y2) = (0.0, 0.0);
            let samples = (0..n)
                .map(|k| {
                    let gain = if stop.contains(&k) { 0.01 } else { 1.0 };
                    let y = a1 * y1 + a2 * y2 + gain * r.gen_range(-1.0..1.0);
                    y2 = y1;
                    y1 = y;
                    let t = k as f64 / fs;
                    y + 3.0 * (2.0 * std::f64::consts::PI * 9.0 * t + c as f64).sin()
                })
                .collect();
            Channel::new(name.to_string(), "m/s^2".to_string(), samples)
        })
        .collect();
    Recording {
        fs_hz: fs,
        channels: chans,
        time_axis: None,
    }
}

#[test]
fn streamed_analysis_is_the_same_on_one_thread_and_on_two() {
    let dir = tempfile::tempdir().unwrap();
    let mut cfg = AnalysisConfig::default();
    cfg.sweep.order_max = 8;
    let id = SweepIdentifier {
        sweep: cfg.sweep.clone(),
        poles: cfg.poles.clone(),
    };
    let rec = recording_with_roles(5, 72.0);
    let p = dir.path().join("roles.f32");
    write_path(&p, &rec).unwrap();
    let run = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| {
            let mut src = ChainedRecords::new(1, |_| {
                Ok(StreamRecords::cut(
                    "roles",
                    open_stream(&p, &ReadOptions::default())?,
                    cfg.record_length_s,
                ))
            });
            let (mut r, _) = analyze_source(&mut src, &cfg, &id, &[], &|_| {}, &|_, _| {}).unwrap();
            r.timing.elapsed_s = 0.0;
            r
        })
    };
    let one = run(1);
    let two = run(2);
    // What the test is about is there: 7 records, one stop, both pools, a line track, the
    // body stage.
    assert_eq!(one.records.len(), 7);
    assert_eq!(one.n_stationary, 1);
    assert_eq!(one.roles.len(), 2);
    assert!(one
        .channels
        .iter()
        .all(|c| !c.invariant_modes.is_empty() && !c.poles.is_empty()));
    assert!(one.channels.iter().any(|c| !c.lines.is_empty()));
    assert!(one.body_ssi.is_some());
    assert_eq!(
        serde_json::to_string(&one).unwrap(),
        serde_json::to_string(&two).unwrap()
    );
    // Each channel's modes and each pool's are the clustering of its own poles alone (the
    // records renumbered without the stop): no result went to another's slot.
    let mut k = 0;
    let active: Vec<Option<usize>> = one
        .records
        .iter()
        .map(|r| {
            (!r.stationary).then(|| {
                k += 1;
                k - 1
            })
        })
        .collect();
    let cluster = cfg.cluster.for_band(&one.records[0].band);
    let clustered = |chs: &[&vibmode_analysis::ChannelAnalysis]| {
        let obs: Vec<vibmode_core::PoleObservation> = chs
            .iter()
            .flat_map(|c| {
                c.poles.iter().filter_map(|p| {
                    Some(vibmode_core::PoleObservation {
                        frequency_hz: p.frequency_hz,
                        damping_ratio: p.damping_ratio,
                        order: p.order,
                        record: active[p.record]?,
                        channel: c.name.clone(),
                        role: Some(c.role),
                        shape: None,
                    })
                })
            })
            .collect();
        let modes = vibmode_modal::find_invariant_modes(&obs, k, &cfg.orders(), &cluster).unwrap();
        modes
            .iter()
            .map(|m| (m.frequency_hz, m.damping_ratio, m.n_poles))
            .collect::<Vec<_>>()
    };
    let got = |modes: &[vibmode_core::InvariantMode]| {
        modes
            .iter()
            .map(|m| (m.frequency_hz, m.damping_ratio, m.n_poles))
            .collect::<Vec<_>>()
    };
    for c in &one.channels {
        assert_eq!(got(&c.invariant_modes), clustered(&[c]), "{}", c.name);
    }
    for r in &one.roles {
        let chs: Vec<&vibmode_analysis::ChannelAnalysis> =
            one.channels.iter().filter(|c| c.role == r.role).collect();
        assert_eq!(chs.len(), 2);
        assert_eq!(got(&r.invariant_modes), clustered(&chs), "{:?}", r.role);
    }
}
