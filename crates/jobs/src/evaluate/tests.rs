//! The evaluation pipeline against independent computations and its settings' checks.

use super::*;
use crate::models::arx::checked;
use crate::models::lrqsm::LrqsmLoadModel;
use crate::models::prssm::PrssmLoadModel;
use crate::models::{Fit, ModelPrediction};
use crate::progress::NoProgress;
use crate::test_data::tiny_dataset;
use crate::train::{TrainingOptions, train_prssm};
use flapssm_analysis::authority::AuthorityConfig;
use flapssm_qs::arx::ArxSettings;
use flapssm_wing::cycles::{published_u_ref, published_window};

/// The pipeline's LRQSM errors agree with the qs crate's own RMSE (computed there from raw
/// loads divided by σ), and its sums are consistent: overall² = mean of per-output RMSE²,
/// ratio = PR-SSM / LRQSM, the windows are the published ones.
#[test]
fn metrics_agree_with_independent_computations() {
    let ds = tiny_dataset();
    let lrqsm =
        flapssm_qs::lrqsm::fit_dataset(&ds, Default::default(), &Default::default(), "tiny")
            .unwrap();
    let q = flapssm_qs::lrqsm::predict_dataset(&lrqsm, &ds, lrqsm.prediction_intercept).unwrap();
    let opts = TrainingOptions {
        dx: Some(5),
        inducing: Some(6),
        particles: Some(3),
        epochs: Some(1),
        val_fraction: 0.0,
        ..TrainingOptions::default()
    };
    let plan = opts.check().unwrap();
    let fit = train_prssm(ds.train(), &plan, None, None, None, &NoProgress, None).unwrap();
    let dir = std::env::temp_dir().join(format!("flapssm-pipeline-{}", std::process::id()));
    let eo = EvalOptions {
        start_sample: 0,
        particles: 3,
        authority: AuthorityConfig {
            grid_points: 20,
            ..AuthorityConfig::default()
        },
        ..EvalOptions::default()
    };
    let prssm = PrssmLoadModel::new(&fit.best, &ds, eo.particles, eo.seed).unwrap();
    let lq = LrqsmLoadModel::new(&lrqsm).unwrap();
    let arx = checked(ArxSettings::default())
        .unwrap()
        .fit(&ds, &NoProgress)
        .unwrap();
    let r = evaluate(
        &ds,
        "tiny",
        &[&prssm, &lq, &arx],
        &eo,
        &ReportContext::default(),
        &dir,
        &NoProgress,
    )
    .unwrap();
    assert_eq!(
        r.models.iter().map(|m| m.key.as_str()).collect::<Vec<_>>(),
        ["prssm", "lrqsm", "arx"]
    );
    let (rp, rl) = (r.model("prssm").unwrap(), r.model("lrqsm").unwrap());
    let lt = rl.test.as_ref().unwrap();
    let qt = q.rmse_test.as_ref().unwrap();
    for j in 0..5 {
        assert!((lt.rmse_standardized[j] - qt.standardized[j]).abs() < 1e-10);
        assert!(
            (rl.train.rmse_standardized[j] - q.rmse_train.as_ref().unwrap().standardized[j]).abs()
                < 1e-10
        );
    }
    let pt = rp.test.as_ref().unwrap();
    let ms: f64 = pt.rmse_standardized.iter().map(|v| v * v).sum::<f64>() / 5.0;
    assert!((pt.overall_rmse_standardized - ms.sqrt()).abs() < 1e-12);
    for j in 0..5 {
        assert_eq!(
            r.rmse_ratio[j],
            pt.rmse_standardized[j] / lt.rmse_standardized[j]
        );
    }
    for (t, m) in ds.trajectories.iter().zip(&r.trajectories) {
        let stroke: Vec<f64> = t.euler_rad.iter().map(|e| e[0]).collect();
        let w = published_window(&stroke).unwrap();
        assert_eq!((m.window_start, m.period_samples), (w.first, w.duration));
    }
    // 4 inputs on x1..x5; with D_x 5 there is no x7..x12.
    assert_eq!(r.authority_findings.len(), 20);
    // The paper beside us: each endpoint from the report's own numbers.
    let row = |prefix: &str| {
        r.paper_comparison
            .iter()
            .find(|c| c.endpoint.starts_with(prefix))
            .unwrap_or_else(|| panic!("no row {prefix}: {:#?}", r.paper_comparison))
    };
    let ex = &r.example_trajectories;
    assert!(!ex.is_empty() && ex.iter().all(|&i| i >= r.n_train));
    let cfx: Vec<f64> = ex
        .iter()
        .map(|&i| r.trajectories[i].models[0].cycle_rmse_cf[0])
        .collect();
    let (lo, hi) = (
        cfx.iter().copied().fold(f64::INFINITY, f64::min),
        cfx.iter().copied().fold(0.0, f64::max),
    );
    let fig3 = row("C_Fx RMSE, PR-SSM");
    assert!(
        fig3.flapssm.starts_with(&format!("{lo:.2}–{hi:.2} (")),
        "{fig3:?}"
    );
    assert_eq!(fig3.paper, "0.11–0.21");
    let bound = pt
        .error_interval
        .iter()
        .map(|i| i.lo.abs().max(i.hi.abs()))
        .fold(0.0, f64::max);
    let fig4a = row("95 % error bounds over the 5 outputs (σ), PR-SSM, test");
    assert!(
        fig4a.flapssm.ends_with(&format!("–{bound:.2}")),
        "{fig4a:?}"
    );
    let c = &rl.cycle_average_error_interval_all[1];
    let fig4b = row("95 % interval of half-stroke-average C_Fy errors, LRQSM");
    assert!(
        fig4b
            .flapssm
            .starts_with(&format!("[{:.2}, {:.2}]", c.lo, c.hi))
    );
    assert_eq!(fig4b.paper, "[-0.20, 0.20]");
    for prefix in [
        "C_Fy RMSE, LRQSM",
        "C_Fx RMSE ratio LRQSM / PR-SSM",
        "C_Fy RMSE ratio LRQSM / PR-SSM",
        "95 % error bounds over the 5 outputs (σ), LRQSM, training",
        "AoA → the outputs",
        "a_x → the outputs",
        "d²α/dt² → the outputs",
        "prediction of one trajectory, PR-SSM",
    ] {
        row(prefix);
    }
    assert!(
        r.paper_comparison
            .iter()
            .all(|c| !c.endpoint.contains("x7"))
    );
    assert!(
        r.prediction_timing
            .iter()
            .any(|t| t.model == "prssm" && t.median_ms > 0.0)
    );
    let written: EvaluationReport =
        serde_json::from_slice(&std::fs::read(dir.join("metrics.json")).unwrap()).unwrap();
    assert_eq!(written.paper_comparison, r.paper_comparison);
    for f in &r.files {
        assert!(dir.join(f).exists(), "{f}");
    }
    let csv = std::fs::read_to_string(dir.join("trajectories.csv")).unwrap();
    assert!(csv.lines().next().unwrap().ends_with(
        "prssm_rmse_cfx,prssm_rmse_cfy,lrqsm_rmse_cfx,lrqsm_rmse_cfy,arx_rmse_cfx,arx_rmse_cfy,\
         prssm_overall_rmse_std,lrqsm_overall_rmse_std,arx_overall_rmse_std"
    ));
    std::fs::remove_dir_all(&dir).ok();

    // One model without latent states: no authority analysis, no Fig. 5, no ratio.
    let dir = std::env::temp_dir().join(format!("flapssm-one-model-{}", std::process::id()));
    let r = evaluate(
        &ds,
        "tiny",
        &[&arx],
        &eo,
        &ReportContext::default(),
        &dir,
        &NoProgress,
    )
    .unwrap();
    assert!(r.authority_findings.is_empty() && r.rmse_ratio.is_empty());
    assert!(
        !r.files
            .iter()
            .any(|f| f.starts_with("fig5") || f.starts_with("authority"))
    );
    for f in &r.files {
        assert!(dir.join(f).exists(), "{f}");
    }
    std::fs::remove_dir_all(&dir).ok();
    let e = evaluate(
        &ds,
        "tiny",
        &[],
        &eo,
        &ReportContext::default(),
        &dir,
        &NoProgress,
    )
    .unwrap_err();
    assert!(e.to_string().contains("models to evaluate"), "{e}");
}

