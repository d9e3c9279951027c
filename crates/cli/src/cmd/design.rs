//! `flapssm design …`: wing kinematics chosen with a load model, verified on the default
//! virtual wing (docs/design.md).

use std::path::PathBuf;
use std::time::Instant;

use anyhow::Context;
use clap::{Args, Subcommand};
use flapssm_design::OptimizerSettings;
use flapssm_jobs::design::control::{CONTROL_FILES, ControlSettings, closed_loop, write_control};
use flapssm_jobs::design::hover::{
    DESIGN_FILES, cycle_design, hover, median_frequency, write_cycle_design,
};
use flapssm_jobs::design::standin::RigStandIn;
use flapssm_jobs::design::study::{STUDY_FILES, StudyModels, study, write_study};
use flapssm_jobs::design::{DesignContext, DesignSettings, ModelChoice};
use flapssm_jobs::rig::load_reference_model;
use flapssm_jobs::{NoProgress, Progress};
use flapssm_prssm::PrssmModel;
use flapssm_qs::LrqsmModel;
use flapssm_wing::virtual_wing::VirtualWingConfig;

use crate::progress::Bars;

/// Wing kinematics chosen with a learned model (docs/design.md).
#[derive(Args)]
pub struct DesignArgs {
    #[command(subcommand)]
    command: DesignCommand,
}

#[derive(Subcommand)]
enum DesignCommand {
    /// Kinematics whose cycle-mean stroke-frame loads meet the targets given (the others
    /// free), optionally at least power; designed with each model, verified on the wing.
    Target(TargetArgs),
    /// Hover: mean lift equal to a weight, zero mean thrust and pitch moment, least power.
    Hover(HoverArgs),
    /// Designs for the held-out measured trajectories' cycle means and load histories with the
    /// PR-SSM, the LRQSM and the quasi-steady wing, with paired intervals.
    Study(StudyArgs),
    /// Cycle-to-cycle control of the mean lift on a wing the model has not seen (another
    /// fluid density, a sensor bias), from a hover design.
    Control(ControlArgs),
}

#[derive(Args)]
struct Common {
    /// The PR-SSM (.json, `flapssm train` or the demo's prssm.json).
    #[arg(long, value_name = "FILE")]
    prssm: PathBuf,
    /// An LRQSM (.json, `flapssm qs fit` or the demo's lrqsm.json) to design with as well.
    #[arg(long, value_name = "FILE")]
    lrqsm: Option<PathBuf>,
    /// Harmonics per Euler angle.
    #[arg(long, default_value_t = 3)]
    harmonics: usize,
    /// PR-SSM particles of a design's prediction.
    #[arg(long, default_value_t = 16)]
    particles: usize,
    /// Starts (the training trajectories' fits nearest the target).
    #[arg(long, default_value_t = 4)]
    starts: usize,
    /// Adam iterations per start.
    #[arg(long, default_value_t = 150)]
    iterations: usize,
    /// Adam step (rad).
    #[arg(long, default_value_t = 0.01)]
    learning_rate: f64,
    /// Weight κ of the PR-SSM's predictive variance in the objective (the robust term).
    #[arg(long, default_value_t = 0.5)]
    robust_weight: f64,
    /// Master seed (the model's draws, the wing's sensor).
    #[arg(long, default_value_t = 0)]
    seed: u64,
    /// Output directory.
    #[arg(long, value_name = "DIR")]
    out: PathBuf,
    /// Hide the progress bars.
    #[arg(long)]
    quiet: bool,
}

#[derive(Args)]
struct TargetArgs {
    #[command(flatten)]
    common: Common,
    /// Mean thrust (N, along x₀; docs/design.md has the frame).
    #[arg(long, allow_hyphen_values = true)]
    thrust_n: Option<f64>,
    /// Mean lift (N, up).
    #[arg(long, allow_hyphen_values = true)]
    lift_n: Option<f64>,
    /// Mean side force (N, along the mid-stroke span).
    #[arg(long, allow_hyphen_values = true)]
    side_n: Option<f64>,
    /// Mean roll moment about x₀ (N·mm, about the stroke axis).
    #[arg(long, allow_hyphen_values = true)]
    roll_n_mm: Option<f64>,
    /// Mean yaw moment about y₀ (N·mm).
    #[arg(long, allow_hyphen_values = true)]
    yaw_n_mm: Option<f64>,
    /// Mean pitch moment about z₀ (N·mm).
    #[arg(long, allow_hyphen_values = true)]
    pitch_n_mm: Option<f64>,
    /// Flapping frequency (Hz; default the measured set's median).
    #[arg(long)]
    frequency_hz: Option<f64>,
    /// Weight of the mean aerodynamic power (per its spread over the measured set).
    #[arg(long, default_value_t = 0.0)]
    power_weight: f64,
}

