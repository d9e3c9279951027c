//! The rig as the judge: a dataset on the paper's measured trajectories against the published
//! model's prediction of the rig's loads on the same motions (docs/rig-agreement.md).
//!
//! The authors' trained PR-SSM was fitted to the robot's measured loads; driven by the paper's
//! own trajectories, with the inputs standardized on the 512 training trajectories as the authors
//! did, its predictive mean stands in for what the rig measured (its test errors put it within
//! about 0.1–0.25 σ of the rig). [`RigReference`] is that prediction (standardized units, the
//! paper's trajectories 0..n, computed once); [`rig_check`] scores a dataset of those
//! trajectories against it with [`flapssm_analysis::rig`], separately on the paper's 512
//! training and 36 test trajectories, the dataset's loads standardized by the mean and SD of its
//! own trajectories among the 512.

use std::path::{Path, PathBuf};

use flapssm_analysis::authority::AuthorityConfig;
use flapssm_analysis::metrics::PUBLISHED_START_SAMPLE;
use flapssm_analysis::report::{Figure, Section, Table};
pub use flapssm_analysis::rig::{ChannelAgreement, Couplings, SetAgreement};
use flapssm_analysis::rig::{RigTrajectory, set_agreement};
use flapssm_analysis::stats::Rows;
use flapssm_prssm::{Normalization, PrssmModel};
use flapssm_wing::dataset::ValidDataset;
use flapssm_wing::mount::Mount;
use flapssm_wing::sensor::SensorConfig;
use flapssm_wing::trajectories::paper::{
    PAPER_N_TRAIN, PAPER_N_TRAJECTORIES, paper_angles, paper_kinematics, paper_sampling,
};
use flapssm_wing::virtual_wing::{Fidelity, VirtualWingConfig, simulate_angles_dataset};
use serde::{Deserialize, Serialize};

use crate::error::{JobError, Result, analysis};
use crate::evaluate::report::INPUT_LABELS;
use crate::predict::predict_prssm;
use crate::progress::Progress;

/// The largest difference (rad) between a dataset's Euler angles and the paper's for the same
/// trajectory: the encoders' quantization is 1.5 mrad, a different trajectory differs by far
/// more.
const SAME_ANGLES_RAD: f64 = 0.02;

/// Settings of the reference prediction and the comparison.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct RigSettings {
    /// Particles of the reference's prediction (30, the authors').
    pub particles: usize,
    /// Seed of its draws (trajectory `i` uses [`crate::seed::prediction_seed`]`(seed, i)`).
    pub seed: u64,
    /// First compared sample (93, the published transient).
    pub start_sample: usize,
}

impl Default for RigSettings {
    fn default() -> Self {
        Self {
            particles: 30,
            seed: 1,
            start_sample: PUBLISHED_START_SAMPLE,
        }
    }
}

/// Reads the reference model: the published parameter file (`.npz`, as in
/// `../shared/reference/bayiz2021-prssm/`) or a flapssm model file (`.json`) of a model in
/// standardized units (no normalization statistics).
///
/// # Errors
/// [`JobError::PublishedModel`] / [`JobError::ModelFile`] naming the file;
/// [`JobError::Mismatch`] for a model that is not 7 → 5 in standardized units.
pub fn load_reference_model(path: &Path) -> Result<PrssmModel> {
    let is_npz = path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("npz"));
    let model = if is_npz {
        flapssm_prssm::published::import_published(path).map_err(|source| {
            JobError::PublishedModel {
                path: path.to_path_buf(),
                source,
            }
        })?
    } else {
        PrssmModel::load(path).map_err(|source| JobError::ModelFile {
            path: path.to_path_buf(),
            source,
        })?
    };
    let c = &model.config;
    if c.n_input != 7 || c.n_output != 5 || model.normalization.is_some() {
        return Err(JobError::Mismatch {
            what: format!("reference model {}", path.display()),
            expected: "7 inputs → 5 outputs in standardized units (the published model)".into(),
            found: format!(
                "{} inputs → {} outputs{}",
                c.n_input,
                c.n_output,
                if model.normalization.is_some() {
                    ", with normalization statistics"
                } else {
                    ""
                }
            ),
        });
    }
    Ok(model)
}

