//! Column tables of system-identification records, read from whitespace-separated ASCII
//! (`.dat`, no header; columns named `0`, `1`, …), CSV with a header line, or MAT variables.
//!
//! All values must be finite numbers. Lines that are empty or start with `#` or `%` are
//! skipped in ASCII and CSV files. Line and column numbers in errors are 1-based.

use std::path::{Path, PathBuf};

use crate::mat::{MatError, MatFile};

/// Errors reading or selecting table columns.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum TableError {
    /// The file cannot be read.
    #[error("{path}: {error}")]
    Io {
        /// File involved.
        path: PathBuf,
        /// The I/O error.
        error: std::io::Error,
    },
    /// A field is not a finite number.
    #[error("{path}: line {line}, column {column}: '{text}' is not a finite number")]
    Number {
        /// File involved.
        path: PathBuf,
        /// Line (1-based).
        line: usize,
        /// Column (1-based).
        column: usize,
        /// The field text.
        text: String,
    },
    /// A row has a different number of fields than the first.
    #[error("{path}: line {line} has {found} fields, expected {expected}")]
    Ragged {
        /// File involved.
        path: PathBuf,
        /// Line (1-based).
        line: usize,
        /// Fields found.
        found: usize,
        /// Fields expected.
        expected: usize,
    },
    /// A malformed line (e.g. an unterminated quote).
    #[error("{path}: line {line}: {message}")]
    Syntax {
        /// File involved.
        path: PathBuf,
        /// Line (1-based).
        line: usize,
        /// What is wrong.
        message: String,
    },
    /// The file holds no data row.
    #[error("{path}: no data rows")]
    Empty {
        /// File involved.
        path: PathBuf,
    },
    /// A selected column does not exist.
    #[error("{path}: no column {column} (available: {available})")]
    UnknownColumn {
        /// File involved.
        path: PathBuf,
        /// The selection as written.
        column: String,
        /// Available names, with their 0-based indices.
        available: String,
    },
    /// A MAT variable cannot be used as table columns.
    #[error("{path}: variable '{variable}' has dimensions {dims:?}: {message}")]
    MatShape {
        /// File involved.
        path: PathBuf,
        /// Variable name.
        variable: String,
        /// Its dimensions.
        dims: Vec<usize>,
        /// What is wrong.
        message: String,
    },
    /// Reading the MAT file failed.
    #[error(transparent)]
    Mat(#[from] MatError),
}

/// A column selection: by name or by 0-based index.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Column {
    /// By header name (or MAT variable name).
    Name(String),
    /// By 0-based position.
    Index(usize),
}

impl std::str::FromStr for Column {
    type Err = std::convert::Infallible;
    /// All digits → [`Column::Index`], anything else → [`Column::Name`].
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        Ok(match s.parse::<usize>() {
            Ok(i) => Column::Index(i),
            Err(_) => Column::Name(s.to_string()),
        })
    }
}

impl std::fmt::Display for Column {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Column::Name(n) => write!(f, "'{n}'"),
            Column::Index(i) => write!(f, "#{i}"),
        }
    }
}

/// Named columns of equal length.
#[derive(Debug, Clone, PartialEq)]
pub struct Table {
    /// File the table was read from (for messages).
    pub source: PathBuf,
    /// Column names.
    pub names: Vec<String>,
    /// Columns, each of [`Table::n_rows`] values.
    pub columns: Vec<Vec<f64>>,
}

/// Whether every field of a line is a number: a data row, not a header of column names.
pub fn is_number_row(fields: &[String]) -> bool {
    fields.iter().all(|f| f.trim().parse::<f64>().is_ok())
}

/// The file's text, without a leading UTF-8 byte-order mark (spreadsheet exports write one).
fn read_text(path: &Path) -> Result<String, TableError> {
    let text = std::fs::read_to_string(path).map_err(|error| TableError::Io {
        path: path.to_path_buf(),
        error,
    })?;
    Ok(match text.strip_prefix('\u{feff}') {
        Some(rest) => rest.to_string(),
        None => text,
    })
}

fn is_skipped(line: &str) -> bool {
    let t = line.trim();
    t.is_empty() || t.starts_with('#') || t.starts_with('%')
}

impl Table {
    /// Number of rows.
    pub fn n_rows(&self) -> usize {
        self.columns.first().map_or(0, Vec::len)
    }

