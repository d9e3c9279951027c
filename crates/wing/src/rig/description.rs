//! The rig description: one file (TOML, read by the jobs layer) that says what a rig is and how
//! its raw recordings are processed. Checked once ([`RigDescription::check`]); every error names
//! the field as written in the file.

use serde::{Deserialize, Serialize};

use super::RigError;
use super::convention::AngleConvention;
use super::identify::{Medium, Reference};
use crate::dataset::{Fluid, WingGeometry};

/// A rig: its wing, fluid, angles, sensor, sampling and processing.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RigDescription {
    /// A name for reports.
    #[serde(default)]
    pub name: String,
    /// The wing's planform and axes.
    pub wing: RigWing,
    /// The fluid.
    pub fluid: RigFluid,
    /// How the angles are recorded.
    pub angles: AngleConvention,
    /// The force/torque sensor.
    pub sensor: SensorPose,
    /// Rates of the recording and of the dataset.
    pub sampling: RigSampling,
    /// The zero-phase low-pass of the loads.
    #[serde(default)]
    pub filter: LoadFilter,
    /// The tare: the rest at the home pose that starts every recording.
    #[serde(default)]
    pub tare: Tare,
    /// Mass properties of everything the sensor carries (for gravity, buoyancy, inertia).
    #[serde(default)]
    pub mass: Option<MassProperties>,
    /// Reference runs that the rigid-body loads are identified from, instead of `[mass]`.
    #[serde(default)]
    pub reference: Option<Reference>,
    /// Which rigid-body loads to subtract.
    #[serde(default)]
    pub subtract: Subtract,
    /// How recordings are cut into trajectories.
    #[serde(default)]
    pub trajectories: Cutting,
}

/// A flat wing: a rectangle (`chord_m`, `pitch_axis_frac`) or an `outline`. The coefficients use
/// its area S and mean chord c̄ = S / span; an outline enters the dataset (and the virtual wing)
/// as the rectangle of the same span, area and mean leading-edge position.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RigWing {
    /// Span of the plate (m).
    pub span_m: f64,
    /// Chord of a rectangular plate (m).
    #[serde(default)]
    pub chord_m: Option<f64>,
    /// Distance from the stroke axis to the wing root (m).
    pub root_offset_m: f64,
    /// Pitch axis behind the leading edge, as a fraction of the rectangle's chord.
    #[serde(default)]
    pub pitch_axis_frac: Option<f64>,
    /// The planform instead of a rectangle: rows [z, y_LE, y_TE] (m), z along the span from the
    /// root (increasing, from 0 to `span_m`), y_LE and y_TE the leading and trailing edges'
    /// chordwise positions from the pitch axis (towards the leading edge positive); linear
    /// between rows.
    #[serde(default)]
    pub outline: Option<Vec<[f64; 3]>>,
    /// Radius of U_ref (m); default the tip, `root_offset_m + span_m`.
    #[serde(default)]
    pub u_ref_radius_m: Option<f64>,
}

/// The fluid the wing moves in.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RigFluid {
    /// Density ρ (kg/m³).
    pub density_kg_m3: f64,
    /// Kinematic viscosity ν (m²/s).
    pub kinematic_viscosity_m2_s: f64,
}

/// Units a sensor reports forces in.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum ForceUnit {
    /// Newton.
    N,
    /// Millinewton.
    #[serde(rename = "mN")]
    MilliN,
}

/// Units a sensor reports moments in.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum MomentUnit {
    /// Newton metre.
    #[serde(rename = "N*m")]
    NM,
    /// Newton millimetre.
    #[serde(rename = "N*mm")]
    NMm,
    /// Millinewton metre.
    #[serde(rename = "mN*m")]
    MilliNM,
}

