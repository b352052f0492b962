//! The cache folder: one file per entry, written beside its final name and renamed into
//! place, so a reader (this process or another sharing the folder) sees a whole entry or
//! none. An entry that cannot be read, parsed or verified is a miss and is written again.
//! A folder that cannot be written (read-only, full disk) turns writing off with one warning.

use super::record_codec::Entry;
use super::trace_codec;
use crate::sim::WallRecord;
use crate::sim::record::PoseTrace;
use serde::Serialize;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};
use std::thread::JoinHandle;

/// Subfolder of wall simulation entries.
const WALLS: &str = "walls";
/// Subfolder of `plan`'s part entries.
const PLANS: &str = "plans";
/// Entries of the single-wall cache `why` kept before it shared the wall entries (still
/// counted and cleared).
const WHY_PREFIX: &str = "sim-";

/// A cache folder in use.
pub struct Cache {
    pub(super) shared: Arc<Folder>,
    /// Entries being written behind the caller's back (`PlanWriter`); joined by the
    /// next lookup of plan entries, by `take_warning` and on drop.
    behind: Mutex<Vec<JoinHandle<()>>>,
}

/// What the writers of a cache folder share.
pub(super) struct Folder {
    dir: PathBuf,
    pub(super) write_failed: AtomicBool,
    warning: Mutex<Option<String>>,
}

/// What looking up a wall found.
pub enum Lookup {
    Hit(Box<WallRecord>),
    Miss,
    /// An entry was there but was torn, corrupt, of another format or answered another key.
    Rejected,
}

impl Cache {
    pub fn new(dir: impl Into<PathBuf>) -> Cache {
        Cache {
            shared: Arc::new(Folder {
                dir: dir.into(),
                write_failed: AtomicBool::new(false),
                warning: Mutex::new(None),
            }),
            behind: Mutex::new(Vec::new()),
        }
    }

    pub fn dir(&self) -> &Path {
        &self.shared.dir
    }

    fn wall_path(&self, key: &str) -> PathBuf {
        self.shared.entry_path(WALLS, key, "json")
    }

    /// The bytes of a plan part's entry (the caller verifies them), None when absent. Waits
    /// for this cache's entries still being written, so a lookup sees every entry stored
    /// before it.
    pub fn get_plan(&self, key: &str) -> Option<Vec<u8>> {
        self.wait_for_writes();
        std::fs::read(self.shared.plan_path(key)).ok()
    }

    /// Whether the folder may hold plan entries: false when it has no plan folder or an
    /// empty one, so a first run need not look up each of its parts.
    pub fn may_hold_plans(&self) -> bool {
        self.wait_for_writes();
        std::fs::read_dir(self.shared.dir.join(PLANS))
            .is_ok_and(|mut entries| entries.next().is_some())
    }

    /// Stores a plan part's entry, like `put_wall`.
    pub fn put_plan(&self, key: &str, bytes: &[u8]) {
        self.shared
            .put(&self.shared.plan_path(key), |w| w.write_all(bytes));
    }

    pub(super) fn pending(&self) -> std::sync::MutexGuard<'_, Vec<JoinHandle<()>>> {
        // A writer that panicked left no half entry (entries are renamed into place whole);
        // its handles are still there to join.
        self.behind.lock().unwrap_or_else(|e| e.into_inner())
    }

    /// Waits until the entries written behind are on disk (or failed, with a warning). The
    /// list stays locked while they are joined, so a lookup on another thread waits too.
    pub fn wait_for_writes(&self) {
        let mut pending = self.pending();
        for h in pending.drain(..) {
            let _ = h.join();
        }
    }

    /// A wall's pose trace sits beside its record, under the same key.
    fn trace_path(&self, key: &str) -> PathBuf {
        self.wall_path(key).with_extension("trace")
    }

    pub fn get_wall(&self, key: &str) -> Lookup {
        let Ok(bytes) = std::fs::read(self.wall_path(key)) else {
            return Lookup::Miss;
        };
        match serde_json::from_slice::<Entry>(&bytes)
            .ok()
            .and_then(|e| e.into_record(key))
        {
            Some(record) => Lookup::Hit(Box::new(record)),
            None => Lookup::Rejected,
        }
    }

    /// A wall's pose trace: None when absent, torn, altered or of another key or format.
    pub fn get_trace(&self, key: &str) -> Option<PoseTrace> {
        let bytes = std::fs::read(self.trace_path(key)).ok()?;
        trace_codec::decode(key, &bytes)
    }

    /// Stores a wall's record; a failure turns writing off for this run and leaves a warning.
    pub fn put_wall(&self, key: &str, record: &WallRecord) {
        self.shared.put(&self.wall_path(key), |w| {
            serde_json::to_writer(w, &Entry::new(key, record)).map_err(std::io::Error::other)
        });
    }

    /// Stores a wall's pose trace (for the report's animation), like `put_wall`.
    pub fn put_trace(&self, key: &str, trace: &PoseTrace) {
        if let Some(bytes) = trace_codec::encode(key, trace) {
            self.shared
                .put(&self.trace_path(key), |w| w.write_all(&bytes));
        }
    }

    /// The warning of a failed write, once (after the writes behind are done).
    pub fn take_warning(&self) -> Option<String> {
        self.wait_for_writes();
        self.shared.warning.lock().ok().and_then(|mut w| w.take())
    }
}

