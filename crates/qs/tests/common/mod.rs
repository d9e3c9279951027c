//! Shared test helpers: smooth random wing inputs and a small dense solver.
#![allow(dead_code, clippy::needless_range_loop)]

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// Random smooth inputs u = [AoA, |v|, a_x, a_y, a_z, α̇, α̈] of `n_traj` trajectories of
/// `n_t` samples at `dt_s`: each a sum of 3 random sinusoids (0.1–0.8 Hz), α̇ and α̈ the exact
/// derivatives of a random pitch angle α(t), |v| kept positive.
pub fn smooth_inputs(n_traj: usize, n_t: usize, dt_s: f64, seed: u64) -> Vec<Vec<[f64; 7]>> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut harmonics = |amp: f64| -> Vec<(f64, f64, f64)> {
        (0..3)
            .map(|_| {
                let w = std::f64::consts::TAU * rng.random_range(0.1..0.8);
                (
                    amp * rng.random_range(0.3..1.0),
                    w,
                    rng.random_range(0.0..6.3),
                )
            })
            .collect()
    };
    (0..n_traj)
        .map(|_| {
            let aoa = harmonics(0.6);
            let speed = harmonics(1.5);
            let ax = harmonics(8.0);
            let ay = harmonics(5.0);
            let az = harmonics(3.0);
            let pitch = harmonics(0.7);
            let eval = |h: &[(f64, f64, f64)], t: f64, d: u32| -> f64 {
                h.iter()
                    .map(|&(a, w, ph)| match d {
                        0 => a * (w * t + ph).sin(),
                        1 => a * w * (w * t + ph).cos(),
                        _ => -a * w * w * (w * t + ph).sin(),
                    })
                    .sum()
            };
            (0..n_t)
                .map(|i| {
                    let t = i as f64 * dt_s;
                    [
                        eval(&aoa, t, 0),
                        4.0 + eval(&speed, t, 0),
                        eval(&ax, t, 0),
                        eval(&ay, t, 0),
                        eval(&az, t, 0),
                        eval(&pitch, t, 1),
                        eval(&pitch, t, 2),
                    ]
                })
                .collect()
        })
        .collect()
}

/// Standard normal draws (Box–Muller), seeded.
pub fn normals(n: usize, seed: u64) -> Vec<f64> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    (0..n)
        .map(|_| {
            let u1: f64 = rng.random_range(f64::EPSILON..1.0);
            let u2: f64 = rng.random_range(0.0..1.0);
            (-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos()
        })
        .collect()
}

/// Inverse of a symmetric positive-definite matrix (k × k row-major) by Cholesky.
pub fn spd_inverse(a: &[f64], k: usize) -> Vec<f64> {
    let mut l = vec![0.0; k * k];
    for i in 0..k {
        for j in 0..=i {
            let s: f64 = a[i * k + j] - (0..j).map(|m| l[i * k + m] * l[j * k + m]).sum::<f64>();
            l[i * k + j] = if i == j {
                assert!(s > 0.0, "not positive definite");
                s.sqrt()
            } else {
                s / l[j * k + j]
            };
        }
    }
    let mut inv = vec![0.0; k * k];
    for c in 0..k {
        // Solve L z = e_c, then Lᵀ x = z.
        let mut z = vec![0.0; k];
        for i in 0..k {
            let e = if i == c { 1.0 } else { 0.0 };
            z[i] = (e - (0..i).map(|m| l[i * k + m] * z[m]).sum::<f64>()) / l[i * k + i];
        }
        for i in (0..k).rev() {
            z[i] = (z[i] - (i + 1..k).map(|m| l[m * k + i] * z[m]).sum::<f64>()) / l[i * k + i];
        }
        for i in 0..k {
            inv[i * k + c] = z[i];
        }
    }
    inv
}

/// Ordinary least squares with intercept: returns (intercept, slopes, slope standard errors),
/// SE_j = σ̂ sqrt([(X_cᵀX_c)⁻¹]_jj), σ̂² = SSE / (n − p − 1), X_c the centred design.
pub fn ols(x: &[f64], y: &[f64], p: usize) -> (f64, Vec<f64>, Vec<f64>) {
    let n = y.len();
    let mx: Vec<f64> = (0..p)
        .map(|j| (0..n).map(|i| x[i * p + j]).sum::<f64>() / n as f64)
        .collect();
    let my = y.iter().sum::<f64>() / n as f64;
    let mut a = vec![0.0; p * p];
    let mut b = vec![0.0; p];
    for i in 0..n {
        for j in 0..p {
            let xj = x[i * p + j] - mx[j];
            b[j] += xj * (y[i] - my);
            for k in 0..p {
                a[j * p + k] += xj * (x[i * p + k] - mx[k]);
            }
        }
    }
    let inv = spd_inverse(&a, p);
    let beta: Vec<f64> = (0..p)
        .map(|j| (0..p).map(|k| inv[j * p + k] * b[k]).sum())
        .collect();
    let b0 = my - (0..p).map(|j| mx[j] * beta[j]).sum::<f64>();
    let sse: f64 = (0..n)
        .map(|i| {
            let r = y[i] - b0 - (0..p).map(|j| x[i * p + j] * beta[j]).sum::<f64>();
            r * r
        })
        .sum();
    let s2 = sse / (n - p - 1) as f64;
    let se = (0..p).map(|j| (s2 * inv[j * p + j]).sqrt()).collect();
    (b0, beta, se)
}