/// The six-axis sensor: its channels, units and pose on the wing.
///
/// The sensor rides on the wing. Its origin is `offset_m` from the wing root on the pitch
/// axis; its axes are the wing's rotated by R_ws = R_x(r_x)·R_y(r_y)·R_z(r_z)
/// (`rotation_deg` = [r_x, r_y, r_z]): a vector of sensor components v_s has the wing components
/// R_ws·v_s. It reports the force and the moment about its origin that the wing exerts on it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SensorPose {
    /// The recording's columns of F_x, F_y, F_z, M_x, M_y, M_z in the sensor's axes.
    pub columns: [String; 6],
    /// Unit of the forces.
    pub force_unit: ForceUnit,
    /// Unit of the moments.
    pub moment_unit: MomentUnit,
    /// Sensor origin from the wing root on the pitch axis, wing axes (m).
    #[serde(default)]
    pub offset_m: [f64; 3],
    /// Rotation of the sensor's axes from the wing's (deg, module docs).
    #[serde(default)]
    pub rotation_deg: [f64; 3],
    /// White-noise standard deviation of each channel (sensor units) — only for rehearsals
    /// with the virtual wing.
    #[serde(default)]
    pub noise_sd: [f64; 6],
    /// Standard deviation of each channel's offset per recording (sensor units) — only for
    /// rehearsals; the tare removes it.
    #[serde(default)]
    pub bias_sd: [f64; 6],
}

impl SensorPose {
    /// SI per recorded unit of each channel: newtons per force unit (F_x, F_y, F_z), newton-metres
    /// per moment unit (M_x, M_y, M_z).
    pub fn si_per_unit(&self) -> [f64; 6] {
        let f = match self.force_unit {
            ForceUnit::N => 1.0,
            ForceUnit::MilliN => 1e-3,
        };
        let m = match self.moment_unit {
            MomentUnit::NM => 1.0,
            MomentUnit::NMm | MomentUnit::MilliNM => 1e-3,
        };
        [f, f, f, m, m, m]
    }
}

/// Sampling of the recording and of the dataset.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RigSampling {
    /// Sampling rate of the recording (Hz).
    pub rate_hz: f64,
    /// A column of time stamps (s), checked against `rate_hz`; none: the rate alone.
    #[serde(default)]
    pub time_column: Option<String>,
    /// Rate of the dataset (Hz): the loads are low-passed, then resampled to it.
    pub dataset_rate_hz: f64,
}

/// The loads' zero-phase low-pass: a 4th-order Butterworth run forward and backward
/// ([`crate::sensor::filtfilt`]; −6 dB at the cut-off).
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LoadFilter {
    /// Cut-off (Hz); none: no filter (then the dataset rate must not alias the noise).
    #[serde(default)]
    pub cutoff_hz: Option<f64>,
}

/// The tare: every recording starts with the wing at rest at its home pose, and the sensor's
/// zero is set there.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Tare {
    /// Length of the rest at the start of each recording (s); 0: no tare.
    #[serde(default)]
    pub rest_s: f64,
    /// The home pose, as recorded (the recording's angle unit and convention).
    #[serde(default)]
    pub home_pose: [f64; 3],
    /// Largest distance (deg) of any angle from the home pose during the rest.
    #[serde(default = "default_tolerance_deg")]
    pub tolerance_deg: f64,
}

fn default_tolerance_deg() -> f64 {
    1.0
}

impl Default for Tare {
    fn default() -> Self {
        Self {
            rest_s: 0.0,
            home_pose: [0.0; 3],
            tolerance_deg: default_tolerance_deg(),
        }
    }
}

/// Mass properties of everything between the sensor and the fluid (wing, clamp, screws).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MassProperties {
    /// Mass (kg).
    pub mass_kg: f64,
    /// Volume displacing fluid (m³), for the buoyancy.
    pub volume_m3: f64,
    /// Centre of mass from the wing root on the pitch axis, wing axes (m).
    pub center_of_mass_m: [f64; 3],
    /// Centre of buoyancy (m); default the centre of mass.
    #[serde(default)]
    pub center_of_buoyancy_m: Option<[f64; 3]>,
    /// Inertia tensor about the centre of mass, wing axes (kg·m²): [I_xx, I_yy, I_zz, I_xy,
    /// I_xz, I_yz].
    pub inertia_kg_m2: [f64; 6],
}

