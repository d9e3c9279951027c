//! KL(q(u) ‖ p(u)) against a direct dense computation (Gauss–Jordan inverse, LU determinant),
//! independent of the engine's Cholesky-based formulas.

use flapssm_prssm::CovarianceStructure;
use flapssm_prssm::kl::kl_divergence;
use flapssm_prssm::linalg::cholesky_in_place;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// Returns (inverse, ln det) of a dense n × n matrix by Gauss–Jordan with partial pivoting.
fn inv_logdet(a: &[f64], n: usize) -> (Vec<f64>, f64) {
    let mut w: Vec<Vec<f64>> = (0..n)
        .map(|i| {
            (0..2 * n)
                .map(|j| {
                    if j < n {
                        a[j * n + i]
                    } else if j - n == i {
                        1.0
                    } else {
                        0.0
                    }
                })
                .collect()
        })
        .collect();
    let mut logdet = 0.0;
    for c in 0..n {
        let p = (c..n)
            .max_by(|&x, &y| w[x][c].abs().total_cmp(&w[y][c].abs()))
            .unwrap();
        w.swap(c, p);
        let piv = w[c][c];
        logdet += piv.abs().ln();
        for v in w[c].iter_mut() {
            *v /= piv;
        }
        for r in 0..n {
            if r != c {
                let f = w[r][c];
                let rowc = w[c].clone();
                for (v, pc) in w[r].iter_mut().zip(rowc) {
                    *v -= f * pc;
                }
            }
        }
    }
    let mut inv = vec![0.0; n * n];
    for i in 0..n {
        for j in 0..n {
            inv[j * n + i] = w[i][n + j];
        }
    }
    (inv, logdet)
}

fn dense_kl(k: &[f64], m_vec: &[f64], s: &[f64], n: usize) -> f64 {
    let (ki, ldk) = inv_logdet(k, n);
    let (_, lds) = inv_logdet(s, n);
    let mut tr = 0.0;
    let mut quad = 0.0;
    for i in 0..n {
        for j in 0..n {
            tr += ki[j * n + i] * s[i * n + j];
            quad += m_vec[i] * ki[j * n + i] * m_vec[j];
        }
    }
    0.5 * (tr + quad - n as f64 + ldk - lds)
}

#[test]
fn kl_matches_dense_computation() {
    let mut rng = ChaCha8Rng::seed_from_u64(4);
    for (n, dx) in [(1, 1), (5, 2), (12, 3)] {
        let b: Vec<f64> = (0..n * n).map(|_| rng.random_range(-1.0..1.0)).collect();
        let mut k = vec![0.0; n * n];
        for i in 0..n {
            for j in 0..n {
                k[j * n + i] = (0..n).map(|q| b[q * n + i] * b[q * n + j]).sum::<f64>()
                    + if i == j { 0.5 } else { 0.0 };
            }
        }
        let mut l = k.clone();
        cholesky_in_place(&mut l, n).unwrap();
        let mean: Vec<f64> = (0..n * dx).map(|_| rng.random_range(-1.0..1.0)).collect();
        let diag: Vec<f64> = (0..n * dx).map(|_| rng.random_range(0.1..2.0)).collect();
        let mut full = vec![0.0; dx * n * n];
        for d in 0..dx {
            for j in 0..n {
                for i in j..n {
                    full[d * n * n + j * n + i] = if i == j {
                        rng.random_range(0.3..1.5)
                    } else {
                        rng.random_range(-0.5..0.5)
                    };
                }
            }
        }
        let mut id = vec![0.0; n * n];
        (0..n).for_each(|i| id[i * n + i] = 1.0);
        for whitened in [false, true] {
            let prior = if whitened { &id } else { &k };
            let lfac = (!whitened).then_some(&l[..]);
            let mut want_diag = 0.0;
            let mut want_full = 0.0;
            for d in 0..dx {
                let md: Vec<f64> = (0..n).map(|i| mean[i * dx + d]).collect();
                let mut sd = vec![0.0; n * n];
                (0..n).for_each(|i| sd[i * n + i] = diag[i * dx + d]);
                want_diag += dense_kl(prior, &md, &sd, n);
                let ld = &full[d * n * n..(d + 1) * n * n];
                let sf: Vec<f64> = (0..n * n)
                    .map(|idx| {
                        let (i, j) = (idx % n, idx / n);
                        (0..n).map(|q| ld[q * n + i] * ld[q * n + j]).sum()
                    })
                    .collect();
                want_full += dense_kl(prior, &md, &sf, n);
            }
            let got = kl_divergence(lfac, n, dx, &mean, &diag, CovarianceStructure::Diagonal).value;
            assert!(
                (got - want_diag).abs() <= 1e-10 * want_diag.abs().max(1.0),
                "diag n={n}: {got} vs {want_diag}"
            );
            let got = kl_divergence(lfac, n, dx, &mean, &full, CovarianceStructure::Full).value;
            assert!(
                (got - want_full).abs() <= 1e-10 * want_full.abs().max(1.0),
                "full n={n}: {got} vs {want_full}"
            );
        }
    }
}
