//! Writes `plan`'s part entries while the run goes on, and shows them only if it succeeds.
//! Entries go to threads of their own as they are encoded; each is written beside its final
//! name and renamed into place on `commit`. A run that fails (a rule bound, an error in a
//! later storey) removes what it wrote, so the cache never holds a part of a run that did
//! not finish: a later run under the same bounds reasons as much as an uncached one and
//! stops where it stops.
//!
//! Creating a file (its inode) is the kernel's work and on some filesystems most of the
//! writing (ext4 searching its inode groups, slower still just after a large delete), so
//! it runs on more than one thread, beside the rules and the plan.

use super::store::{Cache, Folder};
use rustc_hash::FxHashSet;
use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::{Receiver, Sender, channel};
use std::sync::{Arc, Mutex};
use std::thread::JoinHandle;
use tempfile::TempPath;

/// Threads that write plan entries.
const WRITERS: usize = 2;

/// One entry: its key and its bytes.
type Entry = (String, Vec<u8>);

/// Plan entries being written; see the module's comment.
pub struct PlanWriter<'a> {
    cache: &'a Cache,
    to_writers: Option<Sender<Entry>>,
    committed: Arc<AtomicBool>,
    writers: Vec<JoinHandle<()>>,
    /// Entries kept to be written on `commit` when no thread could be started.
    unwritten: Mutex<Vec<Entry>>,
}

impl Cache {
    /// A writer of plan entries. Its files are on disk (or failed, with a warning) once it is
    /// dropped and the cache waits for its writes (the next lookup, `take_warning`, drop).
    pub fn plan_writer(&self) -> PlanWriter<'_> {
        let (to_writers, from_run) = channel::<Entry>();
        let from_run = Arc::new(Mutex::new(from_run));
        let committed = Arc::new(AtomicBool::new(false));
        let writers: Vec<JoinHandle<()>> = (0..WRITERS)
            .filter_map(|_| {
                let (folder, from_run, committed) = (
                    Arc::clone(&self.shared),
                    Arc::clone(&from_run),
                    Arc::clone(&committed),
                );
                std::thread::Builder::new()
                    .name("framewright cache writer".into())
                    .spawn(move || write_entries(&folder, &from_run, &committed))
                    .ok()
            })
            .collect();
        PlanWriter {
            cache: self,
            to_writers: (!writers.is_empty()).then_some(to_writers),
            committed,
            writers,
            unwritten: Mutex::new(Vec::new()),
        }
    }
}

impl PlanWriter<'_> {
    /// Writes an entry (not yet visible).
    pub fn put(&self, key: String, bytes: Vec<u8>) {
        let entry = (key, bytes);
        // A send fails only when every writer has stopped (a panic): keep the entry.
        let entry = match &self.to_writers {
            Some(to) => match to.send(entry) {
                Ok(()) => return,
                Err(e) => e.0,
            },
            None => entry,
        };
        lock(&self.unwritten).push(entry);
    }

    /// Puts every entry written into place (they are renamed as the writers finish).
    pub fn commit(self) {
        self.committed.store(true, Ordering::Release);
        for (key, bytes) in std::mem::take(&mut *lock(&self.unwritten)) {
            self.cache.put_plan(&key, &bytes);
        }
    }
}

impl Drop for PlanWriter<'_> {
    /// Closes the writers' queue; the cache joins them when it next waits for its writes.
    fn drop(&mut self) {
        self.to_writers = None;
        self.cache.pending().append(&mut self.writers);
    }
}

/// One writer thread: entries from the queue to files beside their names, each folder made
/// once; renamed into place when the run committed, removed when it did not.
fn write_entries(folder: &Folder, queue: &Mutex<Receiver<Entry>>, committed: &AtomicBool) {
    let mut made: FxHashSet<PathBuf> = FxHashSet::default();
    let mut written: Vec<(TempPath, PathBuf)> = Vec::new();
    loop {
        // The lock is held only while waiting for the next entry.
        let next = lock(queue).recv();
        let Ok((key, bytes)) = next else { break };
        if folder.write_failed.load(Ordering::Relaxed) {
            continue;
        }
        let path = folder.plan_path(&key);
        let written_beside = match path.parent() {
            Some(dir) if !made.contains(dir) => std::fs::create_dir_all(dir).map(|()| {
                made.insert(dir.to_path_buf());
            }),
            _ => Ok(()),
        }
        .and_then(|()| crate::atomic::write_entry_beside(&path, |w| w.write_all(&bytes)));
        match written_beside {
            Ok(tmp) => written.push((tmp, path)),
            Err(e) => folder.failed(&e),
        }
    }
    // The queue closes when the writer is dropped, after `commit` when there was one.
    if committed.load(Ordering::Acquire) {
        for (tmp, path) in written {
            if let Err(e) = tmp.persist(&path) {
                folder.failed(&e.error);
            }
        }
    }
}

/// A lock that a panicked holder left usable (what it guards is whole between operations).
fn lock<T>(m: &Mutex<T>) -> std::sync::MutexGuard<'_, T> {
    m.lock().unwrap_or_else(|e| e.into_inner())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn files_under(dir: &std::path::Path) -> Vec<String> {
        let mut found = Vec::new();
        let mut stack = vec![dir.to_path_buf()];
        while let Some(d) = stack.pop() {
            for e in std::fs::read_dir(&d).into_iter().flatten().flatten() {
                if e.path().is_dir() {
                    stack.push(e.path());
                } else {
                    found.push(e.file_name().to_string_lossy().into_owned());
                }
            }
        }
        found.sort();
        found
    }

    #[test]
    fn committed_entries_are_in_place_and_uncommitted_ones_leave_nothing() {
        let dir = tempfile::tempdir().expect("temp dir");
        let cache = Cache::new(dir.path());
        let keys: Vec<String> = (0..40).map(|i| format!("{:02x}{i}", i * 7)).collect();

        let writer = cache.plan_writer();
        for k in &keys {
            writer.put(k.clone(), format!("entry {k}").into_bytes());
        }
        drop(writer);
        cache.wait_for_writes();
        assert!(keys.iter().all(|k| cache.get_plan(k).is_none()));
        assert_eq!(
            files_under(dir.path()),
            Vec::<String>::new(),
            "no leftovers"
        );

        let writer = cache.plan_writer();
        for k in &keys {
            writer.put(k.clone(), format!("entry {k}").into_bytes());
        }
        writer.commit();
        for k in &keys {
            assert_eq!(cache.get_plan(k), Some(format!("entry {k}").into_bytes()));
        }
        assert_eq!(
            files_under(dir.path()).len(),
            keys.len(),
            "only the entries"
        );
        assert!(cache.take_warning().is_none());
    }

    #[test]
    fn a_folder_that_cannot_be_written_gives_one_warning() {
        let dir = tempfile::tempdir().expect("temp dir");
        // A file where the cache folder should be.
        let blocked = dir.path().join("cache");
        std::fs::write(&blocked, b"not a folder").expect("file");
        let cache = Cache::new(&blocked);
        let writer = cache.plan_writer();
        writer.put("ab12".into(), b"entry".to_vec());
        writer.put("cd34".into(), b"entry".to_vec());
        writer.commit();
        let warning = cache.take_warning().expect("a warning");
        assert!(
            warning.contains("cannot write to the cache folder"),
            "{warning}"
        );
        assert!(cache.take_warning().is_none(), "said once");
    }
}
