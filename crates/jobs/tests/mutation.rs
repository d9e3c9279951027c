//! Seeded mutation suite of every file reader: small valid files (dataset `.npz` written by
//! flapssm and by numpy, dataset CSV, PR-SSM model, training checkpoint, LRQSM model, MAT level 4
//! and 5, the published dataset's `.mat` layout, CSV and whitespace tables) are corrupted thousands of times — bits flipped, truncated, bytes
//! overwritten, inserted or deleted — and each reader must answer every case with `Ok` or an
//! error naming the file, never a panic. Prints the count of cases, errors and accepted
//! mutations (a flipped digit can leave a valid file) and the time.

use std::panic::{AssertUnwindSafe, catch_unwind};
use std::path::{Path, PathBuf};
use std::time::Instant;

use flapssm_data::mat::MatFile;
use flapssm_data::table::Table;
use flapssm_jobs::NoProgress;
use flapssm_jobs::models::Fit;
use flapssm_jobs::models::lrqsm::LrqsmFit;
use flapssm_jobs::train::{TrainFiles, TrainingOptions, train_dataset};
use flapssm_prssm::PrssmModel;
use flapssm_prssm::train::Checkpoint;
use flapssm_qs::{EnetOptions, LrqsmModel};
use flapssm_wing::dataset::Dataset;
use flapssm_wing::dataset::published::import_published_mat;
use flapssm_wing::features::FeatureSet;
use flapssm_wing::virtual_wing::{Fidelity, SimulationConfig, simulate_dataset};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// A reader: `Ok(content)` (a fingerprint of what it read) when it accepted the file,
/// `Err(message)` otherwise.
type Reader = fn(&Path) -> Result<u64, String>;

/// A fingerprint of a value read (its debug text, hashed).
fn content<T: std::fmt::Debug>(v: T) -> u64 {
    use std::hash::{Hash, Hasher};
    let mut h = std::collections::hash_map::DefaultHasher::new();
    format!("{v:?}").hash(&mut h);
    h.finish()
}

fn err(e: impl std::fmt::Display) -> String {
    e.to_string()
}

/// The valid files, written into `dir`, each with its reader.
fn fixtures(dir: &Path) -> Vec<(&'static str, PathBuf, Reader)> {
    let mut cfg = SimulationConfig::default();
    cfg.wing.fidelity = Fidelity::L0;
    cfg.trajectories.n_trajectories = 3;
    cfg.trajectories.n_train = 2;
    cfg.trajectories.seed = 1;
    cfg.trajectories.sampling.n_samples = 200;
    cfg.trajectories.frequency_hz = [0.2, 0.3];
    let ds = simulate_dataset(&cfg, &|| {}).unwrap();
    let npz = dir.join("d.npz");
    ds.save(&npz).unwrap();
    let csv = dir.join("d.csv");
    ds.export_csv(&csv).unwrap();

    let plan = TrainingOptions {
        dx: Some(5),
        inducing: Some(3),
        particles: Some(2),
        epochs: Some(1),
        batch: Some(2),
        checkpoint_every: 1,
        val_fraction: 0.0,
        ..TrainingOptions::default()
    }
    .check()
    .unwrap();
    let files = TrainFiles::beside(&dir.join("m.json"), None);
    train_dataset(&ds, &plan, &files, false, &NoProgress, None).unwrap();

    let lq = LrqsmFit {
        features: FeatureSet::Published,
        prediction_intercept: Default::default(),
        options: EnetOptions {
            n_lambdas: 5,
            n_folds: 2,
            ..EnetOptions::default()
        },
        source: "d.npz".into(),
    }
    .fit(&ds, &NoProgress)
    .unwrap();
    let lq_path = dir.join("lq.json");
    lq.model().save(&lq_path).unwrap();

    let table = dir.join("t.csv");
    std::fs::write(&table, "u,y\n0.1,0.2\n0.3,-0.4\n1e-3,5\n").unwrap();
    let ascii = dir.join("t.dat");
    std::fs::write(&ascii, "% u y\n0.1 0.2\n0.3 -0.4\n1e-3 5\n").unwrap();
    let fixture = |name: &str| {
        Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../data/tests/fixtures")
            .join(name)
    };

    vec![
        ("dataset npz", npz, |p| {
            Dataset::load(p).map(content).map_err(err)
        }),
        ("dataset csv", csv, |p| {
            Dataset::import_csv(p).map(content).map_err(err)
        }),
        ("PR-SSM model", files.model.clone(), |p| {
            PrssmModel::load(p).map(content).map_err(err)
        }),
        ("checkpoint", files.checkpoint.clone(), |p| {
            Checkpoint::load(p).map(content).map_err(err)
        }),
        ("LRQSM model", lq_path, |p| {
            LrqsmModel::load(p).map(content).map_err(err)
        }),
        ("table csv", table, |p| {
            Table::read_csv(p).map(content).map_err(err)
        }),
        ("table ascii", ascii, |p| {
            Table::read_ascii(p).map(content).map_err(err)
        }),
        ("published MAT v5", fixture("published_v5.mat"), |p| {
            import_published_mat(p, Some(3), |_, _| Ok(0.1))
                .map(content)
                .map_err(err)
        }),
        (
            "published MAT v5 compressed",
            fixture("published_v5z.mat"),
            |p| {
                import_published_mat(p, Some(3), |_, _| Ok(0.1))
                    .map(content)
                    .map_err(err)
            },
        ),
        (
            "numpy-written dataset npz",
            fixture("tiny_dataset.npz"),
            |p| Dataset::load(p).map(content).map_err(err),
        ),
        ("MAT v4", fixture("small_v4.mat"), |p| {
            MatFile::read(p).map(content).map_err(err)
        }),
        ("MAT v5", fixture("classes_v5.mat"), |p| {
            MatFile::read(p).map(content).map_err(err)
        }),
        ("MAT v5 compressed", fixture("classes_v5z.mat"), |p| {
            MatFile::read(p).map(content).map_err(err)
        }),
    ]
}

