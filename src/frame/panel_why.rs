//! `why` for panels: a panel (`W1-P2`), a cut plate segment (`PLATE~2`), an added end stud
//! (`STUD~end2`), and `why-not 'panel_break(W1, 7.0)'` for a break that was not made. The
//! answers come from the plan and the rules' break relations, with the numbers behind them.

use super::panel::{Panel, WallPanels};
use super::panels::{BreakIndex, TOLERANCE, split_wall};
use super::plan::{Plan, Wall};
use crate::cell::{Cell, PanelLimits, PanelMode};
use crate::logic::compiled::Relations;
use serde::Serialize;

/// A `why-not panel_break(...)` query that cannot be answered.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum PanelWhyError {
    #[error(
        "`{tuple}`: write panel_break(WALL, U), e.g. panel_break(W1, 7.0), with U in m from the wall's start"
    )]
    Form { tuple: String },
    #[error("`{tuple}`: `{u}` is not a position in m")]
    Position { tuple: String, u: String },
    /// `known`: the first walls of the plan, comma-separated.
    #[error("no wall `{wall}` in the plan (walls: {known}, …)")]
    UnknownWall { wall: String, known: String },
    #[error("the rule base derives no panel limits (a rules directory without panels.dl)")]
    NoPanelLimits,
}

/// An answer: what was asked about and the explanation, one statement per line.
#[derive(Debug, Serialize)]
pub struct PanelWhy {
    pub subject: String,
    pub kind: &'static str,
    pub wall_id: String,
    pub panel_id: Option<String>,
    pub explanation: Vec<String>,
}

impl PanelWhy {
    pub fn to_text(&self) -> String {
        let mut out = String::new();
        for (i, line) in self.explanation.iter().enumerate() {
            out.push_str(if i == 0 { "" } else { "  " });
            out.push_str(line);
            out.push('\n');
        }
        out
    }
}

/// Whether `id` has the form of a panel, a cut segment or an added stud.
pub fn names_a_panel_part(id: &str) -> bool {
    id.contains('~')
        || id
            .rsplit_once("-P")
            .is_some_and(|(_, n)| n.parse::<usize>().is_ok())
}

/// Explains the panel, cut segment or added stud `id`; None when the plan has none such.
pub fn why(plan: &Plan, cell: &Cell, id: &str) -> Option<PanelWhy> {
    let limits = plan.panel_limits?;
    for wall in &plan.walls {
        for panel in &wall.panels.panels {
            let context = || panel_lines(plan, wall, panel, &limits, cell);
            if panel.id == id {
                return Some(answer(id, "panel", wall, Some(panel), context()));
            }
            if let Some(c) = panel.cut_pieces.iter().find(|c| c.id == id) {
                let role = plan.roles.get(&c.of).map_or("plate", String::as_str);
                let cuts: Vec<String> = cuts_of(&wall.panels, &c.of)
                    .iter()
                    .map(|u| format!("{u:.3}"))
                    .collect();
                let mut lines = vec![format!(
                    "{id}: a segment of {role} {} at u = {:.3} .. {:.3} m ({:.3} m, {:.1} kg), in panel {}",
                    c.of,
                    c.u_start,
                    c.u_end,
                    c.u_end - c.u_start,
                    c.mass,
                    panel.id
                )];
                lines.push(format!(
                    "plates lying level are cut where their wall is split (rules/panels.dl, cut_{role}); {} is cut at u = {} m",
                    c.of,
                    cuts.join(", ")
                ));
                lines.extend(lap_line(&wall.panels, &c.of, limits.cap_lap));
                lines.extend(context());
                return Some(answer(id, "cut_piece", wall, Some(panel), lines));
            }
            if let Some(a) = panel.added_pieces.iter().find(|a| a.id == id) {
                let at = if (a.u_start - panel.u_start).abs() < 1e-9 {
                    panel.u_start
                } else {
                    panel.u_end
                };
                let mut lines = vec![format!(
                    "{id}: an end stud added to panel {}, a copy of {} ({}) at u = {:.3} .. {:.3} m ({:.1} kg)",
                    panel.id, a.of, a.role, a.u_start, a.u_end, a.mass
                )];
                lines.push(format!(
                    "the break at u = {at:.3} m lies at a face of {}, with no stud face to face with it on the panel's side; a panel ends in a stud, so the rules add one (rules/panels.dl, added_after / added_before)",
                    a.of
                ));
                lines.extend(context());
                return Some(answer(id, "added_piece", wall, Some(panel), lines));
            }
        }
        if let Some(s) = wall.panels.site_pieces.iter().find(|s| s.id == id) {
            let role = plan.roles.get(&s.of).map_or("plate", String::as_str);
            let mut lines = vec![format!(
                "{id}: the stretch of {role} {} across the joint of panels {}, u = {:.3} .. {:.3} m ({:.3} m, {:.1} kg): fixed on site once the panels stand, built in no panel",
                s.of,
                s.laps.join(" and "),
                s.u_start,
                s.u_end,
                s.u_end - s.u_start,
                s.mass
            )];
            lines.extend(lap_line(&wall.panels, &s.of, limits.cap_lap));
            return Some(answer(id, "site_piece", wall, None, lines));
        }
    }
    None
}

