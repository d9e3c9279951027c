//! The evaluation's figures drawn from its tables: example choice, Figs. 2C–5 and the training
//! curves, and the list of what was drawn for the report.

use std::path::{Path, PathBuf};

use flapssm_prssm::train::EpochRecord;
use flapssm_wing::dataset::{Dataset, OUTPUT_NAMES, ValidDataset};

use flapssm_analysis::metrics::Histogram;
use flapssm_analysis::plots::{authority as pa, errors as pe, timeseries as pt, training, wing3d};

use super::authority::Authority;
use super::paper::FIG3_TEST_NUMBERS;
use super::prepared::{Prepared, cycle_errors, pooled};
use super::report::{COEFFICIENT_LABELS, EvalOptions, TrajectoryMetrics};
use super::scores::Sets;
use crate::error::{Result, analysis};
use crate::models::LoadModel;

/// The figures an evaluation drew, for the report.
pub(super) struct ReportFigures {
    pub(super) f_2c: PathBuf,
    pub(super) f_3: PathBuf,
    pub(super) f_4a_train: Option<PathBuf>,
    pub(super) f_4a_test: Option<PathBuf>,
    pub(super) f_4b: PathBuf,
    /// Fig. 5Ai, 5Aii, 5B, with a latent-state model.
    pub(super) fig5: Option<(PathBuf, PathBuf, PathBuf)>,
    /// Training loss and RMSE, with a training history.
    pub(super) training: Option<(PathBuf, PathBuf)>,
}

impl ReportFigures {
    /// Whether the file named `name` was written (the training curves are named before it is
    /// known whether the history has any).
    pub(super) fn written(&self, name: &str) -> bool {
        !name.starts_with("training_") || self.training.is_some()
    }
}

