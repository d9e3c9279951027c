//! Free point vortices: storage (allocated once), induced velocities with a Vatistas (n = 2)
//! core, convection, decay, far-field deletion and Spalart amalgamation.
//!
//! Velocity induced at point P by a counter-clockwise vortex Γ (m²/s) at P_k, d = P − P_k:
//!
//! u = Γ/(2π) · (−d_z, d_x) / sqrt(r_c⁴ + |d|⁴)   (m/s).
//!
//! Each vortex has its own core radius r_c,k (it grows by viscous diffusion, see
//! [`LdvmParams::core_growth_reynolds`](super::LdvmParams::core_growth_reynolds)); between two free
//! vortices the pair core is r_c² = (r_c,j² + r_c,k²)/2.

use std::f64::consts::PI;

/// Pose of the plate: leading edge, chord unit vector t̂ (LE → TE) and normal n̂.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub(crate) struct PlateFrame {
    pub le: [f64; 2],
    pub t: [f64; 2],
    pub n: [f64; 2],
}

impl PlateFrame {
    /// Chord and normal coordinates (m) of the point (x, z) relative to the LE.
    pub fn local(&self, x: f64, z: f64) -> (f64, f64) {
        let (dx, dz) = (x - self.le[0], z - self.le[1]);
        (
            dx * self.t[0] + dz * self.t[1],
            dx * self.n[0] + dz * self.n[1],
        )
    }
}

/// Where a free vortex was shed.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum VortexKind {
    /// Trailing-edge vortex.
    Tev,
    /// Leading-edge vortex.
    Lev,
}

/// The free vortices (structure of arrays, capacity fixed at construction).
#[derive(Debug, Clone)]
pub struct Wake {
    x: Vec<f64>,
    z: Vec<f64>,
    gamma: Vec<f64>,
    /// Core radius squared r_c² (m²) of each vortex.
    core2: Vec<f64>,
    kind: Vec<VortexKind>,
    u: Vec<f64>,
    w: Vec<f64>,
    keep: Vec<bool>,
    best: Vec<(f64, u32, u32)>,
    /// Amalgamation workspace: distance to the plate d (m), weight (D0 + d)^{−3/2} and the
    /// measures of one vortex's pairs.
    plate_dist: Vec<f64>,
    merge_weight: Vec<f64>,
    pair_measure: Vec<f64>,
    /// Pair-loop workspace of `compute_velocities`.
    pair_fx: Vec<f64>,
    pair_fz: Vec<f64>,
    /// Index of the newest TEV / LEV (protected from merging; used to place the next one).
    pub(crate) last_tev: Option<usize>,
    pub(crate) last_lev: Option<usize>,
    /// Circulation of the vortices removed from the plane (far-field deletion, last-resort
    /// removal, `clear_wake`) (m²/s): it still counts in Kelvin's theorem, as vortices at
    /// infinity that induce no velocity, so a deletion does not force the plate to shed.
    far_circulation: f64,
    /// r_c² (m²) of a newly shed vortex.
    new_core2: f64,
}

/// Lanes of the vectorized loops: the symmetric pair loop's `LANES` independent partial sums (a
/// fixed summation order: deterministic results) and the bound sheet's points per block.
pub(crate) const LANES: usize = 8;

/// The velocity (m/s) at (px, pz) induced by vortices (xs, zs, gs).
#[inline(always)]
pub(crate) fn induced_at(
    px: f64,
    pz: f64,
    xs: &[f64],
    zs: &[f64],
    gs: &[f64],
    rc4: f64,
) -> (f64, f64) {
    let (mut u, mut w) = (0.0, 0.0);
    for ((&x, &z), &g) in xs.iter().zip(zs).zip(gs) {
        let dx = px - x;
        let dz = pz - z;
        let d2 = dx * dx + dz * dz;
        let f = g / (rc4 + d2 * d2).sqrt();
        u -= dz * f;
        w += dx * f;
    }
    (u / (2.0 * PI), w / (2.0 * PI))
}