#[derive(Args)]
struct HoverArgs {
    #[command(flatten)]
    common: Common,
    /// The weight this wing carries (N).
    #[arg(long, allow_hyphen_values = true)]
    weight_n: f64,
    /// Flapping frequency (Hz; default the measured set's median).
    #[arg(long)]
    frequency_hz: Option<f64>,
    /// Weight of the mean aerodynamic power.
    #[arg(long, default_value_t = 0.05)]
    power_weight: f64,
}

#[derive(Args)]
struct StudyArgs {
    #[command(flatten)]
    common: Common,
    /// Held-out targets (2–36).
    #[arg(long, default_value_t = 36)]
    targets: usize,
    /// Cycle-mean designs only (no history designs).
    #[arg(long)]
    no_histories: bool,
    /// The rig's stand-in (the published …/bayiz2021-prssm/reference.npz or a model imported
    /// from it): every cycle-mean design judged on it too.
    #[arg(long, value_name = "FILE")]
    reference: Option<PathBuf>,
}

#[derive(Args)]
struct ControlArgs {
    #[command(flatten)]
    common: Common,
    /// Mean lift to hold (N).
    #[arg(long, allow_hyphen_values = true)]
    lift_n: f64,
    /// The plant's fluid density as a multiple of the model's (unseen mismatch).
    #[arg(long, default_value_t = 1.2)]
    density_factor: f64,
    /// A bias added to the plant's normal force F_x (N; unseen mismatch).
    #[arg(long, default_value_t = 0.0, allow_hyphen_values = true)]
    bias_fx_n: f64,
    /// Cycles of the loop.
    #[arg(long, default_value_t = 12)]
    cycles: usize,
    /// Flapping frequency (Hz; default the measured set's median).
    #[arg(long)]
    frequency_hz: Option<f64>,
}

/// Runs `flapssm design …`.
pub fn run(args: DesignArgs) -> anyhow::Result<()> {
    match args.command {
        DesignCommand::Target(a) => target(a),
        DesignCommand::Hover(a) => run_hover(a),
        DesignCommand::Study(a) => run_study(a),
        DesignCommand::Control(a) => control(a),
    }
}

fn progress_of(quiet: bool, bars: &Bars) -> &dyn Progress {
    if quiet { &NoProgress } else { bars }
}

struct Loaded {
    prssm: PrssmModel,
    lrqsm: Option<LrqsmModel>,
    settings: DesignSettings,
    ctx: DesignContext,
}

fn load(c: &Common, files: &[&str], bars: &Bars) -> anyhow::Result<Loaded> {
    let mut inputs = vec![c.prssm.as_path()];
    inputs.extend(c.lrqsm.as_deref());
    flapssm_jobs::files::check_output_dir(&c.out, files, &inputs)?;
    let prssm = PrssmModel::load(&c.prssm)
        .with_context(|| format!("loading PR-SSM model {}", c.prssm.display()))?;
    let lrqsm = c
        .lrqsm
        .as_ref()
        .map(|p| {
            LrqsmModel::load(p).with_context(|| format!("loading LRQSM model {}", p.display()))
        })
        .transpose()?;
    let settings = DesignSettings {
        harmonics: c.harmonics,
        particles: c.particles,
        starts: c.starts,
        optimizer: OptimizerSettings {
            iterations: c.iterations,
            learning_rate_rad: c.learning_rate,
        },
        robust_weight: c.robust_weight,
        seed: c.seed,
        ..DesignSettings::default()
    };
    settings.check()?;
    let ctx = DesignContext::paper(
        &VirtualWingConfig::default(),
        settings.harmonics,
        settings.ramp_cycles,
        settings.seed,
        progress_of(c.quiet, bars),
    )?;
    Ok(Loaded {
        prssm,
        lrqsm,
        settings,
        ctx,
    })
}

