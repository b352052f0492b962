//! `simulate` through the cache: the model is reasoned as always (walls, targets, scene),
//! each selected wall's record is looked up by its key, only the misses are simulated, and
//! the verdicts are reasoned over all records. The result is the one an uncached run gives.

use super::key::{build_id, wall_key};
use super::store::{Cache, Lookup};
use crate::cell::Cell;
use crate::frame::Facts;
use crate::ifc::Model;
use crate::sim::{
    Prepared, SimError, SimOptions, Simulation, WallRecord, check_options, prepare,
    prepare_named_walls, records_facts, run_prepared, select_walls,
};
use serde::Serialize;

/// How many walls were simulated and how many came from the cache.
#[derive(Debug, Clone, Copy, Default, Serialize, PartialEq, Eq)]
pub struct CacheCounts {
    pub computed: usize,
    pub cached: usize,
    /// Entries found torn, corrupt or stale, and simulated again (included in `computed`).
    pub rejected: usize,
}

/// Shard `index` of `count` (1-based, as `--shard 2/3` writes it).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Shard {
    pub index: u64,
    pub count: u64,
}

impl std::str::FromStr for Shard {
    type Err = String;
    fn from_str(s: &str) -> Result<Shard, String> {
        let bad = || format!("`{s}` is not a shard: write K/N with 1 <= K <= N, e.g. 2/3");
        let (k, n) = s.split_once('/').ok_or_else(bad)?;
        let index: u64 = k.trim().parse().map_err(|_| bad())?;
        let count: u64 = n.trim().parse().map_err(|_| bad())?;
        if index == 0 || index > count {
            return Err(bad());
        }
        Ok(Shard { index, count })
    }
}

impl std::fmt::Display for Shard {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}/{}", self.index, self.count)
    }
}

impl Shard {
    /// Whether a wall with this key belongs to the shard: its key's first 8 bytes, modulo the
    /// shard count. Keys are content hashes, so shards get about equal numbers of walls.
    pub fn holds(&self, key: &str) -> bool {
        let head = u64::from_str_radix(&key[..16.min(key.len())], 16).unwrap_or(0);
        head % self.count == self.index - 1
    }
}

/// What a shard run did.
#[derive(Debug, Serialize)]
pub struct ShardRun {
    pub shard: String,
    /// Wall ids (as the plan names them) of this shard, in plan order.
    pub walls: Vec<String>,
    /// Walls of the other shards.
    pub other_walls: usize,
    pub cache: CacheCounts,
}

/// A prepared run and the cache keys of its selected walls.
struct Keyed {
    prepared: Prepared,
    /// (wall key piece, cache key) of the selected walls, in plan order.
    walls: Vec<(String, String)>,
}

fn prepare_keyed(
    model: &Model,
    model_name: &str,
    cell: &Cell,
    options: &SimOptions,
) -> Result<Keyed, SimError> {
    check_options(options)?;
    let prepared = prepare(model, model_name, cell, &options.engine)?;
    key_walls(prepared, cell, options)
}

/// The cache keys of the walls `options.walls` selects of a prepared run.
fn key_walls(prepared: Prepared, cell: &Cell, options: &SimOptions) -> Result<Keyed, SimError> {
    let (scene, plan) = (&prepared.scene, &prepared.plan);
    let build = build_id();
    let mut walls = Vec::new();
    for key_piece in select_walls(plan, &options.walls)? {
        let (Some(scene_wall), Some(plan_wall)) = (
            scene.walls.iter().find(|w| w.id == key_piece),
            plan.walls.iter().find(|w| w.key == key_piece),
        ) else {
            // The executor skips such a wall too.
            continue;
        };
        let pieces: Vec<_> = scene_wall
            .pieces
            .iter()
            .filter_map(|id| scene.pieces.iter().find(|p| &p.id == id))
            .collect();
        let key = wall_key(build, cell, options, scene_wall, &pieces, plan_wall);
        walls.push((key_piece, key));
    }
    Ok(Keyed { prepared, walls })
}