/// Which rigid-body loads the processing subtracts (from `[mass]`, or identified from
/// `[reference]` runs).
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Subtract {
    /// The weight.
    #[serde(default)]
    pub gravity: bool,
    /// The buoyancy.
    #[serde(default)]
    pub buoyancy: bool,
    /// The inertial (d'Alembert) loads of the accelerated mass.
    #[serde(default)]
    pub inertia: bool,
}

impl Subtract {
    /// Whether anything is subtracted.
    pub fn any(&self) -> bool {
        self.gravity || self.buoyancy || self.inertia
    }
}

/// How a recording becomes trajectories: after the tare's rest, `skip_s` (the move from the
/// home pose to the motion) is dropped; the rest is one trajectory, or consecutive pieces of
/// `duration_s`.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Cutting {
    /// Seconds dropped after the rest.
    #[serde(default)]
    pub skip_s: f64,
    /// Length of each trajectory (s); none: the whole remainder.
    #[serde(default)]
    pub duration_s: Option<f64>,
}

impl RigDescription {
    /// The dataset's wing geometry: the rectangle, or the outline's equivalent one (the same
    /// span and area S = ∫(y_LE − y_TE) dz, so c̄ = S / span, and the pitch axis
    /// ∫y_LE dz / S of the chord behind its leading edge).
    pub fn geometry(&self) -> WingGeometry {
        let w = &self.wing;
        let (chord_m, pitch_axis_frac) = match &w.outline {
            Some(rows) => {
                let trapz = |f: &dyn Fn(&[f64; 3]) -> f64| -> f64 {
                    rows.windows(2)
                        .map(|p| 0.5 * (f(&p[0]) + f(&p[1])) * (p[1][0] - p[0][0]))
                        .sum()
                };
                let area = trapz(&|r| r[1] - r[2]);
                let le = trapz(&|r| r[1]);
                (area / w.span_m, le / area)
            }
            None => (w.chord_m.unwrap_or(0.0), w.pitch_axis_frac.unwrap_or(0.0)),
        };
        WingGeometry {
            span_m: w.span_m,
            chord_m,
            root_offset_m: w.root_offset_m,
            pitch_axis_frac,
            u_ref_radius_m: w.u_ref_radius_m.unwrap_or(w.root_offset_m + w.span_m),
        }
    }

    /// The rigid body of the `[mass]` section, if any.
    pub fn rigid_body(&self) -> Option<super::rigid_body::RigidBody> {
        self.mass.as_ref().map(|m| {
            super::rigid_body::RigidBody::new(m, self.fluid.density_kg_m3, self.wing.root_offset_m)
        })
    }

    /// The dataset's fluid.
    pub fn fluid(&self) -> Fluid {
        Fluid {
            density_kg_m3: self.fluid.density_kg_m3,
            kinematic_viscosity_m2_s: self.fluid.kinematic_viscosity_m2_s,
        }
    }

