//! Stationary ARD kernels `k(a, b) = σ_f² g(τ)` with the scaled squared distance
//! `τ = Σ_j ((a_j − b_j)/ℓ_j)²`, and their reverse-mode adjoints.
//!
//! | kind | `g(τ)` | `dg/dτ` |
//! |---|---|---|
//! | [`KernelKind::Matern32`] | `(1 + r) e^{−r}`, `r = √3 √(τ + δ)` | `−(3/2) e^{−r}` |
//! | [`KernelKind::SquaredExponential`] | `e^{−τ/2}` | `−g/2` |
//!
//! `δ` (`matern_tau_jitter`) is `1e-8` in the published code and `0` by default. Written in
//! `τ`, the Matern-3/2 derivative is finite at `a = b`.
//!
//! Layouts: point sets are column-major `D × N` slices (one point per column, i.e. point-major
//! rows of length `D`); kernel matrices are column-major `M × N`.

use serde::{Deserialize, Serialize};

use crate::linalg::F32_OPERAND_FLOOR;

/// Which stationary kernel the transition GP uses (one kernel shared by all latent dims).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum KernelKind {
    /// Matern-3/2 ARD (the paper's kernel).
    Matern32,
    /// Squared-exponential (RBF) ARD.
    SquaredExponential,
}

impl KernelKind {
    /// Shape function `g(τ)` and its derivative `dg/dτ` (dimensionless).
    #[inline(always)]
    pub fn shape(self, tau: f64, matern_tau_jitter: f64) -> (f64, f64) {
        match self {
            KernelKind::Matern32 => {
                let r = (3.0 * (tau + matern_tau_jitter)).sqrt();
                let e = exp(-r);
                ((1.0 + r) * e, -1.5 * e)
            }
            KernelKind::SquaredExponential => {
                let g = exp(-0.5 * tau);
                (g, -0.5 * g)
            }
        }
    }
}

/// `eˣ`, branch-free so that loops over slices vectorize (AVX-512/AVX2).
///
/// `x = k ln2 + r` with `k = round(x / ln2)`, `|r| ≤ ln2/2` (Cody–Waite split of `ln2`),
/// `eʳ = 1 + r + r² q(r)` with `q` the degree-9 Chebyshev approximation of `(eʳ − 1 − r)/r²`
/// on `[−ln2/2, ln2/2]` (relative error of `eʳ` `< 2·10⁻¹⁷`; Estrin's scheme, so the
/// dependency chain is short), scaled by `2ᵏ` in one product. Within 1 ulp of the correctly
/// rounded value for results of at least `2.23·10⁻³⁰⁸` (`x ≥ −708.39`); smaller results are
/// `0` (no subnormals); arguments above 709 are clamped (no `+∞`); NaN propagates.
#[inline(always)]
pub fn exp(x: f64) -> f64 {
    // ln2 = LN2_HI + LN2_LO, LN2_HI with 21 trailing zero bits (k·LN2_HI is exact).
    const LN2_HI: f64 = f64::from_bits(0x3fe6_2e42_fee0_0000);
    const LN2_LO: f64 = f64::from_bits(0x3dea_39ef_3579_3c76);
    // 1.5·2⁵²: adding it rounds to an integer, which is then the low bits of the sum.
    const SHIFT: f64 = 6_755_399_441_055_744.0;
    // Ascending coefficients of `q` (mpmath `chebyfit`, 200-bit arithmetic, rounded to f64).
    const Q: [f64; 10] = [
        0.500_000_000_000_000_1,
        0.166_666_666_666_666_69,
        0.041_666_666_666_624_164,
        0.008_333_333_333_330_065,
        0.001_388_888_891_719_671_9,
        1.984_126_986_304_054_5e-4,
        2.480_152_132_236_869_2e-5,
        2.755_726_848_031_002_4e-6,
        2.762_007_587_998_336_7e-7,
        2.510_037_583_256_123_4e-8,
    ];
    // From here up `k ≥ −1022` and `r > 0` when `k = −1022`, so `p·2ᵏ` is normal and exact;
    // below it (`−1022·ln2 = −708.396`) results are subnormal or within 0.07 % of `2⁻¹⁰²²`.
    const FLUSH: f64 = -708.39;
    let xc = if x > 709.0 { 709.0 } else { x };
    let t = xc.mul_add(std::f64::consts::LOG2_E, SHIFT);
    let kf = t - SHIFT;
    let k = (t.to_bits() as i64).wrapping_sub(SHIFT.to_bits() as i64);
    let r = kf.mul_add(-LN2_LO, kf.mul_add(-LN2_HI, xc));
    let r2 = r * r;
    let r4 = r2 * r2;
    let a = |i: usize| Q[i + 1].mul_add(r, Q[i]);
    let b0 = a(2).mul_add(r2, a(0));
    let b1 = a(6).mul_add(r2, a(4));
    let q = a(8).mul_add(r4 * r4, b1.mul_add(r4, b0));
    let p = 1.0 + r2.mul_add(q, r);
    let scale = f64::from_bits((k.wrapping_add(1023) as u64) << 52);
    if xc < FLUSH { 0.0 } else { p * scale }
}

