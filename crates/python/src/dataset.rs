//! Datasets as numpy arrays, and the virtual wing.

use std::path::PathBuf;

use flapssm_jobs::simulate::SimulateSettings;
use flapssm_wing::cycles::published_u_ref;
use flapssm_wing::dataset::{Dataset as WingDataset, DatasetMeta, Trajectory, ValidDataset};
use flapssm_wing::virtual_wing::{Fidelity, VirtualWingConfig};
use numpy::{
    PyArray1, PyArray3, PyArrayMethods, PyReadonlyArray1, PyReadonlyArray3, PyUntypedArrayMethods,
};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;

use crate::errors::{job_error, read_error, save_checked};
use crate::progress::PyProgress;

/// A validated wing dataset: `n` trajectories of `T` samples, the first `n_train` for
/// training. Arrays are copies (float64): `euler_rad` `(n, T, 3)` [stroke φ, deviation ψ,
/// pitch α] (rad); `inputs` `(n, T, 7)` [AoA rad, |v| m/s, a_x a_y a_z m/s², α̇ rad/s,
/// α̈ rad/s²] in the wing frame at unit span distance; `outputs` `(n, T, 5)` [F_x N, F_y N,
/// M_x M_y M_z N·mm] in the wing frame, or `None`; `u_ref_m_s` `(n,)`.
#[pyclass(module = "flapssm._native", frozen)]
pub struct Dataset {
    pub(crate) inner: ValidDataset,
}

fn array3<'py, const K: usize>(
    py: Python<'py>,
    ds: &ValidDataset,
    rows: impl Fn(&Trajectory) -> &[[f64; K]],
) -> PyResult<Bound<'py, PyArray3<f64>>> {
    let (n, t) = (ds.len(), ds.n_samples());
    let flat: Vec<f64> = ds
        .trajectories
        .iter()
        .flat_map(|tr| rows(tr).iter().flatten().copied())
        .collect();
    PyArray1::from_vec(py, flat).reshape([n, t, K])
}

#[pymethods]
impl Dataset {
    /// Reads a dataset `.npz` file (`flapssm simulate`'s format).
    #[staticmethod]
    fn load(py: Python<'_>, path: PathBuf) -> PyResult<Self> {
        py.detach(|| WingDataset::load(&path))
            .map(|inner| Self { inner })
            .map_err(|e| read_error(&path, format!("dataset {}: {e}", path.display())))
    }

    /// Writes the dataset `.npz` file atomically.
    fn save(&self, py: Python<'_>, path: PathBuf) -> PyResult<()> {
        save_checked(&path, |p| {
            py.detach(|| self.inner.save(p))
                .map_err(|e| format!("{}: {e}", p.display()))
        })
    }