/// The examples of Fig. 3: on the paper's own trajectories (its 512 / 36 split, the angles of
/// its six example test trajectories found from sample 93 on) the paper's six in its order, as
/// many as `k` allows; else up to `k` test trajectories (training ones when there is no test
/// set), distinct families first, in dataset order.
pub(super) fn example_trajectories(ds: &Dataset, k: usize) -> Vec<usize> {
    if let Some(paper) = paper_examples(ds) {
        return paper.into_iter().take(k).collect();
    }
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

/// Largest difference (rad) between a dataset's angles and the paper's for the same trajectory.
const SAME_ANGLE_RAD: f64 = 3.5e-3;

/// The paper's six example test trajectories as dataset indices, when `ds` holds the paper's
/// trajectories in the paper's split.
fn paper_examples(ds: &Dataset) -> Option<Vec<usize>> {
    use flapssm_wing::trajectories::paper::{PAPER_N_TRAIN, PAPER_N_TRAJECTORIES, paper_angles};
    if ds.len() != PAPER_N_TRAJECTORIES || ds.n_train != PAPER_N_TRAIN {
        return None;
    }
    let angles = paper_angles(PAPER_N_TRAJECTORIES);
    let s0 = flapssm_analysis::metrics::PUBLISHED_START_SAMPLE;
    let examples: Vec<usize> = FIG3_TEST_NUMBERS
        .iter()
        .map(|n| PAPER_N_TRAIN + n - 1)
        .collect();
    // The dataset holds the angles as smoothed for differentiation (Savitzky–Golay): measured
    // within 0.05° of the file's on the six; distinct trajectories differ by degrees.
    let same = |i: usize| {
        let (a, b) = (&ds.trajectories[i].euler_rad, &angles[i]);
        a.len() == b.len()
            && a[s0..]
                .iter()
                .zip(&b[s0..])
                .all(|(x, y)| x.iter().zip(y).all(|(p, q)| (p - q).abs() < SAME_ANGLE_RAD))
    };
    examples.iter().all(|&i| same(i)).then_some(examples)
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

/// Draws every figure; `file` names (and records) each file.
#[allow(clippy::too_many_arguments)]
pub(super) fn draw_figures(
    ds: &ValidDataset,
    models: &[&dyn LoadModel],
    prep: &[Prepared],
    sets: &Sets<'_>,
    trajectories: &[TrajectoryMetrics],
    authority: Option<&Authority>,
    opts: &EvalOptions,
    examples: &[usize],
    file: &mut dyn FnMut(&str) -> PathBuf,
) -> Result<ReportFigures> {
    let n = ds.n_samples();
    let wing = &ds.meta.wing;
    let labels: Vec<String> = examples
        .iter()
        .map(|&i| example_title(ds, i, &trajectories[i]))
        .collect();
    let f_2c = file("fig2c_wing_motion.png");
    let paths: Vec<wing3d::WingPath<'_>> = examples
        .iter()
        .zip(&labels)
        .map(|(&i, l)| wing3d::WingPath {
            label: l,
            euler_rad: &ds.trajectories[i].euler_rad[prep[i].window.range(n).unwrap_or(0..=0)],
        })
        .collect();
    let geom = wing3d::WingSketchGeometry {
        r_m: wing.u_ref_radius_m,
        chord_m: wing.chord_m,
        pitch_axis_frac: wing.pitch_axis_frac,
        ..Default::default()
    };
    wing3d::wing_motion_3d(&f_2c, &paths, &geom).map_err(analysis("Fig. 2C"))?;
    let f_3 = file("fig3_time_histories.png");
    draw_fig3(&f_3, ds, models, prep, examples, &labels)?;

    let edges = Histogram::uniform_edges(-1.1, 1.1, 0.01);
    let out_names = OUTPUT_NAMES
        .iter()
        .map(|s| format!("{s}/σ"))
        .collect::<Vec<_>>();
    let out_refs: Vec<&str> = out_names.iter().map(String::as_str).collect();
    let mut f_4a = Vec::new();
    for (set, label) in [(&sets.train, "train"), (&sets.test, "test")] {
        if set.is_empty() {
            continue;
        }
        let path = file(&format!("fig4a_histograms_{label}.png"));
        let errors = (0..models.len())
            .map(|k| pooled(set, k, opts.start_sample))
            .collect::<Result<Vec<_>>>()?;
        let labels: Vec<String> = models
            .iter()
            .map(|m| format!("{} {label}", m.name()))
            .collect();
        let series: Vec<pe::ModelErrors<'_>> = labels
            .iter()
            .zip(&errors)
            .map(|(l, e)| pe::ModelErrors {
                label: l,
                errors: &e.errors,
            })
            .collect();
        pe::error_histograms(&path, &out_refs, &series, &edges, opts.level)
            .map_err(analysis("Fig. 4A"))?;
        f_4a.push(path);
    }
    let f_4b = file("fig4b_cycle_averages.png");
    let cycles = (0..models.len())
        .map(|k| cycle_errors(&sets.all, k))
        .collect::<Result<Vec<_>>>()?;
    let series: Vec<pe::ModelCycleAverages<'_>> = models
        .iter()
        .zip(&cycles)
        .map(|(m, c)| pe::ModelCycleAverages {
            label: m.name(),
            observed: &c.observed,
            error: &c.error,
        })
        .collect();
    pe::cycle_average_scatter(
        &f_4b,
        &COEFFICIENT_LABELS,
        &series,
        Some(&[0.75, 0.75, 2.0, 2.0, 2.0]),
        opts.level,
    )
    .map_err(analysis("Fig. 4B"))?;
    let fig5 = match authority {
        Some(a) => {
            let (f_5a, f_5s, f_5b) = (
                file("fig5a_hdr.png"),
                file("fig5a_scatter_x1.png"),
                file("fig5b_summary.png"),
            );
            pa::hdr_contours(&f_5a, &a.summary).map_err(analysis("Fig. 5Ai"))?;
            pa::pair_scatter(&f_5s, &a.table, &a.summary, 0).map_err(analysis("Fig. 5Aii"))?;
            pa::summary_grid(&f_5b, &a.summary).map_err(analysis("Fig. 5B"))?;
            Some((f_5a, f_5s, f_5b))
        }
        None => None,
    };
    let training = models
        .iter()
        .find_map(|m| m.training_history().map(|h| (m.name(), h)));
    let training = match training {
        Some((name, history)) => {
            let (f_loss, f_rmse) = (file("training_loss.png"), file("training_rmse.png"));
            draw_training(&f_loss, &f_rmse, name, history)?.then_some((f_loss, f_rmse))
        }
        None => None,
    };
    Ok(ReportFigures {
        f_2c,
        f_3,
        f_4a_train: f_4a.first().cloned(),
        f_4a_test: f_4a.get(1).cloned(),
        f_4b,
        fig5,
        training,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::progress::NoProgress;
    use flapssm_wing::virtual_wing::SimulationConfig;

    /// On the paper's trajectories the examples are the paper's six test trajectories in its
    /// order; one changed angle and the dataset is no longer the paper's.
    #[test]
    fn the_paper_set_gets_the_papers_examples() {
        let mut cfg = SimulationConfig::default();
        cfg.wing.fidelity = flapssm_wing::virtual_wing::Fidelity::L0;
        cfg.trajectories.n_trajectories = 548;
        cfg.trajectories.n_train = 512;
        let mut ds = crate::simulate::paper_dataset(&cfg, None, &NoProgress)
            .unwrap()
            .into_inner();
        assert_eq!(example_trajectories(&ds, 6), [537, 525, 524, 544, 516, 543]);
        assert_eq!(example_trajectories(&ds, 2), [537, 525]);
        ds.trajectories[537].euler_rad[200][0] += 0.05;
        let fallback = example_trajectories(&ds, 6);
        assert_eq!(fallback.len(), 6);
        assert!(fallback.iter().all(|&i| i >= 512) && fallback.windows(2).all(|w| w[0] < w[1]));
    }
}
