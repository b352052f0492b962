//! The limits a wall spec must stay within, and where its openings and partitions go: each
//! checked against the wall and the others, with the extents their framing takes.
use super::spec::{
    CornerStyle, HeaderStyle, OpeningKind, OpeningSpec, PartitionSpec, PartitionStyle, WallSpec,
};
use crate::synth::error::SynthError;
use crate::synth::units::{INCH, Lumber, feet};

// Limits that keep the generator inside what wall framing means; outside them the
// input is a typo or a unit mix-up, so it is refused rather than drawn.
pub(super) const MIN_LENGTH: f64 = 0.3;
pub(super) const MAX_LENGTH: f64 = 30.0;
pub(super) const MIN_STUD: f64 = 0.3;
pub(super) const MAX_HEIGHT: f64 = 6.0;
pub(super) const MIN_SPACING: f64 = 8.0 * INCH;
pub(super) const MAX_SPACING: f64 = 48.0 * INCH;
pub(super) const SPACER: f64 = 0.5 * INCH;
/// Gaps above a header smaller than this get no cripple (too short to nail).
pub(super) const MIN_CRIPPLE: f64 = 1.0 * INCH;
/// Clear bay of ladder blocking (studs 16 in on centre, less one stud).
pub(super) const LADDER_BAY: f64 = 14.5 * INCH;
/// Ladder blocks every 24 in up the wall.
pub(super) const LADDER_STEP: f64 = 24.0 * INCH;
/// A let-in brace's 1x4 section.
pub(super) const BRACE_WIDTH: f64 = 3.5 * INCH;
pub(super) const BRACE_THICKNESS: f64 = 0.75 * INCH;
/// Length of a three-stud corner's spacer blocks.
pub(super) const SPACER_BLOCK: f64 = 12.0 * INCH;

/// Header lumber by clear span: deep enough for light residential loads.
fn header_lumber(span: f64) -> Option<Lumber> {
    if span <= feet(6.0) + 1e-9 {
        Some(Lumber::L2X10)
    } else if span <= feet(10.0) + 1e-9 {
        Some(Lumber::L2X12)
    } else {
        None
    }
}

pub(super) fn wall_err(spec: &WallSpec, what: String, hint: &str) -> SynthError {
    SynthError::Wall {
        wall: spec.id.clone(),
        what,
        hint: hint.to_string(),
    }
}

pub(super) fn check_range(
    spec: &WallSpec,
    name: &str,
    value: f64,
    lo: f64,
    hi: f64,
) -> Result<(), SynthError> {
    if !value.is_finite() || value < lo || value > hi {
        return Err(wall_err(
            spec,
            format!("{name} {value} m is outside {lo:.3}..{hi:.3} m"),
            "lengths are in metres unless given with a unit (ft, in, mm)",
        ));
    }
    Ok(())
}

/// One opening after validation, with its framing extents.
pub(super) struct PlacedOpening {
    index: usize,
    pub(super) spec: OpeningSpec,
    pub(super) u0: f64,
    pub(super) u1: f64,
    /// Bottom of the rough opening (0 for doors).
    pub(super) v0: f64,
    /// Top of the rough opening = bottom of the header.
    pub(super) v1: f64,
    pub(super) header: Lumber,
    /// Stud thicknesses of framing beside the rough opening on each side (2: jack and king;
    /// 3 with doubled kings).
    beside: f64,
}

impl PlacedOpening {
    /// Extent from the outer face of one king stud to the other.
    pub(super) fn zone(&self, t: f64) -> [f64; 2] {
        [self.u0 - self.beside * t, self.u1 + self.beside * t]
    }

    /// Where the left and right king studs start (u): beyond the jacks, or at the opening's
    /// edges when a flat header has none.
    pub(super) fn kings(&self, t: f64, jacks: bool) -> [f64; 2] {
        if jacks {
            [self.u0 - 2.0 * t, self.u1 + t]
        } else {
            [self.u0 - t, self.u1]
        }
    }
}

/// How far a corner's framing reaches in from the wall end, end stud included.
pub(super) fn corner_extent(style: CornerStyle, t: f64, depth: f64) -> f64 {
    match style {
        CornerStyle::Single => t,
        CornerStyle::Backer => t + depth,
        CornerStyle::ThreeStud => 3.0 * t,
        CornerStyle::Ladder => 2.0 * t + LADDER_BAY,
    }
}

/// The clear space between a partition's two studs.
fn partition_clear(style: PartitionStyle, depth: f64) -> f64 {
    match style {
        PartitionStyle::Backer => depth,
        PartitionStyle::Ladder => LADDER_BAY,
    }
}

/// The u range of a partition's framing, outer face to outer face of its studs.
pub(super) fn partition_zone(p: &PartitionSpec, t: f64, depth: f64) -> [f64; 2] {
    let half = 0.5 * partition_clear(p.style, depth);
    [p.u - half - t, p.u + half + t]
}

