//! Integration tests on hand-made inputs with known answers: KDE of known distributions,
//! the control-authority pipeline on delayed copies, and every figure plus the report.

use std::f64::consts::PI;

use flapssm_analysis::authority::{
    AuthorityConfig, AuthoritySummary, AuthorityTrajectory, peak_table,
};
use flapssm_analysis::kde::{Kde2, Support, linspace};
use flapssm_analysis::plots::{authority as pa, errors as pe, timeseries as pt, training, wing3d};
use flapssm_analysis::report::{Figure, Report, Section, Table};
use flapssm_analysis::stats::Rows;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, Normal};

fn gaussian_sample(n: usize, mean: [f64; 2], sd: [f64; 2], seed: u64) -> Vec<[f64; 2]> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let z = Normal::new(0.0, 1.0).unwrap();
    (0..n)
        .map(|_| {
            [
                mean[0] + sd[0] * z.sample(&mut rng),
                mean[1] + sd[1] * z.sample(&mut rng),
            ]
        })
        .collect()
}

#[test]
fn kde_of_a_gaussian_sample_integrates_to_one_with_mode_at_the_mean() {
    let pts = gaussian_sample(3000, [0.4, 0.6], [0.08, 0.05], 11);
    let kde = Kde2::new(pts, [0.02, 0.02], [Support::UNBOUNDED; 2]).unwrap();
    let g = kde
        .grid(linspace(0.0, 1.0, 201), linspace(0.0, 1.0, 201))
        .unwrap();
    assert!(
        (g.integral() - 1.0).abs() < 2e-3,
        "integral {}",
        g.integral()
    );
    let [mx, my] = g.mode();
    // Sampling error of the mode of n = 3000 points: a few hundredths of a sd.
    assert!(
        (mx - 0.4).abs() < 0.03 && (my - 0.6).abs() < 0.02,
        "mode ({mx}, {my})"
    );
}

#[test]
fn hdr_of_a_standard_gaussian_holds_seventy_percent_at_the_analytic_threshold() {
    // For N(0, s²I) the 70 % HDR is {f ≥ 0.3/(2π s²)}; the KDE of a large sample with bandwidth
    // h estimates N(0, (1 + h²) I).
    let pts = gaussian_sample(4000, [0.0, 0.0], [1.0, 1.0], 5);
    let h = 0.15;
    let kde = Kde2::new(pts, [h, h], [Support::UNBOUNDED; 2]).unwrap();
    let g = kde
        .grid(linspace(-5.0, 5.0, 161), linspace(-5.0, 5.0, 161))
        .unwrap();
    let hdr = g.hdr(0.7, 1e-5).unwrap();
    let want = 0.3 / (2.0 * PI * (1.0 + h * h));
    assert!(
        (hdr.threshold / want - 1.0).abs() < 0.08,
        "threshold {} vs {want}",
        hdr.threshold
    );
    assert!((g.integral_above(hdr.threshold) - 0.7).abs() < 0.01);
    assert!(hdr.grid_mass <= 0.7 && hdr.grid_mass > 0.69);
}

#[test]
fn positive_support_reflection_keeps_mass_for_points_at_the_boundary() {
    // Exponential-like points piled up at lag 0 (as AoA → state peaks near zero delay).
    let mut rng = ChaCha8Rng::seed_from_u64(3);
    let e = rand_distr::Exp::new(10.0).unwrap();
    let pts: Vec<[f64; 2]> = (0..500)
        .map(|_| [e.sample(&mut rng), 0.5 + 0.3 * e.sample(&mut rng)])
        .collect();
    let kde = Kde2::positive(pts, 0.085).unwrap();
    let g = kde
        .grid(linspace(0.0, 2.0, 241), linspace(0.0, 2.0, 241))
        .unwrap();
    assert!((g.integral() - 1.0).abs() < 3e-3, "{}", g.integral());
}

/// Inputs: 3 smooth periodic signals; states: state j copies input j delayed by `delays[j]`
/// samples (state 2 = −input 0 delayed), plus independent noise.
fn delayed_copies(n_traj: usize, period: usize, delays: [usize; 3]) -> Vec<(Vec<f64>, Vec<f64>)> {
    let mut rng = ChaCha8Rng::seed_from_u64(9);
    let z = Normal::new(0.0, 0.05).unwrap();
    let t_len = 6 * period;
    (0..n_traj)
        .map(|i| {
            let ph = 0.37 * i as f64;
            let u = |k: usize, t: f64| -> f64 {
                let w = 2.0 * PI / period as f64;
                match k {
                    0 => (w * t + ph).sin() + 0.5 * (3.0 * w * t).cos(),
                    1 => (2.0 * w * t).cos() + 0.3 * (5.0 * w * t + ph).sin(),
                    _ => (w * t).cos().powi(3) + 0.4 * (4.0 * w * t).sin(),
                }
            };
            let mut ins = Vec::new();
            let mut sts = Vec::new();
            for t in 0..t_len {
                for k in 0..3 {
                    ins.push(u(k, t as f64) + z.sample(&mut rng));
                }
                let src = [0usize, 1, 0];
                for j in 0..3 {
                    let sign = if j == 2 { -1.0 } else { 1.0 };
                    sts.push(sign * u(src[j], t as f64 - delays[j] as f64) + z.sample(&mut rng));
                }
            }
            (ins, sts)
        })
        .collect()
}