/// `eˣ` in `f32`, branch-free (vectorizable) for `x ≤ 0` as the kernels need: `x = k ln2 + r`,
/// `k = round(x / ln2)`, `|r| ≤ ln2/2` (Cody–Waite), `eʳ` by its degree-7 Taylor polynomial in
/// Horner form with fused multiply-adds (truncation `< 6·10⁻⁹`; with `f32` rounding within
/// `2·10⁻⁷` of `eˣ`, tested), scaled by `2ᵏ` through the exponent bits. `x < −87` is taken as
/// `−87` (`e⁻⁸⁷ ≈ 1.6·10⁻³⁸`, a normal `f32`); NaN propagates.
#[inline(always)]
pub(crate) fn exp_f32(x: f32) -> f32 {
    // ln2 = LN2_HI + LN2_LO: `k · LN2_HI` is exact for |k| < 2¹⁵.
    const LN2_HI: f32 = 0.693_359_4;
    const LN2_LO: f32 = -2.121_944_4e-4;
    // 1.5·2²³: adding it rounds to an integer, which is then the low bits of the sum.
    const SHIFT: f32 = 12_582_912.0;
    const C: [f32; 6] = [
        1.0 / 2.0,
        1.0 / 6.0,
        1.0 / 24.0,
        1.0 / 120.0,
        1.0 / 720.0,
        1.0 / 5040.0,
    ];
    let x = if x < -87.0 { -87.0 } else { x };
    let t = x.mul_add(std::f32::consts::LOG2_E, SHIFT);
    let kf = t - SHIFT;
    let k = (t.to_bits() as i32).wrapping_sub(SHIFT.to_bits() as i32);
    let r = kf.mul_add(-LN2_LO, kf.mul_add(-LN2_HI, x));
    let q = C[5].mul_add(r, C[4]).mul_add(r, C[3]).mul_add(r, C[2]);
    let q = q.mul_add(r, C[1]).mul_add(r, C[0]).mul_add(r, 1.0);
    let p = q.mul_add(r, 1.0);
    let scale = f32::from_bits((k.wrapping_add(127) as u32) << 23);
    p * scale
}

/// Scales a row-major `N × D` point set by `1/ℓ` into a column-major `D × N` slice
/// (`out[j + n·D] = points[n·D + j] / ℓ_j`; the same memory order).
pub fn scale_points(points: &[f64], inv_len: &[f64], out: &mut [f64]) {
    let d = inv_len.len();
    for (o, p) in out.chunks_exact_mut(d).zip(points.chunks_exact(d)) {
        for j in 0..d {
            o[j] = p[j] * inv_len[j];
        }
    }
}

/// Transposes scaled inducing inputs into dimension-major `M`-vectors:
/// `zt[j·M + m] = Z[m, j] / ℓ_j` (`Z` row-major `M × D`).
pub fn scale_inducing(z: &[f64], inv_len: &[f64], zt: &mut [f64]) {
    let d = inv_len.len();
    let m_n = z.len() / d;
    for m in 0..m_n {
        for j in 0..d {
            zt[j * m_n + m] = z[m * d + j] * inv_len[j];
        }
    }
}

