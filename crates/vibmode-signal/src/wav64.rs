//! The header of a 64-bit IEEE float WAV, which hound (3.5) refuses ("bits per sample is not
//! 32"). It is what numpy's default `float64` arrays become through
//! `scipy.io.wavfile.write(path, fs, data)`, so a scipy user's processed accelerations arrive
//! in it. Only the RIFF chunks are walked here; the samples are little-endian `f64` interleaved
//! in the data chunk and are decoded by the readers (`read.rs`, `stream.rs`) as they decode
//! 32-bit floats.

use std::io::{Read, Seek, SeekFrom};

/// `WAVE_FORMAT_IEEE_FLOAT`.
const FORMAT_IEEE_FLOAT: u16 = 3;
/// `WAVE_FORMAT_EXTENSIBLE`: the format is the first two bytes of the sub-format GUID.
const FORMAT_EXTENSIBLE: u16 = 0xFFFE;
/// The sub-format GUID after its first two bytes (`KSDATAFORMAT_SUBTYPE_*`'s common tail).
const SUBFORMAT_TAIL: [u8; 14] = [
    0x00, 0x00, 0x00, 0x00, 0x10, 0x00, 0x80, 0x00, 0x00, 0xAA, 0x00, 0x38, 0x9B, 0x71,
];

/// Where the samples of a 64-bit float WAV lie.
#[derive(Debug, Clone, PartialEq, Eq)]
pub(crate) struct Float64Wav {
    pub channels: u16,
    pub sample_rate: u32,
    /// Byte offset of the data chunk's first sample from the start of the file.
    pub data_offset: u64,
    /// Bytes the data chunk's header declares (the file may hold fewer: cut off mid-write).
    pub data_len: u64,
}

impl Float64Wav {
    /// Whole frames the data chunk declares.
    pub fn frames(&self) -> u64 {
        self.data_len / (8 * u64::from(self.channels.max(1)))
    }
}

fn read_array<const N: usize>(r: &mut impl Read) -> Option<[u8; N]> {
    let mut b = [0u8; N];
    r.read_exact(&mut b).ok()?;
    Some(b)
}

fn u16_at(b: &[u8], at: usize) -> u16 {
    u16::from_le_bytes([b[at], b[at + 1]])
}

fn u32_at(b: &[u8], at: usize) -> u32 {
    u32::from_le_bytes([b[at], b[at + 1], b[at + 2], b[at + 3]])
}

