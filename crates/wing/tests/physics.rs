//! Physics validation of the virtual wing (physics notes §4.4), noise-free.

mod common;

use common::{
    assert_recorded, blade, figure_eight_hover_state, lift_n, mirrored, robofly_hover_state,
};

use flapssm_wing::aero::blade_element::BladeElement;
use flapssm_wing::aero::quasi_steady::{
    ChordwiseModel, QuasiSteadyParams, QuasiSteadySection, added_mass, blasius_skin_friction,
    centre_of_pressure_frac, dickinson_drag, dickinson_lift, dickinson_normal,
    dickinson_tangential, plate_tangential, rotational_coefficient, translational_coefficients,
};
use flapssm_wing::aero::unsteady::{UnsteadyParams, UnsteadySection};
use flapssm_wing::aero::{SectionGeometry, SectionKinematics, SectionModel, SectionModelFactory};
use flapssm_wing::kinematics::{EulerState, WingKinematics};
use flapssm_wing::vortex::{Inflow, WakeMotion};
use std::f64::consts::{FRAC_PI_2, FRAC_PI_4, PI};

fn section() -> SectionGeometry {
    SectionGeometry {
        chord_m: 0.06,
        pitch_axis_frac: 0.15,
        radius_m: 0.178,
        density_kg_m3: 800.0,
    }
}

/// L1 with only the Wagner lag (LEV lag and inflow off).
fn wagner_only() -> UnsteadyParams {
    UnsteadyParams {
        lev_lag: false,
        inflow: false,
        ..UnsteadyParams::default()
    }
}

#[test]
fn dickinson_coefficients_match_published_values() {
    let d45 = 45f64.to_radians();
    assert!((dickinson_lift(d45) - 1.805).abs() < 1e-3);
    assert!((dickinson_drag(d45) - 1.704).abs() < 1e-3);
    assert!((dickinson_normal(FRAC_PI_2) - 3.461).abs() < 1e-3);
    assert!((centre_of_pressure_frac(FRAC_PI_4) - 0.255).abs() < 1e-3);
    assert!((rotational_coefficient(0.15) - 1.885).abs() < 1e-3);
    assert!((rotational_coefficient(0.25) - 1.571).abs() < 1e-3);
}

#[test]
fn blade_element_integrals_are_exact() {
    let be = BladeElement::new(blade(), 8, &QuasiSteadyParams::default()).unwrap();
    let i2: f64 = be
        .radii_m()
        .iter()
        .zip(be.weights_m())
        .map(|(r, w)| w * r * r)
        .sum();
    let i3: f64 = be
        .radii_m()
        .iter()
        .zip(be.weights_m())
        .map(|(r, w)| w * r * r * r)
        .sum();
    let exact2 = (0.235f64.powi(3) - 0.055f64.powi(3)) / 3.0;
    assert!((exact2 - 4.2705e-3).abs() < 1e-7);
    assert!((i2 - exact2).abs() / exact2 < 1e-12);
    let r_cp = i3 / i2;
    let exact_cp = (0.235f64.powi(4) - 0.055f64.powi(4)) / 4.0 / exact2;
    assert!((r_cp - exact_cp).abs() / exact_cp < 1e-12);
    assert!((r_cp - 0.1780).abs() < 1e-4);
}

/// Steady translation at 45° AoA: blade-element F_x = ½ρc C_N* |v|² ∫r²dr and
/// M_y = ½ρc C_N* |v|² ∫r²(r − r_s)dr (analytic), and 20 → 40 strips changes F by < 0.1 %.
#[test]
fn blade_element_translation_matches_analytic_and_converges() {
    let state = EulerState {
        angles_rad: [0.0, 0.0, -FRAC_PI_4],
        rates_rad_s: [2.0, 0.0, 0.0],
        accels_rad_s2: [0.0; 3],
    };
    let kin = WingKinematics::from_euler(&state);
    let params = QuasiSteadyParams {
        rotational: false,
        added_mass: false,
        ..Default::default()
    };
    let mut be = BladeElement::new(blade(), 6, &params).unwrap();
    let f = be.step(&kin, 0.0);
    let cn = flapssm_wing::aero::quasi_steady::plate_normal(FRAC_PI_4);
    let q = 0.5 * 800.0 * 0.06 * 4.0;
    let i2 = (0.235f64.powi(3) - 0.055f64.powi(3)) / 3.0;
    let i3 = (0.235f64.powi(4) - 0.055f64.powi(4)) / 4.0;
    // AoA = −45° here (v_x > 0), so the normal force is along −x.
    assert!((f[0] + cn * q * i2).abs() < 1e-12, "{}", f[0]);
    assert!((f[3] + 1e3 * cn * q * (i3 - 0.055 * i2)).abs() < 1e-9);
    for params in [QuasiSteadyParams::default()] {
        let state = EulerState {
            angles_rad: [0.3, 0.2, -0.7],
            rates_rad_s: [2.0, 0.7, 3.0],
            accels_rad_s2: [5.0, -2.0, 9.0],
        };
        let kin = WingKinematics::from_euler(&state);
        let f20 = BladeElement::new(blade(), 20, &params)
            .unwrap()
            .step(&kin, 0.0);
        let f40 = BladeElement::new(blade(), 40, &params)
            .unwrap()
            .step(&kin, 0.0);
        for i in 0..5 {
            assert!(
                (f20[i] - f40[i]).abs() <= 1e-3 * f40[i].abs(),
                "channel {i}: {} vs {}",
                f20[i],
                f40[i]
            );
        }
    }
}

/// Chordwise loads: the physics notes' C_T table, the flat-plate symmetry (no chordwise force
/// broadside on, continuity where t changes sign), the Re correction of the friction, and the
/// Kirchhoff force −ω × (m_a n_m x̂) of a plate translating normal to itself while rotating.
#[test]
fn chordwise_loads() {
    for (deg, c_t) in [(0.0, -0.393), (20.0, -0.165), (45.0, 0.071), (90.0, 0.101)] {
        let a = f64::to_radians(deg);
        assert!((dickinson_tangential(a) - c_t).abs() < 1e-3, "{deg}°");
    }
    assert!((plate_tangential(0.0) + 0.393).abs() < 1e-3);
    assert!(plate_tangential(FRAC_PI_2).abs() < 1e-15);
    assert!((blasius_skin_friction(1000.0) - 0.08399).abs() < 1e-4);
    let params = QuasiSteadyParams::default();
    assert_eq!(params.chordwise, ChordwiseModel::Dickinson);
    // LE-first along the chord: drag, reduced by the friction moved from Re 150 to Re 1000.
    let along = translational_coefficients(0.0, 1.0, &params);
    let expected = -0.393 + blasius_skin_friction(150.0) - blasius_skin_friction(1000.0);
    assert!((along.c_t - expected).abs() < 1e-3);
    // Reversing t mirrors c_t; near broadside on it tends to zero from both sides.
    for (n, t) in [(0.3, 0.7), (-0.5, 0.2), (1.0, 1e-9)] {
        let a = translational_coefficients(n, t, &params);
        let b = translational_coefficients(n, -t, &params);
        assert!((a.c_t + b.c_t).abs() < 1e-15);
        assert!((a.c_n - b.c_n).abs() < 1e-15);
    }
    assert!(translational_coefficients(1.0, 1e-9, &params).c_t.abs() < 1e-8);
    let friction = QuasiSteadyParams {
        chordwise: ChordwiseModel::SkinFriction,
        ..params
    };
    let f = translational_coefficients(0.6, 0.8, &friction);
    assert!((f.c_t + blasius_skin_friction(1000.0) * 0.8).abs() < 1e-12);
    // Kirchhoff: n = 0.2 m/s, ω_z = 3 rad/s about the axis at 15 % chord, so the mid-chord
    // normal velocity is n + (½ − x̂0)c·ω_z.
    let kin = SectionKinematics {
        normal_velocity_m_s: 0.2,
        rotation_rate_rad_s: 3.0,
        ..Default::default()
    };
    let m_a = PI / 4.0 * 800.0 * 0.06 * 0.06;
    let n_mid = 0.2 + 0.35 * 0.06 * 3.0;
    let l = added_mass(&section(), &kin);
    assert!((l.chordwise_n_m + m_a * 3.0 * n_mid).abs() < 1e-12);
}

