//! `plan` through the cache: the model's facts split into independent parts
//! (`frame::partition`), each part's reasoning (placement search and the rule base, the
//! relations `plan` reads) stored under a hash of exactly the facts it read, the cell and the
//! build. A part's walls also depend on how far the rest of their storey reaches along their
//! across direction (`storey_reach`, which decides the outer face of an exterior wall): an
//! entry keeps the rows it was computed with, and is used only while the storey's lumber
//! still reaches exactly that far. An edit to one wall recomputes that wall's part (and the
//! parts whose storey extent it moved), nothing else.

use super::key::build_id_noted;
use super::value_codec::{Reader, Writer};
use super::{Cache, CacheCounts, PlanWriter};
use crate::cell::{Cell, OffsetX};
use crate::frame::builtin;
use crate::frame::partition::{Indices, Partition};
use crate::frame::placement::{FIRST_PASS, SearchMemo, SearchOptions, placement_relations};
use crate::frame::plan::Plan;
use crate::frame::rows::{PieceBox, PieceContainer, PieceSize, Row, StoreyReach, Wall, rows_of};
use crate::frame::{Ask, Facts, FrameError, Reasoned, RuleEngine, RuleLimits};
use crate::logic::compiled::Relations;
use crate::logic::functors::defs::{box_centre, box_radius, dot};
use crate::logic::value::{F64, OBox, Sym, Value, Vec3};
use rayon::prelude::*;
use rustc_hash::{FxHashMap, FxHashSet};
use std::sync::Mutex;

/// The relation an entry's context check reads.
const REACH: &str = crate::frame::rule_reads::STOREY_REACH;
/// Start of every entry: the format.
const MAGIC: &[u8] = b"framewright plan part 2\n";
/// Above this share of missed parts a container is reasoned whole (one run, split into
/// entries afterwards) instead of part by part (each part with its storey as context).
const WHOLE_CONTAINER_SHARE: f64 = 0.25;

/// `plan`'s reasoning through the cache: the same relations `Ask::new(&Compiled)
/// .only(Plan::RELATIONS).placed(facts, cell)` gives, in the same order, and
/// how many walls were reasoned and how many came from the cache. `facts` are the model's
/// and the cell's, without placement facts (the search runs per part here).
#[cfg(test)]
pub(crate) fn reason_plan_cached(
    facts: Facts,
    cell: &Cell,
    cache: &Cache,
    limits: &RuleLimits,
) -> Result<(Reasoned, CacheCounts), FrameError> {
    let (reasoned, counts, ()) = reason_plan_cached_with(facts, cell, cache, limits, |_| ())?;
    Ok((reasoned, counts))
}

