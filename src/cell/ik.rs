//! Inverse kinematics for a `Robot`: closed form (OPW) when the robot has OPW parameters, damped
//! least squares otherwise. Every returned solution is checked with the URDF's FK; failures are
//! data with the numbers that explain them.

use super::opw::wrap;
use super::robot::Robot;
use nalgebra::Isometry3;
use serde::{Deserialize, Serialize};
use std::f64::consts::PI;

/// Why IK gave no solution. Serialises as `{"kind": "out_of_reach", "distance": …, …}`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum IkFailure {
    /// The wrist centre (OPW) or the tip (numeric IK) is farther from the shoulder than the arm
    /// reaches, or closer than its inner limit. Distances in m.
    OutOfReach {
        distance: f64,
        reach: f64,
        min_reach: f64,
    },
    /// Every exact solution breaks a joint limit; the one closest to its limits is reported:
    /// `value` of `joint` lies `excess` beyond `limit` (rad or m).
    JointLimit {
        joint: String,
        value: f64,
        limit: f64,
        excess: f64,
    },
    /// Every solution within limits has the wrist closer to singular than asked for:
    /// `margin` is the best wrist angle found, `required` the asked minimum (rad).
    WristSingularity { margin: f64, required: f64 },
    /// No collision-free solution (filled by the executor): the colliding pair of bodies.
    AllSolutionsCollide { pair: [String; 2] },
    /// The numeric solver could not get the tip onto the pose: best residual left (m, rad).
    NoExactSolution {
        position_error: f64,
        rotation_error: f64,
    },
    /// A straight TCP line leaves every IK branch it starts on: following the branch,
    /// `joint` would jump `jump` (rad or m) between two samples, `at` (0..1) of the way along.
    BranchJump { joint: String, jump: f64, at: f64 },
    /// Both ends of a move are reachable and clear, but no collision-free path between them
    /// was found (filled by the executor's planner): the pair of bodies on the direct path.
    PathBlocked { pair: [String; 2] },
    /// The pose has NaN or infinite numbers.
    InvalidPose,
}

impl std::fmt::Display for IkFailure {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            IkFailure::OutOfReach {
                distance,
                reach,
                min_reach,
            } => write!(
                f,
                "out of reach: {distance:.4} m from the shoulder, the arm reaches {min_reach:.4}..{reach:.4} m"
            ),
            IkFailure::JointLimit {
                joint,
                value,
                limit,
                excess,
            } => write!(
                f,
                "joint limit: {joint} would be {value:.4}, {excess:.4} beyond its limit {limit:.4}"
            ),
            IkFailure::WristSingularity { margin, required } => write!(
                f,
                "wrist singularity: wrist angle {margin:.4} rad, at least {required:.4} rad needed"
            ),
            IkFailure::AllSolutionsCollide { pair } => {
                write!(f, "every solution collides: {} with {}", pair[0], pair[1])
            }
            IkFailure::NoExactSolution {
                position_error,
                rotation_error,
            } => write!(
                f,
                "no exact solution: best residual {position_error:.3e} m, {rotation_error:.3e} rad"
            ),
            IkFailure::BranchJump { joint, jump, at } => write!(
                f,
                "no continuous solution along the straight line: {joint} would jump {jump:.3} between two poses {:.0} % of the way",
                at * 100.0
            ),
            IkFailure::PathBlocked { pair } => write!(
                f,
                "no collision-free path to the pose: {} runs into {} on the direct path and the planner found no way around",
                pair[0], pair[1]
            ),
            IkFailure::InvalidPose => write!(f, "the pose is not finite"),
        }
    }
}

impl std::error::Error for IkFailure {}

/// Tuning of `Robot::ik_with`.
#[derive(Debug, Clone, Copy)]
pub struct IkOptions {
    /// A solution is accepted only if FK puts the tip within this distance (m) ...
    pub position_tolerance: f64,
    /// ... and this rotation angle (rad) of the target.
    pub rotation_tolerance: f64,
    /// Minimum wrist angle (rad, distance of θ5 from 0 and π); 0 accepts singular solutions
    /// (the free wrist angle is then taken from the seed).
    pub wrist_margin: f64,
}

impl Default for IkOptions {
    fn default() -> Self {
        IkOptions {
            position_tolerance: 1e-6,
            rotation_tolerance: 1e-6,
            wrist_margin: 0.0,
        }
    }
}

