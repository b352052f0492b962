//! A linear track (a 7th axis): the robot's base rides a carriage along a straight,
//! horizontal rail. Defined in the cell file, not in the URDF: the carriage only translates
//! the base, so the arm's kinematics (and its exact IK) are unchanged; the executor chooses a
//! carriage position per element and moves the carriage between them.

use nalgebra::{Isometry3, Point3, Translation3, Vector3};

/// Carriage positions are tried this far apart (m).
pub const CARRIAGE_STEP: f64 = 0.1;

#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Track {
    /// base_link with the carriage at position 0 (the cell file's `base_position`), cell frame.
    pub home: Isometry3<f64>,
    /// Unit direction of travel, cell frame, horizontal.
    pub direction: Vector3<f64>,
    /// The carriage's travel from home, m: `[min, max]`, `min <= 0 <= max`.
    pub travel: [f64; 2],
    /// Programmed carriage speed, m/s.
    pub speed: f64,
    /// Carriage acceleration and deceleration, m/s².
    pub accel: f64,
}

impl Track {
    /// base_link with the carriage at `s`.
    pub fn base_at(&self, s: f64) -> Isometry3<f64> {
        Translation3::from(self.direction * s) * self.home
    }

    /// The carriage position of a base pose (its offset from home along the rail).
    pub fn position_of(&self, base: &Isometry3<f64>) -> f64 {
        (base.translation.vector - self.home.translation.vector).dot(&self.direction)
    }

    /// The position within the travel that puts the base abeam of `point` (cell frame).
    pub fn abeam(&self, point: &Point3<f64>) -> f64 {
        self.clamp((point.coords - self.home.translation.vector).dot(&self.direction))
    }

    pub fn clamp(&self, s: f64) -> f64 {
        s.clamp(self.travel[0], self.travel[1])
    }

    /// Every carriage position tried, nearest `from` first: `from` itself, then outwards in
    /// steps of [`CARRIAGE_STEP`] on both sides (the nearer side first), within the travel.
    pub fn positions_from(&self, from: f64) -> Vec<f64> {
        let from = self.clamp(from);
        let mut positions = vec![from];
        let reach = (self.travel[1] - self.travel[0]) / CARRIAGE_STEP;
        for k in 1..=(reach.ceil() as usize) {
            let d = k as f64 * CARRIAGE_STEP;
            for s in [from - d, from + d] {
                if s >= self.travel[0] - 1e-9 && s <= self.travel[1] + 1e-9 {
                    positions.push(self.clamp(s));
                }
            }
        }
        positions
    }

    /// How long the carriage takes to move `distance` (m): a trapezoidal (or, for short
    /// moves, triangular) speed profile.
    pub fn travel_time(&self, distance: f64) -> f64 {
        let d = distance.abs();
        let ramp = self.speed / self.accel;
        if d >= ramp * self.speed {
            d / self.speed + ramp
        } else {
            2.0 * (d / self.accel).sqrt()
        }
    }

    /// Distance covered `t` seconds into a move of `distance` (signed), on the profile of
    /// [`Track::travel_time`].
    pub fn covered(&self, distance: f64, t: f64) -> f64 {
        let d = distance.abs();
        let total = self.travel_time(d);
        let t = t.clamp(0.0, total);
        let v = self.speed.min((d * self.accel).sqrt());
        let ramp = v / self.accel;
        let x = if t < ramp {
            0.5 * self.accel * t * t
        } else if t <= total - ramp {
            0.5 * self.accel * ramp * ramp + v * (t - ramp)
        } else {
            let left = total - t;
            d - 0.5 * self.accel * left * left
        };
        x.min(d).copysign(distance)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn track() -> Track {
        Track {
            home: Isometry3::translation(0.0, 0.0, 0.0),
            direction: Vector3::y(),
            travel: [-3.0, 3.0],
            speed: 1.0,
            accel: 0.5,
        }
    }

    #[test]
    fn positions_start_at_the_current_one_and_stay_on_the_rail() {
        let t = track();
        let p = t.positions_from(2.85);
        assert_eq!(p[0], 2.85);
        assert!(p.iter().all(|s| (-3.0..=3.0).contains(s)));
        // Outwards: every later position is at least as far from the start.
        assert!(
            p.windows(2)
                .all(|w| (w[1] - 2.85).abs() >= (w[0] - 2.85).abs() - 1e-12)
        );
        assert!(p.iter().any(|s| (*s + 3.0).abs() < 0.06));
    }

    #[test]
    fn the_profile_covers_the_distance_in_the_travel_time() {
        let t = track();
        for d in [0.05, 1.0, 2.0, 5.5, -4.0] {
            let total = t.travel_time(d);
            assert!((t.covered(d, total) - d).abs() < 1e-9);
            assert_eq!(t.covered(d, 0.0), 0.0);
            // Monotone and never faster than the programmed speed.
            let mut last = 0.0;
            for k in 1..=200 {
                let x = t.covered(d, total * k as f64 / 200.0).abs();
                assert!(x + 1e-12 >= last);
                assert!(x - last <= t.speed * total / 200.0 + 1e-9);
                last = x;
            }
        }
        // 5.5 m at 1 m/s with 0.5 m/s² ramps: 5.5 s cruising plus 2 s of ramps.
        assert!((t.travel_time(5.5) - 7.5).abs() < 1e-12);
    }

    #[test]
    fn base_moves_along_the_rail() {
        let t = track();
        let b = t.base_at(1.5);
        assert!((b.translation.vector - Vector3::new(0.0, 1.5, 0.0)).norm() < 1e-12);
        assert!((t.position_of(&b) - 1.5).abs() < 1e-12);
        assert_eq!(t.abeam(&Point3::new(2.0, 7.0, 0.0)), 3.0);
    }
}
