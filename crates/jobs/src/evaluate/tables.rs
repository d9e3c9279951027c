//! The evaluation's tables written as files: per-trajectory CSV and the predictions archive.

use std::path::Path;

use flapssm_wing::dataset::Dataset;

use flapssm_data::npz::{NpyData, NpzWriter};

use super::report::TrajectoryMetrics;
use crate::error::{JobError, Result};
use crate::models::{LoadModel, ModelPrediction};

/// `trajectories.csv`: per trajectory its split, family, U_ref and window, then each model's
/// last-cycle C_Fx and C_Fy RMSE (`<key>_rmse_cfx`, `<key>_rmse_cfy`), then each model's
/// overall standardized RMSE (`<key>_overall_rmse_std`).
pub(super) fn trajectories_csv(models: &[&dyn LoadModel], t: &[TrajectoryMetrics]) -> String {
    let mut s = String::from("index,split,family,u_ref_m_s,period_samples,window_start");
    for m in models {
        s.push_str(&format!(",{0}_rmse_cfx,{0}_rmse_cfy", m.key()));
    }
    for m in models {
        s.push_str(&format!(",{}_overall_rmse_std", m.key()));
    }
    s.push('\n');
    for m in t {
        s.push_str(&format!(
            "{},{},{},{},{},{}",
            m.index, m.split, m.family, m.u_ref_m_s, m.period_samples, m.window_start,
        ));
        for r in &m.models {
            s.push_str(&format!(",{},{}", r.cycle_rmse_cf[0], r.cycle_rmse_cf[1]));
        }
        for r in &m.models {
            s.push_str(&format!(",{}", r.overall_rmse));
        }
        s.push('\n');
    }
    s
}

/// `predictions.npz`: per model `<key>_mean` and, where it has them, `<key>_var`
/// (`n_traj × T × 5`, N and N·mm) and `<key>_latent_mean` (`n_traj × T × n_latent`); and
/// `is_train` (`n_traj`).
pub(super) fn write_predictions(
    path: &Path,
    ds: &Dataset,
    models: &[&dyn LoadModel],
    predictions: &[Vec<ModelPrediction>],
) -> Result<()> {
    let (k, n) = (ds.len(), ds.n_samples());
    let mut w = NpzWriter::new();
    for (m, p) in models.iter().zip(predictions) {
        let key = m.key();
        let cat = |f: fn(&ModelPrediction) -> &[f64]| {
            NpyData::F64(p.iter().flat_map(f).copied().collect())
        };
        w.add(&format!("{key}_mean"), &[k, n, 5], cat(|p| &p.mean));
        if m.has_variance() {
            w.add(
                &format!("{key}_var"),
                &[k, n, 5],
                cat(|p| p.var.as_deref().unwrap_or_default()),
            );
        }
        if m.n_latent() > 0 {
            w.add(
                &format!("{key}_latent_mean"),
                &[k, n, m.n_latent()],
                cat(|p| &p.latent_mean),
            );
        }
    }
    w.add(
        "is_train",
        &[k],
        NpyData::Bool((0..k).map(|i| i < ds.n_train).collect()),
    );
    w.save(path).map_err(|e| JobError::Io {
        path: path.to_path_buf(),
        source: std::io::Error::other(e.to_string()),
    })
}