impl Robot {
    /// All joint solutions (within limits, closest to `seed` first) that put the TCP at `pose`.
    /// `pose` is the TCP in `base_link`; `tcp` is the TCP in the tip frame (`tool0`).
    pub fn ik(
        &self,
        pose: &Isometry3<f64>,
        tcp: &Isometry3<f64>,
        seed: &[f64],
    ) -> Result<Vec<Vec<f64>>, IkFailure> {
        self.ik_with(pose, tcp, seed, &IkOptions::default())
    }

    /// `ik` with explicit tolerances and wrist margin.
    pub fn ik_with(
        &self,
        pose: &Isometry3<f64>,
        tcp: &Isometry3<f64>,
        seed: &[f64],
        options: &IkOptions,
    ) -> Result<Vec<Vec<f64>>, IkFailure> {
        self.ik_variants(pose, tcp, seed, options, Variants::All)
    }

    /// One solution per closed-form branch (of each, the whole-turn copy nearest `seed`),
    /// closest to `seed` first: `ik` without the copies that differ only by whole turns of a
    /// joint, which leave the arm's shape as it is (what a question about the arm's shape,
    /// such as how low it reaches, needs). Robots without a closed form: `ik`.
    pub fn ik_branches(
        &self,
        pose: &Isometry3<f64>,
        tcp: &Isometry3<f64>,
        seed: &[f64],
    ) -> Result<Vec<Vec<f64>>, IkFailure> {
        self.ik_variants(pose, tcp, seed, &IkOptions::default(), Variants::Nearest)
    }

    /// `ik_with`, keeping `variants` of the closed form's whole-turn copies.
    fn ik_variants(
        &self,
        pose: &Isometry3<f64>,
        tcp: &Isometry3<f64>,
        seed: &[f64],
        options: &IkOptions,
        variants: Variants,
    ) -> Result<Vec<Vec<f64>>, IkFailure> {
        assert_eq!(seed.len(), self.dof(), "seed length");
        let target = self.tip_target(pose, tcp)?;
        match &self.opw {
            Some(_) => Ok(self
                .ik_closed_form(&target, seed, options, variants)?
                .into_iter()
                .map(|q| q.to_vec())
                .collect()),
            None => self.ik_numeric(&target, seed, options),
        }
    }

    /// How far (m) the wrist centre for this TCP pose is inside the arm's reach from the shoulder
    /// (negative: out of reach). `None` for robots without a closed form.
    pub fn reach_margin(&self, pose: &Isometry3<f64>, tcp: &Isometry3<f64>) -> Option<f64> {
        let opw = self.opw.as_ref()?;
        let target = self.mount.inverse() * pose * tcp.inverse();
        let [front, _] = opw.solve(&target, 0.0).shoulder_distance;
        let (min_reach, reach) = opw.shoulder_reach();
        Some((reach - front).min(front - min_reach))
    }

    /// Reach of the wrist centre from the shoulder (min, max) in m, for closed-form robots.
    pub fn shoulder_reach(&self) -> Option<(f64, f64)> {
        self.opw.as_ref().map(|o| o.shoulder_reach())
    }

    /// 6-axis IK as fixed-size arrays (the executor's and the bench's form); same answers as
    /// `ik`. Panics for robots without 6 moving joints (a programming error).
    pub fn ik6(
        &self,
        pose: &Isometry3<f64>,
        tcp: &Isometry3<f64>,
        seed: &[f64; 6],
    ) -> Result<Vec<[f64; 6]>, IkFailure> {
        self.ik6_with(pose, tcp, seed, &IkOptions::default())
    }

    /// `ik6` with explicit tolerances and wrist margin.
    pub fn ik6_with(
        &self,
        pose: &Isometry3<f64>,
        tcp: &Isometry3<f64>,
        seed: &[f64; 6],
        options: &IkOptions,
    ) -> Result<Vec<[f64; 6]>, IkFailure> {
        assert_eq!(self.dof(), 6, "ik6 needs a 6-axis robot");
        let target = self.tip_target(pose, tcp)?;
        match &self.opw {
            Some(_) => self.ik_closed_form(&target, seed, options, Variants::All),
            None => Ok(self
                .ik_numeric(&target, seed, options)?
                .into_iter()
                .map(|s| std::array::from_fn(|i| s[i]))
                .collect()),
        }
    }

    /// The solution of `ik` closest to `seed` (its first), without listing the others: the
    /// distance to the seed is a sum over joints, so each closed-form branch contributes only
    /// its whole-turn copy nearest the seed. Same answer and same failures as `ik`.
    pub fn ik_closest(
        &self,
        pose: &Isometry3<f64>,
        tcp: &Isometry3<f64>,
        seed: &[f64],
    ) -> Result<Vec<f64>, IkFailure> {
        if self.opw.is_some() && self.dof() == 6 {
            let seed6: [f64; 6] = std::array::from_fn(|i| seed[i]);
            return self.ik6_closest(pose, tcp, &seed6).map(|q| q.to_vec());
        }
        let mut solutions = self.ik(pose, tcp, seed)?;
        Ok(solutions.swap_remove(0))
    }

