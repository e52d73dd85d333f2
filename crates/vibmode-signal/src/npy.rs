//! NumPy's `.npy` files (`numpy.save`): a 1-D array of samples or a 2-D array of samples by
//! channels, little-endian `float32` or `float64`, in C or Fortran order.
//!
//! The format (NumPy's NEP 1, versions 1.0, 2.0 and 3.0): the magic `\x93NUMPY`, two version
//! bytes, the header's length (2 bytes little-endian in version 1, 4 bytes in 2 and 3), then the
//! header, a Python dict literal with the keys `descr`, `fortran_order` and `shape`, padded with
//! spaces and ended by a newline; the data follows. The header is parsed here (three keys of
//! fixed kinds) rather than by a crate that brings a whole Python-literal grammar.

use crate::error::{io_err, NpyProblem, Result, SidecarProblem, SignalError};
use crate::read::{reconcile_fs, sidecar_of};
use std::io::Read;
use std::path::Path;
use vibmode_core::limits::CHANNELS_MAX;

/// The magic bytes that start every `.npy` file.
pub const NPY_MAGIC: &[u8; 6] = b"\x93NUMPY";

/// Headers longer than this are refused (NumPy writes a few hundred bytes).
const HEADER_MAX_BYTES: usize = 1 << 16;

/// What a `.npy` header says about its data.
#[derive(Clone, Debug, PartialEq, Eq)]
pub(crate) struct NpyLayout {
    /// Bytes per value (4 or 8).
    pub width: usize,
    /// The values are stored channel after channel (Fortran order of a 2-D array).
    pub fortran: bool,
    /// Samples per channel.
    pub frames: u64,
    /// Channels.
    pub channels: usize,
    /// Where the data starts, bytes from the file's start.
    pub data_offset: u64,
}

fn problem(path: &Path, problem: NpyProblem) -> SignalError {
    SignalError::Npy {
        path: path.display().to_string(),
        problem,
    }
}

/// Reads and checks the header of the `.npy` file `path` from `r` (positioned at the file's
/// start), whose length is `file_bytes`.
pub(crate) fn npy_layout(path: &Path, r: &mut impl Read, file_bytes: u64) -> Result<NpyLayout> {
    let header = |message: String| problem(path, NpyProblem::Header { message });
    let mut pre = [0u8; 10];
    r.read_exact(&mut pre).map_err(|_| {
        header(format!(
            "the file has {file_bytes} bytes, fewer than a header"
        ))
    })?;
    if &pre[..6] != NPY_MAGIC {
        return Err(header("it does not start with \\x93NUMPY".into()));
    }
    let (major, minor) = (pre[6], pre[7]);
    let (len, fixed) = match major {
        1 => (u16::from_le_bytes([pre[8], pre[9]]) as usize, 10usize),
        2 | 3 => {
            let mut more = [0u8; 2];
            r.read_exact(&mut more)
                .map_err(|_| header("the file ends inside the header".into()))?;
            (
                u32::from_le_bytes([pre[8], pre[9], more[0], more[1]]) as usize,
                12usize,
            )
        }
        _ => {
            return Err(header(format!(
                "format version {major}.{minor} is not known"
            )))
        }
    };
    if len > HEADER_MAX_BYTES {
        return Err(header(format!(
            "a header of {len} bytes (at most {HEADER_MAX_BYTES})"
        )));
    }
    let mut text = vec![0u8; len];
    r.read_exact(&mut text)
        .map_err(|_| header("the file ends inside the header".into()))?;
    let text = std::str::from_utf8(&text)
        .map_err(|_| header("the header is not text".into()))?
        .trim();
    let dict = parse_dict(text).map_err(header)?;
    let descr = dict.descr.ok_or_else(|| header("no 'descr' key".into()))?;
    let fortran = dict
        .fortran_order
        .ok_or_else(|| header("no 'fortran_order' key".into()))?;
    let shape = dict.shape.ok_or_else(|| header("no 'shape' key".into()))?;
    let width = match descr.as_str() {
        "<f4" => 4,
        "<f8" => 8,
        _ => return Err(problem(path, NpyProblem::Dtype { descr })),
    };
    let (frames, channels) = match shape.as_slice() {
        [n] => (*n, 1u64),
        [n, c] => (*n, *c),
        _ => {
            return Err(problem(
                path,
                NpyProblem::Dimensions {
                    shape: shape_text(&shape),
                },
            ))
        }
    };
    if frames == 0 || channels == 0 {
        return Err(problem(
            path,
            NpyProblem::Empty {
                shape: shape_text(&shape),
            },
        ));
    }
    if channels > frames {
        return Err(problem(
            path,
            NpyProblem::Transposed {
                rows: frames,
                columns: channels,
            },
        ));
    }
    if channels > CHANNELS_MAX as u64 {
        return Err(vibmode_core::RecordingError::TooManyChannels {
            what: path.display().to_string(),
            count: channels as usize,
            max: CHANNELS_MAX,
        }
        .into());
    }
    let data_offset = (fixed + len) as u64;
    let expected = frames
        .checked_mul(channels)
        .and_then(|v| v.checked_mul(width as u64));
    let present = file_bytes.saturating_sub(data_offset);
    if expected != Some(present) {
        return Err(problem(
            path,
            NpyProblem::DataSize {
                bytes: present,
                shape: shape_text(&shape),
                width,
            },
        ));
    }
    Ok(NpyLayout {
        width,
        fortran: fortran && channels > 1,
        frames,
        channels: channels as usize,
        data_offset,
    })
}