    /// A dataset from arrays (checked by the Python layer for dtype and shape; validated
    /// here: finite values, equal lengths), of the rig of the description `rig` (a file) or
    /// `rig_json` (a dict), or else the paper's wing. `u_ref_m_s` defaults to the published
    /// rule (mean speed at the rig's `u_ref_radius_m` over the last full cycle).
    #[staticmethod]
    #[pyo3(signature = (euler_rad, inputs, outputs, n_train, dt_s, u_ref_m_s=None, rig=None, rig_json=None))]
    #[allow(clippy::too_many_arguments)]
    fn from_arrays(
        euler_rad: PyReadonlyArray3<'_, f64>,
        inputs: PyReadonlyArray3<'_, f64>,
        outputs: Option<PyReadonlyArray3<'_, f64>>,
        n_train: usize,
        dt_s: f64,
        u_ref_m_s: Option<PyReadonlyArray1<'_, f64>>,
        rig: Option<PathBuf>,
        rig_json: Option<&str>,
    ) -> PyResult<Self> {
        let desc = if rig.is_some() || rig_json.is_some() {
            Some(crate::own_rig::rig_of(rig.as_deref(), rig_json)?.0)
        } else {
            None
        };
        let mut meta = DatasetMeta::new("python arrays", None, serde_json::Value::Null);
        if let Some(d) = &desc {
            meta.wing = d.geometry();
            meta.fluid = d.fluid();
            meta.settings = serde_json::json!({ "rig": d });
        }
        let radius = meta.wing.u_ref_radius_m;
        let e = euler_rad.as_slice()?;
        let u = inputs.as_slice()?;
        let y = outputs.as_ref().map(|o| o.as_slice()).transpose()?;
        let u_ref = u_ref_m_s.as_ref().map(|r| r.as_slice()).transpose()?;
        let (n, t) = (euler_rad.shape()[0], euler_rad.shape()[1]);
        let expect = |name: &str, shape: &[usize], k: usize| {
            if shape == [n, t, k] {
                Ok(())
            } else {
                Err(PyValueError::new_err(format!(
                    "{name}: shape {shape:?}, expected ({n}, {t}, {k})"
                )))
            }
        };
        expect("euler_rad", euler_rad.shape(), 3)?;
        expect("inputs", inputs.shape(), 7)?;
        if let Some(o) = &outputs {
            expect("outputs", o.shape(), 5)?;
        }
        if let Some(r) = u_ref.filter(|r| r.len() != n) {
            return Err(PyValueError::new_err(format!(
                "u_ref_m_s: {} values, expected {n}",
                r.len()
            )));
        }
        let mut trajectories = Vec::with_capacity(n);
        for i in 0..n {
            let rows = |a: &[f64], k: usize| a[i * t * k..(i + 1) * t * k].to_vec();
            let euler: Vec<[f64; 3]> = as_rows(&rows(e, 3));
            let u_ref = match u_ref {
                Some(r) => r[i],
                None => {
                    published_u_ref(&euler, dt_s, radius)
                        .map_err(|err| {
                            PyValueError::new_err(format!("trajectory {i}: U_ref: {err}"))
                        })?
                        .0
                }
            };
            trajectories.push(Trajectory {
                euler_rad: euler,
                inputs: as_rows(&rows(u, 7)),
                outputs: y.map(|y| as_rows(&rows(y, 5))),
                u_ref_m_s: u_ref,
                family: "arrays".into(),
            });
        }
        let ds = WingDataset {
            meta,
            dt_s,
            trajectories,
            n_train,
        };
        ValidDataset::new(ds)
            .map(|inner| Self { inner })
            .map_err(|e| PyValueError::new_err(format!("dataset: {e}")))
    }

    /// Trajectories.
    fn __len__(&self) -> usize {
        self.inner.len()
    }

    /// Samples per trajectory.
    #[getter]
    fn n_samples(&self) -> usize {
        self.inner.n_samples()
    }

    /// Training trajectories (the first ones).
    #[getter]
    fn n_train(&self) -> usize {
        self.inner.n_train
    }

    /// Sampling period (s).
    #[getter]
    fn dt_s(&self) -> f64 {
        self.inner.dt_s
    }

    #[getter]
    fn euler_rad<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray3<f64>>> {
        array3(py, &self.inner, |t| &t.euler_rad)
    }

    #[getter]
    fn inputs<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray3<f64>>> {
        array3(py, &self.inner, |t| &t.inputs)
    }

    #[getter]
    fn outputs<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyArray3<f64>>>> {
        if !self.inner.has_outputs() {
            return Ok(None);
        }
        array3(py, &self.inner, |t| t.outputs.as_deref().unwrap_or(&[])).map(Some)
    }

    #[getter]
    fn u_ref_m_s<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        let v: Vec<f64> = self
            .inner
            .trajectories
            .iter()
            .map(|t| t.u_ref_m_s)
            .collect();
        PyArray1::from_vec(py, v)
    }

    /// Family label of each trajectory.
    #[getter]
    fn families(&self) -> Vec<String> {
        self.inner
            .trajectories
            .iter()
            .map(|t| t.family.clone())
            .collect()
    }

    /// The metadata (wing geometry, fluid, generator, seed, units) as JSON text.
    #[getter]
    fn metadata_json(&self) -> String {
        serde_json::to_string(&self.inner.meta).unwrap_or_default()
    }

    fn __repr__(&self) -> String {
        format!(
            "Dataset({} trajectories × {} samples, {} training, dt {} s)",
            self.inner.len(),
            self.inner.n_samples(),
            self.inner.n_train,
            self.inner.dt_s
        )
    }
}

