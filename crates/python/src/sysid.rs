//! The system-identification protocol (`flapssm sysid`) on a recorded input/output file.

use std::path::PathBuf;

use flapssm_data::table::Column;
use flapssm_jobs::sysid::{Combine, IoRecord, SysidSpec, run};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyString;

use crate::errors::read_error;

/// A column given as a name (`str`) or a 0-based index (`int`).
fn column(value: &Bound<'_, PyAny>) -> PyResult<Column> {
    if let Ok(s) = value.cast::<PyString>() {
        return Ok(Column::Name(s.to_str()?.to_string()));
    }
    value
        .extract::<usize>()
        .map(Column::Index)
        .map_err(|_| PyValueError::new_err(format!("column {value}: expected a name or an index")))
}

/// Runs the protocol (Doerr et al.: the first `split` of the samples for training, the rest
/// for the open-loop test, one fit per seed) and returns the report (`sysid --json`) as JSON
/// text. `progress(seed, test_rmse)` is called after each seed.
#[pyfunction]
#[pyo3(signature = (path, inputs, outputs, split=0.5, seeds=3, restarts=2, combine="ensemble",
    iterations=3000, lr=0.1, progress=None))]
#[allow(clippy::too_many_arguments)]
pub fn sysid(
    py: Python<'_>,
    path: PathBuf,
    inputs: Vec<Bound<'_, PyAny>>,
    outputs: Vec<Bound<'_, PyAny>>,
    split: f64,
    seeds: u64,
    restarts: usize,
    combine: &str,
    iterations: u64,
    lr: f64,
    progress: Option<Py<PyAny>>,
) -> PyResult<String> {
    let inputs = inputs.iter().map(column).collect::<PyResult<Vec<_>>>()?;
    let outputs = outputs.iter().map(column).collect::<PyResult<Vec<_>>>()?;
    let combine: Combine = serde_json::from_value(serde_json::Value::String(combine.into()))
        .map_err(|_| {
            PyValueError::new_err(format!(
                "combine '{combine}': expected 'ensemble', 'select' or 'snapshots'"
            ))
        })?;
    let record = py
        .detach(|| IoRecord::read(&path, &inputs, &outputs))
        .map_err(|e| read_error(&path, format!("reading {}: {e}", path.display())))?;
    let mut spec = SysidSpec {
        split,
        seeds,
        restarts,
        combine,
        ..SysidSpec::reference(inputs.len(), outputs.len())
    }
    .with_iterations(iterations);
    spec.fit.train.lr = lr;
    let mut failure = None;
    let result = py.detach(|| {
        run(&record, &spec, false, |r| {
            if let Some(cb) = &progress {
                Python::attach(|py| {
                    if let Err(e) = cb.call1(py, (r.seed, r.test.rmse)) {
                        failure.get_or_insert(e);
                    }
                });
            }
        })
    });
    if let Some(e) = failure {
        return Err(e);
    }
    let (report, _) =
        result.map_err(|e| PyValueError::new_err(format!("{}: {e}", path.display())))?;
    serde_json::to_string(&report).map_err(|e| PyValueError::new_err(e.to_string()))
}
