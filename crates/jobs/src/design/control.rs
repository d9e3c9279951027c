//! The closed loop: a hover design flown on a wing the model has not seen (another fluid
//! density, a bias on the normal-force channel), its stroke amplitude adjusted cycle by cycle
//! by [`flapssm_design::control`]'s receding-horizon choice with the streaming PR-SSM, beside
//! the same design flown open loop.

use std::path::Path;
use std::time::Instant;

use flapssm_design::DesignGrid;
use flapssm_design::control::{AmplitudeSchedule, advance, cycle_samples, mean_lift, next_scale};
use flapssm_prssm::PrssmModel;
use flapssm_prssm::stream::StreamPredictor;
use flapssm_wing::kinematics::EulerState;
use flapssm_wing::stroke_loads::quantity;
use flapssm_wing::trajectories::SamplingConfig;
use flapssm_wing::virtual_wing::VirtualWing;
use serde::{Deserialize, Serialize};

use super::hover::{VerifiedDesign, cycle_design};
use super::{DesignContext, DesignSettings, ModelChoice, PLANT_STREAM, plant_loads};
use crate::error::{JobError, Result};
use crate::files::{save_json, save_text};
use crate::progress::Progress;
use crate::seed::derive_seed;

/// Files of [`write_control`].
pub const CONTROL_FILES: [&str; 4] = ["control.json", "control.md", "control.csv", "control.png"];

/// Cycles predicted ahead.
pub const HORIZON_CYCLES: usize = 2;

/// Blend between two cycles' scales (cycles).
pub const BLEND_CYCLES: f64 = 0.5;

/// The hover design keeps the stroke within this share of its limits (angle, rate and
/// acceleration), so that the loop has room to raise the amplitude.
pub const STROKE_HEADROOM: f64 = 0.8;

/// Gain of the disturbance estimate's exponential filter: `d̂_k = d̂_{k−1} + β (d_k − d̂_{k−1})`
/// (`β = 1`: the last cycle's difference alone). One half halves the variance of a cycle
/// mean's sensor noise in the estimate at the cost of half a cycle's lag behind a drift.
pub const DISTURBANCE_GAIN: f64 = 0.5;

/// Settings of the loop.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct ControlSettings {
    /// Mean lift to hold (N).
    pub lift_n: f64,
    /// The plant's fluid density / the model's.
    pub density_factor: f64,
    /// Bias added to the plant's F_x (N).
    pub bias_fx_n: f64,
    /// Cycles after the ramp.
    pub cycles: usize,
    /// Frequency (Hz).
    pub frequency_hz: f64,
    /// The hover design's settings.
    pub design: DesignSettings,
}

/// One cycle of the loop.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct CycleRecord {
    /// Cycle (1 = the first after the ramp).
    pub cycle: usize,
    /// Stroke scale flown.
    pub scale: f64,
    /// The plant's mean lift (N).
    pub measured_lift_n: f64,
    /// The predictor's mean lift (N).
    pub predicted_lift_n: f64,
    /// Their difference (N).
    pub disturbance_n: f64,
    /// The filtered disturbance the next cycle is chosen with (N).
    pub disturbance_estimate_n: f64,
    /// (measured − target) / target (%).
    pub error_pct: f64,
    /// The open-loop flight's mean lift in this cycle (N).
    pub open_loop_lift_n: f64,
}

/// The loop's record.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct ControlReport {
    /// Settings.
    pub settings: ControlSettings,
    /// The hover design (PR-SSM) on the nominal wing.
    pub design: VerifiedDesign,
    /// Per cycle.
    pub cycles: Vec<CycleRecord>,
    /// The first cycle whose lift is within 5 % of the target.
    pub reached_5pct_at_cycle: Option<usize>,
    /// The share of the cycles from then on within 5 %.
    pub held_5pct_share: Option<f64>,
    /// The first cycle from which every cycle's lift is within 5 % of the target.
    pub within_5pct_from_cycle: Option<usize>,
    /// Open loop: the last cycle's error (%).
    pub open_loop_error_pct: f64,
    /// Wall time (s).
    pub wall_s: f64,
}

