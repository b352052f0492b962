//! The bid in a page: the cells' figures side by side, a chart of the time each panel took on
//! each cell, and each cell's failures by cause and root causes. `compare --report DIR` writes
//! it as `index.html` (self-contained: inline CSS and SVG, no script); a single cell's report
//! opens with the same table in one column.

use super::bid::{Bid, duration, rows};
use super::causes::root_causes;
use super::markup_text::replace_forbidden;
use super::simulate::SimReport;
use maud::{DOCTYPE, Markup, PreEscaped, html};
use std::collections::{BTreeMap, BTreeSet};

/// Colours of the cells' bars, in cell order (repeating after six).
const CELL_COLOURS: [&str; 6] = [
    "#1e88e5", "#43a047", "#8e24aa", "#f4511e", "#00897b", "#6d4c41",
];
/// Root causes listed per cell before the rest are only counted.
const CAUSES_LISTED: usize = 40;
/// Ids shown per failure class before the rest are only counted.
const IDS_LISTED: usize = 30;

fn colour(i: usize) -> &'static str {
    CELL_COLOURS[i % CELL_COLOURS.len()]
}

/// The figures, one column per cell.
pub fn summary_table(bids: &[Bid]) -> Markup {
    let rows = rows(bids);
    html! {
        table class="bid" {
            @for (label, values) in rows.iter().take(1) {
                tr { th { (label) } @for (i, v) in values.iter().enumerate() { th style=(format!("border-bottom: 4px solid {}", colour(i))) { (v) } } }
            }
            @for (label, values) in rows.iter().skip(1) {
                tr { th { (label) } @for v in values { td class="num" { (v) } } }
            }
        }
        p class="note" { "Metres of wall per hour count only the panels built whole (every piece framed, every nail driven on target) against the time spent on them; panels are built one after another and the time to change panels is not simulated." }
    }
}

/// A horizontal bar per panel and cell: framing time dark, nailing time light; panels in the
/// order the first cell that has them builds them.
pub fn panel_chart(bids: &[Bid]) -> Markup {
    let mut order: Vec<String> = Vec::new();
    let mut seen = BTreeSet::new();
    // Walls in first-seen order; within a wall, panels by their number.
    let mut by_wall: BTreeMap<usize, BTreeSet<(usize, String)>> = BTreeMap::new();
    let mut wall_rank: BTreeMap<&str, usize> = BTreeMap::new();
    for b in bids {
        for (k, p) in b.per_panel.iter().enumerate() {
            let next = wall_rank.len();
            let rank = *wall_rank.entry(p.wall_id.as_str()).or_insert(next);
            if seen.insert(p.panel_id.clone()) {
                let number = p
                    .panel_id
                    .rsplit_once("-P")
                    .and_then(|(_, n)| n.parse().ok())
                    .unwrap_or(k);
                by_wall
                    .entry(rank)
                    .or_default()
                    .insert((number, p.panel_id.clone()));
            }
        }
    }
    for panels in by_wall.values() {
        order.extend(panels.iter().map(|(_, id)| id.clone()));
    }
    let longest = bids
        .iter()
        .flat_map(|b| b.per_panel.iter().map(|p| p.framing_s + p.nailing_s))
        .fold(0.0f64, f64::max)
        .max(1.0);
    // Labels of up to LABEL_CHARS characters (longer ids keep their end, where the panel's
    // number is), at up to 7.5 px a character (ids are mostly capitals and digits, wider than
    // the average character at the chart's font size).
    const LABEL_CHARS: usize = 28;
    let label = |id: &str| {
        let n = id.chars().count();
        if n <= LABEL_CHARS {
            id.to_string()
        } else {
            format!(
                "…{}",
                id.chars().skip(n - LABEL_CHARS + 1).collect::<String>()
            )
        }
    };
    let widest = order
        .iter()
        .map(|id| label(id).chars().count())
        .max()
        .unwrap_or(4);
    let (label_w, bar_w, bar_h, gap) = (12.0 + 7.5 * widest as f64, 560.0, 9.0, 6.0);
    let group_h = bar_h * bids.len() as f64 + gap;
    let height = 24.0 + group_h * order.len() as f64 + 24.0;
    let x = |s: f64| label_w + s / longest * bar_w;
    let ticks: Vec<f64> = {
        let step = nice_step(longest / 5.0);
        (0..=((longest / step).floor() as usize))
            .map(|i| i as f64 * step)
            .collect()
    };
    html! {
        svg xmlns="http://www.w3.org/2000/svg" class="panel-chart" width=(label_w + bar_w + 60.0) height=(height) {
            @for t in &ticks {
                line x1=(x(*t)) x2=(x(*t)) y1="18" y2=(height - 20.0) stroke="#ddd" {}
                text x=(x(*t)) y=(height - 6.0) font-size="10" text-anchor="middle" { (duration(*t)) }
            }
            @for (row, id) in order.iter().enumerate() {
                @let y0 = 24.0 + group_h * row as f64;
                text x=(label_w - 6.0) y=(y0 + group_h / 2.0) font-size="10" text-anchor="end" { title { (id) } (label(id)) }
                @for (i, b) in bids.iter().enumerate() {
                    @if let Some(p) = b.per_panel.iter().find(|p| &p.panel_id == id) {
                        @let y = y0 + bar_h * i as f64;
                        g class="bar" data-cell=(b.cell) data-panel=(p.panel_id) {
                            title { (format!("{} on {}: framing {}, nailing {}; {} of {} pieces, {} of {} nails", p.panel_id, b.cell, duration(p.framing_s), duration(p.nailing_s), p.framed, p.pieces, p.driven, p.nails)) }
                            rect x=(x(0.0)) y=(y) width=(x(p.framing_s) - x(0.0)) height=(bar_h - 1.0) fill=(colour(i)) {}
                            rect x=(x(p.framing_s)) y=(y) width=(x(p.framing_s + p.nailing_s) - x(p.framing_s)) height=(bar_h - 1.0) fill=(colour(i)) fill-opacity="0.4" {}
                            @if !p.complete {
                                text x=(x(p.framing_s + p.nailing_s) + 3.0) y=(y + bar_h - 2.0) font-size="9" fill="#c62828" { "partial" }
                            }
                        }
                    }
                }
            }
        }
        p class="legend" {
            @for (i, b) in bids.iter().enumerate() {
                span style=(format!("background: {}; color: #fff", colour(i))) { (b.cell) }
            }
            " Dark: framing, light: nailing; “partial”: a panel not built whole."
        }
    }
}

