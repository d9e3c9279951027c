//! `flapssm train` on a small simulated dataset: the model files load and predict, a run
//! interrupted with Ctrl-C and resumed ends bit-identical to an uninterrupted one, a changed
//! configuration is refused on resume, and a divergent learning rate is reported.

mod common;

use std::io::{BufRead, BufReader};
use std::path::Path;
use std::process::{Command, Stdio};

use common::{assert_fails, flapssm, json, ok, s, simulated};
use flapssm_jobs::curve::read_curve;
use flapssm_prssm::PrssmModel;

const EPOCHS: &str = "60";

/// Tiny configuration: D_x 5, M 10, 4 particles, batches of 2 sequences.
fn train_args<'a>(data: &'a Path, out: &'a Path, epochs: &'a str) -> Vec<&'a str> {
    vec![
        "train",
        s(data),
        "--out",
        s(out),
        "--dx",
        "5",
        "--inducing",
        "10",
        "--particles",
        "4",
        "--batch",
        "2",
        "--epochs",
        epochs,
        "--seed",
        "7",
        "--checkpoint-every",
        "5",
    ]
}

/// Runs training, sends SIGINT once the first epoch is reported, and waits.
fn interrupted_run(args: &[&str]) -> (Option<i32>, String) {
    let mut child = Command::new(env!("CARGO_BIN_EXE_flapssm"))
        .args(args)
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let mut lines = BufReader::new(child.stderr.take().unwrap()).lines();
    let mut err = String::new();
    for line in lines.by_ref() {
        let line = line.unwrap();
        err.push_str(&line);
        err.push('\n');
        if line.starts_with("epoch") {
            let kill = Command::new("kill")
                .args(["-INT", &child.id().to_string()])
                .status()
                .unwrap();
            assert!(kill.success());
            break;
        }
    }
    for line in lines {
        err.push_str(&line.unwrap());
        err.push('\n');
    }
    (child.wait().unwrap().code(), err)
}

#[test]
fn ctrl_c_then_resume_is_bit_identical_and_the_model_predicts() {
    let dir = tempfile::tempdir().unwrap();
    let data = simulated(dir.path(), 12, 2);

    let a = dir.path().join("a.json");
    let stdout = ok(&train_args(&data, &a, EPOCHS));
    assert!(stdout.contains("60 epochs"), "{stdout}");

    let b = dir.path().join("b.json");
    let ckpt = dir.path().join("b.ckpt.json");
    let (code, err) = interrupted_run(&train_args(&data, &b, EPOCHS));
    assert_eq!(code, Some(1), "{err}");
    assert!(err.contains("interrupted at step"), "{err}");
    assert!(!err.contains("panicked"), "{err}");
    assert!(ckpt.exists() && !b.exists(), "{err}");
    let step = json(&ckpt)["state"]["step"].as_u64().unwrap();
    assert!(step > 0 && step < 300, "interrupted at step {step}");

    ok(&[&train_args(&data, &b, EPOCHS)[..], &["--resume"]].concat());
    for (x, y) in [
        (a.clone(), b.clone()),
        (
            dir.path().join("a.last.json"),
            dir.path().join("b.last.json"),
        ),
    ] {
        let (fx, fy) = (std::fs::read(&x).unwrap(), std::fs::read(&y).unwrap());
        assert!(fx == fy, "{} and {} differ", x.display(), y.display());
    }
    let history = json(&b)["model"]["training"]["history"].clone();
    assert_eq!(history.as_array().unwrap().len(), 60);
    // The learning curve beside the model: one row per evaluated epoch, the resumed run's
    // rows continuing the interrupted one's (same epochs, steps and RMSEs as the
    // uninterrupted run, wall time never going back).
    let curve_a = read_curve(&dir.path().join("a.curve.csv")).unwrap();
    let curve_b = read_curve(&dir.path().join("b.curve.csv")).unwrap();
    assert_eq!(curve_b.len(), 60);
    for (k, (pa, pb)) in curve_a.iter().zip(&curve_b).enumerate() {
        assert_eq!((pa.epoch, pa.step), (pb.epoch, pb.step));
        assert_eq!(pa.val_rmse.to_bits(), pb.val_rmse.to_bits());
        assert_eq!(pb.val_rmse, history[k]["val_rmse"].as_f64().unwrap());
    }
    assert!(curve_b.windows(2).all(|w| w[1].wall_s >= w[0].wall_s));
    let ttq = ok(&[
        "bench",
        "--batches",
        "1",
        "--reps",
        "1",
        "--train",
        s(&dir.path().join("b.curve.csv")),
    ]);
    assert!(
        ttq.contains("time to quality") && ttq.contains("reached at epoch"),
        "{ttq}"
    );

    let model = PrssmModel::load(&b).unwrap();
    assert_eq!(
        (
            model.config.n_state,
            model.config.n_inducing,
            model.config.n_input
        ),
        (5, 10, 7)
    );
    assert!(model.normalization.is_some());
    let pred = dir.path().join("pred.npz");
    ok(&[
        "predict",
        s(&b),
        s(&data),
        "--particles",
        "4",
        "--out",
        s(&pred),
    ]);
    let mean = flapssm_data::npz::NpzReader::open(&pred)
        .unwrap()
        .f64_shaped("output_mean", &[12, 470, 5])
        .unwrap();
    assert!(mean.iter().all(|m| m.is_finite()));
}

