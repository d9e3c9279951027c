//! The evaluation and analyses (`flapssm evaluate`): metrics, intervals, cycle averages,
//! control authority, figures and the HTML report, returned as the `metrics.json` dict.

use std::path::PathBuf;

use flapssm_jobs::evaluate::{EVALUATION_FILES, EvalOptions, EvaluationModels, evaluate_models};
use pyo3::prelude::*;

use crate::dataset::Dataset;
use crate::errors::job_error;
use crate::lrqsm::Lrqsm;
use crate::progress::PyProgress;
use crate::prssm::Prssm;

/// Evaluates the models on `dataset`, writes the outputs into `out` and returns the
/// report (`metrics.json`) as JSON text.
#[pyfunction]
#[pyo3(signature = (dataset, out, prssm=None, lrqsm=None, particles=30, seed=0, start_sample=93, progress=None, baselines=Vec::new()))]
#[allow(clippy::too_many_arguments)]
pub fn evaluate(
    py: Python<'_>,
    dataset: &Dataset,
    out: PathBuf,
    prssm: Option<&Prssm>,
    lrqsm: Option<&Lrqsm>,
    particles: usize,
    seed: u64,
    start_sample: usize,
    progress: Option<Py<PyAny>>,
    baselines: Vec<String>,
) -> PyResult<String> {
    flapssm_jobs::files::check_output_dir(&out, &EVALUATION_FILES, &[])
        .map_err(|e| job_error(e, None))?;
    let opts = EvalOptions {
        particles,
        seed,
        start_sample,
        ..EvalOptions::default()
    };
    let ds = &dataset.inner;
    let models = EvaluationModels {
        prssm: prssm.map(|m| &m.model),
        lrqsm: lrqsm.map(|m| &m.model),
        baselines: &baselines,
        ..EvaluationModels::default()
    };
    let bar = PyProgress::new(progress);
    let report = py
        .detach(|| {
            evaluate_models(
                ds,
                "python dataset",
                &models,
                &opts,
                serde_json::Value::Null,
                &out,
                &bar,
            )
        })
        .map_err(|e| job_error(e, None))?;
    if let Some(e) = bar.take_error() {
        return Err(e);
    }
    serde_json::to_string(&report)
        .map_err(|e| pyo3::exceptions::PyValueError::new_err(e.to_string()))
}

/// The history curve (`flapssm history`) of each `(label, dataset)` into `out`; returns
/// `history_curve.json` as JSON text.
#[pyfunction]
#[pyo3(signature = (datasets, out, cycles=None, start_sample=93, seed=0, progress=None))]
pub fn history_curve(
    py: Python<'_>,
    datasets: Vec<(String, PyRef<'_, Dataset>)>,
    out: PathBuf,
    cycles: Option<Vec<f64>>,
    start_sample: usize,
    seed: u64,
    progress: Option<Py<PyAny>>,
) -> PyResult<String> {
    use flapssm_jobs::history::{HISTORY_FILES, HistoryOptions, run_history_curves};
    flapssm_jobs::files::check_output_dir(&out, &HISTORY_FILES, &[])
        .map_err(|e| job_error(e, None))?;
    let defaults = HistoryOptions::default();
    let opts = HistoryOptions {
        history_cycles: cycles.unwrap_or(defaults.history_cycles.clone()),
        start_sample,
        seed,
        ..defaults
    };
    let owned: Vec<_> = datasets
        .iter()
        .map(|(label, d)| (label.clone(), d.inner.clone()))
        .collect();
    let bar = PyProgress::new(progress);
    let curves = py
        .detach(|| run_history_curves(&owned, &opts, &out, &bar))
        .map_err(|e| job_error(e, None))?;
    if let Some(e) = bar.take_error() {
        return Err(e);
    }
    serde_json::to_string(&curves)
        .map_err(|e| pyo3::exceptions::PyValueError::new_err(e.to_string()))
}
