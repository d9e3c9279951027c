//! The unsteady vortex-lattice wing: bound rings on the plate, a shed wake, loads from the
//! unsteady Bernoulli equation and the leading-edge suction (module docs of [`super`]).

use super::biot_savart::{Points, add_segment_velocity};
use super::inflow::{WingInflow, slipstream_speed};
use super::wake::Wake;
use super::{LatticeError, VortexLatticeParams};
use crate::dataset::{Fluid, WingGeometry};
use crate::kinematics::{EulerState, Mat3, WingKinematics, rotation_global_from_wing};
use crate::vec3::{add, cross, midpoint, norm, sub};
use faer::linalg::solvers::DenseSolveCore;

/// The vortex-lattice model of one rigid plate (reuse it: [`Self::loads_into`] resets it).
#[derive(Debug, Clone)]
pub struct VortexLatticeWing {
    params: VortexLatticeParams,
    chord_m: f64,
    density_kg_m3: f64,
    viscosity_m2_s: f64,
    sensor_radius_m: f64,
    /// Radius of the wing tip (m): the disk of the slipstream.
    tip_radius_m: f64,
    /// Reference point (pitch axis at the U_ref radius), wing frame (m).
    reference_point: [f64; 3],
    chordwise: usize,
    spanwise: usize,
    /// y of the leading edge (m, wing frame).
    y_le: f64,
    /// y of the bound ring lines, i = 0..=N_c, LE → TE (m, wing frame; the quarter-panel lines).
    ring_y: Vec<f64>,
    /// Chord length of each ring row on the plate (m): the trailing-edge row's ring reaches a
    /// quarter panel beyond it.
    on_plate: Vec<f64>,
    /// z of the lattice nodes, j = 0..=N_s, root → tip (m).
    node_z: Vec<f64>,
    /// Collocation points (three-quarter panel), index i·N_s + j, wing frame (m).
    collocation: Vec<[f64; 3]>,
    /// The inverse of the normal-influence matrix of the bound rings, row-major.
    influence_inverse: Vec<f64>,
    /// 2-D leading-edge singularity factor of the first panel, πρ/(4c g²) (kg/m⁴).
    suction_factor: f64,
    /// Local speed × this = the first panel's circulation at LESP 1 (m): 2c·g.
    lesp_circulation_m: f64,
    state: LatticeState,
}

/// What changes from step to step, and the workspaces.
#[derive(Debug, Clone)]
struct LatticeState {
    gamma: Vec<f64>,
    gamma_before: Vec<f64>,
    wake: Wake,
    inflow: WingInflow,
    time_s: f64,
    travel_m: f64,
    started: bool,
    points_global: Points,
    wake_global: Points,
    wake_velocity: Vec<[f64; 3]>,
    trailing_edge: Vec<[f64; 3]>,
    shed: Vec<f64>,
    rhs: Vec<f64>,
}

