//! The generator's trajectories beside the paper's measured ones: per-trajectory statistics
//! ([`flapssm_wing::trajectories::stats`]), their 5 / 50 / 95th percentiles over trajectories,
//! and a two-sample Kolmogorov–Smirnov test per statistic.

use flapssm_analysis::ks::{KsTest, ks_two_sample};
use flapssm_analysis::stats::prctile;
use flapssm_wing::trajectories::GeneratorConfig;
use flapssm_wing::trajectories::paper::{PAPER_DT_S, PAPER_N_TRAJECTORIES, paper_angles};
use flapssm_wing::trajectories::stats::{STAT_NAMES, TrajectoryStats};

use crate::error::{JobError, Result};

/// One statistic of both sets.
#[derive(Debug, Clone, PartialEq)]
pub struct StatComparison {
    /// Name and unit ([`STAT_NAMES`]).
    pub name: &'static str,
    /// 5th, 50th, 95th percentile over the paper's 548 measured trajectories.
    pub paper: [f64; 3],
    /// The same over the generated trajectories.
    pub generated: [f64; 3],
    /// Two-sample KS test of the two sets of per-trajectory values.
    pub ks: KsTest,
}

/// Statistics of every trajectory, one column per statistic (NaNs dropped).
fn columns(sets: impl Iterator<Item = Option<TrajectoryStats>>) -> Vec<Vec<f64>> {
    let mut cols = vec![Vec::new(); STAT_NAMES.len()];
    for s in sets.flatten() {
        for (c, v) in cols.iter_mut().zip(s.values()) {
            if v.is_finite() {
                c.push(v);
            }
        }
    }
    cols
}

/// Compares the trajectories of `cfg` with the paper's measured set, statistic by statistic.
///
/// # Errors
/// [`JobError::Simulate`] when the generator fails; [`JobError::Setting`] when a statistic
/// has no finite value in a set.
pub fn compare_with_paper(cfg: &GeneratorConfig) -> Result<Vec<StatComparison>> {
    let specs = cfg
        .generate()
        .map_err(flapssm_wing::virtual_wing::SimulateError::from)?;
    let dt = cfg.sampling.dataset_dt_s();
    let generated = columns(specs.iter().map(|s| {
        let rows: Vec<[f64; 3]> = s
            .sample_dataset(&cfg.sampling)
            .iter()
            .map(|st| st.angles_rad)
            .collect();
        TrajectoryStats::of(&rows, dt)
    }));
    let paper = columns(
        paper_angles(PAPER_N_TRAJECTORIES)
            .iter()
            .map(|t| TrajectoryStats::of(t, PAPER_DT_S)),
    );
    let pct = |v: &[f64]| -> Result<[f64; 3]> {
        let p = |q| prctile(v, q).map_err(|e| setting(e.to_string()));
        Ok([p(5.0)?, p(50.0)?, p(95.0)?])
    };
    STAT_NAMES
        .iter()
        .zip(paper.iter().zip(&generated))
        .map(|(name, (p, g))| {
            Ok(StatComparison {
                name,
                paper: pct(p)?,
                generated: pct(g)?,
                ks: ks_two_sample(p, g).map_err(|e| setting(e.to_string()))?,
            })
        })
        .collect()
}

fn setting(why: String) -> JobError {
    JobError::Setting {
        name: "trajectories".into(),
        value: "generated".into(),
        expected: format!("statistics with finite values ({why})"),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_statistic_is_compared_and_a_far_off_generator_is_rejected() {
        let cfg = GeneratorConfig {
            n_trajectories: 60,
            n_train: 50,
            seed: 3,
            ..GeneratorConfig::default()
        };
        let rows = compare_with_paper(&cfg).unwrap();
        assert_eq!(rows.len(), STAT_NAMES.len());
        // The measured set's U_ref is one value (0.1746 m/s to ±0.5 %).
        let u = &rows[7];
        assert!(u.paper[0] > 0.17 && u.paper[2] < 0.18, "{u:?}");
        // The default generator's frequencies are the measured ones (every trajectory counted).
        let f = &rows[0];
        assert!(f.ks.p_value > 0.01, "{f:?}");
        // Twice the frequency and nothing else changed: the KS test sees it.
        let fast = GeneratorConfig {
            frequency_hz: [0.4, 0.5],
            u_ref_m_s: None,
            ..cfg
        };
        let f = &compare_with_paper(&fast).unwrap()[0];
        assert!(f.ks.p_value < 1e-6 && f.generated[1] > 0.38, "{f:?}");
    }
}
