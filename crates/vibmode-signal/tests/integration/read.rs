//! Reading and writing: every format, the real files, identities, and the bad-input errors.

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::path::{Path, PathBuf};
use vibmode_signal::ResampleRecording;
use vibmode_signal::{
    read_delimited, read_path, read_path_bytes, write_path, Channel, ChannelSelector,
    DelimitedReader, Format, ReadOptions, Recording,
};

fn write(dir: &Path, name: &str, text: &str) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p
}

fn opts_fs(fs: f64) -> ReadOptions {
    ReadOptions {
        fs_hz: Some(fs),
        ..ReadOptions::default()
    }
}

/// Error message, checked to be one line.
fn err_of<T: std::fmt::Debug, E: std::fmt::Display + std::fmt::Debug>(r: Result<T, E>) -> String {
    let s = r.unwrap_err().to_string();
    assert!(!s.contains('\n'), "not one line: {s}");
    s
}

fn random_recording(seed: u64, n: usize, nch: usize, fs: f64) -> Recording {
    let mut r = ChaCha8Rng::seed_from_u64(seed);
    let chans = (0..nch)
        .map(|c| Channel {
            name: ["FL", "FR", "RL", "RR", "S_FR", "S_RL", "S_RR"][c % 7].to_string(),
            unit: "m/s^2".into(),
            samples: (0..n).map(|_| r.gen_range(-30.0..30.0)).collect(),
            placement: Default::default(),
        })
        .collect();
    Recording::new(fs, chans).unwrap()
}

/// Says "skipped: <why>" when `what` (`shared`: the shared data folder, `chromium`: a headless
/// browser) is absent here; fails instead where CI requires it (`VIBMODE_REQUIRE=shared,chromium`,
/// set by `.ci/run` when the resource is present).
fn skipped(what: &str, why: &str) {
    let required = std::env::var("VIBMODE_REQUIRE").unwrap_or_default();
    assert!(
        !required.split(',').any(|r| r.trim() == what),
        "{why}, but VIBMODE_REQUIRE={required} requires it here"
    );
    eprintln!("skipped: {why}");
}

#[test]
fn comma_csv_with_time_column_and_units() {
    let d = tempfile::tempdir().unwrap();
    let p = write(
        d.path(),
        "a.csv",
        "Time (s),X-Axis (m/s2),Y [m/s^2],plain\n0.0,1,2,3\n0.01,4,5,6\n0.02,7,8,9\n0.03,1e-3,-2.5E+1,.5\n",
    );
    let rec = read_path(&p, &ReadOptions::default()).unwrap();
    assert!((rec.fs_hz - 100.0).abs() < 1e-9);
    assert_eq!(rec.names(), vec!["X-Axis", "Y", "plain"]);
    assert_eq!(rec.channels[0].unit, "m/s2");
    assert_eq!(rec.channels[1].unit, "m/s^2");
    assert_eq!(rec.channels[2].unit, "");
    assert_eq!(rec.channels[0].samples, vec![1.0, 4.0, 7.0, 1e-3]);
    assert_eq!(rec.channels[1].samples, vec![2.0, 5.0, 8.0, -25.0]);
    assert_eq!(rec.channels[2].samples, vec![3.0, 6.0, 9.0, 0.5]);
    let ta = rec.time_axis.as_ref().unwrap();
    assert_eq!(ta.column, "Time");
    assert!(ta.jitter_rel < 1e-12);
    assert_eq!(ta.start_s, 0.0);
    // opts.unit only fills missing units.
    let rec = read_path(
        &p,
        &ReadOptions {
            unit: Some("g".into()),
            ..ReadOptions::default()
        },
    )
    .unwrap();
    assert_eq!(rec.channels[0].unit, "m/s2");
    assert_eq!(rec.channels[2].unit, "g");
}

#[test]
fn semicolon_decimal_comma_trailing_separator_and_ms_time() {
    let text = "\u{feff}t [ms];a;b;\r\n0;1,5;2,25;\r\n2;-0,5;3;\r\n4;1e-1;7,0;\r\n";
    let rec = read_delimited(text.as_bytes(), "s.csv", &ReadOptions::default()).unwrap();
    assert!((rec.fs_hz - 500.0).abs() < 1e-9);
    assert_eq!(rec.channels[0].samples, vec![1.5, -0.5, 0.1]);
    assert_eq!(rec.channels[1].samples, vec![2.25, 3.0, 7.0]);
    let r = DelimitedReader::new(text.as_bytes(), "s.csv").unwrap();
    assert_eq!(r.separator(), vibmode_signal::Separator::Semicolon);
    assert_eq!(r.time_column(), Some(0));
}

