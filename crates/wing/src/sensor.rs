//! The experiment around the wing: a Nano17-like 6-axis force/torque sensor in oil, its
//! errors, and the post-processing of the published data (physics notes §4.3, §4.5).
//!
//! Applied to the loads y = [F_x, F_y (N), M_x, M_y, M_z (N·mm)] at the raw rate (250 Hz), in
//! this order, every effect switchable:
//!
//! 1. residual of the static (weight − buoyancy) calibration: ε_s·y_static, ε_s fixed per
//!    dataset, |ε_s| = `static_residual_frac`;
//! 2. residual of the inertial subtraction: ε_i·y_inertial (rigid plate, ε_i per dataset,
//!    |ε_i| = `inertial_residual_frac`);
//! 3. cross-axis coupling y/FS ← (I + E)(y/FS) on full-scale-normalized signals,
//!    E_ij ~ N(0, σ_E²) fixed per dataset;
//! 4. per-trajectory bias N(0, (b·FS)²) plus a Gaussian random walk reaching a standard
//!    deviation d·FS after 20 s (FS = 12 N, 120 N·mm);
//! 5. servo vibration: one sinusoid per channel at a random 5–30 Hz, amplitude a·RMS(y);
//! 6. white noise σ_F, σ_M; 7. quantisation to 1/320 N and 1/64 N·mm;
//! 8. zero-phase low-pass: 4th-order Butterworth (two bilinear biquads) run forward and
//!    backward (cut-off 5 Hz, −6 dB at the cut-off), then decimation (every 10th sample).
//!
//! **Tare** (`tare`, on by default): before each trajectory the wing rests at the home pose
//! (`home_pose_deg`; the authors' `[0, 0, −90]°`, the horizontal plate) and the reading is
//! zeroed, as a rig operator does. What the tare removes is what is constant over the
//! trajectory: the per-trajectory bias (step 4: the offset starts at zero and the drift
//! accumulates from the tare) and the static residual at the home pose (step 1 becomes
//! ε_s·(y_static − y_static,home)). The noise of the tare reading itself (an average over many
//! samples) is neglected.

use rand::Rng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, Normal};
use serde::{Deserialize, Serialize};
use std::f64::consts::PI;

/// Sensor and post-processing settings. [`Default`] is the full experiment; see
/// [`SensorConfig::noise_free`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct SensorConfig {
    /// Static calibration residual (true).
    pub static_residual: bool,
    /// |ε_s|, fraction of the static weight − buoyancy load (0.015).
    pub static_residual_frac: f64,
    /// Inertial-subtraction residual (true).
    pub inertial_residual: bool,
    /// |ε_i|, fraction of the rigid-plate inertial load (0.02).
    pub inertial_residual_frac: f64,
    /// Plate density for the weight and inertia (kg/m³; 1190, acrylic).
    pub plate_density_kg_m3: f64,
    /// Plate thickness (m; 0.003).
    pub plate_thickness_m: f64,
    /// Cross-axis coupling (true).
    pub cross_axis: bool,
    /// σ_E of the coupling matrix entries (0.01).
    pub cross_axis_sd: f64,
    /// Per-trajectory bias and drift (true).
    pub bias_drift: bool,
    /// Bias standard deviation b, fraction of full scale (0.003).
    pub bias_frac_fs: f64,
    /// Drift standard deviation d after 20 s, fraction of full scale (0.001).
    pub drift_frac_fs: f64,
    /// Full scale of the force channels (N; 12).
    pub force_full_scale_n: f64,
    /// Full scale of the moment channels (N·mm; 120).
    pub moment_full_scale_n_mm: f64,
    /// Servo vibration (true).
    pub vibration: bool,
    /// Vibration amplitude a, fraction of the channel's RMS (0.01).
    pub vibration_rel_amplitude: f64,
    /// Vibration frequency range (Hz; [5, 30]).
    pub vibration_hz: [f64; 2],
    /// White noise (true).
    pub white_noise: bool,
    /// σ_F (N; 0.008).
    pub force_noise_sd_n: f64,
    /// σ_M (N·mm; 0.1).
    pub moment_noise_sd_n_mm: f64,
    /// Quantisation (true).
    pub quantization: bool,
    /// Force resolution (N; 1/320).
    pub force_lsb_n: f64,
    /// Moment resolution (N·mm; 1/64).
    pub moment_lsb_n_mm: f64,
    /// Zero-phase low-pass before decimation (true).
    pub lowpass: bool,
    /// Low-pass cut-off (Hz; 5).
    pub cutoff_hz: f64,
    /// Quantize the Euler angles to the servo encoders and differentiate them
    /// (Savitzky–Golay, [`crate::differentiate`]) for the inputs (true).
    pub encoder: bool,
    /// Encoder counts per revolution (4096).
    pub encoder_counts_per_rev: u32,
    /// Zero the reading at the home pose before each trajectory (true; false for files written
    /// before the tare existed).
    #[serde(default)]
    pub tare: bool,
    /// Home pose [φ, ψ, α] (deg) of the tare: [0, 0, 90], the authors' `[0, 0, −90]` in this
    /// crate's pitch sign (docs/kinematics.md) — the horizontal plate.
    pub home_pose_deg: [f64; 3],
}

