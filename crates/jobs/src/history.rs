//! The history curve: does half a stroke of input history suffice? The GP baseline
//! ([`crate::models::gp`]) is given a controlled history of `h` samples, `h` from 0 (the
//! instantaneous inputs) to a stroke cycle or more; each is fitted on the training trajectories
//! (its settings chosen on held-out training trajectories) and scored on the test trajectories
//! from `start_sample` on. Each `h > 0` is compared with `h = 0` by a paired bootstrap over the
//! test trajectories ([`flapssm_analysis::bootstrap`]).
//!
//! Written into the output folder: `history_curve.json` ([`HistoryCurves`]),
//! `history_curve.csv` (one row per dataset and history) and `history_curve.png`.

use std::path::Path;

use flapssm_analysis::bootstrap::{PairedDifference, TrajectoryErrors, paired_bootstrap};
use flapssm_analysis::plots::history::{HistoryPanel, HistoryPoint, history_curve};
use flapssm_wing::dataset::{OUTPUT_NAMES, ValidDataset};
use serde::{Deserialize, Serialize};

use crate::error::{JobError, Result, analysis};
use crate::files::{save_json, save_text};
use crate::models::gp::{GpSettings, cycle_samples, fit_histories};
use crate::models::{LoadModel, LoadPrediction};
use crate::progress::Progress;

/// The files [`run_history_curves`] writes.
pub const HISTORY_FILES: [&str; 3] = [
    "history_curve.json",
    "history_curve.csv",
    "history_curve.png",
];

/// Settings of the history curve.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct HistoryOptions {
    /// Histories given, in stroke cycles (the training trajectories' median cycle); 0 is the
    /// static model and the reference of the comparisons.
    pub history_cycles: Vec<f64>,
    /// First scored sample of each test trajectory (published 93).
    pub start_sample: usize,
    /// Bootstrap draws.
    pub n_draws: usize,
    /// Interval level (%).
    pub level: f64,
    /// Seed of the bootstrap.
    pub seed: u64,
    /// The GP's settings.
    pub gp: GpSettings,
}

impl Default for HistoryOptions {
    fn default() -> Self {
        Self {
            history_cycles: vec![0.0, 0.0625, 0.125, 0.25, 0.5, 0.75, 1.0],
            start_sample: 93,
            n_draws: 2000,
            level: 95.0,
            seed: 0,
            gp: GpSettings::default(),
        }
    }
}

/// One history length on one dataset.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct HistoryRow {
    /// History given (stroke cycles).
    pub history_cycles: f64,
    /// History given (samples).
    pub history_samples: usize,
    /// Pooled standardized RMSE on the held-out training trajectories (chosen settings).
    pub validation_rmse: f64,
    /// Whether the chosen length scales use the history (else the fit is the static one).
    pub history_used: bool,
    /// Test RMSE per output (σ units).
    pub test_rmse: Vec<f64>,
    /// Test RMSE of every output pooled (σ units).
    pub test_overall: f64,
    /// Per output, this history's test RMSE minus the static model's with its paired
    /// interval (empty for `h = 0`).
    pub versus_static: Vec<PairedDifference>,
}

/// One dataset's curve.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct HistoryCurve {
    /// The dataset's label (its file name).
    pub dataset: String,
    /// The training stroke cycle (samples).
    pub cycle_samples: usize,
    /// Test trajectories scored.
    pub n_test: usize,
    /// The rows, by history.
    pub rows: Vec<HistoryRow>,
    /// The history with the lowest held-out training error (stroke cycles; 0 when that fit
    /// ignores its history): the choice a user makes without the test set.
    pub best_by_validation_cycles: f64,
}

/// Every dataset's curve and the options.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct HistoryCurves {
    /// The options.
    pub options: HistoryOptions,
    /// One curve per dataset.
    pub curves: Vec<HistoryCurve>,
}

fn check(opts: &HistoryOptions) -> Result<()> {
    opts.gp.check()?;
    let bad = |name: &str, value: String, expected: &str| {
        Err(JobError::Setting {
            name: name.into(),
            value,
            expected: expected.into(),
        })
    };
    let h = &opts.history_cycles;
    if h.first() != Some(&0.0)
        || !h.windows(2).all(|w| w[0] < w[1])
        || !h.iter().all(|v| v.is_finite())
    {
        return bad(
            "history_cycles",
            format!("{h:?}"),
            "increasing finite values starting at 0",
        );
    }
    if opts.n_draws < 100 {
        return bad("n_draws", opts.n_draws.to_string(), "at least 100");
    }
    if !(opts.level > 0.0 && opts.level < 100.0) {
        return bad("level", opts.level.to_string(), "between 0 and 100 (%)");
    }
    Ok(())
}

