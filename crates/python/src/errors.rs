//! Job errors as Python exceptions: a missing file is `FileNotFoundError`, other I/O
//! `OSError`, an interruption `KeyboardInterrupt`, everything the user gave wrong `ValueError`.

use std::path::Path;

use flapssm_jobs::JobError;
use pyo3::PyErr;
use pyo3::exceptions::{PyFileNotFoundError, PyKeyboardInterrupt, PyOSError, PyValueError};

/// The exception of a job error; `path`, when given, is the file the job read.
pub fn job_error(e: JobError, path: Option<&Path>) -> PyErr {
    let message = e.to_string();
    if path.is_some_and(|p| !p.exists()) {
        return PyFileNotFoundError::new_err(message);
    }
    match e {
        JobError::Interrupted { .. } => PyKeyboardInterrupt::new_err(message),
        JobError::Io { source, .. } if source.kind() == std::io::ErrorKind::NotFound => {
            PyFileNotFoundError::new_err(message)
        }
        JobError::Io { .. } | JobError::Output(_) => PyOSError::new_err(message),
        _ => PyValueError::new_err(message),
    }
}

/// The exception of a file that could not be read: `FileNotFoundError` when it is missing,
/// `ValueError` when its content is wrong.
pub fn read_error(path: &Path, message: String) -> PyErr {
    if path.exists() {
        PyValueError::new_err(message)
    } else {
        PyFileNotFoundError::new_err(message)
    }
}