/// Cross-covariance `K[m, n] = σ_f² g(τ(z_m, x_n))` (column-major `M × N`) and
/// `kd[m, n] = σ_f² g'(τ)` for the backward pass.
///
/// `zt`: scaled inducing inputs from [`scale_inducing`] (`D·M`); `xs`: scaled points
/// (`D × N`, column-major). `k` and `kd` have `M·N` entries. Allocates nothing.
#[allow(clippy::too_many_arguments)]
pub fn cross_cov(
    kind: KernelKind,
    variance: f64,
    matern_tau_jitter: f64,
    zt: &[f64],
    xs: &[f64],
    d: usize,
    k: &mut [f64],
    kd: &mut [f64],
) {
    let m_n = zt.len() / d;
    for ((kc, kdc), x) in k
        .chunks_exact_mut(m_n)
        .zip(kd.chunks_exact_mut(m_n))
        .zip(xs.chunks_exact(d))
    {
        sq_dist(zt, m_n, 0, x, None, kc);
        apply_shape(kind, variance, matern_tau_jitter, kc, kdc);
    }
}

/// The operands of a grouped cross-covariance: the kernel (`kind`, `σ_f²`, the Matern `τ`
/// jitter), the scaled inducing inputs `zt` (`D·M`, from [`scale_inducing`]) and the scaled
/// points `xs` (`D × N`, column-major, from [`scale_points`]), whose consecutive groups of
/// `group` share their coordinates `shared_from..D` (particles of one window share the input
/// `u`).
#[derive(Debug, Clone, Copy)]
pub(crate) struct GroupedPoints<'a> {
    pub kind: KernelKind,
    pub variance: f64,
    pub tau_jitter: f64,
    pub zt: &'a [f64],
    pub xs: &'a [f64],
    pub d: usize,
    pub shared_from: usize,
    pub group: usize,
}

impl GroupedPoints<'_> {
    /// `M`, the number of inducing inputs.
    fn m(&self) -> usize {
        self.zt.len() / self.d
    }

    /// `τ` of group `xg` into `tg` (`M × group`); see [`group_sq_dist`].
    #[inline(always)]
    fn group_tau(&self, xg: &[f64], tau_shared: &mut [f64], tg: &mut [f64]) {
        let (zt, d, from) = (self.zt, self.d, self.shared_from);
        group_sq_dist(zt, self.m(), d, from, xg, tau_shared, tg);
    }
}

/// [`cross_cov`] of grouped points: the shared part of `τ` is computed once per group into
/// `tau_shared` (`M`). Same results as [`cross_cov`] up to the order of the sum.
pub(crate) fn cross_cov_grouped(
    p: GroupedPoints,
    k: &mut [f64],
    kd: &mut [f64],
    tau_shared: &mut [f64],
) {
    let (m_n, group) = (p.m(), p.group);
    let tau_shared = &mut tau_shared[..m_n];
    for ((kg, kdg), xg) in k
        .chunks_mut(m_n * group)
        .zip(kd.chunks_mut(m_n * group))
        .zip(p.xs.chunks(p.d * group))
    {
        p.group_tau(xg, tau_shared, kg);
        apply_shape(p.kind, p.variance, p.tau_jitter, kg, kdg);
    }
}

/// [`cross_cov_grouped`] with the shape in `f32`, for the products of mixed precision
/// ([`crate::precision`]): `τ` in `f64` into `tau` (`M × N`), then `k32 = σ_f² g(τ)` by
/// [`exp_f32`] and the `f32` square root, as product operands (values below
/// [`F32_OPERAND_FLOOR`] become zero), and, if `scaled_exp` is given, `σ_f² e^{x(τ)}` into
/// it, from which `σ_f² g'(τ) = c' · σ_f² e^{x}` ([`shape_slope`]). Within a few `f32`
/// roundings of the `f64` values; twice the lanes of the `f64` shape.
pub(crate) fn cross_cov_grouped_f32(
    p: GroupedPoints,
    tau: &mut [f64],
    k32: &mut [f32],
    mut scaled_exp: Option<&mut [f32]>,
    tau_shared: &mut [f64],
) {
    let (m_n, group) = (p.m(), p.group);
    let tau_shared = &mut tau_shared[..m_n];
    let n = p.xs.len() / p.d;
    let (tau, k32) = (&mut tau[..m_n * n], &mut k32[..m_n * n]);
    let variance = p.variance as f32;
    for (g, xg) in p.xs.chunks(p.d * group).enumerate() {
        let cols = g * m_n * group..((g + 1) * m_n * group).min(m_n * n);
        let tg = &mut tau[cols.clone()];
        p.group_tau(xg, tau_shared, tg);
        let eg = scaled_exp.as_deref_mut().map(|e| &mut e[cols.clone()]);
        apply_shape_f32(p.kind, variance, p.tau_jitter, tg, &mut k32[cols], eg);
    }
}

