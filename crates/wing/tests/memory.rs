//! Memory evidence on small noise-free datasets (physics notes §4.4 item 10).
//!
//! - L0 data are (nearly) exactly quasi-steady: a least-squares fit on the 11 published
//!   features (plus intercept) reaches a standardized test RMSE < 0.1.
//! - L1 data have memory: the same quasi-steady fit is at least 2× worse than a ridge-regularized
//!   linear model that also sees one stroke cycle of past features and inputs, and the
//!   cross-correlation between a_x and the quasi-steady residual of F_x peaks 0.1–0.3 cycle
//!   later.
//!
//! All three targets hold for the Sane–Dickinson normal-force wing (chordwise skin friction
//! only) on a flat stroke plane — the quasi-steady model the 11 features were designed for. The
//! full-chordwise wing adds the Dickinson chordwise coefficient C_T* and the chordwise Kirchhoff
//! added-mass force −m_a ω_z(n + dω_z); with deviation, ω_z = α̇ + φ̇ sin ψ ≠ α̇. Neither is in
//! the span of the 11 features (F_y and M_x are fit only to ≈ 1.0–1.15), so on that wing
//! only the lag target holds, on the default (measured-like) generator (L3:
//! lag 0.289 cycle, ratio 1.24; L2: lag 0.114 cycle, ratio 1.16; L1: lag 0.139, ratio 1.36; on the hovering generator before it, L2 0.249 and 1.00,
//! L1 0.157 and 1.11). L0 (≈ 0.72) and the ratios are pinned with a margin as regression
//! guards, not as the issue-3 targets (see docs/virtual-wing.md).

mod common;

use common::assert_recorded;
use faer::Mat;
use faer::linalg::solvers::Solve;
use flapssm_wing::aero::quasi_steady::ChordwiseModel;
use flapssm_wing::dataset::Dataset;
use flapssm_wing::features::published_features;
use flapssm_wing::mount::Mount;
use flapssm_wing::sensor::SensorConfig;
use flapssm_wing::trajectories::paper::paper_angles;
use flapssm_wing::trajectories::stats::TrajectoryStats;
use flapssm_wing::trajectories::{GeneratorConfig, SamplingConfig};
use flapssm_wing::virtual_wing::{
    Fidelity, SimulationConfig, VirtualWingConfig, simulate_angles_dataset, simulate_dataset,
};

const N_TRAJ: usize = 72;
const N_TRAIN: usize = 56;
/// First sample used (the published analysis drops 93; the history model needs 100).
const SKIP: usize = 100;
const SEED: u64 = 2021;
/// L0 quasi-steady fit of the full-chordwise wing on the default generator: measured 0.72, pinned with
/// a margin.
const L0_PIN: f64 = 0.8;
/// L1 quasi-steady / history ratio there: measured 1.11, pinned with a margin.
const RATIO_PIN: f64 = 1.05;
/// The same on L2, the default generator: measured 1.00 (the history model, linear in one
/// cycle of past inputs, does not capture the vortex method's nonlinear memory).
const RATIO_PIN_L2: f64 = 0.95;
/// The same on L3: measured 1.24.
const RATIO_PIN_L3: f64 = 1.15;
/// Past samples seen by the history model (25 Hz): covers one cycle for f ≥ 0.25 Hz.
const LAGS: [usize; 20] = [
    0, 1, 2, 3, 4, 6, 8, 10, 13, 16, 20, 25, 30, 36, 43, 50, 60, 70, 85, 100,
];

/// Which loads the wing produces.
#[derive(Clone, Copy, Debug)]
enum Chordwise {
    /// Dickinson C_T* and the chordwise Kirchhoff added-mass force (the wing of the L3 default
    /// before the rig check, docs/rig-agreement.md).
    Full,
    /// The Sane–Dickinson normal-force model: skin friction only along the chord.
    FrictionOnly,
}

/// Which trajectories drive the wing.
#[derive(Clone, Copy, Debug)]
enum Set {
    /// The default (measured-like) generator.
    Default,
    /// A flat stroke plane (ψ = 0) of the hovering generator (`GeneratorConfig::hovering()`,
    /// 0.2–0.4 Hz: the history model's lags cover one cycle).
    FlatHovering,
    /// The paper's measured trajectories (the first 72).
    Paper,
}

