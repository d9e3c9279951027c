//! The design objective's gradient through a PR-SSM against central differences of the same
//! objective, and the refusals of bad targets.

use flapssm_design::{DesignGrid, DesignProblem, Objective, PrssmDesign, Target};
use flapssm_prssm::params::{ModelConfig, ParamInit, Params};
use flapssm_prssm::{Normalization, PrssmModel};
use flapssm_wing::trajectories::harmonic::KinematicLimits;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

fn model() -> PrssmModel {
    let mut rng = ChaCha8Rng::seed_from_u64(3);
    let config = ModelConfig::new(6, 5, 7, 12);
    let mut p = Params::init(&config, &ParamInit::default(), 5);
    p.q_mean
        .iter_mut()
        .for_each(|v| *v = rng.random_range(-0.3..0.3));
    p.lengthscales.iter_mut().for_each(|l| *l = 2.0);
    PrssmModel {
        config,
        params: p,
        normalization: Some(Normalization {
            input_mean: vec![0.0, 1.5, 0.0, 0.0, -3.0, 0.0, 0.0],
            input_std: vec![1.0, 0.8, 5.0, 5.0, 3.0, 2.0, 10.0],
            output_mean: vec![0.0, 0.0, 0.0, 0.0, 0.0],
            output_std: vec![0.3, 0.05, 20.0, 50.0, 3.0],
        }),
        training: serde_json::Value::Null,
    }
}

fn problem(target: Target) -> DesignProblem {
    DesignProblem {
        target,
        grid: DesignGrid {
            dt_s: 0.04,
            n_samples: 120,
            skip: 20,
        },
        frequency_hz: 0.5,
        frequency_range_hz: [0.1, 1.0],
        harmonics: 2,
        ramp_cycles: 1.0,
        limits: KinematicLimits {
            angle_rad: [1.2, 0.5, 1.0],
            rate_rad_s: [4.0, 2.0, 5.0],
            accel_rad_s2: [20.0, 10.0, 20.0],
        },
        quantity_scales: [0.1, 0.1, 0.1, 10.0, 10.0, 10.0, 0.05],
        output_scales: [0.3, 0.05, 20.0, 50.0, 3.0],
        reachable: [0.5, 0.5, 0.5, 50.0, 50.0, 50.0, 0.5],
        robust_weight: 0.7,
        power_weight: 0.3,
        limit_weight: 10.0,
        sensor_radius_m: 0.055,
    }
}

fn theta() -> Vec<f64> {
    // stroke: offset, cos1, cos2, sin1, sin2; deviation; pitch. The stroke's sin1 is large
    // enough that the rate limit binds (the penalty's gradient is checked too).
    vec![
        0.05, 0.1, 0.02, 1.3, -0.05, 0.02, 0.05, -0.1, 0.03, 0.01, 0.2, 0.6, 0.05, 0.1, -0.08,
    ]
}

fn check_gradient(target: Target) {
    let m = PrssmDesign::new(&model(), 8, 4).unwrap();
    let mut obj = Objective::new(&problem(target), Box::new(m)).unwrap();
    let th = theta();
    let mut g = vec![0.0; th.len()];
    let ev = obj.evaluate(&th, Some(&mut g)).unwrap();
    assert!(ev.penalty > 0.0, "the limits' penalty should be active");
    assert!(ev.robust > 0.0 && ev.fit > 0.0);
    let scale = g.iter().fold(0.0_f64, |a, v| a.max(v.abs()));
    for i in 0..th.len() {
        let h = 1e-6;
        let (mut up, mut dn) = (th.clone(), th.clone());
        up[i] += h;
        dn[i] -= h;
        let fd = (obj.evaluate(&up, None).unwrap().value - obj.evaluate(&dn, None).unwrap().value)
            / (2.0 * h);
        assert!(
            (fd - g[i]).abs() <= 1e-5 * scale,
            "θ{i}: exact {} vs central {fd} (scale {scale})",
            g[i]
        );
    }
}

#[test]
fn cycle_mean_gradient_matches_central_differences() {
    check_gradient(Target::CycleMeans {
        values: [Some(0.0), Some(0.2), None, None, None, Some(1.0)],
    });
}

#[test]
fn history_gradient_matches_central_differences() {
    let window = problem(Target::CycleMeans { values: [None; 6] })
        .grid
        .window(0.5, 1.0)
        .unwrap();
    let outputs = window
        .map(|t| {
            let x = t as f64 * 0.1;
            [0.2 * x.sin(), 0.01, 5.0 * x.cos(), 20.0 * x.sin(), 1.0]
        })
        .collect();
    check_gradient(Target::History { outputs });
}

#[test]
fn bad_targets_are_refused_naming_the_field() {
    let cases = [
        (
            Target::CycleMeans {
                values: [None, Some(f64::NAN), None, None, None, None],
            },
            "target.lift_n",
            "not finite",
        ),
        (
            Target::CycleMeans {
                values: [None, Some(3.0), None, None, None, None],
            },
            "target.lift_n",
            "unreachable",
        ),
        (
            Target::History {
                outputs: vec![[0.0; 5]; 3],
            },
            "target.outputs",
            "rows",
        ),
    ];
    for (target, field, what) in cases {
        let e = Objective::new(
            &problem(target),
            Box::new(PrssmDesign::new(&model(), 4, 1).unwrap()),
        )
        .err()
        .unwrap()
        .to_string();
        assert!(e.contains(field) && e.contains(what), "{e}");
    }
    let mut p = problem(Target::CycleMeans {
        values: [None, Some(0.1), None, None, None, None],
    });
    p.frequency_hz = 2.0;
    let e = p.check().unwrap_err().to_string();
    assert!(e.contains("frequency_hz") && e.contains("outside"), "{e}");
    p.frequency_hz = 0.5;
    p.limits.rate_rad_s[1] = f64::NAN;
    let e = p.check().unwrap_err().to_string();
    assert!(e.contains("deviation_rate_rad_s"), "{e}");
}
