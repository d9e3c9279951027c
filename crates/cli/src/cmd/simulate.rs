//! `flapssm simulate`: run the virtual robotic wing on the seeded generator's trajectories or on
//! the paper's measured ones, and write a dataset.

use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::Context;
use clap::Args;
use flapssm_jobs::NoProgress;
use flapssm_jobs::files::{check_output_dir, check_outputs};
use flapssm_jobs::own_rig::{RehearsalSettings, load_rig, rehearsal_file_name, rehearse_rig};
use flapssm_jobs::simulate::{SimulateSettings, simulate, simulate_paper};
use flapssm_wing::virtual_wing::Fidelity;

use crate::cmd::choices::SourceArg;
use crate::progress::Bars;

/// Simulate the robotic wing (aerodynamics + sensor chain) on generated or measured trajectories.
#[derive(Args)]
pub struct SimulateArgs {
    /// Trajectories: the seeded generator, or the paper's measured set.
    #[arg(long, value_enum, default_value = "generator")]
    source: SourceArg,
    /// Number of trajectories (with --source paper: the first N of 548); default 548, with
    /// --rig 10 recordings.
    #[arg(long, value_name = "N")]
    n: Option<usize>,
    /// Seed of the generated trajectories and of the sensor noise (same seed → identical file).
    #[arg(long, value_name = "S", default_value_t = 0)]
    seed: u64,
    /// Aerodynamic fidelity: l0 (quasi-steady), l1 (unsteady low-order), l2 (vortex strips), l3
    /// (vortex lattice of the whole plate with a prescribed wake). Default: the wing's
    /// (`--wing-config`, else the default wing).
    #[arg(long, value_name = "LEVEL")]
    fidelity: Option<String>,
    /// The wing as a JSON file of `VirtualWingConfig` fields (geometry, fluid, fidelity,
    /// aerodynamic, sensor-pose and sensor settings; a missing field keeps the default wing's,
    /// an unknown one is refused). The options above apply on top of it.
    #[arg(long, value_name = "FILE")]
    wing_config: Option<PathBuf>,
    /// Output dataset file (.npz).
    #[arg(long, value_name = "FILE")]
    out: PathBuf,
    /// Switch off every sensor effect (noise, bias, drift, coupling, residuals, filter).
    #[arg(long)]
    noise_free: bool,
    /// Training trajectories (the first K); default 512, or the published split for N ≤ 512.
    #[arg(long, value_name = "K")]
    n_train: Option<usize>,
    /// Flat stroke plane: no deviation (ψ = 0).
    #[arg(long)]
    flat: bool,
    /// L2 wake: free (vortex dynamics, the default) or frozen (vortices stay where shed, in
    /// the moving fluid; docs/vortex-method.md). Refused at other fidelities.
    #[arg(long, value_name = "MOTION")]
    wake: Option<String>,
    /// Induced inflow of L2 and L3: still, momentum (momentum theory from the recent lift: of
    /// each strip at L2, of the whole wing at L3) or uniform:K (the fluid sinks at K·U_ref at
    /// L2, at K × the reference point's recent mean speed at L3). Default: still at L2,
    /// momentum at L3. Refused at L0 and L1.
    #[arg(long, value_name = "INFLOW")]
    inflow: Option<String>,
    /// Rehearse a rig (its description, TOML; docs/own-rig.md): write the raw recordings it
    /// would make of generated motions into --recordings, and to --out the virtual wing's own
    /// loads on them, the answer that `flapssm dataset build` should recover.
    #[arg(long, value_name = "FILE", requires = "recordings",
          conflicts_with_all = ["source", "wing_config", "noise_free", "flat", "wake", "inflow"])]
    rig: Option<PathBuf>,
    /// With --rig: the directory of the raw recordings (recording_000.csv, …).
    #[arg(long, value_name = "DIR", requires = "rig")]
    recordings: Option<PathBuf>,
    /// With --rig: the length of each motion after the move from the home pose (s).
    #[arg(long, value_name = "SECONDS", default_value_t = 16.0, requires = "rig")]
    motion_s: f64,
    /// Hide the progress bar.
    #[arg(long)]
    quiet: bool,
}