    /// `ik6`'s first solution, computed as `ik_closest` does.
    pub fn ik6_closest(
        &self,
        pose: &Isometry3<f64>,
        tcp: &Isometry3<f64>,
        seed: &[f64; 6],
    ) -> Result<[f64; 6], IkFailure> {
        assert_eq!(self.dof(), 6, "ik6 needs a 6-axis robot");
        let target = self.tip_target(pose, tcp)?;
        let mut solutions = match &self.opw {
            Some(_) => {
                let options = IkOptions::default();
                if let Some(q) = self.nearest_exact(&target, seed, &options) {
                    return Ok(q);
                }
                // None found this way: the full pass finds why (or the same answer).
                self.ik_closed_form(&target, seed, &options, Variants::Nearest)?
            }
            None => {
                let q = self
                    .ik_numeric(&target, seed, &IkOptions::default())?
                    .swap_remove(0);
                return Ok(std::array::from_fn(|i| q[i]));
            }
        };
        Ok(solutions.swap_remove(0))
    }

    /// The tool0 pose in `base_link` (the mount undone) that puts `tcp` on `pose` (base frame);
    /// Err(InvalidPose) when either is not finite.
    fn tip_target(
        &self,
        pose: &Isometry3<f64>,
        tcp: &Isometry3<f64>,
    ) -> Result<Isometry3<f64>, IkFailure> {
        let finite = |m: nalgebra::Matrix4<f64>| m.iter().all(|v| v.is_finite());
        if !finite(pose.to_homogeneous()) || !finite(tcp.to_homogeneous()) {
            return Err(IkFailure::InvalidPose);
        }
        Ok(self.mount.inverse() * pose * tcp.inverse())
    }

    /// Distance (m) and rotation angle (rad) between the tip at `q` and `target`.
    pub(crate) fn residual(&self, q: &[f64], target: &Isometry3<f64>) -> (f64, f64) {
        let got = self.fk_tip_unmounted(q);
        (
            (got.translation.vector - target.translation.vector).norm(),
            got.rotation.angle_to(&target.rotation),
        )
    }

    /// The six moving joints' limits (closed form).
    fn limits6(&self) -> [(f64, f64); 6] {
        std::array::from_fn(|i| {
            let j = &self.joints[self.active[i]];
            (j.lower, j.upper)
        })
    }

    /// `ik_closed_form`'s first answer with `Variants::Nearest`, checking candidates with FK
    /// nearest first and stopping at the first exact one (one FK instead of up to eight on a
    /// path sampled densely). Filtering and sorting commute, so it is the same answer; `None`
    /// when there is none, for the full pass to say why.
    fn nearest_exact(
        &self,
        target: &Isometry3<f64>,
        seed: &[f64; 6],
        options: &IkOptions,
    ) -> Option<[f64; 6]> {
        let opw = self.opw.as_ref()?;
        let raw = opw.solve(target, seed[3]);
        let limits = self.limits6();
        let mut nearest: Vec<([f64; 6], f64)> = Vec::with_capacity(8);
        // (distance to the seed, generation order, raw candidate) as `ik_closed_form` sorts.
        let mut keys: Vec<(f64, usize, usize)> = Vec::with_capacity(8);
        for k in 0..raw.count {
            let wrist = wrist_clearance(raw.wrist_angles[k]);
            let before = nearest.len();
            push_nearest_variant(&raw.candidates[k], &limits, wrist, seed, &mut nearest);
            if nearest.len() > before && wrist >= options.wrist_margin {
                keys.push((seed_distance(&nearest[before].0, seed), before, k));
            }
        }
        keys.sort_unstable_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
        keys.into_iter()
            .find(|&(_, _, k)| {
                let (dp, dr) = self.residual(&raw.candidates[k], target);
                dp <= options.position_tolerance && dr <= options.rotation_tolerance
            })
            .map(|(_, i, _)| nearest[i].0)
    }

