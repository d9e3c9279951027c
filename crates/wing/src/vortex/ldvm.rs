//! The 2-D LDVM solver for one plate section (equations in the [module docs](super)).

use std::f64::consts::PI;

use super::wake::{LANES, PlateFrame, Wake, induced_at};
use super::{LdvmParams, MergeParams, VortexError, VortexKind, WakeMotion};

/// Pose and velocity of the plate in the inertial plane.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct PlateState {
    /// Pivot position [X, Z] (m).
    pub pivot_m: [f64; 2],
    /// Pivot velocity [Ẋ, Ż] (m/s).
    pub pivot_vel_m_s: [f64; 2],
    /// Chord angle ϑ (rad): t̂ = (cos ϑ, sin ϑ) points from the leading to the trailing edge.
    pub angle_rad: f64,
    /// ϑ̇ = Ω (rad/s), counter-clockwise positive.
    pub angle_rate_rad_s: f64,
}

/// Sectional loads per unit span, in plate axes.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct SectionLoads {
    /// Normal force N' along n̂ (N/m).
    pub normal_n_m: f64,
    /// Chordwise force along t̂ (leading → trailing edge) (N/m); the suction makes it negative.
    pub chord_n_m: f64,
    /// Moment about the pivot, counter-clockwise positive (N·m/m = N).
    pub moment_pivot_n: f64,
}

/// Per-step state of the solution, for inspection and tests.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct LdvmDiagnostics {
    /// Leading-edge suction parameter LESP = A0 = B0/U_ref (after shedding).
    pub lesp: f64,
    /// LESP with the TEV alone, before any LEV is shed: the shedding criterion.
    pub lesp_unshed: f64,
    /// [B0, B1, B2, B3] (m/s).
    pub fourier_m_s: [f64; 4],
    /// Bound circulation, counter-clockwise (m²/s): −cπ(B0 + B1/2).
    pub bound_circulation_m2_s: f64,
    /// Strength of the TEV shed this step (m²/s, counter-clockwise).
    pub tev_m2_s: f64,
    /// Strength of the LEV shed this step (0 when none).
    pub lev_m2_s: f64,
    /// Number of free vortices after this step.
    pub n_vortices: usize,
    /// Terms of N' (N/m): [ρV_t cπ(B0 + B1/2) (circulatory, plate motion), ρΣ u_t,j Γ_j (free-vortex
    /// induced), ρπc²(¾Ḃ0 + ¼Ḃ1 + ⅛Ḃ2) (unsteady), −ρcΓ_LEV/Δt (LE feeding sheet)].
    pub normal_terms_n_m: [f64; 4],
}

/// 2-D LDVM for a flat plate. Built once, stepped with [`Ldvm::step`]; all storage is
/// allocated in [`Ldvm::new`] (the step allocates nothing).
///
/// Cost per step: O(n_chord·N + N²/2) with N ≤ `max_vortices` free vortices.
#[derive(Debug, Clone)]
pub struct Ldvm {
    p: LdvmParams,
    /// The current U_ref (m/s): `p.u_ref_m_s` until [`Ldvm::set_reference_speed`] changes it.
    u_ref_m_s: f64,
    c: f64,
    xp: f64,
    rc4: f64,
    n_f: usize,
    /// Chord positions of the collocation points / bound elements (m from the LE).
    xc: Vec<f64>,
    /// Fourier quadrature weights, row n: B_n = Σ_j q[n·n_chord + j] W_j.
    q: Vec<f64>,
    /// Element weights, row j: Γ_j = c Σ_n pw[j·n_f + n] B_n (clockwise).
    pw: Vec<f64>,
    wn: Vec<f64>,
    ut: Vec<f64>,
    wn_tev: Vec<f64>,
    ut_tev: Vec<f64>,
    wn_lev: Vec<f64>,
    ut_lev: Vec<f64>,
    b: Vec<f64>,
    b_prev: Vec<f64>,
    b_prev2: Vec<f64>,
    dt_prev_s: f64,
    bx: Vec<f64>,
    bz: Vec<f64>,
    bg_ccw: Vec<f64>,
    wake: Wake,
    step: u64,
    last_lev_step: Option<u64>,
    prev_speed_m_s: f64,
    prev_frame: PlateFrame,
    diag: LdvmDiagnostics,
}

/// Lamb–Oseen vortex: the radius of peak swirl velocity is r_c = 2.2418·√(νt), so
/// r_c² grows by 5.0257·ν per second.
const LAMB_OSEEN_CORE: f64 = 5.0257;

