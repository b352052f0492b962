//! The placement search behind `offset_x = "auto"`: for every wall and every offset along the
//! robot's +x from the cell's `assembly_offset_min` to `_max`, which of the wall's pieces the
//! arm reaches there. The choice itself (most pieces, then nearest the base) is a rule of
//! `rules/targets.dl`, so `why` shows it; this module only states the reach facts, each with
//! the offset and the piece it is about.
//!
//! A piece counts as reached when its place pose and the pose the gripper descends from both
//! have an exact IK solution within the joint limits, the gripper pointing down and holding
//! the piece at its centre of mass (the study's framing target), either way round; a nail
//! when the nailer's firing pose and the start of its approach along the nail line both
//! solve, at one of the rolls the executor tries. Every solution counted keeps the arm and
//! its tool above the floor.

use super::{Facts, Reasoned};
use crate::cell::Cell;
use crate::cell::tcp_poses::{
    centre_grip, lowest_point, nail_pose, nail_rolls, retreat, two_gripper_shifts,
};
use crate::logic::compiled::Relations;
use crate::logic::{Origin, Value};
use nalgebra::{Isometry3, Point3, Translation3, Vector3};
use rustc_hash::FxHashMap;
use std::collections::BTreeMap;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex, OnceLock};

/// Spacing of the offsets tried (m).
pub const OFFSET_STEP: f64 = 0.01;
/// A target counts as reached at an offset only if it is also reached this many steps nearer
/// and farther (2 cm).
const ROBUST_STEPS: usize = 2;
/// Height above the place pose the gripper descends from (m); the executor's clearance.
pub const APPROACH_HEIGHT: f64 = 0.25;
/// The nailer approaches a nail along its line from this far back (m), and fires with its
/// nose this far off the face (m): the executor's numbers.
const NAIL_APPROACH: f64 = 0.10;
const NOSE_GAP: f64 = 0.002;
/// The arm and its tool keep at least this far above the floor (m).
const FLOOR_CLEARANCE: f64 = 0.002;

/// How the placement search runs.
#[derive(Debug, Clone, Copy)]
pub struct SearchOptions {
    /// Targets whose poses agree to SHARE_GRID run the search once (repeated walls of a
    /// big model are searched once); off, every target runs its own search.
    pub share_equal_poses: bool,
    /// Every tried offset becomes a `placement_candidate` of every wall; off (the default),
    /// only the offsets where a wall's count can rise: the first, and the start of each run
    /// of its pieces and nails. The most reached, nearest the base, is always among them, so
    /// the chosen offset is the same, and the rules count far fewer (wall, offset) pairs.
    pub every_offset: bool,
}

impl Default for SearchOptions {
    fn default() -> Self {
        SearchOptions {
            share_equal_poses: true,
            every_offset: false,
        }
    }
}

/// Poses whose coordinates (m), unit-quaternion components and sizes (m) round to the same
/// multiple of this share one search: 1 nm, far below the 1 cm step of the offsets.
pub const SHARE_GRID: f64 = 1e-9;

/// What the search reads of the first pass.
pub(crate) const FIRST_PASS: &[&str] = super::rule_reads::PLACEMENT_FIRST_PASS;

/// The offsets tried: `min` to `max` every OFFSET_STEP, in whole millimetres.
pub fn candidate_offsets(min: f64, max: f64) -> Vec<f64> {
    let n = ((max - min) / OFFSET_STEP).floor().max(0.0) as usize;
    (0..=n)
        .map(|k| ((min + k as f64 * OFFSET_STEP) * 1000.0).round() / 1000.0)
        .collect()
}

/// `placement_candidate(w, x)` for every wall and each offset where its count can rise
/// (every offset with `SearchOptions::every_offset`), `placement_reaches(p, from, to)` for
/// every run of offsets at which the arm reaches a piece, `placement_nail_reaches(…, from, to)`
/// the same for nails.
pub fn placement_facts(
    cell: &Cell,
    first: &Reasoned,
    min: f64,
    max: f64,
    options: &SearchOptions,
) -> Facts {
    let mut facts = Facts::default();
    search(
        cell,
        &first.relations,
        (min, max),
        options,
        &SearchMemo::default(),
        &mut |relation, tuple, origin| facts.add(relation, tuple, Origin::Event(origin())),
    );
    facts
}

