//! What kind of limit each failure met, so failures can be counted by cause (the bid table of
//! `compare`, the summary opening a report).
//!
//! The verdicts come from the rules; the class is read off the executor's typed record of the
//! same run: a piece's refusal (belts, gripper), its first failed pick or place pose (IK, or the
//! bodies every solution meets), its first contact while framing, or its rest pose. A failure
//! the record does not explain (a verdict of a replaced rule base) is `DecidedByRule`.

use crate::cell::{IkFailure, Robot};
use crate::sim::WallRecord;
use crate::sim::record::{NailOutcome, Op, RefusalKind};
use serde::Serialize;

/// A kind of failure, for counting.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum FailureClass {
    TooLongForConveyors,
    NotFed,
    NoGripper,
    OutsideJawRange,
    NarrowerThanPads,
    TooHeavyForGripper,
    ShorterThanGripperSpacing,
    TooShortForOneGripper,
    TooHeavyForOneGripper,
    Toppled,
    Slipped,
    BeyondReach,
    JointLimit,
    WristSingularity,
    CollisionWithFixture,
    CollisionWithPiece,
    CollisionWithFloor,
    CollisionWithRobot,
    NoStraightPath,
    OffTarget,
    /// A nail whose plate or member was not placed.
    PieceNotPlaced,
    /// A nail driven that misses its target or its member.
    NailOffTarget,
    DecidedByRule,
}

impl FailureClass {
    /// Short words for tables.
    pub fn label(self) -> &'static str {
        match self {
            FailureClass::TooLongForConveyors => "too long for the conveyors",
            FailureClass::NotFed => "not fed to the sensor",
            FailureClass::NoGripper => "no gripper on the tool",
            FailureClass::OutsideJawRange => "outside the jaws' range",
            FailureClass::NarrowerThanPads => "narrower than the pads",
            FailureClass::TooHeavyForGripper => "too heavy for the gripper",
            FailureClass::ShorterThanGripperSpacing => "shorter than the gripper spacing",
            FailureClass::TooShortForOneGripper => "too short for one gripper",
            FailureClass::TooHeavyForOneGripper => "too heavy for one gripper",
            FailureClass::Toppled => "toppled at the end stop",
            FailureClass::Slipped => "slipped in the jaws",
            FailureClass::BeyondReach => "beyond reach",
            FailureClass::JointLimit => "joint limit",
            FailureClass::WristSingularity => "wrist singularity",
            FailureClass::CollisionWithFixture => "collision with a cell fixture",
            FailureClass::CollisionWithPiece => "collision with a piece",
            FailureClass::CollisionWithFloor => "collision with the floor or table",
            FailureClass::CollisionWithRobot => "collision of the robot with itself",
            FailureClass::NoStraightPath => "no straight or exact path",
            FailureClass::OffTarget => "off target after release",
            FailureClass::PieceNotPlaced => "its piece was not placed",
            FailureClass::NailOffTarget => "driven off target",
            FailureClass::DecidedByRule => "decided by a rule",
        }
    }
}

/// What a body named in a contact or a colliding pair is.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
enum BodyKind {
    Robot,
    Piece,
    Fixture,
    Floor,
}

/// The executor names lumber `piece ID`, the tool's parts `tool …`, the robot's colliders by
/// their URDF link, the floor and the table the wall is laid on by those words; every other
/// body is one of the cell's fixtures (conveyors, sensor, tool table, …).
fn body_kind(name: &str, robot: &Robot) -> BodyKind {
    if name.starts_with("piece ") {
        BodyKind::Piece
    } else if name == "floor" || name == "assembly table" {
        BodyKind::Floor
    } else if name.starts_with("tool ") || robot.links.iter().any(|l| l.name == name) {
        BodyKind::Robot
    } else {
        BodyKind::Fixture
    }
}

/// Two bodies that met: the class is set by the one that is not the robot (the floor before a
/// fixture before a piece).
fn collision(a: &str, b: &str, robot: &Robot) -> FailureClass {
    match body_kind(a, robot).max(body_kind(b, robot)) {
        BodyKind::Floor => FailureClass::CollisionWithFloor,
        BodyKind::Fixture => FailureClass::CollisionWithFixture,
        BodyKind::Piece => FailureClass::CollisionWithPiece,
        BodyKind::Robot => FailureClass::CollisionWithRobot,
    }
}

