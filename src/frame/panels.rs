//! Panels: each wall split at the breaks `rules/panels.dl` allows, to the cell's panel limits.
//!
//! The rules say where a break may lie and which end studs it adds; this module chooses:
//! 1. a wall the rules do not split (`wall_split`: it fits) is one panel;
//! 2. otherwise the **fewest panels** such that every panel is within `max_length`, no shorter
//!    than `min_length` and no heavier than `max_mass`, with a break at every allowed site a
//!    shop's rule wants (`break_wanted`);
//! 3. among those, the breaks nearest the wall's equal division (break k of K − 1 nearest
//!    k·L/K, least sum of squares; the first in u on a tie). The targets depend only on the
//!    wall's length, so an edit moves only the break whose allowed sites it changed.
//!
//! Where no choice meets every limit, the mass limit is dropped, then the minimum length, and the
//! wall's note says so; where no split exists at all the wall stays one panel and says why.
//! Plates lying level (`cut_at_break`) are cut at the breaks into segments `PLATE~k` (k from 1
//! along u: the k-th panel the plate runs through); an end stud a break adds is `STUD~endK`,
//! K the panel (from 1) it belongs to. A plate that laps over the joints (`cut_lapped`, cap
//! plates) is held back `lap` on both sides of each break: its segments stop `lap` short of
//! the break (a segment shorter than `lap` is not made) and the stretch across the joint is a
//! site piece `PLATE~lapK` (K the first break it spans along the plate), fixed on site.

use super::panel::{AddedPiece, CutPiece, Panel, PanelBreak, SitePiece, WallPanels};
use super::plan::Wall;
use crate::cell::PanelLimits;
use crate::logic::Value;
use crate::logic::compiled::Relations;
use rustc_hash::{FxHashMap, FxHashSet};
use std::collections::BTreeMap;

/// Faces closer than this meet, m (`break_tolerance` of the rules).
pub(crate) const TOLERANCE: f64 = 0.003;

/// One piece of a wall as the panel split sees it (wall coordinates, m).
#[derive(Debug, Clone)]
pub struct PieceSpan<'a> {
    pub id: &'a str,
    pub u0: f64,
    pub u1: f64,
    pub v0: f64,
    pub v1: f64,
    pub mass: f64,
    /// Cut at a break (a plate lying level) rather than kept whole.
    pub cut: bool,
    /// How far a cut piece is held back from each break (0: cut at the break), m.
    pub lap: f64,
}

