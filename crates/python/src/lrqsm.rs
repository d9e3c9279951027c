//! The LRQSM (quasi-steady elastic net with cross-validation).

use std::path::PathBuf;

use flapssm_jobs::NoProgress;
use flapssm_jobs::models::lrqsm::{LrqsmFit, LrqsmLoadModel};
use flapssm_jobs::models::{Fit, LoadModel, LoadPrediction};
use flapssm_qs::{EnetOptions, LrqsmModel};
use flapssm_wing::features::FeatureSet;
use numpy::{PyArray1, PyArray2, PyArray3, PyArrayMethods};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::dataset::Dataset;
use crate::errors::{job_error, read_error, save_checked};

/// A fitted LRQSM: one elastic net per output on the quasi-steady features, λ chosen by
/// K-fold cross-validation (1-SE rule by default).
#[pyclass(module = "flapssm._native", frozen)]
pub struct Lrqsm {
    pub(crate) model: LrqsmModel,
}

#[pymethods]
impl Lrqsm {
    /// Fits on the training trajectories of `dataset` (`flapssm qs fit`).
    #[staticmethod]
    #[pyo3(signature = (dataset, features="published", l1_ratio=None, n_folds=None))]
    fn fit(
        py: Python<'_>,
        dataset: &Dataset,
        features: &str,
        l1_ratio: Option<f64>,
        n_folds: Option<usize>,
    ) -> PyResult<Self> {
        let features = match features {
            "published" => FeatureSet::Published,
            "paper-text" => FeatureSet::PaperText,
            other => {
                return Err(PyValueError::new_err(format!(
                    "features '{other}': expected 'published' or 'paper-text'"
                )));
            }
        };
        let mut options = EnetOptions::default();
        if let Some(a) = l1_ratio {
            options.l1_ratio = a;
        }
        if let Some(k) = n_folds {
            options.n_folds = k;
        }
        let fit = LrqsmFit {
            features,
            options,
            prediction_intercept: Default::default(),
            source: "python".into(),
        };
        let model = py
            .detach(|| fit.fit(&dataset.inner, &NoProgress))
            .map_err(|e| job_error(e, None))?;
        Ok(Self {
            model: model.model().clone(),
        })
    }

    /// Reads an LRQSM model file.
    #[staticmethod]
    fn load(path: PathBuf) -> PyResult<Self> {
        LrqsmModel::load(&path)
            .map(|model| Self { model })
            .map_err(|e| read_error(&path, e.to_string()))
    }

    /// Writes the model file atomically.
    fn save(&self, path: PathBuf) -> PyResult<()> {
        save_checked(&path, |p| self.model.save(p).map_err(|e| e.to_string()))
    }

    /// Predicted loads of every trajectory of `dataset`, `(n, T, 5)` (N, N·mm).
    fn predict<'py>(
        &self,
        py: Python<'py>,
        dataset: &Dataset,
    ) -> PyResult<Bound<'py, PyArray3<f64>>> {
        let load = LrqsmLoadModel::new(&self.model).map_err(|e| job_error(e, None))?;
        let ds = &dataset.inner;
        let (n, t) = (ds.len(), ds.n_samples());
        let mut mean = vec![0.0; n * t * 5];
        py.detach(|| {
            for (i, (tr, m)) in ds
                .trajectories
                .iter()
                .zip(mean.chunks_exact_mut(t * 5))
                .enumerate()
            {
                load.predict_into(
                    i,
                    tr,
                    LoadPrediction {
                        mean: m,
                        var: None,
                        latent_mean: None,
                    },
                )?;
            }
            Ok(())
        })
        .map_err(|e| job_error(e, None))?;
        PyArray1::from_vec(py, mean).reshape([n, t, 5])
    }

    /// Coefficients on the original features, `(5, n_features)` (rows: outputs; targets
    /// standardized with the training statistics: the published `LRmodel` columns).
    #[getter]
    fn coef_<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let k = self.model.n_features();
        let flat: Vec<f64> = self
            .model
            .chosen
            .iter()
            .flat_map(|c| c.coef.iter().copied())
            .collect();
        PyArray1::from_vec(py, flat).reshape([self.model.chosen.len(), k])
    }

    /// Intercepts on the standardized-target scale `(5,)`.
    #[getter]
    fn intercept_<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_vec(py, self.model.chosen.iter().map(|c| c.intercept).collect())
    }

    /// The chosen λ of each output `(5,)`.
    #[getter]
    fn lambda_<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_vec(py, self.model.chosen.iter().map(|c| c.lambda).collect())
    }

    /// The elastic-net path of output `k` (0..5) as arrays: `lambdas` `(L,)`, `coef_path`
    /// `(L, n_features)` (original features), `intercept_path` `(L,)`, `cv_mse_mean` and
    /// `cv_mse_se` `(L,)` (standardized targets), and the indices `index_min`, `index_1se`,
    /// `index_chosen`.
    fn cv_path<'py>(&self, py: Python<'py>, k: usize) -> PyResult<Bound<'py, PyDict>> {
        let Some(t) = self.model.fit.targets.get(k) else {
            return Err(PyValueError::new_err(format!(
                "output {k}: the model has {} outputs",
                self.model.fit.targets.len()
            )));
        };
        let d = PyDict::new(py);
        let n = t.lambdas.len();
        let p = self.model.n_features();
        let flat: Vec<f64> = t.coef_path.iter().flatten().copied().collect();
        d.set_item("name", &t.name)?;
        d.set_item("lambdas", PyArray1::from_slice(py, &t.lambdas))?;
        d.set_item("coef_path", PyArray1::from_vec(py, flat).reshape([n, p])?)?;
        d.set_item(
            "intercept_path",
            PyArray1::from_slice(py, &t.intercept_path),
        )?;
        d.set_item("cv_mse_mean", PyArray1::from_slice(py, &t.cv_mse_mean))?;
        d.set_item("cv_mse_se", PyArray1::from_slice(py, &t.cv_mse_se))?;
        d.set_item("index_min", t.index_min)?;
        d.set_item("index_1se", t.index_1se)?;
        d.set_item("index_chosen", t.index_chosen)?;
        Ok(d)
    }

    /// The model file's JSON text (options, the cross-validation path of every output).
    fn to_json(&self) -> PyResult<String> {
        serde_json::to_string(&self.model).map_err(|e| PyValueError::new_err(e.to_string()))
    }

    /// A model from the model file's JSON text (`to_json`).
    #[staticmethod]
    fn from_json(text: &str) -> PyResult<Self> {
        LrqsmModel::from_json(text, std::path::Path::new("(JSON text)"))
            .map(|model| Self { model })
            .map_err(|e| PyValueError::new_err(e.to_string()))
    }

    /// Pickling: the model file's text.
    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<(Bound<'py, PyAny>, (String,))> {
        let from_json = slf.get_type().getattr("from_json")?;
        Ok((from_json, (slf.get().to_json()?,)))
    }
}
