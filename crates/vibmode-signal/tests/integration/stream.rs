//! Streaming readers and the streaming FIR resampler: identities with the whole-file readers
//! and the ideal filter, the filter's response, and the bad-input errors.

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::path::{Path, PathBuf};
use vibmode_signal::stream_resample::{bessel_i0, kaiser_beta, rational_ratio};
use vibmode_signal::{
    open_stream, read_path, resample, write_path, Channel, ChannelSelector, FirDecimator,
    FirDesign, ReadOptions, Recording, ResampleParams, StreamResampleParams,
};

fn random_recording(seed: u64, n: usize, nch: usize, fs: f64) -> Recording {
    let mut r = ChaCha8Rng::seed_from_u64(seed);
    Recording {
        fs_hz: fs,
        channels: (0..nch)
            .map(|c| {
                Channel::new(
                    format!("c{c}"),
                    "m/s^2".to_string(),
                    (0..n).map(|_| r.gen_range(-3.0..3.0)).collect(),
                )
            })
            .collect(),
        time_axis: None,
    }
}

fn stream_all(path: &Path, opts: &ReadOptions, block: usize) -> Recording {
    let mut s = open_stream(path, opts).unwrap();
    let mut data = vec![Vec::new(); s.info().n_channels()];
    let mut expect_first = 0u64;
    while let Some(b) = s.next_block(block).unwrap() {
        assert_eq!(b.first_frame, expect_first);
        assert!(b.n_frames() >= 1 && b.n_frames() <= block);
        expect_first += b.n_frames() as u64;
        for (d, c) in data.iter_mut().zip(b.channels) {
            d.extend(c);
        }
    }
    Recording {
        fs_hz: s.info().fs_hz,
        channels: s
            .info()
            .names
            .iter()
            .zip(&s.info().units)
            .zip(data)
            .map(|((n, u), d)| Channel::new(n.clone(), u.clone(), d))
            .collect(),
        time_axis: None,
    }
}

fn same(a: &Recording, b: &Recording) {
    assert_eq!(a.fs_hz, b.fs_hz);
    assert_eq!(a.names(), b.names());
    for (x, y) in a.channels.iter().zip(&b.channels) {
        assert_eq!(x.unit, y.unit);
        assert_eq!(x.samples, y.samples, "channel {}", x.name);
    }
}

fn tmp() -> tempfile::TempDir {
    tempfile::tempdir().unwrap()
}

#[test]
fn every_format_streams_like_the_whole_file_reader_over_seeds_and_block_sizes() {
    let dir = tmp();
    for seed in 0..6u64 {
        let n = 1000 + 377 * seed as usize;
        let rec = random_recording(seed, n, 1 + (seed as usize % 4), 1000.0);
        for ext in ["f32", "f64", "wav", "csv"] {
            let p: PathBuf = dir.path().join(format!("r{seed}.{ext}"));
            write_path(&p, &rec).unwrap();
            let whole = read_path(&p, &ReadOptions::default()).unwrap();
            for block in [1, 7, 256, 100_000] {
                let s = stream_all(&p, &ReadOptions::default(), block);
                same(&s, &whole);
            }
            let s = open_stream(&p, &ReadOptions::default()).unwrap();
            assert_eq!(s.info().n_frames, Some(n as u64), "{ext}");
        }
    }
}

/// A `.npy` file as `numpy.save` lays it out (format version `major`): the header with
/// `descr`, `fortran_order` and the shape as given (text), padded to 64 bytes, then `data`.
fn npy_file(descr: &str, fortran: bool, shape: &str, data: &[u8], major: u8) -> Vec<u8> {
    let order = if fortran { "True" } else { "False" };
    let mut h = format!("{{'descr': '{descr}', 'fortran_order': {order}, 'shape': {shape}, }}");
    let fixed = if major == 1 { 10 } else { 12 };
    while (fixed + h.len() + 1) % 64 != 0 {
        h.push(' ');
    }
    h.push('\n');
    let mut out = b"\x93NUMPY".to_vec();
    out.extend([major, 0]);
    if major == 1 {
        out.extend((h.len() as u16).to_le_bytes());
    } else {
        out.extend((h.len() as u32).to_le_bytes());
    }
    out.extend(h.as_bytes());
    out.extend(data);
    out
}

/// A `.npy` file of the values given by channel, stored in C order (frame by frame) or Fortran
/// order (channel by channel).
fn npy_bytes(chans: &[Vec<f64>], f32_values: bool, fortran: bool, major: u8) -> Vec<u8> {
    let (n, nch) = (chans[0].len(), chans.len());
    let descr = if f32_values { "<f4" } else { "<f8" };
    let shape = if nch == 1 {
        format!("({n},)")
    } else {
        format!("({n}, {nch})")
    };
    let mut data = Vec::new();
    let mut put = |v: f64| {
        if f32_values {
            data.extend((v as f32).to_le_bytes())
        } else {
            data.extend(v.to_le_bytes())
        }
    };
    if fortran {
        chans.iter().flatten().for_each(|&v| put(v));
    } else {
        (0..n).for_each(|i| chans.iter().for_each(|c| put(c[i])));
    }
    npy_file(descr, fortran, &shape, &data, major)
}

/// By hand: the values 1..6 as a (3, 2) float64 array are read row by row in C order
/// (channels [1, 3, 5] and [2, 4, 6]) and column by column in Fortran order ([1, 2, 3] and
/// [4, 5, 6]), in format versions 1 and 2; a (2,) float32 array is one channel; Python 2's
/// `(3L, 2L)` is read; each refusal names its value (an integer or big-endian type, one with
/// control characters, a 3-D array, more columns than rows, more than 1024 channels, data cut
/// short, another magic, an unknown key).
#[test]
fn npy_small_arrays_by_hand() {
    let dir = tmp();
    let p = dir.path().join("h.npy");
    let opts = ReadOptions {
        fs_hz: Some(10.0),
        ..ReadOptions::default()
    };
    let read = |bytes: Vec<u8>| {
        std::fs::write(&p, bytes).unwrap();
        read_path(&p, &opts).map(|r| {
            r.channels
                .into_iter()
                .map(|c| c.samples)
                .collect::<Vec<_>>()
        })
    };
    let vals: Vec<u8> = [1.0f64, 2.0, 3.0, 4.0, 5.0, 6.0]
        .iter()
        .flat_map(|v| v.to_le_bytes())
        .collect();
    for major in [1, 2] {
        let c = read(npy_file("<f8", false, "(3, 2)", &vals, major)).unwrap();
        assert_eq!(c, [vec![1.0, 3.0, 5.0], vec![2.0, 4.0, 6.0]]);
        let f = read(npy_file("<f8", true, "(3, 2)", &vals, major)).unwrap();
        assert_eq!(f, [vec![1.0, 2.0, 3.0], vec![4.0, 5.0, 6.0]]);
    }
    let py2 = read(npy_file("<f8", false, "(3L, 2L)", &vals, 1)).unwrap();
    assert_eq!(py2.len(), 2);
    let one: Vec<u8> = [0.5f32, -1.5]
        .iter()
        .flat_map(|v| v.to_le_bytes())
        .collect();
    assert_eq!(
        read(npy_file("<f4", false, "(2,)", &one, 1)).unwrap(),
        [vec![0.5, -1.5]]
    );
    let msg = |b: Vec<u8>| read(b).unwrap_err().to_string();
    let d8 = vec![0u8; 48];
    assert!(msg(npy_file("<i8", false, "(3, 2)", &d8, 1)).contains("'<i8'"));
    assert!(msg(npy_file(">f8", false, "(3, 2)", &d8, 1)).contains("'>f8'"));
    assert!(msg(npy_file("<f8", false, "(1, 3, 2)", &d8, 1)).contains("(1, 3, 2)"));
    // The file's own text is shown without its control characters (one line).
    let ctl = msg(npy_file("<f\n\x1b8", false, "(3, 2)", &d8, 1));
    assert!(
        ctl.contains("'<f??8'") && !ctl.chars().any(char::is_control),
        "{ctl:?}"
    );
    let t = msg(npy_file("<f8", false, "(2, 3)", &d8, 1));
    assert!(t.contains("3 channels of 2 samples"), "{t}");
    let wide = msg(npy_file("<f8", false, "(2000, 1500)", &d8, 1));
    assert!(wide.contains("1500") && wide.contains("1024"), "{wide}");
    let cut = msg(npy_file("<f8", false, "(3, 2)", &d8[..40], 1));
    assert!(cut.contains("40 bytes"), "{cut}");
    let mut magic = npy_file("<f8", false, "(3, 2)", &d8, 1);
    magic[5] = b'X';
    std::fs::write(&p, &magic).unwrap();
    let e = read_path(&p, &opts).unwrap_err().to_string();
    assert!(e.contains("NUMPY"), "{e}");
    let mut key = npy_file("<f8", false, "(3, 2)", &d8, 1);
    let at = key.windows(7).position(|w| w == b"'shape'").unwrap();
    key[at + 1] = b'x';
    assert!(msg(key).contains("unexpected key 'xhape'"));
}