/// `reason_plan_cached`, and `then` called on the reasoned relations (`Plan::RELATIONS`, maybe
/// more). A first run calls it while it splits and encodes its entries, so the caller's next
/// step (building the plan) runs beside the cache's own work.
pub(crate) fn reason_plan_cached_with<T: Send>(
    facts: Facts,
    cell: &Cell,
    cache: &Cache,
    limits: &RuleLimits,
    then: impl FnOnce(&Relations) -> T + Send,
) -> Result<(Reasoned, CacheCounts, T), FrameError> {
    let partition = Partition::of(&facts);
    let base = base_key(
        cell,
        build_id_noted(cache.dir()),
        limits,
        &partition,
        &facts,
    );
    let keys: Vec<String> = (0..partition.parts.len())
        .into_par_iter()
        .map(|i| part_key(&base, &partition, &facts, i))
        .collect();
    let mut counts = CacheCounts::default();
    // Each part's relations (with its storey_reach rows), from the cache or computed.
    let looked: Vec<Found> = if cache.may_hold_plans() {
        let extents = Extents::of(&facts, &partition);
        keys.par_iter()
            .zip(&partition.parts)
            .map(
                |(key, part)| match cache.get_plan(key).map(|b| decode(key, &b)) {
                    Some(Some(r)) if extents.agree(part.container, &r) => Found::Hit(r),
                    Some(Some(_)) | None => Found::Miss,
                    Some(None) => Found::Rejected,
                },
            )
            .collect()
    } else {
        keys.iter().map(|_| Found::Miss).collect()
    };
    let rejected: Vec<bool> = looked
        .iter()
        .map(|f| matches!(f, Found::Rejected))
        .collect();
    let mut results: Vec<Option<Relations>> = looked
        .into_iter()
        .map(|f| match f {
            Found::Hit(r) => Some(r),
            Found::Miss | Found::Rejected => None,
        })
        .collect();
    counts.cached = results
        .iter()
        .flatten()
        .map(|r| r.get(Wall::RELATION).map_or(0, Vec::len))
        .sum();

    if results.iter().all(Option::is_none) {
        let stored = Stored {
            cache,
            partition: &partition,
            keys: &keys,
            rejected: &rejected,
        };
        return first_run(facts, cell, limits, stored, then);
    }

    // What to compute: whole containers where many parts missed, single parts elsewhere.
    let mut jobs: Vec<Job> = Vec::new();
    for (c, container) in partition.containers.iter().enumerate() {
        let parts: Vec<usize> = (0..partition.parts.len())
            .filter(|&i| partition.parts[i].container == c)
            .collect();
        let missed: Vec<usize> = parts
            .iter()
            .copied()
            .filter(|&i| results[i].is_none())
            .collect();
        if missed.is_empty() {
            continue;
        }
        if missed.len() as f64 > WHOLE_CONTAINER_SHARE * parts.len() as f64 {
            jobs.push(Job::Container {
                parts,
                size: container.pieces.len(),
            });
        } else {
            jobs.extend(missed.into_iter().map(Job::Part));
        }
    }
    jobs.sort_by_key(|j| std::cmp::Reverse(j.size(&partition)));
    let total = std::sync::atomic::AtomicU64::new(0);
    let computed: Mutex<Vec<(usize, Relations)>> = Mutex::new(Vec::new());
    let memo = SearchMemo::default();
    let writer = cache.plan_writer();
    jobs.par_iter()
        .try_for_each(|job| -> Result<(), FrameError> {
            let (done, tuples) = job.run(&facts, &partition, cell, &memo)?;
            let sum = total.fetch_add(tuples, std::sync::atomic::Ordering::Relaxed) + tuples;
            limits.check_tuples(sum)?;
            for (i, relations) in &done {
                writer.put(keys[*i].clone(), encode(&keys[*i], relations));
            }
            computed.lock().map_err(|_| poisoned())?.extend(done);
            Ok(())
        })?;
    writer.commit();
    for (i, relations) in computed.into_inner().map_err(|_| poisoned())? {
        if results[i].is_none() {
            let walls = relations.get(Wall::RELATION).map_or(0, Vec::len);
            counts.computed += walls;
            if rejected[i] {
                counts.rejected += walls;
            }
            results[i] = Some(relations);
        }
    }

    let relations = merge(&partition, results);
    limits.check_walls(relations.get(Wall::RELATION).map_or(0, Vec::len) as u64)?;
    let after = then(&relations);
    Ok((
        Reasoned {
            relations,
            engine: None,
        },
        counts,
        after,
    ))
}

/// What the cache held for a part: a usable entry, none (or one whose storey has changed),
/// or one found torn, altered or foreign.
enum Found {
    Hit(Relations),
    Miss,
    Rejected,
}

fn poisoned() -> FrameError {
    FrameError::Compiled("a reasoning thread failed".into())
}

/// Where a first run stores its parts, and what the lookups found.
struct Stored<'a> {
    cache: &'a Cache,
    partition: &'a Partition,
    keys: &'a [String],
    rejected: &'a [bool],
}

