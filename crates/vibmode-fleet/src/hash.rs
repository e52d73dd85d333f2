//! The content hash that keys a vehicle's records in the store: the same bytes ingested twice
//! are one record.
//!
//! A store made by this version keys records by BLAKE3 (about 20 times the throughput of
//! SHA-256 in software on a processor without SHA instructions, where hashing a CSV record's
//! text cost a third of `fleet ingest`). A store that already held records when it was migrated
//! keeps SHA-256: its stored hashes cannot be recomputed without the files. The store says which
//! ([`crate::Store::content_hash`]); every hash of its records is made with that one.

use serde::{Deserialize, Serialize};
use sha2::Digest;
use vibmode_core::Recording;

use crate::error::{FleetError, Result};

/// The hash function of a store's record keys. Hashes are lower-case hex (64 characters).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
#[non_exhaustive]
pub enum ContentHash {
    /// SHA-256 (stores that held records before schema 4).
    Sha256,
    /// BLAKE3 (stores made since).
    Blake3,
}

impl Default for ContentHash {
    /// The hash of a store made now ([`ContentHash::Blake3`]; migration 4 writes the same).
    fn default() -> Self {
        ContentHash::Blake3
    }
}

impl ContentHash {
    /// The name kept in the store's `meta` table and accepted by [`std::str::FromStr`].
    pub fn as_str(self) -> &'static str {
        match self {
            ContentHash::Sha256 => "sha256",
            ContentHash::Blake3 => "blake3",
        }
    }

    /// The hash of `bytes`, lower-case hex.
    pub fn hex(self, bytes: &[u8]) -> String {
        match self {
            ContentHash::Sha256 => hex(&sha2::Sha256::digest(bytes)),
            ContentHash::Blake3 => blake3::hash(bytes).to_hex().to_string(),
        }
    }

    /// A file's bytes and their hash, hashed piece by piece as they are read (each piece of
    /// [`READ_PIECE`] bytes while it is still in the processor's cache, rather than the whole
    /// file again after reading it): the same hash as [`ContentHash::hex`] of the bytes.
    /// A file that cannot be read is [`FleetError::Io`], naming it.
    pub fn read_file(self, path: &std::path::Path) -> Result<(Vec<u8>, String)> {
        use std::io::Read;
        let read = || -> std::io::Result<(Vec<u8>, String)> {
            let mut f = std::fs::File::open(path)?;
            let size = f.metadata().map_or(0, |m| m.len());
            let mut bytes = Vec::with_capacity(usize::try_from(size).unwrap_or(0));
            let mut h = Incremental::new(self);
            loop {
                let start = bytes.len();
                if (&mut f).take(READ_PIECE as u64).read_to_end(&mut bytes)? == 0 {
                    break;
                }
                h.update(&bytes[start..]);
            }
            Ok((bytes, h.finish()))
        };
        read().map_err(|e| FleetError::Io {
            path: path.display().to_string(),
            reason: e.to_string(),
        })
    }

    /// The hash of a recording's content (rate, channel names and samples, little-endian), for
    /// records that are not files.
    pub fn of_recording(self, rec: &Recording) -> String {
        let mut h = Incremental::new(self);
        h.update(&rec.fs_hz.to_le_bytes());
        for c in &rec.channels {
            h.update(c.name.as_bytes());
            h.update(&[0u8]);
            for s in &c.samples {
                h.update(&s.to_le_bytes());
            }
        }
        h.finish()
    }
}

impl std::str::FromStr for ContentHash {
    type Err = FleetError;
    fn from_str(s: &str) -> Result<Self> {
        match s.trim().to_ascii_lowercase().as_str() {
            "sha256" => Ok(ContentHash::Sha256),
            "blake3" => Ok(ContentHash::Blake3),
            _ => Err(FleetError::BadContentHash {
                value: s.to_string(),
            }),
        }
    }
}

impl std::fmt::Display for ContentHash {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.as_str())
    }
}

/// The piece [`ContentHash::read_file`] reads and hashes at a time: 256 KiB, within a core's
/// second-level cache and long enough for BLAKE3's wide hashing.
pub const READ_PIECE: usize = 256 * 1024;

