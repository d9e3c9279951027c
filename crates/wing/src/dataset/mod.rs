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
//!
//! One dataset type, [`Dataset`], for every flapssm command: per trajectory the Euler angles
//! (rad), the 7 inputs, the 5 outputs, the sampling period, `U_ref` and a family label, plus
//! metadata, a train/test split and standardization statistics computed on the training part
//! only. Its files:
//! - [`store`]: the dataset file (one self-describing `.npz`), [`ValidDataset::save`]/[`Dataset::load`].
//! - [`csv`]: long-format CSV export/import.
//! - [`published`]: import of the published Bayiz & Cheng dataset layout from a `.mat` file.
//! - [`summary`]: a printable overview ([`Dataset::summary`]).
//!
//! Every reader returns a [`ValidDataset`] ([`valid`]): checked once, where it enters.

pub mod csv;
pub mod published;
pub mod store;
pub mod summary;
pub mod valid;

pub use store::StoreError;
pub use valid::ValidDataset;

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
    /// Mineral oil of the original experiment: ρ = 800 kg/m³ (the authors' code) and
    /// ν = 1.05e-5 m²/s (10.5 cSt, μ = 8.4 mPa·s), from the paper's Re = U_ref c̄/ν ≈ 1000 with
    /// the measured trajectories' U_ref (published recipe, R = 0.235 m: 0.1746 m/s, the same for
    /// all 548 to ±0.5 %) and c̄ = 0.06 m: ν = 0.1746 · 0.06 / 1000.
    fn default() -> Self {
        Self {
            density_kg_m3: 800.0,
            kinematic_viscosity_m2_s: 1.05e-5,
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

/// Errors of dataset validation and statistics. Indices are 0-based.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum DatasetError {
    /// The dataset holds no trajectory.
    #[error("dataset holds no trajectory")]
    Empty,
    /// The sampling period is not a positive finite number.
    #[error("dt_s = {dt_s}: must be positive and finite")]
    BadDt {
        /// The offending period (s).
        dt_s: f64,
    },
    /// `n_train` exceeds the number of trajectories.
    #[error("n_train = {n_train} exceeds the {n_trajectories} trajectories")]
    BadNTrain {
        /// Requested training count.
        n_train: usize,
        /// Number of trajectories.
        n_trajectories: usize,
    },
    /// A trajectory field has a different length than the first trajectory's `euler_rad`.
    #[error("trajectory {trajectory}: field '{field}' has {len} samples, expected {expected}")]
    LengthMismatch {
        /// Trajectory index.
        trajectory: usize,
        /// Field name (`euler_rad`, `u`, `y`).
        field: &'static str,
        /// Its length.
        len: usize,
        /// The expected length.
        expected: usize,
    },
    /// Some trajectories have outputs and others do not.
    #[error("trajectory {trajectory}: outputs y are {state} while trajectory 0's are not")]
    OutputsMixed {
        /// Trajectory index.
        trajectory: usize,
        /// `"present"` or `"absent"`.
        state: &'static str,
    },
    /// A value is NaN or infinite.
    #[error("trajectory {trajectory}: field '{field}' sample {sample} column {column} is {value}")]
    NotFinite {
        /// Trajectory index.
        trajectory: usize,
        /// Field name (`euler_rad`, `u`, `y`, `u_ref_m_s`).
        field: &'static str,
        /// Sample index.
        sample: usize,
        /// Column index within the field.
        column: usize,
        /// The value.
        value: f64,
    },
    /// `meta.input_units`/`meta.output_units` do not have 7/5 entries.
    #[error("metadata field '{field}' has {len} entries, expected {expected}")]
    BadUnits {
        /// `input_units` or `output_units`.
        field: &'static str,
        /// Number found.
        len: usize,
        /// Number expected.
        expected: usize,
    },
    /// Statistics need at least one training trajectory with samples.
    #[error("standardization needs at least one training sample (n_train = {n_train})")]
    NoTrainingData {
        /// Training count.
        n_train: usize,
    },
    /// Output statistics were asked of a kinematics-only dataset.
    #[error("dataset has no outputs y (kinematics only)")]
    NoOutputs,
    /// A training column is constant, so it cannot be standardized.
    #[error("field '{field}' column {column} ({name}) is constant on the training set (std = 0)")]
    ConstantColumn {
        /// `u` or `y`.
        field: &'static str,
        /// Column index.
        column: usize,
        /// Column name.
        name: &'static str,
    },
}

/// Per-column z-score statistics of the training part (population std, ddof 0):
/// `ū_j = (1/N) Σ u_j`, `σ_j = sqrt((1/N) Σ (u_j − ū_j)²)`, N = all training samples.
#[derive(Debug, Clone, PartialEq)]
pub struct Standardization {
    /// Mean of each input (input units).
    pub mean_u: [f64; 7],
    /// Standard deviation of each input (input units), > 0.
    pub std_u: [f64; 7],
    /// Mean of each output (N, N·mm).
    pub mean_y: [f64; 5],
    /// Standard deviation of each output (N, N·mm), > 0.
    pub std_y: [f64; 5],
}

impl Standardization {
    /// z-scores an input row: `(u − ū) / σ_u`.
    pub fn normalize_u(&self, u: &[f64; 7]) -> [f64; 7] {
        std::array::from_fn(|j| (u[j] - self.mean_u[j]) / self.std_u[j])
    }
    /// z-scores an output row: `(y − ȳ) / σ_y`.
    pub fn normalize_y(&self, y: &[f64; 5]) -> [f64; 5] {
        std::array::from_fn(|j| (y[j] - self.mean_y[j]) / self.std_y[j])
    }
    /// z-scores a row-major `n × 5` table of outputs (a trailing partial row is dropped).
    pub fn normalize_y_table(&self, y: &[f64]) -> Vec<f64> {
        y.chunks_exact(5)
            .flat_map(|r| (0..5).map(move |j| (r[j] - self.mean_y[j]) / self.std_y[j]))
            .collect()
    }
    /// Inverse of [`Self::normalize_y`]: `ȳ + σ_y z`.
    pub fn denormalize_y(&self, z: &[f64; 5]) -> [f64; 5] {
        std::array::from_fn(|j| self.mean_y[j] + self.std_y[j] * z[j])
    }
}

/// Column means and population standard deviations (ddof 0) of the rows of `rows`, two-pass.
/// Returns `None` if there is no row.
pub(crate) fn column_stats<'a, const N: usize>(
    rows: impl Iterator<Item = &'a [f64; N]> + Clone,
) -> Option<([f64; N], [f64; N])> {
    let mut n = 0usize;
    let mut mean = [0.0; N];
    for r in rows.clone() {
        n += 1;
        for j in 0..N {
            mean[j] += r[j];
        }
    }
    if n == 0 {
        return None;
    }
    mean.iter_mut().for_each(|m| *m /= n as f64);
    let mut var = [0.0; N];
    for r in rows {
        for j in 0..N {
            let d = r[j] - mean[j];
            var[j] += d * d;
        }
    }
    Some((mean, var.map(|v| (v / n as f64).sqrt())))
}

