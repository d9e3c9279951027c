//! Kinematics chosen with a learned model (`flapssm design …`): cycle-mean targets, hover at
//! least power, and the closed loop, each returned as its report's dict.

use std::path::{Path, PathBuf};

use flapssm_design::OptimizerSettings;
use flapssm_jobs::design::control::{CONTROL_FILES, ControlSettings, closed_loop, write_control};
use flapssm_jobs::design::hover::{
    CycleDesignReport, DESIGN_FILES, cycle_design, median_frequency, write_cycle_design,
};
use flapssm_jobs::design::{DesignContext, DesignSettings, ModelChoice};
use flapssm_prssm::PrssmModel;
use flapssm_qs::LrqsmModel;
use flapssm_wing::virtual_wing::VirtualWingConfig;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;

use crate::errors::{job_error, read_error};
use crate::progress::PyProgress;

/// The settings of the keyword arguments every design function takes.
#[derive(Clone, Copy)]
struct Knobs {
    harmonics: usize,
    particles: usize,
    starts: usize,
    iterations: usize,
    learning_rate: f64,
    robust_weight: f64,
    seed: u64,
}

impl Knobs {
    fn settings(self) -> DesignSettings {
        DesignSettings {
            harmonics: self.harmonics,
            particles: self.particles,
            starts: self.starts,
            optimizer: OptimizerSettings {
                iterations: self.iterations,
                learning_rate_rad: self.learning_rate,
            },
            robust_weight: self.robust_weight,
            seed: self.seed,
            ..DesignSettings::default()
        }
    }
}

fn load_models(prssm: &Path, lrqsm: Option<&Path>) -> PyResult<(PrssmModel, Option<LrqsmModel>)> {
    let p = PrssmModel::load(prssm).map_err(|e| read_error(prssm, e.to_string()))?;
    let l = lrqsm
        .map(|path| LrqsmModel::load(path).map_err(|e| read_error(path, e.to_string())))
        .transpose()?;
    Ok((p, l))
}

fn to_json(v: impl FnOnce() -> serde_json::Result<String>) -> PyResult<String> {
    v().map_err(|e| PyValueError::new_err(e.to_string()))
}

/// Designs for cycle-mean `targets` (`[thrust_n, lift_n, side_force_n, roll_moment_n_mm,
/// yaw_moment_n_mm, pitch_moment_n_mm]`, `None` free) with the PR-SSM, the LRQSM (when
/// given) and the quasi-steady wing, verified on the default virtual wing; with `out`, writes
/// `design.json` and `design.md`. Returns the report as JSON text.
#[pyfunction]
#[pyo3(signature = (prssm, targets, lrqsm=None, frequency_hz=None, power_weight=0.0, out=None,
    harmonics=3, particles=16, starts=4, iterations=150, learning_rate=0.01, robust_weight=0.5,
    seed=0, progress=None))]
#[allow(clippy::too_many_arguments)]
pub fn design_target(
    py: Python<'_>,
    prssm: PathBuf,
    targets: [Option<f64>; 6],
    lrqsm: Option<PathBuf>,
    frequency_hz: Option<f64>,
    power_weight: f64,
    out: Option<PathBuf>,
    harmonics: usize,
    particles: usize,
    starts: usize,
    iterations: usize,
    learning_rate: f64,
    robust_weight: f64,
    seed: u64,
    progress: Option<Py<PyAny>>,
) -> PyResult<String> {
    let knobs = Knobs {
        harmonics,
        particles,
        starts,
        iterations,
        learning_rate,
        robust_weight,
        seed,
    };
    run_cycle_design(
        py,
        &prssm,
        lrqsm.as_deref(),
        targets,
        frequency_hz,
        power_weight,
        out,
        knobs,
        progress,
    )
}