/// Why a plate stops short of the breaks, if it laps over them.
fn lap_line(split: &WallPanels, plate: &str, lap: f64) -> Option<String> {
    if !split.site_pieces.iter().any(|s| s.of == plate) {
        return None;
    }
    Some(format!(
        "it laps over the panel joints: held back {lap:.3} m on both sides of each break (rules/panels.dl, cap_plate_laps; the cell's [panels] cap_lap), so its joints lie {lap:.3} m from the top plate's; a segment shorter than that is not made"
    ))
}

/// The breaks at which a piece (a cut plate) is cut: the breaks inside its span (its
/// segments' and site pieces' extent).
fn cuts_of(split: &WallPanels, plate: &str) -> Vec<f64> {
    let spans = split
        .panels
        .iter()
        .flat_map(|p| &p.cut_pieces)
        .filter(|c| c.of == plate)
        .map(|c| (c.u_start, c.u_end))
        .chain(
            split
                .site_pieces
                .iter()
                .filter(|s| s.of == plate)
                .map(|s| (s.u_start, s.u_end)),
        );
    let (lo, hi) = spans.fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), (a, b)| {
        (lo.min(a), hi.max(b))
    });
    split
        .breaks
        .iter()
        .map(|b| b.u)
        .filter(|&u| u > lo + TOLERANCE && u < hi - TOLERANCE)
        .collect()
}

fn answer(
    id: &str,
    kind: &'static str,
    wall: &Wall,
    panel: Option<&Panel>,
    explanation: Vec<String>,
) -> PanelWhy {
    PanelWhy {
        subject: id.to_string(),
        kind,
        wall_id: wall.id.clone(),
        panel_id: panel.map(|p| p.id.clone()),
        explanation,
    }
}

/// What the cell builds, with where the length limit comes from.
fn limits_line(limits: &PanelLimits, cell: &Cell) -> String {
    let source = if cell.carry_length() < cell.panels.max_length - 1e-9 {
        format!(
            "what its conveyors carry; [panels] max_length is {:.3} m",
            cell.panels.max_length
        )
    } else {
        "[panels] max_length".to_string()
    };
    format!(
        "cell {} builds panels of at most {:.3} m ({source}), {:.3} m high and {:.1} kg, and at least {:.3} m long",
        cell.name, limits.max_length, limits.max_height, limits.max_mass, limits.min_length
    )
}

/// Why the wall is split as it is (or not at all).
fn wall_line(plan: &Plan, wall: &Wall, limits: &PanelLimits, cell: &Cell) -> String {
    // The modelled members' mass (the panels' also counts the end studs they add).
    let mass: f64 = wall.members.iter().filter_map(|m| plan.masses.get(m)).sum();
    let count = wall.panels.panels.len();
    let verdict = if count > 1 {
        format!("split into {count} panels")
    } else if cell.panel_mode == PanelMode::Off {
        "one panel (--panels off)".to_string()
    } else if wall.length > limits.max_length + 1e-9 || mass > limits.max_mass + 1e-9 {
        "one panel: it cannot be split (see the notes)".to_string()
    } else {
        "within the limits: one panel".to_string()
    };
    format!(
        "wall {} ({}) is {:.3} m long and {mass:.1} kg: {verdict}",
        wall.id, wall.name, wall.length
    )
}

