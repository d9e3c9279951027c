//! Kinematics checks against analytic identities, finite differences of rotation matrices and
//! symmetries; trajectory-level checks of the smoothing differentiator.

use flapssm_wing::kinematics::{
    EulerState, Mat3, WingKinematics, mat_mul, rot_x, rot_y, rot_z, rotation_global_from_wing,
};
use std::f64::consts::PI;

/// A smooth test motion (not from the generator): a few incommensurate harmonics per angle.
fn test_angles(t: f64) -> [f64; 3] {
    [
        1.2 * (2.0 * PI * 0.3 * t).sin() + 0.2 * (2.0 * PI * 0.9 * t + 0.4).cos(),
        0.4 * (2.0 * PI * 0.6 * t + 0.3).sin() - 0.1 * (2.0 * PI * 0.3 * t).cos(),
        -0.8 * (2.0 * PI * 0.3 * t + 1.0).cos() + 0.15 * (2.0 * PI * 1.5 * t).sin() + 0.05,
    ]
}

/// Exact derivatives of [`test_angles`].
fn test_state(t: f64) -> EulerState {
    let w1 = 2.0 * PI * 0.3;
    let w3 = 2.0 * PI * 0.9;
    let w2 = 2.0 * PI * 0.6;
    let w5 = 2.0 * PI * 1.5;
    EulerState {
        angles_rad: test_angles(t),
        rates_rad_s: [
            1.2 * w1 * (w1 * t).cos() - 0.2 * w3 * (w3 * t + 0.4).sin(),
            0.4 * w2 * (w2 * t + 0.3).cos() + 0.1 * w1 * (w1 * t).sin(),
            0.8 * w1 * (w1 * t + 1.0).sin() + 0.15 * w5 * (w5 * t).cos(),
        ],
        accels_rad_s2: [
            -1.2 * w1 * w1 * (w1 * t).sin() - 0.2 * w3 * w3 * (w3 * t + 0.4).cos(),
            -0.4 * w2 * w2 * (w2 * t + 0.3).sin() + 0.1 * w1 * w1 * (w1 * t).cos(),
            0.8 * w1 * w1 * (w1 * t + 1.0).cos() - 0.15 * w5 * w5 * (w5 * t).sin(),
        ],
    }
}

/// 6th-order central differences: first and second derivatives of f at t with step h.
fn central6<const N: usize>(f: impl Fn(f64) -> [f64; N], t: f64, h: f64) -> ([f64; N], [f64; N]) {
    let d1 = [
        -1.0 / 60.0,
        3.0 / 20.0,
        -3.0 / 4.0,
        0.0,
        3.0 / 4.0,
        -3.0 / 20.0,
        1.0 / 60.0,
    ];
    let d2 = [
        1.0 / 90.0,
        -3.0 / 20.0,
        3.0 / 2.0,
        -49.0 / 18.0,
        3.0 / 2.0,
        -3.0 / 20.0,
        1.0 / 90.0,
    ];
    let mut first = [0.0; N];
    let mut second = [0.0; N];
    for k in 0..7 {
        let fk = f(t + (k as f64 - 3.0) * h);
        for i in 0..N {
            first[i] += d1[k] * fk[i] / h;
            second[i] += d2[k] * fk[i] / (h * h);
        }
    }
    (first, second)
}

fn flat(m: &Mat3) -> [f64; 9] {
    let mut out = [0.0; 9];
    for i in 0..3 {
        for j in 0..3 {
            out[3 * i + j] = m[i][j];
        }
    }
    out
}

fn unflat(v: &[f64; 9]) -> Mat3 {
    [[v[0], v[1], v[2]], [v[3], v[4], v[5]], [v[6], v[7], v[8]]]
}

/// Inputs from finite differences of Q·R_0w(t) and of α(t).
fn inputs_from_rotations(q: &Mat3, t: f64) -> [f64; 7] {
    let h = 2e-3;
    let rot = |s: f64| flat(&mat_mul(q, &rotation_global_from_wing(&test_angles(s))));
    let (r_dot, r_ddot) = central6(rot, t, h);
    let (ang_dot, ang_ddot) = central6(test_angles, t, h);
    let r = unflat(&rot(t));
    WingKinematics::from_rotation(
        &r,
        &unflat(&r_dot),
        &unflat(&r_ddot),
        ang_dot[2],
        ang_ddot[2],
    )
    .inputs()
}

