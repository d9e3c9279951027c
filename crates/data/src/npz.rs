//! NumPy `.npy` arrays and `.npz` archives (a zip of `.npy` members), read and written.
//!
//! Supported element types: little-endian `f8`, `f4`, `i8`, `i4`, `u1`, `b1` (read as `f64`
//! or `i64`), and fixed-width unicode `<U{n}` (read as strings). C order only, as NumPy writes
//! by default; Fortran-ordered arrays are transposed on read so the returned data are always
//! in C (row-major) order.
//!
//! numpy opens what this module writes with `np.load(path)`.

use std::collections::BTreeMap;
use std::io::{Read, Seek, Write};
use std::path::{Path, PathBuf};

use crate::atomic::write_atomic;

/// Errors reading or writing `.npy`/`.npz` data.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum NpzError {
    /// Underlying I/O failure.
    #[error("{path}: {source}")]
    Io {
        /// File involved.
        path: PathBuf,
        /// The I/O error.
        source: std::io::Error,
    },
    /// The zip container is corrupt or truncated.
    #[error("{path}: not a readable .npz archive ({message})")]
    Zip {
        /// File involved.
        path: PathBuf,
        /// What the zip reader reported.
        message: String,
    },
    /// A requested array is not in the archive.
    #[error("{path}: array '{name}' is missing")]
    Missing {
        /// File involved.
        path: PathBuf,
        /// The array name.
        name: String,
    },
    /// An array's header or payload is malformed.
    #[error("{path}: array '{name}': {message}")]
    Malformed {
        /// File involved.
        path: PathBuf,
        /// The array name.
        name: String,
        /// What is wrong.
        message: String,
    },
}

/// Decodes a whole `.npy` byte buffer (any numeric dtype, C or Fortran order) as `f64`.
///
/// # Errors
/// What is wrong with the header or the payload.
pub fn decode_npy_f64(bytes: &[u8]) -> Result<Array<f64>, String> {
    split_npy(bytes).and_then(|(h, p)| decode_numeric(&h, p))
}

/// An array read from a `.npy` member: its shape and its values in C order.
#[derive(Debug, Clone, PartialEq)]
pub struct Array<T> {
    /// Shape (empty for a 0-d scalar).
    pub shape: Vec<usize>,
    /// Values in C (row-major) order; `shape.iter().product()` of them.
    pub data: Vec<T>,
}

impl<T: Copy> Array<T> {
    /// The single value of a 0-d or one-element array.
    pub fn scalar(&self) -> Option<T> {
        (self.data.len() == 1).then(|| self.data[0])
    }
}

/// Element kind parsed from a `descr` string.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Kind {
    F8,
    F4,
    I8,
    I4,
    U1,
    B1,
    Unicode(usize),
}

struct Header {
    kind: Kind,
    fortran: bool,
    shape: Vec<usize>,
}

fn parse_header(text: &str) -> Result<Header, String> {
    let field = |key: &str| -> Result<&str, String> {
        let pat = format!("'{key}':");
        let start = text
            .find(&pat)
            .ok_or_else(|| format!("header lacks '{key}'"))?
            + pat.len();
        Ok(text[start..].trim_start())
    };
    let descr_rest = field("descr")?;
    let descr = descr_rest
        .strip_prefix('\'')
        .and_then(|s| s.split('\'').next())
        .ok_or("descr is not a string")?;
    let kind = match descr {
        "<f8" | "f8" => Kind::F8,
        "<f4" | "f4" => Kind::F4,
        "<i8" | "i8" => Kind::I8,
        "<i4" | "i4" => Kind::I4,
        "|u1" | "<u1" | "u1" => Kind::U1,
        "|b1" | "b1" => Kind::B1,
        d if d.starts_with("<U") => {
            Kind::Unicode(d[2..].parse().map_err(|_| format!("bad descr {d}"))?)
        }
        d => {
            return Err(format!(
                "unsupported dtype '{d}' (expected little-endian f8/f4/i8/i4/u1/b1/U)"
            ));
        }
    };
    let fortran = field("fortran_order")?.starts_with("True");
    let shape_rest = field("shape")?;
    let inner = shape_rest
        .strip_prefix('(')
        .and_then(|s| s.split(')').next())
        .ok_or("shape is not a tuple")?;
    let shape = inner
        .split(',')
        .map(str::trim)
        .filter(|s| !s.is_empty())
        .map(|s| {
            s.parse::<usize>()
                .map_err(|_| format!("bad shape entry '{s}'"))
        })
        .collect::<Result<Vec<_>, _>>()?;
    Ok(Header {
        kind,
        fortran,
        shape,
    })
}

