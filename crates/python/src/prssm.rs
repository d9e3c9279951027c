//! The PR-SSM: training, prediction, streaming, model files.

use std::path::PathBuf;

use flapssm_jobs::JobError;
use flapssm_jobs::stream::{LoadStream, StreamSettings};
use flapssm_jobs::train::{TrainFiles, TrainingOptions, train_dataset, train_in_memory};
use flapssm_prssm::PrssmModel;
use numpy::{
    PyArray1, PyArray2, PyArray3, PyArrayMethods, PyReadonlyArray1, PyReadonlyArray2,
    PyUntypedArrayMethods,
};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;

use crate::dataset::Dataset;
use crate::errors::{job_error, read_error, save_checked};
use crate::progress::PyProgress;

/// Arrays of a prediction: output mean, output variance, latent mean.
type Moments<'py, A> = PyResult<(Bound<'py, A>, Bound<'py, A>, Bound<'py, A>)>;
/// [`Prssm::predict_inputs`]' arrays: output mean and variance, latent mean, particles.
type InputsMoments<'py> = (
    Bound<'py, PyArray2<f64>>,
    Bound<'py, PyArray2<f64>>,
    Bound<'py, PyArray2<f64>>,
    Option<Bound<'py, PyArray3<f64>>>,
);
/// A step's output mean and variance.
type StepMoments<'py> = PyResult<(Bound<'py, PyArray1<f64>>, Bound<'py, PyArray1<f64>>)>;

/// A trained PR-SSM (`x_{t+1} = x_t + f(x_t, u_t) + noise`, `y_t = x_t[:D_y] + noise`, `f`
/// a sparse GP), in the units of its normalization (physical for a wing model).
#[pyclass(module = "flapssm._native", frozen)]
pub struct Prssm {
    pub(crate) model: PrssmModel,
}

#[pymethods]
impl Prssm {
    /// Reads a model file (`flapssm train`'s JSON).
    #[staticmethod]
    fn load(path: PathBuf) -> PyResult<Self> {
        PrssmModel::load(&path)
            .map(|model| Self { model })
            .map_err(|e| read_error(&path, e.to_string()))
    }

    /// Imports the authors' published parameters (`.npz`, `flapssm model import-published`).
    #[staticmethod]
    fn import_published(path: PathBuf) -> PyResult<Self> {
        flapssm_prssm::published::import_published(&path)
            .map(|model| Self { model })
            .map_err(|e| read_error(&path, e.to_string()))
    }

    /// Writes the model file atomically.
    fn save(&self, path: PathBuf) -> PyResult<()> {
        save_checked(&path, |p| self.model.save(p).map_err(|e| e.to_string()))
    }

    #[getter]
    fn n_state(&self) -> usize {
        self.model.config.n_state
    }

    #[getter]
    fn n_input(&self) -> usize {
        self.model.config.n_input
    }

    #[getter]
    fn n_output(&self) -> usize {
        self.model.config.n_output
    }

    #[getter]
    fn n_inducing(&self) -> usize {
        self.model.config.n_inducing
    }