fn assert_inputs_close(got: &[f64; 7], want: &[f64; 7], rel: f64, what: &str) {
    let scale = want.iter().map(|x| x.abs()).fold(0.0, f64::max).max(1.0);
    for i in 0..7 {
        assert!(
            (got[i] - want[i]).abs() <= rel * want[i].abs().max(1e-3 * scale),
            "{what}: input {i}: {} vs {}",
            got[i],
            want[i]
        );
    }
}

#[test]
fn pure_stroke_speed_centripetal_and_tangential_split() {
    for &alpha in &[-1.2, -0.5, 0.0, 0.3, 0.9, 2.0] {
        for &(phi_d, phi_dd) in &[(1.3, 0.7), (-0.8, 2.5), (2.0, -1.1)] {
            let k = WingKinematics::from_euler(&EulerState {
                angles_rad: [0.4, 0.0, alpha],
                rates_rad_s: [phi_d, 0.0, 0.0],
                accels_rad_s2: [phi_dd, 0.0, 0.0],
            });
            let s: f64 = if phi_d > 0.0 { 1.0 } else { -1.0 };
            assert!((k.speed - phi_d.abs()).abs() < 1e-14);
            assert!((k.a[2] + phi_d * phi_d).abs() < 1e-13);
            // The tangential acceleration φ̈ lies along v̂ = (−sin AoA, cos AoA).
            assert!((k.a[0] + s * phi_dd * k.aoa_rad.sin()).abs() < 1e-13);
            assert!((k.a[1] - s * phi_dd * k.aoa_rad.cos()).abs() < 1e-13);
            // pol2cart(AoA + π/2, |v|) = (v_x, v_y).
            assert!((k.speed * (k.aoa_rad + PI / 2.0).cos() - k.v_x).abs() < 1e-14);
            assert!((k.speed * (k.aoa_rad + PI / 2.0).sin() - k.v_y).abs() < 1e-14);
        }
    }
}

#[test]
fn analytic_inputs_match_finite_differences_of_rotations() {
    let identity = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    for i in 0..40 {
        let t = 0.173 * i as f64;
        let analytic = WingKinematics::from_euler(&test_state(t)).inputs();
        let fd = inputs_from_rotations(&identity, t);
        assert_inputs_close(&fd, &analytic, 1e-6, &format!("t = {t}"));
    }
}

#[test]
fn rotating_the_stroke_plane_leaves_inputs_unchanged() {
    let q = mat_mul(&mat_mul(&rot_x(0.7), &rot_y(-1.9)), &rot_z(0.35));
    for i in 0..25 {
        let t = 0.31 * i as f64;
        let analytic = WingKinematics::from_euler(&test_state(t)).inputs();
        let rotated = inputs_from_rotations(&q, t);
        assert_inputs_close(&rotated, &analytic, 1e-6, &format!("t = {t}"));
    }
}

#[test]
fn mirror_and_time_reversal() {
    for i in 0..30 {
        let t = 0.27 * i as f64;
        let s = test_state(t);
        let k = WingKinematics::from_euler(&s).inputs();
        // Reflection x_0 → −x_0: (φ, ψ, α) → (−φ, ψ, −α); R' = M R M with M = diag(−1, 1, 1).
        let m = EulerState {
            angles_rad: [-s.angles_rad[0], s.angles_rad[1], -s.angles_rad[2]],
            rates_rad_s: [-s.rates_rad_s[0], s.rates_rad_s[1], -s.rates_rad_s[2]],
            accels_rad_s2: [-s.accels_rad_s2[0], s.accels_rad_s2[1], -s.accels_rad_s2[2]],
        };
        let r = rotation_global_from_wing(&s.angles_rad);
        let rm = rotation_global_from_wing(&m.angles_rad);
        let sign = [-1.0, 1.0, 1.0];
        for a in 0..3 {
            for b in 0..3 {
                assert!((rm[a][b] - sign[a] * sign[b] * r[a][b]).abs() < 1e-14);
            }
        }
        let km = WingKinematics::from_euler(&m).inputs();
        let want = [-k[0], k[1], -k[2], k[3], k[4], -k[5], -k[6]];
        assert_inputs_close(&km, &want, 1e-12, "mirror");
        // Time reversal: rates flip, accelerations stay; v flips so AoA shifts by π.
        let rev = EulerState {
            angles_rad: s.angles_rad,
            rates_rad_s: s.rates_rad_s.map(|x| -x),
            accels_rad_s2: s.accels_rad_s2,
        };
        let kr = WingKinematics::from_euler(&rev).inputs();
        let d_aoa = (kr[0] - k[0]).rem_euclid(2.0 * PI);
        assert!((d_aoa - PI).abs() < 1e-12, "AoA shift {d_aoa}");
        let want = [kr[0], k[1], k[2], k[3], k[4], -k[5], k[6]];
        assert_inputs_close(&kr, &want, 1e-12, "time reversal");
    }
}

