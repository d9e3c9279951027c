//! Elastic-net paths with K-fold cross-validation, as MATLAB's
//! `lasso(X, y, 'Alpha', α, 'CV', K)` and scikit-learn's `enet_path` + fold loop compute them.
//!
//! ## Standardization and intercept
//! With `intercept` on, features and targets are centred on their means; with `standardize`
//! on, each feature is divided by its population standard deviation (ddof 0, as MATLAB's
//! `lasso` does: σ_j = sqrt((1/n) Σ (x_ij − x̄_j)²)). Without an intercept nothing is centred
//! and `standardize` divides by the root mean square sqrt((1/n) Σ x_ij²). Coordinate descent
//! runs on the standardized problem (coefficients `w`, see [`crate::enet`]); coefficients on
//! the original feature scale are b_j = w_j / σ_j with intercept b₀ = ȳ − Σ_j x̄_j b_j.
//! Every training fold is re-centred and re-scaled on its own rows (as MATLAB does).
//!
//! ## λ path and cross-validation
//! λ_max = max_j |x̃_jᵀ ỹ| / (n α) on the full (standardized) data; `n_lambdas` values geometric
//! down to `lambda_min_ratio · λ_max`. Each fold's path uses the same λ. Held-out MSE_k(λ)
//! = (1/n_k) Σ_{i∈k} (y_i − b₀ − x_iᵀ b)²; `cv_mse_mean` is the mean over the K folds and
//! `cv_mse_se` their standard deviation (ddof 1) / √K. `index_min` = argmin of the mean
//! (first on ties); `index_1se` = the largest λ (smallest index) with
//! `mean ≤ mean[index_min] + se[index_min]`.
//!
//! ## Cost
//! Only first and second moments of the data enter, so the rows are read once: per fold the
//! sums Σx, Σy, XᵀX, XᵀY (about the global mean, for accuracy); a training fold's moments are
//! the total minus the held-out fold's, and held-out MSEs are quadratic forms in the held-out
//! moments. Reading 240 640 × 11 rows is O(n p²); the K + 1 paths cost O(n_λ · sweeps · p²).

use rand::SeedableRng;
use rand::seq::SliceRandom;
use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize};

use crate::enet::{CdWorkspace, Convergence, lambda_grid, lambda_max, solve_path};
use crate::error::QsError;

/// How rows are assigned to the K folds.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case", tag = "kind")]
pub enum FoldLayout {
    /// Contiguous blocks in row order, sizes as `np.array_split(range(n), K)`: the first
    /// n mod K folds hold ⌈n/K⌉ rows, the others ⌊n/K⌋. For trajectory-major data this keeps
    /// trajectories (nearly) whole within a fold.
    Contiguous,
    /// A seeded random permutation of the rows (ChaCha8), then split as above: rows of one
    /// trajectory fall in every fold, as MATLAB's `lasso(…, 'CV', K)` partitions them
    /// (the published baseline; [`Default`]: seed 0).
    Random {
        /// Seed of the permutation.
        seed: u64,
    },
}

impl Default for FoldLayout {
    fn default() -> Self {
        Self::Random { seed: 0 }
    }
}

/// Which λ of the path to keep.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
pub enum LambdaRule {
    /// The largest λ whose CV MSE is within one standard error of the minimum (MATLAB's
    /// `Index1SE`; the published baseline).
    #[default]
    #[serde(rename = "1se")]
    OneSe,
    /// The λ of minimum CV MSE (`IndexMinMSE`).
    #[serde(rename = "min")]
    Min,
}

/// Options of [`fit_enet_cv`]. [`Default`] is MATLAB's `lasso(X, y, 'Alpha', 0.75, 'CV', 10)`
/// with the one-standard-error rule and contiguous folds.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct EnetOptions {
    /// α ∈ (0, 1]: weight of the l1 penalty (1 = lasso).
    pub l1_ratio: f64,
    /// Number of λ on the path.
    pub n_lambdas: usize,
    /// λ_min / λ_max ∈ (0, 1).
    pub lambda_min_ratio: f64,
    /// Scale features to unit population std (ddof 0) before fitting.
    pub standardize: bool,
    /// Fit an intercept (centre features and targets).
    pub intercept: bool,
    /// Number of cross-validation folds K ≥ 2.
    pub n_folds: usize,
    /// Fold layout.
    pub folds: FoldLayout,
    /// λ selection rule.
    pub rule: LambdaRule,
    /// Coordinate descent stops when no standardized coefficient moves by more than this.
    pub tol: f64,
    /// Sweep limit per λ.
    pub max_sweeps: usize,
}

