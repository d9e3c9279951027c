//! Control authority on the hidden subspace: the paper's latent rows in a form that survives a
//! change of basis.
//!
//! The paper reads Fig. 5 state by state (x7, x8, x10, x12), but a PR-SSM's latent states beyond
//! its outputs are defined only up to an invertible linear map (and the addition of multiples of
//! the outputs): the same model in another basis gives other rows. What is invariant is the
//! hidden subspace `H`, the span of the states beyond the outputs after the part explained by
//! the outputs (and a constant) is removed. Per trajectory, with `w_1 … w_h` an orthonormal
//! basis of `H` (zero mean, unit variance, mutually uncorrelated over the trajectory) and `z_k`
//! the standardized input `k`, the multiple correlation at lag `τ` samples is
//!
//! `R_k(τ) = √(Σ_m r_m(τ)²)`, `r_m(τ) = (1/T) Σ_{t<T−τ} z_k(t) w_m(t + τ)`,
//!
//! the largest correlation of the lagged input with any combination of hidden states: a change
//! of basis leaves it unchanged. Its peak over `0 < τ < max_lag_cycles` periods gives one
//! `(lag, R)` point per trajectory, summarized as the published analysis summarizes `|r|`
//! (median, median lag, interquartile range of the lag).
//!
//! `R` of `h` series is large by chance alone: smooth series have few independent samples per
//! trajectory. The **chance level** is the same statistic with each trajectory's hidden states
//! paired with another trajectory's input (trajectory `(i + K/2) mod K`). An input has authority
//! on the hidden subspace when the per-trajectory excess `R − R_chance` has a mean whose 95 %
//! bootstrap interval over trajectories excludes zero.

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use crate::authority::{AuthorityConfig, AuthorityTrajectory};
use crate::error::{AnalysisError, Result, param};
use crate::stats::{Interval, Rows, central_interval, median, quartiles};
use crate::xcorr::{peak_within_cycle, standardize_into, xcf_positive_into};

/// One input's authority on the hidden subspace.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct HiddenAuthority {
    /// Input index (0-based).
    pub input: usize,
    /// Trajectories with a peak.
    pub n_points: usize,
    /// Dimension of the hidden subspace (median over trajectories).
    pub dimension: usize,
    /// Median peak `R`.
    pub median_r: f64,
    /// Median lag of the peak (cycles).
    pub median_lag_cycles: f64,
    /// Interquartile range of that lag (cycles).
    pub lag_iqr_cycles: f64,
    /// Median peak `R` at chance (another trajectory's input).
    pub chance_median_r: f64,
    /// Mean over trajectories of `R − R_chance`.
    pub excess: f64,
    /// Its 95 % bootstrap interval.
    pub excess_interval: Interval,
    /// Whether that interval excludes zero from above.
    pub above_chance: bool,
}

/// Bootstrap draws of the excess interval.
pub const HIDDEN_BOOTSTRAP_DRAWS: usize = 2000;

/// Orthonormal basis (as columns, each of length `T`, zero mean, `Σ_t w² = T`) of the hidden
/// subspace of `states`: columns `n_output..` with the constant and the first `n_output`
/// columns projected out (modified Gram–Schmidt; directions under `1e-8` of their original
/// norm are dropped as numerically absent).
pub fn hidden_basis(states: Rows<'_>, n_output: usize) -> Vec<Vec<f64>> {
    let t_len = states.n_rows();
    let mut basis: Vec<Vec<f64>> = vec![vec![1.0 / (t_len as f64).sqrt(); t_len]];
    let mut hidden = Vec::new();
    for j in 0..states.n_cols() {
        let mut v = states.column(j);
        let norm0 = v.iter().map(|x| x * x).sum::<f64>().sqrt();
        for b in &basis {
            let dot: f64 = v.iter().zip(b).map(|(a, b)| a * b).sum();
            v.iter_mut().zip(b).for_each(|(a, b)| *a -= dot * b);
        }
        let norm = v.iter().map(|x| x * x).sum::<f64>().sqrt();
        if norm.is_nan() || norm <= 1e-8 * norm0 {
            continue;
        }
        v.iter_mut().for_each(|a| *a /= norm);
        if j >= n_output {
            hidden.push(v.iter().map(|a| a * (t_len as f64).sqrt()).collect());
        }
        basis.push(v);
    }
    hidden
}

/// Peak `(lag in cycles, R)` of input series `z` (standardized) against `hidden` within
/// `max_lag_cycles` periods; `None` where the subspace is empty or no lag qualifies.
fn peak(
    z: &[f64],
    hidden: &[Vec<f64>],
    period: f64,
    config: &AuthorityConfig,
    xcf: &mut [f64],
    r2: &mut [f64],
) -> Option<(f64, f64)> {
    if hidden.is_empty() {
        return None;
    }
    r2.fill(0.0);
    for w in hidden {
        xcf_positive_into(z, w, xcf);
        r2.iter_mut().zip(xcf.iter()).for_each(|(s, r)| *s += r * r);
    }
    r2.iter_mut().for_each(|s| *s = s.sqrt());
    peak_within_cycle(r2, period, config.max_lag_cycles).map(|p| (p.lag_cycles, p.r))
}