#[test]
fn tab_whitespace_headerless_and_comments() {
    let tab = "timestamp\tacc x (g)\tacc y (g)\n10.0\t1\t2\n10.5\t3\t4\n11.0\t5\t6\n";
    let rec = read_delimited(tab.as_bytes(), "t.tsv", &ReadOptions::default()).unwrap();
    assert!((rec.fs_hz - 2.0).abs() < 1e-12);
    assert_eq!(rec.names(), vec!["acc x", "acc y"]);
    assert_eq!(rec.time_axis.as_ref().unwrap().start_s, 10.0);
    assert!((rec.time_s(2) - 11.0).abs() < 1e-12);

    // Headerless whitespace runs, leading spaces, blank lines and a comment preamble.
    let ws = "% exported by logger\n# comment\n\n  1.0   2.0\t3\n4 5 6\n\n7   8 9   \n";
    let e = err_of(read_delimited(
        ws.as_bytes(),
        "w.txt",
        &ReadOptions::default(),
    ));
    assert_eq!(e, "no time column in w.txt; give its sampling rate (fs_hz)");
    let rec = read_delimited(ws.as_bytes(), "w.txt", &opts_fs(50.0)).unwrap();
    assert_eq!(rec.fs_hz, 50.0);
    assert_eq!(rec.names(), vec!["ch0", "ch1", "ch2"]);
    assert_eq!(rec.channels[2].samples, vec![3.0, 6.0, 9.0]);
    assert!(rec.time_axis.is_none());
    assert!((rec.duration_s() - 3.0 / 50.0).abs() < 1e-15);

    // Headerless comma file.
    let rec = read_delimited("1,2\n3,4\n".as_bytes(), "c.csv", &opts_fs(1.0)).unwrap();
    assert_eq!(rec.channels[1].samples, vec![2.0, 4.0]);
}

/// numpy's `savetxt(..., header="time,a,b")` writes the header as a comment (`# time,a,b`): the
/// comment line just above the first row names the columns when it has as many cells as the rows
/// and one of them is not a number (before, its time column was read as a channel).
#[test]
fn numpy_savetxt_header_names_the_columns() {
    let comma = "# time,acc_a [m/s^2],acc_b\n0.0,1,2\n0.5,3,4\n1.0,5,6\n";
    let ws = "# time acc_a acc_b\n0.000000000000000000e+00 1 2\n5.0e-01 3 4\n1.0 5 6\n";
    for (name, text) in [("c.csv", comma), ("w.txt", ws)] {
        let rec = read_delimited(text.as_bytes(), name, &ReadOptions::default()).unwrap();
        assert_eq!(rec.names(), vec!["acc_a", "acc_b"], "{name}");
        assert_eq!(rec.fs_hz, 2.0);
        assert_eq!(rec.channels[1].samples, vec![2.0, 4.0, 6.0]);
    }
    assert_eq!(
        read_delimited(comma.as_bytes(), "c.csv", &ReadOptions::default())
            .unwrap()
            .channels[0]
            .unit,
        "m/s^2"
    );
    // Not a header: another cell count, all numbers, or a blank line before the rows.
    for text in [
        "# exported by logger, v2\n1,2,3\n4,5,6\n",
        "# 1,2,3\n1,2,3\n4,5,6\n",
        "# time,a,b\n\n1,2,3\n4,5,6\n",
    ] {
        let rec = read_delimited(text.as_bytes(), "n.csv", &opts_fs(1.0)).unwrap();
        assert_eq!(rec.names(), vec!["ch0", "ch1", "ch2"], "{text}");
    }
}

/// Excel's "Unicode Text" export is UTF-16 with a byte-order mark: refused in one line that
/// says so and how to convert it (not "not a text file").
#[test]
fn utf16_text_is_named_with_the_fix() {
    let text = "time\tacc\n0\t1\n0.01\t2\n";
    for bom in [[0xFFu8, 0xFE], [0xFE, 0xFF]] {
        let mut bytes = bom.to_vec();
        for u in text.encode_utf16() {
            let b = if bom[0] == 0xFF {
                u.to_le_bytes()
            } else {
                u.to_be_bytes()
            };
            bytes.extend_from_slice(&b);
        }
        let e = err_of(read_delimited(&bytes[..], "u.txt", &ReadOptions::default()));
        assert!(
            e.contains("UTF-16") && e.contains("CSV UTF-8") && !e.contains('\n'),
            "{e}"
        );
    }
}

#[test]
fn rate_from_time_and_fs_option_must_agree() {
    let text = "time,x\n0,1\n0.002,2\n0.004,3\n";
    // 500 Hz vs 502 Hz: within 1 %, the given nominal rate wins, measured kept in time_axis.
    let rec = read_delimited(text.as_bytes(), "f.csv", &opts_fs(502.0)).unwrap();
    assert_eq!(rec.fs_hz, 502.0);
    assert!((rec.time_axis.unwrap().fs_hz - 500.0).abs() < 1e-9);
    let e = err_of(read_delimited(text.as_bytes(), "f.csv", &opts_fs(1000.0)));
    assert!(
        e.contains("500") && e.contains("1000") && e.contains("'time'"),
        "{e}"
    );
}