/// A first run (nothing cached): the model reasoned as `plan` does without the cache (one
/// placement search over every wall, so repeated walls search once), its parts' entries
/// written while `then` runs.
fn first_run<T: Send>(
    facts: Facts,
    cell: &Cell,
    limits: &RuleLimits,
    stored: Stored,
    then: impl FnOnce(&Relations) -> T + Send,
) -> Result<(Reasoned, CacheCounts, T), FrameError> {
    let mut wanted: Vec<&str> = Plan::RELATIONS.to_vec();
    wanted.push(REACH);
    let mut reasoned = Ask::new(&RuleEngine::Compiled)
        .within(*limits)
        .only(&wanted)
        .placed(facts, cell)?;
    let relations = &reasoned.relations;
    let writer = stored.cache.plan_writer();
    let (rejected, after) = rayon::join(
        || store_parts(relations, &stored, &writer),
        || then(relations),
    );
    writer.commit();
    reasoned.relations.remove(REACH);
    let counts = CacheCounts {
        computed: reasoned.get(Wall::RELATION).len(),
        rejected,
        ..CacheCounts::default()
    };
    Ok((reasoned, counts, after))
}

/// Splits a whole run's relations into the parts' entries, encodes them and hands them to
/// the writer; returns how many walls replace entries that were found rejected.
fn store_parts(out: &Relations, stored: &Stored, writer: &PlanWriter) -> usize {
    let everything: Vec<usize> = (0..stored.partition.parts.len()).collect();
    let shares = shares(stored.partition, &everything, out);
    let wall_slot = out.keys().position(|n| n == Wall::RELATION);
    shares
        .par_iter()
        .enumerate()
        .map(|(i, share)| {
            let key = &stored.keys[i];
            writer.put(key.clone(), encode_share(key, out, share));
            if stored.rejected[i] {
                share.iter().filter(|(r, _)| Some(*r) == wall_slot).count()
            } else {
                0
            }
        })
        .sum()
}

/// A unit of reasoning.
enum Job {
    /// Every part of a container in one run.
    Container { parts: Vec<usize>, size: usize },
    /// One part, its storey as context.
    Part(usize),
}

impl Job {
    fn size(&self, partition: &Partition) -> usize {
        match self {
            Job::Container { size, .. } => *size,
            Job::Part(i) => partition.parts[*i].pieces.len(),
        }
    }

    /// The job's parts' relations and the tuples its runs derived.
    fn run(
        &self,
        facts: &Facts,
        partition: &Partition,
        cell: &Cell,
        memo: &SearchMemo,
    ) -> Result<(Vec<(usize, Relations)>, u64), FrameError> {
        match self {
            Job::Container { parts, .. } => {
                // The parts' facts, with the file's piece indices: the rules take a wall's
                // name from the piece of its least index.
                let input = partition.relations(facts, parts, Indices::File);
                let (out, tuples) = reason_part(input, cell, memo)?;
                let shares = shares(partition, parts, &out);
                let split = parts
                    .iter()
                    .zip(shares)
                    .map(|(&i, share)| (i, owned_share(&out, &share)))
                    .collect();
                Ok((split, tuples))
            }
            Job::Part(i) => {
                let mut input = partition.relations(facts, &[*i], Indices::Renumbered);
                let context = partition.context(facts, *i);
                let others: FxHashSet<&str> = rows_of::<PieceContainer>(&context)?
                    .into_iter()
                    .map(|row| row.p)
                    .collect();
                for (name, tuples) in &context {
                    input
                        .entry(name.clone())
                        .or_default()
                        .extend(tuples.iter().cloned());
                }
                let (mut out, tuples) = reason_part(input, cell, memo)?;
                // What was derived about the context pieces is theirs, not this part's.
                for rows in out.values_mut() {
                    rows.retain(|t| {
                        !t.iter()
                            .any(|v| v.as_symbol().is_some_and(|s| others.contains(s)))
                    });
                }
                Ok((vec![(*i, out)], tuples))
            }
        }
    }
}

