//! `flapssm rig …`: a dataset on the paper's trajectories against the published model's
//! prediction of the rig's loads, and the mount angles that bring a wing closest to it.

use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::Context;
use clap::{Args, Subcommand};
use flapssm_jobs::known_answer::{
    DRAW_UNITS, RECOVERY_FILES, recovery, reference_draws, write_recovery,
};
use flapssm_jobs::rig::{
    MountFitSettings, RIG_FILES, RigSettings, fit_mount, load_reference_model, rig_check,
    rig_reference, write_rig_check,
};
use flapssm_jobs::{NoProgress, Progress};
use flapssm_wing::trajectories::paper::PAPER_N_TRAIN;
use flapssm_wing::virtual_wing::{Fidelity, VirtualWingConfig};

use crate::progress::Bars;

/// The rig as the judge (docs/rig-agreement.md).
#[derive(Args)]
pub struct RigArgs {
    #[command(subcommand)]
    command: RigCommand,
}

#[derive(Subcommand)]
enum RigCommand {
    /// Score a dataset of the paper's trajectories (`simulate --source paper`, any fidelity or
    /// sensor setting) against the published model's prediction: per channel r, z-RMSE and the
    /// share inside its 95 % band, the chordwise couplings and the Fig. 5 lags, on the 512
    /// training and the 36 test trajectories; a figure of the paper's six example trajectories.
    Check(CheckArgs),
    /// Identify the plate's and the sensor's angles on the pitch shaft that bring a wing closest
    /// to the published model's prediction, on the 512 training trajectories only.
    FitMount(FitMountArgs),
    /// The published 2-D hovering case (Wang, Birch & Dickinson 2004) through every fidelity:
    /// lift and drag histories against the experiment and two computations.
    Wang2004(Wang2004Args),
    /// A known answer at the paper's scale: loads drawn from the reference model on the paper's
    /// 548 measured trajectories (its standardized units), a dataset to train a PR-SSM on.
    Draws(DrawsArgs),
    /// How well a PR-SSM trained on `rig draws` recovers the model that drew them, on the 36
    /// test trajectories: per channel its mean against the drawing model's, and both against the
    /// draws with a paired bootstrap interval.
    Recovery(RecoveryArgs),
}

#[derive(Args)]
struct DrawsArgs {
    /// The drawing model: the published parameter file (…/bayiz2021-prssm/reference.npz) or a
    /// model file imported from it.
    #[arg(long, value_name = "FILE")]
    reference: PathBuf,
    /// Seed of the draws (same seed, identical file).
    #[arg(long, value_name = "S", default_value_t = 1)]
    seed: u64,
    /// Output dataset file (.npz).
    #[arg(long, value_name = "FILE")]
    out: PathBuf,
    /// Hide the progress bar.
    #[arg(long)]
    quiet: bool,
}

#[derive(Args)]
struct RecoveryArgs {
    /// The draws (`flapssm rig draws`) the model was trained on.
    dataset: PathBuf,
    /// The trained PR-SSM (.json, `flapssm train`).
    #[arg(long, value_name = "FILE")]
    prssm: PathBuf,
    #[command(flatten)]
    reference: ReferenceArgs,
    /// Output directory: recovery.json and recovery.md.
    #[arg(long, value_name = "DIR")]
    out: PathBuf,
}

#[derive(Args)]
struct Wang2004Args {
    /// Directory of the published histories (CL_EXP.dat, CD_EXP.dat, …; ../shared/data/wang2004-hovering).
    #[arg(long, value_name = "DIR")]
    data: PathBuf,
    /// Output directory: wang2004.json, wang2004.md, wang2004.png.
    #[arg(long, value_name = "DIR")]
    out: PathBuf,
}

/// The reference and its prediction settings.
#[derive(Args)]
struct ReferenceArgs {
    /// The reference model: the published parameter file (…/bayiz2021-prssm/reference.npz) or
    /// a model file imported from it (`flapssm model import-published`).
    #[arg(long, value_name = "FILE")]
    reference: PathBuf,
    /// Particles of the reference's prediction.
    #[arg(long, value_name = "N", default_value_t = 30, value_parser = crate::cmd::positive::<usize>)]
    particles: usize,
    /// Seed of the reference's draws.
    #[arg(long, value_name = "S", default_value_t = 1)]
    seed: u64,
    /// Hide the progress bar.
    #[arg(long)]
    quiet: bool,
}