/// What a cached run must hand back of each wall.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Need {
    /// The record: verdicts, times, contacts (what `--json` and the rules read).
    Records,
    /// The record and the pose trace the report animates; a wall whose trace the cache lacks
    /// is simulated again, and its trace stored.
    Traces,
}

/// Simulates the model, reading and filling the cache.
pub fn simulate_cached(
    model: &Model,
    model_name: &str,
    cell: &Cell,
    options: &SimOptions,
    cache: &Cache,
    progress: &(dyn Fn(&str, usize, usize) + Sync),
) -> Result<(Simulation, CacheCounts), SimError> {
    simulate_cached_for(
        Need::Records,
        model,
        model_name,
        cell,
        options,
        cache,
        progress,
    )
}

/// Simulates the model, reading and filling the cache, with what `need` asks of each wall.
pub fn simulate_cached_for(
    need: Need,
    model: &Model,
    model_name: &str,
    cell: &Cell,
    options: &SimOptions,
    cache: &Cache,
    progress: &(dyn Fn(&str, usize, usize) + Sync),
) -> Result<(Simulation, CacheCounts), SimError> {
    let keyed = prepare_keyed(model, model_name, cell, options)?;
    let (found, misses, mut counts) = look_up(cache, &keyed.walls, need);
    let mut computed = simulate_misses(
        &keyed.prepared,
        cell,
        options,
        Some(cache),
        &misses,
        need,
        progress,
    )?;
    counts.computed = computed.len();
    let records = in_wall_order(found, &mut computed, &keyed.walls)?;
    let sim = Simulation::from_prepared(keyed.prepared, records, &options.engine)?;
    Ok((sim, counts))
}

/// The `rules/sim.dl` facts of the walls `options.walls` names (`why` explains an element
/// from its wall's), each wall's record read from the cache under the key `simulate` gives
/// it, else simulated and stored: one cache, one key, so `why` after `simulate` (or the
/// other way round) simulates nothing again, and whatever misses `simulate`'s entry misses
/// this one. The walls are planned from their containers alone (`sim::prepare_named_walls`).
pub fn wall_facts_cached(
    model: &Model,
    cell: &Cell,
    options: &SimOptions,
    cache: Option<&Cache>,
) -> Result<(Facts, CacheCounts), SimError> {
    let prepared = prepare_named_walls(model, cell, options)?;
    let keyed = key_walls(prepared, cell, options)?;
    let (found, misses, mut counts) = match cache {
        Some(cache) => look_up(cache, &keyed.walls, Need::Records),
        None => (
            keyed.walls.iter().map(|_| None).collect(),
            keyed.walls.clone(),
            CacheCounts::default(),
        ),
    };
    let mut computed = simulate_misses(
        &keyed.prepared,
        cell,
        options,
        cache,
        &misses,
        Need::Records,
        &|_, _, _| {},
    )?;
    counts.computed = computed.len();
    let records = in_wall_order(found, &mut computed, &keyed.walls)?;
    Ok((records_facts(&records), counts))
}