/// Standardized test errors of `model` per test trajectory (row-major `n × 5` from
/// `start_sample`).
fn test_errors(model: &dyn LoadModel, ds: &ValidDataset, start: usize) -> Result<TrajectoryErrors> {
    let stats = ds.standardization()?;
    let tables = ds
        .test()
        .iter()
        .enumerate()
        .map(|(i, t)| {
            let n = t.inputs.len();
            let mut mean = vec![0.0; n * 5];
            model.predict_into(
                ds.n_train + i,
                t,
                LoadPrediction {
                    mean: &mut mean,
                    var: None,
                    latent_mean: None,
                },
            )?;
            let measured = t.outputs.as_deref().unwrap_or_default();
            Ok(measured
                .iter()
                .zip(mean.chunks_exact(5))
                .skip(start)
                .flat_map(|(y, p)| (0..5).map(move |j| (y[j] - p[j]) / stats.std_y[j]))
                .collect::<Vec<f64>>())
        })
        .collect::<Result<Vec<_>>>()?;
    TrajectoryErrors::of_tables(tables.iter().map(|t| &t[..]), 5)
        .map_err(analysis("history curve test errors"))
}

/// The history curve of `ds` (module docs).
///
/// # Errors
/// Bad options; a dataset without outputs, test trajectories or full training cycles, or
/// with `start_sample` beyond its length; the GP's errors.
pub fn history_curve_of(
    ds: &ValidDataset,
    label: &str,
    opts: &HistoryOptions,
    progress: &dyn Progress,
) -> Result<HistoryCurve> {
    check(opts)?;
    if !ds.has_outputs() {
        return Err(flapssm_wing::dataset::DatasetError::NoOutputs.into());
    }
    if ds.test().is_empty() {
        return Err(JobError::Mismatch {
            what: format!("{label}: test trajectories"),
            expected: "at least one".into(),
            found: "none".into(),
        });
    }
    if opts.start_sample >= ds.n_samples() {
        return Err(JobError::Mismatch {
            what: "start_sample".into(),
            expected: format!("fewer than the {} samples per trajectory", ds.n_samples()),
            found: opts.start_sample.to_string(),
        });
    }
    let cycle = cycle_samples(ds)?;
    let histories: Vec<usize> = opts
        .history_cycles
        .iter()
        .map(|c| (c * cycle as f64).round() as usize)
        .collect();
    let models = fit_histories(ds, &histories, &opts.gp, progress)?;
    let mut rows = Vec::new();
    let mut static_errors = None;
    for ((&c, &h), model) in opts.history_cycles.iter().zip(&histories).zip(&models) {
        let errors = test_errors(model, ds, opts.start_sample)?;
        let versus_static = match &static_errors {
            None => Vec::new(),
            Some(s) => paired_bootstrap(&errors, s, opts.n_draws, opts.level, opts.seed)
                .map_err(analysis(format!("{label}: history {h} against static")))?,
        };
        let rmse = errors.rmse();
        let overall = (rmse.iter().map(|r| r * r).sum::<f64>() / rmse.len() as f64).sqrt();
        rows.push(HistoryRow {
            history_cycles: c,
            history_samples: h,
            validation_rmse: model.candidates[0].validation_rmse,
            history_used: model.history_samples() > 0,
            test_rmse: rmse,
            test_overall: overall,
            versus_static,
        });
        if static_errors.is_none() {
            static_errors = Some(errors);
        }
    }
    // A fit whose chosen length scales ignore the history is the static model, whatever `h`.
    let best = rows
        .iter()
        .min_by(|a, b| a.validation_rmse.total_cmp(&b.validation_rmse))
        .map_or(0.0, |r| {
            if r.history_used {
                r.history_cycles
            } else {
                0.0
            }
        });
    Ok(HistoryCurve {
        dataset: label.into(),
        cycle_samples: cycle,
        n_test: ds.test().len(),
        rows,
        best_by_validation_cycles: best,
    })
}

/// `history_curve.csv`: one row per dataset and history.
pub fn curves_csv(curves: &HistoryCurves) -> String {
    let mut s = String::from("dataset,history_cycles,history_samples,validation_rmse_std");
    for o in OUTPUT_NAMES {
        s.push_str(&format!(",test_rmse_std_{o}"));
    }
    s.push_str(",test_overall_rmse_std");
    for o in OUTPUT_NAMES {
        s.push_str(&format!(",vs_static_{o},vs_static_lo_{o},vs_static_hi_{o}"));
    }
    s.push('\n');
    for c in &curves.curves {
        for r in &c.rows {
            s.push_str(&format!(
                "{},{},{},{}",
                c.dataset, r.history_cycles, r.history_samples, r.validation_rmse
            ));
            for v in &r.test_rmse {
                s.push_str(&format!(",{v}"));
            }
            s.push_str(&format!(",{}", r.test_overall));
            for j in 0..OUTPUT_NAMES.len() {
                match r.versus_static.get(j) {
                    Some(d) => s.push_str(&format!(
                        ",{},{},{}",
                        d.difference, d.interval.lo, d.interval.hi
                    )),
                    None => s.push_str(",,,"),
                }
            }
            s.push('\n');
        }
    }
    s
}

