//! `flapssm demo`: simulate, fit the LRQSM, train the PR-SSM, evaluate and report, resumably.

use flapssm_jobs::presets::Preset;
use std::path::PathBuf;

use anyhow::Context;
use clap::Args;
use flapssm_jobs::JobError;
use flapssm_jobs::demo::{DEMO_FILES, DemoConfig, run_demo};
use flapssm_jobs::evaluate::EVALUATION_FILES;
use flapssm_jobs::files::check_output_dir;

use crate::cmd::choices::{BestByArg, ObjectiveArg, SourceArg, TrainingChoices};
use crate::progress::{Bars, stop_flag};

/// Run the whole pipeline on a simulated wing.
#[derive(Args)]
pub struct DemoArgs {
    /// Output folder (stages already there with the same configuration are skipped).
    #[arg(long, default_value = "flapssm-demo")]
    out: PathBuf,
    /// The paper's configuration (548 trajectories, D_x 12, M 100, 30 particles, 1000 epochs;
    /// hours) instead of the default 15-minute one.
    #[arg(long)]
    full: bool,
    /// The training preset of --full: paper (the published schedule, the default; hours) or
    /// paper-fast (the paper's model trained for time to quality, minutes; docs/training.md).
    /// The protocol stays the published one (all 512 fitted, the lowest training loss kept).
    #[arg(long, requires = "full")]
    preset: Option<Preset>,
    /// Master seed (simulation, training, prediction).
    #[arg(long, default_value_t = 0)]
    seed: u64,
    /// Override the number of trajectories (train/test split scaled as published).
    #[arg(long)]
    trajectories: Option<usize>,
    /// Override the number of training epochs.
    #[arg(long)]
    epochs: Option<u64>,
    /// Override the latent state dimension D_x.
    #[arg(long)]
    dx: Option<usize>,
    /// Override the number of inducing points M.
    #[arg(long)]
    inducing: Option<usize>,
    /// Override the number of training particles.
    #[arg(long)]
    particles: Option<usize>,
    /// Override the virtual wing's aerodynamic fidelity: l0 (quasi-steady, the default wing of
    /// the demo and of `simulate`), l1 (unsteady low-order), l2 (vortex strips), l3 (vortex
    /// lattice).
    #[arg(long, value_name = "LEVEL")]
    fidelity: Option<String>,
    /// Check the dataset against this reference model of the rig (the published
    /// …/bayiz2021-prssm/reference.npz, or a model imported from it): the rig agreement heads
    /// the report and enters summary.json (needs the paper's trajectories: --full or --source
    /// paper; docs/rig-agreement.md).
    #[arg(long, value_name = "FILE")]
    reference: Option<PathBuf>,
    /// Override the fraction of the training trajectories held out for validation (default
    /// 0.1; with --full 0, the published protocol).
    #[arg(long, value_name = "F")]
    val_fraction: Option<f64>,
    /// Override how the best model is chosen: rmse (validation, the default) or training-loss
    /// (the published code's, the default with --full).
    #[arg(long, value_enum, value_name = "RULE")]
    best_by: Option<BestByArg>,
    /// Override the training objective: standard (the default) or published-code (the
    /// authors' objective and shared noise draws).
    #[arg(long, value_enum, value_name = "FORM")]
    objective: Option<ObjectiveArg>,
    #[command(flatten)]
    training: TrainingChoices,
    /// Override where the trajectories come from: generator (the default) or paper (the
    /// paper's measured trajectories, the default with --full; the first --trajectories).
    #[arg(long, value_enum, value_name = "SOURCE")]
    source: Option<SourceArg>,
}