#[test]
fn resuming_with_another_configuration_is_refused_naming_the_field() {
    let dir = tempfile::tempdir().unwrap();
    let data = simulated(dir.path(), 6, 1);
    let first = dir.path().join("m.json");
    ok(&train_args(&data, &first, "5"));
    let ckpt = dir.path().join("m.ckpt.json");
    assert!(ckpt.exists());
    let out = dir.path().join("n.json");
    let mut args = train_args(&data, &out, "5");
    args.extend(["--lr", "0.01", "--resume", "--checkpoint", s(&ckpt)]);
    let o = flapssm(&args);
    assert_fails(&o, &["lr", "0.01", s(&data)], &out);
}

/// Regression: resuming used to compare only the optimizer settings, so a checkpoint was
/// silently continued with another particle count or on other data.
#[test]
fn resuming_with_another_model_setting_or_dataset_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let data = simulated(dir.path(), 6, 1);
    let first = dir.path().join("m.json");
    ok(&train_args(&data, &first, "5"));
    let ckpt = dir.path().join("m.ckpt.json");
    let out = dir.path().join("n.json");

    let mut args = train_args(&data, &out, "5");
    let p = args.iter().position(|a| *a == "--particles").unwrap();
    args[p + 1] = "9";
    args.extend(["--resume", "--checkpoint", s(&ckpt)]);
    assert_fails(&flapssm(&args), &["particles", "4", "9"], &out);

    let other_dir = dir.path().join("other");
    std::fs::create_dir(&other_dir).unwrap();
    let other = simulated(&other_dir, 6, 2);
    let mut args = train_args(&other, &out, "5");
    args.extend(["--resume", "--checkpoint", s(&ckpt)]);
    assert_fails(&flapssm(&args), &["run_context.data"], &out);
}

#[test]
fn a_divergent_learning_rate_is_reported_and_the_step_undone() {
    let dir = tempfile::tempdir().unwrap();
    let data = simulated(dir.path(), 6, 1);
    let out = dir.path().join("m.json");
    let mut args = train_args(&data, &out, "2");
    args.extend(["--lr", "50"]);
    let o = flapssm(&args);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{err}");
    assert!(
        err.contains("warning: step") && err.contains("rejected") && err.contains("step undone"),
        "{err}"
    );
    assert!(err.contains("learning-rate factor now 5.000e-1"), "{err}");
    assert!(out.exists());
}

