//! Finite Fourier series of the periodic parts of the Euler angles, and the smooth square wave
//! of the pitch plateaus.

use std::f64::consts::PI;

use serde::{Deserialize, Serialize};

use super::BOUND_GRID;

/// A finite Fourier series g(x) = c₀ + Σ_{k=1..K} (a_k cos kx + b_k sin kx) (rad).
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct FourierSeries {
    /// Constant term c₀ (rad).
    pub offset_rad: f64,
    /// a_k, k = 1..K (rad).
    pub cos_rad: Vec<f64>,
    /// b_k, k = 1..K (rad); same length as `cos_rad`.
    pub sin_rad: Vec<f64>,
}

impl FourierSeries {
    pub(super) fn with_len(k: usize) -> Self {
        Self {
            offset_rad: 0.0,
            cos_rad: vec![0.0; k],
            sin_rad: vec![0.0; k],
        }
    }

    fn grow(&mut self, k: usize) {
        if self.cos_rad.len() < k {
            self.cos_rad.resize(k, 0.0);
            self.sin_rad.resize(k, 0.0);
        }
    }

    /// Adds a·cos(kx) + b·sin(kx).
    fn add_harmonic(&mut self, k: usize, a: f64, b: f64) {
        if k == 0 {
            self.offset_rad += a;
            return;
        }
        self.grow(k);
        self.cos_rad[k - 1] += a;
        self.sin_rad[k - 1] += b;
    }

    /// Adds amp·sin(kx + p).
    pub(super) fn add_sin(&mut self, k: usize, amp: f64, p: f64) {
        self.add_harmonic(k, amp * p.sin(), amp * p.cos());
    }

    /// Adds amp·cos(kx + p).
    pub(super) fn add_cos(&mut self, k: usize, amp: f64, p: f64) {
        self.add_harmonic(k, amp * p.cos(), -amp * p.sin());
    }

    pub(super) fn scaled(&self, s: f64) -> Self {
        Self {
            offset_rad: s * self.offset_rad,
            cos_rad: self.cos_rad.iter().map(|c| s * c).collect(),
            sin_rad: self.sin_rad.iter().map(|c| s * c).collect(),
        }
    }

    pub(super) fn add(&mut self, other: &Self) {
        self.grow(other.cos_rad.len());
        self.offset_rad += other.offset_rad;
        for k in 0..other.cos_rad.len() {
            self.cos_rad[k] += other.cos_rad[k];
            self.sin_rad[k] += other.sin_rad[k];
        }
    }

    /// g(x + δ).
    pub(super) fn shifted(&self, delta: f64) -> Self {
        let mut out = Self::with_len(self.cos_rad.len());
        out.offset_rad = self.offset_rad;
        for k in 1..=self.cos_rad.len() {
            let (s, c) = (k as f64 * delta).sin_cos();
            let (a, b) = (self.cos_rad[k - 1], self.sin_rad[k - 1]);
            out.cos_rad[k - 1] = a * c + b * s;
            out.sin_rad[k - 1] = b * c - a * s;
        }
        out
    }

    /// Product g·h, exact (harmonics up to K_g + K_h).
    pub(super) fn product(&self, other: &Self) -> Self {
        let terms = |f: &Self| {
            let mut t = vec![(0usize, f.offset_rad, 0.0)];
            t.extend((1..=f.cos_rad.len()).map(|k| (k, f.cos_rad[k - 1], f.sin_rad[k - 1])));
            t
        };
        let mut out = Self::with_len(self.cos_rad.len() + other.cos_rad.len());
        for &(j, aj, bj) in &terms(self) {
            for &(k, ak, bk) in &terms(other) {
                // (aj cos jx + bj sin jx)(ak cos kx + bk sin kx), with sin 0 = 0 for the constant.
                let sum = j + k;
                let diff = j.abs_diff(k);
                let sgn = if j >= k { 1.0 } else { -1.0 };
                out.add_harmonic(sum, 0.5 * (aj * ak - bj * bk), 0.5 * (aj * bk + bj * ak));
                let (dc, ds) = (0.5 * (aj * ak + bj * bk), 0.5 * sgn * (bj * ak - aj * bk));
                if diff == 0 {
                    out.offset_rad += dc;
                } else {
                    out.add_harmonic(diff, dc, ds);
                }
            }
        }
        out
    }

    /// [g, dg/dx, d²g/dx²] at x.
    pub fn eval(&self, x: f64) -> [f64; 3] {
        let (s1, c1) = x.sin_cos();
        let (mut s, mut c) = (0.0, 1.0);
        let mut out = [self.offset_rad, 0.0, 0.0];
        for k in 1..=self.cos_rad.len() {
            (s, c) = (s * c1 + c * s1, c * c1 - s * s1);
            let (a, b) = (self.cos_rad[k - 1], self.sin_rad[k - 1]);
            let kf = k as f64;
            out[0] += a * c + b * s;
            out[1] += kf * (b * c - a * s);
            out[2] -= kf * kf * (a * c + b * s);
        }
        out
    }

    /// Half peak-to-peak range (max g − min g)/2 over one period, sampled on a grid.
    pub(super) fn half_range(&self) -> f64 {
        let (lo, hi) = (0..BOUND_GRID).fold((f64::MAX, f64::MIN), |(lo, hi), i| {
            let v = self.eval(2.0 * PI * i as f64 / BOUND_GRID as f64)[0];
            (lo.min(v), hi.max(v))
        });
        0.5 * (hi - lo)
    }

    /// Bounds over one period, sampled on a grid: (max |g|, max |dg/dx|).
    pub(super) fn bounds(&self) -> (f64, f64) {
        (0..BOUND_GRID).fold((0.0, 0.0), |(m0, m1), i| {
            let v = self.eval(2.0 * PI * i as f64 / BOUND_GRID as f64);
            (f64::max(m0, v[0].abs()), f64::max(m1, v[1].abs()))
        })
    }
}

/// The Fejér-smoothed square wave S(x) (harmonics cos kx, odd k ≤ `k_max`) with S(0) = 1.
pub(super) fn smooth_square(k_max: usize) -> FourierSeries {
    let mut s = FourierSeries::with_len(k_max);
    for k in (1..=k_max).step_by(2) {
        let fejer = 1.0 - k as f64 / (k_max as f64 + 1.0);
        let sign = if (k / 2) % 2 == 0 { 1.0 } else { -1.0 };
        s.cos_rad[k - 1] = 4.0 / PI * sign * fejer / k as f64;
    }
    let s0 = s.eval(0.0)[0];
    s.scaled(1.0 / s0)
}