/// Coefficients of the unsteady normal force: N'_unsteady = ρπc² Σ NF_n Ḃ_n.
const NF: [f64; 3] = [0.75, 0.25, 0.125];
/// Coefficients of the unsteady moment about the LE: ρπc³ Σ MF_n Ḃ_n.
const MF: [f64; 4] = [7.0 / 16.0, 11.0 / 64.0, 1.0 / 16.0, -1.0 / 64.0];

impl Ldvm {
    /// Validates `params` and allocates all storage.
    pub fn new(params: LdvmParams) -> Result<Self, VortexError> {
        params.check()?;
        let (nc, nf) = (params.n_chord, params.n_fourier);
        let c = params.chord_m;
        let dth = PI / (nc - 1) as f64;
        let theta: Vec<f64> = (0..nc).map(|j| j as f64 * dth).collect();
        let xc: Vec<f64> = theta.iter().map(|t| 0.5 * c * (1.0 - t.cos())).collect();
        let mut q = vec![0.0; nf * nc];
        for n in 0..nf {
            for (j, &th) in theta.iter().enumerate() {
                let wj = if j == 0 || j == nc - 1 {
                    0.5 * dth
                } else {
                    dth
                };
                q[n * nc + j] = if n == 0 {
                    wj / PI
                } else {
                    -2.0 * wj * (n as f64 * th).cos() / PI
                };
            }
        }
        // ∫ of (1+cos θ) [n = 0] and sin nθ sin θ [n ≥ 1] over each element's θ range.
        let prim = |n: usize, t: f64| -> f64 {
            match n {
                0 => t + t.sin(),
                1 => 0.5 * (t - t.sin() * t.cos()),
                _ => {
                    let (a, b) = ((n - 1) as f64, (n + 1) as f64);
                    0.5 * ((a * t).sin() / a - (b * t).sin() / b)
                }
            }
        };
        let mut pw = vec![0.0; nc * nf];
        for (j, &th) in theta.iter().enumerate() {
            let lo = (th - 0.5 * dth).max(0.0);
            let hi = (th + 0.5 * dth).min(PI);
            for n in 0..nf {
                pw[j * nf + n] = prim(n, hi) - prim(n, lo);
            }
        }
        let rc = params.core_radius_frac * c;
        Ok(Self {
            c,
            xp: params.pivot_frac * c,
            rc4: rc.powi(4),
            n_f: nf,
            xc,
            q,
            pw,
            wn: vec![0.0; nc],
            ut: vec![0.0; nc],
            wn_tev: vec![0.0; nc],
            ut_tev: vec![0.0; nc],
            wn_lev: vec![0.0; nc],
            ut_lev: vec![0.0; nc],
            b: vec![0.0; nf],
            b_prev: vec![0.0; nf],
            b_prev2: vec![0.0; nf],
            dt_prev_s: 0.0,
            bx: vec![0.0; nc],
            bz: vec![0.0; nc],
            bg_ccw: vec![0.0; nc],
            wake: Wake::with_capacity(params.max_vortices, rc),
            step: 0,
            last_lev_step: None,
            prev_speed_m_s: 0.0,
            prev_frame: PlateFrame::default(),
            diag: LdvmDiagnostics::default(),
            u_ref_m_s: params.u_ref_m_s,
            p: params,
        })
    }

    /// The validated parameters (`u_ref_m_s` as constructed; see [`Ldvm::reference_speed`]).
    pub fn params(&self) -> &LdvmParams {
        &self.p
    }

    /// The U_ref (m/s) in use: the constructed one until [`Ldvm::set_reference_speed`].
    pub fn reference_speed(&self) -> f64 {
        self.u_ref_m_s
    }

    /// Back to the state before the first step (fluid at rest, no vortices).
    pub fn reset(&mut self) {
        self.wake.clear();
        self.b.fill(0.0);
        self.b_prev.fill(0.0);
        self.b_prev2.fill(0.0);
        self.dt_prev_s = 0.0;
        self.bg_ccw.fill(0.0);
        self.step = 0;
        self.last_lev_step = None;
        self.prev_speed_m_s = 0.0;
        self.prev_frame = PlateFrame::default();
        self.u_ref_m_s = self.p.u_ref_m_s;
        self.diag = LdvmDiagnostics::default();
    }

    /// Removes every free vortex (wake and LEVs) to infinity but keeps the bound sheet and its
    /// history: the plate no longer feels their induced velocity, and their circulation stays
    /// in Kelvin's balance, so nothing is shed to replace them. For wake-capture experiments.
    pub fn clear_wake(&mut self) {
        self.wake.remove_all_to_far();
        self.last_lev_step = None;
    }

