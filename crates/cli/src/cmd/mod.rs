//! One module per subcommand group.

pub mod bench;
pub mod choices;
pub mod dataset;
pub mod demo;
pub mod design;
pub mod evaluate;
pub mod history;
pub mod model;
pub mod predict;
pub mod qs;
pub mod rig;
pub mod simulate;
pub mod stream;
pub mod sweep;
pub mod sysid;
pub mod train;
pub mod trajectories;

/// Parses a count that must be at least 1 (particles, epochs, batch size, …).
pub fn positive<T: std::str::FromStr + PartialOrd + From<u8>>(s: &str) -> Result<T, String> {
    match s.parse::<T>() {
        Ok(v) if v >= T::from(1) => Ok(v),
        _ => Err(format!("'{s}' is not a whole number >= 1")),
    }
}

/// The error and its causes joined by ": ", skipping a cause whose text the message already
/// holds (many library errors repeat their source, e.g. `file: No such file (os error 2)`).
pub fn error_message(err: &anyhow::Error) -> String {
    let mut out = String::new();
    for cause in err.chain() {
        let text = cause.to_string();
        if out.is_empty() {
            out = text;
        } else if !out.contains(&text) {
            out.push_str(": ");
            out.push_str(&text);
        }
    }
    out
}

/// `flapssm version`.
pub fn version() -> anyhow::Result<()> {
    println!("flapssm {}", env!("CARGO_PKG_VERSION"));
    Ok(())
}

#[cfg(test)]
mod tests {
    use anyhow::Context;

    #[test]
    fn error_message_drops_repeated_causes_and_keeps_new_ones() {
        let io = std::io::Error::new(std::io::ErrorKind::NotFound, "no such file");
        let err = Err::<(), _>(io)
            .context("d.npz: no such file")
            .context("reading dataset d.npz")
            .unwrap_err();
        assert_eq!(
            super::error_message(&err),
            "reading dataset d.npz: d.npz: no such file"
        );
        let err = anyhow::anyhow!("line 3: bad").context("reading u.csv");
        assert_eq!(super::error_message(&err), "reading u.csv: line 3: bad");
    }
}