#[test]
fn added_mass_of_a_plunging_plate() {
    let geom = SectionGeometry {
        pitch_axis_frac: 0.3,
        ..section()
    };
    for h_ddot in [-3.0, 0.5, 7.0] {
        let kin = SectionKinematics {
            normal_velocity_rate_m_s2: h_ddot,
            ..Default::default()
        };
        let l = added_mass(&geom, &kin);
        let exact = -PI / 4.0 * 800.0 * 0.06 * 0.06 * h_ddot;
        assert!((l.normal_n_m - exact).abs() <= 1e-12 * exact.abs());
    }
    // In still fluid with zero circulation the L0 and L1 forces are the added mass alone, in
    // phase with the acceleration (harmonic plunge, zero chordwise motion).
    let mut l1 = UnsteadySection::new(section(), UnsteadyParams::default());
    let l0 = QuasiSteadySection::new(section(), QuasiSteadyParams::default());
    let (omega, amp) = (2.0 * PI, 0.01);
    let dt = 1e-3;
    for k in 0..2000 {
        let t = k as f64 * dt;
        let kin = SectionKinematics {
            normal_velocity_m_s: 0.0,
            normal_velocity_rate_m_s2: -amp * omega * omega * (omega * t).sin(),
            ..Default::default()
        };
        let exact = -PI / 4.0 * 800.0 * 0.0036 * kin.normal_velocity_rate_m_s2;
        assert!((l0.loads(&kin).normal_n_m - exact).abs() < 1e-12);
        assert!((l1.step(&kin, dt).normal_n_m - exact).abs() < 1e-12);
    }
}

#[test]
fn zero_motion_gives_zero_load() {
    let kin = WingKinematics::from_euler(&EulerState {
        angles_rad: [0.4, -0.2, 1.0],
        ..Default::default()
    });
    for factory in [
        &QuasiSteadyParams::default() as &dyn SectionModelFactory,
        &UnsteadyParams::default(),
    ] {
        let mut be = BladeElement::new(blade(), 10, factory).unwrap();
        for _ in 0..50 {
            assert_eq!(be.step(&kin, 0.004), [0.0; 5]);
        }
    }
}

/// Impulsive start at 3°: the attached share cos²α of the translational force follows the
/// exact Wagner function φ(s) of the physics notes' table (the LEV share, sin²α, is
/// instantaneous when the LEV lag is off), within 0.015.
#[test]
fn wagner_step_response() {
    let table = [
        (1.0, 0.601),
        (2.0, 0.669),
        (4.0, 0.758),
        (10.0, 0.875),
        (20.0, 0.937),
    ];
    let (u, c) = (0.3, 0.06);
    let aoa = 3f64.to_radians();
    let kin = SectionKinematics {
        normal_velocity_m_s: -u * aoa.sin(),
        chord_velocity_m_s: u * aoa.cos(),
        ..Default::default()
    };
    let mut l1 = UnsteadySection::new(section(), wagner_only());
    let steady = QuasiSteadySection::new(section(), QuasiSteadyParams::default())
        .loads(&kin)
        .normal_n_m;
    let ds = 0.01;
    let dt = ds * c / (2.0 * u);
    let att = aoa.cos().powi(2);
    let expect = |phi: f64| att * phi + (1.0 - att);
    let first = l1.step(&kin, 0.0).normal_n_m / steady;
    assert!((first - expect(0.5)).abs() < 1e-12);
    let mut s = 0.0;
    let mut k = 0;
    while k < table.len() {
        let ratio = l1.step(&kin, dt).normal_n_m / steady;
        s += ds;
        if (s - table[k].0).abs() < 1e-6 {
            assert!(
                (ratio - expect(table[k].1)).abs() < 0.015,
                "s = {s}: {ratio} vs {}",
                table[k].1
            );
            k += 1;
        }
    }
}

/// Small-amplitude harmonic plunge at constant speed: the circulatory normal force relative to
/// its quasi-steady value must follow Theodorsen's C(k) (2 %, 2°).
#[test]
fn theodorsen_function() {
    let exact = [
        (0.1, 0.8319, -0.1723),
        (0.5, 0.5979, -0.1507),
        (1.0, 0.5394, -0.1003),
    ];
    let (u, c) = (0.3, 0.06);
    let params = UnsteadyParams {
        quasi_steady: QuasiSteadyParams {
            added_mass: false,
            ..Default::default()
        },
        ..wagner_only()
    };
    for (k, re, im) in exact {
        let omega = 2.0 * u * k / c;
        let period = 2.0 * PI / omega;
        let dt = period / 400.0;
        let mut l1 = UnsteadySection::new(section(), params);
        let qs = QuasiSteadySection::new(section(), params.quasi_steady);
        let (mut a_l1, mut a_qs) = ([0.0f64; 2], [0.0f64; 2]);
        let n_steps = 400 * 60;
        for i in 0..=n_steps {
            let t = i as f64 * dt;
            let kin = SectionKinematics {
                normal_velocity_m_s: 0.002 * u * (omega * t).sin(),
                chord_velocity_m_s: u,
                ..Default::default()
            };
            let y = l1.step(&kin, if i == 0 { 0.0 } else { dt }).normal_n_m;
            let y_qs = qs.loads(&kin).normal_n_m;
            if i >= n_steps - 400 * 10 && i < n_steps {
                let (s, co) = (omega * t).sin_cos();
                a_l1[0] += y * s;
                a_l1[1] += y * co;
                a_qs[0] += y_qs * s;
                a_qs[1] += y_qs * co;
            }
        }
        let amp = a_l1[0].hypot(a_l1[1]) / a_qs[0].hypot(a_qs[1]);
        let d = a_l1[1].atan2(a_l1[0]) - a_qs[1].atan2(a_qs[0]);
        let phase = d.sin().atan2(d.cos());
        let exact_amp = f64::hypot(re, im);
        let exact_phase = f64::atan2(im, re);
        assert!(
            (amp / exact_amp - 1.0).abs() < 0.02,
            "k = {k}: |C| {amp} vs {exact_amp}"
        );
        assert!(
            (phase - exact_phase).to_degrees().abs() < 2.0,
            "k = {k}: arg C {phase} vs {exact_phase}"
        );
    }
}

use flapssm_wing::trajectories::{Family, GeneratorConfig};
use flapssm_wing::virtual_wing::{Fidelity, VirtualWing, VirtualWingConfig};

/// The level `fidelity` as its module defines it ([`VirtualWingConfig::ideal`]).
fn wing(fidelity: Fidelity) -> VirtualWing {
    VirtualWing::new(&VirtualWingConfig {
        fidelity,
        ..VirtualWingConfig::ideal()
    })
    .unwrap()
}

