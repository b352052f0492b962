//! Closed-form inverse kinematics for 6-axis arms with an ortho-parallel base and a spherical
//! wrist (OPW: Brandstötter, Angerer & Hofbaur, 2014). Written for this project from the paper's
//! equations; the parameters are checked against the URDF chain when a robot is loaded.

use super::meta::OpwParams;
use nalgebra::{Isometry3, Vector3};
use std::f64::consts::PI;

#[derive(Debug, Clone)]
pub(crate) struct Opw {
    pub p: OpwParams,
}

/// What the closed form found for one tool0 pose, before joint limits.
pub(crate) struct OpwResult {
    /// Joint vectors in URDF joint values (not yet wrapped or limit-checked).
    pub candidates: [[f64; 6]; 8],
    /// Number of valid entries in `candidates` and `wrist_angles`.
    pub count: usize,
    /// Wrist-centre distance from the front and the back shoulder position, m.
    pub shoulder_distance: [f64; 2],
    /// Internal wrist angle θ5 of each candidate (0 = axes 4 and 6 aligned).
    pub wrist_angles: [f64; 8],
}

impl Opw {
    /// The solver of parameters `p` (the robot checks them against its URDF chain when it
    /// loads: `Robot::checked_opw`).
    pub fn new(p: OpwParams) -> Opw {
        Opw { p }
    }

    /// Reach of the wrist centre from the shoulder: (min, max), m.
    pub fn shoulder_reach(&self) -> (f64, f64) {
        let k = (self.p.a2 * self.p.a2 + self.p.c3 * self.p.c3).sqrt();
        ((self.p.c2 - k).abs(), self.p.c2 + k)
    }

    /// Internal angle θ of joint i from URDF joint value q.
    pub fn internal(&self, i: usize, q: f64) -> f64 {
        q * self.p.signs[i] - self.p.offsets[i]
    }