fn panel_lines(
    plan: &Plan,
    wall: &Wall,
    panel: &Panel,
    limits: &PanelLimits,
    cell: &Cell,
) -> Vec<String> {
    let mut lines = vec![format!(
        "panel {} of wall {}: u = {:.3} .. {:.3} m ({:.3} m long), {:.3} m high, {:.1} kg",
        panel.id,
        wall.id,
        panel.u_start,
        panel.u_end,
        panel.length(),
        panel.height,
        panel.mass
    )];
    lines.push(wall_line(plan, wall, limits, cell));
    lines.push(limits_line(limits, cell));
    let reason_at = |u: f64| {
        wall.panels
            .breaks
            .iter()
            .find(|b| (b.u - u).abs() < 1e-9)
            .map_or(String::new(), |b| b.reason.clone())
    };
    if panel.index > 1 {
        lines.push(format!(
            "starts at the break at u = {:.3} m: {}",
            panel.u_start,
            reason_at(panel.u_start)
        ));
    }
    if panel.index < wall.panels.panels.len() {
        lines.push(format!(
            "ends at the break at u = {:.3} m: {}",
            panel.u_end,
            reason_at(panel.u_end)
        ));
    }
    let cut: Vec<String> = panel
        .cut_pieces
        .iter()
        .map(|c| {
            format!(
                "{} (of {}, u {:.3} .. {:.3} m)",
                c.id, c.of, c.u_start, c.u_end
            )
        })
        .collect();
    let added: Vec<String> = panel
        .added_pieces
        .iter()
        .map(|a| {
            format!(
                "{} (a copy of {}, u {:.3} .. {:.3} m)",
                a.id, a.of, a.u_start, a.u_end
            )
        })
        .collect();
    lines.push(format!(
        "{} members whole; plate segments: {}; end studs added: {}",
        panel.member_ids.len(),
        if cut.is_empty() {
            "none".into()
        } else {
            cut.join(", ")
        },
        if added.is_empty() {
            "none".into()
        } else {
            added.join(", ")
        }
    ));
    if !panel.exceeds.is_empty() {
        lines.push(format!("exceeds the limits: {}", panel.exceeds.join(", ")));
    }
    lines.extend(wall.panels.notes.iter().map(|n| format!("note: {n}")));
    lines
}

/// `panel_break(WALL, U)`: the wall id and u (m) of a why-not query, if it has that form.
pub fn parse_break_query(tuple: &str) -> Option<Result<(String, f64), PanelWhyError>> {
    let inner = tuple
        .trim()
        .strip_prefix("panel_break(")?
        .strip_suffix(')')?;
    let Some((wall, u)) = inner.rsplit_once(',') else {
        return Some(Err(PanelWhyError::Form {
            tuple: tuple.to_string(),
        }));
    };
    let wall = wall.trim().trim_matches('"').to_string();
    Some(
        u.trim()
            .parse::<f64>()
            .ok()
            .filter(|u| u.is_finite())
            .map(|u| (wall, u))
            .ok_or_else(|| PanelWhyError::Position {
                tuple: tuple.to_string(),
                u: u.trim().to_string(),
            }),
    )
}