mod generator {
    use flapssm_wing::cycles::{StrokeDirection, half_strokes, stroke_reversals};
    use flapssm_wing::kinematics::WingKinematics;
    use flapssm_wing::trajectories::{Family, GeneratorConfig, TrajectorySpec};
    use std::f64::consts::PI;

    const DEG: f64 = PI / 180.0;

    /// Signed AoA at the mid-point of every post-ramp half-stroke, normalised so that the
    /// conventional hovering sign (AoA·φ̇ < 0) is positive (deg).
    fn mid_stroke_aoa_deg(
        spec: &TrajectorySpec,
        states: &[flapssm_wing::kinematics::EulerState],
        dt: f64,
    ) -> Vec<f64> {
        let phi_dot: Vec<f64> = states.iter().map(|s| s.rates_rad_s[0]).collect();
        let rev = stroke_reversals(&phi_dot, dt, 0.05).unwrap();
        half_strokes(&rev)
            .iter()
            .filter(|h| h.start_s > spec.ramp_s)
            .map(|h| {
                let k = WingKinematics::from_euler(&spec.euler_state(h.mid_s()));
                let s = if h.direction == StrokeDirection::Positive {
                    -1.0
                } else {
                    1.0
                };
                s * k.aoa_rad / DEG
            })
            .collect()
    }

    /// The measured-like default: frequency from the one U_ref, ramp within the skipped
    /// samples, amplitudes and pitch in their stated ranges, servo limits kept.
    #[test]
    fn default_set_covers_families_and_stated_ranges() {
        let cfg = GeneratorConfig {
            seed: 11,
            ..GeneratorConfig::default()
        };
        let specs = cfg.generate().unwrap();
        let ds = flapssm_wing::trajectories::kinematics_dataset(&cfg).unwrap();
        for f in Family::ALL {
            assert!(
                specs.iter().filter(|s| s.family == f).count() >= 40,
                "{f:?}"
            );
        }
        let dt = cfg.sampling.raw_dt_s();
        for ((i, spec), t) in specs.iter().enumerate().zip(&ds.trajectories) {
            assert!((0.1..=0.3).contains(&spec.frequency_hz), "{i}");
            assert!(spec.ramp_s <= 3.72 + 1e-12, "{i}: ramp {} s", spec.ramp_s);
            assert!(
                (t.u_ref_m_s - 0.1746).abs() < 0.02 * 0.1746,
                "{i}: U_ref {}",
                t.u_ref_m_s
            );
            let states = spec.sample_raw(&cfg.sampling);
            let after = &states[(spec.ramp_s / dt).ceil() as usize..];
            let half_range = |a: usize| {
                let (lo, hi) = after.iter().fold((f64::MAX, f64::MIN), |(lo, hi), s| {
                    (lo.min(s.angles_rad[a]), hi.max(s.angles_rad[a]))
                });
                0.5 * (hi - lo) / DEG
            };
            let stroke = half_range(0);
            assert!((39.9..=89.1).contains(&stroke), "{i}: stroke {stroke}");
            assert!(half_range(1) <= 40.1, "{i}: deviation");
            let pitch = half_range(2);
            // The harmonic family's pitch perturbation adds up to 10°.
            let extra = if spec.family == Family::Harmonic {
                10.0
            } else {
                0.0
            };
            assert!(
                (9.9..=80.1 + extra).contains(&pitch),
                "{i}: pitch half-range {pitch}"
            );
            for s in &states {
                for a in 0..3 {
                    assert!(s.angles_rad[a].abs() <= 110.0 * DEG, "{i}: angle {a}");
                    assert!(s.rates_rad_s[a].abs() <= 900.0 * DEG, "{i}: rate {a}");
                }
            }
        }
    }

