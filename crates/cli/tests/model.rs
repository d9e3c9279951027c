//! `flapssm model import-published` + `flapssm predict --inputs` against the authors' own runs
//! of the published model (shared/reference/bayiz2021-prssm), and a malformed parameter file.

mod common;

use std::path::Path;

use common::{assert_fails, flapssm, ok, read_csv, reference, s};
use flapssm_data::npz::{NpyData, NpzReader, NpzWriter};

const T: usize = 470;
const DY: usize = 5;

fn reference_npz() -> std::path::PathBuf {
    reference("bayiz2021-prssm/reference.npz")
}

/// Writes `u_in` (470 × 7, standardized) as a CSV with a header line.
fn write_inputs(r: &mut NpzReader, path: &Path) {
    let u = r.f64_shaped("u_in", &[T, 7]).unwrap();
    let mut text = String::from("aoa,speed,a_x,a_y,a_z,pitch_rate,pitch_acc\n");
    for row in u.chunks_exact(7) {
        let cells: Vec<String> = row.iter().map(|v| format!("{v:?}")).collect();
        text.push_str(&cells.join(","));
        text.push('\n');
    }
    std::fs::write(path, text).unwrap();
}

/// Largest |a − b| over all elements.
fn max_abs_diff(a: &[f64], b: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max)
}

/// Our prediction is a sixth independent Monte-Carlo run (30 fresh particles) of the authors'
/// model. For run k of their five, |run_k − mean of the other four| has variance
/// σ²(1 + 1/4) per point, slightly more than |ours − mean of all five| (σ²(1 + 1/5)), so the
/// largest leave-one-out deviation of their runs, +25 %, bounds ours. Variances: the ratio to
/// their mean variance must stay in the band their own runs span (±25 %). Step 0 is exact:
/// every particle starts at x₀ = 0, so the mean is 0 and the variance is σ_y².
#[test]
fn import_published_then_predict_lies_within_the_authors_run_to_run_spread() {
    let dir = tempfile::tempdir().unwrap();
    let model = dir.path().join("published.json");
    let stdout = ok(&[
        "model",
        "import-published",
        s(&reference_npz()),
        "--out",
        s(&model),
    ]);
    assert!(stdout.contains("D_x 12, D_y 5, D_u 7, M 100"), "{stdout}");

    let mut r = NpzReader::open(reference_npz()).unwrap();
    let u_csv = dir.path().join("u_in.csv");
    write_inputs(&mut r, &u_csv);
    let runs = r.f64_shaped("pred_mean_runs", &[5, T, DY]).unwrap();
    let var_runs = r.f64_shaped("pred_var_runs", &[5, T, DY]).unwrap();
    let var_y = r.f64_shaped("param_var_y", &[DY]).unwrap();
    let run = |k: usize| &runs[k * T * DY..(k + 1) * T * DY];
    let mean_of = |ks: &[usize], src: &[f64]| -> Vec<f64> {
        (0..T * DY)
            .map(|i| ks.iter().map(|&k| src[k * T * DY + i]).sum::<f64>() / ks.len() as f64)
            .collect()
    };
    let all = [0, 1, 2, 3, 4];
    let mean5 = mean_of(&all, &runs);
    let loo = (0..5)
        .map(|k| {
            let others: Vec<usize> = all.iter().copied().filter(|&j| j != k).collect();
            max_abs_diff(run(k), &mean_of(&others, &runs))
        })
        .fold(0.0, f64::max);
    let bound = 1.25 * loo;
    let var_mean = mean_of(&all, &var_runs);
    let ratios = |v: &[f64]| -> (f64, f64) {
        (DY..T * DY)
            .map(|i| v[i] / var_mean[i])
            .fold((f64::INFINITY, 0.0), |(lo, hi), x| (lo.min(x), hi.max(x)))
    };
    let (lo, hi) = (0..5)
        .map(|k| ratios(&var_runs[k * T * DY..(k + 1) * T * DY]))
        .fold((f64::INFINITY, 0.0f64), |(lo, hi), (a, b)| {
            (lo.min(a), hi.max(b))
        });

    for seed in ["1", "2", "3"] {
        let pred = dir.path().join(format!("pred{seed}.csv"));
        ok(&[
            "predict",
            s(&model),
            "--inputs",
            s(&u_csv),
            "--particles",
            "30",
            "--seed",
            seed,
            "--out",
            s(&pred),
        ]);
        let (header, rows) = read_csv(&pred);
        assert_eq!(header.len(), 1 + 2 * DY, "{header:?}");
        assert_eq!(
            (header[1].as_str(), header[6].as_str()),
            ("mean_0", "var_0")
        );
        assert_eq!(rows.len(), T);
        for (t, row) in rows.iter().enumerate() {
            assert_eq!(row[0], t as f64);
        }
        let mean: Vec<f64> = rows.iter().flat_map(|r| r[1..=DY].to_vec()).collect();
        let var: Vec<f64> = rows.iter().flat_map(|r| r[DY + 1..].to_vec()).collect();
        assert!(mean[..DY].iter().all(|&m| m == 0.0), "{:?}", &mean[..DY]);
        for j in 0..DY {
            assert!((var[j] - var_y[j]).abs() <= 1e-12 * var_y[j]);
        }
        let dev = max_abs_diff(&mean, &mean5);
        assert!(
            dev <= bound,
            "seed {seed}: max |ours − mean of 5 runs| = {dev:.4} > {bound:.4}"
        );
        let (a, b) = ratios(&var);
        assert!(
            a >= lo / 1.25 && b <= hi * 1.25,
            "seed {seed}: variance ratio {a:.3}..{b:.3}, the authors' runs {lo:.3}..{hi:.3}"
        );
    }
}

