//! Atomic file output: write to a temporary file in the target's directory, then rename.
//! A failure or interruption never leaves a half-written file under the target name.
//!
//! Every flapssm output goes through [`write_atomic`], which also decides what an output may be:
//! - a regular file (replaced) or a new name in an existing directory;
//! - a symbolic link to a regular file: written through, so the link stays a link and its target
//!   gets the new content;
//! - never a directory, a device, a pipe or a socket (refused: renaming over them would replace
//!   them), never `-` (standard output is not a file here), never a dangling link.
//!
//! [`check_output`] applies the same rules and proves the directory writable, so a command can
//! refuse a bad output before its expensive work. Temporary files are named
//! `.<name>.<pid>.<random>.tmp`; one left behind by a killed process (its pid no longer running)
//! is removed by the next successful write of the same name ([`remove_stale_temporaries`]).

use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};

/// An output path flapssm refuses, with the reason in words: an
/// [`std::io::ErrorKind::InvalidInput`] error `path: why`.
pub fn refused(path: &Path, why: &str) -> std::io::Error {
    std::io::Error::new(
        std::io::ErrorKind::InvalidInput,
        format!("{}: {why}", path.display()),
    )
}

/// Where a write to `path` lands (see the module docs): `path` itself, or the regular file a
/// symbolic link points to.
///
/// # Errors
/// An [`std::io::ErrorKind::InvalidInput`] error naming `path` for `-`, a directory, a device,
/// pipe or socket, or a dangling link; a missing parent directory.
pub fn resolve_output(path: &Path) -> std::io::Result<PathBuf> {
    if path.as_os_str() == "-" {
        return Err(refused(
            path,
            "standard output is not supported for this output; give a file name",
        ));
    }
    let target = match std::fs::symlink_metadata(path) {
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => path.to_path_buf(),
        Err(e) => return Err(e),
        Ok(m) if m.file_type().is_symlink() => std::fs::canonicalize(path)
            .map_err(|_| refused(path, "is a symbolic link to a missing file"))?,
        Ok(_) => path.to_path_buf(),
    };
    match std::fs::metadata(&target) {
        Ok(m) if m.is_dir() => return Err(refused(path, "is a directory; give a file name")),
        Ok(m) if !m.is_file() => {
            return Err(refused(
                path,
                "is not a regular file (a device, pipe or socket); give a file name",
            ));
        }
        _ => {}
    }
    let dir = parent(&target);
    if !dir.is_dir() {
        return Err(refused(
            path,
            &format!("directory {} does not exist", dir.display()),
        ));
    }
    Ok(target)
}

/// Checks before any work that `path` can be written: [`resolve_output`]'s rules, and a
/// temporary file can be created (and is removed) in its directory.
///
/// # Errors
/// As [`resolve_output`]; the directory's error (e.g. permission denied) naming `path`.
pub fn check_output(path: &Path) -> std::io::Result<()> {
    let target = resolve_output(path)?;
    temporary(&target)
        .map(drop)
        .map_err(|e| refused(path, &format!("cannot be written: {e}")))
}

fn parent(path: &Path) -> &Path {
    match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    }
}

fn file_name(path: &Path) -> &str {
    path.file_name().and_then(|n| n.to_str()).unwrap_or("out")
}

/// A temporary file `.<name>.<pid>.<random>.tmp` beside `target`.
fn temporary(target: &Path) -> std::io::Result<tempfile::NamedTempFile> {
    let mut builder = tempfile::Builder::new();
    // Like `File::create`: 0o666 restricted by the umask (tempfile's default is 0o600).
    #[cfg(unix)]
    builder.permissions(std::os::unix::fs::PermissionsExt::from_mode(0o666));
    builder
        .prefix(&format!(".{}.{}.", file_name(target), std::process::id()))
        .suffix(".tmp")
        .tempfile_in(parent(target))
}

/// Removes the temporary files of earlier writes to `target` whose process is gone (Linux:
/// no `/proc/<pid>`; elsewhere nothing is removed). Returns how many were removed.
pub fn remove_stale_temporaries(target: &Path) -> usize {
    let proc = Path::new("/proc/self");
    if !proc.exists() {
        return 0;
    }
    let prefix = format!(".{}.", file_name(target));
    let Ok(entries) = std::fs::read_dir(parent(target)) else {
        return 0;
    };
    let mut removed = 0;
    for entry in entries.flatten() {
        let name = entry.file_name();
        let Some(rest) = name
            .to_str()
            .and_then(|n| n.strip_prefix(&prefix))
            .filter(|n| n.ends_with(".tmp"))
        else {
            continue;
        };
        let Some(pid) = rest.split('.').next().and_then(|p| p.parse::<u32>().ok()) else {
            continue;
        };
        let running = Path::new("/proc").join(pid.to_string()).exists();
        if !running && std::fs::remove_file(entry.path()).is_ok() {
            removed += 1;
        }
    }
    removed
}

