//! Small dense linear-algebra pieces on column-major slices: Cholesky factorization and its
//! reverse mode (Murray 2016), triangular solves and products through faer.

use faer::linalg::matmul::matmul;
use faer::linalg::triangular_solve::{
    solve_lower_triangular_in_place, solve_upper_triangular_in_place,
};
use faer::traits::ComplexField;
use faer::{Accum, MatMut, MatRef, Par};

/// Column-major read-only view of `rows × cols` values.
#[inline]
pub(crate) fn view<T>(data: &[T], rows: usize, cols: usize) -> MatRef<'_, T> {
    MatRef::from_column_major_slice(&data[..rows * cols], rows, cols)
}

/// Column-major mutable view of `rows × cols` values.
#[inline]
pub(crate) fn view_mut<T>(data: &mut [T], rows: usize, cols: usize) -> MatMut<'_, T> {
    MatMut::from_column_major_slice_mut(&mut data[..rows * cols], rows, cols)
}

/// `dst (+)= α · lhs · rhs` (sequential), in `f64` or `f32`.
#[inline]
pub(crate) fn gemm<T: ComplexField>(
    dst: MatMut<'_, T>,
    accum: Accum,
    lhs: MatRef<'_, T>,
    rhs: MatRef<'_, T>,
    alpha: T,
) {
    matmul(dst, accum, lhs, rhs, alpha, Par::Seq);
}

/// Magnitude below which an `f32` operand of a product is taken as zero: `2⁻⁶²`, so that the
/// product of two nonzero operands (`≥ 2⁻¹²⁴`) is a normal `f32`. Subnormal operands or results
/// slow the `f32` kernels down many times over; what is flushed is below `2⁻⁶²` in absolute
/// terms, far under `f32`'s rounding of the standardized values these products see.
pub(crate) const F32_OPERAND_FLOOR: f64 = 2.168_404_344_971_009e-19;

/// `x` rounded to `f32` as a product operand: zero below [`F32_OPERAND_FLOOR`] in magnitude.
#[inline(always)]
pub(crate) fn f32_operand(x: f64) -> f32 {
    if x.abs() < F32_OPERAND_FLOOR {
        0.0
    } else {
        x as f32
    }
}

/// `dst[i] = f32_operand(src[i])` over `src` (round to nearest, tiny values to zero).
#[inline]
pub(crate) fn round_into(src: &[f64], dst: &mut [f32]) {
    dst[..src.len()]
        .iter_mut()
        .zip(src)
        .for_each(|(d, &s)| *d = f32_operand(s));
}

/// `dst[i] = src[i]` (`accum = Replace`) or `dst[i] += src[i]` (`Add`), widened to `f64`.
#[inline]
pub(crate) fn widen_into(src: &[f32], dst: &mut [f64], accum: Accum) {
    let pairs = dst[..src.len()].iter_mut().zip(src);
    match accum {
        Accum::Replace => pairs.for_each(|(d, &s)| *d = f64::from(s)),
        Accum::Add => pairs.for_each(|(d, &s)| *d += f64::from(s)),
    }
}

/// `Σ aᵢbᵢ` in eight interleaved partial sums (vectorizes; fixed order, so deterministic);
/// `a` and `b` in `f64` or widened from `f32`.
#[inline]
pub(crate) fn dot<A: Copy + Into<f64>, B: Copy + Into<f64>>(a: &[A], b: &[B]) -> f64 {
    let mut acc = [0.0; 8];
    let (ac, bc) = (a.chunks_exact(8), b.chunks_exact(8));
    let (ar, br) = (ac.remainder(), bc.remainder());
    for (x, y) in ac.zip(bc) {
        for l in 0..8 {
            acc[l] = x[l].into().mul_add(y[l].into(), acc[l]);
        }
    }
    let mut s = ((acc[0] + acc[4]) + (acc[1] + acc[5])) + ((acc[2] + acc[6]) + (acc[3] + acc[7]));
    for (&x, &y) in ar.iter().zip(br) {
        s = x.into().mul_add(y.into(), s);
    }
    s
}

