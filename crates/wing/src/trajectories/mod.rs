//! Seeded generator of servo-feasible 3-DoF wing trajectories, and their sampling.
//!
//! Every trajectory is an analytic function of time, θ(t) = r(t)·g(2πft) for each Euler angle,
//! with g a finite Fourier series (rad) and r the C² ramp-in r(t) = 10s³ − 15s⁴ + 6s⁵,
//! s = min(t/T_ramp, 1), T_ramp = 1–2 cycles. Rates and accelerations are therefore exact
//! (`θ̇ = ṙg + rġ`, `θ̈ = r̈g + 2ṙġ + rg̈`).
//!
//! With x = 2πft the stroke is φ ≈ φ₀ + Φ sin x (plus small harmonics, scaled so that the
//! half peak-to-peak amplitude is exactly Φ), so φ̇ > 0 around x = 0
//! and φ̇ < 0 around x = π. Families differ in the deviation ψ:
//!
//! | family | deviation ψ |
//! |---|---|
//! | figure-eight | −Ψ sin(2x + p), tip path crosses itself, tip rising through the reversals |
//! | u-shaped | −Ψ cos(2x + p), p ∈ [−0.4, 0], Ψ ≤ 0.3Φ (highest at or just after each reversal) |
//! | oval | Ψ cos(x + p) (the two half-strokes at different heights) |
//! | flat | |ψ| ≤ 3° |
//! | harmonic | random harmonics 1–3, half peak-to-peak 5–40° (and random harmonics on φ and α) |
//!
//! Pitch α = −A_m S(x + δ) − A_d S(x + δ)², with S a Fejér-smoothed square wave (odd harmonics
//! up to K ∈ {1, 3, 5, 7}) in phase with φ̇ and normalised to S(0) = 1. The two plateau values
//! −A_1 = −(A_m + A_d) (φ̇ > 0) and A_2 = A_m − A_d (φ̇ < 0) are solved so that the angle of
//! attack at the plateau centre equals its target exactly: since v = R_z(−α)·v|_{α=0},
//! AoA(α) = AoA(α = 0) − α. Conventional targets have |AoA| 20–70° with the hovering sign
//! (AoA·φ̇ < 0); an unconventional half-stroke has |AoA| near zero or the opposite sign
//! (paper test trajectories #5 and #32).

use crate::cycles::{self, CycleError, U_REF_RADIUS_M};
use crate::dataset::{Dataset, DatasetError, Trajectory, ValidDataset};
use crate::dataset::{DatasetMeta, FORMAT_VERSION, Fluid, INPUT_UNITS, OUTPUT_UNITS, WingGeometry};
use crate::kinematics::{EulerState, WingKinematics};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use std::f64::consts::PI;
use thiserror::Error;

const DEG: f64 = PI / 180.0;
/// Grid points per period used to bound the periodic part of each angle.
const BOUND_GRID: usize = 2048;
/// Attempts per trajectory before giving up on the feasibility constraints.
const MAX_ATTEMPTS: usize = 1000;

/// Errors of the trajectory generator.
#[derive(Debug, Clone, PartialEq, Error)]
#[non_exhaustive]
pub enum TrajectoryError {
    /// A configuration field is out of range.
    #[error("invalid trajectory config: {field} = {value} ({reason})")]
    InvalidConfig {
        /// Field name.
        field: &'static str,
        /// Its value.
        value: f64,
        /// What is required.
        reason: &'static str,
    },
    /// No feasible trajectory was found for one index.
    #[error(
        "trajectory {index}: no feasible trajectory in {attempts} attempts (limits too tight?)"
    )]
    Infeasible {
        /// Trajectory index.
        index: usize,
        /// Attempts made.
        attempts: usize,
    },
    /// U_ref could not be computed.
    #[error("trajectory {index}: U_ref cannot be computed")]
    Cycle {
        /// Trajectory index.
        index: usize,
        /// Cause.
        source: CycleError,
    },
    /// Differentiating measured angles failed.
    #[error("trajectory {index}: differentiating the measured angles: {source}")]
    Differentiate {
        /// Trajectory index.
        index: usize,
        /// Cause.
        source: crate::differentiate::DifferentiateError,
    },
    /// The assembled dataset failed [`Dataset::validate`].
    #[error("the generated dataset is invalid: {0}")]
    Invalid(#[from] DatasetError),
}

/// Trajectory family (shape of the tip path).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Family {
    /// Figure-of-eight: deviation at twice the stroke frequency.
    FigureEight,
    /// U-shaped: tip rises at both reversals.
    UShaped,
    /// Oval: deviation at the stroke frequency.
    Oval,
    /// Flat: (almost) no deviation.
    Flat,
    /// Free random harmonics on all three angles.
    Harmonic,
}

impl Family {
    /// All families.
    pub const ALL: [Family; 5] = [
        Family::FigureEight,
        Family::UShaped,
        Family::Oval,
        Family::Flat,
        Family::Harmonic,
    ];

    /// Label stored in datasets.
    pub fn label(self) -> &'static str {
        match self {
            Family::FigureEight => "figure-eight",
            Family::UShaped => "u-shaped",
            Family::Oval => "oval",
            Family::Flat => "flat",
            Family::Harmonic => "harmonic",
        }
    }
}

