//! The library's errors as Python exceptions, each carrying the library's one-line message.

use pyo3::PyErr;
use pyo3::exceptions::{
    PyFileExistsError, PyFileNotFoundError, PyMemoryError, PyOSError, PyPermissionError,
    PyValueError,
};

/// The exception a Python caller expects: `ValueError` for a bad argument or array,
/// `OSError` (or its `FileNotFoundError`, `PermissionError`, `FileExistsError` subclasses) for a
/// file, `MemoryError` for work beyond the memory budget.
pub fn to_py(error: haarshift_relight::Error) -> PyErr {
    use haarshift::Error as Core;
    use haarshift_relight::Error;
    let message = error.to_string();
    match &error {
        Error::Core(Core::Io { source, .. }) => match source.kind() {
            std::io::ErrorKind::NotFound => PyFileNotFoundError::new_err(message),
            std::io::ErrorKind::PermissionDenied => PyPermissionError::new_err(message),
            _ => PyOSError::new_err(message),
        },
        Error::Core(Core::OutputExists { .. }) => PyFileExistsError::new_err(message),
        Error::Core(Core::Format { .. })
        | Error::Merl { .. }
        | Error::Scene { path: Some(_), .. } => PyOSError::new_err(message),
        Error::Core(Core::MemoryBudget { .. }) => PyMemoryError::new_err(message),
        _ => PyValueError::new_err(message),
    }
}

/// `Result` of the library, converted with [`to_py`].
pub trait OrRaise<T> {
    /// The value, or the library's error as its Python exception.
    fn or_raise(self) -> pyo3::PyResult<T>;
}

impl<T, E: Into<haarshift_relight::Error>> OrRaise<T> for Result<T, E> {
    fn or_raise(self) -> pyo3::PyResult<T> {
        self.map_err(|e| to_py(e.into()))
    }
}

/// A `ValueError` naming the argument: `"image: expected 2 or 3 dimensions, got 4"`.
pub fn bad_argument(name: &str, reason: impl std::fmt::Display) -> PyErr {
    PyValueError::new_err(format!("{name}: {reason}"))
}