/// The sampling rate of the `.npy` file `path`: `"fs_hz"` of its sidecar `<path>.json` when
/// it has one (checked against `given` within 1 %), else `given`, else an error.
pub(crate) fn npy_rate(path: &Path, given: Option<f64>) -> Result<f64> {
    let p = path.display().to_string();
    let side = sidecar_of(path);
    let from_side = if side.is_file() {
        let sp = side.display().to_string();
        let text =
            vibmode_core::files::read_text_capped(&side).map_err(|e| io_err("read", &side, &e))?;
        let bad = |problem| SignalError::Sidecar {
            path: sp.clone(),
            problem,
        };
        let v: serde_json::Value = serde_json::from_str(&text).map_err(|e| {
            bad(SidecarProblem::WavJson {
                message: e.to_string(),
            })
        })?;
        match v.get("fs_hz") {
            None | Some(serde_json::Value::Null) => None,
            Some(serde_json::Value::Number(n)) => {
                let fs_hz = n.as_f64().unwrap_or(f64::NAN);
                if !(fs_hz.is_finite() && fs_hz > 0.0) {
                    return Err(bad(SidecarProblem::Rate { fs_hz }));
                }
                Some((fs_hz, sp))
            }
            Some(_) => return Err(bad(SidecarProblem::Rate { fs_hz: f64::NAN })),
        }
    } else {
        None
    };
    match (from_side, given) {
        (Some((fs_hz, sp)), given) => reconcile_fs(&p, format!("the sidecar {sp}"), fs_hz, given),
        (None, Some(g)) => Ok(g),
        (None, None) => Err(SignalError::NpyNoSampleRate { path: p }),
    }
}

/// The layout of the file `path`, opened and measured.
pub(crate) fn npy_layout_of(path: &Path) -> Result<NpyLayout> {
    let mut f = std::fs::File::open(path).map_err(|e| io_err("read", path, &e))?;
    let bytes = f.metadata().map_err(|e| io_err("read", path, &e))?.len();
    npy_layout(path, &mut std::io::BufReader::new(&mut f), bytes)
}

/// The channels of a `.npy` file's data bytes (after the header) laid out as `layout` says.
pub(crate) fn npy_channels(data: &[u8], layout: &NpyLayout) -> Vec<Vec<f64>> {
    use crate::stream::{deinterleave, f32_le};
    let decode = |bytes: &[u8], nch: usize| {
        if layout.width == 4 {
            deinterleave(bytes, nch, 1.0, f32_le)
        } else {
            deinterleave(bytes, nch, 1.0, f64::from_le_bytes)
        }
    };
    if layout.fortran {
        data.chunks_exact(layout.frames as usize * layout.width)
            .flat_map(|column| decode(column, 1))
            .collect()
    } else {
        decode(data, layout.channels)
    }
}