mod fourier;
pub mod harmonic;
pub mod measured;
pub mod paper;
mod spec;
pub mod stats;

pub use fourier::FourierSeries;
use fourier::smooth_square;
pub use spec::{TrajectorySpec, ramp};

/// Sampling rates and lengths.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SamplingConfig {
    /// Raw (logging) rate (Hz). Default 250.
    pub raw_rate_hz: f64,
    /// Decimation factor from raw to dataset rate. Default 10 (→ 25 Hz).
    pub decimation: usize,
    /// Samples per trajectory at the dataset rate. Default 470.
    pub n_samples: usize,
}

impl Default for SamplingConfig {
    fn default() -> Self {
        Self {
            raw_rate_hz: 250.0,
            decimation: 10,
            n_samples: 470,
        }
    }
}

impl SamplingConfig {
    /// Raw sampling period (s).
    pub fn raw_dt_s(&self) -> f64 {
        1.0 / self.raw_rate_hz
    }

    /// Dataset sampling period (s).
    pub fn dataset_dt_s(&self) -> f64 {
        self.decimation as f64 / self.raw_rate_hz
    }

    /// Raw samples per trajectory (`n_samples · decimation`).
    pub fn n_raw(&self) -> usize {
        self.n_samples * self.decimation
    }
}

/// Generator settings (angles in degrees for readability; converted once).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct GeneratorConfig {
    /// Number of trajectories. Default 548.
    pub n_trajectories: usize,
    /// Training trajectories (the first `n_train`). Default 512.
    pub n_train: usize,
    /// Seed of the generator.
    pub seed: u64,
    /// Sampling.
    pub sampling: SamplingConfig,
    /// Flapping frequency range (Hz). Without [`u_ref_m_s`](Self::u_ref_m_s) the frequency is
    /// drawn uniformly from it; with it, the derived frequency must lie in it (else the draw is
    /// repeated). Default [0.2, 0.4].
    pub frequency_hz: [f64; 2],
    /// Reference speed U_ref (m/s) every trajectory is given, as the robot's were (constant
    /// Reynolds number): the frequency is U_ref / (R·L), L = ∮ √(φ′² + ψ′²) dx the tip path
    /// per cycle at unit radius, R = [`U_REF_RADIUS_M`]. `None`: the frequency is drawn.
    pub u_ref_m_s: Option<f64>,
    /// Stroke half-amplitude Φ range (deg). Default [40, 89].
    pub stroke_amplitude_deg: [f64; 2],
    /// Largest |stroke offset φ₀| (deg), within the servo room left by Φ. Default 0.
    pub max_stroke_offset_deg: f64,
    /// Largest |second-harmonic coefficient| of the stroke (relative to the first; sets the
    /// asymmetry of the two half-strokes). Default 0.35.
    pub stroke_second_harmonic: f64,
    /// Maximum deviation amplitude Ψ (deg). Default 40.
    pub max_deviation_deg: f64,
    /// Largest |deviation offset ψ₀| (deg). Default 0.
    pub max_deviation_offset_deg: f64,
    /// Deviation shaped to keep the leading edge leading: Ψ ≥ 8° (harmonic 5°), capped at 0.5Φ
    /// (figure-eight, oval) or 0.3Φ (u-shaped), the tip rising through the reversals. Off
    /// (default): Ψ uniform in [0, max] for every family and either orientation, as measured.
    pub leading_edge_deviation: bool,
    /// Pitch half-range range (deg): with it (default [10, 80]) the pitch's half-range and
    /// offset ([`pitch_offset_deg`](Self::pitch_offset_deg)) are drawn uniformly, as the
    /// measured set's are; `None`: the plateaus follow AoA targets ([`aoa_deg`](Self::aoa_deg),
    /// [`p_aoa_near_zero`](Self::p_aoa_near_zero), [`p_aoa_reversed`](Self::p_aoa_reversed)).
    pub pitch_half_range_deg: Option<[f64; 2]>,
    /// Pitch offset range (deg; the mean of the two plateaus). Default [−30, 30].
    pub pitch_offset_deg: [f64; 2],
    /// Largest |phase| δ of the pitch against the stroke (cycles; advanced or delayed
    /// rotation). Default 0.24, as measured (uniform over ±0.23 cycle).
    pub max_pitch_phase_cycles: f64,
    /// Highest odd harmonic of the pitch's smoothed square wave (1, 3, 5 or 7; the order is
    /// drawn among the odd ones up to it). Default 5 (the measured peak pitch rates).
    pub max_pitch_harmonic: usize,
    /// Conventional mid-stroke |AoA| range (deg), with the AoA-target pitch. Default [20, 70].
    pub aoa_deg: [f64; 2],
    /// Probability that one half-stroke of a trajectory has |AoA| near zero (|AoA| ≤ 8°).
    pub p_aoa_near_zero: f64,
    /// Probability that one half-stroke is pitched the wrong way (AoA of opposite sign, 8–20°).
    pub p_aoa_reversed: f64,
    /// Ramp-in duration range (cycles). Default [1, 2].
    pub ramp_cycles: [f64; 2],
    /// Longest ramp-in (s). Default 3.72 s, the 93 samples the published analyses skip, so that
    /// the analysed part is in full motion, as the measured trajectories are. `None`: no limit.
    pub max_ramp_s: Option<f64>,
    /// Servo limit on every |angle| (deg). Default 110.
    pub max_angle_deg: f64,
    /// Servo limit on every |rate| (deg/s). Default 900.
    pub max_rate_deg_s: f64,
    /// Family mix: relative weights of [figure-eight, u-shaped, oval, flat, harmonic].
    /// Default [0.3, 0.2, 0.2, 0.15, 0.15].
    pub family_weights: [f64; 5],
}