#[test]
fn nonuniform_time_refused_then_interpolated() {
    // y = 2 t + 1 at jittered times; interpolation onto the uniform grid at the mean rate is
    // exact for a linear signal.
    let times = [0.0, 0.13, 0.2, 0.29, 0.4, 0.52, 0.6];
    let mut text = String::from("Time [s],y\n");
    for t in times {
        text.push_str(&format!("{t},{}\n", 2.0 * t + 1.0));
    }
    let e = err_of(read_delimited(
        text.as_bytes(),
        "j.csv",
        &ReadOptions::default(),
    ));
    // mean dt 0.1; max |dt - 0.1| = 0.03 -> jitter 0.3.
    assert!(
        e.contains("3.000e-1")
            && e.contains("allow_nonuniform")
            && e.contains("10.0000")
            && !e.contains("--"),
        "{e}"
    );
    let o = ReadOptions {
        allow_nonuniform: true,
        ..ReadOptions::default()
    };
    let rec = read_delimited(text.as_bytes(), "j.csv", &o).unwrap();
    assert!((rec.fs_hz - 10.0).abs() < 1e-9);
    assert!((rec.time_axis.as_ref().unwrap().jitter_rel - 0.3).abs() < 1e-9);
    for (i, v) in rec.channels[0].samples.iter().enumerate() {
        let t = i as f64 * 0.1;
        assert!((v - (2.0 * t + 1.0)).abs() < 1e-12, "{i}: {v}");
    }
    // A looser tolerance accepts it as is.
    let o = ReadOptions {
        max_jitter_rel: 0.5,
        ..ReadOptions::default()
    };
    let rec = read_delimited(text.as_bytes(), "j.csv", &o).unwrap();
    assert_eq!(rec.channels[0].samples[1], 2.0 * 0.13 + 1.0);
}

#[test]
fn bad_delimited_inputs() {
    let d = tempfile::tempdir().unwrap();
    let o = opts_fs(100.0);
    let missing = d.path().join("nope.csv");
    let e = err_of(read_path(&missing, &o));
    assert!(e.contains("cannot read") && e.contains("nope.csv"), "{e}");
    let e = err_of(read_path(&write(d.path(), "e.csv", ""), &o));
    assert!(e.contains("e.csv is empty"), "{e}");
    let e = err_of(read_path(&write(d.path(), "b.csv", "\n  \n"), &o));
    assert!(e.contains("is empty"), "{e}");
    let e = err_of(read_path(&write(d.path(), "h.csv", "x,y,z\n\n"), &o));
    assert!(e.contains("header row but no data rows"), "{e}");
    let e = err_of(read_path(
        &write(d.path(), "r.csv", "x,y,z\n1,2,3\n4,5,6\n7,8\n"),
        &o,
    ));
    assert!(
        e.contains("line 4") && e.contains("has 2 columns but 3 were expected"),
        "{e}"
    );
    let e = err_of(read_path(
        &write(d.path(), "n.csv", "x,y\n1,2\n3,abc\n"),
        &o,
    ));
    assert!(
        e.contains("line 3, column 2 ('y')") && e.contains("'abc'"),
        "{e}"
    );
    let e = err_of(read_path(
        &write(d.path(), "m.csv", "x,y\n1,2\n3,\n4,5\n"),
        &o,
    ));
    // `3,` is a missing value in column 2 (pandas writes NaN as an empty cell), not a short row.
    assert!(
        e.contains("line 3, column 2 ('y')") && e.contains("is empty"),
        "{e}"
    );
    let e = err_of(read_path(
        &write(d.path(), "nan.csv", "x,y\n1,2\n3,4\n5,NaN\n"),
        &o,
    ));
    assert!(
        e.contains("nan.csv: channel 'y' sample 2 is NaN") && e.contains("clean the data"),
        "{e}"
    );
    let e = err_of(read_path(&write(d.path(), "inf.csv", "x\n1\n-inf\n"), &o));
    assert!(e.contains("inf.csv: channel 'x' sample 1 is -inf"), "{e}");
    // Streamed too, the file is named (among many records the channel alone does not tell).
    let e = vibmode_signal::open_stream(&d.path().join("inf.csv"), &o)
        .and_then(|mut s| s.read_to_recording())
        .unwrap_err()
        .to_string();
    assert!(e.contains("inf.csv: channel 'x' sample 1 is -inf"), "{e}");
    let ok = write(d.path(), "ok.csv", "x\n1\n2\n");
    for bad in [0.0, -3.0, f64::NAN, f64::INFINITY] {
        let e = err_of(read_path(&ok, &opts_fs(bad)));
        assert!(e.contains("must be a positive finite number"), "{e}");
    }
    let e = err_of(read_path(
        &write(d.path(), "t.csv", "time,x\n0,1\n0.1,2\n0.1,3\n"),
        &ReadOptions::default(),
    ));
    assert!(e.contains("does not increase at line 4"), "{e}");
    let e = err_of(read_path(
        &write(d.path(), "only.csv", "time\n0\n1\n"),
        &ReadOptions::default(),
    ));
    assert!(e.contains("no data channels"), "{e}");
}

