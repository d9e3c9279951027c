//! Renders every figure and the HTML report from synthetic, seeded data, for visual checks:
//! `cargo run --release -p flapssm-analysis --example gallery -- <out_dir> [seed]`.
//!
//! The data are made up (harmonic wing motions, a "good" and a "poor" model of a made-up load);
//! only the plumbing and the look of the figures are exercised.

use std::f64::consts::PI;
use std::path::PathBuf;

use flapssm_analysis::authority::{
    AuthorityConfig, AuthoritySummary, AuthorityTrajectory, peak_table,
};
use flapssm_analysis::cycles_avg::{CycleAverageErrors, CycleWindow};
use flapssm_analysis::metrics::{Histogram, PooledErrors};
use flapssm_analysis::plots::{authority as pa, errors as pe, timeseries as pt, training, wing3d};
use flapssm_analysis::report::{Figure, Report, Section, Table};
use flapssm_analysis::stats::Rows;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, Normal};

struct Traj {
    euler: Vec<[f64; 3]>,
    inputs: Vec<f64>,   // n × 7
    states: Vec<f64>,   // n × 12
    measured: Vec<f64>, // n × 5 (coefficients)
    good: Vec<f64>,
    good_std: Vec<f64>,
    poor: Vec<f64>,
    period: usize,
}

fn make(i: usize, n: usize, rng: &mut ChaCha8Rng) -> Traj {
    let noise = Normal::new(0.0, 1.0).unwrap();
    let period = 60 + (i * 7) % 30;
    let w = 2.0 * PI / period as f64;
    let (a_phi, a_psi, a_alpha) = (1.0 + 0.3 * (i % 3) as f64, 0.15 + 0.1 * (i % 4) as f64, 0.8);
    let shape = (i % 3 + 1) as f64; // deviation harmonic: 2 → figure eight, 1 → oval
    let mut t = Traj {
        euler: Vec::new(),
        inputs: Vec::new(),
        states: Vec::new(),
        measured: Vec::new(),
        good: Vec::new(),
        good_std: Vec::new(),
        poor: Vec::new(),
        period,
    };
    for k in 0..n {
        let s = w * k as f64;
        let phi = a_phi * s.sin();
        let psi = a_psi * (shape * s).sin();
        let alpha = -PI / 2.0 + a_alpha * (s + 0.3).cos();
        t.euler.push([phi, psi, alpha]);
        let speed = (a_phi * w * s.cos()).abs() + 0.05;
        let aoa = (PI / 2.0 - (alpha + PI / 2.0).abs()).abs();
        let inputs = [
            aoa,
            speed,
            -a_phi * w * w * s.sin(),
            0.3 * (2.0 * s).cos(),
            speed * speed,
            -a_alpha * w * (s + 0.3).sin(),
            -a_alpha * w * w * (s + 0.3).cos(),
        ];
        t.inputs.extend(inputs);
        let delayed = |d: f64, h: f64| (h * (s - w * d)).sin();
        for j in 0..12 {
            t.states
                .push(delayed(3.0 + j as f64, 1.0 + (j % 3) as f64) + 0.2 * noise.sample(rng));
        }
        let cfx = 2.5 * (2.0 * aoa).sin() * (s.cos()).signum() + 0.4 * delayed(12.0, 1.0);
        let cfy = 0.4 * (aoa).cos() * s.cos();
        let meas = [cfx, cfy, 3.0 * cfx, 2.5 * cfy, 0.3 * cfx];
        for (m, v) in meas.iter().enumerate() {
            t.measured.push(v + 0.03 * noise.sample(rng));
            t.good
                .push(v + 0.08 * noise.sample(rng) + 0.05 * (s * 3.0).sin());
            t.good_std.push(0.08);
            let bias = if m == 1 { 0.4 * v } else { 0.15 * v };
            t.poor.push(v - bias + 0.2 * noise.sample(rng));
        }
    }
    t
}

