//! The bid figures of one cell on one model: what it builds, what fails and why, how long it
//! takes and how many metres of wall an hour that makes. `compare` sets several cells side by
//! side; a report opens with its cell's.
//!
//! Every count is the rules' verdict of the run (`wall_framing_count`, `wall_nail_count`,
//! `nail_ok`), every time the results table's, so the figures equal what `simulate` gives.
//! Failures are counted by [`FailureClass`] (read off the run's record).
//!
//! Metres of wall per hour count only panels built whole (every piece framed, every nail driven
//! on target) against the time the cell spent on them: a cell that leaves pieces out is not
//! credited with the time it saved by skipping them. Panels are built one after another; time
//! to change panels on the table is not simulated.

use super::failure_class::{FailureClass, nail_class, piece_class};
use super::simulate::SimReport;
use crate::cell::Cell;
use crate::frame::rows::{NailOk, Row, RowError, WallFramingCount, WallNailCount};
use crate::sim::Simulation;
use serde::Serialize;
use std::collections::{BTreeMap, BTreeSet};

/// One cell's figures on one model.
#[derive(Debug, Clone, Serialize)]
pub struct Bid {
    pub cell: String,
    pub robot: String,
    /// The carriage's travel on its track, m (none for a fixed base).
    pub track_travel_m: Option<f64>,
    pub tool: String,
    pub walls: usize,
    pub panels: usize,
    pub pieces: Tally,
    pub nails: Tally,
    pub framing_s: f64,
    pub nailing_s: f64,
    pub total_s: f64,
    /// Length of every panel simulated, m.
    pub wall_metres: f64,
    /// Panels built whole, and their length.
    pub complete_panels: usize,
    pub complete_metres: f64,
    /// Metres of whole panels per hour of the time spent on them; none when no panel is whole.
    pub metres_per_hour: Option<f64>,
    pub per_panel: Vec<PanelFigures>,
}

/// How many were planned, done and failed, and the failures by cause (most frequent first).
#[derive(Debug, Clone, Default, Serialize)]
pub struct Tally {
    pub planned: usize,
    pub done: usize,
    pub failed: usize,
    pub by_cause: Vec<CauseCount>,
}

#[derive(Debug, Clone, Serialize)]
pub struct CauseCount {
    pub cause: FailureClass,
    pub label: &'static str,
    pub count: usize,
    /// The failed pieces (ids) or nails (`plate -> member #k`), in run order.
    pub ids: Vec<String>,
}

/// One panel (a wall that fits is one) as the cell built it.
#[derive(Debug, Clone, Serialize)]
pub struct PanelFigures {
    pub panel_id: String,
    pub wall_id: String,
    pub name: String,
    pub length_m: f64,
    pub pieces: usize,
    pub framed: usize,
    pub nails: usize,
    pub driven: usize,
    pub framing_s: f64,
    pub nailing_s: f64,
    pub complete: bool,
}

fn round(x: f64, per: f64) -> f64 {
    let r = (x * per).round() / per;
    if r == 0.0 { 0.0 } else { r }
}