fn as_rows<const K: usize>(flat: &[f64]) -> Vec<[f64; K]> {
    flat.chunks_exact(K)
        .map(|c| std::array::from_fn(|j| c[j]))
        .collect()
}

/// The fidelity named (`None`: the wing's) and the wing given as JSON text (`None`: the
/// default wing), checked as `flapssm simulate --wing-config` checks its file.
fn wing_choices(
    fidelity: Option<&str>,
    wing_json: Option<&str>,
) -> PyResult<(Option<Fidelity>, Option<VirtualWingConfig>)> {
    let fidelity = fidelity
        .map(|f| f.parse::<Fidelity>())
        .transpose()
        .map_err(|e| PyValueError::new_err(format!("fidelity: {e}")))?;
    let wing = wing_json
        .map(|text| {
            let value: serde_json::Value = serde_json::from_str(text)
                .map_err(|e| PyValueError::new_err(format!("wing: {e}")))?;
            flapssm_jobs::files::config_from_value(value, std::path::Path::new("wing"))
                .map_err(|e| job_error(e, None))
        })
        .transpose()?;
    Ok((fidelity, wing))
}

/// Simulates the virtual wing on `n` generated trajectories (`flapssm simulate`).
#[pyfunction]
#[pyo3(signature = (n, seed, fidelity=None, wing=None, n_train=None, noise_free=false, flat=false, progress=None))]
#[allow(clippy::too_many_arguments)]
pub fn simulate(
    py: Python<'_>,
    n: usize,
    seed: u64,
    fidelity: Option<&str>,
    wing: Option<&str>,
    n_train: Option<usize>,
    noise_free: bool,
    flat: bool,
    progress: Option<Py<PyAny>>,
) -> PyResult<Dataset> {
    let (fidelity, wing) = wing_choices(fidelity, wing)?;
    let cfg = SimulateSettings {
        n_trajectories: n,
        n_train,
        seed,
        wing,
        fidelity,
        noise_free,
        flat,
        ..SimulateSettings::default()
    }
    .check()
    .map_err(|e| job_error(e, None))?;
    let bar = PyProgress::new(progress);
    let ds = py.detach(|| flapssm_jobs::simulate::simulate(&cfg, None, &bar));
    if let Some(e) = bar.take_error() {
        return Err(e);
    }
    ds.map(|inner| Dataset { inner })
        .map_err(|e| job_error(e, None))
}

/// Generates `n` random wing trajectories (`flapssm trajectories`): a kinematics-only
/// dataset (no outputs), the same for the same seed as the CLI.
#[pyfunction]
#[pyo3(signature = (n, seed, n_train=None))]
pub fn trajectories(
    py: Python<'_>,
    n: usize,
    seed: u64,
    n_train: Option<usize>,
) -> PyResult<Dataset> {
    use flapssm_wing::trajectories::{GeneratorConfig, default_n_train, kinematics_dataset};
    let cfg = GeneratorConfig {
        n_trajectories: n,
        n_train: n_train.unwrap_or_else(|| default_n_train(n)),
        seed,
        ..GeneratorConfig::default()
    };
    flapssm_jobs::resources::check_dataset("n", n, cfg.sampling.n_samples)
        .map_err(|e| job_error(e, None))?;
    py.detach(|| kinematics_dataset(&cfg))
        .map(|inner| Dataset { inner })
        .map_err(|e| PyValueError::new_err(format!("trajectories: {e}")))
}