enum Incremental {
    Sha256(Box<sha2::Sha256>),
    Blake3(Box<blake3::Hasher>),
}

impl Incremental {
    fn new(kind: ContentHash) -> Incremental {
        match kind {
            ContentHash::Sha256 => Incremental::Sha256(Box::default()),
            ContentHash::Blake3 => Incremental::Blake3(Box::default()),
        }
    }
    fn update(&mut self, bytes: &[u8]) {
        match self {
            Incremental::Sha256(h) => h.update(bytes),
            Incremental::Blake3(h) => {
                h.update(bytes);
            }
        }
    }
    fn finish(self) -> String {
        match self {
            Incremental::Sha256(h) => hex(&h.finalize()),
            Incremental::Blake3(h) => h.finalize().to_hex().to_string(),
        }
    }
}

fn hex(bytes: &[u8]) -> String {
    use std::fmt::Write;
    let mut s = String::with_capacity(2 * bytes.len());
    for b in bytes {
        // Writing to a String cannot fail.
        let _ = write!(s, "{b:02x}");
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Reading piece by piece gives the bytes and the hash of the whole: files of 0 and 1
    /// bytes, one byte either side of one and of two pieces, and several pieces and a bit, with
    /// both hashes.
    #[test]
    fn a_file_read_piece_by_piece_has_the_hash_of_its_bytes() {
        let dir = tempfile::tempdir().expect("temp dir");
        for (i, len) in [
            0,
            1,
            READ_PIECE - 1,
            READ_PIECE,
            READ_PIECE + 1,
            2 * READ_PIECE,
            3 * READ_PIECE + 7,
        ]
        .into_iter()
        .enumerate()
        {
            let bytes: Vec<u8> = (0..len).map(|k| (k * 131 + k / 7 + i) as u8).collect();
            let path = dir.path().join(format!("f{i}"));
            std::fs::write(&path, &bytes).expect("write");
            for kind in [ContentHash::Sha256, ContentHash::Blake3] {
                let (read, key) = kind.read_file(&path).expect("read");
                assert!(read == bytes, "{kind}, {len} bytes: the bytes differ");
                assert_eq!(key, kind.hex(&bytes), "{kind}, {len} bytes");
            }
        }
        let err = ContentHash::Blake3
            .read_file(&dir.path().join("missing"))
            .expect_err("a missing file")
            .to_string();
        assert!(
            err.contains("missing") && err.contains("check the path"),
            "{err}"
        );
    }

    /// Published test vectors: FIPS 180-2 for SHA-256 ("abc"), the BLAKE3 reference
    /// implementation's empty-input hash.
    #[test]
    fn known_vectors() {
        assert_eq!(
            ContentHash::Sha256.hex(b"abc"),
            "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad"
        );
        assert_eq!(
            ContentHash::Blake3.hex(b""),
            "af1349b9f5f9a1a6a0404dea36dcc9499bcb25c9adc112b7cc9a93cae41f3262"
        );
        assert_eq!(ContentHash::Blake3.hex(b"abc").len(), 64);
    }

    /// A recording's hash is the hash of its bytes laid out as documented, incremental or not.
    #[test]
    fn recording_hash_is_the_hash_of_its_layout() {
        let rec = Recording::new(
            500.0,
            vec![vibmode_core::Channel::new(
                "z",
                "m/s^2",
                vec![1.0, -2.5, 3.25],
            )],
        )
        .expect("recording");
        let mut bytes = 500.0f64.to_le_bytes().to_vec();
        bytes.extend_from_slice(b"z\0");
        for s in [1.0f64, -2.5, 3.25] {
            bytes.extend_from_slice(&s.to_le_bytes());
        }
        for kind in [ContentHash::Sha256, ContentHash::Blake3] {
            assert_eq!(kind.of_recording(&rec), kind.hex(&bytes), "{kind}");
        }
    }

    #[test]
    fn names_round_trip_and_unknown_names_are_refused() {
        for kind in [ContentHash::Sha256, ContentHash::Blake3] {
            assert_eq!(kind.as_str().parse::<ContentHash>().expect("parse"), kind);
        }
        let e = "md5".parse::<ContentHash>().expect_err("md5");
        assert!(e.to_string().contains("md5"), "{e}");
    }
}
