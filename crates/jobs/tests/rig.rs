//! The rig check against the published model (../shared/reference/bayiz2021-prssm) on a small
//! subset of the paper's trajectories: it ranks the wings as the full check does, it refuses a
//! dataset that is not on the paper's trajectories, and the mount fit's shortcut is exact.

use std::path::PathBuf;

use flapssm_jobs::NoProgress;
use flapssm_jobs::rig::{
    MountFitSettings, RigReference, RigSettings, fit_mount, load_reference_model, rig_check,
    rig_reference,
};
use flapssm_jobs::simulate::{SimulateSettings, simulate, simulate_paper};
use flapssm_wing::dataset::ValidDataset;
use flapssm_wing::trajectories::paper::paper_kinematics;
use flapssm_wing::virtual_wing::{Fidelity, VirtualWingConfig};

/// Trajectories of the subset: the first 24 (all in the paper's training set).
const N: usize = 24;

fn published() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../../../shared/reference/bayiz2021-prssm/reference.npz")
}

fn reference(n: usize) -> RigReference {
    let model = load_reference_model(&published()).unwrap();
    rig_reference(&model, n, &RigSettings::default(), &NoProgress).unwrap()
}

fn paper_wing(wing: VirtualWingConfig, n: usize) -> ValidDataset {
    let settings = SimulateSettings {
        n_trajectories: n,
        wing: Some(wing),
        noise_free: true,
        ..SimulateSettings::default()
    };
    simulate_paper(&settings, &NoProgress).unwrap()
}

/// The level `fidelity` as its module defines it, the plate aligned.
fn at(fidelity: Fidelity) -> VirtualWingConfig {
    VirtualWingConfig {
        fidelity,
        ..VirtualWingConfig::ideal()
    }
}

/// The quasi-steady wing agrees with the stand-in on the normal channels as on the whole set
/// (r 0.970 / 0.977 / 0.933 on the 512 training trajectories) and not on the chordwise ones; a
/// wing with the slow LEV lag of L1 agrees less; the default wing's mount turns the normal
/// force into the chordwise channels with the stand-in's signs and couplings. The L0 bounds
/// fail if the wing, the inputs' standardization or the reference's prediction goes wrong.
#[test]
fn the_check_ranks_the_wings_on_a_subset() {
    let reference = reference(N);
    let check = |wing| {
        let c = rig_check(&paper_wing(wing, N), &reference, true).unwrap();
        assert!(c.test.is_none());
        c.train
    };
    let l0 = check(at(Fidelity::L0));
    let r: Vec<f64> = l0.channels.iter().map(|c| c.r).collect();
    assert!(r[0] > 0.95 && r[3] > 0.95 && r[4] > 0.9, "L0 r {r:?}");
    assert!(r[1].abs() < 0.3 && r[2].abs() < 0.3, "L0 chordwise r {r:?}");
    assert!(l0.channels.iter().all(|c| c.z_rmse.is_finite()));
    assert!(l0.channels[0].band_share > 0.6, "{:?}", l0.channels[0]);
    let stand_in = l0.reference_couplings;
    assert!(
        stand_in.fy_fx > 0.8 && stand_in.mx_fx < -0.8,
        "{stand_in:?}"
    );
    // The a_x → F_x lag of a memoryless wing is the paper's ≈ 0.2 cycle.
    let ax = l0.lag("a_x", "F_x").unwrap();
    assert!(
        (0.15..0.27).contains(&ax.dataset.median_lag_cycles),
        "{ax:?}"
    );

    let mut lev = at(Fidelity::L1);
    lev.aero.wagner = false;
    lev.aero.inflow = false;
    let lagged = check(lev);
    assert!(
        lagged.channels[0].r < l0.channels[0].r - 0.05,
        "LEV lag {} vs L0 {}",
        lagged.channels[0].r,
        l0.channels[0].r
    );

    let rig = check(VirtualWingConfig::default());
    let (c, s) = (rig.dataset_couplings, rig.reference_couplings);
    assert!(
        (c.fy_fx - s.fy_fx).abs() < 0.1 && (c.mx_fx - s.mx_fx).abs() < 0.1,
        "{c:?} vs the stand-in's {s:?}"
    );
    let r: Vec<f64> = rig.channels.iter().map(|c| c.r).collect();
    assert!(r[1] > 0.7 && r[2] > 0.7, "default wing r {r:?}");
    assert!(
        r[0] > 0.95 && r[3] > 0.95 && r[4] > 0.9,
        "default wing r {r:?}"
    );
}

