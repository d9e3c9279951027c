//! Import of the published flapping-wing PR-SSM (Bayiz & Cheng 2021) from an `.npz` holding
//! the arrays `param_zeta_pos` (M × D), `param_zeta_mean` (M × D_x), `param_zeta_var`
//! (M × D_x), `param_var_x` (D_x), `param_var_y` (D_y), `param_kern_var` (1),
//! `param_kern_len` (D). The result is a compat-mode model: Matern-3/2, diagonal,
//! unwhitened, `K_mm` jitter 1e-8, Matern `δ = 1e-8`, transition jitter 1e-8, shared draws;
//! no normalization statistics (inputs are standardized).

use std::path::Path;

use flapssm_data::npz::{NpzError, NpzReader};

use crate::model::PrssmModel;
use crate::params::{ConfigError, ModelConfig, Params};

/// Errors importing published parameters.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum ImportError {
    /// Reading the archive or an array failed.
    #[error(transparent)]
    Npz(#[from] NpzError),
    /// Array shapes disagree with each other.
    #[error("{path}: array '{name}' has shape {shape:?}, expected {expected}")]
    Shape {
        /// File.
        path: String,
        /// Array.
        name: &'static str,
        /// Found shape.
        shape: Vec<usize>,
        /// Expected shape in words.
        expected: String,
    },
    /// Values out of range.
    #[error("{path}: {source}")]
    Invalid {
        /// File.
        path: String,
        /// What is wrong.
        source: ConfigError,
    },
}

/// Reads the published parameters from `path` into a compat-mode model with `D_y` outputs
/// taken from `param_var_y`.
///
/// # Errors
/// [`ImportError`] naming the file and array.
pub fn import_published(path: &Path) -> Result<PrssmModel, ImportError> {
    let ps = path.display().to_string();
    let mut r = NpzReader::open(path)?;
    let z = r.f64("param_zeta_pos")?;
    let shape_err = |name: &'static str, shape: &[usize], expected: String| ImportError::Shape {
        path: ps.clone(),
        name,
        shape: shape.to_vec(),
        expected,
    };
    if z.shape.len() != 2 {
        return Err(shape_err("param_zeta_pos", &z.shape, "(M, D)".into()));
    }
    let (m, d) = (z.shape[0], z.shape[1]);
    let mean = r.f64("param_zeta_mean")?;
    if mean.shape.len() != 2 || mean.shape[0] != m || mean.shape[1] >= d {
        return Err(shape_err(
            "param_zeta_mean",
            &mean.shape,
            format!("({m}, D_x) with D_x < {d}"),
        ));
    }
    let dx = mean.shape[1];
    let var = r.f64_shaped("param_zeta_var", &[m, dx])?;
    let var_x = r.f64_shaped("param_var_x", &[dx])?;
    let var_y = r.f64("param_var_y")?;
    if var_y.shape.len() != 1 || var_y.shape[0] == 0 || var_y.shape[0] > dx {
        return Err(shape_err(
            "param_var_y",
            &var_y.shape,
            format!("(D_y,) with 1 ≤ D_y ≤ {dx}"),
        ));
    }
    let kern_var = r.f64("param_kern_var")?;
    let kv = kern_var
        .scalar()
        .ok_or_else(|| shape_err("param_kern_var", &kern_var.shape, "(1,)".into()))?;
    let len = r.f64_shaped("param_kern_len", &[d])?;
    let config = ModelConfig::new(dx, var_y.shape[0], d - dx, m).published_compat();
    let params = Params {
        inducing_inputs: z.data,
        kernel_variance: kv,
        lengthscales: len,
        q_mean: mean.data,
        q_cov: var,
        process_noise_var: var_x,
        obs_noise_var: var_y.data,
    };
    let model = PrssmModel {
        config,
        params,
        normalization: None,
        training: serde_json::json!({ "source": "published", "file": ps }),
    };
    model.check().map_err(|source| ImportError::Invalid {
        path: ps.clone(),
        source,
    })?;
    Ok(model)
}
