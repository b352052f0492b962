//! The executor's facts for one wall, simulated once and then read from a
//! cache: `why` explains one element, so it simulates only that element's
//! wall, and asking again about the same model, cell and rules costs no
//! simulation. The cache key hashes everything the simulation depends on
//! (model bytes, the loaded cell with its robot and tool, rule files, wall,
//! framewright version and the executor's source); a stale or unreadable
//! entry is simulated again, never trusted.

use crate::cache::key::build_id_noted;
use crate::cell::Cell;
use crate::frame::{Facts, RuleEngine};
use crate::ifc::Model;
use crate::logic::compiled::BUILTIN_SOURCES;
use crate::logic::{Origin, Value};
use crate::sim::{SimError, SimOptions, simulate_wall_facts};
use serde::{Deserialize, Serialize};
use std::hash::{Hash, Hasher};
use std::path::{Path, PathBuf};

/// The relations of `rules/sim.dl` (the executor's facts), with their column types:
/// `s` symbol, `f` float, `n` number.
pub const SIM_RELATIONS: &[(&str, &str)] = &[
    ("sim_operation", "ssff"),
    ("sim_ik_solved", "ssf"),
    ("sim_ik_failed", "ssssffs"),
    ("sim_contact", "ssfssf"),
    ("sim_placed", "sff"),
    ("sim_fed", "sf"),
    ("sim_not_fed", "ss"),
    ("sim_grip_failed", "ss"),
    ("sim_nail", "ssnfff"),
    ("sim_nail_fired", "ssnffn"),
    ("sim_nail_lean", "ssnf"),
    ("sim_nail_skipped", "ssnssffs"),
    ("sim_nail_as_built", "ssnfff"),
    ("sim_wall", "sfff"),
    ("sim_belt_event", "sfsss"),
];

