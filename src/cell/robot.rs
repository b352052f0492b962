//! A robot model read from URDF: links with collision primitives, joints, the serial chain from
//! `base_link` to the tip (usually `tool0`), and forward kinematics on nalgebra.

use super::error::CellError;
use super::meta::{OpwParams, RobotMeta};
use super::opw::Opw;
use super::shapes::{PlacedShape, Shape, isometry_from_xyz_rpy};
use nalgebra::{Isometry3, Translation3, Unit, UnitQuaternion, Vector3};
use std::path::Path;

#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum JointKind {
    Revolute,
    Continuous,
    Prismatic,
    Fixed,
}

#[derive(Debug, Clone)]
pub struct Joint {
    pub name: String,
    pub kind: JointKind,
    /// Index into `Robot::links`.
    pub parent: usize,
    pub child: usize,
    /// Child frame in the parent frame at joint value 0.
    pub origin: Isometry3<f64>,
    pub axis: Unit<Vector3<f64>>,
    /// Position limits (rad or m); ±∞ for continuous joints.
    pub lower: f64,
    pub upper: f64,
    /// Speed limit (rad/s or m/s); +∞ when the URDF gives 0 or none.
    pub velocity: f64,
    /// Acceleration limit from the robot metadata (an estimate); +∞ when unknown.
    pub acceleration: f64,
    /// Position of this joint's value in the joint vector (`None` for fixed joints).
    pub dof_index: Option<usize>,
}

impl Joint {
    /// The motion of the joint at value `q` (child frame relative to the joint origin).
    pub fn motion(&self, q: f64) -> Isometry3<f64> {
        match self.kind {
            JointKind::Fixed => Isometry3::identity(),
            JointKind::Revolute | JointKind::Continuous => Isometry3::from_parts(
                Translation3::identity(),
                UnitQuaternion::from_axis_angle(&self.axis, q),
            ),
            JointKind::Prismatic => Isometry3::from_parts(
                Translation3::from(self.axis.into_inner() * q),
                UnitQuaternion::identity(),
            ),
        }
    }

    /// The child frame in the parent frame at joint value `q`.
    pub fn transform(&self, q: f64) -> Isometry3<f64> {
        match self.kind {
            JointKind::Fixed => self.origin,
            JointKind::Revolute | JointKind::Continuous => {
                self.origin * UnitQuaternion::from_axis_angle(&self.axis, q)
            }
            JointKind::Prismatic => self.origin * Translation3::from(self.axis.into_inner() * q),
        }
    }
}

#[derive(Debug, Clone)]
pub struct Inertial {
    pub mass: f64,
    pub origin: Isometry3<f64>,
    /// ixx, iyy, izz, ixy, ixz, iyz about the origin, kg·m².
    pub inertia: [f64; 6],
}

#[derive(Debug, Clone)]
pub struct Link {
    pub name: String,
    /// Index of the joint whose child this link is (`None` for the root).
    pub parent_joint: Option<usize>,
    pub collisions: Vec<PlacedShape>,
    pub visuals: Vec<PlacedShape>,
    pub inertial: Option<Inertial>,
    /// Mesh geometries in the URDF that were not loaded (framewright uses primitives only);
    /// callers may warn that the link's collision shape is incomplete.
    pub skipped_meshes: usize,
}

/// A serial-chain robot (any number of moving joints on the path from the root to the tip;
/// side branches must be fixed).
#[derive(Debug, Clone)]
pub struct Robot {
    pub name: String,
    /// Links, parents before children; `links[0]` is the root.
    pub links: Vec<Link>,
    /// Joints in the order of their child links.
    pub joints: Vec<Joint>,
    /// Indices into `joints` of the moving joints, base to tip (joint vector order).
    pub active: Vec<usize>,
    /// Indices into `joints` from the root to the tip link (fixed ones included).
    pub(crate) tip_path: Vec<usize>,
    /// The root → tip path with fixed joints folded into the next moving joint's origin (and the
    /// trailing ones into `tip_offset`): the FK that IK runs for every candidate.
    pub(crate) tip_steps: Vec<(Isometry3<f64>, usize)>,
    pub(crate) tip_offset: Isometry3<f64>,
    /// Index into `links` of the IK/FK tip (usually `tool0`).
    pub tip: usize,
    pub meta: RobotMeta,
    pub(crate) opw: Option<Opw>,
    /// How `base_link` hangs in the base frame the rest of framewright works in (identity:
    /// on the floor; a half turn about x: inverted, under a gantry). FK answers and IK takes
    /// poses in that frame, whose z points up whatever the mounting; the URDF chain and the
    /// closed form run in `base_link` itself.
    pub(crate) mount: Isometry3<f64>,
}

