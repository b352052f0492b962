//! Content keys. A wall's simulation reads the cell (robot, tool, layout), the time step,
//! speed and stepping mode (fixed and event-driven runs agree on verdicts, not to the bit), the wall's laid-flat frame and its pieces (sizes, masses, spawn and target poses),
//! and its nailing targets; the rules reach it only through those derived values. The key
//! hashes exactly these, plus the build of the program, so an edit to one wall keeps the
//! other walls' keys, and a new cell, rule change that moves a target, or new build misses.

use crate::cell::Cell;
use crate::frame::plan;
use crate::sim::SimOptions;
use crate::world::{ScenePiece, SceneWall};
use std::fmt::Write as _;
use std::path::Path;
use std::sync::OnceLock;

/// Feeds formatted text into a hash without building the string.
struct HashText<'a>(&'a mut blake3::Hasher);

impl std::fmt::Write for HashText<'_> {
    fn write_str(&mut self, s: &str) -> std::fmt::Result {
        self.0.update(s.as_bytes());
        Ok(())
    }
}

/// The program's identity: its version and a hash of the running executable, so entries of
/// another build (whose executor or kinematics may differ) are never reused. When the
/// executable cannot be read, the identity is unique to this process: nothing is reused.
pub fn build_id() -> &'static str {
    BUILD_ID.get_or_init(hash_executable)
}

static BUILD_ID: OnceLock<String> = OnceLock::new();

/// `build_id`, taken from a note in the cache folder `dir` when this executable file (same
/// path, size, inode, modification and change times) was hashed before: hashing a 100 MB
/// executable is most of a cached `plan`'s time. A rebuilt or replaced executable has new
/// times, so it is hashed again; a note that cannot be read or written only costs the hash.
pub fn build_id_noted(dir: &Path) -> &'static str {
    BUILD_ID.get_or_init(|| {
        let Some(note) = executable_stamp().map(|s| dir.join(BUILDS).join(s)) else {
            return hash_executable();
        };
        if let Ok(text) = std::fs::read_to_string(&note)
            && text.len() == 64
            && text.bytes().all(|b| b.is_ascii_hexdigit())
        {
            return text;
        }
        let id = hash_executable();
        if let Some(folder) = note.parent()
            && std::fs::create_dir_all(folder).is_ok()
        {
            let _ = crate::atomic::write_entry_with(&note, |w| w.write_all(id.as_bytes()));
        }
        id
    })
}

/// Subfolder of the build notes.
pub const BUILDS: &str = "builds";

/// A name for the running executable file as it is now: a hash of its path and metadata.
#[cfg(not(unix))]
fn executable_stamp() -> Option<String> {
    None
}

/// A name for the running executable file as it is now: a hash of its path and metadata.
#[cfg(unix)]
fn executable_stamp() -> Option<String> {
    use std::os::unix::fs::MetadataExt;
    let exe = std::env::current_exe().ok()?;
    let m = std::fs::metadata(&exe).ok()?;
    let text = format!(
        "{}\0{}\0{}\0{}\0{}.{}\0{}.{}",
        exe.display(),
        m.len(),
        m.dev(),
        m.ino(),
        m.mtime(),
        m.mtime_nsec(),
        m.ctime(),
        m.ctime_nsec()
    );
    Some(blake3::hash(text.as_bytes()).to_hex().to_string())
}

fn hash_executable() -> String {
    let mut h = blake3::Hasher::new();
    h.update(env!("CARGO_PKG_VERSION").as_bytes());
    let hashed = std::env::current_exe()
        .ok()
        .and_then(|exe| h.update_mmap_rayon(exe).ok().map(|_| ()));
    if hashed.is_none() {
        let now = std::time::SystemTime::now()
            .duration_since(std::time::UNIX_EPOCH)
            .map_or(0, |d| d.as_nanos());
        h.update(format!("unreadable build {} {now}", std::process::id()).as_bytes());
    }
    h.finalize().to_hex().to_string()
}

/// The key of one wall's simulation.
pub fn wall_key(
    build: &str,
    cell: &Cell,
    options: &SimOptions,
    wall: &SceneWall,
    pieces: &[&ScenePiece],
    plan_wall: &plan::Wall,
) -> String {
    let mut h = blake3::Hasher::new();
    let mut t = HashText(&mut h);
    // Debug output prints every field, floats in their shortest exact form; sections are
    // separated so that no two inputs can run into each other.
    let _ = write!(t, "framewright wall simulation\u{0}{build}\u{0}");
    let _ = write!(t, "{cell:?}\u{0}");
    let _ = write!(
        t,
        "dt {:016x} speed {:016x} stepping {}\u{0}",
        options.dt.to_bits(),
        options.speed.to_bits(),
        options.stepping.name()
    );
    let _ = write!(t, "{wall:?}\u{0}");
    for p in pieces {
        let _ = write!(t, "{p:?}\u{0}");
    }
    let _ = write!(
        t,
        "{:?}\u{0}{:?}\u{0}",
        plan_wall.frame, plan_wall.nailing_targets
    );
    h.finalize().to_hex().to_string()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::frame::{Ask, cell_facts, model_facts};
    use crate::geom::ContactOptions;
    use crate::ifc::Model;
    use crate::world::Scene;

    /// The keys of TM3's walls for a build, cell and options.
    fn keys(build: &str, cell: &Cell, options: &SimOptions) -> Vec<String> {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/models/tm3.ifc");
        let model = Model::open(&path).unwrap();
        let mut facts = model_facts(&model, &ContactOptions::default());
        facts.extend(cell_facts(cell));
        let (reasoned, _) = Ask::new(&options.engine).placing(facts, cell).unwrap();
        let scene = Scene::build("tm3.ifc", &model, cell, &reasoned).unwrap();
        let plan = plan::Plan::from_reasoned(&model, &reasoned).unwrap();
        plan.walls
            .iter()
            .map(|pw| {
                let w = scene.walls.iter().find(|w| w.id == pw.key).unwrap();
                let pieces: Vec<_> = w
                    .pieces
                    .iter()
                    .map(|id| scene.pieces.iter().find(|p| &p.id == id).unwrap())
                    .collect();
                wall_key(build, cell, options, w, &pieces, pw)
            })
            .collect()
    }

    #[test]
    fn keys_are_stable_distinct_per_wall_and_change_with_build_cell_step_and_stepping() {
        let cell = Cell::load("study-abb").unwrap();
        let options = SimOptions::default();
        let base = keys("b1", &cell, &options);
        assert_eq!(base, keys("b1", &cell, &options));
        let mut distinct = base.clone();
        distinct.sort();
        distinct.dedup();
        assert_eq!(
            distinct.len(),
            base.len(),
            "walls 1 and 3 are alike but are not one wall"
        );
        let differ = |other: Vec<String>| base.iter().zip(&other).all(|(a, b)| a != b);
        assert!(
            differ(keys("b2", &cell, &options)),
            "a new build misses every wall"
        );
        let slower = SimOptions {
            speed: 0.5,
            ..SimOptions::default()
        };
        assert!(differ(keys("b1", &cell, &slower)));
        let fixed = SimOptions {
            stepping: crate::sim::Stepping::Fixed,
            ..SimOptions::default()
        };
        assert!(
            differ(keys("b1", &cell, &fixed)),
            "fixed-step results are not reused for event-driven runs"
        );
        let mut moved_tool = cell.clone();
        moved_tool.tool.parts[1].shape.origin.translation.x += 0.01;
        assert!(
            differ(keys("b1", &moved_tool, &options)),
            "a changed cell misses every wall"
        );
    }
}
