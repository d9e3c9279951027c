//! Designs for achievable targets: the cycle-mean loads and the load histories of the paper's
//! held-out measured trajectories run through the plant, designed with the PR-SSM, the LRQSM
//! and the quasi-steady wing, each verified on the plant.
//!
//! A target is achievable by construction: the plant produced it. Its harmonic fit (the
//! kinematics family of a design, fitted to the trajectory's periodic part) run through the
//! plant gives the floor of the family ("fit floor"). Cycle-mean targets are thrust, lift,
//! side force and pitch moment ([`TARGETED`]; roll and yaw follow lift and thrust through the
//! span of the centre of pressure and are left free); the error of a design is the RMS over
//! them of (achieved − target) / scale, the scale being the SD of that cycle mean over the
//! training trajectories. A history design targets the plant's wing-frame loads sample by
//! sample over the window; its error is the RMS over samples and outputs in units of each
//! output's SD. Model differences are paired by target, with 95 % Student-t intervals.
//!
//! With the rig's stand-in ([`super::standin`]), every cycle-mean design is judged a second
//! time: its cycle means on the stand-in against the stand-in's own on the held-out trajectory
//! (a target the rig achieved), in the same units.

use std::path::Path;
use std::time::Instant;

use flapssm_analysis::stats::mean_t_interval;
use flapssm_design::{DesignGrid, Target};
use flapssm_prssm::PrssmModel;
use flapssm_qs::LrqsmModel;
use flapssm_wing::stroke_loads::{QUANTITY_NAMES, quantity};
use flapssm_wing::trajectories::paper::PAPER_N_TRAIN;
use serde::{Deserialize, Serialize};

use super::standin::RigStandIn;
use super::{
    DesignContext, DesignSettings, ModelChoice, PLANT_STREAM, design_error, design_with, verify,
};
use crate::error::{JobError, Result};
use crate::files::{save_json, save_text};
use crate::progress::Progress;
use crate::seed::derive_seed;

/// The cycle means a study targets.
pub const TARGETED: [usize; 4] = [
    quantity::THRUST,
    quantity::LIFT,
    quantity::SIDE,
    quantity::PITCH,
];

/// Files of [`write_study`].
pub const STUDY_FILES: [&str; 2] = ["design-study.json", "design-study.md"];

/// One model's designs for one target.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct ModelResult {
    /// The design model.
    pub model: String,
    /// Predicted cycle means (7).
    pub predicted: [f64; 7],
    /// Predictive SD of the cycle means (PR-SSM).
    pub predicted_sd: Option<[f64; 7]>,
    /// The plant's cycle means (7).
    pub achieved: [f64; 7],
    /// Error of the cycle-mean design (module docs).
    pub cycle_error: f64,
    /// Targeted cycle means inside the predicted 95 % band (PR-SSM).
    pub inside_band: Option<usize>,
    /// Error of the history design.
    pub history_error: Option<f64>,
    /// Share of the history design's plant samples inside its predicted 95 % band (PR-SSM).
    pub history_band_share: Option<f64>,
    /// The cycle-mean design's cycle means on the rig's stand-in (7).
    pub rig_achieved: Option<[f64; 7]>,
    /// Their error against the stand-in's target (module docs).
    pub rig_cycle_error: Option<f64>,
    /// The designs' limit excess, if any.
    pub limit_excess: Option<String>,
    /// Wall time of both designs (s).
    pub wall_s: f64,
}

/// One target.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct TargetResult {
    /// The measured trajectory.
    pub index: usize,
    /// Its frequency (the designs') (Hz).
    pub frequency_hz: f64,
    /// The plant's cycle means over the window (7).
    pub target: [f64; 7],
    /// The error of the trajectory's own harmonic fit on the plant (cycle means; history).
    pub fit_floor: [f64; 2],
    /// The rig stand-in's cycle means on the measured trajectory (7).
    pub rig_target: Option<[f64; 7]>,
    /// The error of the trajectory's own fit on the stand-in.
    pub rig_fit_floor: Option<f64>,
    /// Per model.
    pub models: Vec<ModelResult>,
}

/// A mean with its 95 % interval.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct MeanInterval {
    /// What.
    pub what: String,
    /// Mean.
    pub mean: f64,
    /// 95 % lower bound.
    pub lo: f64,
    /// 95 % upper bound.
    pub hi: f64,
}