    /// Reads by extension: `.mat` (all numeric vector/matrix variables, see
    /// [`Table::read_mat`]), `.csv` ([`Table::read_csv`]), anything else as whitespace ASCII.
    ///
    /// # Errors
    /// As the reader chosen.
    pub fn read(path: &Path) -> Result<Table, TableError> {
        match path.extension().and_then(|e| e.to_str()) {
            Some(e) if e.eq_ignore_ascii_case("mat") => Table::read_mat(path, &[]),
            Some(e) if e.eq_ignore_ascii_case("csv") => Table::read_csv(path),
            _ => Table::read_ascii(path),
        }
    }

    /// Reads whitespace-separated numbers without header; columns are named `0`, `1`, ….
    ///
    /// # Errors
    /// [`TableError::Number`] or [`TableError::Ragged`] naming the line, [`TableError::Empty`].
    pub fn read_ascii(path: &Path) -> Result<Table, TableError> {
        let text = read_text(path)?;
        let mut columns: Vec<Vec<f64>> = Vec::new();
        for (k, line) in text.lines().enumerate().filter(|(_, l)| !is_skipped(l)) {
            push_row(path, k + 1, line.split_whitespace(), &mut columns)?;
        }
        finish(
            path,
            (0..columns.len()).map(|i| i.to_string()).collect(),
            columns,
        )
    }

    /// Reads a CSV file whose first non-comment line is a header of unique column names (a
    /// leading UTF-8 byte-order mark is skipped).
    ///
    /// # Errors
    /// As [`Table::read_ascii`], plus [`TableError::Syntax`] for a malformed line, a header
    /// name given twice (a column selected by name would otherwise be the first of them) or a
    /// first line of numbers (it would otherwise be taken as names and the row lost).
    pub fn read_csv(path: &Path) -> Result<Table, TableError> {
        let text = read_text(path)?;
        let mut lines = text.lines().enumerate().filter(|(_, l)| !is_skipped(l));
        let (hk, header) = lines.next().ok_or_else(|| TableError::Empty {
            path: path.to_path_buf(),
        })?;
        let syntax = |line: usize, message: String| TableError::Syntax {
            path: path.to_path_buf(),
            line,
            message,
        };
        let names: Vec<String> = split_csv_line(header).map_err(|m| syntax(hk + 1, m))?;
        if is_number_row(&names) {
            return Err(syntax(
                hk + 1,
                "the first line holds numbers, not column names: a CSV needs a header line \
                 (plain numbers: a whitespace-separated file with another extension)"
                    .into(),
            ));
        }
        for (j, name) in names.iter().enumerate() {
            if let Some(i) = names[..j].iter().position(|n| n.trim() == name.trim()) {
                return Err(syntax(
                    hk + 1,
                    format!(
                        "header name '{}' names columns {} and {}; names must be unique",
                        name.trim(),
                        i + 1,
                        j + 1
                    ),
                ));
            }
        }
        let mut columns: Vec<Vec<f64>> = vec![Vec::new(); names.len()];
        for (k, line) in lines {
            let fields = split_csv_line(line).map_err(|m| syntax(k + 1, m))?;
            push_row(path, k + 1, fields.iter().map(String::as_str), &mut columns)?;
        }
        finish(path, names, columns)
    }

    /// Reads MAT variables as columns. Each variable must be a vector (n×1 or 1×n, one column
    /// named after it) or an n×k matrix (k columns named `name[0]`, …). With `variables`
    /// empty, every numeric variable of the file is taken.
    ///
    /// # Errors
    /// [`TableError::Mat`] (including a missing variable), [`TableError::MatShape`] for
    /// N-D arrays or columns of different lengths.
    pub fn read_mat(path: &Path, variables: &[&str]) -> Result<Table, TableError> {
        let mut mat = MatFile::read(path)?;
        let wanted: Vec<String> = if variables.is_empty() {
            mat.names().iter().map(|s| s.to_string()).collect()
        } else {
            variables.iter().map(|s| s.to_string()).collect()
        };
        let mut names = Vec::new();
        let mut columns: Vec<Vec<f64>> = Vec::new();
        for name in &wanted {
            let v = mat.take(name)?;
            let shape_err = |message: String| TableError::MatShape {
                path: path.to_path_buf(),
                variable: name.clone(),
                dims: v.dims.clone(),
                message,
            };
            let (rows, cols) = match *v.shape() {
                [1, n] | [n, 1] => (n, 1),
                [r, c] => (r, c),
                _ => return Err(shape_err("expected a vector or a matrix".into())),
            };
            if let Some(first) = columns.first()
                && first.len() != rows
            {
                return Err(shape_err(format!(
                    "{rows} rows, but column '{}' has {}",
                    names[0],
                    first.len()
                )));
            }
            if let Some(k) = v.data.iter().position(|x| !x.is_finite()) {
                return Err(shape_err(format!(
                    "element {} (row {}, column {}) is {}, not a finite number",
                    k,
                    k / cols + 1,
                    k % cols + 1,
                    v.data[k]
                )));
            }
            for j in 0..cols {
                names.push(if cols == 1 {
                    name.clone()
                } else {
                    format!("{name}[{j}]")
                });
                columns.push((0..rows).map(|i| v.data[i * cols + j]).collect());
            }
        }
        finish(path, names, columns)
    }

