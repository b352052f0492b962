//! One run of the pipeline: prepare (reason, place, plan, scene), each selected wall's record
//! taken from the cache or simulated (and stored), the verdicts reasoned once over the
//! prepared facts and every record. `simulate`, `watch`, `compare`, `diff`, `check`,
//! `annotate` and `why` all run through it; with or without a cache the result is the same.

use super::prepare::{Prepared, prepare, prepare_named_walls};
use crate::cache::key::{build_id, wall_key};
use crate::cache::{Cache, CacheCounts, Need, Shard, ShardRun, look_up, store};
use crate::cell::Cell;
use crate::frame::{Ask, Facts, RuleLimits};
use crate::ifc::Model;
use crate::sim::{
    SimError, SimOptions, Simulation, WallRecord, check_options, records_facts, run_walls,
    select_walls,
};

/// Reports (wall name, elements done, elements) as walls progress.
pub type Progress<'p> = dyn Fn(&str, usize, usize) + Sync + 'p;

/// What a run reads: the model, the cell, the options, and optionally a cache.
pub struct Run<'a> {
    pub model: &'a Model,
    /// The model's name in the scene and the report (its file name).
    pub model_name: &'a str,
    pub cell: &'a Cell,
    pub options: &'a SimOptions,
    /// Bounds on the rule base (the CLI reads them from the environment).
    pub limits: RuleLimits,
    pub cache: Option<&'a Cache>,
    /// What the cache must hand back of each wall.
    pub need: Need,
    pub progress: &'a Progress<'a>,
}

/// What the cache gave a run that must not simulate.
pub enum FromCache {
    /// Every selected wall was there: the simulation.
    Whole(Box<Simulation>),
    /// Some wall was not: the run as prepared.
    Missing(Box<Prepared>),
}

/// A run's walls: (key piece, cache key) of each selected wall, in plan order; the cache key
/// is empty when the run has no cache.
type Keyed = Vec<(String, String)>;

impl<'a> Run<'a> {
    /// A run of `model` in `cell` named "model", without a cache, with the default bounds.
    pub fn new(model: &'a Model, cell: &'a Cell, options: &'a SimOptions) -> Run<'a> {
        Run {
            model,
            model_name: "model",
            cell,
            options,
            limits: RuleLimits::default(),
            cache: None,
            need: Need::Records,
            progress: &|_, _, _| {},
        }
    }

    pub fn named(self, model_name: &'a str) -> Run<'a> {
        Run { model_name, ..self }
    }

    pub fn limits(self, limits: RuleLimits) -> Run<'a> {
        Run { limits, ..self }
    }

    pub fn cache(self, cache: Option<&'a Cache>) -> Run<'a> {
        Run { cache, ..self }
    }

    pub fn need(self, need: Need) -> Run<'a> {
        Run { need, ..self }
    }

    pub fn progress(self, progress: &'a Progress<'a>) -> Run<'a> {
        Run { progress, ..self }
    }

    /// The model and cell reasoned, placed and planned for this run.
    pub fn prepare(&self) -> Result<Prepared, SimError> {
        check_options(self.options)?;
        prepare(
            self.model,
            self.model_name,
            self.cell,
            &self.options.engine,
            &self.limits,
        )
    }

    /// Simulates the selected walls (each from the cache when it holds it) and reasons the
    /// verdicts. The counts are None without a cache.
    pub fn simulate(&self) -> Result<(Simulation, Option<CacheCounts>), SimError> {
        let prepared = self.prepare()?;
        let walls = self.keyed(&prepared)?;
        let (records, counts) = self.records(&prepared, &walls)?;
        let sim = self.verdicts(prepared, records)?;
        Ok((sim, self.cache.map(|_| counts)))
    }

    /// The simulation when the cache holds every selected wall; otherwise the prepared run
    /// (nothing is simulated).
    pub fn from_cache(&self) -> Result<FromCache, SimError> {
        let prepared = self.prepare()?;
        let Some(cache) = self.cache else {
            return Ok(FromCache::Missing(Box::new(prepared)));
        };
        let walls = self.keyed(&prepared)?;
        let (found, misses, _) = look_up(cache, &walls, self.need);
        if !misses.is_empty() {
            return Ok(FromCache::Missing(Box::new(prepared)));
        }
        let records = found.into_iter().flatten().collect();
        Ok(FromCache::Whole(Box::new(
            self.verdicts(prepared, records)?,
        )))
    }

    /// Simulates the walls of one shard that the cache lacks, and stores them.
    pub fn shard(&self, cache: &Cache, shard: Shard) -> Result<ShardRun, SimError> {
        let prepared = self.prepare()?;
        let run = Run {
            cache: Some(cache),
            ..*self
        };
        let walls = run.keyed(&prepared)?;
        let mine: Keyed = walls
            .iter()
            .filter(|(_, key)| shard.holds(key))
            .cloned()
            .collect();
        let (_, misses, mut counts) = look_up(cache, &mine, self.need);
        counts.computed = run.simulate_misses(&prepared, &misses)?.len();
        let wall_ids = mine
            .iter()
            .filter_map(|(k, _)| prepared.plan.walls.iter().find(|w| &w.key == k))
            .map(|w| w.id.clone())
            .collect();
        Ok(ShardRun {
            shard: shard.to_string(),
            walls: wall_ids,
            other_walls: walls.len() - mine.len(),
            cache: counts,
        })
    }