/// The study.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct StudyReport {
    /// Settings.
    pub settings: DesignSettings,
    /// Names of the targeted cycle means.
    pub targeted: Vec<String>,
    /// Scales of the 7 quantities.
    pub quantity_scales: [f64; 7],
    /// Per target.
    pub targets: Vec<TargetResult>,
    /// Mean error per model and kind, with its interval.
    pub errors: Vec<MeanInterval>,
    /// Paired differences PR-SSM − other, per kind.
    pub paired: Vec<MeanInterval>,
    /// Share of targeted PR-SSM cycle means inside its 95 % band.
    pub cycle_band_share: Option<f64>,
    /// Share of PR-SSM history samples inside its 95 % band.
    pub history_band_share: Option<f64>,
    /// Wall time (s).
    pub wall_s: f64,
}

fn interval(what: String, v: &[f64]) -> Option<MeanInterval> {
    let (mean, i) = mean_t_interval(v)?;
    Some(MeanInterval {
        what,
        mean,
        lo: i.lo,
        hi: i.hi,
    })
}

fn cycle_error(achieved: &[f64; 7], target: &[f64; 7], scales: &[f64; 7]) -> f64 {
    let s: f64 = TARGETED
        .iter()
        .map(|&i| ((achieved[i] - target[i]) / scales[i]).powi(2))
        .sum();
    (s / TARGETED.len() as f64).sqrt()
}

fn history_error(achieved: &[[f64; 5]], target: &[[f64; 5]], scales: &[f64; 5]) -> f64 {
    let mut s = 0.0;
    for (a, t) in achieved.iter().zip(target) {
        for k in 0..5 {
            s += ((a[k] - t[k]) / scales[k]).powi(2);
        }
    }
    (s / (5 * achieved.len()).max(1) as f64).sqrt()
}

/// The models of a study and its second judge.
pub struct StudyModels<'a> {
    /// The PR-SSM.
    pub prssm: &'a PrssmModel,
    /// The LRQSM, when given.
    pub lrqsm: Option<&'a LrqsmModel>,
    /// The rig's stand-in, when given.
    pub rig: Option<&'a RigStandIn>,
}

