//! # flapssm-data — dataset files and readers
//!
//! One dataset type, [`Dataset`], for every flapssm command: per trajectory the Euler angles
//! (rad), the 7 wing-frame inputs `u`, the 5 wing-frame outputs `y` (N and N·mm), the sampling
//! period, `U_ref` and a family label, plus metadata, a train/test split and standardization
//! statistics computed on the training part only.
//!
//! Modules:
//! - [`dataset`]: the [`Dataset`] type, validation, split and standardization statistics.
//! - [`npz`]: NumPy `.npy`/`.npz` reading and writing.
//! - [`atomic`]: atomic file writes (temporary file + rename).
//!
//! Everything that writes a file writes a temporary file next to the target and renames it,
//! so no half-written file is ever left behind.
#![warn(missing_docs)]

pub mod atomic;
pub mod dataset;
pub mod npz;

pub use dataset::{
    Dataset, DatasetMeta, Fluid, INPUT_NAMES, OUTPUT_NAMES, Trajectory, WingGeometry,
};