    /// Closed-form IK on fixed-size arrays (no allocation per candidate).
    fn ik_closed_form(
        &self,
        target: &Isometry3<f64>,
        seed: &[f64],
        options: &IkOptions,
        variants: Variants,
    ) -> Result<Vec<[f64; 6]>, IkFailure> {
        let opw = self.opw.as_ref().expect("closed form");
        let raw = opw.solve(target, seed[3]);
        if raw.count == 0 {
            let (min_reach, reach) = opw.shoulder_reach();
            let [front, back] = raw.shoulder_distance;
            // Report the shoulder position that is nearer to being in range.
            let miss = |d: f64| (d - reach).max(min_reach - d);
            let distance = if miss(front) <= miss(back) {
                front
            } else {
                back
            };
            return Err(IkFailure::OutOfReach {
                distance,
                reach,
                min_reach,
            });
        }
        let limits = self.limits6();
        let mut within: Vec<([f64; 6], f64)> = Vec::with_capacity(32);
        // FK check only where it matters: candidates with copies inside the limits now, the
        // others only if nothing is left (to tell a joint limit from a numeric failure).
        let exact = |q: &[f64; 6]| {
            let (dp, dr) = self.residual(q, target);
            (
                dp <= options.position_tolerance && dr <= options.rotation_tolerance,
                dp,
                dr,
            )
        };
        let mut beyond_limits = [0usize; 8];
        let mut n_beyond = 0;
        let mut best_residual = (f64::INFINITY, f64::INFINITY);
        for k in 0..raw.count {
            let cand = &raw.candidates[k];
            let wrist = wrist_clearance(raw.wrist_angles[k]);
            let before = within.len();
            match variants {
                Variants::All => push_turn_variants(cand, &limits, wrist, &mut within),
                Variants::Nearest => push_nearest_variant(cand, &limits, wrist, seed, &mut within),
            }
            if within.len() == before {
                beyond_limits[n_beyond] = k;
                n_beyond += 1;
                continue;
            }
            let (ok, dp, dr) = exact(cand);
            if !ok {
                within.truncate(before);
                if dp + dr < best_residual.0 + best_residual.1 {
                    best_residual = (dp, dr);
                }
            }
        }
        let mut best_violation: Option<(f64, IkFailure)> = None;
        if within.is_empty() {
            for &k in &beyond_limits[..n_beyond] {
                let cand = &raw.candidates[k];
                let (ok, dp, dr) = exact(cand);
                if !ok {
                    if dp + dr < best_residual.0 + best_residual.1 {
                        best_residual = (dp, dr);
                    }
                    continue;
                }
                let failure = self.worst_limit(cand, &limits);
                if let IkFailure::JointLimit { excess, .. } = failure
                    && best_violation.as_ref().is_none_or(|(e, _)| excess < *e)
                {
                    best_violation = Some((excess, failure));
                }
            }
        }
        if within.is_empty() {
            return Err(match best_violation {
                Some((_, failure)) => failure,
                None => IkFailure::NoExactSolution {
                    position_error: best_residual.0,
                    rotation_error: best_residual.1,
                },
            });
        }
        let best_wrist = within.iter().map(|(_, w)| *w).fold(0.0, f64::max);
        within.retain(|(_, w)| *w >= options.wrist_margin);
        if within.is_empty() {
            return Err(IkFailure::WristSingularity {
                margin: best_wrist,
                required: options.wrist_margin,
            });
        }
        // Sort small (distance, index) keys, ties by generation order (deterministic), then
        // gather, dropping exact duplicates (equal distance, so adjacent).
        let mut keys: Vec<(f64, usize)> = within
            .iter()
            .enumerate()
            .map(|(i, (q, _))| (seed_distance(q, seed), i))
            .collect();
        keys.sort_unstable_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
        let mut out: Vec<[f64; 6]> = Vec::with_capacity(keys.len());
        for (_, i) in keys {
            let q = within[i].0;
            if out.last().is_some_and(|last: &[f64; 6]| {
                last.iter().zip(&q).all(|(x, y)| (x - y).abs() < 1e-9)
            }) {
                continue;
            }
            out.push(q);
        }
        Ok(out)
    }

    /// The limit violation of `q` that matters most (largest excess, whole turns allowed).
    fn worst_limit(&self, q: &[f64], limits: &[(f64, f64)]) -> IkFailure {
        let mut worst: Option<(f64, usize, f64, f64)> = None;
        for (i, (&v, &(lo, hi))) in q.iter().zip(limits).enumerate() {
            // The whole-turn copy of v nearest to the allowed range.
            let nearest = if self.joints[self.active[i]].kind == super::robot::JointKind::Prismatic
            {
                v
            } else {
                let mid = (lo + hi) / 2.0;
                mid + wrap(v - mid)
            };
            let (excess, limit) = if nearest < lo {
                (lo - nearest, lo)
            } else if nearest > hi {
                (nearest - hi, hi)
            } else {
                (0.0, lo)
            };
            if excess > 0.0 && worst.is_none_or(|(e, ..)| excess > e) {
                worst = Some((excess, i, nearest, limit));
            }
        }
        let (excess, i, value, limit) = worst.unwrap_or((0.0, 0, q[0], limits[0].0));
        IkFailure::JointLimit {
            joint: self.joints[self.active[i]].name.clone(),
            value,
            limit,
            excess,
        }
    }
}