/// `(7, 204800)` or `(5,)`, as NumPy prints a shape.
fn shape_text(shape: &[u64]) -> String {
    match shape {
        [n] => format!("({n},)"),
        _ => format!(
            "({})",
            shape
                .iter()
                .map(u64::to_string)
                .collect::<Vec<_>>()
                .join(", ")
        ),
    }
}

#[derive(Default)]
struct Dict {
    descr: Option<String>,
    fortran_order: Option<bool>,
    shape: Option<Vec<u64>>,
}

/// Parses `{'descr': '<f8', 'fortran_order': False, 'shape': (3, 2), }`.
fn parse_dict(text: &str) -> std::result::Result<Dict, String> {
    let mut p = Parser {
        s: text.as_bytes(),
        i: 0,
    };
    let mut d = Dict::default();
    p.expect(b'{')?;
    loop {
        p.skip_ws();
        if p.eat(b'}') {
            break;
        }
        let key = p.string()?;
        p.skip_ws();
        p.expect(b':')?;
        p.skip_ws();
        match key.as_str() {
            "descr" => d.descr = Some(p.string()?),
            "fortran_order" => d.fortran_order = Some(p.boolean()?),
            "shape" => d.shape = Some(p.tuple()?),
            other => return Err(format!("unexpected key '{other}'")),
        }
        p.skip_ws();
        if !p.eat(b',') {
            p.skip_ws();
            p.expect(b'}')?;
            break;
        }
    }
    Ok(d)
}

struct Parser<'a> {
    s: &'a [u8],
    i: usize,
}

impl Parser<'_> {
    fn skip_ws(&mut self) {
        while self.s.get(self.i).is_some_and(u8::is_ascii_whitespace) {
            self.i += 1;
        }
    }
    fn eat(&mut self, c: u8) -> bool {
        if self.s.get(self.i) == Some(&c) {
            self.i += 1;
            true
        } else {
            false
        }
    }
    fn expect(&mut self, c: u8) -> std::result::Result<(), String> {
        if self.eat(c) {
            Ok(())
        } else {
            Err(format!("expected '{}' at byte {}", c as char, self.i))
        }
    }
    fn string(&mut self) -> std::result::Result<String, String> {
        let q = match self.s.get(self.i) {
            Some(&q @ (b'\'' | b'"')) => q,
            _ => return Err(format!("expected a quoted string at byte {}", self.i)),
        };
        self.i += 1;
        let start = self.i;
        while self.s.get(self.i).is_some_and(|&c| c != q) {
            self.i += 1;
        }
        let out = String::from_utf8_lossy(&self.s[start..self.i.min(self.s.len())]).into_owned();
        self.expect(q)?;
        Ok(out)
    }
    fn boolean(&mut self) -> std::result::Result<bool, String> {
        let rest = &self.s[self.i..];
        if rest.starts_with(b"True") {
            self.i += 4;
            Ok(true)
        } else if rest.starts_with(b"False") {
            self.i += 5;
            Ok(false)
        } else {
            Err(format!("expected True or False at byte {}", self.i))
        }
    }
    fn tuple(&mut self) -> std::result::Result<Vec<u64>, String> {
        self.expect(b'(')?;
        let mut out = Vec::new();
        loop {
            self.skip_ws();
            if self.eat(b')') {
                return Ok(out);
            }
            let start = self.i;
            while self.s.get(self.i).is_some_and(u8::is_ascii_digit) {
                self.i += 1;
            }
            // Digits only, so the text is ASCII; an empty or too long run is refused.
            let digits = std::str::from_utf8(&self.s[start..self.i]).unwrap_or("");
            let v = digits
                .parse::<u64>()
                .map_err(|_| format!("expected a dimension at byte {start}"))?;
            out.push(v);
            // Python 2's NumPy wrote long integers: `(3000L, 4L)`.
            self.eat(b'L');
            self.skip_ws();
            if !self.eat(b',') {
                self.skip_ws();
                self.expect(b')')?;
                return Ok(out);
            }
        }
    }
}