impl Default for SensorConfig {
    fn default() -> Self {
        Self {
            static_residual: true,
            static_residual_frac: 0.015,
            inertial_residual: true,
            inertial_residual_frac: 0.02,
            plate_density_kg_m3: 1190.0,
            plate_thickness_m: 0.003,
            cross_axis: true,
            cross_axis_sd: 0.01,
            bias_drift: true,
            bias_frac_fs: 0.003,
            drift_frac_fs: 0.001,
            force_full_scale_n: 12.0,
            moment_full_scale_n_mm: 120.0,
            vibration: true,
            vibration_rel_amplitude: 0.01,
            vibration_hz: [5.0, 30.0],
            white_noise: true,
            force_noise_sd_n: 0.008,
            moment_noise_sd_n_mm: 0.1,
            quantization: true,
            force_lsb_n: 1.0 / 320.0,
            moment_lsb_n_mm: 1.0 / 64.0,
            lowpass: true,
            cutoff_hz: 5.0,
            encoder: true,
            encoder_counts_per_rev: 4096,
            tare: true,
            home_pose_deg: [0.0, 0.0, 90.0],
        }
    }
}

impl SensorConfig {
    /// Every effect off: the decimated loads are the exact aerodynamic loads.
    pub fn noise_free() -> Self {
        Self {
            static_residual: false,
            inertial_residual: false,
            cross_axis: false,
            bias_drift: false,
            vibration: false,
            white_noise: false,
            quantization: false,
            lowpass: false,
            encoder: false,
            tare: false,
            ..Self::default()
        }
    }
}

/// Per-dataset sensor errors (fixed across trajectories).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct DatasetSensorErrors {
    /// ε_s.
    pub static_residual: f64,
    /// ε_i.
    pub inertial_residual: f64,
    /// E (5 × 5, rows first).
    pub cross_axis: [[f64; 5]; 5],
}

impl DatasetSensorErrors {
    /// Draws the per-dataset errors from `rng` (all zero for effects that are off).
    pub fn draw(cfg: &SensorConfig, rng: &mut ChaCha8Rng) -> Self {
        let sign = |rng: &mut ChaCha8Rng| if rng.random::<bool>() { 1.0 } else { -1.0 };
        let s = sign(rng) * cfg.static_residual_frac;
        let i = sign(rng) * cfg.inertial_residual_frac;
        let mut e = [[0.0; 5]; 5];
        if cfg.cross_axis && cfg.cross_axis_sd > 0.0 {
            let nd = Normal::new(0.0, cfg.cross_axis_sd)
                .unwrap_or_else(|_| Normal::new(0.0, 0.0).expect("σ = 0"));
            e.iter_mut().flatten().for_each(|x| *x = nd.sample(rng));
        }
        Self {
            static_residual: if cfg.static_residual { s } else { 0.0 },
            inertial_residual: if cfg.inertial_residual { i } else { 0.0 },
            cross_axis: e,
        }
    }
}

