//! The robot's work on one wall as the executor ran it, cut down to what the simulation
//! completed, in the terms every controller language shares: joint and Cartesian targets
//! (in the wall's own frame), moves, signals and waits. `rapid` and `krl` write it out.

use crate::cell::Cell;
use crate::sim::record::{NailOutcome, RobotStep, StepFor, WallRecord};
use nalgebra::Isometry3;
use std::collections::{BTreeMap, BTreeSet};

/// A joint target: the arm's joints (rad) and the carriage's position on the track (m from
/// its home), if the cell has a track.
#[derive(Debug, Clone, PartialEq)]
pub struct JointTarget {
    pub q: Vec<f64>,
    pub track: Option<f64>,
}

/// A Cartesian target: the TCP's pose in the wall frame (m), with the joints the simulation
/// reached it with (they give the configuration data) and the carriage's position.
#[derive(Debug, Clone, PartialEq)]
pub struct CartTarget {
    pub pose: Isometry3<f64>,
    pub q: Vec<f64>,
    pub track: Option<f64>,
}

/// A signal of the cell's `[io]`, by what it does.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub enum SignalRole {
    GripperClose,
    GripperOpen,
    NailerFire,
    NailerSlide,
    PartPresent,
}

impl SignalRole {
    /// The `[io]` key.
    pub fn key(self) -> &'static str {
        match self {
            SignalRole::GripperClose => "gripper_close",
            SignalRole::GripperOpen => "gripper_open",
            SignalRole::NailerFire => "nailer_fire",
            SignalRole::NailerSlide => "nailer_slide",
            SignalRole::PartPresent => "part_present",
        }
    }
}

/// One instruction of the program.
#[derive(Debug, Clone, PartialEq)]
pub enum Instr {
    Comment(String),
    /// A joint move at `speed`, a fraction of the joints' speed and acceleration limits,
    /// taking `duration` s in the simulation (None: the controller's own time).
    Joint {
        target: usize,
        speed: f64,
        duration: Option<f64>,
        tcp: String,
        fine: bool,
    },
    /// The carriage alone moves (a joint target with the arm's joints unchanged).
    Carriage {
        target: usize,
        tcp: String,
    },
    /// A straight TCP move at `speed` m/s.
    Line {
        target: usize,
        speed: f64,
        tcp: String,
        fine: bool,
    },
    Set {
        signal: SignalRole,
        on: bool,
    },
    AwaitInput(SignalRole),
    Wait(f64),
    /// The program stops for the operator: a piece was fed that the cell does not build
    /// (it lies at the sensor's end stop); the message says what to do.
    OperatorStop(&'static str),
}

/// What the operator is asked at a piece that was fed but not framed (within RAPID's 80
/// characters for `TPWrite`).
pub const TAKE_OFF_PIECE: &str = "framewright: take the piece off the end stop, then start";

/// The program of one wall.
#[derive(Debug, Clone, Default)]
pub struct Routine {
    pub joints: Vec<JointTarget>,
    pub carts: Vec<CartTarget>,
    pub body: Vec<Instr>,
    /// The TCPs the program uses, in name order.
    pub tcps: Vec<String>,
    /// The signals the program uses.
    pub signals: BTreeSet<SignalRole>,
    pub pieces_framed: usize,
    pub pieces_left_out: usize,
    pub nails_fired: usize,
    pub nails_left_out: usize,
}

/// What the routine is made from.
pub struct RoutineInput<'a> {
    pub cell: &'a Cell,
    pub record: &'a WallRecord,
    /// The wall frame (as laid on the assembly surface) in the cell frame.
    pub wall_in_cell: Isometry3<f64>,
    /// The pieces the simulation framed.
    pub framed: &'a BTreeSet<String>,
    /// The pieces that reached the touch sensor.
    pub fed: &'a BTreeSet<String>,
    /// Why each other piece was not framed (its first reason), by id.
    pub reasons: &'a BTreeMap<String, String>,
}