#[derive(Debug, thiserror::Error)]
pub enum SimCacheError {
    #[error(transparent)]
    Sim(#[from] SimError),
    #[error("{}: cannot read the model to key the simulation cache: {message}", path.display())]
    Model { path: PathBuf, message: String },
}

/// One cached tuple: relation, values, the event it came from.
#[derive(Serialize, Deserialize)]
struct Row(String, Vec<serde_json::Value>, String);

#[derive(Serialize, Deserialize)]
struct Entry {
    key: String,
    rows: Vec<Row>,
}

/// The simulation facts of `wall` (a wall key, as in `wall_of`) and whether
/// they came from the cache.
pub fn wall_sim_facts(
    model_path: &Path,
    model: &Model,
    cell: &Cell,
    wall: &str,
    engine: &RuleEngine,
    cache_dir: Option<&Path>,
) -> Result<(Facts, bool), SimCacheError> {
    let entry = match cache_dir {
        Some(dir) => {
            let key = cache_key(model_path, cell, wall, engine, build_id_noted(dir))?;
            Some((dir.join(format!("sim-{key}.json")), key))
        }
        None => None,
    };
    if let Some(facts) = entry.as_ref().and_then(|(f, key)| read_entry(f, key)) {
        return Ok((facts, true));
    }
    let options = SimOptions {
        walls: vec![wall.to_string()],
        engine: engine.clone(),
        ..SimOptions::default()
    };
    let facts = simulate_wall_facts(model, cell, &options)?;
    if let Some((f, key)) = entry {
        // A cache that cannot be written only costs the next run a simulation.
        let _ = write_entry(&f, &key, &facts);
    }
    Ok((facts, false))
}

/// The default cache directory: `$FRAMEWRIGHT_CACHE`, else
/// `$XDG_CACHE_HOME/framewright`, else `$HOME/.cache/framewright`.
pub fn default_cache_dir() -> Option<PathBuf> {
    let var = |k: &str| {
        std::env::var_os(k)
            .filter(|v| !v.is_empty())
            .map(PathBuf::from)
    };
    var("FRAMEWRIGHT_CACHE")
        .or_else(|| var("XDG_CACHE_HOME").map(|d| d.join("framewright")))
        .or_else(|| var("HOME").map(|d| d.join(".cache/framewright")))
}

fn cache_key(
    model_path: &Path,
    cell: &Cell,
    wall: &str,
    engine: &RuleEngine,
    build: &str,
) -> Result<String, SimCacheError> {
    let bytes = std::fs::read(model_path).map_err(|e| SimCacheError::Model {
        path: model_path.to_path_buf(),
        message: e.to_string(),
    })?;
    // FNV-1a: stable across runs and Rust versions (the std hasher is not promised to be).
    let mut h = Fnv::default();
    env!("CARGO_PKG_VERSION").hash(&mut h);
    bytes.hash(&mut h);
    // The cell as loaded: layout, robot (links, collision shapes, limits) and tool, whichever
    // files they came from.
    format!("{cell:?}").hash(&mut h);
    // The build itself (the main cache's identity: a hash of the executable), so a changed
    // executor, planner or pipeline is never answered from an old entry.
    build.hash(&mut h);
    wall.hash(&mut h);
    match engine {
        RuleEngine::Directory(dir) => {
            if let Ok(files) = super::directory_files(dir) {
                for f in files {
                    std::fs::read(&f).unwrap_or_default().hash(&mut h);
                }
            }
        }
        RuleEngine::Compiled | RuleEngine::Interpreted | RuleEngine::Extended(_) => {
            for (name, text) in BUILTIN_SOURCES {
                name.hash(&mut h);
                text.hash(&mut h);
            }
            if let RuleEngine::Extended(files) = engine {
                for f in files {
                    std::fs::read(f).unwrap_or_default().hash(&mut h);
                }
            }
        }
    }
    Ok(format!("{:016x}", h.finish()))
}

#[derive(Default)]
struct Fnv(u64);

impl Hasher for Fnv {
    fn finish(&self) -> u64 {
        self.0
    }
    fn write(&mut self, bytes: &[u8]) {
        if self.0 == 0 {
            self.0 = 0xcbf2_9ce4_8422_2325;
        }
        for b in bytes {
            self.0 ^= u64::from(*b);
            self.0 = self.0.wrapping_mul(0x0100_0000_01b3);
        }
    }
}

fn read_entry(file: &Path, key: &str) -> Option<Facts> {
    let text = std::fs::read_to_string(file).ok()?;
    let entry: Entry = serde_json::from_str(&text).ok()?;
    if entry.key != key {
        return None;
    }
    let mut facts = Facts::default();
    for Row(rel, values, event) in entry.rows {
        let &(name, types) = SIM_RELATIONS.iter().find(|(n, _)| *n == rel)?;
        if types.len() != values.len() {
            return None;
        }
        let tuple = types
            .chars()
            .zip(&values)
            .map(|(t, v)| match t {
                's' => v.as_str().map(Value::sym),
                'f' => v.as_f64().map(Value::float),
                _ => v.as_i64().map(Value::Number),
            })
            .collect::<Option<Vec<Value>>>()?;
        facts.add(name, tuple, Origin::Event(event));
    }
    Some(facts)
}

fn write_entry(file: &Path, key: &str, facts: &Facts) -> std::io::Result<()> {
    let mut rows = Vec::new();
    for (name, tuples) in &facts.tuples {
        for (t, origin) in tuples {
            let values = t
                .iter()
                .map(|v| serde_json::to_value(v).unwrap_or(serde_json::Value::Null))
                .collect();
            let event = match origin {
                Origin::Event(e) => e.clone(),
                other => other.to_string(),
            };
            rows.push(Row(name.to_string(), values, event));
        }
    }
    let entry = Entry {
        key: key.to_string(),
        rows,
    };
    let text = serde_json::to_string(&entry).map_err(std::io::Error::other)?;
    if let Some(dir) = file.parent() {
        std::fs::create_dir_all(dir)?;
    }
    crate::atomic::write_atomically(file, text.as_bytes())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::logic::Program;

    #[test]
    fn the_column_types_match_rules_sim_dl() {
        let p = Program::builtin().unwrap();
        let sim: Vec<&str> = p
            .relations
            .iter()
            .filter(|r| r.name.starts_with("sim_") && r.input.is_some())
            .map(|r| r.name.as_str())
            .collect();
        assert_eq!(sim.len(), SIM_RELATIONS.len(), "{sim:?}");
        for (name, types) in SIM_RELATIONS {
            let d = p.relation(name).unwrap();
            let want: String = d
                .attrs
                .iter()
                .map(|a| match a.ty.name() {
                    "symbol" => 's',
                    "float" => 'f',
                    _ => 'n',
                })
                .collect();
            assert_eq!(&want, types, "{name}");
        }
    }

    #[test]
    fn the_key_changes_with_the_robot_and_tool_geometry() {
        let model = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/models/tm1.ifc");
        let cell = Cell::load("study-abb").unwrap();
        let key = |c: &Cell| cache_key(&model, c, "W1", &RuleEngine::Compiled, "b").unwrap();
        assert_eq!(key(&cell), key(&cell.clone()));
        // Another build: another key.
        let other = cache_key(&model, &cell, "W1", &RuleEngine::Compiled, "c").unwrap();
        assert_ne!(key(&cell), other);
        // A tool part moved 10 mm: no cell key or fact changes, the simulation does.
        let mut moved = cell.clone();
        moved.tool.parts[1].shape.origin.translation.x += 0.01;
        assert_ne!(key(&cell), key(&moved));
        let mut link = cell.clone();
        link.robot.joints[2].origin.translation.z += 0.001;
        assert_ne!(key(&cell), key(&link));
    }

    #[test]
    fn entries_round_trip_and_a_wrong_key_is_a_miss() {
        let dir = tempfile::tempdir().unwrap();
        let f = dir.path().join("e.json");
        let mut facts = Facts::default();
        facts.add(
            "sim_ik_solved",
            vec![
                Value::sym("p\t1"),
                Value::sym("place"),
                Value::float(0.1 + 0.2),
            ],
            Origin::Event("W1 IK".into()),
        );
        facts.add(
            "sim_nail_fired",
            vec![
                Value::sym("a"),
                Value::sym("b"),
                Value::Number(2),
                Value::float(3.5),
                Value::float(1e-17),
                Value::Number(1),
            ],
            Origin::Event("W1 nail".into()),
        );
        write_entry(&f, "k1", &facts).unwrap();
        let back = read_entry(&f, "k1").unwrap();
        assert_eq!(format!("{:?}", back.tuples), format!("{:?}", facts.tuples));
        assert!(read_entry(&f, "k2").is_none());
        std::fs::write(&f, "{not json").unwrap();
        assert!(read_entry(&f, "k1").is_none());
    }
}
