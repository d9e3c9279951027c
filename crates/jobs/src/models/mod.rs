//! Load models: wing kinematics in, the five loads out, one trajectory at a time.
//!
//! [`LoadModel`] is what evaluation, the report and the demo's summary need of a model; [`Fit`]
//! turns validated settings into one (linfa's `Fit`). Evaluation takes any number of models.
//! A baseline fitted from the data with default settings is a [`Baseline`]: a new one is a new
//! file here and its line in [`BASELINES`]; `flapssm evaluate --baseline KEY` and the demo then
//! fit, evaluate, tabulate and report it with no other change.
//!
//! | model | file | fitted by |
//! |---|---|---|
//! | PR-SSM | [`prssm`] | particle ELBO with Adam ([`crate::train`]) |
//! | LRQSM | [`lrqsm`] | elastic net with cross-validation (`flapssm-qs`) |
//! | ARX (a [`Baseline`]) | [`arx`] | least squares on lagged inputs |
//! | GP-static, GP-history ([`Baseline`]s) | [`gp`] | sparse GP regression of the inputs (and a controlled history) |

use flapssm_prssm::train::EpochRecord;
use flapssm_wing::dataset::{Trajectory, ValidDataset};
use rayon::prelude::*;

use crate::error::{JobError, Result};
use crate::progress::Progress;

pub mod arx;
pub mod gp;
pub mod lrqsm;
pub mod prssm;

/// Loads a model writes for one trajectory of `n` samples: row-major `n × 5` tables in N and
/// N·mm (variances in N², (N·mm)²), latent means `n × n_latent`.
pub struct LoadPrediction<'a> {
    /// Output means, `n × 5`.
    pub mean: &'a mut [f64],
    /// Output variances, `n × 5`, for a model with [`LoadModel::has_variance`].
    pub var: Option<&'a mut [f64]>,
    /// Latent means, `n × n_latent`, for a model with latent states.
    pub latent_mean: Option<&'a mut [f64]>,
}

/// A model of the wing's loads.
pub trait LoadModel: Sync {
    /// Display name ("PR-SSM", "LRQSM", …).
    fn name(&self) -> &str;
    /// File-safe identifier ("prssm", "lrqsm", …): prefixes of its columns and arrays.
    fn key(&self) -> &str;
    /// A summary of its parameters and settings, for the report.
    fn parameters(&self) -> serde_json::Value;
    /// Whether [`LoadModel::predict_into`] writes output variances.
    fn has_variance(&self) -> bool {
        false
    }
    /// Latent states per sample (0: none).
    fn n_latent(&self) -> usize {
        0
    }
    /// The per-epoch training history, for a model trained by epochs.
    fn training_history(&self) -> Option<&[EpochRecord]> {
        None
    }
    /// Predicts trajectory `index` (`trajectory`) open loop into `out`, whose tables have
    /// `trajectory`'s sample count. `index` seeds any random draws, so the same model predicts
    /// the same trajectory identically whatever else is predicted.
    ///
    /// # Errors
    /// [`JobError::Mismatch`] for buffers of the wrong length; the model's own errors naming
    /// the trajectory.
    fn predict_into(
        &self,
        index: usize,
        trajectory: &Trajectory,
        out: LoadPrediction<'_>,
    ) -> Result<()>;
}

/// Validated settings that fit a [`LoadModel`] on a dataset's training trajectories.
pub trait Fit {
    /// The fitted model.
    type Model: LoadModel;
    /// Fits on `ds`'s training trajectories.
    ///
    /// # Errors
    /// The model's fitting errors, naming the dataset or trajectory.
    fn fit(&self, ds: &ValidDataset, progress: &dyn Progress) -> Result<Self::Model>;
}

