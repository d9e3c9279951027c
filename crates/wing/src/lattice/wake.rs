//! The shed wake of the vortex lattice: rings between the trailing-edge lines of successive
//! steps, held in the fluid (a prescribed wake: carried down with the induced inflow, no
//! self-induction), with viscous cores that grow with age.
//!
//! Lines are stored oldest first; the newest line is the trailing-edge line of the current
//! step, attached to the wing. Ring k lies between lines k (behind) and k + 1 (ahead) and has
//! one strength per spanwise column, oriented as the bound rings (leading side ahead). The
//! filament of line m carries G_{m−1} − G_m along +span (G_{−1} = 0; the newest line carries
//! only G_{K−1}: the bound trailing-edge ring's own filament there belongs to the bound
//! lattice), and the streamwise filament at node j of ring k carries G_{k,j} − G_{k,j−1}
//! (zero outside the wing) from line k to line k + 1.

use super::biot_savart::{Points, add_segment_velocity};

/// 4·1.25643: r_c² = r_c0² + 4·α·ν·t with Lamb–Oseen's α = 1.25643 (the core radius of
/// maximum swirl velocity), as the strips' vortices (`vortex::LdvmParams::core_growth`).
const LAMB_OSEEN_4_ALPHA: f64 = 5.02572;

/// The wake of one wing.
#[derive(Debug, Clone)]
pub(crate) struct Wake {
    /// Nodes per line (spanwise panels + 1).
    nodes: usize,
    /// Line nodes, global frame (m), `nodes` per line, oldest line first.
    points: Vec<[f64; 3]>,
    /// Ring strengths (m²/s), `nodes − 1` per ring, oldest first.
    strengths: Vec<f64>,
    /// Time each line was shed (s).
    shed_time_s: Vec<f64>,
    /// Travel of the reference point when each line was shed (m).
    shed_travel_m: Vec<f64>,
    /// Initial core radius squared (m²).
    core0_sq: f64,
    /// 4αν (m²/s).
    core_growth_m2_s: f64,
}

impl Wake {
    pub fn new(spanwise_panels: usize, core0_m: f64, viscosity_m2_s: f64) -> Self {
        Self {
            nodes: spanwise_panels + 1,
            points: Vec::new(),
            strengths: Vec::new(),
            shed_time_s: Vec::new(),
            shed_travel_m: Vec::new(),
            core0_sq: core0_m * core0_m,
            core_growth_m2_s: LAMB_OSEEN_4_ALPHA * viscosity_m2_s,
        }
    }

    /// Sets the initial core radius r_c0 (m) of the filaments shed from now on.
    pub fn set_initial_core(&mut self, core0_m: f64) {
        self.core0_sq = core0_m * core0_m;
    }

    pub fn clear(&mut self) {
        self.points.clear();
        self.strengths.clear();
        self.shed_time_s.clear();
        self.shed_travel_m.clear();
    }

    /// Number of rings (rows of the wake).
    #[cfg(test)]
    pub fn rows(&self) -> usize {
        self.strengths.len() / (self.nodes - 1)
    }

    fn lines(&self) -> usize {
        self.shed_time_s.len()
    }

    /// One step: every node so far is moved by `carry` (the fluid's displacement over the step),
    /// then `trailing_edge` (the current trailing-edge line, global) is added with the ring
    /// between it and the last line of strength `shed` per column (the bound trailing-edge
    /// strengths of the step before). The first call only records the line.
    pub fn shed(
        &mut self,
        carry: impl Fn(&mut [f64; 3]),
        trailing_edge: &[[f64; 3]],
        shed: &[f64],
        time_s: f64,
        travel_m: f64,
    ) {
        debug_assert_eq!(trailing_edge.len(), self.nodes);
        self.points.iter_mut().for_each(carry);
        if self.lines() > 0 {
            self.strengths.extend_from_slice(shed);
        }
        self.points.extend_from_slice(trailing_edge);
        self.shed_time_s.push(time_s);
        self.shed_travel_m.push(travel_m);
    }

    /// Deletes the oldest lines (and their rings) shed before the reference point's travel
    /// `oldest_travel_m`; the newest line always stays. Whole rings go, so Kelvin's theorem holds.
    pub fn prune(&mut self, oldest_travel_m: f64) {
        let old = self
            .shed_travel_m
            .iter()
            .take(self.lines().saturating_sub(1))
            .take_while(|&&s| s < oldest_travel_m)
            .count();
        if old > 0 {
            let panels = self.nodes - 1;
            self.points.drain(..old * self.nodes);
            self.strengths.drain(..old * panels);
            self.shed_time_s.drain(..old);
            self.shed_travel_m.drain(..old);
        }
    }