impl Robot {
    /// How many moving joints lie between a link and the robot's root (0 for the base, 1 for
    /// the turntable on it).
    pub fn moving_joints_above(&self, mut link: usize) -> usize {
        let mut n = 0;
        while let Some(j) = self.links[link].parent_joint {
            n += usize::from(self.joints[j].dof_index.is_some());
            link = self.joints[j].parent;
        }
        n
    }

    /// Build a robot from URDF text and its metadata. `path` is used in messages only.
    pub fn from_urdf_str(path: &Path, urdf: &str, meta: RobotMeta) -> Result<Robot, CellError> {
        if let Some(line) = super::urdf_depth::too_deep(urdf) {
            return Err(CellError::urdf(
                path,
                format!(
                    "line {line}: elements nest more than {} levels deep; a robot description \
                     needs about six (robot, link, visual, geometry, mesh)",
                    super::urdf_depth::MAX_DEPTH
                ),
            ));
        }
        let parsed =
            urdf_rs::read_from_string(urdf).map_err(|e| CellError::urdf(path, e.to_string()))?;
        let mut robot = build_tree(path, &parsed, &meta)?;
        robot.meta = meta;
        if let Some(params) = robot.meta.opw {
            robot.opw = Some(robot.checked_opw(path, params)?);
        }
        Ok(robot)
    }

    /// The closed-form solver of OPW parameters `p`, checked against the URDF's FK on a fixed
    /// set of joint vectors.
    fn checked_opw(&self, path: &Path, p: OpwParams) -> Result<Opw, CellError> {
        if self.dof() != 6 {
            return Err(CellError::urdf(
                path,
                format!(
                    "OPW parameters given for a robot with {} moving joints (need 6)",
                    self.dof()
                ),
            ));
        }
        if let Some(j) = self
            .active_joints()
            .find(|j| !matches!(j.kind, JointKind::Revolute | JointKind::Continuous))
        {
            return Err(CellError::urdf(
                path,
                format!(
                    "OPW parameters need six revolute joints; `{}` is not revolute",
                    j.name
                ),
            ));
        }
        let opw = Opw::new(p);
        let probes: [[f64; 6]; 4] = [
            [0.0; 6],
            [0.3, -0.4, 0.5, 0.7, -0.9, 1.1],
            [-1.2, 0.2, -0.3, -2.0, 1.0, -0.5],
            [2.0, -0.1, 0.9, 1.5, 0.4, 2.5],
        ];
        for q in probes {
            let urdf = self.fk_tip_unmounted(&q);
            let own = opw.forward(&q);
            let dp = (urdf.translation.vector - own.translation.vector).norm();
            let dr = urdf.rotation.angle_to(&own.rotation);
            if dp > 1e-9 || dr > 1e-9 {
                return Err(CellError::urdf(
                    path,
                    format!(
                        "the OPW parameters do not match the URDF chain (at q = {q:?} the tip differs by {dp:.3e} m, {dr:.3e} rad); fix [opw] in the robot's metadata or remove it to use the numeric IK"
                    ),
                ));
            }
        }
        Ok(opw)
    }