/// Runs the study on the first `n_targets` of the 36 held-out trajectories with the PR-SSM,
/// the LRQSM (when given) and the quasi-steady wing; with `histories`, also a history design
/// per model and target; with the rig's stand-in, every cycle-mean design judged on it too.
/// `progress.advance(1)` per target.
///
/// # Errors
/// [`JobError::Setting`] for `n_targets` outside 2..=36 and bad settings; design and plant
/// errors.
pub fn study(
    ctx: &DesignContext,
    models: &StudyModels<'_>,
    n_targets: usize,
    histories: bool,
    settings: &DesignSettings,
    progress: &dyn Progress,
) -> Result<StudyReport> {
    settings.check()?;
    let held_out = ctx.cases.len() - PAPER_N_TRAIN;
    if n_targets < 2 || n_targets > held_out {
        return Err(JobError::Setting {
            name: "targets".into(),
            value: n_targets.to_string(),
            expected: format!("2..={held_out} (the held-out measured trajectories)"),
        });
    }
    let start = Instant::now();
    let rig = models.rig;
    let mut choices = vec![ModelChoice::Prssm(models.prssm)];
    if let Some(l) = models.lrqsm {
        choices.push(ModelChoice::Lrqsm(l));
    }
    choices.push(ModelChoice::QuasiSteady);
    let grid = DesignGrid::paper();
    let r_s = ctx.wing.sensor_radius_m;
    progress.start("designs for held-out targets", n_targets as u64);
    let mut targets = Vec::with_capacity(n_targets);
    for case in &ctx.cases[PAPER_N_TRAIN..PAPER_N_TRAIN + n_targets] {
        let f = case.frequency_hz;
        let window = grid.window(f, ctx.ramp_cycles).map_err(design_error)?;
        let target = case.cycle_means(window.clone(), r_s);
        let history: Vec<[f64; 5]> = case.outputs[window.clone()].to_vec();
        let mut values = [None; 6];
        for i in TARGETED {
            values[i] = Some(target[i]);
        }
        let plant_seed = derive_seed(settings.seed, PLANT_STREAM, case.index as u64);
        let floor = verify(ctx, &case.fit, window.clone(), plant_seed)?;
        let fit_floor = [
            cycle_error(&floor.cycle_means, &target, &ctx.quantity_scales),
            history_error(&floor.outputs, &history, &ctx.output_scales),
        ];
        let grid_states = |k: &flapssm_wing::trajectories::harmonic::HarmonicKinematics| {
            let mut st = vec![flapssm_wing::kinematics::EulerState::default(); grid.n_samples];
            k.sample_into(grid.dt_s, &mut st);
            st
        };
        let rig_target = rig
            .map(|r| r.cycle_means(&case.states, window.clone(), r_s))
            .transpose()?;
        let rig_fit_floor = match (rig, &rig_target) {
            (Some(r), Some(t)) => {
                let got = r.cycle_means(&grid_states(&case.fit), window.clone(), r_s)?;
                Some(cycle_error(&got, t, &ctx.quantity_scales))
            }
            _ => None,
        };
        let starts = ctx.starts(&values, settings.starts, None);
        let mut results = Vec::new();
        for m in &choices {
            let t0 = Instant::now();
            let cm = Target::CycleMeans { values };
            let p = ctx.problem(cm, f, settings, 0.0);
            let d = design_with(m, &p, &starts, settings)?;
            let got = verify(ctx, &d.kinematics, window.clone(), plant_seed)?;
            let inside_band = d.cycle_mean_sd.map(|sd| {
                TARGETED
                    .iter()
                    .filter(|&&i| {
                        (got.cycle_means[i] - d.evaluation.cycle_means[i]).abs() <= 1.96 * sd[i]
                    })
                    .count()
            });
            let mut r = ModelResult {
                model: m.name().into(),
                predicted: d.evaluation.cycle_means,
                predicted_sd: d.cycle_mean_sd,
                achieved: got.cycle_means,
                cycle_error: cycle_error(&got.cycle_means, &target, &ctx.quantity_scales),
                inside_band,
                history_error: None,
                history_band_share: None,
                rig_achieved: None,
                rig_cycle_error: None,
                limit_excess: d.limit_excess.clone(),
                wall_s: 0.0,
            };
            if let (Some(rig), Some(t)) = (rig, &rig_target) {
                let got = rig.cycle_means(&grid_states(&d.kinematics), window.clone(), r_s)?;
                r.rig_cycle_error = Some(cycle_error(&got, t, &ctx.quantity_scales));
                r.rig_achieved = Some(got);
            }
            if histories {
                let ht = Target::History {
                    outputs: history.clone(),
                };
                let p = ctx.problem(ht, f, settings, 0.0);
                let d = design_with(m, &p, &starts, settings)?;
                let got = verify(ctx, &d.kinematics, window.clone(), plant_seed)?;
                r.history_error = Some(history_error(&got.outputs, &history, &ctx.output_scales));
                if matches!(m, ModelChoice::Prssm(_)) {
                    let rows = got
                        .outputs
                        .iter()
                        .zip(&d.predicted_mean)
                        .zip(&d.predicted_var);
                    let inside: usize = rows
                        .map(|((a, m), v)| {
                            (0..5)
                                .filter(|&k| (a[k] - m[k]).abs() <= 1.96 * v[k].sqrt())
                                .count()
                        })
                        .sum();
                    r.history_band_share = Some(inside as f64 / (5 * got.outputs.len()) as f64);
                }
                if r.limit_excess.is_none() {
                    r.limit_excess = d.limit_excess;
                }
            }
            r.wall_s = t0.elapsed().as_secs_f64();
            results.push(r);
        }
        targets.push(TargetResult {
            index: case.index,
            frequency_hz: f,
            target,
            fit_floor,
            rig_target,
            rig_fit_floor,
            models: results,
        });
        progress.advance(1);
    }
    progress.finish("");
    Ok(summarize(
        ctx,
        settings,
        targets,
        start.elapsed().as_secs_f64(),
    ))
}