/// Parses a whole `.npy` byte buffer into header and payload.
fn split_npy(bytes: &[u8]) -> Result<(Header, &[u8]), String> {
    if bytes.len() < 10 || &bytes[..6] != b"\x93NUMPY" {
        return Err("not a .npy array (bad magic)".into());
    }
    let (hlen, start) = match bytes[6] {
        1 => (u16::from_le_bytes([bytes[8], bytes[9]]) as usize, 10),
        2 | 3 => {
            if bytes.len() < 12 {
                return Err("truncated header".into());
            }
            (
                u32::from_le_bytes([bytes[8], bytes[9], bytes[10], bytes[11]]) as usize,
                12,
            )
        }
        v => return Err(format!("unsupported .npy version {v}")),
    };
    let end = start + hlen;
    if bytes.len() < end {
        return Err("truncated header".into());
    }
    let text = std::str::from_utf8(&bytes[start..end]).map_err(|_| "header is not text")?;
    Ok((parse_header(text)?, &bytes[end..]))
}

fn element_size(kind: Kind) -> usize {
    match kind {
        Kind::F8 | Kind::I8 => 8,
        Kind::F4 | Kind::I4 => 4,
        Kind::U1 | Kind::B1 => 1,
        Kind::Unicode(n) => 4 * n,
    }
}

/// Reorders Fortran-ordered data into C order.
fn fortran_to_c<T: Clone>(shape: &[usize], data: Vec<T>) -> Vec<T> {
    if shape.len() < 2 {
        return data;
    }
    let n = data.len();
    let mut out = Vec::with_capacity(n);
    let mut idx = vec![0usize; shape.len()];
    for _ in 0..n {
        // C-order multi-index `idx` → Fortran linear offset.
        let mut off = 0;
        let mut stride = 1;
        for (d, &i) in idx.iter().enumerate() {
            off += i * stride;
            stride *= shape[d];
        }
        out.push(data[off].clone());
        for d in (0..shape.len()).rev() {
            idx[d] += 1;
            if idx[d] < shape[d] {
                break;
            }
            idx[d] = 0;
        }
    }
    out
}

fn decode_numeric(header: &Header, payload: &[u8]) -> Result<Array<f64>, String> {
    let n: usize = header.shape.iter().product();
    let size = element_size(header.kind);
    if payload.len() < n * size {
        return Err(format!(
            "truncated data: {} bytes for {n} elements of {size} bytes",
            payload.len()
        ));
    }
    let chunks = payload[..n * size].chunks_exact(size);
    let data: Vec<f64> = match header.kind {
        Kind::F8 => chunks
            .map(|c| f64::from_le_bytes(c.try_into().unwrap()))
            .collect(),
        Kind::F4 => chunks
            .map(|c| f32::from_le_bytes(c.try_into().unwrap()) as f64)
            .collect(),
        Kind::I8 => chunks
            .map(|c| i64::from_le_bytes(c.try_into().unwrap()) as f64)
            .collect(),
        Kind::I4 => chunks
            .map(|c| i32::from_le_bytes(c.try_into().unwrap()) as f64)
            .collect(),
        Kind::U1 | Kind::B1 => chunks.map(|c| c[0] as f64).collect(),
        Kind::Unicode(_) => return Err("is a string array, expected numbers".into()),
    };
    let data = if header.fortran {
        fortran_to_c(&header.shape, data)
    } else {
        data
    };
    Ok(Array {
        shape: header.shape.clone(),
        data,
    })
}

fn decode_strings(header: &Header, payload: &[u8]) -> Result<Array<String>, String> {
    let Kind::Unicode(width) = header.kind else {
        return Err("is not a unicode string array".into());
    };
    let n: usize = header.shape.iter().product();
    let size = 4 * width;
    if payload.len() < n * size {
        return Err("truncated data".into());
    }
    let mut data = Vec::with_capacity(n);
    for c in payload[..n * size].chunks_exact(size) {
        let s: String = c
            .chunks_exact(4)
            .map(|b| u32::from_le_bytes(b.try_into().unwrap()))
            .take_while(|&cp| cp != 0)
            .map(|cp| char::from_u32(cp).ok_or("invalid code point"))
            .collect::<Result<_, _>>()?;
        data.push(s);
    }
    let data = if header.fortran {
        fortran_to_c(&header.shape, data)
    } else {
        data
    };
    Ok(Array {
        shape: header.shape.clone(),
        data,
    })
}