#[test]
fn channel_selection() {
    assert_eq!(
        "2".parse::<ChannelSelector>().unwrap(),
        ChannelSelector::Index(2)
    );
    assert_eq!(
        " Z-Axis ".parse::<ChannelSelector>().unwrap(),
        ChannelSelector::Name("Z-Axis".into())
    );
    assert!("".parse::<ChannelSelector>().is_err());
    let rec = random_recording(1, 10, 3, 100.0);
    let s = rec
        .select(&[
            ChannelSelector::Index(2),
            ChannelSelector::Name("fl".into()),
        ])
        .unwrap();
    assert_eq!(s.names(), vec!["RL", "FL"]);
    assert_eq!(s.channels[0].samples, rec.channels[2].samples);
    let e = err_of(rec.select(&[ChannelSelector::Name("Z".into())]));
    assert_eq!(e, "no channel named 'Z'; available: FL, FR, RL");
    let e = err_of(rec.select(&[ChannelSelector::Index(3)]));
    assert!(
        e.contains("index 3") && e.contains("0=FL, 1=FR, 2=RL"),
        "{e}"
    );
    let s = rec.slice(2, 5).unwrap();
    assert_eq!(s.len(), 3);
    assert_eq!(s.channels[1].samples[0], rec.channels[1].samples[2]);
    assert!(rec.slice(5, 5).is_err());
    let e = err_of(Recording::new(
        10.0,
        vec![
            Channel {
                name: "a".into(),
                unit: String::new(),
                samples: vec![1.0; 3],
                placement: Default::default(),
            },
            Channel {
                name: "b".into(),
                unit: String::new(),
                samples: vec![1.0; 2],
                placement: Default::default(),
            },
        ],
    ));
    assert!(e.contains("'b' has 2 samples but 'a' has 3"), "{e}");
}

fn write_wav_int(path: &Path, bits: u16, fs: u32, frames: &[[i32; 2]]) {
    let spec = hound::WavSpec {
        channels: 2,
        sample_rate: fs,
        bits_per_sample: bits,
        sample_format: hound::SampleFormat::Int,
    };
    let mut w = hound::WavWriter::create(path, spec).unwrap();
    for f in frames {
        for v in f {
            match bits {
                16 => w.write_sample(*v as i16).unwrap(),
                _ => w.write_sample(*v).unwrap(),
            }
        }
    }
    w.finalize().unwrap();
}

#[test]
fn wav_integer_and_float() {
    let d = tempfile::tempdir().unwrap();
    for bits in [16u16, 24, 32] {
        let full = 1i64 << (bits - 1);
        let half = (full / 2) as i32;
        let frames = [[half, -half], [0, (-full) as i32], [(full - 1) as i32, 1]];
        let p = d.path().join(format!("i{bits}.wav"));
        write_wav_int(&p, bits, 8000, &frames);
        let rec = read_path(
            &p,
            &ReadOptions {
                scale: 19.62,
                ..ReadOptions::default()
            },
        )
        .unwrap();
        assert_eq!(rec.fs_hz, 8000.0);
        assert_eq!(rec.names(), vec!["ch0", "ch1"]);
        let c0 = &rec.channels[0].samples;
        let c1 = &rec.channels[1].samples;
        assert!((c0[0] - 0.5 * 19.62).abs() < 1e-12, "{bits}: {}", c0[0]);
        assert!((c1[0] + 0.5 * 19.62).abs() < 1e-12);
        assert!((c1[1] + 19.62).abs() < 1e-12, "-full scale = -1");
        assert!(c0[2] < 19.62 && c0[2] > 19.62 * (1.0 - 1e-4));
    }
    // Float WAV through write_path; fs mismatch and zero samples.
    let rec = random_recording(3, 50, 3, 200.0);
    let p = d.path().join("f.wav");
    write_path(&p, &rec).unwrap();
    let back = read_path(&p, &ReadOptions::default()).unwrap();
    assert_eq!(back.fs_hz, 200.0);
    for (a, b) in rec.channels.iter().zip(&back.channels) {
        for (x, y) in a.samples.iter().zip(&b.samples) {
            assert_eq!(*y, *x as f32 as f64);
        }
    }
    let e = err_of(read_path(&p, &opts_fs(100.0)));
    assert!(
        e.contains("WAV header is 200 Hz") && e.contains("100 Hz"),
        "{e}"
    );
    let z = d.path().join("z.wav");
    write_wav_int(&z, 16, 8000, &[]);
    let e = err_of(read_path(&z, &ReadOptions::default()));
    assert!(e.contains("zero samples"), "{e}");
    let junk = write(d.path(), "junk.wav", "not a wav at all");
    let e = err_of(read_path(&junk, &ReadOptions::default()));
    assert!(e.starts_with("WAV ") && e.contains("junk.wav"), "{e}");
    let e = err_of(write_path(
        &d.path().join("bad.wav"),
        &random_recording(1, 5, 1, 425.08),
    ));
    assert!(e.contains("425.08") && e.contains("whole number"), "{e}");
}