    /// The `rules/sim.dl` facts of the walls `options.walls` names (`why` explains an element
    /// from its wall's), each wall's record read from the cache under the key `simulate`
    /// gives it, else simulated and stored: one cache, one key, so `why` after `simulate` (or
    /// the other way round) simulates nothing again. The walls are planned from their
    /// containers alone (`prepare_named_walls`). `whole`, when given, are the model's and the
    /// cell's facts (`whole_facts`), so they are not built again.
    pub fn wall_facts(&self, whole: Option<&Facts>) -> Result<(Facts, CacheCounts), SimError> {
        let prepared =
            prepare_named_walls(self.model, self.cell, self.options, &self.limits, whole)?;
        let walls = self.keyed(&prepared)?;
        let (records, counts) = self.records(&prepared, &walls)?;
        Ok((records_facts(&records), counts))
    }

    /// The selected walls of a prepared run, with their cache keys when there is a cache.
    fn keyed(&self, prepared: &Prepared) -> Result<Keyed, SimError> {
        let (scene, plan) = (&prepared.scene, &prepared.plan);
        let build = build_id();
        let mut walls = Vec::new();
        for key_piece in select_walls(plan, &self.options.walls)? {
            let (Some(scene_wall), Some(plan_wall)) = (
                scene.walls.iter().find(|w| w.id == key_piece),
                plan.walls.iter().find(|w| w.key == key_piece),
            ) else {
                // The executor skips such a wall too.
                continue;
            };
            let key = match self.cache {
                Some(_) => {
                    let pieces: Vec<_> = scene_wall
                        .pieces
                        .iter()
                        .filter_map(|id| scene.pieces.iter().find(|p| &p.id == id))
                        .collect();
                    wall_key(
                        build,
                        self.cell,
                        self.options,
                        scene_wall,
                        &pieces,
                        plan_wall,
                    )
                }
                None => String::new(),
            };
            walls.push((key_piece, key));
        }
        Ok(walls)
    }

    /// Every selected wall's record, in wall order: from the cache, else simulated (and
    /// stored).
    fn records(
        &self,
        prepared: &Prepared,
        walls: &Keyed,
    ) -> Result<(Vec<WallRecord>, CacheCounts), SimError> {
        let (found, misses, mut counts) = match self.cache {
            Some(cache) => look_up(cache, walls, self.need),
            None => (
                walls.iter().map(|_| None).collect(),
                walls.clone(),
                CacheCounts::default(),
            ),
        };
        let mut computed = self.simulate_misses(prepared, &misses)?;
        counts.computed = computed.len();
        let records = in_wall_order(found, &mut computed, walls)?;
        Ok((records, counts))
    }

    /// Simulates the missing walls of a prepared run and stores their records.
    fn simulate_misses(
        &self,
        prepared: &Prepared,
        misses: &Keyed,
    ) -> Result<Vec<WallRecord>, SimError> {
        if misses.is_empty() {
            return Ok(Vec::new());
        }
        let keys: Vec<String> = misses.iter().map(|(k, _)| k.clone()).collect();
        let records = run_walls(
            &prepared.scene,
            &prepared.plan,
            self.cell,
            self.options,
            &keys,
            self.progress,
        )?;
        if let Some(cache) = self.cache {
            for r in &records {
                if let Some((_, key)) = misses.iter().find(|(k, _)| k == &r.wall) {
                    store(cache, key, r, self.need);
                }
            }
        }
        Ok(records)
    }

    /// The simulation of `records` (in wall order): their facts added to the prepared facts
    /// and reasoned over with the rule base, once.
    fn verdicts(
        &self,
        prepared: Prepared,
        records: Vec<WallRecord>,
    ) -> Result<Simulation, SimError> {
        let Prepared {
            mut facts,
            scene,
            plan,
            panelized,
            model_plan,
        } = prepared;
        let sim_facts = records_facts(&records);
        facts.extend(sim_facts.clone());
        let reasoned = Ask::new(&self.options.engine)
            .within(self.limits)
            .over(&facts)?;
        Ok(Simulation {
            scene,
            plan,
            records,
            facts: sim_facts,
            reasoned,
            panelized,
            model_plan,
        })
    }
}

/// The walls' records in their order: the cached ones `found`, the others taken from
/// `computed`.
fn in_wall_order(
    found: Vec<Option<WallRecord>>,
    computed: &mut Vec<WallRecord>,
    walls: &Keyed,
) -> Result<Vec<WallRecord>, SimError> {
    let mut records = Vec::with_capacity(found.len());
    for (record, (key_piece, _)) in found.into_iter().zip(walls) {
        match record {
            Some(r) => records.push(r),
            None => {
                let at = computed.iter().position(|r| &r.wall == key_piece);
                let r = at.map(|i| computed.swap_remove(i)).ok_or_else(|| {
                    SimError::Option(format!("wall {key_piece} was not simulated"))
                })?;
                records.push(r);
            }
        }
    }
    Ok(records)
}

/// Simulates the walls of a model in a cell, without a cache: `Run::new(…).simulate()`.
pub fn simulate(model: &Model, cell: &Cell, options: &SimOptions) -> Result<Simulation, SimError> {
    Ok(Run::new(model, cell, options).simulate()?.0)
}
