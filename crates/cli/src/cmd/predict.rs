//! `flapssm predict MODEL --inputs U.csv`: open-loop PR-SSM prediction from an input CSV.
//! `flapssm predict MODEL DATASET --out PRED.npz`: prediction of every trajectory of a dataset.

use std::path::PathBuf;

use anyhow::{Context, bail};
use clap::Args;
use flapssm_jobs::predict::{predict_dataset_file, predict_input_file};
use flapssm_prssm::PrssmModel;
use flapssm_wing::dataset::Dataset;

use crate::progress::Bars;

/// Open-loop prediction with a PR-SSM model.
#[derive(Args)]
pub struct PredictArgs {
    /// Model file (.json).
    model: PathBuf,
    /// Dataset file (flapssm .npz): predict every trajectory (initial state by the model's
    /// rule, from the trajectory's first outputs where needed); writes an .npz.
    #[arg(required_unless_present = "inputs", conflicts_with = "inputs")]
    dataset: Option<PathBuf>,
    /// Input CSV with a header line and D_u columns, one row per time step (physical units
    /// when the model has normalization statistics, else standardized).
    #[arg(long)]
    inputs: Option<PathBuf>,
    /// Number of particles.
    #[arg(long, default_value_t = 30, value_parser = super::positive::<usize>)]
    particles: usize,
    /// Seed of the particle draws.
    #[arg(long, default_value_t = 0)]
    seed: u64,
    /// Output file: with --inputs a CSV (step, mean_0.., var_0..), with DATASET an .npz.
    #[arg(long)]
    out: PathBuf,
}

/// Runs `flapssm predict`.
pub fn run(args: PredictArgs) -> anyhow::Result<()> {
    let inputs: Vec<&std::path::Path> = [
        Some(&args.model),
        args.dataset.as_ref(),
        args.inputs.as_ref(),
    ]
    .into_iter()
    .flatten()
    .map(PathBuf::as_path)
    .collect();
    flapssm_jobs::files::check_outputs(&[&args.out], &inputs)?;
    let model = PrssmModel::load(&args.model)
        .with_context(|| format!("loading model {}", args.model.display()))?;
    if let Some(inputs_path) = &args.inputs {
        let p = predict_input_file(&model, inputs_path, args.particles, args.seed).with_context(
            || {
                format!(
                    "predicting {} with {}",
                    inputs_path.display(),
                    args.model.display()
                )
            },
        )?;
        for note in &p.notes {
            eprintln!("warning: {}: {note}", args.model.display());
        }
        p.prediction
            .write_csv(&args.out, model.config.n_output)
            .with_context(|| format!("writing {}", args.out.display()))?;
        println!(
            "{} steps, {} particles -> {}",
            p.prediction.output_mean.len() / model.config.n_output.max(1),
            args.particles,
            args.out.display()
        );
        return Ok(());
    }
    let Some(ds_path) = args.dataset.as_ref() else {
        bail!("give a DATASET or --inputs");
    };
    let ds =
        Dataset::load(ds_path).with_context(|| format!("loading dataset {}", ds_path.display()))?;
    let s = predict_dataset_file(
        &model,
        &ds,
        args.particles,
        args.seed,
        &args.out,
        &Bars::new(),
    )
    .with_context(|| {
        format!(
            "predicting {} with {}",
            ds_path.display(),
            args.model.display()
        )
    })?;
    for note in &s.notes {
        eprintln!("note: {}: {note}", args.model.display());
    }
    println!(
        "{} trajectories x {} steps, {} particles -> {}",
        s.n_trajectories,
        s.n_samples,
        args.particles,
        args.out.display()
    );
    Ok(())
}
