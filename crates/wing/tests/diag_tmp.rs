//! Memory evidence on small noise-free datasets (physics notes §4.4 item 10).
//!
//! - L0 data are (nearly) exactly quasi-steady: a least-squares fit on the 11 published
//!   features (plus intercept) reaches a standardized test RMSE < 0.1.
//! - L1 data have memory: the same quasi-steady fit is at least 2× worse than a ridge-regularized
//!   linear model that also sees one stroke cycle of past features and inputs, and the
//!   cross-correlation between a_x and the quasi-steady residual of F_x peaks 0.1–0.3 cycle
//!   later.

use faer::Mat;
use faer::linalg::solvers::Solve;
use flapssm_data::Dataset;
use flapssm_wing::features::published_features;
use flapssm_wing::sensor::SensorConfig;
use flapssm_wing::trajectories::GeneratorConfig;
use flapssm_wing::virtual_wing::{Fidelity, SimulationConfig, VirtualWingConfig, simulate_dataset};

const N_TRAJ: usize = 72;
const N_TRAIN: usize = 56;
/// First sample used (the published analysis drops 93; the history model needs 100).
const SKIP: usize = 100;
const SEED: u64 = 2021;
/// Past samples seen by the history model (25 Hz): covers one cycle for f ≥ 0.25 Hz.
const LAGS: [usize; 20] = [
    0, 1, 2, 3, 4, 6, 8, 10, 13, 16, 20, 25, 30, 36, 43, 50, 60, 70, 85, 100,
];

fn dataset_with(
    fidelity: Fidelity,
    aero: flapssm_wing::aero::unsteady::UnsteadyParams,
    gcfg: GeneratorConfig,
) -> (Dataset, Vec<f64>) {
    let trajectories = GeneratorConfig {
        n_trajectories: N_TRAJ,
        n_train: N_TRAIN,
        seed: SEED,
        ..gcfg
    };
    let freqs = trajectories
        .generate()
        .unwrap()
        .iter()
        .map(|s| s.frequency_hz)
        .collect();
    let cfg = SimulationConfig {
        wing: VirtualWingConfig {
            fidelity,
            aero,
            sensor: SensorConfig::noise_free(),
            ..Default::default()
        },
        trajectories,
    };
    (simulate_dataset(&cfg, &|| {}).unwrap(), freqs)
}

/// Regressor rows: `history` = false → [1, 11 features]; true → [1, (11 features + 7 inputs)
/// at every lag in LAGS].
fn regressors(inputs: &[[f64; 7]], k: usize, history: bool, out: &mut Vec<f64>) {
    out.clear();
    out.push(1.0);
    let lags: &[usize] = if history { &LAGS } else { &[0] };
    for &lag in lags {
        let u = &inputs[k - lag];
        out.extend_from_slice(&published_features(u));
        if history {
            out.extend_from_slice(u);
        }
    }
}

struct Fit {
    test_rmse: f64,
    /// Per output channel.
    channel_rmse: [f64; 5],
    /// Test residuals of F_x per test trajectory (standardized), from sample SKIP on.
    residual_fx: Vec<Vec<f64>>,
}

fn fit(ds: &Dataset, history: bool) -> Fit {
    let train = &ds.trajectories[..ds.n_train];
    let (mut mean, mut sd) = ([0.0; 5], [0.0; 5]);
    let mut n = 0.0;
    for t in train {
        for y in &t.outputs.as_ref().unwrap()[SKIP..] {
            n += 1.0;
            for c in 0..5 {
                mean[c] += y[c];
                sd[c] += y[c] * y[c];
            }
        }
    }
    for c in 0..5 {
        mean[c] /= n;
        sd[c] = (sd[c] / n - mean[c] * mean[c]).sqrt();
    }
    let mut row = Vec::new();
    regressors(&train[0].inputs, SKIP, history, &mut row);
    let p = row.len();
    let mut rows = Vec::new();
    let mut targets = Vec::new();
    for t in train {
        let y = t.outputs.as_ref().unwrap();
        for k in SKIP..t.inputs.len() {
            regressors(&t.inputs, k, history, &mut row);
            rows.extend_from_slice(&row);
            targets.push(
                (0..5)
                    .map(|c| (y[k][c] - mean[c]) / sd[c])
                    .collect::<Vec<_>>(),
            );
        }
    }
    let n_rows = targets.len();
    // Columns scaled to unit RMS so that one ridge λ suits all of them.
    let scale: Vec<f64> = (0..p)
        .map(|j| {
            ((0..n_rows).map(|i| rows[i * p + j].powi(2)).sum::<f64>() / n_rows as f64)
                .sqrt()
                .max(1e-300)
        })
        .collect();
    let x = Mat::from_fn(n_rows, p, |i, j| rows[i * p + j] / scale[j]);
    let yt = Mat::from_fn(n_rows, 5, |i, c| targets[i][c]);
    let mut g = x.transpose() * &x;
    let ridge = if history {
        1e-4 * n_rows as f64
    } else {
        1e-10 * n_rows as f64
    };
    for j in 1..p {
        g[(j, j)] += ridge;
    }
    let rhs = x.transpose() * &yt;
    let beta = g
        .llt(faer::Side::Lower)
        .expect("normal equations are positive definite")
        .solve(&rhs);
    let (mut sse, mut count) = (0.0, 0.0);
    let mut ch = [0.0; 5];
    let mut residual_fx = Vec::new();
    for t in &ds.trajectories[ds.n_train..] {
        let y = t.outputs.as_ref().unwrap();
        let mut res = Vec::new();
        for k in SKIP..t.inputs.len() {
            regressors(&t.inputs, k, history, &mut row);
            for c in 0..5 {
                let pred: f64 = (0..p).map(|j| row[j] / scale[j] * beta[(j, c)]).sum();
                let e = (y[k][c] - mean[c]) / sd[c] - pred;
                sse += e * e;
                ch[c] += e * e;
                count += 1.0;
                if c == 0 {
                    res.push(e);
                }
            }
        }
        residual_fx.push(res);
    }
    let per = count / 5.0;
    Fit {
        test_rmse: (sse / count).sqrt(),
        channel_rmse: ch.map(|v| (v / per).sqrt()),
        residual_fx,
    }
}