    /// This arm with every length multiplied by `k`: joint origins, link shapes, the closed
    /// form's parameters, the published reach; a prismatic joint's travel too. Joint angle
    /// limits, speeds and the mounting stay. What a remedy checks "a robot like this one with
    /// more reach" against.
    pub fn scaled(&self, k: f64) -> Robot {
        let mut r = self.clone();
        let stretch = |iso: &mut Isometry3<f64>| iso.translation.vector *= k;
        for j in &mut r.joints {
            stretch(&mut j.origin);
            if j.kind == JointKind::Prismatic {
                j.lower *= k;
                j.upper *= k;
            }
        }
        for (origin, _) in &mut r.tip_steps {
            stretch(origin);
        }
        stretch(&mut r.tip_offset);
        for link in &mut r.links {
            for s in link.collisions.iter_mut().chain(link.visuals.iter_mut()) {
                stretch(&mut s.origin);
                s.shape = s.shape.scaled(k);
            }
        }
        let scale_opw = |p: &mut OpwParams| {
            for v in [
                &mut p.a1, &mut p.a2, &mut p.b, &mut p.c1, &mut p.c2, &mut p.c3, &mut p.c4,
            ] {
                *v *= k;
            }
        };
        if let Some(p) = &mut r.meta.opw {
            scale_opw(p);
        }
        if let Some(o) = &mut r.opw {
            scale_opw(&mut o.p);
        }
        r.meta.reach = r.meta.reach.map(|v| v * k);
        r
    }

    /// Number of moving joints.
    pub fn dof(&self) -> usize {
        self.active.len()
    }

    pub fn active_joints(&self) -> impl Iterator<Item = &Joint> {
        self.active.iter().map(|&j| &self.joints[j])
    }

    pub fn link_index(&self, name: &str) -> Option<usize> {
        self.links.iter().position(|l| l.name == name)
    }

    /// Whether IK uses the closed form (OPW) rather than the numeric fallback.
    pub fn has_closed_form_ik(&self) -> bool {
        self.opw.is_some()
    }

    /// Mounts the robot: `mount` is `base_link` in the base frame (identity on the floor).
    pub fn set_mount(&mut self, mount: Isometry3<f64>) {
        self.mount = mount;
    }

    /// Pose of every link in the base frame (`base_link` as mounted), in `links` order.
    /// Panics if `q.len() != self.dof()` (a programming error, not input).
    pub fn fk_all(&self, q: &[f64]) -> Vec<Isometry3<f64>> {
        self.fk_all_from(self.mount, q)
    }

    /// Pose of every link in `base_link` itself (the URDF's own frame).
    pub(crate) fn fk_all_unmounted(&self, q: &[f64]) -> Vec<Isometry3<f64>> {
        self.fk_all_from(Isometry3::identity(), q)
    }

    /// Pose of every link with the root at `root`.
    fn fk_all_from(&self, root: Isometry3<f64>, q: &[f64]) -> Vec<Isometry3<f64>> {
        assert_eq!(q.len(), self.dof(), "joint vector length");
        let mut poses = vec![root; self.links.len()];
        for joint in &self.joints {
            let value = joint.dof_index.map_or(0.0, |i| q[i]);
            poses[joint.child] = poses[joint.parent] * joint.transform(value);
        }
        poses
    }

    /// Pose of the tip link (e.g. `tool0`) in the base frame (`base_link` as mounted).
    pub fn fk_tip(&self, q: &[f64]) -> Isometry3<f64> {
        self.mount * self.fk_tip_unmounted(q)
    }

    /// Pose of the tip link in `base_link` itself (what the closed form solves for).
    pub(crate) fn fk_tip_unmounted(&self, q: &[f64]) -> Isometry3<f64> {
        let mut pose = Isometry3::identity();
        for (i, (origin, j)) in self.tip_steps.iter().enumerate() {
            let joint = &self.joints[*j];
            // `origin` already holds the fixed joints before this one and its own origin.
            pose *= origin;
            match joint.kind {
                // A pure rotation: compose the rotations only (this FK checks every IK answer).
                JointKind::Revolute | JointKind::Continuous => {
                    pose.rotation *= UnitQuaternion::from_axis_angle(&joint.axis, q[i]);
                }
                JointKind::Prismatic => {
                    pose.translation.vector += pose.rotation * (joint.axis.into_inner() * q[i]);
                }
                JointKind::Fixed => {}
            }
        }
        pose * self.tip_offset
    }