fn generated_states(dt_s: f64, n: usize) -> Vec<EulerState> {
    let spec = GeneratorConfig::hovering()
        .generate_one(3, Family::FigureEight)
        .unwrap();
    (0..n).map(|k| spec.euler_state(k as f64 * dt_s)).collect()
}

/// (φ, ψ, α) → (−φ, ψ, −α) reflects the wing frame in x_w: F_x, M_y, M_z change sign,
/// F_y and M_x do not. Exact up to rounding for L0 and L1.
#[test]
fn mirror_symmetry() {
    let dt = 0.004;
    let states = generated_states(dt, 2000);
    let mirrored = mirrored(&states);
    for fidelity in [Fidelity::L0, Fidelity::L1, Fidelity::L3] {
        let mut w = wing(fidelity);
        let mut a = vec![[0.0; 5]; states.len()];
        let mut b = a.clone();
        w.aero_loads_into(&states, dt, &mut a);
        w.aero_loads_into(&mirrored, dt, &mut b);
        let scale: Vec<f64> = (0..5)
            .map(|c| a.iter().map(|y| y[c].abs()).fold(0.0, f64::max))
            .collect();
        let sign = [-1.0, 1.0, 1.0, -1.0, -1.0];
        for (ya, yb) in a.iter().zip(&b) {
            for c in 0..5 {
                assert!(
                    (yb[c] - sign[c] * ya[c]).abs() <= 1e-12 * scale[c],
                    "{fidelity:?} channel {c}"
                );
            }
        }
    }
}

/// Doubling the flapping frequency (and the viscosity: the same Reynolds number) multiplies
/// every load by 4 (coefficients unchanged).
#[test]
fn time_scaling_invariance() {
    let spec = GeneratorConfig::default()
        .generate_one(5, Family::Oval)
        .unwrap();
    let dt = 0.004;
    let n = 2500;
    let slow: Vec<EulerState> = (0..n).map(|k| spec.euler_state(k as f64 * dt)).collect();
    let fast: Vec<EulerState> = slow
        .iter()
        .map(|s| EulerState {
            angles_rad: s.angles_rad,
            rates_rad_s: s.rates_rad_s.map(|v| 2.0 * v),
            accels_rad_s2: s.accels_rad_s2.map(|v| 4.0 * v),
        })
        .collect();
    for fidelity in [Fidelity::L0, Fidelity::L1, Fidelity::L3] {
        let mut a = vec![[0.0; 5]; n];
        let mut b = a.clone();
        wing(fidelity).aero_loads_into(&slow, dt, &mut a);
        // The same Reynolds number: L3's wake cores diffuse with ν (L0 and L1 ignore it).
        let mut fast_cfg = VirtualWingConfig {
            fidelity,
            ..VirtualWingConfig::ideal()
        };
        fast_cfg.fluid.kinematic_viscosity_m2_s *= 2.0;
        VirtualWing::new(&fast_cfg)
            .unwrap()
            .aero_loads_into(&fast, dt / 2.0, &mut b);
        for c in 0..5 {
            let scale = a.iter().map(|y| y[c].abs()).fold(0.0, f64::max);
            for (ya, yb) in a.iter().zip(&b) {
                assert!(
                    (yb[c] / 4.0 - ya[c]).abs() <= 1e-9 * scale,
                    "{fidelity:?} channel {c}"
                );
            }
        }
    }
}

/// Asserts that sample `i` of the dataset plate's loads `y` (N, N·mm) lies inside the
/// dataset's plotted ranges: C_F ∈ [−4, 7] with `q_s` = ½ρSU_ref² (N), C_M ∈ [−11, 13] with
/// q_s·c̄ (c̄ = 0.06 m).
fn assert_in_dataset_ranges(y: &[f64; 5], q_s: f64, fidelity: Fidelity, i: usize) {
    let cf = [y[0] / q_s, y[1] / q_s];
    let cm = [2, 3, 4].map(|c| y[c] / (1e3 * q_s * 0.06));
    assert!(
        cf.iter().all(|v| (-4.0..=7.0).contains(v)),
        "{fidelity:?} sample {i}: C_F {cf:?}"
    );
    assert!(
        cm.iter().all(|v| (-11.0..=13.0).contains(v)),
        "{fidelity:?} sample {i}: C_M {cm:?}"
    );
}

/// Robofly-like hovering: φ = 80° sin(2πft), ψ = 0, symmetric rotation with α = ∓45° at
/// mid-stroke (AoA = 45°). Robofly convention for the mean lift coefficient (Sane & Dickinson
/// 2001): C̄_L = L̄ / (½ρc ∫r²dr · mean φ̇²) in [1.0, 1.8]; dataset convention (½ρSU_ref²,
/// ½ρc̄SU_ref²) for the instantaneous coefficients: inside the published plot ranges
/// C_F ∈ [−4, 7], C_M ∈ [−11, 13]; mid-stroke normal coefficient (Robofly convention) near
/// C_N ≈ 2.5.
#[test]
fn hovering_sanity() {
    let (f, amp) = (0.3, 80f64.to_radians());
    let state = |t: f64| robofly_hover_state(t, f);
    let dt = 1.0 / f / 800.0;
    let per_cycle = 800;
    let n = 6 * per_cycle;
    let states: Vec<EulerState> = (0..n).map(|i| state(i as f64 * dt)).collect();
    let u_ref = 0.235 * 4.0 * amp * f;
    let q_s = 0.5 * 800.0 * 0.0108 * u_ref * u_ref;
    let i2 = (0.235f64.powi(3) - 0.055f64.powi(3)) / 3.0;
    let q_robofly = |phi_dot2: f64| 0.5 * 800.0 * 0.06 * i2 * phi_dot2;
    for fidelity in [Fidelity::L0, Fidelity::L1, Fidelity::L3] {
        let mut wg = wing(fidelity);
        let mut y = vec![[0.0; 5]; n];
        wg.aero_loads_into(&states, dt, &mut y);
        let (mut lift, mut phi_dot2) = (0.0, 0.0);
        for i in n - per_cycle..n {
            lift += lift_n(&states[i], &y[i]);
            phi_dot2 += states[i].rates_rad_s[0].powi(2);
            assert_in_dataset_ranges(&y[i], q_s, fidelity, i);
        }
        let cl = lift / per_cycle as f64 / q_robofly(phi_dot2 / per_cycle as f64);
        let mid = n - per_cycle;
        let cn_mid = (y[mid][0] / q_robofly(states[mid].rates_rad_s[0].powi(2))).abs();
        eprintln!("{fidelity:?}: mean C_L = {cl:.3}, mid-stroke C_N = {cn_mid:.3}");
        assert!(
            (1.0..=1.8).contains(&cl),
            "{fidelity:?}: cycle-mean C_L = {cl}"
        );
        // L1 sits below QS at mid-stroke: at r_cp a ±80° half-stroke is only ≈ 8 chords of
        // travel, so the Wagner and LEV lags and the inflow have not settled.
        let band = if fidelity == Fidelity::L0 {
            2.3..=2.6
        } else {
            1.5..=2.6
        };
        assert!(
            band.contains(&cn_mid),
            "{fidelity:?}: mid-stroke C_N = {cn_mid}"
        );
    }
}