impl Default for EnetOptions {
    fn default() -> Self {
        Self {
            l1_ratio: 0.75,
            n_lambdas: 100,
            lambda_min_ratio: 1e-4,
            standardize: true,
            intercept: true,
            n_folds: 10,
            folds: FoldLayout::default(),
            rule: LambdaRule::OneSe,
            tol: 1e-10,
            max_sweeps: 100_000,
        }
    }
}

impl EnetOptions {
    /// Checks every option's range.
    ///
    /// # Errors
    /// [`QsError::InvalidOption`] naming the first bad option.
    pub fn validate(&self) -> Result<(), QsError> {
        let bad = |name, value: String, reason: &str| {
            Err(QsError::InvalidOption {
                name,
                value,
                reason: reason.to_string(),
            })
        };
        if !(self.l1_ratio > 0.0 && self.l1_ratio <= 1.0) {
            return bad("l1_ratio", self.l1_ratio.to_string(), "must be in (0, 1]");
        }
        if self.n_lambdas == 0 {
            return bad("n_lambdas", "0".into(), "must be at least 1");
        }
        if !(self.lambda_min_ratio > 0.0 && self.lambda_min_ratio < 1.0) {
            return bad(
                "lambda_min_ratio",
                self.lambda_min_ratio.to_string(),
                "must be in (0, 1)",
            );
        }
        if self.n_folds < 2 {
            return bad("n_folds", self.n_folds.to_string(), "must be at least 2");
        }
        if !(self.tol > 0.0 && self.tol.is_finite()) {
            return bad("tol", self.tol.to_string(), "must be positive and finite");
        }
        if self.max_sweeps == 0 {
            return bad("max_sweeps", "0".into(), "must be at least 1");
        }
        Ok(())
    }
}

/// Row-major columns with names: `data` is n × `names.len()`.
#[derive(Debug, Clone, Copy)]
pub struct Columns<'a> {
    /// Column names.
    pub names: &'a [String],
    /// Values, row-major.
    pub data: &'a [f64],
}

/// The path, CV curve and chosen λ of one target.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TargetPath {
    /// Target name.
    pub name: String,
    /// The λ path, descending.
    pub lambdas: Vec<f64>,
    /// Coefficients w on the standardized features, one row of p per λ.
    pub coef_path_standardized: Vec<Vec<f64>>,
    /// Coefficients b on the original feature scale (b_j = w_j / σ_j), one row per λ.
    pub coef_path: Vec<Vec<f64>>,
    /// Intercepts b₀ = ȳ − Σ x̄_j b_j per λ (0 without intercept).
    pub intercept_path: Vec<f64>,
    /// Mean held-out MSE over folds, per λ.
    pub cv_mse_mean: Vec<f64>,
    /// Standard error (ddof 1, / √K) of the held-out MSE, per λ.
    pub cv_mse_se: Vec<f64>,
    /// Index of the minimum CV MSE.
    pub index_min: usize,
    /// Index of the one-standard-error λ.
    pub index_1se: usize,
    /// Index chosen by the rule.
    pub index_chosen: usize,
    /// Coordinate-descent sweeps over all K + 1 paths.
    pub sweeps: usize,
    /// λ values (over all K + 1 paths) that hit `max_sweeps` before `tol`.
    pub unconverged: usize,
}

impl TargetPath {
    /// λ at the chosen index.
    pub fn lambda(&self) -> f64 {
        self.lambdas[self.index_chosen]
    }
    /// Original-scale coefficients at the chosen index.
    pub fn coef(&self) -> &[f64] {
        &self.coef_path[self.index_chosen]
    }
    /// Standardized-scale coefficients at the chosen index.
    pub fn coef_standardized(&self) -> &[f64] {
        &self.coef_path_standardized[self.index_chosen]
    }
    /// Intercept at the chosen index.
    pub fn intercept(&self) -> f64 {
        self.intercept_path[self.index_chosen]
    }
}

