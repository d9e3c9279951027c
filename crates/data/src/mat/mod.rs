//! MATLAB `.mat` readers: Level 4 (v4), Level 5 (v5, v6, v7 incl. zlib-compressed
//! `miCOMPRESSED` elements) and the HDF5-based v7.3.
//!
//! Supported variables: numeric full arrays of any class (double, single, int8…uint64, also
//! logical), any number of dimensions, stored in any numeric type (e.g. a double array saved as
//! int16). Values are returned as `f64` in **row-major (C) order** with MATLAB's dimensions
//! (`dims = [n_rows, n_cols, …]`): element `(i, j, k)` of a 3-D array is
//! `data[(i·n_cols + j)·n_pages + k]`. int64/uint64 values beyond 2⁵³ lose precision.
//!
//! Char, cell, struct, object, sparse and complex variables are skipped (listed in
//! [`MatFile::skipped`]), or rejected with [`MatError::Unsupported`] when
//! [`MatOptions::strict`] is set.

use std::path::{Path, PathBuf};

mod v4;
mod v5;
mod v73;

/// Errors reading a `.mat` file.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum MatError {
    /// The file cannot be read.
    #[error("{path}: {error}")]
    Io {
        /// File involved.
        path: PathBuf,
        /// The I/O error.
        error: std::io::Error,
    },
    /// The file is malformed, truncated or corrupt.
    #[error("{path}: byte {offset}: {message}")]
    Format {
        /// File involved.
        path: PathBuf,
        /// Byte offset of the element at fault (in the decompressed stream for compressed
        /// elements: offset of the compressed element).
        offset: usize,
        /// What is wrong.
        message: String,
    },
    /// A variable of an unsupported kind: on reading with [`MatOptions::strict`], or when a
    /// skipped variable is asked for by name.
    #[error("{path}: variable '{variable}': {message}")]
    Unsupported {
        /// File involved.
        path: PathBuf,
        /// Variable name.
        variable: String,
        /// What is not supported.
        message: String,
    },
    /// A requested variable is not in the file.
    #[error("{path}: variable '{variable}' is missing (file has: {available})")]
    Missing {
        /// File involved.
        path: PathBuf,
        /// Requested name.
        variable: String,
        /// Comma-separated names of the numeric variables present.
        available: String,
    },
    /// A variable has the wrong shape for its use.
    #[error("{path}: variable '{variable}' has dimensions {found:?}, expected {expected}")]
    Shape {
        /// File involved.
        path: PathBuf,
        /// Variable name.
        variable: String,
        /// Dimensions found.
        found: Vec<usize>,
        /// Expected shape, in words.
        expected: String,
    },
}

/// Options of [`MatFile::read_with`].
#[derive(Debug, Clone, Copy, Default)]
pub struct MatOptions {
    /// Fail on char/cell/struct/object/sparse/complex variables instead of skipping them.
    pub strict: bool,
}

/// Which MAT-file level the file is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum MatVersion {
    /// Level 4 (`save -v4`).
    V4,
    /// Level 5 (`-v6`, `-v7`; `-v7` compresses each variable).
    V5,
    /// HDF5-based (`-v7.3`, the default of many installations).
    V73,
}

/// MATLAB class of a numeric variable.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub enum MatClass {
    /// double
    Double,
    /// single
    Single,
    /// int8
    Int8,
    /// uint8 (also `logical`, see [`MatVariable::logical`])
    Uint8,
    /// int16
    Int16,
    /// uint16
    Uint16,
    /// int32
    Int32,
    /// uint32
    Uint32,
    /// int64
    Int64,
    /// uint64
    Uint64,
}

/// One numeric variable.
#[derive(Debug, Clone, PartialEq)]
pub struct MatVariable {
    /// Variable name.
    pub name: String,
    /// MATLAB dimensions `[n_rows, n_cols, …]` (at least 2).
    pub dims: Vec<usize>,
    /// Values in row-major order, `dims.iter().product()` of them.
    pub data: Vec<f64>,
    /// MATLAB class.
    pub class: MatClass,
    /// True for `logical` arrays (values 0/1).
    pub logical: bool,
}