/// The default wing (L0 without the chordwise Kirchhoff force, docs/rig-agreement.md) on the
/// flat Robofly hover of [`hovering_sanity`]: that force took lift at the flips, so its
/// cycle-mean C_L rises above the L0 of the module (measured 1.861 against 1.799), above the
/// physics notes' [1.0, 1.8] band; pinned here, with the loads inside the dataset's ranges.
#[test]
fn default_wing_hover_lift() {
    let f = 0.3;
    let dt = 1.0 / f / 800.0;
    let (per_cycle, n) = (800, 6 * 800);
    let states: Vec<EulerState> = (0..n)
        .map(|i| robofly_hover_state(i as f64 * dt, f))
        .collect();
    let i2 = (0.235f64.powi(3) - 0.055f64.powi(3)) / 3.0;
    let q_robofly = |phi_dot2: f64| 0.5 * 800.0 * 0.06 * i2 * phi_dot2;
    let mean_cl = |cfg: &VirtualWingConfig| {
        let mut y = vec![[0.0; 5]; n];
        VirtualWing::new(cfg)
            .unwrap()
            .aero_loads_into(&states, dt, &mut y);
        let (mut lift, mut phi_dot2) = (0.0, 0.0);
        for i in n - per_cycle..n {
            lift += lift_n(&states[i], &y[i]);
            phi_dot2 += states[i].rates_rad_s[0].powi(2);
        }
        lift / per_cycle as f64 / q_robofly(phi_dot2 / per_cycle as f64)
    };
    let default = mean_cl(&VirtualWingConfig::default());
    let module = mean_cl(&VirtualWingConfig::ideal());
    eprintln!("flat Robofly hover, L0: mean C_L {default:.3} (default wing), {module:.3} (module)");
    assert!(
        (1.82..=1.90).contains(&default),
        "default wing C_L {default}"
    );
    assert!(
        module < default && (1.0..=1.8).contains(&module),
        "module L0 C_L {module}"
    );
}

/// Hovering figure-of-eight (physics notes §4.4.9): the Robofly stroke ±80° at 0.3 Hz
/// with deviation ψ = −15° sin 2x (tip falling through mid-stroke, rising through the
/// reversals) and AoA = 45° at mid-stroke, 8 cycles, 500 samples per cycle, at every fidelity.
/// In every cycle after the first:
/// - mean lift (global y₀) coefficient C̄_L = L̄ / (½ρc∫r²dr · mean |v|²) in [1.0, 1.8]; |v|² at
///   unit span includes ψ̇², so with ψ = 0 this is the Robofly convention of `hovering_sanity`;
/// - every sample's C_F (½ρSU_ref²) in [−4, 7] and C_M (½ρc̄SU_ref²) in [−11, 13], with U_ref
///   the published R·mean sqrt(φ̇² + ψ̇²) over a cycle.
///
/// Measured per-cycle C̄_L: L0 1.700, L1 1.033, L2 1.632–1.645 (docs/virtual-wing.md). L3, the
/// default wing, gives 0.965, below this band, which is the flat stroke's carried over without a
/// published figure-of-eight value; it is an open gap of L3 (docs/lab/vortex-method-rounds.md, rounds 13
/// and 14), not loosened here.
#[test]
fn hovering_figure_eight_sanity() {
    for fidelity in [Fidelity::L0, Fidelity::L1, Fidelity::L2] {
        let hover = figure_eight_hover(&mut wing(fidelity), 15.0);
        for (i, y) in hover.loads.iter().enumerate().skip(PER_CYCLE_8) {
            assert_in_dataset_ranges(y, hover.q_s, fidelity, i);
        }
        let mean_cl = hover.mean_cl;
        eprintln!("figure-of-eight hover, {fidelity:?}: per-cycle mean C_L {mean_cl:.3?}");
        assert!(
            mean_cl.iter().all(|c| (1.0..=1.8).contains(c)),
            "{fidelity:?}: per-cycle mean C_L {mean_cl:?}"
        );
    }
}

const PER_CYCLE_8: usize = 500;

/// The figure-of-eight hover of `hovering_figure_eight_sanity` (0.3 Hz, 8 cycles, deviation
/// amplitude `deviation_deg`; 0 is the flat Robofly stroke) through `wing`.
struct FigureEightHover {
    /// Noise-free loads per sample.
    loads: Vec<[f64; 5]>,
    /// Force scale ½ρSU_ref² (N).
    q_s: f64,
    /// Mean C_L of cycles 2–8.
    mean_cl: Vec<f64>,
}

fn figure_eight_hover(wing: &mut VirtualWing, deviation_deg: f64) -> FigureEightHover {
    let (f, per_cycle, cycles) = (0.3, PER_CYCLE_8, 8);
    let dt = 1.0 / f / per_cycle as f64;
    let states: Vec<EulerState> = (0..cycles * per_cycle)
        .map(|i| figure_eight_hover_state(i as f64 * dt, f, deviation_deg.to_radians()))
        .collect();
    let u_ref = 0.235
        * states[..per_cycle]
            .iter()
            .map(|s| s.rates_rad_s[0].hypot(s.rates_rad_s[1]))
            .sum::<f64>()
        / per_cycle as f64;
    let q_s = 0.5 * 800.0 * 0.0108 * u_ref * u_ref;
    let i2 = (0.235f64.powi(3) - 0.055f64.powi(3)) / 3.0;
    let mut loads = vec![[0.0; 5]; states.len()];
    wing.aero_loads_into(&states, dt, &mut loads);
    let mean_cl = (1..cycles)
        .map(|cycle| {
            let (mut lift, mut speed2) = (0.0, 0.0);
            for i in cycle * per_cycle..(cycle + 1) * per_cycle {
                lift += lift_n(&states[i], &loads[i]);
                speed2 += WingKinematics::from_euler(&states[i]).speed.powi(2);
            }
            lift / (0.5 * 800.0 * 0.06 * i2 * speed2)
        })
        .collect();
    FigureEightHover {
        loads,
        q_s,
        mean_cl,
    }
}

/// The default strip count (8) is converged for L1 on a generated trajectory: every channel
/// within 0.5 % of its peak of the 40-strip result.
#[test]
fn default_strip_count_is_converged() {
    let dt = 0.004;
    let states = generated_states(dt, 3000);
    let run = |n_strips| {
        let cfg = VirtualWingConfig {
            fidelity: Fidelity::L1,
            n_strips,
            ..VirtualWingConfig::ideal()
        };
        let mut w = VirtualWing::new(&cfg).unwrap();
        let mut y = vec![[0.0; 5]; states.len()];
        w.aero_loads_into(&states, dt, &mut y);
        y
    };
    assert_eq!(VirtualWingConfig::default().n_strips, 8);
    let (a, b) = (run(8), run(40));
    for c in 0..5 {
        let peak = b.iter().map(|y| y[c].abs()).fold(0.0, f64::max);
        let err = a
            .iter()
            .zip(&b)
            .map(|(x, y)| (x[c] - y[c]).abs())
            .fold(0.0, f64::max);
        assert!(err <= 5e-3 * peak, "channel {c}: {err} vs peak {peak}");
    }
}

/// `simulate_dataset` of `n` hovering-generator trajectories (the first `n_train` for training,
/// seed `seed`) on `wing` with every sensor effect off.
fn noise_free_dataset(
    mut wing: VirtualWingConfig,
    n: usize,
    n_train: usize,
    seed: u64,
) -> flapssm_wing::dataset::ValidDataset {
    use flapssm_wing::sensor::SensorConfig;
    use flapssm_wing::trajectories::GeneratorConfig;
    use flapssm_wing::virtual_wing::{SimulationConfig, simulate_dataset};
    wing.sensor = SensorConfig::noise_free();
    let cfg = SimulationConfig {
        wing,
        trajectories: GeneratorConfig {
            n_trajectories: n,
            n_train,
            seed,
            ..GeneratorConfig::hovering()
        },
    };
    simulate_dataset(&cfg, &|| {}).unwrap()
}

