//! The paper's measured trajectories in this crate's convention (`trajectories::paper`): the
//! stroke sign, the pitch sign and zero, and the deviation sign checked on the measured data
//! against what the paper and its code state.

use flapssm_wing::differentiate::{SavitzkyGolayConfig, measured_inputs};
use flapssm_wing::trajectories::paper::{
    PAPER_DT_S, PAPER_N_TRAIN, PAPER_N_TRAJECTORIES, paper_angles,
};
use flapssm_wing::trajectories::stats::pearson;

/// First sample of the published evaluation window (MATLAB sample 94).
const START: usize = 93;

/// Amplitude of harmonic `k` (of the window's length) of `x`, by a direct DFT.
fn harmonic(x: &[f64], k: usize) -> f64 {
    let n = x.len() as f64;
    let (mut c, mut s) = (0.0, 0.0);
    for (i, v) in x.iter().enumerate() {
        let w = std::f64::consts::TAU * k as f64 * i as f64 / n;
        c += v * w.cos();
        s += v * w.sin();
    }
    2.0 * (c * c + s * s).sqrt() / n
}

/// Deviation amplitude at the stroke frequency and at twice it (rad), and corr(ψ, |φ|).
fn deviation_shape(t: &[[f64; 3]]) -> (f64, f64, f64) {
    let w = &t[START..];
    let phi: Vec<f64> = w.iter().map(|r| r[0]).collect();
    let psi: Vec<f64> = w.iter().map(|r| r[1]).collect();
    let k = (1..w.len() / 2)
        .max_by(|&a, &b| harmonic(&phi, a).total_cmp(&harmonic(&phi, b)))
        .unwrap();
    let abs_phi: Vec<f64> = phi.iter().map(|p| p.abs()).collect();
    (
        harmonic(&psi, k)
            .max(harmonic(&psi, k + 1))
            .max(harmonic(&psi, k - 1)),
        harmonic(&psi, 2 * k)
            .max(harmonic(&psi, 2 * k + 1))
            .max(harmonic(&psi, 2 * k - 1)),
        pearson(&psi, &abs_phi),
    )
}

#[test]
fn every_trajectory_ends_at_mid_stroke_moving_towards_positive_stroke() {
    let all = paper_angles(PAPER_N_TRAJECTORIES);
    assert_eq!(all.len(), 548);
    for (i, t) in all.iter().enumerate() {
        let (last, before) = (t[t.len() - 1], t[t.len() - 2]);
        assert!(
            last[0].abs() < 4f64.to_radians(),
            "trajectory {i}: φ {}",
            last[0]
        );
        assert!(
            last[0] > before[0],
            "trajectory {i}: stroke not moving to +φ at the end"
        );
    }
}

#[test]
fn the_leading_edge_leads_on_most_fast_samples_and_pitch_is_centred_on_the_vertical_plate() {
    let all = paper_angles(PAPER_N_TRAJECTORIES);
    let sg = SavitzkyGolayConfig::spanning_default(PAPER_DT_S);
    let (mut leading, mut fast, mut pitch_sum, mut n) = (0usize, 0usize, 0.0, 0usize);
    for t in all.iter().step_by(7) {
        let u = measured_inputs(t, PAPER_DT_S, sg).unwrap();
        let mut speeds: Vec<f64> = u[START..].iter().map(|r| r[1]).collect();
        speeds.sort_by(f64::total_cmp);
        let median = speeds[speeds.len() / 2];
        for r in u[START..].iter().filter(|r| r[1] > median) {
            fast += 1;
            leading += usize::from(r[0].abs() < std::f64::consts::FRAC_PI_2);
        }
        for r in &t[START..] {
            pitch_sum += r[2];
            n += 1;
        }
    }
    let share = leading as f64 / fast as f64;
    // Measured on all 548: 0.75 (0.25 with the file's pitch sign).
    assert!(
        share > 0.65,
        "leading edge leads on {share:.3} of the fast samples"
    );
    let mean_pitch_deg = (pitch_sum / n as f64).to_degrees();
    assert!(
        mean_pitch_deg.abs() < 5.0,
        "mean pitch {mean_pitch_deg:.1}°"
    );
}

#[test]
fn the_named_test_trajectories_have_the_shapes_of_fig_3() {
    let all = paper_angles(PAPER_N_TRAJECTORIES);
    let test = |n: usize| &all[PAPER_N_TRAIN + n - 1];
    let deg = 1f64.to_radians();
    for n in [26, 14, 13] {
        let (once, twice, _) = deviation_shape(test(n));
        assert!(
            twice > 5.0 * once && twice > 10.0 * deg,
            "#{n}: {once} {twice}"
        );
    }
    // #13, the U: highest at the reversals (|φ| largest) with ψ > 0 lifting the tip.
    let (_, _, c) = deviation_shape(test(13));
    assert!(c > 0.9, "#13: corr(ψ, |φ|) = {c}");
    for n in [5, 32] {
        let (once, twice, _) = deviation_shape(test(n));
        assert!(
            once > 3.0 * twice && once > 10.0 * deg,
            "#{n}: {once} {twice}"
        );
    }
    let flat = test(33)[START..]
        .iter()
        .map(|r| r[1].abs())
        .fold(0.0, f64::max);
    assert!(flat < 5.0 * deg, "#33: |ψ| up to {flat}");
}