/// Result of [`fit_enet_cv`]: the standardization of the full data and one path per target.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct EnetCvFit {
    /// Feature names, in column order.
    pub feature_names: Vec<String>,
    /// Rows fitted.
    pub n_rows: usize,
    /// x̄_j subtracted from each feature (0 without intercept).
    pub feature_center: Vec<f64>,
    /// σ_j dividing each centred feature (1 without standardization).
    pub feature_scale: Vec<f64>,
    /// ȳ of each target (0 without intercept).
    pub target_center: Vec<f64>,
    /// Held-out row count of each fold.
    pub fold_sizes: Vec<usize>,
    /// One path per target.
    pub targets: Vec<TargetPath>,
}

/// Row indices of each fold (see [`FoldLayout`]).
///
/// # Errors
/// [`QsError::TooFewRows`] if `n_rows < k`.
pub fn fold_rows(n_rows: usize, k: usize, layout: FoldLayout) -> Result<Vec<Vec<usize>>, QsError> {
    if n_rows < k || k < 2 {
        return Err(QsError::TooFewRows {
            rows: n_rows,
            folds: k,
        });
    }
    let mut order: Vec<usize> = (0..n_rows).collect();
    if let FoldLayout::Random { seed } = layout {
        order.shuffle(&mut ChaCha8Rng::seed_from_u64(seed));
    }
    let (base, extra) = (n_rows / k, n_rows % k);
    let mut start = 0;
    Ok((0..k)
        .map(|f| {
            let len = base + usize::from(f < extra);
            let mut rows = order[start..start + len].to_vec();
            rows.sort_unstable();
            start += len;
            rows
        })
        .collect())
}

/// Sums of a set of rows about a fixed shift: n, Σx, Σy, XᵀX (p × p), XᵀY (p × m), Σy².
#[derive(Debug, Clone)]
struct Moments {
    n: usize,
    sx: Vec<f64>,
    sy: Vec<f64>,
    xtx: Vec<f64>,
    xty: Vec<f64>,
    yty: Vec<f64>,
}

impl Moments {
    fn zeros(p: usize, m: usize) -> Self {
        Self {
            n: 0,
            sx: vec![0.0; p],
            sy: vec![0.0; m],
            xtx: vec![0.0; p * p],
            xty: vec![0.0; p * m],
            yty: vec![0.0; m],
        }
    }

    /// Accumulates the rows `rows` of (x − shift_x, y − shift_y); `xs`, `ys` are scratch.
    #[allow(clippy::too_many_arguments)]
    fn accumulate(
        &mut self,
        x: &[f64],
        y: &[f64],
        shift_x: &[f64],
        shift_y: &[f64],
        rows: &[usize],
        xs: &mut [f64],
        ys: &mut [f64],
    ) {
        let (p, m) = (shift_x.len(), shift_y.len());
        for &i in rows {
            for (j, v) in xs.iter_mut().enumerate() {
                *v = x[i * p + j] - shift_x[j];
            }
            for (t, v) in ys.iter_mut().enumerate() {
                *v = y[i * m + t] - shift_y[t];
            }
            for a in 0..p {
                let xa = xs[a];
                self.sx[a] += xa;
                let row = &mut self.xtx[a * p..(a + 1) * p];
                for b in a..p {
                    row[b] += xa * xs[b];
                }
                let row = &mut self.xty[a * m..(a + 1) * m];
                for (r, yv) in row.iter_mut().zip(ys.iter()) {
                    *r += xa * yv;
                }
            }
            for ((sy, yty), yv) in self.sy.iter_mut().zip(&mut self.yty).zip(ys.iter()) {
                *sy += yv;
                *yty += yv * yv;
            }
        }
        self.n += rows.len();
        for a in 0..p {
            for b in 0..a {
                self.xtx[a * p + b] = self.xtx[b * p + a];
            }
        }
    }

