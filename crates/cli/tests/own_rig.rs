//! A user's own rig end to end: the template, a rehearsal with the virtual wing, the build back
//! to the wing's loads, and bad descriptions and recordings refused (docs/own-rig.md).

mod common;

use std::path::{Path, PathBuf};

use common::{assert_fails, flapssm, ok, s};
use flapssm_wing::dataset::Dataset;

/// The template rig, rehearsed: (rig file, recordings directory, known-answer dataset).
fn rehearsed(dir: &Path, n: usize, motion_s: &str) -> (PathBuf, PathBuf, PathBuf) {
    let rig = dir.join("rig.toml");
    ok(&["dataset", "rig-template", "--out", s(&rig)]);
    let raw = dir.join("raw");
    let truth = dir.join("truth.npz");
    ok(&[
        "simulate",
        "--rig",
        s(&rig),
        "--recordings",
        s(&raw),
        "--n",
        &n.to_string(),
        "--motion-s",
        motion_s,
        "--seed",
        "3",
        "--out",
        s(&truth),
        "--quiet",
    ]);
    (rig, raw, truth)
}

fn recordings(raw: &Path) -> Vec<String> {
    let mut files: Vec<String> = std::fs::read_dir(raw)
        .unwrap()
        .map(|e| e.unwrap().path().to_str().unwrap().to_string())
        .collect();
    files.sort();
    files
}

fn rms(x: impl Iterator<Item = f64>) -> f64 {
    let (s, n) = x.fold((0.0, 0usize), |(s, n), v| (s + v * v, n + 1));
    (s / n as f64).sqrt()
}

/// The built dataset is the wing's own loads within 1 % of each kind's RMS (forces, moments),
/// at the rig's geometry and fluid, with the step files written.
#[test]
fn a_rehearsed_rig_builds_back_to_the_wings_loads() {
    let dir = tempfile::tempdir().unwrap();
    let (rig, raw, truth) = rehearsed(dir.path(), 2, "10");
    let out = dir.path().join("rig.npz");
    let steps = dir.path().join("steps");
    let mut args = vec![
        "dataset",
        "build",
        "--rig",
        s(&rig),
        "--out",
        s(&out),
        "--steps",
        s(&steps),
    ];
    let files = recordings(&raw);
    args.extend(files.iter().map(String::as_str));
    let stdout = ok(&args);
    assert!(stdout.contains("residual at rest"), "{stdout}");
    assert!(steps.join("recording_000.steps.csv").is_file());
    let (got, want) = (Dataset::load(&out).unwrap(), Dataset::load(&truth).unwrap());
    assert_eq!(got.meta.wing, want.meta.wing);
    assert_eq!(got.meta.wing.span_m, 0.12);
    assert_eq!(got.meta.fluid.density_kg_m3, 1000.0);
    assert_eq!(got.meta.generator, "flapssm dataset build");
    assert_eq!(got.trajectories.len(), 2);
    assert_within_one_percent(&got, &want);
}

/// Each channel of `got` within 1 % of the RMS of the largest channel of its kind in `want`
/// (forces, moments).
fn assert_within_one_percent(got: &Dataset, want: &Dataset) {
    for (g, w) in got.trajectories.iter().zip(&want.trajectories) {
        let (g, w) = (g.outputs.as_ref().unwrap(), w.outputs.as_ref().unwrap());
        let scale: Vec<f64> = (0..5).map(|c| rms(w.iter().map(|r| r[c]))).collect();
        for c in 0..5 {
            let kind = if c < 2 {
                scale[0].max(scale[1])
            } else {
                scale[2..].iter().cloned().fold(0.0, f64::max)
            };
            let e = rms(g.iter().zip(w).map(|(a, b)| a[c] - b[c])) / kind;
            assert!(e < 0.01, "channel {c}: {e}");
        }
    }
}

/// Writes `text` to `dir/name` and returns the path.
fn write(dir: &Path, name: &str, text: &str) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p
}

