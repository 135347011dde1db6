//! Writing a file so that it appears complete or not at all, and never over something the user
//! did not agree to replace.

use std::io::BufWriter;
use std::path::{Path, PathBuf};

use tempfile::NamedTempFile;

use super::io_error;
use crate::{Error, Result};

/// An output being written: a temporary file beside its destination, renamed into place by
/// [`commit`](Self::commit) and deleted if dropped before that. For outputs streamed in parts
/// ([`write_file_atomically`](super::write_file_atomically) takes them whole).
///
/// ```
/// use std::io::Write;
/// let dir = tempfile::tempdir().unwrap();
/// let path = dir.path().join("out.txt");
/// let mut file = haarshift::io::PendingFile::create(&path, false).unwrap();
/// file.writer().write_all(b"one part, ").unwrap();
/// file.writer().write_all(b"then another").unwrap();
/// assert!(!path.exists()); // nothing at the destination until commit
/// file.commit().unwrap();
/// assert_eq!(std::fs::read(&path).unwrap(), b"one part, then another");
/// // An existing output is kept unless asked to replace it.
/// assert!(haarshift::io::PendingFile::create(&path, false).is_err());
/// ```
pub struct PendingFile {
    path: PathBuf,
    force: bool,
    writer: BufWriter<NamedTempFile>,
}

impl PendingFile {
    /// Starts writing `path`; fails at once when it exists and `force` is off.
    pub fn create(path: &Path, force: bool) -> Result<Self> {
        if !force && path.symlink_metadata().is_ok() {
            return Err(Error::OutputExists {
                path: path.to_path_buf(),
            });
        }
        let dir = match path.parent() {
            Some(p) if !p.as_os_str().is_empty() => p,
            _ => Path::new("."),
        };
        let mut builder = tempfile::Builder::new();
        builder.prefix(".haarshift-").suffix(".tmp");
        #[cfg(unix)]
        {
            use std::os::unix::fs::PermissionsExt;
            // The usual mode of a new file (the umask still applies), not tempfile's 0600.
            builder.permissions(std::fs::Permissions::from_mode(0o666));
        }
        let temp = builder.tempfile_in(dir).map_err(|e| {
            // tempfile's message names the temporary file, which the user never asked for.
            let e = match e.kind() {
                std::io::ErrorKind::NotFound => std::io::Error::new(
                    std::io::ErrorKind::NotFound,
                    "the output directory does not exist",
                ),
                kind => std::io::Error::from(kind),
            };
            io_error(path, e)
        })?;
        Ok(PendingFile {
            path: path.to_path_buf(),
            force,
            writer: BufWriter::new(temp),
        })
    }

    /// Where to write the content.
    pub fn writer(&mut self) -> &mut BufWriter<NamedTempFile> {
        &mut self.writer
    }

    /// Flushes the content to disk and renames it to the destination.
    pub fn commit(self) -> Result<()> {
        let path = self.path;
        let temp = self
            .writer
            .into_inner()
            .map_err(|e| io_error(&path, e.into_error()))?;
        temp.as_file().sync_all().map_err(|e| io_error(&path, e))?;
        let persisted = if self.force {
            temp.persist(&path)
        } else {
            temp.persist_noclobber(&path)
        };
        match persisted {
            Ok(_) => Ok(()),
            Err(e) if e.error.kind() == std::io::ErrorKind::AlreadyExists => {
                Err(Error::OutputExists { path })
            }
            Err(e) => Err(io_error(&path, e.error)),
        }
    }
}

/// Refuses an `output` that is the same file as `input` (by identity, so through links and
/// different spellings of the path), since replacing it would destroy the input.
///
/// ```
/// use haarshift::io::ensure_distinct_paths;
/// let dir = tempfile::tempdir().unwrap();
/// let input = dir.path().join("in.png");
/// std::fs::write(&input, b"x").unwrap();
/// let same = dir.path().join(".").join("in.png");
/// let err = ensure_distinct_paths(&input, &same).unwrap_err();
/// assert!(err.to_string().ends_with("in.png: is the input file; choose a different output"));
/// assert!(ensure_distinct_paths(&input, &dir.path().join("out.png")).is_ok());
/// ```
pub fn ensure_distinct_paths(input: &Path, output: &Path) -> Result<()> {
    if is_same_file(input, output) {
        return Err(io_error(
            output,
            std::io::Error::new(
                std::io::ErrorKind::InvalidInput,
                "is the input file; choose a different output",
            ),
        ));
    }
    Ok(())
}

/// Whether both paths exist and name the same file.
fn is_same_file(a: &Path, b: &Path) -> bool {
    let (Ok(ma), Ok(mb)) = (std::fs::metadata(a), std::fs::metadata(b)) else {
        return false;
    };
    #[cfg(unix)]
    {
        use std::os::unix::fs::MetadataExt;
        ma.dev() == mb.dev() && ma.ino() == mb.ino()
    }
    #[cfg(not(unix))]
    {
        let _ = (ma, mb);
        matches!((a.canonicalize(), b.canonicalize()), (Ok(x), Ok(y)) if x == y)
    }
}

/// Writes a file atomically: `write` fills a temporary file in the destination's directory,
/// which is then synced and renamed over `path`. An existing `path` is replaced only when
/// `force` is set; on any error nothing is left behind.
///
/// ```
/// use std::io::Write;
/// let dir = tempfile::tempdir().unwrap();
/// let path = dir.path().join("notes.txt");
/// haarshift::io::write_file_atomically(&path, false, |w| w.write_all(b"hello")).unwrap();
/// assert_eq!(std::fs::read(&path).unwrap(), b"hello");
/// let again = haarshift::io::write_file_atomically(&path, false, |w| w.write_all(b"again"));
/// assert!(matches!(again, Err(haarshift::Error::OutputExists { .. })));
/// ```
pub fn write_file_atomically(
    path: &Path,
    force: bool,
    write: impl FnOnce(&mut dyn std::io::Write) -> std::io::Result<()>,
) -> Result<()> {
    let mut file = PendingFile::create(path, force)?;
    write(file.writer()).map_err(|e| io_error(path, e))?;
    file.commit()
}
