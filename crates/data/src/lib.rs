//! # flapssm-data — dataset files and readers
//!
//! One dataset type, [`Dataset`], for every flapssm command: per trajectory the Euler angles
//! (rad), the 7 wing-frame inputs `u`, the 5 wing-frame outputs `y` (N and N·mm), the sampling
//! period, `U_ref` and a family label, plus metadata, a train/test split and standardization
//! statistics computed on the training part only.
//!
//! Modules:
//! - [`dataset`]: the [`Dataset`] type, validation, split and standardization statistics.
//! - [`store`]: the dataset file (one self-describing `.npz`), [`Dataset::save`]/[`Dataset::load`].
//! - [`csv`]: long-format CSV export/import of a dataset.
//! - [`mat`]: MATLAB Level 4 and Level 5 (incl. compressed) `.mat` readers.
//! - [`published`]: import of the published Bayiz & Cheng dataset layout from a `.mat` file.
//! - [`summary`]: a printable overview ([`Dataset::summary`]).
//! - [`table`]: generic column tables from whitespace ASCII, CSV and MAT files.
//! - [`npz`]: NumPy `.npy`/`.npz` reading and writing.
//! - [`atomic`]: atomic file writes (temporary file + rename).
//!
//! Everything that writes a file writes a temporary file next to the target and renames it,
//! so no half-written file is ever left behind.
#![warn(missing_docs)]

pub mod atomic;
pub mod csv;
pub mod dataset;
pub mod mat;
pub mod npz;
pub mod published;
pub mod store;
pub mod summary;
pub mod table;

pub use dataset::{
    Dataset, DatasetError, DatasetMeta, EULER_NAMES, FORMAT_VERSION, Fluid, INPUT_NAMES,
    INPUT_UNITS, OUTPUT_NAMES, OUTPUT_UNITS, Standardization, Trajectory, WingGeometry,
};
pub use store::StoreError;