    /// Sets U_ref (m/s, > 0 and finite; other values are ignored) for the LESP criterion and
    /// amalgamation from the next step on.
    pub fn set_reference_speed(&mut self, u_ref_m_s: f64) {
        if u_ref_m_s.is_finite() && u_ref_m_s > 0.0 {
            self.u_ref_m_s = u_ref_m_s;
        }
    }

    /// The free vortices.
    pub fn wake(&self) -> &Wake {
        &self.wake
    }

    /// Bound elements after the last step: chord positions (m from the LE) and counter-clockwise
    /// circulations (m²/s), each of length `n_chord`.
    pub fn bound_elements(&self) -> (&[f64], &[f64]) {
        (&self.xc, &self.bg_ccw)
    }

    /// Diagnostics of the last step.
    pub fn diagnostics(&self) -> &LdvmDiagnostics {
        &self.diag
    }

    /// Advances to the plate state `plate`, `dt_s` after the previous call (for the first call,
    /// after the plate started from rest in still fluid), and returns the loads at that instant.
    ///
    /// Errors: non-finite input, `dt_s` ≤ 0, or a singular shedding system.
    pub fn step(&mut self, plate: &PlateState, dt_s: f64) -> Result<SectionLoads, VortexError> {
        self.check_input(plate, dt_s)?;
        let c = self.c;
        let [vx, vz] = plate.pivot_vel_m_s;
        let speed = vx.hypot(vz);
        if self.step > 0 {
            self.advance_wake(plate, dt_s, speed);
        }
        let omega = plate.angle_rate_rad_s;
        let (s, co) = plate.angle_rad.sin_cos();
        let (tx, tz) = (co, s);
        let (nx, nz) = (-s, co);
        let le = [
            plate.pivot_m[0] - self.xp * tx,
            plate.pivot_m[1] - self.xp * tz,
        ];
        let vpn = vx * nx + vz * nz;
        let vpt = vx * tx + vz * tz;

        // downwash of everything but the bound sheet and the new vortices
        for j in 0..self.xc.len() {
            self.bx[j] = le[0] + self.xc[j] * tx;
            self.bz[j] = le[1] + self.xc[j] * tz;
        }
        // (wn, ut) first hold the wake's (u, w)
        self.wake
            .velocities_at(&self.bx, &self.bz, &mut self.wn, &mut self.ut);
        for j in 0..self.xc.len() {
            let (u, w) = (self.wn[j], self.ut[j]);
            self.wn[j] = u * nx + w * nz - vpn - omega * (self.xc[j] - self.xp);
            self.ut[j] = u * tx + w * tz;
        }
        let kb = |b0: f64, b1: f64| c * PI * (b0 + 0.5 * b1);
        let (b0b, b1b) = (self.coef(0, Field::Base), self.coef(1, Field::Base));
        let s_free = self.wake.total_circulation();

        // new TEV: 1/3 of the way from the TE to the previous TEV while that one lies behind the
        // TE; otherwise (first TEV, or after a reversal has carried the plate over its wake) half a
        // step downstream. Placed towards a TEV over the plate, the new one would sit on the plate
        // (1 − kb → 0) and the Kelvin solve would shed a runaway TEV.
        let te = [le[0] + c * tx, le[1] + c * tz];
        let v_te = [
            vx - omega * (c - self.xp) * tz,
            vz + omega * (c - self.xp) * tx,
        ];
        let p_tev = match self.wake.last_tev.map(|i| self.wake.pos(i)) {
            Some((x, z)) if (x - le[0]) * tx + (z - le[1]) * tz > c => {
                [te[0] + (x - te[0]) / 3.0, te[1] + (z - te[1]) / 3.0]
            }
            _ => first_position(te, v_te, [tx, tz], dt_s, c),
        };
        self.unit_influence(p_tev, le, [tx, tz], [nx, nz], true);
        let (b0t, b1t) = (self.coef(0, Field::Tev), self.coef(1, Field::Tev));
        let a_t = 1.0 - kb(b0t, b1t);
        if a_t.abs() < 1e-12 {
            return Err(VortexError::SingularShedding {
                step: self.step,
                det: a_t,
            });
        }
        let rhs_k = kb(b0b, b1b) - s_free;
        let mut g_tev = rhs_k / a_t;
        let mut g_lev = 0.0;
        let mut p_lev = [0.0; 2];
        let lesp0 = (b0b + g_tev * b0t) / self.u_ref_m_s;
        if let Some(crit) = self.p.lesp_crit.filter(|&cr| lesp0.abs() > cr) {
            let v_le = [vx + omega * self.xp * tz, vz - omega * self.xp * tx];
            // continue the feeding sheet (1/3 of the way to the LEV shed the step before) only
            // while the LE keeps shedding the same sign (Γ_LEV = −sign(LESP)) and that LEV still
            // lies on the suction side (normal coordinate of the sign of LESP, the side a fresh
            // LEV takes). After a sign flip, or once the last LEV has drifted round the LE to the
            // other face, a new one placed towards it would have the wrong side: each such LEV
            // raises |LESP| instead of lowering it, and the 2×2 solve sheds runaway pairs
            let previous = match (self.wake.last_lev, self.last_lev_step) {
                (Some(i), Some(st)) if st + 1 == self.step => {
                    Some((self.wake.pos(i), self.wake.gamma_m2_s()[i]))
                }
                _ => None,
            };
            p_lev = match previous {
                Some(((x, z), g))
                    if g * lesp0 < 0.0 && ((x - le[0]) * nx + (z - le[1]) * nz) * lesp0 > 0.0 =>
                {
                    [le[0] + (x - le[0]) / 3.0, le[1] + (z - le[1]) / 3.0]
                }
                _ => {
                    // on the suction side, along the bisector of chord and normal (UNSflow's
                    // half-step-downstream point at 45°, kept off the plate at small angles)
                    let d = (0.5 * v_le[0].hypot(v_le[1]) * dt_s).max(self.p.core_radius_frac * c);
                    let sn = lesp0.signum() * std::f64::consts::FRAC_1_SQRT_2;
                    let k = d * std::f64::consts::FRAC_1_SQRT_2;
                    [le[0] + k * tx + d * sn * nx, le[1] + k * tz + d * sn * nz]
                }
            };
            self.unit_influence(p_lev, le, [tx, tz], [nx, nz], false);
            let (b0l, b1l) = (self.coef(0, Field::Lev), self.coef(1, Field::Lev));
            let a_l = 1.0 - kb(b0l, b1l);
            let det = b0t * a_l - b0l * a_t;
            if det.abs() < 1e-14 * (b0t.abs() + b0l.abs()) * (a_t.abs() + a_l.abs()) || det == 0.0 {
                return Err(VortexError::SingularShedding {
                    step: self.step,
                    det,
                });
            }
            let r0 = lesp0.signum() * crit * self.u_ref_m_s - b0b;
            g_tev = (r0 * a_l - b0l * rhs_k) / det;
            g_lev = (b0t * rhs_k - a_t * r0) / det;
        }

        // make room, then add the new vortices
        let need = if g_lev != 0.0 { 2 } else { 1 };
        if self.wake.len() + need > self.wake.capacity() {
            let d0 = self.p.merge.unwrap_or_default().d0_chords * c;
            self.wake
                .amalgamate(le, te, d0, 0.0, 0.0, self.p.max_vortices * 4 / 5);
            while self.wake.len() + need > self.wake.capacity() {
                self.wake.remove_weakest();
            }
        }
        self.wake.push(p_tev[0], p_tev[1], g_tev, VortexKind::Tev);
        if g_lev != 0.0 {
            self.wake.push(p_lev[0], p_lev[1], g_lev, VortexKind::Lev);
            self.last_lev_step = Some(self.step);
        }
        for j in 0..self.wn.len() {
            self.wn[j] += g_tev * self.wn_tev[j] + g_lev * self.wn_lev[j];
            self.ut[j] += g_tev * self.ut_tev[j] + g_lev * self.ut_lev[j];
        }
        for n in 0..self.n_f {
            self.b[n] = self.coef(n, Field::Base);
        }

        // bound elements and loads
        let rho = self.p.rho_kg_m3;
        let (mut sum_ut, mut sum_xut) = (0.0, 0.0);
        for j in 0..self.xc.len() {
            let row = &self.pw[j * self.n_f..(j + 1) * self.n_f];
            let g_cw: f64 = c * row.iter().zip(&self.b).map(|(w, b)| w * b).sum::<f64>();
            self.bg_ccw[j] = -g_cw;
            sum_ut += self.ut[j] * g_cw;
            sum_xut += self.xc[j] * self.ut[j] * g_cw;
        }
        // Ḃ: second-order backward difference on a non-uniform grid (first order on step 1)
        let (h1, h2) = (dt_s, self.dt_prev_s);
        let bd = |n: usize, s: &Self| {
            if s.step < 2 {
                (s.b[n] - s.b_prev[n]) / h1
            } else {
                let (d1, d2) = (s.b[n] - s.b_prev[n], s.b_prev[n] - s.b_prev2[n]);
                ((2.0 * h1 + h2) / (h1 * (h1 + h2))) * d1 - (h1 / (h2 * (h1 + h2))) * d2
            }
        };
        let (b0, b1, b2, b3) = (self.b[0], self.b[1], self.b[2], self.b[3]);
        let vt = -vpt;
        let n_terms = [
            rho * vt * kb(b0, b1),
            rho * sum_ut,
            rho * PI * c * c * (NF[0] * bd(0, self) + NF[1] * bd(1, self) + NF[2] * bd(2, self)),
            -rho * c * g_lev / dt_s,
        ];
        let normal = n_terms.iter().sum::<f64>();
        let m_le = rho * (vt * c * c * PI * (0.25 * b0 + 0.25 * b1 - 0.125 * b2) + sum_xut)
            + rho
                * PI
                * c.powi(3)
                * (MF[0] * bd(0, self)
                    + MF[1] * bd(1, self)
                    + MF[2] * bd(2, self)
                    + MF[3] * bd(3, self))
            + 0.5 * c * n_terms[3];
        let loads = SectionLoads {
            normal_n_m: normal,
            chord_n_m: -self.p.suction_factor * rho * PI * c * b0 * b0,
            moment_pivot_n: m_le - self.xp * normal,
        };

        // free-vortex velocities for the next convection
        let sheet = BoundSheet {
            le,
            t: [tx, tz],
            n: [nx, nz],
            c,
            eps4: (4.0 * self.p.core_radius_frac).powi(2),
            b: &self.b,
        };
        match self.p.wake_motion {
            WakeMotion::Free => self
                .wake
                .compute_velocities(|x, z, u, w| sheet.velocities_at(x, z, u, w)),
            WakeMotion::Frozen => self.wake.hold_still(),
        }
        self.diag = LdvmDiagnostics {
            lesp: b0 / self.u_ref_m_s,
            lesp_unshed: lesp0,
            fourier_m_s: [b0, b1, b2, b3],
            bound_circulation_m2_s: -kb(b0, b1),
            tev_m2_s: g_tev,
            lev_m2_s: g_lev,
            n_vortices: self.wake.len(),
            normal_terms_n_m: n_terms,
        };
        self.b_prev2.copy_from_slice(&self.b_prev);
        self.b_prev.copy_from_slice(&self.b);
        self.dt_prev_s = dt_s;
        self.prev_speed_m_s = speed;
        self.prev_frame = PlateFrame {
            le,
            t: [tx, tz],
            n: [nx, nz],
        };
        self.step += 1;
        Ok(loads)
    }