/// The reference's prediction of the paper's trajectories `0..n`, standardized.
#[derive(Debug, Clone)]
pub struct RigReference {
    /// Per trajectory, the predictive mean, `470 × 5`, row-major.
    pub mean_z: Vec<Vec<f64>>,
    /// Per trajectory, the predictive variance, `470 × 5`.
    pub var_z: Vec<Vec<f64>>,
    /// The trajectories' kinematics ([`paper_kinematics`]).
    pub kinematics: ValidDataset,
    /// Each trajectory's stroke period (samples, [`flapssm_wing::cycles::published_window`]).
    pub period_samples: Vec<f64>,
    /// The input standardization: mean and SD over the paper's 512 training trajectories.
    pub input_mean: [f64; 7],
    /// See `input_mean`.
    pub input_std: [f64; 7],
    /// The settings it was predicted with.
    pub settings: RigSettings,
}

impl RigReference {
    /// Trajectories predicted.
    pub fn len(&self) -> usize {
        self.mean_z.len()
    }

    /// Whether it holds no trajectory.
    pub fn is_empty(&self) -> bool {
        self.mean_z.is_empty()
    }
}

/// Predicts the paper's trajectories `0..n` (n ≤ 548) with `model` (standardized units), its
/// inputs standardized on the 512 training trajectories. `progress.advance(1)` per trajectory.
///
/// # Errors
/// [`JobError::Setting`] for `n` of 0 or above 548, the prediction's errors.
pub fn rig_reference(
    model: &PrssmModel,
    n: usize,
    settings: &RigSettings,
    progress: &dyn Progress,
) -> Result<RigReference> {
    if n == 0 || n > PAPER_N_TRAJECTORIES {
        return Err(JobError::Setting {
            name: "n".into(),
            value: n.to_string(),
            expected: format!("1 to the paper's {PAPER_N_TRAJECTORIES} trajectories"),
        });
    }
    let all = paper_kinematics(PAPER_N_TRAJECTORIES)?;
    let (input_mean, input_std) = input_statistics(&all);
    let mut kinematics = all.into_inner();
    kinematics.trajectories.truncate(n);
    kinematics.n_train = n.min(PAPER_N_TRAIN);
    let kinematics = ValidDataset::new(kinematics)?;
    let standardized = on_paper_inputs(model, &input_mean, &input_std);
    let period_samples = kinematics
        .trajectories
        .iter()
        .enumerate()
        .map(|(i, t)| {
            t.published_window()
                .map(|w| w.duration as f64)
                .map_err(|source| JobError::Cycle {
                    trajectory: i,
                    source,
                })
        })
        .collect::<Result<_>>()?;
    progress.start("reference", n as u64);
    let preds = predict_prssm(
        &standardized,
        &kinematics,
        settings.particles,
        settings.seed,
        progress,
    )?;
    progress.finish("");
    let (mean_z, var_z) = preds
        .into_iter()
        .map(|p| (p.output_mean, p.output_var))
        .unzip();
    Ok(RigReference {
        mean_z,
        var_z,
        kinematics,
        period_samples,
        input_mean,
        input_std,
        settings: *settings,
    })
}

/// `model` (standardized units) taking the paper's physical inputs: standardized by `mean` and
/// `std` (the paper's 512 training trajectories, [`input_statistics`]), outputs left
/// standardized.
pub(crate) fn on_paper_inputs(model: &PrssmModel, mean: &[f64; 7], std: &[f64; 7]) -> PrssmModel {
    let mut standardized = model.clone();
    standardized.normalization = Some(Normalization {
        input_mean: mean.to_vec(),
        input_std: std.to_vec(),
        output_mean: vec![0.0; 5],
        output_std: vec![1.0; 5],
    });
    standardized
}

/// Mean and SD (population) of the inputs over every sample of the first 512 trajectories.
pub(crate) fn input_statistics(ds: &ValidDataset) -> ([f64; 7], [f64; 7]) {
    let rows: Vec<&[f64; 7]> = ds.trajectories[..PAPER_N_TRAIN]
        .iter()
        .flat_map(|t| t.inputs.iter())
        .collect();
    let n = rows.len() as f64;
    let mean: [f64; 7] = std::array::from_fn(|k| rows.iter().map(|r| r[k]).sum::<f64>() / n);
    let std = std::array::from_fn(|k| {
        (rows.iter().map(|r| (r[k] - mean[k]).powi(2)).sum::<f64>() / n).sqrt()
    });
    (mean, std)
}

