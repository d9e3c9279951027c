//! Learning-rate schedules for Adam.
//!
//! The learning rate of optimizer step `t` (0-based, counted over the whole run) is
//! `η_t = η_0 · s(t)` with the schedule factor `s`:
//!
//! | schedule | `s(t)` |
//! |---|---|
//! | [`LrSchedule::Constant`] | `1` |
//! | [`LrSchedule::Step`] | `γ^⌊t / every⌋` |
//! | [`LrSchedule::Exponential`] | `γ^(t / T)`, so `s(T) = γ` at the last step `T` |
//! | [`LrSchedule::Cosine`] | `f + (1 − f) · ½ (1 + cos(π · min(t, T) / T))` |
//!
//! `T` is the total number of steps of the run (passed in, so a resumed run uses the same
//! schedule as an uninterrupted one).

use serde::{Deserialize, Serialize};

/// A learning-rate schedule (see the module docs for the formulas).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, Default)]
#[serde(tag = "kind", rename_all = "snake_case")]
#[non_exhaustive]
pub enum LrSchedule {
    /// `η_t = η_0`.
    #[default]
    Constant,
    /// Multiply by `factor` every `every` steps.
    Step {
        /// Steps between decays (≥ 1).
        every: u64,
        /// Decay factor γ in (0, 1].
        factor: f64,
    },
    /// Smooth exponential decay reaching `η_0 · final_factor` at the last step.
    Exponential {
        /// γ = `s(T)` in (0, 1].
        final_factor: f64,
    },
    /// Cosine annealing from `η_0` down to `η_0 · final_factor` at the last step.
    Cosine {
        /// f = `s(T)` in [0, 1].
        final_factor: f64,
    },
}

/// Why a schedule is invalid.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum ScheduleError {
    /// A schedule parameter is out of range.
    #[error("learning-rate schedule: {field} = {value} out of range {range}")]
    OutOfRange {
        /// Field name.
        field: &'static str,
        /// Offending value.
        value: f64,
        /// Allowed range, in words.
        range: &'static str,
    },
}

impl std::str::FromStr for LrSchedule {
    type Err = String;
    /// `constant`, `step:EVERY:FACTOR`, `exp:FINAL_FACTOR` or `cosine:FINAL_FACTOR` (the
    /// command line's and the bindings' spelling); ranges are [`LrSchedule::check`]'s.
    fn from_str(s: &str) -> Result<Self, String> {
        let parts: Vec<&str> = s.split(':').collect();
        let field = |i: usize| -> Result<&str, String> {
            parts
                .get(i)
                .copied()
                .ok_or_else(|| format!("schedule {s:?}: missing field {i}"))
        };
        let num = |i: usize| -> Result<f64, String> {
            field(i)?
                .parse::<f64>()
                .map_err(|_| format!("schedule {s:?}: field {i} is not a number"))
        };
        let (schedule, fields) = match parts[0] {
            "constant" => (LrSchedule::Constant, 1),
            "step" => {
                let every = field(1)?
                    .parse::<u64>()
                    .map_err(|_| format!("schedule {s:?}: EVERY is not a whole number"))?;
                let factor = num(2)?;
                (LrSchedule::Step { every, factor }, 3)
            }
            "exp" => (
                LrSchedule::Exponential {
                    final_factor: num(1)?,
                },
                2,
            ),
            "cosine" => (
                LrSchedule::Cosine {
                    final_factor: num(1)?,
                },
                2,
            ),
            other => {
                return Err(format!(
                    "unknown schedule {other:?} (expected constant, step:EVERY:FACTOR, \
                     exp:FINAL_FACTOR or cosine:FINAL_FACTOR)"
                ));
            }
        };
        if parts.len() != fields {
            return Err(format!(
                "schedule {s:?}: {} fields, expected {fields}",
                parts.len()
            ));
        }
        Ok(schedule)
    }
}

