//! Job errors as Python exceptions: a missing file is `FileNotFoundError`, other I/O
//! `OSError`, an interruption `KeyboardInterrupt`, everything the user gave wrong `ValueError`.

use std::path::Path;

use flapssm_jobs::JobError;
use pyo3::exceptions::{PyFileNotFoundError, PyKeyboardInterrupt, PyOSError, PyValueError};
use pyo3::{PyErr, PyResult};

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

/// Writes an output file the way the CLI does: [`flapssm_jobs::files::check_outputs`] first
/// (`OSError` for a directory, a device, `-`, a missing folder), then `save`, whose message
/// becomes an `OSError`.
pub fn save_checked(path: &Path, save: impl FnOnce(&Path) -> Result<(), String>) -> PyResult<()> {
    flapssm_jobs::files::check_outputs(&[path], &[]).map_err(|e| job_error(e, None))?;
    save(path).map_err(PyOSError::new_err)
}