    /// Checks every field once.
    ///
    /// # Errors
    /// [`RigError::Field`] naming the first field out of range or inconsistent.
    pub fn check(&self) -> Result<(), RigError> {
        let w = &self.wing;
        let s = &self.sampling;
        in_range("wing.span_m", w.span_m, 1e-3, 10.0)?;
        in_range("wing.root_offset_m", w.root_offset_m, 0.0, 10.0)?;
        match (&w.outline, w.chord_m, w.pitch_axis_frac) {
            (None, Some(c), Some(f)) => {
                in_range("wing.chord_m", c, 1e-3, 10.0)?;
                in_range("wing.pitch_axis_frac", f, 0.0, 1.0)?;
            }
            (Some(rows), None, None) => check_outline(rows, w.span_m)?,
            _ => {
                return Err(RigError::field(
                    "wing",
                    "chord_m, pitch_axis_frac, outline",
                    "give chord_m and pitch_axis_frac (a rectangle) or an outline, not both",
                ));
            }
        }
        let g = self.geometry();
        in_range("wing.outline (mean chord)", g.chord_m, 1e-3, 10.0)?;
        in_range("wing.outline (pitch axis)", g.pitch_axis_frac, 0.0, 1.0)?;
        if let Some(r) = w.u_ref_radius_m {
            in_range("wing.u_ref_radius_m", r, 1e-3, 20.0)?;
        }
        in_range(
            "fluid.density_kg_m3",
            self.fluid.density_kg_m3,
            0.01,
            30_000.0,
        )?;
        in_range(
            "fluid.kinematic_viscosity_m2_s",
            self.fluid.kinematic_viscosity_m2_s,
            1e-9,
            1.0,
        )?;
        self.angles.check()?;
        in_range("sampling.rate_hz", s.rate_hz, 1e-3, 1e7)?;
        in_range(
            "sampling.dataset_rate_hz",
            s.dataset_rate_hz,
            1e-3,
            s.rate_hz,
        )?;
        let p = &self.sensor;
        for (field, values) in [
            ("sensor.offset_m", &p.offset_m[..]),
            ("sensor.rotation_deg", &p.rotation_deg[..]),
        ] {
            if let Some(v) = values.iter().find(|v| !(v.is_finite() && v.abs() <= 360.0)) {
                return Err(RigError::field(
                    field,
                    v,
                    "must be finite, at most 360 in size",
                ));
            }
        }
        for (field, values) in [
            ("sensor.noise_sd", &p.noise_sd),
            ("sensor.bias_sd", &p.bias_sd),
        ] {
            if let Some(v) = values.iter().find(|v| !(v.is_finite() && **v >= 0.0)) {
                return Err(RigError::field(field, v, "must be finite and ≥ 0"));
            }
        }
        self.check_columns()?;
        if let Some(f) = self.filter.cutoff_hz {
            in_range("filter.cutoff_hz", f, 1e-6, 0.5 * s.dataset_rate_hz).map_err(|_| {
                RigError::field(
                    "filter.cutoff_hz",
                    f,
                    &format!(
                        "must be positive and below half the dataset rate ({} Hz), else the \
                         resampling aliases",
                        0.5 * s.dataset_rate_hz
                    ),
                )
            })?;
        }
        in_range("tare.rest_s", self.tare.rest_s, 0.0, 1e5)?;
        in_range("tare.tolerance_deg", self.tare.tolerance_deg, 1e-9, 180.0)?;
        if let Some(v) = self.tare.home_pose.iter().find(|v| !v.is_finite()) {
            return Err(RigError::field("tare.home_pose", v, "must be finite"));
        }
        in_range("trajectories.skip_s", self.trajectories.skip_s, 0.0, 1e6)?;
        if let Some(d) = self.trajectories.duration_s {
            in_range("trajectories.duration_s", d, 1e-6, 1e6)?;
        }
        if let Some(m) = &self.mass {
            m.check()?;
        }
        match &self.reference {
            Some(r) => self.check_reference(r)?,
            None if self.mass.is_none() && self.subtract.any() => {
                return Err(RigError::field(
                    "subtract",
                    format!("{:?}", self.subtract),
                    "subtracting gravity, buoyancy or inertia needs the [mass] section or \
                     [reference] runs",
                ));
            }
            None => {}
        }
        Ok(())
    }

    /// The reference runs against what they can identify.
    fn check_reference(&self, r: &Reference) -> Result<(), RigError> {
        if r.recordings.is_empty() {
            return Err(RigError::field(
                "reference.recordings",
                "[]",
                "name at least one recording",
            ));
        }
        if let Some(v) = r.volume_m3 {
            in_range("reference.volume_m3", v, 0.0, 10.0)?;
        }
        if let Some(v) = r
            .center_of_buoyancy_m
            .iter()
            .flatten()
            .find(|v| !(v.is_finite() && v.abs() <= 10.0))
        {
            return Err(RigError::field(
                "reference.center_of_buoyancy_m",
                v,
                "must be finite, within 10 m",
            ));
        }
        let s = &self.subtract;
        match r.medium {
            Medium::Air if s.buoyancy && r.volume_m3.is_none() => Err(RigError::field(
                "reference.volume_m3",
                "none",
                "a run in air gives no buoyancy: give the volume to subtract it",
            )),
            Medium::Fluid if s.gravity != s.buoyancy => Err(RigError::field(
                "subtract",
                format!("{s:?}"),
                "a run in the fluid identifies the weight and the buoyancy together: subtract \
                 both or neither",
            )),
            Medium::Fluid if s.inertia && self.mass.is_none() => Err(RigError::field(
                "subtract.inertia",
                "true",
                "a run in the fluid gives no inertia: give [mass] for it",
            )),
            _ => Ok(()),
        }
    }