impl Wake {
    /// Empty wake able to hold `capacity` vortices without reallocating; new vortices get the
    /// core radius `core_radius_m` (m).
    pub fn with_capacity(capacity: usize, core_radius_m: f64) -> Self {
        Self {
            x: Vec::with_capacity(capacity),
            z: Vec::with_capacity(capacity),
            gamma: Vec::with_capacity(capacity),
            core2: Vec::with_capacity(capacity),
            kind: Vec::with_capacity(capacity),
            u: Vec::with_capacity(capacity),
            w: Vec::with_capacity(capacity),
            keep: Vec::with_capacity(capacity),
            best: Vec::with_capacity(capacity),
            plate_dist: Vec::with_capacity(capacity),
            merge_weight: Vec::with_capacity(capacity),
            pair_measure: Vec::with_capacity(capacity),
            pair_fx: Vec::with_capacity(capacity),
            pair_fz: Vec::with_capacity(capacity),
            last_tev: None,
            last_lev: None,
            far_circulation: 0.0,
            new_core2: core_radius_m * core_radius_m,
        }
    }

    /// Removes every vortex (keeps the storage).
    pub fn clear(&mut self) {
        self.x.clear();
        self.z.clear();
        self.gamma.clear();
        self.core2.clear();
        self.kind.clear();
        self.u.clear();
        self.w.clear();
        self.last_tev = None;
        self.last_lev = None;
        self.far_circulation = 0.0;
    }

    /// Removes every vortex to infinity: their circulation stays in Kelvin's balance.
    pub(crate) fn remove_all_to_far(&mut self) {
        let far = self.total_circulation();
        self.clear();
        self.far_circulation = far;
    }

    /// Number of free vortices.
    pub fn len(&self) -> usize {
        self.x.len()
    }

    /// True when there are no free vortices.
    pub fn is_empty(&self) -> bool {
        self.x.is_empty()
    }

    /// Storage capacity (vortices).
    pub fn capacity(&self) -> usize {
        self.x.capacity()
    }

    /// X positions (m).
    pub fn x_m(&self) -> &[f64] {
        &self.x
    }

    /// Z positions (m).
    pub fn z_m(&self) -> &[f64] {
        &self.z
    }

    /// Counter-clockwise circulations Γ (m²/s).
    pub fn gamma_m2_s(&self) -> &[f64] {
        &self.gamma
    }

    /// Origins of the vortices.
    pub fn kinds(&self) -> &[VortexKind] {
        &self.kind
    }

    /// Σ Γ of the free vortices, including those removed to infinity (m²/s).
    pub fn total_circulation(&self) -> f64 {
        self.gamma.iter().sum::<f64>() + self.far_circulation
    }

    /// Circulation of the vortices removed to infinity (m²/s).
    pub fn far_circulation(&self) -> f64 {
        self.far_circulation
    }

