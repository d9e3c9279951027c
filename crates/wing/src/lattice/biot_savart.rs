//! The velocity induced by a straight vortex segment (Biot–Savart), with a smoothed core, at
//! many points at once.

use crate::vec3::{cross, dot, sub};

/// 1/(4π).
const INV_4PI: f64 = 0.25 / std::f64::consts::PI;

/// Points (or velocities) stored by coordinate, so that a segment's velocity at all of them
/// runs in SIMD lanes.
#[derive(Debug, Clone, Default)]
pub(crate) struct Points {
    pub x: Vec<f64>,
    pub y: Vec<f64>,
    pub z: Vec<f64>,
}

impl Points {
    pub fn zeros(n: usize) -> Self {
        Self {
            x: vec![0.0; n],
            y: vec![0.0; n],
            z: vec![0.0; n],
        }
    }

    pub fn set(&mut self, k: usize, p: [f64; 3]) {
        (self.x[k], self.y[k], self.z[k]) = (p[0], p[1], p[2]);
    }

    pub fn get(&self, k: usize) -> [f64; 3] {
        [self.x[k], self.y[k], self.z[k]]
    }

    pub fn fill_zero(&mut self) {
        self.x.fill(0.0);
        self.y.fill(0.0);
        self.z.fill(0.0);
    }
}

/// Adds to `out` the velocity (m/s) that the segment `p1 → p2` (m) of circulation Γ = `gamma`
/// (m²/s, positive by the right-hand rule along p1 → p2) with core radius r_c = `core_m` (m)
/// induces at each of `points`:
///
/// ```text
/// v = Γ/(4π) · (r1 × r2) / (|r1 × r2|² + r_c²|r0|²) · r0·(r1/|r1| − r2/|r2|),
/// ```
///
/// r1 = x − p1, r2 = x − p2, r0 = p2 − p1. With r_c = 0 it is the exact filament; the core
/// replaces the 1/h singularity at distance h from the line by h/(h² + r_c²) (the algebraic
/// core of Katz & Plotkin §10.4.5). Without branches, so that it runs in SIMD lanes: a point on
/// the segment's line gets zero through the floor on the denominator, far below any distance
/// that occurs.
pub(crate) fn add_segment_velocity(
    points: &Points,
    out: &mut Points,
    p1: [f64; 3],
    p2: [f64; 3],
    gamma: f64,
    core_m: f64,
) {
    let r0 = sub(p2, p1);
    let r0_sq = dot(r0, r0);
    let core_term = core_m * core_m * r0_sq;
    let floor = 1e-24 * r0_sq * r0_sq;
    let scale = INV_4PI * gamma;
    let n = points.x.len();
    let (px, py, pz) = (&points.x[..n], &points.y[..n], &points.z[..n]);
    let (ox, oy, oz) = (&mut out.x[..n], &mut out.y[..n], &mut out.z[..n]);
    for k in 0..n {
        let r1 = [px[k] - p1[0], py[k] - p1[1], pz[k] - p1[2]];
        let r2 = [px[k] - p2[0], py[k] - p2[1], pz[k] - p2[2]];
        let c = cross(r1, r2);
        let den = (dot(c, c) + core_term).max(floor);
        let n1 = dot(r1, r1).sqrt().max(1e-300);
        let n2 = dot(r2, r2).sqrt().max(1e-300);
        let f = scale * (dot(r0, r1) / n1 - dot(r0, r2) / n2) / den;
        ox[k] += f * c[0];
        oy[k] += f * c[1];
        oz[k] += f * c[2];
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The velocity of one segment at one point.
    fn at(x: [f64; 3], p1: [f64; 3], p2: [f64; 3], gamma: f64, core: f64) -> [f64; 3] {
        let points = Points {
            x: vec![x[0]],
            y: vec![x[1]],
            z: vec![x[2]],
        };
        let mut v = Points::zeros(1);
        add_segment_velocity(&points, &mut v, p1, p2, gamma, core);
        v.get(0)
    }

    /// An infinite line (a long segment) induces Γ/(2πh) around itself; a finite one
    /// Γ/(4πh)(cos θ1 − cos θ2); the core only matters within a few r_c; nothing on the line.
    #[test]
    fn segment_matches_the_closed_forms() {
        let gamma = 2.0;
        let v = at(
            [0.0, 0.5, 0.0],
            [0.0, 0.0, -1e6],
            [0.0, 0.0, 1e6],
            gamma,
            0.0,
        );
        // z-directed filament, point on +y: velocity along −x.
        let exact = gamma / (2.0 * std::f64::consts::PI * 0.5);
        assert!((v[0] + exact).abs() < 1e-9 * exact && v[1].abs() < 1e-12 && v[2].abs() < 1e-12);
        // Unit segment seen from its perpendicular bisector at h = 1: cos θ = ±1/√5.
        let v = at(
            [0.0, 1.0, 0.5],
            [0.0, 0.0, 0.0],
            [0.0, 0.0, 1.0],
            gamma,
            0.0,
        );
        let exact = gamma / (4.0 * std::f64::consts::PI) * 2.0 / 5f64.sqrt();
        assert!((v[0] + exact).abs() < 1e-12);
        // A core of 1 % of h changes the velocity by ≈ 1e-4 relative.
        let w = at(
            [0.0, 1.0, 0.5],
            [0.0, 0.0, 0.0],
            [0.0, 0.0, 1.0],
            gamma,
            0.01,
        );
        assert!(((w[0] - v[0]) / v[0] + 1e-4).abs() < 1e-6);
        for x in [[0.0, 0.0, 2.0], [0.0, 0.0, 0.0], [0.0, 0.0, 0.5]] {
            assert_eq!(
                at(x, [0.0; 3], [0.0, 0.0, 1.0], gamma, 0.0),
                [0.0; 3],
                "{x:?}"
            );
        }
    }
}