/// `simulate` at L2 (strip LDVM, 2 strips): every load finite on random trajectories of the
/// hovering generator, and the same size as L0 (least-squares slope of L2 on L0 F_x; measured
/// on these 3 trajectories: slope 0.87, uncentred correlation 0.97; L1 is about half of L0).
#[test]
fn l2_dataset_is_finite_and_sized_like_l0() {
    let run = |fidelity| {
        let wing = VirtualWingConfig {
            fidelity,
            ..Default::default()
        };
        let ds = noise_free_dataset(wing, 3, 2, 1);
        assert_eq!(
            ds.meta.settings["fidelity"] == "l2",
            fidelity == Fidelity::L2,
            "{}",
            ds.meta.settings["fidelity"]
        );
        ds.trajectories
            .iter()
            .flat_map(|t| t.outputs.as_ref().unwrap().iter().map(|row| row[0]))
            .collect::<Vec<f64>>()
    };
    let (l0, l2) = (run(Fidelity::L0), run(Fidelity::L2));
    assert!(l2.iter().all(|v| v.is_finite()));
    let dot = |a: &[f64], b: &[f64]| a.iter().zip(b).map(|(x, y)| x * y).sum::<f64>();
    let slope = dot(&l0, &l2) / dot(&l0, &l0);
    let corr = dot(&l0, &l2) / (dot(&l0, &l0) * dot(&l2, &l2)).sqrt();
    println!("L2 on L0, F_x: slope {slope:.2}, uncentred correlation {corr:.2}");
    assert!((0.6..=1.6).contains(&slope), "slope {slope}");
    assert!(corr > 0.6, "correlation {corr}");
}

/// A bad L2 setting is refused before anything runs, and the message names the field.
#[test]
fn invalid_l2_settings_are_refused_by_name() {
    let mut cfg = VirtualWingConfig {
        fidelity: Fidelity::L2,
        ..Default::default()
    };
    cfg.l2.max_step_chords = 0.0;
    let e = cfg.check().unwrap_err().to_string();
    assert!(e.contains("max_step_chords"), "{e}");
    cfg.l2.max_step_chords = 0.0125;
    cfg.l2.ldvm.core_radius_frac = f64::NAN;
    let e = VirtualWing::new(&cfg)
        .err()
        .expect("NaN core radius")
        .to_string();
    assert!(e.contains("core_radius_frac"), "{e}");
    cfg.l2.ldvm.core_radius_frac = 0.02;
    cfg.l2.profile_drag = -0.1;
    let e = cfg.check().unwrap_err().to_string();
    assert!(e.contains("profile_drag"), "{e}");
    cfg.l2.profile_drag = 0.26;
    assert!(cfg.check().is_ok());
}

/// Raw noise-free loads of trajectories `indices` of the hovering generator (seed 1, 548
/// trajectories; the generator these regression cases were found on), all run in order on one
/// reused wing `cfg`.
fn raw_loads_on_one_wing(cfg: &VirtualWingConfig, indices: &[usize]) -> Vec<Vec<[f64; 5]>> {
    use flapssm_wing::trajectories::{GeneratorConfig, default_n_train};
    let gen_cfg = GeneratorConfig {
        n_trajectories: 548,
        n_train: default_n_train(548),
        seed: 1,
        ..GeneratorConfig::hovering()
    };
    let specs = gen_cfg.generate().unwrap();
    let dt = gen_cfg.sampling.raw_dt_s();
    let mut wing = VirtualWing::new(cfg).unwrap();
    let mut states = vec![EulerState::default(); gen_cfg.sampling.n_raw()];
    indices
        .iter()
        .map(|&i| {
            specs[i].sample_into(dt, &mut states);
            let mut out = vec![[0.0; 5]; states.len()];
            wing.aero_loads_into(&states, dt, &mut out);
            out
        })
        .collect()
}

/// A reused wing (one per rayon worker in `simulate`) gives a trajectory exactly the loads of a
/// fresh wing, whatever ran before: otherwise the same seed could give different files. (At L2
/// the solver kept the previous trajectory's U_ref until the section moved.)
#[test]
fn loads_do_not_depend_on_the_previous_trajectory() {
    for fidelity in [Fidelity::L0, Fidelity::L1, Fidelity::L2] {
        let cfg = VirtualWingConfig {
            fidelity,
            ..Default::default()
        };
        let fresh = raw_loads_on_one_wing(&cfg, &[194]);
        let reused = raw_loads_on_one_wing(&cfg, &[193, 194]);
        assert!(
            fresh[0] == reused[1],
            "{fidelity:?}: trajectory 194 differs after trajectory 193"
        );
    }
}

/// Asserts that the largest |F_x|, |F_y| of each trajectory's raw loads under `cfg` is finite
/// and below 15 N (printed with `label` first).
fn assert_peak_force_below_15_n(cfg: &VirtualWingConfig, indices: &[usize], label: &str) {
    for (run, i) in raw_loads_on_one_wing(cfg, indices).iter().zip(indices) {
        let peak = run
            .iter()
            .flat_map(|y| [y[0].abs(), y[1].abs()])
            .fold(0.0, f64::max);
        println!("{label}trajectory {i}: max |F| {peak:.2} N");
        assert!(
            peak.is_finite() && peak < 15.0,
            "{label}trajectory {i}: max |F| {peak} N"
        );
    }
}

/// Hovering-generator trajectories on which L2 blew up (|F| of 10⁵ N from a strong wake vortex
/// met at the leading edge, before the LEV sign check and the viscous core growth) stay bounded:
/// the noise-free L0 loads of the generator peak at a few newtons.
#[test]
fn l2_stays_bounded_where_it_once_blew_up() {
    let cfg = VirtualWingConfig {
        fidelity: Fidelity::L2,
        ..Default::default()
    };
    assert_peak_force_below_15_n(&cfg, &[475, 133, 434], "");
}

/// With larger vortex cores (r_c0 = 0.05 c and 0.1 c, inside the plausible range), the LEV
/// chain of these trajectories drifted round the leading edge to the pressure face; the next
/// LEVs, placed towards it, raised |LESP| instead of lowering it and ran away (measured before
/// the side check: max |F| 412, 1247, 1585 N at 0.05 c and 81, 297, 148 N at 0.1 c; 9 and 10
/// of the first 150 trajectories above 15 N). Now they stay at the default core's few newtons.
#[test]
fn l2_lev_chain_stays_on_the_suction_side_with_large_cores() {
    for (core, indices) in [(0.05, [31, 37, 84]), (0.1, [17, 52, 139])] {
        let mut cfg = VirtualWingConfig {
            fidelity: Fidelity::L2,
            ..Default::default()
        };
        cfg.l2.ldvm.core_radius_frac = core;
        assert_peak_force_below_15_n(&cfg, &indices, &format!("r_c0 = {core} c, "));
    }
}

/// Noise-free L2 outputs [F_x … M_z] of 24 hovering-generator trajectories (seed 2021) from
/// sample 100 on, with the vortex core r_c0 scaled by `core_scale`.
fn l2_outputs_from_sample_100(core_scale: f64) -> Vec<[f64; 5]> {
    let mut wing = VirtualWingConfig {
        fidelity: Fidelity::L2,
        ..Default::default()
    };
    wing.l2.ldvm.core_radius_frac *= core_scale;
    let ds = noise_free_dataset(wing, 24, 20, 2021);
    from_sample_100(&ds)
}