    /// `GeneratorConfig::hovering()`: hovering-like kinematics, leading edge first.
    #[test]
    fn hovering_set_covers_families_and_stated_ranges() {
        let cfg = GeneratorConfig {
            seed: 11,
            ..GeneratorConfig::hovering()
        };
        let specs = cfg.generate().unwrap();
        assert_eq!(specs.len(), 548);
        for f in Family::ALL {
            assert!(
                specs.iter().filter(|s| s.family == f).count() >= 50,
                "{f:?}"
            );
        }
        let dt = cfg.sampling.raw_dt_s();
        let mut aoa = Vec::new();
        for (i, spec) in specs.iter().enumerate() {
            assert!(
                (0.2..=0.4).contains(&spec.frequency_hz),
                "{i}: f = {}",
                spec.frequency_hz
            );
            let cycles = spec.ramp_s * spec.frequency_hz;
            assert!((1.0..=2.0).contains(&cycles), "{i}: ramp {cycles} cycles");
            let states = spec.sample_raw(&cfg.sampling);
            for s in &states {
                for a in 0..3 {
                    assert!(
                        s.angles_rad[a].abs() <= 110.0 * DEG,
                        "{i}: angle {a} = {}",
                        s.angles_rad[a] / DEG
                    );
                    assert!(s.rates_rad_s[a].abs() <= 900.0 * DEG, "{i}: rate {a}");
                    assert!(s.accels_rad_s2[a].is_finite());
                }
            }
            // Amplitudes over the post-ramp part (whole cycles are present: ≥ 1.7 cycles remain).
            let after: Vec<_> = states
                .iter()
                .enumerate()
                .filter(|(k, _)| *k as f64 * dt > spec.ramp_s)
                .map(|(_, s)| s)
                .collect();
            let half_range = |a: usize| {
                let (lo, hi) = after.iter().fold((f64::MAX, f64::MIN), |(lo, hi), s| {
                    (lo.min(s.angles_rad[a]), hi.max(s.angles_rad[a]))
                });
                0.5 * (hi - lo) / DEG
            };
            let stroke = half_range(0);
            assert!(
                (39.9..=100.1).contains(&stroke),
                "{i}: stroke half-amplitude {stroke}"
            );
            let dev = half_range(1);
            assert!(dev <= 41.0, "{i}: deviation half-amplitude {dev}");
            if spec.family == Family::Flat {
                assert!(dev <= 3.1, "{i}: flat deviation {dev}");
            } else {
                assert!(dev >= 4.0, "{i}: {:?} deviation {dev}", spec.family);
            }
            aoa.extend(mid_stroke_aoa_deg(spec, &states, dt));
        }
        let n = aoa.len() as f64;
        let frac = |p: &dyn Fn(f64) -> bool| aoa.iter().filter(|&&a| p(a)).count() as f64 / n;
        let conventional = frac(&|a| (15.0..=75.0).contains(&a));
        let near_zero = frac(&|a| a.abs() < 10.0);
        let reversed = frac(&|a| a <= -5.0);
        eprintln!(
            "{} half-strokes: conventional {conventional:.3}, near zero {near_zero:.3}, reversed {reversed:.3}",
            aoa.len()
        );
        assert!(conventional >= 0.8, "conventional fraction {conventional}");
        assert!(near_zero >= 0.02, "near-zero fraction {near_zero}");
        assert!(reversed >= 0.02, "reversed fraction {reversed}");
        assert!(
            frac(&|a| (20.0..=40.0).contains(&a)) > 0.2
                && frac(&|a| (50.0..=70.0).contains(&a)) > 0.2,
            "AoA spread"
        );
    }

