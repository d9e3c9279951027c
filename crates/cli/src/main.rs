//! `flapssm` — command-line front end. Parses arguments, calls one library function per
//! subcommand, reports, and maps errors to a nonzero exit code. No numerics live here.

use clap::{Parser, Subcommand};

mod cmd;

/// Compact probabilistic state-space models of flapping-wing aerodynamics.
#[derive(Parser)]
#[command(name = "flapssm", version, about, long_about = None)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Print the version and build configuration.
    Version,
}

fn main() {
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Version => cmd::version(),
    };
    if let Err(err) = result {
        eprintln!("error: {err:#}");
        std::process::exit(1);
    }
}
