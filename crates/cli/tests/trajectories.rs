//! `flapssm trajectories`: reproducible files, the requested split, and refused arguments.

mod common;

use common::{assert_fails, flapssm, ok, s};
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
