//! The scoring stage: the inputs checked, each trajectory's tables prepared, and the metrics of
//! each model (per set) and of each trajectory computed from them.

use flapssm_analysis::cycles_avg::CycleWindow;
use flapssm_analysis::metrics::{CoefficientScales, PooledErrors, coefficients_of, window_rmse};
use flapssm_wing::dataset::ValidDataset;

use super::prepared::{ModelTables, Prepared, cycle_errors, rows, split_metrics};
use super::report::{
    COMPARISON_DRAWS, EvalOptions, ModelMetrics, PairedComparison, TrajectoryMetrics,
    TrajectoryModelMetrics,
};
use crate::error::{JobError, Result, analysis};
use crate::models::{LoadModel, ModelPrediction};
use flapssm_analysis::bootstrap::{TrajectoryErrors, paired_bootstrap};

/// Checks the inputs once, before any prediction.
pub(super) fn check(
    ds: &ValidDataset,
    models: &[&dyn LoadModel],
    opts: &EvalOptions,
) -> Result<()> {
    opts.check()?;
    if !ds.has_outputs() {
        return Err(flapssm_wing::dataset::DatasetError::NoOutputs.into());
    }
    let n_train = ds.n_train.min(ds.len());
    if n_train == 0 {
        return Err(flapssm_wing::dataset::DatasetError::NoTrainingData { n_train }.into());
    }
    if models.is_empty() {
        return Err(JobError::Mismatch {
            what: "models to evaluate".into(),
            expected: "at least one".into(),
            found: "none".into(),
        });
    }
    let n = ds.n_samples();
    if opts.start_sample >= n {
        return Err(JobError::Mismatch {
            what: "start_sample".into(),
            expected: format!("fewer than the {n} samples per trajectory"),
            found: opts.start_sample.to_string(),
        });
    }
    Ok(())
}

/// Each trajectory's window and its measured and predicted tables (standardized and as
/// coefficients).
pub(super) fn prepare(
    ds: &ValidDataset,
    predictions: &[Vec<ModelPrediction>],
) -> Result<Vec<Prepared>> {
    let stats = ds.standardization()?;
    let (fluid, wing) = (&ds.meta.fluid, &ds.meta.wing);
    let z = |y: &[f64]| stats.normalize_y_table(y);
    let mut prep = Vec::with_capacity(ds.len());
    for (i, t) in ds.trajectories.iter().enumerate() {
        let what = format!("trajectory {i}");
        let w = t.published_window().map_err(|source| JobError::Cycle {
            trajectory: i,
            source,
        })?;
        let window = CycleWindow {
            start: w.first,
            duration: w.duration,
        };
        let scales = CoefficientScales::new(
            fluid.density_kg_m3,
            wing.area_m2(),
            wing.chord_m,
            t.u_ref_m_s,
        )
        .map_err(analysis(format!("{what} coefficient scales")))?;
        let measured = t.outputs.as_deref().unwrap_or_default().as_flattened();
        let coef = |v: &[f64]| -> Result<Vec<f64>> {
            coefficients_of(rows(v, 5, &what)?, &scales).map_err(analysis(what.clone()))
        };
        let models = predictions
            .iter()
            .map(|p| {
                let p = &p[i];
                let std_c = p
                    .var
                    .as_ref()
                    .map(|var| coef(&var.iter().map(|v| v.max(0.0).sqrt()).collect::<Vec<_>>()))
                    .transpose()?;
                Ok(ModelTables {
                    z: z(&p.mean),
                    c: coef(&p.mean)?,
                    std_c,
                })
            })
            .collect::<Result<_>>()?;
        prep.push(Prepared {
            window,
            measured_z: z(measured),
            measured_c: coef(measured)?,
            models,
        });
    }
    Ok(prep)
}

/// The prepared trajectories as training, test and all.
pub(super) struct Sets<'p> {
    pub(super) train: Vec<&'p Prepared>,
    pub(super) test: Vec<&'p Prepared>,
    pub(super) all: Vec<&'p Prepared>,
}

impl<'p> Sets<'p> {
    pub(super) fn new(prep: &'p [Prepared], n_train: usize) -> Self {
        Self {
            train: prep[..n_train].iter().collect(),
            test: prep[n_train..].iter().collect(),
            all: prep.iter().collect(),
        }
    }
}

