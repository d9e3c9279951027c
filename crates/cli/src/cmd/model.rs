//! `flapssm model …`: model files.

use std::path::PathBuf;

use anyhow::Context;
use clap::{Args, Subcommand};
use flapssm_prssm::published::import_published;

/// PR-SSM model files.
#[derive(Args)]
pub struct ModelArgs {
    #[command(subcommand)]
    command: ModelCommand,
}

#[derive(Subcommand)]
enum ModelCommand {
    /// Import the published model's parameters (.npz with param_* arrays) into a
    /// published-compat model file.
    ImportPublished {
        /// Input .npz file.
        file: PathBuf,
        /// Output model file (.json).
        #[arg(long)]
        out: PathBuf,
    },
}

/// Runs `flapssm model …`.
pub fn run(args: ModelArgs) -> anyhow::Result<()> {
    match args.command {
        ModelCommand::ImportPublished { file, out } => {
            flapssm_jobs::files::check_outputs(&[&out], &[&file])?;
            let model =
                import_published(&file).with_context(|| format!("importing {}", file.display()))?;
            model
                .save(&out)
                .with_context(|| format!("writing model {}", out.display()))?;
            let c = &model.config;
            println!(
                "{}: D_x {}, D_y {}, D_u {}, M {} ({:?}, published compat) -> {}",
                file.display(),
                c.n_state,
                c.n_output,
                c.n_input,
                c.n_inducing,
                c.kernel,
                out.display()
            );
            Ok(())
        }
    }
}
