//! The evaluation's figures drawn from its tables: example choice, Fig. 3 and training curves.

use std::path::Path;

use flapssm_prssm::train::EpochRecord;
use flapssm_wing::dataset::Dataset;

use flapssm_analysis::plots::{timeseries as pt, training};

use super::TrajectoryMetrics;
use super::prepared::Prepared;
use crate::error::{Result, analysis};
use crate::models::LoadModel;

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

/// Fig. 3: for each example trajectory, the wing's last cycle and measured against each
/// model's C_Fx and C_Fy (with ±2σ bands for models with variances).
pub(super) fn draw_fig3(
    path: &Path,
    ds: &Dataset,
    models: &[&dyn LoadModel],
    prep: &[Prepared],
    examples: &[usize],
    labels: &[String],
) -> Result<()> {
    let n = ds.n_samples();
    /// A pair of [C_Fx, C_Fy] columns over the window.
    type Pair = [Vec<f64>; 2];
    struct Data {
        t: Vec<f64>,
        euler: Vec<[f64; 3]>,
        measured: Pair,
        models: Vec<(Pair, Option<Pair>)>,
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
            let rmse: Vec<String> = p
                .models
                .iter()
                .map(|m| format!("{:.2}", rm(&m.c, 0)))
                .collect();
            Ok(Data {
                t: (0..=p.window.duration)
                    .map(|k| k as f64 / p.window.duration as f64)
                    .collect(),
                euler: range
                    .clone()
                    .map(|k| ds.trajectories[i].euler_rad[k])
                    .collect(),
                measured: pair(&p.measured_c),
                models: p
                    .models
                    .iter()
                    .map(|m| (pair(&m.c), m.std_c.as_deref().map(pair)))
                    .collect(),
                title: format!("{label}: RMSE C_Fx {}", rmse.join("/")),
            })
        })
        .collect::<Result<_>>()?;
    let names: Vec<String> = models
        .iter()
        .map(|m| match m.has_variance() {
            true => format!("{} ±2σ", m.name()),
            false => m.name().to_string(),
        })
        .collect();
    let curves: Vec<Vec<pt::CoefficientCurves<'_>>> = data
        .iter()
        .map(|d| {
            d.models
                .iter()
                .zip(&names)
                .map(|((c, std), label)| pt::CoefficientCurves {
                    label,
                    cfx: &c[0],
                    cfy: &c[1],
                    cfx_std: std.as_ref().map(|s| &s[0][..]),
                    cfy_std: std.as_ref().map(|s| &s[1][..]),
                })
                .collect()
        })
        .collect();
    let panels: Vec<pt::TrajectoryPanel<'_>> = data
        .iter()
        .zip(&curves)
        .map(|(d, m)| pt::TrajectoryPanel {
            title: &d.title,
            t: &d.t,
            euler_rad: &d.euler,
            measured: pt::CoefficientCurves {
                label: "measured",
                cfx: &d.measured[0],
                cfy: &d.measured[1],
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

/// Draws the training curves of `name`'s per-epoch `history`; `false` when it is empty.
pub(super) fn draw_training(
    f_loss: &Path,
    f_rmse: &Path,
    name: &str,
    history: &[EpochRecord],
) -> Result<bool> {
    if history.is_empty() {
        return Ok(false);
    }
    let ep: Vec<f64> = history.iter().map(|r| r.epoch as f64 + 1.0).collect();
    let loss: Vec<f64> = history.iter().map(|r| r.mean_loss).collect();
    let log = loss.iter().all(|v| *v > 0.0);
    training::training_curves(
        f_loss,
        &format!("{name} training objective"),
        "mean minibatch −ELBO",
        &[training::TrainingCurve {
            label: "−ELBO",
            epochs: &ep,
            values: &loss,
        }],
        log,
    )
    .map_err(analysis("training loss figure"))?;
    let series = |f: &dyn Fn(&EpochRecord) -> Option<f64>| {
        let (e, v): (Vec<f64>, Vec<f64>) = history
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
        &format!("{name} open-loop RMSE during training"),
        "RMSE (standardized, after burn-in)",
        &curves,
        false,
    )
    .map_err(analysis("training RMSE figure"))?;
    Ok(true)
}
