//! Designs for given cycle means — hover (a weight held with zero mean thrust and pitch
//! moment) at least aerodynamic power the common case — with each model asked, every design
//! verified on the plant.

use std::path::Path;
use std::time::Instant;

use flapssm_design::{Design, DesignGrid, Target};
use flapssm_wing::stroke_loads::{QUANTITY_NAMES, quantity, stroke_frame_loads};
use serde::{Deserialize, Serialize};

use super::{
    DesignContext, DesignSettings, ModelChoice, PLANT_STREAM, design_error, design_with, verify,
};
use crate::error::{JobError, Result};
use crate::files::{save_json, save_text};
use crate::progress::Progress;
use crate::seed::derive_seed;

/// Files of [`write_cycle_design`].
pub const DESIGN_FILES: [&str; 3] = ["design.json", "design.md", "design.png"];

/// One model's design and what the plant did with it.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct VerifiedDesign {
    /// The design (kinematics, prediction, convergence).
    pub design: Design,
    /// The plant's cycle means (7).
    pub achieved: [f64; 7],
    /// The plant's wing-frame loads over the window.
    pub achieved_outputs: Vec<[f64; 5]>,
    /// Wall time of the design (s).
    pub wall_s: f64,
}

/// Designs for cycle means.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct CycleDesignReport {
    /// The targets (`None` free) of `[thrust, lift, side, roll, yaw, pitch]`.
    pub target: [Option<f64>; 6],
    /// Weight of the mean power.
    pub power_weight: f64,
    /// Frequency (Hz).
    pub frequency_hz: f64,
    /// The window (samples).
    pub window: [usize; 2],
    /// Settings.
    pub settings: DesignSettings,
    /// The sensor's distance from the stroke axis (m; the stroke-frame moments are about the
    /// stroke axis).
    pub sensor_radius_m: f64,
    /// Per model.
    pub designs: Vec<VerifiedDesign>,
}

/// The training trajectories' median frequency (Hz), the default of a design.
pub fn median_frequency(ctx: &DesignContext) -> f64 {
    let mut f: Vec<f64> = ctx.cases[..flapssm_wing::trajectories::paper::PAPER_N_TRAIN]
        .iter()
        .map(|c| c.frequency_hz)
        .collect();
    f.sort_by(f64::total_cmp);
    f[f.len() / 2]
}