fn plant_run(
    wing: &mut VirtualWing,
    ctx: &DesignContext,
    cfg: &flapssm_wing::virtual_wing::VirtualWingConfig,
    schedule: &AmplitudeSchedule,
    n: usize,
    bias_fx_n: f64,
    seed: u64,
) -> Result<(Vec<[f64; 5]>, Vec<EulerState>)> {
    let sampling = SamplingConfig {
        n_samples: n,
        ..ctx.sampling.clone()
    };
    let raw = schedule.sample(sampling.raw_dt_s(), sampling.n_raw());
    let mut out = plant_loads(wing, cfg, &raw, &sampling, seed)?;
    out.iter_mut().for_each(|y| y[0] += bias_fx_n);
    let states = raw.iter().step_by(sampling.decimation).copied().collect();
    Ok((out, states))
}

/// Runs the loop (module docs). `progress.advance(1)` per cycle.
///
/// # Errors
/// [`JobError::Setting`] for a bad lift, factor or cycle count; design, plant and predictor
/// errors.
pub fn closed_loop(
    ctx: &DesignContext,
    prssm: &PrssmModel,
    settings: &ControlSettings,
    progress: &dyn Progress,
) -> Result<ControlReport> {
    let start = Instant::now();
    let bad = |name: &str, value: f64, expected: &str| {
        Err(JobError::Setting {
            name: name.into(),
            value: value.to_string(),
            expected: expected.into(),
        })
    };
    if !(settings.density_factor > 0.0 && settings.density_factor.is_finite()) {
        return bad("density_factor", settings.density_factor, "finite and > 0");
    }
    if !settings.bias_fx_n.is_finite() {
        return bad("bias_fx_n", settings.bias_fx_n, "finite (N)");
    }
    if settings.cycles < 2 || settings.cycles > 100 {
        return bad("cycles", settings.cycles as f64, "2..=100");
    }
    let mut target = [None; 6];
    target[quantity::LIFT] = Some(settings.lift_n);
    target[quantity::THRUST] = Some(0.0);
    target[quantity::PITCH] = Some(0.0);
    let mut design_ctx = ctx.clone();
    design_ctx.limits.angle_rad[0] *= STROKE_HEADROOM;
    design_ctx.limits.rate_rad_s[0] *= STROKE_HEADROOM;
    design_ctx.limits.accel_rad_s2[0] *= STROKE_HEADROOM;
    let report = cycle_design(
        &design_ctx,
        &[ModelChoice::Prssm(prssm)],
        target,
        settings.frequency_hz,
        0.0,
        &settings.design,
        progress,
    )?;
    let design = report.designs.into_iter().next().expect("one design");
    let base = design.design.kinematics.clone();
    let mut plant_cfg = ctx.wing.clone();
    plant_cfg.fluid.density_kg_m3 *= settings.density_factor;
    let mut wing = VirtualWing::new(&plant_cfg)?;
    let seed = derive_seed(settings.design.seed, PLANT_STREAM, u64::MAX - 1);
    let dt = DesignGrid::paper().dt_s;
    let f = base.frequency_hz;
    let r_s = ctx.wing.sensor_radius_m;
    let n_end = cycle_samples(f, dt, settings.cycles).end;
    // The wing flies one cycle beyond the last one scored: the sensor's zero-phase filter
    // runs over the whole record, and its end would bend the last cycle's reading.
    let n_plant = cycle_samples(f, dt, settings.cycles + 1).end;
    // The largest scale the stroke's limits allow.
    let one = AmplitudeSchedule {
        base: base.clone(),
        scales: vec![1.0],
        blend_cycles: BLEND_CYCLES,
    };
    let states = one.sample(dt, n_end);
    let peak = |i: usize, get: &dyn Fn(&EulerState) -> f64| {
        states[cycle_samples(f, dt, 1).start..]
            .iter()
            .map(|s| get(s).abs())
            .fold(0.0, f64::max)
            .max(1e-12)
            / [
                ctx.limits.angle_rad[0],
                ctx.limits.rate_rad_s[0],
                ctx.limits.accel_rad_s2[0],
            ][i]
    };
    let worst = peak(0, &|s| s.angles_rad[0])
        .max(peak(1, &|s| s.rates_rad_s[0]))
        .max(peak(2, &|s| s.accels_rad_s2[0]));
    let bounds = [0.5, (1.0 / worst).max(1.0)];
    let (open, open_states) = plant_run(
        &mut wing,
        ctx,
        &plant_cfg,
        &one,
        n_plant,
        settings.bias_fx_n,
        seed,
    )?;
    let zero = vec![0.0; prssm.config.n_state];
    let mut predictor = StreamPredictor::<f64>::new(
        prssm,
        settings.design.particles,
        &zero,
        &zero,
        derive_seed(settings.design.seed, PLANT_STREAM + 2, 0),
    )
    .map_err(|e| JobError::Mismatch {
        what: "streaming predictor".into(),
        expected: "a PR-SSM that predicts".into(),
        found: e.to_string(),
    })?;
    let design_err = super::design_error;
    let mut schedule = one.clone();
    advance(&mut predictor, &states[cycle_samples(f, dt, 0)], r_s).map_err(design_err)?;
    progress.start("closed loop", settings.cycles as u64);
    let mut cycles = Vec::with_capacity(settings.cycles);
    let mut estimate: Option<f64> = None;
    for k in 1..=settings.cycles {
        while schedule.scales.len() <= k {
            let last = *schedule.scales.last().expect("one scale");
            schedule.scales.push(last);
        }
        let span = cycle_samples(f, dt, k);
        // The whole flight at its full length every time (the future at the last scale): the
        // plant is causal and its sensor draws depend on the flight's length, so the past
        // stays exactly as flown.
        let (out, st) = plant_run(
            &mut wing,
            ctx,
            &plant_cfg,
            &schedule,
            n_plant,
            settings.bias_fx_n,
            seed,
        )?;
        let measured = mean_lift(&out[span.clone()], &st[span.clone()], r_s);
        let predicted = advance(&mut predictor, &st[span.clone()], r_s).map_err(design_err)?;
        let disturbance = measured - predicted;
        let d_hat = estimate.map_or(disturbance, |e| e + DISTURBANCE_GAIN * (disturbance - e));
        estimate = Some(d_hat);
        let open_loop = mean_lift(&open[span.clone()], &open_states[span.clone()], r_s);
        cycles.push(CycleRecord {
            cycle: k,
            scale: schedule.scales[k],
            measured_lift_n: measured,
            predicted_lift_n: predicted,
            disturbance_n: disturbance,
            disturbance_estimate_n: d_hat,
            error_pct: 100.0 * (measured - settings.lift_n) / settings.lift_n,
            open_loop_lift_n: open_loop,
        });
        let next = next_scale(
            &predictor,
            &schedule,
            k,
            HORIZON_CYCLES,
            settings.lift_n,
            d_hat,
            dt,
            bounds,
            r_s,
        )
        .map_err(design_err)?;
        schedule.scales.truncate(k + 1);
        schedule.scales.push(next);
        progress.advance(1);
    }
    progress.finish("");
    let within = (0..cycles.len())
        .find(|&i| cycles[i..].iter().all(|c| c.error_pct.abs() <= 5.0))
        .map(|i| cycles[i].cycle);
    let last = cycles.last().expect("cycles");
    let reached = cycles.iter().position(|c| c.error_pct.abs() <= 5.0);
    let held = reached.map(|i| {
        let after = &cycles[i..];
        after.iter().filter(|c| c.error_pct.abs() <= 5.0).count() as f64 / after.len() as f64
    });
    Ok(ControlReport {
        reached_5pct_at_cycle: reached.map(|i| cycles[i].cycle),
        held_5pct_share: held,
        settings: *settings,
        open_loop_error_pct: 100.0 * (last.open_loop_lift_n - settings.lift_n) / settings.lift_n,
        within_5pct_from_cycle: within,
        design,
        cycles,
        wall_s: start.elapsed().as_secs_f64(),
    })
}