fn check_finite<const N: usize>(
    rows: &[[f64; N]],
    trajectory: usize,
    field: &'static str,
) -> Result<(), DatasetError> {
    for (sample, r) in rows.iter().enumerate() {
        if let Some(column) = r.iter().position(|v| !v.is_finite()) {
            return Err(DatasetError::NotFinite {
                trajectory,
                field,
                sample,
                column,
                value: r[column],
            });
        }
    }
    Ok(())
}

impl DatasetMeta {
    /// Metadata with the default wing and fluid, the current format version and the standard
    /// input/output units.
    pub fn new(
        generator: impl Into<String>,
        seed: Option<u64>,
        settings: serde_json::Value,
    ) -> Self {
        Self {
            format_version: FORMAT_VERSION,
            wing: WingGeometry::default(),
            fluid: Fluid::default(),
            generator: generator.into(),
            seed,
            settings,
            input_units: INPUT_UNITS.iter().map(|s| s.to_string()).collect(),
            output_units: OUTPUT_UNITS.iter().map(|s| s.to_string()).collect(),
        }
    }
}

impl Trajectory {
    /// Number of samples.
    pub fn len(&self) -> usize {
        self.euler_rad.len()
    }
    /// True if the trajectory has no sample.
    pub fn is_empty(&self) -> bool {
        self.euler_rad.is_empty()
    }
    /// The published last-full-cycle window of its stroke angle
    /// ([`crate::cycles::published_window`]).
    ///
    /// # Errors
    /// [`crate::cycles::CycleError`] for a stroke without a full cycle.
    pub fn published_window(
        &self,
    ) -> Result<crate::cycles::PublishedWindow, crate::cycles::CycleError> {
        let stroke: Vec<f64> = self.euler_rad.iter().map(|e| e[0]).collect();
        crate::cycles::published_window(&stroke)
    }
}

impl Dataset {
    /// Number of trajectories.
    pub fn len(&self) -> usize {
        self.trajectories.len()
    }
    /// True if there is no trajectory.
    pub fn is_empty(&self) -> bool {
        self.trajectories.is_empty()
    }
    /// Samples per trajectory (of the first trajectory; all are equal after [`Self::validate`]).
    pub fn n_samples(&self) -> usize {
        self.trajectories.first().map_or(0, Trajectory::len)
    }
    /// True if the trajectories carry outputs y (checked on the first trajectory).
    pub fn has_outputs(&self) -> bool {
        self.trajectories
            .first()
            .is_some_and(|t| t.outputs.is_some())
    }
    /// The training trajectories (the first `n_train`, clamped to the dataset size).
    pub fn train(&self) -> &[Trajectory] {
        &self.trajectories[..self.n_train.min(self.trajectories.len())]
    }
    /// The test trajectories (those after the first `n_train`).
    pub fn test(&self) -> &[Trajectory] {
        &self.trajectories[self.n_train.min(self.trajectories.len())..]
    }