#[test]
fn evaluation_settings_are_checked_and_named() {
    let err = |o: EvalOptions| o.check().unwrap_err().to_string();
    assert!(EvalOptions::default().check().is_ok());
    let e = err(EvalOptions {
        particles: 0,
        ..EvalOptions::default()
    });
    assert!(e.contains("setting particles = 0"), "{e}");
    let e = err(EvalOptions {
        level: 100.0,
        ..EvalOptions::default()
    });
    assert!(e.contains("setting level = 100"), "{e}");
    let e = err(EvalOptions {
        authority: AuthorityConfig {
            hdr_mass: 1.5,
            ..AuthorityConfig::default()
        },
        ..EvalOptions::default()
    });
    assert!(e.contains("authority.hdr_mass"), "{e}");
}

/// A rig's dataset is scored in the rig's coefficients: ½ρSU_ref² with its own density, area and
/// U_ref radius (and c̄ for the moments), never the paper's — the paper's would be a factor
/// ρ_paper S_paper / (ρ S) ≈ 1.8 (and another U_ref) away.
#[test]
fn coefficients_use_the_rigs_geometry() {
    use crate::own_rig::{RIG_TEMPLATE, RehearsalSettings, parse_rig, rehearse_rig};
    let dir = tempfile::tempdir().unwrap();
    let source = std::path::Path::new("rig.toml");
    let desc = parse_rig(RIG_TEMPLATE, source).unwrap();
    let settings = RehearsalSettings {
        n_recordings: 2,
        motion_s: 8.0,
        n_train: Some(1),
        ..RehearsalSettings::default()
    };
    let ds = rehearse_rig(&desc, source, &settings, dir.path(), &NoProgress).unwrap();
    let geometry = desc.geometry();
    assert_eq!(ds.meta.wing, geometry);
    assert_ne!(ds.meta.wing, flapssm_wing::dataset::WingGeometry::default());
    // One "model" that predicts the measured loads.
    let predictions: Vec<ModelPrediction> = ds
        .trajectories
        .iter()
        .map(|t| ModelPrediction {
            mean: t.outputs.as_ref().unwrap().as_flattened().to_vec(),
            var: None,
            latent_mean: Vec::new(),
            wall_s: 0.0,
        })
        .collect();
    let prep = scores::prepare(&ds, &[predictions]).unwrap();
    for (t, p) in ds.trajectories.iter().zip(&prep) {
        // U_ref at the rig's radius (the tip, 0.15 m), not the paper's 0.235 m.
        let (u_ref, _) = published_u_ref(&t.euler_rad, ds.dt_s, geometry.u_ref_radius_m).unwrap();
        assert_eq!(t.u_ref_m_s, u_ref);
        let q_s = 0.5 * 1000.0 * 0.12 * 0.04 * u_ref * u_ref;
        let y = t.outputs.as_ref().unwrap();
        for (k, row) in y.iter().enumerate() {
            let c = &p.measured_c[5 * k..5 * k + 5];
            assert!((c[0] - row[0] / q_s).abs() <= 1e-12 * (1.0 + c[0].abs()));
            assert!((c[3] - row[3] / (q_s * 0.04 * 1000.0)).abs() <= 1e-12 * (1.0 + c[3].abs()));
            assert_eq!(&p.models[0].c[5 * k..5 * k + 5], c);
        }
    }
}