#[test]
fn authority_recovers_known_delays_as_fractions_of_the_period() {
    let period = 50;
    let delays = [10usize, 5, 20];
    let data = delayed_copies(30, period, delays);
    let trajs: Vec<AuthorityTrajectory<'_>> = data
        .iter()
        .map(|(u, x)| AuthorityTrajectory {
            inputs: Rows::new(u, 3).unwrap(),
            states: Rows::new(x, 3).unwrap(),
            period_samples: period as f64,
        })
        .collect();
    let cfg = AuthorityConfig::default();
    let table = peak_table(&trajs, &cfg).unwrap();
    for i in 0..30 {
        assert_eq!(table.get(i, 0, 0).unwrap().lag_samples, 10);
        assert_eq!(table.get(i, 1, 1).unwrap().lag_samples, 5);
        let p = table.get(i, 2, 0).unwrap();
        assert_eq!(p.lag_samples, 20);
        assert!(p.r < -0.9, "anti-correlated copy keeps its sign: {}", p.r);
    }
    let names = |n: usize, p: &str| (1..=n).map(|i| format!("{p}{i}")).collect::<Vec<_>>();
    let s = AuthoritySummary::new(&table, names(3, "x"), names(3, "u"), &cfg).unwrap();
    let p = s.pair(0, 0);
    assert!((p.median_lag_cycles - 0.2).abs() < 1e-12 && p.lag_iqr_cycles.abs() < 1e-12);
    assert!(p.strong && p.median_abs_r > 0.9);
    // KDE mode within one grid step plus bandwidth smoothing of the true point (0.2, ~0.99).
    assert!(
        (p.mode_lag_cycles - 0.2).abs() < 0.02,
        "{}",
        p.mode_lag_cycles
    );
    assert!((s.pair(2, 0).median_lag_cycles - 0.4).abs() < 1e-12);
    assert!((s.pair(1, 1).median_lag_cycles - 0.1).abs() < 1e-12);
    // JSON and CSV round trip through files.
    let dir = tempfile::tempdir().unwrap();
    s.write_json(&dir.path().join("s.json")).unwrap();
    let back: AuthoritySummary =
        serde_json::from_str(&std::fs::read_to_string(dir.path().join("s.json")).unwrap()).unwrap();
    // serde_json parses floats to within one ulp, so compare with a tolerance.
    assert_eq!(back.pairs.len(), s.pairs.len());
    for (a, b) in back.pairs.iter().zip(&s.pairs) {
        assert_eq!(
            (a.state, a.input, a.n_points, a.strong),
            (b.state, b.input, b.n_points, b.strong)
        );
        for (x, y) in [
            (a.median_abs_r, b.median_abs_r),
            (a.median_lag_cycles, b.median_lag_cycles),
            (a.hdr_threshold, b.hdr_threshold),
            (a.mode_lag_cycles, b.mode_lag_cycles),
        ] {
            assert!((x - y).abs() <= 1e-12 * y.abs().max(1.0));
        }
    }
    s.write_csv(&dir.path().join("s.csv")).unwrap();
    let csv = std::fs::read_to_string(dir.path().join("s.csv")).unwrap();
    assert_eq!(csv.lines().count(), 1 + 9);
    // Bad shapes are errors, not panics.
    let bad = AuthorityTrajectory {
        inputs: Rows::new(&data[0].0[..30], 3).unwrap(),
        states: Rows::new(&data[0].1, 3).unwrap(),
        period_samples: 50.0,
    };
    assert!(peak_table(&[bad], &cfg).is_err());
}