pub(super) fn model_metrics(
    name: &str,
    key: &str,
    k: usize,
    sets: &Sets<'_>,
    opts: &EvalOptions,
) -> Result<ModelMetrics> {
    Ok(ModelMetrics {
        model: name.into(),
        key: key.into(),
        train: split_metrics(&sets.train, k, opts, &format!("{name} training metrics"))?,
        test: if sets.test.is_empty() {
            None
        } else {
            Some(split_metrics(
                &sets.test,
                k,
                opts,
                &format!("{name} test metrics"),
            )?)
        },
        cycle_average_error_interval_all: cycle_errors(&sets.all, k)?
            .intervals(opts.level)
            .map_err(analysis(format!("{name} cycle averages")))?,
    })
}

pub(super) fn trajectory_metrics(
    ds: &ValidDataset,
    models: &[&dyn LoadModel],
    prep: &[Prepared],
    n_train: usize,
    opts: &EvalOptions,
) -> Result<Vec<TrajectoryMetrics>> {
    let mut trajectories = Vec::with_capacity(ds.len());
    for (i, (t, p)) in ds.trajectories.iter().zip(prep).enumerate() {
        let what = format!("trajectory {i} metrics");
        let m = rows(&p.measured_c, 5, &what)?;
        let cyc = |v: &[f64]| -> Result<[f64; 2]> {
            let q = rows(v, 5, &what)?;
            Ok([
                window_rmse(m, q, 0, p.window).map_err(analysis(what.clone()))?,
                window_rmse(m, q, 1, p.window).map_err(analysis(what.clone()))?,
            ])
        };
        let overall = |v: &[f64]| -> Result<f64> {
            let e = PooledErrors::new(
                &[rows(&p.measured_z, 5, &what)?],
                &[rows(v, 5, &what)?],
                opts.start_sample,
            )
            .map_err(analysis(what.clone()))?;
            Ok(e.overall_rmse())
        };
        trajectories.push(TrajectoryMetrics {
            index: i,
            split: if i < n_train { "train" } else { "test" }.into(),
            family: t.family.clone(),
            u_ref_m_s: t.u_ref_m_s,
            period_samples: p.window.duration,
            window_start: p.window.start,
            models: models
                .iter()
                .zip(&p.models)
                .map(|(m, q)| {
                    Ok(TrajectoryModelMetrics {
                        model: m.key().into(),
                        cycle_rmse_cf: cyc(&q.c)?,
                        overall_rmse: overall(&q.z)?,
                    })
                })
                .collect::<Result<_>>()?,
        });
    }
    Ok(trajectories)
}

/// The first model against each other one ([`PairedComparison`]) on the test trajectories, or
/// on the training ones without a test set.
pub(super) fn paired_comparisons(
    models: &[&dyn LoadModel],
    sets: &Sets<'_>,
    opts: &EvalOptions,
) -> Result<Vec<PairedComparison>> {
    let (split, set) = if sets.test.is_empty() {
        ("train", &sets.train)
    } else {
        ("test", &sets.test)
    };
    let errors = |k: usize| -> Result<TrajectoryErrors> {
        let tables: Vec<Vec<f64>> = set
            .iter()
            .map(|p| {
                p.measured_z
                    .iter()
                    .zip(&p.models[k].z)
                    .skip(5 * opts.start_sample)
                    .map(|(y, q)| y - q)
                    .collect()
            })
            .collect();
        TrajectoryErrors::of_tables(tables.iter().map(|t| &t[..]), 5)
            .map_err(analysis(format!("{} paired errors", models[k].name())))
    };
    if models.len() < 2 {
        return Ok(Vec::new());
    }
    let first = errors(0)?;
    (1..models.len())
        .map(|k| {
            let what = format!("{} against {}", models[0].name(), models[k].name());
            Ok(PairedComparison {
                a: models[0].key().into(),
                b: models[k].key().into(),
                split: split.into(),
                outputs: paired_bootstrap(
                    &first,
                    &errors(k)?,
                    COMPARISON_DRAWS,
                    opts.level,
                    opts.seed,
                )
                .map_err(analysis(what))?,
            })
        })
        .collect()
}