impl Default for GeneratorConfig {
    /// Calibrated to the paper's 548 measured trajectories (see `docs/kinematics.md`): every
    /// trajectory at U_ref = 0.1746 m/s (their constant Reynolds number), Φ 40–89°, Ψ 0–40°,
    /// pitch half-range 10–80° and offset ±30°, no stroke or deviation offset, and the family
    /// mix of the measured tip paths (figure-eight 21 %, u-shaped 15 %, oval 37 %, flat 8 %,
    /// mixed harmonics 19 %).
    fn default() -> Self {
        Self {
            n_trajectories: 548,
            n_train: 512,
            seed: 0,
            sampling: SamplingConfig::default(),
            frequency_hz: [0.1, 0.3],
            u_ref_m_s: Some(0.1746),
            stroke_amplitude_deg: [40.0, 89.0],
            max_stroke_offset_deg: 0.0,
            stroke_second_harmonic: 0.05,
            max_deviation_deg: 40.0,
            max_deviation_offset_deg: 0.0,
            leading_edge_deviation: false,
            pitch_half_range_deg: Some([10.0, 80.0]),
            pitch_offset_deg: [-30.0, 30.0],
            max_pitch_phase_cycles: 0.24,
            max_pitch_harmonic: 5,
            aoa_deg: [20.0, 70.0],
            p_aoa_near_zero: 0.1,
            p_aoa_reversed: 0.1,
            ramp_cycles: [1.0, 2.0],
            max_ramp_s: Some(3.72),
            max_angle_deg: 110.0,
            max_rate_deg_s: 900.0,
            family_weights: [0.21, 0.15, 0.37, 0.08, 0.19],
        }
    }
}

impl GeneratorConfig {
    /// Hovering-like kinematics, the generator before its calibration to the measured set:
    /// 0.2–0.4 Hz drawn freely, Φ 40–100°, offsets up to 15° (stroke) and 10° (deviation),
    /// the leading edge kept leading by the deviation's shape and by AoA targets (|AoA| 20–70°,
    /// 10 % near-zero and 10 % reversed half-strokes).
    pub fn hovering() -> Self {
        Self {
            frequency_hz: [0.2, 0.4],
            u_ref_m_s: None,
            stroke_amplitude_deg: [40.0, 100.0],
            max_stroke_offset_deg: 15.0,
            stroke_second_harmonic: 0.05,
            max_deviation_offset_deg: 10.0,
            leading_edge_deviation: true,
            pitch_half_range_deg: None,
            max_pitch_phase_cycles: 0.08,
            max_pitch_harmonic: 7,
            max_ramp_s: None,
            family_weights: [0.3, 0.2, 0.2, 0.15, 0.15],
            ..Self::default()
        }
    }
}

/// Default training count for `n` trajectories: 512 as published when n > 512, otherwise the
/// published proportion (36 of 548 held out, at least one when n ≥ 2).
pub fn default_n_train(n: usize) -> usize {
    if n > 512 {
        512
    } else {
        let n_test = (n * 36).div_ceil(548).min(n.saturating_sub(1));
        n - n_test
    }
}

fn check_range(field: &'static str, r: [f64; 2], lo: f64, hi: f64) -> Result<(), TrajectoryError> {
    for v in r {
        if !(v.is_finite() && v >= lo && v <= hi) {
            return Err(TrajectoryError::InvalidConfig {
                field,
                value: v,
                reason: "out of range",
            });
        }
    }
    if r[0] > r[1] {
        return Err(TrajectoryError::InvalidConfig {
            field,
            value: r[0],
            reason: "lower bound above upper bound",
        });
    }
    Ok(())
}