#[test]
fn raw_with_sidecar_both_names() {
    let d = tempfile::tempdir().unwrap();
    // f32, sidecar <path>.json
    let p = d.path().join("a.f32");
    let vals: [f32; 6] = [1.0, -1.0, 2.5, -2.5, 4.0, -4.0];
    let bytes: Vec<u8> = vals.iter().flat_map(|v| v.to_le_bytes()).collect();
    std::fs::write(&p, &bytes).unwrap();
    write(
        d.path(),
        "a.f32.json",
        r#"{"fs_hz": 20000, "dtype": "f32", "channels": ["FL", "FR"], "units": ["m/s^2", "g"]}"#,
    );
    let rec = read_path(&p, &ReadOptions::default()).unwrap();
    assert_eq!(rec.fs_hz, 20000.0);
    assert_eq!(rec.names(), vec!["FL", "FR"]);
    assert_eq!(rec.channels[0].samples, vec![1.0, 2.5, 4.0]);
    assert_eq!(rec.channels[1].samples, vec![-1.0, -2.5, -4.0]);
    assert_eq!(rec.channels[1].unit, "g");
    // f64, sidecar <stem>.json, no units
    let p = d.path().join("b.bin");
    let vals: [f64; 3] = [0.1, 0.2, 0.3];
    std::fs::write(
        &p,
        vals.iter()
            .flat_map(|v| v.to_le_bytes())
            .collect::<Vec<u8>>(),
    )
    .unwrap();
    write(
        d.path(),
        "b.json",
        r#"{"fs_hz": 500, "dtype": "f64", "channels": ["z"]}"#,
    );
    let rec = read_path(&p, &ReadOptions::default()).unwrap();
    assert_eq!(rec.channels[0].samples, vals.to_vec());
    assert_eq!(rec.channels[0].unit, "");
    // Errors: malformed sidecar, bad dtype, missing sidecar, size mismatch, units count.
    write(d.path(), "b.json", r#"{"fs_hz": 500, "dtype": "f64""#);
    let e = err_of(read_path(&p, &ReadOptions::default()));
    assert!(
        e.contains("sidecar") && e.contains("b.json") && e.contains("expected"),
        "{e}"
    );
    write(
        d.path(),
        "b.json",
        r#"{"fs_hz": 500, "dtype": "i16", "channels": ["z"]}"#,
    );
    let e = err_of(read_path(&p, &ReadOptions::default()));
    assert!(
        e.contains("dtype 'i16'") && e.contains("\"f32\" or \"f64\""),
        "{e}"
    );
    write(
        d.path(),
        "b.json",
        r#"{"fs_hz": -1, "dtype": "f64", "channels": ["z"]}"#,
    );
    let e = err_of(read_path(&p, &ReadOptions::default()));
    assert!(e.contains("fs_hz -1"), "{e}");
    write(
        d.path(),
        "b.json",
        r#"{"fs_hz": 500, "dtype": "f64", "channels": ["z", "y"], "units": ["g"]}"#,
    );
    let e = err_of(read_path(&p, &ReadOptions::default()));
    assert!(e.contains("\"units\" has 1 entries"), "{e}");
    write(
        d.path(),
        "b.json",
        r#"{"fs_hz": 500, "dtype": "f64", "channels": ["z", "y"]}"#,
    );
    let e = err_of(read_path(&p, &ReadOptions::default()));
    assert!(e.contains("24 bytes, not a multiple of 16"), "{e}");
    let lone = d.path().join("c.f64");
    std::fs::write(&lone, [0u8; 8]).unwrap();
    let e = err_of(read_path(&lone, &ReadOptions::default()));
    assert!(
        e.contains("c.f64.json or") && e.contains("not found"),
        "{e}"
    );
}

#[test]
fn write_read_roundtrip_identity() {
    // Seeded random data: CSV and f64 round trips are exact, f32 to f32 precision.
    let d = tempfile::tempdir().unwrap();
    let rec = random_recording(7, 1000, 7, 20_000.0);
    for (name, exact) in [
        ("r.csv", true),
        ("r.f64", true),
        ("r.raw", true),
        ("r.f32", false),
        ("r.tsv", true),
    ] {
        let p = d.path().join(name);
        write_path(&p, &rec).unwrap();
        let back = read_path(&p, &ReadOptions::default()).unwrap();
        assert!(
            (back.fs_hz - 20_000.0).abs() < 1e-6,
            "{name}: {}",
            back.fs_hz
        );
        assert_eq!(back.names(), rec.names(), "{name}");
        for (a, b) in rec.channels.iter().zip(&back.channels) {
            assert_eq!(a.unit, b.unit, "{name}");
            if exact {
                assert_eq!(a.samples, b.samples, "{name}");
            } else {
                for (x, y) in a.samples.iter().zip(&b.samples) {
                    assert_eq!(*y, *x as f32 as f64);
                }
            }
        }
    }
    let e = err_of(write_path(&d.path().join("x.xyz"), &rec));
    assert!(e.contains("unknown format '.xyz'"), "{e}");
    assert_eq!("WAV".parse::<Format>().unwrap(), Format::Wav);
    assert_eq!(Format::Raw.to_string(), "raw");
    let e = err_of("mat".parse::<Format>());
    assert!(e.contains("'mat'") && e.contains("delimited"), "{e}");
}

/// Reading from the file's bytes in memory gives what reading the file gives, for every
/// format (names, units from a WAV's sidecar, rate, samples bit for bit), and the same errors.
#[test]
fn bytes_in_memory_read_as_the_file() {
    let d = tempfile::tempdir().unwrap();
    for (seed, name) in [(3u64, "r.csv"), (4, "r.wav"), (5, "r.f32"), (6, "r.txt")] {
        let rec = random_recording(seed, 700, 7, 2_000.0);
        let p = d.path().join(name);
        write_path(&p, &rec).unwrap();
        let bytes = std::fs::read(&p).unwrap();
        let a = read_path(&p, &ReadOptions::default()).unwrap();
        let b = read_path_bytes(&p, &bytes, &ReadOptions::default()).unwrap();
        assert_eq!(a.fs_hz, b.fs_hz, "{name}");
        assert_eq!(a.names(), b.names(), "{name}");
        for (x, y) in a.channels.iter().zip(&b.channels) {
            assert_eq!(x.unit, y.unit, "{name}");
            assert_eq!(x.samples, y.samples, "{name}");
        }
    }
    // A float WAV cut short: both refuse it as truncated.
    let rec = random_recording(8, 300, 3, 1_000.0);
    let p = d.path().join("cut.wav");
    write_path(&p, &rec).unwrap();
    let mut bytes = std::fs::read(&p).unwrap();
    bytes.truncate(bytes.len() - 10);
    std::fs::write(&p, &bytes).unwrap();
    let a = err_of(read_path(&p, &ReadOptions::default()));
    let b = err_of(read_path_bytes(&p, &bytes, &ReadOptions::default()));
    for e in [&a, &b] {
        assert!(e.contains("may be truncated") && !e.contains('\n'), "{e}");
    }
    // Bad bytes: the same one-line errors as the file's.
    for (name, text) in [
        ("bad.csv", "a,b\n1,2\n3,x\n"),
        ("bad.wav", "RIFF....not a wav"),
    ] {
        let p = write(d.path(), name, text);
        let a = err_of(read_path(&p, &opts_fs(100.0)));
        let b = err_of(read_path_bytes(&p, text.as_bytes(), &opts_fs(100.0)));
        assert_eq!(a, b, "{name}");
    }
}

#[test]
fn streaming_blocks_equal_whole_read() {
    let rec = random_recording(11, 2500, 3, 100.0);
    let d = tempfile::tempdir().unwrap();
    let p = d.path().join("s.csv");
    write_path(&p, &rec).unwrap();
    let f = std::io::BufReader::new(std::fs::File::open(&p).unwrap());
    let mut r = DelimitedReader::new(f, "s.csv").unwrap();
    assert_eq!(r.time_column(), Some(0));
    let mut got: Vec<Vec<f64>> = vec![Vec::new(); 4];
    let mut blocks = 0;
    while let Some(b) = r.next_block(700).unwrap() {
        assert!(b.n_rows() <= 700);
        blocks += 1;
        for (g, c) in got.iter_mut().zip(b.columns) {
            g.extend(c);
        }
    }
    assert_eq!(blocks, 4);
    for (c, g) in rec.channels.iter().zip(&got[1..]) {
        assert_eq!(&c.samples, g);
    }
}

fn real_dir(sub: &str) -> Option<PathBuf> {
    let p = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../../shared/data/real")
        .join(sub);
    if p.is_dir() {
        Some(p)
    } else {
        skipped("shared", &format!("{} not present", p.display()));
        None
    }
}

#[test]
fn real_bratislava_transit_files() {
    let Some(dir) = real_dir("bratislava_transit") else {
        return;
    };
    // Row counts from numpy.loadtxt(skiprows=1).
    let expected = [
        ("L35_1915_Borska_Zaluhy.csv", 109_502),
        ("L35_1915_Most_Kutiky_neutral.csv", 8_315),
        ("L3_StnVinohrady_Riazanska.csv", 120_033),
        ("L4_7954_ZaluhyKrizovatka_KutikyObratisko.csv", 97_362),
        ("L9_Lanfranconi_Riviera.csv", 79_010),
    ];
    for (f, n) in expected {
        let p = dir.join(f);
        let e = err_of(read_path(&p, &ReadOptions::default()));
        assert!(
            e.contains("sampling rate (fs_hz)") && !e.contains("--"),
            "{e}"
        );
        let rec = read_path(&p, &opts_fs(500.0)).unwrap();
        assert_eq!(rec.names(), vec!["x", "y", "z"], "{f}");
        assert_eq!(rec.len(), n, "{f}");
    }
    // numpy: mean of z = 10.156972307302874, last x = -0.291 (L9 file).
    let rec = read_path(&dir.join("L9_Lanfranconi_Riviera.csv"), &opts_fs(500.0)).unwrap();
    let z = &rec.channels[2].samples;
    let mean = z.iter().sum::<f64>() / z.len() as f64;
    assert!((mean - 10.156972307302874).abs() < 1e-10, "{mean}");
    assert_eq!(rec.channels[0].samples[rec.len() - 1], -0.291);
}

#[test]
fn real_rc_slab_smartphone_file() {
    let Some(dir) = real_dir("rc_slab_smartphone") else {
        return;
    };
    let p = dir.join("Example02_Smartphone_Data.csv");
    let rec = read_path(&p, &ReadOptions::default()).unwrap();
    // numpy.loadtxt(delimiter=',', skiprows=1, usecols=(0,1,2,3)):
    assert_eq!(rec.len(), 25_291);
    assert_eq!(rec.names(), vec!["X-Axis", "Y- Axis", "Z-Axis"]);
    assert_eq!(rec.channels[2].unit, "m/s2");
    assert!(
        (rec.fs_hz - 425.0796211146227).abs() < 1e-9,
        "{}",
        rec.fs_hz
    );
    let ta = rec.time_axis.as_ref().unwrap();
    assert!((ta.jitter_rel - 0.0010752601122164238).abs() < 1e-9);
    let sz: f64 = rec.channels[2].samples.iter().sum();
    assert!((sz - -0.7252470246561948).abs() < 1e-9, "{sz}");
    assert_eq!(rec.channels[2].samples[rec.len() - 1], -0.08238175256840741);
    // The author's analysis: drop 2000 samples, Z channel, resample to 50 Hz.
    let z = rec
        .select(&["Z-Axis".parse().unwrap()])
        .unwrap()
        .slice(2000, rec.len())
        .unwrap();
    let low = z
        .resample(&vibmode_signal::ResampleParams {
            fs_out_hz: 50.0,
            ..Default::default()
        })
        .unwrap();
    assert!((low.fs_hz - 50.0).abs() < 0.01);
}

#[test]
fn paper_size_csv_round_trip() {
    // 7 channels x 204 800 rows (the paper's record size); speed is measured in bench/.
    let rec = random_recording(5, 204_800, 7, 20_000.0);
    let d = tempfile::tempdir().unwrap();
    let p = d.path().join("big.csv");
    write_path(&p, &rec).unwrap();
    let back = read_path(&p, &ReadOptions::default()).unwrap();
    assert_eq!(back.len(), 204_800);
    assert_eq!(back.channels[6].samples, rec.channels[6].samples);
}

#[test]
fn large_file_parallel_parse_reports_exact_lines() {
    // > 1 MB so that read_path parses in several chunks; errors must still name the right line.
    let d = tempfile::tempdir().unwrap();
    let mut text = String::from("a,b,c\n");
    for i in 0..60_000 {
        text.push_str(&format!("{i},{}.25,{}\n", i * 2, i % 7));
    }
    let p = write(d.path(), "big.csv", &text);
    let rec = read_path(&p, &opts_fs(10.0)).unwrap();
    assert_eq!(rec.len(), 60_000);
    assert_eq!(rec.channels[0].samples[59_999], 59_999.0);
    assert_eq!(rec.channels[1].samples[45_000], 90_000.25);
    assert_eq!(rec.channels[2].samples[45_001], (45_001 % 7) as f64);
    // Same text through the streaming reader.
    let s = read_delimited(text.as_bytes(), "big.csv", &opts_fs(10.0)).unwrap();
    assert_eq!(s, rec);
    // A bad cell at data row 50 000 (line 50 002 counting the header).
    let bad = text.replacen("50000,100000.25,", "50000,1x,", 1);
    let p = write(d.path(), "bad.csv", &bad);
    let e = err_of(read_path(&p, &opts_fs(10.0)));
    assert!(
        e.contains("line 50002, column 2 ('b')") && e.contains("'1x'"),
        "{e}"
    );
    let bad = text.replacen("55000,110000.25,", "55000,", 1);
    let p = write(d.path(), "rag.csv", &bad);
    let e = err_of(read_path(&p, &opts_fs(10.0)));
    assert!(
        e.contains("line 55002 ") && e.contains("has 2 columns"),
        "{e}"
    );
}

#[test]
fn wav_keeps_channel_names_and_units_through_its_sidecar() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("r.wav");
    let rec = vibmode_core::Recording {
        fs_hz: 100.0,
        channels: vec![
            vibmode_core::Channel::new("FL_unsprung", "m/s^2", vec![0.0, 1.0, -1.0, 0.5]),
            vibmode_core::Channel::new("RR_sprung", "g", vec![0.25, 0.0, 0.5, -0.25]),
        ],
        time_axis: None,
    };
    vibmode_signal::write_path(&path, &rec).unwrap();
    let back = vibmode_signal::read_path(&path, &vibmode_signal::ReadOptions::default()).unwrap();
    let names: Vec<&str> = back.channels.iter().map(|c| c.name.as_str()).collect();
    assert_eq!(names, ["FL_unsprung", "RR_sprung"]);
    assert_eq!(back.channels[1].unit, "g");
    assert_eq!(back.channels[1].samples, rec.channels[1].samples);
    // a sidecar naming the wrong number of channels is a clear error
    std::fs::write(dir.path().join("r.wav.json"), r#"{"channels": ["a"]}"#).unwrap();
    let e = vibmode_signal::read_path(&path, &vibmode_signal::ReadOptions::default())
        .unwrap_err()
        .to_string();
    assert!(e.contains("names 1 channels but the file has 2"), "{e}");
    // a sidecar with only a start time: ch0, ch1, and the start time
    std::fs::write(
        dir.path().join("r.wav.json"),
        r#"{"start_time": "2026-11-28T08:00:00Z"}"#,
    )
    .unwrap();
    let timed = vibmode_signal::read_path(&path, &vibmode_signal::ReadOptions::default()).unwrap();
    assert_eq!(timed.channels[1].name, "ch1");
    assert!(timed.time_axis.is_some());
    // without a sidecar: ch0, ch1
    std::fs::remove_file(dir.path().join("r.wav.json")).unwrap();
    let plain = vibmode_signal::read_path(&path, &vibmode_signal::ReadOptions::default()).unwrap();
    assert_eq!(plain.channels[0].name, "ch0");
}

/// Two channels of one name (a header `t,acc,x,acc`) are refused by the whole-file and the
/// streamed readers alike, naming the file, the name and both channels (1-based, the time column
/// not counted); `Recording::new` refuses them too.
#[test]
fn channels_of_one_name_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let p = write(
        dir.path(),
        "dup.csv",
        "t,acc,x,acc\n0,1,2,3\n0.01,1,2,3\n0.02,1,2,3\n0.03,1,2,3\n",
    );
    let want = "channels 1 and 3 are both named 'acc'";
    let e = err_of(read_path(&p, &ReadOptions::default()));
    assert!(e.contains(want) && e.contains("dup.csv"), "{e}");
    let e = err_of(vibmode_signal::open_stream(&p, &ReadOptions::default()).map(|_| ()));
    assert!(e.contains(want) && e.contains("dup.csv"), "{e}");
    let ch = |n: &str| Channel::new(n, "m/s^2", vec![0.0; 4]);
    let e = err_of(Recording::new(100.0, vec![ch("a"), ch("b"), ch("b")]));
    assert!(e.contains("channels 2 and 3 are both named 'b'"), "{e}");
    assert!(Recording::new(100.0, vec![ch("a"), ch("b")]).is_ok());
}