/// Squared scaled distances of one group of points `xg` (`D × group`) to the `M` inducing
/// points into `kg` (`M × group`): the shared coordinates `shared_from..D` (the group's first
/// point) once into `tau_shared`, then each point's own coordinates `0..shared_from` on top.
#[inline(always)]
fn group_sq_dist(
    zt: &[f64],
    m_n: usize,
    d: usize,
    shared_from: usize,
    xg: &[f64],
    tau_shared: &mut [f64],
    kg: &mut [f64],
) {
    sq_dist(zt, m_n, shared_from, &xg[shared_from..d], None, tau_shared);
    for (kc, x) in kg.chunks_exact_mut(m_n).zip(xg.chunks_exact(d)) {
        sq_dist(zt, m_n, 0, &x[..shared_from], Some(tau_shared), kc);
    }
}

/// `out[m] = init[m] + Σ_j (z̃_{m, j0+j} − x_j)²` for all `M` inducing points, in SIMD
/// register blocks (`zt` dimension-major with stride `m_n`).
#[inline(always)]
fn sq_dist(zt: &[f64], m_n: usize, j0: usize, x: &[f64], init: Option<&[f64]>, out: &mut [f64]) {
    let zt = &zt[j0 * m_n..];
    let (wide, narrow) = (m_n / 32 * 32, m_n / 8 * 8);
    for m0 in (0..wide).step_by(32) {
        out[m0..m0 + 32].copy_from_slice(&tau_block::<32>(zt, m_n, m0, x, init));
    }
    for m0 in (wide..narrow).step_by(8) {
        out[m0..m0 + 8].copy_from_slice(&tau_block::<8>(zt, m_n, m0, x, init));
    }
    if narrow < m_n {
        if m_n >= 8 {
            // The last 8 (overlapping entries get identical values).
            let b = tau_block::<8>(zt, m_n, m_n - 8, x, init);
            out[m_n - 8..m_n].copy_from_slice(&b);
        } else {
            for (m, o) in out.iter_mut().enumerate().take(m_n).skip(narrow) {
                *o = tau_block::<1>(zt, m_n, m, x, init)[0];
            }
        }
    }
}

/// `τ` for `m = m0..m0 + W` (independent SIMD accumulators for wide `W`).
#[inline(always)]
fn tau_block<const W: usize>(
    zt: &[f64],
    m_n: usize,
    m0: usize,
    x: &[f64],
    init: Option<&[f64]>,
) -> [f64; W] {
    let mut acc = [0.0; W];
    if let Some(init) = init {
        acc.copy_from_slice(&init[m0..m0 + W]);
    }
    for (j, &xj) in x.iter().enumerate() {
        let z = &zt[j * m_n + m0..][..W];
        for l in 0..W {
            let diff = z[l] - xj;
            acc[l] = diff.mul_add(diff, acc[l]);
        }
    }
    acc
}

/// Replaces `τ` in `k` by `σ_f² g(τ)` and writes `σ_f² g'(τ)` into `kd` (one vectorized
/// loop per kernel kind).
#[inline]
fn apply_shape(kind: KernelKind, variance: f64, jitter: f64, k: &mut [f64], kd: &mut [f64]) {
    match kind {
        KernelKind::Matern32 => {
            for (kv, kdv) in k.iter_mut().zip(kd.iter_mut()) {
                let r = (3.0 * (*kv + jitter)).sqrt();
                let e = variance * exp(-r);
                *kv = (1.0 + r) * e;
                *kdv = -1.5 * e;
            }
        }
        KernelKind::SquaredExponential => {
            for (kv, kdv) in k.iter_mut().zip(kd.iter_mut()) {
                let g = variance * exp(-0.5 * *kv);
                *kv = g;
                *kdv = -0.5 * g;
            }
        }
    }
}