/// A finished run resumed with a larger budget is extended from where it stopped: 3 epochs,
/// then `--resume --epochs 6`, ends byte-identical to 6 epochs in one go (constant learning
/// rate), and says so; a smaller budget than the checkpoint's step is refused.
#[test]
fn a_finished_run_is_extended_by_resuming_with_a_larger_budget() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let data = simulated(d, 4, 5);
    let (ext, once) = (d.join("ext.json"), d.join("once.json"));
    ok(&train_args(&data, &ext, "3"));
    let mut args = train_args(&data, &ext, "6");
    args.push("--resume");
    let o = flapssm(&args);
    let text =
        String::from_utf8_lossy(&o.stdout).into_owned() + &String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{text}");
    assert!(
        text.contains("extending the run from 3 epochs to 6 epochs")
            && text.contains("the constant learning rate continues"),
        "{text}"
    );
    ok(&train_args(&data, &once, "6"));
    for (a, b) in [
        ("ext.json", "once.json"),
        ("ext.last.json", "once.last.json"),
    ] {
        assert_eq!(
            std::fs::read(d.join(a)).unwrap(),
            std::fs::read(d.join(b)).unwrap(),
            "{a}"
        );
    }
    let mut args = train_args(&data, &ext, "2");
    args.push("--resume");
    let o = flapssm(&args);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(err.contains("past this run's"), "{err}");
}

/// `--objective published-code` trains with the authors' objective: the model records it and
/// samples with shared draws; its training loss is the likelihood summed over the 4 particles
/// (about 4× the standard one's, whose likelihood is divided by the particle count and
/// multiplied by sequences / batch = 1 here); a checkpoint of one form is not resumed with the
/// other.
#[test]
fn the_published_code_objective_is_selectable_and_recorded() {
    let dir = tempfile::tempdir().unwrap();
    let data = simulated(dir.path(), 2, 3);
    let loss_of = |out: &Path, objective: &str| {
        let mut args = train_args(&data, out, "1");
        args.extend(["--objective", objective, "--val-fraction", "0"]);
        ok(&args);
        let model = json(out)["model"].clone();
        let first = model["training"]["history"][0]["mean_loss"]
            .as_f64()
            .unwrap();
        (model, first)
    };
    let (pub_model, pub_loss) = loss_of(&dir.path().join("p.json"), "published-code");
    let (std_model, std_loss) = loss_of(&dir.path().join("s.json"), "standard");
    assert_eq!(pub_model["training"]["spec"]["objective"], "published_code");
    assert_eq!(pub_model["config"]["shared_draws"], true);
    assert_eq!(std_model["training"]["spec"]["objective"], "standard");
    assert_eq!(std_model["config"]["shared_draws"], false);
    assert!(
        pub_loss > 2.0 * std_loss,
        "published {pub_loss}, standard {std_loss}"
    );

    let ckpt = dir.path().join("p.ckpt.json");
    let out = dir.path().join("q.json");
    // A larger budget too: the refusal is the first thing said (regression: "extending the
    // run …" used to be printed before the checkpoint's configuration was checked).
    for epochs in ["1", "2"] {
        let mut args = train_args(&data, &out, epochs);
        args.extend(["--val-fraction", "0", "--resume", "--checkpoint", s(&ckpt)]);
        assert_fails(&flapssm(&args), &["run_context.fit"], &out);
    }
}