#[test]
fn every_measured_trajectory_has_a_stroke_frequency() {
    use flapssm_wing::trajectories::stats::TrajectoryStats;
    for (i, t) in paper_angles(PAPER_N_TRAJECTORIES).iter().enumerate() {
        let f = TrajectoryStats::of(t, PAPER_DT_S)
            .unwrap()
            .stroke_frequency_hz;
        assert!((0.08..0.3).contains(&f), "trajectory {i}: {f} Hz");
    }
}

/// The measured set's 5 / 50 / 95th percentiles of f (Hz), U_ref/(R·path rate), stroke path
/// per cycle / 4Φ and e, as docs/kinematics.md quotes them.
const QUOTED_PAPER: [[f64; 3]; 4] = [
    [0.101, 0.143, 0.226],
    [0.983, 0.999, 1.024],
    [0.974, 1.000, 1.024],
    [1.002, 1.103, 1.624],
];
/// The same of the generator's 548 trajectories (seed 1).
const QUOTED_GENERATOR: [[f64; 3]; 4] = [
    [0.109, 0.144, 0.226],
    [0.980, 1.000, 1.022],
    [0.969, 0.996, 1.022],
    [1.001, 1.104, 1.555],
];

/// What sets the stroke frequency, in the measured set and the generator's (seed 1, 548): per
/// trajectory over samples 93.., the frequency, U_ref / (R · mean tip path rate), the stroke's
/// path over 4Φ, and e, the whole tip path over the stroke's. Their 5 / 50 / 95th percentiles
/// are the figures docs/kinematics.md quotes ("What sets the stroke frequency"), to their
/// printed three decimals.
#[test]
fn stroke_frequency_is_set_by_u_ref_amplitude_and_tip_path() {
    use flapssm_wing::cycles::U_REF_RADIUS_M;
    use flapssm_wing::trajectories::stats::TrajectoryStats;
    use flapssm_wing::trajectories::{GeneratorConfig, default_n_train, kinematics_dataset};
    let cfg = GeneratorConfig {
        n_trajectories: 548,
        n_train: default_n_train(548),
        seed: 1,
        ..GeneratorConfig::default()
    };
    let generated: Vec<Vec<[f64; 3]>> = kinematics_dataset(&cfg)
        .unwrap()
        .into_inner()
        .trajectories
        .into_iter()
        .map(|t| t.euler_rad)
        .collect();
    for (name, set) in [
        ("paper", paper_angles(PAPER_N_TRAJECTORIES)),
        ("generator", generated),
    ] {
        let mut cols = [Vec::new(), Vec::new(), Vec::new(), Vec::new()];
        for a in &set {
            let st = TrajectoryStats::of(a, PAPER_DT_S).unwrap();
            let w = &a[START..];
            let (mut path, mut stroke_path) = (0.0, 0.0);
            for p in w.windows(2) {
                path += (p[1][0] - p[0][0]).hypot(p[1][1] - p[0][1]);
                stroke_path += (p[1][0] - p[0][0]).abs();
            }
            let t = (w.len() - 1) as f64 * PAPER_DT_S;
            let per_cycle = stroke_path / t / st.stroke_frequency_hz;
            cols[0].push(st.stroke_frequency_hz);
            cols[1].push(st.u_ref_m_s / (U_REF_RADIUS_M * path / t));
            cols[2].push(per_cycle / (4.0 * st.stroke_half_amplitude_deg.to_radians()));
            cols[3].push(path / stroke_path);
        }
        let percentiles = |v: &mut Vec<f64>| {
            v.sort_by(f64::total_cmp);
            let n = v.len();
            [v[n / 20], v[n / 2], v[n * 19 / 20]]
        };
        let measured = cols.each_mut().map(percentiles);
        let quoted = match name {
            "paper" => QUOTED_PAPER,
            _ => QUOTED_GENERATOR,
        };
        for ((what, got), want) in ["f (Hz)", "U_ref/(R·path rate)", "stroke path/4Φ", "e"]
            .iter()
            .zip(&measured)
            .zip(&quoted)
        {
            for (g, w) in got.iter().zip(want) {
                assert!(
                    (g - w).abs() <= 6e-4,
                    "{name} {what}: {got:.4?}, docs quote {want:?}"
                );
            }
        }
    }
}