impl GeneratorConfig {
    /// Validates every field.
    pub fn check(&self) -> Result<(), TrajectoryError> {
        let bad = |field, value: f64, reason| {
            Err(TrajectoryError::InvalidConfig {
                field,
                value,
                reason,
            })
        };
        if self.n_trajectories == 0 {
            return bad("n_trajectories", 0.0, "must be positive");
        }
        if self.n_train > self.n_trajectories {
            return bad(
                "n_train",
                self.n_train as f64,
                "must not exceed n_trajectories",
            );
        }
        let s = &self.sampling;
        if !(s.raw_rate_hz.is_finite() && s.raw_rate_hz > 0.0) {
            return bad("sampling.raw_rate_hz", s.raw_rate_hz, "must be positive");
        }
        if s.decimation == 0 {
            return bad("sampling.decimation", 0.0, "must be positive");
        }
        if s.n_samples < 12 {
            return bad(
                "sampling.n_samples",
                s.n_samples as f64,
                "must be at least 12",
            );
        }
        check_range(
            "frequency_hz",
            self.frequency_hz,
            1e-3,
            0.25 / self.sampling.dataset_dt_s(),
        )?;
        let duration_s = (s.n_samples - 1) as f64 * s.dataset_dt_s();
        if self.frequency_hz[0] * duration_s < 1.25 {
            return bad(
                "frequency_hz",
                self.frequency_hz[0],
                "gives fewer than the 1.25 cycles per trajectory that the published U_ref needs",
            );
        }
        check_range(
            "stroke_amplitude_deg",
            self.stroke_amplitude_deg,
            1.0,
            0.95 * self.max_angle_deg,
        )?;
        check_range("aoa_deg", self.aoa_deg, 0.0, 89.0)?;
        if let Some(r) = self.pitch_half_range_deg {
            check_range("pitch_half_range_deg", r, 0.0, 0.95 * self.max_angle_deg)?;
        }
        check_range("pitch_offset_deg", self.pitch_offset_deg, -90.0, 90.0)?;
        if ![1, 3, 5, 7].contains(&self.max_pitch_harmonic) {
            return bad(
                "max_pitch_harmonic",
                self.max_pitch_harmonic as f64,
                "must be 1, 3, 5 or 7",
            );
        }
        for (field, v, hi) in [
            ("max_stroke_offset_deg", self.max_stroke_offset_deg, 90.0),
            ("stroke_second_harmonic", self.stroke_second_harmonic, 1.0),
            (
                "max_deviation_offset_deg",
                self.max_deviation_offset_deg,
                45.0,
            ),
            ("max_pitch_phase_cycles", self.max_pitch_phase_cycles, 0.5),
        ] {
            if !(v.is_finite() && (0.0..=hi).contains(&v)) {
                return bad(field, v, "out of range");
            }
        }
        if let Some(u) = self.u_ref_m_s
            && !(u.is_finite() && u > 0.0)
        {
            return bad("u_ref_m_s", u, "must be positive");
        }
        check_range("ramp_cycles", self.ramp_cycles, 0.0, 10.0)?;
        if let Some(r) = self.max_ramp_s
            && !(r.is_finite() && r >= 0.0)
        {
            return bad("max_ramp_s", r, "must be non-negative");
        }
        if !(self.max_deviation_deg >= 0.0 && self.max_deviation_deg <= 0.8 * self.max_angle_deg) {
            return bad(
                "max_deviation_deg",
                self.max_deviation_deg,
                "must be in [0, 0.8·max_angle_deg]",
            );
        }
        if !(self.max_angle_deg > 0.0 && self.max_angle_deg <= 180.0) {
            return bad("max_angle_deg", self.max_angle_deg, "must be in (0, 180]");
        }
        if !(self.max_rate_deg_s.is_finite() && self.max_rate_deg_s > 0.0) {
            return bad("max_rate_deg_s", self.max_rate_deg_s, "must be positive");
        }
        for (field, p) in [
            ("p_aoa_near_zero", self.p_aoa_near_zero),
            ("p_aoa_reversed", self.p_aoa_reversed),
        ] {
            if !(0.0..=1.0).contains(&p) {
                return bad(field, p, "must be a probability");
            }
        }
        if self.p_aoa_near_zero + self.p_aoa_reversed > 1.0 {
            return bad(
                "p_aoa_reversed",
                self.p_aoa_reversed,
                "p_aoa_near_zero + p_aoa_reversed must be ≤ 1",
            );
        }
        if self
            .family_weights
            .iter()
            .any(|w| !(w.is_finite() && *w >= 0.0))
            || self.family_weights.iter().sum::<f64>() <= 0.0
        {
            return bad(
                "family_weights",
                self.family_weights.iter().sum(),
                "must be non-negative with a positive sum",
            );
        }
        Ok(())
    }

    /// Families of the set, in order: counts proportional to `family_weights` (largest
    /// remainders; every family with positive weight appears once `n_trajectories` ≥ 5), in an
    /// order shuffled by `seed`.
    pub fn family_sequence(&self) -> Vec<Family> {
        let n = self.n_trajectories;
        let total: f64 = self.family_weights.iter().sum();
        let exact: Vec<f64> = self
            .family_weights
            .iter()
            .map(|w| w / total * n as f64)
            .collect();
        let mut counts: Vec<usize> = exact
            .iter()
            .zip(&self.family_weights)
            .map(|(e, w)| {
                if *w > 0.0 && n >= Family::ALL.len() {
                    (e.floor() as usize).max(1)
                } else {
                    e.floor() as usize
                }
            })
            .collect();
        let mut order: Vec<usize> = (0..counts.len()).collect();
        order.sort_by(|&a, &b| {
            (exact[b] - exact[b].floor()).total_cmp(&(exact[a] - exact[a].floor()))
        });
        let mut k = 0;
        while counts.iter().sum::<usize>() < n {
            counts[order[k % order.len()]] += 1;
            k += 1;
        }
        while counts.iter().sum::<usize>() > n {
            let i = (0..counts.len()).max_by_key(|&i| counts[i]).unwrap_or(0);
            counts[i] -= 1;
        }
        let mut seq: Vec<Family> = Family::ALL
            .iter()
            .zip(&counts)
            .flat_map(|(f, &c)| std::iter::repeat_n(*f, c))
            .collect();
        let mut rng = ChaCha8Rng::seed_from_u64(self.seed);
        rng.set_stream(u64::MAX);
        for i in (1..seq.len()).rev() {
            let j = rng.random_range(0..=i);
            seq.swap(i, j);
        }
        seq
    }