/// The history curve of each `(label, dataset)` into `out_dir` ([`HISTORY_FILES`]).
///
/// # Errors
/// As [`history_curve_of`]; I/O and plot errors naming the file.
pub fn run_history_curves(
    datasets: &[(String, ValidDataset)],
    opts: &HistoryOptions,
    out_dir: &Path,
    progress: &dyn Progress,
) -> Result<HistoryCurves> {
    check(opts)?;
    std::fs::create_dir_all(out_dir).map_err(|source| JobError::Io {
        path: out_dir.to_path_buf(),
        source,
    })?;
    let curves = HistoryCurves {
        options: opts.clone(),
        curves: datasets
            .iter()
            .map(|(label, ds)| history_curve_of(ds, label, opts, progress))
            .collect::<Result<_>>()?,
    };
    let points: Vec<Vec<HistoryPoint>> = curves
        .curves
        .iter()
        .map(|c| {
            c.rows
                .iter()
                .map(|r| HistoryPoint {
                    history_cycles: r.history_cycles,
                    test_rmse: r.test_rmse.clone(),
                    validation_rmse: r.validation_rmse,
                })
                .collect()
        })
        .collect();
    let panels: Vec<HistoryPanel<'_>> = curves
        .curves
        .iter()
        .zip(&points)
        .map(|(c, p)| HistoryPanel {
            title: &c.dataset,
            outputs: &OUTPUT_NAMES,
            points: p,
        })
        .collect();
    let png = out_dir.join(HISTORY_FILES[2]);
    history_curve(&png, &panels).map_err(analysis(png.display().to_string()))?;
    save_text(&out_dir.join(HISTORY_FILES[1]), &curves_csv(&curves))?;
    save_json(&out_dir.join(HISTORY_FILES[0]), &curves)?;
    Ok(curves)
}

#[cfg(test)]
mod tests {
    use super::*;
    use flapssm_wing::virtual_wing::{SimulationConfig, simulate_dataset};

    fn small_opts() -> HistoryOptions {
        HistoryOptions {
            history_cycles: vec![0.0, 0.25],
            n_draws: 500,
            start_sample: 20,
            gp: GpSettings {
                n_inducing: 96,
                n_inducing_choice: 64,
                fit_stride: 2,
                ..GpSettings::default()
            },
            ..HistoryOptions::default()
        }
    }

    /// `ds` (24 simulated trajectories, 18 for training) with its loads replaced by a nonlinear
    /// function of the inputs `lag` samples back, and its training cycle.
    fn remembering(lag_cycles: f64) -> (ValidDataset, usize) {
        let mut cfg = SimulationConfig::default();
        cfg.trajectories.n_trajectories = 24;
        cfg.trajectories.n_train = 18;
        cfg.trajectories.seed = 5;
        let mut ds = simulate_dataset(&cfg, &|| {}).unwrap().into_inner();
        let cycle = cycle_samples(&ValidDataset::new(ds.clone()).unwrap()).unwrap();
        let lag = (cycle as f64 * lag_cycles).round() as usize;
        for t in &mut ds.trajectories {
            let u = t.inputs.clone();
            for (i, y) in t.outputs.as_mut().unwrap().iter_mut().enumerate() {
                let p = u[i.saturating_sub(lag)];
                *y = [p[0].sin(), p[1] * p[1], p[5], p[2].tanh(), p[0] * p[1]];
            }
        }
        (ValidDataset::new(ds).unwrap(), lag)
    }

    /// A known answer: loads that are a nonlinear function of the inputs a quarter cycle back
    /// (≥ 8 samples), which the static model cannot see. Given a quarter cycle of history (a
    /// tap lands on it) the error falls significantly, to under half, on every output, and the
    /// held-out choice picks that history.
    #[test]
    fn history_helps_where_the_loads_remember() {
        let (ds, lag) = remembering(0.25);
        assert!(lag >= 8, "lag {lag}");
        let c = history_curve_of(&ds, "delayed", &small_opts(), &crate::NoProgress).unwrap();
        let (s, h) = (&c.rows[0], &c.rows[1]);
        assert_eq!(h.history_samples, lag);
        assert!(h.history_used);
        for (j, d) in h.versus_static.iter().enumerate() {
            assert!(d.significant && d.difference < 0.0, "output {j}: {d:?}");
            assert!(
                h.test_rmse[j] < 0.5 * s.test_rmse[j],
                "output {j}: {h:?} vs {s:?}"
            );
        }
        assert_eq!(c.best_by_validation_cycles, 0.25);
    }

    /// The negative control: loads of the instantaneous inputs. The history-given model may
    /// use the history only where held-out training data ask for it, so its test error stays
    /// within 10 % of the static model's on every output.
    #[test]
    fn history_does_not_hurt_where_the_loads_forget() {
        let (ds, _) = remembering(0.0);
        let c = history_curve_of(&ds, "instantaneous", &small_opts(), &crate::NoProgress).unwrap();
        let (s, h) = (&c.rows[0], &c.rows[1]);
        for j in 0..5 {
            assert!(
                h.test_rmse[j] < 1.1 * s.test_rmse[j],
                "output {j}: {h:?} vs {s:?}"
            );
        }
    }

    #[test]
    fn bad_options_are_named() {
        let mut o = small_opts();
        o.history_cycles = vec![0.25, 0.5];
        let e = check(&o).unwrap_err().to_string();
        assert!(e.contains("history_cycles"), "{e}");
    }
}