fn summarize(
    ctx: &DesignContext,
    settings: &DesignSettings,
    targets: Vec<TargetResult>,
    wall_s: f64,
) -> StudyReport {
    let names: Vec<String> = targets[0].models.iter().map(|m| m.model.clone()).collect();
    let col = |j: usize, hist: bool| -> Vec<f64> {
        targets
            .iter()
            .filter_map(|t| {
                let m = &t.models[j];
                if hist {
                    m.history_error
                } else {
                    Some(m.cycle_error)
                }
            })
            .collect()
    };
    let mut errors = Vec::new();
    let mut paired = Vec::new();
    for (kind, hist) in [("cycle means", false), ("history", true)] {
        let floor: Vec<f64> = targets
            .iter()
            .map(|t| t.fit_floor[usize::from(hist)])
            .collect();
        if hist && col(0, true).is_empty() {
            continue;
        }
        errors.extend(interval(format!("fit floor, {kind}"), &floor));
        for (j, n) in names.iter().enumerate() {
            errors.extend(interval(format!("{n}, {kind}"), &col(j, hist)));
        }
        let base = col(0, hist);
        for (j, n) in names.iter().enumerate().skip(1) {
            let d: Vec<f64> = base.iter().zip(col(j, hist)).map(|(a, b)| a - b).collect();
            paired.extend(interval(format!("{} − {n}, {kind}", names[0]), &d));
        }
    }
    let rig_col = |j: usize| -> Vec<f64> {
        targets
            .iter()
            .filter_map(|t| t.models[j].rig_cycle_error)
            .collect()
    };
    if !rig_col(0).is_empty() {
        let kind = "cycle means on the rig stand-in";
        let floor: Vec<f64> = targets.iter().filter_map(|t| t.rig_fit_floor).collect();
        errors.extend(interval(format!("fit floor, {kind}"), &floor));
        for (j, n) in names.iter().enumerate() {
            errors.extend(interval(format!("{n}, {kind}"), &rig_col(j)));
        }
        let base = rig_col(0);
        for (j, n) in names.iter().enumerate().skip(1) {
            let d: Vec<f64> = base.iter().zip(rig_col(j)).map(|(a, b)| a - b).collect();
            paired.extend(interval(format!("{} − {n}, {kind}", names[0]), &d));
        }
    }
    let (inside, total) = targets
        .iter()
        .filter_map(|t| t.models[0].inside_band)
        .fold((0, 0), |(a, b), v| (a + v, b + TARGETED.len()));
    let hist_share: Vec<f64> = targets
        .iter()
        .filter_map(|t| t.models[0].history_band_share)
        .collect();
    StudyReport {
        settings: *settings,
        targeted: TARGETED
            .iter()
            .map(|&i| QUANTITY_NAMES[i].to_string())
            .collect(),
        quantity_scales: ctx.quantity_scales,
        cycle_band_share: (total > 0).then(|| inside as f64 / total as f64),
        history_band_share: (!hist_share.is_empty())
            .then(|| hist_share.iter().sum::<f64>() / hist_share.len() as f64),
        targets,
        errors,
        paired,
        wall_s,
    }
}

impl std::fmt::Display for StudyReport {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        writeln!(
            f,
            "{} held-out targets (cycle means of {}; errors in SDs of the training set's cycle \
             means / outputs), each design verified on the plant",
            self.targets.len(),
            self.targeted.join(", ")
        )?;
        writeln!(f, "\n| error | mean | 95 % interval |\n|---|---|---|")?;
        for e in &self.errors {
            writeln!(
                f,
                "| {} | {:.3} | [{:.3}, {:.3}] |",
                e.what, e.mean, e.lo, e.hi
            )?;
        }
        writeln!(
            f,
            "\n| paired difference | mean | 95 % interval |\n|---|---|---|"
        )?;
        for e in &self.paired {
            writeln!(
                f,
                "| {} | {:+.3} | [{:+.3}, {:+.3}] |",
                e.what, e.mean, e.lo, e.hi
            )?;
        }
        if let Some(s) = self.cycle_band_share {
            writeln!(
                f,
                "\nPR-SSM band: {:.1} % of the targeted cycle means achieved inside the predicted 95 % band",
                100.0 * s
            )?;
        }
        if let Some(s) = self.history_band_share {
            writeln!(
                f,
                "PR-SSM band: {:.1} % of the history designs' plant samples inside the predicted 95 % band",
                100.0 * s
            )?;
        }
        writeln!(f, "\nwall {:.1} s", self.wall_s)
    }
}

/// Writes [`STUDY_FILES`] into `dir` (atomic).
///
/// # Errors
/// I/O errors naming the file.
pub fn write_study(report: &StudyReport, dir: &Path) -> Result<()> {
    std::fs::create_dir_all(dir).map_err(|source| JobError::Io {
        path: dir.to_path_buf(),
        source,
    })?;
    save_json(&dir.join(STUDY_FILES[0]), report)?;
    save_text(&dir.join(STUDY_FILES[1]), &report.to_string())
}