/// The placement search (when the cell places walls itself) and the rule base on one
/// part's or container's facts: `plan`'s relations and the storey's reach rows.
fn reason_part(
    input: Relations,
    cell: &Cell,
    memo: &SearchMemo,
) -> Result<(Relations, u64), FrameError> {
    let mut wanted: Vec<&str> = Plan::RELATIONS.to_vec();
    wanted.push(REACH);
    let run = match cell.assembly.offset_x {
        OffsetX::Auto { min, max } => builtin::run_placed(&input, FIRST_PASS, &wanted, |first| {
            placement_relations(cell, first, (min, max), &SearchOptions::default(), memo)
        }),
        OffsetX::Fixed { .. } => builtin::run_selected(&input, &wanted),
    }
    .map_err(FrameError::CompiledRun)?;
    Ok((run.relations, run.tuples))
}

/// Which tuples of `out` belong to each of `parts`, as (relation slot, tuple index) pairs in
/// relation order (slots count `out`'s relations in name order): a tuple goes to the part of
/// the first piece or group it names; a storey's reach row to every part of that storey; a
/// tuple naming none (what the cell alone gives) to every part. References, not copies: a
/// whole model's relations are split without holding them twice.
fn shares(partition: &Partition, parts: &[usize], out: &Relations) -> Vec<Vec<(usize, usize)>> {
    // Keyed by interned symbols: every value of every tuple is looked up.
    let mut owner: FxHashMap<Sym, usize> = FxHashMap::default();
    let mut of_container: FxHashMap<Sym, Vec<usize>> = FxHashMap::default();
    for (k, &i) in parts.iter().enumerate() {
        let part = &partition.parts[i];
        for id in part.pieces.iter().chain(&part.groups) {
            owner.insert(Sym::from(id.as_str()), k);
        }
        let container = Sym::from(partition.containers[part.container].name.as_str());
        of_container.entry(container).or_default().push(k);
    }
    let everyone: Vec<usize> = (0..parts.len()).collect();
    // Each relation's rows to their parts (relations in parallel), then each part's rows laid
    // out in relation order.
    let rows_of: Vec<Vec<Vec<usize>>> = out
        .par_iter()
        .map(|(name, rows)| {
            let mut to_parts: Vec<Vec<usize>> = vec![Vec::new(); parts.len()];
            for (row, t) in rows.iter().enumerate() {
                let to: &[usize] = if name == REACH {
                    t.first()
                        .and_then(Value::as_sym)
                        .and_then(|c| of_container.get(&c))
                        .map_or(&[], Vec::as_slice)
                } else {
                    match t
                        .iter()
                        .find_map(|v| v.as_sym().and_then(|s| owner.get(&s)))
                    {
                        Some(k) => std::slice::from_ref(k),
                        None => &everyone,
                    }
                };
                for &k in to {
                    to_parts[k].push(row);
                }
            }
            to_parts
        })
        .collect();
    (0..parts.len())
        .into_par_iter()
        .map(|k| {
            rows_of
                .iter()
                .enumerate()
                .flat_map(|(slot, to_parts)| to_parts[k].iter().map(move |&row| (slot, row)))
                .collect()
        })
        .collect()
}

/// A part's share of `out` as its own relations (every relation of `out`, maybe empty).
fn owned_share(out: &Relations, share: &[(usize, usize)]) -> Relations {
    let rows: Vec<&Vec<Vec<Value>>> = out.values().collect();
    let mut r: Relations = out.keys().map(|n| (n.clone(), Vec::new())).collect();
    let slots: Vec<&String> = out.keys().collect();
    for &(slot, row) in share {
        r.get_mut(slots[slot])
            .expect("every relation")
            .push(rows[slot][row].clone());
    }
    r
}