impl ReferenceArgs {
    fn settings(&self) -> RigSettings {
        RigSettings {
            particles: self.particles,
            seed: self.seed,
            ..RigSettings::default()
        }
    }
}

#[derive(Args)]
struct CheckArgs {
    /// Dataset of the paper's trajectories 0..N in the authors' order (.npz or .csv).
    dataset: PathBuf,
    #[command(flatten)]
    reference: ReferenceArgs,
    /// Output directory: rig-check.json, rig-check.md and rig-examples.png (when the dataset
    /// holds the paper's example test trajectories).
    #[arg(long, value_name = "DIR")]
    out: PathBuf,
    /// Leave out the Fig. 5 lag statistics (faster).
    #[arg(long)]
    no_lags: bool,
}

#[derive(Args)]
struct FitMountArgs {
    #[command(flatten)]
    reference: ReferenceArgs,
    /// Fidelity of the wing (default: the wing's, `--wing-config`, else the default wing's).
    #[arg(long, value_name = "LEVEL")]
    fidelity: Option<String>,
    /// The wing as a JSON file of `VirtualWingConfig` fields (as `simulate --wing-config`);
    /// its mount is replaced by the grid's angles and its sensor chain switched off.
    #[arg(long, value_name = "FILE")]
    wing_config: Option<PathBuf>,
    /// Plate angles θ_p tried, FROM:TO:STEP (deg).
    #[arg(long, value_name = "FROM:TO:STEP", default_value = "-15:15:1", value_parser = parse_range, allow_hyphen_values = true)]
    plate_deg: Angles,
    /// Sensor angles θ_s tried, FROM:TO:STEP (deg).
    #[arg(long, value_name = "FROM:TO:STEP", default_value = "-45:45:1", value_parser = parse_range, allow_hyphen_values = true)]
    sensor_deg: Angles,
    /// Output file (.json): the best angles, the agreement there and the whole surface.
    #[arg(long, value_name = "FILE")]
    out: PathBuf,
}

/// A grid of angles (deg).
#[derive(Debug, Clone, PartialEq)]
struct Angles(Vec<f64>);

/// Parses `FROM:TO:STEP` (deg) into the angles FROM, FROM + STEP, … ≤ TO.
fn parse_range(s: &str) -> Result<Angles, String> {
    let parts: Vec<f64> = s
        .split(':')
        .map(|p| p.trim().parse::<f64>())
        .collect::<Result<_, _>>()
        .map_err(|e| format!("'{s}': {e} (expected FROM:TO:STEP in degrees)"))?;
    let [from, to, step] = parts[..] else {
        return Err(format!("'{s}': expected FROM:TO:STEP in degrees"));
    };
    if !(from.is_finite() && to.is_finite() && step.is_finite() && step > 0.0 && to >= from) {
        return Err(format!("'{s}': needs FROM ≤ TO and STEP > 0"));
    }
    let count = ((to - from) / step + 1e-9).floor() as usize + 1;
    if count > 1000 {
        return Err(format!("'{s}': {count} angles, more than 1000"));
    }
    Ok(Angles((0..count).map(|k| from + k as f64 * step).collect()))
}

/// Runs `flapssm rig …`.
pub fn run(args: RigArgs) -> anyhow::Result<()> {
    match args.command {
        RigCommand::Check(a) => check(a),
        RigCommand::FitMount(a) => fit(a),
        RigCommand::Wang2004(a) => wang(a),
        RigCommand::Draws(a) => draws(a),
        RigCommand::Recovery(a) => recover(a),
    }
}

fn draws(a: DrawsArgs) -> anyhow::Result<()> {
    let start = Instant::now();
    flapssm_jobs::files::check_outputs(&[&a.out], &[&a.reference])?;
    let model = load_reference_model(&a.reference)?;
    let bars = Bars::new();
    let ds = reference_draws(&model, a.seed, progress_of(a.quiet, &bars))
        .context("drawing from the reference model")?;
    ds.save(&a.out)
        .with_context(|| format!("writing {}", a.out.display()))?;
    println!(
        "wrote {}: the paper's {} measured trajectories ({} train), loads drawn from {} (seed {}, {}) in {:.1} s",
        a.out.display(),
        ds.len(),
        ds.n_train,
        a.reference.display(),
        a.seed,
        DRAW_UNITS,
        start.elapsed().as_secs_f64()
    );
    Ok(())
}