/// The wing-frame inputs `(T, 7)` of measured Euler angles `(T, 3)` (rad) sampled every
/// `dt_s`: Savitzky–Golay angles, rates and accelerations (window `2·half_window + 1`,
/// default the 0.48 s span of the virtual sensor chain's differentiator; degree `order`,
/// default 6), then the wing kinematics at unit span distance.
#[pyfunction]
#[pyo3(signature = (euler_rad, dt_s, half_window=None, order=None))]
pub fn kinematics<'py>(
    py: Python<'py>,
    euler_rad: numpy::PyReadonlyArray2<'py, f64>,
    dt_s: f64,
    half_window: Option<usize>,
    order: Option<usize>,
) -> PyResult<Bound<'py, numpy::PyArray2<f64>>> {
    use flapssm_wing::differentiate::{SavitzkyGolayConfig, measured_inputs};
    let mut cfg = SavitzkyGolayConfig::spanning_default(dt_s);
    if let Some(m) = half_window {
        cfg.half_window = m;
    }
    if let Some(p) = order {
        cfg.order = p;
    }
    let angles: Vec<[f64; 3]> = as_rows(euler_rad.as_slice()?);
    let t = angles.len();
    let inputs = py
        .detach(|| measured_inputs(&angles, dt_s, cfg))
        .map_err(|e| PyValueError::new_err(format!("kinematics: {e}")))?;
    let flat: Vec<f64> = inputs.iter().flatten().copied().collect();
    PyArray1::from_vec(py, flat).reshape([t, 7])
}

/// The paper's measured trajectories `0..n` (default all 548; Bayiz & Cheng 2021, vendored) as
/// Euler angles `(n, 470, 3)` [φ, ψ, α] (rad, 25 Hz) in flapssm's convention (the file's
/// deviation and pitch negated; docs/kinematics.md).
#[pyfunction]
#[pyo3(signature = (n=None))]
pub fn paper_angles<'py>(
    py: Python<'py>,
    n: Option<usize>,
) -> PyResult<Bound<'py, numpy::PyArray3<f64>>> {
    use flapssm_wing::trajectories::paper::{PAPER_N_SAMPLES, PAPER_N_TRAJECTORIES};
    let n = n.unwrap_or(PAPER_N_TRAJECTORIES);
    if n > PAPER_N_TRAJECTORIES {
        return Err(PyValueError::new_err(format!(
            "n = {n}: at most the paper's {PAPER_N_TRAJECTORIES} measured trajectories"
        )));
    }
    let flat: Vec<f64> = flapssm_wing::trajectories::paper::paper_angles(n)
        .iter()
        .flatten()
        .flatten()
        .copied()
        .collect();
    PyArray1::from_vec(py, flat).reshape([n, PAPER_N_SAMPLES, 3])
}

/// Simulates the virtual wing on given Euler angles `(n, 470, 3)` (rad, 25 Hz; the paper's
/// measured trajectories): the same wing, sensor and split settings as [`simulate`].
#[pyfunction]
#[pyo3(signature = (euler_rad, seed, fidelity=None, wing=None, n_train=None, noise_free=false, progress=None))]
#[allow(clippy::too_many_arguments)]
pub fn simulate_angles(
    py: Python<'_>,
    euler_rad: PyReadonlyArray3<'_, f64>,
    seed: u64,
    fidelity: Option<&str>,
    wing: Option<&str>,
    n_train: Option<usize>,
    noise_free: bool,
    progress: Option<Py<PyAny>>,
) -> PyResult<Dataset> {
    let (fidelity, wing) = wing_choices(fidelity, wing)?;
    let (n, t) = (euler_rad.shape()[0], euler_rad.shape()[1]);
    let flat = euler_rad.as_slice()?;
    let angles: Vec<Vec<[f64; 3]>> = (0..n)
        .map(|i| as_rows(&flat[i * t * 3..(i + 1) * t * 3]))
        .collect();
    let settings = SimulateSettings {
        n_trajectories: n,
        n_train,
        seed,
        wing,
        fidelity,
        noise_free,
        flat: false,
        ..SimulateSettings::default()
    };
    let bar = PyProgress::new(progress);
    let ds = py.detach(|| {
        flapssm_jobs::simulate::simulate_angles(&settings, &angles, "Python arrays", &bar)
    });
    if let Some(e) = bar.take_error() {
        return Err(e);
    }
    ds.map(|inner| Dataset { inner })
        .map_err(|e| job_error(e, None))
}
