//! Cost of the L2 strip-LDVM over one dataset trajectory: 18.8 s at 250 Hz (4700 steps) of a
//! hovering stroke (f = 0.3 Hz, stroke ±70°, pitch ±45° about −90°, deviation ±10° at 2f),
//! one strip at r_cp = 0.178 m, default parameters.

use std::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};
use flapssm_wing::aero::{SectionGeometry, SectionKinematics, SectionModel};
use flapssm_wing::kinematics::{EulerState, WingKinematics};
use flapssm_wing::vortex::{StripLdvm, StripLdvmParams};

fn section_kinematics(t: f64, r: f64) -> SectionKinematics {
    let w = 2.0 * std::f64::consts::PI * 0.3;
    let (a_phi, a_psi, a_al) = (70f64.to_radians(), 10f64.to_radians(), 45f64.to_radians());
    let st = EulerState {
        angles_rad: [
            a_phi * (w * t).sin(),
            a_psi * (2.0 * w * t).sin(),
            -std::f64::consts::FRAC_PI_2 + a_al * (w * t).cos(),
        ],
        rates_rad_s: [
            a_phi * w * (w * t).cos(),
            2.0 * a_psi * w * (2.0 * w * t).cos(),
            -a_al * w * (w * t).sin(),
        ],
        accels_rad_s2: [
            -a_phi * w * w * (w * t).sin(),
            -4.0 * a_psi * w * w * (2.0 * w * t).sin(),
            -a_al * w * w * (w * t).cos(),
        ],
    };
    let k = WingKinematics::from_euler(&st);
    SectionKinematics {
        normal_velocity_m_s: r * k.v_x,
        chord_velocity_m_s: r * k.v_y,
        normal_velocity_rate_m_s2: r * (k.a[0] + k.omega_rad_s[2] * k.v_y),
        chord_velocity_rate_m_s2: r * (k.a[1] - k.omega_rad_s[2] * k.v_x),
        rotation_rate_rad_s: k.omega_rad_s[2],
        rotation_acc_rad_s2: k.omega_dot_rad_s2[2],
        up_section: k.up_wing.map(|u| [u[0], u[1]]),
    }
}

fn bench(c: &mut Criterion) {
    let dt = 0.004;
    let r = 0.178;
    let kins: Vec<SectionKinematics> = (0..4700)
        .map(|i| section_kinematics(i as f64 * dt, r))
        .collect();
    let geom = SectionGeometry {
        chord_m: 0.06,
        pitch_axis_frac: 0.15,
        radius_m: r,
        density_kg_m3: 800.0,
    };
    let mut strip = StripLdvm::new(StripLdvmParams::default(), &geom);
    let mut g = c.benchmark_group("vortex");
    g.sample_size(10);
    g.bench_function("strip_ldvm_trajectory_4700_steps", |b| {
        b.iter(|| {
            strip.reset();
            let mut acc = 0.0;
            for k in &kins {
                acc += strip.step(black_box(k), dt).normal_n_m;
            }
            black_box(acc)
        })
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
