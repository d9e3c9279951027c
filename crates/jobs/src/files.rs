//! JSON and text files of the jobs, written atomically (temporary file and rename).

use std::path::Path;

use flapssm_data::atomic::refused;
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

/// Writes `text`, atomically.
///
/// # Errors
/// [`JobError::Io`] naming the file.
pub fn save_text(path: &Path, text: &str) -> Result<()> {
    write_text(path, text)
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

/// Reads a configuration file (JSON) of the fields that differ from `T::default()`: the file is
/// laid over the default, field by field at every depth (a missing field keeps the default's
/// value, also inside a nested table), and any field the configuration does not have is
/// refused (a misspelt `l3.lesp_critt` would otherwise be ignored without a word).
///
/// # Errors
/// [`JobError::Io`] / [`JobError::Json`] naming the file; [`JobError::Setting`] naming the file
/// and the unknown field's path.
pub fn load_config<T>(path: &Path) -> Result<T>
where
    T: serde::de::DeserializeOwned + Serialize + Default,
{
    config_from_value(load_json(path)?, path)
}

/// A configuration from parsed JSON `given` (from `source`, a file or a language binding's
/// name for it), laid over `T::default()` as [`load_config`] does.
///
/// # Errors
/// [`JobError::Json`] for a value of the wrong type; [`JobError::Setting`] naming `source` and
/// the unknown field's path.
pub fn config_from_value<T>(given: serde_json::Value, source: &Path) -> Result<T>
where
    T: serde::de::DeserializeOwned + Serialize + Default,
{
    let json_error = |source_error| JobError::Json {
        path: source.to_path_buf(),
        source: source_error,
    };
    let mut merged = serde_json::to_value(T::default()).map_err(json_error)?;
    lay_over(&mut merged, &given);
    let config: T = serde_json::from_value(merged).map_err(json_error)?;
    let known = serde_json::to_value(&config).map_err(json_error)?;
    if let Some(field) = unknown_field(&given, &known, "") {
        return Err(JobError::Setting {
            name: field,
            value: format!("(in {})", source.display()),
            expected: "no such field".into(),
        });
    }
    Ok(config)
}

/// Lays `given` over `base`: objects merge key by key, recursively; anything else replaces.
fn lay_over(base: &mut serde_json::Value, given: &serde_json::Value) {
    match (base, given) {
        (serde_json::Value::Object(base), serde_json::Value::Object(given)) => {
            for (key, value) in given {
                match base.get_mut(key) {
                    Some(slot) => lay_over(slot, value),
                    None => {
                        base.insert(key.clone(), value.clone());
                    }
                }
            }
        }
        (base, given) => *base = given.clone(),
    }
}

/// The first key path of `given` that `known` (the parsed value written back) lacks.
fn unknown_field(given: &serde_json::Value, known: &serde_json::Value, at: &str) -> Option<String> {
    let (serde_json::Value::Object(given), serde_json::Value::Object(known)) = (given, known)
    else {
        return None;
    };
    given.iter().find_map(|(key, value)| {
        let path = if at.is_empty() {
            key.clone()
        } else {
            format!("{at}.{key}")
        };
        match known.get(key) {
            None => Some(path),
            Some(k) => unknown_field(value, k, &path),
        }
    })
}

/// Checks, before any work, that every output file can be written
/// ([`flapssm_data::atomic::check_output`]: not `-`, a directory, a device or a dangling link;
/// its directory exists and is writable) and that none is one of the inputs, whatever the name
/// it is given by (`./x`, a symbolic or hard link), nor another output.
///
/// # Errors
/// [`JobError::Output`] naming the output and, for a clash, the input.
pub fn check_outputs(outputs: &[&Path], inputs: &[&Path]) -> Result<()> {
    for (k, out) in outputs.iter().enumerate() {
        flapssm_data::atomic::check_output(out).map_err(JobError::Output)?;
        let clash = |other: &Path, what: &str| {
            JobError::Output(refused(
                out,
                &format!(
                    "is the {what} {}; writing it would destroy it",
                    other.display()
                ),
            ))
        };
        if let Some(input) = inputs.iter().find(|i| same_file(out, i)) {
            return Err(clash(input, "input"));
        }
        if let Some(other) = outputs[..k].iter().find(|o| same_file(out, o)) {
            return Err(clash(other, "output"));
        }
    }
    Ok(())
}

/// [`check_outputs`] for a figure, whose extension must also name a format (`.png`, `.svg`).
///
/// # Errors
/// [`JobError::Analysis`] for another extension; [`check_outputs`]' errors.
pub fn check_figure_output(path: &Path, inputs: &[&Path]) -> Result<()> {
    flapssm_analysis::plots::Format::from_path(path).map_err(|source| JobError::Analysis {
        what: "figure".into(),
        source,
    })?;
    check_outputs(&[path], inputs)
}

/// Checks, before any work, that `dir` can be an output directory (an existing directory or a
/// new name in an existing one) and that the files the job will write in it, `files` (names
/// relative to `dir`), pass [`check_outputs`] against `inputs`: none is one of the inputs, a
/// directory, a device or a dangling link.
///
/// # Errors
/// [`JobError::Output`] for an existing non-directory, a missing parent or a refused file.
pub fn check_output_dir(dir: &Path, files: &[&str], inputs: &[&Path]) -> Result<()> {
    let refuse = |why: String| Err(JobError::Output(refused(dir, &why)));
    match std::fs::metadata(dir) {
        Ok(m) if m.is_dir() => {
            let paths: Vec<_> = files.iter().map(|f| dir.join(f)).collect();
            let existing: Vec<&Path> = paths
                .iter()
                .map(|p| p.as_path())
                .filter(|p| p.parent().is_some_and(Path::is_dir))
                .collect();
            check_outputs(&existing, inputs)
        }
        Ok(_) => refuse("exists and is not a directory".into()),
        Err(_) => match dir.parent().filter(|p| !p.as_os_str().is_empty()) {
            Some(p) if !p.is_dir() => refuse(format!("directory {} does not exist", p.display())),
            _ => Ok(()),
        },
    }
}

/// Whether `a` and `b` name the same existing file (same device and inode on Unix, same
/// canonical path elsewhere); a path that does not exist is no other file.
fn same_file(a: &Path, b: &Path) -> bool {
    let (Ok(ma), Ok(mb)) = (std::fs::metadata(a), std::fs::metadata(b)) else {
        return false;
    };
    #[cfg(unix)]
    {
        use std::os::unix::fs::MetadataExt;
        (ma.dev(), ma.ino()) == (mb.dev(), mb.ino())
    }
    #[cfg(not(unix))]
    {
        let _ = (ma, mb);
        std::fs::canonicalize(a).ok() == std::fs::canonicalize(b).ok()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_output_that_is_an_input_is_refused_by_any_name() {
        let dir = tempfile::tempdir().unwrap();
        let d = dir.path();
        let input = d.join("wing.npz");
        std::fs::write(&input, b"data").unwrap();
        let dotted = d.join(".").join("wing.npz");
        let e = check_outputs(&[&dotted], &[&input])
            .unwrap_err()
            .to_string();
        assert!(e.contains("is the input") && e.contains("wing.npz"), "{e}");
        #[cfg(unix)]
        {
            let link = d.join("link.npz");
            std::os::unix::fs::symlink(&input, &link).unwrap();
            assert!(check_outputs(&[&link], &[&input]).is_err());
            let hard = d.join("hard.npz");
            std::fs::hard_link(&input, &hard).unwrap();
            assert!(check_outputs(&[&hard], &[&input]).is_err());
        }
        let out = d.join("out.json");
        std::fs::write(&out, b"{}").unwrap();
        let e = check_outputs(&[&out, &out], &[&input])
            .unwrap_err()
            .to_string();
        assert!(e.contains("is the output"), "{e}");
        assert!(check_outputs(&[&out, &d.join("new.json")], &[&input]).is_ok());
        assert_eq!(std::fs::read(&input).unwrap(), b"data");

        let none: [&Path; 0] = [];
        assert!(check_output_dir(d, &["metrics.json"], &none).is_ok());
        assert!(check_output_dir(&d.join("new"), &["wing.npz"], &[&input]).is_ok());
        assert!(check_output_dir(&input, &[], &none).is_err());
        assert!(check_output_dir(&d.join("no/such"), &[], &none).is_err());
        let e = check_output_dir(d, &["metrics.json", "wing.npz"], &[&input])
            .unwrap_err()
            .to_string();
        assert!(e.contains("wing.npz: is the input"), "{e}");
        std::fs::create_dir(d.join("metrics.json")).unwrap();
        assert!(check_output_dir(d, &["metrics.json"], &none).is_err());
    }
}