    /// Index of a selected column.
    ///
    /// # Errors
    /// [`TableError::UnknownColumn`] listing the available columns.
    pub fn index_of(&self, column: &Column) -> Result<usize, TableError> {
        let found = match column {
            Column::Name(n) => self.names.iter().position(|m| m == n),
            Column::Index(i) => (*i < self.columns.len()).then_some(*i),
        };
        found.ok_or_else(|| TableError::UnknownColumn {
            path: self.source.clone(),
            column: column.to_string(),
            available: self
                .names
                .iter()
                .enumerate()
                .map(|(i, n)| format!("#{i} '{n}'"))
                .collect::<Vec<_>>()
                .join(", "),
        })
    }

    /// The values of one column.
    ///
    /// # Errors
    /// [`TableError::UnknownColumn`].
    pub fn column(&self, column: &Column) -> Result<&[f64], TableError> {
        Ok(&self.columns[self.index_of(column)?])
    }

    /// A table of the selected columns, in the order given.
    ///
    /// # Errors
    /// [`TableError::UnknownColumn`].
    pub fn select(&self, columns: &[Column]) -> Result<Table, TableError> {
        let idx = columns
            .iter()
            .map(|c| self.index_of(c))
            .collect::<Result<Vec<_>, _>>()?;
        Ok(Table {
            source: self.source.clone(),
            names: idx.iter().map(|&i| self.names[i].clone()).collect(),
            columns: idx.iter().map(|&i| self.columns[i].clone()).collect(),
        })
    }
}

fn push_row<'a>(
    path: &Path,
    line: usize,
    fields: impl Iterator<Item = &'a str>,
    columns: &mut Vec<Vec<f64>>,
) -> Result<(), TableError> {
    let first_row = columns.is_empty() || columns.iter().all(Vec::is_empty);
    let mut n = 0;
    for (j, f) in fields.enumerate() {
        let f = f.trim();
        let v = f
            .parse::<f64>()
            .ok()
            .filter(|v| v.is_finite())
            .ok_or_else(|| TableError::Number {
                path: path.to_path_buf(),
                line,
                column: j + 1,
                text: f.to_string(),
            })?;
        if first_row && j >= columns.len() {
            columns.push(Vec::new());
        }
        if let Some(c) = columns.get_mut(j) {
            c.push(v);
        }
        n += 1;
    }
    if n != columns.len() {
        return Err(TableError::Ragged {
            path: path.to_path_buf(),
            line,
            found: n,
            expected: columns.len(),
        });
    }
    Ok(())
}

fn finish(path: &Path, names: Vec<String>, columns: Vec<Vec<f64>>) -> Result<Table, TableError> {
    if columns.first().is_none_or(Vec::is_empty) {
        return Err(TableError::Empty {
            path: path.to_path_buf(),
        });
    }
    Ok(Table {
        source: path.to_path_buf(),
        names,
        columns,
    })
}