/// `(total, done)` of a per-wall count relation, by wall key; `fields` picks the wall and the
/// counts of a row.
fn counts<R: Row>(
    sim: &Simulation,
    fields: impl Fn(&R) -> (&'static str, i64, i64),
) -> Result<BTreeMap<String, (usize, usize)>, RowError> {
    let n = |n: i64| n.max(0) as usize;
    Ok(sim
        .reasoned
        .rows::<R>()?
        .iter()
        .map(|t| {
            let (wall, total, done) = fields(t);
            (wall.to_string(), (n(total), n(done)))
        })
        .collect())
}

/// The rules' counts with the failures by class; the classes add up to `failed` (a failure
/// the record does not explain is counted as decided by a rule).
fn tally(planned: usize, done: usize, failures: Vec<(FailureClass, String)>) -> Tally {
    let mut by: BTreeMap<FailureClass, Vec<String>> = BTreeMap::new();
    for (class, id) in failures {
        by.entry(class).or_default().push(id);
    }
    let mut by_cause: Vec<CauseCount> = by
        .into_iter()
        .map(|(cause, ids)| CauseCount {
            cause,
            label: cause.label(),
            count: ids.len(),
            ids,
        })
        .collect();
    by_cause.sort_by(|a, b| b.count.cmp(&a.count).then(a.cause.cmp(&b.cause)));
    Tally {
        planned,
        done,
        failed: planned.saturating_sub(done),
        by_cause,
    }
}

impl Bid {
    /// The figures of `sim`; an error when a count tuple does not match its relation's
    /// declaration.
    pub fn new(sim: &Simulation, report: &SimReport, cell: &Cell) -> Result<Bid, RowError> {
        let framing = counts(sim, |t: &WallFramingCount| (t.w, t.total, t.framed))?;
        let nailing = counts(sim, |t: &WallNailCount| (t.w, t.total, t.ok))?;
        let nail_ok: BTreeSet<(String, String, i64)> = sim
            .reasoned
            .rows::<NailOk>()?
            .into_iter()
            .map(|t| (t.plate.to_string(), t.member.to_string(), t.k))
            .collect();
        let robot = &cell.robot;
        let mut piece_failures = Vec::new();
        let mut nail_failures = Vec::new();
        let mut per_panel = Vec::new();
        for (rec, row) in sim.records.iter().zip(&report.panels) {
            let (pieces, framed) = framing.get(&rec.wall).copied().unwrap_or_default();
            let (nails, driven) = nailing.get(&rec.wall).copied().unwrap_or_default();
            for e in report
                .elements
                .iter()
                .filter(|e| e.panel_id == row.panel_id)
            {
                if e.framing.status == "failed" {
                    piece_failures.push((piece_class(rec, &e.id, robot), e.id.clone()));
                }
            }
            for n in &rec.nails {
                if !nail_ok.contains(&(n.plate.clone(), n.member.clone(), n.k)) {
                    nail_failures.push((
                        nail_class(&n.outcome, robot),
                        format!("{} -> {} #{}", n.plate, n.member, n.k),
                    ));
                }
            }
            let length = sim
                .plan
                .walls
                .iter()
                .find(|w| w.key == rec.wall)
                .map_or(0.0, |w| w.length);
            per_panel.push(PanelFigures {
                panel_id: row.panel_id.clone(),
                wall_id: row.wall_id.clone(),
                name: row.name.clone(),
                length_m: round(length, 1e6),
                pieces,
                framed,
                nails,
                driven,
                framing_s: row.framing.time_s,
                nailing_s: row.nailing.time_s,
                complete: framed == pieces && driven == nails,
            });
        }
        let sum = |f: &dyn Fn(&PanelFigures) -> f64, only_complete: bool| -> f64 {
            per_panel
                .iter()
                .filter(|p| p.complete || !only_complete)
                .map(f)
                .sum()
        };
        let framing_s = sum(&|p| p.framing_s, false);
        let nailing_s = sum(&|p| p.nailing_s, false);
        let complete_metres = sum(&|p| p.length_m, true);
        let complete_time = sum(&|p| p.framing_s + p.nailing_s, true);
        let walls: BTreeSet<&str> = per_panel.iter().map(|p| p.wall_id.as_str()).collect();
        Ok(Bid {
            cell: cell.name.clone(),
            robot: robot.name.clone(),
            track_travel_m: cell
                .track
                .as_ref()
                .map(|t| round(t.travel[1] - t.travel[0], 1e6)),
            tool: cell.tool.name.clone(),
            walls: walls.len(),
            panels: per_panel.len(),
            pieces: tally(
                per_panel.iter().map(|p| p.pieces).sum(),
                per_panel.iter().map(|p| p.framed).sum(),
                piece_failures,
            ),
            nails: tally(
                per_panel.iter().map(|p| p.nails).sum(),
                per_panel.iter().map(|p| p.driven).sum(),
                nail_failures,
            ),
            framing_s: round(framing_s, 1e6),
            nailing_s: round(nailing_s, 1e6),
            total_s: round(framing_s + nailing_s, 1e6),
            wall_metres: round(sum(&|p| p.length_m, false), 1e6),
            complete_panels: per_panel.iter().filter(|p| p.complete).count(),
            complete_metres: round(complete_metres, 1e6),
            metres_per_hour: (complete_time > 0.0)
                .then(|| round(complete_metres / complete_time * 3600.0, 1e6)),
            per_panel,
        })
    }

    /// The robot, with its track when it has one.
    pub fn robot_text(&self) -> String {
        match self.track_travel_m {
            Some(t) => format!("{} on a {t:.1} m track", self.robot),
            None => self.robot.clone(),
        }
    }
}

impl Bid {
    /// Two lines for the end of `simulate`'s terminal report: the totals over every panel,
    /// and the failures by cause.
    pub fn totals_text(&self) -> String {
        let rate = self
            .metres_per_hour
            .map_or(String::new(), |m| format!("; {m:.1} m of wall per hour"));
        let mut s = format!(
            "all walls: {} pieces framed, {} nails driven; framing {} + nailing {} = {}; {} of {} panels built whole ({:.1} of {:.1} m){rate}\n",
            done_of(&self.pieces),
            done_of(&self.nails),
            duration(self.framing_s),
            duration(self.nailing_s),
            duration(self.total_s),
            self.complete_panels,
            self.panels,
            self.complete_metres,
            self.wall_metres,
        );
        for (what, t) in [("pieces", &self.pieces), ("nails", &self.nails)] {
            if !t.by_cause.is_empty() {
                let causes: Vec<String> = t
                    .by_cause
                    .iter()
                    .map(|c| format!("{} {}", c.count, c.label))
                    .collect();
                s.push_str(&format!("{what} failed: {}\n", causes.join("; ")));
            }
        }
        s
    }
}

/// The bid table: per figure its label and one value per cell (the terminal's and the page's).
pub fn rows(bids: &[Bid]) -> Vec<(String, Vec<String>)> {
    let mut rows: Vec<(String, Vec<String>)> = vec![
        ("cell".into(), bids.iter().map(|b| b.cell.clone()).collect()),
        ("robot".into(), bids.iter().map(Bid::robot_text).collect()),
        ("tool".into(), bids.iter().map(|b| b.tool.clone()).collect()),
        (
            "walls / panels".into(),
            bids.iter()
                .map(|b| format!("{} / {}", b.walls, b.panels))
                .collect(),
        ),
        (
            "pieces framed".into(),
            bids.iter().map(|b| done_of(&b.pieces)).collect(),
        ),
        (
            "nails driven".into(),
            bids.iter().map(|b| done_of(&b.nails)).collect(),
        ),
        (
            "framing time".into(),
            bids.iter().map(|b| duration(b.framing_s)).collect(),
        ),
        (
            "nailing time".into(),
            bids.iter().map(|b| duration(b.nailing_s)).collect(),
        ),
        (
            "total time".into(),
            bids.iter().map(|b| duration(b.total_s)).collect(),
        ),
        (
            "panels built whole".into(),
            bids.iter()
                .map(|b| {
                    format!(
                        "{} of {} ({:.1} of {:.1} m)",
                        b.complete_panels, b.panels, b.complete_metres, b.wall_metres
                    )
                })
                .collect(),
        ),
        (
            "metres of wall per hour".into(),
            bids.iter()
                .map(|b| b.metres_per_hour.map_or("–".into(), |m| format!("{m:.1}")))
                .collect(),
        ),
    ];
    for (what, pick) in [
        (
            "pieces failed: ",
            (|b: &Bid| &b.pieces) as fn(&Bid) -> &Tally,
        ),
        ("nails failed: ", |b: &Bid| &b.nails),
    ] {
        let causes: BTreeSet<FailureClass> = bids
            .iter()
            .flat_map(|b| pick(b).by_cause.iter().map(|c| c.cause))
            .collect();
        for cause in causes {
            rows.push((
                format!("{what}{}", cause.label()),
                bids.iter()
                    .map(|b| {
                        pick(b)
                            .by_cause
                            .iter()
                            .find(|c| c.cause == cause)
                            .map_or("0".into(), |c| c.count.to_string())
                    })
                    .collect(),
            ));
        }
    }
    rows
}

/// One line per figure, one column per cell: the terminal's bid table.
pub fn table_text(bids: &[Bid]) -> String {
    use std::fmt::Write;
    let rows = rows(bids);
    let label_width = rows
        .iter()
        .map(|(l, _)| l.chars().count())
        .max()
        .unwrap_or(0);
    let widths: Vec<usize> = (0..bids.len())
        .map(|i| {
            rows.iter()
                .map(|(_, v)| v[i].chars().count())
                .max()
                .unwrap_or(0)
        })
        .collect();
    let mut s = String::new();
    for (label, values) in &rows {
        let _ = write!(s, "{label:<label_width$}");
        for (v, w) in values.iter().zip(&widths) {
            let _ = write!(s, "  {v:>w$}");
        }
        let _ = writeln!(s);
    }
    s
}

pub fn done_of(t: &Tally) -> String {
    let pct = if t.planned == 0 {
        100.0
    } else {
        t.done as f64 * 100.0 / t.planned as f64
    };
    format!("{} of {} ({pct:.1} %)", t.done, t.planned)
}

/// Seconds as `1 h 02 min`, `12 min 05 s` or `42.0 s`.
pub fn duration(s: f64) -> String {
    let whole = s.round() as u64;
    if whole >= 3600 {
        format!("{} h {:02} min", whole / 3600, (whole % 3600) / 60)
    } else if whole >= 60 {
        format!("{} min {:02} s", whole / 60, whole % 60)
    } else {
        format!("{s:.1} s")
    }
}