fn rows(v: &[f64], c: usize) -> Rows<'_> {
    Rows::new(v, c).unwrap()
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    let out = PathBuf::from(args.get(1).map(String::as_str).unwrap_or("target/gallery"));
    let seed: u64 = args.get(2).map(|s| s.parse()).transpose()?.unwrap_or(1);
    std::fs::create_dir_all(&out)?;
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let n = 377;
    let trajs: Vec<Traj> = (0..40).map(|i| make(i, n, &mut rng)).collect();
    let names5 = ["C_Fx", "C_Fy", "C_Mx", "C_My", "C_Mz"];

    // Fig. 4A.
    let meas: Vec<Rows<'_>> = trajs.iter().map(|t| rows(&t.measured, 5)).collect();
    let good: Vec<Rows<'_>> = trajs.iter().map(|t| rows(&t.good, 5)).collect();
    let poor: Vec<Rows<'_>> = trajs.iter().map(|t| rows(&t.poor, 5)).collect();
    let eg = PooledErrors::new(&meas, &good, 0)?;
    let ep = PooledErrors::new(&meas, &poor, 0)?;
    let edges = Histogram::uniform_edges(-1.1, 1.1, 0.02);
    let f_hist = out.join("fig4a_histograms.png");
    pe::error_histograms(
        &f_hist,
        &names5,
        &[
            pe::ModelErrors {
                label: "PR-SSM",
                errors: &eg.errors,
            },
            pe::ModelErrors {
                label: "LRQSM",
                errors: &ep.errors,
            },
        ],
        &edges,
        95.0,
    )?;
    pe::error_histograms(
        &out.join("fig4a_histograms.svg"),
        &names5,
        &[pe::ModelErrors {
            label: "PR-SSM",
            errors: &eg.errors,
        }],
        &edges,
        95.0,
    )?;

    // Fig. 4B.
    let windows: Vec<CycleWindow> = trajs
        .iter()
        .map(|t| CycleWindow::published(n, t.period).unwrap())
        .collect();
    let cg = CycleAverageErrors::new(&meas, &good, &windows)?;
    let cp = CycleAverageErrors::new(&meas, &poor, &windows)?;
    let f_cyc = out.join("fig4b_cycle_averages.png");
    pe::cycle_average_scatter(
        &f_cyc,
        &names5,
        &[
            pe::ModelCycleAverages {
                label: "PR-SSM",
                observed: &cg.observed,
                error: &cg.error,
            },
            pe::ModelCycleAverages {
                label: "LRQSM",
                observed: &cp.observed,
                error: &cp.error,
            },
        ],
        Some(&[0.75, 0.75, 2.0, 2.0, 2.0]),
        95.0,
    )?;

    // Fig. 3.
    let col = |v: &Vec<f64>, j: usize, w: &CycleWindow| -> Vec<f64> {
        w.range(n).unwrap().map(|k| v[k * 5 + j]).collect()
    };
    let sel = [0usize, 1, 2, 5];
    let data: Vec<_> = sel
        .iter()
        .map(|&i| {
            let t = &trajs[i];
            let w = windows[i];
            let that: Vec<f64> = (0..=w.duration)
                .map(|k| k as f64 / w.duration as f64)
                .collect();
            let eu: Vec<[f64; 3]> = w.range(n).unwrap().map(|k| t.euler[k]).collect();
            (
                that,
                eu,
                [col(&t.measured, 0, &w), col(&t.measured, 1, &w)],
                [col(&t.good, 0, &w), col(&t.good, 1, &w)],
                [col(&t.good_std, 0, &w), col(&t.good_std, 1, &w)],
                [col(&t.poor, 0, &w), col(&t.poor, 1, &w)],
                format!("trajectory #{i}"),
            )
        })
        .collect();
    let models: Vec<[pt::CoefficientCurves<'_>; 2]> = data
        .iter()
        .map(|d| {
            [
                pt::CoefficientCurves {
                    label: "PR-SSM ±2σ",
                    cfx: &d.3[0],
                    cfy: &d.3[1],
                    cfx_std: Some(&d.4[0]),
                    cfy_std: Some(&d.4[1]),
                },
                pt::CoefficientCurves {
                    label: "LRQSM",
                    cfx: &d.5[0],
                    cfy: &d.5[1],
                    cfx_std: None,
                    cfy_std: None,
                },
            ]
        })
        .collect();
    let panels: Vec<pt::TrajectoryPanel<'_>> = data
        .iter()
        .zip(&models)
        .map(|(d, m)| pt::TrajectoryPanel {
            title: &d.6,
            t: &d.0,
            euler_rad: &d.1,
            measured: pt::CoefficientCurves {
                label: "measured",
                cfx: &d.2[0],
                cfy: &d.2[1],
                cfx_std: None,
                cfy_std: None,
            },
            models: m,
        })
        .collect();
    let f_ts = out.join("fig3_time_histories.png");
    pt::time_histories(&f_ts, "t̂ (cycles)", &panels, &pt::ChordSketch::default())?;

    // Fig. 2C.
    let labels: Vec<String> = sel.iter().map(|i| format!("trajectory #{i}")).collect();
    let paths: Vec<wing3d::WingPath<'_>> = sel
        .iter()
        .zip(&labels)
        .map(|(&i, l)| wing3d::WingPath {
            label: l,
            euler_rad: &trajs[i].euler[n - 1 - trajs[i].period..],
        })
        .collect();
    let f_3d = out.join("fig2c_wing_motion.png");
    wing3d::wing_motion_3d(&f_3d, &paths, &wing3d::WingSketchGeometry::default())?;

    // Fig. 5.
    let at: Vec<AuthorityTrajectory<'_>> = trajs
        .iter()
        .map(|t| AuthorityTrajectory {
            inputs: rows(&t.inputs, 7),
            states: rows(&t.states, 12),
            period_samples: t.period as f64,
        })
        .collect();
    let cfg = AuthorityConfig::default();
    let table = peak_table(&at, &cfg)?;
    let input_names: Vec<String> = ["AoA", "|v|", "a_x", "a_y", "a_z", "dα/dt", "d²α/dt²"]
        .iter()
        .map(|s| s.to_string())
        .collect();
    let state_names: Vec<String> = (1..=12).map(|j| format!("x{j}")).collect();
    let summary = AuthoritySummary::new(&table, state_names.clone(), input_names.clone(), &cfg)?;
    summary.write_json(&out.join("fig5_summary.json"))?;
    summary.write_csv(&out.join("fig5_summary.csv"))?;
    table.write_csv(&out.join("fig5_peaks.csv"), &state_names, &input_names)?;
    let f_hdr = out.join("fig5a_hdr.png");
    pa::hdr_contours(&f_hdr, &summary)?;
    let f_sc = out.join("fig5a_scatter_x1.png");
    pa::pair_scatter(&f_sc, &table, &summary, 0)?;
    let f_grid = out.join("fig5b_summary.png");
    pa::summary_grid(&f_grid, &summary)?;
    pa::summary_grid(&out.join("fig5b_summary.svg"), &summary)?;

    // Training curves.
    let ep_: Vec<f64> = (1..=200).map(f64::from).collect();
    let l1: Vec<f64> = ep_.iter().map(|e| 5e4 / e.sqrt() + 800.0).collect();
    let l2: Vec<f64> = ep_.iter().map(|e| 6e4 / e.powf(0.4) + 1500.0).collect();
    let f_tr = out.join("training.png");
    training::training_curves(
        &f_tr,
        "training objective",
        "negative ELBO",
        &[
            training::TrainingCurve {
                label: "D_x = 12",
                epochs: &ep_,
                values: &l1,
            },
            training::TrainingCurve {
                label: "D_x = 8",
                epochs: &ep_,
                values: &l2,
            },
        ],
        true,
    )?;

    // Report.
    let fmt = |v: &[f64]| v.iter().map(|x| format!("{x:.3}")).collect::<Vec<_>>();
    let rep = Report {
        title: "flapssm analysis gallery (synthetic data)".into(),
        intro: "Every figure of the analysis crate, drawn from seeded synthetic data.".into(),
        headline: vec![
            ("overall RMSE, good model (std. units)".into(), format!("{:.3}", eg.overall_rmse())),
            ("overall RMSE, poor model (std. units)".into(), format!("{:.3}", ep.overall_rmse())),
        ],
        sections: vec![
            Section {
                heading: "Accuracy".into(),
                paragraphs: vec!["Errors are measured − predicted; intervals are the 2.5th and 97.5th percentiles.".into()],
                tables: vec![Table {
                    caption: "RMSE per output".into(),
                    header: std::iter::once("model".to_string()).chain(names5.iter().map(|s| s.to_string())).collect(),
                    rows: vec![
                        std::iter::once("good".to_string()).chain(fmt(&eg.rmse())).collect(),
                        std::iter::once("poor".to_string()).chain(fmt(&ep.rmse())).collect(),
                    ],
                }],
                figures: vec![
                    Figure { caption: "Fig. 3 — time histories".into(), path: f_ts },
                    Figure { caption: "Fig. 4A — error histograms".into(), path: f_hist },
                    Figure { caption: "Fig. 4B — half-stroke averages".into(), path: f_cyc },
                ],
            },
            Section {
                heading: "Control authority".into(),
                figures: vec![
                    Figure { caption: "Fig. 5Ai".into(), path: f_hdr },
                    Figure { caption: "Fig. 5Aii".into(), path: f_sc },
                    Figure { caption: "Fig. 5B".into(), path: out.join("fig5b_summary.svg") },
                ],
                ..Default::default()
            },
            Section {
                heading: "Wing motions and training".into(),
                figures: vec![Figure { caption: "Fig. 2C".into(), path: f_3d }, Figure { caption: "training".into(), path: f_tr }],
                ..Default::default()
            },
        ],
        config: serde_json::json!({ "seed": seed, "authority": cfg }),
        versions: vec![("flapssm-analysis".into(), env!("CARGO_PKG_VERSION").into())],
    };
    rep.write(&out.join("report.html"))?;
    println!("wrote {}", out.display());
    Ok(())
}
