//! MATLAB Level 4 files: a sequence of variables, each a 20-byte header (type code, rows,
//! columns, imaginary flag, name length), the name and the column-major data.

use super::{
    DType, MatClass, MatError, MatFile, MatOptions, MatVariable, c_string, col_major_to_row_major,
    decode,
};

impl MatFile {
    pub(super) fn parse_v4(&mut self, bytes: &[u8], options: MatOptions) -> Result<(), MatError> {
        let mut pos = 0;
        while pos < bytes.len() {
            let start = pos;
            if bytes.len() - pos < 20 {
                return Err(self.format_err(start, "truncated Level 4 variable header"));
            }
            let le = u32::from_le_bytes(bytes[pos..pos + 4].try_into().unwrap());
            let be = u32::from_be_bytes(bytes[pos..pos + 4].try_into().unwrap());
            let plausible = |t: u32| t < 5000 && (t / 100) % 10 == 0;
            let big = match (plausible(le), plausible(be)) {
                (true, _) => false,
                (false, true) => true,
                _ => {
                    return Err(self.format_err(
                        start,
                        format!("not a MAT file (Level 4 type field {le:#x} is invalid)"),
                    ));
                }
            };
            let word = |k: usize| {
                let b: [u8; 4] = bytes[pos + 4 * k..pos + 4 * k + 4].try_into().unwrap();
                if big {
                    u32::from_be_bytes(b)
                } else {
                    u32::from_le_bytes(b)
                }
            };
            let (mopt, m, n, imagf, namlen) = (
                word(0),
                word(1) as usize,
                word(2) as usize,
                word(3),
                word(4) as usize,
            );
            pos += 20;
            let (machine, prec, kind) = (mopt / 1000, (mopt / 10) % 10, mopt % 10);
            if pos + namlen > bytes.len() {
                return Err(self.format_err(start, "truncated variable name"));
            }
            let name = c_string(&bytes[pos..pos + namlen]);
            pos += namlen;
            let (dtype, size) = match prec {
                0 => (DType::F64, 8),
                1 => (DType::F32, 4),
                2 => (DType::I32, 4),
                3 => (DType::I16, 2),
                4 => (DType::U16, 2),
                5 => (DType::U8, 1),
                p => return Err(self.format_err(start, format!("'{name}': unknown precision {p}"))),
            };
            let count = m
                .checked_mul(n)
                .and_then(|c| c.checked_mul(size))
                .ok_or_else(|| self.format_err(start, format!("'{name}': size overflow")))?;
            let total = if imagf != 0 { 2 * count } else { count };
            if bytes.len() - pos < total {
                return Err(self.format_err(
                    start,
                    format!(
                        "'{name}': truncated data ({} of {total} bytes)",
                        bytes.len() - pos
                    ),
                ));
            }
            let payload = &bytes[pos..pos + count];
            pos += total;
            let reason = match (machine, kind, imagf) {
                (0 | 1, 0, 0) => None,
                (0 | 1, 1, _) => Some("text matrix".to_string()),
                (0 | 1, 2, _) => Some("sparse matrix".to_string()),
                (0 | 1, 0, _) => Some("complex matrix".to_string()),
                (0 | 1, t, _) => Some(format!("unknown matrix type {t}")),
                (mach, _, _) => Some(format!("non-IEEE number format (machine id {mach})")),
            };
            if let Some(reason) = reason {
                self.skip(options, name, reason)?;
                continue;
            }
            let class = match dtype {
                DType::F32 => MatClass::Single,
                _ => MatClass::Double,
            };
            let col_major = decode(dtype, payload, machine == 1);
            self.variables.push(MatVariable {
                name,
                data: col_major_to_row_major(&[m, n], &col_major),
                dims: vec![m, n],
                class,
                logical: false,
            });
        }
        Ok(())
    }
}