    /// Core radii r_c (m).
    pub fn core_radii_m(&self) -> impl Iterator<Item = f64> + '_ {
        self.core2.iter().map(|c2| c2.sqrt())
    }

    /// Velocity (m/s) induced at (px, pz) by all free vortices.
    pub fn velocity_at(&self, px: f64, pz: f64) -> (f64, f64) {
        let (mut u, mut w) = (0.0, 0.0);
        self.velocities_at(
            &[px],
            &[pz],
            std::slice::from_mut(&mut u),
            std::slice::from_mut(&mut w),
        );
        (u, w)
    }

    /// Velocities (m/s) induced by all free vortices at the points (px, pz), written to (u, w);
    /// each point's sum runs over the vortices in order. The loop runs over the
    /// vortices outside and over the points inside, so the inner loop has no reduction and
    /// vectorizes.
    pub fn velocities_at(&self, px: &[f64], pz: &[f64], u: &mut [f64], w: &mut [f64]) {
        let n = px.len();
        assert!(
            pz.len() == n && u.len() == n && w.len() == n,
            "point slices differ in length"
        );
        u.fill(0.0);
        w.fill(0.0);
        for (((&x, &z), &g), &c2) in self.x.iter().zip(&self.z).zip(&self.gamma).zip(&self.core2) {
            let rc4 = c2 * c2;
            for (((&pxk, &pzk), uk), wk) in px.iter().zip(pz).zip(u.iter_mut()).zip(w.iter_mut()) {
                let dx = pxk - x;
                let dz = pzk - z;
                let d2 = dx * dx + dz * dz;
                let f = g / (rc4 + d2 * d2).sqrt();
                *uk -= dz * f;
                *wk += dx * f;
            }
        }
        for (uk, wk) in u.iter_mut().zip(w.iter_mut()) {
            *uk /= 2.0 * PI;
            *wk /= 2.0 * PI;
        }
    }

    /// Appends a vortex; returns its index. The caller guarantees `len() < capacity()`.
    pub(crate) fn push(&mut self, x: f64, z: f64, gamma: f64, kind: VortexKind) -> usize {
        debug_assert!(self.len() < self.capacity());
        self.x.push(x);
        self.z.push(z);
        self.gamma.push(gamma);
        self.core2.push(self.new_core2);
        self.kind.push(kind);
        self.u.push(0.0);
        self.w.push(0.0);
        let i = self.x.len() - 1;
        match kind {
            VortexKind::Tev => self.last_tev = Some(i),
            VortexKind::Lev => self.last_lev = Some(i),
        }
        i
    }

    /// Position of vortex `i`.
    pub(crate) fn pos(&self, i: usize) -> (f64, f64) {
        (self.x[i], self.z[i])
    }

    /// Sets (u, w) of every vortex to the velocity induced by the other free vortices plus that
    /// of the bound vortex sheet, which `sheet(x, z, u, w)` writes for the points (x, z).
    /// O(N²/2 + N·cost(sheet)).
    pub(crate) fn compute_velocities(
        &mut self,
        sheet: impl Fn(&[f64], &[f64], &mut [f64], &mut [f64]),
    ) {
        let n = self.len();
        sheet(&self.x, &self.z, &mut self.u, &mut self.w);
        let inv2pi = 1.0 / (2.0 * PI);
        let (xs, zs, gs) = (&self.x[..n], &self.z[..n], &self.gamma[..n]);
        let cs = &self.core2[..n];
        let (us, ws) = (&mut self.u[..n], &mut self.w[..n]);
        self.pair_fx.resize(n, 0.0);
        self.pair_fz.resize(n, 0.0);
        for i in 0..n {
            let (xi, zi, gi, ci) = (xs[i], zs[i], gs[i], cs[i]);
            // j > i: d·f/Γ_j (velocity at i per unit Γ_j, rotated) and the velocity at j from i
            let (fx, fz) = (&mut self.pair_fx[i + 1..n], &mut self.pair_fz[i + 1..n]);
            let (ut, wt) = (&mut us[i + 1..], &mut ws[i + 1..]);
            for ((((((&xj, &zj), &cj), fxj), fzj), uj), wj) in xs[i + 1..]
                .iter()
                .zip(&zs[i + 1..])
                .zip(&cs[i + 1..])
                .zip(fx.iter_mut())
                .zip(fz.iter_mut())
                .zip(ut.iter_mut())
                .zip(wt.iter_mut())
            {
                let (dx, dz) = (xi - xj, zi - zj);
                let d2 = dx * dx + dz * dz;
                let rc2 = 0.5 * (ci + cj);
                let f = inv2pi / (rc2 * rc2 + d2 * d2).sqrt();
                (*fxj, *fzj) = (dx * f, dz * f);
                *uj += *fzj * gi;
                *wj -= *fxj * gi;
            }
            // velocity at i: Σ_j Γ_j (−fz, fx) in LANES partial sums
            let gt = &gs[i + 1..];
            let (mut ul, mut wl) = ([0.0; LANES], [0.0; LANES]);
            let (fxc, fzc, gc) = (
                fx.chunks_exact(LANES),
                fz.chunks_exact(LANES),
                gt.chunks_exact(LANES),
            );
            let (fxr, fzr, gr) = (fxc.remainder(), fzc.remainder(), gc.remainder());
            for ((a, b), g) in fxc.zip(fzc).zip(gc) {
                for k in 0..LANES {
                    ul[k] -= b[k] * g[k];
                    wl[k] += a[k] * g[k];
                }
            }
            let (mut ui, mut wi) = (ul.iter().sum::<f64>(), wl.iter().sum::<f64>());
            for ((a, b), g) in fxr.iter().zip(fzr).zip(gr) {
                ui += -(b * g);
                wi += a * g;
            }
            us[i] += ui;
            ws[i] += wi;
        }
    }

    /// Sets every vortex's velocity to zero (a frozen wake).
    pub(crate) fn hold_still(&mut self) {
        let n = self.len();
        self.u[..n].fill(0.0);
        self.w[..n].fill(0.0);
    }

    /// Moves every vortex by its stored velocity times `dt_s` (forward Euler). A vortex that
    /// would pass through the plate (its normal coordinate changes sign between the plate pose
    /// `before` and `after` while its chord coordinate stays within [0, c]) is mirrored back to
    /// its side: the discrete sheet cannot stop a vortex closer to the plate than its resolution.
    pub(crate) fn convect(&mut self, dt_s: f64, before: &PlateFrame, after: &PlateFrame, c: f64) {
        for i in 0..self.len() {
            let (x0, z0) = before.local(self.x[i], self.z[i]);
            self.x[i] += self.u[i] * dt_s;
            self.z[i] += self.w[i] * dt_s;
            let (x1, z1) = after.local(self.x[i], self.z[i]);
            if z0 * z1 < 0.0 && (0.0..=c).contains(&x0) && (0.0..=c).contains(&x1) {
                self.x[i] -= 2.0 * z1 * after.n[0];
                self.z[i] -= 2.0 * z1 * after.n[1];
            }
        }
    }

    /// Adds `d_core2_m2` to every core radius squared (viscous diffusion over a step).
    pub(crate) fn grow_cores(&mut self, d_core2_m2: f64) {
        for c2 in &mut self.core2 {
            *c2 += d_core2_m2;
        }
    }

    /// Multiplies TEV circulations by `f_tev` and LEV circulations by `f_lev`.
    pub(crate) fn decay(&mut self, f_tev: f64, f_lev: f64) {
        for (g, k) in self.gamma.iter_mut().zip(&self.kind) {
            *g *= match k {
                VortexKind::Tev => f_tev,
                VortexKind::Lev => f_lev,
            };
        }
    }

    /// Removes to infinity every vortex farther than sqrt(r2_max) from (px, pz); then compacts.
    pub(crate) fn delete_far(&mut self, px: f64, pz: f64, r2_max: f64) {
        self.keep.clear();
        let mut any = false;
        for i in 0..self.len() {
            let d2 = (self.x[i] - px).powi(2) + (self.z[i] - pz).powi(2);
            let k = d2 <= r2_max;
            if !k {
                self.far_circulation += self.gamma[i];
            }
            any |= !k;
            self.keep.push(k);
        }
        if any {
            self.compact();
        }
    }

    /// Spalart amalgamation (see [`MergeParams`](super::MergeParams)); `v0_dim` = V0 in 1/s,
    /// `d0_m` = D0 in m, distances d measured to the plate segment `le`–`te`. Merges pairs below
    /// the threshold (only vortices farther than `near_m` from the plate), then more pairs
    /// (smallest measure first, any distance) while the count exceeds `target`. Never merges the
    /// newest TEV/LEV, nor a pair whose merged position would be closer to the plate than both
    /// (a pair on opposite sides of the plate). Conserves Σ Γ.
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn amalgamate(
        &mut self,
        le: [f64; 2],
        te: [f64; 2],
        d0_m: f64,
        near_m: f64,
        v0_dim: f64,
        target: usize,
    ) {
        let n = self.len();
        if n < 2 {
            return;
        }
        let seg = [te[0] - le[0], te[1] - le[1]];
        let seg2 = (seg[0] * seg[0] + seg[1] * seg[1]).max(f64::MIN_POSITIVE);
        let dist = |x: f64, z: f64| {
            let s = (((x - le[0]) * seg[0] + (z - le[1]) * seg[1]) / seg2).clamp(0.0, 1.0);
            let (dx, dz) = (x - le[0] - s * seg[0], z - le[1] - s * seg[1]);
            (dx * dx + dz * dz).sqrt()
        };
        let protected = |i: usize, s: &Self| s.last_tev == Some(i) || s.last_lev == Some(i);
        let forced = n > target;
        // per vortex: distance to the plate and the weight (D0 + d)^{−3/2}, infinite for a
        // vortex that may not merge (the newest TEV/LEV; near the plate unless forced), so that
        // its measure is ∞ (or NaN), never below the best
        self.plate_dist.clear();
        self.merge_weight.clear();
        for i in 0..n {
            let d = dist(self.x[i], self.z[i]);
            let e = d0_m + d;
            let eligible = !protected(i, self) && (forced || d >= near_m);
            self.plate_dist.push(d);
            self.merge_weight.push(if eligible {
                1.0 / (e * e.sqrt())
            } else {
                f64::INFINITY
            });
        }
        self.pair_measure.clear();
        self.pair_measure.resize(n, f64::INFINITY);
        self.best.clear();
        for i in 0..n {
            let (xi, zi, gi, wi) = (self.x[i], self.z[i], self.gamma[i], self.merge_weight[i]);
            if wi == f64::INFINITY {
                continue;
            }
            // the merge measure of (i, j) for every j > i (vectorized), then the first smallest
            // that does not cross the plate
            let (xs, zs, gs) = (&self.x[i + 1..n], &self.z[i + 1..n], &self.gamma[i + 1..n]);
            let (ws, ms) = (
                &self.merge_weight[i + 1..n],
                &mut self.pair_measure[i + 1..n],
            );
            for ((((&xj, &zj), &gj), &wj), m) in
                xs.iter().zip(zs).zip(gs).zip(ws).zip(ms.iter_mut())
            {
                let (dx, dz) = (xi - xj, zi - zj);
                let dij = (dx * dx + dz * dz).sqrt();
                let mij = (gi * gj).abs() / (gi + gj).abs() * dij * (wi * wj);
                *m = if gi * gj > 0.0 { mij } else { f64::INFINITY };
            }
            let di = self.plate_dist[i];
            let mut best = (f64::INFINITY, 0u32);
            for j in (i + 1)..n {
                let m = self.pair_measure[j];
                // never merge across the plate: the merged vortex must not lie closer to it
                // than both constituents (it would sit on the plate)
                if m < best.0 {
                    let (gj, g) = (self.gamma[j], gi + self.gamma[j]);
                    let xm = (gi * xi + gj * self.x[j]) / g;
                    let zm = (gi * zi + gj * self.z[j]) / g;
                    if dist(xm, zm) >= 0.999 * di.min(self.plate_dist[j]) {
                        best = (m, j as u32);
                    }
                }
            }
            if best.0.is_finite() {
                self.best.push((best.0, i as u32, best.1));
            }
        }
        self.best.sort_unstable_by(|a, b| a.0.total_cmp(&b.0));
        self.keep.clear();
        self.keep.resize(n, true);
        let mut count = n;
        for k in 0..self.best.len() {
            let (m, i, j) = self.best[k];
            let (i, j) = (i as usize, j as usize);
            if m >= v0_dim && count <= target {
                break;
            }
            if !self.keep[i] || !self.keep[j] {
                continue;
            }
            let (gi, gj) = (self.gamma[i], self.gamma[j]);
            let g = gi + gj;
            self.x[i] = (gi * self.x[i] + gj * self.x[j]) / g;
            self.z[i] = (gi * self.z[i] + gj * self.z[j]) / g;
            // |Γ|-weighted core (same-sign pair: weights Γ/ΣΓ are positive)
            self.core2[i] = (gi * self.core2[i] + gj * self.core2[j]) / g;
            self.u[i] = (gi * self.u[i] + gj * self.u[j]) / g;
            self.w[i] = (gi * self.w[i] + gj * self.w[j]) / g;
            if gj.abs() > gi.abs() {
                self.kind[i] = self.kind[j];
            }
            self.gamma[i] = g;
            self.keep[j] = false;
            count -= 1;
        }
        if count < n {
            self.compact();
        }
    }

    /// Removes the weakest unprotected vortex to infinity (last resort when amalgamation cannot
    /// make room).
    pub(crate) fn remove_weakest(&mut self) {
        let mut weakest = None;
        for i in 0..self.len() {
            if self.last_tev == Some(i) || self.last_lev == Some(i) {
                continue;
            }
            if weakest.is_none_or(|k: usize| self.gamma[i].abs() < self.gamma[k].abs()) {
                weakest = Some(i);
            }
        }
        let Some(k) = weakest else { return };
        self.far_circulation += self.gamma[k];
        self.keep.clear();
        self.keep.resize(self.len(), true);
        self.keep[k] = false;
        self.compact();
    }

    /// Removes the vortices with `keep[i] == false`, preserving order and the newest indices.
    fn compact(&mut self) {
        let n = self.len();
        let mut dst = 0;
        let (mut tev, mut lev) = (None, None);
        for src in 0..n {
            if !self.keep[src] {
                continue;
            }
            self.x[dst] = self.x[src];
            self.z[dst] = self.z[src];
            self.gamma[dst] = self.gamma[src];
            self.core2[dst] = self.core2[src];
            self.kind[dst] = self.kind[src];
            self.u[dst] = self.u[src];
            self.w[dst] = self.w[src];
            if self.last_tev == Some(src) {
                tev = Some(dst);
            }
            if self.last_lev == Some(src) {
                lev = Some(dst);
            }
            dst += 1;
        }
        self.last_tev = tev;
        self.last_lev = lev;
        self.x.truncate(dst);
        self.z.truncate(dst);
        self.gamma.truncate(dst);
        self.core2.truncate(dst);
        self.kind.truncate(dst);
        self.u.truncate(dst);
        self.w.truncate(dst);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Same-sign vortices on opposite sides of the plate are never merged (the merged vortex
    /// would sit on the plate); on the same side they are.
    #[test]
    fn amalgamation_never_merges_across_the_plate() {
        let (le, te) = ([0.0, 0.0], [1.0, 0.0]);
        for (zb, expect) in [(-0.1, 3), (0.12, 2)] {
            let mut wake = Wake::with_capacity(8, 0.01);
            wake.push(0.5, 0.1, 1.0, VortexKind::Lev);
            wake.push(0.55, zb, 1.0, VortexKind::Lev);
            wake.push(5.0, 5.0, -1.0, VortexKind::Lev); // newest: protected
            wake.amalgamate(le, te, 1.0, 0.0, 1e9, 1);
            assert_eq!(wake.len(), expect, "second vortex at z = {zb}");
            assert!((wake.total_circulation() - 1.0).abs() < 1e-15);
        }
    }

    /// Vortices deleted in the far field, removed to make room or cleared keep their
    /// circulation in the Kelvin balance; `clear` (a reset) forgets it.
    #[test]
    fn removed_vortices_keep_their_circulation_at_infinity() {
        let mut wake = Wake::with_capacity(8, 0.01);
        wake.push(0.0, 0.0, 0.3, VortexKind::Tev);
        wake.push(20.0, 0.0, -0.2, VortexKind::Tev);
        wake.push(0.5, 0.0, 0.05, VortexKind::Lev);
        wake.push(1.0, 0.0, 0.7, VortexKind::Tev); // newest TEV, protected
        wake.delete_far(0.0, 0.0, 4.0);
        assert_eq!(wake.len(), 3);
        assert!((wake.far_circulation() + 0.2).abs() < 1e-15);
        wake.remove_weakest(); // the newest LEV and TEV are protected: removes the 0.3
        assert_eq!(wake.len(), 2);
        assert!((wake.far_circulation() - 0.1).abs() < 1e-15);
        assert!((wake.total_circulation() - 0.85).abs() < 1e-15);
        // removed vortices induce nothing
        let (u, w) = wake.velocity_at(0.5, 1.0);
        let (u2, w2) = induced_at(0.5, 1.0, &[0.5, 1.0], &[0.0, 0.0], &[0.05, 0.7], 1e-8);
        assert!((u - u2).abs() < 1e-15 && (w - w2).abs() < 1e-15);
        wake.remove_all_to_far();
        assert!(wake.is_empty() && (wake.total_circulation() - 0.85).abs() < 1e-15);
        wake.clear();
        assert_eq!(wake.total_circulation(), 0.0);
    }

    /// Grown cores: a vortex induces with its own core at the points, and a pair of free
    /// vortices with the mean of their r_c².
    #[test]
    fn grown_cores_set_the_induced_velocity() {
        let mut wake = Wake::with_capacity(4, 0.01);
        wake.push(0.0, 0.0, 1.0, VortexKind::Tev);
        wake.grow_cores(0.03 * 0.03 - 0.01 * 0.01);
        wake.push(0.02, 0.0, 0.5, VortexKind::Tev);
        let r: Vec<f64> = wake.core_radii_m().collect();
        assert!((r[0] - 0.03).abs() < 1e-15 && (r[1] - 0.01).abs() < 1e-15);
        let (u, w) = wake.velocity_at(0.0, 0.02);
        let (u0, w0) = induced_at(0.0, 0.02, &[0.0], &[0.0], &[1.0], 0.03f64.powi(4));
        let (u1, w1) = induced_at(0.0, 0.02, &[0.02], &[0.0], &[0.5], 0.01f64.powi(4));
        assert!((u - u0 - u1).abs() < 1e-12 && (w - w0 - w1).abs() < 1e-12);
        wake.compute_velocities(|_, _, u, w| {
            u.fill(0.0);
            w.fill(0.0);
        });
        let rc2: f64 = 0.5 * (0.03 * 0.03 + 0.01 * 0.01);
        let (_, w1) = induced_at(0.02, 0.0, &[0.0], &[0.0], &[1.0], rc2 * rc2);
        assert!(
            (wake.w[1] - w1).abs() < 1e-12
                && w1 < induced_at(0.02, 0.0, &[0.0], &[0.0], &[1.0], 1e-8).1
        );
    }

    #[test]
    fn point_vortex_far_field_is_biot_savart() {
        // Γ = 2π at the origin induces unit-speed counter-clockwise flow at distance 1.
        let (u, w) = induced_at(1.0, 0.0, &[0.0], &[0.0], &[2.0 * PI], 1e-16);
        assert!((u - 0.0).abs() < 1e-12 && (w - 1.0).abs() < 1e-12);
        let (u, w) = induced_at(0.0, 2.0, &[0.0], &[0.0], &[2.0 * PI], 1e-16);
        assert!((u + 0.5).abs() < 1e-12 && w.abs() < 1e-12);
    }

    #[test]
    fn pair_velocities_match_direct_sum_and_merging_conserves_circulation() {
        let mut wake = Wake::with_capacity(16, 0.01);
        let pts = [
            (0.0, 0.0, 1.0),
            (0.3, 0.1, -0.5),
            (1.0, -0.2, 0.7),
            (5.0, 5.0, 0.2),
            (5.1, 5.0, 0.3),
            (-2.0, 1.0, 0.1),
        ];
        for &(x, z, g) in &pts {
            wake.push(x, z, g, VortexKind::Tev);
        }
        let rc4 = 0.01f64.powi(4);
        wake.compute_velocities(|_, _, u, w| {
            u.fill(0.0);
            w.fill(0.0);
        });
        for (i, &(x, z, _)) in pts.iter().enumerate() {
            let (mut u, mut w) = (0.0, 0.0);
            for (j, &(xj, zj, gj)) in pts.iter().enumerate() {
                if i != j {
                    let (du, dw) = induced_at(x, z, &[xj], &[zj], &[gj], rc4);
                    u += du;
                    w += dw;
                }
            }
            assert!((wake.u[i] - u).abs() < 1e-13 && (wake.w[i] - w).abs() < 1e-13);
        }
        let total = wake.total_circulation();
        wake.amalgamate([0.0, 0.0], [0.0, 0.0], 1.0, 0.0, 1e9, 2);
        assert!(wake.len() < pts.len());
        assert!((wake.total_circulation() - total).abs() < 1e-14);
        // the newest vortex is protected and still last
        assert_eq!(wake.last_tev, Some(wake.len() - 1));
        assert_eq!(wake.gamma_m2_s()[wake.len() - 1], 0.1);
    }
}
