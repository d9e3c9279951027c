//! `flapssm sysid …`: bad input fails with a clear message and a nonzero exit; one short
//! end-to-end run on the hydraulic-actuator benchmark beats the training-mean predictor.

mod common;

use std::path::{Path, PathBuf};

use common::flapssm;

fn sysid_file(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../../shared/data/sysid")
        .join(name)
}

/// A MAT v4 column vector `name` (`n × 1`, little-endian doubles `0, 1, …`).
fn mat_v4(name: &str, n: usize) -> Vec<u8> {
    let mut b = Vec::new();
    for v in [0i32, n as i32, 1, 0, name.len() as i32 + 1] {
        b.extend(v.to_le_bytes());
    }
    b.extend(name.as_bytes());
    b.push(0);
    for i in 0..n {
        b.extend((i as f64).to_le_bytes());
    }
    b
}

/// Runs and asserts failure; returns stderr.
fn fails(args: &[&str]) -> String {
    let out = flapssm(args);
    let err = String::from_utf8_lossy(&out.stderr).into_owned();
    assert!(!out.status.success(), "{args:?} succeeded; stderr: {err}");
    assert!(
        !err.contains("panicked"),
        "{args:?} panicked instead of reporting: {err}"
    );
    err
}

#[test]
fn unknown_column_lists_available_ones() {
    let csv = sysid_file("actuator.csv");
    let err = fails(&[
        "sysid",
        csv.to_str().unwrap(),
        "--input",
        "u",
        "--output",
        "p",
    ]);
    assert!(
        err.contains("'p'") && err.contains("#0 'u', #1 'y'"),
        "{err}"
    );
    let mat = sysid_file("drive.mat");
    let err = fails(&[
        "sysid",
        mat.to_str().unwrap(),
        "--input",
        "u1",
        "--output",
        "z9",
    ]);
    assert!(err.contains("z9") && err.contains("z1"), "{err}");
    let dat = sysid_file("ballbeam.dat");
    let err = fails(&[
        "sysid",
        dat.to_str().unwrap(),
        "--input",
        "0",
        "--output",
        "2",
    ]);
    assert!(err.contains("#2") && err.contains("#1 '1'"), "{err}");
}

#[test]
fn corrupt_or_misshaped_files_are_reported() {
    let dir = tempfile::tempdir().unwrap();
    let ragged = dir.path().join("ragged.dat");
    std::fs::write(&ragged, "1 2\n3 4\n5\n").unwrap();
    let err = fails(&[
        "sysid",
        ragged.to_str().unwrap(),
        "--input",
        "0",
        "--output",
        "1",
    ]);
    assert!(
        err.contains("ragged.dat") && err.contains("line 3"),
        "{err}"
    );
    let text = dir.path().join("bad.csv");
    std::fs::write(&text, "u,y\n1,2\n3,oops\n").unwrap();
    let err = fails(&[
        "sysid",
        text.to_str().unwrap(),
        "--input",
        "u",
        "--output",
        "y",
    ]);
    assert!(
        err.contains("line 3, column 2") && err.contains("oops"),
        "{err}"
    );
    // A MAT file cut in the middle of its data.
    let bytes = std::fs::read(sysid_file("actuator.mat")).unwrap();
    let cut = dir.path().join("cut.mat");
    std::fs::write(&cut, &bytes[..bytes.len() / 2]).unwrap();
    let err = fails(&[
        "sysid",
        cut.to_str().unwrap(),
        "--input",
        "u",
        "--output",
        "p",
    ]);
    assert!(err.contains("cut.mat"), "{err}");
    // Input and output variables of different lengths (MAT v4, little-endian doubles).
    let uneven = dir.path().join("uneven.mat");
    std::fs::write(&uneven, [mat_v4("u", 200), mat_v4("y", 150)].concat()).unwrap();
    let err = fails(&[
        "sysid",
        uneven.to_str().unwrap(),
        "--input",
        "u",
        "--output",
        "y",
    ]);
    assert!(
        err.contains("uneven.mat") && err.contains("150 rows"),
        "{err}"
    );
    let err = fails(&["sysid", "no/such/file.csv", "--input", "u", "--output", "y"]);
    assert!(err.contains("no/such/file.csv"), "{err}");
}

