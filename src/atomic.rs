//! The one way framewright writes an output file: into a temporary file beside
//! the target, flushed to disk, then renamed over it. An interrupted run (a
//! signal, a full disk, an error half-way) leaves the previous file or none,
//! never half a file; the temporary file is removed on error. Cache entries, which are
//! checked when read, skip the flush (`write_entry_with`).

use std::io::Write;
use std::path::Path;

/// Writes `bytes` to `path` atomically.
pub fn write_atomically(path: &Path, bytes: &[u8]) -> std::io::Result<()> {
    write_atomically_with(path, |w| w.write_all(bytes))
}

/// Writes what `fill` produces to `path` atomically (for large outputs that
/// stream instead of building one buffer).
pub fn write_atomically_with(
    path: &Path,
    fill: impl FnOnce(&mut dyn Write) -> std::io::Result<()>,
) -> std::io::Result<()> {
    write_via_temp(path, fill, true)
}

/// `write_atomically_with` without flushing to disk: a run that stops half-way still leaves
/// the previous file or none, but a power loss may leave a torn file under the final name.
/// For cache entries only, which are checked (key and digest) whenever they are read and
/// recomputed when they fail; the two flushes per file cost more than the entry's work.
pub fn write_entry_with(
    path: &Path,
    fill: impl FnOnce(&mut dyn Write) -> std::io::Result<()>,
) -> std::io::Result<()> {
    write_via_temp(path, fill, false)
}

/// A cache entry written beside `path` and not yet in place: `tempfile::TempPath::persist`
/// renames it there; dropping it removes it. Lets a caller write entries while it works
/// and show them only once the whole run has succeeded.
pub fn write_entry_beside(
    path: &Path,
    fill: impl FnOnce(&mut dyn Write) -> std::io::Result<()>,
) -> std::io::Result<tempfile::TempPath> {
    Ok(write_temp_beside(path, fill)?.into_temp_path())
}

fn write_via_temp(
    path: &Path,
    fill: impl FnOnce(&mut dyn Write) -> std::io::Result<()>,
    durable: bool,
) -> std::io::Result<()> {
    let tmp = write_temp_beside(path, fill)?;
    if durable {
        tmp.as_file().sync_all()?;
    }
    // Dropping `tmp` on any error above removes the temporary file.
    tmp.persist(path).map_err(|e| e.error)?;
    // Make the rename itself durable; not every platform can open a folder.
    if durable && let Ok(d) = std::fs::File::open(folder_of(path)) {
        let _ = d.sync_all();
    }
    Ok(())
}

/// `fill` written to a new temporary file in `path`'s folder.
fn write_temp_beside(
    path: &Path,
    fill: impl FnOnce(&mut dyn Write) -> std::io::Result<()>,
) -> std::io::Result<tempfile::NamedTempFile> {
    let name = path.file_name().ok_or_else(|| {
        std::io::Error::other(format!("the output path {} names no file", path.display()))
    })?;
    // Hidden and tagged so a leftover from a killed run is easy to recognise.
    let tmp = tempfile::Builder::new()
        .prefix(&format!(".{}.", name.to_string_lossy()))
        .suffix(".tmp")
        .tempfile_in(folder_of(path))?;
    {
        let mut w = std::io::BufWriter::with_capacity(1 << 16, tmp.as_file());
        fill(&mut w)?;
        w.flush()?;
    }
    Ok(tmp)
}

/// The folder `path` is in ("." for a bare file name).
fn folder_of(path: &Path) -> &Path {
    match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    }
}
