//! What an output may be, for every command that writes one: an output that is one of the inputs
//! (by any name), a directory, a device, `-`, a file in a missing directory or a figure of an
//! unknown format is refused before any work, with exit status 1, the output and the reason
//! named, and nothing changed on disk; a symbolic link is written through. SIGTERM stops training
//! like Ctrl-C: a checkpoint, a message naming it, exit status 1, and `--resume` continues.

mod common;

use std::path::{Path, PathBuf};

use common::{flapssm, ok, reference, s, simulated};

/// Every file below `dir` with its bytes, sorted by path.
fn snapshot(dir: &Path) -> Vec<(PathBuf, Vec<u8>)> {
    let mut out = Vec::new();
    for e in std::fs::read_dir(dir).unwrap() {
        let p = e.unwrap().path();
        let meta = p.symlink_metadata().unwrap();
        if meta.is_dir() {
            out.extend(snapshot(&p));
        } else if meta.is_file() {
            out.push((p.clone(), std::fs::read(&p).unwrap()));
        } else {
            out.push((p.clone(), Vec::new()));
        }
    }
    out.sort();
    out
}

/// Exit status 1, every needle in stderr, no panic, and `dir` exactly as it was.
fn refused(args: &[&str], needles: &[&str], dir: &Path) {
    let before = snapshot(dir);
    let o = flapssm(args);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{args:?}: {err}");
    assert!(!err.contains("panicked"), "{args:?}: {err}");
    for n in needles {
        assert!(err.contains(n), "{args:?}: stderr lacks {n:?}: {err}");
    }
    assert!(
        snapshot(dir) == before,
        "{args:?} changed {}",
        dir.display()
    );
}

#[test]
fn bad_outputs_are_refused_before_any_work() {
    let tmp = tempfile::tempdir().unwrap();
    let d = tmp.path();
    let data = simulated(d, 3, 1);
    let ds = s(&data);
    let model = d.join("published.json");
    let reference_copy = d.join("reference.npz");
    std::fs::copy(reference("bayiz2021-prssm/reference.npz"), &reference_copy).unwrap();
    ok(&[
        "model",
        "import-published",
        s(&reference_copy),
        "--out",
        s(&model),
    ]);
    let m = s(&model);
    let sweep = d.join("dx6.json");
    std::fs::write(&sweep, b"{\"format\": \"flapssm-sweep-result\"}").unwrap();
    let sub = d.join("sub");
    std::fs::create_dir(&sub).unwrap();
    let dotted = format!(
        "{}/./{}",
        d.display(),
        data.file_name().unwrap().to_str().unwrap()
    );

    let (table, nodir) = (d.join("dx6.csv"), d.join("nodir/m.json"));
    let ballbeam =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../shared/data/sysid/ballbeam.csv");
    let jpg = d.join("x.jpg");
    let run = d.join("run");
    std::fs::create_dir_all(run.join("summary.json")).unwrap();
    let in_folder = run.join("predictions.npz");
    std::fs::copy(&data, &in_folder).unwrap();
    let is_input = "is the input";
    let cases: Vec<(Vec<&str>, Vec<&str>)> = vec![
        (vec!["dataset", "export", ds, "--csv", ds], vec![is_input]),
        (
            vec!["dataset", "export", ds, "--csv", &dotted],
            vec![is_input],
        ),
        (vec!["predict", m, ds, "--out", ds], vec![is_input]),
        (vec!["predict", m, ds, "--out", m], vec![is_input]),
        (
            vec![
                "model",
                "import-published",
                s(&reference_copy),
                "--out",
                s(&reference_copy),
            ],
            vec![is_input],
        ),
        (
            vec!["train", ds, "--out", ds, "--epochs", "1"],
            vec![is_input],
        ),
        (vec!["qs", "fit", ds, "--out", ds], vec![is_input]),
        (
            vec![
                "sweep",
                "run",
                "--kind",
                "dx",
                "--value",
                "6",
                "--dataset",
                ds,
                "--out",
                ds,
            ],
            vec![is_input],
        ),
        // The merged table's side-car (dx6.json) would overwrite an input.
        (
            vec!["sweep", "merge", s(&sweep), "--out", s(&table)],
            vec!["dx6.json: is the input"],
        ),
        (
            vec!["simulate", "--n", "2", "--out", "-"],
            vec!["standard output is not supported"],
        ),
        (
            vec!["simulate", "--n", "2", "--out", s(&sub)],
            vec!["is a directory"],
        ),
        (
            vec!["simulate", "--n", "2", "--out", "/dev/null"],
            vec!["not a regular file"],
        ),
        (
            vec!["train", ds, "--out", s(&nodir), "--epochs", "100000"],
            vec!["nodir", "does not exist"],
        ),
        (
            vec!["trajectories", "--n", "2", "--out", s(&sub)],
            vec!["is a directory"],
        ),
        (
            vec!["evaluate", "--dataset", ds, "--prssm", m, "--out", ds],
            vec!["is not a directory"],
        ),
        (vec!["demo", "--out", ds], vec!["is not a directory"]),
        // A file the job writes inside its folder: an input, or an existing directory.
        (
            vec![
                "evaluate",
                "--dataset",
                s(&in_folder),
                "--prssm",
                m,
                "--out",
                s(&run),
            ],
            vec!["predictions.npz: is the input"],
        ),
        (
            vec!["demo", "--out", s(&run)],
            vec!["summary.json", "is a directory"],
        ),
        (
            vec![
                "sysid",
                s(&ballbeam),
                "--input",
                "u",
                "--output",
                "y",
                "--plot",
                s(&jpg),
            ],
            vec!["x.jpg", "use a .png or .svg"],
        ),
    ];
    for (args, needles) in &cases {
        refused(args, needles, d);
    }
    assert!(!Path::new("-").exists());

    // A link is written through: it stays a link and its target gets the file.
    #[cfg(unix)]
    {
        let target = d.join("target.npz");
        std::fs::write(&target, b"old").unwrap();
        let link = d.join("link.npz");
        std::os::unix::fs::symlink(&target, &link).unwrap();
        ok(&[
            "simulate",
            "--n",
            "2",
            "--fidelity",
            "l0",
            "--quiet",
            "--out",
            s(&link),
        ]);
        assert!(link.symlink_metadata().unwrap().file_type().is_symlink());
        assert_eq!(&std::fs::read(&target).unwrap()[..2], b"PK");

        // So is a figure's.
        let figure = d.join("figure.png");
        std::fs::write(&figure, b"old").unwrap();
        let figure_link = d.join("link.png");
        std::os::unix::fs::symlink(&figure, &figure_link).unwrap();
        ok(&[
            "sysid",
            s(&ballbeam),
            "--input",
            "u",
            "--output",
            "y",
            "--seeds",
            "1",
            "--restarts",
            "1",
            "--iterations",
            "5",
            "--plot",
            s(&figure_link),
        ]);
        assert!(
            figure_link
                .symlink_metadata()
                .unwrap()
                .file_type()
                .is_symlink()
        );
        assert_eq!(&std::fs::read(&figure).unwrap()[1..4], b"PNG");
    }
}