/// Runs `flapssm demo`.
pub fn run(args: DemoArgs) -> anyhow::Result<()> {
    check_output_dir(&args.out, &DEMO_FILES, &[])?;
    if args.out.is_dir() {
        check_output_dir(&args.out.join("eval"), &EVALUATION_FILES, &[])?;
    }
    let mut cfg = if args.full {
        DemoConfig::full(args.seed)
    } else {
        DemoConfig::default_for(args.seed)
    };
    if let Some(p) = args.preset {
        cfg.training.preset = p;
    }
    if let Some(n) = args.trajectories {
        let t = &mut cfg.simulation.trajectories;
        t.n_trajectories = n;
        t.n_train = flapssm_wing::trajectories::default_n_train(n);
    }
    if let Some(e) = args.epochs {
        cfg.training.epochs = Some(e);
    }
    if let Some(d) = args.dx {
        cfg.training.dx = Some(d);
    }
    if let Some(m) = args.inducing {
        cfg.training.inducing = Some(m);
    }
    if let Some(p) = args.particles {
        cfg.training.particles = Some(p);
    }
    if let Some(f) = &args.fidelity {
        cfg.simulation.wing.fidelity = f.parse().context("parsing --fidelity")?;
    }
    if let Some(source) = args.source {
        cfg.source = source.into();
    }
    if let Some(v) = args.val_fraction {
        cfg.training.val_fraction = v;
    }
    if let Some(b) = args.best_by {
        cfg.training.best_by = b.into();
    }
    if let Some(o) = args.objective {
        cfg.training.objective = o.into();
    }
    args.training.apply(&mut cfg.training);
    cfg.rig_reference = args.reference;
    let stop = stop_flag()?;
    let bars = Bars::new();
    let s = run_demo(&args.out, &cfg, &bars, Some(&stop))
        .map_err(|e| match e {
            JobError::Interrupted { .. } => {
                anyhow::anyhow!("{e}; rerun the same command to resume")
            }
            e => e.into(),
        })
        .with_context(|| format!("demo in {}", args.out.display()))?;
    let f = |v: &[f64]| {
        v.iter()
            .map(|x| format!("{x:.3}"))
            .collect::<Vec<_>>()
            .join(" ")
    };
    println!(
        "{} configuration, {} train / {} test trajectories",
        s.config.name, s.n_train, s.n_test
    );
    println!("the paper beside flapssm (paper | flapssm | flapssm vs paper):");
    for c in &s.paper_comparison {
        println!(
            "  {}\n      {} | {} | {}",
            c.endpoint,
            c.paper,
            c.flapssm,
            c.relation.map_or("—", |r| r.words())
        );
    }
    println!("test RMSE (σ)         {}", s.outputs.join(" "));
    println!("  PR-SSM              {}", f(&s.prssm_test_rmse));
    println!("  LRQSM               {}", f(&s.lrqsm_test_rmse));
    for b in &s.baselines {
        println!("  {:<19} {}", b.model, f(&b.test_rmse));
    }
    let better = s.rmse_ratio.iter().filter(|r| **r < 1.0).count();
    let lrqsm_over_prssm: Vec<f64> = s.rmse_ratio.iter().map(|r| 1.0 / r).collect();
    println!(
        "LRQSM / PR-SSM        {}  (PR-SSM more accurate on {better} of {} outputs; \
         the paper's examples: 1.7–3× on C_Fx, 2.5–4× on C_Fy)",
        f(&lrqsm_over_prssm),
        s.rmse_ratio.len()
    );
    if let Some(rig) = &s.rig_agreement {
        let r = |a: &flapssm_jobs::rig::SetAgreement| {
            f(&a.channels.iter().map(|c| c.r).collect::<Vec<_>>())
        };
        println!("rig agreement r (train) {}", r(&rig.train));
        if let Some(test) = &rig.test {
            println!("rig agreement r (test)  {}", r(test));
        }
    }
    println!(
        "AoA / a_x on the output states: median lag {:.3} / {:.3}, KDE-mode lag {:.3} / {:.3} cycles",
        s.aoa_median_lag_cycles,
        s.a_x_median_lag_cycles,
        s.aoa_mode_lag_cycles,
        s.a_x_mode_lag_cycles
    );
    for t in &s.timings {
        println!(
            "  {:<10} {:>8.1} s{}",
            t.stage,
            t.wall_s,
            if t.skipped {
                " (skipped, earlier run)"
            } else {
                ""
            }
        );
    }
    println!("total {:.1} s", s.total_wall_s);
    println!(
        "report {}; summary {}",
        args.out.join(&s.report).display(),
        args.out.join("summary.json").display()
    );
    Ok(())
}