    /// OPW forward kinematics (base_link → tool0), used to check parameters.
    pub fn forward(&self, q: &[f64; 6]) -> Isometry3<f64> {
        use nalgebra::{Matrix3, Rotation3, Translation3, UnitQuaternion};
        let p = &self.p;
        let t: [f64; 6] = std::array::from_fn(|i| self.internal(i, q[i]));
        let (s1, c1) = t[0].sin_cos();
        let (s2, c2) = t[1].sin_cos();
        let (s23, c23) = (t[1] + t[2]).sin_cos();
        let (s4, c4) = t[3].sin_cos();
        let (s5, c5) = t[4].sin_cos();
        let (s6, c6) = t[5].sin_cos();
        // Wrist centre.
        let cx1 = p.c2 * s2 + p.c3 * s23 + p.a2 * c23 + p.a1;
        let cy1 = p.b;
        let cz1 = p.c2 * c2 + p.c3 * c23 - p.a2 * s23;
        let wc = Vector3::new(cx1 * c1 - cy1 * s1, cx1 * s1 + cy1 * c1, cz1 + p.c1);
        // Rotation: R_0c (arm) · Rz(θ4) Ry(θ5) Rz(θ6) (wrist).
        let r0c = Matrix3::new(
            c1 * c23,
            -s1,
            c1 * s23, //
            s1 * c23,
            c1,
            s1 * s23, //
            -s23,
            0.0,
            c23,
        );
        let rz4 = Matrix3::new(c4, -s4, 0.0, s4, c4, 0.0, 0.0, 0.0, 1.0);
        let ry5 = Matrix3::new(c5, 0.0, s5, 0.0, 1.0, 0.0, -s5, 0.0, c5);
        let rz6 = Matrix3::new(c6, -s6, 0.0, s6, c6, 0.0, 0.0, 0.0, 1.0);
        let r = r0c * rz4 * ry5 * rz6;
        let pos = wc + r.column(2) * p.c4;
        Isometry3::from_parts(
            Translation3::from(pos),
            UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix_unchecked(r)),
        )
    }

    /// All closed-form candidates for a tool0 pose. `q4_hint` (URDF value of joint 4) fixes the
    /// free wrist angle when the wrist is exactly singular.
    pub fn solve(&self, pose: &Isometry3<f64>, q4_hint: f64) -> OpwResult {
        let p = &self.p;
        let r = pose.rotation.to_rotation_matrix();
        let r = r.matrix();
        let z = r.column(2);
        let c = pose.translation.vector - z * p.c4;

        let nx1 = (c.x * c.x + c.y * c.y - p.b * p.b).max(0.0).sqrt() - p.a1;
        let tmp3 = c.z - p.c1;
        let s1_2 = nx1 * nx1 + tmp3 * tmp3;
        let tmp4 = nx1 + 2.0 * p.a1;
        let s2_2 = tmp4 * tmp4 + tmp3 * tmp3;
        let kappa_2 = p.a2 * p.a2 + p.c3 * p.c3;
        let c2_2 = p.c2 * p.c2;
        let (s1, s2) = (s1_2.sqrt(), s2_2.sqrt());
        let mut out = OpwResult {
            candidates: [[0.0; 6]; 8],
            count: 0,
            shoulder_distance: [s1, s2],
            wrist_angles: [0.0; 8],
        };
        // The elbow's cosine rule (the loop's first test below), before any angle: a pose
        // beyond reach from both shoulder positions costs no trigonometry (a track's
        // placement search asks many such).
        let elbow = |s: f64, s_2: f64| safe_acos((s_2 + c2_2 - kappa_2) / (2.0 * s * p.c2));
        if elbow(s1, s1_2).is_none() && elbow(s2, s2_2).is_none() {
            return out;
        }
        let tmp1 = c.y.atan2(c.x);
        let tmp2 = p.b.atan2(nx1 + p.a1);
        let theta1 = [tmp1 - tmp2, tmp1 + tmp2 - PI];
        let tmp9 = 2.0 * p.c2 * kappa_2.sqrt();
        let tmp10 = p.a2.atan2(p.c3);
        // Front shoulder (θ1 = tmp1 - tmp2) and back shoulder (θ1 + π) branches.
        for (branch, (s, s_2, reach_x)) in
            [(s1, s1_2, nx1), (s2, s2_2, tmp4)].into_iter().enumerate()
        {
            let Some(a) = elbow(s, s_2) else {
                continue;
            };
            let Some(b) = safe_acos((s_2 - c2_2 - kappa_2) / tmp9) else {
                continue;
            };
            let base = reach_x.atan2(tmp3);
            let arms = if branch == 0 {
                [(-a + base, b - tmp10), (a + base, -b - tmp10)]
            } else {
                [(-a - base, b - tmp10), (a - base, -b - tmp10)]
            };
            let t1 = theta1[branch];
            for (t2, t3) in arms {
                self.wrist(r, t1, t2, t3, q4_hint, &mut out);
            }
        }
        out
    }

    fn wrist(
        &self,
        r: &nalgebra::Matrix3<f64>,
        t1: f64,
        t2: f64,
        t3: f64,
        q4_hint: f64,
        out: &mut OpwResult,
    ) {
        let (s1, c1) = t1.sin_cos();
        let (s23, c23) = (t2 + t3).sin_cos();
        // Columns of the arm rotation R_0c.
        let xc = Vector3::new(c1 * c23, s1 * c23, -s23);
        let yc = Vector3::new(-s1, c1, 0.0);
        let zc = Vector3::new(c1 * s23, s1 * s23, c23);
        let (col0, col1, col2) = (r.column(0), r.column(1), r.column(2));
        let m = zc.dot(&col2).clamp(-1.0, 1.0);
        let s5 = (1.0 - m * m).sqrt();
        let push = |out: &mut OpwResult, t4: f64, t5: f64, t6: f64| {
            let t = [t1, t2, t3, t4, t5, t6];
            out.candidates[out.count] =
                std::array::from_fn(|i| wrap((t[i] + self.p.offsets[i]) * self.p.signs[i]));
            out.wrist_angles[out.count] = t5;
            out.count += 1;
        };
        if s5 < 1e-7 {
            // Axes 4 and 6 are aligned: only θ4 + θ6 is defined. Keep θ4 at the hint.
            let phi = yc.dot(&col0).atan2(xc.dot(&col0));
            let t4 = self.internal(3, q4_hint);
            if m > 0.0 {
                push(out, t4, 0.0, phi - t4);
            } else {
                // θ5 = π: R = Rz(θ4) Ry(π) Rz(θ6) = Ry(π) Rz(θ6 - θ4).
                let psi = yc.dot(&col0).atan2(-xc.dot(&col0));
                push(out, t4, PI, psi + t4);
            }
            return;
        }
        let t4 = yc.dot(&col2).atan2(xc.dot(&col2));
        let t5 = s5.atan2(m);
        let t6 = zc.dot(&col1).atan2(-zc.dot(&col0));
        push(out, t4, t5, t6);
        push(out, t4 + PI, -t5, t6 - PI);
    }
}

/// acos that tolerates round-off just outside [-1, 1] and refuses anything further out.
fn safe_acos(x: f64) -> Option<f64> {
    if x.is_nan() || x.abs() > 1.0 + 1e-12 {
        None
    } else {
        Some(x.clamp(-1.0, 1.0).acos())
    }
}

/// Angle into (-π, π].
pub(crate) fn wrap(a: f64) -> f64 {
    let w = (a + PI).rem_euclid(2.0 * PI) - PI;
    if w <= -PI { w + 2.0 * PI } else { w }
}