impl MatVariable {
    /// Number of elements.
    pub fn len(&self) -> usize {
        self.data.len()
    }
    /// True if the array has no element.
    pub fn is_empty(&self) -> bool {
        self.data.is_empty()
    }
    /// Dimensions without trailing singleton dimensions beyond the second (MATLAB drops them too).
    pub fn shape(&self) -> &[usize] {
        let mut n = self.dims.len();
        while n > 2 && self.dims[n - 1] == 1 {
            n -= 1;
        }
        &self.dims[..n]
    }
}

/// A parsed `.mat` file.
#[derive(Debug, Clone)]
pub struct MatFile {
    /// Path it was read from.
    pub path: PathBuf,
    /// File level.
    pub version: MatVersion,
    /// Numeric variables, in file order.
    pub variables: Vec<MatVariable>,
    /// Skipped variables: (name, reason).
    pub skipped: Vec<(String, String)>,
}

impl MatFile {
    /// Reads a `.mat` file, skipping unsupported variables.
    ///
    /// # Errors
    /// [`MatError::Io`] or [`MatError::Format`] (truncated, corrupt, not a MAT file).
    pub fn read(path: impl AsRef<Path>) -> Result<Self, MatError> {
        Self::read_with(path, MatOptions::default())
    }

    /// Reads a `.mat` file with options.
    ///
    /// # Errors
    /// As [`MatFile::read`], plus [`MatError::Unsupported`] in strict mode.
    pub fn read_with(path: impl AsRef<Path>, options: MatOptions) -> Result<Self, MatError> {
        let path = path.as_ref().to_path_buf();
        let bytes = std::fs::read(&path).map_err(|error| MatError::Io {
            path: path.clone(),
            error,
        })?;
        Self::parse(path, &bytes, options)
    }

    /// Parses the bytes of a `.mat` file; `path` is used in messages only.
    ///
    /// # Errors
    /// As [`MatFile::read_with`].
    pub fn parse(path: PathBuf, bytes: &[u8], options: MatOptions) -> Result<Self, MatError> {
        let mut file = MatFile {
            path,
            version: MatVersion::V4,
            variables: Vec::new(),
            skipped: Vec::new(),
        };
        let is_v5 = bytes.len() >= 128
            && (&bytes[126..128] == b"IM" || &bytes[126..128] == b"MI")
            && bytes[..4].iter().all(|&b| b != 0);
        // v7.3: the same 128-byte header, version 0x0200, HDF5 from byte 512.
        let is_v73 = is_v5
            && bytes.len() > 520
            && u16::from_le_bytes([bytes[124], bytes[125]]) == 0x0200
            && &bytes[512..520] == b"\x89HDF\r\n\x1a\n";
        if is_v73 {
            file.version = MatVersion::V73;
            file.parse_v73(bytes, options)?;
        } else if is_v5 {
            file.version = MatVersion::V5;
            file.parse_v5(bytes, options)?;
        } else {
            file.parse_v4(bytes, options)?;
        }
        Ok(file)
    }

    /// The numeric variable `name`.
    ///
    /// # Errors
    /// [`MatError::Unsupported`] for a variable of a kind that was skipped (char, cell, complex,
    /// …), saying which; [`MatError::Missing`] listing the variables present.
    pub fn get(&self, name: &str) -> Result<&MatVariable, MatError> {
        if let Some((_, reason)) = self.skipped.iter().find(|(n, _)| n == name) {
            return Err(MatError::Unsupported {
                path: self.path.clone(),
                variable: name.to_string(),
                message: format!("{reason}; only numeric arrays can be read"),
            });
        }
        self.variables
            .iter()
            .find(|v| v.name == name)
            .ok_or_else(|| MatError::Missing {
                path: self.path.clone(),
                variable: name.to_string(),
                available: self.names().join(", "),
            })
    }

