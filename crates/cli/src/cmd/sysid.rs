//! `flapssm sysid FILE --input COL --output COL`: the Doerr et al. system-identification
//! protocol on a recorded input/output table (see `flapssm_jobs::sysid`).

use flapssm_prssm::Precision;
use std::path::PathBuf;

use anyhow::Context;
use clap::Args;
use flapssm_data::table::Column;
use flapssm_jobs::sysid::{
    Combine, IoRecord, SeedRun, SysidSpec, plot_test_prediction, run as run_protocol,
};
use flapssm_prssm::train::LrSchedule;

use crate::cmd::choices::InducingInitArg;

/// Fit a PR-SSM on the first part of a record, simulate the rest open loop, report test
/// RMSE (raw units) and NLL per seed and mean ± std.
#[derive(Args)]
pub struct SysidArgs {
    /// Table file: .mat (MATLAB v4/v5), .csv (with a header) or whitespace ASCII (.dat).
    file: PathBuf,
    /// Input column: name (CSV header, MAT variable) or 0-based index; repeat for several.
    #[arg(long = "input", required = true)]
    inputs: Vec<Column>,
    /// Output column: name or 0-based index; repeat for several.
    #[arg(long = "output", required = true)]
    outputs: Vec<Column>,
    /// Fraction of the samples (the first ones) used for training.
    #[arg(long, default_value_t = 0.5)]
    split: f64,
    /// Number of seeds (0, 1, …), one fit each.
    #[arg(long, default_value_t = 3)]
    seeds: u64,
    /// Independent fits per seed, run in parallel and combined (`--combine`).
    #[arg(long, default_value_t = 2)]
    restarts: usize,
    /// How restarts are combined: `ensemble` (moment-matched mixture of their predictions)
    /// `select` (lowest open-loop RMSE on the training part) or `snapshots` (mixture of the best and
    /// last parameters of every restart).
    #[arg(long, default_value = "ensemble", value_parser = parse_combine)]
    combine: Combine,
    /// Optimizer steps per fit.
    #[arg(long, default_value_t = 3000)]
    iterations: u64,
    /// Adam learning rate (protocol: 0.1).
    #[arg(long, default_value_t = 0.1)]
    lr: f64,
    /// Cosine-anneal the learning rate to `lr · F` at the last step (default: constant).
    #[arg(long, value_name = "F")]
    cosine: Option<f64>,
    /// How the inducing inputs and q(u) means start: uniform (the protocol's) or kmeans of
    /// the training inputs.
    #[arg(long, value_enum, default_value = "uniform")]
    inducing_init: InducingInitArg,
    /// Arithmetic of the ELBO's large products: f64 (the reference) or mixed (those products
    /// in f32, everything else in f64; docs/training.md).
    #[arg(long, default_value = "f64")]
    precision: Precision,
    /// Also score the last parameters of each fit (not only the selected best), for diagnosis.
    #[arg(long)]
    diagnose_last: bool,
    /// Print the report as JSON on stdout.
    #[arg(long)]
    json: bool,
    /// Figure of the test-part prediction of seed 0 with its ±2σ band (.png or .svg).
    #[arg(long)]
    plot: Option<PathBuf>,
}

fn parse_combine(s: &str) -> Result<Combine, String> {
    match s {
        "ensemble" => Ok(Combine::Ensemble),
        "select" => Ok(Combine::Select),
        "snapshots" => Ok(Combine::Snapshots),
        _ => Err(format!(
            "unknown combination {s:?} (expected ensemble, select or snapshots)"
        )),
    }
}

fn print_run(r: &SeedRun) {
    let members = match r.restarts.len() {
        1 => String::new(),
        _ => format!(
            "  (restarts: train RMSE {}; test RMSE {})",
            r.restarts
                .iter()
                .map(|x| format!("{:.3}", x.best_train_rmse.unwrap_or(f64::NAN)))
                .collect::<Vec<_>>()
                .join(", "),
            r.restarts
                .iter()
                .map(|x| format!("{:.4}", x.test.rmse))
                .collect::<Vec<_>>()
                .join(", ")
        ),
    };
    println!(
        "seed {:>2}: test RMSE {:.4}  NLL {:.3}  wall {:.1} s{members}{}{}",
        r.seed,
        r.test.rmse,
        r.test.nll,
        r.wall_s,
        r.last_test
            .map(|l| format!("  (last parameters: RMSE {:.4} NLL {:.3})", l.rmse, l.nll))
            .unwrap_or_default(),
        if r.rejected_steps > 0 {
            format!("  ({} rejected steps)", r.rejected_steps)
        } else {
            String::new()
        }
    );
}

/// Runs `flapssm sysid`.
pub fn run(args: SysidArgs) -> anyhow::Result<()> {
    if let Some(plot) = &args.plot {
        flapssm_jobs::files::check_figure_output(plot, &[&args.file])?;
    }
    let record = IoRecord::read(&args.file, &args.inputs, &args.outputs)
        .with_context(|| format!("reading {}", args.file.display()))?;
    let mut spec = SysidSpec {
        split: args.split,
        seeds: args.seeds,
        restarts: args.restarts,
        combine: args.combine,
        ..SysidSpec::reference(args.inputs.len(), args.outputs.len())
    }
    .with_iterations(args.iterations);
    spec.fit.train.lr = args.lr;
    spec.fit.inducing_init = args.inducing_init.into();
    spec.fit.precision = args.precision;
    if let Some(f) = args.cosine {
        spec.fit.train.schedule = LrSchedule::Cosine { final_factor: f };
    }
    let json = args.json;
    if !json {
        println!(
            "{}: {} samples, inputs {:?} → outputs {:?}",
            args.file.display(),
            record.n_samples(),
            record.input_names,
            record.output_names
        );
    }
    let (report, trace) = run_protocol(&record, &spec, args.diagnose_last, |r| {
        if json {
            eprintln!("seed {} done: test RMSE {:.4}", r.seed, r.test.rmse);
        } else {
            print_run(r);
        }
    })
    .with_context(|| format!("sysid protocol on {}", args.file.display()))?;
    if let Some(path) = &args.plot {
        let label = args
            .file
            .file_name()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_default();
        plot_test_prediction(path, &label, &report, &trace)
            .with_context(|| format!("writing figure {}", path.display()))?;
    }
    if json {
        println!("{}", serde_json::to_string_pretty(&report)?);
    } else {
        println!(
            "train {} / test {} samples; training-mean predictor RMSE {:.4}",
            report.n_train, report.n_test, report.mean_predictor_rmse
        );
        println!(
            "mean ± std over {} seeds: test RMSE {:.4} ± {:.4}  NLL {:.3} ± {:.3}  wall {:.1} ± {:.1} s",
            report.runs.len(),
            report.rmse.mean,
            report.rmse.std,
            report.nll.mean,
            report.nll.std,
            report.wall_s.mean,
            report.wall_s.std
        );
        if let Some(p) = &args.plot {
            println!("figure: {}", p.display());
        }
    }
    Ok(())
}