/// One biquad section, b = [b0, b1, b2], a = [1, a1, a2].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Biquad {
    /// Numerator.
    pub b: [f64; 3],
    /// Denominator a1, a2.
    pub a: [f64; 2],
}

/// 4th-order Butterworth low-pass as two biquads (bilinear transform with pre-warping,
/// K = tan(π f_c / f_s), section Q = 1/(2 cos(π/8)) and 1/(2 cos(3π/8))). Requires
/// 0 < f_c < f_s/2.
pub fn butterworth4(cutoff_hz: f64, sample_rate_hz: f64) -> [Biquad; 2] {
    let k = (PI * cutoff_hz / sample_rate_hz).tan();
    let section = |q: f64| {
        let norm = 1.0 + k / q + k * k;
        let b0 = k * k / norm;
        Biquad {
            b: [b0, 2.0 * b0, b0],
            a: [2.0 * (k * k - 1.0) / norm, (1.0 - k / q + k * k) / norm],
        }
    };
    [
        section(1.0 / (2.0 * (PI / 8.0).cos())),
        section(1.0 / (2.0 * (3.0 * PI / 8.0).cos())),
    ]
}

/// Runs the biquads over `x` in place (direct form II transposed), starting in the steady
/// state of the first sample (a constant signal passes unchanged).
fn run_biquads(sections: &[Biquad; 2], x: &mut [f64]) {
    let Some(&x0) = x.first() else { return };
    for s in sections {
        let [b0, b1, b2] = s.b;
        let [a1, a2] = s.a;
        let mut z2 = (b2 - a2) * x0;
        let mut z1 = (b1 - a1) * x0 + z2;
        for v in x.iter_mut() {
            let xin = *v;
            let y = b0 * xin + z1;
            z1 = b1 * xin - a1 * y + z2;
            z2 = b2 * xin - a2 * y;
            *v = y;
        }
    }
}

/// Zero-phase filtering (forward, then backward) of `x` in place, with odd reflection padding
/// of `pad` samples at both ends; `work` is resized to `x.len() + 2·pad` once and reused.
pub fn filtfilt(sections: &[Biquad; 2], x: &mut [f64], pad: usize, work: &mut Vec<f64>) {
    let n = x.len();
    if n < 2 {
        return;
    }
    let pad = pad.min(n - 1);
    work.clear();
    work.extend((1..=pad).rev().map(|k| 2.0 * x[0] - x[k]));
    work.extend_from_slice(x);
    work.extend((1..=pad).map(|k| 2.0 * x[n - 1] - x[n - 1 - k]));
    run_biquads(sections, work);
    work.reverse();
    run_biquads(sections, work);
    work.reverse();
    x.copy_from_slice(&work[pad..pad + n]);
}