/// A dataset's agreement with the rig reference.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RigCheck {
    /// The dataset's fidelity, where its metadata says (`"l0"`, …).
    pub fidelity: Option<String>,
    /// Trajectories compared.
    pub n_trajectories: usize,
    /// The reference's settings.
    pub settings: RigSettings,
    /// On the paper's training trajectories (index < 512).
    pub train: SetAgreement,
    /// On the paper's test trajectories (index ≥ 512), when the dataset holds any.
    pub test: Option<SetAgreement>,
}

/// The dataset's loads, standardized by the mean and SD of its trajectories among the paper's
/// training set (every sample), row-major `470 × 5` each.
///
/// # Errors
/// [`JobError::Mismatch`] for a dataset without outputs or with a constant channel.
pub fn standardized_loads(ds: &ValidDataset) -> Result<Vec<Vec<f64>>> {
    let outputs: Vec<&[[f64; 5]]> = ds
        .trajectories
        .iter()
        .map(|t| {
            t.outputs.as_deref().ok_or_else(|| JobError::Mismatch {
                what: "dataset for the rig check".into(),
                expected: "a dataset with loads".into(),
                found: "a kinematics-only dataset".into(),
            })
        })
        .collect::<Result<_>>()?;
    standardize(&outputs)
}

/// Loads standardized by the mean and SD over every sample of the trajectories among the
/// paper's first 512.
fn standardize(outputs: &[&[[f64; 5]]]) -> Result<Vec<Vec<f64>>> {
    let train = &outputs[..outputs.len().min(PAPER_N_TRAIN)];
    let count = train.iter().map(|t| t.len()).sum::<usize>() as f64;
    let mut mean = [0.0; 5];
    for row in train.iter().flat_map(|t| t.iter()) {
        for c in 0..5 {
            mean[c] += row[c] / count;
        }
    }
    let mut var = [0.0; 5];
    for row in train.iter().flat_map(|t| t.iter()) {
        for c in 0..5 {
            var[c] += (row[c] - mean[c]).powi(2) / count;
        }
    }
    let std = var.map(f64::sqrt);
    if let Some(c) = std.iter().position(|s| !(s.is_finite() && *s > 0.0)) {
        return Err(JobError::Mismatch {
            what: format!("dataset output {}", flapssm_analysis::rig::CHANNELS[c]),
            expected: "a spread over the training trajectories".into(),
            found: "a constant channel".into(),
        });
    }
    Ok(outputs
        .iter()
        .map(|t| {
            t.iter()
                .flat_map(|row| (0..5).map(move |c| (row[c] - mean[c]) / std[c]))
                .collect()
        })
        .collect())
}

fn table<'a>(v: &'a [f64], c: usize, what: &str) -> Result<Rows<'a>> {
    Rows::new(v, c).map_err(analysis(what))
}

/// Checks that `ds` holds the paper's trajectories `0..ds.len()` in the authors' order, within
/// `reference`, with its loads.
pub(crate) fn check_same_trajectories(ds: &ValidDataset, reference: &RigReference) -> Result<()> {
    if ds.len() > reference.len() {
        return Err(JobError::Mismatch {
            what: "dataset for the rig check".into(),
            expected: format!(
                "at most the {} trajectories of the reference",
                reference.len()
            ),
            found: format!("{} trajectories", ds.len()),
        });
    }
    if ds.n_samples() != reference.kinematics.n_samples() {
        return Err(JobError::Mismatch {
            what: "dataset for the rig check".into(),
            expected: format!(
                "the paper's {} samples per trajectory",
                reference.kinematics.n_samples()
            ),
            found: format!("{} samples", ds.n_samples()),
        });
    }
    for (i, (t, p)) in ds
        .trajectories
        .iter()
        .zip(&reference.kinematics.trajectories)
        .enumerate()
    {
        let worst = t
            .euler_rad
            .iter()
            .zip(&p.euler_rad)
            .flat_map(|(a, b)| (0..3).map(move |k| (a[k] - b[k]).abs()))
            .fold(0.0, f64::max);
        if worst.is_nan() || worst > SAME_ANGLES_RAD {
            return Err(JobError::Mismatch {
                what: format!("dataset trajectory {i}"),
                expected: format!(
                    "the paper's measured trajectory {i} (Euler angles within {SAME_ANGLES_RAD} rad; \
                     simulate with --source paper)"
                ),
                found: format!("angles {worst:.3} rad away"),
            });
        }
    }
    Ok(())
}

