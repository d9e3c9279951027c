//! The paper's own 548 measured wing trajectories (Bayiz & Cheng 2021), vendored in
//! `crates/wing/data/` (CC0, provenance in its README), as Euler angles in this crate's
//! convention.
//!
//! The file holds `[548, 470, 3]` float32 radians at 25 Hz in the order [stroke, deviation,
//! pitch]. Its signs are the robot's; this crate's are those of [`crate::kinematics`]. Three
//! facts fix the conversion `[φ, ψ, α] = [φ_file, −ψ_file, −α_file]`:
//!
//! - **stroke sign**: every trajectory ends at mid-stroke (|φ| < 4°) moving towards +φ, which is
//!   what the published U_ref recipe assumes of its last sample, as this crate does;
//! - **pitch sign and zero**: the pitch file channel is centred on zero (median −0.1°, range
//!   ±107°) and correlates positively with the stroke rate (median r = 0.70). With α = 0 the
//!   plate vertical, the leading edge leads when α has the sign opposite to φ̇, so the file's
//!   pitch is −α: the leading edge then leads on 75 % of the fast samples (25 % as filed) and
//!   mid-stroke |AoA| has median 64° (116° as filed);
//! - **deviation sign**: test trajectory #13 (index 524), the paper's "U-shaped" one, has its
//!   deviation lowest at both reversals as filed (corr(ψ_file, |φ|) = −0.98); with ψ > 0
//!   lifting the tip it is a U only as −ψ_file. Together with the pitch flip this is the
//!   reflection through the stroke plane, which maps a physical motion onto a physical motion.
//!
//! The test set is the last 36 (trajectory `512 + n − 1` is the paper's test trajectory #n): the
//! shapes named in Fig. 3 check out — #26 and #14 deviate at twice the stroke frequency
//! (figure-eight), #13 too, lowest mid-stroke (U), #33 by under 4° (flat), #5 and #32 at the
//! stroke frequency (oval); see `tests/paper_trajectories.rs`.

use super::{SamplingConfig, TrajectoryError, measured};
use crate::cycles::{self, U_REF_RADIUS_M};
use crate::dataset::{Dataset, DatasetMeta, FORMAT_VERSION, Fluid, INPUT_UNITS, OUTPUT_UNITS};
use crate::dataset::{Trajectory, ValidDataset, WingGeometry};
use crate::kinematics::WingKinematics;

/// Number of measured trajectories.
pub const PAPER_N_TRAJECTORIES: usize = 548;
/// The published training count: the first 512 trajectories train, the last 36 test.
pub const PAPER_N_TRAIN: usize = 512;
/// Samples per trajectory (25 Hz, 18.8 s).
pub const PAPER_N_SAMPLES: usize = 470;
/// Sampling period of the measured trajectories (s).
pub const PAPER_DT_S: f64 = 0.04;
/// Signs taking the file's [stroke, deviation, pitch] to this crate's [φ, ψ, α].
pub const PAPER_ANGLE_SIGNS: [f64; 3] = [1.0, -1.0, -1.0];

/// The vendored array (`crates/wing/data/bayiz2021-euler-angles.npy`, sha256
/// 3b4212fe729049753568bf778193a8b01056e3a7e49c39c53b004fbe6ac8bfaa).
const PAPER_NPY: &[u8] = include_bytes!("../../data/bayiz2021-euler-angles.npy");

/// The paper's trajectories `0..n` (n ≤ 548, in the authors' order) as Euler angles
/// [φ, ψ, α] (rad) in this crate's convention, 470 rows each at 25 Hz.
///
/// # Panics
/// Never for the vendored file (its decoding is tested); `n` above 548 is clamped.
pub fn paper_angles(n: usize) -> Vec<Vec<[f64; 3]>> {
    let arr = flapssm_data::npz::decode_npy_f64(PAPER_NPY)
        .expect("the vendored measured trajectories decode");
    let n = n.min(PAPER_N_TRAJECTORIES);
    arr.data
        .chunks_exact(PAPER_N_SAMPLES * 3)
        .take(n)
        .map(|t| {
            t.chunks_exact(3)
                .map(|r| std::array::from_fn(|k| PAPER_ANGLE_SIGNS[k] * r[k]))
                .collect()
        })
        .collect()
}