    /// Every column named once, none empty.
    fn check_columns(&self) -> Result<(), RigError> {
        let named: Vec<(&str, &String)> = self
            .angles
            .columns
            .iter()
            .map(|c| ("angles.columns", c))
            .chain(self.sensor.columns.iter().map(|c| ("sensor.columns", c)))
            .chain(
                self.sampling
                    .time_column
                    .iter()
                    .map(|c| ("sampling.time_column", c)),
            )
            .collect();
        for (k, (field, name)) in named.iter().enumerate() {
            if name.trim().is_empty() {
                return Err(RigError::field(
                    field,
                    "\"\"",
                    "column names must not be empty",
                ));
            }
            if named[..k].iter().any(|(_, n)| n == name) {
                return Err(RigError::field(
                    field,
                    name,
                    "names a column that another channel already uses",
                ));
            }
        }
        Ok(())
    }
}

impl MassProperties {
    /// Checks the mass properties (fields prefixed `mass.`).
    pub fn check(&self) -> Result<(), RigError> {
        in_range("mass.mass_kg", self.mass_kg, 1e-9, 1e4)?;
        in_range("mass.volume_m3", self.volume_m3, 0.0, 10.0)?;
        let points = [
            ("mass.center_of_mass_m", Some(self.center_of_mass_m)),
            ("mass.center_of_buoyancy_m", self.center_of_buoyancy_m),
        ];
        for (field, p) in points {
            if let Some(v) = p
                .iter()
                .flatten()
                .find(|v| !(v.is_finite() && v.abs() <= 10.0))
            {
                return Err(RigError::field(field, v, "must be finite, within 10 m"));
            }
        }
        let [ixx, iyy, izz, ..] = self.inertia_kg_m2;
        let i = &self.inertia_kg_m2;
        let physical = i.iter().all(|v| v.is_finite())
            && ixx >= 0.0
            && iyy >= 0.0
            && izz >= 0.0
            // The triangle inequalities, to rounding (a thin plate meets one with equality).
            && (ixx + iyy) * (1.0 + 1e-9) >= izz
            && (iyy + izz) * (1.0 + 1e-9) >= ixx
            && (izz + ixx) * (1.0 + 1e-9) >= iyy;
        if !physical {
            return Err(RigError::field(
                "mass.inertia_kg_m2",
                format!("{i:?}"),
                "the principal moments must be ≥ 0 and each at most the sum of the other two",
            ));
        }
        Ok(())
    }
}

/// An outline's rows: at least two, z increasing from 0 to the span, the leading edge ahead of
/// the trailing edge.
fn check_outline(rows: &[[f64; 3]], span_m: f64) -> Result<(), RigError> {
    let field = "wing.outline";
    if rows.len() < 2 {
        return Err(RigError::field(
            field,
            rows.len(),
            "needs at least two rows [z, y_LE, y_TE]",
        ));
    }
    if let Some(v) = rows
        .iter()
        .flatten()
        .find(|v| !(v.is_finite() && v.abs() <= 10.0))
    {
        return Err(RigError::field(field, v, "must be finite, within 10 m"));
    }
    let (first, last) = (rows[0][0], rows[rows.len() - 1][0]);
    if first.abs() > 1e-9 * span_m || (last - span_m).abs() > 1e-9 * span_m {
        return Err(RigError::field(
            field,
            format!("z from {first} to {last}"),
            "must run from the root (z = 0) to the tip (z = span_m)",
        ));
    }
    if let Some(k) = rows.windows(2).position(|p| p[1][0] <= p[0][0]) {
        return Err(RigError::field(
            field,
            format!("row {}", k + 2),
            "z must increase",
        ));
    }
    if let Some(k) = rows.iter().position(|r| r[1] <= r[2]) {
        return Err(RigError::field(
            field,
            format!("row {}", k + 1),
            "the leading edge y_LE must be ahead of the trailing edge y_TE",
        ));
    }
    Ok(())
}