/// Scores `ds` (the paper's trajectories `0..n` in order, with loads, any fidelity or sensor
/// setting) against `reference` (module docs). `with_lags` adds the Fig. 5 lag statistics.
///
/// # Errors
/// [`JobError::Mismatch`] naming a dataset that is not on the paper's trajectories or has no
/// loads; the analysis' errors.
pub fn rig_check(ds: &ValidDataset, reference: &RigReference, with_lags: bool) -> Result<RigCheck> {
    check_same_trajectories(ds, reference)?;
    let (train, test) = agreement(&standardized_loads(ds)?, reference, with_lags)?;
    Ok(RigCheck {
        fidelity: ds
            .meta
            .settings
            .get("fidelity")
            .and_then(|f| f.as_str())
            .map(str::to_string),
        n_trajectories: ds.len(),
        settings: reference.settings,
        train,
        test,
    })
}

/// The agreement of standardized loads of the paper's trajectories `0..n` with `reference`, on
/// the training and (when `n > 512`) the test trajectories.
fn agreement(
    loads_z: &[Vec<f64>],
    reference: &RigReference,
    with_lags: bool,
) -> Result<(SetAgreement, Option<SetAgreement>)> {
    let trajectories: Vec<RigTrajectory<'_>> = loads_z
        .iter()
        .enumerate()
        .map(|(i, loads)| {
            Ok(RigTrajectory {
                loads_z: table(loads, 5, "dataset loads")?,
                reference_mean_z: table(&reference.mean_z[i], 5, "reference mean")?,
                reference_var_z: table(&reference.var_z[i], 5, "reference variance")?,
                inputs: table(
                    reference.kinematics.trajectories[i].inputs.as_flattened(),
                    7,
                    "inputs",
                )?,
                period_samples: reference.period_samples[i],
            })
        })
        .collect::<Result<_>>()?;
    let authority = AuthorityConfig::default();
    let lags = with_lags.then_some(&authority);
    let start = reference.settings.start_sample;
    let (train, test) = trajectories.split_at(trajectories.len().min(PAPER_N_TRAIN));
    let train = set_agreement(train, &INPUT_LABELS, start, lags)
        .map_err(analysis("rig agreement, training trajectories"))?;
    let test = if test.is_empty() {
        None
    } else {
        Some(
            set_agreement(test, &INPUT_LABELS, start, lags)
                .map_err(analysis("rig agreement, test trajectories"))?,
        )
    };
    Ok((train, test))
}

/// The paper's six example test trajectories (Fig. 3) as dataset indices, where the dataset
/// holds them: test trajectory #k is index 511 + k.
pub fn example_indices(n_trajectories: usize) -> Vec<(usize, usize)> {
    crate::evaluate::paper::FIG3_TEST_NUMBERS
        .iter()
        .map(|&k| (k, PAPER_N_TRAIN - 1 + k))
        .filter(|&(_, i)| i < n_trajectories)
        .collect()
}

