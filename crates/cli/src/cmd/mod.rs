//! One module per subcommand group.

pub mod bench;
pub mod dataset;
pub mod demo;
pub mod evaluate;
pub mod model;
pub mod predict;
pub mod qs;
pub mod simulate;
pub mod sweep;
pub mod sysid;
pub mod train;
pub mod trajectories;

/// `flapssm version`.
pub fn version() -> anyhow::Result<()> {
    println!("flapssm {}", env!("CARGO_PKG_VERSION"));
    Ok(())
}