    /// Generates the trajectory specifications. Trajectory i uses ChaCha8 stream i of `seed`,
    /// so the result does not depend on threading.
    pub fn generate(&self) -> Result<Vec<TrajectorySpec>, TrajectoryError> {
        self.check()?;
        let families = self.family_sequence();
        let one = |(i, fam): (usize, &Family)| self.generate_one(i, *fam);
        families.par_iter().enumerate().map(one).collect()
    }

    /// Generates trajectory `index` of family `family` (deterministic in `seed` and `index`).
    pub fn generate_one(
        &self,
        index: usize,
        family: Family,
    ) -> Result<TrajectorySpec, TrajectoryError> {
        let mut rng = ChaCha8Rng::seed_from_u64(self.seed);
        rng.set_stream(index as u64);
        for _ in 0..MAX_ATTEMPTS {
            let spec = self.draw(&mut rng, family);
            if let Some(spec) = spec.filter(|s| self.feasible(s)) {
                return Ok(spec);
            }
        }
        Err(TrajectoryError::Infeasible {
            index,
            attempts: MAX_ATTEMPTS,
        })
    }

    /// Servo limits: |angle| ≤ max_angle and |rate| ≤ max_rate over the whole trajectory,
    /// including the ramp (|r| ≤ 1, |ṙ| ≤ 15/(8 T_ramp) bound the ramped values).
    fn feasible(&self, spec: &TrajectorySpec) -> bool {
        let w = 2.0 * PI * spec.frequency_hz;
        let r_dot_max = if spec.ramp_s > 0.0 {
            15.0 / (8.0 * spec.ramp_s)
        } else {
            0.0
        };
        spec.angles.iter().all(|g| {
            let (m0, m1) = g.bounds();
            m0 <= self.max_angle_deg * DEG && r_dot_max * m0 + w * m1 <= self.max_rate_deg_s * DEG
        })
    }

    /// Signed AoA targets of the two half-strokes (rad): conventional AoA·φ̇ < 0, i.e. −|AoA|
    /// for φ̇ > 0 and +|AoA| for φ̇ < 0; one half-stroke near zero or reversed with the
    /// configured probabilities.
    fn aoa_targets(&self, rng: &mut ChaCha8Rng) -> [f64; 2] {
        let mut targets = [
            -uniform(rng, self.aoa_deg) * DEG,
            uniform(rng, self.aoa_deg) * DEG,
        ];
        let which = rng.random_range(0..2usize);
        let sign = if which == 0 { -1.0 } else { 1.0 };
        let p: f64 = rng.random();
        if p < self.p_aoa_near_zero {
            targets[which] = sign * rng.random_range(-3.0..8.0) * DEG;
        } else if p < self.p_aoa_near_zero + self.p_aoa_reversed {
            targets[which] = -sign * rng.random_range(8.0..20.0) * DEG;
        }
        targets
    }