/// SIGTERM during training writes the checkpoint and exits 1 naming it; `--resume` continues
/// from it; no temporary file is left.
#[cfg(unix)]
#[test]
fn sigterm_stops_training_with_a_checkpoint() {
    use std::process::{Command, Stdio};
    let tmp = tempfile::tempdir().unwrap();
    let d = tmp.path();
    let data = simulated(d, 4, 2);
    let out = d.join("m.json");
    let args = [
        "train",
        s(&data),
        "--out",
        s(&out),
        "--dx",
        "5",
        "--inducing",
        "8",
        "--particles",
        "2",
        "--batch",
        "2",
        "--epochs",
        "1000000",
    ];
    let child = Command::new(env!("CARGO_BIN_EXE_flapssm"))
        .args(args)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    std::thread::sleep(std::time::Duration::from_millis(1500));
    let killed = Command::new("kill")
        .args(["-TERM", &child.id().to_string()])
        .status()
        .unwrap();
    assert!(killed.success());
    let o = child.wait_with_output().unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(
        err.contains("interrupted at step") && err.contains("m.ckpt.json"),
        "{err}"
    );
    assert!(err.contains("--resume"), "{err}");
    let ckpt = d.join("m.ckpt.json");
    assert!(ckpt.exists());
    let leftovers = common::temporaries(d);
    assert!(leftovers.is_empty(), "{leftovers:?}");

    // Resuming reads the checkpoint (it would refuse one of another run).
    let child = Command::new(env!("CARGO_BIN_EXE_flapssm"))
        .args(args)
        .arg("--resume")
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    std::thread::sleep(std::time::Duration::from_millis(1500));
    Command::new("kill")
        .args(["-TERM", &child.id().to_string()])
        .status()
        .unwrap();
    let o = child.wait_with_output().unwrap();
    let text = format!(
        "{}{}",
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    );
    assert!(text.contains("resum"), "{text}");
    assert_eq!(o.status.code(), Some(1), "{text}");
}