#[allow(clippy::too_many_arguments)]
fn run_cycle_design(
    py: Python<'_>,
    prssm: &Path,
    lrqsm: Option<&Path>,
    targets: [Option<f64>; 6],
    frequency_hz: Option<f64>,
    power_weight: f64,
    out: Option<PathBuf>,
    knobs: Knobs,
    progress: Option<Py<PyAny>>,
) -> PyResult<String> {
    let mut inputs = vec![prssm];
    inputs.extend(lrqsm);
    if let Some(dir) = &out {
        flapssm_jobs::files::check_output_dir(dir, &DESIGN_FILES, &inputs)
            .map_err(|e| job_error(e, None))?;
    }
    let (p, l) = load_models(prssm, lrqsm)?;
    let settings = knobs.settings();
    let bar = PyProgress::new(progress);
    let report = py.detach(|| -> flapssm_jobs::Result<CycleDesignReport> {
        settings.check()?;
        let ctx = DesignContext::paper(
            &VirtualWingConfig::default(),
            settings.harmonics,
            settings.ramp_cycles,
            settings.seed,
            &bar,
        )?;
        let mut models = vec![ModelChoice::Prssm(&p)];
        models.extend(l.as_ref().map(ModelChoice::Lrqsm));
        models.push(ModelChoice::QuasiSteady);
        let f = frequency_hz.unwrap_or_else(|| median_frequency(&ctx));
        let r = cycle_design(&ctx, &models, targets, f, power_weight, &settings, &bar)?;
        if let Some(dir) = &out {
            write_cycle_design(&r, dir)?;
        }
        Ok(r)
    });
    if let Some(e) = bar.take_error() {
        return Err(e);
    }
    let report = report.map_err(|e| job_error(e, None))?;
    to_json(|| serde_json::to_string(&report))
}

/// The closed loop: a hover design for `lift_n` flown on the default wing with the fluid's
/// density × `density_factor` and a bias of `bias_fx_n` on F_x (unseen by the model), its
/// stroke amplitude chosen cycle by cycle with the streaming PR-SSM; with `out`, writes
/// `control.json`, `control.md` and `control.csv`. Returns the report as JSON text.
#[pyfunction]
#[pyo3(signature = (prssm, lift_n, density_factor=1.2, bias_fx_n=0.0, cycles=12,
    frequency_hz=None, out=None, particles=16, seed=0, progress=None))]
#[allow(clippy::too_many_arguments)]
pub fn design_control(
    py: Python<'_>,
    prssm: PathBuf,
    lift_n: f64,
    density_factor: f64,
    bias_fx_n: f64,
    cycles: usize,
    frequency_hz: Option<f64>,
    out: Option<PathBuf>,
    particles: usize,
    seed: u64,
    progress: Option<Py<PyAny>>,
) -> PyResult<String> {
    if let Some(dir) = &out {
        flapssm_jobs::files::check_output_dir(dir, &CONTROL_FILES, &[&prssm])
            .map_err(|e| job_error(e, None))?;
    }
    let (p, _) = load_models(&prssm, None)?;
    let design = DesignSettings {
        particles,
        seed,
        ..DesignSettings::default()
    };
    let bar = PyProgress::new(progress);
    let report = py.detach(|| {
        design.check()?;
        let ctx = DesignContext::paper(
            &VirtualWingConfig::default(),
            design.harmonics,
            design.ramp_cycles,
            seed,
            &bar,
        )?;
        let settings = ControlSettings {
            lift_n,
            density_factor,
            bias_fx_n,
            cycles,
            frequency_hz: frequency_hz.unwrap_or_else(|| median_frequency(&ctx)),
            design,
        };
        let r = closed_loop(&ctx, &p, &settings, &bar)?;
        if let Some(dir) = &out {
            write_control(&r, dir)?;
        }
        Ok::<_, flapssm_jobs::JobError>(r)
    });
    if let Some(e) = bar.take_error() {
        return Err(e);
    }
    let report = report.map_err(|e| job_error(e, None))?;
    to_json(|| serde_json::to_string(&report))
}
