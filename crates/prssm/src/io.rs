//! The model file: versioned, self-describing JSON.
//!
//! ```json
//! { "format": "flapssm-prssm-model", "version": 1,
//!   "model": { "config": {..}, "params": {..}, "normalization": null | {..}, "training": {..} } }
//! ```
//! `f64` values round-trip exactly (serde_json shortest representation, `float_roundtrip`).
//! Files are written atomically (temporary file + rename).

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use crate::model::PrssmModel;

/// Format tag of model files.
pub const MODEL_FORMAT: &str = "flapssm-prssm-model";
/// Current model-file version.
pub const MODEL_VERSION: u32 = 1;

/// Errors reading or writing a model file.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum ModelFileError {
    /// I/O failure.
    #[error("{path}: {source}")]
    Io {
        /// File.
        path: PathBuf,
        /// Cause.
        source: std::io::Error,
    },
    /// Not valid JSON of the expected structure (truncated, malformed, missing field).
    #[error("{path}: not a valid model file: {message}")]
    Parse {
        /// File.
        path: PathBuf,
        /// Parser message with line and column.
        message: String,
    },
    /// A different file type.
    #[error("{path}: format '{found}', expected '{MODEL_FORMAT}'")]
    Format {
        /// File.
        path: PathBuf,
        /// Found tag.
        found: String,
    },
    /// Written by a newer version of flapssm.
    #[error("{path}: model-file version {found} is newer than supported version {MODEL_VERSION}")]
    Version {
        /// File.
        path: PathBuf,
        /// Found version.
        found: u64,
    },
    /// Parses, but the contents are inconsistent.
    #[error("{path}: {source}")]
    Invalid {
        /// File.
        path: PathBuf,
        /// What is inconsistent.
        source: crate::params::ConfigError,
    },
}

#[derive(Serialize)]
struct FileOut<'a> {
    format: &'static str,
    version: u32,
    model: &'a PrssmModel,
}

fn not_a_model(path: &Path, message: &str) -> ModelFileError {
    ModelFileError::Parse {
        path: path.to_path_buf(),
        message: message.into(),
    }
}

/// The tags a file is recognized by before its body is parsed (another flapssm file, e.g. an
/// LRQSM model, carries `kind` instead of `format`).
#[derive(Deserialize)]
struct Header {
    format: Option<String>,
    kind: Option<String>,
    version: Option<u64>,
}

#[derive(Deserialize)]
struct FileIn {
    model: PrssmModel,
}

impl PrssmModel {
    /// The model file's text, compact ([`PrssmModel::from_json`] reads it back).
    ///
    /// # Errors
    /// A parameter that JSON cannot hold (never for a checked model).
    pub fn to_json(&self) -> Result<String, serde_json::Error> {
        serde_json::to_string(&FileOut {
            format: MODEL_FORMAT,
            version: MODEL_VERSION,
            model: self,
        })
    }

    /// Writes the model atomically as pretty JSON.
    ///
    /// # Errors
    /// [`ModelFileError::Io`].
    pub fn save(&self, path: &Path) -> Result<(), ModelFileError> {
        let out = FileOut {
            format: MODEL_FORMAT,
            version: MODEL_VERSION,
            model: self,
        };
        flapssm_data::atomic::write_atomic(path, |w| {
            serde_json::to_writer_pretty(&mut *w, &out).map_err(std::io::Error::other)
        })
        .map_err(|source| ModelFileError::Io {
            path: path.to_path_buf(),
            source,
        })
    }

    /// Reads and validates a model file.
    ///
    /// # Errors
    /// [`ModelFileError`] naming the file: unreadable, malformed/truncated, wrong format,
    /// future version, inconsistent contents.
    pub fn load(path: &Path) -> Result<Self, ModelFileError> {
        let bytes = std::fs::read(path).map_err(|source| ModelFileError::Io {
            path: path.to_path_buf(),
            source,
        })?;
        let not_json = |message: &str| ModelFileError::Parse {
            path: path.to_path_buf(),
            message: message.to_string(),
        };
        if bytes.starts_with(b"PK\x03\x04") {
            return Err(not_json(
                "a zip (.npz) archive, not a JSON model file (the authors' published .npz \
                 is converted by `flapssm model import-published`)",
            ));
        }
        let text = String::from_utf8(bytes).map_err(|e| {
            not_json(&format!(
                "not UTF-8 text (byte {})",
                e.utf8_error().valid_up_to()
            ))
        })?;
        Self::from_json(&text, path)
    }

    /// Parses model-file text (`path` only names the source in errors).
    ///
    /// # Errors
    /// As [`PrssmModel::load`].
    pub fn from_json(text: &str, path: &Path) -> Result<Self, ModelFileError> {
        let parse = |e: serde_json::Error| ModelFileError::Parse {
            path: path.to_path_buf(),
            message: e.to_string(),
        };
        let header: Header = serde_json::from_str(text).map_err(parse)?;
        if header.format.as_deref() != Some(MODEL_FORMAT) {
            return Err(ModelFileError::Format {
                path: path.to_path_buf(),
                found: header
                    .format
                    .or(header.kind)
                    .unwrap_or_else(|| "none".into()),
            });
        }
        let version = header
            .version
            .ok_or_else(|| not_a_model(path, "the field 'version' is missing"))?;
        if version > MODEL_VERSION as u64 {
            return Err(ModelFileError::Version {
                path: path.to_path_buf(),
                found: version,
            });
        }
        let file: FileIn = serde_json::from_str(text).map_err(parse)?;
        file.model
            .check()
            .map_err(|source| ModelFileError::Invalid {
                path: path.to_path_buf(),
                source,
            })?;
        Ok(file.model)
    }
}
