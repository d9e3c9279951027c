//! `flapssm dataset …`: inspect, export and import dataset files.

use std::path::{Path, PathBuf};

use anyhow::{Context, bail};
use clap::{Args, Subcommand};
use flapssm_jobs::files::check_outputs;
use flapssm_wing::cycles::{U_REF_RADIUS_M, published_u_ref};
use flapssm_wing::dataset::Dataset;
use flapssm_wing::dataset::published::import_published_mat;

/// Dataset files: inspect, export to CSV, import from MAT or CSV.
#[derive(Args)]
pub struct DatasetArgs {
    #[command(subcommand)]
    command: DatasetCommand,
}

#[derive(Subcommand)]
enum DatasetCommand {
    /// Print counts, split, families, per-column ranges, dt and metadata of a dataset file.
    Info {
        /// Dataset file (.npz).
        file: PathBuf,
    },
    /// Export a dataset file to long-format CSV (one row per sample).
    Export {
        /// Dataset file (.npz).
        file: PathBuf,
        /// Output CSV file.
        #[arg(long)]
        csv: PathBuf,
    },
    /// Import a dataset from the published MAT layout (ds_pos, ds_u_raw, ds_y_raw) or a CSV.
    Import {
        /// MAT file in the published layout.
        #[arg(long, conflicts_with = "csv", required_unless_present = "csv")]
        mat: Option<PathBuf>,
        /// Long-format CSV written by `flapssm dataset export`.
        #[arg(long)]
        csv: Option<PathBuf>,
        /// Output dataset file (.npz).
        #[arg(long)]
        out: PathBuf,
        /// Training trajectories (the first K) for --mat; default 512 as published.
        #[arg(long, value_name = "K", conflicts_with = "csv")]
        n_train: Option<usize>,
    },
}

/// Runs a `flapssm dataset` subcommand.
pub fn run(args: DatasetArgs) -> anyhow::Result<()> {
    match args.command {
        DatasetCommand::Info { file } => {
            let ds = Dataset::load(&file)
                .with_context(|| format!("reading dataset {}", file.display()))?;
            println!("{}", file.display());
            println!("{}", ds.summary());
        }
        DatasetCommand::Export { file, csv } => {
            check_outputs(&[&csv], &[&file])?;
            let ds = Dataset::load(&file)
                .with_context(|| format!("reading dataset {}", file.display()))?;
            ds.export_csv(&csv)
                .with_context(|| format!("writing CSV {}", csv.display()))?;
            println!(
                "wrote {} ({} trajectories × {} samples)",
                csv.display(),
                ds.len(),
                ds.n_samples()
            );
        }
        DatasetCommand::Import {
            mat,
            csv,
            out,
            n_train,
        } => {
            let inputs: Vec<&Path> = mat.iter().chain(&csv).map(PathBuf::as_path).collect();
            check_outputs(&[&out], &inputs)?;
            let ds = match (mat, csv) {
                (Some(mat), None) => import_published_mat(&mat, n_train, |euler, dt_s| {
                    published_u_ref(euler, dt_s, U_REF_RADIUS_M)
                        .map(|(u_ref, _)| u_ref)
                        .map_err(|e| e.to_string())
                })
                .with_context(|| format!("importing MAT file {}", mat.display()))?,
                (None, Some(csv)) => Dataset::import_csv(&csv)
                    .with_context(|| format!("importing CSV file {}", csv.display()))?,
                _ => bail!("give exactly one of --mat FILE or --csv FILE"),
            };
            ds.save(&out)
                .with_context(|| format!("writing dataset {}", out.display()))?;
            println!(
                "wrote {} ({} trajectories × {} samples, {} train)",
                out.display(),
                ds.len(),
                ds.n_samples(),
                ds.n_train
            );
        }
    }
    Ok(())
}
