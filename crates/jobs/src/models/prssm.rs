//! The PR-SSM as a [`LoadModel`]: open-loop prediction from the model's initial-state rule with
//! a fixed particle count, trajectory `i` drawn with [`prediction_seed`]`(seed, i)`.

use std::borrow::Cow;

use flapssm_prssm::PrssmModel;
use flapssm_prssm::predict::Prediction;
use flapssm_prssm::train::EpochRecord;
use flapssm_prssm::train::fit::training_record;
use flapssm_wing::dataset::{Trajectory, ValidDataset};

use super::{Fit, LoadModel, LoadPrediction, check_buffer};
use crate::adapters::{in_dataset_units, trajectory_sequence};
use crate::error::{JobError, Result};
use crate::progress::Progress;
use crate::resources;
use crate::seed::prediction_seed;
use crate::train::{TrainingPlan, train_prssm};

/// A PR-SSM in a dataset's physical units with its prediction settings.
#[derive(Debug, Clone)]
pub struct PrssmLoadModel<'m> {
    model: Cow<'m, PrssmModel>,
    particles: usize,
    seed: u64,
    history: Option<Vec<EpochRecord>>,
}

impl<'m> PrssmLoadModel<'m> {
    /// `model` applied to `ds`'s units ([`in_dataset_units`]), predicting with `particles`
    /// particles and master seed `seed`.
    ///
    /// # Errors
    /// [`JobError::Mismatch`] for a model that is not 7 inputs → 5 outputs or no particles;
    /// [`JobError::Dataset`] when the model has no statistics and `ds` none to offer.
    pub fn new(
        model: &'m PrssmModel,
        ds: &ValidDataset,
        particles: usize,
        seed: u64,
    ) -> Result<Self> {
        let c = &model.config;
        if c.n_input != 7 || c.n_output != 5 {
            return Err(JobError::Mismatch {
                what: "PR-SSM model inputs/outputs".into(),
                expected: "7 inputs and 5 outputs (the dataset's)".into(),
                found: format!("{} inputs, {} outputs", c.n_input, c.n_output),
            });
        }
        if particles == 0 {
            return Err(JobError::Setting {
                name: "particles".into(),
                value: "0".into(),
                expected: "must be at least 1".into(),
            });
        }
        // Each thread simulates one trajectory's particles; every trajectory's moments are kept.
        let threads = crate::threads::current_threads();
        let moments = 4.0 * (ds.len() * ds.n_samples() * c.n_state) as f64 * 8.0;
        resources::check_prediction(c, particles, threads, moments)?;
        let history = training_record(model)
            .ok()
            .map(|r| r.history)
            .filter(|h| !h.is_empty());
        Ok(Self {
            model: in_dataset_units(model, ds)?,
            particles,
            seed,
            history,
        })
    }

    /// The model (with the normalization statistics it predicts with).
    pub fn model(&self) -> &PrssmModel {
        &self.model
    }

    /// The same, owning its model.
    pub fn into_owned(self) -> PrssmLoadModel<'static> {
        PrssmLoadModel {
            model: Cow::Owned(self.model.into_owned()),
            particles: self.particles,
            seed: self.seed,
            history: self.history,
        }
    }

    /// The full open-loop prediction of trajectory `index` (latent variances included): the
    /// one prediction path of the PR-SSM in every job.
    ///
    /// # Errors
    /// [`JobError::Prssm`] naming the trajectory.
    pub fn predict(&self, index: usize, trajectory: &Trajectory) -> Result<Prediction> {
        self.model
            .predict_sequence(
                trajectory_sequence(trajectory),
                self.particles,
                prediction_seed(self.seed, index),
            )
            .map_err(|source| JobError::Prssm {
                what: format!("prediction of trajectory {index}"),
                source: source.into(),
            })
    }
}

impl LoadModel for PrssmLoadModel<'_> {
    fn name(&self) -> &str {
        "PR-SSM"
    }

    fn key(&self) -> &str {
        "prssm"
    }

    fn parameters(&self) -> serde_json::Value {
        serde_json::json!({
            "config": self.model.config,
            "training": training_record(&self.model).ok().map(|t| t.spec),
            "prediction": { "particles": self.particles, "seed": self.seed },
        })
    }

    fn has_variance(&self) -> bool {
        true
    }

    fn n_latent(&self) -> usize {
        self.model.config.n_state
    }

    fn training_history(&self) -> Option<&[EpochRecord]> {
        self.history.as_deref()
    }

    fn predict_into(
        &self,
        index: usize,
        trajectory: &Trajectory,
        out: LoadPrediction<'_>,
    ) -> Result<()> {
        let n = trajectory.inputs.len();
        let dx = self.n_latent();
        check_buffer("PR-SSM mean", out.mean, n, 5)?;
        let p = self.predict(index, trajectory)?;
        out.mean.copy_from_slice(&p.output_mean);
        if let Some(var) = out.var {
            check_buffer("PR-SSM variance", var, n, 5)?;
            var.copy_from_slice(&p.output_var);
        }
        if let Some(latent) = out.latent_mean {
            check_buffer("PR-SSM latent mean", latent, n, dx)?;
            latent.copy_from_slice(&p.latent_mean);
        }
        Ok(())
    }
}

/// Fits a PR-SSM by [`train_prssm`] (no checkpoint) and predicts with `particles` particles
/// and master seed `seed`.
#[derive(Debug, Clone)]
pub struct PrssmFit {
    /// The validated training settings.
    pub plan: TrainingPlan,
    /// Particles of the predictions.
    pub particles: usize,
    /// Master seed of the prediction draws.
    pub seed: u64,
}

impl Fit for PrssmFit {
    type Model = PrssmLoadModel<'static>;

    fn fit(&self, ds: &ValidDataset, progress: &dyn Progress) -> Result<Self::Model> {
        let out = train_prssm(ds.train(), &self.plan, None, None, None, progress, None)?;
        Ok(PrssmLoadModel::new(&out.best, ds, self.particles, self.seed)?.into_owned())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::progress::NoProgress;
    use crate::test_data::tiny_dataset;
    use crate::train::TrainingOptions;

    /// `PrssmFit` is `train_prssm` followed by [`PrssmLoadModel::new`]: the same parameters,
    /// its training history kept, and the same prediction of a trajectory.
    #[test]
    fn fit_trains_and_wraps_the_best_model() {
        let ds = tiny_dataset();
        let plan = TrainingOptions {
            dx: Some(5),
            inducing: Some(6),
            particles: Some(3),
            epochs: Some(2),
            val_fraction: 0.0,
            ..TrainingOptions::default()
        }
        .check()
        .unwrap();
        let fitted = PrssmFit {
            plan: plan.clone(),
            particles: 4,
            seed: 2,
        }
        .fit(&ds, &NoProgress)
        .unwrap();
        let out = train_prssm(ds.train(), &plan, None, None, None, &NoProgress, None).unwrap();
        assert_eq!(fitted.model().params, out.best.params);
        assert_eq!(fitted.training_history().map(<[_]>::len), Some(2));
        let direct = PrssmLoadModel::new(&out.best, &ds, 4, 2).unwrap();
        let t = &ds.trajectories[5];
        assert_eq!(
            fitted.predict(5, t).unwrap().output_mean,
            direct.predict(5, t).unwrap().output_mean
        );
    }
}