    fn check_input(&self, p: &PlateState, dt_s: f64) -> Result<(), VortexError> {
        let fields = [
            ("pivot_m[0]", p.pivot_m[0]),
            ("pivot_m[1]", p.pivot_m[1]),
            ("pivot_vel_m_s[0]", p.pivot_vel_m_s[0]),
            ("pivot_vel_m_s[1]", p.pivot_vel_m_s[1]),
            ("angle_rad", p.angle_rad),
            ("angle_rate_rad_s", p.angle_rate_rad_s),
            ("dt_s", dt_s),
        ];
        for (field, value) in fields {
            if !value.is_finite() {
                return Err(VortexError::NonFiniteKinematics {
                    step: self.step,
                    field,
                    value,
                });
            }
        }
        if dt_s <= 0.0 {
            return Err(VortexError::InvalidParameter {
                name: "dt_s",
                value: dt_s,
                reason: "must be > 0",
            });
        }
        Ok(())
    }

    /// Convects, decays, deletes and amalgamates the free vortices over the step of `dt_s`.
    fn advance_wake(&mut self, plate: &PlateState, dt_s: f64, speed: f64) {
        let c = self.c;
        let (s, co) = plate.angle_rad.sin_cos();
        let frame = PlateFrame {
            le: [
                plate.pivot_m[0] - self.xp * co,
                plate.pivot_m[1] - self.xp * s,
            ],
            t: [co, s],
            n: [-s, co],
        };
        self.wake.convect(dt_s, &self.prev_frame, &frame, c);
        let travel_chords = 0.5 * (speed + self.prev_speed_m_s) * dt_s / c;
        let f = |s: Option<f64>| s.map_or(1.0, |s| (-travel_chords / s).exp());
        let (f_tev, f_lev) = (f(self.p.tev_decay_chords), f(self.p.lev_decay_chords));
        if f_tev != 1.0 || f_lev != 1.0 {
            self.wake.decay(f_tev, f_lev);
        }
        if let Some(re) = self.p.core_growth_reynolds {
            self.wake
                .grow_cores(LAMB_OSEEN_CORE * travel_chords * c * c / re);
        }
        let [px, pz] = plate.pivot_m;
        if let Some(r) = self.p.far_field_chords {
            self.wake.delete_far(px, pz, (r * c).powi(2));
        }
        let merge = self
            .p
            .merge
            .filter(|m| self.step % m.interval_steps as u64 == 0);
        if let Some(MergeParams {
            d0_chords,
            v0,
            near_chords,
            ..
        }) = merge
        {
            let v0_dim = v0 * self.u_ref_m_s / c;
            let (s, co) = plate.angle_rad.sin_cos();
            let le = [px - self.xp * co, pz - self.xp * s];
            let te = [le[0] + c * co, le[1] + c * s];
            let target = self.p.max_vortices * 4 / 5;
            self.wake
                .amalgamate(le, te, d0_chords * c, near_chords * c, v0_dim, target);
        }
    }

