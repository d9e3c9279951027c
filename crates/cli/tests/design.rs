//! `flapssm design`: bad targets refused before any work (exit 1, the field named, nothing
//! written), and a design's files. The model is the published one imported (its outputs are
//! the rig's standardized units: enough to run the command, not to read its loads as newtons;
//! the designs' figures come from the jobs' tests and docs/design.md).

mod common;

use common::{assert_fails, flapssm, ok, reference, s};

fn published(dir: &std::path::Path) -> std::path::PathBuf {
    let model = dir.join("published.json");
    let npz = reference("bayiz2021-prssm/reference.npz");
    ok(&["model", "import-published", s(&npz), "--out", s(&model)]);
    model
}

#[test]
fn bad_targets_are_refused_naming_the_field() {
    let dir = tempfile::tempdir().unwrap();
    let model = published(dir.path());
    let out = dir.path().join("out");
    let m = s(&model);
    let cases: [(&[&str], &[&str]); 5] = [
        (
            &["target", "--lift-n", "50"],
            &["target.lift_n", "unreachable"],
        ),
        (
            &["target", "--pitch-n-mm", "nan"],
            &["target.pitch_moment_n_mm", "not finite"],
        ),
        (
            &["target", "--lift-n", "0.05", "--frequency-hz", "3"],
            &["frequency_hz", "outside"],
        ),
        (&["hover", "--weight-n", "-1"], &["weight_n"]),
        (&["target"], &["nothing to design for"]),
    ];
    for (args, needles) in cases {
        let mut a = vec!["design"];
        a.extend_from_slice(&args[..1]);
        a.extend(["--prssm", m, "--out", s(&out), "--quiet"]);
        a.extend_from_slice(&args[1..]);
        assert_fails(&flapssm(&a), needles, &out.join("design.json"));
    }
    let o = flapssm(&[
        "design",
        "hover",
        "--prssm",
        "missing.json",
        "--weight-n",
        "0.1",
        "--out",
        s(&out),
    ]);
    assert_fails(&o, &["missing.json"], &out.join("design.json"));
}

#[test]
fn a_design_writes_its_report_and_figure() {
    let dir = tempfile::tempdir().unwrap();
    let model = published(dir.path());
    let out = dir.path().join("hover");
    std::fs::create_dir(&out).unwrap();
    let stdout = ok(&[
        "design",
        "target",
        "--prssm",
        s(&model),
        "--lift-n",
        "0.05",
        "--iterations",
        "3",
        "--starts",
        "1",
        "--particles",
        "4",
        "--out",
        s(&out),
        "--quiet",
    ]);
    assert!(
        stdout.contains("prssm predicted") && stdout.contains("quasi-steady on the wing"),
        "{stdout}"
    );
    for f in ["design.json", "design.md", "design.png"] {
        assert!(out.join(f).exists(), "{f}");
    }
}
