//! The flapssm dataset: trajectories of wing kinematics and loads.
//!
//! Frames and units: inputs and outputs are in the wing frame (x normal to the plate, y
//! chordwise, z spanwise), at unit distance along the span on the pitch axis.
//!
//! | input | unit | meaning |
//! |---|---|---|
//! | `aoa` | rad | geometric angle of attack |
//! | `speed` | m/s per m of span (= rad/s) | \|v\| of the pitch-axis point at unit span |
//! | `a_x` | m/s² per m | normal acceleration |
//! | `a_y` | m/s² per m | chordwise acceleration |
//! | `a_z` | m/s² per m | spanwise (centripetal) acceleration |
//! | `pitch_rate` | rad/s | α̇ |
//! | `pitch_acc` | rad/s² | α̈ |
//!
//! Outputs: `F_x`, `F_y` in N; `M_x`, `M_y`, `M_z` in N·mm.

use serde::{Deserialize, Serialize};

/// Names of the 7 inputs, in the published dataset's order.
pub const INPUT_NAMES: [&str; 7] = [
    "aoa",
    "speed",
    "a_x",
    "a_y",
    "a_z",
    "pitch_rate",
    "pitch_acc",
];
/// Units of the 7 inputs.
pub const INPUT_UNITS: [&str; 7] = ["rad", "1/s", "1/s^2", "1/s^2", "1/s^2", "rad/s", "rad/s^2"];
/// Names of the 5 outputs.
pub const OUTPUT_NAMES: [&str; 5] = ["F_x", "F_y", "M_x", "M_y", "M_z"];
/// Units of the 5 outputs.
pub const OUTPUT_UNITS: [&str; 5] = ["N", "N", "N*mm", "N*mm", "N*mm"];
/// Names of the 3 Euler angles.
pub const EULER_NAMES: [&str; 3] = ["stroke", "deviation", "pitch"];

/// Geometry of a rigid flat rectangular wing.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct WingGeometry {
    /// Span of the plate (m).
    pub span_m: f64,
    /// Chord of the plate (m).
    pub chord_m: f64,
    /// Distance from the stroke axis to the wing root (m).
    pub root_offset_m: f64,
    /// Pitch axis position behind the leading edge, as a fraction of the chord.
    pub pitch_axis_frac: f64,
    /// Radius used for `U_ref` (m); the wing-tip radius in the original experiment.
    pub u_ref_radius_m: f64,
}

impl Default for WingGeometry {
    /// The wing of Bayiz & Cheng (2021): 0.18 m × 0.06 m, root offset 0.055 m, axis at 15 % chord.
    fn default() -> Self {
        Self {
            span_m: 0.18,
            chord_m: 0.06,
            root_offset_m: 0.055,
            pitch_axis_frac: 0.15,
            u_ref_radius_m: 0.235,
        }
    }
}

impl WingGeometry {
    /// Planform area S = span · chord (m²).
    pub fn area_m2(&self) -> f64 {
        self.span_m * self.chord_m
    }
}

/// The fluid the wing moves in.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Fluid {
    /// Density ρ (kg/m³).
    pub density_kg_m3: f64,
    /// Kinematic viscosity ν (m²/s).
    pub kinematic_viscosity_m2_s: f64,
}

impl Default for Fluid {
    /// Mineral oil of the original experiment: ρ = 800 kg/m³, ν = 2.2e-5 m²/s (Re ≈ 1000 at
    /// U_ref ≈ 0.37 m/s, c̄ = 0.06 m).
    fn default() -> Self {
        Self {
            density_kg_m3: 800.0,
            kinematic_viscosity_m2_s: 2.2e-5,
        }
    }
}

/// Dataset-level metadata, stored as JSON inside the file.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct DatasetMeta {
    /// Format version of the file (see [`crate::dataset::FORMAT_VERSION`]).
    pub format_version: u32,
    /// Wing geometry.
    pub wing: WingGeometry,
    /// Fluid properties.
    pub fluid: Fluid,
    /// What produced the data: `"flapssm trajectories"`, `"flapssm simulate"`, `"import:mat"`, …
    pub generator: String,
    /// Seed of the generator, if any.
    pub seed: Option<u64>,
    /// Free-form, generator-specific settings (fidelity, physical parameters, sensor model, …).
    pub settings: serde_json::Value,
    /// Units of the 7 inputs, in order.
    pub input_units: Vec<String>,
    /// Units of the 5 outputs, in order.
    pub output_units: Vec<String>,
}

/// Current dataset format version.
pub const FORMAT_VERSION: u32 = 1;

/// One trajectory, sampled at the dataset's period `dt_s`. All vectors have the same length.
#[derive(Debug, Clone, PartialEq)]
pub struct Trajectory {
    /// Euler angles [stroke φ, deviation ψ, pitch α] (rad), one row per sample.
    pub euler_rad: Vec<[f64; 3]>,
    /// Inputs u in [`INPUT_NAMES`] order, one row per sample.
    pub inputs: Vec<[f64; 7]>,
    /// Outputs y in [`OUTPUT_NAMES`] order (N, N·mm), one row per sample; `None` for
    /// kinematics-only datasets.
    pub outputs: Option<Vec<[f64; 5]>>,
    /// Reference speed U_ref (m/s): mean speed of the point at `u_ref_radius_m` over the last
    /// full cycle.
    pub u_ref_m_s: f64,
    /// Family label ("figure-eight", "u-shaped", "oval", "flat", "harmonic", "measured", …).
    pub family: String,
}

/// A dataset: trajectories of equal length, a split and metadata.
#[derive(Debug, Clone, PartialEq)]
pub struct Dataset {
    /// Metadata.
    pub meta: DatasetMeta,
    /// Sampling period (s).
    pub dt_s: f64,
    /// The trajectories; the first `n_train` are the training set, the rest the test set.
    pub trajectories: Vec<Trajectory>,
    /// Number of training trajectories (the first `n_train`).
    pub n_train: usize,
}