/// A `.npz` archive opened for reading; members are decoded on demand.
pub struct NpzReader {
    path: PathBuf,
    archive: zip::ZipArchive<std::io::BufReader<std::fs::File>>,
}

impl NpzReader {
    /// Opens an `.npz` file.
    ///
    /// # Errors
    /// [`NpzError::Io`] if the file cannot be opened, [`NpzError::Zip`] if it is not a zip
    /// archive (corrupt or truncated).
    pub fn open(path: impl AsRef<Path>) -> Result<Self, NpzError> {
        let path = path.as_ref().to_path_buf();
        let file = std::fs::File::open(&path).map_err(|source| NpzError::Io {
            path: path.clone(),
            source,
        })?;
        let archive =
            zip::ZipArchive::new(std::io::BufReader::new(file)).map_err(|e| NpzError::Zip {
                path: path.clone(),
                message: e.to_string(),
            })?;
        Ok(Self { path, archive })
    }

    /// Names of the arrays in the archive (without the `.npy` suffix), sorted.
    pub fn names(&self) -> Vec<String> {
        let mut v: Vec<String> = self
            .archive
            .file_names()
            .map(|n| n.strip_suffix(".npy").unwrap_or(n).to_string())
            .collect();
        v.sort();
        v
    }

    /// True if the archive holds an array called `name`.
    pub fn contains(&self, name: &str) -> bool {
        self.archive
            .file_names()
            .any(|n| n == format!("{name}.npy") || n == name)
    }

    fn raw(&mut self, name: &str) -> Result<Vec<u8>, NpzError> {
        let member = format!("{name}.npy");
        let mut file = match self.archive.by_name(&member) {
            Ok(f) => f,
            Err(zip::result::ZipError::FileNotFound) => {
                return Err(NpzError::Missing {
                    path: self.path.clone(),
                    name: name.to_string(),
                });
            }
            Err(e) => {
                return Err(NpzError::Zip {
                    path: self.path.clone(),
                    message: e.to_string(),
                });
            }
        };
        let mut buf = Vec::with_capacity(file.size() as usize);
        file.read_to_end(&mut buf)
            .map_err(|e| NpzError::Malformed {
                path: self.path.clone(),
                name: name.to_string(),
                message: format!("cannot decompress: {e}"),
            })?;
        Ok(buf)
    }

    fn malformed(&self, name: &str, message: String) -> NpzError {
        NpzError::Malformed {
            path: self.path.clone(),
            name: name.to_string(),
            message,
        }
    }

    /// Reads a numeric array as `f64` (integers and booleans are converted exactly).
    pub fn f64(&mut self, name: &str) -> Result<Array<f64>, NpzError> {
        let bytes = self.raw(name)?;
        split_npy(&bytes)
            .and_then(|(h, p)| decode_numeric(&h, p))
            .map_err(|m| self.malformed(name, m))
    }

    /// Reads a numeric array and checks its shape.
    ///
    /// # Errors
    /// [`NpzError::Malformed`] naming the expected and found shapes.
    pub fn f64_shaped(&mut self, name: &str, shape: &[usize]) -> Result<Vec<f64>, NpzError> {
        let a = self.f64(name)?;
        if a.shape != shape {
            return Err(self.malformed(name, format!("shape {:?}, expected {:?}", a.shape, shape)));
        }
        Ok(a.data)
    }

    /// Reads a scalar (0-d or one-element) numeric array.
    pub fn scalar(&mut self, name: &str) -> Result<f64, NpzError> {
        let a = self.f64(name)?;
        a.scalar()
            .ok_or_else(|| self.malformed(name, format!("shape {:?}, expected a scalar", a.shape)))
    }

    /// Reads a unicode string array.
    pub fn strings(&mut self, name: &str) -> Result<Array<String>, NpzError> {
        let bytes = self.raw(name)?;
        split_npy(&bytes)
            .and_then(|(h, p)| decode_strings(&h, p))
            .map_err(|m| self.malformed(name, m))
    }
}