/// With its sensor chain the default wing keeps the stand-in's chordwise signature on every
/// seed: the couplings' signs and r(F_y) well above zero (with a random cross-axis coupling of
/// 1 % of full scale, seeds 1–3 of 0–3 reversed F_y's coupling, docs/rig-agreement.md).
#[test]
fn the_default_dataset_keeps_the_rigs_chordwise_signature_on_every_seed() {
    let reference = reference(N);
    for seed in 0..4 {
        let settings = SimulateSettings {
            n_trajectories: N,
            seed,
            ..SimulateSettings::default()
        };
        let ds = simulate_paper(&settings, &NoProgress).unwrap();
        let check = rig_check(&ds, &reference, false).unwrap().train;
        let c = check.dataset_couplings;
        assert!(c.fy_fx > 0.6 && c.mx_fx < -0.8, "seed {seed}: {c:?}");
        assert!(
            check.channels[1].r > 0.5,
            "seed {seed}: {:?}",
            check.channels[1]
        );
    }
}

/// The reference's inputs are the noise-free simulation's, and a dataset that is not the
/// paper's trajectories, or has no loads, is refused by name.
#[test]
fn the_reference_is_the_papers_trajectories_and_others_are_refused() {
    let reference = reference(4);
    let ds = paper_wing(at(Fidelity::L0), 4);
    for (t, k) in ds
        .trajectories
        .iter()
        .zip(&reference.kinematics.trajectories)
    {
        assert_eq!(t.inputs, k.inputs);
        assert_eq!(t.euler_rad, k.euler_rad);
    }
    let generated = simulate(
        &SimulateSettings {
            n_trajectories: 4,
            fidelity: Some(Fidelity::L0),
            noise_free: true,
            ..SimulateSettings::default()
        }
        .check()
        .unwrap(),
        None,
        &NoProgress,
    )
    .unwrap();
    let e = rig_check(&generated, &reference, false)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("trajectory 0") && e.contains("--source paper"),
        "{e}"
    );
    let kinematics = paper_kinematics(4).unwrap();
    let e = rig_check(&kinematics, &reference, false)
        .unwrap_err()
        .to_string();
    assert!(e.contains("loads"), "{e}");
    let longer = paper_wing(at(Fidelity::L0), 5);
    let e = rig_check(&longer, &reference, false)
        .unwrap_err()
        .to_string();
    assert!(e.contains("at most the 4 trajectories"), "{e}");
    let e = rig_reference(
        &load_reference_model(&published()).unwrap(),
        549,
        &RigSettings::default(),
        &NoProgress,
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains("setting n = 549"), "{e}");
}

/// The fit scores a sensor angle by turning the loads of the plate's simulation; that equals
/// simulating with both angles, and the fit picks the grid point its two criteria name.
#[test]
fn the_mount_fit_is_exact_and_follows_its_criteria() {
    let n = 12;
    let reference = reference(n);
    let settings = MountFitSettings {
        plate_deg: vec![4.0],
        sensor_deg: vec![-20.0, -10.0],
    };
    let fit = fit_mount(&at(Fidelity::L0), &reference, &settings, &NoProgress).unwrap();
    assert_eq!(fit.aligned.channels.len(), 5);
    assert_eq!(fit.surface.len(), 2 * 3);
    let direct = rig_check(
        &paper_wing(
            VirtualWingConfig {
                mount: fit.best,
                ..at(Fidelity::L0)
            },
            n,
        ),
        &reference,
        false,
    )
    .unwrap();
    for (a, b) in fit.at_best.channels.iter().zip(&direct.train.channels) {
        assert!((a.r - b.r).abs() < 1e-12 && (a.z_rmse - b.z_rmse).abs() < 1e-12);
    }
    let target = direct.train.reference_couplings;
    let chosen = fit
        .surface
        .iter()
        .find(|p| {
            p.plate_deg == fit.best.plate_pitch_deg && p.sensor_deg == fit.best.sensor_pitch_deg
        })
        .unwrap();
    for p in &fit.surface {
        if p.plate_deg == chosen.plate_deg {
            assert!(chosen.coupling_error(&target) <= p.coupling_error(&target));
        }
    }
    let e = fit_mount(
        &at(Fidelity::L0),
        &reference,
        &MountFitSettings {
            plate_deg: vec![50.0],
            sensor_deg: vec![0.0],
        },
        &NoProgress,
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains("plate_deg") && e.contains("45"), "{e}");
}