/// A per-channel measure of the tables: its label and value.
type ChannelMeasure = (&'static str, fn(&ChannelAgreement) -> f64);

/// The per-channel rows of the tables.
const CHANNEL_MEASURES: [ChannelMeasure; 3] = [
    ("r", channel_r),
    ("z-RMSE (σ)", channel_z_rmse),
    ("in 95 % band", channel_band_share),
];

fn channel_r(c: &ChannelAgreement) -> f64 {
    c.r
}

fn channel_z_rmse(c: &ChannelAgreement) -> f64 {
    c.z_rmse
}

fn channel_band_share(c: &ChannelAgreement) -> f64 {
    c.band_share
}

/// A coupling row of the tables: its label and value.
type CouplingMeasure = (&'static str, fn(&Couplings) -> f64);

/// The coupling rows of the tables.
const COUPLINGS: [CouplingMeasure; 2] = [("r(F_y, F_x)", fy_fx), ("r(M_x, F_x)", mx_fx)];

fn fy_fx(c: &Couplings) -> f64 {
    c.fy_fx
}

fn mx_fx(c: &Couplings) -> f64 {
    c.mx_fx
}

/// Inputs of the lag rows of [`RigCheck::markdown`] (all pairs are in the JSON).
const TABLE_LAG_INPUTS: [&str; 4] = ["AoA", "a_x", "dα/dt", "d²α/dt²"];

impl RigCheck {
    /// The agreement as Markdown tables: per channel r, z-RMSE and band share on each set; the
    /// couplings; the Fig. 5 lags of four inputs on F_x.
    pub fn markdown(&self, title: &str) -> String {
        use std::fmt::Write;
        let sets: Vec<(&str, &SetAgreement)> = std::iter::once(("train", &self.train))
            .chain(self.test.as_ref().map(|t| ("test", t)))
            .collect();
        let mut s = format!(
            "### {title}\n\nAgainst the published model's prediction ({} particles, seed {}), \
             samples {}.., standardized; {}.\n\n| | F_x | F_y | M_x | M_y | M_z |\n|---|---|---|---|---|---|\n",
            self.settings.particles,
            self.settings.seed,
            self.settings.start_sample,
            sets.iter()
                .map(|(name, a)| format!("{name}: {} trajectories", a.n_trajectories))
                .collect::<Vec<_>>()
                .join(", ")
        );
        for (label, f) in CHANNEL_MEASURES {
            for (name, a) in &sets {
                let cells: Vec<String> =
                    a.channels.iter().map(|c| format!("{:.3}", f(c))).collect();
                let _ = writeln!(s, "| {label}, {name} | {} |", cells.join(" | "));
            }
        }
        s.push_str("\n| coupling |");
        for (name, _) in &sets {
            let _ = write!(s, " dataset, {name} | stand-in, {name} |");
        }
        s.push_str(&format!("\n|---|{}\n", "---|---|".repeat(sets.len())));
        for (label, f) in COUPLINGS {
            let _ = write!(s, "| {label} |");
            for (_, a) in &sets {
                let _ = write!(
                    s,
                    " {:.3} | {:.3} |",
                    f(&a.dataset_couplings),
                    f(&a.reference_couplings)
                );
            }
            s.push('\n');
        }
        if sets.iter().all(|(_, a)| !a.lags.is_empty()) {
            s.push_str("\n| Fig. 5 on the loads: median lag (cycles) [IQR], median \\|r\\| |");
            for (name, _) in &sets {
                let _ = write!(s, " dataset, {name} | stand-in, {name} |");
            }
            s.push_str(&format!("\n|---|{}\n", "---|---|".repeat(sets.len())));
            let cell = |l: &flapssm_analysis::rig::LagStats| {
                format!(
                    "{:.3} [{:.3}], {:.2}",
                    l.median_lag_cycles, l.lag_iqr_cycles, l.median_abs_r
                )
            };
            for input in TABLE_LAG_INPUTS {
                let _ = write!(s, "| {input} → F_x |");
                for (_, a) in &sets {
                    if let Some(p) = a.lag(input, "F_x") {
                        let _ = write!(s, " {} | {} |", cell(&p.dataset), cell(&p.reference));
                    }
                }
                s.push('\n');
            }
        }
        s
    }
}

/// The files [`write_rig_check`] writes in its directory.
pub const RIG_FILES: [&str; 3] = ["rig-check.json", "rig-check.md", "rig-examples.png"];

/// Writes `check` into `dir` (created if missing): `rig-check.json`, `rig-check.md` and, when
/// `ds` holds any of the paper's six example test trajectories, `rig-examples.png` (each
/// written atomically).
///
/// # Errors
/// File and figure errors naming the file.
pub fn write_rig_check(
    dir: &Path,
    check: &RigCheck,
    ds: &ValidDataset,
    reference: &RigReference,
    title: &str,
) -> Result<()> {
    std::fs::create_dir_all(dir).map_err(|source| JobError::Io {
        path: dir.to_path_buf(),
        source,
    })?;
    crate::files::save_json(&dir.join(RIG_FILES[0]), check)?;
    crate::files::write_text(&dir.join(RIG_FILES[1]), &check.markdown(title))?;
    let examples = example_indices(ds.len());
    if examples.is_empty() {
        return Ok(());
    }
    let loads = standardized_loads(ds)?;
    let start = reference
        .settings
        .start_sample
        .min(ds.n_samples().saturating_sub(2));
    let t_s: Vec<f64> = (start..ds.n_samples())
        .map(|i| i as f64 * ds.dt_s)
        .collect();
    let titles: Vec<String> = examples.iter().map(|(k, _)| format!("test #{k}")).collect();
    let panels: Vec<flapssm_analysis::plots::rig::RigPanel<'_>> = examples
        .iter()
        .zip(&titles)
        .map(|(&(_, i), title)| flapssm_analysis::plots::rig::RigPanel {
            title,
            t_s: &t_s,
            loads_z: &loads[i][start * 5..],
            reference_mean_z: &reference.mean_z[i][start * 5..],
            reference_var_z: &reference.var_z[i][start * 5..],
        })
        .collect();
    let path = dir.join(RIG_FILES[2]);
    flapssm_analysis::plots::rig::rig_overlay(&path, title, "dataset", &panels)
        .map_err(analysis(path.display().to_string()))
}

/// Settings of [`fit_mount`]: the grid of the two mount angles (deg,
/// [`flapssm_wing::mount::Mount`]).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct MountFitSettings {
    /// Plate angles θ_p tried: one simulation each.
    pub plate_deg: Vec<f64>,
    /// Sensor angles θ_s tried: each simulation's loads turned into each sensor's axes.
    pub sensor_deg: Vec<f64>,
}

impl Default for MountFitSettings {
    /// θ_p from −15° to 15° and θ_s from −45° to 45°, both in 1° steps.
    fn default() -> Self {
        Self {
            plate_deg: (-15..=15).map(f64::from).collect(),
            sensor_deg: (-45..=45).map(f64::from).collect(),
        }
    }
}

/// One point of the fit's grid.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct MountPoint {
    /// θ_p (deg).
    pub plate_deg: f64,
    /// θ_s (deg).
    pub sensor_deg: f64,
    /// Per channel, the mean squared standardized difference from the reference on the
    /// training trajectories.
    pub z_mse: Vec<f64>,
    /// The wing's r(F_y, F_x) there.
    pub fy_fx: f64,
    /// The wing's r(M_x, F_x) there.
    pub mx_fx: f64,
}