/// Sizes whose memory the machine does not have are refused before any work, with the
/// estimate (they used to abort on a failed allocation, exit 134).
#[cfg(target_os = "linux")]
#[test]
fn sizes_beyond_the_machine_are_refused_up_front() {
    let tmp = tempfile::tempdir().unwrap();
    let d = tmp.path();
    let data = simulated(d, 3, 1);
    let ds = s(&data);
    let model = d.join("m.json");
    ok(&[
        "train",
        ds,
        "--out",
        s(&model),
        "--dx",
        "5",
        "--inducing",
        "4",
        "--particles",
        "2",
        "--epochs",
        "1",
    ]);
    let m = s(&model);
    let out = d.join("out.npz");
    let o = s(&out);
    let demo = d.join("demo");
    let cases: Vec<(Vec<&str>, &str)> = vec![
        (
            vec!["simulate", "--n", "100000000000", "--out", o],
            "n = 100000000000",
        ),
        (
            vec!["predict", m, ds, "--particles", "1000000000", "--out", o],
            "particles = 1000000000",
        ),
        (
            vec![
                "train",
                ds,
                "--out",
                o,
                "--particles",
                "100000000",
                "--epochs",
                "1",
            ],
            "particles = 100000000",
        ),
        (
            vec!["demo", "--trajectories", "10000000000", "--out", s(&demo)],
            "trajectories = 10000000000",
        ),
    ];
    for (args, setting) in &cases {
        refused(args, &[setting, "of memory, more than the", "available"], d);
    }
    assert!(!demo.exists());
}

/// `kill -9` at 24 seeded random moments of `simulate` and of `train` (checkpoint every epoch,
/// resumed after each kill) never leaves a corrupt dataset, model or checkpoint at the target
/// paths; `--resume` always continues; the temporaries of killed writes are gone after the next
/// successful write of the same names.
#[cfg(target_os = "linux")]
#[test]
fn kill_9_never_leaves_a_corrupt_file() {
    use std::process::{Command, Stdio};
    use std::time::Duration;
    let tmp = tempfile::tempdir().unwrap();
    let d = tmp.path();
    // A seeded generator of kill times (64-bit LCG; the test needs no more).
    let mut state = 0x2545_f491_4f6c_dd1du64;
    let mut uniform = move || {
        state = state
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        (state >> 11) as f64 / (1u64 << 53) as f64
    };
    let run_killed = |args: &[&str], after: Duration| {
        let mut child = Command::new(env!("CARGO_BIN_EXE_flapssm"))
            .args(args)
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .spawn()
            .unwrap();
        std::thread::sleep(after);
        let _ = child.kill(); // SIGKILL
        child.wait().unwrap()
    };

    let data = d.join("ds.npz");
    let simulate = [
        "simulate",
        "--n",
        "300",
        "--fidelity",
        "l0",
        "--quiet",
        "--out",
        s(&data),
    ];
    for k in 0..12 {
        run_killed(&simulate, Duration::from_secs_f64(1.5 * uniform()));
        if data.exists() {
            let ds = flapssm_wing::dataset::Dataset::load(&data)
                .unwrap_or_else(|e| panic!("kill {k}: corrupt dataset: {e}"));
            assert_eq!(ds.len(), 300);
        }
    }
    ok(&simulate);
    assert!(
        common::temporaries(d).is_empty(),
        "{:?}",
        common::temporaries(d)
    );

    let model = d.join("m.json");
    let ckpt = d.join("m.ckpt.json");
    let train = |resume: bool| {
        let mut a = vec![
            "train",
            s(&data),
            "--out",
            s(&model),
            "--dx",
            "5",
            "--inducing",
            "8",
            "--particles",
            "2",
            "--batch",
            "8",
            "--epochs",
            "160",
            "--checkpoint-every",
            "1",
            "--seed",
            "3",
        ];
        if resume {
            a.push("--resume");
        }
        a.into_iter().map(String::from).collect::<Vec<_>>()
    };
    for k in 0..12 {
        let args = train(ckpt.exists());
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        let status = run_killed(&args, Duration::from_secs_f64(0.2 + 1.5 * uniform()));
        assert!(
            status.success() || status.code().is_none(),
            "kill {k}: a resumed run failed by itself: {status}"
        );
        if ckpt.exists() {
            let c = flapssm_prssm::train::Checkpoint::load(&ckpt)
                .unwrap_or_else(|e| panic!("kill {k}: corrupt checkpoint: {e}"));
            eprintln!("kill {k}: {status}; checkpoint at step {}", c.state.step);
        }
        for m in [&model, &d.join("m.last.json")] {
            if m.exists() {
                flapssm_prssm::PrssmModel::load(m)
                    .unwrap_or_else(|e| panic!("kill {k}: corrupt model: {e}"));
            }
        }
    }
    let args = train(ckpt.exists());
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    ok(&args);
    flapssm_prssm::PrssmModel::load(&model).unwrap();
    assert!(
        common::temporaries(d).is_empty(),
        "{:?}",
        common::temporaries(d)
    );
}