/// A baseline fitted on a dataset's training trajectories with its default settings (see the
/// module docs).
#[derive(Clone, Copy)]
pub struct Baseline {
    /// Its [`LoadModel::key`], the value of `--baseline`.
    pub key: &'static str,
    /// One line for `--help` and the report.
    pub about: &'static str,
    /// Fits it on `ds`'s training trajectories.
    pub fit: fn(ds: &ValidDataset, progress: &dyn Progress) -> Result<Box<dyn LoadModel>>,
}

impl PartialEq for Baseline {
    fn eq(&self, other: &Self) -> bool {
        self.key == other.key
    }
}

impl std::fmt::Debug for Baseline {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Baseline").field("key", &self.key).finish()
    }
}

/// Every registered baseline.
pub const BASELINES: &[Baseline] = &[arx::BASELINE, gp::STATIC, gp::HISTORY];

/// The registered baseline `key`.
///
/// # Errors
/// [`JobError::Setting`] naming the known keys.
pub fn baseline(key: &str) -> Result<&'static Baseline> {
    BASELINES
        .iter()
        .find(|b| b.key == key)
        .ok_or_else(|| JobError::Setting {
            name: "baseline".into(),
            value: key.into(),
            expected: format!(
                "one of {}",
                BASELINES
                    .iter()
                    .map(|b| b.key)
                    .collect::<Vec<_>>()
                    .join(", ")
            ),
        })
}

/// One model's open-loop prediction of one trajectory (owned tables of [`LoadPrediction`]).
#[derive(Debug, Clone, PartialEq)]
pub struct ModelPrediction {
    /// Output means, `n × 5` (N, N·mm).
    pub mean: Vec<f64>,
    /// Output variances, `n × 5`, when the model has them.
    pub var: Option<Vec<f64>>,
    /// Latent means, `n × n_latent` (empty without latent states).
    pub latent_mean: Vec<f64>,
    /// Wall time of this trajectory's prediction (s, on one thread).
    pub wall_s: f64,
}

/// Predicts every trajectory of `ds` with `model` (in parallel on the caller's rayon pool;
/// results do not depend on threading). `progress.advance(1)` per trajectory.
///
/// # Errors
/// The first trajectory's error.
pub fn predict_all(
    model: &dyn LoadModel,
    ds: &ValidDataset,
    progress: &dyn Progress,
) -> Result<Vec<ModelPrediction>> {
    map_trajectories(ds, |i, t| {
        let n = t.inputs.len();
        let mut p = ModelPrediction {
            mean: vec![0.0; n * 5],
            var: model.has_variance().then(|| vec![0.0; n * 5]),
            latent_mean: vec![0.0; n * model.n_latent()],
            wall_s: 0.0,
        };
        let start = std::time::Instant::now();
        model.predict_into(
            i,
            t,
            LoadPrediction {
                mean: &mut p.mean,
                var: p.var.as_deref_mut(),
                latent_mean: (model.n_latent() > 0).then_some(&mut p.latent_mean[..]),
            },
        )?;
        p.wall_s = start.elapsed().as_secs_f64();
        progress.advance(1);
        Ok(p)
    })
}

/// `f(i, trajectory)` for every trajectory of `ds`, in parallel on the caller's rayon pool,
/// results in trajectory order; the first error wins.
///
/// # Errors
/// The first trajectory's error.
pub fn map_trajectories<T: Send>(
    ds: &ValidDataset,
    f: impl Fn(usize, &Trajectory) -> Result<T> + Sync,
) -> Result<Vec<T>> {
    ds.trajectories
        .par_iter()
        .enumerate()
        .map(|(i, t)| f(i, t))
        .collect()
}

/// Checks that `buffer` holds `n × width` values.
pub(crate) fn check_buffer(what: &str, buffer: &[f64], n: usize, width: usize) -> Result<()> {
    if buffer.len() != n * width {
        return Err(JobError::Mismatch {
            what: format!("{what} buffer"),
            expected: format!("{n} × {width} = {} values", n * width),
            found: buffer.len().to_string(),
        });
    }
    Ok(())
}