/// The walls' records in their order: the cached ones `found`, the others taken from
/// `computed`.
fn in_wall_order(
    found: Vec<Option<WallRecord>>,
    computed: &mut Vec<WallRecord>,
    walls: &[(String, String)],
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

/// The simulation of the model when the cache holds every selected wall; None otherwise
/// (nothing is simulated).
pub fn cached_simulation(
    model: &Model,
    model_name: &str,
    cell: &Cell,
    options: &SimOptions,
    cache: &Cache,
) -> Result<Option<Simulation>, SimError> {
    let keyed = prepare_keyed(model, model_name, cell, options)?;
    let (found, misses, _) = look_up(cache, &keyed.walls, Need::Records);
    if !misses.is_empty() {
        return Ok(None);
    }
    let records = found.into_iter().flatten().collect();
    let sim = Simulation::from_prepared(keyed.prepared, records, &options.engine)?;
    Ok(Some(sim))
}

/// Simulates the walls of one shard that the cache lacks, and stores them.
pub fn simulate_shard(
    model: &Model,
    model_name: &str,
    cell: &Cell,
    options: &SimOptions,
    cache: &Cache,
    shard: Shard,
    progress: &(dyn Fn(&str, usize, usize) + Sync),
) -> Result<ShardRun, SimError> {
    let keyed = prepare_keyed(model, model_name, cell, options)?;
    let mine: Vec<(String, String)> = keyed
        .walls
        .iter()
        .filter(|(_, key)| shard.holds(key))
        .cloned()
        .collect();
    let (_, misses, mut counts) = look_up(cache, &mine, Need::Records);
    counts.computed = simulate_misses(
        &keyed.prepared,
        cell,
        options,
        Some(cache),
        &misses,
        Need::Records,
        progress,
    )?
    .len();
    let wall_ids = mine
        .iter()
        .filter_map(|(k, _)| keyed.prepared.plan.walls.iter().find(|w| &w.key == k))
        .map(|w| w.id.clone())
        .collect();
    Ok(ShardRun {
        shard: shard.to_string(),
        walls: wall_ids,
        other_walls: keyed.walls.len() - mine.len(),
        cache: counts,
    })
}

/// The cached record of each wall (None for a miss), the misses, and the counts so far.
/// With `Need::Traces` a wall counts as cached only when its trace is there too.
fn look_up(
    cache: &Cache,
    walls: &[(String, String)],
    need: Need,
) -> (Vec<Option<WallRecord>>, Vec<(String, String)>, CacheCounts) {
    let mut counts = CacheCounts::default();
    let mut found = Vec::with_capacity(walls.len());
    let mut misses = Vec::new();
    for (key_piece, key) in walls {
        match cache.get_wall(key) {
            // An entry names its wall; one for another wall with equal inputs is not reused.
            Lookup::Hit(r) if &r.wall == key_piece => {
                let mut record = *r;
                if need == Need::Traces {
                    match cache.get_trace(key) {
                        Some(trace) => record.trace = trace,
                        None => {
                            found.push(None);
                            misses.push((key_piece.clone(), key.clone()));
                            continue;
                        }
                    }
                }
                counts.cached += 1;
                found.push(Some(record));
                continue;
            }
            Lookup::Hit(_) | Lookup::Miss => {}
            Lookup::Rejected => counts.rejected += 1,
        }
        found.push(None);
        misses.push((key_piece.clone(), key.clone()));
    }
    (found, misses, counts)
}

/// Stores what a run needs of a wall: its record, and with `Need::Traces` its trace.
fn store(cache: &Cache, key: &str, record: &WallRecord, need: Need) {
    cache.put_wall(key, record);
    if need == Need::Traces {
        cache.put_trace(key, &record.trace);
    }
}

/// Simulates the missing walls of a prepared run and stores their records.
fn simulate_misses(
    prepared: &Prepared,
    cell: &Cell,
    options: &SimOptions,
    cache: Option<&Cache>,
    misses: &[(String, String)],
    need: Need,
    progress: &(dyn Fn(&str, usize, usize) + Sync),
) -> Result<Vec<WallRecord>, SimError> {
    if misses.is_empty() {
        return Ok(Vec::new());
    }
    let keys: Vec<String> = misses.iter().map(|(k, _)| k.clone()).collect();
    let records = run_prepared(prepared, cell, options, &keys, progress)?;
    if let Some(cache) = cache {
        for r in &records {
            if let Some((_, key)) = misses.iter().find(|(k, _)| k == &r.wall) {
                store(cache, key, r, need);
            }
        }
    }
    Ok(records)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shards_parse_and_split_keys() {
        assert_eq!("2/3".parse::<Shard>(), Ok(Shard { index: 2, count: 3 }));
        for bad in ["0/3", "4/3", "3", "a/b", "1/0", ""] {
            assert!(bad.parse::<Shard>().is_err(), "{bad}");
        }
        // Every key lies in exactly one shard.
        for i in 0..50u32 {
            let key = blake3::hash(&i.to_le_bytes()).to_hex().to_string();
            let n = (1..=3)
                .filter(|k| {
                    Shard {
                        index: *k,
                        count: 3,
                    }
                    .holds(&key)
                })
                .count();
            assert_eq!(n, 1, "{key}");
        }
    }
}