impl VortexLatticeWing {
    /// Builds the lattice of `wing` in `fluid` with the sensor at `sensor_radius_m` on the pitch
    /// axis.
    pub fn new(
        params: &VortexLatticeParams,
        wing: &WingGeometry,
        fluid: &Fluid,
        sensor_radius_m: f64,
    ) -> Result<Self, LatticeError> {
        params.check()?;
        let (nc, ns) = (params.chordwise_panels, params.spanwise_panels);
        let c = wing.chord_m;
        let y_le = wing.pitch_axis_frac * c;
        // Equal panels (for which the quarter-panel vortex and the three-quarter-panel point
        // give the exact 2-D flat-plate lift; cosine spacing along the span converged no faster
        // here): edges as distance from the LE (m) and radius (m).
        let chord_edges: Vec<f64> = (0..=nc).map(|i| c * i as f64 / nc as f64).collect();
        let node_z: Vec<f64> = (0..=ns)
            .map(|j| wing.root_offset_m + wing.span_m * j as f64 / ns as f64)
            .collect();
        let panel = |i: usize| chord_edges[i + 1] - chord_edges[i];
        // Leading filaments a quarter panel behind each panel's front edge; the last ring ends a
        // quarter of the last panel behind the trailing edge.
        let lead: Vec<f64> = (0..=nc)
            .map(|i| {
                if i < nc {
                    chord_edges[i] + 0.25 * panel(i)
                } else {
                    c + 0.25 * panel(nc - 1)
                }
            })
            .collect();
        let ring_y: Vec<f64> = lead.iter().map(|x| y_le - x).collect();
        let on_plate: Vec<f64> = (0..nc).map(|i| lead[i + 1].min(c) - lead[i]).collect();
        let collocation: Vec<[f64; 3]> = (0..nc * ns)
            .map(|k| {
                let (i, j) = (k / ns, k % ns);
                let x = chord_edges[i] + 0.75 * panel(i);
                [0.0, y_le - x, 0.5 * (node_z[j] + node_z[j + 1])]
            })
            .collect();
        let n = nc * ns;
        // Column l: the normal velocity at every collocation point of ring l of unit strength.
        let mut points = Points::zeros(n);
        for (k, p) in collocation.iter().enumerate() {
            points.set(k, *p);
        }
        let mut velocity = Points::zeros(n);
        let mut influence = faer::Mat::<f64>::zeros(n, n);
        for l in 0..n {
            let (i, j) = (l / ns, l % ns);
            let corners = [
                [0.0, ring_y[i], node_z[j]],
                [0.0, ring_y[i], node_z[j + 1]],
                [0.0, ring_y[i + 1], node_z[j + 1]],
                [0.0, ring_y[i + 1], node_z[j]],
            ];
            velocity.fill_zero();
            for e in 0..4 {
                add_segment_velocity(
                    &points,
                    &mut velocity,
                    corners[e],
                    corners[(e + 1) % 4],
                    1.0,
                    0.0,
                );
            }
            for k in 0..n {
                influence[(k, l)] = velocity.x[k];
            }
        }
        let inverse = influence.partial_piv_lu().inverse();
        let influence_inverse = (0..n * n).map(|kl| inverse[(kl / n, kl % n)]).collect();
        let theta = panel(0) / c;
        let g = (theta * (1.0 - theta)).sqrt() + theta.sqrt().asin();
        let rho = fluid.density_kg_m3;
        let state = LatticeState {
            gamma: vec![0.0; n],
            gamma_before: vec![0.0; n],
            wake: Wake::new(
                ns,
                params.core_radius_frac.unwrap_or(0.0) * c,
                fluid.kinematic_viscosity_m2_s,
            ),
            inflow: WingInflow::new(
                params.inflow,
                params.inflow_window_chords * c,
                rho,
                wing.root_offset_m,
                wing.root_offset_m + wing.span_m,
                c,
            ),
            time_s: 0.0,
            travel_m: 0.0,
            started: false,
            points_global: Points::zeros(n),
            wake_global: Points::zeros(n),
            wake_velocity: vec![[0.0; 3]; n],
            trailing_edge: vec![[0.0; 3]; ns + 1],
            shed: vec![0.0; ns],
            rhs: vec![0.0; n],
        };
        Ok(Self {
            params: *params,
            chord_m: c,
            density_kg_m3: rho,
            viscosity_m2_s: fluid.kinematic_viscosity_m2_s,
            sensor_radius_m,
            tip_radius_m: wing.root_offset_m + wing.span_m,
            reference_point: [0.0, 0.0, wing.u_ref_radius_m],
            chordwise: nc,
            spanwise: ns,
            y_le,
            ring_y,
            on_plate,
            node_z,
            collocation,
            influence_inverse,
            suction_factor: std::f64::consts::PI * rho / (4.0 * c * g * g),
            lesp_circulation_m: 2.0 * c * g,
            state,
        })
    }

