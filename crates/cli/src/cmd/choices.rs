//! Command-line choices that more than one subcommand takes.

use clap::ValueEnum;
use flapssm_jobs::simulate::TrajectorySource;
use flapssm_prssm::train::fit::ObjectiveForm;
use flapssm_prssm::train::{BestBy, InducingInit};

/// `--source`: where the wing's trajectories come from.
#[derive(Clone, Copy, ValueEnum)]
pub enum SourceArg {
    /// The seeded random trajectory generator.
    Generator,
    /// The paper's 548 measured trajectories (Bayiz & Cheng 2021, vendored; the first N).
    Paper,
}

impl From<SourceArg> for TrajectorySource {
    fn from(s: SourceArg) -> Self {
        match s {
            SourceArg::Generator => TrajectorySource::Generator,
            SourceArg::Paper => TrajectorySource::Paper,
        }
    }
}

/// `--best-by`: which evaluated epoch's model is kept.
#[derive(Clone, Copy, ValueEnum)]
pub enum BestByArg {
    /// Validation RMSE, else the training rollouts' RMSE.
    Rmse,
    /// The lowest epoch-mean training loss (−ELBO), the published code's `best.ckpt`.
    TrainingLoss,
}

impl From<BestByArg> for BestBy {
    fn from(b: BestByArg) -> Self {
        match b {
            BestByArg::Rmse => BestBy::Rmse,
            BestByArg::TrainingLoss => BestBy::TrainingLoss,
        }
    }
}

/// `--objective`: which training objective is minimized.
#[derive(Clone, Copy, ValueEnum)]
pub enum ObjectiveArg {
    /// The unbiased minibatch ELBO with independent noise draws.
    Standard,
    /// The published code's: likelihood summed over particles, one KL per minibatch, one
    /// noise draw per particle and step shared by all latent dims.
    PublishedCode,
}

impl From<ObjectiveArg> for ObjectiveForm {
    fn from(o: ObjectiveArg) -> Self {
        match o {
            ObjectiveArg::Standard => ObjectiveForm::Standard,
            ObjectiveArg::PublishedCode => ObjectiveForm::PublishedCode,
        }
    }
}

/// `--inducing-init`: how the inducing inputs and `q(u)` means start.
#[derive(Clone, Copy, ValueEnum)]
pub enum InducingInitArg {
    /// Uniform in [−2, 2] (standardized units), as the published code.
    Uniform,
    /// k-means of the training inputs visited; `q(u)` means from the output increments.
    Kmeans,
}

impl From<InducingInitArg> for InducingInit {
    fn from(i: InducingInitArg) -> Self {
        match i {
            InducingInitArg::Uniform => InducingInit::Uniform,
            InducingInitArg::Kmeans => InducingInit::Kmeans,
        }
    }
}