    fn draw(&self, rng: &mut ChaCha8Rng, family: Family) -> Option<TrajectorySpec> {
        // Drawn in either frequency mode, so that the other draws of a trajectory do not depend
        // on the mode.
        let drawn_f = uniform(rng, self.frequency_hz);
        let ramp_cycles = uniform(rng, self.ramp_cycles);
        let amp = uniform(rng, self.stroke_amplitude_deg) * DEG;
        let max_dev = self.max_deviation_deg * DEG;

        // Stroke: Φ (sin x + c3 sin 3x + c2 sin 2x) / peak + φ₀.
        let mut stroke = FourierSeries::default();
        stroke.add_sin(1, 1.0, 0.0);
        stroke.add_sin(3, rng.random_range(-0.1..0.03), 0.0);
        let h2 = self.stroke_second_harmonic;
        stroke.add_sin(2, uniform(rng, [-h2, h2]), rng.random_range(-PI..PI));
        if family == Family::Harmonic {
            for k in 2..=4 {
                stroke.add_sin(
                    k,
                    rng.random_range(0.0..0.12) / k as f64,
                    rng.random_range(-PI..PI),
                );
            }
        }
        let mut stroke = stroke.scaled(amp / stroke.half_range());
        let room = (self.max_angle_deg * DEG - amp).max(0.0);
        stroke.offset_rad =
            rng.random_range(-1.0..1.0) * room.min(self.max_stroke_offset_deg * DEG);

        let mut dev = FourierSeries::default();
        let guard = self.leading_edge_deviation;
        // Ψ from [lo, max] (or [0, max] without the leading-edge guard), capped at `cap`·Φ.
        let dev_amp = |rng: &mut ChaCha8Rng, lo: f64, cap: f64| {
            if guard {
                rng.random_range(lo.min(max_dev)..=max_dev).min(cap * amp)
            } else {
                rng.random_range(0.0..=max_dev)
            }
        };
        // Orientation of the tip path: fixed with the guard, either way as measured.
        let orientation = |rng: &mut ChaCha8Rng| {
            if guard || rng.random::<bool>() {
                1.0
            } else {
                -1.0
            }
        };
        match family {
            Family::FigureEight => {
                // Guarded: the tip rises through both reversals (ψ̇ > 0 while the pitch flips
                // through α = 0, leading edge up), so the leading edge keeps leading.
                let a = dev_amp(rng, 8.0 * DEG, 0.5) * orientation(rng);
                dev.add_sin(2, -a, rng.random_range(-0.5..0.5));
            }
            Family::UShaped => {
                // Guarded: Ψ ≤ 0.3Φ keeps the descent after the reversal shallower than ~30°,
                // which the pitch rotation can follow with the leading edge first, and the
                // highest point is at or just after the reversal (ψ̇ ≥ 0 during the flip).
                let a = dev_amp(rng, 8.0 * DEG, 0.3) * orientation(rng);
                dev.add_cos(2, -a, rng.random_range(-0.4..0.0));
            }
            Family::Oval => {
                let a = dev_amp(rng, 8.0 * DEG, 0.5);
                dev.add_cos(1, a, rng.random_range(-0.6..0.6));
            }
            Family::Flat => {
                dev.add_sin(
                    1,
                    rng.random_range(0.0..=max_dev).min(3.0 * DEG),
                    rng.random_range(-PI..PI),
                );
            }
            Family::Harmonic => {
                let total = dev_amp(rng, 5.0 * DEG, f64::INFINITY);
                let mut weights = [0.0; 3];
                for (k, wk) in weights.iter_mut().enumerate() {
                    *wk = rng.random_range(0.0..1.0) / (k + 1) as f64;
                }
                weights[0] = weights[0].max(0.2);
                for (k, wk) in weights.iter().enumerate() {
                    dev.add_sin(k + 1, *wk, rng.random_range(-PI..PI));
                }
                dev = dev.scaled(total / dev.half_range());
            }
        }
        if family != Family::Flat {
            let o = self.max_deviation_offset_deg;
            dev.offset_rad = uniform(rng, [-o, o]) * DEG;
        }

        let drawn_pitch = match self.pitch_half_range_deg {
            Some(range) => PitchDraw::HalfRangeOffset(
                uniform(rng, range) * DEG,
                uniform(rng, self.pitch_offset_deg) * DEG,
            ),
            None => PitchDraw::AoaTargets(self.aoa_targets(rng)),
        };
        let phase = self.max_pitch_phase_cycles;
        let delta = uniform(rng, [-phase, phase]) * 2.0 * PI;
        let aoa_flat = |x: f64| {
            let [p0, p1, _] = stroke.eval(x);
            let [d0, d1, _] = dev.eval(x);
            let st = EulerState {
                angles_rad: [p0, d0, 0.0],
                rates_rad_s: [p1, d1, 0.0],
                accels_rad_s2: [0.0; 3],
            };
            WingKinematics::from_euler(&st).aoa_rad
        };
        let wrap = |a: f64| (a + PI).rem_euclid(2.0 * PI) - PI;
        // Plateaus −A₁ (φ̇ > 0, centre x = −δ) and A₂ (φ̇ < 0, centre x = π − δ), and the
        // signed AoA there: AoA(α) = AoA(α = 0) − α.
        let (a1, a2, targets) = match drawn_pitch {
            PitchDraw::HalfRangeOffset(half, offset) => {
                let (a1, a2) = (half - offset, half + offset);
                let targets = [wrap(aoa_flat(-delta) + a1), wrap(aoa_flat(PI - delta) - a2)];
                (a1, a2, targets)
            }
            PitchDraw::AoaTargets(targets) => (
                -wrap(aoa_flat(-delta) - targets[0]),
                wrap(aoa_flat(PI - delta) - targets[1]),
                targets,
            ),
        };
        let k_max = [1, 3, 5, 7][rng.random_range(0..self.max_pitch_harmonic.div_ceil(2))];
        let sq = smooth_square(k_max).shifted(delta);
        let mut pitch = sq.scaled(-0.5 * (a1 + a2));
        match drawn_pitch {
            // The measured law: a constant offset, the mean of the two plateaus.
            PitchDraw::HalfRangeOffset(..) => pitch.offset_rad = -0.5 * (a1 - a2),
            // α = 0 at the flips (S = 0), the plateaus set by S² = 1.
            PitchDraw::AoaTargets(_) => pitch.add(&sq.product(&sq).scaled(-0.5 * (a1 - a2))),
        }
        if family == Family::Harmonic {
            // Perturbation vanishing at both plateau centres keeps the AoA targets exact.
            let mut bump = FourierSeries::default();
            bump.add_sin(1, rng.random_range(0.0..10.0) * DEG, -delta);
            let mut wobble = FourierSeries::default();
            wobble.add_cos(1, 1.0, rng.random_range(-PI..PI));
            wobble.add_cos(2, 0.5, rng.random_range(-PI..PI));
            pitch.add(&bump.product(&wobble));
        }
        if !(a1.is_finite() && a2.is_finite()) {
            return None;
        }
        let f = match self.u_ref_m_s {
            None => drawn_f,
            Some(u_ref) => {
                let f = u_ref / (U_REF_RADIUS_M * path_per_cycle(&stroke, &dev));
                if !(self.frequency_hz[0]..=self.frequency_hz[1]).contains(&f) {
                    return None;
                }
                f
            }
        };
        let ramp_s = (ramp_cycles / f).min(self.max_ramp_s.unwrap_or(f64::INFINITY));
        let t_end = (self.sampling.n_samples - 1) as f64 * self.sampling.dataset_dt_s();
        let phase_rad = (-2.0 * PI * f * t_end).rem_euclid(2.0 * PI);
        Some(TrajectorySpec {
            family,
            frequency_hz: f,
            ramp_s,
            phase_rad,
            angles: [stroke, dev, pitch],
            aoa_targets_rad: targets,
        })
    }
}