    /// Open-loop prediction from inputs `(T, D_u)` (`flapssm predict --inputs`): from
    /// `x₀ = 0`, draws of `prediction_seed(seed, 0)`. Returns output mean and variance
    /// `(T, D_y)`, latent mean `(T, D_x)` (standardized units) and, with `return_particles`,
    /// every particle `(T, P, D_x)` (standardized units; else `None`).
    #[pyo3(signature = (inputs, particles=30, seed=0, return_particles=false))]
    fn predict_inputs<'py>(
        &self,
        py: Python<'py>,
        inputs: PyReadonlyArray2<'py, f64>,
        particles: usize,
        seed: u64,
        return_particles: bool,
    ) -> PyResult<InputsMoments<'py>> {
        let (t, du) = (inputs.shape()[0], inputs.shape()[1]);
        let u = inputs.as_slice()?.to_vec();
        let out = py
            .detach(|| {
                flapssm_jobs::predict::predict_inputs_kept(
                    &self.model,
                    &u,
                    du,
                    particles,
                    seed,
                    return_particles,
                )
            })
            .map_err(|e| job_error(e, None))?;
        let (p, kept) = (out.prediction, out.particles);
        let (dy, dx) = (self.model.config.n_output, self.model.config.n_state);
        let kept = kept
            .map(|k| PyArray1::from_vec(py, k).reshape([t, particles, dx]))
            .transpose()?;
        Ok((
            PyArray1::from_vec(py, p.output_mean).reshape([t, dy])?,
            PyArray1::from_vec(py, p.output_var).reshape([t, dy])?,
            PyArray1::from_vec(py, p.latent_mean).reshape([t, dx])?,
            kept,
        ))
    }

    /// Prediction of every trajectory of a dataset (`flapssm predict MODEL DATASET`):
    /// trajectory `i` drawn with `prediction_seed(seed, i)`. Returns output mean and variance
    /// `(n, T, 5)` (N, N·mm) and latent mean `(n, T, D_x)`.
    #[pyo3(signature = (dataset, particles=30, seed=0, progress=None))]
    fn predict_dataset<'py>(
        &self,
        py: Python<'py>,
        dataset: &Dataset,
        particles: usize,
        seed: u64,
        progress: Option<Py<PyAny>>,
    ) -> Moments<'py, PyArray3<f64>> {
        let bar = PyProgress::new(progress);
        let ds = &dataset.inner;
        let preds = py
            .detach(|| flapssm_jobs::predict::predict_prssm(&self.model, ds, particles, seed, &bar))
            .map_err(|e| job_error(e, None))?;
        if let Some(e) = bar.take_error() {
            return Err(e);
        }
        let (n, t, dx) = (ds.len(), ds.n_samples(), self.model.config.n_state);
        let cat = |f: fn(&flapssm_prssm::predict::Prediction) -> &Vec<f64>| {
            preds
                .iter()
                .flat_map(|p| f(p).iter().copied())
                .collect::<Vec<_>>()
        };
        Ok((
            PyArray1::from_vec(py, cat(|p| &p.output_mean)).reshape([n, t, 5])?,
            PyArray1::from_vec(py, cat(|p| &p.output_var)).reshape([n, t, 5])?,
            PyArray1::from_vec(py, cat(|p| &p.latent_mean)).reshape([n, t, dx])?,
        ))
    }

    /// A streaming predictor (`flapssm stream`): equal to `predict_inputs` step by step.
    #[pyo3(signature = (particles=30, seed=0))]
    fn stream(&self, particles: usize, seed: u64) -> PyResult<Stream> {
        let stream = LoadStream::new(&self.model, &StreamSettings { particles, seed })
            .map_err(|e| job_error(e, None))?;
        Ok(Stream { stream })
    }

    /// The model file's JSON text.
    fn to_json(&self) -> PyResult<String> {
        self.model
            .to_json()
            .map_err(|e| PyValueError::new_err(format!("model: {e}")))
    }

    /// A model from the model file's JSON text (`to_json`).
    #[staticmethod]
    fn from_json(text: &str) -> PyResult<Self> {
        PrssmModel::from_json(text, std::path::Path::new("(JSON text)"))
            .map(|model| Self { model })
            .map_err(|e| PyValueError::new_err(e.to_string()))
    }

    /// Pickling: the model file's text.
    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<(Bound<'py, PyAny>, (String,))> {
        let from_json = slf.get_type().getattr("from_json")?;
        Ok((from_json, (slf.get().to_json()?,)))
    }

    fn __repr__(&self) -> String {
        let c = &self.model.config;
        format!(
            "Prssm(D_x {}, D_u {}, D_y {}, M {})",
            c.n_state, c.n_input, c.n_output, c.n_inducing
        )
    }
}

/// One input sample in, the loads' mean and variance out (allocation-free per step).
#[pyclass(module = "flapssm._native")]
pub struct Stream {
    stream: LoadStream,
}