fn models<'a>(l: &'a Loaded) -> Vec<ModelChoice<'a>> {
    let mut m = vec![ModelChoice::Prssm(&l.prssm)];
    m.extend(l.lrqsm.as_ref().map(ModelChoice::Lrqsm));
    m.push(ModelChoice::QuasiSteady);
    m
}

/// Prints the report and the files written.
fn print_report(r: &impl std::fmt::Display, out: &std::path::Path, files: &[&str], start: Instant) {
    print!("{r}");
    println!(
        "wrote {}/{{{}}} in {:.1} s",
        out.display(),
        files.join(","),
        start.elapsed().as_secs_f64()
    );
}

fn target(a: TargetArgs) -> anyhow::Result<()> {
    let start = Instant::now();
    let bars = Bars::new();
    let l = load(&a.common, &DESIGN_FILES, &bars)?;
    let values = [
        a.thrust_n,
        a.lift_n,
        a.side_n,
        a.roll_n_mm,
        a.yaw_n_mm,
        a.pitch_n_mm,
    ];
    let f = a.frequency_hz.unwrap_or_else(|| median_frequency(&l.ctx));
    let p = progress_of(a.common.quiet, &bars);
    let report = cycle_design(
        &l.ctx,
        &models(&l),
        values,
        f,
        a.power_weight,
        &l.settings,
        p,
    )?;
    write_cycle_design(&report, &a.common.out)?;
    print_report(&report, &a.common.out, &DESIGN_FILES, start);
    Ok(())
}

fn run_hover(a: HoverArgs) -> anyhow::Result<()> {
    let start = Instant::now();
    let bars = Bars::new();
    let l = load(&a.common, &DESIGN_FILES, &bars)?;
    let f = a.frequency_hz.unwrap_or_else(|| median_frequency(&l.ctx));
    let p = progress_of(a.common.quiet, &bars);
    let report = hover(
        &l.ctx,
        &models(&l),
        a.weight_n,
        f,
        a.power_weight,
        &l.settings,
        p,
    )?;
    write_cycle_design(&report, &a.common.out)?;
    print_report(&report, &a.common.out, &DESIGN_FILES, start);
    Ok(())
}

fn run_study(a: StudyArgs) -> anyhow::Result<()> {
    let start = Instant::now();
    let bars = Bars::new();
    let l = load(&a.common, &STUDY_FILES, &bars)?;
    let p = progress_of(a.common.quiet, &bars);
    let rig = a
        .reference
        .as_ref()
        .map(|p| -> anyhow::Result<RigStandIn> {
            let m = load_reference_model(p)?;
            Ok(RigStandIn::new(&m, &l.ctx, 30, a.common.seed)?)
        })
        .transpose()?;
    let models = StudyModels {
        prssm: &l.prssm,
        lrqsm: l.lrqsm.as_ref(),
        rig: rig.as_ref(),
    };
    let report = study(&l.ctx, &models, a.targets, !a.no_histories, &l.settings, p)?;
    write_study(&report, &a.common.out)?;
    print_report(&report, &a.common.out, &STUDY_FILES, start);
    Ok(())
}

fn control(a: ControlArgs) -> anyhow::Result<()> {
    let start = Instant::now();
    let bars = Bars::new();
    let l = load(
        &a.common,
        &flapssm_jobs::design::control::CONTROL_FILES,
        &bars,
    )?;
    let f = a.frequency_hz.unwrap_or_else(|| median_frequency(&l.ctx));
    let settings = ControlSettings {
        lift_n: a.lift_n,
        density_factor: a.density_factor,
        bias_fx_n: a.bias_fx_n,
        cycles: a.cycles,
        frequency_hz: f,
        design: l.settings,
    };
    let p = progress_of(a.common.quiet, &bars);
    let report = closed_loop(&l.ctx, &l.prssm, &settings, p)?;
    write_control(&report, &a.common.out)?;
    print_report(&report, &a.common.out, &CONTROL_FILES, start);
    Ok(())
}