/// What the rules say about one wall.
#[derive(Debug, Clone, Default)]
pub struct WallBreaks<'a> {
    /// The rules split this wall (`wall_split`).
    pub split: bool,
    /// Allowed break sites, u.
    pub allowed: Vec<f64>,
    /// (u, stud, side): the end stud a break at u adds (side 1 after u, −1 before).
    pub added: Vec<(f64, &'a str, i64)>,
    /// (u, reason): breaks a shop's rule asks for.
    pub wanted: Vec<(f64, &'a str)>,
    /// (u, reason, piece): why a site is not allowed.
    pub blocked: Vec<(f64, &'a str, &'a str)>,
}

/// Splits one wall. `pieces` in the wall's member order; `roles` gives an added stud's role.
pub fn split_wall(
    wall_id: &str,
    length: f64,
    pieces: &[PieceSpan],
    breaks: &WallBreaks,
    limits: &PanelLimits,
    role_of: &dyn Fn(&str) -> String,
) -> WallPanels {
    let mut notes = vec![];
    let sites = clusters(&breaks.allowed);
    let mut mandatory = vec![false; sites.len()];
    for &(u, reason) in &breaks.wanted {
        match sites.iter().position(|s| s.holds(u)) {
            Some(i) => mandatory[i] = true,
            None => notes.push(format!(
                "the break a rule wants at u = {u:.3} m ({reason}) is not made: {}",
                why_not_site(u, breaks)
            )),
        }
    }
    let chosen: Vec<usize> = if breaks.split {
        let mass = MassIndex::new(pieces, breaks, &sites);
        choose(length, &sites, &mandatory, &mass, limits, &mut notes)
    } else {
        vec![]
    };
    let cuts: Vec<f64> = chosen.iter().map(|&i| sites[i].u).collect();
    let (panels, site_pieces) = build_panels(
        wall_id, length, pieces, breaks, &sites, &chosen, role_of, limits,
    );
    let count = panels.len();
    let reasons = cuts
        .iter()
        .enumerate()
        .map(|(k, &u)| PanelBreak {
            u,
            reason: format!(
                "{count} panels are the fewest within the limits; this break is the allowed one nearest {:.3} m ({} of {count} along the wall)",
                (k + 1) as f64 * length / count as f64,
                k + 1
            ),
        })
        .collect();
    WallPanels {
        panels,
        breaks: reasons,
        site_pieces,
        notes,
    }
}

/// Allowed sites closer than the tolerance are one site (two layers of studs, rounding).
#[derive(Debug, Clone)]
struct Site {
    u: f64,
    members: Vec<f64>,
}

impl Site {
    fn holds(&self, u: f64) -> bool {
        self.members
            .iter()
            .any(|m| (m - u).abs() <= TOLERANCE + 1e-12)
    }
}

fn clusters(allowed: &[f64]) -> Vec<Site> {
    let mut us: Vec<f64> = allowed.iter().copied().filter(|u| u.is_finite()).collect();
    us.sort_by(f64::total_cmp);
    let mut sites: Vec<Site> = vec![];
    for u in us {
        match sites.last_mut() {
            Some(s) if u - s.members[s.members.len() - 1] <= TOLERANCE => s.members.push(u),
            _ => sites.push(Site {
                u,
                members: vec![u],
            }),
        }
    }
    sites
}

/// Why there is no allowed site at `u`, from the rules' `break_blocked`.
fn why_not_site(u: f64, breaks: &WallBreaks) -> String {
    match breaks
        .blocked
        .iter()
        .find(|(b, _, _)| (b - u).abs() <= TOLERANCE)
    {
        Some((_, reason, "")) => reason.to_string(),
        Some((_, reason, piece)) => format!("{reason} ({piece})"),
        None if !breaks.split => "the wall is not split".into(),
        None => "no stud face lies there".into(),
    }
}

/// The mass between two points of the wall, from prefix sums of the whole pieces.
struct MassIndex {
    /// Whole pieces' centres along u, sorted, with the running mass up to each.
    centres: Vec<f64>,
    running: Vec<f64>,
    /// Cut pieces: (u0, u1, mass, lap).
    cut: Vec<(f64, f64, f64, f64)>,
    /// Per site: mass of the end studs it adds after it and before it.
    added_after: Vec<f64>,
    added_before: Vec<f64>,
}

impl MassIndex {
    fn new(pieces: &[PieceSpan], breaks: &WallBreaks, sites: &[Site]) -> MassIndex {
        let mut whole: Vec<(f64, f64)> = pieces
            .iter()
            .filter(|p| !p.cut)
            .map(|p| ((p.u0 + p.u1) / 2.0, p.mass))
            .collect();
        whole.sort_by(|a, b| a.0.total_cmp(&b.0));
        let mut running = Vec::with_capacity(whole.len() + 1);
        running.push(0.0);
        for (_, m) in &whole {
            running.push(running.last().copied().unwrap_or(0.0) + m);
        }
        let masses: FxHashMap<&str, f64> = pieces.iter().map(|p| (p.id, p.mass)).collect();
        let mass_of = |id: &str| masses.get(id).copied().unwrap_or(0.0);
        let added = |side: i64| -> Vec<f64> {
            sites
                .iter()
                .map(|s| {
                    breaks
                        .added
                        .iter()
                        .filter(|(u, _, sd)| *sd == side && s.holds(*u))
                        .map(|(_, stud, _)| mass_of(stud))
                        .sum()
                })
                .collect()
        };
        MassIndex {
            centres: whole.iter().map(|w| w.0).collect(),
            running,
            cut: pieces
                .iter()
                .filter(|p| p.cut)
                .map(|p| (p.u0, p.u1, p.mass, p.lap))
                .collect(),
            added_after: added(1),
            added_before: added(-1),
        }
    }

    /// Mass of the pieces between `a` and `b` (whole pieces by their centre, cut ones by share;
    /// a lapped piece held back from `a` or `b` where that end is a break).
    fn between(&self, a: f64, b: f64, a_break: bool, b_break: bool) -> f64 {
        let at = |u: f64| self.centres.partition_point(|c| *c < u);
        let whole = self.running[at(b)] - self.running[at(a)];
        let cut: f64 = self
            .cut
            .iter()
            .map(|&(u0, u1, m, lap)| {
                let a = if a_break { a + lap } else { a };
                let b = if b_break { b - lap } else { b };
                let overlap = (b.min(u1) - a.max(u0)).max(0.0);
                if u1 > u0 {
                    m * overlap / (u1 - u0)
                } else {
                    0.0
                }
            })
            .sum();
        whole + cut
    }
}

/// Which limits a choice must meet.
#[derive(Clone, Copy)]
struct Check {
    mass: bool,
    min_length: bool,
}

/// The chosen sites (indices into `sites`, along u); empty when the wall stays whole.
fn choose(
    length: f64,
    sites: &[Site],
    mandatory: &[bool],
    mass: &MassIndex,
    limits: &PanelLimits,
    notes: &mut Vec<String>,
) -> Vec<usize> {
    // Points: the wall's start, the sites, its end.
    let mut points = vec![0.0];
    points.extend(sites.iter().map(|s| s.u));
    points.push(length);
    let n = points.len();
    let mass_of = |i: usize, j: usize| {
        let mut m = mass.between(points[i], points[j], i > 0, j < n - 1);
        if i > 0 {
            m += mass.added_after[i - 1];
        }
        if j < n - 1 {
            m += mass.added_before[j - 1];
        }
        m
    };
    let attempts = [
        (
            Check {
                mass: true,
                min_length: true,
            },
            None,
        ),
        (
            Check {
                mass: false,
                min_length: true,
            },
            Some(
                "no split keeps every panel within the mass limit; panels are split by length only",
            ),
        ),
        (
            Check {
                mass: false,
                min_length: false,
            },
            Some(
                "no split keeps every panel within the mass limit and above the minimum length; panels are split by the maximum length only",
            ),
        ),
    ];
    for (check, note) in attempts {
        let fits = |i: usize, j: usize| {
            let l = points[j] - points[i];
            l <= limits.max_length + 1e-9
                && (!check.min_length || l >= limits.min_length - 1e-9)
                && (!check.mass || mass_of(i, j) <= limits.max_mass + 1e-9)
        };
        if let Some(path) = fewest_nearest(&points, mandatory, &fits) {
            if let Some(note) = note {
                notes.push(note.to_string());
            }
            // Points 1..n-1 are the sites.
            return path[1..path.len() - 1].iter().map(|&p| p - 1).collect();
        }
    }
    notes.push(format!(
        "the wall cannot be split within the cell's {:.2} m: {}; it stays one panel",
        limits.max_length,
        longest_gap(&points)
    ));
    vec![]
}

/// The longest stretch without an allowed break, in words.
fn longest_gap(points: &[f64]) -> String {
    let (mut at, mut gap) = (0, 0.0);
    for i in 1..points.len() {
        if points[i] - points[i - 1] > gap {
            (at, gap) = (i, points[i] - points[i - 1]);
        }
    }
    if points.len() == 2 {
        return "no break is allowed anywhere in it".into();
    }
    format!(
        "no break is allowed between u = {:.3} and {:.3} m ({gap:.2} m)",
        points[at - 1],
        points[at]
    )
}

/// The path from the first to the last point with the fewest steps (each step `fits`, passing
/// no mandatory point), and among those the one whose inner points lie nearest the equal
/// division. Point indices, first and last included; None when no path exists.
fn fewest_nearest(
    points: &[f64],
    mandatory: &[bool],
    fits: &dyn Fn(usize, usize) -> bool,
) -> Option<Vec<usize>> {
    let n = points.len();
    let last = n - 1;
    // Mandatory sites are points 1..n-1; a step may end at one but not pass one.
    let is_mandatory = |p: usize| p > 0 && p < last && mandatory[p - 1];
    let predecessors = |j: usize| {
        let mut from = vec![];
        for i in (0..j).rev() {
            if points[j] - points[i] > 0.0 && fits(i, j) {
                from.push(i);
            }
            if is_mandatory(i) {
                break;
            }
        }
        from
    };
    let steps: Vec<Vec<usize>> = (0..n).map(predecessors).collect();
    let mut fewest = vec![usize::MAX; n];
    fewest[0] = 0;
    for j in 1..n {
        fewest[j] = steps[j]
            .iter()
            .filter(|&&i| fewest[i] != usize::MAX)
            .map(|&i| fewest[i] + 1)
            .min()
            .unwrap_or(usize::MAX);
    }
    let panels = fewest[last];
    if panels == usize::MAX {
        return None;
    }
    let length = points[last];
    let target = |k: usize| k as f64 * length / panels as f64;
    // cost[k][j]: least squared distance of breaks 1..k from their targets, the k-th at j.
    let mut cost = vec![vec![f64::INFINITY; n]; panels + 1];
    let mut from = vec![vec![usize::MAX; n]; panels + 1];
    cost[0][0] = 0.0;
    for k in 1..=panels {
        for j in 1..n {
            if (j == last) != (k == panels) {
                continue;
            }
            let here = if j == last {
                0.0
            } else {
                (points[j] - target(k)).powi(2)
            };
            // Predecessors come in decreasing u; `<=` keeps the first in u on a tie.
            for &i in &steps[j] {
                let c = cost[k - 1][i] + here;
                if c <= cost[k][j] && cost[k - 1][i].is_finite() {
                    cost[k][j] = c;
                    from[k][j] = i;
                }
            }
        }
    }
    let mut path = vec![last];
    let mut j = last;
    for k in (1..=panels).rev() {
        j = from[k][j];
        if j == usize::MAX {
            return None;
        }
        path.push(j);
    }
    path.reverse();
    Some(path)
}

/// The panels between the chosen sites.
#[allow(clippy::too_many_arguments)]
fn build_panels(
    wall_id: &str,
    length: f64,
    pieces: &[PieceSpan],
    breaks: &WallBreaks,
    sites: &[Site],
    chosen: &[usize],
    role_of: &dyn Fn(&str) -> String,
    limits: &PanelLimits,
) -> (Vec<Panel>, Vec<SitePiece>) {
    let mut bounds = vec![0.0];
    bounds.extend(chosen.iter().map(|&i| sites[i].u));
    bounds.push(length);
    let count = bounds.len() - 1;
    let mut panels: Vec<Panel> = (0..count)
        .map(|k| Panel {
            id: format!("{wall_id}-P{}", k + 1),
            index: k + 1,
            u_start: bounds[k],
            u_end: bounds[k + 1],
            height: 0.0,
            mass: 0.0,
            member_ids: vec![],
            cut_pieces: vec![],
            added_pieces: vec![],
            exceeds: vec![],
        })
        .collect();
    let panel_at = |u: f64| bounds[1..count].partition_point(|b| *b <= u);
    let mut spans: Vec<Vec<(f64, f64)>> = vec![vec![]; count];
    let mut site_pieces = vec![];
    for p in pieces {
        let inner: Vec<f64> = bounds[1..count]
            .iter()
            .copied()
            .filter(|b| p.cut && *b > p.u0 + TOLERANCE && *b < p.u1 - TOLERANCE)
            .collect();
        if inner.is_empty() {
            let k = panel_at((p.u0 + p.u1) / 2.0);
            panels[k].member_ids.push(p.id.to_string());
            panels[k].mass += p.mass;
            spans[k].push((p.v0, p.v1));
            continue;
        }
        let mut ends = vec![p.u0];
        ends.extend(inner);
        ends.push(p.u1);
        let share = |a: f64, b: f64| p.mass * (b - a) / (p.u1 - p.u0);
        let last = ends.len() - 2;
        // Where the plate is covered so far (the start of the next site piece).
        let mut covered = p.u0;
        // The first break the next site piece spans (breaks numbered from 1 along the plate).
        let mut gap_from_break = 1;
        for (s, pair) in ends.windows(2).enumerate() {
            let k = panel_at((pair[0] + pair[1]) / 2.0);
            let start = if s == 0 { pair[0] } else { pair[0] + p.lap };
            let end = if s == last { pair[1] } else { pair[1] - p.lap };
            if end - start < p.lap.max(TOLERANCE) {
                continue;
            }
            if start > covered + 1e-9 {
                site_pieces.push(site_piece(p, covered, start, gap_from_break, &panels));
            }
            panels[k].cut_pieces.push(CutPiece {
                id: format!("{}~{}", p.id, s + 1),
                of: p.id.to_string(),
                u_start: start,
                u_end: end,
                mass: share(start, end),
            });
            panels[k].mass += share(start, end);
            spans[k].push((p.v0, p.v1));
            covered = end;
            gap_from_break = s + 1;
        }
        if covered < p.u1 - 1e-9 {
            site_pieces.push(site_piece(p, covered, p.u1, gap_from_break, &panels));
        }
    }
    let by_id: FxHashMap<&str, &PieceSpan> = pieces.iter().map(|p| (p.id, p)).collect();
    for (b, &i) in chosen.iter().enumerate() {
        let site = &sites[i];
        let mut added: Vec<&(f64, &str, i64)> =
            breaks.added.iter().filter(|a| site.holds(a.0)).collect();
        added.sort_by(|x, y| (x.1, x.2).cmp(&(y.1, y.2)));
        for &&(u, stud, side) in &added {
            let Some(s) = by_id.get(stud) else {
                continue;
            };
            let width = s.u1 - s.u0;
            // Side 1: the panel after break b (index b + 1); −1: the one before (index b).
            let (k, u_start) = if side > 0 { (b + 1, u) } else { (b, u - width) };
            panels[k].added_pieces.push(AddedPiece {
                id: format!("{stud}~end{}", k + 1),
                of: stud.to_string(),
                role: role_of(stud),
                u_start,
                u_end: u_start + width,
                mass: s.mass,
            });
            panels[k].mass += s.mass;
            spans[k].push((s.v0, s.v1));
        }
    }
    for (panel, spans) in panels.iter_mut().zip(&spans) {
        let lo = spans.iter().map(|s| s.0).fold(f64::INFINITY, f64::min);
        let hi = spans.iter().map(|s| s.1).fold(f64::NEG_INFINITY, f64::max);
        panel.height = if hi > lo { hi - lo } else { 0.0 };
        panel
            .added_pieces
            .sort_by(|a, b| a.u_start.total_cmp(&b.u_start));
        panel.exceeds = exceeded(panel, limits, count > 1);
    }
    site_pieces.sort_by(|a, b| a.u_start.total_cmp(&b.u_start).then(a.id.cmp(&b.id)));
    (panels, site_pieces)
}

/// The site piece of lapped plate `p` from `u_start` to `u_end` (`PLATE~lapK`, K the first
/// break it spans, numbered from 1 along the plate).
fn site_piece(
    p: &PieceSpan,
    u_start: f64,
    u_end: f64,
    first_break: usize,
    panels: &[Panel],
) -> SitePiece {
    SitePiece {
        id: format!("{}~lap{first_break}", p.id),
        of: p.id.to_string(),
        u_start,
        u_end,
        mass: p.mass * (u_end - u_start) / (p.u1 - p.u0),
        laps: panels
            .iter()
            .filter(|k| k.u_start < u_end - TOLERANCE && k.u_end > u_start + TOLERANCE)
            .map(|k| k.id.clone())
            .collect(),
    }
}

/// The limits a panel breaks, in words.
fn exceeded(panel: &Panel, limits: &PanelLimits, split: bool) -> Vec<String> {
    let mut out = vec![];
    let length = panel.length();
    if length > limits.max_length + 1e-9 {
        out.push(format!(
            "length {length:.3} m > the cell's {:.3} m",
            limits.max_length
        ));
    }
    if split && length < limits.min_length - 1e-9 {
        out.push(format!(
            "length {length:.3} m < the minimum {:.3} m",
            limits.min_length
        ));
    }
    if panel.height > limits.max_height + 1e-9 {
        out.push(format!(
            "height {:.3} m > the cell's {:.3} m",
            panel.height, limits.max_height
        ));
    }
    if panel.mass > limits.max_mass + 1e-9 {
        out.push(format!(
            "mass {:.1} kg > the cell's {:.1} kg",
            panel.mass, limits.max_mass
        ));
    }
    out
}

/// The effective limits the rules derived (`panel_limit`), if the cell gave them.
pub fn limits_from(relations: &Relations) -> Option<PanelLimits> {
    let t = relations.get("panel_limit")?.first()?;
    let f = |i: usize| t.get(i).and_then(Value::as_float).unwrap_or(f64::NAN);
    let cap_lap = relations
        .get("panel_cap_lap")
        .and_then(|r| r.first())
        .and_then(|t| t.first())
        .and_then(Value::as_float)
        .unwrap_or(0.0);
    Some(PanelLimits {
        max_length: f(0),
        max_height: f(1),
        max_mass: f(2),
        min_length: f(3),
        cap_lap,
    })
}

/// The rules' break relations, by wall key, and the pieces' extents in their walls.
pub struct BreakIndex<'r> {
    boxes: FxHashMap<&'r str, [f64; 6]>,
    cut: FxHashSet<&'r str>,
    /// Cut pieces that lap over the joints, and how far (`cut_lapped`).
    lapped: FxHashMap<&'r str, f64>,
    by_wall: FxHashMap<&'r str, WallBreaks<'r>>,
    none: WallBreaks<'r>,
}