/// A round tick step near `raw` seconds: 1, 2 or 5 times a power of ten below a minute, whole
/// minutes (1, 2, 5, 10, 15, 30) below an hour, then whole hours.
fn nice_step(raw: f64) -> f64 {
    const STEPS: [f64; 12] = [
        60.0, 120.0, 300.0, 600.0, 900.0, 1800.0, 3600.0, 7200.0, 18000.0, 36000.0, 72000.0,
        180000.0,
    ];
    let raw = raw.max(1e-3);
    if raw > 30.0 {
        return STEPS.into_iter().find(|s| *s >= raw).unwrap_or(raw.ceil());
    }
    let power = 10f64.powf(raw.log10().floor());
    [1.0, 2.0, 5.0, 10.0]
        .into_iter()
        .map(|m| m * power)
        .find(|s| *s >= raw)
        .unwrap_or(10.0 * power)
}

/// One cell's failures by cause (with the ids) and its root causes.
fn cell_section(index: usize, bid: &Bid, report: &SimReport) -> Markup {
    let mut causes = Vec::new();
    for w in &report.walls {
        for c in root_causes(report, &w.wall_id) {
            causes.push((w.name.clone(), c));
        }
    }
    html! {
        section class="cell" data-cell=(bid.cell) {
            h2 style=(format!("border-left: 8px solid {}; padding-left: 6px", colour(index))) { (bid.cell) ": " (bid.robot_text()) ", " (bid.tool) }
            @for (what, tally) in [("Pieces", &bid.pieces), ("Nails", &bid.nails)] {
                @if tally.failed == 0 {
                    p { (what) ": all " (tally.planned) " done." }
                } @else {
                    p { (what) ": " (tally.failed) " of " (tally.planned) " failed." }
                    ul class="by-cause" {
                        @for c in &tally.by_cause {
                            li data-cause=(format!("{:?}", c.cause)) {
                                details {
                                    summary { strong { (c.label) } ": " (c.count) }
                                    (c.ids.iter().take(IDS_LISTED).cloned().collect::<Vec<_>>().join(", "))
                                    @if c.ids.len() > IDS_LISTED { (format!(" and {} more", c.ids.len() - IDS_LISTED)) }
                                }
                            }
                        }
                    }
                }
            }
            @if !causes.is_empty() {
                h3 { "Root causes" }
                ul class="causes" {
                    @for (wall, c) in causes.iter().take(CAUSES_LISTED) {
                        li data-id=(c.piece) {
                            (wall) ": " strong { (c.component) } " (" (c.stage) ") " (c.piece) ": " (c.message)
                            @if !c.consequences.is_empty() { (format!(" — and {} consequence{}", c.consequences.len(), if c.consequences.len() == 1 { "" } else { "s" })) }
                        }
                    }
                }
                @if causes.len() > CAUSES_LISTED {
                    p { (format!("and {} more root causes (framewright simulate --cell {} --report DIR lists them all).", causes.len() - CAUSES_LISTED, bid.cell)) }
                }
            }
        }
    }
}

/// The whole comparison page.
pub fn compare_page(model_name: &str, bids: &[Bid], reports: &[&SimReport]) -> String {
    let page = html! {
        (DOCTYPE)
        html lang="en" {
            head {
                meta charset="utf-8";
                title { "Cells compared — " (model_name) }
                style { (PreEscaped(super::style::STYLE)) "table.bid th { white-space: nowrap; }" }
            }
            body {
                h1 { "Cells compared on " (model_name) }
                p { "Each cell simulated the model on its own (framewright simulate --cell C gives the same figures)." }
                h2 { "Summary" }
                (summary_table(bids))
                h2 { "Time per panel" }
                (panel_chart(bids))
                @for (i, (b, r)) in bids.iter().zip(reports).enumerate() { (cell_section(i, b, r)) }
            }
        }
    };
    replace_forbidden(page.into_string())
}