    /// Normal and chordwise velocity at the collocation points induced by a unit vortex at `pv`.
    fn unit_influence(&mut self, pv: [f64; 2], le: [f64; 2], t: [f64; 2], n: [f64; 2], tev: bool) {
        let (wn, ut) = if tev {
            (&mut self.wn_tev, &mut self.ut_tev)
        } else {
            (&mut self.wn_lev, &mut self.ut_lev)
        };
        for j in 0..self.xc.len() {
            let (px, pz) = (le[0] + self.xc[j] * t[0], le[1] + self.xc[j] * t[1]);
            let (u, w) = induced_at(px, pz, &[pv[0]], &[pv[1]], &[1.0], self.rc4);
            wn[j] = u * n[0] + w * n[1];
            ut[j] = u * t[0] + w * t[1];
        }
    }

    /// Fourier coefficient B_n of a normal-velocity field.
    fn coef(&self, n: usize, field: Field) -> f64 {
        let nc = self.xc.len();
        let w = match field {
            Field::Base => &self.wn,
            Field::Tev => &self.wn_tev,
            Field::Lev => &self.wn_lev,
        };
        self.q[n * nc..(n + 1) * nc]
            .iter()
            .zip(w)
            .map(|(q, w)| q * w)
            .sum()
    }
}

