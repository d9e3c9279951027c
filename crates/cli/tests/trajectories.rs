//! `flapssm trajectories`: reproducible files, the requested split, and refused arguments.

mod common;

use common::{assert_fails, flapssm, ok, s};
use std::path::Path;

use flapssm_wing::dataset::Dataset;

fn generate(dir: &std::path::Path, name: &str, extra: &[&str]) -> std::path::PathBuf {
    let out = dir.join(name);
    ok(&[&["trajectories", "--out", s(&out)], extra].concat());
    out
}

#[test]
fn same_seed_gives_a_byte_identical_file_and_another_seed_does_not() {
    let dir = tempfile::tempdir().unwrap();
    let a = generate(dir.path(), "a.npz", &["--n", "6", "--seed", "9"]);
    let b = generate(dir.path(), "b.npz", &["--n", "6", "--seed", "9"]);
    let c = generate(dir.path(), "c.npz", &["--n", "6", "--seed", "10"]);
    let (a, b, c) = (
        std::fs::read(a).unwrap(),
        std::fs::read(b).unwrap(),
        std::fs::read(c).unwrap(),
    );
    assert!(a == b, "same seed, different files");
    assert!(a != c, "different seeds, same file");
}

#[test]
fn the_file_is_a_kinematics_dataset_with_the_requested_split() {
    let dir = tempfile::tempdir().unwrap();
    let p = generate(
        dir.path(),
        "t.npz",
        &["--n", "5", "--seed", "2", "--n-train", "3"],
    );
    let ds = Dataset::load(&p).unwrap();
    assert_eq!((ds.len(), ds.n_train, ds.n_samples()), (5, 3, 470));
    assert!(!ds.has_outputs());
    assert_eq!(ds.meta.seed, Some(2));
    // Servo limits of the generator: |angle| ≤ 110°.
    let limit = 110f64.to_radians() + 1e-9;
    assert!(
        ds.trajectories
            .iter()
            .flat_map(|t| t.euler_rad.iter().flatten())
            .all(|a| a.abs() <= limit)
    );
    // Default split for a small set keeps a test part.
    let d = Dataset::load(&generate(dir.path(), "d.npz", &["--n", "20"])).unwrap();
    assert!(d.n_train >= 1 && d.n_train < 20, "n_train {}", d.n_train);
}

#[test]
fn bad_arguments_are_refused_and_write_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("t.npz");
    let o = flapssm(&["trajectories", "--n", "0", "--out", s(&out)]);
    assert_fails(&o, &["n_trajectories", "0"], &out);
    let o = flapssm(&[
        "trajectories",
        "--n",
        "4",
        "--n-train",
        "5",
        "--out",
        s(&out),
    ]);
    assert_fails(&o, &["n_train", "5"], &out);
    let missing = dir.path().join("no/such/dir/t.npz");
    let o = flapssm(&["trajectories", "--n", "2", "--out", s(&missing)]);
    assert_fails(&o, &[s(&missing)], &missing);
    let o = flapssm(&["trajectories", "--n", "two", "--out", s(&out)]);
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("--n"));
    assert!(!out.exists());
}

#[test]
fn compare_paper_prints_every_statistic_and_needs_no_output_file() {
    let text = ok(&[
        "trajectories",
        "--n",
        "40",
        "--seed",
        "1",
        "--compare-paper",
    ]);
    for name in flapssm_wing::trajectories::stats::STAT_NAMES {
        assert!(text.contains(name), "{name} missing from:\n{text}");
    }
    assert!(text.contains("KS D"), "{text}");
    // The hovering preset flaps about twice as fast as the paper's robot: its frequency row
    // differs from the default's.
    let hovering = ok(&[
        "trajectories",
        "--n",
        "40",
        "--seed",
        "1",
        "--compare-paper",
        "--preset",
        "hovering",
    ]);
    let row = |t: &str| {
        t.lines()
            .find(|l| l.starts_with("stroke frequency"))
            .unwrap()
            .to_string()
    };
    assert_ne!(row(&text), row(&hovering));
    // Neither an output nor a comparison: a usage error.
    let o = flapssm(&["trajectories", "--n", "4"]);
    assert_eq!(o.status.code(), Some(2));
}

#[test]
fn simulate_drives_the_wing_with_the_papers_trajectories() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("p.npz");
    let text = ok(&[
        "simulate",
        "--source",
        "paper",
        "--n",
        "3",
        "--fidelity",
        "l0",
        "--quiet",
        "--out",
        s(&out),
    ]);
    assert!(text.contains("measured (the paper's)"), "{text}");
    let ds = Dataset::load(&out).unwrap();
    assert_eq!((ds.len(), ds.n_train), (3, 2));
    assert!(ds.trajectories.iter().all(|t| t.family == "measured"));
    let source = ds.meta.settings["angles_source"].as_str().unwrap();
    assert!(source.contains("0..3"), "{source}");
    // Re ≈ 1000 with the default fluid (ν from the paper's Re and the measured U_ref).
    let re = ds.meta.settings["mean_reynolds_number"].as_f64().unwrap();
    assert!((950.0..1050.0).contains(&re), "Re {re}");
    let bad = dir.path().join("q.npz");
    let o = flapssm(&[
        "simulate",
        "--source",
        "paper",
        "--n",
        "549",
        "--out",
        s(&bad),
    ]);
    assert_fails(&o, &["setting n = 549", "548"], &bad);
}