impl MountPoint {
    /// Mean z-MSE over the five channels.
    pub fn mean_mse(&self) -> f64 {
        self.z_mse.iter().sum::<f64>() / self.z_mse.len() as f64
    }

    /// Mean z-MSE of the normal channels F_x, M_y, M_z (the plate angle's criterion).
    pub fn normal_mse(&self) -> f64 {
        (self.z_mse[0] + self.z_mse[3] + self.z_mse[4]) / 3.0
    }

    /// Squared distance of the couplings from `reference`'s (the sensor angle's criterion).
    pub fn coupling_error(&self, reference: &Couplings) -> f64 {
        (self.fy_fx - reference.fy_fx).powi(2) + (self.mx_fx - reference.mx_fx).powi(2)
    }
}

/// The mount angles that bring a wing closest to the rig reference ([`fit_mount`]).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct MountFit {
    /// The wing's fidelity.
    pub fidelity: Fidelity,
    /// Training trajectories the criteria pooled.
    pub n_trajectories: usize,
    /// The chosen angles.
    pub best: Mount,
    /// The agreement there (no lag statistics).
    pub at_best: SetAgreement,
    /// The agreement with both angles 0.
    pub aligned: SetAgreement,
    /// The grid point of the smallest mean z-MSE over all five channels, for comparison (not
    /// the fit's criterion: see [`fit_mount`]).
    pub all_channels_best: MountPoint,
    /// Every grid point, plate-major.
    pub surface: Vec<MountPoint>,
}