fn sym(v: &Value) -> &str {
    v.as_symbol().unwrap_or_default()
}

fn float(v: &Value) -> f64 {
    v.as_float().unwrap_or(f64::NAN)
}

impl<'r> BreakIndex<'r> {
    pub fn new(relations: &'r Relations) -> BreakIndex<'r> {
        let get = |relation: &str| relations.get(relation).map_or(&[][..], Vec::as_slice);
        let boxes = get("local_box")
            .iter()
            .map(|t| (sym(&t[0]), std::array::from_fn(|i| float(&t[i + 1]))))
            .collect();
        let cut = get("cut_at_break").iter().map(|t| sym(&t[0])).collect();
        let mut lapped: FxHashMap<&str, f64> = FxHashMap::default();
        for t in get("cut_lapped") {
            // Two rules lapping one piece: the longer lap holds.
            let lap = lapped.entry(sym(&t[0])).or_insert(0.0);
            *lap = lap.max(float(&t[1]));
        }
        let mut by_wall: FxHashMap<&str, WallBreaks> = FxHashMap::default();
        fn wall<'m, 'r>(
            by_wall: &'m mut FxHashMap<&'r str, WallBreaks<'r>>,
            t: &'r [Value],
        ) -> &'m mut WallBreaks<'r> {
            by_wall.entry(sym(&t[0])).or_default()
        }
        for t in get("wall_split") {
            wall(&mut by_wall, t).split = true;
        }
        for t in get("break_allowed") {
            wall(&mut by_wall, t).allowed.push(float(&t[1]));
        }
        for t in get("break_added") {
            let side = t[3].as_number().unwrap_or(0);
            wall(&mut by_wall, t)
                .added
                .push((float(&t[1]), sym(&t[2]), side));
        }
        for t in get("break_wanted") {
            wall(&mut by_wall, t)
                .wanted
                .push((float(&t[1]), sym(&t[2])));
        }
        for t in get("break_blocked") {
            wall(&mut by_wall, t)
                .blocked
                .push((float(&t[1]), sym(&t[2]), sym(&t[3])));
        }
        BreakIndex {
            boxes,
            cut,
            lapped,
            by_wall,
            none: WallBreaks::default(),
        }
    }

    /// What the rules say about the wall named by its key piece.
    pub fn breaks(&self, key: &str) -> &WallBreaks<'r> {
        self.by_wall.get(key).unwrap_or(&self.none)
    }