fn from_sample_100(ds: &flapssm_wing::dataset::ValidDataset) -> Vec<[f64; 5]> {
    ds.trajectories
        .iter()
        .flat_map(|t| t.outputs.as_ref().unwrap()[100..].to_vec())
        .collect()
}

/// RMS change of each output between `base` and `nudged`, in standard deviations of `base`.
fn change_in_sd(base: &[[f64; 5]], nudged: &[[f64; 5]]) -> [f64; 5] {
    let n = base.len() as f64;
    std::array::from_fn(|c| {
        let mean = base.iter().map(|y| y[c]).sum::<f64>() / n;
        let sd = (base.iter().map(|y| (y[c] - mean).powi(2)).sum::<f64>() / n).sqrt();
        let rms = (base
            .iter()
            .zip(nudged)
            .map(|(a, b)| (a[c] - b[c]).powi(2))
            .sum::<f64>()
            / n)
            .sqrt();
        rms / sd
    })
}

/// The L2 data are a reproducible function of the kinematics: a 0.1 % change of the vortex
/// core moves no output by more than a quarter of its standard deviation (measured: F_x … M_z
/// 0.128, 0.049, 0.055, 0.138, 0.150 σ). With a long-lived 2-D wake (TEV decay
/// over 40 chords) it moved F_x, M_y and M_z by 0.40–0.44 σ here, about as much as L2 differed
/// from L0: the wake encounters were chaotic, and no model could learn them from the kinematics.
#[test]
fn l2_outputs_are_insensitive_to_a_small_parameter_change() {
    let shares = change_in_sd(
        &l2_outputs_from_sample_100(1.0),
        &l2_outputs_from_sample_100(1.001),
    );
    println!("rms change from r_c0 × 1.001, in σ of each output: {shares:.3?}");
    for (c, share) in shares.iter().enumerate() {
        assert!(*share < 0.25, "output {c}: {share:.3} σ");
    }
}

/// The same 0.1 % core change on the measured-like default generator and on the paper's
/// measured trajectories (24 each, noise-free L2), checked against its record
/// (docs/vortex-method.md); `cargo test --release -p flapssm-wing --test physics
/// l2_sensitivity_study -- --nocapture` prints it.
#[test]
fn l2_sensitivity_study() {
    let [d, p] = l2_sensitivity(&l2_config());
    println!("default generator: rms change from r_c0 × 1.001 (σ): {d:.3?}");
    println!("paper's trajectories: rms change from r_c0 × 1.001 (σ): {p:.3?}");
    assert_recorded(
        "default generator",
        &d,
        &[0.280, 0.239, 0.214, 0.253, 0.309],
        0.01,
    );
    assert_recorded("paper", &p, &[0.227, 0.201, 0.209, 0.241, 0.263], 0.01);
}

/// The default wing at L2.
fn l2_config() -> VirtualWingConfig {
    VirtualWingConfig {
        fidelity: Fidelity::L2,
        ..Default::default()
    }
}

/// RMS change (σ of each output) of the noise-free outputs of `base` from sample 100 on when its
/// vortex core r_c0 grows by 0.1 % (L3: the viscosity, which sets its cores): on 24 default-generator trajectories (seed 2021) and on the
/// paper's first 24 measured trajectories.
fn l2_sensitivity(base: &VirtualWingConfig) -> [[f64; 5]; 2] {
    use flapssm_wing::sensor::SensorConfig;
    use flapssm_wing::trajectories::paper::paper_angles;
    use flapssm_wing::trajectories::{GeneratorConfig, SamplingConfig};
    use flapssm_wing::virtual_wing::{SimulationConfig, simulate_angles_dataset, simulate_dataset};
    let wing = |scale: f64| {
        let mut w = VirtualWingConfig {
            sensor: SensorConfig::noise_free(),
            ..base.clone()
        };
        w.l2.ldvm.core_radius_frac *= scale;
        if w.fidelity == Fidelity::L3 {
            // L3's cores follow from the viscosity (the Blasius thickness, then diffusion).
            w.fluid.kinematic_viscosity_m2_s *= scale;
        }
        w
    };
    let generated = |scale| {
        let cfg = SimulationConfig {
            wing: wing(scale),
            trajectories: GeneratorConfig {
                n_trajectories: 24,
                n_train: 20,
                seed: 2021,
                ..GeneratorConfig::default()
            },
        };
        from_sample_100(&simulate_dataset(&cfg, &|| {}).unwrap())
    };
    let angles = paper_angles(24);
    let paper = |scale| {
        let ds = simulate_angles_dataset(
            &wing(scale),
            &angles,
            &SamplingConfig::default(),
            1,
            20,
            "paper 0..24",
            &|| {},
        );
        from_sample_100(&ds.unwrap())
    };
    [
        change_in_sd(&generated(1.0), &generated(1.001)),
        change_in_sd(&paper(1.0), &paper(1.001)),
    ]
}

/// Trajectories whose raw (250 Hz, noise-free) L2 peak |F_x| exceeds 1.5× the L0 peak + 1 N
/// (the burst criterion of docs/vortex-method.md), among the first 150 of the hovering
/// generator, the default generator (seed 1, 548) and the paper's measured trajectories. A
/// study checked against its record: `cargo test --release -p flapssm-wing --test physics l2_burst_study --
/// --ignored --nocapture`.
#[test]
#[ignore = "study (≈ 2 min): L2 bursts on three trajectory sets against their record; run by scripts/wing_studies.py, output in docs/lab/wing-studies.md"]
fn l2_burst_study() {
    let found = l2_bursts(&l2_config(), true);
    for (name, bursts, worst) in &found {
        println!(
            "{name}: {bursts} of 150 with a burst; worst L2 peak / (1.5·L0 peak + 1 N) = {worst:.2}"
        );
    }
    let counts: Vec<f64> = found.iter().map(|f| f.1 as f64).collect();
    assert_recorded("bursts", &counts, &[8.0, 10.0, 11.0], 1.0);
    let worst: Vec<f64> = found.iter().map(|f| f.2).collect();
    assert_recorded("worst ratio", &worst, &[3.30, 1.86, 2.65], 0.05);
}

/// (set, trajectories with a burst among the first 150, worst ratio) of the wing `l2` on the
/// default generator (seed 1, 548) and the paper's measured trajectories, and on the hovering
/// generator if `hovering`.
fn l2_bursts(l2: &VirtualWingConfig, hovering: bool) -> Vec<(&'static str, usize, f64)> {
    use flapssm_wing::trajectories::measured::raw_states;
    use flapssm_wing::trajectories::paper::paper_angles;
    use flapssm_wing::trajectories::{GeneratorConfig, SamplingConfig, default_n_train};
    let sampling = SamplingConfig::default();
    let dt = sampling.raw_dt_s();
    let generated = |cfg: GeneratorConfig| -> Vec<Vec<EulerState>> {
        let cfg = GeneratorConfig {
            n_trajectories: 548,
            n_train: default_n_train(548),
            seed: 1,
            ..cfg
        };
        let specs = cfg.generate().unwrap();
        specs[..150]
            .iter()
            .map(|s| s.sample_raw(&sampling))
            .collect()
    };
    let paper: Vec<Vec<EulerState>> = paper_angles(150)
        .iter()
        .map(|a| raw_states(a, &sampling).unwrap())
        .collect();
    let mut sets = vec![
        ("default", generated(GeneratorConfig::default())),
        ("paper", paper),
    ];
    if hovering {
        sets.insert(0, ("hovering", generated(GeneratorConfig::hovering())));
    }
    let peak = |mut w: VirtualWing, states: &[EulerState]| {
        let mut y = vec![[0.0; 5]; states.len()];
        w.aero_loads_into(states, dt, &mut y);
        y[250..].iter().map(|r| r[0].abs()).fold(0.0, f64::max)
    };
    sets.into_iter()
        .map(|(name, set)| {
            let ratios: Vec<f64> = set
                .iter()
                .map(|s| {
                    peak(VirtualWing::new(l2).unwrap(), s)
                        / (1.5 * peak(wing(Fidelity::L0), s) + 1.0)
                })
                .collect();
            let bursts = ratios.iter().filter(|&&r| r > 1.0).count();
            (name, bursts, ratios.iter().copied().fold(0.0, f64::max))
        })
        .collect()
}