/// The bound vortex sheet of the plate, γ(θ) = 2[B0 (1 + cos θ)/sin θ + Σ B_n sin nθ].
///
/// Its velocity off the plate is exact for the truncated series (conformal map of the plate to
/// the unit circle): in plate axes (x along t̂ from the LE, z along n̂), with
/// x + iz − c/2 = −(c/4)(σ + 1/σ), |σ| ≥ 1,
///
/// u − iw = −2iB0/(σ − 1) − i Σ_{n≥1} B_n σ^{−n}   (m/s).
///
/// On the plate this gives w = −B0 + Σ B_n cos nθ (cancelling the downwash W_n) and the jump
/// u_upper − u_lower = γ. The square-root singularity at the LE is regularised over the vortex
/// core: 1/(σ − 1) → conj(σ − 1)/√(|σ − 1|⁴ + ε⁴), ε² = 4 r_c/c (|σ − 1|² ≈ 4r/c at distance r).
pub(crate) struct BoundSheet<'a> {
    pub le: [f64; 2],
    pub t: [f64; 2],
    pub n: [f64; 2],
    pub c: f64,
    pub eps4: f64,
    pub b: &'a [f64],
}

impl BoundSheet<'_> {
    /// Velocity (m/s, inertial axes) induced by the sheet at (px, pz).
    pub fn velocity_at(&self, px: f64, pz: f64) -> (f64, f64) {
        let (u, w) = self.velocity_lanes(&[px], &[pz]);
        (u[0], w[0])
    }

    /// Velocities (m/s) at the points (px, pz), written to (u, w): [`BoundSheet::velocity_at`]
    /// bit for bit, computed for `LANES` points at a time so that it vectorizes.
    pub fn velocities_at(&self, px: &[f64], pz: &[f64], u: &mut [f64], w: &mut [f64]) {
        let (xc, zc) = (px.chunks_exact(LANES), pz.chunks_exact(LANES));
        let (uc, wc) = (u.chunks_exact_mut(LANES), w.chunks_exact_mut(LANES));
        let tail = xc.len() * LANES;
        for (((x, z), uk), wk) in xc.zip(zc).zip(uc).zip(wc) {
            let (ul, wl) = self.velocity_lanes::<LANES>(
                x.try_into().expect("chunk of LANES"),
                z.try_into().expect("chunk of LANES"),
            );
            uk.copy_from_slice(&ul);
            wk.copy_from_slice(&wl);
        }
        for k in tail..px.len() {
            (u[k], w[k]) = self.velocity_at(px[k], pz[k]);
        }
    }

    /// The sheet velocity at `L` points, each lane computed independently.
    #[inline(always)]
    fn velocity_lanes<const L: usize>(&self, px: &[f64; L], pz: &[f64; L]) -> ([f64; L], [f64; L]) {
        // σ: the root of x + iz − c/2 = −(c/4)(σ + 1/σ) outside the unit circle
        let (mut sgr, mut sgi) = ([0.0; L], [0.0; L]);
        for k in 0..L {
            let (dx, dz) = (px[k] - self.le[0], pz[k] - self.le[1]);
            let x = dx * self.t[0] + dz * self.t[1];
            let z = dx * self.n[0] + dz * self.n[1];
            // s = 2(x + iz − c/2)/c; σ = −s ± √(s² − 1)
            let (sr, si) = (2.0 * x / self.c - 1.0, 2.0 * z / self.c);
            let (qr, qi) = csqrt(sr * sr - si * si - 1.0, 2.0 * sr * si);
            let (a, b) = ((-sr + qr, -si + qi), (-sr - qr, -si - qi));
            let pick_a = a.0 * a.0 + a.1 * a.1 >= b.0 * b.0 + b.1 * b.1;
            sgr[k] = if pick_a { a.0 } else { b.0 };
            sgi[k] = if pick_a { a.1 } else { b.1 };
        }
        // F = u − iw = −i[2B0/(σ − 1) + Σ B_n σ^{−n}], 1/(σ − 1) regularised
        let (mut fr, mut fi) = ([0.0; L], [0.0; L]);
        let (mut rr, mut ri) = ([0.0; L], [0.0; L]);
        for k in 0..L {
            let (er, ei) = (sgr[k] - 1.0, sgi[k]);
            let m2 = er * er + ei * ei;
            let inv = 1.0 / (m2 * m2 + self.eps4).sqrt();
            fr[k] = 2.0 * self.b[0] * (er * inv);
            fi[k] = 2.0 * self.b[0] * (-ei * inv);
            let d2 = sgr[k] * sgr[k] + sgi[k] * sgi[k];
            (rr[k], ri[k]) = (sgr[k] / d2, -sgi[k] / d2); // 1/σ
        }
        let (mut pr, mut pi) = ([1.0; L], [0.0; L]);
        for &bn in &self.b[1..] {
            for k in 0..L {
                (pr[k], pi[k]) = (pr[k] * rr[k] - pi[k] * ri[k], pr[k] * ri[k] + pi[k] * rr[k]);
                fr[k] += bn * pr[k];
                fi[k] += bn * pi[k];
            }
        }
        // multiply by −i: (fr + i fi)(−i) = fi − i fr  →  u = fi, w = fr
        let (mut u, mut w) = ([0.0; L], [0.0; L]);
        for k in 0..L {
            u[k] = fi[k] * self.t[0] + fr[k] * self.n[0];
            w[k] = fi[k] * self.t[1] + fr[k] * self.n[1];
        }
        (u, w)
    }
}

