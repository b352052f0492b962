//! The executor: simulates the framing and nailing of every wall in rapier and feeds what
//! happened back into the rules (`rules/sim.dl` facts → `rules/verdicts.dl` verdicts).
//!
//! Each wall runs in its own world (the study frames walls one at a time), so walls run in
//! parallel and a wall's result depends only on its own pieces and the cell: same inputs,
//! same bytes out.

mod executor;
mod motion;
mod physics;
pub mod planner;
mod reach;
pub mod record;

pub use executor::NailPlan;
pub use motion::{JointMove, LinearMove, Profile};
pub use record::WallRecord;

use crate::cell::Cell;
use crate::frame::plan::Plan;
use crate::frame::{Facts, FrameError, Reasoned, RuleEngine};
use crate::ifc::Model;
use crate::world::{Scene, SceneWall, WorldError};

/// How to simulate.
#[derive(Debug, Clone)]
pub struct SimOptions {
    /// Walls to run, by id or name; empty = every wall.
    pub walls: Vec<String>,
    /// Physics time step, s.
    pub dt: f64,
    /// Fraction of the robot's joint speed and acceleration limits its joint moves use.
    pub speed: f64,
    /// The rule base for reasoning and verdicts.
    pub engine: RuleEngine,
    /// When rapier steps: every time step, or only while something can move on its own.
    pub stepping: Stepping,
    /// The bound on simulated time per wall, s: a wall still running past it stops the run
    /// with an error (`SimError::TimeLimit`).
    pub max_seconds_per_wall: f64,
}

/// The default physics time step, s (240 Hz).
pub const DEFAULT_DT: f64 = 1.0 / 240.0;

/// A piece is released this far above its framing target and drops into place (m).
pub const RELEASE_GAP: f64 = 0.001;

/// How the executor advances time.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, clap::ValueEnum)]
pub enum Stepping {
    /// rapier steps at every time step of the run.
    Fixed,
    /// rapier steps only while lumber is loose (running belts, settling, a robot touching a
    /// loose piece); while nothing can move on its own the robot's motion is advanced without
    /// the solver, its contacts found by collision queries.
    #[default]
    Events,
}

impl Stepping {
    pub fn name(self) -> &'static str {
        match self {
            Stepping::Fixed => "fixed",
            Stepping::Events => "events",
        }
    }
}

impl Default for SimOptions {
    fn default() -> Self {
        SimOptions {
            walls: Vec::new(),
            dt: DEFAULT_DT,
            speed: 1.0,
            engine: RuleEngine::Compiled,
            stepping: Stepping::Events,
            max_seconds_per_wall: DEFAULT_MAX_SIM_SECONDS_PER_WALL,
        }
    }
}

#[derive(Debug, thiserror::Error)]
pub enum SimError {
    #[error(transparent)]
    World(#[from] WorldError),
    #[error(transparent)]
    Frame(#[from] FrameError),
    #[error("no wall `{name}` in the model; its walls are: {known}")]
    UnknownWall { name: String, known: String },
    #[error("the model has no walls to simulate{reason}")]
    NoWalls { reason: String },
    #[error("bad simulation option: {0}")]
    Option(String),
    #[error(
        "{wall} did not finish within the bound of {limit} s of simulated time per wall (it had run {reached:.1} s); raise the bound with {ENV_MAX_SIM_SECONDS_PER_WALL}=SECONDS if the wall really takes longer"
    )]
    TimeLimit {
        wall: String,
        limit: f64,
        reached: f64,
    },
}

/// The environment variable with which the CLI sets the bound on simulated time per wall (s).
pub const ENV_MAX_SIM_SECONDS_PER_WALL: &str = "FRAMEWRIGHT_MAX_SIM_SECONDS_PER_WALL";
/// The bound's default: 10 h of simulated time, some ten times the longest wall of the
/// 3-storey test model.
pub const DEFAULT_MAX_SIM_SECONDS_PER_WALL: f64 = 36_000.0;