/// `--inducing-init kmeans` starts `Z` on the training inputs, is recorded in the model file,
/// and a bad value is refused naming the choices.
#[test]
fn the_inducing_start_is_selectable_and_recorded() {
    let dir = tempfile::tempdir().unwrap();
    let data = simulated(dir.path(), 3, 4);
    let start_of = |rule: &str| {
        let out = dir.path().join(format!("{rule}.json"));
        let mut args = train_args(&data, &out, "1");
        args.extend([
            "--inducing-init",
            rule,
            "--val-fraction",
            "0",
            "--lr",
            "1e-9",
        ]);
        ok(&args);
        let model = json(&out)["model"].clone();
        assert_eq!(model["training"]["spec"]["inducing_init"], rule);
        let z: Vec<f64> = model["params"]["inducing_inputs"]
            .as_array()
            .unwrap()
            .iter()
            .map(|v| v.as_f64().unwrap())
            .collect();
        z
    };
    // With a learning rate of 1e-9 the trained Z is its start: the two starts differ, and
    // the k-means start is seeded (a second run gives it again).
    let (uniform, kmeans) = (start_of("uniform"), start_of("kmeans"));
    assert_ne!(uniform, kmeans);
    assert_eq!(kmeans, start_of("kmeans"));
    let refused = dir.path().join("x.json");
    let mut args = train_args(&data, &refused, "1");
    args.extend(["--inducing-init", "random"]);
    let out = flapssm(&args);
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("kmeans") && err.contains("uniform"), "{err}");
}

/// Trains one epoch of `data` into `dir/<name>.json` with `flags` (and no validation split);
/// returns the model's training spec and its first-epoch mean loss.
fn one_epoch(dir: &Path, data: &Path, name: &str, flags: &[&str]) -> (serde_json::Value, f64) {
    let out = dir.join(format!("{name}.json"));
    let mut args = train_args(data, &out, "1");
    args.extend(["--val-fraction", "0"]);
    args.extend(flags);
    ok(&args);
    let training = json(&out)["model"]["training"].clone();
    let loss = training["history"][0]["mean_loss"].as_f64().unwrap();
    (training["spec"].clone(), loss)
}

/// Resuming the checkpoint of the `one_epoch` run `name` with `flags` is refused naming the
/// run context, and writes nothing.
fn resume_is_refused(dir: &Path, data: &Path, name: &str, flags: &[&str]) {
    let ckpt = dir.join(format!("{name}.ckpt.json"));
    let out = dir.join("resumed.json");
    let mut args = train_args(data, &out, "2");
    args.extend(["--val-fraction", "0", "--resume", "--checkpoint", s(&ckpt)]);
    args.extend(flags);
    assert_fails(&flapssm(&args), &["run_context.fit"], &out);
}

/// A bad flag value is a usage error (status 2) whose message contains every needle.
fn usage_error(dir: &Path, data: &Path, flags: &[&str], needles: &[&str]) {
    let out = dir.join("refused.json");
    let mut args = train_args(data, &out, "1");
    args.extend(flags);
    let o = flapssm(&args);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(needles.iter().all(|n| err.contains(n)), "{err}");
}

/// `--precision mixed` trains with the large products in f32: recorded in the model file, a
/// first-epoch loss within 1e-5 relative of f64's but not equal to it; a checkpoint of one
/// precision is not resumed with the other; a bad value is refused naming the choices.
#[test]
fn the_precision_is_selectable_and_recorded() {
    let dir = tempfile::tempdir().unwrap();
    let (dir, data) = (dir.path(), simulated(dir.path(), 2, 3));
    let (f64_spec, f64_loss) = one_epoch(dir, &data, "f64", &["--precision", "f64"]);
    let (mixed_spec, mixed_loss) = one_epoch(dir, &data, "mixed", &["--precision", "mixed"]);
    assert_eq!(
        (&f64_spec["precision"], &mixed_spec["precision"]),
        (&"f64".into(), &"mixed".into())
    );
    let rel = (mixed_loss - f64_loss).abs() / f64_loss.abs();
    assert!(
        rel > 0.0 && rel < 1e-5,
        "f64 {f64_loss}, mixed {mixed_loss}"
    );
    resume_is_refused(dir, &data, "f64", &["--precision", "mixed"]);
    usage_error(dir, &data, &["--precision", "half"], &["f64", "mixed"]);
}