#[pymethods]
impl Stream {
    /// The moments of `y_t` (mean, variance; `(D_y,)` each), then the particles advanced by
    /// `u_t` (`(D_u,)`).
    fn step<'py>(&mut self, py: Python<'py>, u: PyReadonlyArray1<'py, f64>) -> StepMoments<'py> {
        let (m, v) = self
            .stream
            .step(u.as_slice()?)
            .map_err(|e| job_error(e, None))?;
        Ok((PyArray1::from_slice(py, m), PyArray1::from_slice(py, v)))
    }

    /// Starts again from `x₀ = 0` with the first draws.
    fn reset(&mut self) {
        self.stream.reset();
    }

    #[getter]
    fn n_input(&self) -> usize {
        self.stream.n_input()
    }

    #[getter]
    fn n_output(&self) -> usize {
        self.stream.n_output()
    }
}

/// Trains a PR-SSM on the training trajectories of `dataset` (`flapssm train`), writing the
/// best model to `out`, the last to `<out>.last.json`, checkpoints to `<out>.ckpt.json` and
/// the learning curve (one row per evaluated epoch, with wall time) to `<out>.curve.csv`.
/// Returns the best model. Ctrl-C (or an exception of `progress`) stops at the next step
/// with a checkpoint; `resume=True` continues from it. With `out=None` nothing is written:
/// the best model is returned from memory (no checkpoint, so no `resume`).
///
/// `options` are `(name, value)` pairs of `TrainingOptions::NAMES` (the one schema of the
/// command line and Python), each value spelled as on the command line; the Python wrapper
/// `flapssm.train` makes them from its keywords.
#[pyfunction]
#[pyo3(signature = (dataset, out, options, resume=false, progress=None))]
pub fn train(
    py: Python<'_>,
    dataset: &Dataset,
    out: Option<PathBuf>,
    options: Vec<(String, String)>,
    resume: bool,
    progress: Option<Py<PyAny>>,
) -> PyResult<Prssm> {
    let mut plan = TrainingOptions::default();
    for (name, value) in &options {
        plan.set(name, value).map_err(|e| job_error(e, None))?;
    }
    let plan = plan.check().map_err(|e| job_error(e, None))?;
    let Some(out) = out else {
        if resume {
            return Err(PyValueError::new_err(
                "resume=True needs the out path of the interrupted run's checkpoint",
            ));
        }
        let bar = PyProgress::new(progress);
        let result = py.detach(|| train_in_memory(&dataset.inner, &plan, &bar, Some(&bar.stop)));
        let model = training_result(py, result, bar.take_error(), "")?;
        return Ok(Prssm { model });
    };
    let files = TrainFiles::beside(&out, None);
    flapssm_jobs::files::check_outputs(
        &[&files.model, &files.last, &files.checkpoint, &files.curve],
        &[],
    )
    .map_err(|e| job_error(e, None))?;
    let bar = PyProgress::new(progress);
    let result =
        py.detach(|| train_dataset(&dataset.inner, &plan, &files, resume, &bar, Some(&bar.stop)));
    training_result(
        py,
        result,
        bar.take_error(),
        "; call train(..., resume=True) to continue",
    )?;
    Prssm::load(files.model)
}

/// A training's outcome as Python sees it: an interruption is `KeyboardInterrupt` (its message
/// followed by `hint`) unless the progress callback raised something else, which is raised
/// instead; so is a callback's error behind any other failure.
fn training_result<T>(
    py: Python<'_>,
    result: Result<T, JobError>,
    pending: Option<PyErr>,
    hint: &str,
) -> PyResult<T> {
    match result {
        Ok(value) => Ok(value),
        Err(e @ JobError::Interrupted { .. }) => match pending {
            Some(err) if !err.is_instance_of::<pyo3::exceptions::PyKeyboardInterrupt>(py) => {
                Err(err)
            }
            _ => Err(pyo3::exceptions::PyKeyboardInterrupt::new_err(format!(
                "{e}{hint}"
            ))),
        },
        Err(e) => Err(pending.unwrap_or_else(|| job_error(e, None))),
    }
}
