//! Agreement of a dataset's loads with a reference of the rig's loads (the published model's
//! prediction on the same motions), all in standardized units.
//!
//! Per set of trajectories (the paper's 512 training and 36 test), pooled over the samples from
//! `start_sample` on, for each output channel c with dataset loads z_c and the reference's mean
//! m_c and variance s_c² (both standardized):
//!
//! - Pearson r(z_c, m_c);
//! - z-RMSE √mean((z_c − m_c)²);
//! - the share of samples inside the reference's 95 % band, |z_c − m_c| ≤ 1.96 s_c;
//!
//! the couplings r(F_y, F_x) and r(M_x, F_x) of the dataset and of the reference; and, per
//! input–output pair, the Fig. 5 cross-correlation rule ([`crate::authority::peak_table`]: the
//! lag of the largest |r| within one stroke cycle) on the dataset's loads and on the reference's
//! means: median |r|, median lag and its interquartile range (cycles).

use serde::{Deserialize, Serialize};

use crate::authority::{AuthorityConfig, AuthorityTrajectory, PeakTable, peak_table};
use crate::error::{AnalysisError, Result, param};
use crate::stats::{Rows, median, quartiles};

/// Output channels, in the dataset's order.
pub const CHANNELS: [&str; 5] = ["F_x", "F_y", "M_x", "M_y", "M_z"];

/// Half-width of the 95 % band in standard deviations.
const BAND_95: f64 = 1.959_963_984_540_054;

/// One trajectory of the comparison: every table `n_time × channels`, row-major.
#[derive(Debug, Clone, Copy)]
pub struct RigTrajectory<'a> {
    /// The dataset's loads, standardized, `n_time × 5`.
    pub loads_z: Rows<'a>,
    /// The reference's predictive mean, standardized, `n_time × 5`.
    pub reference_mean_z: Rows<'a>,
    /// The reference's predictive variance, standardized, `n_time × 5`.
    pub reference_var_z: Rows<'a>,
    /// The inputs, `n_time × n_inputs`, for the lag statistics.
    pub inputs: Rows<'a>,
    /// Stroke period (samples).
    pub period_samples: f64,
}

/// Agreement of one channel.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ChannelAgreement {
    /// Channel name.
    pub channel: String,
    /// Pearson r of the dataset's loads with the reference's mean.
    pub r: f64,
    /// RMS difference (standardized units, σ).
    pub z_rmse: f64,
    /// Share of samples inside the reference's 95 % band.
    pub band_share: f64,
}

/// The couplings of the chordwise channels with the normal force.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Couplings {
    /// r(F_y, F_x).
    pub fy_fx: f64,
    /// r(M_x, F_x).
    pub mx_fx: f64,
}

/// Fig. 5's statistics of one input–output pair over the trajectories.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct LagStats {
    /// Trajectories with a peak inside the cycle.
    pub n: usize,
    /// Median of the largest |r|.
    pub median_abs_r: f64,
    /// Median lag (cycles).
    pub median_lag_cycles: f64,
    /// Interquartile range of the lag (cycles).
    pub lag_iqr_cycles: f64,
}

/// One input–output pair's lag statistics, of the dataset and of the reference.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct LagPair {
    /// Input name.
    pub input: String,
    /// Output channel.
    pub output: String,
    /// On the dataset's loads.
    pub dataset: LagStats,
    /// On the reference's mean.
    pub reference: LagStats,
}

/// The agreement on one set of trajectories.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SetAgreement {
    /// Trajectories.
    pub n_trajectories: usize,
    /// Pooled samples per channel.
    pub n_samples: usize,
    /// Per channel, in [`CHANNELS`] order.
    pub channels: Vec<ChannelAgreement>,
    /// The dataset's couplings.
    pub dataset_couplings: Couplings,
    /// The reference's couplings.
    pub reference_couplings: Couplings,
    /// Every input–output pair, input-major.
    pub lags: Vec<LagPair>,
}

impl SetAgreement {
    /// The lag statistics of `input` → `output`.
    pub fn lag(&self, input: &str, output: &str) -> Option<&LagPair> {
        self.lags
            .iter()
            .find(|p| p.input == input && p.output == output)
    }

    /// Mean squared standardized difference over the five channels, the rig parameters'
    /// objective ([`crate::rig`] module docs).
    pub fn mean_z_mse(&self) -> f64 {
        self.channels
            .iter()
            .map(|c| c.z_rmse * c.z_rmse)
            .sum::<f64>()
            / self.channels.len() as f64
    }
}