/// Designs for `target` at `frequency_hz` with each of `models`, minimizing also
/// `power_weight × P̄ / σ_P`; `progress.advance(1)` per model.
///
/// # Errors
/// [`JobError::Setting`] naming a bad target (not finite, unreachable), frequency or setting.
pub fn cycle_design(
    ctx: &DesignContext,
    models: &[ModelChoice<'_>],
    target: [Option<f64>; 6],
    frequency_hz: f64,
    power_weight: f64,
    settings: &DesignSettings,
    progress: &dyn Progress,
) -> Result<CycleDesignReport> {
    settings.check()?;
    let problem = ctx.problem(
        Target::CycleMeans { values: target },
        frequency_hz,
        settings,
        power_weight,
    );
    let window = problem.check().map_err(design_error)?;
    let starts = ctx.starts(&target, settings.starts, None);
    let seed = derive_seed(settings.seed, PLANT_STREAM, u64::MAX);
    progress.start("designs", models.len() as u64);
    let mut designs = Vec::new();
    for m in models {
        let t0 = Instant::now();
        let design = design_with(m, &problem, &starts, settings)?;
        let wall_s = t0.elapsed().as_secs_f64();
        let got = verify(ctx, &design.kinematics, window.clone(), seed)?;
        designs.push(VerifiedDesign {
            design,
            achieved: got.cycle_means,
            achieved_outputs: got.outputs,
            wall_s,
        });
        progress.advance(1);
    }
    progress.finish("");
    Ok(CycleDesignReport {
        target,
        power_weight,
        frequency_hz,
        window: [window.start, window.end],
        settings: *settings,
        sensor_radius_m: ctx.wing.sensor_radius_m,
        designs,
    })
}

/// Hover for `weight_n` (N, carried by this wing): mean lift = weight, zero mean thrust and
/// pitch moment, at least power (`power_weight`).
///
/// # Errors
/// As [`cycle_design`]; a weight that is not finite and > 0 (`weight_n`).
pub fn hover(
    ctx: &DesignContext,
    models: &[ModelChoice<'_>],
    weight_n: f64,
    frequency_hz: f64,
    power_weight: f64,
    settings: &DesignSettings,
    progress: &dyn Progress,
) -> Result<CycleDesignReport> {
    if !(weight_n > 0.0 && weight_n.is_finite()) {
        return Err(JobError::Setting {
            name: "weight_n".into(),
            value: weight_n.to_string(),
            expected: "finite and > 0 (N)".into(),
        });
    }
    let mut target = [None; 6];
    target[quantity::LIFT] = Some(weight_n);
    target[quantity::THRUST] = Some(0.0);
    target[quantity::PITCH] = Some(0.0);
    cycle_design(
        ctx,
        models,
        target,
        frequency_hz,
        power_weight,
        settings,
        progress,
    )
}

impl std::fmt::Display for CycleDesignReport {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        writeln!(
            f,
            "target at {:.4} Hz over samples {}..{} (power weight {}):",
            self.frequency_hz, self.window[0], self.window[1], self.power_weight
        )?;
        write!(f, "\n| quantity | target |")?;
        for d in &self.designs {
            write!(
                f,
                " {} predicted | {} on the wing |",
                d.design.model, d.design.model
            )?;
        }
        write!(f, "\n|---|---|")?;
        for _ in &self.designs {
            write!(f, "---|---|")?;
        }
        writeln!(f)?;
        for (i, name) in QUANTITY_NAMES.iter().enumerate() {
            let t = self.target.get(i).copied().flatten();
            write!(
                f,
                "| {name} | {} |",
                t.map_or("free".into(), |v| format!("{v:.4}"))
            )?;
            for d in &self.designs {
                let p = d.design.evaluation.cycle_means[i];
                match d.design.cycle_mean_sd {
                    Some(sd) => write!(f, " {p:.4} ± {:.4} |", 1.96 * sd[i])?,
                    None => write!(f, " {p:.4} |")?,
                }
                write!(f, " {:.4} |", d.achieved[i])?;
            }
            writeln!(f)?;
        }
        for d in &self.designs {
            writeln!(
                f,
                "\n{}: J {:.4} (fit {:.4}, robust {:.4}, power {:.4}, limits {:.2e}), start {} of {}, {} evaluations, {:.1} s{}",
                d.design.model,
                d.design.evaluation.value,
                d.design.evaluation.fit,
                d.design.evaluation.robust,
                d.design.evaluation.power,
                d.design.evaluation.penalty,
                d.design.start + 1,
                d.design.start_values.len(),
                d.design.evaluations,
                d.wall_s,
                d.design
                    .limit_excess
                    .as_ref()
                    .map_or(String::new(), |e| format!("; over a limit: {e}"))
            )?;
        }
        Ok(())
    }
}

/// Writes [`DESIGN_FILES`] into `dir` (atomic).
///
/// # Errors
/// I/O errors naming the file.
pub fn write_cycle_design(report: &CycleDesignReport, dir: &Path) -> Result<()> {
    std::fs::create_dir_all(dir).map_err(|source| JobError::Io {
        path: dir.to_path_buf(),
        source,
    })?;
    save_json(&dir.join(DESIGN_FILES[0]), report)?;
    save_text(&dir.join(DESIGN_FILES[1]), &report.to_string())?;
    design_figure(report, &dir.join(DESIGN_FILES[2]))
}

/// The figure of a report: each design's stroke, deviation and pitch over its last cycle,
/// its lift over the window on the wing (the PR-SSM's predicted mean and 95 % band beside
/// it), and the objective at every iteration of the winning start.
fn design_figure(report: &CycleDesignReport, path: &Path) -> Result<()> {
    use flapssm_analysis::plots::design::{Curve, Panel, panels};
    use flapssm_wing::stroke_loads::stroke_frame_jacobian;
    let grid = DesignGrid::paper();
    let [w0, w1] = report.window;
    let f = report.frequency_hz;
    let per_cycle = (1.0 / (f * grid.dt_s)).round() as usize;
    let mut angle_curves: Vec<[Vec<f64>; 3]> = Vec::new();
    // Per design: the lift on the wing, and the PR-SSM's predicted lift with its band.
    type Lifts = (Vec<f64>, Option<[Vec<f64>; 3]>);
    let mut lifts: Vec<Lifts> = Vec::new();
    let t_cycle: Vec<f64> = (0..per_cycle)
        .map(|k| k as f64 / per_cycle as f64)
        .collect();
    let t_window: Vec<f64> = (w0..w1).map(|k| k as f64 * grid.dt_s).collect();
    for d in &report.designs {
        let mut states = vec![flapssm_wing::kinematics::EulerState::default(); grid.n_samples];
        d.design.kinematics.sample_into(grid.dt_s, &mut states);
        let last = &states[grid.n_samples - per_cycle..];
        angle_curves.push(std::array::from_fn(|i| {
            last.iter().map(|s| s.angles_rad[i].to_degrees()).collect()
        }));
        let r_s = report.sensor_radius_m;
        let achieved: Vec<f64> = d
            .achieved_outputs
            .iter()
            .zip(&states[w0..w1])
            .map(|(y, s)| stroke_frame_loads(y, s, r_s)[quantity::LIFT])
            .collect();
        let predicted = d.design.cycle_mean_sd.map(|_| {
            let mut m = Vec::new();
            let (mut lo, mut hi) = (Vec::new(), Vec::new());
            for ((y, v), s) in d
                .design
                .predicted_mean
                .iter()
                .zip(&d.design.predicted_var)
                .zip(&states[w0..w1])
            {
                let (dy, _) = stroke_frame_jacobian(y, s, r_s);
                let mean = stroke_frame_loads(y, s, r_s)[quantity::LIFT];
                let sd = (0..5)
                    .map(|k| dy[quantity::LIFT][k].powi(2) * v[k])
                    .sum::<f64>()
                    .sqrt();
                m.push(mean);
                lo.push(mean - 1.96 * sd);
                hi.push(mean + 1.96 * sd);
            }
            [m, lo, hi]
        });
        lifts.push((achieved, predicted));
    }
    let names: Vec<String> = report
        .designs
        .iter()
        .map(|d| d.design.model.clone())
        .collect();
    let predicted_names: Vec<String> = names.iter().map(|n| format!("{n} predicted")).collect();
    let achieved_names: Vec<String> = names.iter().map(|n| format!("{n} on the wing")).collect();
    let iterations: Vec<Vec<f64>> = report
        .designs
        .iter()
        .map(|d| (0..d.design.convergence.len()).map(|i| i as f64).collect())
        .collect();
    let log_j: Vec<Vec<f64>> = report
        .designs
        .iter()
        .map(|d| {
            d.design
                .convergence
                .iter()
                .map(|j| j.max(1e-12).log10())
                .collect()
        })
        .collect();
    let mut out = Vec::new();
    for (i, label) in ["stroke φ (deg)", "deviation ψ (deg)", "pitch α (deg)"]
        .iter()
        .enumerate()
    {
        out.push(Panel {
            x_label: "t / T (last cycle)",
            y_label: label,
            curves: angle_curves
                .iter()
                .enumerate()
                .map(|(j, a)| Curve {
                    label: &names[j],
                    x: &t_cycle,
                    y: &a[i],
                    band: None,
                    colour: Some(j),
                    markers: false,
                })
                .collect(),
        });
    }
    let mut lift_curves = Vec::new();
    for (j, (achieved, predicted)) in lifts.iter().enumerate() {
        if let Some([m, lo, hi]) = predicted {
            lift_curves.push(Curve {
                label: &predicted_names[j],
                x: &t_window,
                y: m,
                band: Some((lo, hi)),
                colour: Some(j),
                markers: false,
            });
        }
        lift_curves.push(Curve {
            label: &achieved_names[j],
            x: &t_window,
            y: achieved,
            band: None,
            colour: Some(j),
            markers: false,
        });
    }
    let target_line: Option<Vec<f64>> =
        report.target[quantity::LIFT].map(|v| vec![v; t_window.len()]);
    if let Some(t) = &target_line {
        lift_curves.push(Curve {
            label: "target mean",
            x: &t_window,
            y: t,
            band: None,
            colour: None,
            markers: false,
        });
    }
    out.push(Panel {
        x_label: "t (s)",
        y_label: "lift (N)",
        curves: lift_curves,
    });
    out.push(Panel {
        x_label: "Adam iteration (winning start)",
        y_label: "log10 J",
        curves: (0..names.len())
            .map(|j| Curve {
                label: &names[j],
                x: &iterations[j],
                y: &log_j[j],
                band: None,
                colour: Some(j),
                markers: false,
            })
            .collect(),
    });
    panels(
        path,
        "designed kinematics, lift on the wing, convergence",
        &out,
        3,
    )
    .map_err(|source| JobError::Analysis {
        what: format!("figure {}", path.display()),
        source,
    })
}
