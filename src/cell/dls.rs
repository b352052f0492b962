//! Numeric IK fallback for arms without a closed form: damped least squares on the URDF chain,
//! restarted from a few fixed starts. Only a solution whose FK residual is within tolerance is
//! returned; otherwise the best residual is reported as `no_exact_solution`.

use super::ik::{IkFailure, IkOptions, sort_by_distance};
use super::robot::{JointKind, Robot};
use nalgebra::{DMatrix, DVector, Isometry3, Vector3};

/// Iterations per start and number of starts (seed, home, middle of the limits, then fixed
/// pseudo-random starts).
const ITERATIONS: usize = 200;
const STARTS: usize = 12;

impl Robot {
    pub(crate) fn ik_numeric(
        &self,
        target: &Isometry3<f64>,
        seed: &[f64],
        options: &IkOptions,
    ) -> Result<Vec<Vec<f64>>, IkFailure> {
        if let Some(fail) = self.reach_check(target) {
            return Err(fail);
        }
        let limits = self.limits();
        let mut rng = 0x9e37_79b9_7f4a_7c15u64;
        let mut best = (f64::INFINITY, f64::INFINITY);
        for start in 0..STARTS {
            let q0: Vec<f64> = match start {
                0 => seed.to_vec(),
                1 => self.home(),
                2 => limits.iter().map(|&(lo, hi)| finite_mid(lo, hi)).collect(),
                _ => limits
                    .iter()
                    .map(|&(lo, hi)| {
                        rng = rng
                            .wrapping_mul(6364136223846793005)
                            .wrapping_add(1442695040888963407);
                        let u = (rng >> 11) as f64 / (1u64 << 53) as f64;
                        let (lo, hi) =
                            (lo.max(-std::f64::consts::PI), hi.min(std::f64::consts::PI));
                        lo + (hi - lo) * u
                    })
                    .collect(),
            };
            let q = self.dls_from(target, clamp(q0, &limits), &limits, options);
            let (dp, dr) = self.residual(&q, target);
            if dp <= options.position_tolerance && dr <= options.rotation_tolerance {
                let mut sols = vec![q];
                sort_by_distance(&mut sols, seed);
                return Ok(sols);
            }
            if dp + dr < best.0 + best.1 {
                best = (dp, dr);
            }
        }
        Err(IkFailure::NoExactSolution {
            position_error: best.0,
            rotation_error: best.1,
        })
    }

    /// Damped least squares from `q`, with the damping adapted to the error and joints clamped
    /// to their limits after every step.
    fn dls_from(
        &self,
        target: &Isometry3<f64>,
        mut q: Vec<f64>,
        limits: &[(f64, f64)],
        options: &IkOptions,
    ) -> Vec<f64> {
        let n = q.len();
        for _ in 0..ITERATIONS {
            let (tip, frames) = self.tip_and_axes(&q);
            let e_lin = target.translation.vector - tip.translation.vector;
            let e_ang = (target.rotation * tip.rotation.inverse()).scaled_axis();
            if e_lin.norm() <= options.position_tolerance * 0.1
                && e_ang.norm() <= options.rotation_tolerance * 0.1
            {
                break;
            }
            let mut j = DMatrix::<f64>::zeros(6, n);
            for (i, (kind, origin, axis)) in frames.iter().enumerate() {
                let (lin, ang) = match kind {
                    JointKind::Prismatic => (*axis, Vector3::zeros()),
                    _ => (axis.cross(&(tip.translation.vector - origin)), *axis),
                };
                j.fixed_view_mut::<3, 1>(0, i).copy_from(&lin);
                j.fixed_view_mut::<3, 1>(3, i).copy_from(&ang);
            }
            let e =
                DVector::from_column_slice(&[e_lin.x, e_lin.y, e_lin.z, e_ang.x, e_ang.y, e_ang.z]);
            // Damping shrinks as the error shrinks: fast, stable near singular configurations.
            let lambda = (0.05 * e.norm()).clamp(1e-6, 0.1);
            let jjt = &j * j.transpose() + DMatrix::identity(6, 6) * (lambda * lambda);
            let Some(chol) = jjt.cholesky() else { break };
            let dq = j.transpose() * chol.solve(&e);
            for i in 0..n {
                q[i] = (q[i] + dq[i].clamp(-0.3, 0.3)).clamp(limits[i].0, limits[i].1);
            }
        }
        q
    }

    /// Tip pose and, per moving joint, (kind, world origin, world axis).
    fn tip_and_axes(&self, q: &[f64]) -> (Isometry3<f64>, Vec<AxisFrame>) {
        let mut pose = Isometry3::identity();
        let mut frames = Vec::with_capacity(q.len());
        for &j in &self.tip_path {
            let joint = &self.joints[j];
            match joint.dof_index {
                None => pose *= joint.origin,
                Some(i) => {
                    let at = pose * joint.origin;
                    frames.push((
                        joint.kind,
                        at.translation.vector,
                        at.rotation * joint.axis.into_inner(),
                    ));
                    pose *= joint.transform(q[i]);
                }
            }
        }
        (pose, frames)
    }

    /// A sound bound: the tip cannot be farther from the first moving joint than the sum of the
    /// link offsets after it (plus prismatic travel).
    fn reach_check(&self, target: &Isometry3<f64>) -> Option<IkFailure> {
        let first = *self.active.first()?;
        let zero = vec![0.0; self.dof()];
        let poses = self.fk_all_unmounted(&zero);
        let shoulder = (poses[self.joints[first].parent] * self.joints[first].origin)
            .translation
            .vector;
        let mut reach = 0.0;
        let mut on_path = false;
        for &j in &self.tip_path {
            let joint = &self.joints[j];
            if j == first {
                on_path = true;
                continue;
            }
            if on_path {
                reach += joint.origin.translation.vector.norm();
                if joint.kind == JointKind::Prismatic {
                    reach += joint.lower.abs().max(joint.upper.abs());
                }
            }
        }
        let distance = (target.translation.vector - shoulder).norm();
        (distance > reach + 1e-9).then_some(IkFailure::OutOfReach {
            distance,
            reach,
            min_reach: 0.0,
        })
    }
}

/// A moving joint in the world: kind, origin, axis.
type AxisFrame = (JointKind, Vector3<f64>, Vector3<f64>);

fn finite_mid(lo: f64, hi: f64) -> f64 {
    match (lo.is_finite(), hi.is_finite()) {
        (true, true) => (lo + hi) / 2.0,
        _ => 0.0f64.clamp(lo, hi),
    }
}

fn clamp(mut q: Vec<f64>, limits: &[(f64, f64)]) -> Vec<f64> {
    for (v, &(lo, hi)) in q.iter_mut().zip(limits) {
        *v = v.clamp(lo, hi);
    }
    q
}