/// Compares one set of trajectories (see the module docs). `input_names` names the inputs'
/// columns; `authority` sets the cross-correlation rule of the lag statistics (`None`: none are
/// computed, `lags` is empty).
///
/// # Errors
/// [`AnalysisError::Empty`] for no trajectory or no sample from `start_sample` on,
/// [`AnalysisError::Shape`] naming the table of a trajectory that does not fit,
/// [`AnalysisError::ConstantSeries`] for a channel without spread, and the cross-correlation's
/// errors.
pub fn set_agreement(
    trajectories: &[RigTrajectory<'_>],
    input_names: &[&str],
    start_sample: usize,
    authority: Option<&AuthorityConfig>,
) -> Result<SetAgreement> {
    if trajectories.is_empty() {
        return Err(AnalysisError::Empty {
            what: "trajectories of the rig comparison".into(),
        });
    }
    for (i, t) in trajectories.iter().enumerate() {
        check_shapes(i, t, input_names.len())?;
    }
    let tail = |rows: Rows<'_>| rows.n_rows().saturating_sub(start_sample);
    let n_samples: usize = trajectories.iter().map(|t| tail(t.loads_z)).sum();
    if n_samples < 2 {
        return Err(AnalysisError::Empty {
            what: format!("samples from {start_sample} on"),
        });
    }
    let pooled = |pick: for<'r, 'b> fn(&'r RigTrajectory<'b>) -> Rows<'b>, c: usize| -> Vec<f64> {
        trajectories
            .iter()
            .flat_map(|t| {
                let rows = pick(t);
                (start_sample..rows.n_rows()).map(move |i| rows.get(i, c))
            })
            .collect()
    };
    let mut channels = Vec::with_capacity(5);
    let (mut loads, mut means) = (Vec::new(), Vec::new());
    for (c, &channel) in CHANNELS.iter().enumerate() {
        let z = pooled(|t| t.loads_z, c);
        let m = pooled(|t| t.reference_mean_z, c);
        let v = pooled(|t| t.reference_var_z, c);
        let (mut sq, mut inside) = (0.0f64, 0usize);
        for ((z, m), v) in z.iter().zip(&m).zip(&v) {
            let d = z - m;
            sq += d * d;
            inside += usize::from(d.abs() <= BAND_95 * v.max(0.0).sqrt());
        }
        channels.push(ChannelAgreement {
            channel: channel.into(),
            r: pearson(
                &z,
                &m,
                &format!("{channel} of the dataset or the reference"),
            )?,
            z_rmse: (sq / z.len() as f64).sqrt(),
            band_share: inside as f64 / z.len() as f64,
        });
        loads.push(z);
        means.push(m);
    }
    let couplings = |series: &[Vec<f64>], whose: &str| -> Result<Couplings> {
        Ok(Couplings {
            fy_fx: pearson(&series[1], &series[0], &format!("{whose} F_y or F_x"))?,
            mx_fx: pearson(&series[2], &series[0], &format!("{whose} M_x or F_x"))?,
        })
    };
    let lag_table = |pick: for<'r, 'b> fn(&'r RigTrajectory<'b>) -> Rows<'b>,
                     authority: &AuthorityConfig|
     -> Result<PeakTable> {
        let series: Vec<AuthorityTrajectory<'_>> = trajectories
            .iter()
            .map(|t| {
                Ok(AuthorityTrajectory {
                    inputs: tail_rows(t.inputs, start_sample)?,
                    states: tail_rows(pick(t), start_sample)?,
                    period_samples: t.period_samples,
                })
            })
            .collect::<Result<_>>()?;
        peak_table(&series, authority)
    };
    let mut lags = Vec::with_capacity(input_names.len() * 5);
    if let Some(authority) = authority {
        let on_dataset = lag_table(|t| t.loads_z, authority)?;
        let on_reference = lag_table(|t| t.reference_mean_z, authority)?;
        for (k, input) in input_names.iter().enumerate() {
            for (c, &output) in CHANNELS.iter().enumerate() {
                lags.push(LagPair {
                    input: input.to_string(),
                    output: output.into(),
                    dataset: lag_stats(&on_dataset, c, k)?,
                    reference: lag_stats(&on_reference, c, k)?,
                });
            }
        }
    }
    Ok(SetAgreement {
        n_trajectories: trajectories.len(),
        n_samples: loads[0].len(),
        channels,
        dataset_couplings: couplings(&loads, "the dataset's")?,
        reference_couplings: couplings(&means, "the reference's")?,
        lags,
    })
}