/// One seeded corruption of `bytes`.
fn mutate(bytes: &[u8], rng: &mut ChaCha8Rng) -> Vec<u8> {
    let mut b = bytes.to_vec();
    let n = b.len().max(1);
    match rng.random_range(0..5) {
        0 => {
            for _ in 0..rng.random_range(1..=8) {
                let i = rng.random_range(0..n).min(b.len().saturating_sub(1));
                if !b.is_empty() {
                    b[i] ^= 1 << rng.random_range(0..8);
                }
            }
        }
        1 => b.truncate(rng.random_range(0..n)),
        2 => {
            let i = rng.random_range(0..n).min(b.len());
            let len = rng.random_range(1..=16).min(b.len() - i);
            for x in &mut b[i..i + len] {
                *x = rng.random();
            }
        }
        3 => {
            let i = rng.random_range(0..=b.len());
            let extra: Vec<u8> = (0..rng.random_range(1..=16))
                .map(|_| rng.random())
                .collect();
            b.splice(i..i, extra);
        }
        _ => {
            let i = rng.random_range(0..n).min(b.len());
            let len = rng.random_range(1..=64).min(b.len() - i);
            b.drain(i..i + len);
        }
    }
    b
}

#[test]
fn corrupted_files_are_errors_never_panics() {
    const CASES_PER_FILE: usize = 400;
    let dir = tempfile::tempdir().unwrap();
    let files = fixtures(dir.path());
    let t0 = Instant::now();
    let (mut cases, mut errors, mut accepted) = (0, 0, 0);
    let mut panics = Vec::new();
    // Per reader: accepted mutations, and those of them that read as other content.
    let mut accepted_by: Vec<(&str, usize, usize)> = Vec::new();
    for (k, (kind, path, read)) in files.iter().enumerate() {
        let original =
            read(path).unwrap_or_else(|e| panic!("{kind}: the valid file is refused: {e}"));
        let bytes = std::fs::read(path).unwrap();
        let ext = path.extension().unwrap().to_str().unwrap();
        let bad = dir.path().join(format!("bad{k}.{ext}"));
        let mut rng = ChaCha8Rng::seed_from_u64(k as u64);
        for case in 0..CASES_PER_FILE {
            let m = mutate(&bytes, &mut rng);
            if m == bytes {
                continue;
            }
            std::fs::write(&bad, &m).unwrap();
            cases += 1;
            match catch_unwind(AssertUnwindSafe(|| read(&bad))) {
                Ok(Ok(read_as)) => {
                    accepted += 1;
                    let changed = usize::from(read_as != original);
                    match accepted_by.last_mut() {
                        Some((k, n, c)) if k == kind => {
                            *n += 1;
                            *c += changed;
                        }
                        _ => accepted_by.push((kind, 1, changed)),
                    }
                }
                Ok(Err(message)) => {
                    errors += 1;
                    assert!(
                        message.contains(bad.file_name().unwrap().to_str().unwrap()),
                        "{kind} case {case}: the error does not name the file: {message}"
                    );
                }
                Err(_) => panics.push(format!("{kind} case {case}")),
            }
        }
    }
    eprintln!(
        "mutation suite: {cases} cases over {} readers, {errors} errors, {accepted} accepted \
         (reader, accepted, of them read as other content) {accepted_by:?}, {} panics, {:.2} s",
        files.len(),
        panics.len(),
        t0.elapsed().as_secs_f64()
    );
    assert!(panics.is_empty(), "panics: {panics:?}");
    // The dataset files are CRC-checked zip members: a corruption they accept must be one that
    // does not change what is read (a byte outside the members' data).
    for (kind, _, changed) in &accepted_by {
        if kind.ends_with("npz") {
            assert_eq!(*changed, 0, "{kind}: corrupted files read as other data");
        }
    }
}
