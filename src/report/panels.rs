//! The panels of the `plan` report: each wall's panels, the breaks between them and the
//! limits they were split to (`frame::panels`).

use super::round_m;
use crate::cell::PanelLimits;
use crate::frame::panel::WallPanels;
use serde::Serialize;

/// Masses to the gram.
fn round_kg(x: f64) -> f64 {
    (x * 1e3).round() / 1e3
}

#[derive(Debug, Clone, Copy, Serialize)]
pub struct LimitsRow {
    pub max_length: f64,
    pub max_height: f64,
    pub max_mass: f64,
    pub min_length: f64,
    /// How far cap plates are held back from each break (0: cut at the break).
    pub cap_lap: f64,
}

impl LimitsRow {
    pub fn new(l: &PanelLimits) -> LimitsRow {
        LimitsRow {
            max_length: round_m(l.max_length),
            max_height: round_m(l.max_height),
            max_mass: round_kg(l.max_mass),
            min_length: round_m(l.min_length),
            cap_lap: round_m(l.cap_lap),
        }
    }
}

#[derive(Debug, Serialize)]
pub struct PanelRow<'a> {
    pub panel_id: &'a str,
    pub index: usize,
    pub u_start: f64,
    pub u_end: f64,
    pub length: f64,
    pub height: f64,
    pub mass: f64,
    pub member_ids: &'a [String],
    pub cut_pieces: Vec<CutRow<'a>>,
    pub added_pieces: Vec<AddedRow<'a>>,
    /// The limits the panel breaks, in words (empty when it fits).
    pub exceeds: &'a [String],
}

#[derive(Debug, Serialize)]
pub struct CutRow<'a> {
    pub id: &'a str,
    pub of: &'a str,
    pub u_start: f64,
    pub u_end: f64,
    pub length: f64,
    pub mass: f64,
}

#[derive(Debug, Serialize)]
pub struct AddedRow<'a> {
    pub id: &'a str,
    pub role: &'a str,
    /// The stud it copies (same section and height), moved along the wall.
    pub of: &'a str,
    pub u_start: f64,
    pub u_end: f64,
    pub mass: f64,
}

impl<'a> CutRow<'a> {
    fn new(id: &'a str, of: &'a str, u_start: f64, u_end: f64, mass: f64) -> CutRow<'a> {
        CutRow {
            id,
            of,
            u_start: round_m(u_start),
            u_end: round_m(u_end),
            length: round_m(u_end - u_start),
            mass: round_kg(mass),
        }
    }
}

/// A stretch of a lapped plate across a joint, fixed on site: a cut piece in no panel.
#[derive(Debug, Serialize)]
pub struct SiteRow<'a> {
    #[serde(flatten)]
    pub piece: CutRow<'a>,
    /// The panels it laps over.
    pub laps: &'a [String],
}

#[derive(Debug, Serialize)]
pub struct BreakRow<'a> {
    pub u: f64,
    pub reason: &'a str,
}

pub fn panel_rows(split: &WallPanels) -> Vec<PanelRow<'_>> {
    split
        .panels
        .iter()
        .map(|p| PanelRow {
            panel_id: &p.id,
            index: p.index,
            u_start: round_m(p.u_start),
            u_end: round_m(p.u_end),
            length: round_m(p.length()),
            height: round_m(p.height),
            mass: round_kg(p.mass),
            member_ids: &p.member_ids,
            cut_pieces: p
                .cut_pieces
                .iter()
                .map(|c| CutRow::new(&c.id, &c.of, c.u_start, c.u_end, c.mass))
                .collect(),
            added_pieces: p
                .added_pieces
                .iter()
                .map(|a| AddedRow {
                    id: &a.id,
                    role: &a.role,
                    of: &a.of,
                    u_start: round_m(a.u_start),
                    u_end: round_m(a.u_end),
                    mass: round_kg(a.mass),
                })
                .collect(),
            exceeds: &p.exceeds,
        })
        .collect()
}

pub fn site_rows(split: &WallPanels) -> Vec<SiteRow<'_>> {
    split
        .site_pieces
        .iter()
        .map(|s| SiteRow {
            piece: CutRow::new(&s.id, &s.of, s.u_start, s.u_end, s.mass),
            laps: &s.laps,
        })
        .collect()
}

pub fn break_rows(split: &WallPanels) -> Vec<BreakRow<'_>> {
    split
        .breaks
        .iter()
        .map(|b| BreakRow {
            u: round_m(b.u),
            reason: &b.reason,
        })
        .collect()
}

/// One line per split wall for the text report: its panels' lengths and where the breaks lie.
pub fn text_line(split: &WallPanels) -> Option<String> {
    if split.panels.len() < 2 {
        return None;
    }
    let lengths: Vec<String> = split
        .panels
        .iter()
        .map(|p| format!("{:.2}", p.length()))
        .collect();
    let at: Vec<String> = split.breaks.iter().map(|b| format!("{:.3}", b.u)).collect();
    let site = match split.site_pieces.len() {
        0 => String::new(),
        1 => "; 1 piece laps a joint on site".to_string(),
        n => format!("; {n} pieces lap the joints on site"),
    };
    Some(format!(
        "  {} panels of {} m, split at u = {} m{site}",
        split.panels.len(),
        lengths.join(", "),
        at.join(", ")
    ))
}