    #[test]
    fn analytic_rates_match_finite_differences_of_angles() {
        let cfg = GeneratorConfig {
            n_trajectories: 10,
            n_train: 8,
            seed: 3,
            ..GeneratorConfig::default()
        };
        let h = 1e-4;
        for spec in cfg.generate().unwrap() {
            for i in 0..40 {
                // Away from t = 0, where the C² ramp makes central differences first order.
                let t = 0.05 + 0.37 * i as f64;
                let s = spec.euler_state(t);
                let (p, m) = (spec.euler_state(t + h), spec.euler_state(t - h));
                for a in 0..3 {
                    let d1 = (p.angles_rad[a] - m.angles_rad[a]) / (2.0 * h);
                    let d2 = (p.rates_rad_s[a] - m.rates_rad_s[a]) / (2.0 * h);
                    assert!(
                        (d1 - s.rates_rad_s[a]).abs() < 1e-6 * (1.0 + s.rates_rad_s[a].abs()),
                        "rate {a} at {t}"
                    );
                    assert!(
                        (d2 - s.accels_rad_s2[a]).abs() < 1e-5 * (1.0 + s.accels_rad_s2[a].abs()),
                        "acc {a} at {t}"
                    );
                }
            }
        }
    }

    #[test]
    fn seeds_are_reproducible_and_distinct() {
        let cfg = |seed| GeneratorConfig {
            n_trajectories: 20,
            n_train: 16,
            seed,
            ..GeneratorConfig::default()
        };
        let a = cfg(5).generate().unwrap();
        assert_eq!(a, cfg(5).generate().unwrap());
        let b = cfg(6).generate().unwrap();
        assert!(a.iter().zip(&b).all(|(x, y)| x != y));
        // Trajectory i does not depend on how many trajectories are generated.
        let big = GeneratorConfig {
            n_trajectories: 40,
            n_train: 30,
            seed: 5,
            ..GeneratorConfig::default()
        };
        let c = big.generate_one(3, a[3].family).unwrap();
        assert_eq!(c, a[3]);
    }

    #[test]
    fn sampling_helpers_are_consistent() {
        let cfg = GeneratorConfig {
            n_trajectories: 3,
            n_train: 2,
            seed: 1,
            ..GeneratorConfig::default()
        };
        let spec = &cfg.generate().unwrap()[0];
        let raw = spec.sample_raw(&cfg.sampling);
        let ds = spec.sample_dataset(&cfg.sampling);
        assert_eq!(raw.len(), 4700);
        assert_eq!(ds.len(), 470);
        assert!((cfg.sampling.dataset_dt_s() - 0.04).abs() < 1e-15);
        for (k, s) in ds.iter().enumerate() {
            assert_eq!(*s, raw[10 * k]);
        }
    }
}

mod measured {
    use flapssm_wing::differentiate::{SavitzkyGolay, SavitzkyGolayConfig, quantize_to_encoder};
    use flapssm_wing::kinematics::{EulerState, WingKinematics};
    use flapssm_wing::trajectories::GeneratorConfig;

    /// Per-input relative RMS error of SG inputs from 4096-count, 250 Hz angles vs the analytic
    /// inputs (AoA: absolute RMS in degrees where |v| > 30 % of its maximum), worst over `n`
    /// generated trajectories.
    fn worst_errors(sg_cfg: SavitzkyGolayConfig, n: usize) -> [f64; 7] {
        let cfg = GeneratorConfig {
            n_trajectories: n,
            n_train: n,
            seed: 21,
            // The tolerances were set on hovering-like kinematics (0.2–0.4 Hz); the measured-like
            // default flaps half as fast, so its accelerations are 4× smaller against the same
            // quantization (docs/kinematics.md).
            ..GeneratorConfig::hovering()
        };
        let sg = SavitzkyGolay::new(sg_cfg).unwrap();
        let dt = cfg.sampling.raw_dt_s();
        let mut worst = [0.0f64; 7];
        for spec in cfg.generate().unwrap() {
            let exact = spec.sample_raw(&cfg.sampling);
            let measured: Vec<[f64; 3]> = exact
                .iter()
                .map(|s| s.angles_rad.map(|a| quantize_to_encoder(a, 4096)))
                .collect();
            let mut states = vec![EulerState::default(); measured.len()];
            let mut column = vec![0.0; measured.len()];
            sg.euler_states(&measured, dt, &mut states, &mut column)
                .unwrap();
            let u_exact: Vec<[f64; 7]> = exact
                .iter()
                .map(|s| WingKinematics::from_euler(s).inputs())
                .collect();
            let u_meas: Vec<[f64; 7]> = states
                .iter()
                .map(|s| WingKinematics::from_euler(s).inputs())
                .collect();
            let v_max = u_exact.iter().map(|u| u[1]).fold(0.0, f64::max);
            for c in 0..7 {
                let (mut se, mut ss, mut cnt) = (0.0, 0.0, 0);
                for (ue, um) in u_exact.iter().zip(&u_meas) {
                    if c == 0 {
                        if ue[1] > 0.3 * v_max {
                            let d = (um[0] - ue[0] + std::f64::consts::PI)
                                .rem_euclid(2.0 * std::f64::consts::PI)
                                - std::f64::consts::PI;
                            se += d * d;
                            cnt += 1;
                        }
                    } else {
                        se += (um[c] - ue[c]).powi(2);
                        ss += ue[c] * ue[c];
                        cnt += 1;
                    }
                }
                let e = if c == 0 {
                    (se / cnt as f64).sqrt().to_degrees()
                } else {
                    (se / ss).sqrt()
                };
                worst[c] = worst[c].max(e);
            }
        }
        worst
    }

