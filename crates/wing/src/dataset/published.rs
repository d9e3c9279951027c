//! Import of the published Bayiz & Cheng (2021) dataset layout from a `.mat` file.
//!
//! | variable | dimensions | meaning |
//! |---|---|---|
//! | `ds_pos` | n_traj × n_t × 3 | stroke, deviation, pitch (rad) |
//! | `ds_u_raw` | n_traj × n_t × 7 | inputs, [`crate::dataset::INPUT_NAMES`] order |
//! | `ds_y_raw` | n_traj × n_t × 5 | outputs (N, N·mm) |
//! | `ds_u`, `ds_y` | as above | optional, z-scored copies (shape-checked, not used) |
//! | `ds_mean_u`, `ds_std_u`, `ds_mean_y`, `ds_std_y` | 1 × 7 / 1 × 5 | optional published statistics, kept in `meta.settings.published_statistics` |
//!
//! The sampling period is 0.04 s (25 Hz), the family `"measured"`; the first `n_train`
//! (default [`PUBLISHED_N_TRAIN`] = 512) trajectories are the training set. `U_ref` is computed
//! per trajectory by a caller-supplied function of the Euler angles (this crate does not know
//! the wing kinematics).

use std::path::{Path, PathBuf};

use crate::dataset::{Dataset, DatasetError, DatasetMeta, Trajectory, ValidDataset};
use flapssm_data::mat::{MatError, MatFile};

/// Sampling period of the published dataset (s).
pub const PUBLISHED_DT_S: f64 = 0.04;
/// Training trajectories of the published split (`train_ind = 1:512`).
pub const PUBLISHED_N_TRAIN: usize = 512;

/// Errors importing the published layout.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum PublishedError {
    /// Reading the MAT file failed, or a required variable is missing.
    #[error(transparent)]
    Mat(#[from] MatError),
    /// A variable has the wrong dimensions.
    #[error("{path}: variable '{variable}' has dimensions {found:?}, expected {expected}")]
    Shape {
        /// File involved.
        path: PathBuf,
        /// Variable name.
        variable: &'static str,
        /// Dimensions found.
        found: Vec<usize>,
        /// Expected dimensions, in words.
        expected: String,
    },
    /// The U_ref function failed on a trajectory.
    #[error("{path}: U_ref of trajectory {trajectory}: {message}")]
    URef {
        /// File involved.
        path: PathBuf,
        /// Trajectory index (0-based).
        trajectory: usize,
        /// The function's message.
        message: String,
    },
    /// The imported dataset is invalid (NaN, n_train too large, …).
    #[error("{path}: {error}")]
    Invalid {
        /// File involved.
        path: PathBuf,
        /// The validation error.
        error: DatasetError,
    },
}

/// Rows of `width` values of trajectory `k` in a row-major `[n, n_t, width]` array.
fn rows<const W: usize>(data: &[f64], k: usize, n_t: usize) -> Vec<[f64; W]> {
    data[k * n_t * W..(k + 1) * n_t * W]
        .chunks_exact(W)
        .map(|c| std::array::from_fn(|j| c[j]))
        .collect()
}