/// Lag (in cycles, 0 < lag < 1 cycle) of the largest |cross-correlation| between input a_x and
/// a later residual, per test trajectory.
fn xcorr_peak_lags(ds: &Dataset, freqs: &[f64], residuals: &[Vec<f64>]) -> Vec<f64> {
    let mut lags = Vec::new();
    for ((t, res), f) in ds.trajectories[ds.n_train..]
        .iter()
        .zip(residuals)
        .zip(&freqs[ds.n_train..])
    {
        let a: Vec<f64> = t.inputs[SKIP..].iter().map(|u| u[2]).collect();
        let n = a.len();
        let ma = a.iter().sum::<f64>() / n as f64;
        let mr = res.iter().sum::<f64>() / n as f64;
        let sa = (a.iter().map(|v| (v - ma).powi(2)).sum::<f64>() / n as f64).sqrt();
        let sr = (res.iter().map(|v| (v - mr).powi(2)).sum::<f64>() / n as f64).sqrt();
        let period = 1.0 / (f * ds.dt_s);
        let max_lag = period.floor() as usize;
        let mut best = (0.0, 0usize);
        for lag in 1..max_lag.min(n - 1) {
            let r: f64 = (0..n - lag)
                .map(|i| (a[i] - ma) * (res[i + lag] - mr))
                .sum::<f64>()
                / (n as f64 * sa * sr);
            if r.abs() > best.0 {
                best = (r.abs(), lag);
            }
        }
        lags.push(best.1 as f64 / period);
    }
    lags
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

#[test]
fn diag_aoa() {
    let (ds, _) = dataset_with(Fidelity::L0, Default::default(), GeneratorConfig::default());
    let (mut n, mut te, mut w, mut wte) = (0.0, 0.0, 0.0, 0.0);
    for t in &ds.trajectories {
        for u in &t.inputs[100..] {
            n += 1.0;
            w += u[1] * u[1];
            if u[0].abs() > std::f64::consts::FRAC_PI_2 {
                te += 1.0;
                wte += u[1] * u[1];
            }
        }
    }
    eprintln!("TE-first fraction {:.3}, |v|^2-weighted {:.3}", te / n, wte / w);
}

#[test]
fn diag_variants() {
    use flapssm_wing::aero::quasi_steady::QuasiSteadyParams;
    use flapssm_wing::aero::unsteady::UnsteadyParams;
    let base = UnsteadyParams::default();
    let flat = GeneratorConfig {
        max_deviation_deg: 0.0,
        ..Default::default()
    };
    for (name, fid, p, g) in [
        ("L0 base", Fidelity::L0, base, GeneratorConfig::default()),
        (
            "L0 no rot",
            Fidelity::L0,
            UnsteadyParams {
                quasi_steady: QuasiSteadyParams {
                    rotational: false,
                    ..Default::default()
                },
                ..base
            },
            GeneratorConfig::default(),
        ),
        (
            "L0 no am",
            Fidelity::L0,
            UnsteadyParams {
                quasi_steady: QuasiSteadyParams {
                    added_mass: false,
                    ..Default::default()
                },
                ..base
            },
            GeneratorConfig::default(),
        ),
        (
            "L0 trans only",
            Fidelity::L0,
            UnsteadyParams {
                quasi_steady: QuasiSteadyParams {
                    added_mass: false,
                    rotational: false,
                    ..Default::default()
                },
                ..base
            },
            GeneratorConfig::default(),
        ),
        ("L0 no dev", Fidelity::L0, base, flat.clone()),
        (
            "L0 trans no dev",
            Fidelity::L0,
            UnsteadyParams {
                quasi_steady: QuasiSteadyParams {
                    added_mass: false,
                    rotational: false,
                    ..Default::default()
                },
                ..base
            },
            flat.clone(),
        ),
    ] {
        let (ds, _) = dataset_with(fid, p, g);
        let qs = fit(&ds, false);
        eprintln!(
            "{name:16}: QS {:.3} {:?}",
            qs.test_rmse,
            qs.channel_rmse.map(|v| (v * 1000.0).round() / 1000.0)
        );
    }
}
