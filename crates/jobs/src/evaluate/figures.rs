//! The evaluation's figures drawn from its tables: example choice, Fig. 3 and training curves.

use std::path::Path;

use flapssm_data::Dataset;
use flapssm_prssm::PrssmModel;
use flapssm_prssm::train::fit::training_record;

use flapssm_analysis::plots::{timeseries as pt, training};

use super::TrajectoryMetrics;
use super::prepared::Prepared;
use crate::error::{Result, analysis};

/// Up to `k` test trajectories (training ones when there is no test set), distinct families
/// first, in dataset order.
pub(super) fn example_trajectories(ds: &Dataset, k: usize) -> Vec<usize> {
    let n_train = ds.n_train.min(ds.len());
    let pool: Vec<usize> = if n_train < ds.len() {
        (n_train..ds.len()).collect()
    } else {
        (0..ds.len()).collect()
    };
    let mut chosen: Vec<usize> = Vec::new();
    for &i in &pool {
        if chosen.len() < k
            && !chosen
                .iter()
                .any(|&c| ds.trajectories[c].family == ds.trajectories[i].family)
        {
            chosen.push(i);
        }
    }
    for &i in &pool {
        if chosen.len() < k && !chosen.contains(&i) {
            chosen.push(i);
        }
    }
    chosen.sort_unstable();
    chosen
}

pub(super) fn example_title(ds: &Dataset, i: usize, m: &TrajectoryMetrics) -> String {
    let n_train = ds.n_train.min(ds.len());
    let name = if i >= n_train {
        format!("test #{}", i - n_train + 1)
    } else {
        format!("train #{}", i + 1)
    };
    format!("{name} ({})", m.family)
}

pub(super) fn draw_fig3(
    path: &Path,
    ds: &Dataset,
    prep: &[Prepared],
    examples: &[usize],
    labels: &[String],
) -> Result<()> {
    let n = ds.n_samples();
    struct Data {
        t: Vec<f64>,
        euler: Vec<[f64; 3]>,
        cols: [[Vec<f64>; 2]; 4],
        title: String,
    }
    let data: Vec<Data> = examples
        .iter()
        .zip(labels)
        .map(|(&i, label)| {
            let p = &prep[i];
            let range = p.window.range(n).map_err(analysis("Fig. 3 window"))?;
            let col = |v: &[f64], j: usize| range.clone().map(|k| v[k * 5 + j]).collect();
            let pair = |v: &[f64]| [col(v, 0), col(v, 1)];
            let rm = |v: &[f64], j: usize| -> f64 {
                let e: Vec<f64> = range
                    .clone()
                    .map(|k| p.measured_c[k * 5 + j] - v[k * 5 + j])
                    .collect();
                flapssm_analysis::metrics::rms(&e)
            };
            Ok(Data {
                t: (0..=p.window.duration)
                    .map(|k| k as f64 / p.window.duration as f64)
                    .collect(),
                euler: range
                    .clone()
                    .map(|k| ds.trajectories[i].euler_rad[k])
                    .collect(),
                cols: [
                    pair(&p.measured_c),
                    pair(&p.prssm_c),
                    pair(&p.prssm_std_c),
                    pair(&p.lrqsm_c),
                ],
                title: format!(
                    "{label}: RMSE C_Fx {:.2}/{:.2}",
                    rm(&p.prssm_c, 0),
                    rm(&p.lrqsm_c, 0)
                ),
            })
        })
        .collect::<Result<_>>()?;
    let models: Vec<[pt::CoefficientCurves<'_>; 2]> = data
        .iter()
        .map(|d| {
            [
                pt::CoefficientCurves {
                    label: "PR-SSM ±2σ",
                    cfx: &d.cols[1][0],
                    cfy: &d.cols[1][1],
                    cfx_std: Some(&d.cols[2][0]),
                    cfy_std: Some(&d.cols[2][1]),
                },
                pt::CoefficientCurves {
                    label: "LRQSM",
                    cfx: &d.cols[3][0],
                    cfy: &d.cols[3][1],
                    cfx_std: None,
                    cfy_std: None,
                },
            ]
        })
        .collect();
    let panels: Vec<pt::TrajectoryPanel<'_>> = data
        .iter()
        .zip(&models)
        .map(|(d, m)| pt::TrajectoryPanel {
            title: &d.title,
            t: &d.t,
            euler_rad: &d.euler,
            measured: pt::CoefficientCurves {
                label: "measured",
                cfx: &d.cols[0][0],
                cfy: &d.cols[0][1],
                cfx_std: None,
                cfy_std: None,
            },
            models: m,
        })
        .collect();
    let sketch = pt::ChordSketch {
        chord_deg: (ds.meta.wing.chord_m / ds.meta.wing.u_ref_radius_m).to_degrees(),
        pitch_axis_frac: ds.meta.wing.pitch_axis_frac,
        ..Default::default()
    };
    pt::time_histories(path, "t̂ (cycles)", &panels, &sketch).map_err(analysis("Fig. 3"))
}

/// Draws the training curves of a model fitted by the trainer; `false` when it has no history.
pub(super) fn draw_training(f_loss: &Path, f_rmse: &Path, model: &PrssmModel) -> Result<bool> {
    let Ok(rec) = training_record(model) else {
        return Ok(false);
    };
    if rec.history.is_empty() {
        return Ok(false);
    }
    let ep: Vec<f64> = rec.history.iter().map(|r| r.epoch as f64 + 1.0).collect();
    let loss: Vec<f64> = rec.history.iter().map(|r| r.mean_loss).collect();
    let log = loss.iter().all(|v| *v > 0.0);
    training::training_curves(
        f_loss,
        "PR-SSM training objective",
        "mean minibatch −ELBO",
        &[training::TrainingCurve {
            label: "−ELBO",
            epochs: &ep,
            values: &loss,
        }],
        log,
    )
    .map_err(analysis("training loss figure"))?;
    let series = |f: &dyn Fn(&flapssm_prssm::train::EpochRecord) -> Option<f64>| {
        let (e, v): (Vec<f64>, Vec<f64>) = rec
            .history
            .iter()
            .filter_map(|r| f(r).map(|v| (r.epoch as f64 + 1.0, v)))
            .unzip();
        (e, v)
    };
    let (et, vt) = series(&|r| r.train_rmse);
    let (ev, vv) = series(&|r| r.val_rmse);
    let mut curves = Vec::new();
    if !et.is_empty() {
        curves.push(training::TrainingCurve {
            label: "training RMSE",
            epochs: &et,
            values: &vt,
        });
    }
    if !ev.is_empty() {
        curves.push(training::TrainingCurve {
            label: "validation RMSE",
            epochs: &ev,
            values: &vv,
        });
    }
    if curves.is_empty() {
        return Ok(false);
    }
    training::training_curves(
        f_rmse,
        "PR-SSM open-loop RMSE during training",
        "RMSE (standardized, after burn-in)",
        &curves,
        false,
    )
    .map_err(analysis("training RMSE figure"))?;
    Ok(true)
}