    /// Pose of the named link in the root frame.
    pub fn fk_link(&self, q: &[f64], link: &str) -> Option<Isometry3<f64>> {
        self.link_index(link).map(|i| self.fk_all(q)[i])
    }

    /// Lower and upper limits of the moving joints.
    pub fn limits(&self) -> Vec<(f64, f64)> {
        self.active_joints().map(|j| (j.lower, j.upper)).collect()
    }

    /// The start pose from the metadata (zeros clamped into the limits when none is given).
    pub fn home(&self) -> Vec<f64> {
        match &self.meta.home {
            Some(h) if h.len() == self.dof() => h.clone(),
            _ => self
                .active_joints()
                .map(|j| 0.0f64.clamp(j.lower, j.upper))
                .collect(),
        }
    }
}

fn build_tree(path: &Path, urdf: &urdf_rs::Robot, meta: &RobotMeta) -> Result<Robot, CellError> {
    let err = |m: String| CellError::urdf(path, m);
    if urdf.links.is_empty() {
        return Err(err("no <link>".into()));
    }
    let link_pos = |name: &str| urdf.links.iter().position(|l| l.name == name);
    for (i, l) in urdf.links.iter().enumerate() {
        if urdf.links[..i].iter().any(|o| o.name == l.name) {
            return Err(err(format!("link `{}` is defined twice", l.name)));
        }
    }
    // Parent joint of every URDF link.
    let mut parent_of: Vec<Option<usize>> = vec![None; urdf.links.len()];
    for (ji, j) in urdf.joints.iter().enumerate() {
        let child = link_pos(&j.child.link).ok_or_else(|| {
            err(format!(
                "joint `{}`: unknown child link `{}`",
                j.name, j.child.link
            ))
        })?;
        link_pos(&j.parent.link).ok_or_else(|| {
            err(format!(
                "joint `{}`: unknown parent link `{}`",
                j.name, j.parent.link
            ))
        })?;
        if parent_of[child].replace(ji).is_some() {
            return Err(err(format!(
                "link `{}` has two parent joints",
                j.child.link
            )));
        }
    }
    let roots: Vec<usize> = (0..urdf.links.len())
        .filter(|&i| parent_of[i].is_none())
        .collect();
    if roots.len() != 1 {
        let names: Vec<&str> = roots.iter().map(|&i| urdf.links[i].name.as_str()).collect();
        return Err(err(format!("expected one root link, found {names:?}")));
    }
    // Breadth-first order from the root; children sorted by URDF order for determinism.
    let mut order = vec![roots[0]];
    let mut k = 0;
    while k < order.len() {
        let parent_name = &urdf.links[order[k]].name;
        for j in &urdf.joints {
            if &j.parent.link == parent_name {
                order.push(link_pos(&j.child.link).expect("checked"));
            }
        }
        k += 1;
        if order.len() > urdf.links.len() {
            return Err(err("the joints form a cycle".into()));
        }
    }
    if order.len() != urdf.links.len() {
        return Err(err(
            "the joints form a cycle or leave links unconnected".into()
        ));
    }
    let new_index = |urdf_link: usize| order.iter().position(|&o| o == urdf_link).expect("all");

    let mut links = Vec::with_capacity(order.len());
    let mut joints = Vec::with_capacity(order.len() - 1);
    for &ul in &order {
        let l = &urdf.links[ul];
        let parent_joint = parent_of[ul].map(|uj| {
            let j = &urdf.joints[uj];
            joints.push((uj, j));
            joints.len() - 1
        });
        links.push(Link {
            name: l.name.clone(),
            parent_joint,
            collisions: shapes(l.collision.iter().map(|c| (&c.origin, &c.geometry))),
            visuals: shapes(l.visual.iter().map(|v| (&v.origin, &v.geometry))),
            skipped_meshes: l
                .collision
                .iter()
                .map(|c| &c.geometry)
                .chain(l.visual.iter().map(|v| &v.geometry))
                .filter(|g| matches!(g, urdf_rs::Geometry::Mesh { .. }))
                .count(),
            inertial: (l.inertial.mass.value > 0.0).then(|| Inertial {
                mass: l.inertial.mass.value,
                origin: isometry_from_xyz_rpy(l.inertial.origin.xyz.0, l.inertial.origin.rpy.0),
                inertia: [
                    l.inertial.inertia.ixx,
                    l.inertial.inertia.iyy,
                    l.inertial.inertia.izz,
                    l.inertial.inertia.ixy,
                    l.inertial.inertia.ixz,
                    l.inertial.inertia.iyz,
                ],
            }),
        });
    }

    // The tip: the metadata's `tip_link`, else `tool0`, else the only leaf link.
    let leaves: Vec<usize> = (0..links.len())
        .filter(|&i| !joints.iter().any(|(_, j)| j.parent.link == links[i].name))
        .collect();
    let tip_name = match &meta.tip_link {
        Some(t) => t.clone(),
        None if links.iter().any(|l| l.name == "tool0") => "tool0".into(),
        None if leaves.len() == 1 => links[leaves[0]].name.clone(),
        None => {
            let names: Vec<&str> = leaves.iter().map(|&i| links[i].name.as_str()).collect();
            return Err(err(format!(
                "no `tool0` link and several end links {names:?}: name the tip with `tip_link` in the robot's metadata file"
            )));
        }
    };
    let tip = links
        .iter()
        .position(|l| l.name == tip_name)
        .ok_or_else(|| err(format!("tip link `{tip_name}` not found")))?;
    // Joints on the root → tip path.
    let mut tip_path = vec![];
    let mut at = tip;
    while let Some(j) = links[at].parent_joint {
        tip_path.push(j);
        at = new_index(link_pos(&joints[j].1.parent.link).expect("checked"));
    }
    tip_path.reverse();

    let mut out_joints = Vec::with_capacity(joints.len());
    let mut dof = 0;
    let accelerations = meta.acceleration.clone().unwrap_or_default();
    for (ji, (_, j)) in joints.iter().enumerate() {
        let kind = match j.joint_type {
            urdf_rs::JointType::Revolute => JointKind::Revolute,
            urdf_rs::JointType::Continuous => JointKind::Continuous,
            urdf_rs::JointType::Prismatic => JointKind::Prismatic,
            urdf_rs::JointType::Fixed => JointKind::Fixed,
            ref other => {
                return Err(err(format!(
                    "joint `{}`: type {other:?} is not supported (revolute, continuous, prismatic, fixed)",
                    j.name
                )));
            }
        };
        let on_path = tip_path.contains(&ji);
        if kind != JointKind::Fixed && !on_path {
            return Err(err(format!(
                "joint `{}` moves but is not on the chain from `{}` to `{}`: only serial chains are supported",
                j.name, links[0].name, tip_name
            )));
        }
        let axis = Vector3::from(j.axis.xyz.0);
        if kind != JointKind::Fixed && !(axis.norm() > 1e-9 && axis.iter().all(|v| v.is_finite())) {
            return Err(err(format!(
                "joint `{}`: axis must be a non-zero vector",
                j.name
            )));
        }
        let (lower, upper) = match kind {
            JointKind::Continuous => (f64::NEG_INFINITY, f64::INFINITY),
            JointKind::Fixed => (0.0, 0.0),
            _ => (j.limit.lower, j.limit.upper),
        };
        if kind != JointKind::Fixed
            && lower
                .partial_cmp(&upper)
                .is_none_or(|o| o == std::cmp::Ordering::Greater)
        {
            return Err(err(format!(
                "joint `{}`: lower limit {lower} is above the upper limit {upper}",
                j.name
            )));
        }
        let dof_index = (kind != JointKind::Fixed).then(|| {
            dof += 1;
            dof - 1
        });
        let origin = isometry_from_xyz_rpy(j.origin.xyz.0, j.origin.rpy.0);
        if !origin.to_homogeneous().iter().all(|v| v.is_finite()) {
            return Err(err(format!("joint `{}`: origin is not finite", j.name)));
        }
        out_joints.push(Joint {
            name: j.name.clone(),
            kind,
            parent: new_index(link_pos(&j.parent.link).expect("checked")),
            child: new_index(link_pos(&j.child.link).expect("checked")),
            origin,
            axis: Unit::new_normalize(if kind == JointKind::Fixed {
                Vector3::z()
            } else {
                axis
            }),
            lower,
            upper,
            velocity: if j.limit.velocity > 0.0 {
                j.limit.velocity
            } else {
                f64::INFINITY
            },
            acceleration: dof_index
                .and_then(|i| accelerations.get(i).copied())
                .unwrap_or(f64::INFINITY),
            dof_index,
        });
    }
    let active: Vec<usize> = tip_path
        .iter()
        .copied()
        .filter(|&j| out_joints[j].kind != JointKind::Fixed)
        .collect();
    // dof_index must follow the chain order: renumber along the path.
    for (i, &j) in active.iter().enumerate() {
        out_joints[j].dof_index = Some(i);
    }
    let mut tip_steps = vec![];
    let mut pending = Isometry3::identity();
    for &j in &tip_path {
        let joint = &out_joints[j];
        if joint.kind == JointKind::Fixed {
            pending *= joint.origin;
        } else {
            tip_steps.push((pending * joint.origin, j));
            pending = Isometry3::identity();
        }
    }
    Ok(Robot {
        tip_steps,
        tip_offset: pending,
        name: meta.name.clone().unwrap_or_else(|| urdf.name.clone()),
        links,
        joints: out_joints,
        active,
        tip_path,
        tip,
        meta: meta.clone(),
        opw: None,
        mount: Isometry3::identity(),
    })
}