/// The routine of one wall's record: every step of a piece that was framed and of a nail
/// that was fired; of a piece or nail that failed, a comment naming it and its reason, and
/// its moves without the tool's signals (the arm keeps to the path that was simulated and
/// checked, and does nothing on the way).
pub fn routine(input: &RoutineInput) -> Routine {
    let mut out = Routine::default();
    let track = input.cell.track.is_some();
    let to_wall = input.wall_in_cell.inverse();
    let fired: BTreeSet<(&str, &str, i64)> = input
        .record
        .nails
        .iter()
        .filter(|n| matches!(n.outcome, NailOutcome::Fired { .. }))
        .map(|n| (n.plate.as_str(), n.member.as_str(), n.k))
        .collect();
    let skipped: BTreeMap<(&str, &str, i64), &str> = input
        .record
        .nails
        .iter()
        .filter_map(|n| match &n.outcome {
            NailOutcome::Skipped { message, .. } => {
                Some(((n.plate.as_str(), n.member.as_str(), n.k), message.as_str()))
            }
            NailOutcome::Fired { .. } => None,
        })
        .collect();
    // The TCP active: the grip TCP until a move names another.
    let mut current_tcp = "grip".to_string();
    let mut carriage = track.then_some(0.0);
    let mut kept = true;
    let mut fire_pending = false;
    for step in &input.record.program {
        match step {
            RobotStep::Begin(owner) => {
                fire_pending = false;
                let (comment, keep) = begin_comment(owner, input, &fired, &skipped, &mut out);
                kept = keep;
                out.body.push(Instr::Comment(comment));
                // A piece fed to the sensor and then not framed lies at the end stop: the
                // operator takes it off before the arm goes on (the next wait for the sensor
                // would pass on it).
                if let StepFor::Piece(id) = owner
                    && !keep
                    && input.fed.contains(id)
                {
                    out.body.push(Instr::AwaitInput(SignalRole::PartPresent));
                    out.body.push(Instr::OperatorStop(TAKE_OFF_PIECE));
                }
            }
            RobotStep::Joint {
                q,
                speed,
                duration,
                tcp,
            } => {
                out.joints.push(JointTarget {
                    q: q.clone(),
                    track: carriage,
                });
                current_tcp = tcp.clone();
                out.body.push(Instr::Joint {
                    target: out.joints.len() - 1,
                    speed: *speed,
                    duration: Some(*duration),
                    tcp: tcp.clone(),
                    fine: true,
                });
            }
            RobotStep::Line {
                pose,
                q,
                tcp,
                speed,
            } => {
                out.carts.push(CartTarget {
                    pose: to_wall * pose,
                    q: q.clone(),
                    track: carriage,
                });
                current_tcp = tcp.clone();
                out.body.push(Instr::Line {
                    target: out.carts.len() - 1,
                    speed: *speed,
                    tcp: tcp.clone(),
                    fine: true,
                });
            }
            RobotStep::Carriage { s, q } => {
                let start = out.joints.is_empty();
                carriage = track.then_some(*s);
                out.joints.push(JointTarget {
                    q: q.clone(),
                    track: carriage,
                });
                let target = out.joints.len() - 1;
                // The run's first step puts the arm at its home pose: a joint move there
                // from wherever the arm stands, in the controller's own time; the jaws open,
                // the nailer off and back on its slide, whatever an aborted run left them.
                if start {
                    out.body.push(Instr::Joint {
                        target,
                        speed: input.cell.motion.transfer_speed,
                        duration: None,
                        tcp: current_tcp.clone(),
                        fine: true,
                    });
                    out.body.push(set(SignalRole::NailerFire, false));
                    if input.cell.tool.nailer_slide > 0.0 {
                        out.body.push(set(SignalRole::NailerSlide, false));
                    }
                    out.body.push(set(SignalRole::GripperClose, false));
                    out.body.push(set(SignalRole::GripperOpen, true));
                } else {
                    out.body.push(Instr::Carriage {
                        target,
                        tcp: current_tcp.clone(),
                    });
                }
            }
            RobotStep::Grip if kept => {
                out.body.push(set(SignalRole::GripperOpen, false));
                out.body.push(set(SignalRole::GripperClose, true));
            }
            RobotStep::Release if kept => {
                out.body.push(set(SignalRole::GripperClose, false));
                out.body.push(set(SignalRole::GripperOpen, true));
            }
            // The slide moves whether or not the nail it serves was driven: the arm's next
            // moves assume where it stands.
            RobotStep::NailerSlide {
                out: extend,
                seconds,
            } => {
                out.body.push(set(SignalRole::NailerSlide, *extend));
                out.body.push(Instr::Wait(*seconds));
            }
            RobotStep::Fire if kept => {
                out.body.push(set(SignalRole::NailerFire, true));
                fire_pending = true;
            }
            RobotStep::AwaitPart if kept => {
                out.body.push(Instr::AwaitInput(SignalRole::PartPresent));
            }
            RobotStep::Dwell(seconds) if kept => {
                out.body.push(Instr::Wait(*seconds));
                if std::mem::take(&mut fire_pending) {
                    out.body.push(set(SignalRole::NailerFire, false));
                }
            }
            RobotStep::Grip
            | RobotStep::Release
            | RobotStep::Fire
            | RobotStep::AwaitPart
            | RobotStep::Dwell(_) => {}
        }
    }
    if fire_pending {
        out.body.push(set(SignalRole::NailerFire, false));
    }
    mark_fine_points(&mut out.body);
    let mut tcps = BTreeSet::new();
    for instr in &out.body {
        match instr {
            Instr::Set { signal, .. } | Instr::AwaitInput(signal) => {
                out.signals.insert(*signal);
            }
            Instr::Joint { tcp, .. } | Instr::Line { tcp, .. } | Instr::Carriage { tcp, .. } => {
                tcps.insert(tcp.clone());
            }
            _ => {}
        }
    }
    out.tcps = tcps.into_iter().collect();
    out
}