/// Search results shared by every part of a model reasoned part by part, so repeated
/// walls in different storeys search once.
#[derive(Default)]
pub(crate) struct SearchMemo {
    pieces: Memo,
    nails: Memo,
}

type Memo = Mutex<FxHashMap<[i64; 10], Shared>>;

/// Reach runs of one search key, filled by whichever part searches the key first.
type Shared = Arc<Slot>;

/// One search key's result, and whether a thread has taken it on.
#[derive(Default)]
struct Slot {
    taken: AtomicBool,
    runs: OnceLock<Vec<(f64, f64)>>,
}

impl Slot {
    /// Searches the key unless a thread has taken it on already.
    fn search_unless_taken(&self, search: impl FnOnce() -> Vec<(f64, f64)>) {
        if !self.taken.swap(true, Ordering::AcqRel) {
            self.fill(search);
        }
    }

    /// The result, once the thread that took the key on has it (a key is taken on only to
    /// be searched at once, so this waits at most one search); searched here if the key was
    /// given back.
    fn get(&self, search: impl FnOnce() -> Vec<(f64, f64)>) -> &Vec<(f64, f64)> {
        loop {
            if let Some(runs) = self.runs.get() {
                return runs;
            }
            if !self.taken.swap(true, Ordering::AcqRel) {
                return self.fill(search);
            }
            std::thread::sleep(std::time::Duration::from_micros(20));
        }
    }

    /// Searches the key this thread has taken on. A search that panics gives the key back,
    /// so no other thread waits for it forever.
    fn fill(&self, search: impl FnOnce() -> Vec<(f64, f64)>) -> &Vec<(f64, f64)> {
        struct GiveBack<'a>(&'a AtomicBool);
        impl Drop for GiveBack<'_> {
            fn drop(&mut self) {
                self.0.store(false, Ordering::Release);
            }
        }
        let give_back = GiveBack(&self.taken);
        let runs = self.runs.get_or_init(search);
        std::mem::forget(give_back);
        runs
    }
}

/// Takes one placement fact: relation, tuple, and how to say where it came from.
type AddFact<'a> = dyn FnMut(&'static str, Vec<Value>, &dyn Fn() -> String) + 'a;

/// The placement facts of one part for the typed runner (`builtin::run_placed`):
/// what `placement_facts` gives, without origins, each relation sorted.
pub(crate) fn placement_relations(
    cell: &Cell,
    first: &Relations,
    range: (f64, f64),
    options: &SearchOptions,
    memo: &SearchMemo,
) -> Relations {
    let mut relations = Relations::new();
    search(
        cell,
        first,
        range,
        options,
        memo,
        &mut |relation, tuple, _| {
            relations
                .entry(relation.to_string())
                .or_default()
                .push(tuple)
        },
    );
    for tuples in relations.values_mut() {
        tuples.sort_unstable();
        tuples.dedup();
    }
    relations
}