/// The rows of `rows` from `start` on.
fn tail_rows(rows: Rows<'_>, start: usize) -> Result<Rows<'_>> {
    let cols = rows.n_cols();
    Rows::new(&rows.as_slice()[start.min(rows.n_rows()) * cols..], cols)
}

fn check_shapes(i: usize, t: &RigTrajectory<'_>, n_inputs: usize) -> Result<()> {
    let n = t.loads_z.n_rows();
    let tables = [
        ("loads", t.loads_z, 5),
        ("reference mean", t.reference_mean_z, 5),
        ("reference variance", t.reference_var_z, 5),
        ("inputs", t.inputs, n_inputs),
    ];
    for (what, rows, cols) in tables {
        if rows.n_rows() != n || rows.n_cols() != cols {
            return Err(AnalysisError::Shape {
                what: format!("trajectory {i} {what}"),
                expected: format!("{n} × {cols}"),
                found: format!("{} × {}", rows.n_rows(), rows.n_cols()),
            });
        }
    }
    if !(t.period_samples.is_finite() && t.period_samples > 0.0) {
        return Err(param(
            &format!("trajectory {i} period_samples"),
            t.period_samples,
            "must be finite and > 0",
        ));
    }
    Ok(())
}

/// Median |r|, median lag and lag IQR of pair (output `c`, input `k`) over the table's
/// trajectories with a peak (NaN when none has one).
fn lag_stats(table: &PeakTable, c: usize, k: usize) -> Result<LagStats> {
    let points = table.points(c, k);
    if points.is_empty() {
        return Ok(LagStats {
            n: 0,
            median_abs_r: f64::NAN,
            median_lag_cycles: f64::NAN,
            lag_iqr_cycles: f64::NAN,
        });
    }
    let lag: Vec<f64> = points.iter().map(|p| p[0]).collect();
    let abs_r: Vec<f64> = points.iter().map(|p| p[1]).collect();
    let (q1, _, q3) = quartiles(&lag)?;
    Ok(LagStats {
        n: points.len(),
        median_abs_r: median(&abs_r)?,
        median_lag_cycles: median(&lag)?,
        lag_iqr_cycles: q3 - q1,
    })
}

/// Pearson correlation of two equally long series.
///
/// # Errors
/// [`AnalysisError::ConstantSeries`] naming `what` when either has no spread.
pub fn pearson(a: &[f64], b: &[f64], what: &str) -> Result<f64> {
    let n = a.len().min(b.len()) as f64;
    let (ma, mb) = (a.iter().sum::<f64>() / n, b.iter().sum::<f64>() / n);
    let (mut sab, mut saa, mut sbb) = (0.0, 0.0, 0.0);
    for (x, y) in a.iter().zip(b) {
        let (dx, dy) = (x - ma, y - mb);
        sab += dx * dy;
        saa += dx * dx;
        sbb += dy * dy;
    }
    if !(saa > 0.0 && sbb > 0.0) {
        return Err(AnalysisError::ConstantSeries { what: what.into() });
    }
    Ok(sab / (saa * sbb).sqrt())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A trajectory whose loads are `scale` × a reference of sines plus `offset`, with unit
    /// reference variance; F_y = 0.5 F_x + its own sine in the reference.
    fn series(n: usize, phase: f64) -> (Vec<f64>, Vec<f64>) {
        let mut mean = Vec::with_capacity(n * 5);
        let mut inputs = Vec::with_capacity(n * 2);
        for i in 0..n {
            let t = i as f64 * 0.1 + phase;
            let fx = t.sin();
            mean.extend([
                fx,
                0.5 * fx + 0.3 * (2.3 * t).cos(),
                -fx,
                2.0 * fx,
                (1.7 * t).sin(),
            ]);
            inputs.extend([(t + 0.3).sin(), (0.5 * t).cos()]);
        }
        (mean, inputs)
    }

    #[test]
    fn agreement_of_a_known_dataset() {
        let n = 300;
        let (mean, inputs) = series(n, 0.0);
        let (mean2, inputs2) = series(n, 1.0);
        // Dataset: the reference on F_x, F_y and M_x; M_y shifted by 1.0σ; M_z sign-flipped.
        let shift = |m: &[f64]| -> Vec<f64> {
            m.chunks(5)
                .flat_map(|r| [r[0], r[1], r[2], r[3] + 1.0, -r[4]])
                .collect()
        };
        let (loads, loads2) = (shift(&mean), shift(&mean2));
        let var = vec![0.25; n * 5];
        let traj = |l: &'static [f64], m: &'static [f64], u: &'static [f64]| RigTrajectory {
            loads_z: Rows::new(l, 5).unwrap(),
            reference_mean_z: Rows::new(m, 5).unwrap(),
            reference_var_z: Rows::new(Box::leak(var.clone().into_boxed_slice()), 5).unwrap(),
            inputs: Rows::new(u, 2).unwrap(),
            period_samples: 63.0,
        };
        let leak = |v: Vec<f64>| -> &'static [f64] { Box::leak(v.into_boxed_slice()) };
        let set = [
            traj(leak(loads), leak(mean), leak(inputs)),
            traj(leak(loads2), leak(mean2), leak(inputs2)),
        ];
        let a = set_agreement(&set, &["u0", "u1"], 20, Some(&AuthorityConfig::default())).unwrap();
        assert_eq!((a.n_trajectories, a.n_samples), (2, 2 * 280));
        let ch = &a.channels;
        for c in [0, 1, 2] {
            assert!((ch[c].r - 1.0).abs() < 1e-12 && ch[c].z_rmse < 1e-12);
            assert_eq!(ch[c].band_share, 1.0);
        }
        // A constant shift keeps r = 1, costs 1σ, and leaves the band (half-width 0.98σ).
        assert!((ch[3].r - 1.0).abs() < 1e-12 && (ch[3].z_rmse - 1.0).abs() < 1e-12);
        assert_eq!(ch[3].band_share, 0.0);
        assert!((ch[4].r + 1.0).abs() < 1e-12);
        assert!((a.dataset_couplings.mx_fx + 1.0).abs() < 1e-12);
        assert!(a.reference_couplings.fy_fx > 0.8 && a.reference_couplings.fy_fx < 0.99);
        // u0 = sin(t + 0.3) leads F_x = sin t by 0.3 rad, 3 samples (3/63 cycle); the biased
        // cross-correlation of a short series pulls the peak by up to a sample.
        let lag = a.lag("u0", "F_x").unwrap();
        assert_eq!(lag.dataset, lag.reference);
        let median = lag.dataset.median_lag_cycles * 63.0;
        assert!((2.0 - 1e-9..=3.0 + 1e-9).contains(&median), "{lag:?}");
        assert!(lag.dataset.median_abs_r > 0.99);
        assert_eq!(a.lags.len(), 10);
        // M_z = −reference: the difference is 2 sin(1.7 t), RMS ≈ √2.
        assert!(
            (ch[4].z_rmse - 2f64.sqrt()).abs() < 0.05,
            "{}",
            ch[4].z_rmse
        );
        let mse = (1.0 + ch[4].z_rmse * ch[4].z_rmse) / 5.0;
        assert!((a.mean_z_mse() - mse).abs() < 1e-12);
    }

    #[test]
    fn bad_tables_are_named() {
        let m = vec![0.0; 50];
        let u = vec![0.0; 20];
        let t = RigTrajectory {
            loads_z: Rows::new(&m, 5).unwrap(),
            reference_mean_z: Rows::new(&m, 5).unwrap(),
            reference_var_z: Rows::new(&m, 5).unwrap(),
            inputs: Rows::new(&u, 2).unwrap(),
            period_samples: 5.0,
        };
        let e = set_agreement(&[t], &["a", "b"], 0, Some(&AuthorityConfig::default())).unwrap_err();
        assert!(e.to_string().contains("constant"), "{e}");
        let short = Rows::new(&u[..10], 2).unwrap();
        let e = set_agreement(
            &[RigTrajectory { inputs: short, ..t }],
            &["a", "b"],
            0,
            Some(&AuthorityConfig::default()),
        )
        .unwrap_err();
        assert!(e.to_string().contains("trajectory 0 inputs"), "{e}");
        assert!(set_agreement(&[], &[], 0, Some(&AuthorityConfig::default())).is_err());
    }
}
