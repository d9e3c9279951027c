//! Long-format CSV of a dataset: one row per sample.
//!
//! ```text
//! # flapssm-dataset-csv 1
//! # dt_s: 0.04
//! # metadata: {"format_version":1,"wing":{…},…}
//! trajectory,family,split,t_s,stroke_rad,deviation_rad,pitch_rad,aoa,speed,a_x,a_y,a_z,pitch_rate,pitch_acc,F_x,F_y,M_x,M_y,M_z,u_ref_m_s
//! 0,oval,train,0,0.1,…
//! ```
//!
//! - `trajectory`: 0-based index; rows of one trajectory are contiguous and in time order.
//! - `split`: `train` or `test`; training trajectories come first.
//! - `t_s = sample · dt_s`; `u_ref_m_s`, `family`, `split` are repeated on every row.
//! - The 5 output fields are empty for kinematics-only datasets.
//! - Numbers are written in shortest round-trip form, so export → import is exact.
//! - Comment lines start with `#`: `pandas.read_csv(path, comment="#")` reads the table.

use std::io::Write;
use std::path::{Path, PathBuf};

use crate::dataset::{
    Dataset, DatasetError, DatasetMeta, EULER_NAMES, FORMAT_VERSION, INPUT_NAMES, OUTPUT_NAMES,
    Trajectory, ValidDataset,
};
use flapssm_data::atomic::write_atomic;
use flapssm_data::table::split_csv_line;

/// First line of every dataset CSV.
pub const CSV_MAGIC: &str = "# flapssm-dataset-csv";

/// Errors exporting or importing a dataset CSV. Lines and columns are 1-based.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum CsvError {
    /// The file cannot be read or written.
    #[error("{path}: {error}")]
    Io {
        /// File involved.
        path: PathBuf,
        /// The I/O error.
        error: std::io::Error,
    },
    /// A header comment or the column header is wrong.
    #[error("{path}: line {line}: {message}")]
    Header {
        /// File involved.
        path: PathBuf,
        /// Line.
        line: usize,
        /// What is wrong.
        message: String,
    },
    /// A data field is wrong.
    #[error("{path}: line {line}, column {column} ({name}): {message}")]
    Field {
        /// File involved.
        path: PathBuf,
        /// Line.
        line: usize,
        /// Column.
        column: usize,
        /// Column name.
        name: String,
        /// What is wrong.
        message: String,
    },
    /// The metadata comment is missing, not JSON, or of an unsupported version.
    #[error("{path}: metadata: {message}")]
    Metadata {
        /// File involved.
        path: PathBuf,
        /// What is wrong.
        message: String,
    },
    /// The assembled dataset is invalid (or, on export, the dataset given).
    #[error("{path}: {error}")]
    Invalid {
        /// File involved.
        path: PathBuf,
        /// The validation error.
        error: DatasetError,
    },
}

/// The 20 column names, in order.
pub fn csv_columns() -> Vec<String> {
    let mut c: Vec<String> = ["trajectory", "family", "split", "t_s"]
        .iter()
        .map(|s| s.to_string())
        .collect();
    c.extend(EULER_NAMES.iter().map(|n| format!("{n}_rad")));
    c.extend(INPUT_NAMES.iter().map(|s| s.to_string()));
    c.extend(OUTPUT_NAMES.iter().map(|s| s.to_string()));
    c.push("u_ref_m_s".into());
    c
}

fn quote(s: &str) -> String {
    if s.contains([',', '"', '\n', '\r']) {
        format!("\"{}\"", s.replace('"', "\"\""))
    } else {
        s.to_string()
    }
}

