//! The authors' published model and its 470 input samples (shared/reference/bayiz2021-prssm).

use std::path::{Path, PathBuf};

use flapssm_data::npz::NpzReader;
use flapssm_prssm::PrssmModel;

/// Samples of the reference trajectory.
pub const T: usize = 470;
/// Inputs per sample.
pub const DU: usize = 7;

fn reference() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../../shared/reference/bayiz2021-prssm/reference.npz")
}

/// The published model, imported and saved as a flapssm model file in `dir`.
pub fn published_model(dir: &Path) -> (PrssmModel, PathBuf) {
    let model = flapssm_prssm::published::import_published(&reference()).unwrap();
    let path = dir.join("published.json");
    model.save(&path).unwrap();
    (model, path)
}

/// The reference inputs `u_in` (`T × D_u`, row-major).
pub fn inputs() -> Vec<f64> {
    NpzReader::open(reference())
        .unwrap()
        .f64_shaped("u_in", &[T, DU])
        .unwrap()
}