    /// Back to rest: no wake, no circulation.
    pub fn reset(&mut self) {
        let s = &mut self.state;
        s.gamma.fill(0.0);
        s.gamma_before.fill(0.0);
        s.wake.clear();
        s.inflow.reset();
        s.time_s = 0.0;
        s.travel_m = 0.0;
        s.started = false;
    }

    /// Deletes the whole shed wake (for measuring what it does: the wing then starts a new one
    /// at its next step, without the vorticity it would have shed).
    pub fn clear_wake(&mut self) {
        self.state.wake.clear();
    }

    /// Mean speed (m/s) of the reference point over `states`.
    pub fn mean_reference_speed(&self, states: &[EulerState]) -> f64 {
        states
            .iter()
            .map(|st| {
                norm(cross(
                    WingKinematics::from_euler(st).omega_rad_s,
                    self.reference_point,
                ))
            })
            .sum::<f64>()
            / states.len().max(1) as f64
    }

    /// Lattice steps for samples `dt_s` apart: the whole number closest to the samples in which
    /// the reference point travels `step_chords` chords at its mean speed over `states`
    /// (at least 1), so that the lattice steps scale with the motion.
    pub fn samples_per_step(&self, states: &[EulerState], dt_s: f64) -> usize {
        self.samples_per_step_at(self.mean_reference_speed(states), dt_s)
    }

    /// [`Self::samples_per_step`] for a known mean speed (m/s).
    fn samples_per_step_at(&self, mean_speed_m_s: f64, dt_s: f64) -> usize {
        let per_sample = mean_speed_m_s * dt_s;
        if per_sample > 0.0 {
            ((self.params.step_chords * self.chord_m / per_sample).round() as usize).max(1)
        } else {
            1
        }
    }

    /// Sets the speed U (m/s) of the Reynolds number Uc/ν that gives the initial core of the
    /// wake filaments when `core_radius_frac` is `None` (module docs); [`Self::loads_into`] sets
    /// it from the trajectory. Until it is set the cores start at zero.
    pub fn set_reference_speed(&mut self, speed_m_s: f64) {
        if self.params.core_radius_frac.is_none() && speed_m_s > 0.0 {
            let core = 5.0 * (self.viscosity_m2_s * self.chord_m / speed_m_s).sqrt();
            self.state.wake.set_initial_core(core);
        }
    }

    /// Loads [F_x, F_y (N), M_x, M_y, M_z (N·mm)] at the sensor for Euler states sampled every
    /// `dt_s` from rest: the lattice steps every [`Self::samples_per_step`] samples (and at the
    /// last), and the loads in between are interpolated linearly in time. The mean speed of the
    /// reference point sets the initial wake core ([`Self::set_reference_speed`]).
    pub fn loads_into(&mut self, states: &[EulerState], dt_s: f64, out: &mut [[f64; 5]]) {
        self.reset();
        let n = states.len();
        if n == 0 {
            return;
        }
        let speed = self.mean_reference_speed(states);
        let every = self.samples_per_step_at(speed, dt_s);
        self.set_reference_speed(speed);
        out[0] = self.step(&states[0], 0.0);
        let mut k = 0;
        while k + 1 < n {
            let next = (k + every).min(n - 1);
            out[next] = self.step(&states[next], (next - k) as f64 * dt_s);
            let (a, b) = (out[k], out[next]);
            for (m, y) in out[k + 1..next].iter_mut().enumerate() {
                let t = (m + 1) as f64 / (next - k) as f64;
                *y = std::array::from_fn(|c| (1.0 - t) * a[c] + t * b[c]);
            }
            k = next;
        }
    }