    /// Checks the dataset: at least one trajectory; `dt_s > 0`; `n_train ≤ len`; every
    /// trajectory has the same number of samples in `euler_rad`, `u` and `y`; outputs present in
    /// all trajectories or in none; every value finite; 7 input and 5 output units in `meta`.
    ///
    /// # Errors
    /// The first violation found, naming trajectory, field and sample.
    pub fn validate(&self) -> Result<(), DatasetError> {
        if !(self.dt_s.is_finite() && self.dt_s > 0.0) {
            return Err(DatasetError::BadDt { dt_s: self.dt_s });
        }
        let first = self.trajectories.first().ok_or(DatasetError::Empty)?;
        if self.n_train > self.trajectories.len() {
            return Err(DatasetError::BadNTrain {
                n_train: self.n_train,
                n_trajectories: self.trajectories.len(),
            });
        }
        for (field, len, expected) in [
            ("input_units", self.meta.input_units.len(), 7),
            ("output_units", self.meta.output_units.len(), 5),
        ] {
            if len != expected {
                return Err(DatasetError::BadUnits {
                    field,
                    len,
                    expected,
                });
            }
        }
        let n_t = first.len();
        let with_y = first.outputs.is_some();
        for (i, t) in self.trajectories.iter().enumerate() {
            let y_len = t.outputs.as_ref().map(Vec::len);
            let lens = [
                ("euler_rad", t.euler_rad.len()),
                ("u", t.inputs.len()),
                ("y", y_len.unwrap_or(n_t)),
            ];
            for (field, len) in lens {
                if len != n_t {
                    return Err(DatasetError::LengthMismatch {
                        trajectory: i,
                        field,
                        len,
                        expected: n_t,
                    });
                }
            }
            if y_len.is_some() != with_y {
                return Err(DatasetError::OutputsMixed {
                    trajectory: i,
                    state: if with_y { "absent" } else { "present" },
                });
            }
            check_finite(&t.euler_rad, i, "euler_rad")?;
            check_finite(&t.inputs, i, "u")?;
            if let Some(y) = &t.outputs {
                check_finite(y, i, "y")?;
            }
            if !t.u_ref_m_s.is_finite() {
                return Err(DatasetError::NotFinite {
                    trajectory: i,
                    field: "u_ref_m_s",
                    sample: 0,
                    column: 0,
                    value: t.u_ref_m_s,
                });
            }
        }
        Ok(())
    }

    /// Raw input statistics (mean, population std) over all training samples; std may be 0.
    pub(crate) fn input_stats(&self) -> Option<([f64; 7], [f64; 7])> {
        column_stats(self.train().iter().flat_map(|t| t.inputs.iter()))
    }

    /// Raw output statistics over all training samples; `None` without outputs.
    pub(crate) fn output_stats(&self) -> Option<([f64; 5], [f64; 5])> {
        column_stats(
            self.train()
                .iter()
                .filter_map(|t| t.outputs.as_ref())
                .flat_map(|y| y.iter()),
        )
    }

