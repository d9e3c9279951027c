//! # flapssm-data — file formats
//!
//! The formats flapssm reads and writes, with nothing of the wing in them (the wing dataset and
//! its files live in `flapssm_wing::dataset`):
//! - [`npz`]: NumPy `.npy`/`.npz` reading and writing.
//! - [`mat`]: MATLAB Level 4 and Level 5 (incl. compressed) `.mat` readers.
//! - [`table`]: generic column tables from whitespace ASCII, CSV and MAT files.
//! - [`atomic`]: atomic file writes (temporary file + rename).
//!
//! Everything that writes a file writes a temporary file next to the target and renames it,
//! so no half-written file is ever left behind.
#![warn(missing_docs)]

pub mod atomic;
pub mod mat;
pub mod npz;
pub mod table;