/// Runs the search and hands each fact to `add` (relation, tuple, and how to say where it
/// came from).
fn search(
    cell: &Cell,
    first: &Relations,
    (min, max): (f64, f64),
    options: &SearchOptions,
    memo: &SearchMemo,
    add: &mut AddFact,
) {
    let get = |relation: &str| first.get(relation).map_or(&[][..], Vec::as_slice);
    let offsets = candidate_offsets(min, max);
    let sizes: BTreeMap<&str, [f64; 3]> = get("piece_size")
        .iter()
        .filter_map(|t| {
            let p = t.first()?.as_symbol()?;
            let f = |k: usize| t.get(k).and_then(Value::as_float);
            Some((p, [f(1)?, f(2)?, f(3)?]))
        })
        .collect();
    let walls: BTreeMap<&str, &str> = get("wall_of")
        .iter()
        .filter_map(|t| Some((t.first()?.as_symbol()?, t.get(1)?.as_symbol()?)))
        .collect();
    let pieces: Vec<(&str, Isometry3<f64>, [f64; 3])> = get("placement_target_at_zero")
        .iter()
        .filter_map(|t| {
            let p = t.first()?.as_symbol()?;
            let Some(Value::Iso(pose)) = t.get(1) else {
                return None;
            };
            Some((p, pose.0, *sizes.get(p)?))
        })
        .collect();
    let share = options.share_equal_poses;
    let reached = search_each(
        &pieces,
        |(_, pose, size)| pose_key(pose, size),
        share.then_some(&memo.pieces),
        |(_, at_zero, size)| {
            let ok: Vec<bool> = offsets
                .iter()
                .map(|x| reaches(cell, &shifted(at_zero, *x), size))
                .collect();
            robustly(&offsets, &ok)
        },
    );
    let nails: Vec<(Vec<Value>, Point3<f64>, Vector3<f64>)> = get("placement_nail_at_zero")
        .iter()
        .filter_map(|t| {
            let (Some(Value::Vec3(point)), Some(Value::Vec3(direction))) = (t.get(5), t.get(6))
            else {
                return None;
            };
            Some((t[..5].to_vec(), Point3::from(point.0), direction.0))
        })
        .collect();
    let nails_reached = search_each(
        &nails,
        |(_, point, direction)| {
            let mut key = [0; 10];
            key[..3].copy_from_slice(&grid(&point.coords));
            key[3..6].copy_from_slice(&grid(direction));
            key
        },
        share.then_some(&memo.nails),
        |(_, point, direction)| {
            let ok: Vec<bool> = offsets
                .iter()
                .map(|x| nail_reached(cell, &(point + Vector3::new(*x, 0.0, 0.0)), direction))
                .collect();
            robustly(&offsets, &ok)
        },
    );

    let candidates = wall_candidates(
        &offsets,
        &walls,
        pieces.iter().map(|(p, _, _)| *p).zip(&reached),
        nails
            .iter()
            .filter_map(|(key, _, _)| key.first()?.as_symbol())
            .zip(&nails_reached),
        options.every_offset,
    );
    for (w, xs) in candidates {
        for x in xs {
            add(
                "placement_candidate",
                vec![Value::sym(w), Value::float(x)],
                &|| format!("placement search: wall {w} tried at x = {x:.3} m"),
            );
        }
    }
    for ((p, _, _), runs) in pieces.iter().zip(&reached) {
        for &(from, to) in runs {
            add(
                "placement_reaches",
                vec![Value::sym(p), Value::float(from), Value::float(to)],
                &|| {
                    format!(
                        "placement search: IK solves the place pose of {p} and the pose above it with its wall at every x from {from:.3} to {to:.3} m"
                    )
                },
            );
        }
    }
    for ((key, _, _), runs) in nails.iter().zip(&nails_reached) {
        for &(from, to) in runs {
            let mut tuple = key.clone();
            tuple.extend([Value::float(from), Value::float(to)]);
            add("placement_nail_reaches", tuple, &|| {
                format!(
                    "placement search: IK solves the nailer's pose and its approach for a nail of {} into {} with the wall at every x from {from:.3} to {to:.3} m",
                    key[0], key[1]
                )
            });
        }
    }
}

/// The offsets tried for each wall (walls sorted by name, offsets ascending). The count of
/// a wall at x (its pieces and nails reached) only rises at the first offset or where a run
/// starts, so the smallest x with the largest count is one of those: with `every` false only
/// they are candidates.
fn wall_candidates<'a>(
    offsets: &[f64],
    walls: &BTreeMap<&'a str, &'a str>,
    pieces: impl Iterator<Item = (&'a str, &'a Vec<(f64, f64)>)>,
    nails: impl Iterator<Item = (&'a str, &'a Vec<(f64, f64)>)>,
    every: bool,
) -> BTreeMap<&'a str, Vec<f64>> {
    let mut starts: BTreeMap<&str, Vec<f64>> = walls.values().map(|w| (*w, Vec::new())).collect();
    if every {
        starts.values_mut().for_each(|xs| xs.extend(offsets));
        return starts;
    }
    for (piece, runs) in pieces.chain(nails) {
        if let Some(xs) = walls.get(piece).and_then(|w| starts.get_mut(w)) {
            xs.extend(runs.iter().map(|(from, _)| *from));
        }
    }
    for xs in starts.values_mut() {
        xs.extend(offsets.first());
        xs.sort_by(f64::total_cmp);
        xs.dedup();
    }
    starts
}

