//! The robot in the world: its base, its joints driven or placed, the gripper jaws and the
//! nailer's slide.

use super::build::retracted;
use super::world::*;
use nalgebra::Isometry3;
use rapier3d::prelude::*;

impl Physics {
    /// Moves the robot's base (its carriage on a linear track); the links follow at the
    /// next drive or placement.
    pub fn set_robot_base(&mut self, base: nalgebra::Isometry3<f64>) {
        self.bodies_may_move();
        self.cell.robot_base = base;
    }

    /// Moves the robot's bodies to joint values `q` by the end of the next step.
    pub fn drive_robot(&mut self, q: &[f64]) {
        // The step moves the bodies from where they stand now.
        self.bodies_may_move();
        let poses = self.cell.robot.fk_all(q);
        for &(i, body) in &self.links {
            let pose = to_pose(&(self.cell.robot_base * poses[i]));
            self.world.bodies[body].set_next_kinematic_position(pose);
        }
        let tool = self.cell.robot_base * self.cell.robot.fk_tip(q);
        self.world.bodies[self.tool].set_next_kinematic_position(to_pose(&tool));
    }

    /// Opens the jaws (`None`) or closes them on lumber of this thickness.
    pub fn set_jaws(&mut self, closed_on: Option<f64>) {
        self.changed(true);
        let open = self
            .cell
            .tool
            .gripper
            .as_ref()
            .and_then(|g| g.jaws())
            .map_or(0.1, |j| j.open_width);
        let width = closed_on.unwrap_or(open);
        for f in &self.fingers {
            if let Some(c) = self.world.colliders.get_mut(f.collider) {
                c.set_position_wrt_parent(to_pose(&f.offset(width)));
            }
        }
    }

    /// A finger's pose in tool0 with the jaws standing `width` apart; None for any other
    /// collider.
    pub fn finger_at(&self, c: ColliderHandle, width: f64) -> Option<Isometry3<f64>> {
        self.fingers
            .iter()
            .find(|f| f.collider == c)
            .map(|f| f.offset(width))
    }

    /// Runs the nailer out on its slide (`true`: where the tool file places it) or back.
    pub fn set_nailer(&mut self, out: bool) {
        if self.nailer.is_empty() || self.nailer_out == out {
            return;
        }
        self.changed(true);
        self.nailer_out = out;
        let slide = self.cell.tool.nailer_slide;
        for (c, origin) in &self.nailer {
            let pose = if out {
                *origin
            } else {
                retracted(origin, slide)
            };
            if let Some(c) = self.world.colliders.get_mut(*c) {
                c.set_position_wrt_parent(to_pose(&pose));
            }
        }
    }

    /// Puts the robot's bodies (and the held piece, at `in_tool` in tool0) at joint values
    /// `q` at once, without a step: nothing is pushed and no velocity results. The bodies
    /// move when anything may see them (a step, a collision detection, a change to the
    /// world, the held piece's pose asked for): a robot moving through a quiet world is
    /// placed once per look, not once per tick. What is seen is the same.
    pub fn place_robot(&mut self, q: &[f64], held: Option<(&str, &Isometry3<f64>)>) {
        // A robot standing still (waiting for a piece) is where the last placement left it.
        let same = |p: &RobotPlacement| {
            p.q.as_slice() == q && p.held.as_ref().map(|(id, g)| (id.as_str(), g)) == held
        };
        if self
            .pending
            .as_ref()
            .or(self.placed.as_ref())
            .is_some_and(same)
        {
            return;
        }
        // Written over the waiting placement's buffers: no allocation per tick.
        let p = self.pending.get_or_insert_with(|| RobotPlacement {
            q: Vec::new(),
            held: None,
        });
        p.q.clear();
        p.q.extend_from_slice(q);
        match (held, &mut p.held) {
            (Some((id, g)), Some((was, in_tool))) => {
                if was != id {
                    was.clear();
                    was.push_str(id);
                }
                *in_tool = *g;
            }
            (held, slot) => *slot = held.map(|(id, g)| (id.to_string(), *g)),
        }
    }

    /// Before anything that may move the robot's bodies or look at them: they stand where
    /// `place_robot` was last asked to put them, and the next placement places them again.
    pub(super) fn bodies_may_move(&mut self) {
        self.flush();
        self.placed = None;
    }

    /// Moves the robot's bodies where `place_robot` was last asked to put them.
    pub(super) fn flush(&mut self) {
        let Some(placement) = self.pending.take() else {
            return;
        };
        let poses = self.cell.robot.fk_all(&placement.q);
        for &(i, body) in &self.links {
            let pose = to_pose(&(self.cell.robot_base * poses[i]));
            self.world.bodies[body].set_position(pose, false);
        }
        let tool = self.cell.robot_base * self.cell.robot.fk_tip(&placement.q);
        self.world.bodies[self.tool].set_position(to_pose(&tool), false);
        if let Some((id, in_tool)) = &placement.held
            && let Some(b) = self.lumber.get(id)
        {
            self.world.bodies[b.body].set_position(to_pose(&(tool * in_tool)), false);
        }
        self.placed = Some(placement);
    }

    /// The held piece's pose while its placement waits (see `place_robot`), as `flush` will
    /// set it.
    pub(super) fn pending_held(&self) -> Option<(&str, Isometry3<f64>)> {
        let placement = self.pending.as_ref()?;
        let (id, in_tool) = placement.held.as_ref()?;
        self.lumber.get(id)?;
        let tool = self.cell.robot_base * self.cell.robot.fk_tip(&placement.q);
        Some((id.as_str(), to_iso(&to_pose(&(tool * in_tool)))))
    }

    /// Where the robot's base stands (it moves with a carriage).
    pub fn robot_base(&self) -> Isometry3<f64> {
        self.cell.robot_base
    }
}