/// `Σ aᵢ` in eight interleaved partial sums (vectorizes; fixed order).
#[inline]
pub(crate) fn sum(a: &[f64]) -> f64 {
    let mut acc = [0.0; 8];
    let ac = a.chunks_exact(8);
    let ar = ac.remainder();
    for x in ac {
        for l in 0..8 {
            acc[l] += x[l];
        }
    }
    let mut s = ((acc[0] + acc[4]) + (acc[1] + acc[5])) + ((acc[2] + acc[6]) + (acc[3] + acc[7]));
    for x in ar {
        s += x;
    }
    s
}

/// `B ← L⁻¹ B` for the lower-triangular `L` (`M × M`) and `B` (`M × N`).
#[inline]
pub(crate) fn solve_lower(l: &[f64], m: usize, b: &mut [f64], n: usize) {
    solve_lower_triangular_in_place(view(l, m, m), view_mut(b, m, n), Par::Seq);
}

/// `B ← L⁻ᵀ B` for the lower-triangular `L` (`M × M`) and `B` (`M × N`).
#[inline]
pub(crate) fn solve_lower_transpose(l: &[f64], m: usize, b: &mut [f64], n: usize) {
    solve_upper_triangular_in_place(view(l, m, m).transpose(), view_mut(b, m, n), Par::Seq);
}

/// In-place lower Cholesky factor `A = L Lᵀ` of a column-major `n × n` matrix; the strict
/// upper triangle is set to zero.
///
/// # Errors
/// `Err(index)`: the pivot `index` is not positive (or not finite).
pub fn cholesky_in_place(a: &mut [f64], n: usize) -> Result<(), usize> {
    // Left-looking by columns: `a[j.., j] −= L[j, k] · L[j.., k]` for `k < j` (contiguous
    // axpys, same summation order as the scalar dot-product form).
    for j in 0..n {
        let (done, rest) = a.split_at_mut(j * n);
        let col = &mut rest[j..n];
        for k in 0..j {
            let lk = &done[k * n + j..(k + 1) * n];
            let ljk = lk[0];
            col.iter_mut().zip(lk).for_each(|(c, &l)| *c -= l * ljk);
        }
        let d = col[0];
        if !(d > 0.0 && d.is_finite()) {
            return Err(j);
        }
        let djj = d.sqrt();
        col[0] = djj;
        col[1..].iter_mut().for_each(|c| *c /= djj);
        rest[..j].fill(0.0);
    }
    Ok(())
}

/// Reverse mode of the Cholesky factorization: given `L` and `L̄` (only its lower triangle is
/// read), returns the symmetric `Σ̄ = sym(L⁻ᵀ Φ(Lᵀ L̄) L⁻¹)`, where `Φ` keeps the lower
/// triangle and halves the diagonal (Murray 2016). `n × n`, column-major; `lbar` is
/// overwritten with scratch. Cost `O(n³)`.
pub fn cholesky_backward(l: &[f64], lbar: &mut [f64], n: usize) -> Vec<f64> {
    for j in 0..n {
        for i in 0..j {
            lbar[j * n + i] = 0.0;
        }
    }
    let mut p = vec![0.0; n * n];
    gemm(
        view_mut(&mut p, n, n),
        Accum::Replace,
        view(l, n, n).transpose(),
        view(lbar, n, n),
        1.0,
    );
    for j in 0..n {
        p[j * n + j] *= 0.5;
        for i in 0..j {
            p[j * n + i] = 0.0;
        }
    }
    // Y = L⁻ᵀ P; Σ̄ = Y L⁻¹ = (L⁻ᵀ Yᵀ)ᵀ.
    solve_lower_transpose(l, n, &mut p, n);
    let mut yt = vec![0.0; n * n];
    for j in 0..n {
        for i in 0..n {
            yt[j * n + i] = p[i * n + j];
        }
    }
    solve_lower_transpose(l, n, &mut yt, n);
    // yt now holds Σ̄ᵀ; symmetrize.
    let mut s = vec![0.0; n * n];
    for j in 0..n {
        for i in 0..n {
            s[j * n + i] = 0.5 * (yt[j * n + i] + yt[i * n + j]);
        }
    }
    s
}