/// `search` for every item, in parallel; with a memo, items of one key run it once (in this
/// call or an earlier one with the same memo; equal keys give equal results, so the result
/// is deterministic).
fn search_each<T: Sync>(
    items: &[T],
    key: impl Fn(&T) -> [i64; 10] + Sync,
    memo: Option<&Memo>,
    search: impl Fn(&T) -> Vec<(f64, f64)> + Sync,
) -> Vec<Vec<(f64, f64)>> {
    use rayon::prelude::*;
    let Some(memo) = memo else {
        return items.par_iter().map(&search).collect();
    };
    let mut first_of: FxHashMap<[i64; 10], usize> = FxHashMap::default();
    let mut unique: Vec<&T> = Vec::new();
    let slot: Vec<usize> = items
        .iter()
        .map(|item| {
            *first_of.entry(key(item)).or_insert_with(|| {
                unique.push(item);
                unique.len() - 1
            })
        })
        .collect();
    let cells: Vec<Shared> = {
        let mut memo = memo.lock().unwrap_or_else(|e| e.into_inner());
        unique
            .iter()
            .map(|item| memo.entry(key(item)).or_default().clone())
            .collect()
    };
    // Parts that reach the same keys at once share them out: each searches the keys no one
    // has taken on yet, then waits for the rest. (Waiting on each key in turn would block a
    // pool thread for the whole of the other part's search: the first storeys of a model
    // reach the same keys together.)
    unique
        .par_iter()
        .zip(&cells)
        .for_each(|(item, cell)| cell.search_unless_taken(|| search(item)));
    let found: Vec<&Vec<(f64, f64)>> = unique
        .iter()
        .zip(&cells)
        .map(|(item, cell)| cell.get(|| search(item)))
        .collect();
    slot.into_iter().map(|k| found[k].clone()).collect()
}

/// Coordinates in whole SHARE_GRID steps.
fn grid(v: &Vector3<f64>) -> [i64; 3] {
    v.map(|c| (c / SHARE_GRID).round() as i64).into()
}

/// The search key of a piece: its pose at offset 0 and its size, on the SHARE_GRID.
fn pose_key(pose: &Isometry3<f64>, size: &[f64; 3]) -> [i64; 10] {
    let mut q = pose.rotation.into_inner().coords;
    // q and -q are one rotation.
    if q.iter()
        .find(|c| c.abs() > 0.5 * SHARE_GRID)
        .is_some_and(|c| *c < 0.0)
    {
        q = -q;
    }
    let mut key = [0; 10];
    key[..3].copy_from_slice(&grid(&pose.translation.vector));
    key[3..6].copy_from_slice(&grid(&q.xyz()));
    key[6] = (q.w / SHARE_GRID).round() as i64;
    key[7..].copy_from_slice(&grid(&Vector3::from(*size)));
    key
}

/// The runs of consecutive offsets (first, last) at which something is reached with
/// ROBUST_STEPS offsets to spare on both sides: a piece held a little off its planned grip, or
/// a wall a little off its place, still works. One fact per run keeps the facts few.
fn robustly(offsets: &[f64], ok: &[bool]) -> Vec<(f64, f64)> {
    let robust = |i: usize| {
        let lo = i.saturating_sub(ROBUST_STEPS);
        let hi = (i + ROBUST_STEPS).min(ok.len() - 1);
        ok[lo..=hi].iter().all(|b| *b)
    };
    let mut runs: Vec<(f64, f64)> = Vec::new();
    let mut previous = false;
    for (i, &x) in offsets.iter().enumerate() {
        let now = robust(i);
        match runs.last_mut() {
            Some(run) if now && previous => run.1 = x,
            _ if now => runs.push((x, x)),
            _ => {}
        }
        previous = now;
    }
    runs
}

/// A robot-frame pose moved `x` along the robot's +x.
fn shifted(pose: &Isometry3<f64>, x: f64) -> Isometry3<f64> {
    Translation3::new(x, 0.0, 0.0) * pose
}

/// Whether the arm places a piece whose body frame (robot frame) is `target`, gripping it at
/// its centre of mass from above, either way round.
pub fn reaches(cell: &Cell, target: &Isometry3<f64>, size: &[f64; 3]) -> bool {
    let Some(grip) = cell.tool.tcp("grip") else {
        return false;
    };
    [false, true].into_iter().any(|flip| {
        let Some(place) = centre_grip(target, size, flip) else {
            return false;
        };
        let above = Translation3::new(0.0, 0.0, APPROACH_HEIGHT) * place;
        reached_together(cell, &[place, above], grip)
    })
}