/// A uniform draw from [r₀, r₁), or r₀ for an empty range.
fn uniform(rng: &mut ChaCha8Rng, r: [f64; 2]) -> f64 {
    if r[1] > r[0] {
        rng.random_range(r[0]..r[1])
    } else {
        r[0]
    }
}

/// The pitch drawn for one trajectory, before its plateaus are placed.
enum PitchDraw {
    /// Half-range and offset (rad).
    HalfRangeOffset(f64, f64),
    /// Signed AoA targets of the two half-strokes (rad).
    AoaTargets([f64; 2]),
}

/// The tip path per cycle at unit radius, L = ∮ √(φ′(x)² + ψ′(x)²) dx (rad; ′ = d/dx), by the
/// midpoint rule on [`BOUND_GRID`] points (exact to rounding for these trigonometric series).
fn path_per_cycle(stroke: &FourierSeries, dev: &FourierSeries) -> f64 {
    let h = 2.0 * PI / BOUND_GRID as f64;
    (0..BOUND_GRID)
        .map(|i| {
            let x = (i as f64 + 0.5) * h;
            stroke.eval(x)[1].hypot(dev.eval(x)[1])
        })
        .sum::<f64>()
        * h
}

/// Kinematics-only dataset: analytic inputs at the dataset rate, `outputs = None`, U_ref as
/// published ([`cycles::published_u_ref`], R = [`U_REF_RADIUS_M`]), family labels, metadata with
/// generator `"flapssm trajectories"`, the seed and the full [`GeneratorConfig`], checked once.
pub fn kinematics_dataset(cfg: &GeneratorConfig) -> Result<ValidDataset, TrajectoryError> {
    let specs = cfg.generate()?;
    let dt_s = cfg.sampling.dataset_dt_s();
    let mut trajectories = Vec::with_capacity(specs.len());
    let mut states = vec![EulerState::default(); cfg.sampling.n_samples];
    for (index, spec) in specs.iter().enumerate() {
        spec.sample_into(dt_s, &mut states);
        let euler_rad: Vec<[f64; 3]> = states.iter().map(|s| s.angles_rad).collect();
        let inputs = states
            .iter()
            .map(|s| WingKinematics::from_euler(s).inputs())
            .collect();
        let (u_ref_m_s, _) = cycles::published_u_ref(&euler_rad, dt_s, U_REF_RADIUS_M)
            .map_err(|source| TrajectoryError::Cycle { index, source })?;
        trajectories.push(Trajectory {
            euler_rad,
            inputs,
            outputs: None,
            u_ref_m_s,
            family: spec.family.label().to_string(),
        });
    }
    let settings = serde_json::to_value(cfg).unwrap_or(serde_json::Value::Null);
    let ds = Dataset {
        meta: DatasetMeta {
            format_version: FORMAT_VERSION,
            wing: WingGeometry::default(),
            fluid: Fluid::default(),
            generator: "flapssm trajectories".to_string(),
            seed: Some(cfg.seed),
            settings,
            input_units: INPUT_UNITS.iter().map(|s| s.to_string()).collect(),
            output_units: OUTPUT_UNITS.iter().map(|s| s.to_string()).collect(),
        },
        dt_s,
        trajectories,
        n_train: cfg.n_train,
    };
    Ok(ValidDataset::new(ds)?)
}

#[cfg(test)]
mod tests {
    use super::*;
    use spec::ramp;

    fn pointwise_check(f: &FourierSeries, g: impl Fn(f64) -> f64) {
        for i in 0..50 {
            let x = -3.0 + 0.13 * i as f64;
            assert!(
                (f.eval(x)[0] - g(x)).abs() < 1e-12,
                "x = {x}: {} vs {}",
                f.eval(x)[0],
                g(x)
            );
        }
    }

    fn sample_series() -> (FourierSeries, FourierSeries) {
        let mut a = FourierSeries {
            offset_rad: 0.3,
            ..FourierSeries::default()
        };
        a.add_sin(1, 0.7, 0.2);
        a.add_cos(3, -0.4, 1.1);
        let mut b = FourierSeries {
            offset_rad: -0.2,
            ..FourierSeries::default()
        };
        b.add_cos(2, 0.5, -0.7);
        b.add_sin(1, 0.25, 2.0);
        (a, b)
    }