impl Drop for Cache {
    fn drop(&mut self) {
        self.wait_for_writes();
    }
}

impl Folder {
    /// `DIR/<folder>/<first two characters of key>/<key>.<extension>`: the two-character
    /// fan-out keeps folders small on shared filesystems.
    fn entry_path(&self, folder: &str, key: &str, extension: &str) -> PathBuf {
        self.dir
            .join(folder)
            .join(&key[..2.min(key.len())])
            .join(format!("{key}.{extension}"))
    }

    pub(super) fn plan_path(&self, key: &str) -> PathBuf {
        self.entry_path(PLANS, key, "part")
    }

    /// Writes one entry, making its folder; a failure turns writing off for this run and
    /// leaves a warning.
    fn put(&self, path: &Path, write: impl FnOnce(&mut dyn std::io::Write) -> std::io::Result<()>) {
        if self.write_failed.load(Ordering::Relaxed) {
            return;
        }
        let written = match path.parent().map(std::fs::create_dir_all) {
            Some(Err(e)) => Err(e),
            _ => crate::atomic::write_entry_with(path, |w| write(w)),
        };
        if let Err(e) = written {
            self.failed(&e);
        }
    }

    /// Turns writing off for this run, with one warning (the first failure's).
    pub(super) fn failed(&self, e: &std::io::Error) {
        if !self.write_failed.swap(true, Ordering::Relaxed)
            && let Ok(mut w) = self.warning.lock()
        {
            *w = Some(format!(
                "cannot write to the cache folder {} ({e}); going on without storing results \
                 (give --cache DIR for a writable folder, or --no-cache)",
                self.dir.display()
            ));
        }
    }
}

/// What a cache folder holds.
#[derive(Debug, Default, Serialize, PartialEq)]
pub struct CacheInfo {
    pub dir: PathBuf,
    /// Simulated walls (`simulate`, `plan`, `diff`, `watch`).
    pub walls: u64,
    /// Pose traces of cached walls (kept for `simulate --report`).
    pub traces: u64,
    /// Walls simulated for `why`.
    pub why_walls: u64,
    /// Reasoned parts of models for `plan` (a part: the walls that touch one another).
    pub plan_parts: u64,
    pub bytes: u64,
}

/// Counts the entries of a cache folder (an absent folder is empty).
pub fn info(dir: &Path) -> std::io::Result<CacheInfo> {
    let mut info = CacheInfo {
        dir: dir.to_path_buf(),
        ..CacheInfo::default()
    };
    for file in entry_files(dir)? {
        let bytes = std::fs::metadata(&file.path).map_or(0, |m| m.len());
        info.bytes += bytes;
        match file.kind {
            Kind::Wall => info.walls += 1,
            Kind::Trace => info.traces += 1,
            Kind::Why => info.why_walls += 1,
            Kind::Plan => info.plan_parts += 1,
        }
    }
    Ok(info)
}