fn ik_class(failure: &IkFailure, robot: &Robot) -> FailureClass {
    match failure {
        IkFailure::OutOfReach { .. } => FailureClass::BeyondReach,
        IkFailure::JointLimit { .. } => FailureClass::JointLimit,
        IkFailure::WristSingularity { .. } => FailureClass::WristSingularity,
        IkFailure::AllSolutionsCollide { pair } | IkFailure::PathBlocked { pair } => {
            collision(&pair[0], &pair[1], robot)
        }
        IkFailure::NoExactSolution { .. }
        | IkFailure::BranchJump { .. }
        | IkFailure::InvalidPose => FailureClass::NoStraightPath,
    }
}

fn refusal_class(kind: RefusalKind) -> FailureClass {
    match kind {
        RefusalKind::TooLongForConveyors => FailureClass::TooLongForConveyors,
        RefusalKind::NotFed => FailureClass::NotFed,
        RefusalKind::NoGripper => FailureClass::NoGripper,
        RefusalKind::OutsideJawRange => FailureClass::OutsideJawRange,
        RefusalKind::NarrowerThanPads => FailureClass::NarrowerThanPads,
        RefusalKind::TooHeavyForGripper => FailureClass::TooHeavyForGripper,
        RefusalKind::ShorterThanGripperSpacing => FailureClass::ShorterThanGripperSpacing,
        RefusalKind::TooShortForOneGripper => FailureClass::TooShortForOneGripper,
        RefusalKind::TooHeavyForOneGripper => FailureClass::TooHeavyForOneGripper,
        RefusalKind::Toppled => FailureClass::Toppled,
        RefusalKind::Slipped => FailureClass::Slipped,
    }
}

/// The class of a piece whose framing failed, from its wall's record.
pub fn piece_class(record: &WallRecord, piece: &str, robot: &Robot) -> FailureClass {
    let refused = record
        .not_fed
        .iter()
        .chain(&record.grip_failed)
        .find(|(p, _)| p == piece);
    if let Some((_, refusal)) = refused {
        return refusal_class(refusal.kind);
    }
    let ik = record
        .ik
        .iter()
        .filter(|r| r.piece == piece && r.op != Op::Nail)
        .find_map(|r| r.result.as_ref().err());
    if let Some(failure) = ik {
        return ik_class(failure, robot);
    }
    if let Some(c) = record
        .contacts
        .iter()
        .find(|c| c.piece == piece && c.op != Op::Nail)
    {
        return collision(&c.body_a, &c.body_b, robot);
    }
    if record.placements.iter().any(|p| p.piece == piece) {
        return FailureClass::OffTarget;
    }
    FailureClass::DecidedByRule
}

/// The class of a nail that was not driven on target (`nail_ok` did not hold for it).
pub fn nail_class(outcome: &NailOutcome, robot: &Robot) -> FailureClass {
    match outcome {
        NailOutcome::Fired { .. } => FailureClass::NailOffTarget,
        NailOutcome::Skipped { kind, what, .. } => match kind.as_str() {
            "not_framed" => FailureClass::PieceNotPlaced,
            "out_of_reach" => FailureClass::BeyondReach,
            "joint_limit" => FailureClass::JointLimit,
            "wrist_singularity" => FailureClass::WristSingularity,
            "all_solutions_collide" | "path_blocked" => match what.split_once(" / ") {
                Some((a, b)) => collision(a, b, robot),
                None => FailureClass::CollisionWithRobot,
            },
            "no_exact_solution" | "branch_jump" | "invalid_pose" => FailureClass::NoStraightPath,
            _ => FailureClass::DecidedByRule,
        },
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cell::Cell;

    #[test]
    fn bodies_are_told_apart_by_what_the_executor_names_them() {
        let cell = Cell::load("study-abb").unwrap();
        let robot = &cell.robot;
        let link = robot.links[2].name.clone();
        assert_eq!(
            collision("tool gripper_2_jaws finger", "touch sensor", robot),
            FailureClass::CollisionWithFixture
        );
        assert_eq!(
            collision("piece A", "piece B", robot),
            FailureClass::CollisionWithPiece
        );
        assert_eq!(
            collision("piece A", "floor", robot),
            FailureClass::CollisionWithFloor
        );
        assert_eq!(
            collision(&link, "tool nailer", robot),
            FailureClass::CollisionWithRobot
        );
        assert_eq!(
            collision(&link, "conveyor 2 frame", robot),
            FailureClass::CollisionWithFixture
        );
    }
}
