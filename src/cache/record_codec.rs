//! A wall's executor record as a cache entry and back. The record type only serialises, so the
//! entry is a mirror of it: floats as their IEEE bits (exact, NaN and infinities included) and
//! the executor's fixed names (`pick`, `place`, belts, events) as strings. Reading an entry
//! rebuilds the record and checks that it serialises to the bytes the original did, so a mirror
//! that falls behind the record type is a cache miss, never a wrong answer.

use crate::cell::IkFailure;
use crate::sim::WallRecord;
use crate::sim::record::{
    BeltEvent, ContactRecord, IkRecord, NailOutcome, NailRecord, Op, Operation, Placement,
    PoseRecord, Refusal, RefusalKind, ReleaseRecord, TouchAt, TouchRecord,
};
use serde::{Deserialize, Serialize};
use std::collections::BTreeSet;
use std::sync::{Mutex, OnceLock};

/// The entry file: what it answers (key), the digest of the record's own serialisation, and
/// the record.
#[derive(Serialize, Deserialize)]
pub struct Entry {
    pub format: u32,
    pub key: String,
    pub record_digest: String,
    record: Rec,
}

/// The entry format; entries of another format are misses.
pub const FORMAT: u32 = 2;

impl Entry {
    pub fn new(key: &str, record: &WallRecord) -> Entry {
        Entry {
            format: FORMAT,
            key: key.to_string(),
            record_digest: record_digest(record),
            record: Rec::from(record),
        }
    }

    /// The record, when the entry is of this format, answers `key` and rebuilds exactly.
    pub fn into_record(self, key: &str) -> Option<WallRecord> {
        if self.format != FORMAT || self.key != key {
            return None;
        }
        let record = self.record.into_record()?;
        (record_digest(&record) == self.record_digest).then_some(record)
    }
}

/// blake3 of the record's JSON: what the report and the rules see of it.
fn record_digest(record: &WallRecord) -> String {
    let mut hasher = blake3::Hasher::new();
    // Serialising plain data into a hasher cannot fail.
    let _ = serde_json::to_writer(HashSink(&mut hasher), record);
    hasher.finalize().to_hex().to_string()
}

struct HashSink<'a>(&'a mut blake3::Hasher);

impl std::io::Write for HashSink<'_> {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        self.0.update(buf);
        Ok(buf.len())
    }
    fn flush(&mut self) -> std::io::Result<()> {
        Ok(())
    }
}

/// The executor names its belts and events with `&'static str`; rebuilt records
/// borrow each distinct name from this set, which holds a handful of words. An entry with
/// more distinct names than any executor uses is not a record.
fn intern(name: String) -> Option<&'static str> {
    const MOST_NAMES: usize = 256;
    static NAMES: OnceLock<Mutex<BTreeSet<&'static str>>> = OnceLock::new();
    let mut names = NAMES.get_or_init(Default::default).lock().ok()?;
    if let Some(known) = names.get(name.as_str()) {
        return Some(known);
    }
    if names.len() >= MOST_NAMES {
        return None;
    }
    let leaked: &'static str = Box::leak(name.into_boxed_str());
    names.insert(leaked);
    Some(leaked)
}

fn bits(x: f64) -> u64 {
    x.to_bits()
}

fn float(b: u64) -> f64 {
    f64::from_bits(b)
}

fn refusals_bits(list: &[(String, Refusal)]) -> Vec<(String, RefusalKind, String)> {
    list.iter()
        .map(|(p, r)| (p.clone(), r.kind, r.message.clone()))
        .collect()
}

fn refusals(list: Vec<(String, RefusalKind, String)>) -> Vec<(String, Refusal)> {
    list.into_iter()
        .map(|(p, kind, message)| (p, Refusal { kind, message }))
        .collect()
}