/// `.npy` files in C and Fortran order, float32 and float64, format versions 1 and 2, 1 to 4
/// channels: the whole-file reader gives the array's values (float32 widened), channels
/// `ch0`, `ch1`, ..., at the given rate, and the stream gives the same at every block size.
#[test]
fn npy_files_read_and_stream_as_their_arrays_over_seeds() {
    let dir = tmp();
    let opts = ReadOptions {
        fs_hz: Some(250.0),
        ..ReadOptions::default()
    };
    for seed in 0..8u64 {
        let n = 500 + 311 * seed as usize;
        let rec = random_recording(seed, n, 1 + (seed as usize % 4), 250.0);
        let chans: Vec<Vec<f64>> = rec.channels.iter().map(|c| c.samples.clone()).collect();
        for (f32_values, fortran, major) in [
            (false, false, 1),
            (true, false, 2),
            (false, true, 1),
            (true, true, 3),
        ] {
            let p = dir
                .path()
                .join(format!("r{seed}_{f32_values}_{fortran}.npy"));
            std::fs::write(&p, npy_bytes(&chans, f32_values, fortran, major)).unwrap();
            let whole = read_path(&p, &opts).unwrap();
            assert_eq!(whole.fs_hz, 250.0);
            let names: Vec<String> = (0..chans.len()).map(|i| format!("ch{i}")).collect();
            assert_eq!(whole.names(), names);
            for (got, want) in whole.channels.iter().zip(&chans) {
                let want: Vec<f64> = if f32_values {
                    want.iter().map(|&v| v as f32 as f64).collect()
                } else {
                    want.clone()
                };
                assert_eq!(
                    got.samples, want,
                    "seed {seed} f32 {f32_values} F {fortran}"
                );
            }
            for block in [1, 7, 256, 100_000] {
                same(&stream_all(&p, &opts, block), &whole);
            }
            // Named by its first bytes too, whatever its extension.
            let q = dir
                .path()
                .join(format!("r{seed}_{f32_values}_{fortran}.array"));
            std::fs::copy(&p, &q).unwrap();
            same(&read_path(&q, &opts).unwrap(), &whole);
        }
    }
}

