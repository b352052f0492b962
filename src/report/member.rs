//! What every member row of a report says of a piece: who it is (`MemberId`) and its axis and
//! section (`MemberShape`); `inspect` and `plan` add what each knows beside.

use super::{round_m, round_point};
use crate::geom::Point3;
use crate::ifc::Piece;
use serde::Serialize;

/// A piece by its ids: framewright's, the entity's, the IFC GlobalId, the ply (a piece of a
/// built-up member), its name and IFC type.
#[derive(Debug, Serialize)]
pub struct MemberId<'a> {
    pub id: &'a str,
    pub entity: u64,
    pub global_id: &'a str,
    pub piece: Option<usize>,
    pub name: Option<&'a str>,
    pub ifc_type: &'a str,
}

impl<'a> MemberId<'a> {
    pub fn of(p: &'a Piece) -> MemberId<'a> {
        MemberId {
            id: &p.id,
            entity: p.entity,
            global_id: &p.global_id,
            piece: p.piece,
            name: p.name.as_deref(),
            ifc_type: &p.ifc_type,
        }
    }
}

/// A piece's axis (m, model frame) and its box's section and length (m), rounded to 1 nm.
#[derive(Debug, Serialize)]
pub struct MemberShape {
    pub axis_start: [f64; 3],
    pub axis_end: [f64; 3],
    pub width: f64,
    pub thickness: f64,
    pub length: f64,
}

impl MemberShape {
    /// The shape of `p` with its axis from `start` to `end`.
    pub fn of(p: &Piece, start: &Point3, end: &Point3) -> MemberShape {
        MemberShape {
            axis_start: round_point(start),
            axis_end: round_point(end),
            width: round_m(p.obox.width()),
            thickness: round_m(p.obox.thickness()),
            length: round_m(p.obox.length()),
        }
    }
}