/// Principal square root of a + ib.
#[inline(always)]
fn csqrt(a: f64, b: f64) -> (f64, f64) {
    // |a + ib| without `hypot`'s overflow guard: the arguments are O(1) (chord-scaled)
    let r = (a * a + b * b).sqrt();
    let re = (0.5 * (r + a)).max(0.0).sqrt();
    let im = (0.5 * (r - a)).max(0.0).sqrt();
    (re, if b < 0.0 { -im } else { im })
}

#[derive(Clone, Copy)]
enum Field {
    Base,
    Tev,
    Lev,
}

/// Position of a first shed vortex: half a step along the relative flow −v_edge from the edge,
/// or 10⁻³ c along `t` when the edge is (nearly) at rest.
fn first_position(edge: [f64; 2], v_edge: [f64; 2], t: [f64; 2], dt_s: f64, c: f64) -> [f64; 2] {
    let d = [-0.5 * v_edge[0] * dt_s, -0.5 * v_edge[1] * dt_s];
    if d[0].hypot(d[1]) > 1e-3 * c {
        [edge[0] + d[0], edge[1] + d[1]]
    } else {
        [edge[0] + 1e-3 * c * t[0], edge[1] + 1e-3 * c * t[1]]
    }
}

#[cfg(test)]
mod tests {
    use super::super::wake::induced_at;
    use super::*;