impl LrSchedule {
    /// Checks the parameters.
    ///
    /// # Errors
    /// [`ScheduleError::OutOfRange`] naming the field.
    pub fn check(&self) -> Result<(), ScheduleError> {
        let bad = |field, value, range| {
            Err(ScheduleError::OutOfRange {
                field,
                value,
                range,
            })
        };
        match *self {
            LrSchedule::Constant => Ok(()),
            LrSchedule::Step { every, factor } => {
                if every == 0 {
                    bad("every", 0.0, ">= 1")
                } else if !(factor > 0.0 && factor <= 1.0) {
                    bad("factor", factor, "(0, 1]")
                } else {
                    Ok(())
                }
            }
            LrSchedule::Exponential { final_factor } => {
                if !(final_factor > 0.0 && final_factor <= 1.0) {
                    bad("final_factor", final_factor, "(0, 1]")
                } else {
                    Ok(())
                }
            }
            LrSchedule::Cosine { final_factor } => {
                if !(0.0..=1.0).contains(&final_factor) {
                    bad("final_factor", final_factor, "[0, 1]")
                } else {
                    Ok(())
                }
            }
        }
    }

    /// Schedule factor `s(t)` of step `step` in a run of `total_steps` steps.
    pub fn factor(&self, step: u64, total_steps: u64) -> f64 {
        let horizon = total_steps.saturating_sub(1).max(1) as f64;
        let frac = (step as f64 / horizon).min(1.0);
        match *self {
            LrSchedule::Constant => 1.0,
            LrSchedule::Step { every, factor } => factor.powf((step / every.max(1)) as f64),
            LrSchedule::Exponential { final_factor } => final_factor.powf(frac),
            LrSchedule::Cosine { final_factor } => {
                final_factor
                    + (1.0 - final_factor) * 0.5 * (1.0 + (std::f64::consts::PI * frac).cos())
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn schedules_parse_as_the_command_line_spells_them() {
        assert_eq!("constant".parse(), Ok(LrSchedule::Constant));
        assert_eq!(
            "step:100:0.5".parse(),
            Ok(LrSchedule::Step {
                every: 100,
                factor: 0.5
            })
        );
        assert_eq!(
            "exp:0.1".parse(),
            Ok(LrSchedule::Exponential { final_factor: 0.1 })
        );
        assert_eq!(
            "cosine:0.1".parse(),
            Ok(LrSchedule::Cosine { final_factor: 0.1 })
        );
        for (bad, says) in [
            ("linear", "unknown schedule"),
            ("step:10", "missing field 2"),
            ("step:1.5:0.5", "EVERY"),
            ("cosine:x", "not a number"),
            ("cosine:0.1:2", "3 fields, expected 2"),
        ] {
            let e = bad.parse::<LrSchedule>().unwrap_err();
            assert!(e.contains(says), "{bad}: {e}");
        }
    }

    #[test]
    fn schedules_hit_their_defining_values() {
        let t = 101;
        assert_eq!(LrSchedule::Constant.factor(57, t), 1.0);
        let step = LrSchedule::Step {
            every: 10,
            factor: 0.5,
        };
        assert_eq!(step.factor(9, t), 1.0);
        assert_eq!(step.factor(10, t), 0.5);
        assert_eq!(step.factor(35, t), 0.125);
        let exp = LrSchedule::Exponential { final_factor: 0.01 };
        assert_eq!(exp.factor(0, t), 1.0);
        assert!((exp.factor(50, t) - 0.1).abs() < 1e-12);
        assert!((exp.factor(100, t) - 0.01).abs() < 1e-12);
        let cos = LrSchedule::Cosine { final_factor: 0.1 };
        assert_eq!(cos.factor(0, t), 1.0);
        assert!((cos.factor(50, t) - 0.55).abs() < 1e-12);
        assert!((cos.factor(100, t) - 0.1).abs() < 1e-12);
        assert!((cos.factor(500, t) - 0.1).abs() < 1e-12);
    }

    #[test]
    fn invalid_parameters_are_named() {
        let e = LrSchedule::Step {
            every: 0,
            factor: 0.5,
        }
        .check()
        .unwrap_err();
        assert!(e.to_string().contains("every"));
        let e = LrSchedule::Cosine { final_factor: 2.0 }
            .check()
            .unwrap_err();
        assert!(e.to_string().contains("final_factor"));
        assert!(
            LrSchedule::Exponential { final_factor: 0.0 }
                .check()
                .is_err()
        );
    }
}