#[test]
fn split_with_too_few_training_samples_is_rejected() {
    let csv = sysid_file("actuator.csv");
    let err = fails(&[
        "sysid",
        csv.to_str().unwrap(),
        "--input",
        "u",
        "--output",
        "y",
        "--split",
        "0.05",
    ]);
    assert!(
        err.contains("51 training") && err.contains("at least 100 training"),
        "{err}"
    );
    let err = fails(&[
        "sysid",
        csv.to_str().unwrap(),
        "--input",
        "u",
        "--output",
        "y",
        "--split",
        "1.5",
    ]);
    assert!(err.contains("split = 1.5"), "{err}");
}

#[test]
fn short_run_on_actuator_beats_the_mean_predictor() {
    let dir = tempfile::tempdir().unwrap();
    let fig = dir.path().join("actuator.svg");
    let r = actuator_run("150", &["--plot", fig.to_str().unwrap()]);
    assert_eq!(r["n_train"], 512);
    assert_eq!(r["n_test"], 512);
    // Published sanity value of the data README: predicting the training mean gives 1.630.
    let mean_rmse = r["mean_predictor_rmse"].as_f64().unwrap();
    assert!((mean_rmse - 1.630).abs() < 5e-4, "{mean_rmse}");
    let rmse = r["rmse"]["mean"].as_f64().unwrap();
    assert!(
        rmse < 0.8 * mean_rmse,
        "test RMSE {rmse} vs mean {mean_rmse}"
    );
    assert!(r["nll"]["mean"].as_f64().unwrap().is_finite());
    let svg = std::fs::read_to_string(&fig).unwrap();
    assert!(svg.starts_with("<svg") && svg.contains("test sample"));
}

/// One-seed actuator run of `iterations` with the given extra arguments; the parsed JSON report.
fn actuator_run(iterations: &str, extra: &[&str]) -> serde_json::Value {
    let mat = sysid_file("actuator.mat");
    let mut args = vec![
        "sysid",
        mat.to_str().unwrap(),
        "--input",
        "u",
        "--output",
        "p",
        "--seeds",
        "1",
        "--iterations",
        iterations,
        "--json",
    ];
    args.extend_from_slice(extra);
    let out = flapssm(&args);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice(&out.stdout).unwrap()
}

/// Short (100-iteration) actuator run with the given extra arguments.
fn short_actuator_run(extra: &[&str]) -> serde_json::Value {
    actuator_run("100", extra)
}

#[test]
fn restarts_are_independent_reproducible_and_combined_by_their_rule() {
    let ens = short_actuator_run(&["--restarts", "2"]);
    let run = &ens["runs"][0];
    let restarts = run["restarts"].as_array().unwrap();
    assert_eq!(restarts.len(), 2);
    // Restart 0 keeps the seed; restart 1 trains from a different one.
    assert_eq!(restarts[0]["train_seed"], 0);
    assert_ne!(restarts[1]["train_seed"], 0);
    assert!(run["selected_restart"].is_null());
    // The mixture mean's RMSE is at most the mean of the members' (triangle inequality).
    let member: Vec<f64> = restarts
        .iter()
        .map(|r| r["test"]["rmse"].as_f64().unwrap())
        .collect();
    let rmse = run["test"]["rmse"].as_f64().unwrap();
    assert!(
        rmse <= 0.5 * (member[0] + member[1]) + 1e-12,
        "{rmse} {member:?}"
    );
    assert_ne!(member[0], member[1]);
    // Same seed, same numbers.
    assert_eq!(
        short_actuator_run(&["--restarts", "2"])["runs"][0]["test"],
        run["test"]
    );
    // Selection keeps the restart with the lowest training open-loop RMSE, and the restarts
    // themselves do not depend on how they are combined.
    let sel = short_actuator_run(&["--restarts", "2", "--combine", "select"]);
    let sel_run = &sel["runs"][0];
    assert_eq!(sel_run["restarts"], run["restarts"]);
    let train: Vec<f64> = restarts
        .iter()
        .map(|r| r["best_train_rmse"].as_f64().unwrap())
        .collect();
    let best = usize::from(train[1] < train[0]);
    assert_eq!(sel_run["selected_restart"], best);
    assert_eq!(sel_run["test"], restarts[best]["test"]);
    // One restart is the plain protocol: its only member is the reported result.
    let single = short_actuator_run(&["--restarts", "1"]);
    let single_run = &single["runs"][0];
    assert_eq!(single_run["restarts"][0], restarts[0]);
    assert_eq!(single_run["test"], restarts[0]["test"]);
    let err = fails(&[
        "sysid",
        sysid_file("actuator.mat").to_str().unwrap(),
        "--input",
        "u",
        "--output",
        "p",
        "--restarts",
        "0",
    ]);
    assert!(err.contains("restarts"), "{err}");
}