/// The parts' relations as the container-by-container run returns them: containers
/// largest first, each container's tuples sorted, small relations sorted whole; without
/// the reach rows.
fn merge(partition: &Partition, results: Vec<Option<Relations>>) -> Relations {
    let mut by_container: Vec<Relations> = vec![Relations::new(); partition.containers.len()];
    for (part, r) in partition.parts.iter().zip(results) {
        for (name, rows) in r.into_iter().flatten() {
            if name != REACH {
                by_container[part.container]
                    .entry(name)
                    .or_default()
                    .extend(rows);
            }
        }
    }
    let mut order: Vec<usize> = (0..partition.containers.len()).collect();
    order.sort_by_key(|&c| std::cmp::Reverse(partition.containers[c].pieces.len()));
    let mut ordered: Vec<Relations> = order
        .into_iter()
        .map(|c| std::mem::take(&mut by_container[c]))
        .collect();
    ordered.par_iter_mut().for_each(|relations| {
        relations.par_iter_mut().for_each(|(_, rows)| {
            rows.sort_unstable();
            rows.dedup();
        })
    });
    let mut merged = Relations::new();
    for relations in ordered {
        for (name, rows) in relations {
            merged.entry(name).or_default().extend(rows);
        }
    }
    for rows in merged.values_mut() {
        if rows.len() <= crate::frame::SMALL_RELATION {
            rows.sort_unstable();
            rows.dedup();
        }
    }
    merged
}

/// What every part's key shares: the format, the build, the cell (its facts and what the
/// placement search reads: robot, tool, offsets), the search options, the rule tuple bound (a
/// run under a lower bound must stop where an uncached run stops, not read a result derived
/// under a higher one; the wall bound is checked on every run), and the facts every part
/// reads (those about no piece).
fn base_key(
    cell: &Cell,
    build: &str,
    limits: &RuleLimits,
    partition: &Partition,
    facts: &Facts,
) -> blake3::Hasher {
    let mut h = blake3::Hasher::new();
    h.update(b"framewright plan part\0");
    h.update(build.as_bytes());
    h.update(
        format!(
            "\0{cell:?}\0{:?}\0{}\0",
            SearchOptions::default(),
            limits.max_rule_tuples
        )
        .as_bytes(),
    );
    let mut w = Writer::default();
    write_named(&mut w, &partition.common_rows(facts));
    h.update(&w.bytes);
    h
}

/// A part's key: the base and the part's own facts, byte for byte.
fn part_key(base: &blake3::Hasher, partition: &Partition, facts: &Facts, i: usize) -> String {
    let mut w = Writer::default();
    write_named(&mut w, &partition.own_rows(facts, i));
    let mut h = base.clone();
    h.update(&w.bytes);
    h.finalize().to_hex().to_string()
}

/// Relations given as (name, rows), written as `Writer::relations` writes a relation set.
fn write_named<T: AsRef<[Value]>>(w: &mut Writer, named: &[(&str, Vec<T>)]) {
    w.u64(named.len() as u64);
    for (name, rows) in named {
        w.relation(name, rows.iter().map(AsRef::as_ref));
    }
}

fn encode(key: &str, relations: &Relations) -> Vec<u8> {
    let mut w = Writer::new(MAGIC.to_vec());
    w.str(key);
    w.relations(relations);
    seal(w.bytes)
}

/// `encode` of a part's share of a run's relations, read in place.
fn encode_share(key: &str, out: &Relations, share: &[(usize, usize)]) -> Vec<u8> {
    let mut w = Writer::new(MAGIC.to_vec());
    w.str(key);
    w.u64(out.len() as u64);
    let mut next = 0;
    for (slot, (name, rows)) in out.iter().enumerate() {
        let start = next;
        while next < share.len() && share[next].0 == slot {
            next += 1;
        }
        let tuples = share[start..next]
            .iter()
            .map(|&(_, row)| rows[row].as_slice());
        w.relation(name, tuples);
    }
    seal(w.bytes)
}

/// An entry's bytes followed by their blake3 digest.
fn seal(mut bytes: Vec<u8>) -> Vec<u8> {
    let digest = blake3::hash(&bytes);
    bytes.extend_from_slice(digest.as_bytes());
    bytes
}

/// An entry's relations, or None when it is torn, altered, of another format or key.
fn decode(key: &str, bytes: &[u8]) -> Option<Relations> {
    let body = bytes.get(..bytes.len().checked_sub(32)?)?;
    let digest = bytes.get(body.len()..)?;
    if blake3::hash(body).as_bytes() != digest {
        return None;
    }
    let mut r = Reader::new(body.strip_prefix(MAGIC)?);
    if r.str()? != key {
        return None;
    }
    let relations = r.relations()?;
    r.is_empty().then_some(relations)
}