/// Repeatability as a rig has it: the same kinematics reached from two histories (ramp-ins of
/// 0.5 s and 3.72 s, identical motion after the longer one) should give the same noise-free
/// loads within a cycle or two. Prints the rms difference of each output per cycle after the
/// longer ramp, in standard deviations, on 12 default-generator trajectories, for L1 and L2.
/// Checked against its record; `cargo test --release -p flapssm-wing --test physics
/// repeatability_study -- --nocapture` prints it.
#[test]
fn repeatability_study() {
    // Recorded: L1 forgets within a cycle; L2's free wake keeps 0.05–0.17 σ.
    let recorded = [
        (Fidelity::L1, [0.075, 0.005, 0.004, 0.008], 0.005),
        (Fidelity::L2, [0.199, 0.170, 0.131, 0.142], 0.01),
    ];
    for (fidelity, worst_per_cycle, tol) in recorded {
        let cfg = VirtualWingConfig {
            fidelity,
            ..VirtualWingConfig::ideal()
        };
        let rep = repeatability(&cfg, 12);
        for (cycle, rel) in rep.iter().enumerate() {
            println!(
                "{fidelity:?}, cycle {} after the long ramp: rms difference / σ {rel:.3?}",
                cycle + 1
            );
        }
        let worst: Vec<f64> = rep
            .iter()
            .map(|r| r.iter().copied().fold(0.0, f64::max))
            .collect();
        assert_recorded(
            &format!("{fidelity:?} worst output per cycle"),
            &worst,
            &worst_per_cycle,
            tol,
        );
    }
}

/// Loads of `n` default-generator trajectories (seed 7) reached through ramp-ins of 0.5 s and
/// 3.72 s (identical motion after the longer one): per cycle after the longer ramp (1st … 4th),
/// the rms difference of each output [F_x, F_y, M_x, M_y, M_z] in standard deviations.
fn repeatability(wing_cfg: &VirtualWingConfig, n: usize) -> [[f64; 5]; 4] {
    use flapssm_wing::trajectories::GeneratorConfig;
    let cfg = GeneratorConfig {
        n_trajectories: n,
        n_train: n - 1,
        seed: 7,
        ..GeneratorConfig::default()
    };
    let sampling = &cfg.sampling;
    let dt = sampling.raw_dt_s();
    // Per cycle: Σ squared difference, Σ squared deviation.
    let mut sums = [[[0.0f64; 2]; 5]; 4];
    for spec in cfg.generate().unwrap() {
        let run = |ramp_s: f64| {
            let mut s = spec.clone();
            s.ramp_s = ramp_s;
            let states = s.sample_raw(sampling);
            let mut w = VirtualWing::new(wing_cfg).unwrap();
            let mut y = vec![[0.0; 5]; states.len()];
            w.aero_loads_into(&states, dt, &mut y);
            y
        };
        let (short, long) = (run(0.5), run(3.72));
        let period = 1.0 / spec.frequency_hz;
        let start = (3.72 / dt).ceil() as usize;
        let mean: [f64; 5] = std::array::from_fn(|c| {
            long[start..].iter().map(|y| y[c]).sum::<f64>() / (long.len() - start) as f64
        });
        for (k, (a, b)) in short.iter().zip(&long).enumerate().skip(start) {
            let cycle = ((k - start) as f64 * dt / period) as usize;
            if cycle < 4 {
                for c in 0..5 {
                    sums[cycle][c][0] += (a[c] - b[c]).powi(2);
                    sums[cycle][c][1] += (b[c] - mean[c]).powi(2);
                }
            }
        }
    }
    sums.map(|s| s.map(|[d, v]| (d / v).sqrt()))
}

/// The chordwise loads (F_y, M_x) of L2 forget how the motion began: two ramp-ins of the same
/// kinematics, 4 trajectories, under 0.15 σ apart in the 2nd cycle after the longer ramp.
#[test]
fn l2_chordwise_loads_forget_how_the_motion_began() {
    let cfg = VirtualWingConfig {
        fidelity: Fidelity::L2,
        ..VirtualWingConfig::ideal()
    };
    let second = repeatability(&cfg, 4)[1];
    assert!(second[1] < 0.15 && second[2] < 0.15, "{second:?}");
}

/// L2 with a frozen wake ([`WakeMotion::Frozen`]) and no inflow is not chaotic: the 0.1 % core
/// change of `l2_outputs_are_insensitive_to_a_small_parameter_change` moves no output by more
/// than 0.06 σ (measured 0.025, 0.005, 0.005, 0.014, 0.033 σ; the free wake 0.13–0.29 σ).
#[test]
fn l2_frozen_wake_is_not_chaotic() {
    let outputs = |scale: f64| {
        let mut wing = l2_config();
        wing.l2.ldvm.wake_motion = WakeMotion::Frozen;
        wing.l2.ldvm.core_radius_frac *= scale;
        from_sample_100(&noise_free_dataset(wing, 24, 20, 2021))
    };
    let shares = change_in_sd(&outputs(1.0), &outputs(1.001));
    for (c, share) in shares.iter().enumerate() {
        assert!(*share < 0.06, "output {c}: {share:.3} σ");
    }
}