/// Removes every entry framewright wrote in `dir` (and nothing else); returns how many.
pub fn clear(dir: &Path) -> std::io::Result<u64> {
    let mut removed = 0;
    for file in entry_files(dir)? {
        match std::fs::remove_file(&file.path) {
            Ok(()) => removed += 1,
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => {}
            Err(e) => return Err(e),
        }
    }
    // The notes of hashed executables (`key::build_id_noted`) go too, uncounted.
    if let Ok(notes) = std::fs::read_dir(dir.join(super::key::BUILDS)) {
        for note in notes.flatten() {
            let name = note.file_name().to_string_lossy().into_owned();
            if name.len() == 64 && name.bytes().all(|b| b.is_ascii_hexdigit()) {
                let _ = std::fs::remove_file(note.path());
            }
        }
        let _ = std::fs::remove_dir(dir.join(super::key::BUILDS));
    }
    // Now-empty fan-out folders go too; a folder something else put files in stays.
    for folder in [WALLS, PLANS] {
        if let Ok(subdirs) = std::fs::read_dir(dir.join(folder)) {
            for sub in subdirs.flatten() {
                let _ = std::fs::remove_dir(sub.path());
            }
            let _ = std::fs::remove_dir(dir.join(folder));
        }
    }
    Ok(removed)
}

enum Kind {
    Wall,
    Trace,
    Why,
    Plan,
}

struct EntryFile {
    path: PathBuf,
    kind: Kind,
}

/// The files of a fan-out folder (`<folder>/<2 characters>/<file>`) that `kind_of` names.
fn fan_out_files(
    folder: &Path,
    files: &mut Vec<EntryFile>,
    kind_of: impl Fn(&str) -> Option<Kind>,
) {
    let Ok(subdirs) = std::fs::read_dir(folder) else {
        return;
    };
    for sub in subdirs.flatten() {
        let Ok(entries) = std::fs::read_dir(sub.path()) else {
            continue;
        };
        for e in entries.flatten() {
            if let Some(kind) = kind_of(&e.file_name().to_string_lossy()) {
                files.push(EntryFile {
                    path: e.path(),
                    kind,
                });
            }
        }
    }
}

/// The entry files (and left-over temporary files) of a cache folder, sorted.
fn entry_files(dir: &Path) -> std::io::Result<Vec<EntryFile>> {
    let mut files = Vec::new();
    let top = match std::fs::read_dir(dir) {
        Ok(t) => t,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(files),
        Err(e) => return Err(e),
    };
    for e in top.flatten() {
        let name = e.file_name().to_string_lossy().into_owned();
        // Temporary files of the atomic writer are `.<target name>.<random>.tmp`.
        let leftover =
            |prefix: &str| name.starts_with(&format!(".{prefix}")) && name.ends_with(".tmp");
        if (name.starts_with(WHY_PREFIX) && name.ends_with(".json")) || leftover(WHY_PREFIX) {
            files.push(EntryFile {
                path: e.path(),
                kind: Kind::Why,
            });
        }
    }
    // A temporary file of the atomic writer is `.<target name>.<random>.tmp`.
    let leftover = |name: &str| name.starts_with('.') && name.ends_with(".tmp");
    fan_out_files(&dir.join(WALLS), &mut files, |name| {
        if name.ends_with(".trace") {
            Some(Kind::Trace)
        } else if name.ends_with(".json") || leftover(name) {
            Some(Kind::Wall)
        } else {
            None
        }
    });
    fan_out_files(&dir.join(PLANS), &mut files, |name| {
        (name.ends_with(".part") || leftover(name)).then_some(Kind::Plan)
    });
    files.sort_by(|a, b| a.path.cmp(&b.path));
    Ok(files)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_folder_holds_plans_once_one_is_stored_or_being_stored() {
        let dir = tempfile::tempdir().expect("temp dir");
        let cache = Cache::new(dir.path().join("cache"));
        assert!(!cache.may_hold_plans(), "no folder yet");
        std::fs::create_dir_all(dir.path().join("cache").join(PLANS)).expect("plans folder");
        assert!(!cache.may_hold_plans(), "an empty plans folder");
        // Entries still being written behind count: the check waits for them.
        let writer = cache.plan_writer();
        writer.put("ab12".into(), b"entry".to_vec());
        writer.commit();
        assert!(cache.may_hold_plans());
        assert_eq!(cache.get_plan("ab12").as_deref(), Some(&b"entry"[..]));
    }
}
