//! What the binary files of the relighting share (the scene cache `.hsr`, the occlusion field
//! file `.hsf`): an 8-byte magic, a `u32` format version, the CRC-32 of everything after it, a
//! JSON header behind its `u64` length, then flat little-endian arrays, each starting at a file
//! offset that is a multiple of [`ALIGN`] (zero bytes fill the gaps), so that a memory-mapped
//! file's arrays can be read in place ([`Buffer`]). Every check on reading is the format's own
//! typed [`SceneError`], so that one parser serves both files and each names itself in its
//! messages.

use std::io::{Seek, SeekFrom, Write};
use std::path::Path;

use bytemuck::Pod;
use serde::Serialize;
use serde::de::DeserializeOwned;

use crate::SceneError;
use crate::mapped::{Buffer, MappedFile};
use crate::{Error, Result};
use haarshift::io::PendingFile;

/// Every array starts at a file offset that is a multiple of this: the widest element, `u64`
/// and `f64`.
pub(crate) const ALIGN: usize = 8;

/// Bytes before the body (magic, version, checksum): the body's offsets are the file's minus
/// this, a multiple of [`ALIGN`].
const PREFIX: usize = 16;

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

/// A number stored as its little-endian bytes.
pub(crate) trait LittleEndian: Pod {
    /// Appends the bytes to `out`.
    fn put(self, out: &mut Vec<u8>);
    /// The number of `size_of::<Self>()` bytes.
    fn from_le(bytes: &[u8]) -> Self;
}

macro_rules! little_endian {
    ($($t:ty),*) => {$(
        impl LittleEndian for $t {
            fn put(self, out: &mut Vec<u8>) {
                out.extend_from_slice(&self.to_le_bytes());
            }
            fn from_le(bytes: &[u8]) -> Self {
                <$t>::from_le_bytes(bytes.try_into().expect("the width of the type"))
            }
        }
    )*};
}
little_endian!(u64, u32, f64, f32);

/// A file's body as it is written: the header, then arrays at aligned offsets, streamed to
/// `out` in pieces of at most [`PIECE`] bytes, with their CRC-32 and length kept.
pub(crate) struct Body<'w> {
    out: &'w mut dyn Write,
    crc: crc32fast::Hasher,
    len: usize,
    error: Option<std::io::Error>,
}

/// The most bytes of one write of a [`Body`].
const PIECE: usize = 4 << 20;

impl Body<'_> {
    /// Appends one array at the next aligned offset: the values of `parts`, one after another.
    pub fn array<'a, T: LittleEndian + 'a>(&mut self, parts: impl IntoIterator<Item = &'a [T]>) {
        let gap = (ALIGN - self.len % ALIGN) % ALIGN;
        self.bytes(&[0; ALIGN][..gap]);
        for values in parts {
            if cfg!(target_endian = "little") {
                self.bytes(bytemuck::cast_slice(values));
            } else {
                for piece in values.chunks(PIECE / 8) {
                    let mut le = Vec::with_capacity(std::mem::size_of_val(piece));
                    piece.iter().for_each(|&x| x.put(&mut le));
                    self.bytes(&le);
                }
            }
        }
    }

    fn bytes(&mut self, bytes: &[u8]) {
        self.crc.update(bytes);
        self.len += bytes.len();
        for piece in bytes.chunks(PIECE) {
            if self.error.is_none() {
                self.error = self.out.write_all(piece).err();
            }
        }
    }

    /// The header's length and bytes, then the arrays `arrays` appends, written to `out`:
    /// the body's CRC-32 and length.
    fn stream(
        out: &mut dyn Write,
        json: &[u8],
        arrays: impl FnOnce(&mut Body),
    ) -> std::io::Result<(u32, usize)> {
        let mut body = Body {
            out,
            crc: crc32fast::Hasher::new(),
            len: 0,
            error: None,
        };
        body.bytes(&(json.len() as u64).to_le_bytes());
        body.bytes(json);
        arrays(&mut body);
        match body.error {
            Some(e) => Err(e),
            None => Ok((body.crc.finalize(), body.len)),
        }
    }
}

impl Format {
    /// The format's "damaged" error for `reason`.
    pub fn corrupt(&self, reason: impl Into<String>) -> Error {
        (self.corrupt)(reason.into()).into()
    }

