//! `flapssm predict MODEL --inputs U.csv`: open-loop PR-SSM prediction from an input CSV.
//! `flapssm predict MODEL DATASET --out PRED.npz`: prediction of every trajectory of a dataset.

use std::path::PathBuf;

use anyhow::{Context, bail};
use clap::Args;
use flapssm_data::table::Table;
use flapssm_prssm::PrssmModel;
use flapssm_prssm::train::InitialStateSpec;
use flapssm_prssm::train::fit::training_record;

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
    let Some(inputs_path) = args.inputs.clone() else {
        return run_dataset(args);
    };
    let model = PrssmModel::load(&args.model)
        .with_context(|| format!("loading model {}", args.model.display()))?;
    let table = Table::read_csv(&inputs_path)
        .with_context(|| format!("reading inputs {}", inputs_path.display()))?;
    let du = model.config.n_input;
    if table.columns.len() != du {
        bail!(
            "{}: {} columns, the model expects D_u = {du} inputs",
            inputs_path.display(),
            table.columns.len()
        );
    }
    if let Ok(r) = training_record(&model) {
        let rule = match r.initial_state.spec {
            InitialStateSpec::Zeros => None,
            InitialStateSpec::Outputs => Some("outputs"),
            _ => Some("recognition"),
        };
        if let Some(rule) = rule {
            eprintln!(
                "warning: {} was trained with the '{rule}' initial-state rule, which needs the \
                 first outputs; --inputs predicts from x_0 = 0 (predict a dataset to apply it)",
                args.model.display()
            );
        }
    }
    let t_n = table.n_rows();
    let inputs: Vec<f64> = (0..t_n)
        .flat_map(|t| table.columns.iter().map(move |c| c[t]))
        .collect();
    let pred = model
        .predict_inputs(
            &inputs,
            args.particles,
            flapssm_jobs::seed::prediction_seed(args.seed, 0),
        )
        .with_context(|| format!("predicting with {}", args.model.display()))?;
    pred.write_csv(&args.out, model.config.n_output)
        .with_context(|| format!("writing {}", args.out.display()))?;
    println!(
        "{t_n} steps, {} particles -> {}",
        args.particles,
        args.out.display()
    );
    Ok(())
}

/// `flapssm predict MODEL DATASET --out PRED.npz`: arrays `output_mean`, `output_var`
/// (n_traj × T × D_y, raw units), `latent_mean`, `latent_var` (n_traj × T × D_x,
/// standardized), `y` (observed outputs, if any) and `is_train` (n_traj). A model without
/// normalization statistics (the published one) works in standardized units: the dataset's
/// training statistics are used.
fn run_dataset(args: PredictArgs) -> anyhow::Result<()> {
    use flapssm_data::npz::{NpyData, NpzWriter};
    use flapssm_prssm::train::fit::predict_raw;
    use rayon::prelude::*;
    let Some(ds_path) = args.dataset.as_ref() else {
        bail!("give a DATASET or --inputs");
    };
    let model = PrssmModel::load(&args.model)
        .with_context(|| format!("loading model {}", args.model.display()))?;
    let ds = flapssm_data::Dataset::load(ds_path)
        .with_context(|| format!("loading dataset {}", ds_path.display()))?;
    let (dx, dy, du) = (
        model.config.n_state,
        model.config.n_output,
        model.config.n_input,
    );
    if du != 7 || dy != 5 {
        bail!(
            "{}: model has D_u = {du}, D_y = {dy}; a flapssm dataset has 7 inputs and 5 outputs",
            args.model.display()
        );
    }
    let bare = model.normalization.is_none();
    let model = flapssm_jobs::predict::in_dataset_units(&model, &ds)
        .with_context(|| {
            format!(
                "{} has no normalization statistics (standardized units) and {} has none to \
                 offer",
                args.model.display(),
                ds_path.display()
            )
        })?
        .into_owned();
    if bare {
        eprintln!(
            "note: {} has no normalization statistics; standardizing with the training \
             statistics of {}",
            args.model.display(),
            ds_path.display()
        );
    }
    let (n, t_n) = (ds.len(), ds.n_samples());
    let bar = crate::progress::progress_bar(n as u64, "trajectories")?;
    let preds = ds
        .trajectories
        .par_iter()
        .enumerate()
        .map(|(i, traj)| {
            let seq = flapssm_jobs::predict::trajectory_sequence(traj);
            let p = predict_raw(
                &model,
                &seq,
                args.particles,
                flapssm_jobs::seed::prediction_seed(args.seed, i),
            )
            .with_context(|| format!("{}: trajectory {i}", ds_path.display()));
            bar.inc(1);
            p.map(|p| (p, seq.outputs))
        })
        .collect::<anyhow::Result<Vec<_>>>()?;
    bar.finish_and_clear();
    let mut out: [Vec<f64>; 4] = Default::default();
    let mut y = Vec::new();
    for (p, outputs) in preds {
        out[0].extend(p.output_mean);
        out[1].extend(p.output_var);
        out[2].extend(p.latent_mean);
        out[3].extend(p.latent_var);
        y.extend(outputs);
    }
    let [om, ov, lm, lv] = out;
    let mut w = NpzWriter::new();
    w.add("output_mean", &[n, t_n, dy], NpyData::F64(om))
        .add("output_var", &[n, t_n, dy], NpyData::F64(ov))
        .add("latent_mean", &[n, t_n, dx], NpyData::F64(lm))
        .add("latent_var", &[n, t_n, dx], NpyData::F64(lv))
        .add(
            "is_train",
            &[n],
            NpyData::Bool((0..n).map(|i| i < ds.n_train).collect()),
        );
    if y.len() == n * t_n * dy {
        w.add("y", &[n, t_n, dy], NpyData::F64(y));
    }
    w.save(&args.out)
        .with_context(|| format!("writing {}", args.out.display()))?;
    println!(
        "{n} trajectories x {t_n} steps, {} particles -> {}",
        args.particles,
        args.out.display()
    );
    Ok(())
}
