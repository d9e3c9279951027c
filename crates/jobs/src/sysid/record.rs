//! The recorded input/output table of one system: columns chosen by name or index.

use std::path::Path;

use flapssm_data::table::{Column, Table, TableError};
use flapssm_prssm::SequenceView;

use super::SysidError;

/// Input/output columns of a recorded table, row-major.
#[derive(Debug, Clone, PartialEq)]
pub struct IoRecord {
    /// Input column names.
    pub input_names: Vec<String>,
    /// Output column names.
    pub output_names: Vec<String>,
    /// Inputs `u`, row-major `T × D_u`.
    pub inputs: Vec<f64>,
    /// Outputs `y`, row-major `T × D_y`.
    pub outputs: Vec<f64>,
}

impl IoRecord {
    /// Samples `T`.
    pub fn n_samples(&self) -> usize {
        self.outputs.len() / self.output_names.len().max(1)
    }

    /// Reads `path` ([`Table::read`] by extension; for `.mat`, only the named variables when
    /// every column is given by name) and selects the input and output columns.
    ///
    /// # Errors
    /// [`SysidError::Table`] for unreadable files and unknown columns (listing the available
    /// ones), [`SysidError::Setting`] when no input or output is selected.
    pub fn read(path: &Path, inputs: &[Column], outputs: &[Column]) -> Result<Self, SysidError> {
        if inputs.is_empty() || outputs.is_empty() {
            return Err(SysidError::Setting {
                field: if inputs.is_empty() { "input" } else { "output" },
                value: "none".into(),
                why: "select at least one column".into(),
            });
        }
        let is_mat = path
            .extension()
            .and_then(|e| e.to_str())
            .is_some_and(|e| e.eq_ignore_ascii_case("mat"));
        let names: Option<Vec<&str>> = inputs
            .iter()
            .chain(outputs)
            .map(|c| match c {
                Column::Name(n) => Some(n.as_str()),
                Column::Index(_) => None,
            })
            .collect();
        let table = match (is_mat, names) {
            (true, Some(n)) => {
                let mut uniq: Vec<&str> = Vec::new();
                for v in n {
                    if !uniq.contains(&v) {
                        uniq.push(v);
                    }
                }
                Table::read_mat(path, &uniq)?
            }
            _ => Table::read(path)?,
        };
        Ok(Self::from_table(&table, inputs, outputs)?)
    }

    /// Selects the input and output columns of `table`.
    ///
    /// # Errors
    /// [`TableError::UnknownColumn`].
    pub fn from_table(
        table: &Table,
        inputs: &[Column],
        outputs: &[Column],
    ) -> Result<Self, TableError> {
        let u = table.select(inputs)?;
        let y = table.select(outputs)?;
        let interleave = |t: &Table| -> Vec<f64> {
            (0..t.n_rows())
                .flat_map(|i| t.columns.iter().map(move |c| c[i]))
                .collect()
        };
        Ok(Self {
            inputs: interleave(&u),
            outputs: interleave(&y),
            input_names: u.names,
            output_names: y.names,
        })
    }

    /// The first `n` samples (all when `n ≥ T`), e.g. the training part for a validation split.
    pub fn head(&self, n: usize) -> IoRecord {
        let n = n.min(self.n_samples());
        let (du, dy) = (self.input_names.len(), self.output_names.len());
        IoRecord {
            input_names: self.input_names.clone(),
            output_names: self.output_names.clone(),
            inputs: self.inputs[..n * du].to_vec(),
            outputs: self.outputs[..n * dy].to_vec(),
        }
    }

    /// The samples `range` as a raw PR-SSM sequence (a view, no copy).
    pub(super) fn sequence(&self, range: std::ops::Range<usize>) -> SequenceView<'_> {
        let (du, dy) = (self.input_names.len(), self.output_names.len());
        SequenceView {
            inputs: &self.inputs[range.start * du..range.end * du],
            outputs: &self.outputs[range.start * dy..range.end * dy],
        }
    }
}