/// Identifies the plate's and the sensor's angles on the pitch shaft
/// ([`flapssm_wing::mount::Mount`]) of the wing `base` on the paper's training trajectories
/// only, with noise-free loads (every other setting of `base` kept, its sensor chain off), on
/// the grid of `settings` (0° always tried):
///
/// 1. for each plate angle, the sensor angle whose loads reproduce the reference's couplings
///    r(F_y, F_x) and r(M_x, F_x) (least squares): the normal force's leak into the chordwise
///    channels, the signature of the rotation between the plate and the sensor;
/// 2. of those pairs, the one with the smallest mean squared standardized difference from the
///    reference on the normal channels F_x, M_y and M_z, which the plate angle moves through
///    the angle of attack.
///
/// (Minimizing the difference on all five channels instead turns the sensor until the
/// chordwise channels copy the normal force: the reference's chordwise channels hold more
/// than a wing's own chordwise load and the leak.) `progress.advance(1)` per simulated
/// trajectory.
///
/// # Errors
/// [`JobError::Setting`] for an angle beyond ±45°; the simulation's and the analysis' errors.
pub fn fit_mount(
    base: &VirtualWingConfig,
    reference: &RigReference,
    settings: &MountFitSettings,
    progress: &dyn Progress,
) -> Result<MountFit> {
    let grid = |name: &str, values: &[f64]| -> Result<Vec<f64>> {
        if let Some(bad) = values
            .iter()
            .find(|a| !(a.is_finite() && a.abs() <= flapssm_wing::mount::MAX_MOUNT_DEG))
        {
            return Err(JobError::Setting {
                name: name.into(),
                value: bad.to_string(),
                expected: format!("angles within ±{}°", flapssm_wing::mount::MAX_MOUNT_DEG),
            });
        }
        let mut v: Vec<f64> = values.iter().copied().chain([0.0]).collect();
        v.sort_by(f64::total_cmp);
        v.dedup();
        Ok(v)
    };
    let plates = grid("plate_deg", &settings.plate_deg)?;
    let sensors = grid("sensor_deg", &settings.sensor_deg)?;
    let n = reference.len().min(PAPER_N_TRAIN);
    let angles = paper_angles(n);
    let sampling = paper_sampling();
    let simulate = |plate_deg: f64, tick: &(dyn Fn() + Sync)| {
        let wing = VirtualWingConfig {
            sensor: SensorConfig::noise_free(),
            mount: Mount {
                plate_pitch_deg: plate_deg,
                sensor_pitch_deg: 0.0,
            },
            ..base.clone()
        };
        simulate_angles_dataset(&wing, &angles, &sampling, 0, n, "fit_mount", tick)
    };
    // The loads of plate angle θ_p read by a sensor at θ_s: the plate's loads in the encoder's
    // axes (sensor at 0) turned by −θ_s, exactly what a simulation with both angles gives.
    let agreement_at = |ds: &ValidDataset, sensor_deg: f64| -> Result<SetAgreement> {
        let turn = Mount {
            plate_pitch_deg: 0.0,
            sensor_pitch_deg: sensor_deg,
        };
        let turned: Vec<Vec<[f64; 5]>> = ds
            .trajectories
            .iter()
            .map(|t| {
                let mut rows = t.outputs.clone().unwrap_or_default();
                rows.iter_mut().for_each(|r| turn.plate_to_sensor(r));
                rows
            })
            .collect();
        let views: Vec<&[[f64; 5]]> = turned.iter().map(Vec::as_slice).collect();
        Ok(agreement(&standardize(&views)?, reference, false)?.0)
    };
    progress.start("fit mount", ((plates.len() + 1) * n) as u64);
    let tick = || progress.advance(1);
    let mut surface = Vec::with_capacity(plates.len() * sensors.len());
    let mut aligned = None;
    for &plate_deg in &plates {
        let ds = simulate(plate_deg, &tick)?;
        for &sensor_deg in &sensors {
            let a = agreement_at(&ds, sensor_deg)?;
            surface.push(MountPoint {
                plate_deg,
                sensor_deg,
                z_mse: a.channels.iter().map(|c| c.z_rmse * c.z_rmse).collect(),
                fy_fx: a.dataset_couplings.fy_fx,
                mx_fx: a.dataset_couplings.mx_fx,
            });
            if plate_deg == 0.0 && sensor_deg == 0.0 {
                aligned = Some(a);
            }
        }
    }
    let target = reference_couplings(reference)?;
    let best = surface
        .chunks(sensors.len())
        .filter_map(|row| {
            row.iter().min_by(|a, b| {
                a.coupling_error(&target)
                    .total_cmp(&b.coupling_error(&target))
            })
        })
        .min_by(|a, b| a.normal_mse().total_cmp(&b.normal_mse()))
        .cloned()
        .ok_or_else(|| JobError::Setting {
            name: "plate_deg".into(),
            value: "[]".into(),
            expected: "at least one angle".into(),
        })?;
    let all_channels_best = surface
        .iter()
        .min_by(|a, b| a.mean_mse().total_cmp(&b.mean_mse()))
        .cloned()
        .unwrap_or_else(|| best.clone());
    let at_best = agreement_at(&simulate(best.plate_deg, &tick)?, best.sensor_deg)?;
    progress.finish("");
    Ok(MountFit {
        fidelity: base.fidelity,
        n_trajectories: n,
        best: Mount {
            plate_pitch_deg: best.plate_deg,
            sensor_pitch_deg: best.sensor_deg,
        },
        at_best,
        aligned: aligned.ok_or_else(|| JobError::Setting {
            name: "plate_deg".into(),
            value: "[]".into(),
            expected: "0° in the grid".into(),
        })?,
        all_channels_best,
        surface,
    })
}