    /// Takes ownership of the numeric variable `name` (see [`MatFile::get`]).
    ///
    /// # Errors
    /// [`MatError::Missing`].
    pub fn take(&mut self, name: &str) -> Result<MatVariable, MatError> {
        match self.variables.iter().position(|v| v.name == name) {
            Some(k) => Ok(self.variables.remove(k)),
            None => Err(self.get(name).unwrap_err()),
        }
    }

    /// Names of the numeric variables, in file order.
    pub fn names(&self) -> Vec<&str> {
        self.variables.iter().map(|v| v.name.as_str()).collect()
    }

    fn format_err(&self, offset: usize, message: impl Into<String>) -> MatError {
        MatError::Format {
            path: self.path.clone(),
            offset,
            message: message.into(),
        }
    }

    fn skip(&mut self, options: MatOptions, name: String, reason: String) -> Result<(), MatError> {
        if options.strict {
            return Err(MatError::Unsupported {
                path: self.path.clone(),
                variable: name,
                message: reason,
            });
        }
        self.skipped.push((name, reason));
        Ok(())
    }
}

pub(super) fn read_u32(b: &[u8], big: bool) -> u32 {
    let a: [u8; 4] = b[..4].try_into().unwrap();
    if big {
        u32::from_be_bytes(a)
    } else {
        u32::from_le_bytes(a)
    }
}

pub(super) fn c_string(b: &[u8]) -> String {
    let end = b.iter().position(|&c| c == 0).unwrap_or(b.len());
    String::from_utf8_lossy(&b[..end]).into_owned()
}

/// Storage type of numbers on disk.
#[derive(Debug, Clone, Copy)]
pub(super) enum DType {
    I8,
    U8,
    I16,
    U16,
    I32,
    U32,
    F32,
    F64,
    I64,
    U64,
}

impl DType {
    fn from_mi(t: u32) -> Option<DType> {
        Some(match t {
            1 => DType::I8,
            2 | 16 => DType::U8,
            3 => DType::I16,
            4 => DType::U16,
            5 => DType::I32,
            6 => DType::U32,
            7 => DType::F32,
            9 => DType::F64,
            12 => DType::I64,
            13 => DType::U64,
            _ => return None,
        })
    }
    fn size(self) -> usize {
        match self {
            DType::I8 | DType::U8 => 1,
            DType::I16 | DType::U16 => 2,
            DType::I32 | DType::U32 | DType::F32 => 4,
            DType::F64 | DType::I64 | DType::U64 => 8,
        }
    }
}

/// Decodes `bytes` as a sequence of `dtype` numbers (trailing partial element ignored).
pub(super) fn decode(dtype: DType, bytes: &[u8], big: bool) -> Vec<f64> {
    macro_rules! conv {
        ($t:ty) => {
            bytes
                .chunks_exact(dtype.size())
                .map(|c| {
                    let a = c.try_into().unwrap();
                    (if big {
                        <$t>::from_be_bytes(a)
                    } else {
                        <$t>::from_le_bytes(a)
                    }) as f64
                })
                .collect()
        };
    }
    match dtype {
        DType::I8 => bytes.iter().map(|&b| b as i8 as f64).collect(),
        DType::U8 => bytes.iter().map(|&b| b as f64).collect(),
        DType::I16 => conv!(i16),
        DType::U16 => conv!(u16),
        DType::I32 => conv!(i32),
        DType::U32 => conv!(u32),
        DType::F32 => conv!(f32),
        DType::F64 => conv!(f64),
        DType::I64 => conv!(i64),
        DType::U64 => conv!(u64),
    }
}