    /// The wall's members as the split sees them.
    pub fn pieces<'w>(&self, wall: &'w Wall, masses: &BTreeMap<String, f64>) -> Vec<PieceSpan<'w>> {
        wall.members
            .iter()
            .map(|id| {
                let b = self.boxes.get(id.as_str()).copied().unwrap_or([0.0; 6]);
                PieceSpan {
                    id,
                    u0: b[0],
                    u1: b[1],
                    v0: b[2],
                    v1: b[3],
                    mass: masses.get(id).copied().unwrap_or(0.0),
                    cut: self.cut.contains(id.as_str()),
                    lap: self.lapped.get(id.as_str()).copied().unwrap_or(0.0),
                }
            })
            .collect()
    }
}

/// Splits every wall of the plan (`Wall::panels`) from the rules' break relations.
pub(super) fn split_walls(
    walls: &mut [Wall],
    relations: &Relations,
    roles: &BTreeMap<String, String>,
    masses: &BTreeMap<String, f64>,
    limits: &PanelLimits,
) {
    use rayon::prelude::*;
    let index = BreakIndex::new(relations);
    let role_of = |p: &str| roles.get(p).cloned().unwrap_or_else(|| "other".into());
    walls.par_iter_mut().for_each(|wall| {
        let pieces = index.pieces(wall, masses);
        let breaks = index.breaks(&wall.key);
        wall.panels = split_wall(&wall.id, wall.length, &pieces, breaks, limits, &role_of);
    });
}

#[cfg(test)]
mod tests;
