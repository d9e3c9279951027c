//! One module per subcommand group.

/// `flapssm version`.
pub fn version() -> anyhow::Result<()> {
    println!("flapssm {}", env!("CARGO_PKG_VERSION"));
    Ok(())
}
