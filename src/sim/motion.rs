//! Robot motions as the controller of a position-controlled industrial arm runs them: joint
//! moves with a synchronised trapezoidal profile inside every joint's velocity and acceleration
//! limit, and straight-line tool moves (IK at every control step) with a trapezoidal profile
//! along the line.

use crate::cell::Robot;
use nalgebra::{Isometry3, UnitQuaternion, Vector3};

/// A normalised trapezoidal profile: position s(t) from 0 to 1 over `duration`.
#[derive(Debug, Clone, Copy)]
pub struct Profile {
    pub duration: f64,
    /// Time spent accelerating (= decelerating).
    accel_time: f64,
    /// Peak ds/dt.
    peak: f64,
}

impl Profile {
    /// The fastest profile whose ds/dt stays within `max_rate` and d²s/dt² within `max_accel`.
    pub fn fastest(max_rate: f64, max_accel: f64) -> Profile {
        if !(max_rate.is_finite() && max_accel.is_finite()) || max_rate <= 0.0 || max_accel <= 0.0 {
            return Profile {
                duration: 0.0,
                accel_time: 0.0,
                peak: 0.0,
            };
        }
        if max_rate * max_rate / max_accel < 1.0 {
            // Reaches the peak rate: accelerate, cruise, decelerate.
            let accel_time = max_rate / max_accel;
            Profile {
                duration: 1.0 / max_rate + accel_time,
                accel_time,
                peak: max_rate,
            }
        } else {
            // Triangle: accelerate to half way, then decelerate.
            let accel_time = (1.0 / max_accel).sqrt();
            Profile {
                duration: 2.0 * accel_time,
                accel_time,
                peak: max_accel * accel_time,
            }
        }
    }

    /// s at time t (clamped to 0..=1 outside the profile).
    pub fn at(&self, t: f64) -> f64 {
        if self.duration <= 0.0 || t >= self.duration {
            return 1.0;
        }
        if t <= 0.0 {
            return 0.0;
        }
        let a = self.peak / self.accel_time;
        let s = if t < self.accel_time {
            0.5 * a * t * t
        } else if t <= self.duration - self.accel_time {
            0.5 * self.peak * self.accel_time + self.peak * (t - self.accel_time)
        } else {
            let left = self.duration - t;
            1.0 - 0.5 * a * left * left
        };
        s.clamp(0.0, 1.0)
    }
}

/// A joint-space move from `from` to `to`.
#[derive(Debug, Clone)]
pub struct JointMove {
    pub from: Vec<f64>,
    pub to: Vec<f64>,
    pub profile: Profile,
}

impl JointMove {
    /// The fastest synchronised move within the robot's joint limits scaled by `speed` (0..=1).
    pub fn new(robot: &Robot, from: &[f64], to: &[f64], speed: f64) -> JointMove {
        let mut rate = f64::INFINITY;
        let mut accel = f64::INFINITY;
        for (i, joint) in robot.active_joints().enumerate() {
            let d = (to[i] - from[i]).abs();
            if d < 1e-12 {
                continue;
            }
            rate = rate.min(joint.velocity * speed / d);
            accel = accel.min(joint.acceleration * speed / d);
        }
        JointMove {
            from: from.to_vec(),
            to: to.to_vec(),
            profile: Profile::fastest(rate, accel),
        }
    }

    pub fn at(&self, t: f64) -> Vec<f64> {
        let s = self.profile.at(t);
        self.from
            .iter()
            .zip(&self.to)
            .map(|(a, b)| a + (b - a) * s)
            .collect()
    }
}

/// A straight-line move of the TCP from `from` to `to` (robot frame), the orientation turning
/// evenly along the way.
#[derive(Debug, Clone)]
pub struct LinearMove {
    pub from: Isometry3<f64>,
    pub to: Isometry3<f64>,
    /// The programmed speed along the line, m/s.
    pub speed: f64,
    pub profile: Profile,
}

impl LinearMove {
    /// At `speed` m/s and `accel` m/s² along the line (a pure rotation takes 1 rad/s).
    pub fn new(from: Isometry3<f64>, to: Isometry3<f64>, speed: f64, accel: f64) -> LinearMove {
        let length = (to.translation.vector - from.translation.vector).norm();
        let angle = from.rotation.angle_to(&to.rotation);
        let scale = length.max(angle * 0.2).max(1e-9);
        LinearMove {
            from,
            to,
            speed,
            profile: Profile::fastest(speed / scale, accel / scale),
        }
    }

    /// The TCP pose at s (0..=1) along the line.
    pub fn pose_at_fraction(&self, s: f64) -> Isometry3<f64> {
        let t: Vector3<f64> = self
            .from
            .translation
            .vector
            .lerp(&self.to.translation.vector, s);
        let r: UnitQuaternion<f64> = self.from.rotation.slerp(&self.to.rotation, s);
        Isometry3::from_parts(t.into(), r)
    }

    pub fn pose_at(&self, t: f64) -> Isometry3<f64> {
        self.pose_at_fraction(self.profile.at(t))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn profiles_end_at_one_and_respect_limits() {
        for (rate, accel) in [(2.0, 4.0), (0.5, 10.0), (10.0, 0.5)] {
            let p = Profile::fastest(rate, accel);
            assert!((p.at(p.duration) - 1.0).abs() < 1e-12);
            let dt = p.duration / 2000.0;
            let mut prev_v = 0.0;
            for k in 0..2000 {
                let t = k as f64 * dt;
                let v = (p.at(t + dt) - p.at(t)) / dt;
                assert!(v <= rate * 1.001, "rate {v} > {rate}");
                assert!((v - prev_v).abs() / dt <= accel * 1.05 + 1e-6);
                prev_v = v;
            }
        }
    }

    #[test]
    fn a_zero_move_takes_no_time() {
        let p = Profile::fastest(f64::INFINITY, f64::INFINITY);
        assert_eq!(p.duration, 0.0);
        assert_eq!(p.at(0.0), 1.0);
    }
}