    /// Writes `path` atomically (an existing file only with `force`): the magic, the version,
    /// the checksum, then the header and the arrays `arrays` appends. The body is streamed
    /// to the file as it is made, so that no copy of it is held, and its checksum written
    /// into its place once it is known. Returns the file's size in bytes.
    pub fn write(
        &self,
        path: &Path,
        force: bool,
        header: &impl Serialize,
        arrays: impl FnOnce(&mut Body),
    ) -> Result<u64> {
        let json = serde_json::to_vec(header).expect("the header serialises");
        let mut file = PendingFile::create(path, force)?;
        let w = file.writer();
        let write = || -> std::io::Result<usize> {
            w.write_all(self.magic)?;
            w.write_all(&self.version.to_le_bytes())?;
            w.write_all(&[0; 4])?;
            let (checksum, len) = Body::stream(w, &json, arrays)?;
            w.seek(SeekFrom::Start(PREFIX as u64 - 4))?;
            w.write_all(&checksum.to_le_bytes())?;
            Ok(len)
        };
        let len = write().map_err(|source| crate::Error::io(path.to_path_buf(), source))?;
        file.commit()?;
        Ok((PREFIX + len) as u64)
    }

    /// [`Format::open`] on a mapped file, whose arrays the reader then reads in place.
    pub fn open_mapped<'a, H: DeserializeOwned>(
        &'a self,
        file: &'a MappedFile,
    ) -> Result<(H, Reader<'a>)> {
        let (header, mut r) = self.open(file.bytes())?;
        r.file = Some(file);
        Ok((header, r))
    }

    /// Checks the magic, the version and the checksum, in this order, and parses the header;
    /// the arrays are left to the returned reader, which copies them.
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
            offset: PREFIX,
            file: None,
            format: self,
        };
        let header_len =
            usize::try_from(r.values::<u64>(1)?[0]).map_err(|_| self.corrupt("cut short"))?;
        let header = serde_json::from_slice(r.take(header_len)?)
            .map_err(|e| self.corrupt(format!("header: {e}")))?;
        Ok((header, r))
    }
}

/// The little-endian values of `raw`, copied.
fn decode<T: LittleEndian>(raw: &[u8]) -> Vec<T> {
    raw.chunks_exact(size_of::<T>()).map(T::from_le).collect()
}

/// Reads little-endian arrays off the front of a file's body: in place from a mapped file
/// ([`Format::open_mapped`]) where they can be, copied otherwise.
pub(crate) struct Reader<'a> {
    bytes: &'a [u8],
    /// The file offset of `bytes[0]`.
    offset: usize,
    file: Option<&'a MappedFile>,
    format: &'a Format,
}

impl<'a> Reader<'a> {
    fn take(&mut self, n: usize) -> Result<&'a [u8]> {
        if n > self.bytes.len() {
            return Err(self.format.corrupt("cut short"));
        }
        let (head, tail) = self.bytes.split_at(n);
        self.bytes = tail;
        self.offset += n;
        Ok(head)
    }

    /// The next `count` values of `T` (at the next aligned offset), `T`'s width in bytes each.
    fn next_array<T: LittleEndian>(&mut self, count: usize) -> Result<(usize, &'a [u8])> {
        let gap = (ALIGN - self.offset % ALIGN) % ALIGN;
        if self.take(gap)?.iter().any(|&b| b != 0) {
            return Err(self.format.corrupt("padding that is not zero"));
        }
        let n = count
            .checked_mul(size_of::<T>())
            .ok_or_else(|| self.format.corrupt("size overflows"))?;
        let start = self.offset;
        Ok((start, self.take(n)?))
    }

    /// The next array of `count` values, copied.
    pub fn values<T: LittleEndian>(&mut self, count: usize) -> Result<Vec<T>> {
        let (_, raw) = self.next_array::<T>(count)?;
        Ok(decode(raw))
    }

    /// The next array of `count` values, in place when the file is mapped.
    pub fn array<T: LittleEndian>(&mut self, count: usize) -> Result<Buffer<T>> {
        let (start, raw) = self.next_array::<T>(count)?;
        if let Some(buffer) = self.file.and_then(|f| Buffer::mapped(f, start, count)) {
            return Ok(buffer);
        }
        Ok(Buffer::from(
            raw.chunks_exact(size_of::<T>())
                .map(T::from_le)
                .collect::<Vec<_>>(),
        ))
    }

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

#[cfg(test)]
#[path = "framed_tests.rs"]
mod tests;
