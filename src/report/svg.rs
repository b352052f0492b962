//! The drawings of one wall as SVG (built with maud, which escapes every text and attribute
//! value): its elevation in the wall frame, the cell seen from above with the wall laid on
//! the assembly area, and the timeline of its run. Coordinates are written with fixed
//! decimals so the same run gives the same bytes.

use super::simulate::SimReport;
use super::verdict;
use super::wall_view::{PieceView, WallView};
use crate::cell::Cell;
use crate::frame::panel::WallPanels;
use crate::sim::Simulation;
use crate::sim::record::Op;
use maud::{Markup, html};
use nalgebra::{Isometry3, Point3, Translation3, UnitQuaternion, Vector3};

/// Drawing width of the elevation and the plan view (px).
const WIDTH: f64 = 880.0;
const MARGIN: f64 = 30.0;
/// Tallest drawing of the cell from above (px).
const PLAN_HEIGHT: f64 = 700.0;

fn f1(x: f64) -> String {
    format!("{x:.1}")
}

/// The tooltip of a piece: its IFC name, `#entity`, role, verdict and reason.
fn tooltip(p: &PieceView) -> String {
    let entity = p.entity.map(|e| format!(" #{e}")).unwrap_or_default();
    let name = if p.name.is_empty() {
        "(no name)"
    } else {
        &p.name
    };
    let mut s = format!(
        "{name}{entity} — {} — {}",
        p.role,
        p.class.replace('-', " ")
    );
    if !p.reason.is_empty() {
        s.push_str(" — ");
        s.push_str(&p.reason);
    }
    s
}

/// A scale bar of `metres` drawn at (x, y) with `px_per_m`.
fn scale_bar(x: f64, y: f64, px_per_m: f64) -> Markup {
    // The largest of 0.1 / 0.5 / 1 / 2 / 5 m that fits in 200 px.
    let metres = [5.0, 2.0, 1.0, 0.5, 0.2, 0.1]
        .into_iter()
        .find(|m| m * px_per_m <= 200.0)
        .unwrap_or(0.1);
    let w = metres * px_per_m;
    html! {
        g class="scale-bar" {
            line x1=(f1(x)) y1=(f1(y)) x2=(f1(x + w)) y2=(f1(y)) stroke="#000" stroke-width="2" {}
            line x1=(f1(x)) y1=(f1(y - 4.0)) x2=(f1(x)) y2=(f1(y + 4.0)) stroke="#000" {}
            line x1=(f1(x + w)) y1=(f1(y - 4.0)) x2=(f1(x + w)) y2=(f1(y + 4.0)) stroke="#000" {}
            text x=(f1(x + w + 6.0)) y=(f1(y + 4.0)) font-size="12" { (format!("{metres} m")) }
        }
    }
}

/// The elevation of one wall (the report's wall id) as a standalone SVG document: every
/// piece a rectangle coloured by verdict and labelled by role, every nailing target a dot,
/// a scale bar. `None` when the simulation has no such wall.
pub fn elevation_svg(sim: &Simulation, report: &SimReport, wall_id: &str) -> Option<String> {
    let view = WallView::new(sim, report, None, wall_id)?;
    Some(super::markup_text::replace_forbidden(
        elevation(&view).into_string(),
    ))
}

