//! `flapssm qs …`: the quasi-steady baseline (LRQSM): elastic net with cross-validation.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result};
use clap::{Args, Subcommand, ValueEnum};
use flapssm_jobs::NoProgress;
use flapssm_jobs::files::check_outputs;
use flapssm_jobs::models::Fit;
use flapssm_jobs::models::lrqsm::{LrqsmFit, fit_csv as fit_csv_table, predict_file};
use flapssm_qs::cv::{EnetOptions, FoldLayout, LambdaRule};
use flapssm_qs::lrqsm::Rmse;
use flapssm_qs::{InterceptMode, LrqsmModel};
use flapssm_wing::dataset::{Dataset, ValidDataset};
use flapssm_wing::features::FeatureSet;

/// Quasi-steady baseline subcommands.
#[derive(Subcommand)]
pub enum QsCommand {
    /// Fit the LRQSM on a dataset's training trajectories (targets: outputs standardized with
    /// training statistics), one elastic net per output with K-fold CV.
    Fit(FitArgs),
    /// Apply a model to every trajectory of a dataset; write predictions (.npz), print RMSE.
    Predict(PredictArgs),
    /// Fit an elastic net with CV on columns of a CSV file (header line of names).
    FitCsv(FitCsvArgs),
}

#[derive(Clone, Copy, ValueEnum)]
enum Features {
    /// The 11 features of the published code.
    Published,
    /// The 10 features of the paper's text.
    PaperText,
}

#[derive(Clone, Copy, ValueEnum)]
enum Rule {
    /// Largest λ within one standard error of the minimum CV MSE (published).
    #[value(name = "1se")]
    OneSe,
    /// Minimum CV MSE.
    Min,
}

/// Options shared by `fit` and `fit-csv`.
#[derive(Args)]
pub struct PathArgs {
    /// l1 ratio α ∈ (0, 1] (MATLAB's Alpha; 1 = lasso).
    #[arg(long, default_value_t = 0.75)]
    alpha: f64,
    /// Number of cross-validation folds.
    #[arg(long, default_value_t = 10)]
    folds: usize,
    /// λ selection rule.
    #[arg(long, value_enum, default_value = "1se")]
    rule: Rule,
    /// Seed of the random fold partition of the rows (default 0; the published baseline's
    /// layout, as MATLAB's `lasso(…, 'CV', K)`).
    #[arg(long, value_name = "SEED")]
    random_folds: Option<u64>,
    /// Contiguous blocks of rows as folds instead (whole trajectories, up to the boundaries).
    #[arg(long, conflicts_with = "random_folds")]
    contiguous: bool,
    /// Number of λ on the path.
    #[arg(long, default_value_t = 100)]
    n_lambdas: usize,
    /// Coordinate-descent tolerance (largest standardized coefficient change per sweep).
    #[arg(long, default_value_t = 1e-10)]
    tol: f64,
    /// Print the model JSON to stdout instead of a summary.
    #[arg(long)]
    json: bool,
}

impl PathArgs {
    fn options(&self) -> EnetOptions {
        EnetOptions {
            l1_ratio: self.alpha,
            n_folds: self.folds,
            n_lambdas: self.n_lambdas,
            tol: self.tol,
            rule: match self.rule {
                Rule::OneSe => LambdaRule::OneSe,
                Rule::Min => LambdaRule::Min,
            },
            folds: if self.contiguous {
                FoldLayout::Contiguous
            } else {
                FoldLayout::Random {
                    seed: self.random_folds.unwrap_or(0),
                }
            },
            ..EnetOptions::default()
        }
    }
}

/// `flapssm qs fit`.
#[derive(Args)]
pub struct FitArgs {
    /// Dataset file (.npz).
    dataset: PathBuf,
    /// Model file to write (JSON).
    #[arg(long)]
    out: PathBuf,
    /// Feature set.
    #[arg(long, value_enum, default_value = "published")]
    features: Features,
    /// Predict with the fitted intercept (default: dropped, as the published `y = x*LRmodel`).
    #[arg(long)]
    predict_intercept: bool,
    #[command(flatten)]
    path: PathArgs,
}

/// `flapssm qs predict`.
#[derive(Args)]
pub struct PredictArgs {
    /// Model file (JSON) from `flapssm qs fit`.
    model: PathBuf,
    /// Dataset file (.npz).
    dataset: PathBuf,
    /// Predictions file to write (.npz).
    #[arg(long)]
    out: PathBuf,
    /// Drop the intercept whatever the model file says (models predict as they were fitted:
    /// without it by default, as the published `y = x*LRmodel`).
    #[arg(long)]
    published: bool,
}

/// `flapssm qs fit-csv`.
#[derive(Args)]
pub struct FitCsvArgs {
    /// CSV file with a header line of column names.
    file: PathBuf,
    /// Target columns, comma separated.
    #[arg(long, value_delimiter = ',', required = true)]
    targets: Vec<String>,
    /// Feature columns, comma separated (default: every non-target column).
    #[arg(long, value_delimiter = ',')]
    features: Option<Vec<String>>,
    /// Model file to write (JSON).
    #[arg(long)]
    out: PathBuf,
    /// Standardize features (default).
    #[arg(long, overrides_with = "no_standardize")]
    standardize: bool,
    /// Do not standardize features.
    #[arg(long)]
    no_standardize: bool,
    /// Fit an intercept (default).
    #[arg(long, overrides_with = "no_intercept")]
    intercept: bool,
    /// Fit without intercept (nothing is centred).
    #[arg(long)]
    no_intercept: bool,
    #[command(flatten)]
    path: PathArgs,
}