/// The shift along the piece (m, from its middle) of the first grip at which the arm takes a
/// piece's place pose and the pose APPROACH_HEIGHT above it: at its centre of mass first, then
/// shifted towards either end as the executor may grip it with two grippers
/// (`tcp_poses::two_gripper_shifts`; it may set a piece down either end first). None when no
/// grip does.
pub fn reached_held_at(cell: &Cell, target: &Isometry3<f64>, size: &[f64; 3]) -> Option<f64> {
    let grip = cell.tool.tcp("grip")?;
    let spacing = cell.tool.gripper.as_ref().map_or(0.0, |g| g.spacing);
    let along = target.rotation * Vector3::x();
    two_gripper_shifts(size[0], spacing)
        .into_iter()
        .flat_map(|s| if s > 0.0 { vec![s, -s] } else { vec![s] })
        .find(|s| {
            [false, true].into_iter().any(|flip| {
                let Some(centre) = centre_grip(target, size, flip) else {
                    return false;
                };
                let place = Translation3::from(along * *s) * centre;
                let above = Translation3::new(0.0, 0.0, APPROACH_HEIGHT) * place;
                reached_together(cell, &[place, above], grip)
            })
        })
}

/// Whether the nailer reaches a nail at `point` (robot frame) driven along `direction`.
pub fn nail_reached(cell: &Cell, point: &Point3<f64>, direction: &Vector3<f64>) -> bool {
    let Some(tcp) = cell.tool.tcp("nail") else {
        return false;
    };
    nail_rolls(point, direction, &Point3::origin())
        .into_iter()
        .any(|roll| {
            let fire = retreat(&nail_pose(point, direction, roll), NOSE_GAP);
            let back = retreat(&fire, NAIL_APPROACH);
            reached_together(cell, &[fire, back], tcp)
        })
}

/// Whether the arm reaches every one of `poses` (robot frame, the carriage at home) from
/// one base position: the base itself, or on a track some carriage position (tried from the
/// one abeam of the first pose outwards).
fn reached_together(cell: &Cell, poses: &[Isometry3<f64>], tcp: &Isometry3<f64>) -> bool {
    let Some(track) = &cell.track else {
        return poses.iter().all(|p| solves_above_floor(cell, p, tcp));
    };
    let Some(first) = poses.first() else {
        return true;
    };
    if poses
        .iter()
        .any(|p| beyond_reach_along_the_rail(cell, track, p, tcp))
    {
        return false;
    }
    let abeam = track.abeam(&Point3::from((cell.robot_base * first).translation.vector));
    track.positions_from(abeam).into_iter().any(|s| {
        // Robot frame at home → robot frame with the carriage at s.
        let shift = track.base_at(s).inverse() * cell.robot_base;
        poses
            .iter()
            .all(|p| solves_above_floor(cell, &(shift * p), tcp))
    })
}

/// Whether the closed form's wrist centre for `pose` (robot frame, carriage at home) lies beyond
/// the arm's reach from every carriage position: on a level rail the wrist centre's height
/// above the shoulder stays put and its distance from the base axis is least at the position
/// abeam of it (within the travel), where both shoulder distances are least too while the
/// wrist lies outside the shoulder's offset; beyond reach there, the IK says "out of reach" at
/// every position the search would try. False when that cannot be shown (no closed form, a
/// rail that is not level in the arm's frame, a wrist inside the shoulder offset).
fn beyond_reach_along_the_rail(
    cell: &Cell,
    track: &crate::cell::track::Track,
    pose: &Isometry3<f64>,
    tcp: &Isometry3<f64>,
) -> bool {
    let Some(opw) = &cell.robot.opw else {
        return false;
    };
    let p = &opw.p;
    let wrist = pose * tcp.inverse() * Point3::new(0.0, 0.0, -p.c4);
    // The wrist centre in base_link with the carriage at s: affine in s.
    let at = |s: f64| {
        cell.robot.mount.inverse() * (track.base_at(s).inverse() * cell.robot_base) * wrist
    };
    let (a, b) = (at(0.0), at(1.0) - at(0.0));
    let along = b.xy().norm_squared();
    if b.z.abs() > 1e-9 || along < 1e-12 {
        return false;
    }
    let s = (-a.coords.xy().dot(&b.xy()) / along).clamp(track.travel[0], track.travel[1]);
    let nearest = a + b * s;
    let rho_2 = nearest.coords.xy().norm_squared() - p.b * p.b;
    let front = rho_2.max(0.0).sqrt() - p.a1;
    let back = front + 2.0 * p.a1;
    if front < 0.0 || back < 0.0 {
        return false;
    }
    let (_, reach) = opw.shoulder_reach();
    let up = nearest.z - p.c1;
    let margin = 1e-6;
    (front * front + up * up).sqrt() > reach + margin
        && (back * back + up * up).sqrt() > reach + margin
}

