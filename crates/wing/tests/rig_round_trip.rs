//! A rig unlike the paper's, rehearsed with the virtual wing and processed back: the wing-frame
//! loads recovered from its raw recording match the wing's own (docs/own-rig.md).

use flapssm_wing::dataset::Trajectory;
use flapssm_wing::rig::{
    AngleConvention, AngleUnit, Cutting, EulerAngle, ForceUnit, LoadFilter, MassProperties,
    MomentUnit, RigDescription, RigError, RigFluid, RigSampling, RigWing, SensorPose, Subtract,
    Tare, process_recording, rehearse, virtual_wing_of,
};
use flapssm_wing::trajectories::{GeneratorConfig, SamplingConfig};
use flapssm_wing::virtual_wing::{Fidelity, VirtualWing};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

/// A 0.12 × 0.04 m acrylic plate in water, pitch axis at a quarter chord, a sensor 5 mm off the
/// pitch axis and turned, stroke–pitch–deviation gimbal read in degrees with two signs flipped,
/// 1 kHz with a time column, mN and mN·m with noise and an offset.
fn water_rig() -> RigDescription {
    let (span, chord, thick) = (0.12, 0.04, 0.002);
    let volume = span * chord * thick;
    let mass = 1190.0 * volume;
    RigDescription {
        name: "water rig".into(),
        wing: RigWing {
            span_m: span,
            chord_m: chord,
            root_offset_m: 0.03,
            pitch_axis_frac: 0.25,
            u_ref_radius_m: None,
        },
        fluid: RigFluid {
            density_kg_m3: 1000.0,
            kinematic_viscosity_m2_s: 1.0e-6,
        },
        angles: AngleConvention {
            columns: [
                "stroke_deg".into(),
                "elevation_deg".into(),
                "rotation_deg".into(),
            ],
            unit: AngleUnit::Deg,
            order: [EulerAngle::Stroke, EulerAngle::Pitch, EulerAngle::Deviation],
            sign: [-1.0, 1.0, -1.0],
            zero: [0.0, 0.0, 90.0],
        },
        sensor: SensorPose {
            columns: ["Fx", "Fy", "Fz", "Tx", "Ty", "Tz"].map(String::from),
            force_unit: ForceUnit::MilliN,
            moment_unit: MomentUnit::MilliNM,
            offset_m: [0.004, -0.005, -0.012],
            rotation_deg: [10.0, -5.0, 30.0],
            noise_sd: [1.0, 1.0, 1.0, 0.02, 0.02, 0.02],
            bias_sd: [20.0, 20.0, 20.0, 1.0, 1.0, 1.0],
        },
        sampling: RigSampling {
            rate_hz: 1000.0,
            time_column: Some("t".into()),
            dataset_rate_hz: 100.0,
        },
        filter: LoadFilter {
            cutoff_hz: Some(10.0),
        },
        tare: Tare {
            rest_s: 1.0,
            home_pose: [0.0, 0.0, 0.0],
            tolerance_deg: 0.5,
        },
        mass: Some(MassProperties {
            mass_kg: mass,
            volume_m3: volume,
            center_of_mass_m: [0.0, (0.25 - 0.5) * chord, 0.5 * span],
            center_of_buoyancy_m: None,
            inertia_kg_m2: [
                mass * (chord * chord + span * span) / 12.0,
                mass * span * span / 12.0,
                mass * chord * chord / 12.0,
                0.0,
                0.0,
                0.0,
            ],
        }),
        subtract: Subtract {
            gravity: true,
            buoyancy: true,
            inertia: true,
        },
        trajectories: Cutting {
            skip_s: 1.5,
            duration_s: None,
        },
    }
}

/// The generator's trajectory `index` at the rig's 1 kHz, 16 s.
fn motion(index: usize) -> Vec<flapssm_wing::kinematics::EulerState> {
    let generator = GeneratorConfig::default();
    let family = generator.family_sequence()[index];
    let spec = generator.generate_one(index, family).expect("feasible");
    spec.sample_raw(&SamplingConfig {
        raw_rate_hz: 1000.0,
        decimation: 1,
        n_samples: 16_000,
    })
}

fn rms(x: impl Iterator<Item = f64>) -> f64 {
    let (s, n) = x.fold((0.0, 0usize), |(s, n), v| (s + v * v, n + 1));
    (s / n as f64).sqrt()
}