/// The sampling of the measured trajectories: this crate's default (250 Hz raw, ×10 to 25 Hz,
/// 470 samples), which is the robot's.
pub fn paper_sampling() -> SamplingConfig {
    SamplingConfig::default()
}

/// The paper's trajectories `0..n` (n ≤ 548) as a kinematics-only dataset: the Euler angles,
/// inputs and U_ref at 25 Hz of the smoothed measured angles ([`measured::raw_states`] at its
/// knots), exactly as a noise-free `simulate --source paper` computes them; the first
/// min(n, 512) train, family `measured`, no outputs.
///
/// # Errors
/// [`TrajectoryError::Differentiate`] or [`TrajectoryError::Cycle`] naming the trajectory
/// (never for the vendored file); an empty `n` gives an invalid dataset.
pub fn paper_kinematics(n: usize) -> Result<ValidDataset, TrajectoryError> {
    let sampling = paper_sampling();
    let dt_s = sampling.dataset_dt_s();
    let trajectories = paper_angles(n)
        .iter()
        .enumerate()
        .map(|(index, angles)| {
            let states = measured::raw_states(angles, &sampling)
                .map_err(|source| TrajectoryError::Differentiate { index, source })?;
            let knots: Vec<_> = states
                .iter()
                .step_by(sampling.decimation.max(1))
                .take(sampling.n_samples)
                .collect();
            let euler_rad: Vec<[f64; 3]> = knots.iter().map(|s| s.angles_rad).collect();
            let inputs = knots
                .iter()
                .map(|s| WingKinematics::from_euler(s).inputs())
                .collect();
            let (u_ref_m_s, _) = cycles::published_u_ref(&euler_rad, dt_s, U_REF_RADIUS_M)
                .map_err(|source| TrajectoryError::Cycle { index, source })?;
            Ok(Trajectory {
                euler_rad,
                inputs,
                outputs: None,
                u_ref_m_s,
                family: "measured".to_string(),
            })
        })
        .collect::<Result<Vec<_>, TrajectoryError>>()?;
    let ds = Dataset {
        meta: DatasetMeta {
            format_version: FORMAT_VERSION,
            wing: WingGeometry::default(),
            fluid: Fluid::default(),
            generator: "flapssm (the paper's measured trajectories)".to_string(),
            seed: None,
            settings: serde_json::json!({ "angles_source": "crates/wing/data/bayiz2021-euler-angles.npy", "signs": PAPER_ANGLE_SIGNS }),
            input_units: INPUT_UNITS.iter().map(|s| s.to_string()).collect(),
            output_units: OUTPUT_UNITS.iter().map(|s| s.to_string()).collect(),
        },
        dt_s,
        n_train: trajectories.len().min(PAPER_N_TRAIN),
        trajectories,
    };
    Ok(ValidDataset::new(ds)?)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_vendored_file_has_the_papers_shape_and_signs_are_applied() {
        let arr = flapssm_data::npz::decode_npy_f64(PAPER_NPY).unwrap();
        assert_eq!(arr.shape, vec![548, 470, 3]);
        let a = paper_angles(600);
        assert_eq!(a.len(), 548);
        assert!(a.iter().all(|t| t.len() == PAPER_N_SAMPLES));
        for k in 0..3 {
            assert_eq!(
                a[3][7][k],
                PAPER_ANGLE_SIGNS[k] * arr.data[(3 * 470 + 7) * 3 + k]
            );
        }
        let s = paper_sampling();
        assert_eq!(s.n_samples, PAPER_N_SAMPLES);
        assert!((s.dataset_dt_s() - PAPER_DT_S).abs() < 1e-15);
    }
}
