//! The evaluation's tables written as files: per-trajectory CSV and the predictions archive.

use std::path::Path;

use flapssm_data::Dataset;

use super::TrajectoryMetrics;
use crate::error::{JobError, Result};
use crate::predict::PrssmPrediction;

pub(super) fn trajectories_csv(t: &[TrajectoryMetrics]) -> String {
    let mut s = String::from(
        "index,split,family,u_ref_m_s,period_samples,window_start,prssm_rmse_cfx,prssm_rmse_cfy,lrqsm_rmse_cfx,lrqsm_rmse_cfy,prssm_overall_rmse_std,lrqsm_overall_rmse_std\n",
    );
    for m in t {
        s.push_str(&format!(
            "{},{},{},{},{},{},{},{},{},{},{},{}\n",
            m.index,
            m.split,
            m.family,
            m.u_ref_m_s,
            m.period_samples,
            m.window_start,
            m.prssm_cycle_rmse_cf[0],
            m.prssm_cycle_rmse_cf[1],
            m.lrqsm_cycle_rmse_cf[0],
            m.lrqsm_cycle_rmse_cf[1],
            m.prssm_overall_rmse,
            m.lrqsm_overall_rmse
        ));
    }
    s
}

pub(super) fn write_predictions(
    path: &Path,
    ds: &Dataset,
    pp: &[PrssmPrediction],
    lq: &[Vec<f64>],
    dx: usize,
) -> Result<()> {
    use flapssm_data::npz::{NpyData, NpzWriter};
    let (k, n) = (ds.len(), ds.n_samples());
    let cat = |parts: Vec<&[f64]>| NpyData::F64(parts.concat());
    let mut w = NpzWriter::new();
    w.add(
        "prssm_mean",
        &[k, n, 5],
        cat(pp.iter().map(|p| p.output_mean.as_slice()).collect()),
    )
    .add(
        "prssm_var",
        &[k, n, 5],
        cat(pp.iter().map(|p| p.output_var.as_slice()).collect()),
    )
    .add(
        "prssm_latent_mean",
        &[k, n, dx],
        cat(pp.iter().map(|p| p.latent_mean.as_slice()).collect()),
    )
    .add(
        "lrqsm",
        &[k, n, 5],
        cat(lq.iter().map(Vec::as_slice).collect()),
    )
    .add(
        "is_train",
        &[k],
        NpyData::Bool((0..k).map(|i| i < ds.n_train).collect()),
    );
    w.save(path).map_err(|e| JobError::Io {
        path: path.to_path_buf(),
        source: std::io::Error::other(e.to_string()),
    })
}