/// Small noise-free dataset of `set` and each trajectory's stroke frequency (Hz).
fn dataset(fidelity: Fidelity, set: Set, chordwise: Chordwise) -> (Dataset, Vec<f64>) {
    // The plate aligned with the encoder and the sensor (the default wing's mount turns part
    // of the normal force into the chordwise channels, docs/rig-agreement.md).
    let mut wing = VirtualWingConfig {
        fidelity,
        sensor: SensorConfig::noise_free(),
        mount: Mount::default(),
        ..Default::default()
    };
    match chordwise {
        Chordwise::Full => wing.aero.quasi_steady.added_mass_chordwise = true,
        Chordwise::FrictionOnly => {
            wing.aero.quasi_steady.chordwise = ChordwiseModel::SkinFriction;
            wing.aero.quasi_steady.added_mass_chordwise = false;
        }
    }
    if let Set::Paper = set {
        let angles = paper_angles(N_TRAJ);
        let freqs = angles
            .iter()
            .map(|a| TrajectoryStats::of(a, 0.04).unwrap().stroke_frequency_hz)
            .collect();
        let sampling = SamplingConfig::default();
        let ds = simulate_angles_dataset(&wing, &angles, &sampling, SEED, N_TRAIN, "paper", &|| {});
        return (ds.unwrap().into_inner(), freqs);
    }
    let flat = matches!(set, Set::FlatHovering);
    let defaults = if flat {
        GeneratorConfig::hovering()
    } else {
        GeneratorConfig::default()
    };
    let trajectories = GeneratorConfig {
        n_trajectories: N_TRAJ,
        n_train: N_TRAIN,
        seed: SEED,
        max_deviation_deg: if flat {
            0.0
        } else {
            defaults.max_deviation_deg
        },
        ..defaults
    };
    let freqs = trajectories
        .generate()
        .unwrap()
        .iter()
        .map(|s| s.frequency_hz)
        .collect();
    let cfg = SimulationConfig { wing, trajectories };
    (simulate_dataset(&cfg, &|| {}).unwrap().into_inner(), freqs)
}

