//! Bad input across commands: each case exits with 1 (no panic), names the offending file
//! (and field, line or version where there is one) and writes no output. Also: writing to a
//! closed pipe ends the process by SIGPIPE, not by a panic.

mod common;

use std::path::Path;

use common::{assert_fails, flapssm, ok, reference, s, simulated};

/// Fixture files for the table, all in `dir`.
fn fixtures(dir: &Path) {
    let w = |name: &str, text: &str| std::fs::write(dir.join(name), text).unwrap();
    w("corrupt.npz", "PK\u{3}\u{4} this is not a zip archive");
    w("table.csv", "a,b,c\n1,2,3\n2,3,5\n3,5,8\n4,7,9\n5,8,13\n");
    let published = dir.join("published.json");
    ok(&[
        "model",
        "import-published",
        s(&reference("bayiz2021-prssm/reference.npz")),
        "--out",
        s(&published),
    ]);
    let mut m: serde_json::Value =
        serde_json::from_slice(&std::fs::read(&published).unwrap()).unwrap();
    m["version"] = 99.into();
    std::fs::write(dir.join("future.json"), m.to_string()).unwrap();
    let text = std::fs::read_to_string(&published).unwrap();
    w("truncated.json", &text[..text.len() / 2]);
    w(
        "foreign.json",
        r#"{"format": "something-else", "version": 1}"#,
    );
    let data = simulated(dir, 3, 1);
    std::fs::rename(data, dir.join("data.npz")).unwrap();
    ok(&[
        "qs",
        "fit",
        s(&dir.join("data.npz")),
        "--out",
        s(&dir.join("lrqsm.json")),
    ]);
    // The exported CSV with one value (line 10, column 12: a_z) replaced by NaN.
    let csv = dir.join("data.csv");
    ok(&[
        "dataset",
        "export",
        s(&dir.join("data.npz")),
        "--csv",
        s(&csv),
    ]);
    let text = std::fs::read_to_string(&csv).unwrap();
    let mut lines: Vec<String> = text.lines().map(String::from).collect();
    let mut cells: Vec<&str> = lines[9].split(',').collect();
    cells[11] = "NaN";
    lines[9] = cells.join(",");
    w("nan.csv", &(lines.join("\n") + "\n"));
}