/// Applies steps 1–8 of the module docs to one trajectory's raw loads and decimates.
///
/// `raw` holds the raw loads (one row per raw sample, in place: modified), `static_loads` and
/// `inertial_loads` the rigid-plate loads on the same grid, `home_static` the static load at the
/// home pose (used with `cfg.tare`), `rng` the trajectory's stream. Returns every
/// `decimation`-th sample, starting at 0.
#[allow(clippy::too_many_arguments)]
pub fn measure(
    cfg: &SensorConfig,
    errors: &DatasetSensorErrors,
    raw: &mut [[f64; 5]],
    static_loads: &[[f64; 5]],
    inertial_loads: &[[f64; 5]],
    home_static: &[f64; 5],
    raw_rate_hz: f64,
    decimation: usize,
    rng: &mut ChaCha8Rng,
) -> Vec<[f64; 5]> {
    let n = raw.len();
    let dt = 1.0 / raw_rate_hz;
    let fs = |c: usize| {
        if c < 2 {
            cfg.force_full_scale_n
        } else {
            cfg.moment_full_scale_n_mm
        }
    };
    let tared = if cfg.tare { *home_static } else { [0.0; 5] };
    for ((y, ys), yi) in raw.iter_mut().zip(static_loads).zip(inertial_loads) {
        for c in 0..5 {
            y[c] += errors.static_residual * (ys[c] - tared[c]) + errors.inertial_residual * yi[c];
        }
        if cfg.cross_axis {
            // E acts on full-scale-normalized signals (calibration-matrix error).
            let y0 = *y;
            for (c, row) in errors.cross_axis.iter().enumerate() {
                let coupled: f64 = row
                    .iter()
                    .zip(&y0)
                    .enumerate()
                    .map(|(j, (e, v))| e * v / fs(j))
                    .sum();
                y[c] += fs(c) * coupled;
            }
        }
    }
    let std = Normal::new(0.0, 1.0).expect("unit normal");
    let mut column = vec![0.0; n];
    let mut work = Vec::with_capacity(n + 512);
    let sections = butterworth4(cfg.cutoff_hz, raw_rate_hz);
    let pad = ((3.0 * raw_rate_hz / cfg.cutoff_hz).ceil() as usize).max(12);
    for c in 0..5 {
        column
            .iter_mut()
            .zip(raw.iter())
            .for_each(|(v, y)| *v = y[c]);
        if cfg.bias_drift {
            let bias = cfg.bias_frac_fs * fs(c) * std.sample(rng);
            let mut offset = if cfg.tare { 0.0 } else { bias };
            let step_sd = cfg.drift_frac_fs * fs(c) * (dt / 20.0).sqrt();
            for v in column.iter_mut() {
                *v += offset;
                offset += step_sd * std.sample(rng);
            }
        }
        if cfg.vibration {
            let rms = (column.iter().map(|v| v * v).sum::<f64>() / n.max(1) as f64).sqrt();
            let f = rng.random_range(cfg.vibration_hz[0]..=cfg.vibration_hz[1]);
            let phase = rng.random_range(0.0..2.0 * PI);
            let amp = cfg.vibration_rel_amplitude * rms * std::f64::consts::SQRT_2;
            for (k, v) in column.iter_mut().enumerate() {
                *v += amp * (2.0 * PI * f * k as f64 * dt + phase).sin();
            }
        }
        if cfg.white_noise {
            let sd = if c < 2 {
                cfg.force_noise_sd_n
            } else {
                cfg.moment_noise_sd_n_mm
            };
            column.iter_mut().for_each(|v| *v += sd * std.sample(rng));
        }
        if cfg.quantization {
            let lsb = if c < 2 {
                cfg.force_lsb_n
            } else {
                cfg.moment_lsb_n_mm
            };
            column
                .iter_mut()
                .for_each(|v| *v = (*v / lsb).round() * lsb);
        }
        if cfg.lowpass {
            filtfilt(&sections, &mut column, pad, &mut work);
        }
        raw.iter_mut().zip(&column).for_each(|(y, v)| y[c] = *v);
    }
    raw.iter().step_by(decimation.max(1)).copied().collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;

    #[test]
    fn butterworth_gain_and_zero_phase() {
        let fs = 250.0;
        let sections = butterworth4(5.0, fs);
        let mut work = Vec::new();
        // Analytic Butterworth magnitude 1/sqrt(1 + (f/fc)^8) per pass (bilinear: prewarped).
        for (f, expect) in [(0.3, 1.0), (5.0, 0.5)] {
            let n = 5000;
            let mut x: Vec<f64> = (0..n)
                .map(|k| (2.0 * PI * f * k as f64 / fs).sin())
                .collect();
            let orig = x.clone();
            filtfilt(&sections, &mut x, 150, &mut work);
            let mid = 1000..4000;
            let num: f64 = mid.clone().map(|k| x[k] * orig[k]).sum();
            let den: f64 = mid.clone().map(|k| orig[k] * orig[k]).sum();
            let gain = num / den;
            assert!((gain - expect).abs() < 2e-3, "f = {f}: gain {gain}");
            // Zero phase: the residual is orthogonal-free (no quadrature component).
            let quad: f64 = mid
                .map(|k| x[k] * (2.0 * PI * f * k as f64 / fs).cos())
                .sum();
            assert!(quad.abs() / den < 1e-3);
        }
        let mut c = vec![3.5; 300];
        filtfilt(&sections, &mut c, 150, &mut work);
        assert!(c.iter().all(|v| (v - 3.5).abs() < 1e-12));
    }

    /// At rest in the home pose, the tared reading is zero whatever the bias and the static
    /// residual; untared, it is the bias plus ε_s·y_static,home. Away from home the tare leaves
    /// ε_s·(y_static − y_static,home).
    #[test]
    fn the_tare_removes_the_bias_and_the_static_residual_at_home() {
        let n = 2500;
        let home = [0.3, -0.2, 5.0, 7.0, -1.0];
        let cfg = SensorConfig {
            static_residual: true,
            bias_drift: true,
            drift_frac_fs: 0.0,
            tare: true,
            ..SensorConfig::noise_free()
        };
        let mut rng = ChaCha8Rng::seed_from_u64(4);
        let errs = DatasetSensorErrors::draw(&cfg, &mut rng);
        let zeros = vec![[0.0; 5]; n];
        let at_home = vec![home; n];
        let run = |cfg: &SensorConfig, statics: &[[f64; 5]]| {
            let mut rng = ChaCha8Rng::seed_from_u64(9);
            let mut raw = vec![[0.0; 5]; n];
            measure(
                cfg, &errs, &mut raw, statics, &zeros, &home, 250.0, 10, &mut rng,
            )
        };
        assert!(
            run(&cfg, &at_home)
                .iter()
                .flatten()
                .all(|v| v.abs() < 1e-15)
        );
        let untared = run(
            &SensorConfig {
                tare: false,
                ..cfg.clone()
            },
            &at_home,
        );
        let first = untared[0];
        assert!(untared.iter().all(|y| *y == first));
        assert!(
            (first[0] - errs.static_residual * home[0]).abs() > 1e-6,
            "a bias is present"
        );
        let away = vec![[1.3, -0.2, 5.0, 9.0, -1.0]; n];
        let tared = run(&cfg, &away);
        assert!((tared[5][0] - errs.static_residual * 1.0).abs() < 1e-12);
        assert!((tared[5][3] - errs.static_residual * 2.0).abs() < 1e-12);
    }

    #[test]
    fn noise_free_is_identity_and_noise_has_expected_size() {
        let n = 4700;
        let clean: Vec<[f64; 5]> = (0..n)
            .map(|k| [(k as f64 * 0.01).sin(), 0.1, 1.0, 2.0, -3.0])
            .collect();
        let zeros = vec![[0.0; 5]; n];
        let mut rng = ChaCha8Rng::seed_from_u64(1);
        let cfg = SensorConfig::noise_free();
        let errs = DatasetSensorErrors::draw(&cfg, &mut rng);
        let mut raw = clean.clone();
        let out = measure(
            &cfg, &errs, &mut raw, &zeros, &zeros, &[0.0; 5], 250.0, 10, &mut rng,
        );
        assert_eq!(out.len(), 470);
        for (k, y) in out.iter().enumerate() {
            assert_eq!(*y, clean[10 * k]);
        }
        // White noise alone, filtered at 5 Hz of 250 Hz: σ shrinks by about sqrt(2·5·0.5/125)
        // (equivalent noise bandwidth of the squared 4th-order response ≈ 0.9 f_c).
        let cfg = SensorConfig {
            white_noise: true,
            lowpass: true,
            ..SensorConfig::noise_free()
        };
        let mut raw = vec![[0.0; 5]; n];
        let out = measure(
            &cfg, &errs, &mut raw, &zeros, &zeros, &[0.0; 5], 250.0, 10, &mut rng,
        );
        let sd = (out.iter().map(|y| y[0] * y[0]).sum::<f64>() / out.len() as f64).sqrt();
        let expect = 0.008 * (0.9 * 5.0 / 125.0f64).sqrt();
        assert!((sd / expect - 1.0).abs() < 0.25, "{sd} vs {expect}");
        // Same seed → same result.
        let run = |seed| {
            let mut rng = ChaCha8Rng::seed_from_u64(seed);
            let cfg = SensorConfig::default();
            let errs = DatasetSensorErrors::draw(&cfg, &mut rng);
            let mut raw = clean.clone();
            measure(
                &cfg, &errs, &mut raw, &zeros, &zeros, &[0.0; 5], 250.0, 10, &mut rng,
            )
        };
        assert_eq!(run(7), run(7));
        assert_ne!(run(7), run(8));
    }
}
