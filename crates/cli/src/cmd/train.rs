//! `flapssm train DATASET --out MODEL`: fit a PR-SSM to a flapssm dataset.

use std::path::PathBuf;

use anyhow::{Context, bail};
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
    /// cosine:FINAL_FACTOR.
    #[arg(long)]
    schedule: Option<String>,
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

fn parse_schedule(s: &str) -> anyhow::Result<LrSchedule> {
    let parts: Vec<&str> = s.split(':').collect();
    let num = |i: usize| -> anyhow::Result<f64> {
        parts
            .get(i)
            .with_context(|| format!("--schedule {s}: missing field {i}"))?
            .parse::<f64>()
            .with_context(|| format!("--schedule {s}: field {i} is not a number"))
    };
    Ok(match parts[0] {
        "constant" => LrSchedule::Constant,
        "step" => LrSchedule::Step {
            every: num(1)? as u64,
            factor: num(2)?,
        },
        "exp" => LrSchedule::Exponential {
            final_factor: num(1)?,
        },
        "cosine" => LrSchedule::Cosine {
            final_factor: num(1)?,
        },
        other => bail!("--schedule: unknown kind {other:?} (constant, step, exp, cosine)"),
    })
}

/// Runs `flapssm train`.
pub fn run(args: TrainArgs) -> anyhow::Result<()> {
    let schedule = args.schedule.as_deref().map(parse_schedule).transpose()?;
    let mut plan = TrainingOptions {
        preset: args.preset,
        dx: args.dx,
        inducing: args.inducing,
        particles: args.particles,
        epochs: args.epochs,
        iterations: args.iterations,
        batch: args.batch,
        lr: args.lr,
        schedule,
        eval_every: None,
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