/// Per channel, RMS(recovered − truth) over the trajectory, relative to the RMS of the largest
/// channel of its kind (forces F_x, F_y; moments M_x, M_y, M_z): a chordwise force a fiftieth of
/// the normal force is judged on the force's scale, not its own.
fn relative_errors(got: &Trajectory, truth: &Trajectory) -> [f64; 5] {
    let (g, t) = (
        got.outputs.as_ref().unwrap(),
        truth.outputs.as_ref().unwrap(),
    );
    assert_eq!(g.len(), t.len());
    let scale: Vec<f64> = (0..5).map(|c| rms(t.iter().map(|b| b[c]))).collect();
    let force = scale[0].max(scale[1]);
    let moment = scale[2].max(scale[3]).max(scale[4]);
    std::array::from_fn(|c| {
        rms(g.iter().zip(t).map(|(a, b)| a[c] - b[c])) / if c < 2 { force } else { moment }
    })
}

fn round_trip(desc: &RigDescription, tolerance: f64) {
    desc.check().expect("valid description");
    let mut wing = VirtualWing::new(&virtual_wing_of(desc, Fidelity::L0)).expect("wing");
    let mut rng = ChaCha8Rng::seed_from_u64(11);
    for index in [0, 1] {
        let rehearsed =
            rehearse(desc, &mut wing, &motion(index), "rehearsal.csv", &mut rng).expect("rehearse");
        let processed = process_recording(desc, &rehearsed.recording).expect("process");
        assert_eq!(processed.trajectories.len(), 1);
        let (got, truth) = (&processed.trajectories[0], &rehearsed.truth[0]);
        let errors = relative_errors(got, truth);
        println!("trajectory {index}: RMS errors F_x F_y M_x M_y M_z = {errors:.5?} of scale");
        for (c, e) in errors.iter().enumerate() {
            assert!(*e < tolerance, "channel {c}: relative error {e}");
        }
        let angle_error = got
            .euler_rad
            .iter()
            .zip(&truth.euler_rad)
            .flat_map(|(a, b)| (0..3).map(move |k| (a[k] - b[k]).abs()))
            .fold(0.0, f64::max);
        assert!(angle_error < 3e-4, "angles differ by {angle_error} rad");
        assert!((got.u_ref_m_s / truth.u_ref_m_s - 1.0).abs() < 1e-6);
        let residual = processed.report.rest_residual.expect("tared");
        println!("rest residual (N, N·mm) {residual:.6?}");
    }
}

/// The round trip of the issue, with the sensor's noise and offsets: every channel within 1 %
/// of its kind's RMS (measured: 0.3 % for the forces, 0.1 % for the moments, the filtered noise),
/// angles within 3e-4 rad (the differentiator's smoothing of the pitch reversals), U_ref to
/// 1e-6.
#[test]
fn a_rehearsed_recording_of_another_rig_comes_back_as_the_wings_loads() {
    round_trip(&water_rig(), 0.01);
}

/// Without noise the processing itself is what remains: the filter and the inertia of the
/// differentiated angles, 0.1 % on M_z (the pitch acceleration's), at most 0.02 % elsewhere.
#[test]
fn without_noise_the_round_trip_is_the_processing_alone() {
    let mut desc = water_rig();
    desc.sensor.noise_sd = [0.0; 6];
    round_trip(&desc, 2e-3);
}

/// Without the subtraction the weight and buoyancy stay in the loads: the test above would
/// fail, so it can.
#[test]
fn without_the_subtraction_the_loads_are_wrong() {
    let mut desc = water_rig();
    let mut wing = VirtualWing::new(&virtual_wing_of(&desc, Fidelity::L0)).expect("wing");
    let mut rng = ChaCha8Rng::seed_from_u64(11);
    let rehearsed = rehearse(&desc, &mut wing, &motion(0), "r.csv", &mut rng).expect("rehearse");
    desc.subtract = Subtract::default();
    let processed = process_recording(&desc, &rehearsed.recording).expect("process");
    let errors = relative_errors(&processed.trajectories[0], &rehearsed.truth[0]);
    assert!(errors.iter().any(|e| *e > 0.05), "{errors:?}");
}

/// A wing that moves during the tare's rest is refused, naming the column.
#[test]
fn a_wing_moving_during_the_tare_is_refused() {
    let desc = water_rig();
    let mut wing = VirtualWing::new(&virtual_wing_of(&desc, Fidelity::L0)).expect("wing");
    let mut rng = ChaCha8Rng::seed_from_u64(1);
    let mut rec = rehearse(&desc, &mut wing, &motion(0), "r.csv", &mut rng)
        .expect("rehearse")
        .recording;
    rec.angles[100][2] += 3.0;
    let err = process_recording(&desc, &rec).unwrap_err();
    assert!(
        matches!(&err, RigError::Recording { reason, .. } if reason.contains("rotation_deg")),
        "{err}"
    );
}