/// Whether some exact IK solution of a robot-frame TCP pose keeps the arm and its tool above
/// the floor (one solution per branch: whole turns of a joint do not move the arm).
fn solves_above_floor(cell: &Cell, pose: &Isometry3<f64>, tcp: &Isometry3<f64>) -> bool {
    let floor = cell.floor.z - cell.robot_base.translation.z + FLOOR_CLEARANCE;
    cell.robot
        .ik_branches(pose, tcp, &cell.robot.home())
        .is_ok_and(|solutions| {
            solutions
                .iter()
                .any(|q| lowest_point(cell, q) - cell.robot_base.translation.z >= floor)
        })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_pose_pruned_as_beyond_reach_along_the_rail_is_out_of_reach_at_every_position() {
        // Poses over and around a track cell's table, tool pointing down and tilted: wherever
        // the prune says "beyond reach", the IK says so at every carriage position tried, and
        // some poses are pruned and some not (the test is not vacuous).
        let cell = Cell::load("study-abb-track").unwrap();
        let track = cell.track.expect("a track cell");
        let tcp = *cell.tool.tcp("grip").unwrap();
        let (mut pruned, mut kept) = (0, 0);
        let mut seed = 12345u64;
        let mut next = || {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (seed >> 11) as f64 / (1u64 << 53) as f64
        };
        for _ in 0..400 {
            let at = Vector3::new(next() * 8.0 - 2.0, next() * 8.0 - 4.0, next() * 1.5);
            let turn = nalgebra::UnitQuaternion::from_euler_angles(
                std::f64::consts::PI + (next() - 0.5) * 0.6,
                (next() - 0.5) * 0.6,
                next() * 6.0,
            );
            let pose = Isometry3::from_parts(Translation3::from(at), turn);
            if !beyond_reach_along_the_rail(&cell, &track, &pose, &tcp) {
                kept += 1;
                continue;
            }
            pruned += 1;
            let home = cell.robot.home();
            for s in track.positions_from(0.0) {
                let shift = track.base_at(s).inverse() * cell.robot_base;
                let got = cell.robot.ik_branches(&(shift * pose), &tcp, &home);
                assert!(
                    matches!(got, Err(crate::cell::IkFailure::OutOfReach { .. })),
                    "pruned, yet at s = {s} the IK gives {got:?} for {pose:?}"
                );
            }
        }
        assert!(pruned > 20 && kept > 20, "pruned {pruned}, kept {kept}");
    }

    #[test]
    fn parts_reaching_the_same_keys_at_once_search_each_key_once() {
        use rayon::prelude::*;
        use std::sync::atomic::AtomicUsize;
        // Eight parts of 200 items over 50 keys, all at once, one memo.
        let memo: Memo = Mutex::default();
        let searched = AtomicUsize::new(0);
        let items: Vec<i64> = (0..200).map(|i| (i * 7) % 50).collect();
        let key = |item: &i64| {
            let mut k = [0; 10];
            k[0] = *item;
            k
        };
        let search = |item: &i64| {
            searched.fetch_add(1, Ordering::Relaxed);
            std::thread::sleep(std::time::Duration::from_micros(200));
            vec![(*item as f64, *item as f64 + 0.5)]
        };
        let results: Vec<Vec<Vec<(f64, f64)>>> = (0..8)
            .into_par_iter()
            .map(|_| search_each(&items, key, Some(&memo), search))
            .collect();
        assert_eq!(
            searched.load(Ordering::Relaxed),
            50,
            "each key searched once"
        );
        let expected: Vec<Vec<(f64, f64)>> = items
            .iter()
            .map(|&i| vec![(i as f64, i as f64 + 0.5)])
            .collect();
        assert!(results.iter().all(|r| *r == expected));
    }

    #[test]
    fn a_search_that_panics_leaves_no_part_waiting_for_its_key() {
        let memo: Memo = Mutex::default();
        let key = |item: &i64| {
            let mut k = [0; 10];
            k[0] = *item;
            k
        };
        let panicked = std::panic::catch_unwind(|| {
            search_each(&[1, 2, 3], key, Some(&memo), |item: &i64| {
                assert!(*item != 2, "a search that fails");
                vec![(0.0, 1.0)]
            })
        });
        assert!(panicked.is_err());
        // Another part reaching the same keys searches the one given back (on a thread of
        // its own, so a wait that never ends fails the test instead of hanging it).
        let (done, result) = std::sync::mpsc::channel();
        std::thread::spawn(move || {
            let runs = search_each(&[1, 2, 3], key, Some(&memo), |_: &i64| vec![(0.0, 2.0)]);
            let _ = done.send(runs);
        });
        let runs = result
            .recv_timeout(std::time::Duration::from_secs(20))
            .expect("the key given back is searched, not waited for");
        assert_eq!(runs[1], vec![(0.0, 2.0)]);
    }

    #[test]
    fn reached_offsets_come_as_robust_runs() {
        let offsets: Vec<f64> = (0..12).map(|k| k as f64).collect();
        // Reached everywhere but 7: robust (two reached steps each side, or the end of the
        // range) at 0..=4 and 10..=11.
        let ok: Vec<bool> = (0..12).map(|k| k != 7).collect();
        assert_eq!(robustly(&offsets, &ok), vec![(0.0, 4.0), (10.0, 11.0)]);
        let all = vec![true; 12];
        assert_eq!(robustly(&offsets, &all), vec![(0.0, 11.0)]);
        let none = vec![false; 12];
        assert!(robustly(&offsets, &none).is_empty());
    }

    /// The offset the rules choose (most reached, nearest the base) over some candidates.
    fn choice(xs: &[f64], runs: &[Vec<(f64, f64)>]) -> f64 {
        let count = |x: f64| {
            runs.iter()
                .flatten()
                .filter(|(lo, hi)| *lo <= x && x <= *hi)
                .count()
        };
        let best = xs.iter().map(|x| count(*x)).max().unwrap();
        *xs.iter().find(|x| count(**x) == best).unwrap()
    }

    #[test]
    fn the_chosen_offset_is_among_the_fewer_candidates() {
        let offsets = candidate_offsets(0.5, 0.7);
        let walls: BTreeMap<&str, &str> = [("a", "W"), ("b", "W"), ("c", "W"), ("d", "V")]
            .into_iter()
            .collect();
        // Pieces a, b, c of W and d of V, reached over runs of the tried offsets.
        let runs = [
            vec![(0.52, 0.6), (0.65, 0.7)],
            vec![(0.55, 0.62)],
            vec![(0.58, 0.66)],
            vec![],
        ];
        let names = ["a", "b", "c", "d"];
        for every in [false, true] {
            let c = wall_candidates(
                &offsets,
                &walls,
                names.into_iter().zip(&runs),
                std::iter::empty(),
                every,
            );
            let w = &c["W"];
            if !every {
                assert_eq!(w, &vec![0.5, 0.52, 0.55, 0.58, 0.65]);
                // A wall nothing reaches keeps the first offset (where the rules put it).
                assert_eq!(c["V"], vec![0.5]);
            }
            assert_eq!(choice(w, &runs[..3]), choice(&offsets, &runs[..3]));
        }
        assert_eq!(choice(&offsets, &runs[..3]), 0.58);
    }

    #[test]
    fn offsets_cover_the_range_in_whole_millimetres() {
        let xs = candidate_offsets(0.5, 0.55);
        assert_eq!(xs, vec![0.5, 0.51, 0.52, 0.53, 0.54, 0.55]);
    }
}