/// `c'` of [`apply_shape_f32`]: `σ_f² g'(τ) = c' · σ_f² e^{x(τ)}` (`−3/2` for Matern-3/2,
/// `−1/2` for the squared exponential).
pub(crate) fn shape_slope(kind: KernelKind) -> f64 {
    match kind {
        KernelKind::Matern32 => -1.5,
        KernelKind::SquaredExponential => -0.5,
    }
}

/// `k[i] = σ_f² g(τ[i])` in `f32`, as a product operand (below [`F32_OPERAND_FLOOR`]: zero),
/// and `scaled_exp[i] = σ_f² e^{x(p)}` if given: `g = c(p) e^{x(p)}` with `p = √(3(τ + δ))`,
/// `x = −p`, `c = 1 + p` (Matern-3/2) or `p = −τ/2`, `x = p`, `c = 1` (squared exponential);
/// `g' = c' e^{x(p)}` ([`shape_slope`]). `τ` is overwritten.
#[inline]
fn apply_shape_f32(
    kind: KernelKind,
    variance: f32,
    jitter: f64,
    tau: &mut [f64],
    k: &mut [f32],
    scaled_exp: Option<&mut [f32]>,
) {
    match kind {
        KernelKind::Matern32 => shape_passes(
            (tau, k, scaled_exp),
            variance,
            |t| ((3.0 * (t + jitter)) as f32).sqrt(),
            |p| (-p, 1.0 + p),
        ),
        KernelKind::SquaredExponential => shape_passes(
            (tau, k, scaled_exp),
            variance,
            |t| (-0.5 * t) as f32,
            |p| (p, 1.0),
        ),
    }
}

/// The loops of [`apply_shape_f32`] as separate passes over slices of one type each, so that
/// the `f32` work runs on 8 lanes and not on the 4 of `τ`'s `f64`: `p` narrowed into `k`,
/// then `k` and `σ_f² eˣ`.
#[inline(always)]
fn shape_passes(
    (tau, k, scaled_exp): (&mut [f64], &mut [f32], Option<&mut [f32]>),
    variance: f32,
    p_of: impl Fn(f64) -> f32,
    x_c: impl Fn(f32) -> (f32, f32),
) {
    let n = k.len();
    k.iter_mut().zip(&tau[..n]).for_each(|(k, &t)| *k = p_of(t));
    match scaled_exp {
        Some(e) => {
            for (k, e) in k.iter_mut().zip(e[..n].iter_mut()) {
                let (x, c) = x_c(*k);
                *e = variance * exp_f32(x);
                *k = operand(c * *e);
            }
        }
        None => k.iter_mut().for_each(|k| {
            let (x, c) = x_c(*k);
            *k = operand(c * (variance * exp_f32(x)));
        }),
    }
}

/// A kernel value as an `f32` product operand: zero below [`F32_OPERAND_FLOOR`] (`K ≥ 0`).
#[inline(always)]
fn operand(v: f32) -> f32 {
    if v < F32_OPERAND_FLOOR as f32 { 0.0 } else { v }
}