#[derive(Serialize, Deserialize)]
struct Rec {
    wall: String,
    operations: Vec<(String, String, u64, u64)>,
    ik: Vec<(String, String, Result<u64, IkFailureBits>)>,
    contacts: Vec<(String, String, u64, String, String, u64)>,
    /// piece, op, body a, body b, point, point in the wall, centre a, centre b, depth
    touches: Vec<TouchBits>,
    poses: Vec<(String, String, [u64; 3], [u64; 3])>,
    releases: Vec<(String, String, u64)>,
    placements: Vec<(String, u64, u64)>,
    fed: Vec<(String, u64)>,
    not_fed: Vec<(String, RefusalKind, String)>,
    grip_failed: Vec<(String, RefusalKind, String)>,
    grips: Vec<(String, u64)>,
    nails: Vec<NailBits>,
    belt_events: Vec<(u64, String, String, String)>,
    framing_end: u64,
    nailing_end: u64,
    nailing_while_framing: u64,
    steps: u64,
}

type TouchBits = (String, String, String, String, [[u64; 3]; 4], u64);

#[derive(Serialize, Deserialize)]
enum IkFailureBits {
    OutOfReach(u64, u64, u64),
    JointLimit(String, u64, u64, u64),
    WristSingularity(u64, u64),
    AllSolutionsCollide([String; 2]),
    NoExactSolution(u64, u64),
    BranchJump(String, u64, u64),
    PathBlocked([String; 2]),
    InvalidPose,
}

#[derive(Serialize, Deserialize)]
struct NailBits {
    plate: String,
    member: String,
    k: i64,
    planned: [u64; 3],
    outcome: OutcomeBits,
}

#[derive(Serialize, Deserialize)]
enum OutcomeBits {
    Fired {
        t: u64,
        as_built: [u64; 3],
        position_error: u64,
        member_inside: bool,
        driven: [u64; 3],
        lean: u64,
    },
    Skipped {
        kind: String,
        what: String,
        value: u64,
        limit: u64,
        message: String,
    },
}

impl From<&IkFailure> for IkFailureBits {
    fn from(f: &IkFailure) -> Self {
        match f {
            IkFailure::OutOfReach {
                distance,
                reach,
                min_reach,
            } => IkFailureBits::OutOfReach(bits(*distance), bits(*reach), bits(*min_reach)),
            IkFailure::JointLimit {
                joint,
                value,
                limit,
                excess,
            } => {
                IkFailureBits::JointLimit(joint.clone(), bits(*value), bits(*limit), bits(*excess))
            }
            IkFailure::WristSingularity { margin, required } => {
                IkFailureBits::WristSingularity(bits(*margin), bits(*required))
            }
            IkFailure::AllSolutionsCollide { pair } => {
                IkFailureBits::AllSolutionsCollide(pair.clone())
            }
            IkFailure::PathBlocked { pair } => IkFailureBits::PathBlocked(pair.clone()),
            IkFailure::NoExactSolution {
                position_error,
                rotation_error,
            } => IkFailureBits::NoExactSolution(bits(*position_error), bits(*rotation_error)),
            IkFailure::BranchJump { joint, jump, at } => {
                IkFailureBits::BranchJump(joint.clone(), bits(*jump), bits(*at))
            }
            IkFailure::InvalidPose => IkFailureBits::InvalidPose,
        }
    }
}

impl IkFailureBits {
    fn into_failure(self) -> IkFailure {
        match self {
            IkFailureBits::OutOfReach(d, r, m) => IkFailure::OutOfReach {
                distance: float(d),
                reach: float(r),
                min_reach: float(m),
            },
            IkFailureBits::JointLimit(joint, v, l, e) => IkFailure::JointLimit {
                joint,
                value: float(v),
                limit: float(l),
                excess: float(e),
            },
            IkFailureBits::WristSingularity(m, r) => IkFailure::WristSingularity {
                margin: float(m),
                required: float(r),
            },
            IkFailureBits::AllSolutionsCollide(pair) => IkFailure::AllSolutionsCollide { pair },
            IkFailureBits::PathBlocked(pair) => IkFailure::PathBlocked { pair },
            IkFailureBits::BranchJump(joint, j, a) => IkFailure::BranchJump {
                joint,
                jump: float(j),
                at: float(a),
            },
            IkFailureBits::NoExactSolution(p, r) => IkFailure::NoExactSolution {
                position_error: float(p),
                rotation_error: float(r),
            },
            IkFailureBits::InvalidPose => IkFailure::InvalidPose,
        }
    }
}

