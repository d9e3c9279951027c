//! Starting values of the inducing inputs `Z` and the `q(u)` means: uniform (the published
//! code) or from the training data (k-means).
//!
//! The GP's input is `[x_t, u_t]`. Before training, the best proxy of the latent states a
//! rollout visits is `x̂_t = [y_t, 0, …, 0]`: the observation model reads `y_t = x_t[0..D_y]`
//! plus noise. [`InducingInit::Kmeans`] sets `Z` to the k-means centres of the proxies
//! `[x̂_t, u_t]` over the training steps after the burn-in (standardized units; k-means++
//! seeding, then Lloyd iterations) and, for the unwhitened form, the `q(u)` mean
//! `m_{j,d}` to the mean increment `y_{t+1,d} − y_{t,d}` of the steps nearest centre `j`
//! (`0` for `d ≥ D_y`), which is what `f_d = x_{t+1,d} − x_{t,d}` should be there. For the
//! whitened form `m` lives in `L⁻¹` coordinates and keeps its random start.

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize};

use crate::elbo::Sequence;
use crate::params::{ConfigError, ModelConfig, Parametrization, Params};

/// At most this many training steps enter the k-means (an even stride over all of them).
pub const KMEANS_MAX_POINTS: usize = 12_000;
/// At most this many Lloyd iterations (they stop earlier when no assignment changes).
pub const KMEANS_MAX_ITERATIONS: usize = 60;

/// How the inducing inputs and `q(u)` means start.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum InducingInit {
    /// `Z ~ U[−r, r]^D`, `m ~ 0.01 · U[0, 1)` ([`crate::ParamInit`]), as the published code.
    #[default]
    Uniform,
    /// `Z` from k-means of the training inputs visited, `m` from the output increments.
    Kmeans,
}

impl std::str::FromStr for InducingInit {
    type Err = String;
    /// `uniform` or `kmeans`.
    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "uniform" => Ok(InducingInit::Uniform),
            "kmeans" => Ok(InducingInit::Kmeans),
            _ => Err(format!("unknown rule {s:?} (expected uniform or kmeans)")),
        }
    }
}

/// Replaces `params.inducing_inputs` (and, unwhitened, `params.q_mean`) by their k-means
/// start on the standardized training `sequences`; the first `⌊burn_in_fraction · T⌋` steps
/// of each sequence, and its last step (no increment), are left out.
///
/// # Errors
/// [`ConfigError`] on `n_inducing` when the data have fewer usable steps than inducing points.
pub fn kmeans_start(
    config: &ModelConfig,
    sequences: &[Sequence],
    burn_in_fraction: f64,
    seed: u64,
    params: &mut Params,
) -> Result<(), ConfigError> {
    let (dx, du, dy, m) = (
        config.n_state,
        config.n_input,
        config.n_output,
        config.n_inducing,
    );
    let d = dx + du;
    // (sequence, step) of every usable step.
    let steps: Vec<(usize, usize)> = sequences
        .iter()
        .enumerate()
        .flat_map(|(i, s)| {
            let len = s.outputs.len() / dy;
            let first = (burn_in_fraction * len as f64).floor() as usize;
            (first..len.saturating_sub(1)).map(move |t| (i, t))
        })
        .collect();
    if steps.len() < m {
        return Err(ConfigError {
            field: "n_inducing",
            message: format!(
                "is {m}, but the k-means start needs at least as many training steps after the \
                 burn-in; the data have {}",
                steps.len()
            ),
        });
    }
    let stride = steps.len().div_ceil(KMEANS_MAX_POINTS);
    let chosen: Vec<(usize, usize)> = steps.into_iter().step_by(stride).collect();
    let n = chosen.len();
    // Points `[ŷ_t, 0, u_t]` (n × d) and increments `y_{t+1} − y_t` (n × D_y).
    let mut points = vec![0.0; n * d];
    let mut increments = vec![0.0; n * dy];
    for (k, &(i, t)) in chosen.iter().enumerate() {
        let s = &sequences[i];
        let p = &mut points[k * d..(k + 1) * d];
        p[..dy].copy_from_slice(&s.outputs[t * dy..(t + 1) * dy]);
        p[dx..].copy_from_slice(&s.inputs[t * du..(t + 1) * du]);
        for j in 0..dy {
            increments[k * dy + j] = s.outputs[(t + 1) * dy + j] - s.outputs[t * dy + j];
        }
    }
    let (centres, assignment) = kmeans(&points, d, m, seed);
    params.inducing_inputs = centres;
    if config.parametrization == Parametrization::Unwhitened {
        let mut sums = vec![0.0; m * dy];
        let mut counts = vec![0usize; m];
        for (k, &c) in assignment.iter().enumerate() {
            counts[c] += 1;
            for j in 0..dy {
                sums[c * dy + j] += increments[k * dy + j];
            }
        }
        params.q_mean = vec![0.0; m * dx];
        for c in 0..m {
            if counts[c] > 0 {
                for j in 0..dy {
                    params.q_mean[c * dx + j] = sums[c * dy + j] / counts[c] as f64;
                }
            }
        }
    }
    Ok(())
}

