//! The rig as the judge (`flapssm rig check`): a dataset of the paper's trajectories against
//! the published model's prediction of the rig's loads, returned as the `rig-check.json` dict.

use std::path::PathBuf;

use flapssm_jobs::rig::{
    RIG_FILES, RigSettings, load_reference_model, rig_check as check, rig_reference,
    write_rig_check,
};
use pyo3::prelude::*;

use crate::dataset::Dataset;
use crate::errors::job_error;
use crate::progress::PyProgress;

/// Scores `dataset` against the reference model `reference` (the published `.npz` or an
/// imported model file); with `out`, writes `rig-check.json`, `rig-check.md` and the figure.
/// Returns the check as JSON text.
#[pyfunction]
#[pyo3(signature = (dataset, reference, out=None, particles=30, seed=1, lags=true, progress=None))]
#[allow(clippy::too_many_arguments)]
pub fn rig_check(
    py: Python<'_>,
    dataset: &Dataset,
    reference: PathBuf,
    out: Option<PathBuf>,
    particles: usize,
    seed: u64,
    lags: bool,
    progress: Option<Py<PyAny>>,
) -> PyResult<String> {
    if let Some(dir) = &out {
        flapssm_jobs::files::check_output_dir(dir, &RIG_FILES, &[&reference])
            .map_err(|e| job_error(e, None))?;
    }
    let model = load_reference_model(&reference).map_err(|e| job_error(e, Some(&reference)))?;
    let settings = RigSettings {
        particles,
        seed,
        ..RigSettings::default()
    };
    let ds = &dataset.inner;
    let bar = PyProgress::new(progress);
    let result = py.detach(|| {
        let reference = rig_reference(&model, ds.len(), &settings, &bar)?;
        let result = check(ds, &reference, lags)?;
        if let Some(dir) = &out {
            write_rig_check(dir, &result, ds, &reference, "python dataset")?;
        }
        Ok::<_, flapssm_jobs::JobError>(result)
    });
    if let Some(e) = bar.take_error() {
        return Err(e);
    }
    let result = result.map_err(|e| job_error(e, None))?;
    serde_json::to_string(&result)
        .map_err(|e| pyo3::exceptions::PyValueError::new_err(e.to_string()))
}