/// `L⁻¹` of a lower-triangular `n × n` factor (column-major).
pub fn lower_inverse(l: &[f64], n: usize) -> Vec<f64> {
    let mut inv = vec![0.0; n * n];
    for i in 0..n {
        inv[i * n + i] = 1.0;
    }
    solve_lower(l, n, &mut inv, n);
    inv
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    fn spd(n: usize, rng: &mut ChaCha8Rng) -> Vec<f64> {
        let b: Vec<f64> = (0..n * n).map(|_| rng.random_range(-1.0..1.0)).collect();
        let mut a = vec![0.0; n * n];
        for i in 0..n {
            for j in 0..n {
                let mut s = 0.0;
                for k in 0..n {
                    s += b[k * n + i] * b[k * n + j];
                }
                a[j * n + i] = s + if i == j { n as f64 } else { 0.0 };
            }
        }
        a
    }

    /// Operands below the floor become zero, all others round to nearest; the product of any
    /// two nonzero operands is a normal `f32` (no subnormal reaches the `f32` kernels).
    #[test]
    fn f32_operands_are_zero_or_large_enough_for_normal_products() {
        assert_eq!(f32_operand(0.99 * F32_OPERAND_FLOOR), 0.0);
        assert_eq!(f32_operand(-1e-30), 0.0);
        assert_eq!(f32_operand(F32_OPERAND_FLOOR), F32_OPERAND_FLOOR as f32);
        assert_eq!(f32_operand(-0.1), -0.1f32);
        let smallest = f32_operand(F32_OPERAND_FLOOR);
        assert!((smallest * smallest).is_normal());
        let mut dst = [1.0f32; 3];
        round_into(&[1e-25, 2.5, -3e-20], &mut dst);
        assert_eq!(dst, [0.0, 2.5, 0.0]);
    }

    #[test]
    fn cholesky_reconstructs() {
        let mut rng = ChaCha8Rng::seed_from_u64(1);
        for n in [1, 3, 17] {
            let a = spd(n, &mut rng);
            let mut l = a.clone();
            cholesky_in_place(&mut l, n).unwrap();
            for i in 0..n {
                for j in 0..n {
                    let s: f64 = (0..n).map(|k| l[k * n + i] * l[k * n + j]).sum();
                    assert!((s - a[j * n + i]).abs() < 1e-12 * n as f64);
                }
            }
        }
        let mut bad = vec![1.0, 2.0, 2.0, 1.0];
        assert_eq!(cholesky_in_place(&mut bad, 2), Err(1));
    }

    #[test]
    fn cholesky_backward_matches_finite_differences() {
        // f(A) = Σ W ⊙ chol(A) for a fixed random W; perturb symmetric entries.
        let mut rng = ChaCha8Rng::seed_from_u64(2);
        let n = 6;
        let a = spd(n, &mut rng);
        let w: Vec<f64> = (0..n * n).map(|_| rng.random_range(-1.0..1.0)).collect();
        let f = |a: &[f64]| {
            let mut l = a.to_vec();
            cholesky_in_place(&mut l, n).unwrap();
            l.iter().zip(&w).map(|(x, y)| x * y).sum::<f64>()
        };
        let mut l = a.clone();
        cholesky_in_place(&mut l, n).unwrap();
        let mut lbar = w.clone();
        let g = cholesky_backward(&l, &mut lbar, n);
        let h = 1e-6;
        for i in 0..n {
            for j in 0..=i {
                let mut ap = a.clone();
                let mut am = a.clone();
                ap[j * n + i] += h;
                am[j * n + i] -= h;
                if i != j {
                    ap[i * n + j] += h;
                    am[i * n + j] -= h;
                }
                let fd = (f(&ap) - f(&am)) / (2.0 * h);
                let an = if i == j {
                    g[j * n + i]
                } else {
                    2.0 * g[j * n + i]
                };
                assert!((fd - an).abs() < 1e-7, "({i},{j}) fd {fd} an {an}");
            }
        }
    }
}
