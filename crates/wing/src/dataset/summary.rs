//! A printable overview of a dataset: counts, split, families, per-column ranges, metadata.

use std::fmt;

use crate::dataset::{Dataset, DatasetMeta, EULER_NAMES, INPUT_NAMES, OUTPUT_NAMES};

/// Range and moments of one column over all samples of all trajectories.
#[derive(Debug, Clone, PartialEq)]
pub struct ColumnSummary {
    /// Column name.
    pub name: String,
    /// Unit.
    pub unit: String,
    /// Minimum.
    pub min: f64,
    /// Maximum.
    pub max: f64,
    /// Mean.
    pub mean: f64,
    /// Population standard deviation.
    pub std: f64,
}

/// Trajectory counts of one family.
#[derive(Debug, Clone, PartialEq)]
pub struct FamilyCount {
    /// Family label.
    pub family: String,
    /// Training trajectories.
    pub train: usize,
    /// Test trajectories.
    pub test: usize,
}

/// Overview of a dataset (see [`Dataset::summary`]).
#[derive(Debug, Clone, PartialEq)]
pub struct DatasetSummary {
    /// Number of trajectories.
    pub n_trajectories: usize,
    /// Samples per trajectory.
    pub n_samples: usize,
    /// Training trajectories.
    pub n_train: usize,
    /// Sampling period (s).
    pub dt_s: f64,
    /// Counts per family, in order of first appearance.
    pub families: Vec<FamilyCount>,
    /// Euler angle columns (rad).
    pub euler: Vec<ColumnSummary>,
    /// Input columns.
    pub inputs: Vec<ColumnSummary>,
    /// Output columns (empty for kinematics-only data).
    pub outputs: Vec<ColumnSummary>,
    /// U_ref over trajectories (m/s).
    pub u_ref_m_s: Option<ColumnSummary>,
    /// Metadata.
    pub meta: DatasetMeta,
}

fn column<'a>(
    name: &str,
    unit: &str,
    values: impl Iterator<Item = f64> + Clone + 'a,
) -> Option<ColumnSummary> {
    let (mut n, mut sum, mut min, mut max) = (0usize, 0.0, f64::INFINITY, f64::NEG_INFINITY);
    for v in values.clone() {
        n += 1;
        sum += v;
        min = min.min(v);
        max = max.max(v);
    }
    if n == 0 {
        return None;
    }
    let mean = sum / n as f64;
    let var = values.map(|v| (v - mean) * (v - mean)).sum::<f64>() / n as f64;
    Some(ColumnSummary {
        name: name.into(),
        unit: unit.into(),
        min,
        max,
        mean,
        std: var.sqrt(),
    })
}

impl Dataset {
    /// Counts, split, families and per-column ranges over all samples. Cost: two passes.
    pub fn summary(&self) -> DatasetSummary {
        let ts = &self.trajectories;
        let mut families: Vec<FamilyCount> = Vec::new();
        for (k, t) in ts.iter().enumerate() {
            let idx = match families.iter().position(|f| f.family == t.family) {
                Some(i) => i,
                None => {
                    families.push(FamilyCount {
                        family: t.family.clone(),
                        train: 0,
                        test: 0,
                    });
                    families.len() - 1
                }
            };
            if k < self.n_train {
                families[idx].train += 1;
            } else {
                families[idx].test += 1;
            }
        }
        let unit = |units: &[String], j: usize| units.get(j).cloned().unwrap_or_default();
        let euler = (0..3)
            .filter_map(|j| {
                column(
                    EULER_NAMES[j],
                    "rad",
                    ts.iter()
                        .flat_map(move |t| t.euler_rad.iter().map(move |r| r[j])),
                )
            })
            .collect();
        let inputs = (0..7)
            .filter_map(|j| {
                column(
                    INPUT_NAMES[j],
                    &unit(&self.meta.input_units, j),
                    ts.iter()
                        .flat_map(move |t| t.inputs.iter().map(move |r| r[j])),
                )
            })
            .collect();
        let outputs = (0..5)
            .filter_map(|j| {
                column(
                    OUTPUT_NAMES[j],
                    &unit(&self.meta.output_units, j),
                    ts.iter()
                        .filter_map(|t| t.outputs.as_ref())
                        .flat_map(move |y| y.iter().map(move |r| r[j])),
                )
            })
            .collect();
        DatasetSummary {
            n_trajectories: ts.len(),
            n_samples: self.n_samples(),
            n_train: self.n_train,
            dt_s: self.dt_s,
            families,
            euler,
            inputs,
            outputs,
            u_ref_m_s: column("u_ref", "m/s", ts.iter().map(|t| t.u_ref_m_s)),
            meta: self.meta.clone(),
        }
    }
}