#[test]
fn every_figure_and_the_report_are_written() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    // Fig. 4.
    let errs = vec![vec![-0.2, 0.1, 0.0, 0.3, -0.1]; 2];
    let obs = vec![vec![1.0, -1.0, 0.5, 0.2, 0.0]; 2];
    let m = [pe::ModelErrors {
        label: "A",
        errors: &errs,
    }];
    pe::error_histograms(
        &d.join("h.png"),
        &["F_x", "F_y"],
        &m,
        &[-1.0, -0.5, 0.0, 0.5, 1.0],
        95.0,
    )
    .unwrap();
    pe::error_histograms(
        &d.join("h.svg"),
        &["F_x", "F_y"],
        &m,
        &[-1.0, 0.0, 1.0],
        95.0,
    )
    .unwrap();
    let c = [pe::ModelCycleAverages {
        label: "A",
        observed: &obs,
        error: &errs,
    }];
    pe::cycle_average_scatter(&d.join("c.png"), &["F_x", "F_y"], &c, None, 95.0).unwrap();
    // Fig. 3.
    let t: Vec<f64> = linspace(0.0, 1.0, 41);
    let eu: Vec<[f64; 3]> = t
        .iter()
        .map(|s| [(2.0 * PI * s).sin(), 0.2 * (4.0 * PI * s).sin(), -1.0])
        .collect();
    let y: Vec<f64> = t.iter().map(|s| (2.0 * PI * s).cos()).collect();
    let sd = vec![0.1; 41];
    let cc = |label| pt::CoefficientCurves {
        label,
        cfx: &y,
        cfy: &y,
        cfx_std: Some(&sd),
        cfy_std: None,
    };
    let models = [cc("model")];
    let panel = pt::TrajectoryPanel {
        title: "t",
        t: &t,
        euler_rad: &eu,
        measured: cc("measured"),
        models: &models,
    };
    pt::time_histories(&d.join("t.png"), "t̂", &[panel], &pt::ChordSketch::default()).unwrap();
    let short = pt::TrajectoryPanel {
        t: &t[..10],
        ..panel
    };
    assert!(
        pt::time_histories(
            &d.join("bad.png"),
            "t̂",
            &[short],
            &pt::ChordSketch::default()
        )
        .is_err()
    );
    // Fig. 2C and training curves.
    wing3d::wing_motion_3d(
        &d.join("w.svg"),
        &[wing3d::WingPath {
            label: "w",
            euler_rad: &eu,
        }],
        &Default::default(),
    )
    .unwrap();
    training::training_curves(
        &d.join("l.png"),
        "loss",
        "nelbo",
        &[training::TrainingCurve {
            label: "a",
            epochs: &t,
            values: &y,
        }],
        false,
    )
    .unwrap();
    // Fig. 5.
    let data = delayed_copies(8, 40, [4, 8, 12]);
    let trajs: Vec<_> = data
        .iter()
        .map(|(u, x)| AuthorityTrajectory {
            inputs: Rows::new(u, 3).unwrap(),
            states: Rows::new(x, 3).unwrap(),
            period_samples: 40.0,
        })
        .collect();
    let cfg = AuthorityConfig {
        grid_points: 40,
        ..Default::default()
    };
    let table = peak_table(&trajs, &cfg).unwrap();
    let names: Vec<String> = ["a", "b", "c"].map(String::from).to_vec();
    let s = AuthoritySummary::new(&table, names.clone(), names, &cfg).unwrap();
    pa::hdr_contours(&d.join("k.png"), &s).unwrap();
    pa::pair_scatter(&d.join("p.png"), &table, &s, 1).unwrap();
    pa::summary_grid(&d.join("g.svg"), &s).unwrap();
    assert!(pa::pair_scatter(&d.join("p.png"), &table, &s, 3).is_err());
    assert!(
        pe::error_histograms(&d.join("x.pdf"), &["F_x", "F_y"], &m, &[-1.0, 1.0], 95.0).is_err()
    );
    for f in ["h.png", "c.png", "t.png", "l.png", "k.png", "p.png"] {
        let b = std::fs::read(d.join(f)).unwrap();
        assert_eq!(&b[..8], b"\x89PNG\r\n\x1a\n", "{f}");
    }
    for f in ["h.svg", "w.svg", "g.svg"] {
        assert!(
            std::fs::read_to_string(d.join(f)).unwrap().contains("<svg"),
            "{f}"
        );
    }
    // Report: PNG as base64, SVG inline, text escaped.
    let rep = Report {
        title: "T <1>".into(),
        headline: vec![("rmse".into(), "0.1".into())],
        sections: vec![Section {
            heading: "S".into(),
            tables: vec![Table {
                caption: "c".into(),
                header: vec!["a".into()],
                rows: vec![vec!["1".into()]],
            }],
            figures: vec![
                Figure {
                    caption: "png".into(),
                    path: d.join("k.png"),
                },
                Figure {
                    caption: "svg".into(),
                    path: d.join("g.svg"),
                },
            ],
            ..Default::default()
        }],
        config: serde_json::json!({"bandwidth": 0.085}),
        ..Default::default()
    };
    rep.write(&d.join("r.html")).unwrap();
    let html = std::fs::read_to_string(d.join("r.html")).unwrap();
    assert!(html.contains("data:image/png;base64,iVBORw0KGgo"));
    assert!(html.contains("<svg") && html.contains("T &lt;1&gt;") && html.contains("0.085"));
    assert!(!html.contains("src=\"http"));
    let missing = Report {
        sections: vec![Section {
            figures: vec![Figure {
                caption: "x".into(),
                path: d.join("nope.png"),
            }],
            ..Default::default()
        }],
        ..Default::default()
    };
    assert!(missing.write(&d.join("r2.html")).is_err());
}