/// The authority of every input on the hidden subspace of states `n_output..` (module docs),
/// with its chance level; bootstrap from `seed`. The trajectories are those of the published
/// analysis ([`AuthorityTrajectory`]: inputs, latent means, stroke period).
///
/// # Errors
/// [`AnalysisError::Empty`] for no trajectory, [`AnalysisError::Shape`] for tables of other
/// widths or lengths, a parameter error for a bad config or period, or `n_output` not below the
/// states; [`AnalysisError::ConstantSeries`] naming a constant input.
pub fn hidden_authority(
    trajectories: &[AuthorityTrajectory<'_>],
    n_output: usize,
    config: &AuthorityConfig,
    seed: u64,
) -> Result<Vec<HiddenAuthority>> {
    config.check()?;
    let first = trajectories.first().ok_or_else(|| AnalysisError::Empty {
        what: "trajectory list".into(),
    })?;
    let (n_input, n_state, t_len) = (
        first.inputs.n_cols(),
        first.states.n_cols(),
        first.inputs.n_rows(),
    );
    if n_output >= n_state {
        return Err(param(
            "n_output",
            n_output,
            &format!("must be below the {n_state} latent states"),
        ));
    }
    for (i, tr) in trajectories.iter().enumerate() {
        tr.check(i, n_input, n_state, Some(t_len))?;
    }
    let n_traj = trajectories.len();
    let standardized: Vec<Vec<Vec<f64>>> = trajectories
        .iter()
        .enumerate()
        .map(|(i, tr)| {
            (0..n_input)
                .map(|k| {
                    let mut z = vec![0.0; t_len];
                    standardize_into(
                        &format!("trajectory {i} input {k}"),
                        &tr.inputs.column(k),
                        &mut z,
                    )?;
                    Ok(z)
                })
                .collect()
        })
        .collect::<Result<_>>()?;
    let n_lags = config.num_lags.min(t_len - 1) + 1;
    // Per trajectory: (dimension, per input (own peak, chance peak)).
    type Peaks = (usize, Vec<(Option<(f64, f64)>, Option<(f64, f64)>)>);
    let per: Vec<Peaks> = trajectories
        .par_iter()
        .enumerate()
        .map(|(i, tr)| {
            let hidden = hidden_basis(tr.states, n_output);
            let other = &standardized[(i + n_traj / 2) % n_traj];
            let (mut xcf, mut r2) = (vec![0.0; n_lags], vec![0.0; n_lags]);
            let peaks = (0..n_input)
                .map(|k| {
                    let own = peak(
                        &standardized[i][k],
                        &hidden,
                        tr.period_samples,
                        config,
                        &mut xcf,
                        &mut r2,
                    );
                    let chance = peak(
                        &other[k],
                        &hidden,
                        tr.period_samples,
                        config,
                        &mut xcf,
                        &mut r2,
                    );
                    (own, chance)
                })
                .collect();
            (hidden.len(), peaks)
        })
        .collect();
    let mut dims: Vec<f64> = per.iter().map(|(d, _)| *d as f64).collect();
    dims.sort_by(f64::total_cmp);
    let dimension = dims[dims.len() / 2] as usize;
    (0..n_input)
        .map(|k| {
            let pairs: Vec<((f64, f64), (f64, f64))> = per
                .iter()
                .filter_map(|(_, p)| Some((p[k].0?, p[k].1?)))
                .collect();
            if pairs.is_empty() {
                return Err(AnalysisError::Empty {
                    what: format!("hidden-subspace peaks of input {k}"),
                });
            }
            let r: Vec<f64> = pairs.iter().map(|(o, _)| o.1).collect();
            let lags: Vec<f64> = pairs.iter().map(|(o, _)| o.0).collect();
            let chance: Vec<f64> = pairs.iter().map(|(_, c)| c.1).collect();
            let diff: Vec<f64> = r.iter().zip(&chance).map(|(a, b)| a - b).collect();
            let (q1, _, q3) = quartiles(&lags)?;
            let mut rng = ChaCha8Rng::seed_from_u64(seed.wrapping_add(k as u64));
            let n = diff.len();
            let means: Vec<f64> = (0..HIDDEN_BOOTSTRAP_DRAWS)
                .map(|_| (0..n).map(|_| diff[rng.random_range(0..n)]).sum::<f64>() / n as f64)
                .collect();
            let interval = central_interval(&means, 95.0)?;
            Ok(HiddenAuthority {
                input: k,
                n_points: n,
                dimension,
                median_r: median(&r)?,
                median_lag_cycles: median(&lags)?,
                lag_iqr_cycles: q3 - q1,
                chance_median_r: median(&chance)?,
                excess: diff.iter().sum::<f64>() / n as f64,
                excess_interval: interval,
                above_chance: interval.lo > 0.0,
            })
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Smooth noise: a sum of a few random-phase sines of periods 20–200 samples.
    fn smooth(t_len: usize, rng: &mut ChaCha8Rng) -> Vec<f64> {
        let comps: Vec<(f64, f64)> = (0..6)
            .map(|_| {
                (
                    rng.random_range(20.0..200.0),
                    rng.random_range(0.0..std::f64::consts::TAU),
                )
            })
            .collect();
        (0..t_len)
            .map(|t| {
                comps
                    .iter()
                    .map(|(p, ph)| (t as f64 / p * std::f64::consts::TAU + ph).sin())
                    .sum()
            })
            .collect()
    }

    /// 40 trajectories of 2 inputs and 5 states (2 outputs, 3 hidden). Input 0 drives a hidden
    /// state 10 samples later; input 1 drives nothing. The states are mixed by `mix` (3 × 3,
    /// applied to the hidden part) plus `leak` × the outputs.
    fn dataset(mix: [[f64; 3]; 3], leak: f64) -> (Vec<Vec<f64>>, Vec<Vec<f64>>) {
        let (t_len, lag) = (400, 10);
        let mut rng = ChaCha8Rng::seed_from_u64(4);
        let mut inputs = Vec::new();
        let mut states = Vec::new();
        for _ in 0..40 {
            let u0 = smooth(t_len + lag, &mut rng);
            let u1 = smooth(t_len + lag, &mut rng);
            let y: Vec<[f64; 2]> = (0..t_len)
                .map(|_| [rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0)])
                .collect();
            let n1 = smooth(t_len, &mut rng);
            let n2 = smooth(t_len, &mut rng);
            let mut inp = Vec::new();
            let mut st = Vec::new();
            for t in 0..t_len {
                inp.extend([u0[t + lag], u1[t + lag]]);
                let h = [u0[t], n1[t], n2[t]];
                st.extend(y[t]);
                for row in mix {
                    let v: f64 = row.iter().zip(&h).map(|(a, b)| a * b).sum();
                    st.push(v + leak * y[t][0]);
                }
            }
            inputs.push(inp);
            states.push(st);
        }
        (inputs, states)
    }

    fn run(mix: [[f64; 3]; 3], leak: f64) -> Vec<HiddenAuthority> {
        let (inputs, states) = dataset(mix, leak);
        let trs: Vec<AuthorityTrajectory<'_>> = inputs
            .iter()
            .zip(&states)
            .map(|(u, x)| AuthorityTrajectory {
                inputs: Rows::new(u, 2).unwrap(),
                states: Rows::new(x, 5).unwrap(),
                period_samples: 100.0,
            })
            .collect();
        hidden_authority(&trs, 2, &AuthorityConfig::default(), 1).unwrap()
    }

    /// The driving input is found at its lag (10 samples = 0.1 cycle) with R ≈ 1, above
    /// chance; the idle one is not; and any change of basis of the hidden states, or adding
    /// the outputs to them, changes nothing.
    #[test]
    fn finds_the_driving_input_in_any_basis() {
        let identity = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
        let a = run(identity, 0.0);
        assert!(a[0].above_chance && a[0].median_r > 0.95, "{:?}", a[0]);
        assert!((a[0].median_lag_cycles - 0.1).abs() < 0.011, "{:?}", a[0]);
        assert!(!a[1].above_chance, "{:?}", a[1]);
        assert_eq!(a[0].dimension, 3);
        let mixed = run([[0.3, -1.2, 0.5], [2.0, 0.4, -0.7], [-0.6, 0.9, 1.5]], 0.8);
        for (p, q) in a.iter().zip(&mixed) {
            assert!((p.median_r - q.median_r).abs() < 1e-9, "{p:?} {q:?}");
            assert!((p.median_lag_cycles - q.median_lag_cycles).abs() < 1e-12);
            assert!((p.chance_median_r - q.chance_median_r).abs() < 1e-9);
        }
    }

    /// A hidden state that is a copy of an output adds no dimension.
    #[test]
    fn outputs_copied_into_the_hidden_states_are_not_hidden() {
        let x: Vec<f64> = (0..50)
            .flat_map(|t| {
                let y = (t as f64 * 0.3).sin();
                let h = (t as f64 * 0.11).cos();
                [y, 2.0 * y + 1.0, h]
            })
            .collect();
        assert_eq!(hidden_basis(Rows::new(&x, 3).unwrap(), 1).len(), 1);
    }

    #[test]
    fn bad_shapes_are_refused() {
        let u = vec![0.0; 20];
        let x = vec![0.0; 30];
        let tr = [AuthorityTrajectory {
            inputs: Rows::new(&u, 2).unwrap(),
            states: Rows::new(&x, 3).unwrap(),
            period_samples: 5.0,
        }];
        assert!(hidden_authority(&tr, 1, &AuthorityConfig::default(), 0).is_err());
        let x = vec![0.0; 20];
        let tr = [AuthorityTrajectory {
            inputs: Rows::new(&u, 2).unwrap(),
            states: Rows::new(&x, 2).unwrap(),
            period_samples: 5.0,
        }];
        let e = hidden_authority(&tr, 2, &AuthorityConfig::default(), 0).unwrap_err();
        assert!(e.to_string().contains("n_output"), "{e}");
    }
}
