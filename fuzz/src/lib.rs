//! One function per fuzz target: each feeds arbitrary bytes to a reader of framewright the way
//! the command line does and only returns; a panic, an abort or a run past AFL's time limit is
//! the finding. `tests/fuzz_regressions.rs` in the crate root replays kept inputs through the
//! same calls.

use framewright::cell::{Cell, Robot, RobotMeta, Tool};
use framewright::ifc::Model;
use framewright::logic::{Engine, Limits, Options, Program};
use framewright::report::inspect::InspectReport;
use framewright::step::ReadOptions;
use std::path::Path;
use std::sync::Arc;

/// STEP reader and IFC layer: header, index, units, placements, products and shapes.
pub fn ifc(data: &[u8]) {
    match Model::from_bytes("fuzz.ifc", data.to_vec(), &ReadOptions::default()) {
        Ok(model) => {
            // What `inspect` prints of it, as text and as JSON.
            let report = InspectReport::new(&model);
            let _ = report.to_text();
            let _ = report.write_json(&mut std::io::sink());
        }
        Err(e) => {
            let _ = e.to_string();
        }
    }
}

/// Rule language front end: lexer, parser and checker, and the rendering of its diagnostics
/// (spans into arbitrary UTF-8).
pub fn rules_front(data: &[u8]) {
    let text = String::from_utf8_lossy(data);
    if let Err(d) = Program::parse_str("fuzz.dl", &text) {
        let _ = d.to_string();
    }
}

/// Bounds for fuzzed programs: small enough that every input ends well inside AFL's time limit.
pub const RUN_LIMITS: Limits = Limits {
    max_tuples: 20_000,
    max_iterations: 200,
    max_steps: 2_000_000,
};

/// The interpreter on a checked program (with provenance, as `why` runs it).
pub fn rules_run(data: &[u8]) {
    let text = String::from_utf8_lossy(data);
    let Ok(program) = Program::parse_str("fuzz.dl", &text) else {
        return;
    };
    let names: Vec<String> = program.relations.iter().map(|r| r.name.clone()).collect();
    let mut engine = Engine::new(
        Arc::new(program),
        Options {
            provenance: true,
            limits: RUN_LIMITS,
        },
    );
    match engine.run() {
        Ok(_) => {
            for name in &names {
                if let Ok(tuples) = engine.relation(name) {
                    let arity = tuples.first().map_or(0, Vec::len);
                    let _ = framewright::logic::io::format_tuples(&tuples, "\t", arity);
                }
            }
        }
        Err(e) => {
            let _ = e.to_string();
        }
    }
}

/// Cell, tool and robot-metadata TOML; the first byte picks the reader so one corpus covers all.
pub fn cell_toml(data: &[u8]) {
    let Some((&which, rest)) = data.split_first() else {
        return;
    };
    let text = String::from_utf8_lossy(rest);
    let message = match which % 3 {
        0 => Cell::from_toml(Path::new("fuzz/cell.toml"), &text).err(),
        1 => Tool::parse(Path::new("fuzz/tool.toml"), &text).err(),
        _ => RobotMeta::parse(Path::new("fuzz/robot.toml"), &text).err(),
    };
    if let Some(e) = message {
        let _ = e.to_string();
    }
}

/// URDF loader: XML, the kinematic tree, and forward kinematics at the home pose.
pub fn urdf(data: &[u8]) {
    let text = String::from_utf8_lossy(data);
    match Robot::from_urdf_str(Path::new("fuzz.urdf"), &text, RobotMeta::default()) {
        Ok(robot) => {
            let _ = robot.fk_all(&robot.home());
        }
        Err(e) => {
            let _ = e.to_string();
        }
    }
}
