//! `flapssm train DATASET --out MODEL`: fit a PR-SSM to a flapssm dataset.

use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};

use anyhow::{Context, bail};
use clap::Args;
use flapssm_data::Dataset;
use flapssm_jobs::predict::trajectory_sequence;
use flapssm_jobs::train::TrainingOptions;
use flapssm_prssm::Sequence;
use flapssm_prssm::train::fit::{Preset, fit};
use flapssm_prssm::train::{Budget, Checkpoint, LrSchedule, TrainEvent, TrainHooks};
use indicatif::{ProgressBar, ProgressStyle};

/// Train a PR-SSM (negative-ELBO minimization with Adam).
#[derive(Args)]
pub struct TrainArgs {
    /// Dataset file (flapssm .npz); its training trajectories are used.
    dataset: PathBuf,
    /// Output model file (.json): the best model by validation RMSE; the last model goes to
    /// `<out stem>.last.json`.
    #[arg(long)]
    out: PathBuf,
    /// Named preset: paper (Bayiz & Cheng 2021) or sysid (Doerr et al. 2018).
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

/// `<dir>/<stem><suffix>` next to `path`.
fn sibling(path: &Path, suffix: &str) -> PathBuf {
    let stem = path
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "model".into());
    path.with_file_name(format!("{stem}{suffix}"))
}

/// Runs `flapssm train`.
pub fn run(args: TrainArgs) -> anyhow::Result<()> {
    let ds = Dataset::load(&args.dataset)
        .with_context(|| format!("loading dataset {}", args.dataset.display()))?;
    if !ds.has_outputs() {
        bail!(
            "{}: dataset has no outputs y to train on",
            args.dataset.display()
        );
    }
    if !(0.0..1.0).contains(&args.val_fraction) {
        bail!("--val-fraction {} must be in [0, 1)", args.val_fraction);
    }
    let schedule = args.schedule.as_deref().map(parse_schedule).transpose()?;
    let options = TrainingOptions {
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
        checkpoint_every: args.checkpoint_every,
    };
    let (fit_part, val_part) = options
        .split(ds.train())
        .with_context(|| format!("{}: no training trajectories", args.dataset.display()))?;
    let train_seqs: Vec<Sequence> = fit_part.iter().map(trajectory_sequence).collect();
    let val_seqs: Vec<Sequence> = val_part.iter().map(trajectory_sequence).collect();
    let spec = options.spec();

    let ck_path = args
        .checkpoint
        .clone()
        .unwrap_or_else(|| sibling(&args.out, ".ckpt.json"));
    let resume = if args.resume {
        Some(
            Checkpoint::load(&ck_path)
                .with_context(|| format!("resuming from {}", ck_path.display()))?,
        )
    } else {
        None
    };

    let stop = Arc::new(AtomicBool::new(false));
    {
        let stop = Arc::clone(&stop);
        ctrlc::set_handler(move || stop.store(true, Ordering::SeqCst))
            .context("installing the Ctrl-C handler")?;
    }
    let bar = ProgressBar::new(0);
    bar.set_style(
        ProgressStyle::with_template(
            "{elapsed_precise} [{bar:30}] {pos}/{len} steps (eta {eta}) {msg}",
        )
        .context("progress bar template")?
        .progress_chars("=> "),
    );
    let say = |line: String| bar.suspend(|| eprintln!("{line}"));
    let mut progress = |e: &TrainEvent<'_>| match e {
        TrainEvent::Step {
            step,
            total_steps,
            epoch,
            loss,
            lr,
        } => {
            bar.set_length(*total_steps);
            bar.set_position(step + 1);
            bar.set_message(format!("epoch {epoch} loss {loss:.4e} lr {lr:.2e}"));
        }
        TrainEvent::Epoch(r) => {
            let f = |v: Option<f64>| v.map_or("-".to_string(), |v| format!("{v:.4}"));
            say(format!(
                "epoch {:>4}: -ELBO {:.5e}  train RMSE {}  val RMSE {}{}",
                r.epoch,
                r.mean_loss,
                f(r.train_rmse),
                f(r.val_rmse),
                if r.is_best { "  (best)" } else { "" }
            ));
        }
        TrainEvent::Rejected {
            step,
            reason,
            lr_scale,
            retry,
        } => say(format!(
            "warning: step {step} rejected ({reason}); step undone, learning-rate factor now {lr_scale:.3e} (retry {retry})"
        )),
        TrainEvent::Checkpoint { path, step } => {
            say(format!("checkpoint at step {step} -> {}", path.display()))
        }
        TrainEvent::Interrupted { step } => say(format!(
            "interrupted at step {step}; continue with --resume (checkpoint {})",
            ck_path.display()
        )),
        _ => {}
    };
    println!(
        "{}: {} training / {} validation trajectories; D_x {}, M {}, {} particles, {}",
        args.dataset.display(),
        train_seqs.len(),
        val_seqs.len(),
        spec.model.n_state,
        spec.model.n_inducing,
        spec.particles,
        match spec.train.budget {
            Budget::Epochs(n) => format!("{n} epochs"),
            Budget::Iterations(n) => format!("{n} iterations"),
        }
    );
    let out = fit(
        &spec,
        &train_seqs,
        &val_seqs,
        TrainHooks {
            evaluate: None,
            progress: Some(&mut progress),
            stop: Some(&stop),
            checkpoint: Some(ck_path.clone()),
        },
        resume,
    )
    .with_context(|| format!("training on {}", args.dataset.display()))?;
    bar.finish_and_clear();
    if out.outcome.interrupted {
        bail!(
            "interrupted at step {}; resumable checkpoint {}",
            out.outcome.state.step,
            ck_path.display()
        );
    }
    let last_path = sibling(&args.out, ".last.json");
    out.best
        .save(&args.out)
        .with_context(|| format!("writing model {}", args.out.display()))?;
    out.last
        .save(&last_path)
        .with_context(|| format!("writing model {}", last_path.display()))?;
    let best = out.outcome.state.best.as_ref();
    println!(
        "{} steps ({} rejected); best model (epoch {}, score {}) -> {}; last -> {}",
        out.outcome.state.step,
        out.outcome.state.rejected,
        best.map_or("-".into(), |b| b.epoch.to_string()),
        best.map_or("-".into(), |b| format!("{:.4}", b.score)),
        args.out.display(),
        last_path.display()
    );
    Ok(())
}