#[test]
fn simulate_takes_the_l2_wake_model_and_refuses_unknown_names() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("w.npz");
    ok(&[
        "simulate",
        "--source",
        "paper",
        "--n",
        "2",
        "--fidelity",
        "l2",
        "--wake",
        "frozen",
        "--inflow",
        "momentum",
        "--noise-free",
        "--quiet",
        "--out",
        s(&out),
    ]);
    let ds = Dataset::load(&out).unwrap();
    let settings = ds.meta.settings.to_string();
    assert!(settings.contains(r#""wake_motion":"frozen""#), "{settings}");
    assert!(settings.contains(r#""inflow":"momentum""#), "{settings}");
    assert!(ds.trajectories.iter().all(|t| {
        t.outputs
            .as_ref()
            .unwrap()
            .iter()
            .flatten()
            .all(|v| v.is_finite())
    }));
    let bad = dir.path().join("b.npz");
    for (flag, value, said) in [
        (
            "--wake",
            "swirling",
            "unknown wake motion `swirling` (expected free or frozen)",
        ),
        ("--inflow", "uniform:-1", "unknown inflow `uniform:-1`"),
    ] {
        let o = flapssm(&["simulate", "--n", "2", flag, value, "--out", s(&bad)]);
        assert_fails(&o, &[flag, said], &bad);
    }
    // A wake motion only the strips have, or an inflow at a fidelity without one, is refused
    // rather than ignored.
    for (args, said) in [
        (
            ["--wake", "frozen", "--fidelity", "l3"],
            "setting wake = frozen",
        ),
        (
            ["--inflow", "momentum", "--fidelity", "l1"],
            "setting inflow = momentum",
        ),
    ] {
        let mut argv = vec!["simulate", "--n", "2", "--out", s(&bad)];
        argv.extend(args);
        assert_fails(&flapssm(&argv), &[said, "applies to"], &bad);
    }
}

/// `simulate` runs the default wing (L0 with the rig's mount, docs/rig-agreement.md), `--fidelity
/// l3` the vortex lattice and `--inflow` sets its wake's inflow (all recorded in the metadata;
/// finite loads, changed by the inflow); `--wing-config` sets any field of the wing and refuses
/// a misspelt one by name; an unknown level is refused with the levels named.
#[test]
fn simulate_runs_the_default_wing_and_the_vortex_lattice() {
    let dir = tempfile::tempdir().unwrap();
    let default = dir.path().join("default.npz");
    let out = dir.path().join("l3.npz");
    let still = dir.path().join("still.npz");
    let run = |extra: &[&str], out: &Path| {
        let mut argv = vec!["simulate", "--source", "paper", "--n", "2", "--noise-free"];
        argv.extend(extra);
        argv.extend(["--quiet", "--out", s(out)]);
        ok(&argv);
        Dataset::load(out).unwrap()
    };
    let d = run(&[], &default);
    assert_eq!(d.meta.settings["fidelity"], "l0");
    assert_eq!(d.meta.settings["wing"]["mount"]["plate_pitch_deg"], 4.5);
    let ds = run(&["--fidelity", "l3"], &out);
    let ds_still = run(&["--fidelity", "l3", "--inflow", "still"], &still);
    for (d, inflow) in [(&ds, "momentum"), (&ds_still, "still")] {
        assert_eq!(d.meta.settings["fidelity"], "l3");
        assert_eq!(d.meta.settings["wing"]["l3"]["inflow"], inflow);
    }
    let config = dir.path().join("wing.json");
    std::fs::write(
        &config,
        r#"{"fidelity": "l1", "mount": {"sensor_pitch_deg": -2.0}}"#,
    )
    .unwrap();
    let configured = run(&["--wing-config", s(&config)], &dir.path().join("c.npz"));
    assert_eq!(configured.meta.settings["fidelity"], "l1");
    assert_eq!(
        configured.meta.settings["wing"]["mount"]["sensor_pitch_deg"],
        -2.0
    );
    assert_eq!(
        configured.meta.settings["wing"]["mount"]["plate_pitch_deg"],
        4.5
    );
    std::fs::write(&config, r#"{"mount": {"plate_pich_deg": 2.0}}"#).unwrap();
    let bad = dir.path().join("bad.npz");
    let o = flapssm(&[
        "simulate",
        "--source",
        "paper",
        "--n",
        "2",
        "--wing-config",
        s(&config),
        "--out",
        s(&bad),
    ]);
    assert_fails(
        &o,
        &["mount.plate_pich_deg", "wing.json", "no such field"],
        &bad,
    );
    std::fs::write(&config, r#"{"mount": {"plate_pitch_deg": 50.0}}"#).unwrap();
    let o = flapssm(&[
        "simulate",
        "--source",
        "paper",
        "--n",
        "2",
        "--wing-config",
        s(&config),
        "--out",
        s(&bad),
    ]);
    assert_fails(&o, &["mount.plate_pitch_deg", "45"], &bad);
    let outputs = |d: &Dataset| -> Vec<f64> {
        d.trajectories
            .iter()
            .flat_map(|t| t.outputs.as_ref().unwrap().iter().flatten().copied())
            .collect()
    };
    assert!(outputs(&ds).iter().all(|v| v.is_finite()));
    assert_ne!(outputs(&ds), outputs(&ds_still));
    let bad = dir.path().join("b.npz");
    let o = flapssm(&["simulate", "--n", "2", "--fidelity", "l4", "--out", s(&bad)]);
    assert_fails(&o, &["--fidelity", "expected l0, l1, l2 or l3"], &bad);
}