/// `--windows-per-task N` is recorded in the model file and changes the first-epoch loss only
/// by rounding (the same draws, summed in other tasks); a checkpoint of one task size is not
/// resumed with another; 0 is refused naming the flag.
#[test]
fn the_task_size_is_recorded_and_changes_only_rounding() {
    let dir = tempfile::tempdir().unwrap();
    let (dir, data) = (dir.path(), simulated(dir.path(), 2, 3));
    let (one_spec, one) = one_epoch(dir, &data, "t1", &["--windows-per-task", "1"]);
    let (four_spec, four) = one_epoch(dir, &data, "t4", &["--windows-per-task", "4"]);
    assert_eq!(
        (
            &one_spec["windows_per_task"],
            &four_spec["windows_per_task"]
        ),
        (&1.into(), &4.into())
    );
    assert!(
        (one - four).abs() <= 1e-6 * four.abs(),
        "1 per task {one}, 4 per task {four}"
    );
    resume_is_refused(dir, &data, "t1", &["--windows-per-task", "4"]);
    usage_error(
        dir,
        &data,
        &["--windows-per-task", "0"],
        &["--windows-per-task"],
    );
}

/// `--lengthscale-init L` starts every lengthscale at L: recorded in the model's spec, visible
/// in the parameters after a step of a vanishing learning rate; a non-positive value is
/// refused naming the setting.
#[test]
fn the_initial_lengthscale_is_selectable() {
    let dir = tempfile::tempdir().unwrap();
    let (dir, data) = (dir.path(), simulated(dir.path(), 2, 3));
    let (spec, _) = one_epoch(
        dir,
        &data,
        "l",
        &["--lengthscale-init", "7.5", "--lr", "1e-9"],
    );
    assert_eq!(spec["init"]["lengthscale"], 7.5);
    let model = json(&dir.join("l.json"))["model"].clone();
    for l in model["params"]["lengthscales"].as_array().unwrap() {
        assert!((l.as_f64().unwrap() - 7.5).abs() < 1e-6, "{l}");
    }
    let bad = dir.join("bad.json");
    let mut args = train_args(&data, &bad, "1");
    args.extend(["--lengthscale-init", "0"]);
    let o = flapssm(&args);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        !o.status.success() && err.contains("lengthscale_init"),
        "{err}"
    );
}

/// `--preset paper-fast` trains with its own precision, task size and initial lengthscale
/// unless a flag overrides them (`--precision f64`).
#[test]
fn the_fast_preset_brings_its_settings_and_flags_override_them() {
    let dir = tempfile::tempdir().unwrap();
    let (dir, data) = (dir.path(), simulated(dir.path(), 2, 3));
    let (fast, _) = one_epoch(dir, &data, "fast", &["--preset", "paper-fast"]);
    assert_eq!(fast["precision"], "mixed");
    assert_eq!(fast["windows_per_task"], 2);
    assert_eq!(fast["init"]["lengthscale"], 10.0);
    let flags = ["--preset", "paper-fast", "--precision", "f64"];
    let (f64_spec, _) = one_epoch(dir, &data, "fast64", &flags);
    assert_eq!(f64_spec["precision"], "f64");
    assert_eq!(f64_spec["init"]["lengthscale"], 10.0);
}

/// `--patience N` ends the run once N evaluated epochs in a row bring no new best model, and
/// says so; the model files are written as for a whole run.
#[test]
fn patience_stops_training_early_and_says_so() {
    let dir = tempfile::tempdir().unwrap();
    let data = simulated(dir.path(), 6, 5);
    let out = dir.path().join("p.json");
    let mut args = train_args(&data, &out, "60");
    args.extend(["--patience", "2", "--lr", "0.3"]);
    let o = flapssm(&args);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("stopped early at step"), "{err}");
    let history = json(&out)["model"]["training"]["history"].clone();
    let h = history.as_array().unwrap();
    assert!(h.len() < 60);
    assert!(h[h.len() - 2..].iter().all(|r| r["is_best"] == false));
    assert_eq!(
        read_curve(&dir.path().join("p.curve.csv")).unwrap().len(),
        h.len()
    );
    let mut zero = train_args(&data, &out, "60");
    zero.extend(["--patience", "0"]);
    let o = flapssm(&zero);
    assert!(!o.status.success());
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("--patience"), "{err}");
}