impl ValidDataset {
    /// Writes the dataset as long-format CSV (see [`crate::dataset::csv`]) atomically to `path`.
    ///
    /// # Errors
    /// [`CsvError::Io`] on I/O failure (no file is left behind).
    pub fn export_csv(&self, path: &Path) -> Result<(), CsvError> {
        let meta = serde_json::to_string(&self.meta).map_err(|e| CsvError::Metadata {
            path: path.to_path_buf(),
            message: e.to_string(),
        })?;
        write_atomic(path, |w| {
            writeln!(w, "{CSV_MAGIC} {FORMAT_VERSION}")?;
            writeln!(w, "# dt_s: {}", self.dt_s)?;
            writeln!(w, "# metadata: {meta}")?;
            writeln!(w, "{}", csv_columns().join(","))?;
            for (k, t) in self.trajectories.iter().enumerate() {
                let family = quote(&t.family);
                let split = if k < self.n_train { "train" } else { "test" };
                for i in 0..t.len() {
                    write!(w, "{k},{family},{split},{}", i as f64 * self.dt_s)?;
                    for v in t.euler_rad[i].iter().chain(&t.inputs[i]) {
                        write!(w, ",{v}")?;
                    }
                    match &t.outputs {
                        Some(y) => y[i].iter().try_for_each(|v| write!(w, ",{v}"))?,
                        None => write!(w, ",,,,,")?,
                    }
                    writeln!(w, ",{}", t.u_ref_m_s)?;
                }
            }
            Ok(())
        })
        .map_err(|error| CsvError::Io {
            path: path.to_path_buf(),
            error,
        })
    }
}

impl Dataset {
    /// Reads a long-format dataset CSV written by [`ValidDataset::export_csv`] (or by hand in
    /// the same layout) and validates it.
    ///
    /// # Errors
    /// A [`CsvError`] naming the file, line and column at fault.
    pub fn import_csv(path: &Path) -> Result<ValidDataset, CsvError> {
        let text = std::fs::read_to_string(path).map_err(|error| CsvError::Io {
            path: path.to_path_buf(),
            error,
        })?;
        CsvImport {
            path: path.to_path_buf(),
        }
        .parse(&text)
    }
}

struct CsvImport {
    path: PathBuf,
}

/// Per-trajectory constants, checked on every row.
struct Current {
    index: usize,
    family: String,
    train: bool,
    u_ref_m_s: f64,
}

impl CsvImport {
    fn header(&self, line: usize, message: impl Into<String>) -> CsvError {
        CsvError::Header {
            path: self.path.clone(),
            line,
            message: message.into(),
        }
    }

    fn field(&self, line: usize, column: usize, message: impl Into<String>) -> CsvError {
        CsvError::Field {
            path: self.path.clone(),
            line,
            column: column + 1,
            name: csv_columns()
                .get(column)
                .cloned()
                .unwrap_or_else(|| "?".into()),
            message: message.into(),
        }
    }

    fn metadata(&self, message: impl Into<String>) -> CsvError {
        CsvError::Metadata {
            path: self.path.clone(),
            message: message.into(),
        }
    }

