//! Command-line choices that more than one subcommand takes.

use clap::{Args, ValueEnum};
use flapssm_jobs::simulate::TrajectorySource;
use flapssm_jobs::train::TrainingOptions;
use flapssm_prssm::Precision;
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

/// The training choices that `train`, `sweep run` and `demo` take alike; one not given keeps
/// the training preset's value (in the demo, its configuration's).
#[derive(Args)]
pub struct TrainingChoices {
    /// How the inducing inputs and q(u) means start: uniform (the published code) or kmeans
    /// of the training inputs.
    #[arg(long, value_enum, value_name = "RULE")]
    inducing_init: Option<InducingInitArg>,
    /// Early stopping: end training when N evaluated epochs in a row bring no new best model.
    #[arg(long, value_name = "N", value_parser = super::positive::<u64>)]
    patience: Option<u64>,
    /// Arithmetic of the ELBO's large products: f64 (the reference) or mixed (those products
    /// in f32, everything else in f64; docs/training.md). The presets: f64, and mixed for
    /// paper-fast.
    #[arg(long)]
    precision: Option<Precision>,
    /// Windows (sequences) per parallel task of the ELBO: a minibatch of B windows keeps at
    /// most ceil(B / N) threads busy (the presets: 4, so batch 16 fills 4 cores; the demo: 2,
    /// so its minibatches of 4 fill 2); results depend on the thread count not at all, on N
    /// only in the last bits (docs/training.md).
    #[arg(long, value_name = "N", value_parser = super::positive::<usize>)]
    windows_per_task: Option<usize>,
    /// Initial lengthscale of every GP input, in standardized units. The presets: 2 as
    /// published, 10 for paper-fast (docs/training.md, "Time to quality").
    #[arg(long, value_name = "L")]
    lengthscale_init: Option<f64>,
}

impl TrainingChoices {
    /// Writes the choices given into `training`.
    pub fn apply(&self, training: &mut TrainingOptions) {
        if let Some(i) = self.inducing_init {
            training.inducing_init = Some(i.into());
        }
        if self.patience.is_some() {
            training.patience = self.patience;
        }
        if self.precision.is_some() {
            training.precision = self.precision;
        }
        if self.windows_per_task.is_some() {
            training.windows_per_task = self.windows_per_task;
        }
        if self.lengthscale_init.is_some() {
            training.lengthscale_init = self.lengthscale_init;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::Parser;

    #[derive(Parser)]
    struct Probe {
        #[command(flatten)]
        training: TrainingChoices,
    }

    fn parse(args: &[&str]) -> Result<TrainingChoices, clap::Error> {
        Probe::try_parse_from(std::iter::once("probe").chain(args.iter().copied()))
            .map(|p| p.training)
    }

    #[test]
    fn the_choices_given_override_and_the_others_keep_the_preset() {
        let start = TrainingOptions {
            windows_per_task: Some(2),
            ..TrainingOptions::default()
        };
        let mut t = start.clone();
        parse(&[]).unwrap().apply(&mut t);
        assert_eq!(t, start);
        let given = [
            "--inducing-init",
            "kmeans",
            "--patience",
            "5",
            "--precision",
            "mixed",
            "--lengthscale-init",
            "10",
        ];
        parse(&given).unwrap().apply(&mut t);
        assert_eq!(t.inducing_init, Some(InducingInit::Kmeans));
        assert_eq!(t.patience, Some(5));
        assert_eq!(t.precision, Some(Precision::Mixed));
        assert_eq!(t.lengthscale_init, Some(10.0));
        assert_eq!(t.windows_per_task, Some(2));
        parse(&["--windows-per-task", "4"]).unwrap().apply(&mut t);
        assert_eq!(t.windows_per_task, Some(4));
    }

    #[test]
    fn a_zero_count_is_refused_by_name() {
        for flag in ["--patience", "--windows-per-task"] {
            let err = parse(&[flag, "0"]).err().expect("0 refused");
            assert!(err.to_string().contains(flag), "{flag}: {err}");
        }
    }
}