    fn combine(&self, other: &Self, sign: f64) -> Self {
        let f = |a: &[f64], b: &[f64]| a.iter().zip(b).map(|(u, v)| u + sign * v).collect();
        Self {
            n: if sign > 0.0 {
                self.n + other.n
            } else {
                self.n - other.n
            },
            sx: f(&self.sx, &other.sx),
            sy: f(&self.sy, &other.sy),
            xtx: f(&self.xtx, &other.xtx),
            xty: f(&self.xty, &other.xty),
            yty: f(&self.yty, &other.yty),
        }
    }
}

/// The standardized problem of one training set (in shifted coordinates).
#[derive(Debug, Clone)]
struct Standardized {
    mean_x: Vec<f64>,
    mean_y: Vec<f64>,
    scale: Vec<f64>,
    /// G = X̃ᵀX̃/n, p × p.
    gram: Vec<f64>,
    /// c = X̃ᵀỸ/n, p × m.
    c: Vec<f64>,
}

fn standardize(
    mo: &Moments,
    opts: &EnetOptions,
    names: &[String],
    fold: Option<usize>,
) -> Result<Standardized, QsError> {
    let (p, m) = (mo.sx.len(), mo.sy.len());
    let n = mo.n as f64;
    let (mean_x, mean_y): (Vec<f64>, Vec<f64>) = if opts.intercept {
        (
            mo.sx.iter().map(|s| s / n).collect(),
            mo.sy.iter().map(|s| s / n).collect(),
        )
    } else {
        (vec![0.0; p], vec![0.0; m])
    };
    let mut cxx = vec![0.0; p * p];
    for a in 0..p {
        for b in 0..p {
            cxx[a * p + b] = mo.xtx[a * p + b] - n * mean_x[a] * mean_x[b];
        }
    }
    let mut scale = vec![1.0; p];
    for j in 0..p {
        let var = cxx[j * p + j] / n;
        let degenerate = var <= 0.0 || (opts.intercept && var <= 1e-14 * mean_x[j] * mean_x[j]);
        if (opts.standardize || opts.intercept) && degenerate {
            return Err(QsError::ConstantFeature {
                name: names[j].clone(),
                value: f64::NAN,
                where_: fold.map_or(String::new(), |k| {
                    format!(" in the training rows of fold {k}")
                }),
            });
        }
        if opts.standardize {
            scale[j] = var.sqrt();
        }
    }
    let gram = (0..p * p)
        .map(|ab| cxx[ab] / (n * scale[ab / p] * scale[ab % p]))
        .collect();
    let c = (0..p * m)
        .map(|jt| {
            let (j, t) = (jt / m, jt % m);
            (mo.xty[jt] - n * mean_x[j] * mean_y[t]) / (n * scale[j])
        })
        .collect();
    Ok(Standardized {
        mean_x,
        mean_y,
        scale,
        gram,
        c,
    })
}

/// `f(0), …, f(n − 1)` on the caller's rayon pool, in index order.
fn par_map<T: Send>(n: usize, f: impl Fn(usize) -> T + Sync + Send) -> Vec<T> {
    use rayon::prelude::*;
    (0..n).into_par_iter().map(f).collect()
}

fn check_columns(c: &Columns, kind: &'static str) -> Result<usize, QsError> {
    let p = c.names.len();
    if p == 0 {
        return Err(QsError::Shape {
            what: format!("{kind} columns"),
            found: 0,
            expected: 1,
        });
    }
    if c.data.len() % p != 0 {
        return Err(QsError::Shape {
            what: format!("{kind} values (row-major, {p} columns)"),
            found: c.data.len(),
            expected: c.data.len() / p * p,
        });
    }
    if let Some(i) = c.data.iter().position(|v| !v.is_finite()) {
        return Err(QsError::NonFinite {
            kind,
            name: c.names[i % p].clone(),
            row: i / p,
            value: c.data[i],
        });
    }
    Ok(c.data.len() / p)
}

