//! JSON and text files of the jobs, written atomically (temporary file and rename).

use std::path::Path;

use serde::Serialize;

use crate::error::{JobError, Result};

pub(crate) fn write_json<T: Serialize>(path: &Path, value: &T) -> Result<()> {
    let text = serde_json::to_vec_pretty(value).map_err(|source| JobError::Json {
        path: path.to_path_buf(),
        source,
    })?;
    flapssm_data::atomic::write_bytes_atomic(path, &text).map_err(|source| JobError::Io {
        path: path.to_path_buf(),
        source,
    })
}

pub(crate) fn write_text(path: &Path, text: &str) -> Result<()> {
    flapssm_data::atomic::write_bytes_atomic(path, text.as_bytes()).map_err(|source| JobError::Io {
        path: path.to_path_buf(),
        source,
    })
}

/// Writes `value` as pretty JSON, atomically.
///
/// # Errors
/// [`JobError::Json`] / [`JobError::Io`] naming the file.
pub fn save_json<T: Serialize>(path: &Path, value: &T) -> Result<()> {
    write_json(path, value)
}

/// Reads a JSON file.
///
/// # Errors
/// [`JobError::Io`] / [`JobError::Json`] (with line and column) naming the file.
pub fn load_json<T: serde::de::DeserializeOwned>(path: &Path) -> Result<T> {
    let bytes = std::fs::read(path).map_err(|source| JobError::Io {
        path: path.to_path_buf(),
        source,
    })?;
    serde_json::from_slice(&bytes).map_err(|source| JobError::Json {
        path: path.to_path_buf(),
        source,
    })
}