/// Reverse mode of [`cross_cov`] with respect to the inducing inputs, the points and the
/// lengthscales, given `c[m, n] = K̄[m, n] · kd[m, n]` (`∂loss/∂τ`).
///
/// With `τ = Σ_j (z̃_{mj} − x̃_{nj})²` and `z̃ = z/ℓ`, `d = z̃_{mj} − x̃_{nj}`:
/// `Z̄[m,j] += 2/ℓ_j Σ_n c d`, `X̄[j,n] −= 2/ℓ_j Σ_m c d`, `ℓ̄_j −= 2/ℓ_j Σ c d²`, evaluated
/// through the products `C X̃ᵀ` and `Z̃ᵀ C` (two GEMMs). `zbar_t` is dimension-major
/// (`zbar_t[j·M + m]`, without the factor `2/ℓ_j`: see [`finish_inducing_grad`]); `xbar`
/// (`n_xbar_rows × N`) gets the full adjoint of rows `j < n_xbar_rows`; `len_acc[j]`
/// accumulates `Σ c d²`. Scratch: `cx` (`M·D`), `zc` (`D·N`; `n_xbar_rows·N` are used),
/// `rowsum` (`M`). Allocates nothing.
#[allow(clippy::too_many_arguments)]
pub fn cross_cov_backward(
    c: &[f64],
    zt: &[f64],
    xs: &[f64],
    inv_len: &[f64],
    n_xbar_rows: usize,
    zbar_t: &mut [f64],
    xbar: &mut [f64],
    len_acc: &mut [f64],
    cx: &mut [f64],
    zc: &mut [f64],
    rowsum: &mut [f64],
) {
    use crate::linalg::{gemm, view, view_mut};
    let d = inv_len.len();
    let m_n = zt.len() / d;
    let n_pts = xs.len() / d;
    gemm(
        view_mut(cx, m_n, d),
        faer::Accum::Replace,
        view(c, m_n, n_pts),
        view(xs, d, n_pts).transpose(),
        1.0,
    );
    // Only the rows of X̄ that are wanted: `Z̃[:, ..n_xbar_rows]ᵀ C`.
    let nx = n_xbar_rows;
    gemm(
        view_mut(zc, nx, n_pts),
        faer::Accum::Replace,
        view(zt, m_n, d).subcols(0, nx).transpose(),
        view(c, m_n, n_pts),
        1.0,
    );
    // One pass over `C`: column sums `s_n = Σ_m c[m, n]` (X̄, ℓ̄) and row sums `Σ_n c[m, n]`.
    let rowsum = &mut rowsum[..m_n];
    rowsum.fill(0.0);
    for (n, col) in c[..m_n * n_pts].chunks_exact(m_n).enumerate() {
        let s = crate::linalg::sum(col);
        rowsum.iter_mut().zip(col).for_each(|(r, v)| *r += v);
        for j in 0..d {
            let x = xs[n * d + j];
            len_acc[j] += x * x * s;
            if j < nx {
                xbar[n * nx + j] -= 2.0 * inv_len[j] * (zc[n * nx + j] - x * s);
            }
        }
    }
    for j in 0..d {
        let zj = &zt[j * m_n..(j + 1) * m_n];
        let cxj = &cx[j * m_n..(j + 1) * m_n];
        let mut l = 0.0;
        for (((zb, &z), &r), &q) in zbar_t[j * m_n..(j + 1) * m_n]
            .iter_mut()
            .zip(zj)
            .zip(rowsum.iter())
            .zip(cxj)
        {
            *zb += z * r - q;
            l += z * z * r - 2.0 * z * q;
        }
        len_acc[j] += l;
    }
}

