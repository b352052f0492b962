//! Robot programs of a simulated assembly: per wall (or panel) the motion the executor ran
//! and validated, as ABB RAPID or KUKA KRL a controller loads. The sequence and every target
//! are exact (the simulated joints, the TCP poses in the wall's own frame); the work object,
//! the tool data and the signal names are templates to calibrate on the real cell.
//!
//! `routine` cuts a wall's recorded steps down to what the simulation completed; `rapid` and
//! `krl` write it out; `conf` gives the configuration data; `text` keeps names inside comments.

pub mod conf;
pub mod krl;
pub mod rapid;
pub mod routine;
pub mod text;

use crate::atomic::write_atomically;
use crate::cell::Cell;
use crate::report::simulate::SimReport;
use crate::sim::Simulation;
use nalgebra::Isometry3;
use routine::{Routine, RoutineInput};
use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// A controller language.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum Language {
    /// ABB RAPID: one `.mod` per wall.
    Rapid,
    /// KUKA KRL: a `.src` and a `.dat` per wall.
    Krl,
}

#[derive(Debug, thiserror::Error)]
pub enum ProgramError {
    #[error("the cell's {0}")]
    Signal(String),
    #[error(
        "the robot {robot} has {dof} axes; RAPID and KRL programs are written for six-axis arms"
    )]
    Axes { robot: String, dof: usize },
    #[error("{path}: cannot write the program: {source}")]
    Write {
        path: PathBuf,
        source: std::io::Error,
    },
}

/// One file of a program.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ProgramFile {
    pub file_name: String,
    pub text: String,
}

/// One wall's program as written: its files and what it keeps and leaves out.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct WallFiles {
    pub files: Vec<ProgramFile>,
    /// `pieces framed: N (left out: K); nails fired: …`
    pub counts: String,
}

/// One wall's program before it is written in a language.
pub struct WallProgram<'a> {
    pub routine: Routine,
    pub cell: &'a Cell,
    /// The module / `DEF` name (an identifier valid in both languages).
    pub name: String,
    /// The wall frame in the controller's world: the robot's base with the carriage at home.
    pub wall_in_world: Isometry3<f64>,
    /// What the header says besides the counts: model, cell, tool, wall.
    pub about: Vec<String>,
}

impl WallProgram<'_> {
    /// The data name of each TCP the routine uses: `prefix1`, `prefix2`, … in TCP-name order.
    pub fn tool_names(&self, prefix: &str) -> BTreeMap<&str, String> {
        self.routine
            .tcps
            .iter()
            .enumerate()
            .map(|(k, tcp)| (tcp.as_str(), format!("{prefix}{}", k + 1)))
            .collect()
    }

    /// Each signal the routine uses as the cell's `[io]` gives it (None: not given), made a
    /// language's signal by `pick` (Err: the other language's kind).
    pub fn signals<T>(
        &self,
        pick: impl Fn(routine::SignalRole, Option<&crate::cell::io::Signal>) -> Result<T, ProgramError>,
    ) -> Result<BTreeMap<routine::SignalRole, T>, ProgramError> {
        let io = &self.cell.io;
        self.routine
            .signals
            .iter()
            .map(|&role| {
                let given = io
                    .signals()
                    .into_iter()
                    .find(|(key, _)| *key == role.key())
                    .and_then(|(_, s)| s);
                pick(role, given).map(|signal| (role, signal))
            })
            .collect()
    }

    /// The header comment's lines.
    pub fn header_lines(&self) -> Vec<String> {
        let mut lines = vec![format!(
            "framewright {} robot program",
            env!("CARGO_PKG_VERSION")
        )];
        lines.extend(self.about.iter().cloned());
        lines.push(self.routine.counts());
        lines.push(
            "Exact: the sequence and every target, as simulated and checked (targets in the wall frame; mm, degrees)."
                .into(),
        );
        lines.push(
            "Templates: the work object (the wall as laid on the table), the tool data and the I/O signals must be calibrated on the real cell before running."
                .into(),
        );
        lines
    }
}