pub(super) fn elevation(view: &WallView) -> Markup {
    let rects: Vec<[f64; 4]> = view.pieces.iter().map(|p| p.wall_rect).collect();
    let u0 = rects
        .iter()
        .map(|r| r[0])
        .fold(f64::INFINITY, f64::min)
        .min(0.0);
    let v0 = rects
        .iter()
        .map(|r| r[1])
        .fold(f64::INFINITY, f64::min)
        .min(0.0);
    let u1 = rects
        .iter()
        .map(|r| r[2])
        .fold(f64::NEG_INFINITY, f64::max)
        .max(u0 + 0.1);
    let v1 = rects
        .iter()
        .map(|r| r[3])
        .fold(f64::NEG_INFINITY, f64::max)
        .max(v0 + 0.1);
    let s = (WIDTH - 2.0 * MARGIN) / (u1 - u0);
    let height = (v1 - v0) * s + 2.0 * MARGIN + 30.0;
    let x = |u: f64| MARGIN + (u - u0) * s;
    let y = |v: f64| MARGIN + (v1 - v) * s;
    html! {
        svg xmlns="http://www.w3.org/2000/svg" class="elevation" width=(f1(WIDTH)) height=(f1(height))
            viewBox=(format!("0 0 {} {}", f1(WIDTH), f1(height))) {
            @for p in &view.pieces {
                @let r = p.wall_rect;
                g class=(format!("piece {}", p.class)) data-id=(p.id) data-guid=(p.guid) data-verdict=(p.class) {
                    title { (tooltip(p)) }
                    rect x=(f1(x(r[0]))) y=(f1(y(r[3]))) width=(f1((r[2] - r[0]) * s)) height=(f1((r[3] - r[1]) * s))
                        fill=(verdict::colour(p.class)) stroke="#222" stroke-width="1" {}
                    @if (r[2] - r[0]) * s > 40.0 && (r[3] - r[1]) * s > 10.0 {
                        text x=(f1(x((r[0] + r[2]) / 2.0))) y=(f1(y((r[1] + r[3]) / 2.0) + 4.0)) font-size="10" text-anchor="middle" { (p.role) }
                    } @else if (r[3] - r[1]) * s > 40.0 {
                        @let (cx, cy) = (x((r[0] + r[2]) / 2.0), y((r[1] + r[3]) / 2.0));
                        text x=(f1(cx)) y=(f1(cy)) font-size="10" text-anchor="middle"
                            transform=(format!("rotate(-90 {} {})", f1(cx), f1(cy))) { (p.role) }
                    }
                }
            }
            @for n in &view.nails {
                circle class=(if n.driven { "nail driven" } else { "nail failed" }) cx=(f1(x(n.u))) cy=(f1(y(n.v))) r="3"
                    fill=(if n.driven { "#1b5e20" } else { "#b71c1c" }) stroke="#fff" stroke-width="0.5" {
                    title { (n.label) }
                }
            }
            (scale_bar(MARGIN, height - 15.0, s))
        }
    }
}

/// The whole wall a panel belongs to, from the side: each panel a box along u (`this` filled),
/// each break a dashed line with its u, each site piece (a lapped cap across a joint) a bar
/// along the top. Panels carry `data-panel`, not `data-id`: they are not pieces.
pub(super) fn panel_strip(panels: &WallPanels, this: &str) -> Markup {
    let length = panels.panels.last().map_or(0.0, |p| p.u_end).max(0.1);
    let high = panels
        .panels
        .iter()
        .map(|p| p.height)
        .fold(0.5_f64, f64::max);
    let s = (WIDTH - 2.0 * MARGIN) / length;
    let (top, band) = (MARGIN, (high * s).min(120.0));
    let height = top + band + 2.0 * MARGIN;
    let x = |u: f64| MARGIN + u * s;
    html! {
        svg xmlns="http://www.w3.org/2000/svg" class="panel-strip" width=(f1(WIDTH)) height=(f1(height))
            viewBox=(format!("0 0 {} {}", f1(WIDTH), f1(height))) {
            @for p in &panels.panels {
                g class=(if p.id == this { "panel this" } else { "panel" }) data-panel=(p.id) {
                    title { (format!("{}: u {:.3} to {:.3} m, {:.3} m long, {:.1} kg", p.id, p.u_start, p.u_end, p.length(), p.mass)) }
                    rect x=(f1(x(p.u_start))) y=(f1(top)) width=(f1(p.length() * s)) height=(f1(band))
                        fill=(if p.id == this { "#bbdefb" } else { "#f5f5f5" }) stroke="#222" stroke-width="1" {}
                    text x=(f1(x((p.u_start + p.u_end) / 2.0))) y=(f1(top + band / 2.0 + 4.0)) font-size="11" text-anchor="middle" { (p.id) }
                }
            }
            @for b in &panels.breaks {
                line class="break" x1=(f1(x(b.u))) y1=(f1(top - 8.0)) x2=(f1(x(b.u))) y2=(f1(top + band + 8.0))
                    stroke="#c62828" stroke-width="2" stroke-dasharray="6 3" {
                    title { (b.reason) }
                }
                text x=(f1(x(b.u))) y=(f1(top + band + 22.0)) font-size="10" text-anchor="middle" { (format!("u = {:.3} m", b.u)) }
            }
            @for site in &panels.site_pieces {
                rect class="site-piece" x=(f1(x(site.u_start))) y=(f1(top - 6.0)) width=(f1((site.u_end - site.u_start) * s)) height="5"
                    fill="#ef6c00" {
                    title { (format!("{}: fixed on site across {}, u {:.3} to {:.3} m", site.id, site.laps.join(" and "), site.u_start, site.u_end)) }
                }
            }
        }
    }
}

