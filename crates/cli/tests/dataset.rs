//! `flapssm dataset …` end to end: import, info, export, round trip, and bad input.

mod common;

use std::path::{Path, PathBuf};

use common::{assert_fails, flapssm, s};
use std::process::Output;

use flapssm_data::npz::{NpyData, NpzReader, NpzWriter};
use flapssm_wing::dataset::Dataset;

fn fixture(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../data/tests/fixtures")
        .join(name)
}

/// Imports the 4 × 40 scipy fixture with 3 training trajectories.
fn imported(dir: &Path) -> PathBuf {
    let out = dir.join("d.npz");
    let o = flapssm(&[
        "dataset",
        "import",
        "--mat",
        s(&fixture("published_v5z.mat")),
        "--out",
        s(&out),
        "--n-train",
        "3",
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    out
}

#[test]
fn import_info_export_round_trip() {
    let dir = tempfile::tempdir().unwrap();
    let npz = imported(dir.path());
    let ds = Dataset::load(&npz).unwrap();
    assert_eq!(
        (ds.len(), ds.n_samples(), ds.n_train, ds.dt_s),
        (4, 40, 3, 0.04)
    );
    // Stroke is a triangle wave with steps of 0.25 rad per 0.04 s and constant deviation, so
    // the speed R·|φ̇| is v = 0.235 · 6.25 m/s at every sample and the published trapezoid
    // over a window of d samples gives U_ref = v (d − 1)/d for some integer d ≥ 2.
    let v = 0.235 * 0.25 / 0.04;
    for t in &ds.trajectories {
        assert!(
            (2..40).any(|d| (t.u_ref_m_s - v * (d - 1) as f64 / d as f64).abs() < 1e-12),
            "U_ref = {}",
            t.u_ref_m_s
        );
    }

    let o = flapssm(&["dataset", "info", s(&npz)]);
    assert!(o.status.success());
    let text = String::from_utf8_lossy(&o.stdout);
    for needle in [
        "4 (3 train, 1 test), 40 samples",
        "dt_s = 0.04",
        "measured",
        "pitch_acc",
        "M_z",
        "import:mat",
    ] {
        assert!(text.contains(needle), "info lacks {needle:?}:\n{text}");
    }

    let csv = dir.path().join("d.csv");
    let o = flapssm(&["dataset", "export", s(&npz), "--csv", s(&csv)]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let text = std::fs::read_to_string(&csv).unwrap();
    // 3 comment lines, the header and one line per sample.
    assert_eq!(text.lines().count(), 4 + 4 * 40);
    let back = dir.path().join("back.npz");
    let o = flapssm(&["dataset", "import", "--csv", s(&csv), "--out", s(&back)]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert_eq!(Dataset::load(&back).unwrap(), ds);
    assert_eq!(std::fs::read(&back).unwrap(), std::fs::read(&npz).unwrap());
}

#[test]
fn mat_missing_variable() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("o.npz");
    let o = flapssm(&[
        "dataset",
        "import",
        "--mat",
        s(&fixture("published_missing.mat")),
        "--out",
        s(&out),
        "--n-train",
        "2",
    ]);
    assert_fails(
        &o,
        &["published_missing.mat", "'ds_y_raw' is missing"],
        &out,
    );
    let o = flapssm(&[
        "dataset",
        "import",
        "--mat",
        s(&fixture("published_v5.mat")),
        "--out",
        s(&out),
    ]);
    assert_fails(&o, &["published_v5.mat", "n_train = 512"], &out);
}

/// Exports the imported fixture, edits its lines, and imports the result.
fn csv_import(dir: &Path, name: &str, edit: impl Fn(&mut Vec<String>)) -> (Output, PathBuf) {
    let npz = imported(dir);
    let csv = dir.join(name);
    assert!(
        flapssm(&["dataset", "export", s(&npz), "--csv", s(&csv)])
            .status
            .success()
    );
    let mut lines: Vec<String> = std::fs::read_to_string(&csv)
        .unwrap()
        .lines()
        .map(String::from)
        .collect();
    edit(&mut lines);
    std::fs::write(&csv, lines.join("\n")).unwrap();
    let out = dir.join("out.npz");
    (
        flapssm(&["dataset", "import", "--csv", s(&csv), "--out", s(&out)]),
        out,
    )
}

fn set_field(line: &mut String, column: usize, value: &str) {
    let mut f: Vec<&str> = line.split(',').collect();
    f[column] = value;
    *line = f.join(",");
}

#[test]
fn bad_csv_input() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    // Line 10 is trajectory 0, sample 5; column 12 (0-based 11) is a_z.
    let (o, out) = csv_import(d, "nan.csv", |l| set_field(&mut l[9], 11, "NaN"));
    assert_fails(&o, &["nan.csv", "line 10, column 12 (a_z)"], &out);
    let (o, out) = csv_import(d, "cols.csv", |l| l[20].push_str(",0"));
    assert_fails(&o, &["cols.csv", "line 21", "21 fields, expected 20"], &out);
    let (o, out) = csv_import(d, "short.csv", |l| {
        l.pop();
    });
    assert_fails(
        &o,
        &[
            "short.csv",
            "trajectory 3",
            "'euler_rad' has 39 samples, expected 40",
        ],
        &out,
    );
    let (o, out) = csv_import(d, "cut.csv", |l| {
        let last = l.last_mut().unwrap();
        last.truncate(last.len() / 2);
    });
    assert_fails(&o, &["cut.csv", "fields, expected 20"], &out);
    let (o, out) = csv_import(d, "version.csv", |l| {
        l[0] = "# flapssm-dataset-csv 2".into();
    });
    assert_fails(
        &o,
        &["version.csv", "format version '2' is not supported"],
        &out,
    );
}

/// Copies the imported fixture's npz with one member replaced.
fn npz_with(dir: &Path, name: &str, member: &str, shape: &[usize], data: NpyData) -> PathBuf {
    let npz = imported(dir);
    let mut r = NpzReader::open(&npz).unwrap();
    let mut w = NpzWriter::new();
    for n in r.names() {
        match r.f64(&n) {
            Ok(a) => w.add(&n, &a.shape, NpyData::F64(a.data)),
            Err(_) => {
                let a = r.strings(&n).unwrap();
                w.add(&n, &a.shape, NpyData::Str(a.data))
            }
        };
    }
    w.add(member, shape, data);
    let path = dir.join(name);
    w.save(&path).unwrap();
    path
}

#[test]
fn bad_dataset_files() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let out = d.join("out.csv");
    let export = |p: &Path| flapssm(&["dataset", "export", s(p), "--csv", s(&out)]);

    let mut u = vec![0.5; 4 * 40 * 7];
    u[(2 * 40 + 7) * 7 + 1] = f64::INFINITY;
    let p = npz_with(d, "inf.npz", "u", &[4, 40, 7], NpyData::F64(u));
    assert_fails(
        &export(&p),
        &["inf.npz", "array 'u' index [2, 7, 1] is inf"],
        &out,
    );

    let p = npz_with(
        d,
        "len.npz",
        "y",
        &[4, 39, 5],
        NpyData::F64(vec![0.0; 4 * 39 * 5]),
    );
    assert_fails(
        &export(&p),
        &["len.npz", "'y'", "[4, 39, 5]", "[4, 40, 5]"],
        &out,
    );

    let meta = Dataset::load(&imported(d)).unwrap().into_inner().meta;
    let mut json = serde_json::to_value(&meta).unwrap();
    json["format_version"] = serde_json::json!(2);
    let p = npz_with(
        d,
        "future.npz",
        "metadata",
        &[],
        NpyData::Str(vec![json.to_string()]),
    );
    assert_fails(
        &export(&p),
        &["future.npz", "format_version 2 is not supported"],
        &out,
    );

    let good = std::fs::read(imported(d)).unwrap();
    let cut = d.join("truncated.npz");
    std::fs::write(&cut, &good[..good.len() - 500]).unwrap();
    assert_fails(&export(&cut), &["truncated.npz"], &out);
    let o = flapssm(&["dataset", "info", s(&cut)]);
    assert!(!o.status.success());

    let mut bad = good.clone();
    let mid = bad.len() / 2;
    bad[mid..mid + 64].iter_mut().for_each(|b| *b ^= 0xff);
    let corrupt = d.join("corrupt.npz");
    std::fs::write(&corrupt, &bad).unwrap();
    assert_fails(&export(&corrupt), &["corrupt.npz"], &out);

    let garbage = d.join("garbage.npz");
    std::fs::write(&garbage, b"this is not a zip archive").unwrap();
    assert_fails(
        &export(&garbage),
        &["garbage.npz", "not a readable .npz"],
        &out,
    );
}
