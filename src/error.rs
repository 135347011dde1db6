//! The one error type of the core crate.
//!
//! The relighting crate (`haarshift-relight`) has an error type of its own that wraps this one
//! (`From<haarshift::Error>`, displayed unchanged) beside what only a scene can get wrong, so
//! that `?` carries a core error up unchanged; the experiments crate uses the relighting's.

use std::path::PathBuf;

/// Everything that can go wrong in haarshift, from a bad parameter to an unreadable file.
///
/// Every variant names what was wrong in words a command-line user can act on; the CLI prints
/// the `Display` form on one line.
///
/// ```
/// use haarshift::Error;
/// let e = Error::InvalidParameter { name: "levels", reason: "must be at most 9".into() };
/// assert_eq!(e.to_string(), "invalid levels: must be at most 9");
/// ```
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// A numeric or enumerated parameter is out of its domain.
    #[error("invalid {name}: {reason}")]
    InvalidParameter {
        /// The parameter, as the user knows it (`levels`, `precision`, `angle`, ...).
        name: &'static str,
        /// What is wrong with the value.
        reason: String,
    },
    /// An array has a shape the operation cannot take (zero size, not a power of two, mismatched).
    #[error("invalid shape {shape:?}: {reason}")]
    InvalidShape {
        /// The offending shape.
        shape: Vec<usize>,
        /// Why it cannot be used.
        reason: String,
    },
    /// The input contains NaN or infinity, which no transform here can carry meaningfully.
    #[error("non-finite value {value} at index {index:?}")]
    NonFinite {
        /// The first non-finite value found.
        value: f64,
        /// Its index in the array.
        index: Vec<usize>,
    },
    /// The operation would need more memory than the caller's budget allows.
    #[error("{what} needs {needed} bytes, more than the memory budget of {budget} bytes")]
    MemoryBudget {
        /// What was being allocated.
        what: String,
        /// Bytes the operation needs.
        needed: u128,
        /// Bytes allowed.
        budget: u128,
    },
    /// A file could not be read or written.
    #[error("{}: {source}", path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// The underlying error.
        #[source]
        source: std::io::Error,
    },
    /// A file was read but its content is not a valid image or array of a supported kind.
    #[error("{}: {reason}", path.display())]
    Format {
        /// The file.
        path: PathBuf,
        /// What is wrong with it.
        reason: String,
    },
    /// The output file exists and the caller did not ask to replace it.
    #[error("{}: already exists", path.display())]
    OutputExists {
        /// The existing file.
        path: PathBuf,
    },
}

/// `Result` with [`Error`].
pub type Result<T, E = Error> = std::result::Result<T, E>;

impl Error {
    /// This error as one about the file `path`: an error that names no file (a bad shape,
    /// parameter or value found while processing the file's content) becomes an
    /// [`Error::Format`] naming it; errors that name a file already are returned unchanged.
    ///
    /// ```
    /// use haarshift::Error;
    /// let e = Error::InvalidParameter { name: "levels", reason: "too many".into() };
    /// assert_eq!(e.in_file("a.png".as_ref()).to_string(), "a.png: invalid levels: too many");
    /// ```
    pub fn in_file(self, path: &std::path::Path) -> Self {
        match self {
            Error::Io { .. } | Error::Format { .. } | Error::OutputExists { .. } => self,
            other => Error::Format {
                path: path.to_path_buf(),
                reason: other.to_string(),
            },
        }
    }

    /// Shorthand for [`Error::InvalidParameter`].
    ///
    /// ```
    /// let e = haarshift::Error::parameter("port", "0 is taken");
    /// assert_eq!(e.to_string(), "invalid port: 0 is taken");
    /// ```
    pub fn parameter(name: &'static str, reason: impl Into<String>) -> Self {
        Error::InvalidParameter {
            name,
            reason: reason.into(),
        }
    }

    /// Shorthand for [`Error::InvalidShape`].
    ///
    /// ```
    /// let e = haarshift::Error::shape(&[0, 3], "empty");
    /// assert_eq!(e.to_string(), "invalid shape [0, 3]: empty");
    /// ```
    pub fn shape(shape: &[usize], reason: impl Into<String>) -> Self {
        Error::InvalidShape {
            shape: shape.to_vec(),
            reason: reason.into(),
        }
    }
}
