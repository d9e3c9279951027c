//! MATLAB v7.3 files (`save -v7.3`): an HDF5 file behind a 512-byte user block that holds the
//! MAT header. Each variable is a dataset of the root group with a `MATLAB_class` attribute;
//! HDF5 stores the array with its dimensions reversed (C order), i.e. MATLAB's column-major
//! layout. Read with `hdf5-reader` (pure Rust, read-only).

use hdf5_reader::{Datatype, H5Type, Hdf5File};

use super::{MatClass, MatError, MatFile, MatOptions, MatVariable, col_major_to_row_major};

impl MatFile {
    pub(super) fn parse_v73(&mut self, bytes: &[u8], options: MatOptions) -> Result<(), MatError> {
        let file = Hdf5File::from_bytes(bytes)
            .map_err(|e| self.format_err(0, format!("MAT v7.3 (HDF5): {e}")))?;
        let root = file
            .root_group()
            .map_err(|e| self.format_err(0, format!("MAT v7.3 root group: {e}")))?;
        let (groups, datasets) = root
            .members()
            .map_err(|e| self.format_err(0, format!("MAT v7.3 variables: {e}")))?;
        for g in groups {
            // Structs (and the references' `#refs#` group) are groups.
            if !g.name().starts_with('#') {
                self.skip(options, g.name().to_string(), "a struct".into())?;
            }
        }
        for ds in datasets {
            let name = ds.name().to_string();
            let class_name = ds
                .attribute("MATLAB_class")
                .and_then(|a| a.read_string())
                .unwrap_or_default();
            let class = match class_name.trim_end_matches('\0') {
                "double" => MatClass::Double,
                "single" => MatClass::Single,
                "int8" => MatClass::Int8,
                "uint8" | "logical" => MatClass::Uint8,
                "int16" => MatClass::Int16,
                "uint16" => MatClass::Uint16,
                "int32" => MatClass::Int32,
                "uint32" => MatClass::Uint32,
                "int64" => MatClass::Int64,
                "uint64" => MatClass::Uint64,
                "" => {
                    self.skip(options, name, "no MATLAB_class attribute".into())?;
                    continue;
                }
                other => {
                    self.skip(options, name, format!("a {other} array"))?;
                    continue;
                }
            };
            if ds.attribute("MATLAB_empty").is_ok() {
                self.skip(options, name, "an empty array".into())?;
                continue;
            }
            let numeric = matches!(
                ds.dtype(),
                Datatype::FloatingPoint { size: 4 | 8, .. } | Datatype::FixedPoint { .. }
            );
            if !numeric {
                // Complex arrays are compounds (real, imag).
                let reason = format!("a {class_name} array of a non-numeric HDF5 type (complex?)");
                self.skip(options, name, reason)?;
                continue;
            }
            let data = read_f64(&ds).map_err(|e| {
                self.format_err(0, format!("MAT v7.3 variable '{name}' ({class_name}): {e}"))
            })?;
            let mut dims: Vec<usize> = ds.shape().iter().rev().map(|&d| d as usize).collect();
            if dims.len() < 2 {
                dims.resize(2, 1);
            }
            self.variables.push(MatVariable {
                data: col_major_to_row_major(&dims, &data),
                dims,
                logical: class_name.trim_end_matches('\0') == "logical",
                class,
                name,
            });
        }
        Ok(())
    }
}

/// The values of a numeric dataset as f64, in the file's (C) order. int64/uint64 beyond 2⁵³
/// lose precision, as in the other levels.
fn read_f64(ds: &hdf5_reader::Dataset) -> Result<Vec<f64>, hdf5_reader::error::Error> {
    fn all<T: H5Type + Copy + Into<f64>>(
        ds: &hdf5_reader::Dataset,
    ) -> Result<Vec<f64>, hdf5_reader::error::Error> {
        Ok(ds.read_array::<T>()?.iter().map(|v| (*v).into()).collect())
    }
    match ds.dtype() {
        Datatype::FloatingPoint { size: 4, .. } => all::<f32>(ds),
        Datatype::FixedPoint {
            size: 1, signed, ..
        } if *signed => all::<i8>(ds),
        Datatype::FixedPoint { size: 1, .. } => all::<u8>(ds),
        Datatype::FixedPoint {
            size: 2, signed, ..
        } if *signed => all::<i16>(ds),
        Datatype::FixedPoint { size: 2, .. } => all::<u16>(ds),
        Datatype::FixedPoint {
            size: 4, signed, ..
        } if *signed => all::<i32>(ds),
        Datatype::FixedPoint { size: 4, .. } => all::<u32>(ds),
        Datatype::FixedPoint {
            size: 8, signed, ..
        } if *signed => Ok(ds.read_array::<i64>()?.iter().map(|v| *v as f64).collect()),
        Datatype::FixedPoint { .. } => {
            Ok(ds.read_array::<u64>()?.iter().map(|v| *v as f64).collect())
        }
        _ => all::<f64>(ds),
    }
}