/// The layout of `r` (read from its start) when it is a RIFF/WAVE file of 64-bit IEEE float
/// samples (format 3, or `WAVE_FORMAT_EXTENSIBLE` with the IEEE float sub-format) with a
/// `fmt ` chunk before its `data` chunk; `None` for anything else (the caller keeps hound's
/// message), including a file whose chunks end before the data chunk.
pub(crate) fn float64_header<R: Read + Seek>(r: &mut R) -> Option<Float64Wav> {
    r.seek(SeekFrom::Start(0)).ok()?;
    let riff: [u8; 12] = read_array(r)?;
    if &riff[..4] != b"RIFF" || &riff[8..] != b"WAVE" {
        return None;
    }
    let mut pos = 12u64;
    let mut format: Option<(u16, u32)> = None;
    loop {
        let head: [u8; 8] = read_array(r)?;
        let size = u64::from(u32_at(&head, 4));
        pos += 8;
        match &head[..4] {
            b"fmt " => {
                if !(16..=1024).contains(&size) {
                    return None;
                }
                let mut fmt = vec![0u8; size as usize];
                r.read_exact(&mut fmt).ok()?;
                let tag = u16_at(&fmt, 0);
                let float = match tag {
                    FORMAT_IEEE_FLOAT => true,
                    FORMAT_EXTENSIBLE if fmt.len() >= 40 => {
                        u16_at(&fmt, 24) == FORMAT_IEEE_FLOAT && fmt[26..40] == SUBFORMAT_TAIL
                    }
                    _ => false,
                };
                let channels = u16_at(&fmt, 2);
                let bits = u16_at(&fmt, 14);
                if !float || bits != 64 || channels == 0 {
                    return None;
                }
                format = Some((channels, u32_at(&fmt, 4)));
                // A chunk of odd size is followed by a pad byte.
                pos += size + size % 2;
                r.seek(SeekFrom::Start(pos)).ok()?;
            }
            b"data" => {
                let (channels, sample_rate) = format?;
                return Some(Float64Wav {
                    channels,
                    sample_rate,
                    data_offset: pos,
                    data_len: size,
                });
            }
            _ => {
                pos += size + size % 2;
                r.seek(SeekFrom::Start(pos)).ok()?;
            }
        }
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use std::io::Cursor;

    /// A WAV of `frames` (interleaved `f64`) with the given format chunk body and, before the
    /// `fmt ` chunk, an odd-sized `LIST` chunk (its pad byte included) when `list` is set.
    pub(crate) fn wav_bytes(fmt: &[u8], frames: &[f64], list: bool) -> Vec<u8> {
        let mut body = b"WAVE".to_vec();
        if list {
            body.extend_from_slice(b"LIST");
            body.extend_from_slice(&3u32.to_le_bytes());
            body.extend_from_slice(b"abc\0");
        }
        body.extend_from_slice(b"fmt ");
        body.extend_from_slice(&(fmt.len() as u32).to_le_bytes());
        body.extend_from_slice(fmt);
        body.extend_from_slice(b"data");
        body.extend_from_slice(&((frames.len() * 8) as u32).to_le_bytes());
        for v in frames {
            body.extend_from_slice(&v.to_le_bytes());
        }
        let mut out = b"RIFF".to_vec();
        out.extend_from_slice(&(body.len() as u32).to_le_bytes());
        out.extend_from_slice(&body);
        out
    }

    /// The 16-byte format chunk body of `tag`, `channels`, `rate` and `bits`.
    pub(crate) fn fmt_chunk(tag: u16, channels: u16, rate: u32, bits: u16) -> Vec<u8> {
        let align = channels * bits / 8;
        let mut f = Vec::new();
        f.extend_from_slice(&tag.to_le_bytes());
        f.extend_from_slice(&channels.to_le_bytes());
        f.extend_from_slice(&rate.to_le_bytes());
        f.extend_from_slice(&(rate * u32::from(align)).to_le_bytes());
        f.extend_from_slice(&align.to_le_bytes());
        f.extend_from_slice(&bits.to_le_bytes());
        f
    }

    #[test]
    fn the_header_of_a_plain_64_bit_float_wav_by_hand() {
        // 12 (RIFF, size, WAVE) + 8 + 16 (fmt) + 8 (data header): the samples start at byte 44.
        let b = wav_bytes(&fmt_chunk(3, 2, 500, 64), &[1.0, -2.0, 3.5, 4.0], false);
        let h = float64_header(&mut Cursor::new(&b)).unwrap();
        assert_eq!(
            h,
            Float64Wav {
                channels: 2,
                sample_rate: 500,
                data_offset: 44,
                data_len: 32
            }
        );
        assert_eq!(h.frames(), 2);
    }

    #[test]
    fn an_odd_chunk_before_fmt_is_skipped_with_its_pad_byte() {
        // LIST: 8 + 3 + 1 pad byte before the 44 bytes above.
        let b = wav_bytes(&fmt_chunk(3, 1, 2000, 64), &[0.5; 3], true);
        let h = float64_header(&mut Cursor::new(&b)).unwrap();
        assert_eq!((h.channels, h.data_offset, h.frames()), (1, 56, 3));
    }

    #[test]
    fn the_extensible_format_with_the_float_sub_format_is_read() {
        let mut f = fmt_chunk(FORMAT_EXTENSIBLE, 3, 1000, 64);
        f.extend_from_slice(&22u16.to_le_bytes()); // cbSize
        f.extend_from_slice(&64u16.to_le_bytes()); // valid bits
        f.extend_from_slice(&0u32.to_le_bytes()); // channel mask
        f.extend_from_slice(&3u16.to_le_bytes());
        f.extend_from_slice(&SUBFORMAT_TAIL);
        let b = wav_bytes(&f, &[0.0; 6], false);
        assert_eq!(float64_header(&mut Cursor::new(&b)).unwrap().frames(), 2);
        // The PCM sub-format (1) is not a float.
        let mut pcm = f.clone();
        pcm[24] = 1;
        assert_eq!(
            float64_header(&mut Cursor::new(wav_bytes(&pcm, &[0.0; 6], false))),
            None
        );
    }

    #[test]
    fn other_formats_and_broken_files_are_not_taken() {
        let samples = [0.0; 4];
        for fmt in [
            fmt_chunk(3, 2, 500, 32), // 32-bit float: hound's
            fmt_chunk(1, 2, 500, 16), // PCM
            fmt_chunk(3, 0, 500, 64), // no channels
        ] {
            let b = wav_bytes(&fmt, &samples, false);
            assert_eq!(float64_header(&mut Cursor::new(&b)), None);
        }
        let good = wav_bytes(&fmt_chunk(3, 2, 500, 64), &samples, false);
        // Cut inside the headers, or not a RIFF file at all.
        for cut in [0, 11, 20, 40] {
            assert_eq!(float64_header(&mut Cursor::new(&good[..cut])), None);
        }
        let mut not_riff = good.clone();
        not_riff[..4].copy_from_slice(b"RIFX");
        assert_eq!(float64_header(&mut Cursor::new(&not_riff)), None);
        // A data chunk before any fmt chunk.
        let mut no_fmt = b"RIFF\x0c\0\0\0WAVEdata\0\0\0\0".to_vec();
        no_fmt.extend_from_slice(&[0u8; 8]);
        assert_eq!(float64_header(&mut Cursor::new(&no_fmt)), None);
    }
}
