//! What a robot's kinematic chain says of its reach, read from the URDF's joint origins at the
//! zero pose (not from the closed-form IK the executor uses), for tests that compute the
//! expected reach verdicts themselves.
#![allow(dead_code)]

use framewright::cell::Cell;
use nalgebra::{Point3, Vector3};

/// A 6-axis arm with an offset shoulder and a spherical wrist, as its chain places them.
pub struct Arm {
    /// The shoulder (joint 2): horizontal distance from the base axis and height, m.
    pub shoulder_radius: f64,
    pub shoulder_height: f64,
    /// Shoulder to wrist centre with the arm stretched, m.
    pub reach: f64,
    /// Wrist centre to the flange (tool0), m.
    pub wrist_to_flange: f64,
}

impl Arm {
    /// The arm of `cell`'s robot (standing at the cell origin, not turned).
    pub fn of(cell: &Cell) -> Arm {
        assert_eq!(
            cell.robot_base.translation.vector,
            Vector3::zeros(),
            "{}: the robot stands at the cell origin",
            cell.name
        );
        let robot = &cell.robot;
        let poses = robot.fk_all(&vec![0.0; robot.dof()]);
        let joint_at = |k: usize| -> Point3<f64> {
            let joint = &robot.joints[robot.active[k]];
            poses[joint.child].translation.vector.into()
        };
        let (shoulder, elbow, wrist) = (joint_at(1), joint_at(2), joint_at(4));
        let flange: Point3<f64> = poses[robot.tip].translation.vector.into();
        Arm {
            shoulder_radius: shoulder.coords.xy().norm(),
            shoulder_height: shoulder.z,
            reach: (elbow - shoulder).norm() + (wrist - elbow).norm(),
            wrist_to_flange: (flange - wrist).norm(),
        }
    }

    /// How far the wrist centre is from the shoulder (turned towards it) when the tool points
    /// straight down with its TCP `tcp_in_flange` m below the flange at `tcp` (cell frame).
    pub fn wrist_distance_tool_down(&self, tcp: &Vector3<f64>, tcp_in_flange: f64) -> f64 {
        let wrist_z = tcp.z + tcp_in_flange + self.wrist_to_flange;
        let radial = tcp.xy().norm() - self.shoulder_radius;
        let rise = wrist_z - self.shoulder_height;
        (radial * radial + rise * rise).sqrt()
    }
}