/// The reference parameters with one `param_*` array left out.
fn without(name: &str, path: &Path) {
    let mut r = NpzReader::open(reference_npz()).unwrap();
    let mut w = NpzWriter::new();
    for n in r.names() {
        if n == name || !n.starts_with("param_") {
            continue;
        }
        let a = r.f64(&n).unwrap();
        w.add(&n, &a.shape, NpyData::F64(a.data));
    }
    w.save(path).unwrap();
}

#[test]
fn malformed_parameter_file_is_refused_naming_the_missing_array() {
    let dir = tempfile::tempdir().unwrap();
    for name in ["param_kern_len", "param_zeta_var"] {
        let bad = dir.path().join(format!("no_{name}.npz"));
        without(name, &bad);
        let out = dir.path().join("m.json");
        let o = flapssm(&["model", "import-published", s(&bad), "--out", s(&out)]);
        assert_fails(&o, &[s(&bad), name], &out);
    }
    // The complete parameter set alone is enough.
    let full = dir.path().join("params_only.npz");
    without("none", &full);
    let out = dir.path().join("m.json");
    ok(&["model", "import-published", s(&full), "--out", s(&out)]);
    assert!(out.exists());
}

/// The published model imported into `dir/published.json`.
fn import_published(dir: &Path) -> std::path::PathBuf {
    let model = dir.join("published.json");
    ok(&[
        "model",
        "import-published",
        s(&reference_npz()),
        "--out",
        s(&model),
    ]);
    model
}

#[test]
fn wrong_input_width_is_refused_naming_the_csv() {
    let dir = tempfile::tempdir().unwrap();
    let model = import_published(dir.path());
    let csv = dir.path().join("six.csv");
    std::fs::write(&csv, "a,b,c,d,e,f\n0,0,0,0,0,0\n1,1,1,1,1,1\n").unwrap();
    let out = dir.path().join("pred.csv");
    let o = flapssm(&["predict", s(&model), "--inputs", s(&csv), "--out", s(&out)]);
    assert_fails(&o, &[s(&csv), "6 columns", "D_u = 7"], &out);
}

/// Runs `flapssm stream ARGS` with `stdin` piped in.
fn stream(args: &[&str], stdin: &[u8]) -> std::process::Output {
    use std::io::Write;
    use std::process::{Command, Stdio};
    let mut child = Command::new(env!("CARGO_BIN_EXE_flapssm"))
        .arg("stream")
        .args(args)
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    child.stdin.take().unwrap().write_all(stdin).unwrap();
    child.wait_with_output().unwrap()
}

/// `flapssm stream` on the authors' inputs writes exactly what `predict --inputs` writes for
/// the same seed (one step shared by both); a malformed row stops it with the line named.
#[test]
fn streaming_the_published_inputs_equals_the_batch_prediction() {
    let dir = tempfile::tempdir().unwrap();
    let model = import_published(dir.path());
    let inputs = dir.path().join("u_in.csv");
    write_inputs(&mut NpzReader::open(reference_npz()).unwrap(), &inputs);
    let batch = dir.path().join("batch.csv");
    ok(&[
        "predict",
        s(&model),
        "--inputs",
        s(&inputs),
        "--particles",
        "12",
        "--seed",
        "5",
        "--out",
        s(&batch),
    ]);
    let text = std::fs::read(&inputs).unwrap();
    let o = stream(&[s(&model), "--particles", "12", "--seed", "5"], &text);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert_eq!(o.stdout, std::fs::read(&batch).unwrap());
    assert!(String::from_utf8_lossy(&o.stderr).contains("470 steps"));

    let cut = text[..text.len() / 2]
        .iter()
        .rposition(|&b| b == b'\n')
        .unwrap();
    let mut bad = text[..=cut].to_vec();
    bad.extend_from_slice(b"1,2,3\n");
    let o = stream(&[s(&model)], &bad);
    assert!(!o.status.success());
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        err.contains("<stdin> line") && err.contains("3 columns, expected the model's 7 inputs"),
        "{err}"
    );
}
