//! What the binary files of the relighting share (the scene cache `.hsr`, the occlusion field
//! file `.hsf`): an 8-byte magic, a `u32` format version, the CRC-32 of everything after it, a
//! JSON header behind its `u64` length, then flat little-endian arrays. Every check on reading
//! is the format's own typed [`SceneError`], so that one parser serves both files and each
//! names itself in its messages.

use std::path::Path;

use serde::Serialize;
use serde::de::DeserializeOwned;

use crate::relight::SceneError;
use crate::{Error, Result};

/// One file format: its magic, version, name and errors.
pub(crate) struct Format {
    /// The first 8 bytes.
    pub magic: &'static [u8; 8],
    /// The version this build reads and writes.
    pub version: u32,
    /// What the file is, for "not a haarshift ...".
    pub name: &'static str,
    /// The format's "damaged" error.
    pub corrupt: fn(String) -> SceneError,
    /// The format's "other version" error, from the version found and the one expected.
    pub other_version: fn(u32, u32) -> SceneError,
}

/// A number written as its little-endian bytes.
pub(crate) trait LittleEndian: Copy {
    /// Appends the bytes to `out`.
    fn put(self, out: &mut Vec<u8>);
}

macro_rules! little_endian {
    ($($t:ty),*) => {$(
        impl LittleEndian for $t {
            fn put(self, out: &mut Vec<u8>) {
                out.extend_from_slice(&self.to_le_bytes());
            }
        }
    )*};
}
little_endian!(u64, u32, f64, f32);

/// Appends every value of `values` to `out`, little endian.
pub(crate) fn put_all<'a, T: LittleEndian + 'a>(
    out: &mut Vec<u8>,
    values: impl IntoIterator<Item = &'a T>,
) {
    values.into_iter().for_each(|x| x.put(out));
}

impl Format {
    /// The format's "damaged" error for `reason`.
    pub fn corrupt(&self, reason: impl Into<String>) -> Error {
        (self.corrupt)(reason.into()).into()
    }

    /// Writes `path` atomically (an existing file only with `force`): the magic, the version,
    /// the checksum, then the header and the arrays `arrays` appends (about `capacity` bytes).
    /// Returns the file's size in bytes.
    pub fn write(
        &self,
        path: &Path,
        force: bool,
        header: &impl Serialize,
        capacity: usize,
        arrays: impl FnOnce(&mut Vec<u8>),
    ) -> Result<u64> {
        let json = serde_json::to_vec(header).expect("the header serialises");
        let mut body = Vec::with_capacity(8 + json.len() + capacity);
        (json.len() as u64).put(&mut body);
        body.extend_from_slice(&json);
        arrays(&mut body);
        let checksum = crc32fast::hash(&body);
        crate::io::write_file_atomically(path, force, |w| {
            w.write_all(self.magic)?;
            w.write_all(&self.version.to_le_bytes())?;
            w.write_all(&checksum.to_le_bytes())?;
            w.write_all(&body)
        })?;
        Ok((16 + body.len()) as u64)
    }

    /// Checks the magic, the version and the checksum, in this order, and parses the header;
    /// the arrays are left to the returned reader.
    pub fn open<'a, H: DeserializeOwned>(&'a self, bytes: &'a [u8]) -> Result<(H, Reader<'a>)> {
        if bytes.len() < 8 || &bytes[..8] != self.magic {
            return Err(self.corrupt(format!("not a haarshift {}", self.name)));
        }
        if bytes.len() < 24 {
            return Err(self.corrupt("cut short"));
        }
        let version = u32::from_le_bytes(bytes[8..12].try_into().expect("4 bytes"));
        if version != self.version {
            return Err((self.other_version)(version, self.version).into());
        }
        let checksum = u32::from_le_bytes(bytes[12..16].try_into().expect("4 bytes"));
        let body = &bytes[16..];
        if crc32fast::hash(body) != checksum {
            return Err(self.corrupt("checksum mismatch"));
        }
        let mut r = Reader {
            bytes: body,
            format: self,
        };
        let header_len = usize::try_from(r.u64s(1)?[0]).map_err(|_| self.corrupt("cut short"))?;
        let header = serde_json::from_slice(r.take(header_len)?)
            .map_err(|e| self.corrupt(format!("header: {e}")))?;
        Ok((header, r))
    }
}

/// Reads little-endian arrays off the front of a file's body.
pub(crate) struct Reader<'a> {
    bytes: &'a [u8],
    format: &'a Format,
}

macro_rules! read_array {
    ($name:ident, $t:ty) => {
        pub fn $name(&mut self, count: usize) -> Result<Vec<$t>> {
            const W: usize = std::mem::size_of::<$t>();
            let raw = self.take(
                count
                    .checked_mul(W)
                    .ok_or_else(|| self.format.corrupt("size overflows"))?,
            )?;
            Ok(raw
                .chunks_exact(W)
                .map(|c| <$t>::from_le_bytes(c.try_into().expect("W bytes")))
                .collect())
        }
    };
}

impl<'a> Reader<'a> {
    fn take(&mut self, n: usize) -> Result<&'a [u8]> {
        if n > self.bytes.len() {
            return Err(self.format.corrupt("cut short"));
        }
        let (head, tail) = self.bytes.split_at(n);
        self.bytes = tail;
        Ok(head)
    }
    read_array!(u64s, u64);
    read_array!(u32s, u32);
    read_array!(f64s, f64);
    read_array!(f32s, f32);

    /// The format's "damaged" error for `reason`.
    pub fn corrupt(&self, reason: impl Into<String>) -> Error {
        self.format.corrupt(reason)
    }

    /// An error unless every byte has been read; `last` names what should have ended the file.
    pub fn finish(self, last: &str) -> Result<()> {
        if self.bytes.is_empty() {
            Ok(())
        } else {
            Err(self.format.corrupt(format!("bytes after the {last}")))
        }
    }
}