/// Reorders column-major (first index fastest) data into row-major (last index fastest).
pub(super) fn col_major_to_row_major(dims: &[usize], data: &[f64]) -> Vec<f64> {
    let n = data.len();
    if dims.len() < 2 || dims.iter().filter(|&&d| d > 1).count() < 2 {
        return data.to_vec();
    }
    // Column-major stride of each dimension.
    let mut stride = vec![1usize; dims.len()];
    for d in 1..dims.len() {
        stride[d] = stride[d - 1] * dims[d - 1];
    }
    let mut out = Vec::with_capacity(n);
    let mut idx = vec![0usize; dims.len()];
    let mut off = 0usize;
    let last = dims.len() - 1;
    for _ in 0..n {
        out.push(data[off]);
        let mut d = last;
        loop {
            idx[d] += 1;
            off += stride[d];
            if idx[d] < dims[d] {
                break;
            }
            off -= stride[d] * dims[d];
            idx[d] = 0;
            if d == 0 {
                break;
            }
            d -= 1;
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn fixture(name: &str) -> PathBuf {
        Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("tests/fixtures")
            .join(name)
    }

    fn sysid(name: &str) -> PathBuf {
        Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../../../shared/data/sysid")
            .join(name)
    }

    /// Column `col` of a `u,y` CSV written with 17 significant digits.
    fn csv_column(name: &str, col: usize) -> Vec<f64> {
        std::fs::read_to_string(sysid(name))
            .unwrap()
            .lines()
            .skip(1)
            .map(|l| l.split(',').nth(col).unwrap().trim().parse().unwrap())
            .collect()
    }

    /// The HDF5-based v7.3 layout (fixture from make_v73.py: the classes of classes_v5.mat,
    /// MATLAB's attributes and transposed storage, a deflated chunked column).
    #[test]
    fn all_classes_v73() {
        let m = MatFile::read(fixture("classes_v73.mat")).unwrap();
        assert_eq!(m.version, MatVersion::V73);
        let d3 = m.get("d3").unwrap();
        assert_eq!(d3.dims, vec![2, 3, 4]);
        assert_eq!(d3.data, (0..24).map(f64::from).collect::<Vec<_>>());
        let s2 = m.get("s2").unwrap();
        assert_eq!(
            (s2.class, s2.dims.as_slice()),
            (MatClass::Single, &[2, 3][..])
        );
        assert_eq!(s2.data, vec![1.5, -2.25, 3.0, 4.0, 5.0, -6.5]);
        let two53 = 2f64.powi(53);
        for (name, class, vals) in [
            ("i8", MatClass::Int8, [-128.0, 0.0, 127.0]),
            ("u16", MatClass::Uint16, [0.0, 9.0, 65535.0]),
            ("i32", MatClass::Int32, [-2147483648.0, 11.0, 2147483647.0]),
            ("u64", MatClass::Uint64, [0.0, 17.0, two53]),
            ("i64", MatClass::Int64, [-two53, 15.0, two53]),
        ] {
            let v = m.get(name).unwrap();
            assert_eq!((v.class, v.dims.as_slice()), (class, &[1, 3][..]), "{name}");
            assert_eq!(v.data, vals, "{name}");
        }
        let b = m.get("b").unwrap();
        assert!(b.logical);
        let col = m.get("col").unwrap();
        assert_eq!(col.dims, vec![1000, 1]);
        assert!(
            col.data
                .iter()
                .enumerate()
                .all(|(k, v)| *v == k as f64 / 8.0)
        );
        let mut skipped: Vec<&str> = m.skipped.iter().map(|(n, _)| n.as_str()).collect();
        skipped.sort();
        assert_eq!(skipped, vec!["st", "txt"]);
        assert!(m.get("txt").unwrap_err().to_string().contains("char"));
        // A table of its columns, as a rig recording is read.
        let t = crate::table::Table::read_mat(&fixture("classes_v73.mat"), &["col", "s2"]);
        assert!(t.is_err(), "columns of different lengths are refused");
    }

    #[test]
    fn all_classes_v5_plain_and_compressed() {
        for f in ["classes_v5.mat", "classes_v5z.mat"] {
            let m = MatFile::read(fixture(f)).unwrap();
            assert_eq!(m.version, MatVersion::V5);
            let d3 = m.get("d3").unwrap();
            assert_eq!(d3.dims, vec![2, 3, 4]);
            let expect: Vec<f64> = (0..24).map(f64::from).collect();
            assert_eq!(d3.data, expect, "{f}: a[i,j,l] = 12i + 4j + l");
            let s2 = m.get("s2").unwrap();
            assert_eq!(s2.class, MatClass::Single);
            assert_eq!(s2.data, vec![1.5, -2.25, 3.0, 4.0, 5.0, -6.5]);
            let two53 = 2f64.powi(53);
            for (name, class, vals) in [
                ("i8", MatClass::Int8, [-128.0, 0.0, 127.0]),
                ("u8", MatClass::Uint8, [0.0, 1.0, 255.0]),
                ("i16", MatClass::Int16, [-32768.0, 7.0, 32767.0]),
                ("u16", MatClass::Uint16, [0.0, 9.0, 65535.0]),
                ("i32", MatClass::Int32, [-2147483648.0, 11.0, 2147483647.0]),
                ("u32", MatClass::Uint32, [0.0, 13.0, 4294967295.0]),
                ("i64", MatClass::Int64, [-two53, 15.0, two53]),
                ("u64", MatClass::Uint64, [0.0, 17.0, two53]),
            ] {
                let v = m.get(name).unwrap();
                assert_eq!(
                    (v.class, v.dims.as_slice()),
                    (class, &[1, 3][..]),
                    "{f} {name}"
                );
                assert_eq!(v.data, vals, "{f} {name}");
            }
            let b = m.get("b").unwrap();
            assert!(b.logical);
            assert_eq!(b.data, vec![1.0, 0.0, 0.0, 1.0]);
            let skipped: Vec<&str> = m.skipped.iter().map(|(n, _)| n.as_str()).collect();
            assert_eq!(skipped, vec!["txt", "cel", "st"], "{f}");
            // Regression: a char variable asked for by name was reported "missing".
            let e = m.get("txt").unwrap_err().to_string();
            assert!(
                e.contains("'txt'") && e.contains("char") && !e.contains("missing"),
                "{e}"
            );
            let e = MatFile::read_with(fixture(f), MatOptions { strict: true }).unwrap_err();
            assert!(
                e.to_string().contains("'txt'") && e.to_string().contains("char"),
                "{e}"
            );
        }
    }

    #[test]
    fn level4_little_and_big_endian() {
        let m = MatFile::read(fixture("small_v4.mat")).unwrap();
        assert_eq!(m.version, MatVersion::V4);
        let m2 = m.get("m2").unwrap();
        assert_eq!(m2.dims, vec![3, 4]);
        let expect: Vec<f64> = (0..3)
            .flat_map(|i| (0..4).map(move |j| (10 * i + j) as f64))
            .collect();
        assert_eq!(m2.data, expect);
        assert_eq!(m.get("col").unwrap().data, vec![0.0, 1.0, 2.0, 3.0, 4.0]);

        // actuator.mat: big-endian Level 4; the CSV holds the same numbers (17 digits).
        let m = MatFile::read(sysid("actuator.mat")).unwrap();
        assert_eq!(m.version, MatVersion::V4);
        assert_eq!(m.names(), vec!["x", "u", "p"]);
        assert_eq!(m.get("u").unwrap().data, csv_column("actuator.csv", 0));
        assert_eq!(m.get("p").unwrap().data, csv_column("actuator.csv", 1));
    }

    #[test]
    fn drive_mat_int16_storage() {
        let m = MatFile::read(sysid("drive.mat")).unwrap();
        assert_eq!(m.version, MatVersion::V5);
        let u1 = m.get("u1").unwrap();
        assert_eq!(u1.dims, vec![500, 1]);
        assert_eq!(u1.data, csv_column("drive.csv", 0));
        assert_eq!(m.get("z1").unwrap().data, csv_column("drive.csv", 1));
    }

    #[test]
    fn missing_variable_lists_the_others() {
        let m = MatFile::read(fixture("small_v4.mat")).unwrap();
        let e = m.get("nope").unwrap_err().to_string();
        assert!(
            e.contains("small_v4.mat") && e.contains("'nope'") && e.contains("m2, col"),
            "{e}"
        );
    }

    #[test]
    fn truncated_and_corrupt_files_are_errors() {
        for f in ["classes_v5.mat", "classes_v5z.mat", "small_v4.mat"] {
            let bytes = std::fs::read(fixture(f)).unwrap();
            for cut in [bytes.len() - 3, bytes.len() / 2, 150] {
                let r = MatFile::parse(PathBuf::from(f), &bytes[..cut], MatOptions::default());
                assert!(r.is_err(), "{f} cut at {cut} parsed");
            }
        }
        let mut bytes = std::fs::read(fixture("classes_v5z.mat")).unwrap();
        for b in &mut bytes[200..260] {
            *b ^= 0xa5;
        }
        assert!(MatFile::parse("z.mat".into(), &bytes, MatOptions::default()).is_err());
        let e = MatFile::parse(
            "t.txt".into(),
            b"hello world, this is text",
            MatOptions::default(),
        )
        .unwrap_err();
        assert!(e.to_string().contains("not a MAT file"), "{e}");
    }

    /// A Level 5 file holding one uncompressed int16 2×3 array `v` (column-major 1..6),
    /// built byte by byte in either byte order.
    fn v5_int16(big: bool) -> Vec<u8> {
        let w32 = |x: u32| {
            if big {
                x.to_be_bytes()
            } else {
                x.to_le_bytes()
            }
        };
        let mut body = Vec::new();
        let sub = |body: &mut Vec<u8>, ty: u32, payload: &[u8]| {
            body.extend_from_slice(&w32(ty));
            body.extend_from_slice(&w32(payload.len() as u32));
            body.extend_from_slice(payload);
            body.resize(body.len().div_ceil(8) * 8, 0);
        };
        let flags: Vec<u8> = [w32(10), w32(0)].concat(); // class int16
        sub(&mut body, 6, &flags);
        let dims: Vec<u8> = [w32(2), w32(3)].concat();
        sub(&mut body, 5, &dims);
        sub(&mut body, 1, b"v");
        let data: Vec<u8> = (1i16..=6)
            .flat_map(|x| {
                if big {
                    x.to_be_bytes()
                } else {
                    x.to_le_bytes()
                }
            })
            .collect();
        sub(&mut body, 3, &data);
        let mut file = vec![b' '; 128];
        file[..6].copy_from_slice(b"MATLAB");
        file[124..126].copy_from_slice(if big { &[1, 0] } else { &[0, 1] });
        file[126..128].copy_from_slice(if big { b"MI" } else { b"IM" });
        file.extend_from_slice(&w32(14));
        file.extend_from_slice(&w32(body.len() as u32));
        file.extend_from_slice(&body);
        file
    }

    #[test]
    fn level5_both_byte_orders() {
        for big in [false, true] {
            let m = MatFile::parse("v.mat".into(), &v5_int16(big), MatOptions::default()).unwrap();
            let v = m.get("v").unwrap();
            assert_eq!((v.class, v.dims.as_slice()), (MatClass::Int16, &[2, 3][..]));
            // Column-major 1..6 of a 2×3 matrix is [[1, 3, 5], [2, 4, 6]].
            assert_eq!(v.data, vec![1.0, 3.0, 5.0, 2.0, 4.0, 6.0], "big = {big}");
        }
    }

    #[test]
    fn reorders_nd_column_major() {
        // 2×3×2 array with value 100 i + 10 j + k, stored column-major (i fastest).
        let dims = [2, 3, 2];
        let mut col = Vec::new();
        for k in 0..2 {
            for j in 0..3 {
                for i in 0..2 {
                    col.push((100 * i + 10 * j + k) as f64);
                }
            }
        }
        let row = col_major_to_row_major(&dims, &col);
        let mut n = 0;
        for i in 0..2 {
            for j in 0..3 {
                for k in 0..2 {
                    assert_eq!(row[n], (100 * i + 10 * j + k) as f64);
                    n += 1;
                }
            }
        }
    }
}