    /// The load weights equal the chord integrals of the pressure jump, by quadrature.
    #[test]
    fn load_weights_match_pressure_integrals() {
        let n = 200_000;
        // ∫_0^c ∫_0^x γ dξ dx = ∫ γ (c − ξ) dξ and ∫ x ∫_0^x γ = ∫ γ (c² − ξ²)/2, c = 1, per B_n;
        // γ dξ = [B0 (1 + cos θ) + B_n sin nθ sin θ] dθ (c = 1).
        for k in 0..4 {
            let (mut f, mut m) = (0.0, 0.0);
            for i in 0..n {
                let th = (i as f64 + 0.5) * PI / n as f64;
                let xi = 0.5 * (1.0 - th.cos());
                let g = if k == 0 {
                    1.0 + th.cos()
                } else {
                    (k as f64 * th).sin() * th.sin()
                };
                f += g * (1.0 - xi) * PI / n as f64;
                m += g * 0.5 * (1.0 - xi * xi) * PI / n as f64;
            }
            let nf = if k < 3 { NF[k] } else { 0.0 };
            assert!(
                (f / PI - nf).abs() < 1e-9,
                "normal weight {k}: {} vs {nf}",
                f / PI
            );
            assert!(
                (m / PI - MF[k]).abs() < 1e-9,
                "moment weight {k}: {} vs {}",
                m / PI,
                MF[k]
            );
        }
    }

    /// The closed-form sheet velocity equals the Biot–Savart sum over a fine discretisation of
    /// γ, off the plate (tilted plate, points above, below, ahead and behind).
    #[test]
    fn sheet_velocity_matches_biot_savart_quadrature() {
        let c = 0.7;
        let b = [0.3, -0.2, 0.1, 0.05, -0.02];
        let th0: f64 = 0.4;
        let (t, n) = ([th0.cos(), th0.sin()], [-th0.sin(), th0.cos()]);
        let le = [0.2, -0.1];
        let sheet = BoundSheet {
            le,
            t,
            n,
            c,
            eps4: 0.0,
            b: &b,
        };
        let m = 400_000;
        let (mut xs, mut zs, mut gs) = (vec![], vec![], vec![]);
        for i in 0..m {
            let th = (i as f64 + 0.5) * PI / m as f64;
            let x = 0.5 * c * (1.0 - th.cos());
            // γ dξ = c [B0 (1 + cos θ) + Σ B_n sin nθ sin θ] dθ, clockwise
            let mut g = b[0] * (1.0 + th.cos());
            for (k, bk) in b.iter().enumerate().skip(1) {
                g += bk * (k as f64 * th).sin() * th.sin();
            }
            xs.push(le[0] + x * t[0]);
            zs.push(le[1] + x * t[1]);
            gs.push(-c * g * PI / m as f64);
        }
        for (xp, zp) in [
            (0.3, 0.2),
            (0.5, -0.15),
            (-0.1, 0.05),
            (1.2, 0.1),
            (0.05, 0.03),
        ] {
            let (px, pz) = (le[0] + xp * t[0] + zp * n[0], le[1] + xp * t[1] + zp * n[1]);
            let (u, w) = sheet.velocity_at(px, pz);
            let (ue, we) = induced_at(px, pz, &xs, &zs, &gs, 1e-30);
            let scale = ue.hypot(we);
            assert!(
                (u - ue).hypot(w - we) < 1e-5 * scale.max(1e-3),
                "at ({xp}, {zp}): ({u}, {w}) vs ({ue}, {we})"
            );
        }
    }

    /// Element circulations integrate γ exactly: their sum is cπ(B0 + B1/2).
    #[test]
    fn element_weights_sum_to_bound_circulation() {
        let l = Ldvm::new(LdvmParams::default()).unwrap();
        let nf = l.n_f;
        for n in 0..nf {
            let s: f64 = (0..l.xc.len()).map(|j| l.pw[j * nf + n]).sum();
            let expect = match n {
                0 => PI,
                1 => PI / 2.0,
                _ => 0.0,
            };
            assert!((s - expect).abs() < 1e-12, "n = {n}: {s}");
        }
    }

    /// Quadrature weights recover the Fourier coefficients of a known downwash.
    #[test]
    fn fourier_weights_recover_linear_downwash() {
        // W_n = a + b·cos θ  →  B0 = a, B1 = −b, B_n≥2 = 0 (trapezoid is exact for these).
        let mut l = Ldvm::new(LdvmParams::default()).unwrap();
        let nc = l.xc.len();
        for j in 0..nc {
            let th = PI * j as f64 / (nc - 1) as f64;
            l.wn[j] = 0.3 + 0.7 * th.cos();
        }
        assert!((l.coef(0, Field::Base) - 0.3).abs() < 1e-12);
        assert!((l.coef(1, Field::Base) + 0.7).abs() < 1e-12);
        assert!(l.coef(2, Field::Base).abs() < 1e-12);
    }
}