impl fmt::Display for DatasetSummary {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        writeln!(
            f,
            "trajectories: {} ({} train, {} test), {} samples each, dt_s = {} ({:.2} s per trajectory)",
            self.n_trajectories,
            self.n_train,
            self.n_trajectories.saturating_sub(self.n_train),
            self.n_samples,
            self.dt_s,
            self.n_samples as f64 * self.dt_s
        )?;
        writeln!(f, "families:")?;
        for c in &self.families {
            writeln!(
                f,
                "  {:<16} {:>5} train {:>5} test",
                c.family, c.train, c.test
            )?;
        }
        let table = |f: &mut fmt::Formatter<'_>, title: &str, cols: &[ColumnSummary]| {
            writeln!(f, "{title}:")?;
            writeln!(
                f,
                "  {:<12} {:<8} {:>13} {:>13} {:>13} {:>13}",
                "name", "unit", "min", "max", "mean", "std"
            )?;
            for c in cols {
                writeln!(
                    f,
                    "  {:<12} {:<8} {:>13.6e} {:>13.6e} {:>13.6e} {:>13.6e}",
                    c.name, c.unit, c.min, c.max, c.mean, c.std
                )?;
            }
            Ok(())
        };
        table(f, "euler angles", &self.euler)?;
        table(f, "inputs u", &self.inputs)?;
        if self.outputs.is_empty() {
            writeln!(f, "outputs y: none (kinematics only)")?;
        } else {
            table(f, "outputs y", &self.outputs)?;
        }
        if let Some(u) = &self.u_ref_m_s {
            table(f, "per trajectory", std::slice::from_ref(u))?;
        }
        let m = &self.meta;
        writeln!(
            f,
            "metadata: format_version {}, generator '{}', seed {}",
            m.format_version,
            m.generator,
            m.seed.map_or("none".to_string(), |s| s.to_string())
        )?;
        writeln!(
            f,
            "  wing: span {} m, chord {} m, root offset {} m, pitch axis {} chord, U_ref radius {} m",
            m.wing.span_m,
            m.wing.chord_m,
            m.wing.root_offset_m,
            m.wing.pitch_axis_frac,
            m.wing.u_ref_radius_m
        )?;
        writeln!(
            f,
            "  fluid: density {} kg/m^3, kinematic viscosity {} m^2/s",
            m.fluid.density_kg_m3, m.fluid.kinematic_viscosity_m2_s
        )?;
        write!(f, "  settings: {}", m.settings)
    }
}

#[cfg(test)]
mod tests {
    use crate::dataset::tests::sample;

    #[test]
    fn summary_counts_and_ranges() {
        // u_j = k + i + j over k < 3, i < 4: min j, max 5 + j, mean 2.5 + j.
        let ds = sample(3, 4, 2, true);
        let s = ds.summary();
        assert_eq!((s.n_trajectories, s.n_samples, s.n_train), (3, 4, 2));
        assert_eq!(s.families.len(), 2);
        assert_eq!((s.families[0].train, s.families[0].test), (1, 1));
        assert_eq!((s.families[1].train, s.families[1].test), (1, 0));
        for (j, c) in s.inputs.iter().enumerate() {
            assert_eq!(
                (c.min, c.max, c.mean),
                (j as f64, 5.0 + j as f64, 2.5 + j as f64)
            );
        }
        assert_eq!(s.outputs.len(), 5);
        let text = s.to_string();
        assert!(
            text.contains("3 (2 train, 1 test)") && text.contains("pitch_acc"),
            "{text}"
        );
        assert!(
            sample(2, 3, 1, false)
                .summary()
                .to_string()
                .contains("kinematics only")
        );
    }
}