/// Every bad description and recording: exit 1, the file and field (or column, row) named,
/// nothing written.
#[test]
fn bad_rigs_and_recordings_are_refused_naming_the_file_and_field() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let (rig, raw, _) = rehearsed(d, 1, "8");
    let template = std::fs::read_to_string(&rig).unwrap();
    let recording = std::fs::read_to_string(raw.join("recording_000.csv")).unwrap();
    let out = d.join("out.npz");
    let build = |rig: &Path, rec: &Path| {
        flapssm(&[
            "dataset",
            "build",
            "--rig",
            s(rig),
            "--out",
            s(&out),
            s(rec),
        ])
    };
    let good = raw.join("recording_000.csv");

    // Descriptions.
    let cases: [(&str, &str, &str, &[&str]); 5] = [
        (
            "order.toml",
            r#"order = ["stroke", "pitch", "deviation"]"#,
            r#"order = ["stroke", "roll", "pitch"]"#,
            &["order.toml", "line", "roll"],
        ),
        (
            "density.toml",
            "density_kg_m3 = 1000.0",
            "density_kg_m3 = -1.0",
            &["density.toml", "fluid.density_kg_m3"],
        ),
        (
            "typo.toml",
            "span_m = 0.12",
            "span_m = 0.12\nspam_m = 1",
            &["typo.toml", "unknown field", "spam_m"],
        ),
        (
            "cutoff.toml",
            "cutoff_hz = 10.0",
            "cutoff_hz = 60.0",
            &["cutoff.toml", "filter.cutoff_hz", "half the dataset rate"],
        ),
        (
            "sign.toml",
            "sign = [-1, 1, -1]",
            "sign = [-1, 2, -1]",
            &["sign.toml", "angles.sign"],
        ),
    ];
    for (name, from, to, needles) in cases {
        assert!(template.contains(from), "{from}");
        let bad = write(d, name, &template.replacen(from, to, 1));
        assert_fails(&build(&bad, &good), needles, &out);
    }
    let no_mass = write(d, "no_mass.toml", &template.replace("[mass]", "[unused]"));
    assert_fails(
        &build(&no_mass, &good),
        &["no_mass.toml", "unknown field", "unused"],
        &out,
    );

    // Recordings: edit the text of the rehearsed one.
    let lines: Vec<String> = recording.lines().map(String::from).collect();
    let edit = |name: &str, f: &dyn Fn(&mut Vec<String>)| {
        let mut l = lines.clone();
        f(&mut l);
        write(d, name, &(l.join("\n") + "\n"))
    };
    let set = |line: &mut String, col: usize, v: &str| {
        let mut f: Vec<String> = line.split(',').map(String::from).collect();
        f[col] = v.into();
        *line = f.join(",");
    };
    // Columns: t, stroke, elevation, rotation, Fx, Fy, Fz, Tx, Ty, Tz; line 1 is the header.
    let nan = edit("nan.csv", &|l| set(&mut l[2001], 5, "NaN"));
    assert_fails(
        &build(&rig, &nan),
        &["nan.csv", "line 2002, column 6", "not a finite number"],
        &out,
    );
    let back = edit("back.csv", &|l| l.swap(3001, 3002));
    assert_fails(
        &build(&rig, &back),
        &[
            "back.csv",
            "time column 't' is not increasing at data row 3002",
        ],
        &out,
    );
    let slow = edit("rate.csv", &|l| {
        for (k, line) in l.iter_mut().enumerate().skip(1) {
            set(line, 0, &format!("{}", (k - 1) as f64 * 0.002));
        }
    });
    assert_fails(
        &build(&rig, &slow),
        &[
            "rate.csv",
            "time column 't' gives 500",
            "sampling.rate_hz is 1000",
        ],
        &out,
    );
    let missing = edit("missing.csv", &|l| l[0] = l[0].replace("Tz", "Mz"));
    assert_fails(
        &build(&rig, &missing),
        &["missing.csv", "'Tz'", "'Mz'"],
        &out,
    );
    let ragged = edit("ragged.csv", &|l| l[500].push_str(",1"));
    assert_fails(&build(&rig, &ragged), &["ragged.csv", "line 501"], &out);
    let moving = edit("moving.csv", &|l| set(&mut l[100], 3, "5"));
    assert_fails(
        &build(&rig, &moving),
        &["moving.csv", "column 'rotation_deg'", "tare.home_pose"],
        &out,
    );
    let short = edit("short.csv", &|l| l.truncate(1500));
    assert_fails(
        &build(&rig, &short),
        &["short.csv", "remain: no trajectory"],
        &out,
    );
}

/// The rigid body identified from a rehearsed run in air replaces `[mass]`: the water
/// recordings still build back to the wing's loads within 1 %.
#[test]
fn a_reference_run_in_air_replaces_the_mass_properties() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let (rig, raw, truth) = rehearsed(d, 2, "10");
    let template = std::fs::read_to_string(&rig).unwrap();
    let air = write(
        d,
        "air.toml",
        &template.replace("density_kg_m3 = 1000.0", "density_kg_m3 = 1.204"),
    );
    let air_raw = d.join("air");
    ok(&[
        "simulate",
        "--rig",
        s(&air),
        "--recordings",
        s(&air_raw),
        "--n",
        "1",
        "--motion-s",
        "12",
        "--seed",
        "8",
        "--out",
        s(&d.join("air-truth.npz")),
        "--quiet",
    ]);
    let (head, tail) = template.split_at(template.find("[mass]").unwrap());
    let tail = &tail[tail.find("[subtract]").unwrap()..];
    let reference = "[reference]\nrecordings = [\"air/recording_000.csv\"]\nmedium = \"air\"\nvolume_m3 = 9.6e-6\n\n";
    let identified = write(d, "identified.toml", &format!("{head}{reference}{tail}"));
    let out = d.join("identified.npz");
    let mut args = vec![
        "dataset",
        "build",
        "--rig",
        s(&identified),
        "--out",
        s(&out),
    ];
    let files = recordings(&raw);
    args.extend(files.iter().map(String::as_str));
    let stdout = ok(&args);
    assert!(stdout.contains("identified from"), "{stdout}");
    let (got, want) = (Dataset::load(&out).unwrap(), Dataset::load(&truth).unwrap());
    assert_within_one_percent(&got, &want);

    assert!(
        got.meta.settings["identified"]["inertial"]["mass_kg"]
            .as_f64()
            .is_some()
    );
    // A reference run in air without the volume cannot subtract the buoyancy.
    let no_volume = write(
        d,
        "no_volume.toml",
        &format!(
            "{head}{}{tail}",
            reference.replace("volume_m3 = 9.6e-6\n", "")
        ),
    );
    let o = flapssm(&[
        "dataset",
        "build",
        "--rig",
        s(&no_volume),
        "--out",
        s(&out.with_extension("x.npz")),
        &files[0],
    ]);
    assert_fails(
        &o,
        &["no_volume.toml", "reference.volume_m3"],
        &out.with_extension("x.npz"),
    );
}