    /// One lattice step to `state`, `dt_s` after the last (0: the first, from rest); returns
    /// the loads at the sensor.
    pub fn step(&mut self, state: &EulerState, dt_s: f64) -> [f64; 5] {
        let (nc, ns) = (self.chordwise, self.spanwise);
        let r = rotation_global_from_wing(&state.angles_rad);
        let kin = WingKinematics::from_euler(state);
        let omega = kin.omega_rad_s;
        let up = r[1];
        let stroke = state.angles_rad[0];
        let s = &mut self.state;
        let w = s.inflow.velocity_m_s(stroke);
        let fluid = [-w * up[0], -w * up[1], -w * up[2]];
        let ds_ref = norm(cross(omega, self.reference_point)) * dt_s;
        s.time_s += dt_s;
        s.travel_m += ds_ref;
        let y_te = self.ring_y[nc];
        for (p, z) in s.trailing_edge.iter_mut().zip(&self.node_z) {
            *p = mul(&r, [0.0, y_te, *z]);
        }
        let shed_start = (nc - 1) * ns;
        s.shed.copy_from_slice(&s.gamma[shed_start..]);
        // The slipstream carries the wake down (nothing at the first step, Δt = 0).
        let radius = self.tip_radius_m;
        s.wake.shed(
            |p| p[1] -= slipstream_speed(w, -p[1], radius) * dt_s,
            &s.trailing_edge,
            &s.shed,
            s.time_s,
            s.travel_m,
        );
        s.wake
            .prune(s.travel_m - self.params.wake_length_chords * self.chord_m);
        for (k, p) in self.collocation.iter().enumerate() {
            s.points_global.set(k, mul(&r, *p));
        }
        s.wake_global.fill_zero();
        s.wake
            .add_induced_velocity(s.time_s, &s.points_global, &mut s.wake_global);
        for (k, v) in s.wake_velocity.iter_mut().enumerate() {
            *v = mul_transposed(&r, s.wake_global.get(k));
        }
        std::mem::swap(&mut s.gamma, &mut s.gamma_before);
        // No flow through the plate at the collocation points: A Γ = −Q·n̂.
        for ((b, p), v) in s
            .rhs
            .iter_mut()
            .zip(&self.collocation)
            .zip(&s.wake_velocity)
        {
            *b = -relative(fluid, omega, *v, *p)[0];
        }
        let n = s.rhs.len();
        for (k, g) in s.gamma.iter_mut().enumerate() {
            *g = dot_slice(&self.influence_inverse[k * n..(k + 1) * n], &s.rhs);
        }
        let loads = self.loads(omega, fluid, dt_s);
        let s = &mut self.state;
        let vertical = up[0] * loads[0] + up[1] * loads[1];
        s.inflow
            .advance(ds_ref, dt_s, vertical, stroke, state.rates_rad_s[0]);
        s.started = true;
        loads
    }

