//! Collision-free joint-space paths: RRT-Connect (the `rrt` crate) over the executor's
//! collision queries, then shortcutting. Seeded, so the same move always gets the same path.
//!
//! The search checks configurations (`point_free`); every leg of the answer is then checked
//! along its sweep (`leg_free`), which is what the arm really passes through.

use rand_chacha::ChaCha8Rng;
use rand_chacha::rand_core::{RngCore, SeedableRng};
use std::cell::RefCell;

/// How hard the planner tries.
#[derive(Debug, Clone, Copy)]
pub struct Budget {
    /// Random samples RRT-Connect draws before it gives up.
    pub samples: usize,
    /// Joint-space step between tree nodes (rad, Euclidean over all joints).
    pub step: f64,
}

/// Searches with fresh seeds when a found path fails the sweep check: where the two trees
/// meet, the crate's path joins nodes up to two steps apart, a chord that can cut a corner.
const SEARCHES: u64 = 3;

/// A path from `start` to `goal` (both included) whose every leg `leg_free` accepts, or None
/// when the search finds none within `budget`. `bounds` are the joints' sampling ranges.
pub fn connect(
    start: &[f64],
    goal: &[f64],
    bounds: &[(f64, f64)],
    seed: u64,
    budget: Budget,
    point_free: impl FnMut(&[f64]) -> bool,
    mut leg_free: impl FnMut(&[f64], &[f64]) -> bool,
) -> Option<Vec<Vec<f64>>> {
    if start.len() != goal.len() || bounds.len() != start.len() || budget.step <= 0.0 {
        return None;
    }
    let mut point_free = point_free;
    (0..SEARCHES).find_map(|k| {
        let rng = RefCell::new(ChaCha8Rng::seed_from_u64(seed.wrapping_add(k)));
        let sample = || -> Vec<f64> {
            let mut rng = rng.borrow_mut();
            bounds
                .iter()
                .map(|&(lo, hi)| lo + (hi - lo) * unit(rng.next_u64()))
                .collect()
        };
        let mut path = rrt::dual_rrt_connect(
            start,
            goal,
            &mut point_free,
            sample,
            budget.step,
            budget.samples,
        )
        .ok()?;
        // The crate returns both roots; make sure of it rather than rely on it.
        if path.first().is_none_or(|q| q.as_slice() != start) {
            path.insert(0, start.to_vec());
        }
        if path.last().is_none_or(|q| q.as_slice() != goal) {
            path.push(goal.to_vec());
        }
        shortcut(&path, &mut leg_free)
    })
}

/// The path with as many waypoints skipped as the sweep check allows: from each kept
/// waypoint, the farthest later one it reaches in a straight leg (tried halving the gap).
/// None when even a leg between neighbours is blocked (the tree's step was too coarse).
fn shortcut(
    path: &[Vec<f64>],
    leg_free: &mut impl FnMut(&[f64], &[f64]) -> bool,
) -> Option<Vec<Vec<f64>>> {
    let last = path.len() - 1;
    let mut kept = vec![path[0].clone()];
    let mut i = 0;
    while i < last {
        let mut j = last;
        while !leg_free(&path[i], &path[j]) {
            if j == i + 1 {
                return None;
            }
            j = i + (j - i) / 2;
        }
        kept.push(path[j].clone());
        i = j;
    }
    Some(kept)
}

/// A uniform number in [0, 1) from 64 random bits (53 of them, a double's mantissa).
fn unit(bits: u64) -> f64 {
    (bits >> 11) as f64 / (1u64 << 53) as f64
}

/// The sampling range of each joint: its limits, but no further than half a turn beyond
/// where the move starts and ends (continuous wrists would otherwise spread the samples over
/// turns the move never needs).
pub fn sampling_bounds(limits: &[(f64, f64)], start: &[f64], goal: &[f64]) -> Vec<(f64, f64)> {
    limits
        .iter()
        .zip(start.iter().zip(goal))
        .map(|(&(lo, hi), (&s, &g))| {
            let span = std::f64::consts::PI;
            (lo.max(s.min(g) - span), hi.min(s.max(g) + span))
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A point robot in the plane; a wall at x in [-0.2, 0.2] with a gap at y > 0.8.
    fn free(p: &[f64]) -> bool {
        !(p[0].abs() < 0.2 && p[1] < 0.8)
    }

    /// Independent check of a leg: 1000 samples along it.
    fn leg(a: &[f64], b: &[f64]) -> bool {
        (0..=1000).all(|k| {
            let s = k as f64 / 1000.0;
            free(&[a[0] + (b[0] - a[0]) * s, a[1] + (b[1] - a[1]) * s])
        })
    }

    const BOUNDS: [(f64, f64); 2] = [(-1.0, 1.0), (-1.0, 1.0)];
    const BUDGET: Budget = Budget {
        samples: 5000,
        step: 0.05,
    };

    #[test]
    fn goes_through_the_gap_and_every_leg_is_clear() {
        let path = connect(&[-0.8, 0.0], &[0.8, 0.0], &BOUNDS, 7, BUDGET, free, leg).unwrap();
        assert_eq!(path.first().unwrap(), &vec![-0.8, 0.0]);
        assert_eq!(path.last().unwrap(), &vec![0.8, 0.0]);
        assert!(path.windows(2).all(|l| leg(&l[0], &l[1])));
        // The only way round is through the gap above y = 0.8.
        assert!(path.iter().any(|p| p[1] > 0.8));
        // Shortcut: a clear path needs few corners (two suffice here).
        assert!(path.len() <= 6, "{} waypoints", path.len());
    }

    #[test]
    fn same_seed_same_path() {
        let a = connect(&[-0.8, 0.0], &[0.8, 0.0], &BOUNDS, 3, BUDGET, free, leg);
        let b = connect(&[-0.8, 0.0], &[0.8, 0.0], &BOUNDS, 3, BUDGET, free, leg);
        // A found path (two misses would be equal too), round the wall through the gap.
        let path = a.as_ref().expect("a path through the gap");
        assert!(path.iter().any(|p| p[1] > 0.8), "{path:?}");
        assert_eq!(a, b);
    }

    #[test]
    fn an_enclosed_goal_has_no_path() {
        // The goal sits in a box with no opening.
        let boxed = |p: &[f64]| {
            let inside = p[0].abs() < 0.3 && p[1].abs() < 0.3;
            let walls = p[0].abs() < 0.4 && p[1].abs() < 0.4;
            inside || !walls
        };
        let leg_boxed = |a: &[f64], b: &[f64]| {
            (0..=1000).all(|k| {
                let s = k as f64 / 1000.0;
                boxed(&[a[0] + (b[0] - a[0]) * s, a[1] + (b[1] - a[1]) * s])
            })
        };
        let budget = Budget {
            samples: 2000,
            step: 0.05,
        };
        assert!(
            connect(
                &[-0.8, 0.0],
                &[0.0, 0.0],
                &BOUNDS,
                1,
                budget,
                boxed,
                leg_boxed
            )
            .is_none()
        );
    }

    #[test]
    fn bounds_stay_within_limits_and_half_a_turn_of_the_move() {
        let b = sampling_bounds(&[(-6.0, 6.0), (-1.0, 1.0)], &[0.0, 0.0], &[1.0, 0.5]);
        let pi = std::f64::consts::PI;
        assert!((b[0].0 + pi).abs() < 1e-12 && (b[0].1 - (1.0 + pi)).abs() < 1e-12);
        assert_eq!(b[1], (-1.0, 1.0));
    }
}
