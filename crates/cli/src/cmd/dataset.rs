//! `flapssm dataset …`: inspect, export and import dataset files.

use std::path::{Path, PathBuf};

use anyhow::{Context, bail};
use clap::{Args, Subcommand};
use std::time::Instant;

use flapssm_jobs::files::{check_output_dir, check_outputs};
use flapssm_jobs::own_rig::{
    RIG_TEMPLATE, build_dataset, load_rig, reference_files, steps_file_names, write_steps,
};
use flapssm_wing::cycles::{U_REF_RADIUS_M, published_u_ref};
use flapssm_wing::dataset::Dataset;
use flapssm_wing::dataset::ValidDataset;
use flapssm_wing::dataset::published::import_published_mat;
use flapssm_wing::rig::Medium;

use crate::progress::Bars;

/// Dataset files: inspect, export to CSV, import from MAT or CSV, build from a rig's raw
/// recordings.
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
        /// For --mat: the rig description (TOML) whose wing, fluid and U_ref radius the
        /// dataset takes; without it, the paper's wing in oil, said on the screen.
        #[arg(long, value_name = "FILE", conflicts_with = "csv")]
        rig: Option<PathBuf>,
    },
    /// Write a documented rig description to start from (docs/own-rig.md).
    RigTemplate {
        /// Output file (.toml).
        #[arg(long)]
        out: PathBuf,
    },
    /// Build a dataset from a rig's raw recordings (angles and six sensor channels; CSV, text
    /// or MAT), processed as its rig description says: tare, sensor frame, subtraction of
    /// gravity, buoyancy and inertia, low-pass, resampling, cutting (docs/own-rig.md).
    Build {
        /// The rig description (TOML; `flapssm dataset rig-template` writes one).
        #[arg(long, value_name = "FILE")]
        rig: PathBuf,
        /// Output dataset file (.npz).
        #[arg(long)]
        out: PathBuf,
        /// Training trajectories (the first K, in the order of the files); default the
        /// published share (512 of 548).
        #[arg(long, value_name = "K")]
        n_train: Option<usize>,
        /// Also write here, per recording, the loads after each processing step (CSV) and
        /// their figure (PNG).
        #[arg(long, value_name = "DIR")]
        steps: Option<PathBuf>,
        /// The raw recordings, one or more trajectories each.
        #[arg(required = true, value_name = "RECORDING")]
        recordings: Vec<PathBuf>,
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
            rig,
        } => {
            let inputs: Vec<&Path> = mat
                .iter()
                .chain(&csv)
                .chain(&rig)
                .map(PathBuf::as_path)
                .collect();
            check_outputs(&[&out], &inputs)?;
            let ds = match (mat, csv) {
                (Some(mat), None) => import_mat(&mat, n_train, rig.as_deref())?,
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
        DatasetCommand::RigTemplate { out } => {
            check_outputs(&[&out], &[])?;
            flapssm_jobs::files::save_text(&out, RIG_TEMPLATE)?;
            println!(
                "wrote {}: a rig description to edit (docs/own-rig.md)",
                out.display()
            );
        }
        DatasetCommand::Build {
            rig,
            out,
            n_train,
            steps,
            recordings,
        } => build(&rig, &out, n_train, steps.as_deref(), &recordings)?,
    }
    Ok(())
}

/// `flapssm dataset import --mat`: the published layout, with the rig's wing and fluid if given.
fn import_mat(
    mat: &Path,
    n_train: Option<usize>,
    rig: Option<&Path>,
) -> anyhow::Result<ValidDataset> {
    let desc = rig.map(load_rig).transpose()?;
    let radius = desc
        .as_ref()
        .map_or(U_REF_RADIUS_M, |d| d.geometry().u_ref_radius_m);
    let mut ds = import_published_mat(mat, n_train, |euler, dt_s| {
        published_u_ref(euler, dt_s, radius)
            .map(|(u_ref, _)| u_ref)
            .map_err(|e| e.to_string())
    })
    .with_context(|| format!("importing MAT file {}", mat.display()))?
    .into_inner();
    match &desc {
        Some(d) => {
            ds.meta.wing = d.geometry();
            ds.meta.fluid = d.fluid();
        }
        None => println!(
            "note: no --rig given: the dataset takes the paper's wing ({} × {} m, U_ref at {} m) \
             in its oil (ρ = {} kg/m³), which its coefficients use",
            ds.meta.wing.span_m,
            ds.meta.wing.chord_m,
            ds.meta.wing.u_ref_radius_m,
            ds.meta.fluid.density_kg_m3
        ),
    }
    Ok(ValidDataset::new(ds)?)
}

/// `flapssm dataset build`.
fn build(
    rig: &Path,
    out: &Path,
    n_train: Option<usize>,
    steps: Option<&Path>,
    recordings: &[PathBuf],
) -> anyhow::Result<()> {
    let start = Instant::now();
    let desc = load_rig(rig)?;
    let references = reference_files(&desc, rig);
    let mut inputs: Vec<&Path> = recordings.iter().map(PathBuf::as_path).collect();
    inputs.push(rig);
    inputs.extend(references.iter().map(PathBuf::as_path));
    check_outputs(&[out], &inputs)?;
    if let Some(dir) = steps {
        let names: Vec<String> = recordings
            .iter()
            .flat_map(|p| steps_file_names(p))
            .collect();
        let names: Vec<&str> = names.iter().map(String::as_str).collect();
        check_output_dir(dir, &names, &inputs)?;
    }
    let bars = Bars::new();
    let built = build_dataset(&desc, rig, recordings, n_train, &bars)?;
    drop(bars);
    if let Some(found) = &built.identified {
        let s = &found.static_parameters;
        let c = s.first_moment_kg_m.map(|h| 1e3 * h / s.mass_kg);
        println!(
            "identified from {} reference samples ({:?}): {} {:.6} kg at ({:.2}, {:.2}, {:.2}) mm from \
             the root; fit residual {:.2e} N, {:.2e} N·m (RMS)",
            found.n_samples,
            found.medium,
            match found.medium {
                Medium::Air => "mass",
                Medium::Fluid => "weight less buoyancy",
            },
            s.mass_kg,
            c[0],
            c[1],
            c[2],
            found.residual_rms[..3].iter().cloned().fold(0.0, f64::max),
            found.residual_rms[3..].iter().cloned().fold(0.0, f64::max),
        );
    }
    if let Some(dir) = steps {
        write_steps(dir, &desc, recordings, &built.processed)?;
    }
    built
        .dataset
        .save(out)
        .with_context(|| format!("writing dataset {}", out.display()))?;
    for r in &built.reports {
        let residual = r
            .rest_residual
            .map(|v| {
                format!(
                    "{:.2e} {:.2e} N, {:.2e} {:.2e} {:.2e} N·mm",
                    v[0], v[1], v[2], v[3], v[4]
                )
            })
            .unwrap_or_else(|| "no tare".into());
        println!(
            "{}: {} trajectories; rest moved {:.3}°, residual at rest {residual}",
            r.source_name,
            r.n_trajectories,
            r.rest_motion_deg.unwrap_or(0.0),
        );
    }
    let ds = &built.dataset;
    println!(
        "wrote {} ({} trajectories × {} samples at {} Hz, {} train; wing {} × {} m in ρ = {} kg/m³) in {:.2} s",
        out.display(),
        ds.len(),
        ds.n_samples(),
        desc.sampling.dataset_rate_hz,
        ds.n_train,
        ds.meta.wing.span_m,
        ds.meta.wing.chord_m,
        ds.meta.fluid.density_kg_m3,
        start.elapsed().as_secs_f64()
    );
    Ok(())
}