/// Least and greatest projection of a container's lumber on a direction.
type Reach = (F64, F64);
/// A container and a direction's bits.
type DirectionKey = (usize, [u64; 3]);

/// How far each container's lumber reaches along a direction, computed as the rule
/// `storey_reach` (rules/frame.dl) computes it: over the pieces the rule `lumber_section`
/// (rules/walls.dl) takes as lumber, the box centre's projection minus / plus its projected
/// radius, the least / greatest in the floats' total order. Tested against the rules.
struct Extents {
    /// Per container, its lumber boxes.
    lumber: Vec<Vec<OBox>>,
    /// Container name → index.
    index: FxHashMap<String, usize>,
    memo: Mutex<FxHashMap<DirectionKey, Option<Reach>>>,
}

impl Extents {
    fn of(facts: &Facts, partition: &Partition) -> Extents {
        // Facts the model's extraction wrote, read as the rules read them (others skipped).
        let facts_of = |relation: &str| facts.tuples.get(relation).into_iter().flatten();
        let boxes: FxHashMap<&str, OBox> = facts_of(PieceBox::RELATION)
            .filter_map(|(t, _)| PieceBox::read(t))
            .map(|t| (t.p, t.b))
            .collect();
        let lumber: FxHashSet<&str> = facts_of(PieceSize::RELATION)
            .filter_map(|(t, _)| PieceSize::read(t))
            .filter(|t| is_lumber_section(t.width, t.thickness))
            .map(|t| t.p)
            .collect();
        Extents {
            lumber: partition
                .containers
                .iter()
                .map(|c| {
                    c.pieces
                        .iter()
                        .map(|&i| partition.pieces[i].as_str())
                        .filter(|p| lumber.contains(p))
                        .filter_map(|p| boxes.get(p).copied())
                        .collect()
                })
                .collect(),
            index: partition
                .containers
                .iter()
                .enumerate()
                .map(|(i, c)| (c.name.clone(), i))
                .collect(),
            memo: Mutex::new(FxHashMap::default()),
        }
    }

    /// The container's reach along `k`: (least, greatest), None without lumber.
    fn along(&self, container: usize, k: Vec3) -> Option<Reach> {
        let memo_key = (
            container,
            [k.0.x.to_bits(), k.0.y.to_bits(), k.0.z.to_bits()],
        );
        if let Some(v) = self.memo.lock().ok()?.get(&memo_key) {
            return *v;
        }
        let projections = self.lumber[container].iter().map(|b| {
            let c = dot(box_centre(*b), k).0;
            let r = box_radius(*b, k).0;
            (F64(c - r), F64(c + r))
        });
        let v = projections.fold(None, |acc: Option<Reach>, (lo, hi)| {
            Some(acc.map_or((lo, hi), |(a, b)| (a.min(lo), b.max(hi))))
        });
        self.memo.lock().ok()?.insert(memo_key, v);
        v
    }

    /// Whether every reach row an entry was computed with still holds for its container.
    fn agree(&self, container: usize, entry: &Relations) -> bool {
        // A row off the declaration rejects the entry (it is recomputed), as a torn one.
        entry.get(REACH).into_iter().flatten().all(|row| {
            let Some(r) = StoreyReach::read(row) else {
                return false;
            };
            self.index.get(r.c) == Some(&container)
                && self.along(container, Vec3(r.k)) == Some((F64(r.lo), F64(r.hi)))
        })
    }
}

/// `lumber_section` of rules/walls.dl: at most 0.2 m thick (and at least 1 cm) and 0.45 m wide.
fn is_lumber_section(width: f64, thickness: f64) -> bool {
    (0.01..=0.2).contains(&thickness) && width <= 0.45
}

#[cfg(test)]
mod tests;
