//! Model file: exact round trip, atomic write, clear errors for malformed, truncated,
//! foreign and future-version files; published import.

use std::path::{Path, PathBuf};

use flapssm_prssm::published::import_published;
use flapssm_prssm::{ModelFileError, Normalization, PrssmModel};

fn reference() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../../shared/reference/bayiz2021-prssm/reference.npz")
}

fn model() -> PrssmModel {
    let mut m = import_published(&reference()).unwrap();
    m.normalization = Some(Normalization {
        input_mean: (0..7).map(|i| 0.1 * i as f64 + 1.0 / 3.0).collect(),
        input_std: vec![std::f64::consts::PI; 7],
        output_mean: vec![1e-300, -2.5e17, 0.1, 0.2, 0.3],
        output_std: vec![1.0 / 7.0; 5],
    });
    m
}

#[test]
fn save_load_round_trips_exactly() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("m.json");
    let m = model();
    m.save(&path).unwrap();
    let back = PrssmModel::load(&path).unwrap();
    // Bitwise equality of every f64 (PartialEq on Vec<f64>).
    assert_eq!(back, m);
    assert_eq!(back.params.inducing_inputs.len(), 100 * 19);
    // No temporary files left behind.
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
}

#[test]
fn published_import_reads_the_arrays() {
    let m = import_published(&reference()).unwrap();
    assert_eq!(
        (
            m.config.n_state,
            m.config.n_output,
            m.config.n_input,
            m.config.n_inducing
        ),
        (12, 5, 7, 100)
    );
    assert!(m.config.shared_draws);
    // prssm-notes §1: kernel variance 0.025; the most relevant input has lengthscale 3.5,
    // the first input lengthscale (GP input 12, after the 12 states).
    assert!(
        (m.params.kernel_variance - 0.025).abs() < 0.001,
        "{}",
        m.params.kernel_variance
    );
    assert!(
        (m.params.lengthscales[12] - 3.5).abs() < 0.05,
        "{}",
        m.params.lengthscales[12]
    );
    let min_input = m.params.lengthscales[12..]
        .iter()
        .cloned()
        .fold(f64::INFINITY, f64::min);
    assert_eq!(min_input, m.params.lengthscales[12]);
}

fn load_text(text: &str) -> ModelFileError {
    PrssmModel::from_json(text, Path::new("x.json")).unwrap_err()
}

#[test]
fn bad_files_give_clear_errors() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("m.json");
    model().save(&path).unwrap();
    let text = std::fs::read_to_string(&path).unwrap();

    let e = load_text(&text[..text.len() / 2]);
    assert!(matches!(e, ModelFileError::Parse { .. }), "{e}");
    assert!(
        e.to_string().contains("x.json") && e.to_string().contains("line"),
        "{e}"
    );

    let e = load_text(&text.replacen("\"version\": 1", "\"version\": 2", 1));
    assert!(matches!(e, ModelFileError::Version { found: 2, .. }), "{e}");

    let e = load_text(&text.replacen("flapssm-prssm-model", "something-else", 1));
    assert!(matches!(e, ModelFileError::Format { .. }), "{e}");

    let e = load_text("{\"format\": \"flapssm-prssm-model\", \"version\": 1, \"model\": {}}");
    assert!(e.to_string().contains("missing field"), "{e}");

    let mut m = model();
    m.params.lengthscales.pop();
    let bad =
        serde_json::json!({"format": "flapssm-prssm-model", "version": 1, "model": m}).to_string();
    let e = load_text(&bad);
    assert!(
        matches!(e, ModelFileError::Invalid { .. }) && e.to_string().contains("lengthscales"),
        "{e}"
    );

    let e = PrssmModel::load(&dir.path().join("missing.json")).unwrap_err();
    assert!(
        matches!(e, ModelFileError::Io { .. }) && e.to_string().contains("missing.json"),
        "{e}"
    );

    // Binary files: an .npz (zip) archive gets a pointer to the importer, other bytes the
    // offset of the first byte that is not UTF-8.
    let npz = dir.path().join("published.npz");
    std::fs::write(&npz, b"PK\x03\x04\x14\x00rest of a zip").unwrap();
    let e = PrssmModel::load(&npz).unwrap_err();
    assert!(
        e.to_string().contains("published.npz") && e.to_string().contains("import-published"),
        "{e}"
    );
    let bin = dir.path().join("model.bin");
    std::fs::write(&bin, b"{\"a\xff").unwrap();
    let e = PrssmModel::load(&bin).unwrap_err();
    assert!(e.to_string().contains("not UTF-8 text (byte 3)"), "{e}");
}