fn recover(a: RecoveryArgs) -> anyhow::Result<()> {
    let start = Instant::now();
    flapssm_jobs::files::check_output_dir(
        &a.out,
        &RECOVERY_FILES,
        &[&a.dataset, &a.prssm, &a.reference.reference],
    )?;
    let ds = flapssm_wing::dataset::Dataset::load(&a.dataset)
        .with_context(|| format!("reading dataset {}", a.dataset.display()))?;
    let reference = load_reference_model(&a.reference.reference)?;
    let trained = flapssm_prssm::PrssmModel::load(&a.prssm)
        .with_context(|| format!("reading model {}", a.prssm.display()))?;
    let bars = Bars::new();
    let progress = progress_of(a.reference.quiet, &bars);
    let result = recovery(&trained, &reference, &ds, &a.reference.settings(), progress)
        .with_context(|| format!("scoring {} on {}", a.prssm.display(), a.dataset.display()))?;
    let title = format!(
        "{} recovering {}",
        a.prssm.display(),
        a.reference.reference.display()
    );
    write_recovery(&a.out, &result, &title)?;
    print!("{}", result.markdown(&title));
    println!(
        "\nwrote {} ({:.1} s)",
        a.out.display(),
        start.elapsed().as_secs_f64()
    );
    Ok(())
}

fn progress_of(quiet: bool, bars: &Bars) -> &dyn Progress {
    if quiet { &NoProgress } else { bars }
}

fn check(a: CheckArgs) -> anyhow::Result<()> {
    let start = Instant::now();
    flapssm_jobs::files::check_output_dir(
        &a.out,
        &RIG_FILES,
        &[&a.dataset, &a.reference.reference],
    )?;
    let ds = flapssm_wing::dataset::Dataset::load(&a.dataset)
        .with_context(|| format!("reading dataset {}", a.dataset.display()))?;
    let model = load_reference_model(&a.reference.reference)?;
    let bars = Bars::new();
    let progress = progress_of(a.reference.quiet, &bars);
    let reference = rig_reference(&model, ds.len(), &a.reference.settings(), progress)
        .context("predicting the rig reference")?;
    let result = rig_check(&ds, &reference, !a.no_lags)
        .with_context(|| format!("checking {}", a.dataset.display()))?;
    let title = format!(
        "{} (fidelity {})",
        a.dataset.display(),
        result.fidelity.as_deref().unwrap_or("not recorded")
    );
    write_rig_check(&a.out, &result, &ds, &reference, &title)?;
    print!("{}", result.markdown(&title));
    println!(
        "\nwrote {} ({:.1} s)",
        a.out.display(),
        start.elapsed().as_secs_f64()
    );
    Ok(())
}