/// Writes a file atomically: `write` fills a buffered temporary file created next to the
/// output ([`resolve_output`]: `path`, or the file a link at `path` points to); on success the
/// file is flushed, synced and renamed over the output, otherwise it is removed. Stale
/// temporaries of the same name are removed after a successful write.
///
/// # Errors
/// [`resolve_output`]'s refusals; any I/O error of `write`, of creating the temporary file, or
/// of the rename.
pub fn write_atomic<F>(path: &Path, write: F) -> std::io::Result<()>
where
    F: FnOnce(&mut BufWriter<&mut std::fs::File>) -> std::io::Result<()>,
{
    let target = resolve_output(path)?;
    let mut tmp = temporary(&target)?;
    {
        let mut w = BufWriter::new(tmp.as_file_mut());
        write(&mut w)?;
        w.flush()?;
    }
    tmp.as_file().sync_all()?;
    tmp.persist(&target).map_err(|e| e.error)?;
    remove_stale_temporaries(&target);
    Ok(())
}

/// Writes bytes atomically (see [`write_atomic`]).
pub fn write_bytes_atomic(path: &Path, bytes: &[u8]) -> std::io::Result<()> {
    write_atomic(path, |w| w.write_all(bytes))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn failed_write_leaves_nothing() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("out.bin");
        let r = write_atomic(&path, |w| {
            w.write_all(b"partial")?;
            Err(std::io::Error::other("boom"))
        });
        assert!(r.is_err());
        assert!(!path.exists());
        assert_eq!(
            std::fs::read_dir(dir.path()).unwrap().count(),
            0,
            "temporary file left behind"
        );
        write_bytes_atomic(&path, b"ok").unwrap();
        assert_eq!(std::fs::read(&path).unwrap(), b"ok");
    }

    /// Output files get the same mode as `File::create` gives (0o666 less the umask), not
    /// the temporary file's private 0o600.
    #[cfg(unix)]
    #[test]
    fn output_mode_follows_the_umask_like_file_create() {
        use std::os::unix::fs::PermissionsExt;
        let dir = tempfile::tempdir().unwrap();
        let plain = dir.path().join("plain.bin");
        std::fs::File::create(&plain).unwrap();
        let atomic = dir.path().join("atomic.bin");
        write_bytes_atomic(&atomic, b"x").unwrap();
        let mode = |p: &Path| std::fs::metadata(p).unwrap().permissions().mode() & 0o777;
        assert_eq!(mode(&atomic), mode(&plain));
    }

    /// Special files, directories and `-` are refused and left as they were; a link is written
    /// through; a missing directory is named.
    #[cfg(unix)]
    #[test]
    fn what_an_output_may_be() {
        use std::os::unix::fs::FileTypeExt;
        let dir = tempfile::tempdir().unwrap();
        let d = dir.path();
        let err = |p: &Path| write_bytes_atomic(p, b"x").unwrap_err().to_string();
        assert!(err(Path::new("-")).contains("standard output is not supported"));
        assert!(err(d).contains("is a directory"));
        assert!(err(Path::new("/dev/null")).contains("not a regular file"));
        assert!(
            Path::new("/dev/null")
                .metadata()
                .unwrap()
                .file_type()
                .is_char_device()
        );
        assert!(err(&d.join("no/such/dir/f.bin")).contains("does not exist"));
        let fifo = d.join("fifo");
        assert!(
            std::process::Command::new("mkfifo")
                .arg(&fifo)
                .status()
                .unwrap()
                .success()
        );
        assert!(err(&fifo).contains("not a regular file"));
        assert!(check_output(&fifo).is_err());

        let target = d.join("target.bin");
        std::fs::write(&target, b"old").unwrap();
        let link = d.join("link.bin");
        std::os::unix::fs::symlink(&target, &link).unwrap();
        write_bytes_atomic(&link, b"new").unwrap();
        assert!(link.symlink_metadata().unwrap().file_type().is_symlink());
        assert_eq!(std::fs::read(&target).unwrap(), b"new");
        let dangling = d.join("dangling.bin");
        std::os::unix::fs::symlink(d.join("missing"), &dangling).unwrap();
        assert!(err(&dangling).contains("symbolic link to a missing file"));

        check_output(&d.join("fresh.bin")).unwrap();
        assert!(!d.join("fresh.bin").exists());
        let names: Vec<_> = std::fs::read_dir(d)
            .unwrap()
            .map(|e| e.unwrap().file_name().into_string().unwrap())
            .filter(|n| n.ends_with(".tmp"))
            .collect();
        assert!(names.is_empty(), "{names:?}");
    }

    /// A temporary left by a process that is gone is removed by the next write of the same
    /// name; one of a running process (this one) and other names' are kept.
    #[cfg(target_os = "linux")]
    #[test]
    fn stale_temporaries_are_removed() {
        let dir = tempfile::tempdir().unwrap();
        let d = dir.path();
        let gone = d.join(".m.json.4194305.aaaa.tmp"); // above any pid_max
        let mine = d.join(format!(".m.json.{}.bbbb.tmp", std::process::id()));
        let other = d.join(".n.json.4194305.cccc.tmp");
        for p in [&gone, &mine, &other] {
            std::fs::write(p, b"partial").unwrap();
        }
        write_bytes_atomic(&d.join("m.json"), b"{}").unwrap();
        assert!(!gone.exists() && mine.exists() && other.exists());
    }
}
