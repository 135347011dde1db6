//! Flat arrays of numbers read in place from a memory-mapped file, or owned.
//!
//! A scene cache's transport can be larger than the memory a render should hold twice
//! (issue 33's production asset: 3.4 GB). `MappedFile` maps the file read-only and
//! `Buffer` is a slice of it seen as `[T]` without a copy: the pages are the file's, which
//! the kernel reads on first touch and may drop again under pressure, so they count in a
//! process's file-backed resident memory and never in its anonymous memory. A buffer made
//! from a `Vec` is the same type, so that code reading an array never asks where it lives.
//!
//! In place means the file's little-endian bytes are the machine's numbers: on a big-endian
//! machine, or where an array is not aligned to its type, a reader copies instead
//! (`Buffer::mapped` says `None`).
//!
//! **The one caveat of every memory map**: a file truncated by another program while it is
//! mapped makes the next read of a lost page fault (`SIGBUS`). haarshift never truncates a
//! file it may be reading: its outputs replace a file by renaming a complete new one over it
//! ([`write_file_atomically`](haarshift::io::write_file_atomically)), which leaves the mapped old file
//! intact.

use std::any::{Any, TypeId};
use std::fmt;
use std::ops::Deref;
use std::path::Path;
use std::sync::Arc;

use bytemuck::Pod;
use memmap2::Mmap;

use crate::Result;

/// A file mapped read-only into memory, shared by the buffers read from it.
#[derive(Clone)]
pub(crate) struct MappedFile(Arc<Mmap>);

impl MappedFile {
    /// Maps `path`; an unreadable file is an [`Error::Io`] naming it.
    pub fn open(path: &Path) -> Result<Self> {
        let io = |source| crate::Error::io(path.to_path_buf(), source);
        let file = std::fs::File::open(path).map_err(io)?;
        // SAFETY: the map is read-only and haarshift never truncates or rewrites a file in
        // place (module docs); another program doing so is the caveat every memory map has.
        let map = unsafe { Mmap::map(&file) }.map_err(io)?;
        Ok(MappedFile(Arc::new(map)))
    }

    /// The file's bytes.
    pub fn bytes(&self) -> &[u8] {
        &self.0
    }
}

/// A flat array of `T`: owned, or read in place from a [`MappedFile`]; see the
/// [module docs](self). It dereferences to `[T]`.
#[derive(Clone)]
pub(crate) struct Buffer<T>(Storage<T>);

/// How a file's bytes are seen as `[T]`: `bytemuck::cast_slice`, chosen where `T` is known to
/// be plain data, so that no other method needs to know it.
type View<T> = for<'a> fn(&'a [u8]) -> &'a [T];

#[derive(Clone)]
enum Storage<T> {
    Owned(Vec<T>),
    Mapped {
        file: MappedFile,
        start: usize,
        len: usize,
        view: View<T>,
    },
}

impl<T: Pod> Buffer<T> {
    /// `len` values of `T` at byte `start` of `file`, in place, when they lie inside the file,
    /// are aligned for `T` and the machine is little endian; `None` otherwise.
    pub fn mapped(file: &MappedFile, start: usize, len: usize) -> Option<Self> {
        let end = len
            .checked_mul(size_of::<T>())
            .and_then(|n| start.checked_add(n))?;
        let bytes = file.bytes().get(start..end)?;
        let fits =
            cfg!(target_endian = "little") && bytemuck::try_cast_slice::<_, T>(bytes).is_ok();
        fits.then(|| {
            Buffer(Storage::Mapped {
                file: file.clone(),
                start,
                len,
                view: bytemuck::cast_slice::<u8, T>,
            })
        })
    }
}

impl<T: Clone + 'static> Buffer<T> {
    /// The same buffer seen as `U` when `U` is `T` itself, sharing a mapped file's pages (a
    /// copy of an owned `Vec`); `None` for another type. Generic code's way to use an `f32`
    /// array as its own `T` without converting it.
    pub fn shared_as<U: 'static>(&self) -> Option<Buffer<U>> {
        if TypeId::of::<T>() != TypeId::of::<U>() {
            return None;
        }
        Some(match &self.0 {
            Storage::Owned(v) => {
                let copy: Box<dyn Any> = Box::new(v.clone());
                Buffer::from(*copy.downcast::<Vec<U>>().ok()?)
            }
            Storage::Mapped {
                file,
                start,
                len,
                view,
            } => Buffer(Storage::Mapped {
                file: file.clone(),
                start: *start,
                len: *len,
                view: *(view as &dyn Any).downcast_ref::<View<U>>()?,
            }),
        })
    }

    /// Whether the values are read in place from a file.
    pub fn is_mapped(&self) -> bool {
        matches!(self.0, Storage::Mapped { .. })
    }

    /// The values as a `Vec` to change, copied out of the file first if they are mapped.
    pub fn to_mut(&mut self) -> &mut Vec<T> {
        if let Storage::Mapped { .. } = self.0 {
            self.0 = Storage::Owned(self.to_vec());
        }
        match &mut self.0 {
            Storage::Owned(v) => v,
            Storage::Mapped { .. } => unreachable!("made owned above"),
        }
    }
}

impl<T> Deref for Buffer<T> {
    type Target = [T];

    #[inline]
    fn deref(&self) -> &[T] {
        match &self.0 {
            Storage::Owned(v) => v,
            // In range and aligned: checked by `Buffer::mapped`, and the map never changes.
            Storage::Mapped {
                file,
                start,
                len,
                view,
            } => view(&file.bytes()[*start..*start + len * size_of::<T>()]),
        }
    }
}

impl<T> From<Vec<T>> for Buffer<T> {
    fn from(v: Vec<T>) -> Self {
        Buffer(Storage::Owned(v))
    }
}

impl<T: PartialEq> PartialEq for Buffer<T> {
    fn eq(&self, other: &Self) -> bool {
        **self == **other
    }
}

impl<T: fmt::Debug> fmt::Debug for Buffer<T> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        (**self).fmt(f)
    }
}

#[cfg(test)]
#[path = "mapped_tests.rs"]
mod tests;