/// Runs a `flapssm qs` subcommand.
pub fn run(cmd: QsCommand) -> Result<()> {
    match cmd {
        QsCommand::Fit(a) => fit(a),
        QsCommand::Predict(a) => predict(a),
        QsCommand::FitCsv(a) => fit_csv(a),
    }
}

fn load_dataset(path: &Path) -> Result<ValidDataset> {
    Dataset::load(path).with_context(|| format!("cannot load dataset {}", path.display()))
}

fn fit(a: FitArgs) -> Result<()> {
    check_outputs(&[&a.out], &[&a.dataset])?;
    let ds = load_dataset(&a.dataset)?;
    let fit = LrqsmFit {
        features: match a.features {
            Features::Published => FeatureSet::Published,
            Features::PaperText => FeatureSet::PaperText,
        },
        options: a.path.options(),
        prediction_intercept: if a.predict_intercept {
            InterceptMode::Fitted
        } else {
            InterceptMode::Dropped
        },
        source: a.dataset.display().to_string(),
    };
    let model = fit
        .fit(&ds, &NoProgress)
        .with_context(|| format!("fitting the LRQSM on {}", a.dataset.display()))?;
    finish(model.model(), &a.out, a.path.json)
}

fn fit_csv(a: FitCsvArgs) -> Result<()> {
    check_outputs(&[&a.out], &[&a.file])?;
    let opts = EnetOptions {
        standardize: !a.no_standardize,
        intercept: !a.no_intercept,
        ..a.path.options()
    };
    let model = fit_csv_table(&a.file, &a.targets, a.features.as_deref(), &opts)
        .with_context(|| format!("fitting on {}", a.file.display()))?;
    finish(&model, &a.out, a.path.json)
}

fn finish(model: &LrqsmModel, out: &Path, json: bool) -> Result<()> {
    model
        .save(out)
        .with_context(|| format!("writing model {}", out.display()))?;
    let unconverged: usize = model.fit.targets.iter().map(|t| t.unconverged).sum();
    if unconverged > 0 {
        eprintln!(
            "warning: {unconverged} path points reached the sweep limit before the tolerance"
        );
    }
    if json {
        println!("{}", serde_json::to_string_pretty(model)?);
        return Ok(());
    }
    let o = &model.options;
    println!(
        "fitted {} rows × {} features ({}), {} {} folds, alpha {}, rule {}",
        model.fit.n_rows,
        model.n_features(),
        model
            .feature_set
            .map_or("custom columns".to_string(), |s| format!("{s:?}")),
        o.n_folds,
        match o.folds {
            FoldLayout::Contiguous => "contiguous".to_string(),
            FoldLayout::Random { seed } => format!("random (seed {seed})"),
        },
        o.l1_ratio,
        match o.rule {
            LambdaRule::OneSe => "1se",
            LambdaRule::Min => "min",
        }
    );
    println!(
        "{:<10} {:>9} {:>9} {:>12} {:>12} {:>12}",
        "output", "index_1se", "index_min", "lambda", "cv_mse", "cv_mse_se"
    );
    for t in &model.fit.targets {
        let k = t.index_chosen;
        println!(
            "{:<10} {:>9} {:>9} {:>12.4e} {:>12.4e} {:>12.4e}",
            t.name, t.index_1se, t.index_min, t.lambdas[k], t.cv_mse_mean[k], t.cv_mse_se[k]
        );
    }
    println!("coefficients on the original feature scale (targets as fitted):");
    print!("{:<22}", "feature");
    model.chosen.iter().for_each(|c| print!(" {:>12}", c.name));
    println!();
    for (j, f) in model.fit.feature_names.iter().enumerate() {
        print!("{f:<22}");
        model
            .chosen
            .iter()
            .for_each(|c| print!(" {:>12.5e}", c.coef[j]));
        println!();
    }
    print!("{:<22}", "intercept");
    model
        .chosen
        .iter()
        .for_each(|c| print!(" {:>12.5e}", c.intercept));
    println!();
    println!("wrote {}", out.display());
    Ok(())
}

fn predict(a: PredictArgs) -> Result<()> {
    check_outputs(&[&a.out], &[&a.model, &a.dataset])?;
    let model = LrqsmModel::load(&a.model)
        .with_context(|| format!("loading LRQSM model {}", a.model.display()))?;
    let ds = load_dataset(&a.dataset)?;
    let mode = if a.published {
        InterceptMode::Dropped
    } else {
        model.prediction_intercept
    };
    let pred = predict_file(&model, &ds, mode, &a.out).with_context(|| {
        format!(
            "applying model {} to {} (predictions {})",
            a.model.display(),
            a.dataset.display(),
            a.out.display()
        )
    })?;
    let show = |label: &str, r: &Option<Rmse>| {
        let Some(r) = r else {
            println!("{label}: no samples with outputs");
            return;
        };
        println!("{label} RMSE ({} samples):", r.n_samples);
        for (t, name) in pred.output_names.iter().enumerate() {
            println!(
                "  {name:<6} {:>12.5e} (output units)  {:>8.4} (standardized)",
                r.raw[t], r.standardized[t]
            );
        }
    };
    show("train", &pred.rmse_train);
    show("test", &pred.rmse_test);
    println!(
        "wrote {} ({} trajectories × {} samples{})",
        a.out.display(),
        pred.n_trajectories,
        pred.n_samples,
        if mode == InterceptMode::Dropped {
            ", intercept dropped"
        } else {
            ", intercept added"
        }
    );
    Ok(())
}
