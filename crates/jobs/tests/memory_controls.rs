//! The PR-SSM against the static nonlinear baseline (GP-static) on wings whose memory is known,
//! a small configuration of the paper-scale runs in docs/results.md ("Conclusions that could
//! fail"): 64 generated trajectories on a flat stroke plane (48 training, the last 16 the test
//! set), noise-free, the PR-SSM trained 100 epochs with `--preset paper-fast`.
//!
//! - Negative control: on L0 (quasi-steady, no memory at all) the PR-SSM must not beat
//!   GP-static significantly on any output (measured: it is worse on all five, F_x +0.067
//!   [+0.052, +0.083] σ).
//! - Positive control: on L1 (Wagner lift: the circulation lags the motion) it must, on F_x
//!   (measured −0.062 [−0.095, −0.036] σ; also M_x and M_y).
//!
//! The paired 95 % bootstrap over the test trajectories decides "significantly". A PR-SSM that
//! learns no memory fails the positive control; a comparison that credits the PR-SSM with
//! memory it cannot have fails the negative one. At the paper's scale it does: trained on 512
//! trajectories the PR-SSM beats GP-static on L0 too (docs/results.md, "The PR-SSM against the
//! static baseline where the memory is known"), so these tests hold the comparison at a size
//! where the PR-SSM is not yet the better static regressor. The same runs from the command line:
//! `flapssm simulate --fidelity l0 --noise-free --flat --n 64 --n-train 48 --seed 3`, `flapssm
//! train --preset paper-fast --epochs 100 --seed 1`, `flapssm evaluate --baseline gp-static`.

use flapssm_jobs::NoProgress;
use flapssm_jobs::evaluate::{EvalOptions, EvaluationModels, evaluate_models};
use flapssm_jobs::presets::Preset;
use flapssm_jobs::simulate::{SimulateSettings, simulate};
use flapssm_jobs::train::{TrainingOptions, train_in_memory};
use flapssm_wing::virtual_wing::Fidelity;

/// PR-SSM minus GP-static test RMSE per output (σ), and whether each interval excludes zero.
fn prssm_minus_gp_static(fidelity: Fidelity) -> Vec<(f64, bool)> {
    let settings = SimulateSettings {
        n_trajectories: 64,
        n_train: Some(48),
        seed: 3,
        fidelity: Some(fidelity),
        noise_free: true,
        flat: true,
        ..SimulateSettings::default()
    };
    let ds = simulate(&settings.check().unwrap(), None, &NoProgress).unwrap();
    let plan = TrainingOptions {
        preset: Preset::PaperFast,
        epochs: Some(100),
        seed: 1,
        ..TrainingOptions::default()
    }
    .check()
    .unwrap();
    let model = train_in_memory(&ds, &plan, &NoProgress, None).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let baselines = ["gp-static".to_string()];
    let models = EvaluationModels {
        prssm: Some(&model),
        baselines: &baselines,
        ..EvaluationModels::default()
    };
    let report = evaluate_models(
        &ds,
        "memory control",
        &models,
        &EvalOptions::default(),
        serde_json::Value::Null,
        dir.path(),
        &NoProgress,
    )
    .unwrap();
    // D_x 12: the paper's latent rows restated on the 7-dimensional hidden subspace.
    assert_eq!(report.hidden_authority.len(), 7);
    assert!(
        report
            .hidden_authority
            .iter()
            .all(|h| h.subspace.dimension == 7)
    );
    let c = &report.comparisons[0];
    assert_eq!(
        (c.a.as_str(), c.b.as_str(), c.split.as_str()),
        ("prssm", "gp-static", "test")
    );
    c.outputs
        .iter()
        .map(|d| (d.difference, d.significant))
        .collect()
}

#[test]
fn without_memory_the_prssm_does_not_beat_the_static_baseline() {
    let d = prssm_minus_gp_static(Fidelity::L0);
    for (j, (diff, significant)) in d.iter().enumerate() {
        assert!(
            !(*significant && *diff < 0.0),
            "output {j}: PR-SSM better by {diff:.3} σ, significantly, on a wing without memory"
        );
    }
}

#[test]
fn with_wagner_memory_the_prssm_beats_the_static_baseline() {
    let d = prssm_minus_gp_static(Fidelity::L1);
    let (fx, significant) = d[0];
    assert!(
        significant && fx < 0.0,
        "F_x: PR-SSM − GP-static {fx:.3} σ (significant: {significant}): {d:?}"
    );
}