fn shapes<'a>(
    items: impl Iterator<Item = (&'a urdf_rs::Pose, &'a urdf_rs::Geometry)>,
) -> Vec<PlacedShape> {
    let mut out = vec![];
    for (origin, geometry) in items {
        let shape = match geometry {
            urdf_rs::Geometry::Box { size } => Shape::Box {
                half_extents: [size.0[0] / 2.0, size.0[1] / 2.0, size.0[2] / 2.0],
            },
            urdf_rs::Geometry::Cylinder { radius, length } => Shape::Cylinder {
                radius: *radius,
                length: *length,
            },
            urdf_rs::Geometry::Capsule { radius, length } => Shape::Capsule {
                radius: *radius,
                length: *length,
            },
            urdf_rs::Geometry::Sphere { radius } => Shape::Sphere { radius: *radius },
            // Meshes are not loaded (counted in `Link::skipped_meshes`).
            urdf_rs::Geometry::Mesh { .. } => continue,
        };
        out.push(PlacedShape {
            origin: isometry_from_xyz_rpy(origin.xyz.0, origin.rpy.0),
            shape,
        });
    }
    out
}

#[cfg(test)]
mod tests {
    use super::super::robot_names;
    use super::*;

    #[test]
    fn a_scaled_arm_is_the_arm_k_times_larger() {
        let q = [0.3, -0.4, 0.5, 0.7, -0.9, 1.1];
        for name in robot_names() {
            let robot = Robot::load(name).unwrap();
            let k = 1.37;
            let big = robot.scaled(k);
            let q = &q[..robot.dof()];
            // Every link k times as far from the base, turned as before.
            for (a, b) in robot.fk_all(q).iter().zip(big.fk_all(q)) {
                let d = (a.translation.vector * k - b.translation.vector).norm();
                assert!(d < 1e-12, "{name}: {d}");
                assert!(a.rotation.angle_to(&b.rotation) < 1e-12, "{name}");
            }
            // The closed form still matches the chain, and reaches k times as far.
            if let Some(opw) = &big.opw {
                let q6: [f64; 6] = q.try_into().unwrap();
                let chain = big.fk_tip_unmounted(q);
                let own = opw.forward(&q6);
                let d = (chain.translation.vector - own.translation.vector).norm();
                assert!(d < 1e-9, "{name}: {d}");
                let (_, far) = robot.opw.as_ref().unwrap().shoulder_reach();
                assert!((opw.shoulder_reach().1 - far * k).abs() < 1e-12, "{name}");
            }
        }
    }
}