/// The L2 wake models side by side: the free wake (default), a
/// frozen wake, and a frozen wake carried down by an induced inflow (w = k·U_ref, or from momentum
/// theory). Prints the mean C_L of the flat-stroke and the figure-of-eight hover (cycles 2–8),
/// the r_c0 × 1.001 change, the repeatability in the 2nd and
/// 3rd cycles and the bursts; the C_L checked against its record. A study: `cargo test --release -p flapssm-wing --test
/// physics l2_wake_motion_study -- --ignored --nocapture` (≈ 8 min on 2 cores).
#[test]
#[ignore = "study (≈ 8 min): the free and the frozen wake on the three criteria, C_L against its record; run by scripts/wing_studies.py, output in docs/lab/wing-studies.md"]
fn l2_wake_motion_study() {
    let uniform = |ratio| Inflow::Uniform { ratio };
    let variants = [
        ("free", WakeMotion::Free, Inflow::Still),
        ("frozen", WakeMotion::Frozen, Inflow::Still),
        ("frozen, k 0.1", WakeMotion::Frozen, uniform(0.1)),
        ("frozen, k 0.2", WakeMotion::Frozen, uniform(0.2)),
        ("frozen, k 0.26", WakeMotion::Frozen, uniform(0.26)),
        ("frozen, momentum", WakeMotion::Frozen, Inflow::Momentum),
        ("free, momentum", WakeMotion::Free, Inflow::Momentum),
    ];
    // Recorded mean C_L (flat stroke, figure-of-eight) of each variant.
    let recorded = [
        [1.622, 1.631],
        [2.883, 2.165],
        [2.281, 1.672],
        [2.078, 1.145],
        [2.009, 0.870],
        [1.987, 1.260],
        [1.369, 1.179],
    ];
    for ((name, motion, inflow), cl_recorded) in variants.into_iter().zip(recorded) {
        let mut cfg = l2_config();
        cfg.l2.ldvm.wake_motion = motion;
        cfg.l2.inflow = inflow;
        let cl = |deviation_deg| {
            let cl =
                figure_eight_hover(&mut VirtualWing::new(&cfg).unwrap(), deviation_deg).mean_cl;
            cl.iter().sum::<f64>() / cl.len() as f64
        };
        let (cl_flat, cl_mean) = (cl(0.0), cl(15.0));
        let [d, p] = l2_sensitivity(&cfg);
        let rep = repeatability(&cfg, 12);
        let bursts = l2_bursts(&cfg, false);
        println!(
            "{name}: C_L flat stroke {cl_flat:.3}, figure-of-eight {cl_mean:.3}; r_c0 × 1.001 default {d:.3?} paper {p:.3?}; \
             two histories, 2nd cycle {:.3?} 3rd {:.3?}; bursts {bursts:?}",
            rep[1], rep[2]
        );
        assert_recorded(
            &format!("{name}: C_L"),
            &[cl_flat, cl_mean],
            &cl_recorded,
            0.02,
        );
    }
}

/// L3 (vortex lattice) on the criteria of a rig's loads (docs/vortex-method.md, "Current
/// figures"): hover lift on the flat and the figure-of-eight stroke, the r_c0 × 1.001 change, two
/// histories per cycle, bursts, checked against its record. A study: `cargo test --release -p flapssm-wing --test physics l3_study --
/// --ignored --nocapture`.
#[test]
#[ignore = "study (≈ 2 min): the L3 vortex lattice on the criteria of a rig's loads against its record; run by scripts/wing_studies.py, output in docs/lab/wing-studies.md"]
fn l3_study() {
    let cfg = VirtualWingConfig {
        fidelity: Fidelity::L3,
        ..VirtualWingConfig::ideal()
    };
    let mut w = VirtualWing::new(&cfg).unwrap();
    let flat = figure_eight_hover(&mut w, 0.0).mean_cl;
    let eight = figure_eight_hover(&mut w, 15.0).mean_cl;
    println!(
        "C_L flat {:.3} figure-of-eight {:.3}",
        mean(&flat),
        mean(&eight)
    );
    assert_recorded("C_L", &[mean(&flat), mean(&eight)], &[1.390, 0.965], 0.02);
    let [d, p] = l2_sensitivity(&cfg);
    println!("r_c0 × 1.001 (σ): default {d:.3?} paper {p:.3?}");
    assert_recorded("r_c0 × 1.001", &[d, p].concat(), &[0.0; 10], 0.002);
    let rep = repeatability(&cfg, 12);
    for (cycle, rel) in rep.iter().enumerate() {
        println!("two histories, cycle {}: {rel:.3?}", cycle + 1);
    }
    let worst: Vec<f64> = rep
        .iter()
        .map(|r| r.iter().copied().fold(0.0, f64::max))
        .collect();
    assert_recorded(
        "two histories, worst output per cycle",
        &worst,
        &[0.355, 0.095, 0.054, 0.047],
        0.01,
    );
    let bursts = l2_bursts(&cfg, false);
    for (name, bursts, worst) in &bursts {
        println!("{name}: {bursts} of 150 with a burst; worst ratio {worst:.2}");
    }
    let counts: Vec<f64> = bursts.iter().map(|b| b.1 as f64).collect();
    assert_recorded("bursts", &counts, &[0.0, 0.0], 0.0);
}

fn mean(v: &[f64]) -> f64 {
    v.iter().sum::<f64>() / v.len() as f64
}

/// L3 is not chaotic: a 0.1 % change of the viscosity (which sets its wake cores) moves no
/// noise-free output of the paper's first 6 trajectories by more than 0.01 σ (the strips' free
/// wake: 0.18–0.32 σ for r_c0 × 1.001, `l2_sensitivity_study`).
#[test]
fn l3_is_not_chaotic() {
    use flapssm_wing::sensor::SensorConfig;
    use flapssm_wing::trajectories::SamplingConfig;
    use flapssm_wing::trajectories::paper::paper_angles;
    use flapssm_wing::virtual_wing::simulate_angles_dataset;
    let angles = paper_angles(6);
    let run = |scale: f64| {
        let mut wing = VirtualWingConfig {
            fidelity: Fidelity::L3,
            sensor: SensorConfig::noise_free(),
            ..Default::default()
        };
        wing.fluid.kinematic_viscosity_m2_s *= scale;
        let ds = simulate_angles_dataset(
            &wing,
            &angles,
            &SamplingConfig::default(),
            1,
            5,
            "paper",
            &|| {},
        );
        from_sample_100(&ds.unwrap())
    };
    let change = change_in_sd(&run(1.0), &run(1.001));
    assert!(change.iter().all(|c| *c < 0.01), "{change:?}");
}

/// The burst criterion of docs/vortex-method.md (raw peak |F_x| ≤ 1.5× the L0 peak + 1 N) holds
/// for L3 on the paper's first 16 measured trajectories and 16 of the default generator (the
/// study `l3_study` counts 150 of each).
#[test]
fn l3_has_no_bursts() {
    use flapssm_wing::trajectories::measured::raw_states;
    use flapssm_wing::trajectories::paper::paper_angles;
    use flapssm_wing::trajectories::{GeneratorConfig, SamplingConfig};
    let sampling = SamplingConfig::default();
    let dt = sampling.raw_dt_s();
    let generated = GeneratorConfig {
        n_trajectories: 16,
        n_train: 15,
        seed: 1,
        ..GeneratorConfig::default()
    };
    let mut sets: Vec<Vec<EulerState>> = paper_angles(16)
        .iter()
        .map(|a| raw_states(a, &sampling).unwrap())
        .collect();
    sets.extend(
        generated
            .generate()
            .unwrap()
            .iter()
            .map(|s| s.sample_raw(&sampling)),
    );
    let peak = |fidelity, states: &[EulerState]| {
        let mut y = vec![[0.0; 5]; states.len()];
        wing(fidelity).aero_loads_into(states, dt, &mut y);
        y[250..].iter().map(|r| r[0].abs()).fold(0.0, f64::max)
    };
    for (i, states) in sets.iter().enumerate() {
        let ratio = peak(Fidelity::L3, states) / (1.5 * peak(Fidelity::L0, states) + 1.0);
        assert!(
            ratio <= 1.0,
            "trajectory {i}: L3 peak / (1.5 L0 peak + 1 N) = {ratio}"
        );
    }
}

/// L3 forgets how the motion began as a rig does: two ramp-ins of the same kinematics, 12
/// trajectories (of 4, none reaches a 3rd cycle), under 0.1 σ apart in every output in the 3rd
/// cycle after the longer ramp.
#[test]
fn l3_forgets_how_the_motion_began() {
    let cfg = VirtualWingConfig {
        fidelity: Fidelity::L3,
        ..VirtualWingConfig::ideal()
    };
    let third = repeatability(&cfg, 12)[2];
    assert!(third.iter().all(|d| *d < 0.1), "{third:?}");
}