    /// Adds the velocity (m/s, global) that the wake induces at each of `points` at `time_s`.
    pub fn add_induced_velocity(&self, time_s: f64, points: &Points, out: &mut Points) {
        let (n, panels) = (self.nodes, self.nodes - 1);
        let lines = self.lines();
        // The newest line lies on the bound trailing-edge filament, whose strength its own
        // filament cancels but for the shed part: it has the bound lattice's zero core.
        let core_sq = |m: usize| {
            if m + 1 == lines {
                0.0
            } else {
                self.core0_sq + self.core_growth_m2_s * (time_s - self.shed_time_s[m])
            }
        };
        let strength = |k: usize, j: usize| -> f64 {
            if j < panels {
                self.strengths[k * panels + j]
            } else {
                0.0
            }
        };
        for m in 0..lines {
            let line = &self.points[m * n..(m + 1) * n];
            let core = core_sq(m).sqrt();
            // Spanwise filaments of line m: G_{m−1} − G_m.
            for j in 0..panels {
                let behind = if m > 0 { strength(m - 1, j) } else { 0.0 };
                let ahead = if m + 1 < lines { strength(m, j) } else { 0.0 };
                let g = behind - ahead;
                if g != 0.0 {
                    add_segment_velocity(points, out, line[j], line[j + 1], g, core);
                }
            }
            // Streamwise filaments of ring m (line m → line m + 1).
            if m + 1 < lines {
                let ahead = &self.points[(m + 1) * n..(m + 2) * n];
                let core = (0.5 * (core_sq(m) + core_sq(m + 1))).sqrt();
                for j in 0..n {
                    let left = if j > 0 { strength(m, j - 1) } else { 0.0 };
                    let g = strength(m, j) - left;
                    if g != 0.0 {
                        add_segment_velocity(points, out, line[j], ahead[j], g, core);
                    }
                }
            }
        }
    }

    /// The ring strengths of row `k` (0 = oldest), per column (m²/s).
    #[cfg(test)]
    pub fn row(&self, k: usize) -> &[f64] {
        let panels = self.nodes - 1;
        &self.strengths[k * panels..(k + 1) * panels]
    }

    /// The nodes of line `m` (0 = oldest), global (m).
    #[cfg(test)]
    pub fn line(&self, m: usize) -> &[[f64; 3]] {
        &self.points[m * self.nodes..(m + 1) * self.nodes]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Lines shed so far move with the fluid, the ring between the last two carries the strengths
    /// shed, and pruning deletes whole rows, oldest first, never the newest line.
    #[test]
    fn shed_rows_move_with_the_fluid_and_go_whole() {
        let mut wake = Wake::new(2, 0.0, 0.0);
        let line = |x: f64| [[x, 0.0, 0.0], [x, 0.0, 1.0], [x, 0.0, 2.0]];
        let sink = |p: &mut [f64; 3]| p[1] -= 0.5;
        wake.shed(|_| {}, &line(0.0), &[9.0, 9.0], 0.0, 0.0);
        assert_eq!(wake.rows(), 0);
        wake.shed(sink, &line(1.0), &[1.0, 2.0], 0.1, 1.0);
        wake.shed(sink, &line(2.0), &[3.0, 4.0], 0.2, 2.0);
        assert_eq!(wake.rows(), 2);
        assert_eq!(wake.row(0), &[1.0, 2.0]);
        assert_eq!(wake.line(0)[1], [0.0, -1.0, 1.0]);
        assert_eq!(wake.line(1)[1], [1.0, -0.5, 1.0]);
        assert_eq!(wake.line(2)[1], [2.0, 0.0, 1.0]);
        wake.prune(0.5);
        assert_eq!(wake.rows(), 1);
        assert_eq!(wake.row(0), &[3.0, 4.0]);
        wake.prune(10.0);
        assert_eq!((wake.rows(), wake.line(0)[0]), (0, [2.0, 0.0, 0.0]));
    }

    /// A single ring far away induces the field of a dipole of moment Γ·area along its normal:
    /// on the axis, Γ·A/(2π d³).
    #[test]
    fn a_far_ring_is_a_dipole() {
        let mut wake = Wake::new(1, 0.0, 0.0);
        wake.shed(
            |_| {},
            &[[0.0, 0.0, 0.0], [0.0, 0.0, 0.1]],
            &[0.0],
            0.0,
            0.0,
        );
        wake.shed(
            |_| {},
            &[[0.1, 0.0, 0.0], [0.1, 0.0, 0.1]],
            &[2.0],
            0.0,
            0.0,
        );
        let points = Points {
            x: vec![0.05],
            y: vec![10.0],
            z: vec![0.05],
        };
        let mut v = Points::zeros(1);
        wake.add_induced_velocity(0.0, &points, &mut v);
        let dipole = 2.0 * 0.01 / (2.0 * std::f64::consts::PI * 1000.0);
        assert!(
            (v.y[0].abs() - dipole).abs() < 1e-3 * dipole,
            "{} vs {dipole}",
            v.y[0]
        );
    }
}