/// Regressor rows. QS: [1, 11 features(t)]. History: [1, 11 features(t), 7 inputs(t)] and, at
/// every lag τ of LAGS, the 11 features(t − τ) and |v(t)|·g(t − τ) with
/// g = [|v|, AoA|v|, AoA²|v|, AoA³|v|, α̇, a_x, a_y] — the Duhamel form of a circulatory force,
/// ρU(t)·∫h(τ)Γ_qs(t − τ)dτ, made linear in the coefficients.
fn regressors(inputs: &[[f64; 7]], k: usize, history: bool, out: &mut Vec<f64>) {
    out.clear();
    out.push(1.0);
    out.extend_from_slice(&published_features(&inputs[k]));
    if !history {
        return;
    }
    out.extend_from_slice(&inputs[k]);
    let speed = inputs[k][1];
    for &lag in &LAGS[1..] {
        let u = &inputs[k - lag];
        out.extend_from_slice(&published_features(u));
        let [aoa, v, a_x, a_y, _, alpha_dot, _] = *u;
        out.extend(
            [
                v,
                aoa * v,
                aoa * aoa * v,
                aoa * aoa * aoa * v,
                alpha_dot,
                a_x,
                a_y,
            ]
            .map(|g| speed * g),
        );
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
        for (k, yk) in y.iter().enumerate().skip(SKIP) {
            regressors(&t.inputs, k, history, &mut row);
            rows.extend_from_slice(&row);
            targets.push(
                (0..5)
                    .map(|c| (yk[c] - mean[c]) / sd[c])
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
        for (k, yk) in y.iter().enumerate().skip(SKIP) {
            regressors(&t.inputs, k, history, &mut row);
            for c in 0..5 {
                let pred: f64 = (0..p).map(|j| row[j] / scale[j] * beta[(j, c)]).sum();
                let e = (yk[c] - mean[c]) / sd[c] - pred;
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
        assert!(f.is_finite() && *f > 0.0, "stroke frequency {f}");
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

struct Memory {
    /// QS fit of the L0 data.
    qs_l0: f64,
    /// QS fit and history model of the L1 or L2 data.
    qs_unsteady: f64,
    history_unsteady: f64,
    median_lag_cycles: f64,
}

/// The three figures for the wing `chordwise` on the generator (`flat` or default), with the
/// memory measured on data of `fidelity` (L1, L2 or L3).
fn memory(set: Set, chordwise: Chordwise, fidelity: Fidelity) -> Memory {
    let label = format!("{set:?}, {chordwise:?}, {fidelity:?}");
    let (ds0, _) = dataset(Fidelity::L0, set, chordwise);
    let l0 = fit(&ds0, false);
    let (ds, freqs) = dataset(fidelity, set, chordwise);
    let qs = fit(&ds, false);
    let hist = fit(&ds, true);
    let median_lag_cycles = median(xcorr_peak_lags(&ds, &freqs, &qs.residual_fx));
    println!(
        "{label}: L0 QS test RMSE = {:.4} {:?}\n{label}: QS = {:.4} {:?}, history model = {:.4} {:?}, ratio = {:.2}, median a_x→residual lag = {:.3} cycle",
        l0.test_rmse,
        l0.channel_rmse,
        qs.test_rmse,
        qs.channel_rmse,
        hist.test_rmse,
        hist.channel_rmse,
        qs.test_rmse / hist.test_rmse,
        median_lag_cycles
    );
    Memory {
        qs_l0: l0.test_rmse,
        qs_unsteady: qs.test_rmse,
        history_unsteady: hist.test_rmse,
        median_lag_cycles,
    }
}

/// The Sane–Dickinson normal-force wing (chordwise skin friction only) on a flat stroke plane
/// meets all three targets: this is the quasi-steady model the 11 features were built for.
#[test]
fn flat_stroke_plane_meets_the_memory_targets() {
    let m = memory(Set::FlatHovering, Chordwise::FrictionOnly, Fidelity::L1);
    assert!(m.qs_l0 < 0.1, "L0 QS test RMSE {}", m.qs_l0);
    let ratio = m.qs_unsteady / m.history_unsteady;
    assert!(ratio >= 2.0, "ratio {ratio}");
    let lag = m.median_lag_cycles;
    assert!((0.1..=0.3).contains(&lag), "median lag {lag} cycle");
}

/// L3 (the vortex lattice, the default wing before docs/rig-agreement.md) with the full chordwise
/// loads on the default generator (measured: L0 QS 0.271, L3
/// QS 0.513, history model 0.414, ratio 1.24, lag 0.289 cycle): the lag target holds; the ratio
/// is pinned with a margin, as a regression guard.
#[test]
fn l3_memory_evidence() {
    let m = memory(Set::Default, Chordwise::Full, Fidelity::L3);
    let lag = m.median_lag_cycles;
    assert!((0.1..=0.3).contains(&lag), "median lag {lag} cycle");
    let ratio = m.qs_unsteady / m.history_unsteady;
    assert!(ratio > RATIO_PIN_L3, "ratio {ratio}");
}

/// L2 on the default generator
/// (measured: L2 QS 0.368, history model 0.316, lag 0.114 cycle; on the hovering generator L0 QS
/// 0.718, L2 QS 0.408, history 0.407, lag 0.249): the lag target holds; the quasi-steady fit of
/// L0 and the ratio are pinned at their measured values with a margin (see the module docs).
#[test]
fn l2_default_generator_memory_evidence() {
    let m = memory(Set::Default, Chordwise::Full, Fidelity::L2);
    let lag = m.median_lag_cycles;
    assert!((0.1..=0.3).contains(&lag), "median lag {lag} cycle");
    assert!(m.qs_l0 < L0_PIN, "L0 QS test RMSE {}", m.qs_l0);
    let ratio = m.qs_unsteady / m.history_unsteady;
    assert!(ratio > RATIO_PIN_L2, "ratio {ratio}");
}

/// The full-chordwise wing on L1 data: the lag target holds; the quasi-steady fit of L0 and the
/// ratio are pinned at their measured values with a margin (see the module docs) — they fall
/// short of the targets (< 0.1, ≥ 2) because the chordwise loads and ω_z ≠ α̇ lie outside
/// the span of the 11 features, quasi-steady or not.
#[test]
fn l1_memory_evidence() {
    let m = memory(Set::Default, Chordwise::Full, Fidelity::L1);
    let lag = m.median_lag_cycles;
    assert!((0.1..=0.3).contains(&lag), "median lag {lag} cycle");
    assert!(m.qs_l0 < L0_PIN, "L0 QS test RMSE {}", m.qs_l0);
    assert!(
        m.qs_unsteady > m.qs_l0,
        "L1 QS {} vs L0 QS {}",
        m.qs_unsteady,
        m.qs_l0
    );
    let ratio = m.qs_unsteady / m.history_unsteady;
    assert!(ratio > RATIO_PIN, "ratio {ratio}");
}

/// Share of the |v|²-weight of the analysed samples (93..) where the trailing edge leads
/// (|AoA| > 90°).
fn trailing_edge_first_share(inputs: impl Iterator<Item = Vec<[f64; 7]>>) -> f64 {
    let (mut te, mut all) = (0.0, 0.0);
    for t in inputs {
        for u in &t[93..] {
            let w = u[1] * u[1];
            all += w;
            if u[0].abs() > std::f64::consts::FRAC_PI_2 {
                te += w;
            }
        }
    }
    te / all
}

/// The hovering generator keeps the trailing edge leading (|AoA| > 90°) to a small share of
/// the |v|²-weight of the analysed samples (measured 6–7 %; before the issue-3 generator fix
/// 17–18 %, mostly figure-eight trajectories descending through the reversals). The
/// measured-like default leads with the trailing edge as often as the paper's trajectories do
/// (measured: default 0.278, paper 0.271, hovering 0.064).
#[test]
fn trailing_edge_leads_as_often_as_in_the_papers_trajectories() {
    let share = |cfg: GeneratorConfig| {
        let cfg = GeneratorConfig {
            n_trajectories: 200,
            n_train: 190,
            seed: SEED,
            ..cfg
        };
        let ds = flapssm_wing::trajectories::kinematics_dataset(&cfg).unwrap();
        trailing_edge_first_share(ds.trajectories.iter().map(|t| t.inputs.clone()))
    };
    let hovering = share(GeneratorConfig::hovering());
    let default = share(GeneratorConfig::default());
    let sg = flapssm_wing::differentiate::SavitzkyGolayConfig::spanning_default(0.04);
    let paper = trailing_edge_first_share(
        flapssm_wing::trajectories::paper::paper_angles(548)
            .iter()
            .map(|a| flapssm_wing::differentiate::measured_inputs(a, 0.04, sg).unwrap()),
    );
    eprintln!(
        "TE-first share of |v|²-weight: hovering {hovering:.3}, default {default:.3}, paper {paper:.3}"
    );
    assert!(hovering < 0.09, "hovering TE-first share {hovering}");
    assert!(
        (default - paper).abs() < 0.08,
        "default {default} vs paper {paper}"
    );
}

/// The memory figures of the normal-force wing on a flat stroke plane with L2 (strip vortex)
/// data (docs/vortex-method.md; L3's are printed by `l3_memory_evidence`), checked against
/// their record: `cargo test --release -p flapssm-wing --test memory study_l2_memory_evidence
/// -- --nocapture` prints them (≈ 10 s).
#[test]
fn study_l2_memory_evidence() {
    let m = memory(Set::FlatHovering, Chordwise::FrictionOnly, Fidelity::L2);
    assert_recorded(
        "flat normal-force wing, L2",
        &figures(&m),
        &RECORDED_L2_FLAT,
        0.01,
    );
}

/// The memory figures of the default wing on the paper's measured trajectories (L1, L2, L3,
/// noise-free, the first 72), checked against their record: `cargo test --release -p
/// flapssm-wing --test memory paper_memory_study -- --nocapture` prints them.
#[test]
fn paper_memory_study() {
    let fidelities = [Fidelity::L1, Fidelity::L2, Fidelity::L3];
    let found = fidelities.map(|f| figures(&memory(Set::Paper, Chordwise::Full, f)));
    for ((f, got), recorded) in fidelities.iter().zip(found).zip(RECORDED_PAPER) {
        assert_recorded(
            &format!("paper's trajectories, {f:?}"),
            &got,
            &recorded,
            0.01,
        );
    }
}

/// Recorded figures ([`figures`]) of `study_l2_memory_evidence` (2026-11-29): the history
/// model beats the quasi-steady fit by 1.28×, the lag 0.264 cycle.
const RECORDED_L2_FLAT: [f64; 4] = [0.0743, 0.3706, 0.2888, 0.264];

/// Recorded figures of `paper_memory_study` (2026-11-29): L1, L2, L3.
const RECORDED_PAPER: [[f64; 4]; 3] = [
    [0.3089, 0.3677, 0.3080, 0.271],
    [0.3089, 0.3482, 0.3380, 0.224],
    [0.3089, 0.4985, 0.4389, 0.118],
];

/// A study's figures: L0 QS, QS and history-model test RMSE, median lag (cycles).
fn figures(m: &Memory) -> [f64; 4] {
    [
        m.qs_l0,
        m.qs_unsteady,
        m.history_unsteady,
        m.median_lag_cycles,
    ]
}