/// A finished simulation.
pub struct Simulation {
    pub scene: Scene,
    /// One wall per panel the cell builds (a wall that fits is one).
    pub plan: Plan,
    /// One record per simulated wall, in wall order.
    pub records: Vec<WallRecord>,
    /// The `rules/sim.dl` facts of every record.
    pub facts: Facts,
    /// Model, cell and simulation facts reasoned with the rule base (verdicts included).
    pub reasoned: Reasoned,
    /// The model cut into panels, when a wall was split: the pieces the scene, the plan and
    /// the records name (cut plates, added studs).
    pub panelized: Option<Model>,
    /// The plan of the model's own walls, each with its panels, when a wall was split
    /// (otherwise `plan` is that plan).
    pub model_plan: Option<Plan>,
}

impl Simulation {
    /// The model the simulation's pieces come from: the panelized one, else `model`.
    pub fn model<'a>(&'a self, model: &'a Model) -> &'a Model {
        self.panelized.as_ref().unwrap_or(model)
    }
}

/// The `rules/sim.dl` facts of some walls' records, in their order.
pub fn records_facts(records: &[WallRecord]) -> Facts {
    let mut facts = Facts::default();
    for r in records {
        facts.extend(r.facts());
    }
    facts
}

/// Runs the walls `selected` (keys, in plan order) of a planned scene in parallel: one record
/// per wall, in their order.
pub fn run_walls(
    scene: &Scene,
    plan: &Plan,
    cell: &Cell,
    options: &SimOptions,
    selected: &[String],
    progress: &(dyn Fn(&str, usize, usize) + Sync),
) -> Result<Vec<WallRecord>, SimError> {
    check_options(options)?;
    let limit = options.max_seconds_per_wall;
    // The rules name a wall by its key piece; the scene does too.
    let walls: Vec<&SceneWall> = selected
        .iter()
        .filter_map(|key| scene.walls.iter().find(|w| &w.id == key))
        .collect();
    let run_wall = |scene_wall: &&SceneWall| -> Option<Result<WallRecord, SimError>> {
        let plan_wall = plan.walls.iter().find(|w| w.key == scene_wall.id)?;
        let pieces = scene_wall
            .pieces
            .iter()
            .filter_map(|id| scene.pieces.iter().find(|p| &p.id == id))
            .collect();
        let nails = NailPlan::from_targets(&plan_wall.nailing_targets, &plan_wall.frame);
        let report = |done: usize, total: usize| progress(&plan_wall.name, done, total);
        let run = executor::WallRun::new(cell, options, scene_wall, pieces, &report)
            .with_time_limit(limit)
            .run(&nails);
        Some(run.map_err(|reached| SimError::TimeLimit {
            wall: format!("{} ({})", plan_wall.name, plan_wall.id),
            limit,
            reached,
        }))
    };
    largest_first(&walls, |w| w.pieces.len(), run_wall)
        .into_iter()
        .flatten()
        .collect()
}

/// `run` on every item on all threads, the costliest first (each thread takes the next item
/// when it is done), so that no long job starts last while the other threads idle; the
/// results come back in the items' order.
fn largest_first<T: Sync, R: Send>(
    items: &[T],
    cost: impl Fn(&T) -> usize,
    run: impl Fn(&T) -> R + Sync,
) -> Vec<R> {
    use rayon::prelude::*;
    use std::sync::Mutex;
    use std::sync::atomic::{AtomicUsize, Ordering};
    let mut order: Vec<usize> = (0..items.len()).collect();
    order.sort_by_key(|&i| (std::cmp::Reverse(cost(&items[i])), i));
    let next = AtomicUsize::new(0);
    let results: Vec<Mutex<Option<R>>> = items.iter().map(|_| Mutex::new(None)).collect();
    // One taker per thread; a taker whose thread is busy elsewhere (a nested call) starts
    // late or not at all, and the others take its share.
    (0..rayon::current_num_threads())
        .into_par_iter()
        .for_each(|_| {
            while let Some(&i) = order.get(next.fetch_add(1, Ordering::Relaxed)) {
                let r = run(&items[i]);
                *results[i].lock().unwrap_or_else(|e| e.into_inner()) = Some(r);
            }
        });
    results
        .into_iter()
        .map(|m| {
            m.into_inner()
                .unwrap_or_else(|e| e.into_inner())
                .expect("every item runs once")
        })
        .collect()
}