    /// Stated accuracy (docs/kinematics.md): default Savitzky–Golay (window 121 samples =
    /// 0.48 s, degree 6) on 4096-count encoder angles at 250 Hz, worst of 40 trajectories,
    /// edges included.
    #[test]
    fn encoder_quantised_trajectories_recover_analytic_inputs() {
        let e = worst_errors(SavitzkyGolayConfig::default(), 40);
        eprintln!("AoA {:.3} deg, relative RMS errors {:?}", e[0], &e[1..]);
        let limits = [0.2, 0.005, 0.08, 0.15, 0.005, 0.03, 0.15];
        for c in 0..7 {
            assert!(
                e[c] <= limits[c],
                "input {c}: error {} above {}",
                e[c],
                limits[c]
            );
        }
        // A too-short window on the same data is much worse, so the test can fail.
        let short = worst_errors(
            SavitzkyGolayConfig {
                half_window: 10,
                order: 6,
            },
            5,
        );
        assert!(
            short[6] > 1.0,
            "alpha_ddot error with a 21-sample window: {}",
            short[6]
        );
    }
}

mod dataset {
    use flapssm_wing::cycles::U_REF_RADIUS_M;
    use flapssm_wing::kinematics::WingKinematics;
    use flapssm_wing::trajectories::{Family, GeneratorConfig, kinematics_dataset};

    #[test]
    fn default_dataset_has_inputs_u_ref_and_metadata() {
        let cfg = GeneratorConfig {
            seed: 4,
            ..GeneratorConfig::default()
        };
        let ds = kinematics_dataset(&cfg).unwrap();
        assert_eq!(ds.trajectories.len(), 548);
        assert_eq!(ds.n_train, 512);
        assert!((ds.dt_s - 0.04).abs() < 1e-15);
        assert_eq!(ds.meta.generator, "flapssm trajectories");
        assert_eq!(ds.meta.seed, Some(4));
        assert_eq!(ds.meta.settings["n_trajectories"], 548);
        ds.validate().unwrap();
        let specs = cfg.generate().unwrap();
        for f in Family::ALL {
            assert!(ds.trajectories.iter().any(|t| t.family == f.label()));
        }
        for (i, (t, spec)) in ds.trajectories.iter().zip(&specs).enumerate() {
            assert!(t.outputs.is_none());
            assert_eq!(t.euler_rad.len(), 470);
            let k = 200;
            let want = WingKinematics::from_euler(&spec.euler_state(k as f64 * 0.04)).inputs();
            assert_eq!(t.inputs[k], want);
            // U_ref vs the analytic mean speed of the point at R over the last full cycle
            // (midpoint rule, 2000 points); the published finite-difference recipe is within 3 %.
            let period = 1.0 / spec.frequency_hz;
            let t_end = 469.0 * 0.04;
            let mean = (0..2000)
                .map(|j| {
                    let s = spec.euler_state(t_end - period * (j as f64 + 0.5) / 2000.0);
                    U_REF_RADIUS_M * s.rates_rad_s[0].hypot(s.rates_rad_s[1])
                })
                .sum::<f64>()
                / 2000.0;
            assert!(
                (t.u_ref_m_s / mean - 1.0).abs() < 0.03,
                "{i}: U_ref {} vs {mean}",
                t.u_ref_m_s
            );
            // The last sample is mid-stroke with φ̇ > 0, as the published recipe expects.
            assert!(spec.euler_state(t_end).rates_rad_s[0] > 0.0);
        }
    }
}