#[test]
fn bad_inputs_are_refused_naming_the_file_and_writing_nothing() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    fixtures(dir);
    let p = |name: &str| dir.join(name).to_str().unwrap().to_string();
    // (arguments with OUT for the output path, needles in the message)
    let cases: Vec<(Vec<String>, Vec<String>)> = vec![
        // missing files
        (
            vec!["dataset", "info", &p("missing.npz")],
            vec!["missing.npz"],
        ),
        (
            vec!["dataset", "export", &p("missing.npz"), "--csv", "OUT"],
            vec!["missing.npz"],
        ),
        (
            vec!["train", &p("missing.npz"), "--out", "OUT"],
            vec!["missing.npz"],
        ),
        (
            vec![
                "predict",
                &p("missing.json"),
                &p("data.npz"),
                "--out",
                "OUT",
            ],
            vec!["missing.json"],
        ),
        (
            vec![
                "predict",
                &p("published.json"),
                "--inputs",
                &p("missing.csv"),
                "--out",
                "OUT",
            ],
            vec!["missing.csv"],
        ),
        (
            vec![
                "qs",
                "predict",
                &p("missing.json"),
                &p("data.npz"),
                "--out",
                "OUT",
            ],
            vec!["missing.json"],
        ),
        (
            vec![
                "model",
                "import-published",
                &p("missing.npz"),
                "--out",
                "OUT",
            ],
            vec!["missing.npz"],
        ),
        (
            vec!["history", "--dataset", &p("missing.npz"), "--out", "OUT"],
            vec!["missing.npz"],
        ),
        (
            vec![
                "history",
                "--dataset",
                &p("data.npz"),
                "--out",
                "OUT",
                "--cycles",
                "0.25,0.5",
            ],
            vec!["history_cycles", "starting at 0"],
        ),
        (
            vec!["train", &p("data.npz"), "--out", "OUT", "--resume"],
            vec!["OUT_STEM.ckpt.json"],
        ),
        // corrupt files
        (
            vec!["dataset", "info", &p("corrupt.npz")],
            vec!["corrupt.npz", ".npz archive"],
        ),
        (
            vec!["qs", "fit", &p("corrupt.npz"), "--out", "OUT"],
            vec!["corrupt.npz"],
        ),
        (
            vec![
                "predict",
                &p("truncated.json"),
                &p("data.npz"),
                "--out",
                "OUT",
            ],
            vec!["truncated.json", "line"],
        ),
        (
            vec!["dataset", "import", "--csv", &p("nan.csv"), "--out", "OUT"],
            vec!["nan.csv", "line 10, column 12 (a_z)", "NaN"],
        ),
        // wrong kind of file
        (
            vec!["train", &p("table.csv"), "--out", "OUT"],
            vec!["table.csv", ".npz"],
        ),
        (
            vec!["dataset", "info", &p("published.json")],
            vec!["published.json"],
        ),
        (
            vec![
                "predict",
                &p("foreign.json"),
                &p("data.npz"),
                "--out",
                "OUT",
            ],
            vec!["foreign.json", "something-else"],
        ),
        // Regression: an LRQSM file given as a PR-SSM model said "missing field `format` at
        // line 15361".
        (
            vec!["predict", &p("lrqsm.json"), &p("data.npz"), "--out", "OUT"],
            vec![
                "lrqsm.json",
                "format 'flapssm-lrqsm', expected 'flapssm-prssm-model'",
            ],
        ),
        (
            vec![
                "qs",
                "predict",
                &p("published.json"),
                &p("data.npz"),
                "--out",
                "OUT",
            ],
            vec!["published.json", "LRQSM"],
        ),
        (
            vec!["model", "import-published", &p("data.npz"), "--out", "OUT"],
            vec!["data.npz", "param_"],
        ),
        (
            vec![
                "predict",
                &p("published.json"),
                "--inputs",
                &p("table.csv"),
                "--out",
                "OUT",
            ],
            vec!["table.csv", "3 columns"],
        ),
        // nonexistent columns
        (
            vec![
                "qs",
                "fit-csv",
                &p("table.csv"),
                "--targets",
                "nope",
                "--out",
                "OUT",
            ],
            vec!["table.csv", "nope", "a, b, c"],
        ),
        (
            vec![
                "qs",
                "fit-csv",
                &p("table.csv"),
                "--targets",
                "c",
                "--features",
                "a,zz",
                "--out",
                "OUT",
            ],
            vec!["table.csv", "zz"],
        ),
        // future version
        (
            vec!["predict", &p("future.json"), &p("data.npz"), "--out", "OUT"],
            vec!["future.json", "version 99"],
        ),
        (
            vec![
                "predict",
                &p("future.json"),
                "--inputs",
                &p("table.csv"),
                "--out",
                "OUT",
            ],
            vec!["future.json", "version 99"],
        ),
        // unknown fidelity level
        (
            vec!["simulate", "--n", "2", "--fidelity", "l4", "--out", "OUT"],
            vec!["--fidelity", "l4"],
        ),
        (
            vec!["demo", "--fidelity", "l4", "--out", "OUT"],
            vec!["--fidelity", "l4"],
        ),
        // no outputs to train on
        (
            vec!["train", &p("kin.npz"), "--out", "OUT"],
            vec!["kin.npz", "no outputs"],
        ),
    ]
    .into_iter()
    .map(|(a, n)| {
        (
            a.into_iter().map(String::from).collect(),
            n.into_iter().map(String::from).collect(),
        )
    })
    .collect();
    ok(&["trajectories", "--n", "2", "--out", &p("kin.npz")]);
    for (i, (args, needles)) in cases.iter().enumerate() {
        let out = dir.join(format!("out{i}.result"));
        let args: Vec<String> = args.iter().map(|a| a.replace("OUT", s(&out))).collect();
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        let needles: Vec<String> = needles
            .iter()
            .map(|n| n.replace("OUT_STEM", &format!("out{i}")))
            .collect();
        let needles: Vec<&str> = needles.iter().map(String::as_str).collect();
        let o = flapssm(&args);
        assert_fails(&o, &needles, &out);
        // Causes are not repeated ("…(os error 2): …(os error 2)").
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(
            err.matches("os error").count() <= 1,
            "case {i} {args:?}: {err}"
        );
    }
}

/// `flapssm qs fit DATA --json | head -c 100`: the model JSON (≈ 400 kB, more than a pipe
/// holds) meets a closed pipe; the process must end by SIGPIPE, not panic in `println!`.
#[cfg(unix)]
#[test]
fn writing_to_a_closed_pipe_ends_quietly() {
    use std::io::Read;
    use std::os::unix::process::ExitStatusExt;
    use std::process::{Command, Stdio};
    let tmp = tempfile::tempdir().unwrap();
    let data = simulated(tmp.path(), 2, 0);
    let model = tmp.path().join("q.json");
    let mut child = Command::new(env!("CARGO_BIN_EXE_flapssm"))
        .args([
            "qs",
            "fit",
            s(&data),
            "--folds",
            "3",
            "--json",
            "--out",
            s(&model),
        ])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let mut head = [0u8; 100];
    child.stdout.take().unwrap().read_exact(&mut head).unwrap();
    let o = child.wait_with_output().unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(!err.contains("panicked"), "{err}");
    assert_eq!(o.status.signal(), Some(13), "status {:?}: {err}", o.status);
    assert!(String::from_utf8_lossy(&head).contains("flapssm-lrqsm"));
    assert!(model.exists());
}
