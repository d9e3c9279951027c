//! Fits on custom feature columns of a table (`flapssm qs fit-csv`), read with
//! [`flapssm_data::table::Table`].

use std::path::Path;

use flapssm_data::table::{Table, TableError};
use flapssm_wing::features::FeatureSet;

use crate::cv::{Columns, EnetOptions, fit_enet_cv};
use crate::error::QsError;
use crate::model::LrqsmModel;

/// Reads a CSV table (header line of names, then numbers), naming the column of a field that
/// is not a finite number.
///
/// # Errors
/// [`QsError::CsvValue`] for a NaN/inf/non-numeric field, else [`QsError::Table`].
pub fn read_csv(path: &Path) -> Result<Table, QsError> {
    Table::read_csv(path).map_err(|e| match e {
        TableError::Number {
            path,
            line,
            column,
            text,
        } => QsError::CsvValue {
            column: header_name(&path, column).unwrap_or_else(|| format!("#{column}")),
            path,
            line,
            text,
        },
        e => QsError::Table(e),
    })
}

/// Name of 1-based column `column` in the header line of a CSV file (for messages).
fn header_name(path: &Path, column: usize) -> Option<String> {
    let text = std::fs::read_to_string(path).ok()?;
    let header = text.lines().find(|l| {
        let t = l.trim();
        !t.is_empty() && !t.starts_with('#') && !t.starts_with('%')
    })?;
    header
        .split(',')
        .nth(column.checked_sub(1)?)
        .map(|s| s.trim().trim_matches('"').to_string())
}

/// Row-major block of the named columns.
fn select(table: &Table, names: &[String], kind: &'static str) -> Result<Vec<f64>, QsError> {
    let cols = names
        .iter()
        .map(|n| {
            table
                .names
                .iter()
                .position(|c| c == n)
                .map(|j| &table.columns[j])
                .ok_or_else(|| QsError::UnknownColumn {
                    file: table.source.display().to_string(),
                    kind,
                    name: n.clone(),
                    available: table.names.join(", "),
                })
        })
        .collect::<Result<Vec<_>, _>>()?;
    Ok((0..table.n_rows())
        .flat_map(|i| cols.iter().map(move |c| c[i]))
        .collect())
}

/// Fits an LRQSM on table columns: `targets` as given (no rescaling) on `features` (default:
/// every other column). If the features are exactly the 11 published (or 10 paper-text)
/// feature names, the model records that feature set.
///
/// # Errors
/// Unknown column names (listing the available ones), a column both target and feature, and
/// every error of [`fit_enet_cv`].
pub fn fit_table(
    table: &Table,
    targets: &[String],
    features: Option<&[String]>,
    opts: &EnetOptions,
) -> Result<LrqsmModel, QsError> {
    if targets.is_empty() {
        return Err(QsError::InvalidOption {
            name: "targets",
            value: String::new(),
            reason: format!(
                "name at least one of the columns {}",
                table.names.join(", ")
            ),
        });
    }
    let y = select(table, targets, "target")?;
    let features: Vec<String> = match features {
        Some(f) => f.to_vec(),
        None => table
            .names
            .iter()
            .filter(|n| !targets.contains(n))
            .cloned()
            .collect(),
    };
    if let Some(both) = features.iter().find(|f| targets.contains(f)) {
        return Err(QsError::InvalidOption {
            name: "features",
            value: both.clone(),
            reason: "a column cannot be both a feature and a target".into(),
        });
    }
    let x = select(table, &features, "feature")?;
    let fit = fit_enet_cv(
        Columns {
            names: &features,
            data: &x,
        },
        Columns {
            names: targets,
            data: &y,
        },
        opts,
    )?;
    let set = [FeatureSet::Published, FeatureSet::PaperText]
        .into_iter()
        .find(|s| s.names().iter().eq(features.iter()));
    Ok(LrqsmModel::new(
        fit,
        *opts,
        set,
        None,
        table.source.display().to_string(),
    ))
}
