//! `flapssm sweep run|merge`: one PR-SSM configuration per process, and the merged table.

use std::path::PathBuf;

use anyhow::Context;
use clap::{Args, Subcommand};
use flapssm_jobs::files::check_outputs;
use flapssm_jobs::files::save_json;
use flapssm_jobs::presets::Preset;
use flapssm_jobs::sweep::{
    SweepKind, SweepSettings, SweepTable, checkpoint_beside, load_result, sweep_run,
};
use flapssm_jobs::train::TrainingOptions;
use flapssm_wing::dataset::Dataset;

use crate::cmd::choices::TrainingChoices;
use crate::progress::{Bars, stop_flag};

/// Sweep subcommands.
#[derive(Subcommand)]
pub enum SweepCommand {
    /// Train and evaluate one configuration, write its result file.
    Run(Box<RunArgs>),
    /// Merge result files into a table (CSV; .json and .png next to it).
    Merge(MergeArgs),
}

/// `flapssm sweep run`.
#[derive(Args)]
pub struct RunArgs {
    /// What to vary: dx (latent dimension; paper 8, 12, 16) or data-size (first V training
    /// trajectories; e.g. 64, 128, 256, 512).
    #[arg(long)]
    kind: SweepKind,
    /// The value of this configuration.
    #[arg(long)]
    value: usize,
    /// Dataset file (flapssm .npz).
    #[arg(long)]
    dataset: PathBuf,
    /// Result file (.json).
    #[arg(long)]
    out: PathBuf,
    /// Training preset: paper, paper-fast or sysid.
    #[arg(long, default_value = "paper")]
    preset: Preset,
    /// Latent dimension D_x (ignored for --kind dx).
    #[arg(long)]
    dx: Option<usize>,
    /// Inducing points M.
    #[arg(long)]
    inducing: Option<usize>,
    /// Particles per window.
    #[arg(long)]
    particles: Option<usize>,
    /// Epochs.
    #[arg(long)]
    epochs: Option<u64>,
    /// Windows per minibatch.
    #[arg(long)]
    batch: Option<usize>,
    /// Adam learning rate.
    #[arg(long)]
    lr: Option<f64>,
    /// Evaluate every this many epochs.
    #[arg(long)]
    eval_every: Option<u64>,
    /// Seed of training and prediction.
    #[arg(long, default_value_t = 0)]
    seed: u64,
    /// Fraction of the training trajectories held out for best-model selection.
    #[arg(long, default_value_t = 0.1)]
    val_fraction: f64,
    #[command(flatten)]
    training: TrainingChoices,
    /// Particles of the evaluation predictions.
    #[arg(long, default_value_t = 30)]
    eval_particles: usize,
    /// First analysed sample (0-based; published 93).
    #[arg(long, default_value_t = 93)]
    start_sample: usize,
    /// Write the training's checkpoint (`<out stem>.ckpt.json` beside --out) every this many
    /// epochs; it is also written when the run is stopped (Ctrl-C, SIGTERM). 0: only then.
    #[arg(long, value_name = "EPOCHS", default_value_t = 10)]
    checkpoint_every: u64,
    /// Continue from the checkpoint beside --out when there is one (a run stopped by Ctrl-C,
    /// SIGTERM or a scheduler's time limit goes on as if never stopped); start from the
    /// beginning when there is none. A checkpoint of another configuration or dataset is an
    /// error.
    #[arg(long)]
    resume: bool,
}

/// `flapssm sweep merge`.
#[derive(Args)]
pub struct MergeArgs {
    /// Result files of `flapssm sweep run`.
    #[arg(required = true)]
    results: Vec<PathBuf>,
    /// Table file (.csv); TABLE.json and TABLE.png are written next to it.
    #[arg(long)]
    out: PathBuf,
}

/// Runs `flapssm sweep`.
pub fn run(cmd: SweepCommand) -> anyhow::Result<()> {
    match cmd {
        SweepCommand::Run(a) => run_one(*a),
        SweepCommand::Merge(a) => merge(a),
    }
}

fn run_one(a: RunArgs) -> anyhow::Result<()> {
    let checkpoint = checkpoint_beside(&a.out);
    check_outputs(&[&a.out, &checkpoint], &[&a.dataset])?;
    let ds = Dataset::load(&a.dataset)
        .with_context(|| format!("loading dataset {}", a.dataset.display()))?;
    let mut training = TrainingOptions {
        preset: a.preset,
        dx: a.dx,
        inducing: a.inducing,
        particles: a.particles,
        epochs: a.epochs,
        batch: a.batch,
        lr: a.lr,
        eval_every: a.eval_every,
        seed: a.seed,
        val_fraction: a.val_fraction,
        checkpoint_every: a.checkpoint_every,
        ..TrainingOptions::default()
    };
    a.training.apply(&mut training);
    let plan = SweepSettings {
        kind: a.kind,
        value: a.value,
        training,
        particles: a.eval_particles,
        seed: a.seed,
        start_sample: a.start_sample,
    }
    .check(&ds)?;
    let stop = stop_flag()?;
    let r = sweep_run(
        &ds,
        &a.dataset.display().to_string(),
        &plan,
        Some(&checkpoint),
        a.resume,
        &Bars::new(),
        Some(&stop),
    )
    .with_context(|| {
        format!(
            "sweep {} = {} on {}",
            a.kind.name(),
            a.value,
            a.dataset.display()
        )
    })?;
    save_json(&a.out, &r).with_context(|| format!("writing {}", a.out.display()))?;
    println!(
        "{} = {}: train RMSE {:.4}, test RMSE {}, {:.1} s -> {}",
        a.kind.name(),
        a.value,
        r.train.overall,
        r.test
            .as_ref()
            .map_or("-".into(), |t| format!("{:.4}", t.overall)),
        r.train_wall_s,
        a.out.display()
    );
    Ok(())
}

fn merge(a: MergeArgs) -> anyhow::Result<()> {
    let (json, png) = (a.out.with_extension("json"), a.out.with_extension("png"));
    let inputs: Vec<&std::path::Path> = a.results.iter().map(PathBuf::as_path).collect();
    check_outputs(&[&a.out, &json, &png], &inputs)?;
    let results = a
        .results
        .iter()
        .map(|p| {
            load_result(p)
                .map(|r| (p.display().to_string(), r))
                .with_context(|| format!("reading sweep result {}", p.display()))
        })
        .collect::<anyhow::Result<Vec<_>>>()?;
    let table = SweepTable::new(&results)?;
    table
        .write(&a.out)
        .with_context(|| format!("writing {}", a.out.display()))?;
    print!("{}", table.to_csv());
    if !table.paper_comparison.is_empty() {
        println!("the paper's selections beside these results:");
        print!(
            "{}",
            flapssm_jobs::evaluate::paper::markdown(&table.paper_comparison)
        );
    }
    println!("wrote {} (+ .json, .png)", a.out.display());
    Ok(())
}