/// A `.npy` file without a rate, cut short, or of integers is refused by both readers with the
/// value named; its channels take names and units from `<file>.json` as a WAV's do, and its
/// rate that file's `fs_hz` (checked against a given rate); writing `.npy` is refused with the
/// formats that are written.
#[test]
fn npy_refusals_name_the_value() {
    let dir = tmp();
    let chans = vec![vec![1.0; 100], vec![2.0; 100]];
    let p = dir.path().join("a.npy");
    std::fs::write(&p, npy_bytes(&chans, false, false, 1)).unwrap();
    for e in [
        read_path(&p, &ReadOptions::default()).unwrap_err(),
        open_stream(&p, &ReadOptions::default()).unwrap_err(),
    ] {
        assert!(e.to_string().contains("holds no sampling rate"), "{e}");
    }
    let opts = ReadOptions {
        fs_hz: Some(100.0),
        ..ReadOptions::default()
    };
    let mut cut = npy_bytes(&chans, false, false, 1);
    cut.truncate(cut.len() - 8);
    std::fs::write(&p, &cut).unwrap();
    for e in [
        read_path(&p, &opts).unwrap_err(),
        open_stream(&p, &opts).unwrap_err(),
    ] {
        assert!(e.to_string().contains("1592 bytes"), "{e}");
    }
    let mut ints = npy_bytes(&chans, false, false, 1);
    let at = ints.windows(3).position(|w| w == b"<f8").unwrap();
    ints[at + 1] = b'i';
    std::fs::write(&p, &ints).unwrap();
    let e = read_path(&p, &opts).unwrap_err().to_string();
    assert!(e.contains("'<i8'") && e.contains("astype"), "{e}");
    // An array with no samples (`numpy.save(p, np.empty((0, 7)))`), and a raw file with none.
    std::fs::write(&p, npy_file("<f8", false, "(0, 7)", &[], 1)).unwrap();
    for e in [
        read_path(&p, &opts).unwrap_err(),
        open_stream(&p, &opts).unwrap_err(),
    ] {
        let e = e.to_string();
        assert!(e.contains("shape (0, 7) holds no samples"), "{e}");
        assert!(!e.contains("header row"), "{e}");
    }
    let raw = dir.path().join("e.f32");
    std::fs::write(&raw, b"").unwrap();
    std::fs::write(
        dir.path().join("e.f32.json"),
        r#"{"fs_hz": 100, "dtype": "f32", "channels": ["a"]}"#,
    )
    .unwrap();
    for e in [
        read_path(&raw, &ReadOptions::default()).unwrap_err(),
        open_stream(&raw, &ReadOptions::default()).unwrap_err(),
    ] {
        let e = e.to_string();
        assert!(
            e.contains("e.f32 is empty; expected the raw samples"),
            "{e}"
        );
    }
    // Names and units from `<file>.json`, as a WAV's; a list of the wrong length is refused.
    let q = dir.path().join("named.npy");
    std::fs::write(&q, npy_bytes(&chans, true, true, 1)).unwrap();
    let side = dir.path().join("named.npy.json");
    std::fs::write(
        &side,
        r#"{"channels": ["FL_z", "S_FR"], "units": ["g", "m/s^2"]}"#,
    )
    .unwrap();
    let whole = read_path(&q, &opts).unwrap();
    assert_eq!(whole.names(), ["FL_z", "S_FR"]);
    assert_eq!(whole.channels[0].unit, "g");
    same(&stream_all(&q, &opts, 33), &whole);
    std::fs::write(&side, r#"{"channels": ["FL_z"]}"#).unwrap();
    let e = read_path(&q, &opts).unwrap_err().to_string();
    assert!(e.contains("names 1 channels but the file has 2"), "{e}");
    // The rate from the sidecar's `fs_hz` (names then ch0, ch1), checked against a given one.
    std::fs::write(&q, npy_bytes(&chans, false, false, 1)).unwrap();
    std::fs::write(&side, r#"{"fs_hz": 512.5}"#).unwrap();
    let rated = read_path(&q, &ReadOptions::default()).unwrap();
    assert_eq!((rated.fs_hz, rated.names()), (512.5, vec!["ch0", "ch1"]));
    same(&stream_all(&q, &ReadOptions::default(), 64), &rated);
    let e = read_path(&q, &opts).unwrap_err().to_string();
    assert!(e.contains("512.5 Hz but 100 Hz was given"), "{e}");
    std::fs::write(&side, r#"{"fs_hz": "fast"}"#).unwrap();
    for e in [
        read_path(&q, &opts).unwrap_err(),
        open_stream(&q, &opts).unwrap_err(),
    ] {
        assert!(
            e.to_string().contains("must be a positive finite number"),
            "{e}"
        );
    }
    let rec = random_recording(1, 100, 2, 100.0);
    let e = write_path(&dir.path().join("out.npy"), &rec)
        .unwrap_err()
        .to_string();
    assert!(e.contains(".npy is read, not written"), "{e}");
    assert!(!dir.path().join("out.npy").exists());
}

#[test]
fn delimited_time_column_rate_and_nonuniform_interpolation_match_read_path() {
    let dir = tmp();
    let mut r = ChaCha8Rng::seed_from_u64(9);
    for case in 0..4 {
        let mut text = String::from("Time (ms);a [g];b\n");
        let mut t = 5.0;
        for _ in 0..3000 {
            let jitter = if case % 2 == 1 {
                r.gen_range(-0.2..0.2)
            } else {
                0.0
            };
            text.push_str(
                &format!(
                    "{};{};{}\n",
                    t + jitter,
                    r.gen_range(-1.0..1.0),
                    r.gen_range(-1.0..1.0)
                )
                .replace('.', ","),
            );
            t += 2.0;
        }
        let p = dir.path().join(format!("t{case}.csv"));
        std::fs::write(&p, text).unwrap();
        let opts = ReadOptions {
            allow_nonuniform: true,
            ..ReadOptions::default()
        };
        let whole = read_path(&p, &opts).unwrap();
        let s = stream_all(&p, &opts, 333);
        assert!((s.fs_hz - whole.fs_hz).abs() < 1e-12 * whole.fs_hz);
        assert!((whole.fs_hz - 500.0).abs() < 1.0);
        for (x, y) in s.channels.iter().zip(&whole.channels) {
            assert_eq!(x.samples.len(), y.samples.len());
            for (a, b) in x.samples.iter().zip(&y.samples) {
                assert!((a - b).abs() < 1e-12, "{a} vs {b}");
            }
        }
        let info = open_stream(&p, &opts).unwrap().info().clone();
        assert!((info.start_s - 0.005).abs() < 1e-3);
        if case % 2 == 1 {
            let e = open_stream(&p, &ReadOptions::default())
                .unwrap_err()
                .to_string();
            assert!(e.contains("not uniform"), "{e}");
        }
    }
}

/// pandas' `DataFrame.to_csv` writes its row index as an unnamed first column (`Unnamed: 0` once
/// read and written again): not a channel, in the whole-file reader and the stream alike, with or
/// without a time column and a jittery one; a first column that does not count up by one is an
/// error naming its line; a named first column, or one starting elsewhere, stays a channel.
#[test]
fn a_pandas_row_index_is_not_a_channel() {
    let dir = tmp();
    let mut r = ChaCha8Rng::seed_from_u64(31);
    let opts = ReadOptions {
        fs_hz: Some(100.0),
        allow_nonuniform: true,
        ..ReadOptions::default()
    };
    for (case, (head, start, time)) in [
        ("", 0, true),
        ("Unnamed: 0", 0, false),
        ("\"\"", 1, true),
        ("", 0, false),
    ]
    .into_iter()
    .enumerate()
    {
        let mut text = format!("{head},{}a [m/s^2],b\n", if time { "time," } else { "" });
        let n = 2500;
        let mut plain = String::from(if time {
            "time,a [m/s^2],b\n"
        } else {
            "a [m/s^2],b\n"
        });
        for i in 0..n {
            let t = if time {
                let jitter = if case == 2 {
                    r.gen_range(-1e-4..1e-4)
                } else {
                    0.0
                };
                format!("{},", i as f64 * 0.01 + jitter)
            } else {
                String::new()
            };
            let row = format!("{t}{},{}\n", r.gen_range(-1.0..1.0), r.gen_range(-1.0..1.0));
            text.push_str(&format!("{},{row}", i + start));
            plain.push_str(&row);
        }
        let p = dir.path().join(format!("pandas{case}.csv"));
        let q = dir.path().join(format!("plain{case}.csv"));
        std::fs::write(&p, &text).unwrap();
        std::fs::write(&q, &plain).unwrap();
        let expected = read_path(&q, &opts).unwrap();
        let whole = read_path(&p, &opts).unwrap();
        assert_eq!(whole.names(), vec!["a", "b"], "case {case}");
        assert_eq!(whole.channels, expected.channels, "case {case}");
        assert_eq!(whole.fs_hz, expected.fs_hz);
        for block in [1, 7, 1000, 5000] {
            let s = stream_all(&p, &opts, block);
            assert_eq!(s.names(), vec!["a", "b"]);
            assert_eq!(s.channels, expected.channels, "case {case}, block {block}");
        }
        // A skipped count: the error names the line (row 1234 is line 1236) in both readers.
        let broken = text.replacen(&format!("\n{},", 1234 + start), "\n99999,", 1);
        assert_ne!(broken, text);
        std::fs::write(&p, &broken).unwrap();
        let e = read_path(&p, &opts).unwrap_err().to_string();
        assert!(
            e.contains("pandas row index") && e.contains("line 1236"),
            "{e}"
        );
        assert!(e.contains(&format!("not {}", 1234 + start)), "{e}");
        let mut st = open_stream(&p, &opts).unwrap();
        let e = loop {
            match st.next_block(100) {
                Ok(Some(_)) => {}
                Ok(None) => panic!("the stream read a broken row index"),
                Err(e) => break e.to_string(),
            }
        };
        assert!(
            e.contains("pandas row index") && e.contains("line 1236"),
            "{e}"
        );
    }
    // Not a row index: the first column named, or starting at 5, or the only column named.
    for (name, text) in [
        ("named", "idx,a\n0,0.5\n1,0.25\n2,0.125\n"),
        ("five", ",a\n5,0.5\n6,0.25\n7,0.125\n"),
        ("headerless", "0,0.5\n1,0.25\n2,0.125\n"),
        ("others unnamed", ",\"\",a\n0,1,0.5\n1,2,0.25\n2,3,0.125\n"),
    ] {
        let p = dir.path().join(format!("{name}.csv"));
        std::fs::write(&p, text).unwrap();
        let whole = read_path(&p, &opts).unwrap();
        assert_eq!(whole.channels[0].samples.len(), 3, "{name}");
        assert!(whole.channels.len() >= 2, "{name}: {:?}", whole.names());
        assert_eq!(stream_all(&p, &opts, 2).names(), whole.names(), "{name}");
    }
}

/// A time column of date-times (pandas' `DatetimeIndex`, written as an unnamed first column, or a
/// `timestamp` column with an offset): read as seconds from the first row, by the whole-file
/// reader and the stream alike, as the same file with seconds; `--time-unit` does not scale it;
/// a cell that is not a date-time is an error naming its line.
#[test]
fn a_date_time_column_is_the_time() {
    let dir = tmp();
    let mut r = ChaCha8Rng::seed_from_u64(5);
    let n = 4000;
    let rows: Vec<(f64, f64)> = (0..n)
        .map(|_| (r.gen_range(-1.0..1.0), r.gen_range(-1.0..1.0)))
        .collect();
    let mut plain = String::from("time,a,b\n");
    for (i, (a, b)) in rows.iter().enumerate() {
        plain.push_str(&format!("{},{a},{b}\n", i as f64 / 200.0));
    }
    let q = dir.path().join("plain.csv");
    std::fs::write(&q, &plain).unwrap();
    let expected = read_path(&q, &ReadOptions::default()).unwrap();
    // 2026-11-27 23:59:58 plus 5 ms steps: the date changes within the file.
    for (case, head, sep_t, zone) in [
        (0, "", ' ', ""),
        (1, "timestamp", 'T', "+01:00"),
        (2, "Date", ' ', "Z"),
    ] {
        let mut text = format!("{head},a,b\n");
        for (i, (a, b)) in rows.iter().enumerate() {
            let us = i as u64 * 5000;
            let s = 58 + us / 1_000_000;
            let (day, h, m, s) = if s >= 60 {
                (28, 0, 0, s - 60)
            } else {
                (27, 23, 59, s)
            };
            text.push_str(&format!(
                "2026-11-{day}{sep_t}{h:02}:{m:02}:{s:02}.{:06}{zone},{a},{b}\n",
                us % 1_000_000
            ));
        }
        let p = dir.path().join(format!("dt{case}.csv"));
        std::fs::write(&p, &text).unwrap();
        for opts in [
            ReadOptions::default(),
            ReadOptions {
                time_scale_s: Some(1e-3),
                ..ReadOptions::default()
            },
        ] {
            let whole = read_path(&p, &opts).unwrap();
            assert_eq!(whole.names(), vec!["a", "b"], "case {case}");
            assert!(
                (whole.fs_hz - 200.0).abs() < 1e-9,
                "case {case}: {}",
                whole.fs_hz
            );
            assert_eq!(whole.channels, expected.channels);
            let axis = whole.time_axis.as_ref().unwrap();
            assert_eq!(axis.start_s, 0.0);
            // 2026-11-27 is day 20784 after 1970-01-01; 23:59:58 UTC, or local at +01:00.
            let start = 20784.0 * 86400.0 + 86398.0 - if case == 1 { 3600.0 } else { 0.0 };
            assert_eq!(axis.start_unix_s(), Some(start), "case {case}");
            for block in [3, 1000] {
                let s = stream_all(&p, &opts, block);
                assert_eq!(s.fs_hz, whole.fs_hz);
                assert_eq!(s.channels, expected.channels, "case {case}, block {block}");
            }
        }
        let broken = text.replacen("\n2026-11-28", "\n2026-13-28", 1);
        assert_ne!(broken, text);
        std::fs::write(&p, &broken).unwrap();
        let e = read_path(&p, &ReadOptions::default())
            .unwrap_err()
            .to_string();
        // Row 400 (2 s after 23:59:58) is line 402.
        assert!(e.contains("line 402") && e.contains("2026-13-28"), "{e}");
    }
    // MATLAB's writetable of a timetable with row times seconds(...): `0.005 sec`; and in ms.
    for (case, unit, per_s) in [(0, "sec", 1.0), (1, "ms", 1e3)] {
        let mut text = String::from("Time,a,b\n");
        for (i, (a, b)) in rows.iter().enumerate() {
            text.push_str(&format!("{} {unit},{a},{b}\n", i as f64 / 200.0 * per_s));
        }
        let p = dir.path().join(format!("matlab{case}.csv"));
        std::fs::write(&p, &text).unwrap();
        let whole = read_path(&p, &ReadOptions::default()).unwrap();
        assert_eq!(whole.names(), vec!["a", "b"]);
        assert!((whole.fs_hz - 200.0).abs() < 1e-9, "{}", whole.fs_hz);
        assert_eq!(whole.channels, expected.channels);
        let s = stream_all(&p, &ReadOptions::default(), 777);
        assert_eq!(s.channels, expected.channels);
        // Row 10 is line 12.
        let row10 = format!("\n{} {unit},", 10.0 / 200.0 * per_s);
        let broken = text.replacen(&row10, &format!("\nten {unit},"), 1);
        assert_ne!(broken, text);
        std::fs::write(&p, &broken).unwrap();
        let e = read_path(&p, &ReadOptions::default())
            .unwrap_err()
            .to_string();
        assert!(e.contains("line 12") && e.contains("ten"), "{e}");
    }
}

#[test]
fn channel_selection_and_start_time_from_the_sidecar() {
    let dir = tmp();
    let rec = random_recording(3, 500, 3, 200.0);
    let p = dir.path().join("s.f32");
    write_path(&p, &rec).unwrap();
    let side = dir.path().join("s.f32.json");
    let mut v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&side).unwrap()).unwrap();
    v["start_time"] = "2024-05-02T07:31:00Z".into();
    std::fs::write(&side, v.to_string()).unwrap();
    let mut s = open_stream(&p, &ReadOptions::default()).unwrap();
    assert_eq!(s.info().start_time.as_deref(), Some("2024-05-02T07:31:00Z"));
    s.select(&[
        ChannelSelector::Name("c2".into()),
        ChannelSelector::Index(0),
    ])
    .unwrap();
    let got = s.read_to_recording().unwrap();
    let want = read_path(&p, &ReadOptions::default()).unwrap();
    assert_eq!(got.names(), ["c2", "c0"]);
    assert_eq!(got.channels[0].samples, want.channels[2].samples);
    assert_eq!(got.channels[1].samples, want.channels[0].samples);
    let mut s = open_stream(&p, &ReadOptions::default()).unwrap();
    let e = s
        .select(&[ChannelSelector::Name("zz".into())])
        .unwrap_err()
        .to_string();
    assert!(e.contains("zz") && e.contains("c0"), "{e}");
}

#[test]
fn cut_off_files_are_refused_with_one_line_naming_the_size_and_the_fix() {
    let dir = tmp();
    let rec = random_recording(4, 1000, 3, 1000.0);
    let p = dir.path().join("cut.f32");
    write_path(&p, &rec).unwrap();
    let bytes = std::fs::read(&p).unwrap();
    std::fs::write(&p, &bytes[..bytes.len() - 5]).unwrap();
    let e = open_stream(&p, &ReadOptions::default())
        .unwrap_err()
        .to_string();
    assert!(!e.contains('\n'));
    assert!(
        e.contains("11995 bytes")
            && e.contains("12-byte frames")
            && e.contains("truncate -s 11988"),
        "{e}"
    );
    // A WAV whose data chunk is cut off: the header announces more than the file holds.
    let w = dir.path().join("cut.wav");
    write_path(&w, &rec).unwrap();
    let bytes = std::fs::read(&w).unwrap();
    std::fs::write(&w, &bytes[..bytes.len() - 1000]).unwrap();
    let mut s = open_stream(&w, &ReadOptions::default()).unwrap();
    let mut err = None;
    loop {
        match s.next_block(100) {
            Ok(Some(_)) => {}
            Ok(None) => break,
            Err(e) => {
                err = Some(e.to_string());
                break;
            }
        }
    }
    let e = err.expect("a cut-off WAV must fail");
    assert!(!e.contains('\n') && e.contains("cut off"), "{e}");
    // Non-finite samples name channel and frame.
    let mut bad = rec.clone();
    bad.channels[1].samples[777] = 0.0;
    let q = dir.path().join("nan.f64");
    write_path(&q, &bad).unwrap();
    let mut raw = std::fs::read(&q).unwrap();
    let at = (777 * 3 + 1) * 8;
    raw[at..at + 8].copy_from_slice(&f64::NAN.to_le_bytes());
    std::fs::write(&q, raw).unwrap();
    let mut s = open_stream(&q, &ReadOptions::default()).unwrap();
    let e = loop {
        match s.next_block(100) {
            Ok(Some(_)) => {}
            Ok(None) => panic!("NaN not found"),
            Err(e) => break e.to_string(),
        }
    };
    assert!(e.contains("c1") && e.contains("777"), "{e}");
}

#[test]
fn design_hand_checks() {
    assert_eq!(bessel_i0(0.0), 1.0);
    assert!((bessel_i0(1.0) - 1.266_065_877_752_008_4).abs() < 1e-15);
    assert!((kaiser_beta(110.0) - 0.1102 * 101.3).abs() < 1e-12);
    assert_eq!(rational_ratio(0.01, 1024), Some((1, 100)));
    assert_eq!(rational_ratio(200.0 / 44100.0, 1024), Some((2, 441)));
    assert_eq!(rational_ratio(3.0, 1024), Some((3, 1)));
    assert_eq!(rational_ratio(50.0 / 425.0803, 1024), None);
    let d = FirDesign::new(20_000.0, &StreamResampleParams::default()).unwrap();
    assert_eq!((d.up, d.down), (1, 100));
    assert_eq!((d.pass_hz, d.stop_hz), (80.0, 100.0));
    // N = (110 - 7.95) / (2.285 * 2 pi 20 / 20000) + 1 = 7108.x + 1, rounded up to odd.
    assert_eq!(d.n_taps, 7109);
    let h = d.taps();
    assert!((h.iter().sum::<f64>() - 1.0).abs() < 1e-12);
    for k in 0..h.len() / 2 {
        assert_eq!(h[k], h[h.len() - 1 - k]);
    }
    let e = FirDesign::new(
        20_000.0,
        &StreamResampleParams {
            cutoff_hz: Some(100.0),
            ..Default::default()
        },
    )
    .unwrap_err()
    .to_string();
    assert!(
        e.contains("cutoff_hz = 100") && e.contains("Nyquist"),
        "{e}"
    );
}

/// |H(f)| of the taps at the up-sampled rate.
fn response(h: &[f64], f_rel: f64) -> f64 {
    let (mut re, mut im) = (0.0, 0.0);
    for (k, v) in h.iter().enumerate() {
        let w = 2.0 * std::f64::consts::PI * f_rel * k as f64;
        re += v * w.cos();
        im -= v * w.sin();
    }
    (re * re + im * im).sqrt()
}

#[test]
fn pass_band_flat_to_1e_5_and_stop_band_below_minus_100_db() {
    for (fs, to, cutoff) in [
        (20_000.0, 200.0, None),
        (20_000.0, 200.0, Some(25.0)),
        (44_100.0, 200.0, None),
        (500.0, 50.0, None),
    ] {
        let d = FirDesign::new(
            fs,
            &StreamResampleParams {
                fs_out_hz: to,
                cutoff_hz: cutoff,
                ..Default::default()
            },
        )
        .unwrap();
        let h = d.taps();
        let fs_up = fs * d.up as f64;
        let mut worst_pass = 0.0f64;
        let mut worst_stop = 0.0f64;
        for i in 0..=200 {
            let f = d.pass_hz * i as f64 / 200.0;
            worst_pass = worst_pass.max((response(&h, f / fs_up) - 1.0).abs());
        }
        // The stop band up to a few times the output rate, and a sample beyond.
        for i in 0..=400 {
            let f = d.stop_hz + (4.0 * to) * i as f64 / 400.0;
            worst_stop = worst_stop.max(response(&h, f / fs_up));
        }
        for i in 0..=100 {
            let f = d.stop_hz + (fs_up / 2.0 - d.stop_hz) * i as f64 / 100.0;
            worst_stop = worst_stop.max(response(&h, f / fs_up));
        }
        assert!(
            worst_pass < 1e-5,
            "{fs}->{to}: pass-band deviation {worst_pass}"
        );
        assert!(
            20.0 * worst_stop.log10() < -100.0,
            "{fs}->{to}: stop band {} dB",
            20.0 * worst_stop.log10()
        );
    }
}

/// Tones on DFT bins of the record (so the ideal filter is exact): some in the pass band, some
/// in the stop band up to the input Nyquist.
fn tones(seed: u64, n: usize, fs: f64, pass: f64, stop: f64) -> Vec<f64> {
    let mut r = ChaCha8Rng::seed_from_u64(seed);
    let df = fs / n as f64;
    let mut x = vec![0.0; n];
    for k in 0..12 {
        let f = if k < 6 {
            r.gen_range(0.5..pass)
        } else {
            r.gen_range(stop..fs / 2.0 - 1.0)
        };
        let bin = (f / df).round();
        let (a, ph) = (
            r.gen_range(0.1..2.0),
            r.gen_range(0.0..std::f64::consts::TAU),
        );
        for (i, v) in x.iter_mut().enumerate() {
            *v += a * (2.0 * std::f64::consts::PI * bin * i as f64 / n as f64 + ph).cos();
        }
    }
    x
}

#[test]
fn agrees_with_the_whole_record_ideal_filter_away_from_the_ends_over_seeds() {
    let fs = 20_000.0;
    let n = 200_000; // 10 s
    let p = StreamResampleParams {
        fs_out_hz: 200.0,
        ..Default::default()
    };
    let mut worst_db = f64::NEG_INFINITY;
    for seed in 0..5u64 {
        let x = tones(seed, n, fs, 75.0, 105.0);
        let ideal = resample(
            &x,
            fs,
            &ResampleParams {
                fs_out_hz: 200.0,
                cutoff_hz: Some(90.0),
                filter: true,
            },
        )
        .unwrap();
        let mut fir = FirDecimator::new(fs, 1, &p).unwrap();
        let mut out = Vec::new();
        for chunk in x.chunks(9_973) {
            out.extend(fir.process(&[chunk.to_vec()]).unwrap().remove(0));
        }
        out.extend(fir.finish().remove(0));
        assert_eq!(out.len(), ideal.len());
        let edge = (fir.design().edge_s() * 200.0).ceil() as usize + 1;
        let rms = (ideal.iter().map(|v| v * v).sum::<f64>() / ideal.len() as f64).sqrt();
        let err = out[edge..out.len() - edge]
            .iter()
            .zip(&ideal[edge..ideal.len() - edge])
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        let db = 20.0 * (err / rms).log10();
        worst_db = worst_db.max(db);
    }
    eprintln!("worst max-error / rms over 5 seeds: {worst_db:.1} dB");
    assert!(worst_db < -100.0, "{worst_db} dB");
}

#[test]
fn output_does_not_depend_on_block_sizes_and_has_ceil_n_l_over_m_samples() {
    let fs = 44_100.0;
    let x = random_recording(1, 30_011, 2, fs);
    let p = StreamResampleParams {
        fs_out_hz: 200.0,
        ..Default::default()
    };
    let run = |block: usize| {
        let mut f = FirDecimator::new(fs, 2, &p).unwrap();
        let mut out = vec![Vec::new(); 2];
        let n = x.len();
        let mut i = 0;
        while i < n {
            let j = (i + block).min(n);
            let b: Vec<Vec<f64>> = x
                .channels
                .iter()
                .map(|c| c.samples[i..j].to_vec())
                .collect();
            for (o, v) in out.iter_mut().zip(f.process(&b).unwrap()) {
                o.extend(v);
            }
            i = j;
        }
        for (o, v) in out.iter_mut().zip(f.finish()) {
            o.extend(v);
        }
        out
    };
    let a = run(30_011);
    assert_eq!(a[0].len(), (30_011usize * 2).div_ceil(441));
    for block in [1, 441, 5000] {
        assert_eq!(run(block), a);
    }
}

#[test]
fn resampler_kind_auto_streams_only_large_filtered_inputs() {
    use vibmode_signal::ResamplerKind;
    let big = Some(ResamplerKind::AUTO_IDEAL_MAX_BYTES + 1);
    let small = Some(ResamplerKind::AUTO_IDEAL_MAX_BYTES);
    assert!(ResamplerKind::Auto.streams(big, true));
    assert!(!ResamplerKind::Auto.streams(small, true));
    assert!(!ResamplerKind::Auto.streams(big, false));
    assert!(!ResamplerKind::Auto.streams(None, true));
    assert!(ResamplerKind::Fir.streams(small, true));
    assert!(!ResamplerKind::Ideal.streams(big, true));
    for name in ResamplerKind::NAMES {
        assert!(name.parse::<ResamplerKind>().is_ok(), "{name}");
    }
    let e = "sinc".parse::<ResamplerKind>().unwrap_err().to_string();
    assert!(
        e.contains("'sinc'") && e.contains("auto, ideal, fir"),
        "{e}"
    );
}

/// The first error of reading `p` by the whole-file reader and by the stream (blocks of 100
/// rows), which must agree.
fn errors_of_both_readers(p: &Path, opts: &ReadOptions) -> String {
    let whole = read_path(p, opts).unwrap_err().to_string();
    let streamed = match open_stream(p, opts) {
        Err(e) => e.to_string(),
        Ok(mut st) => loop {
            match st.next_block(100) {
                Ok(Some(_)) => {}
                Ok(None) => panic!("{}: the stream read it", p.display()),
                Err(e) => break e.to_string(),
            }
        },
    };
    assert_eq!(whole, streamed, "{}", p.display());
    assert!(!whole.contains('\n'), "{whole}");
    whole
}

/// A missing value (an empty cell: pandas writes NaN so) is named as one, with its line and
/// column, wherever it is in the row, with each separator; not as a short row or as "'' is
/// not a number". A trailing separator on every row is still no missing value.
#[test]
fn a_missing_value_is_named_as_an_empty_cell() {
    let dir = tmp();
    let opts = ReadOptions::default();
    for (sep, name) in [(",", "comma"), (";", "semicolon"), ("\t", "tab")] {
        for (col, colname) in [(1, "time"), (2, "a"), (3, "b")] {
            let mut text = format!("time{sep}a{sep}b\n");
            for i in 0..300 {
                let mut cells: [String; 3] =
                    [format!("{}", i as f64 / 100.0), "1".into(), "2".into()];
                if i == 250 {
                    cells[col - 1].clear();
                }
                text.push_str(&cells.join(sep));
                text.push('\n');
            }
            let p = dir.path().join(format!("{name}{col}.csv"));
            std::fs::write(&p, &text).unwrap();
            let e = errors_of_both_readers(&p, &opts);
            // Row 250 is line 252.
            assert!(
                e.contains(&format!("line 252, column {col} ('{colname}')"))
                    && e.contains("is empty")
                    && e.contains("missing value"),
                "{name} {col}: {e}"
            );
        }
    }
    // pandas' own NaN, written by `to_csv(index=False)`: `0.03,,2.5` and `0.04,1.5,`.
    let p = dir.path().join("pandas.csv");
    std::fs::write(&p, "time,a,b\n0.0,1.0,2.0\n0.01,1.5,2.5\n0.02,,2.5\n").unwrap();
    let e = errors_of_both_readers(&p, &opts);
    assert!(e.contains("line 4, column 2 ('a')"), "{e}");
    // A trailing separator on every row: three columns, no missing value.
    let p = dir.path().join("trailing.csv");
    std::fs::write(&p, "time,a,b,\n0,1,2,\n0.01,1,2,\n0.02,1,2,\n").unwrap();
    let rec = read_path(&p, &opts).unwrap();
    assert_eq!(rec.names(), vec!["a", "b"]);
    // A row that is short without empty cells stays a short row.
    let p = dir.path().join("short.csv");
    std::fs::write(&p, "time,a,b\n0,1,2\n0.01,1\n0.02,1,2\n").unwrap();
    let e = errors_of_both_readers(&p, &opts);
    assert!(
        e.contains("line 3 of") && e.contains("has 2 columns but 3"),
        "{e}"
    );
}

/// Binary formats users have (workbooks, MAT-files, HDF5, Parquet, TDMS, compressed files) are
/// named by what they are, with the export that makes them readable, in one line; other binary
/// bytes keep the generic message.
#[test]
fn binary_formats_are_named_with_their_export() {
    let dir = tmp();
    // A ZIP local header (30 bytes) whose first entry is `name`.
    let zip = |name: &str| {
        let mut b = b"PK\x03\x04".to_vec();
        b.extend_from_slice(&[0u8; 22]);
        b.extend_from_slice(&(name.len() as u16).to_le_bytes());
        b.extend_from_slice(&[0, 0]);
        b.extend_from_slice(name.as_bytes());
        b.extend_from_slice(&[0u8; 40]);
        b
    };
    let mut mat = b"MATLAB 5.0 MAT-file, Platform: GLNXA64, Created on: Fri Nov 27 2026".to_vec();
    mat.extend_from_slice(&[0u8; 60]);
    let cases: [(&str, Vec<u8>, &str, &str); 11] = [
        (
            "book.xlsx",
            zip("[Content_Types].xml"),
            "spreadsheet workbook",
            "CSV UTF-8",
        ),
        (
            "book.txt",
            zip("xl/workbook.xml"),
            "spreadsheet workbook",
            "read_excel",
        ),
        (
            "sheet.ods",
            zip("mimetype"),
            "spreadsheet workbook",
            "Text CSV",
        ),
        (
            "renamed.xlsx",
            zip("a.txt"),
            "spreadsheet workbook",
            "CSV UTF-8",
        ),
        ("records.zip", zip("rec01.csv"), "ZIP archive", "unzip"),
        (
            "old.xls",
            b"\xD0\xCF\x11\xE0\xA1\xB1\x1A\xE1\0\0\0\0".to_vec(),
            "97-2003",
            "CSV UTF-8",
        ),
        ("run.mat", mat, "MATLAB MAT-file", "writetable"),
        (
            "run73.mat",
            b"\x89HDF\r\n\x1a\n\0\0\0\0".to_vec(),
            "HDF5",
            "writetable",
        ),
        (
            "df.parquet",
            b"PAR1\x15\x04\x15".to_vec(),
            "Parquet",
            "read_parquet",
        ),
        ("log.tdms", b"TDSm\x0e\0\0\0".to_vec(), "TDMS", "CSV"),
        (
            "rec.csv.gz",
            b"\x1f\x8b\x08\0\0\0\0\0".to_vec(),
            "gzip",
            "gunzip",
        ),
    ];
    let opts = ReadOptions::default();
    for (name, bytes, what, fix) in cases {
        let p = dir.path().join(name);
        std::fs::write(&p, &bytes).unwrap();
        let e = errors_of_both_readers(&p, &opts);
        assert!(
            e.contains(name)
                && e.contains(what)
                && e.contains(fix)
                && e.contains("not delimited text"),
            "{name}: {e}"
        );
    }
    // Unknown binary bytes: the generic message.
    let p = dir.path().join("noise.dat");
    std::fs::write(&p, b"\x00\x01\x02\x03binary").unwrap();
    let e = errors_of_both_readers(&p, &opts);
    assert!(e.contains("is not a text file"), "{e}");
}

/// A units row below the header (data loggers' exports: `s,m/s^2`, or `[ms];[g]`) gives the
/// channels their units and the time column its unit; both readers read it as the same file
/// with the units in the header. A units row whose time cell is not a time unit is data, and an
/// error names it.
#[test]
fn a_units_row_below_the_header_gives_the_units() {
    let dir = tmp();
    let mut r = ChaCha8Rng::seed_from_u64(77);
    let opts = ReadOptions::default();
    let n = 1500;
    let rows: Vec<(f64, f64)> = (0..n)
        .map(|_| (r.gen_range(-1.0..1.0), r.gen_range(-1.0..1.0)))
        .collect();
    for (case, header, units, sep, step, unit_a, unit_b) in [
        ("plain", "time,a,b", "s,m/s^2,g", ",", 0.005, "m/s^2", "g"),
        (
            "brackets",
            "Time;a;b",
            "[ms];[g];(m/s2)",
            ";",
            5.0,
            "g",
            "m/s2",
        ),
        (
            "header wins",
            "t,a [m/s^2],b",
            "s,g,mg",
            ",",
            0.005,
            "m/s^2",
            "mg",
        ),
        ("empty cell", "time\ta\tb", "s\t\tg", "\t", 0.005, "", "g"),
    ] {
        let mut with_units = format!("{header}\n{units}\n");
        let mut expected_text = String::from("time,a,b\n");
        for (i, (a, b)) in rows.iter().enumerate() {
            let t = i as f64 * step;
            with_units.push_str(&format!("{t}{sep}{a}{sep}{b}\n"));
            expected_text.push_str(&format!("{},{a},{b}\n", i as f64 * 0.005));
        }
        let p = dir.path().join(format!("{case}.csv"));
        let q = dir.path().join(format!("{case}-expected.csv"));
        std::fs::write(&p, &with_units).unwrap();
        std::fs::write(&q, &expected_text).unwrap();
        let expected = read_path(&q, &opts).unwrap();
        let whole = read_path(&p, &opts).unwrap();
        assert_eq!(whole.names(), vec!["a", "b"], "{case}");
        assert!(
            (whole.fs_hz - 200.0).abs() < 1e-9,
            "{case}: {}",
            whole.fs_hz
        );
        let units: Vec<&str> = whole.channels.iter().map(|c| c.unit.as_str()).collect();
        assert_eq!(units, vec![unit_a, unit_b], "{case}");
        let samples = |rec: &Recording| -> Vec<Vec<f64>> {
            rec.channels.iter().map(|c| c.samples.clone()).collect()
        };
        assert_eq!(samples(&whole), samples(&expected), "{case}");
        for block in [1, 64, 5000] {
            let s = stream_all(&p, &opts, block);
            assert_eq!(samples(&s), samples(&expected), "{case}, block {block}");
            let su: Vec<&str> = s.channels.iter().map(|c| c.unit.as_str()).collect();
            assert_eq!(su, units, "{case}, block {block}");
        }
    }
    // Not a units row: `g` is no time unit, so the row is data and is refused as such.
    let p = dir.path().join("not-units.csv");
    std::fs::write(&p, "time,a\ng,g\n0,1\n0.01,2\n").unwrap();
    let e = errors_of_both_readers(&p, &opts);
    assert!(
        e.contains("line 2, column 1 ('time')") && e.contains("'g'"),
        "{e}"
    );
}

/// A split date and time (`Date,Time`, as data loggers and Excel write them) and a time of day
/// alone (`Time` = `23:59:59.995`) are the time: read by both readers as the same samples at
/// the same rate as a file with seconds, across midnight (the date changes, or the time of day
/// starts again from 0); the date is no channel, and with it the first sample's absolute time is
/// known.
#[test]
fn a_split_date_and_time_or_a_time_of_day_is_the_time() {
    let dir = tmp();
    let mut r = ChaCha8Rng::seed_from_u64(9);
    let opts = ReadOptions::default();
    let n = 3000;
    let rows: Vec<(f64, f64)> = (0..n)
        .map(|_| (r.gen_range(-1.0..1.0), r.gen_range(-1.0..1.0)))
        .collect();
    let mut plain = String::from("time,a,b\n");
    for (i, (a, b)) in rows.iter().enumerate() {
        plain.push_str(&format!("{},{a},{b}\n", i as f64 / 200.0));
    }
    let q = dir.path().join("plain.csv");
    std::fs::write(&q, &plain).unwrap();
    let expected = read_path(&q, &ReadOptions::default()).unwrap();
    // From 2026-11-27 23:59:55 at 5 ms steps: midnight after 1000 rows.
    let start_s = 86_395.0;
    let clock = |i: usize| {
        let ms = (start_s * 1000.0) as u64 + 5 * i as u64;
        let (day, ms) = (ms / 86_400_000, ms % 86_400_000);
        let s = format!(
            "{:02}:{:02}:{:02}.{:03}",
            ms / 3_600_000,
            ms / 60_000 % 60,
            ms / 1000 % 60,
            ms % 1000
        );
        (day, s)
    };
    // A 24-hour time of day on a 12-hour clock: 23:59:55.000 -> 11:59:55.000 PM.
    let twelve_hour = |hms: &str| {
        let h: u32 = hms[..2].parse().unwrap();
        let (h12, half) = match h {
            0 => (12, "AM"),
            1..=11 => (h, "AM"),
            12 => (12, "PM"),
            _ => (h - 12, "PM"),
        };
        format!("{h12}{} {half}", &hms[2..])
    };
    // (case, header, separator, the dates of the two days, what joins date and time, a 12-hour
    // clock, whether the absolute start is known)
    for (case, header, sep, date_of, glue, twelve, known) in [
        (
            "iso",
            "Date,Time,a,b",
            ",",
            Some(["2026-11-27", "2026-11-28"]),
            ",",
            false,
            true,
        ),
        (
            "european",
            "Datum;Zeit;a;b",
            ";",
            Some(["27.11.2026", "28.11.2026"]),
            ";",
            false,
            true,
        ),
        (
            "european one cell",
            "Zeitstempel;a;b",
            ";",
            Some(["27.11.2026", "28.11.2026"]),
            " ",
            false,
            true,
        ),
        ("time of day", "Time,a,b", ",", None, ",", false, false),
        // Slash dates: the order of day and month from a part above 12.
        (
            "us split",
            "Date,Time,a,b",
            ",",
            Some(["11/27/2026", "11/28/2026"]),
            ",",
            true,
            true,
        ),
        (
            "uk split",
            "Date,Time,a,b",
            ",",
            Some(["27/11/2026", "28/11/2026"]),
            ",",
            false,
            true,
        ),
        (
            "us one cell",
            "timestamp,a,b",
            ",",
            Some(["11/27/2026", "11/28/2026"]),
            " ",
            false,
            true,
        ),
        (
            "uk one cell 12 h",
            "Timestamp,a,b",
            ",",
            Some(["27/11/2026", "28/11/2026"]),
            " ",
            true,
            true,
        ),
        // 5 November or May 11: the times of day are read, the absolute start is unknown.
        (
            "undecided split",
            "Date,Time,a,b",
            ",",
            Some(["05/11/2026", "06/11/2026"]),
            ",",
            false,
            false,
        ),
        (
            "undecided one cell",
            "timestamp,a,b",
            ",",
            Some(["05/11/2026", "06/11/2026"]),
            " ",
            true,
            false,
        ),
    ] {
        let mut text = format!("{header}\n");
        for (i, (a, b)) in rows.iter().enumerate() {
            let (day, hms) = clock(i);
            let hms = if twelve { twelve_hour(&hms) } else { hms };
            // Decimal commas in the times too where the separator is a semicolon.
            let hms = if sep == ";" {
                hms.replace('.', ",")
            } else {
                hms
            };
            let (a, b) = if sep == ";" {
                (
                    a.to_string().replace('.', ","),
                    b.to_string().replace('.', ","),
                )
            } else {
                (a.to_string(), b.to_string())
            };
            match date_of {
                Some(dates) => text.push_str(&format!(
                    "{}{glue}{hms}{sep}{a}{sep}{b}\n",
                    dates[day as usize]
                )),
                None => text.push_str(&format!("{hms}{sep}{a}{sep}{b}\n")),
            }
        }
        let p = dir.path().join(format!("{}.csv", case.replace(' ', "_")));
        std::fs::write(&p, &text).unwrap();
        let whole = read_path(&p, &opts).unwrap();
        assert_eq!(whole.names(), vec!["a", "b"], "{case}");
        assert_eq!(whole.channels, expected.channels, "{case}");
        assert!(
            (whole.fs_hz - 200.0).abs() < 1e-6,
            "{case}: {}",
            whole.fs_hz
        );
        let axis = whole.time_axis.clone().unwrap();
        // A date-time in one cell counts from its first row; times of day from midnight.
        let first_s = if case == "european one cell" {
            0.0
        } else {
            start_s
        };
        assert!((axis.start_s - first_s).abs() < 1e-9, "{case}");
        let start = axis.start_unix_s();
        if known {
            // 2026-11-27 23:59:55 UTC: 20784 days and 86 395 s after 1970-01-01.
            assert_eq!(start, Some(20784.0 * 86_400.0 + 86_395.0), "{case}");
        } else {
            assert_eq!(start, None, "{case}");
        }
        for block in [1, 7, 999, 1000, 5000] {
            let s = stream_all(&p, &opts, block);
            assert_eq!(s.names(), vec!["a", "b"], "{case}, block {block}");
            assert_eq!(s.channels, expected.channels, "{case}, block {block}");
        }
    }
}

#[test]
fn summaries_match_the_whole_files_statistics_over_seeds() {
    // `summarize` (one streamed pass, blocks of 65 536 frames merged by Chan's update) against
    // two-pass statistics of the file read whole, over seeds, lengths across the block size,
    // offsets that make a naive sum of squares cancel, and every format vibmode writes.
    let dir = tmp();
    let (mut clipped, mut held) = (0, 0);
    for seed in 0..12u64 {
        let mut r = ChaCha8Rng::seed_from_u64(1000 + seed);
        let n = [2usize, 3, 65_535, 65_536, 65_537, 150_001][seed as usize % 6];
        let mut rec = random_recording(seed, n, 1 + seed as usize % 4, 250.0);
        let offset = [0.0, 1e6, -3.5e3][seed as usize % 3];
        for ch in &mut rec.channels {
            for v in &mut ch.samples {
                *v += offset + r.gen_range(-1.0..1.0);
            }
        }
        // A clipped channel, and one with a held stretch across the 65 536-frame blocks.
        if n > 100 {
            let c0 = &mut rec.channels[0].samples;
            match seed % 4 {
                1 => c0.iter_mut().for_each(|v| *v = v.min(offset + 2.0)),
                2 => {
                    let a = n / 2 - n.min(300) / 3;
                    let held = c0[a];
                    c0[a..a + n.min(300) / 2].iter_mut().for_each(|v| *v = held);
                }
                _ => {}
            }
        }
        let ext = ["csv", "f64", "wav"][seed as usize % 3];
        let p = dir.path().join(format!("s{seed}.{ext}"));
        write_path(&p, &rec).unwrap();
        let whole = read_path(&p, &ReadOptions::default()).unwrap();
        let s = vibmode_signal::summarize(&p, &ReadOptions::default()).unwrap();
        assert_eq!(s.frames as usize, whole.len(), "{ext} {n}");
        assert_eq!(s.fs_hz, whole.fs_hz);
        assert!((s.duration_s - n as f64 / 250.0).abs() < 1e-12);
        assert_eq!(s.channels.len(), whole.channels.len());
        for (c, w) in s.channels.iter().zip(&whole.channels) {
            let x = &w.samples;
            let m = x.iter().sum::<f64>() / x.len() as f64;
            let var = x.iter().map(|v| (v - m) * (v - m)).sum::<f64>() / x.len() as f64;
            let ms = x.iter().map(|v| v * v).sum::<f64>() / x.len() as f64;
            let min = x.iter().cloned().fold(f64::INFINITY, f64::min);
            let max = x.iter().cloned().fold(f64::NEG_INFINITY, f64::max);
            assert_eq!((c.name.as_str(), c.min, c.max), (w.name.as_str(), min, max));
            let scale = m.abs().max(1.0);
            assert!(
                (c.mean - m).abs() <= 1e-12 * scale,
                "{ext}: {} vs {m}",
                c.mean
            );
            assert!(
                (c.std - var.sqrt()).abs() <= 1e-9 * var.sqrt().max(1e-300) + 1e-12,
                "{ext} offset {offset}: std {} vs {}",
                c.std,
                var.sqrt()
            );
            assert!((c.rms - ms.sqrt()).abs() <= 1e-12 * ms.sqrt(), "{ext}");
            assert_eq!(c.constant, None, "{ext} n {n}");
            // The sensor checks are the analysis's, on the whole channel.
            let h = vibmode_core::stats::channel_health(
                x,
                vibmode_core::stats::held_min_run(whole.fs_hz),
            );
            assert_eq!(
                (c.clipped_samples, c.clipped_value),
                h.clipped.map_or((0, None), |(k, v)| (k, Some(v))),
                "{ext} seed {seed}"
            );
            assert_eq!(
                (c.held_samples, c.held_stretches, c.held_longest),
                h.held,
                "{ext} seed {seed}"
            );
            clipped += usize::from(c.clipped_value.is_some());
            held += usize::from(c.held_stretches > 0);
        }
    }
    // The clipped and held channels made above were found (seeds 5, 9 and 2, 10).
    assert_eq!((clipped, held), (2, 2));
    // A dead channel (all 0) and a stuck one (all 2.5) are marked, a live one is not.
    let rec = Recording {
        fs_hz: 100.0,
        channels: vec![
            Channel::new("dead", "", vec![0.0; 300]),
            Channel::new("stuck", "", vec![2.5; 300]),
            Channel::new("live", "", (0..300).map(|i| i as f64).collect()),
        ],
        time_axis: None,
    };
    let p = dir.path().join("health.f64");
    write_path(&p, &rec).unwrap();
    let s = vibmode_signal::summarize(&p, &ReadOptions::default()).unwrap();
    let c: Vec<Option<f64>> = s.channels.iter().map(|c| c.constant).collect();
    assert_eq!(c, [Some(0.0), Some(2.5), None]);
    let text = s.to_string();
    assert!(text.contains("all 0: a dead sensor"), "{text}");
    assert!(text.contains("constant 2.500: a stuck sensor"), "{text}");
    assert!(
        text.contains(
            "health.f64: raw samples with a sidecar, 3 channels, 300 frames at 100 Hz (3 s)"
        ),
        "{text}"
    );
    // By hand: 0..299 has mean 149.5, population std sqrt((300^2 - 1) / 12) = 86.60 and rms
    // sqrt(299 * 599 / 6) = 172.8.
    assert!(
        text.contains(
            "  live                     0       299.0       149.5       86.60       172.8"
        ),
        "{text}"
    );
    // Refusals are the readers': a NaN names its channel.
    let bad = dir.path().join("nan.csv");
    std::fs::write(&bad, "time_s,a\n0,1\n0.01,nan\n0.02,3\n").unwrap();
    let e = vibmode_signal::summarize(&bad, &ReadOptions::default())
        .unwrap_err()
        .to_string();
    assert!(e.contains("nan.csv: channel 'a' sample 1 is NaN"), "{e}");
}