/// Reads the published layout from `path` into a [`Dataset`].
///
/// `u_ref(euler_rad, dt_s)` returns U_ref (m/s) of one trajectory from its Euler angles
/// [n_t][stroke, deviation, pitch] (rad) and the sampling period (s), or a message.
///
/// # Errors
/// [`PublishedError::Mat`] naming the file and missing variable, [`PublishedError::Shape`],
/// [`PublishedError::URef`], [`PublishedError::Invalid`] (naming trajectory, field, sample).
pub fn import_published_mat(
    path: &Path,
    n_train: Option<usize>,
    mut u_ref: impl FnMut(&[[f64; 3]], f64) -> Result<f64, String>,
) -> Result<ValidDataset, PublishedError> {
    let mut mat = MatFile::read(path)?;
    let shape_err = |variable, found: &[usize], expected: String| PublishedError::Shape {
        path: path.to_path_buf(),
        variable,
        found: found.to_vec(),
        expected,
    };
    let pos = mat.take("ds_pos")?;
    let (n, n_t) = match *pos.shape() {
        [n, n_t, 3] => (n, n_t),
        _ => return Err(shape_err("ds_pos", &pos.dims, "n_traj × n_t × 3".into())),
    };
    let mut take3 = |name: &'static str, width: usize, required: bool| {
        if !required && mat.get(name).is_err() {
            return Ok(None);
        }
        let v = mat.take(name)?;
        if v.shape() != [n, n_t, width] {
            return Err(shape_err(name, &v.dims, format!("{n} × {n_t} × {width}")));
        }
        Ok(Some(v.data))
    };
    let u = take3("ds_u_raw", 7, true)?.expect("required");
    let y = take3("ds_y_raw", 5, true)?.expect("required");
    take3("ds_u", 7, false)?;
    take3("ds_y", 5, false)?;
    let mut stats = serde_json::Map::new();
    for (name, width) in [
        ("ds_mean_u", 7),
        ("ds_std_u", 7),
        ("ds_mean_y", 5),
        ("ds_std_y", 5),
    ] {
        if let Ok(v) = mat.get(name) {
            if v.len() != width || v.shape().len() != 2 {
                return Err(shape_err(name, &v.dims, format!("1 × {width}")));
            }
            stats.insert(name.to_string(), serde_json::json!(v.data));
        }
    }
    let mut trajectories = Vec::with_capacity(n);
    for k in 0..n {
        let euler_rad = rows::<3>(&pos.data, k, n_t);
        let u_ref_m_s =
            u_ref(&euler_rad, PUBLISHED_DT_S).map_err(|message| PublishedError::URef {
                path: path.to_path_buf(),
                trajectory: k,
                message,
            })?;
        trajectories.push(Trajectory {
            euler_rad,
            inputs: rows::<7>(&u, k, n_t),
            outputs: Some(rows::<5>(&y, k, n_t)),
            u_ref_m_s,
            family: "measured".into(),
        });
    }
    let settings = serde_json::json!({
        "source_file": path.display().to_string(),
        "published_statistics": stats,
    });
    let ds = Dataset {
        meta: DatasetMeta::new("import:mat", None, settings),
        dt_s: PUBLISHED_DT_S,
        trajectories,
        n_train: n_train.unwrap_or(PUBLISHED_N_TRAIN),
    };
    ValidDataset::new(ds).map_err(|error| PublishedError::Invalid {
        path: path.to_path_buf(),
        error,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn fixture(name: &str) -> PathBuf {
        Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../data/tests/fixtures")
            .join(name)
    }

    /// U_ref stand-in for the test: mean stroke angle (exactly known for the fixture).
    fn mean_stroke(e: &[[f64; 3]], _dt: f64) -> Result<f64, String> {
        Ok(e.iter().map(|r| r[0]).sum::<f64>() / e.len() as f64)
    }

    #[test]
    fn imports_scipy_fixtures_exactly() {
        for f in ["published_v5.mat", "published_v5z.mat"] {
            let ds = import_published_mat(&fixture(f), Some(3), mean_stroke).unwrap();
            assert_eq!((ds.len(), ds.n_samples(), ds.n_train), (4, 40, 3));
            assert_eq!(ds.dt_s, 0.04);
            for (k, t) in ds.trajectories.iter().enumerate() {
                let kf = k as f64;
                assert_eq!(t.family, "measured");
                // 5 full triangle periods of mean 2 → mean stroke k/8 + 2/4.
                assert_eq!(t.u_ref_m_s, kf / 8.0 + 0.5);
                for i in 0..40 {
                    let fi = i as f64;
                    let tri = 4 - (4 - (i % 8) as i32).abs();
                    assert_eq!(
                        t.euler_rad[i],
                        [kf / 8.0 + f64::from(tri) / 4.0, kf / 4.0, fi / 8.0 - kf]
                    );
                    let u: [f64; 7] =
                        std::array::from_fn(|j| kf * 1000.0 + fi * 10.0 + j as f64 + 0.5);
                    assert_eq!(t.inputs[i], u);
                    let y: [f64; 5] =
                        std::array::from_fn(|j| -(kf * 1000.0 + fi * 10.0 + j as f64) / 8.0);
                    assert_eq!(t.outputs.as_ref().unwrap()[i], y);
                }
            }
            // The published statistics (numpy, ddof 0, first 3 trajectories) equal ours.
            let s = &ds.meta.settings["published_statistics"];
            let mean_u: Vec<f64> = serde_json::from_value(s["ds_mean_u"].clone()).unwrap();
            let std_u: Vec<f64> = serde_json::from_value(s["ds_std_u"].clone()).unwrap();
            let ours = ds.standardization().unwrap();
            for j in 0..7 {
                assert!((mean_u[j] - ours.mean_u[j]).abs() < 1e-9 * ours.mean_u[j].abs());
                assert!((std_u[j] - ours.std_u[j]).abs() < 1e-9 * ours.std_u[j]);
            }
        }
    }

    #[test]
    fn errors_name_file_and_variable() {
        let e = import_published_mat(&fixture("published_missing.mat"), Some(3), mean_stroke)
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("published_missing.mat") && e.contains("'ds_y_raw' is missing"),
            "{e}"
        );
        let e = import_published_mat(&fixture("published_v5.mat"), None, mean_stroke)
            .unwrap_err()
            .to_string();
        assert!(e.contains("n_train = 512 exceeds the 4"), "{e}");
        let e = import_published_mat(&fixture("published_v5.mat"), Some(2), |_, _| {
            Err("no full cycle".to_string())
        })
        .unwrap_err()
        .to_string();
        assert!(e.contains("trajectory 0: no full cycle"), "{e}");
        let e = import_published_mat(&fixture("classes_v5.mat"), Some(1), mean_stroke)
            .unwrap_err()
            .to_string();
        assert!(e.contains("'ds_pos' is missing"), "{e}");
    }
}