/// The option checks of `simulate`: a time step in (0, 0.05] s, a speed fraction in (0, 1], a
/// time bound above 0 s.
pub fn check_options(options: &SimOptions) -> Result<(), SimError> {
    if !(options.dt > 0.0 && options.dt <= 0.05) {
        return Err(SimError::Option(format!(
            "the time step must be in (0, 0.05] s, not {}",
            options.dt
        )));
    }
    if !(options.speed > 0.0 && options.speed <= 1.0) {
        return Err(SimError::Option(format!(
            "the speed fraction must be in (0, 1], not {}",
            options.speed
        )));
    }
    if options.max_seconds_per_wall.is_nan() || options.max_seconds_per_wall <= 0.0 {
        return Err(SimError::Option(format!(
            "the bound on simulated time per wall must be above 0 s, not {}",
            options.max_seconds_per_wall
        )));
    }
    Ok(())
}

/// The keys (rule-base wall ids) of the walls to run: all, or those named (by id, name or
/// key), in plan order.
pub fn select_walls(plan: &Plan, wanted: &[String]) -> Result<Vec<String>, SimError> {
    let with_pieces: Vec<&crate::frame::plan::Wall> = plan.walls.iter().collect();
    if with_pieces.is_empty() {
        let reason = if plan.warnings.is_empty() {
            String::new()
        } else {
            format!(": {}", plan.warnings.join("; "))
        };
        return Err(SimError::NoWalls { reason });
    }
    if wanted.is_empty() {
        return Ok(with_pieces.iter().map(|w| w.key.clone()).collect());
    }
    let mut ids = Vec::new();
    for name in wanted {
        // A wall by its id, name or key piece; else every panel of a whole wall so named.
        let exact: Vec<&&crate::frame::plan::Wall> = with_pieces
            .iter()
            .filter(|w| &w.id == name || &w.name == name || &w.key == name)
            .take(1)
            .collect();
        let found = if exact.is_empty() {
            with_pieces
                .iter()
                .filter(|w| {
                    w.panel.as_ref().is_some_and(|p| {
                        &p.wall_key == name || &p.wall_id == name || &p.wall_name == name
                    })
                })
                .collect()
        } else {
            exact
        };
        if found.is_empty() {
            return Err(SimError::UnknownWall {
                name: name.clone(),
                known: with_pieces
                    .iter()
                    .map(|w| format!("{} ({})", w.name, w.id))
                    .collect::<Vec<_>>()
                    .join(", "),
            });
        }
        for wall in found {
            if !ids.contains(&wall.key) {
                ids.push(wall.key.clone());
            }
        }
    }
    Ok(plan
        .walls
        .iter()
        .filter(|w| ids.contains(&w.key))
        .map(|w| w.key.clone())
        .collect())
}

#[cfg(test)]
mod tests {
    #[test]
    fn largest_first_returns_in_item_order_and_starts_with_the_costliest() {
        let items = [3usize, 9, 1, 9, 4];
        let started = std::sync::Mutex::new(Vec::new());
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(1)
            .build()
            .expect("a pool");
        let out = pool.install(|| {
            super::largest_first(
                &items,
                |x| *x,
                |x| {
                    started.lock().expect("not poisoned").push(*x);
                    x * 10
                },
            )
        });
        assert_eq!(out, vec![30, 90, 10, 90, 40]);
        // One thread takes them costliest first (ties in item order).
        assert_eq!(
            started.into_inner().expect("not poisoned"),
            vec![9, 9, 4, 3, 1]
        );
        // Many threads: every item once, results in order.
        let many: Vec<usize> = (0..200).collect();
        let out = super::largest_first(&many, |x| x % 7, |x| x + 1);
        assert_eq!(out, (1..=200).collect::<Vec<usize>>());
    }
}