/// Fits one elastic-net path per target column, with K-fold cross-validation, and picks the
/// λ of `opts.rule` (see the module documentation for the exact definitions).
///
/// `features` is n × p, `targets` n × m, both row-major.
///
/// # Errors
/// Invalid options, shape mismatch, non-finite values (naming column and row), a constant
/// feature (naming it), fewer rows than folds, or a target with λ_max = 0.
pub fn fit_enet_cv(
    features: Columns,
    targets: Columns,
    opts: &EnetOptions,
) -> Result<EnetCvFit, QsError> {
    opts.validate()?;
    let n = check_columns(&features, "feature")?;
    let n_y = check_columns(&targets, "target")?;
    let (p, m) = (features.names.len(), targets.names.len());
    if n_y != n {
        return Err(QsError::Shape {
            what: "target rows".into(),
            found: n_y,
            expected: n,
        });
    }
    let (x, y) = (features.data, targets.data);
    if opts.intercept || opts.standardize {
        for j in 0..p {
            let first = x[j];
            let constant = (0..n).all(|i| x[i * p + j] == first);
            if constant && (opts.intercept || first == 0.0) {
                return Err(QsError::ConstantFeature {
                    name: features.names[j].clone(),
                    value: first,
                    where_: String::new(),
                });
            }
        }
    }
    let folds = fold_rows(n, opts.n_folds, opts.folds)?;
    let k = folds.len();

    // Shift by the global means (exact moments are shift-invariant once centred).
    let mut shift_x = vec![0.0; p];
    let mut shift_y = vec![0.0; m];
    if opts.intercept {
        for i in 0..n {
            shift_x
                .iter_mut()
                .zip(&x[i * p..])
                .for_each(|(s, v)| *s += v);
            shift_y
                .iter_mut()
                .zip(&y[i * m..])
                .for_each(|(s, v)| *s += v);
        }
        shift_x.iter_mut().for_each(|s| *s /= n as f64);
        shift_y.iter_mut().for_each(|s| *s /= n as f64);
    }
    let held_out: Vec<Moments> = par_map(k, |f| {
        let mut mo = Moments::zeros(p, m);
        let (mut xs, mut ys) = (vec![0.0; p], vec![0.0; m]);
        mo.accumulate(x, y, &shift_x, &shift_y, &folds[f], &mut xs, &mut ys);
        mo
    });
    let total = held_out
        .iter()
        .fold(Moments::zeros(p, m), |acc, mo| acc.combine(mo, 1.0));

    // Fit 0: all rows; fit f ≥ 1: all rows but fold f − 1.
    let problems = par_map(k + 1, |f| match f {
        0 => standardize(&total, opts, features.names, None),
        f => standardize(
            &total.combine(&held_out[f - 1], -1.0),
            opts,
            features.names,
            Some(f - 1),
        ),
    })
    .into_iter()
    .collect::<Result<Vec<_>, _>>()?;

    let full = &problems[0];
    let mut grids = Vec::with_capacity(m);
    for t in 0..m {
        let c_t: Vec<f64> = (0..p).map(|j| full.c[j * m + t]).collect();
        let lmax = lambda_max(&c_t, opts.l1_ratio);
        if !(lmax > 0.0 && lmax.is_finite()) {
            return Err(QsError::DegenerateTarget {
                name: targets.names[t].clone(),
            });
        }
        grids.push(lambda_grid(lmax, opts.lambda_min_ratio, opts.n_lambdas));
    }

    let conv = Convergence {
        tol: opts.tol,
        max_sweeps: opts.max_sweeps,
    };
    let nl = opts.n_lambdas;
    // Task (f, t): path of fit f for target t; for folds also the held-out MSE per λ.
    let solved = par_map((k + 1) * m, |task| {
        let (f, t) = (task / m, task % m);
        let pr = &problems[f];
        let c_t: Vec<f64> = (0..p).map(|j| pr.c[j * m + t]).collect();
        let mut w = vec![0.0; nl * p];
        let st = solve_path(
            &pr.gram,
            &c_t,
            &grids[t],
            opts.l1_ratio,
            conv,
            &mut CdWorkspace::new(p),
            &mut w,
        );
        let mse = (f > 0).then(|| {
            let h = &held_out[f - 1];
            let mut b = vec![0.0; p];
            (0..nl)
                .map(|l| {
                    let b0 = original_scale(pr, t, &w[l * p..(l + 1) * p], &mut b);
                    held_out_sse(h, t, &b, b0) / h.n as f64
                })
                .collect::<Vec<f64>>()
        });
        (w, st, mse)
    });

    let mut out = Vec::with_capacity(m);
    for t in 0..m {
        let (w_full, _, _) = &solved[t];
        let mut coef_path_standardized = Vec::with_capacity(nl);
        let mut coef_path = Vec::with_capacity(nl);
        let mut intercept_path = Vec::with_capacity(nl);
        for l in 0..nl {
            let w = &w_full[l * p..(l + 1) * p];
            let mut b = vec![0.0; p];
            let b0 = original_scale(full, t, w, &mut b);
            let b0 = if opts.intercept {
                b0 + shift_y[t] - (0..p).map(|j| shift_x[j] * b[j]).sum::<f64>()
            } else {
                0.0
            };
            coef_path_standardized.push(w.to_vec());
            coef_path.push(b);
            intercept_path.push(b0);
        }
        let mut mean = vec![0.0; nl];
        let mut se = vec![0.0; nl];
        for l in 0..nl {
            let v: Vec<f64> = (1..=k)
                .map(|f| solved[f * m + t].2.as_ref().map_or(f64::NAN, |e| e[l]))
                .collect();
            let mu = v.iter().sum::<f64>() / k as f64;
            let var = v.iter().map(|e| (e - mu) * (e - mu)).sum::<f64>() / (k - 1) as f64;
            mean[l] = mu;
            se[l] = (var / k as f64).sqrt();
        }
        let index_min = (0..nl).fold(0, |best, l| if mean[l] < mean[best] { l } else { best });
        let bound = mean[index_min] + se[index_min];
        let index_1se = (0..nl).find(|&l| mean[l] <= bound).unwrap_or(index_min);
        let (sweeps, unconverged) = (0..=k).fold((0, 0), |(s, u), f| {
            let st = solved[f * m + t].1;
            (s + st.sweeps, u + st.unconverged)
        });
        out.push(TargetPath {
            name: targets.names[t].clone(),
            lambdas: grids[t].clone(),
            coef_path_standardized,
            coef_path,
            intercept_path,
            cv_mse_mean: mean,
            cv_mse_se: se,
            index_min,
            index_1se,
            index_chosen: match opts.rule {
                LambdaRule::OneSe => index_1se,
                LambdaRule::Min => index_min,
            },
            sweeps,
            unconverged,
        });
    }
    Ok(EnetCvFit {
        feature_names: features.names.to_vec(),
        n_rows: n,
        feature_center: (0..p).map(|j| full.mean_x[j] + shift_x[j]).collect(),
        feature_scale: full.scale.clone(),
        target_center: (0..m).map(|t| full.mean_y[t] + shift_y[t]).collect(),
        fold_sizes: folds.iter().map(Vec::len).collect(),
        targets: out,
    })
}