impl Routine {
    /// What the routine keeps and leaves out, as its header says it.
    pub fn counts(&self) -> String {
        format!(
            "pieces framed: {} (left out: {}); nails fired: {} (left out: {})",
            self.pieces_framed, self.pieces_left_out, self.nails_fired, self.nails_left_out
        )
    }
}

fn set(signal: SignalRole, on: bool) -> Instr {
    Instr::Set { signal, on }
}

/// The comment that opens a stretch of steps, and whether its signals are kept (the piece
/// was framed, the nail fired); counts what is kept and left out.
fn begin_comment(
    owner: &StepFor,
    input: &RoutineInput,
    fired: &BTreeSet<(&str, &str, i64)>,
    skipped: &BTreeMap<(&str, &str, i64), &str>,
    out: &mut Routine,
) -> (String, bool) {
    match owner {
        StepFor::Start => ("start: the arm at its home pose".to_string(), true),
        StepFor::Piece(id) if input.framed.contains(id) => {
            out.pieces_framed += 1;
            (format!("piece {id}: pick, place"), true)
        }
        StepFor::Piece(id) => {
            out.pieces_left_out += 1;
            let why = input
                .reasons
                .get(id)
                .map_or("it was not framed", String::as_str);
            (
                format!(
                    "left out: piece {id}: {why} (its moves, if any, stay as simulated, without gripping)"
                ),
                false,
            )
        }
        StepFor::Nail { plate, member, k } => {
            let key = (plate.as_str(), member.as_str(), *k);
            if fired.contains(&key) {
                out.nails_fired += 1;
                (format!("nail {k} through {plate} into {member}"), true)
            } else {
                out.nails_left_out += 1;
                let why = skipped.get(&key).copied().unwrap_or("it was not driven");
                (
                    format!(
                        "left out: nail {k} through {plate} into {member}: {why} (its moves, if any, stay as simulated, without firing)"
                    ),
                    false,
                )
            }
        }
    }
}

/// A move is a fine point unless the next instruction (comments aside) is another move: the
/// arm stops exactly where it grips, releases, fires or waits, and at the program's end.
fn mark_fine_points(body: &mut [Instr]) {
    let is_move = |i: &Instr| {
        matches!(
            i,
            Instr::Joint { .. } | Instr::Line { .. } | Instr::Carriage { .. }
        )
    };
    for k in 0..body.len() {
        let next_is_move = body[k + 1..]
            .iter()
            .find(|i| !matches!(i, Instr::Comment(_)))
            .is_some_and(is_move);
        match &mut body[k] {
            Instr::Joint { fine, .. } | Instr::Line { fine, .. } => *fine = !next_is_move,
            _ => {}
        }
    }
}
