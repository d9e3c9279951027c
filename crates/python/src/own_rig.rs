//! A user's own rig (docs/own-rig.md): raw recordings built into a dataset with the rig's
//! geometry, and the virtual wing rehearsing the rig.

use std::path::{Path, PathBuf};

use flapssm_jobs::own_rig::{
    RIG_TEMPLATE, RehearsalSettings, build_dataset as build, load_rig, rehearse_rig as rehearse,
    rig_from_json, write_steps,
};
use flapssm_wing::rig::RigDescription;
use flapssm_wing::virtual_wing::Fidelity;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;

use crate::dataset::Dataset;
use crate::errors::job_error;
use crate::progress::PyProgress;

/// The rig of a path (TOML) or of JSON text (a dict from Python), checked; and its name in
/// messages.
pub(crate) fn rig_of(
    path: Option<&Path>,
    json: Option<&str>,
) -> PyResult<(RigDescription, PathBuf)> {
    match (path, json) {
        (Some(p), None) => Ok((
            load_rig(p).map_err(|e| job_error(e, Some(p)))?,
            p.to_path_buf(),
        )),
        (None, Some(text)) => {
            let source = PathBuf::from("<rig dict>");
            Ok((
                rig_from_json(text, &source).map_err(|e| job_error(e, None))?,
                source,
            ))
        }
        _ => Err(PyValueError::new_err(
            "rig: give a rig description file or a dict",
        )),
    }
}

/// A documented rig description (TOML) to start from.
#[pyfunction]
pub fn rig_template() -> &'static str {
    RIG_TEMPLATE
}

/// The checked rig description (TOML file `rig` or JSON text `rig_json`) as JSON text.
#[pyfunction]
#[pyo3(signature = (rig=None, rig_json=None))]
pub fn load_rig_description(rig: Option<PathBuf>, rig_json: Option<&str>) -> PyResult<String> {
    let (desc, _) = rig_of(rig.as_deref(), rig_json)?;
    serde_json::to_string(&desc).map_err(|e| PyValueError::new_err(e.to_string()))
}

/// Builds a dataset from raw recordings (`flapssm dataset build`); with `steps`, writes each
/// recording's processing steps (CSV and figure) there. Returns the dataset and the reports
/// (JSON text).
#[pyfunction]
#[pyo3(signature = (recordings, rig=None, rig_json=None, n_train=None, steps=None, progress=None))]
pub fn build_dataset(
    py: Python<'_>,
    recordings: Vec<PathBuf>,
    rig: Option<PathBuf>,
    rig_json: Option<&str>,
    n_train: Option<usize>,
    steps: Option<PathBuf>,
    progress: Option<Py<PyAny>>,
) -> PyResult<(Dataset, String)> {
    let (desc, source) = rig_of(rig.as_deref(), rig_json)?;
    let bar = PyProgress::new(progress);
    let built = py.detach(|| {
        let built = build(&desc, &source, &recordings, n_train, &bar)?;
        if let Some(dir) = &steps {
            write_steps(dir, &desc, &recordings, &built.processed)?;
        }
        Ok::<_, flapssm_jobs::JobError>(built)
    });
    if let Some(e) = bar.take_error() {
        return Err(e);
    }
    let built = built.map_err(|e| job_error(e, None))?;
    let reports =
        serde_json::to_string(&built.reports).map_err(|e| PyValueError::new_err(e.to_string()))?;
    Ok((
        Dataset {
            inner: built.dataset,
        },
        reports,
    ))
}

/// Writes the raw recordings the rig would make of `n` generated motions into `directory`
/// (`flapssm simulate --rig`) and returns the virtual wing's own loads on them.
#[pyfunction]
#[pyo3(signature = (directory, rig=None, rig_json=None, n=10, seed=0, fidelity=None, motion_s=16.0, n_train=None, progress=None))]
#[allow(clippy::too_many_arguments)]
pub fn rehearse_rig(
    py: Python<'_>,
    directory: PathBuf,
    rig: Option<PathBuf>,
    rig_json: Option<&str>,
    n: usize,
    seed: u64,
    fidelity: Option<&str>,
    motion_s: f64,
    n_train: Option<usize>,
    progress: Option<Py<PyAny>>,
) -> PyResult<Dataset> {
    let (desc, source) = rig_of(rig.as_deref(), rig_json)?;
    let fidelity: Fidelity = fidelity
        .map(str::parse)
        .transpose()
        .map_err(|e| PyValueError::new_err(format!("fidelity: {e}")))?
        .unwrap_or(Fidelity::L0);
    let settings = RehearsalSettings {
        n_recordings: n,
        seed,
        fidelity,
        motion_s,
        n_train,
    };
    let bar = PyProgress::new(progress);
    let truth = py.detach(|| rehearse(&desc, &source, &settings, &directory, &bar));
    if let Some(e) = bar.take_error() {
        return Err(e);
    }
    truth
        .map(|inner| Dataset { inner })
        .map_err(|e| job_error(e, None))
}