/// b = w / σ into `b`; returns the intercept in the shifted coordinates, ȳ − x̄ᵀb.
fn original_scale(pr: &Standardized, t: usize, w: &[f64], b: &mut [f64]) -> f64 {
    for (j, bj) in b.iter_mut().enumerate() {
        *bj = w[j] / pr.scale[j];
    }
    pr.mean_y[t]
        - pr.mean_x
            .iter()
            .zip(b.iter())
            .map(|(a, c)| a * c)
            .sum::<f64>()
}

/// Σ (y − b₀ − xᵀb)² over the rows of `h` (shifted coordinates), expanded in its moments.
fn held_out_sse(h: &Moments, t: usize, b: &[f64], b0: f64) -> f64 {
    let (p, m) = (b.len(), h.sy.len());
    let mut btxtxb = 0.0;
    let mut btxty = 0.0;
    let mut btsx = 0.0;
    for a in 0..p {
        let row = &h.xtx[a * p..(a + 1) * p];
        btxtxb += b[a] * row.iter().zip(b).map(|(g, v)| g * v).sum::<f64>();
        btxty += b[a] * h.xty[a * m + t];
        btsx += b[a] * h.sx[a];
    }
    let sse = h.yty[t] - 2.0 * btxty - 2.0 * b0 * h.sy[t]
        + btxtxb
        + 2.0 * b0 * btsx
        + h.n as f64 * b0 * b0;
    sse.max(0.0)
}