/// Validate partitions against the wall ends and the openings; sorted by u.
pub(super) fn place_partitions(
    spec: &WallSpec,
    openings: &[PlacedOpening],
) -> Result<Vec<PartitionSpec>, SynthError> {
    let (t, depth) = (spec.lumber.thickness, spec.lumber.width);
    let end = corner_extent(spec.detail.corners, t, depth);
    let mut placed: Vec<PartitionSpec> = spec.detail.partitions.clone();
    placed.sort_by(|a, b| a.u.total_cmp(&b.u));
    let mut taken: Vec<[f64; 2]> = openings.iter().map(|o| o.zone(t)).collect();
    for p in &placed {
        let z = partition_zone(p, t, depth);
        let err = |what: String| {
            wall_err(
                spec,
                format!("partition at u {:.4} m: {what}", p.u),
                "move the partition; its two studs need their own place in the wall",
            )
        };
        if !p.u.is_finite() || z[0] < end - 1e-9 || z[1] > spec.length - end + 1e-9 {
            return Err(err(format!(
                "its framing u {:.4}..{:.4} m is not clear of the wall ends' framing ({end:.4} m at each end)",
                z[0], z[1]
            )));
        }
        if let Some(o) = taken
            .iter()
            .find(|o| z[0] < o[1] - 1e-9 && o[0] < z[1] - 1e-9)
        {
            return Err(err(format!(
                "its framing u {:.4}..{:.4} m overlaps framing at u {:.4}..{:.4} m",
                z[0], z[1], o[0], o[1]
            )));
        }
        taken.push(z);
    }
    Ok(placed)
}

/// Validate openings against the wall and each other; sorted by u.
pub(super) fn place_openings(
    spec: &WallSpec,
    stud_top: f64,
) -> Result<Vec<PlacedOpening>, SynthError> {
    let t = spec.lumber.thickness;
    let mut placed = Vec::new();
    for (index, o) in spec.openings.iter().enumerate() {
        let err = |what: String, hint: &str| SynthError::Opening {
            wall: spec.id.clone(),
            index,
            kind: o.kind.name(),
            what,
            hint: hint.to_string(),
        };
        for (name, v) in [("u", o.u), ("width", o.width), ("height", o.height)] {
            if !v.is_finite() || v <= 0.0 {
                return Err(err(
                    format!("{name} must be a positive length, got {v}"),
                    "give U,W,H in metres or with a unit",
                ));
            }
        }
        let (u0, u1) = (o.u, o.u + o.width);
        let beside = if spec.detail.double_kings { 3.0 } else { 2.0 };
        let end = corner_extent(spec.detail.corners, t, spec.lumber.width);
        if u0 - beside * t < end - 1e-9 || u1 + beside * t > spec.length - end + 1e-9 {
            return Err(err(
                format!(
                    "rough opening u {u0:.4}..{u1:.4} m with its jack and king studs does not fit between the corner framing ({end:.4} m at each end) of a {:.4} m wall",
                    spec.length
                ),
                "the opening needs its jack and king studs clear of the wall ends' framing; move or narrow it",
            ));
        }
        let header = header_lumber(o.width).ok_or_else(|| {
            err(
                format!("clear span {:.3} m is over 10 ft", o.width),
                "split the opening; longer spans need an engineered header",
            )
        })?;
        let (v0, v1) = match o.kind {
            OpeningKind::Door => (0.0, o.height),
            OpeningKind::Window { sill } => {
                let plies = if spec.detail.double_sill { 2.0 } else { 1.0 };
                if !sill.is_finite() || sill - plies * t < t + 0.05 {
                    return Err(err(
                        format!(
                            "sill height {sill} m leaves no room for the rough sill and cripples below it"
                        ),
                        "raise the window (sill height is measured from the floor to the rough opening)",
                    ));
                }
                (sill, sill + o.height)
            }
        };
        if v1 <= t + 1e-9 {
            return Err(err(
                format!("opening top {v1:.4} m is not above the bottom plate"),
                "make the opening taller",
            ));
        }
        let (head_nominal, head_depth) = match spec.header_style {
            HeaderStyle::Flat => (spec.lumber.nominal, t),
            _ => (header.nominal, header.width),
        };
        if v1 + head_depth > stud_top + 1e-9 {
            return Err(err(
                format!(
                    "opening top {v1:.4} m plus a {head_nominal} header ({head_depth:.4} m) is above the top plate at {stud_top:.4} m"
                ),
                "lower or shorten the opening, or make the wall taller",
            ));
        }
        placed.push(PlacedOpening {
            index,
            spec: *o,
            u0,
            u1,
            v0,
            v1,
            header,
            beside,
        });
    }
    placed.sort_by(|a, b| a.u0.total_cmp(&b.u0));
    for pair in placed.windows(2) {
        // Side by side, two openings share the king stud between them.
        let jacks = spec.header_style != HeaderStyle::Flat;
        let shared = !spec.detail.double_kings
            && (pair[0].kings(t, jacks)[1] - pair[1].kings(t, jacks)[0]).abs() < 1e-9;
        if !shared && pair[0].zone(t)[1] > pair[1].zone(t)[0] + 1e-9 {
            let o = &pair[1];
            return Err(SynthError::Opening {
                wall: spec.id.clone(),
                index: o.index,
                kind: o.spec.kind.name(),
                what: format!("its framing overlaps opening {}", pair[0].index),
                hint: "keep 4 stud thicknesses between rough openings, or exactly 3 (jack, shared king, jack; 1 with flat headers) to share the king stud".into(),
            });
        }
    }
    Ok(placed)
}