/// Identifier length both languages accept (KRL's limit).
const NAME_MAX: usize = 24;

/// The programs of every simulated wall, in wall order: one entry per wall, its files.
pub fn programs(
    sim: &Simulation,
    report: &SimReport,
    cell: &Cell,
    model_name: &str,
    language: Language,
) -> Result<Vec<WallFiles>, ProgramError> {
    let framed: BTreeSet<String> = report
        .elements
        .iter()
        .filter(|e| e.framing.status == "framed")
        .map(|e| e.id.clone())
        .collect();
    let reasons: BTreeMap<String, String> = report
        .elements
        .iter()
        .filter(|e| e.framing.status != "framed")
        .map(|e| {
            let why = e.framing.reasons.first().map_or_else(
                || format!("framing {}", e.framing.status),
                |r| r.message.clone(),
            );
            (e.id.clone(), why)
        })
        .collect();
    if cell.robot.dof() != 6 {
        return Err(ProgramError::Axes {
            robot: cell.robot.name.clone(),
            dof: cell.robot.dof(),
        });
    }
    let mut taken = BTreeSet::new();
    let mut out = Vec::new();
    for (k, record) in sim.records.iter().enumerate() {
        let Some(scene_wall) = sim.scene.walls.iter().find(|w| w.id == record.wall) else {
            continue;
        };
        let plan_wall = sim.plan.walls.iter().find(|w| w.key == record.wall);
        let wall_in_world = scene_wall.wall_to_robot;
        let fed: BTreeSet<String> = record.fed.iter().map(|(id, _)| id.clone()).collect();
        let routine = routine::routine(&RoutineInput {
            cell,
            record,
            wall_in_cell: cell.robot_base * wall_in_world,
            framed: &framed,
            fed: &fed,
            reasons: &reasons,
        });
        let (id, label) = plan_wall.map_or_else(
            || (record.wall.clone(), record.wall.clone()),
            |w| (w.id.clone(), format!("{} ({})", w.name, w.id)),
        );
        let name = program_name(&id, k + 1, &mut taken);
        let program = WallProgram {
            routine,
            cell,
            name,
            wall_in_world,
            about: vec![
                format!("wall: {label}"),
                format!("model: {model_name}"),
                format!(
                    "cell: {}; robot: {}; tool: {}",
                    cell.name, cell.robot.name, cell.tool.name
                ),
            ],
        };
        let files = match language {
            Language::Rapid => vec![rapid::module(&program)?],
            Language::Krl => krl::files(&program)?.to_vec(),
        };
        out.push(WallFiles {
            files,
            counts: program.routine.counts(),
        });
    }
    Ok(out)
}

/// The program's name: `fw_` and the wall id where it is one framewright gave (`W1`,
/// `W1-P2`), else `fw_wallK`; unique among the walls.
fn program_name(id: &str, k: usize, taken: &mut BTreeSet<String>) -> String {
    let generated = id.starts_with('W')
        && id.len() <= NAME_MAX - 3
        && id[1..]
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || c == '-');
    let mut name = if generated {
        text::identifier("fw_", id, NAME_MAX)
    } else {
        format!("fw_wall{k}")
    };
    // File names must not collide (a wall `Wall3` and the third wall's fallback name).
    let mut n = k;
    while taken.contains(&name.to_ascii_lowercase()) {
        name = format!("fw_wall{n}");
        n += 1;
    }
    taken.insert(name.to_ascii_lowercase());
    name
}

/// Writes the files into `dir` (created if need be), each atomically.
pub fn write_files(dir: &Path, files: &[ProgramFile]) -> Result<(), ProgramError> {
    std::fs::create_dir_all(dir).map_err(|source| ProgramError::Write {
        path: dir.to_path_buf(),
        source,
    })?;
    for file in files {
        let path = dir.join(&file.file_name);
        write_atomically(&path, file.text.as_bytes())
            .map_err(|source| ProgramError::Write { path, source })?;
    }
    Ok(())
}