/// The radius around the robot's base axis within which the grip TCP reaches straight down
/// at height `z` (cell frame), by the closed-form reach margin; `None` for robots without it.
pub fn reach_radius(cell: &Cell, z: f64) -> Option<f64> {
    let grip = *cell.tool.tcp("grip")?;
    let base = cell.robot_base.translation.vector;
    let down = UnitQuaternion::from_axis_angle(&Vector3::x_axis(), std::f64::consts::PI);
    let margin = |r: f64| {
        let pose = Isometry3::from_parts(Translation3::new(base.x + r, base.y, z), down);
        cell.robot.reach_margin(&cell.to_robot(&pose), &grip)
    };
    margin(0.0)?;
    // The farthest radius (1 cm steps, then halving) where the margin is not negative.
    let far = (0..1000)
        .rev()
        .map(|k| k as f64 * 0.01)
        .find(|r| margin(*r).is_some_and(|m| m >= 0.0))?;
    let (mut lo, mut hi) = (far, far + 0.01);
    for _ in 0..30 {
        let mid = (lo + hi) / 2.0;
        if margin(mid).is_some_and(|m| m >= 0.0) {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    Some(lo)
}

/// The cell from above, to scale: floor, conveyors with their direction, touch sensor, tool
/// table, robot base and its reach at the assembly surface, the wall's pieces by verdict.
pub(super) fn plan_view(cell: &Cell, view: &WallView, thickness: f64) -> Markup {
    let (fx, fy) = (cell.floor.size[0] / 2.0, cell.floor.size[1] / 2.0);
    let base = cell.robot_base.translation.vector;
    let reach = reach_radius(cell, cell.surface_height() + thickness);
    // The drawing covers the cell's equipment, the reach and the wall (not the whole floor).
    let mut extent: Vec<[f64; 2]> = view
        .pieces
        .iter()
        .flat_map(|p| p.plan_outline.iter().copied())
        .collect();
    let r = reach.unwrap_or(0.5).max(0.5);
    extent.extend([[base.x - r, base.y - r], [base.x + r, base.y + r]]);
    // On a track the base runs along the rail; its reach is a stadium around the rail.
    let rail: Option<[[f64; 2]; 2]> = cell.track.as_ref().map(|t| {
        t.travel.map(|s| {
            let b = t.base_at(s).translation.vector;
            [b.x, b.y]
        })
    });
    if let Some(ends) = rail {
        for e in ends {
            extent.extend([[e[0] - r, e[1] - r], [e[0] + r, e[1] + r]]);
        }
    }
    for c in [&cell.conveyor1, &cell.conveyor2] {
        for e in [c.upstream_end(), c.downstream_end()] {
            extent.push([e.x, e.y]);
        }
    }
    let tt = cell.tool_table.top_centre;
    extent.extend([
        [tt.x, tt.y],
        [
            cell.touch_sensor.pose.translation.x,
            cell.touch_sensor.pose.translation.y,
        ],
    ]);
    let pad = 0.3;
    let xmin = extent.iter().map(|p| p[0]).fold(f64::INFINITY, f64::min) - pad;
    let xmax = extent
        .iter()
        .map(|p| p[0])
        .fold(f64::NEG_INFINITY, f64::max)
        + pad;
    let ymin = extent.iter().map(|p| p[1]).fold(f64::INFINITY, f64::min) - pad;
    let ymax = extent
        .iter()
        .map(|p| p[1])
        .fold(f64::NEG_INFINITY, f64::max)
        + pad;
    // As wide as the page allows, no taller than PLAN_HEIGHT.
    let s = ((WIDTH - 2.0 * MARGIN) / (xmax - xmin)).min(PLAN_HEIGHT / (ymax - ymin));
    let height = (ymax - ymin) * s + 2.0 * MARGIN + 30.0;
    let x = |v: f64| MARGIN + (v - xmin) * s;
    let y = |v: f64| MARGIN + (ymax - v) * s;
    let points = |pts: &[[f64; 2]]| {
        pts.iter()
            .map(|p| format!("{},{}", f1(x(p[0])), f1(y(p[1]))))
            .collect::<Vec<_>>()
            .join(" ")
    };
    let boxed = |pose: &Isometry3<f64>, half: [f64; 2]| -> Vec<[f64; 2]> {
        [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)]
            .iter()
            .map(|(a, b)| {
                let q = pose * Point3::new(a * half[0], b * half[1], 0.0);
                [q.x, q.y]
            })
            .collect()
    };
    let t = cell.tool_table;
    let table = boxed(
        &Isometry3::translation(t.top_centre.x, t.top_centre.y, 0.0),
        [t.size[0] / 2.0, t.size[1] / 2.0],
    );
    html! {
        svg xmlns="http://www.w3.org/2000/svg" class="plan" width=(f1(WIDTH)) height=(f1(height))
            viewBox=(format!("0 0 {} {}", f1(WIDTH), f1(height))) {
            defs {
                marker id="arrow" viewBox="0 0 10 10" refX="9" refY="5" markerWidth="6" markerHeight="6" orient="auto-start-reverse" {
                    path d="M 0 0 L 10 5 L 0 10 z" fill="#333" {}
                }
            }
            rect class="floor" x=(f1(x(-fx))) y=(f1(y(fy))) width=(f1(2.0 * fx * s)) height=(f1(2.0 * fy * s)) fill="#eceff1" stroke="#90a4ae" {
                title { "floor" }
            }
            @for (name, c) in [("conveyor 1", &cell.conveyor1), ("conveyor 2", &cell.conveyor2)] {
                @let from = c.upstream_end();
                @let to = c.downstream_end();
                g class="conveyor" {
                    title { (format!("{name}: {:.2} m/s", c.speed)) }
                    polygon points=(points(&boxed(&c.pose, [c.length / 2.0, c.width / 2.0]))) fill="#455a64" stroke="#263238" {}
                    line x1=(f1(x(from.x))) y1=(f1(y(from.y))) x2=(f1(x(to.x))) y2=(f1(y(to.y))) stroke="#fff" stroke-width="2" marker-end="url(#arrow)" {}
                }
            }
            polygon class="sensor" points=(points(&boxed(&cell.touch_sensor.pose, [cell.touch_sensor.size[0] / 2.0, cell.touch_sensor.size[1] / 2.0]))) fill="#fbc02d" stroke="#333" {
                title { "touch sensor" }
            }
            polygon class="tool-table" points=(points(&table)) fill="#8d6e63" stroke="#333" {
                title { "tool table" }
            }
            @for p in &view.pieces {
                polygon class=(format!("piece {}", p.class)) data-id=(p.id) points=(points(&p.plan_outline))
                    fill=(verdict::colour(p.class)) stroke="#222" stroke-width="0.5" {
                    title { (tooltip(p)) }
                }
            }
            @if let Some(ends) = rail {
                line class="track" x1=(f1(x(ends[0][0]))) y1=(f1(y(ends[0][1]))) x2=(f1(x(ends[1][0]))) y2=(f1(y(ends[1][1]))) stroke="#6d4c41" stroke-width="6" stroke-linecap="round" {
                    title { (format!("linear track: the base travels {:.2} m", ((ends[1][0] - ends[0][0]).powi(2) + (ends[1][1] - ends[0][1]).powi(2)).sqrt())) }
                }
                @if let Some(r) = reach {
                    polygon class="reach" points=(points(&stadium(ends, r))) fill="none" stroke="#1565c0" stroke-width="2" stroke-dasharray="8 4" {
                        title { (format!("reach of the grip straight down at the assembly surface, {r:.3} m, from anywhere on the track")) }
                    }
                }
            }
            @if let (Some(r), None) = (reach, rail) {
                circle class="reach" cx=(f1(x(base.x))) cy=(f1(y(base.y))) r=(f1(r * s)) fill="none" stroke="#1565c0" stroke-width="2" stroke-dasharray="8 4" {
                    title { (format!("reach of the grip straight down at the assembly surface: {r:.3} m")) }
                }
            }
            circle class="robot-base" cx=(f1(x(base.x))) cy=(f1(y(base.y))) r=(f1(0.3 * s)) fill="#ef6c00" stroke="#333" {
                title { "robot base" }
            }
            (scale_bar(MARGIN, height - 15.0, s))
        }
    }
}

/// The outline of every point within `r` of the segment between `ends` (x/y), as a polygon:
/// a half circle around each end joined by straight sides.
fn stadium(ends: [[f64; 2]; 2], r: f64) -> Vec<[f64; 2]> {
    let [a, b] = ends;
    let heading = (b[1] - a[1]).atan2(b[0] - a[0]);
    let half = |centre: [f64; 2], from: f64| {
        (0..=24).map(move |k| {
            let angle = from + std::f64::consts::PI * k as f64 / 24.0;
            [centre[0] + r * angle.cos(), centre[1] + r * angle.sin()]
        })
    };
    let quarter = std::f64::consts::FRAC_PI_2;
    half(b, heading - quarter)
        .chain(half(a, heading + quarter))
        .collect()
}

/// The operations of a wall's run on a time axis: a row per element, a bar per operation
/// (feed = waiting for the piece, pick = approach and grip, move = transfer, place, retract,
/// nail), failures marked with a cross where the element's work ended. `data-left` and
/// `data-px-per-s` give the time axis (x = left + t × px per s) to the page's 3D view.
pub(super) fn timeline(view: &WallView) -> Markup {
    const ROW: f64 = 14.0;
    const LEFT: f64 = 150.0;
    let end = view.record.nailing_end.max(1e-3);
    let s = (WIDTH - LEFT - MARGIN) / end;
    let height = view.pieces.len() as f64 * ROW + 50.0;
    let x = |t: f64| LEFT + t * s;
    let ticks: Vec<f64> = {
        let step = [1.0, 5.0, 10.0, 30.0, 60.0, 120.0, 300.0, 600.0]
            .into_iter()
            .find(|st| end / st <= 12.0)
            .unwrap_or(1200.0);
        (0..=((end / step) as usize))
            .map(|k| k as f64 * step)
            .collect()
    };
    html! {
        svg xmlns="http://www.w3.org/2000/svg" class="timeline" width=(f1(WIDTH)) height=(f1(height))
            viewBox=(format!("0 0 {} {}", f1(WIDTH), f1(height))) data-left=(f1(LEFT)) data-px-per-s=(format!("{s:.6}")) {
            @for t in &ticks {
                line x1=(f1(x(*t))) y1="0" x2=(f1(x(*t))) y2=(f1(height - 30.0)) stroke="#ddd" {}
                text x=(f1(x(*t))) y=(f1(height - 16.0)) font-size="10" text-anchor="middle" { (format!("{t:.0} s")) }
            }
            line class="framing-end" x1=(f1(x(view.record.framing_end))) y1="0" x2=(f1(x(view.record.framing_end))) y2=(f1(height - 30.0)) stroke="#1565c0" stroke-dasharray="4 2" {
                title { (format!("framing ends at {:.1} s", view.record.framing_end)) }
            }
            @for (i, p) in view.pieces.iter().enumerate() {
                @let y = i as f64 * ROW + 4.0;
                g class="row" data-id=(p.id) {
                    text x=(f1(LEFT - 4.0)) y=(f1(y + ROW - 4.0)) font-size="10" text-anchor="end" { (format!("{} {}", i + 1, p.role)) }
                    @for o in view.record.operations.iter().filter(|o| o.piece == p.id) {
                        rect class=(format!("op {}", o.op)) x=(f1(x(o.start))) y=(f1(y + 1.0)) width=(f1(((o.end - o.start) * s).max(0.5))) height=(f1(ROW - 3.0)) {
                            title { (format!("{} of {} from {:.2} s to {:.2} s", o.op, p.id, o.start, o.end)) }
                        }
                    }
                    @if p.class == "framing-failed" || p.class == "not-attempted" {
                        @let t = view.record.operations.iter().filter(|o| o.piece == p.id && o.op != Op::Nail).map(|o| o.end).fold(0.0, f64::max);
                        text class="failure" x=(f1(x(t) + 2.0)) y=(f1(y + ROW - 3.0)) font-size="12" fill="#c62828" {
                            "✕" title { (p.reason) }
                        }
                    }
                }
            }
        }
    }
}