/// `flapssm simulate --rig`: a rig rehearsed by the virtual wing.
fn rehearse(args: &SimulateArgs, rig: &Path, dir: &Path) -> anyhow::Result<()> {
    let start = Instant::now();
    let n = args.n.unwrap_or(RehearsalSettings::default().n_recordings);
    let names: Vec<String> = (0..n).map(rehearsal_file_name).collect();
    let names: Vec<&str> = names.iter().map(String::as_str).collect();
    check_outputs(&[&args.out], &[rig])?;
    check_output_dir(dir, &names, &[rig, &args.out])?;
    let desc = load_rig(rig)?;
    let fidelity: Fidelity = args
        .fidelity
        .as_deref()
        .map(|f| f.parse().context("parsing --fidelity"))
        .transpose()?
        .unwrap_or(Fidelity::L0);
    let settings = RehearsalSettings {
        n_recordings: n,
        seed: args.seed,
        fidelity,
        motion_s: args.motion_s,
        n_train: args.n_train,
    };
    let bars = Bars::new();
    let progress: &dyn flapssm_jobs::Progress = if args.quiet { &NoProgress } else { &bars };
    let truth = rehearse_rig(&desc, rig, &settings, dir, progress)?;
    truth
        .save(&args.out)
        .with_context(|| format!("writing dataset {}", args.out.display()))?;
    println!(
        "wrote {n} raw recordings of the rig '{}' ({} Hz, fidelity {fidelity:?}, seed {}) to {}, \
         and the wing's own loads on them to {} ({} trajectories × {} samples) in {:.2} s",
        desc.name,
        desc.sampling.rate_hz,
        args.seed,
        dir.display(),
        args.out.display(),
        truth.len(),
        truth.n_samples(),
        start.elapsed().as_secs_f64()
    );
    Ok(())
}

/// Runs `flapssm simulate`.
pub fn run(args: SimulateArgs) -> anyhow::Result<()> {
    if let (Some(rig), Some(dir)) = (&args.rig, &args.recordings) {
        return rehearse(&args, rig, dir);
    }
    let start = Instant::now();
    let inputs: Vec<&std::path::Path> = args.wing_config.iter().map(|p| p.as_path()).collect();
    flapssm_jobs::files::check_outputs(&[&args.out], &inputs)?;
    let fidelity: Option<Fidelity> = args
        .fidelity
        .map(|f| f.parse().context("parsing --fidelity"))
        .transpose()?;
    let wing = args
        .wing_config
        .as_deref()
        .map(|path| {
            flapssm_jobs::files::load_config(path)
                .with_context(|| format!("reading wing configuration {}", path.display()))
        })
        .transpose()?;
    let settings = SimulateSettings {
        n_trajectories: args.n.unwrap_or(548),
        n_train: args.n_train,
        seed: args.seed,
        wing,
        fidelity,
        noise_free: args.noise_free,
        flat: args.flat,
        wake_motion: args
            .wake
            .map(|w| w.parse().context("parsing --wake"))
            .transpose()?,
        inflow: args
            .inflow
            .map(|i| i.parse().context("parsing --inflow"))
            .transpose()?,
    };
    let cfg = settings.check()?;
    let bars = Bars::new();
    let progress: &dyn flapssm_jobs::Progress = if args.quiet { &NoProgress } else { &bars };
    let ds = match args.source {
        SourceArg::Generator => simulate(&cfg, None, progress),
        SourceArg::Paper => simulate_paper(&settings, progress),
    }
    .context("simulating the wing")?;
    let sim_s = start.elapsed().as_secs_f64();
    ds.save(&args.out)
        .with_context(|| format!("writing dataset {}", args.out.display()))?;
    let re = ds.meta.settings["mean_reynolds_number"]
        .as_f64()
        .unwrap_or(f64::NAN);
    println!(
        "wrote {}: {} {} trajectories ({} train) × {} samples, fidelity {:?}, {}, seed {}, mean Re {:.0}; \
         simulated in {:.2} s, total {:.2} s",
        args.out.display(),
        ds.trajectories.len(),
        match args.source {
            SourceArg::Generator => "generated",
            SourceArg::Paper => "measured (the paper's)",
        },
        ds.n_train,
        cfg.trajectories.sampling.n_samples,
        cfg.wing.fidelity,
        if args.noise_free {
            "noise-free"
        } else {
            "with sensor model"
        },
        args.seed,
        re,
        sim_s,
        start.elapsed().as_secs_f64()
    );
    Ok(())
}
