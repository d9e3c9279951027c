//! The adapters between the project's datasets and the generic engine: a trajectory as the
//! engine's sequence, a model in a dataset's units, a table's columns as a model's inputs, and
//! what a model's initial-state rule needs beyond the inputs. Prediction, streaming, training and
//! the load models all use them; none of those modules imports another for them.

use flapssm_prssm::PrssmModel;
use flapssm_prssm::SequenceView;
use flapssm_prssm::train::InitialStateSpec;
use flapssm_wing::dataset::{Trajectory, ValidDataset};

use crate::error::{JobError, Result};

/// The raw PR-SSM sequence of a trajectory, a view of its own arrays (7 inputs, 5 outputs,
/// row-major; outputs empty for kinematics-only trajectories).
pub fn trajectory_sequence(t: &Trajectory) -> SequenceView<'_> {
    SequenceView {
        inputs: t.inputs.as_flattened(),
        outputs: t.outputs.as_deref().map_or(&[], <[[f64; 5]]>::as_flattened),
    }
}

/// The model as it applies to `ds`'s physical units: unchanged when it carries normalization
/// statistics; otherwise (a model trained in standardized units, e.g. the published one) a copy
/// that standardizes with `ds`'s training statistics, as the published post-processing did.
///
/// # Errors
/// [`JobError::Mismatch`] when the model has no statistics and `ds` has no outputs to
/// compute them from.
pub fn in_dataset_units<'m>(
    model: &'m PrssmModel,
    ds: &ValidDataset,
) -> Result<std::borrow::Cow<'m, PrssmModel>> {
    if model.normalization.is_some() {
        return Ok(std::borrow::Cow::Borrowed(model));
    }
    if !ds.has_outputs() {
        return Err(JobError::Mismatch {
            what: "PR-SSM model without normalization statistics".into(),
            expected: "a dataset with outputs to standardize with".into(),
            found: "a dataset with no outputs".into(),
        });
    }
    let s = ds.standardization()?;
    let mut m = model.clone();
    m.normalization = Some(flapssm_prssm::Normalization {
        input_mean: s.mean_u.to_vec(),
        input_std: s.std_u.to_vec(),
        output_mean: s.mean_y.to_vec(),
        output_std: s.std_y.to_vec(),
    });
    Ok(std::borrow::Cow::Owned(m))
}

/// Which column of a table feeds each of a model's `n_input` inputs, from the table's header
/// `names`: for a 7-input model whose header names the wing inputs
/// ([`flapssm_wing::dataset::INPUT_NAMES`]) in any order, by name; for a header that names none
/// of them (a model of other inputs), by position.
///
/// # Errors
/// [`JobError::Mismatch`] for another column count, or a header naming some wing inputs but
/// not all (a renamed or missing column would otherwise be used in another one's place).
pub fn input_columns(names: &[String], n_input: usize) -> Result<Vec<usize>> {
    use flapssm_wing::dataset::INPUT_NAMES;
    if names.len() != n_input {
        return Err(JobError::Mismatch {
            what: "input columns".into(),
            expected: format!("the model's D_u = {n_input} inputs"),
            found: format!("{} columns", names.len()),
        });
    }
    let position = |wanted: &str| names.iter().position(|n| n.trim() == wanted);
    let named: Vec<Option<usize>> = INPUT_NAMES.iter().map(|w| position(w)).collect();
    if named.iter().all(Option::is_none) {
        return Ok((0..n_input).collect());
    }
    if n_input == INPUT_NAMES.len() && named.iter().all(Option::is_some) {
        return Ok(named.into_iter().flatten().collect());
    }
    let missing: Vec<&str> = INPUT_NAMES
        .iter()
        .zip(&named)
        .filter(|(_, p)| p.is_none())
        .map(|(n, _)| *n)
        .collect();
    Err(JobError::Mismatch {
        what: "input columns".into(),
        expected: format!("all of the wing inputs {}", INPUT_NAMES.join(",")),
        found: format!("{} (missing {})", names.join(","), missing.join(",")),
    })
}

/// Why a model's initial-state rule cannot be applied from inputs alone, if it cannot.
pub fn inputs_only_notes(model: &PrssmModel) -> Vec<String> {
    let rule = match model.initial_state_rule().spec {
        InitialStateSpec::Zeros => return Vec::new(),
        InitialStateSpec::Outputs => "outputs",
        _ => "recognition",
    };
    vec![format!(
        "the model was trained with the '{rule}' initial-state rule, which needs the first \
         outputs; inputs alone are predicted from x_0 = 0 (predict a dataset to apply it)"
    )]
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Regression: reordered or renamed columns were used by position.
    #[test]
    fn input_columns_are_matched_by_name() {
        let names = |s: &str| s.split(',').map(String::from).collect::<Vec<_>>();
        let wing = "aoa,speed,a_x,a_y,a_z,pitch_rate,pitch_acc";
        assert_eq!(
            input_columns(&names(wing), 7).unwrap(),
            [0, 1, 2, 3, 4, 5, 6]
        );
        let reversed = "pitch_acc,pitch_rate,a_z,a_y,a_x,speed,aoa";
        assert_eq!(
            input_columns(&names(reversed), 7).unwrap(),
            [6, 5, 4, 3, 2, 1, 0]
        );
        let renamed = "AoA,speed,a_x,a_y,a_z,pitch_rate,pitch_acc";
        let e = input_columns(&names(renamed), 7).unwrap_err().to_string();
        assert!(e.contains("missing aoa"), "{e}");
        assert_eq!(input_columns(&names("u,v"), 2).unwrap(), [0, 1]);
        let e = input_columns(&names("u,v,w"), 2).unwrap_err().to_string();
        assert!(e.contains("3 columns"), "{e}");
    }
}