/// A member to be written into an `.npz` archive.
#[derive(Debug, Clone)]
pub enum NpyData {
    /// `float64` values.
    F64(Vec<f64>),
    /// `int64` values.
    I64(Vec<i64>),
    /// `bool` values.
    Bool(Vec<bool>),
    /// Unicode strings (`<U{max len}`).
    Str(Vec<String>),
}

fn npy_bytes(shape: &[usize], data: &NpyData) -> Vec<u8> {
    let (descr, n) = match data {
        NpyData::F64(v) => ("<f8".to_string(), v.len()),
        NpyData::I64(v) => ("<i8".to_string(), v.len()),
        NpyData::Bool(v) => ("|b1".to_string(), v.len()),
        NpyData::Str(v) => (
            format!(
                "<U{}",
                v.iter()
                    .map(|s| s.chars().count())
                    .max()
                    .unwrap_or(0)
                    .max(1)
            ),
            v.len(),
        ),
    };
    debug_assert_eq!(n, shape.iter().product::<usize>());
    let shape_txt = match shape.len() {
        0 => "()".to_string(),
        1 => format!("({},)", shape[0]),
        _ => format!(
            "({})",
            shape
                .iter()
                .map(|s| s.to_string())
                .collect::<Vec<_>>()
                .join(", ")
        ),
    };
    let mut header =
        format!("{{'descr': '{descr}', 'fortran_order': False, 'shape': {shape_txt}, }}");
    // Pad so that magic (6) + version (2) + len (2) + header + '\n' is a multiple of 64.
    let total = 10 + header.len() + 1;
    header.push_str(&" ".repeat((64 - total % 64) % 64));
    header.push('\n');
    let mut out = Vec::with_capacity(10 + header.len() + n * 8);
    out.extend_from_slice(b"\x93NUMPY\x01\x00");
    out.extend_from_slice(&(header.len() as u16).to_le_bytes());
    out.extend_from_slice(header.as_bytes());
    match data {
        NpyData::F64(v) => v
            .iter()
            .for_each(|x| out.extend_from_slice(&x.to_le_bytes())),
        NpyData::I64(v) => v
            .iter()
            .for_each(|x| out.extend_from_slice(&x.to_le_bytes())),
        NpyData::Bool(v) => v.iter().for_each(|&x| out.push(x as u8)),
        NpyData::Str(v) => {
            let width = descr[2..].parse::<usize>().unwrap();
            for s in v {
                let mut k = 0;
                for ch in s.chars() {
                    out.extend_from_slice(&(ch as u32).to_le_bytes());
                    k += 1;
                }
                for _ in k..width {
                    out.extend_from_slice(&0u32.to_le_bytes());
                }
            }
        }
    }
    out
}

/// Builds an `.npz` archive in memory, then writes it atomically.
#[derive(Debug)]
pub struct NpzWriter {
    members: BTreeMap<String, (Vec<usize>, NpyData)>,
    compress: bool,
}

impl Default for NpzWriter {
    fn default() -> Self {
        Self {
            members: BTreeMap::new(),
            compress: true,
        }
    }
}

impl NpzWriter {
    /// An empty archive (members deflate-compressed, like `np.savez_compressed`).
    pub fn new() -> Self {
        Self::default()
    }

    /// Chooses deflate compression (default) or stored members (like `np.savez`): stored
    /// members are larger for compressible data but several times faster to write and read.
    pub fn compression(&mut self, compress: bool) -> &mut Self {
        self.compress = compress;
        self
    }

    /// Adds an array. `shape` must multiply to the number of values.
    ///
    /// # Panics
    /// If the shape does not match the data length (a programming error, not user data).
    pub fn add(&mut self, name: &str, shape: &[usize], data: NpyData) -> &mut Self {
        let n = match &data {
            NpyData::F64(v) => v.len(),
            NpyData::I64(v) => v.len(),
            NpyData::Bool(v) => v.len(),
            NpyData::Str(v) => v.len(),
        };
        assert_eq!(
            n,
            shape.iter().product::<usize>(),
            "npz member '{name}': shape {shape:?} does not match {n} values"
        );
        self.members
            .insert(name.to_string(), (shape.to_vec(), data));
        self
    }

