//! `flapssm train DATASET --out MODEL`: fit a PR-SSM to a flapssm dataset. Its training
//! flags are `TrainingOptions::NAMES` (tested below).

use std::path::PathBuf;

use anyhow::Context;
use clap::Args;
use flapssm_jobs::JobError;
use flapssm_jobs::presets::Preset;
use flapssm_jobs::train::{TrainFiles, TrainingOptions, train_dataset};
use flapssm_prssm::train::LrSchedule;
use flapssm_wing::dataset::Dataset;

use crate::cmd::choices::{BestByArg, ObjectiveArg, TrainingChoices};
use crate::progress::{Bars, stop_flag};

/// Train a PR-SSM (negative-ELBO minimization with Adam).
#[derive(Args)]
pub struct TrainArgs {
    /// Dataset file (flapssm .npz); its training trajectories are used.
    dataset: PathBuf,
    /// Output model file (.json): the best model by validation RMSE; the last model goes to
    /// `<out stem>.last.json`.
    #[arg(long)]
    out: PathBuf,
    /// Named preset: paper (Bayiz & Cheng 2021), paper-fast (the paper's model trained for
    /// time to quality: initial lengthscales 10, batch 4, 10 particles, mixed precision, 300
    /// epochs with a cosine-annealed rate; docs/training.md) or sysid (Doerr et al. 2018).
    #[arg(long, default_value = "paper")]
    preset: Preset,
    /// Latent dimension D_x.
    #[arg(long, value_parser = super::positive::<usize>)]
    dx: Option<usize>,
    /// Number of inducing points M.
    #[arg(long, value_parser = super::positive::<usize>)]
    inducing: Option<usize>,
    /// Particles per window.
    #[arg(long, value_parser = super::positive::<usize>)]
    particles: Option<usize>,
    /// Epochs (whole passes over all windows).
    #[arg(long, conflicts_with = "iterations", value_parser = super::positive::<u64>)]
    epochs: Option<u64>,
    /// Optimizer steps instead of epochs.
    #[arg(long, value_parser = super::positive::<u64>)]
    iterations: Option<u64>,
    /// Windows per minibatch.
    #[arg(long, value_parser = super::positive::<usize>)]
    batch: Option<usize>,
    /// Adam learning rate.
    #[arg(long)]
    lr: Option<f64>,
    /// Learning-rate schedule: constant, step:EVERY:FACTOR, exp:FINAL_FACTOR,
    /// cosine:FINAL_FACTOR (the preset's when absent).
    #[arg(long)]
    schedule: Option<LrSchedule>,
    /// Evaluate (best-model tracking) every N epochs (the preset's when absent).
    #[arg(long, value_parser = super::positive::<u64>)]
    eval_every: Option<u64>,
    /// Seed of initialization, shuffles and particle draws.
    #[arg(long, default_value_t = 0)]
    seed: u64,
    /// Fraction of the training trajectories (the last ones) held out for validation.
    #[arg(long, default_value_t = 0.1)]
    val_fraction: f64,
    /// Best model by RMSE (validation, else training rollouts) or by the lowest epoch-mean
    /// training loss (the published code's `best.ckpt`).
    #[arg(long, value_enum, default_value = "rmse")]
    best_by: BestByArg,
    /// Training objective: standard (the unbiased ELBO) or published-code (the authors'
    /// objective and shared noise draws, to re-run their exact training).
    #[arg(long, value_enum, default_value = "standard")]
    objective: ObjectiveArg,
    #[command(flatten)]
    training: TrainingChoices,
    /// Write a checkpoint every N epochs (0: only on Ctrl-C).
    #[arg(long, default_value_t = 10)]
    checkpoint_every: u64,
    /// Checkpoint file (default: `<out>.ckpt.json`).
    #[arg(long)]
    checkpoint: Option<PathBuf>,
    /// Continue from the checkpoint file.
    #[arg(long)]
    resume: bool,
}

/// Runs `flapssm train`.
pub fn run(args: TrainArgs) -> anyhow::Result<()> {
    let mut plan = TrainingOptions {
        preset: args.preset,
        dx: args.dx,
        inducing: args.inducing,
        particles: args.particles,
        epochs: args.epochs,
        iterations: args.iterations,
        batch: args.batch,
        lr: args.lr,
        schedule: args.schedule,
        eval_every: args.eval_every,
        seed: args.seed,
        val_fraction: args.val_fraction,
        best_by: args.best_by.into(),
        objective: args.objective.into(),
        checkpoint_every: args.checkpoint_every,
        ..TrainingOptions::default()
    };
    args.training.apply(&mut plan);
    let plan = plan.check()?;
    let files = TrainFiles::beside(&args.out, args.checkpoint.clone());
    flapssm_jobs::files::check_outputs(
        &[&files.model, &files.last, &files.checkpoint, &files.curve],
        &[&args.dataset],
    )?;
    let ds = Dataset::load(&args.dataset)
        .with_context(|| format!("loading dataset {}", args.dataset.display()))?;
    if ds.has_outputs() {
        println!("{}: {}", args.dataset.display(), plan.describe(ds.train())?);
    }
    let stop = stop_flag()?;
    let s = train_dataset(&ds, &plan, &files, args.resume, &Bars::new(), Some(&stop))
        .map_err(|e| match e {
            JobError::Interrupted { .. } => {
                anyhow::anyhow!("{e}; rerun the same command with --resume to continue")
            }
            e => e.into(),
        })
        .with_context(|| format!("training on {}", args.dataset.display()))?;
    println!(
        "{} steps ({} rejected); best model (epoch {}, score {}) -> {}; last -> {}",
        s.steps,
        s.rejected,
        s.best.map_or("-".into(), |b| b.0.to_string()),
        s.best.map_or("-".into(), |b| format!("{:.4}", b.1)),
        files.model.display(),
        files.last.display()
    );
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::{Args, Command};

    /// The training flags are exactly the one schema's options ([`TrainingOptions::NAMES`]);
    /// the rest name files.
    #[test]
    fn the_training_flags_are_the_training_options() {
        let cmd = TrainArgs::augment_args(Command::new("train"));
        let mut flags: Vec<String> = cmd
            .get_arguments()
            .map(|a| a.get_id().to_string())
            .filter(|id| !["dataset", "out", "checkpoint", "resume"].contains(&id.as_str()))
            .collect();
        let mut names: Vec<String> = TrainingOptions::NAMES
            .iter()
            .map(|s| s.to_string())
            .collect();
        flags.sort_unstable();
        names.sort_unstable();
        assert_eq!(flags, names);
    }
}