/// k-means of `n = points.len() / d` points (row-major `n × d`, `n ≥ k`) into `k` clusters:
/// k-means++ seeding from `seed`, then Lloyd iterations until no assignment changes (at most
/// [`KMEANS_MAX_ITERATIONS`]). Returns the centres (row-major `k × d`) and each point's
/// cluster. A cluster that loses all its points keeps its centre.
pub fn kmeans(points: &[f64], d: usize, k: usize, seed: u64) -> (Vec<f64>, Vec<usize>) {
    let n = points.len() / d;
    let point = |i: usize| &points[i * d..(i + 1) * d];
    let dist2 = |a: &[f64], b: &[f64]| a.iter().zip(b).map(|(x, y)| (x - y) * (x - y)).sum();
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut centres = Vec::with_capacity(k * d);
    centres.extend_from_slice(point(rng.random_range(0..n)));
    // Squared distance of every point to its nearest centre so far.
    let mut nearest: Vec<f64> = (0..n).map(|i| dist2(point(i), &centres[..d])).collect();
    for c in 1..k {
        let total: f64 = nearest.iter().sum();
        let pick = if total > 0.0 {
            let mut r = rng.random::<f64>() * total;
            nearest
                .iter()
                .position(|&w| {
                    r -= w;
                    r < 0.0
                })
                .unwrap_or(n - 1)
        } else {
            rng.random_range(0..n)
        };
        centres.extend_from_slice(point(pick));
        let new = &centres[c * d..(c + 1) * d];
        for (i, w) in nearest.iter_mut().enumerate() {
            *w = w.min(dist2(point(i), new));
        }
    }
    let mut assignment = vec![usize::MAX; n];
    let mut sums = vec![0.0; k * d];
    let mut counts = vec![0usize; k];
    for _ in 0..KMEANS_MAX_ITERATIONS {
        let mut changed = false;
        for (i, a) in assignment.iter_mut().enumerate() {
            let p = point(i);
            let mut best = (f64::INFINITY, 0);
            for c in 0..k {
                let e = dist2(p, &centres[c * d..(c + 1) * d]);
                if e < best.0 {
                    best = (e, c);
                }
            }
            if *a != best.1 {
                *a = best.1;
                changed = true;
            }
        }
        if !changed {
            break;
        }
        sums.fill(0.0);
        counts.fill(0);
        for (i, &a) in assignment.iter().enumerate() {
            counts[a] += 1;
            for (s, x) in sums[a * d..(a + 1) * d].iter_mut().zip(point(i)) {
                *s += x;
            }
        }
        for c in 0..k {
            if counts[c] > 0 {
                for j in 0..d {
                    centres[c * d + j] = sums[c * d + j] / counts[c] as f64;
                }
            }
        }
    }
    (centres, assignment)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::params::ParamInit;

    /// Three well-separated blobs are found exactly, whatever the seed.
    #[test]
    fn kmeans_finds_separated_clusters() {
        let blobs = [[0.0, 0.0], [10.0, 0.0], [0.0, 10.0]];
        let mut rng = ChaCha8Rng::seed_from_u64(9);
        let mut points = Vec::new();
        for i in 0..300 {
            let b = blobs[i % 3];
            points.push(b[0] + rng.random_range(-0.5..0.5));
            points.push(b[1] + rng.random_range(-0.5..0.5));
        }
        for seed in 0..5 {
            let (centres, assignment) = kmeans(&points, 2, 3, seed);
            for (i, &a) in assignment.iter().enumerate() {
                assert_eq!(
                    a,
                    assignment[i % 3],
                    "seed {seed}: point {i} split from its blob"
                );
            }
            for b in blobs {
                let near = (0..3).any(|c| {
                    (centres[2 * c] - b[0]).abs() < 0.2 && (centres[2 * c + 1] - b[1]).abs() < 0.2
                });
                assert!(near, "seed {seed}: no centre near blob {b:?}: {centres:?}");
            }
        }
        assert_eq!(kmeans(&points, 2, 3, 4), kmeans(&points, 2, 3, 4));
    }

    /// Two regimes of `(y, u)` with different increments: the centres sit on the regimes,
    /// carry zero in the unobserved latent dims, and their `q(u)` means are the increments.
    #[test]
    fn kmeans_start_places_centres_and_increments() {
        let config = ModelConfig::new(3, 1, 1, 2);
        // Regime A: u = −1, y rises by 0.1 per step from −1; regime B: u = +1, y falls by
        // 0.2 per step from 2.
        let seq = |u: f64, y0: f64, dy: f64| Sequence {
            inputs: vec![u; 10],
            outputs: (0..10).map(|t| y0 + dy * t as f64).collect(),
        };
        let data = [seq(-1.0, -1.0, 0.1), seq(1.0, 2.0, -0.2)];
        let mut p = Params::init(&config, &ParamInit::default(), 1);
        kmeans_start(&config, &data, 0.2, 3, &mut p).unwrap();
        // Usable steps t = 2..=8 of each: y means −1 + 0.5 = −0.5 and 2 − 1 = 1.
        let mut rows: Vec<(Vec<f64>, f64)> = (0..2)
            .map(|c| {
                (
                    p.inducing_inputs[c * 4..(c + 1) * 4].to_vec(),
                    p.q_mean[c * 3],
                )
            })
            .collect();
        rows.sort_by(|a, b| a.0[3].total_cmp(&b.0[3]));
        let close = |a: f64, b: f64| (a - b).abs() < 1e-12;
        assert!(
            close(rows[0].0[0], -0.5) && close(rows[0].0[3], -1.0),
            "{rows:?}"
        );
        assert!(
            close(rows[1].0[0], 1.0) && close(rows[1].0[3], 1.0),
            "{rows:?}"
        );
        assert!(rows.iter().all(|r| r.0[1] == 0.0 && r.0[2] == 0.0));
        assert!(close(rows[0].1, 0.1) && close(rows[1].1, -0.2), "{rows:?}");
        assert!((0..2).all(|c| p.q_mean[c * 3 + 1] == 0.0 && p.q_mean[c * 3 + 2] == 0.0));
    }

    #[test]
    fn kmeans_start_needs_enough_steps() {
        let config = ModelConfig::new(2, 1, 1, 50);
        let data = [Sequence {
            inputs: vec![0.0; 20],
            outputs: vec![0.0; 20],
        }];
        let mut p = Params::init(&config, &ParamInit::default(), 1);
        let err = kmeans_start(&config, &data, 0.2, 0, &mut p).unwrap_err();
        assert_eq!(err.field, "n_inducing");
        assert!(err.message.contains("have 15"), "{}", err.message);
    }

    #[test]
    fn parses_its_names() {
        assert_eq!("kmeans".parse(), Ok(InducingInit::Kmeans));
        assert_eq!("uniform".parse(), Ok(InducingInit::Uniform));
        assert!("random".parse::<InducingInit>().is_err());
    }
}
