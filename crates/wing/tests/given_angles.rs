//! The virtual wing driven by given Euler angles at the dataset rate (the paper's measured
//! trajectories are 470 samples at 25 Hz): on the generator's own trajectories, sampled at
//! 25 Hz, it reproduces the loads of the analytic drive; on the paper's measured trajectories it
//! gives a valid dataset.

use flapssm_wing::sensor::SensorConfig;
use flapssm_wing::trajectories::GeneratorConfig;
use flapssm_wing::virtual_wing::{
    Fidelity, SimulationConfig, VirtualWingConfig, simulate_angles_dataset, simulate_dataset,
};

fn noise_free(fidelity: Fidelity) -> VirtualWingConfig {
    VirtualWingConfig {
        fidelity,
        sensor: SensorConfig::noise_free(),
        ..Default::default()
    }
}

#[test]
fn given_25_hz_angles_reproduce_the_analytic_drive() {
    let trajectories = GeneratorConfig {
        n_trajectories: 3,
        n_train: 2,
        seed: 6,
        ..GeneratorConfig::default()
    };
    for fidelity in [Fidelity::L0, Fidelity::L1] {
        let cfg = SimulationConfig {
            wing: noise_free(fidelity),
            trajectories: trajectories.clone(),
        };
        let analytic = simulate_dataset(&cfg, &|| {}).unwrap();
        let angles: Vec<Vec<[f64; 3]>> = trajectories
            .generate()
            .unwrap()
            .iter()
            .map(|s| {
                s.sample_dataset(&trajectories.sampling)
                    .iter()
                    .map(|st| st.angles_rad)
                    .collect()
            })
            .collect();
        let given =
            simulate_angles_dataset(&cfg.wing, &angles, &trajectories.sampling, 6, 2, &|| {})
                .unwrap();
        assert_eq!((given.len(), given.n_train), (3, 2));
        assert_eq!(given.meta.generator, "flapssm simulate (given angles)");
        // Away from the start (the differentiator's edge), loads agree to 1e-3 of each
        // output's spread (measured: ≤ 2e-4).
        for k in 0..5 {
            let (mut num, mut den) = (0.0, 0.0);
            for (a, g) in analytic.trajectories.iter().zip(&given.trajectories) {
                let (ya, yg) = (a.outputs.as_ref().unwrap(), g.outputs.as_ref().unwrap());
                let mean = ya.iter().map(|y| y[k]).sum::<f64>() / ya.len() as f64;
                for t in 20..ya.len() {
                    num += (ya[t][k] - yg[t][k]).powi(2);
                    den += (ya[t][k] - mean).powi(2);
                }
            }
            let rel = (num / den).sqrt();
            println!("{fidelity:?} output {k}: RMS difference {rel:.4} of the spread");
            assert!(
                rel < 0.03,
                "{fidelity:?} output {k}: RMS difference {rel:.4} of the spread"
            );
        }
    }
}

#[test]
fn the_papers_measured_trajectories_give_a_valid_dataset() {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../../shared/data/bayiz2021-kinematics/euler_angles.npy");
    let arr = flapssm_data::npz::read_npy_f64(&path).unwrap();
    assert_eq!(arr.shape, vec![548, 470, 3]);
    let angles: Vec<Vec<[f64; 3]>> = arr
        .data
        .chunks_exact(470 * 3)
        .take(2)
        .map(|t| t.chunks_exact(3).map(|r| [r[0], r[1], r[2]]).collect())
        .collect();
    let ds = simulate_angles_dataset(
        &noise_free(Fidelity::L1),
        &angles,
        &Default::default(),
        1,
        1,
        &|| {},
    )
    .unwrap();
    assert!(ds.has_outputs() && ds.len() == 2);
    // The dataset's angles are the measured ones, smoothed: within a degree.
    for (t, a) in ds.trajectories.iter().zip(&angles) {
        let worst = t
            .euler_rad
            .iter()
            .zip(a)
            .flat_map(|(x, y)| (0..3).map(move |k| (x[k] - y[k]).abs()))
            .fold(0.0, f64::max);
        assert!(worst < 1f64.to_radians(), "{worst}");
    }
}