/// Converts a dimension-major accumulator of `Σ c d` into `∂loss/∂Z` (row-major `M × D`):
/// `zbar[m·D + j] += 2/ℓ_j · acc[j·M + m]`.
pub fn finish_inducing_grad(acc: &[f64], inv_len: &[f64], zbar: &mut [f64]) {
    let d = inv_len.len();
    let m_n = acc.len() / d;
    for m in 0..m_n {
        for j in 0..d {
            zbar[m * d + j] += 2.0 * inv_len[j] * acc[j * m_n + m];
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};

    /// Distance in units in the last place between two finite doubles of the same sign.
    fn ulps(a: f64, b: f64) -> u64 {
        (a.to_bits() as i64 - b.to_bits() as i64).unsigned_abs()
    }

    /// Inducing inputs `z` (`M × D`), inverse lengthscales, points (`N × D`) and both scaled.
    struct Case {
        z: Vec<f64>,
        inv_len: Vec<f64>,
        pts: Vec<f64>,
        zt: Vec<f64>,
        xs: Vec<f64>,
    }

    const M: usize = 13;
    const D: usize = 5;
    const DX: usize = 3;
    const GROUP: usize = 3;

    /// Random inputs and `n` points in groups of [`GROUP`] that share coordinates `D_x..D`;
    /// `place` edits the points before the groups take their first point's shared coordinates.
    fn case(seed: u64, n: usize, place: impl FnOnce(&mut [f64], &[f64])) -> Case {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
        let z: Vec<f64> = (0..M * D).map(|_| rng.random_range(-2.0..2.0)).collect();
        let inv_len: Vec<f64> = (0..D).map(|_| rng.random_range(0.5..2.0)).collect();
        let mut pts: Vec<f64> = (0..n * D).map(|_| rng.random_range(-2.0..2.0)).collect();
        place(&mut pts, &z);
        for c in 0..n {
            let first = (c / GROUP) * GROUP;
            for j in DX..D {
                pts[c * D + j] = pts[first * D + j];
            }
        }
        let mut zt = vec![0.0; D * M];
        scale_inducing(&z, &inv_len, &mut zt);
        let mut xs = vec![0.0; D * n];
        scale_points(&pts, &inv_len, &mut xs);
        Case {
            z,
            inv_len,
            pts,
            zt,
            xs,
        }
    }

    impl Case {
        fn points(&self, kind: KernelKind) -> GroupedPoints<'_> {
            GroupedPoints {
                kind,
                variance: 0.7,
                tau_jitter: 1e-8,
                zt: &self.zt,
                xs: &self.xs,
                d: D,
                shared_from: DX,
                group: GROUP,
            }
        }
    }

    /// The grouped kernel (shared input part computed once per group) against the direct
    /// elementwise formula `σ_f² g(Σ_j (z_j − x_j)²/ℓ_j²)` with libm `exp`.
    #[test]
    fn grouped_cross_cov_matches_direct_formula() {
        let n = 6;
        let c = case(4, n, |_, _| {});
        for kind in [KernelKind::Matern32, KernelKind::SquaredExponential] {
            let (mut k, mut kd, mut shared) = (vec![0.0; M * n], vec![0.0; M * n], vec![0.0; M]);
            cross_cov_grouped(c.points(kind), &mut k, &mut kd, &mut shared);
            for p in 0..n {
                for i in 0..M {
                    let tau: f64 = (0..D)
                        .map(|j| ((c.z[i * D + j] - c.pts[p * D + j]) * c.inv_len[j]).powi(2))
                        .sum();
                    let (g, dg) = match kind {
                        KernelKind::Matern32 => {
                            let r = (3.0 * (tau + 1e-8)).sqrt();
                            ((1.0 + r) * (-r).exp(), -1.5 * (-r).exp())
                        }
                        KernelKind::SquaredExponential => {
                            ((-0.5 * tau).exp(), -0.5 * (-0.5 * tau).exp())
                        }
                    };
                    assert!((k[p * M + i] - 0.7 * g).abs() < 1e-14, "{kind:?} K");
                    assert!((kd[p * M + i] - 0.7 * dg).abs() < 1e-14, "{kind:?} K'");
                }
            }
        }
    }

    /// The `f32` shape against the `f64` kernel: `K` and `σ_f² g'` within `2·2⁻²³ σ_f²`, `K`
    /// within 4 `f32` roundings where it is large, zero where it is below the operand floor
    /// (a far point); the same `K` with and without the derivative.
    #[test]
    fn f32_shape_matches_the_f64_kernel() {
        let n = 7;
        // A far point (first group) and one on the first inducing input (second group).
        let c = case(6, n, |pts, z| {
            pts[..D].iter_mut().for_each(|p| *p = 40.0);
            pts[GROUP * D..(GROUP + 1) * D].copy_from_slice(&z[..D]);
        });
        for kind in [KernelKind::Matern32, KernelKind::SquaredExponential] {
            let (mut k, mut kd, mut shared) = (vec![0.0; M * n], vec![0.0; M * n], vec![0.0; M]);
            cross_cov_grouped(c.points(kind), &mut k, &mut kd, &mut shared);
            let (mut tau, mut e32) = (vec![0.0; M * n], vec![0.0f32; M * n]);
            let (mut k32, mut values) = (vec![0.0f32; M * n], vec![0.0f32; M * n]);
            let points = c.points(kind);
            cross_cov_grouped_f32(points, &mut tau, &mut k32, Some(&mut e32), &mut shared);
            let kd32: Vec<f64> = e32
                .iter()
                .map(|&e| shape_slope(kind) * f64::from(e))
                .collect();
            cross_cov_grouped_f32(points, &mut tau, &mut values, None, &mut shared);
            assert_eq!(values, k32, "{kind:?}: with and without the derivative");
            // The argument's rounding moves `e^{−r}` by `r·2⁻²⁴` relative, and `r e^{−r} ≤ 1/e`:
            // errors are bounded in units of `σ_f²`, and relative ones where `K` is large.
            let eps = f64::from(f32::EPSILON);
            let mut floored = 0;
            for i in 0..M * n {
                let (dk, dkd) = (f64::from(k32[i]) - k[i], kd32[i] - kd[i]);
                if k[i] < F32_OPERAND_FLOOR {
                    assert_eq!(k32[i], 0.0, "{kind:?} {i}");
                    floored += 1;
                }
                assert!(dk.abs() < 2.0 * eps * 0.7, "{kind:?} K {i}: {dk:e}");
                assert!(dkd.abs() < 2.0 * eps * 0.7, "{kind:?} K' {i}: {dkd:e}");
                if k[i] > 0.1 {
                    assert!(dk.abs() / k[i] < 4.0 * eps, "{kind:?} K {i}: {dk:e}");
                }
            }
            assert!(floored > 0, "{kind:?}: the far point reaches the floor");
            let at_z = k32[GROUP * M];
            assert!(
                (at_z - 0.7).abs() < 1e-6,
                "{kind:?}: K at an inducing input"
            );
        }
    }

    #[test]
    fn exp_within_one_ulp_of_libm() {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(3);
        let mut worst = 0;
        let grid = (0..200_000).map(|i| -745.0 + 1454.0 * i as f64 / 200_000.0);
        let small = (0..20_000).map(|i| (i as f64 - 10_000.0) * 1e-5);
        let random = (0..200_000).map(|_| rng.random_range(-40.0..1.0));
        for x in grid
            .chain(small)
            .chain(random)
            .chain([0.0, -0.0, 1e-300, -1e-300])
        {
            let (ours, libm) = (exp(x), x.exp());
            if x >= -708.39 {
                worst = worst.max(ulps(ours, libm));
            } else {
                // Results below 2.23e-308 flush to zero.
                assert_eq!(ours, 0.0, "{x}");
            }
        }
        assert!(worst <= 1, "max error {worst} ulp");
        assert_eq!(exp(-800.0), 0.0);
        assert_eq!(exp(f64::NEG_INFINITY), 0.0);
        assert_eq!(exp(-1e300), 0.0);
        assert_eq!(exp(1e300), exp(709.0));
        assert_eq!(exp(0.0), 1.0);
        assert!(exp(f64::NAN).is_nan());
    }

    #[test]
    fn exp_f32_is_within_f32_rounding_over_the_kernels_range() {
        let mut worst = 0.0f64;
        for i in 0..86_990 {
            let x = -(i as f32) * 1e-3;
            let e = f64::from(exp_f32(x));
            let rel = (e - f64::from(x).exp()).abs() / f64::from(x).exp();
            worst = worst.max(rel);
        }
        // Measured 7.6e-8.
        assert!(worst < 2e-7, "relative error {worst:e}");
        assert_eq!(exp_f32(-200.0), exp_f32(-87.0));
        assert!(exp_f32(-87.0) > 0.0);
        assert_eq!(exp_f32(0.0), 1.0);
        assert!(exp_f32(f32::NAN).is_nan());
    }

    #[test]
    fn matern_shape_matches_closed_form_and_derivative() {
        for &tau in &[0.0, 1e-6, 0.3, 2.0, 9.0] {
            let (g, dg) = KernelKind::Matern32.shape(tau, 0.0);
            let r = (3.0 * tau).sqrt();
            assert!((g - (1.0 + r) * (-r).exp()).abs() < 1e-15);
            if tau > 1e-3 {
                let h = 1e-6;
                let fd = (KernelKind::Matern32.shape(tau + h, 0.0).0
                    - KernelKind::Matern32.shape(tau - h, 0.0).0)
                    / (2.0 * h);
                assert!((fd - dg).abs() < 1e-8, "{fd} {dg}");
            }
            let (g, dg) = KernelKind::SquaredExponential.shape(tau, 0.0);
            assert!((g - (-0.5 * tau).exp()).abs() < 1e-15);
            assert!((dg + 0.5 * g).abs() < 1e-15);
        }
    }
}