impl std::fmt::Display for ControlReport {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let s = &self.settings;
        writeln!(
            f,
            "target mean lift {:.4} N at {:.4} Hz; plant: fluid density × {}, F_x bias {} N (unseen by the model)",
            s.lift_n, s.frequency_hz, s.density_factor, s.bias_fx_n
        )?;
        writeln!(
            f,
            "hover design on the nominal wing: lift {:.4} N predicted, {:.4} N achieved\n",
            self.design.design.evaluation.cycle_means[quantity::LIFT],
            self.design.achieved[quantity::LIFT]
        )?;
        writeln!(
            f,
            "| cycle | stroke scale | lift (N) | predicted (N) | difference (N) | estimate (N) | error (%) | open-loop lift (N) |"
        )?;
        writeln!(f, "|---|---|---|---|---|---|---|---|")?;
        for c in &self.cycles {
            writeln!(
                f,
                "| {} | {:.4} | {:.4} | {:.4} | {:+.4} | {:+.4} | {:+.2} | {:.4} |",
                c.cycle,
                c.scale,
                c.measured_lift_n,
                c.predicted_lift_n,
                c.disturbance_n,
                c.disturbance_estimate_n,
                c.error_pct,
                c.open_loop_lift_n
            )?;
        }
        match (self.reached_5pct_at_cycle, self.held_5pct_share) {
            (Some(k), Some(h)) => writeln!(
                f,
                "\nwithin 5 % of the target first in cycle {k}; {:.0} % of the cycles from then on within 5 %",
                100.0 * h
            )?,
            _ => writeln!(f, "\nnever within 5 % of the target")?,
        }
        match self.within_5pct_from_cycle {
            Some(k) => writeln!(f, "every cycle within 5 % from cycle {k} on")?,
            None => writeln!(f, "not every cycle to the end within 5 %")?,
        }
        writeln!(
            f,
            "open loop: {:+.2} % in the last cycle; wall {:.1} s",
            self.open_loop_error_pct, self.wall_s
        )
    }
}

