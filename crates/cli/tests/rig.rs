//! `flapssm rig check / fit-mount / wang2004 / draws / recovery`: their files, and bad input refused by name
//! with nothing written.

mod common;

use common::{assert_fails, flapssm, json, ok, reference, s, simulated};

fn published() -> String {
    reference("bayiz2021-prssm/reference.npz")
        .to_string_lossy()
        .into_owned()
}

/// `rig check DATASET --reference REFERENCE --out OUT --quiet`.
fn check_args<'a>(dataset: &'a str, reference: &'a str, out: &'a str) -> [&'a str; 8] {
    [
        "rig",
        "check",
        dataset,
        "--reference",
        reference,
        "--out",
        out,
        "--quiet",
    ]
}

/// The check writes its three files for a dataset holding test trajectories #5 and #13 (indices
/// 516 and 524 need 525 trajectories; the first 8 suffice for the other files) and refuses a
/// generated dataset, naming it, with no file written.
#[test]
fn rig_check_writes_its_files_and_refuses_other_trajectories() {
    let dir = tempfile::tempdir().unwrap();
    let ds = dir.path().join("paper.npz");
    ok(&[
        "simulate",
        "--source",
        "paper",
        "--n",
        "8",
        "--noise-free",
        "--quiet",
        "--out",
        s(&ds),
    ]);
    let out = dir.path().join("rig");
    let text = ok(&check_args(s(&ds), &published(), s(&out)));
    assert!(
        text.contains("| r, train |") && text.contains("r(F_y, F_x)"),
        "{text}"
    );
    let check = json(&out.join("rig-check.json"));
    assert_eq!(check["n_trajectories"], 8);
    assert_eq!(check["fidelity"], "l0");
    assert!(check["test"].is_null());
    assert!(out.join("rig-check.md").exists());
    assert!(
        !out.join("rig-examples.png").exists(),
        "no example trajectory among the first 8"
    );

    let generated = simulated(dir.path(), 3, 1);
    let bad_out = dir.path().join("bad");
    let o = flapssm(&check_args(s(&generated), &published(), s(&bad_out)));
    assert_fails(
        &o,
        &["trajectory 0", "--source paper"],
        &bad_out.join("rig-check.json"),
    );
    let missing = dir.path().join("missing.npz");
    let o = flapssm(&check_args(s(&ds), s(&missing), s(&bad_out)));
    assert_fails(&o, &["missing.npz"], &bad_out.join("rig-check.json"));
}

/// A grid that is not FROM:TO:STEP, or an angle beyond ±45°, is refused before any simulation.
#[test]
fn fit_mount_refuses_bad_grids() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("fit.json");
    let o = flapssm(&[
        "rig",
        "fit-mount",
        "--reference",
        &published(),
        "--plate-deg",
        "2:1:1",
        "--out",
        s(&out),
    ]);
    assert_eq!(
        o.status.code(),
        Some(2),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    let o = flapssm(&[
        "rig",
        "fit-mount",
        "--reference",
        &published(),
        "--plate-deg",
        "40:50:5",
        "--sensor-deg",
        "0:0:1",
        "--out",
        s(&out),
        "--quiet",
    ]);
    assert_fails(&o, &["plate_deg", "45"], &out);
}

/// The hovering case reads the published histories; a directory without them is refused,
/// naming the missing file.
#[test]
fn wang2004_compares_the_published_histories() {
    let dir = tempfile::tempdir().unwrap();
    let data = reference("../data/wang2004-hovering");
    let out = dir.path().join("wang");
    let text = ok(&["rig", "wang2004", "--data", s(&data), "--out", s(&out)]);
    assert!(text.contains("experiment (Wang et al. 2004)") && text.contains("flapssm L3"));
    let result = json(&out.join("wang2004.json"));
    assert_eq!(result["features"].as_array().unwrap().len(), 7);
    assert!(out.join("wang2004.png").exists());
    let empty = dir.path().join("empty");
    std::fs::create_dir(&empty).unwrap();
    let bad = dir.path().join("bad");
    let o = flapssm(&["rig", "wang2004", "--data", s(&empty), "--out", s(&bad)]);
    assert_fails(&o, &["CL_EXP.dat"], &bad.join("wang2004.json"));
}

/// `rig draws` writes the paper's 548 trajectories with drawn loads, the same file for the same
/// seed; `rig recovery` refuses draws that are not those 548 trajectories, and a missing model,
/// by name, with nothing written.
#[test]
fn draws_are_reproducible_and_recovery_refuses_other_data() {
    let dir = tempfile::tempdir().unwrap();
    let draws = |name: &str, seed: &str| {
        let path = dir.path().join(name);
        let text = ok(&[
            "rig",
            "draws",
            "--reference",
            &published(),
            "--seed",
            seed,
            "--out",
            s(&path),
            "--quiet",
        ]);
        assert!(
            text.contains("548 measured trajectories (512 train)"),
            "{text}"
        );
        std::fs::read(&path).unwrap()
    };
    let (a, b, c) = (
        draws("a.npz", "1"),
        draws("b.npz", "1"),
        draws("c.npz", "2"),
    );
    assert!(a == b, "same seed, same file");
    assert!(a != c, "another seed, other draws");

    let paper8 = dir.path().join("paper8.npz");
    ok(&[
        "simulate",
        "--source",
        "paper",
        "--n",
        "8",
        "--noise-free",
        "--quiet",
        "--out",
        s(&paper8),
    ]);
    let model = dir.path().join("published.json");
    ok(&[
        "model",
        "import-published",
        &published(),
        "--out",
        s(&model),
    ]);
    let out = dir.path().join("recovery");
    let recovery = |dataset: &str, prssm: &str| {
        flapssm(&[
            "rig",
            "recovery",
            dataset,
            "--prssm",
            prssm,
            "--reference",
            &published(),
            "--out",
            s(&out),
            "--quiet",
        ])
    };
    let o = recovery(s(&paper8), s(&model));
    assert_fails(&o, &["548", "rig draws"], &out.join("recovery.json"));
    let missing = dir.path().join("missing.json");
    let o = recovery(s(&dir.path().join("a.npz")), s(&missing));
    assert_fails(&o, &["missing.json"], &out.join("recovery.json"));
}
