//! Ground truth the rules must reproduce, computed from the layout's own boxes:
//! precedence (rests on / end nailed through) and the study's nailing targets.
//! This is an independent statement of the rules' intent, not their code.
use crate::synth::layout::{Role, WallLayout};

/// Touching tolerance (metres).
const TOUCH: f64 = 1e-6;

fn overlap(a: [f64; 2], b: [f64; 2]) -> f64 {
    a[1].min(b[1]) - a[0].max(b[0])
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Reason {
    /// `after` rests on `before`.
    RestsOn,
    /// `after` is horizontal and its end touches the side of vertical `before`.
    EndNailedThrough,
}

impl Reason {
    pub fn as_str(self) -> &'static str {
        match self {
            Reason::RestsOn => "rests_on",
            Reason::EndNailedThrough => "end_nailed_through",
        }
    }
}

/// Piece indices: `before` must be placed before `after`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Precedence {
    pub before: usize,
    pub after: usize,
    pub reason: Reason,
}

/// One nail: through `plate` into the end of `member`, in wall coordinates.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Nail {
    pub plate: usize,
    pub member: usize,
    pub kind: &'static str,
    pub u: f64,
    pub v: f64,
    pub w: f64,
    /// +1: driven up (along v); -1: driven down.
    pub v_direction: f64,
}

/// Every precedence pair of a wall, in piece order of `after`, then `before`.
pub fn precedence(wall: &WallLayout) -> Vec<Precedence> {
    let p = &wall.pieces;
    let mut out = Vec::new();
    // A let-in brace crosses the pieces it is let into; it goes in last and rests on none.
    let framing = |k: &usize| p[*k].role != Role::Brace;
    for a in (0..p.len()).filter(framing) {
        let upper = &p[a];
        for b in (0..p.len()).filter(framing) {
            let lower = &p[b];
            let (ub, lb) = (upper.wall_box, lower.wall_box);
            let rests = (ub.v[0] - lb.v[1]).abs() < TOUCH
                && overlap(ub.u, lb.u) > TOUCH
                && overlap(ub.w, lb.w) > TOUCH;
            if rests {
                out.push(Precedence {
                    before: b,
                    after: a,
                    reason: Reason::RestsOn,
                });
                continue;
            }
            let end_touch = !upper.upright
                && lower.upright
                && ((ub.u[0] - lb.u[1]).abs() < TOUCH || (ub.u[1] - lb.u[0]).abs() < TOUCH)
                && overlap(ub.v, lb.v) > TOUCH
                && overlap(ub.w, lb.w) > TOUCH;
            if end_touch {
                out.push(Precedence {
                    before: b,
                    after: a,
                    reason: Reason::EndNailedThrough,
                });
            }
        }
    }
    out
}

/// The study's rule: 2 nails through a plate's outer face into each vertical member
/// end on it, at the member's centre u and 1/3, 2/3 of the plate's width in w.
/// Returns (plate nails, sill-to-cripple nails).
pub fn nailing_targets(wall: &WallLayout) -> (Vec<Nail>, Vec<Nail>) {
    let p = &wall.pieces;
    let (mut primary, mut secondary) = (Vec::new(), Vec::new());
    for (i, plate) in p.iter().enumerate() {
        let pb = plate.wall_box;
        // (kind, face the nail enters, which end of the member touches, direction)
        let (kind, face_v, member_end_at, dir, out) = match plate.role {
            Role::BottomPlate => ("bottom_plate_to_stud", pb.v[0], pb.v[1], 1.0, &mut primary),
            Role::TopPlate => ("top_plate_to_stud", pb.v[1], pb.v[0], -1.0, &mut primary),
            Role::Sill => (
                "sill_to_cripple_stud",
                pb.v[1],
                pb.v[0],
                -1.0,
                &mut secondary,
            ),
            _ => continue,
        };
        for (j, m) in p.iter().enumerate() {
            let mb = m.wall_box;
            let end = if dir > 0.0 { mb.v[0] } else { mb.v[1] };
            // Spacer blocks are nailed through the studs they fill between, not the plates.
            if !m.upright
                || m.role == Role::Blocking
                || (end - member_end_at).abs() > TOUCH
                || overlap(mb.u, pb.u) <= TOUCH
            {
                continue;
            }
            let u = 0.5 * (mb.u[0] + mb.u[1]);
            // Across the width the plate and the member share (a flat stud is thin in w).
            let (w0, w1) = (pb.w[0].max(mb.w[0]), pb.w[1].min(mb.w[1]));
            for k in [1.0, 2.0] {
                let w = w0 + k / 3.0 * (w1 - w0);
                out.push(Nail {
                    plate: i,
                    member: j,
                    kind,
                    u,
                    v: face_v,
                    w,
                    v_direction: dir,
                });
            }
        }
    }
    (primary, secondary)
}
