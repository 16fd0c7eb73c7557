//! Atomic file output.
//!
//! Results are written to a temporary file in the destination directory and
//! renamed over the destination only when complete, so a crash, a full disk
//! or an error never leaves a half-written output, and an existing file is
//! either kept whole or replaced whole. The rename needs the temporary file
//! on the same file system, hence the same directory.

use std::io::{BufWriter, Write};
use std::path::Path;

use anyhow::{Context, Result};
use tempfile::NamedTempFile;

/// Writes `path` atomically with `write`, creating missing parent
/// directories. On any error the destination is untouched and the temporary
/// file is removed.
pub fn write_atomic(
    path: &Path,
    write: impl FnOnce(&mut dyn Write) -> std::io::Result<()>,
) -> Result<()> {
    write_inner(path, write).with_context(|| path.display().to_string())
}

fn write_inner(
    path: &Path,
    write: impl FnOnce(&mut dyn Write) -> std::io::Result<()>,
) -> Result<()> {
    let dir = match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    };
    std::fs::create_dir_all(dir)
        .with_context(|| format!("cannot create directory {}", dir.display()))?;
    let mut tmp = temp_file(dir).context("cannot create a temporary file")?;
    {
        let mut out = BufWriter::new(tmp.as_file_mut());
        write(&mut out).context("cannot write")?;
        out.flush().context("cannot write")?;
    }
    // Flush to disk before the rename, so a crash cannot expose an empty
    // file under the final name.
    tmp.as_file().sync_all().context("cannot write")?;
    tmp.persist(path)
        .map_err(|e| e.error)
        .context("cannot rename the temporary file")?;
    Ok(())
}

/// A temporary file in `dir` with the permissions a plain `File::create`
/// would give (0o666 less the umask), not tempfile's private 0o600, since
/// it becomes the output file.
fn temp_file(dir: &Path) -> std::io::Result<NamedTempFile> {
    #[cfg_attr(not(unix), allow(unused_mut))] // only unix sets a mode
    let mut builder = tempfile::Builder::new();
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        builder.permissions(std::fs::Permissions::from_mode(0o666));
    }
    builder.tempfile_in(dir)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn replaces_whole_and_leaves_no_temp_files() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("sub/out.txt");
        write_atomic(&path, |w| w.write_all(b"first")).unwrap();
        write_atomic(&path, |w| w.write_all(b"second")).unwrap();
        assert_eq!(std::fs::read(&path).unwrap(), b"second");
        let failed = write_atomic(&path, |w| {
            w.write_all(b"partial")?;
            Err(std::io::Error::other("disk full"))
        });
        assert!(format!("{:#}", failed.unwrap_err()).contains("disk full"));
        assert_eq!(std::fs::read(&path).unwrap(), b"second");
        let names: Vec<_> = std::fs::read_dir(path.parent().unwrap()).unwrap().collect();
        assert_eq!(names.len(), 1);
    }
}