/// A WAV without frames and a raw sidecar with an unknown sample type are refused with their
/// problem typed (the values in its fields) and the same one-line message through both readers.
#[test]
fn wav_and_sidecar_problems_are_typed() {
    use vibmode_signal::{SidecarProblem, SignalError, WavProblem};
    let d = tempfile::tempdir().unwrap();
    let w = d.path().join("empty.wav");
    write_wav_int(&w, 16, 1000, &[]);
    for e in [
        read_path(&w, &ReadOptions::default()).unwrap_err(),
        vibmode_signal::open_stream(&w, &ReadOptions::default())
            .map(|_| ())
            .unwrap_err(),
    ] {
        assert!(
            matches!(
                &e,
                SignalError::Wav {
                    problem: WavProblem::NoSamples,
                    ..
                }
            ),
            "{e:?}"
        );
        assert!(e.to_string().contains("zero samples"), "{e}");
    }
    let p = d.path().join("c.f32");
    std::fs::write(&p, [0u8; 8]).unwrap();
    write(
        d.path(),
        "c.f32.json",
        r#"{"fs_hz": 100, "dtype": "i16", "channels": ["FL"]}"#,
    );
    let e = read_path(&p, &ReadOptions::default()).unwrap_err();
    assert!(
        matches!(&e, SignalError::Sidecar { problem: SidecarProblem::Dtype { dtype }, .. } if dtype == "i16"),
        "{e:?}"
    );
    assert!(
        e.to_string().contains("dtype 'i16' is not supported"),
        "{e}"
    );
}