/// `value` finite and in [lo, hi], else a field error.
fn in_range(field: &str, value: f64, lo: f64, hi: f64) -> Result<(), RigError> {
    if value.is_finite() && value >= lo && value <= hi {
        Ok(())
    } else {
        Err(RigError::field(
            field,
            value,
            &format!("must be finite and within [{lo}, {hi}]"),
        ))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn wing(outline: Option<Vec<[f64; 3]>>) -> RigWing {
        RigWing {
            span_m: 0.1,
            chord_m: None,
            root_offset_m: 0.02,
            pitch_axis_frac: None,
            outline,
            u_ref_radius_m: None,
        }
    }

    fn geometry_of(w: RigWing) -> WingGeometry {
        with_wing(w).geometry()
    }

    fn with_wing(w: RigWing) -> RigDescription {
        let mut d: RigDescription = serde_json::from_value(serde_json::json!({
            "wing": {"span_m": 0.1, "chord_m": 0.03, "root_offset_m": 0.02, "pitch_axis_frac": 0.25},
            "fluid": {"density_kg_m3": 1000.0, "kinematic_viscosity_m2_s": 1e-6},
            "angles": {"columns": ["a", "b", "c"], "unit": "rad"},
            "sensor": {"columns": ["1", "2", "3", "4", "5", "6"], "force_unit": "N", "moment_unit": "N*mm"},
            "sampling": {"rate_hz": 100.0, "dataset_rate_hz": 25.0}
        }))
        .unwrap();
        d.wing = w;
        d
    }

    /// A rectangle given as an outline is the rectangle; a triangle (LE straight, TE swept)
    /// has half the area, c̄ = S / span, and its pitch axis at ∫y_LE dz / S.
    #[test]
    fn an_outline_gives_the_equivalent_rectangle() {
        let rect = geometry_of(wing(Some(vec![
            [0.0, 0.0075, -0.0225],
            [0.1, 0.0075, -0.0225],
        ])));
        assert!((rect.chord_m - 0.03).abs() < 1e-15 && (rect.pitch_axis_frac - 0.25).abs() < 1e-12);
        let tri = geometry_of(wing(Some(vec![[0.0, 0.01, -0.05], [0.1, 0.01, 0.0]])));
        // S = ½·0.1·(0.06 + 0.01) = 0.0035 m², c̄ = 0.035 m, ∫y_LE = 0.001 → 0.001/0.0035.
        assert!((tri.area_m2() - 0.0035).abs() < 1e-15);
        assert!((tri.chord_m - 0.035).abs() < 1e-15);
        assert!((tri.pitch_axis_frac - 0.001 / 0.0035).abs() < 1e-12);
        assert!(
            with_wing(wing(Some(vec![[0.0, 0.01, -0.05], [0.1, 0.01, 0.0]])))
                .check()
                .is_ok()
        );
    }

    /// Both a chord and an outline, an outline short of the tip or with the edges crossed:
    /// refused naming the field.
    #[test]
    fn bad_outlines_are_refused() {
        let field = |w: RigWing| match with_wing(w).check() {
            Err(RigError::Field { field, .. }) => field,
            other => panic!("{other:?}"),
        };
        let mut both = wing(Some(vec![[0.0, 0.01, -0.02], [0.1, 0.01, -0.02]]));
        both.chord_m = Some(0.03);
        assert_eq!(field(both), "wing");
        assert_eq!(
            field(wing(Some(vec![[0.0, 0.01, -0.02], [0.08, 0.01, -0.02]]))),
            "wing.outline"
        );
        assert_eq!(
            field(wing(Some(vec![[0.0, 0.01, -0.02], [0.1, -0.03, -0.02]]))),
            "wing.outline"
        );
        assert_eq!(field(wing(None)), "wing");
    }
}