/// Writes [`CONTROL_FILES`] into `dir` (atomic): the record, its table, and the per-cycle CSV.
///
/// # Errors
/// I/O errors naming the file.
pub fn write_control(report: &ControlReport, dir: &Path) -> Result<()> {
    std::fs::create_dir_all(dir).map_err(|source| JobError::Io {
        path: dir.to_path_buf(),
        source,
    })?;
    save_json(&dir.join(CONTROL_FILES[0]), report)?;
    save_text(&dir.join(CONTROL_FILES[1]), &report.to_string())?;
    let mut csv = String::from(
        "cycle,stroke_scale,lift_n,predicted_lift_n,disturbance_n,disturbance_estimate_n,error_pct,open_loop_lift_n\n",
    );
    for c in &report.cycles {
        csv.push_str(&format!(
            "{},{},{},{},{},{},{},{}\n",
            c.cycle,
            c.scale,
            c.measured_lift_n,
            c.predicted_lift_n,
            c.disturbance_n,
            c.disturbance_estimate_n,
            c.error_pct,
            c.open_loop_lift_n
        ));
    }
    save_text(&dir.join(CONTROL_FILES[2]), &csv)?;
    control_figure(report, &dir.join(CONTROL_FILES[3]))
}

/// The loop cycle by cycle: the wing's mean lift closed and open loop against the target and
/// its ±5 % band, and the stroke scale flown.
fn control_figure(report: &ControlReport, path: &Path) -> Result<()> {
    use flapssm_analysis::plots::design::{Curve, Panel, panels};
    let k: Vec<f64> = report.cycles.iter().map(|c| c.cycle as f64).collect();
    let closed: Vec<f64> = report.cycles.iter().map(|c| c.measured_lift_n).collect();
    let open: Vec<f64> = report.cycles.iter().map(|c| c.open_loop_lift_n).collect();
    let predicted: Vec<f64> = report.cycles.iter().map(|c| c.predicted_lift_n).collect();
    let l = report.settings.lift_n;
    let target = vec![l; k.len()];
    let (lo, hi) = (vec![0.95 * l; k.len()], vec![1.05 * l; k.len()]);
    let scale: Vec<f64> = report.cycles.iter().map(|c| c.scale).collect();
    let curve = |label, y, colour, band| Curve {
        label,
        x: &k,
        y,
        band,
        colour,
        markers: true,
    };
    let lift = Panel {
        x_label: "cycle",
        y_label: "mean lift (N)",
        curves: vec![
            curve("target ± 5 %", &target, None, Some((&lo, &hi))),
            curve("closed loop, on the wing", &closed, Some(0), None),
            curve("open loop, on the wing", &open, Some(1), None),
            curve(
                "closed loop, the model's prediction",
                &predicted,
                Some(2),
                None,
            ),
        ],
    };
    let scales = Panel {
        x_label: "cycle",
        y_label: "stroke scale",
        curves: vec![curve("stroke scale flown", &scale, Some(0), None)],
    };
    let title = format!(
        "closed loop: fluid density × {}, F_x bias {} N (unseen)",
        report.settings.density_factor, report.settings.bias_fx_n
    );
    panels(path, &title, &[lift, scales], 2).map_err(|source| JobError::Analysis {
        what: format!("figure {}", path.display()),
        source,
    })
}