/// The reference's couplings on its training trajectories.
fn reference_couplings(reference: &RigReference) -> Result<Couplings> {
    let n = reference.len().min(PAPER_N_TRAIN);
    let start = reference.settings.start_sample;
    let series = |c: usize| -> Vec<f64> {
        reference.mean_z[..n]
            .iter()
            .flat_map(|m| m.chunks_exact(5).skip(start).map(move |r| r[c]))
            .collect()
    };
    let (fx, fy, mx) = (series(0), series(1), series(2));
    let r = |a: &[f64], what: &str| {
        flapssm_analysis::rig::pearson(a, &fx, what).map_err(analysis("reference couplings"))
    };
    Ok(Couplings {
        fy_fx: r(&fy, "F_y")?,
        mx_fx: r(&mx, "M_x")?,
    })
}

impl RigCheck {
    /// The same without the lag statistics (the demo's `summary.json`).
    pub fn without_lags(mut self) -> Self {
        self.train.lags.clear();
        if let Some(t) = &mut self.test {
            t.lags.clear();
        }
        self
    }

    /// The check as a section of the HTML report, with `figure` (the example trajectories)
    /// when there is one.
    pub fn report_section(&self, figure: Option<PathBuf>) -> Section {
        let sets: Vec<(&str, &SetAgreement)> = std::iter::once(("training", &self.train))
            .chain(self.test.as_ref().map(|t| ("test", t)))
            .collect();
        let header = |first: &str| -> Vec<String> {
            std::iter::once(first.to_string())
                .chain(
                    flapssm_analysis::rig::CHANNELS
                        .iter()
                        .map(|c| c.to_string()),
                )
                .collect()
        };
        let mut rows = Vec::new();
        for (label, f) in CHANNEL_MEASURES {
            for (name, a) in &sets {
                rows.push(
                    std::iter::once(format!("{label}, {name}"))
                        .chain(a.channels.iter().map(|c| format!("{:.3}", f(c))))
                        .collect(),
                );
            }
        }
        let couplings = sets
            .iter()
            .flat_map(|(name, a)| {
                [
                    vec![
                        format!("r(F_y, F_x), {name}"),
                        format!("{:.3}", a.dataset_couplings.fy_fx),
                        format!("{:.3}", a.reference_couplings.fy_fx),
                    ],
                    vec![
                        format!("r(M_x, F_x), {name}"),
                        format!("{:.3}", a.dataset_couplings.mx_fx),
                        format!("{:.3}", a.reference_couplings.mx_fx),
                    ],
                ]
            })
            .collect();
        let mut tables = vec![
            Table {
                caption: "Each output against the rig stand-in (standardized units)".into(),
                header: header("measure, set"),
                rows,
            },
            Table {
                caption: "The chordwise channels' coupling to the normal force".into(),
                header: vec![
                    "coupling".into(),
                    "this dataset".into(),
                    "rig stand-in".into(),
                ],
                rows: couplings,
            },
        ];
        if sets.iter().all(|(_, a)| !a.lags.is_empty()) {
            let cell = |l: &flapssm_analysis::rig::LagStats| {
                format!(
                    "{:.3} [{:.3}], {:.2}",
                    l.median_lag_cycles, l.lag_iqr_cycles, l.median_abs_r
                )
            };
            tables.push(Table {
                caption: "Fig. 5's rule on the loads: median lag (cycles) [IQR], median |r|".into(),
                header: vec![
                    "pair, set".into(),
                    "this dataset".into(),
                    "rig stand-in".into(),
                ],
                rows: sets
                    .iter()
                    .flat_map(|(name, a)| {
                        TABLE_LAG_INPUTS.iter().filter_map(move |input| {
                            a.lag(input, "F_x").map(|p| {
                                vec![
                                    format!("{input} → F_x, {name}"),
                                    cell(&p.dataset),
                                    cell(&p.reference),
                                ]
                            })
                        })
                    })
                    .collect(),
            });
        }
        Section {
            heading: "The rig as the judge".into(),
            paragraphs: vec![format!(
                "The dataset's loads against the published PR-SSM's prediction on the same measured trajectories, the stand-in for what the paper's rig measured (its test errors put it within about 0.1–0.25 σ of the rig): inputs standardized on the paper's 512 training trajectories, {} particles, seed {}, samples {}.. of each trajectory, the paper's 512 training and 36 test trajectories apart (docs/rig-agreement.md).",
                self.settings.particles, self.settings.seed, self.settings.start_sample
            )],
            tables,
            figures: figure
                .map(|path| Figure {
                    caption: "The paper's six example test trajectories: this dataset's loads (black) over the rig stand-in's mean and 95 % band".into(),
                    path,
                })
                .into_iter()
                .collect(),
        }
    }
}