    /// z-score statistics of u and y over all samples of the training trajectories (ddof 0).
    ///
    /// # Errors
    /// [`DatasetError::NoTrainingData`] if the training part holds no sample,
    /// [`DatasetError::NoOutputs`] for a kinematics-only dataset,
    /// [`DatasetError::ConstantColumn`] if a column has zero spread.
    pub fn standardization(&self) -> Result<Standardization, DatasetError> {
        let (mean_u, std_u) = self.input_stats().ok_or(DatasetError::NoTrainingData {
            n_train: self.n_train,
        })?;
        if !self.has_outputs() {
            return Err(DatasetError::NoOutputs);
        }
        let (mean_y, std_y) = self.output_stats().ok_or(DatasetError::NoTrainingData {
            n_train: self.n_train,
        })?;
        let zero = |field, std: &[f64], names: &[&'static str]| {
            std.iter()
                .position(|&s| s <= 0.0 || !s.is_finite())
                .map(|column| DatasetError::ConstantColumn {
                    field,
                    column,
                    name: names[column],
                })
        };
        if let Some(e) =
            zero("u", &std_u, &INPUT_NAMES).or_else(|| zero("y", &std_y, &OUTPUT_NAMES))
        {
            return Err(e);
        }
        Ok(Standardization {
            mean_u,
            std_u,
            mean_y,
            std_y,
        })
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    /// A small dataset with analytically known values: trajectory k, sample i has
    /// u_j = k + i + j, y_j = 2(k + i) − j, euler = [0.1 i, −0.1 i, k].
    pub(crate) fn sample(n: usize, n_t: usize, n_train: usize, with_y: bool) -> Dataset {
        let trajectories = (0..n)
            .map(|k| Trajectory {
                euler_rad: (0..n_t)
                    .map(|i| [0.1 * i as f64, -0.1 * i as f64, k as f64])
                    .collect(),
                inputs: (0..n_t)
                    .map(|i| std::array::from_fn(|j| (k + i + j) as f64))
                    .collect(),
                outputs: with_y.then(|| {
                    (0..n_t)
                        .map(|i| std::array::from_fn(|j| 2.0 * (k + i) as f64 - j as f64))
                        .collect()
                }),
                u_ref_m_s: 0.3 + 0.01 * k as f64,
                family: if k % 2 == 0 { "oval" } else { "figure-eight" }.into(),
            })
            .collect();
        Dataset {
            meta: DatasetMeta::new("test", Some(7), serde_json::json!({"k": 1})),
            dt_s: 0.04,
            trajectories,
            n_train,
        }
    }

    #[test]
    fn standardization_matches_closed_form() {
        // Training samples: k ∈ {0,1}, i ∈ {0..3}: s = k + i takes 0,1,2,3,1,2,3,4.
        // mean(s) = 2, population var(s) = (4+1+0+1+1+0+1+4)/8 = 1.5.
        let ds = sample(3, 4, 2, true);
        let s = ds.standardization().unwrap();
        for j in 0..7 {
            assert!((s.mean_u[j] - (2.0 + j as f64)).abs() < 1e-14);
            assert!((s.std_u[j] - 1.5f64.sqrt()).abs() < 1e-14);
        }
        for j in 0..5 {
            assert!((s.mean_y[j] - (4.0 - j as f64)).abs() < 1e-14);
            assert!((s.std_y[j] - 2.0 * 1.5f64.sqrt()).abs() < 1e-14);
        }
        // The test trajectory (k = 2) does not enter the statistics.
        let mut other = ds.clone();
        other.trajectories[2].inputs[0][0] = 1e6;
        assert_eq!(other.standardization().unwrap(), s);
        let y = [1.0, -2.0, 3.5, 0.0, 7.0];
        let back = s.denormalize_y(&s.normalize_y(&y));
        assert!(back.iter().zip(y).all(|(a, b)| (a - b).abs() < 1e-12));
        assert_eq!(s.normalize_u(&s.mean_u), [0.0; 7]);
    }

    #[test]
    fn split_slices() {
        let ds = sample(5, 3, 3, false);
        assert_eq!(ds.train().len(), 3);
        assert_eq!(ds.test().len(), 2);
        assert_eq!(ds.test()[0], ds.trajectories[3]);
        assert_eq!(ds.standardization(), Err(DatasetError::NoOutputs));
        assert!(ds.validate().is_ok());
    }

    #[test]
    fn validate_names_the_fault() {
        let mut ds = sample(3, 4, 2, true);
        ds.trajectories[1].outputs.as_mut().unwrap()[2][4] = f64::NAN;
        assert!(matches!(
            ds.validate(),
            Err(DatasetError::NotFinite {
                trajectory: 1,
                field: "y",
                sample: 2,
                column: 4,
                ..
            })
        ));
        let mut ds = sample(3, 4, 2, true);
        ds.trajectories[2].inputs.pop();
        assert_eq!(
            ds.validate(),
            Err(DatasetError::LengthMismatch {
                trajectory: 2,
                field: "u",
                len: 3,
                expected: 4
            })
        );
        let mut ds = sample(3, 4, 2, true);
        ds.trajectories[1].outputs = None;
        assert!(matches!(
            ds.validate(),
            Err(DatasetError::OutputsMixed { trajectory: 1, .. })
        ));
        let mut ds = sample(3, 4, 4, true);
        assert!(matches!(ds.validate(), Err(DatasetError::BadNTrain { .. })));
        ds.n_train = 3;
        ds.dt_s = 0.0;
        assert!(matches!(ds.validate(), Err(DatasetError::BadDt { .. })));
        ds.dt_s = 0.04;
        ds.trajectories[0].u_ref_m_s = f64::INFINITY;
        assert!(matches!(
            ds.validate(),
            Err(DatasetError::NotFinite {
                field: "u_ref_m_s",
                ..
            })
        ));
        let mut ds = sample(2, 3, 1, true);
        for t in &mut ds.trajectories {
            t.inputs.iter_mut().for_each(|r| r[4] = 1.0);
        }
        assert!(matches!(
            ds.standardization(),
            Err(DatasetError::ConstantColumn {
                field: "u",
                column: 4,
                name: "a_z"
            })
        ));
    }
}