/// A time column of Unix time (seconds since 1970, or milliseconds with its unit), as loggers
/// and phones write a `timestamp`, gives the first sample's absolute time; a relative time
/// column does not. 1795752000 s is 2026-11-27 04:00:00 UTC (20784 days of 86400 s and 4 h).
#[test]
fn a_unix_time_column_gives_the_start() {
    assert_eq!(20784 * 86400 + 4 * 3600, 1_795_752_000);
    let rows = |t0: f64, step: f64| -> String {
        (0..400)
            .map(|i| format!("{},{}\n", t0 + step * i as f64, (i % 7) as f64 / 7.0))
            .collect()
    };
    for (header, t0, step) in [
        ("timestamp,acc\n", 1_795_752_000.0, 0.005),
        ("timestamp_ms,acc\n", 1_795_752_000_000.0, 5.0),
        ("epoch_ms,acc\n", 1_795_752_000_000.0, 5.0),
        ("unix_time,acc\n", 1_795_752_000.0, 0.005),
        ("Time (ms),acc\n", 1_795_752_000_000.0, 5.0),
    ] {
        let text = format!("{header}{}", rows(t0, step));
        let rec = read_delimited(text.as_bytes(), "u.csv", &ReadOptions::default()).unwrap();
        // Seconds near 1.8e9 hold steps of 5 ms to a few 1e-7 s (f64): the rate to ~1e-7.
        assert!((rec.fs_hz - 200.0).abs() < 1e-4, "{header}: {}", rec.fs_hz);
        let start = rec.time_axis.unwrap().start_unix_s();
        assert_eq!(start, Some(1_795_752_000.0), "{header}");
    }
    // Relative times, and a time column in ms read as seconds by its name (a relative 1.8e12 s
    // is not a date either): no absolute start.
    for (header, t0, step) in [("time,acc\n", 0.0, 0.005), ("time,acc\n", 5000.0, 0.005)] {
        let text = format!("{header}{}", rows(t0, step));
        let rec = read_delimited(text.as_bytes(), "r.csv", &ReadOptions::default()).unwrap();
        assert_eq!(rec.time_axis.unwrap().start_unix_s(), None, "{t0}");
    }
}