    /// Loads at the sensor [F_x, F_y, M_x, M_y, M_z] (N, N·mm).
    fn loads(&self, omega: [f64; 3], fluid: [f64; 3], dt_s: f64) -> [f64; 5] {
        let (nc, ns) = (self.chordwise, self.spanwise);
        let s = &self.state;
        let rho = self.density_kg_m3;
        let c = self.chord_m;
        let sensor = [0.0, 0.0, self.sensor_radius_m];
        let mut force = [0.0; 3];
        let mut moment = [0.0; 3];
        let mut add = |p: [f64; 3], f: [f64; 3]| {
            let m = cross(sub(p, sensor), f);
            for a in 0..3 {
                force[a] += f[a];
                moment[a] += m[a];
            }
        };
        let gamma = |i: usize, j: usize| s.gamma[i * ns + j];
        let wake_at = |i: usize, j: usize| s.wake_velocity[i * ns + j];
        let rate = if dt_s > 0.0 && s.started && self.params.unsteady_term {
            1.0 / dt_s
        } else {
            0.0
        };
        for j in 0..ns {
            let z_mid = 0.5 * (self.node_z[j] + self.node_z[j + 1]);
            let span_step = self.node_z[j + 1] - self.node_z[j];
            let mut column_normal = 0.0;
            for i in 0..nc {
                // Spanwise bound filament at the quarter panel: ρ Γ_net Q_y Δs along +x.
                let p = [0.0, self.ring_y[i], z_mid];
                let wake = if i > 0 {
                    midpoint(wake_at(i - 1, j), wake_at(i, j))
                } else {
                    wake_at(i, j)
                };
                let q = relative(fluid, omega, wake, p);
                let net = gamma(i, j) - if i > 0 { gamma(i - 1, j) } else { 0.0 };
                let f = rho * net * q[1] * span_step;
                add(p, [f, 0.0, 0.0]);
                column_normal += f;
                // Unsteady term −ρ ∂Γ/∂t ΔS at the ring centre, over the ring's part on the plate.
                let k = i * ns + j;
                let area = self.on_plate[i] * span_step;
                let f = -rho * (s.gamma[k] - s.gamma_before[k]) * rate * area;
                add(self.collocation[k], [f, 0.0, 0.0]);
                column_normal += f;
            }
            // Leading-edge suction of the column (locally 2-D singularity), the part beyond the
            // critical LESP turned into normal force (Polhamus).
            let p_le = [0.0, self.y_le, z_mid];
            let q = relative(fluid, omega, [0.0; 3], [0.0, 0.0, z_mid]);
            let speed = q[0].hypot(q[1]);
            let g1 = gamma(0, j);
            let suction = self.suction_factor * g1 * g1 * span_step;
            let kept = match self.params.lesp_crit {
                Some(lesp) if g1.abs() > lesp * self.lesp_circulation_m * speed => {
                    lesp * self.lesp_circulation_m * speed / g1.abs()
                }
                _ => 1.0,
            };
            let turned = (1.0 - kept) * suction * column_normal.signum();
            add(p_le, [turned, kept * suction, 0.0]);
            // Profile drag −C_D0·½ρc·U·t along the chord at the pitch axis (t: the plate's
            // chordwise velocity relative to the fluid, −Q_y).
            let drag = 0.5 * rho * c * self.params.profile_drag * speed * q[1] * span_step;
            add([0.0, 0.0, z_mid], [0.0, drag, 0.0]);
        }
        // Chordwise bound filaments at the nodes: −ρ Γ_net Q_z Δc along +x.
        for j in 0..=ns {
            for i in 0..nc {
                let right = if j < ns { gamma(i, j) } else { 0.0 };
                let left = if j > 0 { gamma(i, j - 1) } else { 0.0 };
                let wake = match (j > 0, j < ns) {
                    (true, true) => midpoint(wake_at(i, j - 1), wake_at(i, j)),
                    (true, false) => wake_at(i, j - 1),
                    _ => wake_at(i, j),
                };
                let p = [
                    0.0,
                    0.5 * (self.ring_y[i] + self.ring_y[i + 1]),
                    self.node_z[j],
                ];
                let q = relative(fluid, omega, wake, p);
                let length = self.ring_y[i] - self.ring_y[i + 1];
                add(p, [-rho * (right - left) * q[2] * length, 0.0, 0.0]);
            }
        }
        [
            force[0],
            force[1],
            1e3 * moment[0],
            1e3 * moment[1],
            1e3 * moment[2],
        ]
    }
}

/// The fluid's velocity relative to the plate point `p` (wing frame, m/s): the fluid's own
/// motion `fluid` plus the wake's `wake`, less the point's ω × p.
fn relative(fluid: [f64; 3], omega: [f64; 3], wake: [f64; 3], p: [f64; 3]) -> [f64; 3] {
    sub(add(fluid, wake), cross(omega, p))
}

fn dot_slice(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

/// R·v.
fn mul(r: &Mat3, v: [f64; 3]) -> [f64; 3] {
    [0, 1, 2].map(|i| r[i][0] * v[0] + r[i][1] * v[1] + r[i][2] * v[2])
}

/// Rᵀ·v.
fn mul_transposed(r: &Mat3, v: [f64; 3]) -> [f64; 3] {
    [0, 1, 2].map(|i| r[0][i] * v[0] + r[1][i] * v[1] + r[2][i] * v[2])
}