/// Splits one CSV line into fields; `"…"` quoting with `""` escapes is understood.
///
/// # Errors
/// A message for an unterminated quote.
pub fn split_csv_line(line: &str) -> Result<Vec<String>, String> {
    let mut out = Vec::new();
    let mut field = String::new();
    let mut chars = line.trim_end_matches('\r').chars().peekable();
    let mut quoted = false;
    while let Some(c) = chars.next() {
        match (quoted, c) {
            (false, ',') => out.push(std::mem::take(&mut field)),
            (false, '"') if field.trim().is_empty() => {
                field.clear();
                quoted = true;
            }
            (true, '"') if chars.peek() == Some(&'"') => {
                chars.next();
                field.push('"');
            }
            (true, '"') => quoted = false,
            (_, c) => field.push(c),
        }
    }
    if quoted {
        return Err("unterminated quoted field".into());
    }
    out.push(field);
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sysid(name: &str) -> PathBuf {
        Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../../../shared/data/sysid")
            .join(name)
    }

    fn col(t: &Table, c: &str) -> Vec<f64> {
        t.column(&c.parse().unwrap()).unwrap().to_vec()
    }

    #[test]
    fn ballbeam_dat_matches_csv() {
        let dat = Table::read(&sysid("ballbeam.dat")).unwrap();
        let csv = Table::read(&sysid("ballbeam.csv")).unwrap();
        assert_eq!(dat.names, vec!["0", "1"]);
        assert_eq!(csv.names, vec!["u", "y"]);
        assert_eq!(dat.n_rows(), 1000);
        // The .dat has 8 significant digits; the CSV the same numbers with 17 digits.
        assert_eq!(col(&dat, "0"), col(&csv, "u"));
        assert_eq!(col(&dat, "1"), col(&csv, "y"));
    }

    #[test]
    fn mat_variables_match_csv() {
        let csv = Table::read_csv(&sysid("actuator.csv")).unwrap();
        let mat = Table::read_mat(&sysid("actuator.mat"), &["u", "p"]).unwrap();
        assert_eq!(mat.names, vec!["u", "p"]);
        assert_eq!(mat.columns[0], col(&csv, "u"));
        assert_eq!(mat.columns[1], col(&csv, "y"));
        let csv = Table::read_csv(&sysid("drive.csv")).unwrap();
        let mat = Table::read(&sysid("drive.mat")).unwrap();
        assert_eq!(mat.n_rows(), 500);
        assert_eq!(col(&mat, "u1"), col(&csv, "u"));
        assert_eq!(col(&mat, "z1"), col(&csv, "y"));
        let sel = mat
            .select(&["z1".parse().unwrap(), Column::Index(1)])
            .unwrap();
        assert_eq!(sel.names, vec!["z1", "u1"]);
    }

    #[test]
    fn errors_name_line_and_column() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("r.dat");
        std::fs::write(&p, "1 2\n# note\n3 4\n5\n").unwrap();
        let e = Table::read_ascii(&p).unwrap_err();
        assert!(
            matches!(
                e,
                TableError::Ragged {
                    line: 4,
                    found: 1,
                    expected: 2,
                    ..
                }
            ),
            "{e}"
        );
        let p = dir.path().join("n.csv");
        std::fs::write(&p, "a,b\n1,2\n3,x\n").unwrap();
        let e = Table::read_csv(&p).unwrap_err().to_string();
        assert!(e.contains("n.csv: line 3, column 2: 'x'"), "{e}");
        std::fs::write(&p, "a,b\n1,2\n3,nan\n").unwrap();
        assert!(Table::read_csv(&p).is_err());
        // Regression: a MAT variable with NaN gave 'test RMSE NaN' in sysid (CSV/DAT refused it).
        let mat = dir.path().join("nan.mat");
        let mut bytes = Vec::new();
        for v in [0i32, 3, 1, 0, 2] {
            bytes.extend_from_slice(&v.to_le_bytes()); // level 4: double, 3 × 1, name "u"
        }
        bytes.extend_from_slice(b"u\0");
        for v in [1.0f64, f64::NAN, 3.0] {
            bytes.extend_from_slice(&v.to_le_bytes());
        }
        std::fs::write(&mat, bytes).unwrap();
        let e = Table::read_mat(&mat, &["u"]).unwrap_err().to_string();
        assert!(
            e.contains("nan.mat: variable 'u'") && e.contains("(row 2, column 1) is NaN"),
            "{e}"
        );
        // Regression: a header-less CSV lost its first row (taken as names).
        std::fs::write(&p, "1,2\n3,4\n").unwrap();
        let e = Table::read_csv(&p).unwrap_err().to_string();
        assert!(e.contains("line 1: the first line holds numbers"), "{e}");
        // A byte-order mark is not part of the first name.
        std::fs::write(&p, "\u{feff}a,b\n1,2\n").unwrap();
        assert_eq!(Table::read_csv(&p).unwrap().names, ["a", "b"]);
        // Regression: a repeated header name used to select the first of its columns twice.
        std::fs::write(&p, "# c\nx,y, x\n1,2,3\n").unwrap();
        let e = Table::read_csv(&p).unwrap_err().to_string();
        assert!(
            e.contains("n.csv: line 2: header name 'x' names columns 1 and 3"),
            "{e}"
        );
        std::fs::write(&p, "a,b\n1,2\n").unwrap();
        let t = Table::read_csv(&p).unwrap();
        let e = t.column(&"c".parse().unwrap()).unwrap_err().to_string();
        assert!(e.contains("'c'") && e.contains("#0 'a', #1 'b'"), "{e}");
        assert!(t.column(&Column::Index(2)).is_err());
        let e = Table::read_mat(&sysid("drive.mat"), &["u9"])
            .unwrap_err()
            .to_string();
        assert!(e.contains("'u9' is missing") && e.contains("z1"), "{e}");
    }
}