/// Why there is no break at `u` in the wall `wall_id`.
pub fn why_no_break(
    plan: &Plan,
    relations: &Relations,
    cell: &Cell,
    wall_id: &str,
    u: f64,
) -> Result<PanelWhy, PanelWhyError> {
    let wall = plan
        .walls
        .iter()
        .find(|w| w.id == wall_id || w.name == wall_id)
        .ok_or_else(|| {
            let ids: Vec<&str> = plan.walls.iter().take(8).map(|w| w.id.as_str()).collect();
            PanelWhyError::UnknownWall {
                wall: wall_id.to_string(),
                known: ids.join(", "),
            }
        })?;
    let limits = plan.panel_limits.ok_or(PanelWhyError::NoPanelLimits)?;
    let subject = format!("panel_break({}, {u})", wall.id);
    let mut lines = vec![];
    if let Some(b) = wall
        .panels
        .breaks
        .iter()
        .find(|b| (b.u - u).abs() <= TOLERANCE)
    {
        lines.push(format!(
            "{} is split at u = {:.3} m: {}",
            wall.id, b.u, b.reason
        ));
        return Ok(answer(&subject, "break", wall, None, lines));
    }
    lines.push(format!("no break at u = {u:.3} m in wall {}", wall.id));
    lines.push(wall_line(plan, wall, &limits, cell));
    lines.push(limits_line(&limits, cell));
    let index = BreakIndex::new(relations);
    let breaks = index.breaks(&wall.key);
    if !breaks.split {
        return Ok(answer(&subject, "break", wall, None, lines));
    }
    // The sites near u: blocked ones with every reason, allowed ones with what a break there
    // would cost.
    const NEAR: f64 = 0.3;
    let mut near: Vec<f64> = breaks
        .allowed
        .iter()
        .chain(breaks.blocked.iter().map(|b| &b.0))
        .copied()
        .filter(|s| (s - u).abs() <= NEAR)
        .collect();
    near.sort_by(f64::total_cmp);
    near.dedup_by(|a, b| (*a - *b).abs() <= TOLERANCE);
    let pieces = index.pieces(wall, &plan.masses);
    let through: Vec<String> = pieces
        .iter()
        .filter(|p| !p.cut && u > p.u0 + TOLERANCE && u < p.u1 - TOLERANCE)
        .take(6)
        .map(|p| {
            let role = plan.roles.get(p.id).map_or("other", String::as_str);
            format!("{} ({role}, u {:.3} .. {:.3} m)", p.id, p.u0, p.u1)
        })
        .collect();
    if !through.is_empty() {
        lines.push(format!(
            "a break at u = {u:.3} m would run through {}",
            through.join(", ")
        ));
    }
    if near.is_empty() {
        let before = breaks
            .allowed
            .iter()
            .copied()
            .filter(|s| *s < u)
            .fold(f64::NAN, f64::max);
        let after = breaks
            .allowed
            .iter()
            .copied()
            .filter(|s| *s > u)
            .fold(f64::NAN, f64::min);
        lines.push(format!(
            "no stud face lies within {NEAR} m of u = {u:.3} m (a break lies only at a stud's face: rules/panels.dl, break_site); the nearest allowed sites are at u = {before:.3} and {after:.3} m"
        ));
    }
    let chosen = &wall.panels;
    for site in near {
        let reasons: Vec<String> = breaks
            .blocked
            .iter()
            .filter(|b| (b.0 - site).abs() <= TOLERANCE)
            .map(|(_, reason, by)| {
                if by.is_empty() {
                    reason.to_string()
                } else {
                    format!(
                        "{reason} ({by}, {})",
                        plan.roles.get(*by).map_or("other", String::as_str)
                    )
                }
            })
            .collect();
        if !reasons.is_empty() {
            let mut reasons = reasons;
            reasons.dedup();
            lines.push(format!(
                "u = {site:.3} m: not allowed: {}",
                reasons.join("; ")
            ));
            continue;
        }
        if let Some(b) = chosen
            .breaks
            .iter()
            .find(|b| (b.u - site).abs() <= TOLERANCE)
        {
            lines.push(format!(
                "u = {site:.3} m: the break made here: {}",
                b.reason
            ));
            continue;
        }
        let mut asked = breaks.clone();
        asked.wanted = vec![(site, "asked")];
        let role_of = |p: &str| plan.roles.get(p).cloned().unwrap_or_default();
        let with = split_wall(&wall.id, wall.length, &pieces, &asked, &limits, &role_of);
        let (n, m) = (chosen.panels.len(), with.panels.len());
        let over: Vec<&str> = with
            .panels
            .iter()
            .flat_map(|p| p.exceeds.iter().map(String::as_str))
            .collect();
        let verdict = if m > n {
            format!("allowed, but a split through it needs {m} panels, not {n}")
        } else if !over.is_empty() || !with.notes.is_empty() {
            format!(
                "allowed, but no split through it keeps every panel within the limits ({})",
                over.iter()
                    .copied()
                    .chain(with.notes.iter().map(String::as_str))
                    .collect::<Vec<_>>()
                    .join("; ")
            )
        } else {
            format!(
                "allowed, and a split through it also has {m} panels; the chosen breaks lie nearer the wall's equal division (sum of squared distances {:.4} m² against {:.4} m² through this site)",
                deviation(chosen, wall.length),
                deviation(&with, wall.length)
            )
        };
        lines.push(format!("u = {site:.3} m: {verdict}"));
    }
    Ok(answer(&subject, "break", wall, None, lines))
}

/// Sum of squared distances of the breaks from the equal division, m².
fn deviation(split: &WallPanels, length: f64) -> f64 {
    let n = split.panels.len() as f64;
    split
        .breaks
        .iter()
        .enumerate()
        .map(|(k, b)| (b.u - (k + 1) as f64 * length / n).powi(2))
        .sum()
}