impl From<&WallRecord> for Rec {
    fn from(r: &WallRecord) -> Self {
        Rec {
            wall: r.wall.clone(),
            operations: r
                .operations
                .iter()
                .map(|o| {
                    (
                        o.piece.clone(),
                        o.op.to_string(),
                        bits(o.start),
                        bits(o.end),
                    )
                })
                .collect(),
            ik: r
                .ik
                .iter()
                .map(|i| {
                    let result = match &i.result {
                        Ok(x) => Ok(bits(*x)),
                        Err(f) => Err(IkFailureBits::from(f)),
                    };
                    (i.piece.clone(), i.op.to_string(), result)
                })
                .collect(),
            contacts: r
                .contacts
                .iter()
                .map(|c| {
                    (
                        c.piece.clone(),
                        c.op.to_string(),
                        bits(c.t),
                        c.body_a.clone(),
                        c.body_b.clone(),
                        bits(c.depth),
                    )
                })
                .collect(),
            touches: r
                .touches
                .iter()
                .map(|t| {
                    let at = &t.at;
                    let points = [at.point, at.point_wall, at.centre_a, at.centre_b];
                    (
                        t.piece.clone(),
                        t.op.to_string(),
                        t.body_a.clone(),
                        t.body_b.clone(),
                        points.map(|p| p.map(bits)),
                        bits(at.depth),
                    )
                })
                .collect(),
            poses: r
                .poses
                .iter()
                .map(|p| {
                    (
                        p.piece.clone(),
                        p.op.to_string(),
                        p.centre.map(bits),
                        p.centre_wall.map(bits),
                    )
                })
                .collect(),
            releases: r
                .releases
                .iter()
                .map(|x| (x.piece.clone(), x.below.clone(), bits(x.gap)))
                .collect(),
            placements: r
                .placements
                .iter()
                .map(|p| (p.piece.clone(), bits(p.position_error), bits(p.angle_error)))
                .collect(),
            fed: r.fed.iter().map(|(p, t)| (p.clone(), bits(*t))).collect(),
            not_fed: refusals_bits(&r.not_fed),
            grip_failed: refusals_bits(&r.grip_failed),
            grips: r.grips.iter().map(|(p, g)| (p.clone(), bits(*g))).collect(),
            nails: r
                .nails
                .iter()
                .map(|n| NailBits {
                    plate: n.plate.clone(),
                    member: n.member.clone(),
                    k: n.k,
                    planned: n.planned.map(bits),
                    outcome: match &n.outcome {
                        NailOutcome::Fired {
                            t,
                            as_built,
                            position_error,
                            member_inside,
                            driven,
                            lean,
                        } => OutcomeBits::Fired {
                            t: bits(*t),
                            as_built: as_built.map(bits),
                            position_error: bits(*position_error),
                            member_inside: *member_inside,
                            driven: driven.map(bits),
                            lean: bits(*lean),
                        },
                        NailOutcome::Skipped {
                            kind,
                            what,
                            value,
                            limit,
                            message,
                        } => OutcomeBits::Skipped {
                            kind: kind.clone(),
                            what: what.clone(),
                            value: bits(*value),
                            limit: bits(*limit),
                            message: message.clone(),
                        },
                    },
                })
                .collect(),
            belt_events: r
                .belt_events
                .iter()
                .map(|b| {
                    (
                        bits(b.t),
                        b.belt.to_string(),
                        b.event.to_string(),
                        b.piece.clone(),
                    )
                })
                .collect(),
            framing_end: bits(r.framing_end),
            nailing_end: bits(r.nailing_end),
            nailing_while_framing: bits(r.nailing_while_framing),
            steps: r.steps,
        }
    }
}