    /// Writes the archive to `writer` (see [`NpzWriter::compression`]).
    pub fn write_to<W: Write + Seek>(&self, writer: W) -> std::io::Result<()> {
        let mut zip = zip::ZipWriter::new(writer);
        let method = if self.compress {
            zip::CompressionMethod::Deflated
        } else {
            zip::CompressionMethod::Stored
        };
        let opts = zip::write::SimpleFileOptions::default()
            .compression_method(method)
            .large_file(false);
        for (name, (shape, data)) in &self.members {
            zip.start_file(format!("{name}.npy"), opts)
                .map_err(std::io::Error::other)?;
            zip.write_all(&npy_bytes(shape, data))?;
        }
        zip.finish().map_err(std::io::Error::other)?;
        Ok(())
    }

    /// Writes the archive to `path` atomically (temporary file, then rename).
    pub fn save(&self, path: impl AsRef<Path>) -> Result<(), NpzError> {
        let path = path.as_ref();
        write_atomic(path, |f| self.write_to(f)).map_err(|source| NpzError::Io {
            path: path.to_path_buf(),
            source,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_trip_all_kinds() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("a.npz");
        let mut w = NpzWriter::new();
        w.add(
            "x",
            &[2, 3],
            NpyData::F64(vec![1.0, -2.5, 3.0, 4.0, 5.0, f64::MAX]),
        )
        .add("n", &[], NpyData::I64(vec![42]))
        .add("b", &[3], NpyData::Bool(vec![true, false, true]))
        .add(
            "s",
            &[2],
            NpyData::Str(vec!["oval".into(), "figure-eight".into()]),
        );
        w.save(&path).unwrap();
        let mut r = NpzReader::open(&path).unwrap();
        assert_eq!(r.names(), vec!["b", "n", "s", "x"]);
        let x = r.f64("x").unwrap();
        assert_eq!(x.shape, vec![2, 3]);
        assert_eq!(x.data, vec![1.0, -2.5, 3.0, 4.0, 5.0, f64::MAX]);
        assert_eq!(r.scalar("n").unwrap(), 42.0);
        assert_eq!(r.f64("b").unwrap().data, vec![1.0, 0.0, 1.0]);
        assert_eq!(r.strings("s").unwrap().data, vec!["oval", "figure-eight"]);
        assert!(matches!(r.f64("zzz"), Err(NpzError::Missing { .. })));
        assert!(matches!(r.f64("s"), Err(NpzError::Malformed { .. })));
    }

    #[test]
    fn stored_members_round_trip() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("s.npz");
        let x: Vec<f64> = (0..100).map(|i| i as f64 * 0.5).collect();
        NpzWriter::new()
            .compression(false)
            .add("x", &[10, 10], NpyData::F64(x.clone()))
            .save(&path)
            .unwrap();
        // 100 doubles stored verbatim: the file is larger than the payload.
        assert!(std::fs::metadata(&path).unwrap().len() > 800);
        assert_eq!(NpzReader::open(&path).unwrap().f64("x").unwrap().data, x);
    }

    #[test]
    fn fortran_order_is_transposed() {
        // 2×3 array [[0,1,2],[3,4,5]] stored column-major: 0,3,1,4,2,5.
        let c = fortran_to_c(&[2, 3], vec![0, 3, 1, 4, 2, 5]);
        assert_eq!(c, vec![0, 1, 2, 3, 4, 5]);
    }

    #[test]
    fn truncated_archive_is_an_error() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("a.npz");
        let mut w = NpzWriter::new();
        w.add(
            "x",
            &[1000],
            NpyData::F64((0..1000).map(|i| i as f64).collect()),
        );
        w.save(&path).unwrap();
        let bytes = std::fs::read(&path).unwrap();
        std::fs::write(&path, &bytes[..bytes.len() / 2]).unwrap();
        assert!(NpzReader::open(&path).is_err());
    }

    #[test]
    fn reads_reference_files() {
        let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../shared/reference");
        let mut r = NpzReader::open(root.join("elastic-net/reference.npz")).unwrap();
        assert_eq!(r.f64("X").unwrap().shape, vec![2000, 11]);
        assert_eq!(r.scalar("index_1se").unwrap().fract(), 0.0);
        let mut r = NpzReader::open(root.join("bayiz2021-prssm/reference.npz")).unwrap();
        assert_eq!(r.scalar("num_particles").unwrap(), 30.0);
        assert_eq!(r.f64("x_particles").unwrap().shape, vec![470, 30, 12]);
    }
}