    #[test]
    fn fourier_algebra_matches_pointwise() {
        let (a, b) = sample_series();
        pointwise_check(&a, |x| {
            0.3 + 0.7 * (x + 0.2).sin() - 0.4 * (3.0 * x + 1.1).cos()
        });
        pointwise_check(&a.product(&b), |x| a.eval(x)[0] * b.eval(x)[0]);
        pointwise_check(&b.product(&a), |x| a.eval(x)[0] * b.eval(x)[0]);
        pointwise_check(&a.product(&a), |x| a.eval(x)[0].powi(2));
        pointwise_check(&a.shifted(0.9), |x| a.eval(x + 0.9)[0]);
        let mut s = a.clone();
        s.add(&b.scaled(2.0));
        pointwise_check(&s, |x| a.eval(x)[0] + 2.0 * b.eval(x)[0]);
    }

    #[test]
    fn fourier_derivatives_match_central_differences() {
        let (a, _) = sample_series();
        let h = 1e-4;
        for i in 0..20 {
            let x = 0.31 * i as f64;
            let [_, d1, d2] = a.eval(x);
            let (p, m, c) = (a.eval(x + h)[0], a.eval(x - h)[0], a.eval(x)[0]);
            assert!((d1 - (p - m) / (2.0 * h)).abs() < 1e-7);
            assert!((d2 - (p - 2.0 * c + m) / (h * h)).abs() < 1e-5);
        }
    }

    #[test]
    fn smooth_square_is_unit_plateau_and_bounded() {
        for k in [1, 3, 5, 7] {
            let s = smooth_square(k);
            assert!((s.eval(0.0)[0] - 1.0).abs() < 1e-14);
            assert!((s.eval(PI)[0] + 1.0).abs() < 1e-14);
            assert!(s.bounds().0 <= 1.0 + 1e-12, "K = {k}: max {}", s.bounds().0);
        }
    }

    #[test]
    fn ramp_is_c2_with_exact_derivatives() {
        let t_r = 3.0;
        assert_eq!(ramp(0.0, t_r), (0.0, 0.0, 0.0));
        assert_eq!(ramp(t_r, t_r), (1.0, 0.0, 0.0));
        let (r, d, dd) = ramp(t_r - 1e-9, t_r);
        assert!((r - 1.0).abs() < 1e-12 && d.abs() < 1e-12 && dd.abs() < 1e-7);
        let h = 1e-5;
        for i in 1..30 {
            let t = 0.1 * i as f64;
            let (_, d, dd) = ramp(t, t_r);
            let (p, m) = (ramp(t + h, t_r), ramp(t - h, t_r));
            assert!((d - (p.0 - m.0) / (2.0 * h)).abs() < 1e-8);
            assert!((dd - (p.1 - m.1) / (2.0 * h)).abs() < 1e-7);
            assert!(d <= 15.0 / (8.0 * t_r) + 1e-15);
        }
    }

    #[test]
    fn family_sequence_follows_weights() {
        let cfg = GeneratorConfig::default();
        let seq = cfg.family_sequence();
        assert_eq!(seq.len(), 548);
        let count = |f| seq.iter().filter(|&&g| g == f).count();
        assert_eq!(count(Family::FigureEight), 115); // 0.21 · 548 = 115.08
        assert_eq!(count(Family::Oval), 203); // 0.37 · 548 = 202.76, a largest remainder
        assert_eq!(count(Family::Flat), 44); // 0.08 · 548 = 43.84, the largest remainder
        let hovering = GeneratorConfig::hovering().family_sequence();
        assert_eq!(
            hovering
                .iter()
                .filter(|&&g| g == Family::FigureEight)
                .count(),
            164
        );
        let small = GeneratorConfig {
            n_trajectories: 5,
            n_train: 4,
            ..GeneratorConfig::default()
        };
        let seq = small.family_sequence();
        assert!(Family::ALL.iter().all(|f| seq.contains(f)));
    }

    #[test]
    fn default_split_follows_the_paper() {
        assert_eq!(default_n_train(548), 512);
        assert_eq!(default_n_train(1000), 512);
        assert_eq!(default_n_train(100), 93);
        assert_eq!(default_n_train(2), 1);
        assert_eq!(default_n_train(1), 1);
    }

    #[test]
    fn bad_config_is_rejected() {
        let bad = GeneratorConfig {
            n_train: 600,
            ..GeneratorConfig::default()
        };
        assert!(matches!(
            bad.check(),
            Err(TrajectoryError::InvalidConfig {
                field: "n_train",
                ..
            })
        ));
        let bad = GeneratorConfig {
            frequency_hz: [0.4, 0.2],
            ..GeneratorConfig::default()
        };
        assert!(matches!(
            bad.check(),
            Err(TrajectoryError::InvalidConfig {
                field: "frequency_hz",
                ..
            })
        ));
        let bad = GeneratorConfig {
            p_aoa_near_zero: 1.5,
            ..GeneratorConfig::default()
        };
        assert!(bad.generate().is_err());
    }
}