fn fit(a: FitMountArgs) -> anyhow::Result<()> {
    let start = Instant::now();
    let inputs: Vec<&Path> = std::iter::once(a.reference.reference.as_path())
        .chain(a.wing_config.as_deref())
        .collect();
    flapssm_jobs::files::check_outputs(&[&a.out], &inputs)?;
    let mut wing: VirtualWingConfig = match &a.wing_config {
        Some(path) => flapssm_jobs::files::load_config(path)
            .with_context(|| format!("reading wing configuration {}", path.display()))?,
        None => VirtualWingConfig::default(),
    };
    if let Some(f) = &a.fidelity {
        wing.fidelity = f.parse::<Fidelity>().context("parsing --fidelity")?;
    }
    wing.check().context("checking the wing")?;
    let model = load_reference_model(&a.reference.reference)?;
    let bars = Bars::new();
    let progress = progress_of(a.reference.quiet, &bars);
    let reference = rig_reference(&model, PAPER_N_TRAIN, &a.reference.settings(), progress)
        .context("predicting the rig reference")?;
    let settings = MountFitSettings {
        plate_deg: a.plate_deg.0,
        sensor_deg: a.sensor_deg.0,
    };
    let result = fit_mount(&wing, &reference, &settings, progress).context("fitting the mount")?;
    flapssm_jobs::files::save_json(&a.out, &result)?;
    let r = |a: &flapssm_jobs::rig::SetAgreement| -> String {
        a.channels
            .iter()
            .map(|c| format!("{} {:.3}", c.channel, c.r))
            .collect::<Vec<_>>()
            .join(", ")
    };
    let (best, aligned) = (&result.at_best, &result.aligned);
    println!(
        "fidelity {:?}, {} training trajectories: plate θ_p = {}°, sensor θ_s = {}° (loads turned by {}°)\n  \
         at the fit: r {}; r(F_y, F_x) {:.3}, r(M_x, F_x) {:.3} (stand-in {:.3}, {:.3})\n  \
         aligned:    r {}; r(F_y, F_x) {:.3}, r(M_x, F_x) {:.3}\n  \
         (the smallest mean z-MSE over all five channels lies at θ_p = {}°, θ_s = {}°: r(F_y, F_x) {:.3}, r(M_x, F_x) {:.3})\n-> {} ({:.1} s)",
        result.fidelity,
        result.n_trajectories,
        result.best.plate_pitch_deg,
        result.best.sensor_pitch_deg,
        result.best.plate_pitch_deg - result.best.sensor_pitch_deg,
        r(best),
        best.dataset_couplings.fy_fx,
        best.dataset_couplings.mx_fx,
        best.reference_couplings.fy_fx,
        best.reference_couplings.mx_fx,
        r(aligned),
        aligned.dataset_couplings.fy_fx,
        aligned.dataset_couplings.mx_fx,
        result.all_channels_best.plate_deg,
        result.all_channels_best.sensor_deg,
        result.all_channels_best.fy_fx,
        result.all_channels_best.mx_fx,
        a.out.display(),
        start.elapsed().as_secs_f64()
    );
    Ok(())
}

const WANG_FILES: [&str; 3] = ["wang2004.json", "wang2004.md", "wang2004.png"];

fn wang(a: Wang2004Args) -> anyhow::Result<()> {
    use flapssm_jobs::wang2004::{grid, wang2004};
    let start = Instant::now();
    flapssm_jobs::files::check_output_dir(&a.out, &WANG_FILES, &[&a.data])?;
    let case = flapssm_wing::hovering2d::Hovering2d::default();
    let result = wang2004(&a.data, &case).context("the hovering case of Wang et al. (2004)")?;
    std::fs::create_dir_all(&a.out).with_context(|| format!("creating {}", a.out.display()))?;
    flapssm_jobs::files::save_json(&a.out.join(WANG_FILES[0]), &result)?;
    let table = result.markdown();
    flapssm_jobs::files::save_text(&a.out.join(WANG_FILES[1]), &table)?;
    let t = grid();
    let n_published = flapssm_jobs::wang2004::PUBLISHED.len();
    let series: Vec<flapssm_jobs::wang2004::HoverSeries<'_>> = result
        .histories
        .iter()
        .enumerate()
        .map(|(k, h)| flapssm_jobs::wang2004::HoverSeries {
            label: &h.name,
            t: &t,
            lift: &h.lift,
            drag: &h.drag,
            published: k < n_published,
        })
        .collect();
    let figure = a.out.join(WANG_FILES[2]);
    flapssm_jobs::wang2004::figure(&figure, &series)?;
    print!("{table}");
    println!(
        "\nwrote {} ({:.1} s)",
        a.out.display(),
        start.elapsed().as_secs_f64()
    );
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::{Angles, parse_range};

    #[test]
    fn ranges_parse_and_bad_ones_are_refused() {
        let ok = |s: &str, v: &[f64]| assert_eq!(parse_range(s).unwrap(), Angles(v.to_vec()));
        ok("-2:2:1", &[-2.0, -1.0, 0.0, 1.0, 2.0]);
        ok("0:1:0.5", &[0.0, 0.5, 1.0]);
        ok("3:3:1", &[3.0]);
        for bad in ["1:2", "a:2:1", "2:1:1", "0:1:0", "0:1e6:1"] {
            assert!(parse_range(bad).is_err(), "{bad}");
        }
    }
}
