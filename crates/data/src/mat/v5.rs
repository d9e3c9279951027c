//! MATLAB Level 5 files (v5, v6, v7): a 128-byte header, then data elements; `miMATRIX`
//! elements hold variables, `miCOMPRESSED` elements a zlib stream of more elements.

use std::io::Read;

use super::{
    DType, MatClass, MatError, MatFile, MatOptions, MatVariable, c_string, col_major_to_row_major,
    decode, read_u32,
};

impl MatFile {
    pub(super) fn parse_v5(&mut self, bytes: &[u8], options: MatOptions) -> Result<(), MatError> {
        let big = &bytes[126..128] == b"MI";
        let mut pos = 128;
        while pos < bytes.len() {
            let start = pos;
            // Some writers pad the end of the file; a tag needs 8 bytes.
            if bytes.len() - pos < 8 {
                if bytes[pos..].iter().all(|&b| b == 0) {
                    break;
                }
                return Err(self.format_err(start, "truncated data element tag"));
            }
            let tag = Tag::read(&bytes[pos..], big);
            if tag.small {
                pos += 8;
                continue;
            }
            let body_start = pos + 8;
            let Some(body) = bytes.get(body_start..body_start + tag.nbytes) else {
                return Err(self.format_err(
                    start,
                    format!(
                        "truncated element: {} bytes announced, {} left",
                        tag.nbytes,
                        bytes.len() - body_start
                    ),
                ));
            };
            match tag.dtype {
                MI_COMPRESSED => {
                    let mut inflated = Vec::new();
                    flate2::read::ZlibDecoder::new(body)
                        .read_to_end(&mut inflated)
                        .map_err(|e| {
                            self.format_err(start, format!("corrupt compressed element: {e}"))
                        })?;
                    if inflated.len() < 8 {
                        return Err(self.format_err(start, "empty compressed element"));
                    }
                    let inner = Tag::read(&inflated, big);
                    let Some(inner_body) = inflated.get(8..8 + inner.nbytes) else {
                        return Err(self.format_err(start, "truncated compressed element"));
                    };
                    if inner.dtype == MI_MATRIX {
                        self.parse_matrix(inner_body, big, start, options)?;
                    }
                    pos = body_start + tag.nbytes;
                }
                MI_MATRIX => {
                    self.parse_matrix(body, big, start, options)?;
                    pos = body_start + pad8(tag.nbytes);
                }
                _ => pos = body_start + pad8(tag.nbytes),
            }
        }
        Ok(())
    }

    /// Parses the body of an `miMATRIX` element.
    fn parse_matrix(
        &mut self,
        body: &[u8],
        big: bool,
        offset: usize,
        options: MatOptions,
    ) -> Result<(), MatError> {
        if body.is_empty() {
            return Ok(());
        }
        let mut subs = SubElements { body, pos: 0, big };
        let path = self.path.clone();
        let mut next = |what: &str| {
            subs.next().ok_or_else(|| MatError::Format {
                path: path.clone(),
                offset,
                message: format!("array lacks its {what}"),
            })
        };
        let (_, flags) = next("array flags")?;
        if flags.len() < 8 {
            return Err(self.format_err(offset, "array flags too short"));
        }
        let flag_word = read_u32(&flags[..4], big);
        let class_id = flag_word & 0xff;
        let complex = flag_word & 0x0800 != 0;
        let logical = flag_word & 0x0200 != 0;
        let (dims_type, dims_raw) = next("dimensions")?;
        let dims: Vec<usize> = decode(
            DType::from_mi(dims_type).unwrap_or(DType::I32),
            dims_raw,
            big,
        )
        .into_iter()
        .map(|d| d.max(0.0) as usize)
        .collect();
        let (_, name_raw) = next("name")?;
        let name = c_string(name_raw);
        let class = match class_id {
            6 => MatClass::Double,
            7 => MatClass::Single,
            8 => MatClass::Int8,
            9 => MatClass::Uint8,
            10 => MatClass::Int16,
            11 => MatClass::Uint16,
            12 => MatClass::Int32,
            13 => MatClass::Uint32,
            14 => MatClass::Int64,
            15 => MatClass::Uint64,
            other => {
                let kind = match other {
                    1 => "cell array".to_string(),
                    2 => "struct".to_string(),
                    3 => "object".to_string(),
                    4 => "char array".to_string(),
                    5 => "sparse array".to_string(),
                    c => format!("unknown class {c}"),
                };
                return self.skip(options, name, kind);
            }
        };
        if complex {
            return self.skip(options, name, "complex array".into());
        }
        let (data_type, data_raw) = next("real part")?;
        let dtype = DType::from_mi(data_type).ok_or_else(|| {
            self.format_err(
                offset,
                format!("'{name}': unsupported data type {data_type}"),
            )
        })?;
        let n: usize = dims.iter().product();
        let col_major = decode(dtype, data_raw, big);
        if col_major.len() != n {
            return Err(self.format_err(
                offset,
                format!(
                    "'{name}': {} values stored for dimensions {dims:?}",
                    col_major.len()
                ),
            ));
        }
        self.variables.push(MatVariable {
            name,
            data: col_major_to_row_major(&dims, &col_major),
            dims,
            class,
            logical,
        });
        Ok(())
    }
}

const MI_MATRIX: u32 = 14;
const MI_COMPRESSED: u32 = 15;

fn pad8(n: usize) -> usize {
    n.div_ceil(8) * 8
}

/// A Level 5 data element tag (normal 8-byte or small 4-byte form).
struct Tag {
    dtype: u32,
    nbytes: usize,
    small: bool,
}

impl Tag {
    /// Reads a tag from at least 8 bytes.
    fn read(b: &[u8], big: bool) -> Tag {
        let w0 = read_u32(b, big);
        if w0 >> 16 != 0 {
            Tag {
                dtype: w0 & 0xffff,
                nbytes: (w0 >> 16) as usize,
                small: true,
            }
        } else {
            Tag {
                dtype: w0,
                nbytes: read_u32(&b[4..], big) as usize,
                small: false,
            }
        }
    }
}

/// Iterates over the sub-elements of an `miMATRIX` body: (data type, payload).
struct SubElements<'a> {
    body: &'a [u8],
    pos: usize,
    big: bool,
}

impl<'a> Iterator for SubElements<'a> {
    type Item = (u32, &'a [u8]);
    fn next(&mut self) -> Option<Self::Item> {
        let rest = self.body.get(self.pos..)?;
        if rest.len() < 8 {
            return None;
        }
        let tag = Tag::read(rest, self.big);
        if tag.small {
            self.pos += 8;
            return rest.get(4..4 + tag.nbytes).map(|p| (tag.dtype, p));
        }
        let payload = rest.get(8..8 + tag.nbytes)?;
        self.pos += 8 + pad8(tag.nbytes);
        Some((tag.dtype, payload))
    }
}