impl Rec {
    fn into_record(self) -> Option<WallRecord> {
        let mut operations = Vec::with_capacity(self.operations.len());
        for (piece, op, start, end) in self.operations {
            operations.push(Operation {
                piece,
                op: Op::from_name(&op)?,
                start: float(start),
                end: float(end),
            });
        }
        let mut ik = Vec::with_capacity(self.ik.len());
        for (piece, op, result) in self.ik {
            ik.push(IkRecord {
                piece,
                op: Op::from_name(&op)?,
                result: result.map(float).map_err(IkFailureBits::into_failure),
            });
        }
        let mut contacts = Vec::with_capacity(self.contacts.len());
        for (piece, op, t, body_a, body_b, depth) in self.contacts {
            contacts.push(ContactRecord {
                piece,
                op: Op::from_name(&op)?,
                t: float(t),
                body_a,
                body_b,
                depth: float(depth),
            });
        }
        let mut touches = Vec::with_capacity(self.touches.len());
        for (piece, op, body_a, body_b, points, depth) in self.touches {
            let [point, point_wall, centre_a, centre_b] = points.map(|p| p.map(float));
            touches.push(TouchRecord {
                piece,
                op: Op::from_name(&op)?,
                body_a,
                body_b,
                at: TouchAt {
                    point,
                    point_wall,
                    centre_a,
                    centre_b,
                    depth: float(depth),
                },
            });
        }
        let mut poses = Vec::with_capacity(self.poses.len());
        for (piece, op, centre, centre_wall) in self.poses {
            poses.push(PoseRecord {
                piece,
                op: Op::from_name(&op)?,
                centre: centre.map(float),
                centre_wall: centre_wall.map(float),
            });
        }
        let releases = self
            .releases
            .into_iter()
            .map(|(piece, below, gap)| ReleaseRecord {
                piece,
                below,
                gap: float(gap),
            })
            .collect();
        let mut belt_events = Vec::with_capacity(self.belt_events.len());
        for (t, belt, event, piece) in self.belt_events {
            belt_events.push(BeltEvent {
                t: float(t),
                belt: intern(belt)?,
                event: intern(event)?,
                piece,
            });
        }
        Some(WallRecord {
            // The pose trace (for the report's animation) is not cached: `simulate --report`
            // simulates every wall; nor is the robot's program (`program` simulates its walls).
            trace: Default::default(),
            program: Vec::new(),
            wall: self.wall,
            operations,
            ik,
            contacts,
            touches,
            poses,
            releases,
            placements: self
                .placements
                .into_iter()
                .map(|(piece, p, a)| Placement {
                    piece,
                    position_error: float(p),
                    angle_error: float(a),
                })
                .collect(),
            fed: self.fed.into_iter().map(|(p, t)| (p, float(t))).collect(),
            not_fed: refusals(self.not_fed),
            grip_failed: refusals(self.grip_failed),
            grips: self.grips.into_iter().map(|(p, g)| (p, float(g))).collect(),
            nails: self
                .nails
                .into_iter()
                .map(|n| NailRecord {
                    plate: n.plate,
                    member: n.member,
                    k: n.k,
                    planned: n.planned.map(float),
                    outcome: match n.outcome {
                        OutcomeBits::Fired {
                            t,
                            as_built,
                            position_error,
                            member_inside,
                            driven,
                            lean,
                        } => NailOutcome::Fired {
                            t: float(t),
                            as_built: as_built.map(float),
                            position_error: float(position_error),
                            member_inside,
                            driven: driven.map(float),
                            lean: float(lean),
                        },
                        OutcomeBits::Skipped {
                            kind,
                            what,
                            value,
                            limit,
                            message,
                        } => NailOutcome::Skipped {
                            kind,
                            what,
                            value: float(value),
                            limit: float(limit),
                            message,
                        },
                    },
                })
                .collect(),
            belt_events,
            framing_end: float(self.framing_end),
            nailing_end: float(self.nailing_end),
            nailing_while_framing: float(self.nailing_while_framing),
            steps: self.steps,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample() -> WallRecord {
        WallRecord {
            trace: Default::default(),
            program: Vec::new(),
            wall: "2Ab$x".into(),
            operations: vec![Operation {
                piece: "p1".into(),
                op: Op::Pick,
                start: 0.1 + 0.2,
                end: f64::INFINITY,
            }],
            ik: vec![
                IkRecord {
                    piece: "p1".into(),
                    op: Op::Place,
                    result: Ok(1e-300),
                },
                IkRecord {
                    piece: "p2".into(),
                    op: Op::Pick,
                    result: Err(IkFailure::JointLimit {
                        joint: "joint_3".into(),
                        value: 1.428,
                        limit: 1.3,
                        excess: f64::NAN,
                    }),
                },
            ],
            contacts: vec![],
            touches: vec![TouchRecord {
                piece: "p2".into(),
                op: Op::Pick,
                body_a: "tool gripper_1_jaws finger".into(),
                body_b: "piece p1".into(),
                at: TouchAt {
                    point: [0.1, -0.0, 1e-9],
                    point_wall: [3.0, 0.2, f64::MIN_POSITIVE],
                    centre_a: [1.0, 2.0, 3.0],
                    centre_b: [-1.0, -2.0, 0.3],
                    depth: 0.0589,
                },
            }],
            poses: vec![PoseRecord {
                piece: "p2".into(),
                op: Op::Place,
                centre: [2.0, 0.1, 0.95],
                centre_wall: [1.5, 2.9, -0.045],
            }],
            releases: vec![ReleaseRecord {
                piece: "p1".into(),
                below: "assembly table".into(),
                gap: 0.021,
            }],
            placements: vec![Placement {
                piece: "p1".into(),
                position_error: -0.0,
                angle_error: 3.0e-7,
            }],
            fed: vec![("p1".into(), 2.5)],
            not_fed: vec![(
                "p3".into(),
                Refusal::new(RefusalKind::TooLongForConveyors, "too long"),
            )],
            grip_failed: vec![],
            grips: vec![("p1".into(), -0.25)],
            nails: vec![NailRecord {
                plate: "bp".into(),
                member: "s1".into(),
                k: 2,
                planned: [0.1, 0.2, 0.3],
                outcome: NailOutcome::Skipped {
                    kind: "ik".into(),
                    what: "joint_5".into(),
                    value: 0.01,
                    limit: 0.02,
                    message: "wrist".into(),
                },
            }],
            belt_events: vec![BeltEvent {
                t: 1.0,
                belt: "conveyor 1",
                event: "stop",
                piece: "p1".into(),
            }],
            framing_end: 12.75,
            nailing_end: 30.125,
            nailing_while_framing: 2.5,
            steps: 7200,
        }
    }

    #[test]
    fn a_record_comes_back_bit_for_bit() {
        let r = sample();
        let text = serde_json::to_string(&Entry::new("k", &r)).unwrap();
        let back: Entry = serde_json::from_str(&text).unwrap();
        let back = back.into_record("k").unwrap();
        assert_eq!(
            serde_json::to_string(&back).unwrap(),
            serde_json::to_string(&r).unwrap()
        );
        // NaN serialises as null, so compare the bits where JSON cannot.
        let Err(IkFailure::JointLimit { excess, .. }) = &back.ik[1].result else {
            panic!("the failure changed kind");
        };
        assert!(excess.is_nan());
        assert_eq!(
            back.placements[0].position_error.to_bits(),
            (-0.0f64).to_bits()
        );
        assert_eq!(back.operations[0].end, f64::INFINITY);
    }

    #[test]
    fn another_key_or_a_changed_record_is_a_miss() {
        let r = sample();
        let entry = |key: &str| {
            let text = serde_json::to_string(&Entry::new(key, &r)).unwrap();
            serde_json::from_str::<Entry>(&text).unwrap()
        };
        assert!(entry("k").into_record("other").is_none());
        let mut e = entry("k");
        e.record.steps += 1;
        assert!(e.into_record("k").is_none());
        let mut e = entry("k");
        e.format += 1;
        assert!(e.into_record("k").is_none());
    }
}