    fn parse(&self, text: &str) -> Result<ValidDataset, CsvError> {
        let mut lines = text.lines().enumerate().map(|(k, l)| (k + 1, l));
        let mut dt_s = None;
        let mut meta = None;
        let (header_line, header) = loop {
            let Some((n, line)) = lines.next() else {
                return Err(self.header(1, "no column header line"));
            };
            if n == 1 {
                let version = line
                    .strip_prefix(CSV_MAGIC)
                    .map(str::trim)
                    .ok_or_else(|| self.header(1, format!("expected '{CSV_MAGIC} <version>'")))?;
                if version != FORMAT_VERSION.to_string() {
                    return Err(self.metadata(format!(
                        "format version '{version}' is not supported (this flapssm reads {FORMAT_VERSION})"
                    )));
                }
            } else if let Some(v) = line.strip_prefix("# dt_s:") {
                dt_s =
                    Some(v.trim().parse::<f64>().map_err(|_| {
                        self.header(n, format!("dt_s '{}' is not a number", v.trim()))
                    })?);
            } else if let Some(v) = line.strip_prefix("# metadata:") {
                let value: serde_json::Value = serde_json::from_str(v.trim())
                    .map_err(|e| self.metadata(format!("line {n}: not JSON: {e}")))?;
                match value.get("format_version").and_then(|v| v.as_u64()) {
                    Some(v) if v == u64::from(FORMAT_VERSION) => {}
                    Some(v) => {
                        return Err(self.metadata(format!(
                            "format_version {v} is not supported (this flapssm reads {FORMAT_VERSION})"
                        )));
                    }
                    None => return Err(self.metadata("lacks an integer 'format_version'")),
                }
                meta = Some(
                    serde_json::from_value::<DatasetMeta>(value)
                        .map_err(|e| self.metadata(format!("line {n}: {e}")))?,
                );
            } else if !line.starts_with('#') {
                break (n, line);
            }
        };
        let dt_s = dt_s.ok_or_else(|| self.header(header_line, "missing '# dt_s:' line"))?;
        let meta = meta.ok_or_else(|| self.metadata("missing '# metadata:' line"))?;
        let expected = csv_columns();
        let found = split_csv_line(header).map_err(|m| self.header(header_line, m))?;
        if found != expected {
            let first_diff = (0..expected.len().max(found.len()))
                .find(|&j| found.get(j) != expected.get(j))
                .unwrap_or(0);
            return Err(self.header(
                header_line,
                format!(
                    "column {} is {:?}, expected {:?} (expected header: {})",
                    first_diff + 1,
                    found.get(first_diff).map_or("<none>", String::as_str),
                    expected.get(first_diff).map_or("<none>", String::as_str),
                    expected.join(",")
                ),
            ));
        }
        let mut trajectories: Vec<Trajectory> = Vec::new();
        let mut n_train = 0;
        let mut with_y = None;
        let mut cur: Option<Current> = None;
        for (n, line) in lines {
            if line.trim().is_empty() || line.starts_with('#') {
                continue;
            }
            let f = split_csv_line(line).map_err(|m| self.header(n, m))?;
            if f.len() != expected.len() {
                return Err(self.header(
                    n,
                    format!("{} fields, expected {}", f.len(), expected.len()),
                ));
            }
            let num = |j: usize| -> Result<f64, CsvError> {
                f[j].trim()
                    .parse::<f64>()
                    .ok()
                    .filter(|v| v.is_finite())
                    .ok_or_else(|| self.field(n, j, format!("'{}' is not a finite number", f[j])))
            };
            let index = f[0]
                .trim()
                .parse::<usize>()
                .map_err(|_| self.field(n, 0, format!("'{}' is not an index", f[0])))?;
            let train = match f[2].trim() {
                "train" => true,
                "test" => false,
                s => return Err(self.field(n, 2, format!("'{s}' is neither train nor test"))),
            };
            let u_ref_m_s = num(19)?;
            let new_trajectory = cur.as_ref().is_none_or(|c| c.index != index);
            if new_trajectory {
                if index != trajectories.len() {
                    return Err(self.field(
                        n,
                        0,
                        format!(
                            "trajectory {index} where {} was expected (rows must be grouped, indices 0, 1, …)",
                            trajectories.len()
                        ),
                    ));
                }
                if train && n_train != trajectories.len() {
                    return Err(self.field(n, 2, "train trajectory after a test trajectory"));
                }
                n_train += usize::from(train);
                trajectories.push(Trajectory {
                    euler_rad: Vec::new(),
                    inputs: Vec::new(),
                    outputs: None,
                    u_ref_m_s,
                    family: f[1].clone(),
                });
                cur = Some(Current {
                    index,
                    family: f[1].clone(),
                    train,
                    u_ref_m_s,
                });
            }
            let c = cur.as_ref().expect("set above");
            if f[1] != c.family {
                return Err(self.field(
                    n,
                    1,
                    format!(
                        "'{}' differs from '{}' earlier in the trajectory",
                        f[1], c.family
                    ),
                ));
            }
            if train != c.train {
                return Err(self.field(n, 2, "split changes within a trajectory"));
            }
            if u_ref_m_s != c.u_ref_m_s {
                return Err(self.field(n, 19, "u_ref_m_s changes within a trajectory"));
            }
            let t = trajectories.last_mut().expect("pushed above");
            let sample = t.euler_rad.len();
            let t_s = num(3)?;
            let expected_t = sample as f64 * dt_s;
            if (t_s - expected_t).abs() > 1e-9 * (1.0 + expected_t.abs()) {
                return Err(self.field(
                    n,
                    3,
                    format!("{t_s} but sample {sample} at dt_s = {dt_s} is at {expected_t}"),
                ));
            }
            t.euler_rad.push([num(4)?, num(5)?, num(6)?]);
            let mut u = [0.0; 7];
            for (j, v) in u.iter_mut().enumerate() {
                *v = num(7 + j)?;
            }
            t.inputs.push(u);
            let has_y = f[14..19].iter().any(|s| !s.trim().is_empty());
            if *with_y.get_or_insert(has_y) != has_y {
                let what = if has_y { "present" } else { "empty" };
                return Err(self.field(
                    n,
                    14,
                    format!("outputs are {what} here but not on earlier rows"),
                ));
            }
            if has_y {
                let mut y = [0.0; 5];
                for (j, v) in y.iter_mut().enumerate() {
                    *v = num(14 + j)?;
                }
                t.outputs.get_or_insert_with(Vec::new).push(y);
            }
        }
        let ds = Dataset {
            meta,
            dt_s,
            trajectories,
            n_train,
        };
        ValidDataset::new(ds).map_err(|error| CsvError::Invalid {
            path: self.path.clone(),
            error,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dataset::tests::sample;

    #[test]
    fn round_trip_is_exact() {
        let dir = tempfile::tempdir().unwrap();
        for with_y in [true, false] {
            let p = dir.path().join("d.csv");
            let mut ds = sample(4, 6, 3, with_y);
            ds.trajectories[1].family = "a \"quoted\", family".into();
            ds.trajectories[2].inputs[3][1] = 0.1 + 0.2;
            ValidDataset::new(ds.clone())
                .unwrap()
                .export_csv(&p)
                .unwrap();
            assert_eq!(Dataset::import_csv(&p).unwrap(), ds);
        }
    }

    #[test]
    fn csv_line_splitting() {
        assert_eq!(
            split_csv_line("a,\"b,c\",\"d\"\"e\",").unwrap(),
            vec!["a", "b,c", "d\"e", ""]
        );
        assert!(split_csv_line("\"open").is_err());
    }

    fn edited(dir: &Path, edit: impl Fn(&mut Vec<String>)) -> Result<ValidDataset, CsvError> {
        let p = dir.join("e.csv");
        ValidDataset::new(sample(3, 4, 2, true))
            .unwrap()
            .export_csv(&p)
            .unwrap();
        let mut lines: Vec<String> = std::fs::read_to_string(&p)
            .unwrap()
            .lines()
            .map(String::from)
            .collect();
        edit(&mut lines);
        std::fs::write(&p, lines.join("\n")).unwrap();
        Dataset::import_csv(&p)
    }

    #[test]
    fn import_errors_name_line_and_column() {
        let dir = tempfile::tempdir().unwrap();
        let d = dir.path();
        // Line 6 = trajectory 0, sample 1; column 9 = speed.
        let e = edited(d, |l| {
            let mut f = split_csv_line(&l[5]).unwrap();
            f[8] = "NaN".into();
            l[5] = f.join(",");
        })
        .unwrap_err()
        .to_string();
        assert!(e.contains("e.csv: line 6, column 9 (speed)"), "{e}");
        let e = edited(d, |l| l[6].push_str(",1")).unwrap_err().to_string();
        assert!(
            e.contains("line 7") && e.contains("21 fields, expected 20"),
            "{e}"
        );
        let e = edited(d, |l| l[3] = l[3].replace("a_x", "ax"))
            .unwrap_err()
            .to_string();
        assert!(e.contains("line 4") && e.contains("\"ax\""), "{e}");
        let e = edited(d, |l| {
            l[2] = l[2].replace("\"format_version\":1", "\"format_version\":7");
        })
        .unwrap_err()
        .to_string();
        assert!(e.contains("format_version 7"), "{e}");
        let e = edited(d, |l| {
            l.remove(6);
        })
        .unwrap_err()
        .to_string();
        assert!(e.contains("t_s"), "{e}");
        let e = edited(d, |l| l.truncate(l.len() - 1)).unwrap_err();
        assert!(
            matches!(
                e,
                CsvError::Invalid {
                    error: DatasetError::LengthMismatch { trajectory: 2, .. },
                    ..
                }
            ),
            "{e}"
        );
        // Trajectory 0 (lines 5–8) marked test, trajectory 1 (line 9 on) still train.
        let e = edited(d, |l| {
            for line in &mut l[4..8] {
                *line = line.replace(",train,", ",test,");
            }
        })
        .unwrap_err()
        .to_string();
        assert!(
            e.contains("line 9, column 3 (split): train trajectory after"),
            "{e}"
        );
        let e = edited(d, |l| l[5] = l[5].replace(",train,", ",test,"))
            .unwrap_err()
            .to_string();
        assert!(e.contains("line 6, column 3 (split): split changes"), "{e}");
    }
}