/// How far the wrist angle θ5 is from singular (from 0 and from π, rad).
fn wrist_clearance(t5: f64) -> f64 {
    t5.abs().min(PI - t5.abs())
}

/// Squared joint-space distance from `seed`, the order solutions are returned in.
fn seed_distance(q: &[f64; 6], seed: &[f64]) -> f64 {
    q.iter().zip(seed).map(|(a, b)| (a - b).powi(2)).sum()
}

/// Which whole-turn copies of a closed-form branch to keep.
#[derive(Clone, Copy)]
enum Variants {
    /// Every copy within the limits.
    All,
    /// Per joint, the copy nearest the seed (the first of equals, as `All` sorts them).
    Nearest,
}

/// Push the copy of `q` shifted by whole turns that fits the limits and lies nearest `seed`,
/// joint by joint: the one `push_turn_variants` would sort first.
fn push_nearest_variant(
    q: &[f64; 6],
    limits: &[(f64, f64); 6],
    wrist: f64,
    seed: &[f64],
    out: &mut Vec<([f64; 6], f64)>,
) {
    let mut best = [0.0f64; 6];
    for i in 0..6 {
        let (copies, count) = turn_copies(q[i], limits[i]);
        let Some(&first) = copies[..count].first() else {
            return;
        };
        // The first of equals, as the sort by distance (ties by generation order) keeps.
        best[i] = copies[..count].iter().fold(first, |c, &v| {
            if (v - seed[i]).powi(2) < (c - seed[i]).powi(2) {
                v
            } else {
                c
            }
        });
    }
    out.push((best, wrist));
}

/// The copies of one joint value shifted by whole turns that fit its limits, in increasing
/// order: up to 4 (a range of up to 3 turns, e.g. ±400°, holds at most 3). A continuous
/// joint's wrapped value stands for all its turns.
fn turn_copies(v: f64, (lo, hi): (f64, f64)) -> ([f64; 4], usize) {
    let mut copies = [0.0f64; 4];
    if !(lo.is_finite() && hi.is_finite()) {
        copies[0] = v;
        return (copies, 1);
    }
    let mut count = 0;
    let mut x = v + 2.0 * PI * ((lo - v) / (2.0 * PI)).ceil();
    while x <= hi + 1e-12 && count < 4 {
        copies[count] = x.clamp(lo, hi);
        count += 1;
        x += 2.0 * PI;
    }
    (copies, count)
}

/// Push every copy of `q` shifted by whole turns that fits the limits (all joints revolute).
fn push_turn_variants(
    q: &[f64; 6],
    limits: &[(f64, f64); 6],
    wrist: f64,
    out: &mut Vec<([f64; 6], f64)>,
) {
    let mut options = [[0.0f64; 4]; 6];
    let mut counts = [0usize; 6];
    for i in 0..6 {
        (options[i], counts[i]) = turn_copies(q[i], limits[i]);
        if counts[i] == 0 {
            return;
        }
    }
    let mut idx = [0usize; 6];
    loop {
        out.push((std::array::from_fn(|i| options[i][idx[i]]), wrist));
        // Odometer over the option indices.
        let mut k = 5;
        loop {
            idx[k] += 1;
            if idx[k] < counts[k] {
                break;
            }
            idx[k] = 0;
            if k == 0 {
                return;
            }
            k -= 1;
        }
    }
}

/// Sort joint vectors by Euclidean distance to `seed` (ties: lexicographic, for determinism).
pub(crate) fn sort_by_distance(sols: &mut Vec<Vec<f64>>, seed: &[f64]) {
    let dist = |q: &[f64]| -> f64 { q.iter().zip(seed).map(|(a, b)| (a - b).powi(2)).sum() };
    // Distances computed once per solution, not per comparison.
    let mut keyed: Vec<(f64, Vec<f64>)> = sols.drain(..).map(|q| (dist(&q), q)).collect();
    keyed.sort_by(|(da, a), (db, b)| {
        da.total_cmp(db).then_with(|| {
            a.iter()
                .zip(b.iter())
                .fold(std::cmp::Ordering::Equal, |o, (x, y)| {
                    o.then(x.total_cmp(y))
                })
        })
    });
    sols.extend(keyed.into_iter().map(|(_, q)| q));
}
