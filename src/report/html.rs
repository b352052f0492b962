//! The report a person reads: `simulate --report DIR` writes `index.html` (one self-contained
//! page: inline CSS, SVG and script, no network, no dates), `scene.glb` (or one
//! `scene-NNN.glb` per wall when there are several) and `simulate.json`. Each wall's section
//! shows its scene in a 3D view ([`super::viewer`]: the scene embedded in the page, drawn by
//! the viewer's script). With more than [`WALLS_PER_PAGE`] walls the index keeps the table
//! and the root causes and each wall gets its own page `wall-NNN.html`, with its view.
//!
//! Every name and id from the model goes through maud, which escapes text and attribute
//! values by default; none is written into a script.

use super::glb;
use super::markup_text::replace_forbidden;
use super::simulate::SimReport;
use super::svg;
use super::verdict;
use super::viewer;
use super::wall_view::WallView;
use crate::cell::Cell;
use crate::ifc::Model;
use crate::sim::Simulation;
use maud::{DOCTYPE, Markup, PreEscaped, html};
use rayon::prelude::*;
use std::path::{Path, PathBuf};

/// Walls drawn on the index page itself; more get a page each.
pub const WALLS_PER_PAGE: usize = 8;

/// Everything one report needs.
pub struct ReportInput<'a> {
    pub model: &'a Model,
    /// The model as named on the command line.
    pub model_name: &'a str,
    pub cell: &'a Cell,
    pub sim: &'a Simulation,
    pub report: &'a SimReport,
}

/// The environment variable with which the CLI bounds a report's size in bytes (all its files are built in
/// memory before the folder is swapped in, so this bounds the memory the report takes too).
pub const ENV_MAX_REPORT_BYTES: &str = "FRAMEWRIGHT_MAX_REPORT_BYTES";
/// The default bound: 2 GiB (a 150-wall building's report was about 200 MB before the pages
/// embedded their walls' scenes, which adds about 0.9 times the scenes' size).
pub const DEFAULT_MAX_REPORT_BYTES: u64 = 2 << 30;

/// The files of a report, by name in the report folder, in writing order.
pub fn report_files(input: &ReportInput) -> Vec<(String, Vec<u8>)> {
    // Without a bound nothing is refused.
    report_files_within(input, u64::MAX).unwrap_or_default()
}

/// The files of a report, refused as soon as they add up to more than `max_bytes`.
pub fn report_files_within(
    input: &ReportInput,
    max_bytes: u64,
) -> std::io::Result<Vec<(String, Vec<u8>)>> {
    let mut total = 0u64;
    let mut check = |name: &str, bytes: &[u8]| -> std::io::Result<()> {
        total = total.saturating_add(bytes.len() as u64);
        if total > max_bytes {
            return Err(std::io::Error::other(format!(
                "the report grows past its bound of {max_bytes} bytes at {name} \
                 ({ENV_MAX_REPORT_BYTES}); raise the bound (e.g. {ENV_MAX_REPORT_BYTES}={}) \
                 or report fewer walls with --wall",
                max_bytes.saturating_mul(2)
            )));
        }
        Ok(())
    };
    // One view per wall the cell built: a wall that fits, or a panel of a split wall.
    let model = input.sim.model(input.model);
    let walls: Vec<WallView> = input
        .sim
        .records
        .iter()
        .filter_map(|r| input.sim.plan.walls.iter().find(|w| w.key == r.wall))
        .filter_map(|w| WallView::new(input.sim, input.report, Some(model), &w.id))
        .collect();
    let bid =
        super::bid::Bid::new(input.sim, input.report, input.cell).map_err(std::io::Error::other)?;
    let split = walls.len() > WALLS_PER_PAGE;
    let mut files = Vec::new();
    let scene_name = |i: usize| {
        if walls.len() == 1 {
            "scene.glb".to_string()
        } else {
            format!("scene-{:03}.glb", i + 1)
        }
    };
    let page_name = |i: usize| format!("wall-{:03}.html", i + 1);
    // The walls' scenes are independent: built (and embedded for the pages) in parallel, kept
    // in wall order.
    let (cell, scene, records, report) = (
        input.cell,
        &input.sim.scene,
        input.sim.records.as_slice(),
        input.report,
    );
    let wall_ids: Vec<&str> = walls.iter().map(|w| w.record.wall.as_str()).collect();
    let (scenes, mut embedded): (Vec<Option<Vec<u8>>>, Vec<Option<String>>) = wall_ids
        .par_iter()
        .map(|wall| {
            let glb = glb::scene_wall_glb(cell, scene, records, report, wall);
            let text = glb.as_deref().map(viewer::embed);
            (glb, text)
        })
        .unzip();
    let index = page(
        input,
        "Simulation report",
        !split && embedded.iter().any(Option::is_some),
        html! {
            (header(input))
            h2 { "Summary" }
            (super::bid_html::summary_table(&[bid]))
            (results_table(&walls, split.then_some(&page_name), &scene_name))
            @if split {
                @for w in &walls { (causes(w)) }
            } @else {
                @for (i, w) in walls.iter().enumerate() { (wall_section(input, w, &scene_name(i), embedded[i].as_deref())) }
            }
            (validation(input.report))
        },
    );
    let index = replace_forbidden(index.into_string()).into_bytes();
    check("index.html", &index)?;
    files.push(("index.html".to_string(), index));
    if split {
        for (i, w) in walls.iter().enumerate() {
            // Each page embeds its own wall's scene, dropped once the page is built.
            let view = embedded[i].take();
            let body = html! {
                p { a href="index.html" { "← all walls" } }
                (header(input))
                (wall_section(input, w, &scene_name(i), view.as_deref()))
            };
            let title = format!("{} — simulation report", w.row.name);
            let bytes = replace_forbidden(page(input, &title, view.is_some(), body).into_string())
                .into_bytes();
            check(&page_name(i), &bytes)?;
            files.push((page_name(i), bytes));
        }
    }
    drop(embedded);
    for (i, bytes) in scenes.into_iter().enumerate() {
        if let Some(bytes) = bytes {
            check(&scene_name(i), &bytes)?;
            files.push((scene_name(i), bytes));
        }
    }
    let mut json = Vec::new();
    if input.report.write_json(&mut json).is_ok() {
        check("simulate.json", &json)?;
        files.push(("simulate.json".to_string(), json));
    }
    Ok(files)
}

/// A page; with the viewer's script at the end when it shows a wall's 3D view (`views`).
fn page(input: &ReportInput, title: &str, views: bool, body: Markup) -> Markup {
    html! {
        (DOCTYPE)
        html lang="en" {
            head {
                meta charset="utf-8";
                title { (title) " — " (input.model_name) }
                style { (PreEscaped(super::style::STYLE)) }
            }
            body {
                (body)
                @if views { (viewer::script()) }
            }
        }
    }
}

fn header(input: &ReportInput) -> Markup {
    let m = input.model;
    let robot = &input.cell.robot;
    html! {
        h1 { "Simulation of " (input.model_name) }
        table class="inputs" {
            tr { th { "model" } td { (input.model_name) } }
            tr { th { "schema" } td { (m.schema_identifier) } }
            tr { th { "length unit" } td { (m.length_unit.name) " (" (m.length_unit.metres_per_unit) " m)" } }
            tr { th { "cell" } td { (input.cell.name) } }
            tr { th { "robot" } td { (robot.name) } }
            tr { th { "tool" } td { (input.cell.tool.name) } }
            tr { th { "simulated" } td { (format!("{:.1} s in {} steps of {:.2} ms", input.report.sim.simulated_s, input.report.sim.steps, input.report.sim.dt * 1000.0)) } }
        }
        p class="legend" {
            @for c in verdict::CLASSES {
                span style=(format!("background: {}", verdict::colour(c))) { (c.replace('-', " ")) }
            }
        }
    }
}

fn results_table(
    walls: &[WallView],
    pages: Option<&dyn Fn(usize) -> String>,
    scenes: &dyn Fn(usize) -> String,
) -> Markup {
    html! {
        h2 { "Results" }
        table class="results" {
            tr {
                th { "wall" } th { "material feeding" } th { "framing" } th { "time" } th { "failed component" }
                th { "nailing" } th { "time" } th { "failed component" } th { "pieces placed" } th { "nails driven" }
                th { "smallest reach margin" } th { "simulated time" } th { "3D" }
            }
            @for (i, w) in walls.iter().enumerate() {
                @let r = w.row;
                @let (placed, pieces) = w.placed();
                @let (driven, nails) = w.driven();
                tr data-wall=(w.id) {
                    td {
                        @if let Some(page) = pages { a href=(page(i)) { (r.name) " (" (w.id) ")" } }
                        @else { a href=(format!("#wall-{}", i + 1)) { (r.name) " (" (w.id) ")" } }
                    }
                    td { (r.material_feeding) }
                    td { (r.framing.status) } td class="num" { (format!("{:.1} s", r.framing.time_s)) } td { (r.framing.failed_component) }
                    td { (r.nailing.status) } td class="num" { (format!("{:.1} s", r.nailing.time_s)) } td { (r.nailing.failed_component) }
                    td class="num" { (placed) "/" (pieces) }
                    td class="num" { (driven) "/" (nails) }
                    td class="num" { @if let Some(m) = w.min_margin { (format!("{:.0} mm", m * 1000.0)) } @else { "–" } }
                    td class="num" { (format!("{:.1} s", w.record.nailing_end)) }
                    td { a href=(scenes(i)) { "scene" } }
                }
            }
        }
    }
}

fn causes(w: &WallView) -> Markup {
    html! {
        div class="causes" data-wall=(w.id) {
            h3 { "Root causes in " (w.row.name) }
            @if w.causes.is_empty() { p { "None: every piece placed and every nail driven." } }
            ul {
                @for c in &w.causes {
                    li data-id=(c.piece) {
                        strong { (c.component) } " (" (c.stage) ") " (c.piece) ": " (c.message)
                        @if !c.consequences.is_empty() {
                            details {
                                summary { "and " (c.consequences.len()) (if c.consequences.len() == 1 { " consequence" } else { " consequences" }) }
                                ul { @for q in &c.consequences { li { (q.message) } } }
                            }
                        }
                    }
                }
            }
        }
    }
}

/// A wall's section; with its 3D view when its scene is given (`view`, embedded).
fn wall_section(input: &ReportInput, w: &WallView, scene: &str, view: Option<&str>) -> Markup {
    let index = input
        .sim
        .records
        .iter()
        .position(|r| r.wall == w.record.wall)
        .unwrap_or(0);
    let thickness = input
        .sim
        .plan
        .walls
        .iter()
        .find(|p| p.id == w.id)
        .map_or(0.09, |p| p.thickness);
    let contacts: Vec<_> = input
        .report
        .contacts
        .iter()
        .filter(|c| c.panel_id == w.row.panel_id)
        .collect();
    html! {
        section class="wall" id=(format!("wall-{}", index + 1)) data-wall=(w.id) {
            h2 { (w.row.name) " (" (w.id) ")" }
            p { "3D scene of the run: " a href=(scene) { (scene) } " (glTF 2.0; opens in any glTF viewer)." }
            h3 { "Elevation" }
            p { "Wall frame: u along the wall, v up; hover a piece for its IFC name, entity and reason." }
            (svg::elevation(w))
            (panels(w))
            (causes(w))
            h3 { "The run" }
            @if let Some(v) = view {
                p { "The cell, the robot (blue) and the lumber coloured by verdict; a piece not in the cell at the time shown is drawn faint at its target. Drag to turn, wheel to zoom, click a piece for its verdict and why; the timeline below follows the view (click it to move there)." }
                (viewer::view(v, scene))
            }
            p { (format!("Framing {:.1} s, nailing {:.1} s.", w.record.framing_time(), w.record.nailing_time())) }
            (svg::timeline(w))
            h3 { "Cell from above" }
            p { "The wall laid on the assembly area; the dashed circle is the grip's reach straight down at the assembly surface." }
            (svg::plan_view(input.cell, w, thickness))
            h3 { "Contacts" }
            @if contacts.is_empty() { p { "The robot touched nothing it should not have." } }
            @else {
                table class="contacts" {
                    tr { th { "t (s)" } th { "body" } th { "touched" } th { "depth (mm)" } th { "during" } th { "of" } }
                    @for c in contacts {
                        tr { td class="num" { (format!("{:.2}", c.t)) } td { (c.body_a) } td { (c.body_b) } td class="num" { (format!("{:.1}", c.depth_mm)) } td { (c.op) } td { (c.element) } }
                    }
                }
            }
        }
    }
}

/// Where a panel of a split wall lies in its wall, and the wall's other panels.
fn panels(w: &WallView) -> Markup {
    let split = w.panels;
    html! {
        @if let Some(of) = w.panel {
            h3 { "Panel" }
            p { (format!("Panel {} of {} of {} ({}): the wall is longer or heavier than the cell builds, so it is built as {} panels (rules/panels.dl; framewright why MODEL {} explains this panel). This section frames and nails {} on its own; its cut plate segments (PLATE~k) and added end studs (STUD~endK) are pieces like any other.", of.index, split.panels.len(), of.wall_name, of.wall_id, split.panels.len(), of.panel_id, of.panel_id)) }
            (svg::panel_strip(split, &of.panel_id))
            p class="legend" { (format!("The whole of {} along its length: this panel shaded, breaks dashed with their position u from the wall's start, stretches of lapped plates fixed on site in orange.", of.wall_name)) }
            table class="panels" {
                tr { th { "panel" } th { "u from (m)" } th { "u to (m)" } th { "length (m)" } th { "height (m)" } th { "mass (kg)" } th { "members" } th { "plate segments" } th { "added end studs" } th { "exceeds" } }
                @for p in &split.panels {
                    tr class=[(p.id == of.panel_id).then_some("this")] {
                        td { (p.id) }
                        td class="num" { (format!("{:.3}", p.u_start)) }
                        td class="num" { (format!("{:.3}", p.u_end)) }
                        td class="num" { (format!("{:.3}", p.length())) }
                        td class="num" { (format!("{:.3}", p.height)) }
                        td class="num" { (format!("{:.1}", p.mass)) }
                        td class="num" { (p.member_ids.len()) }
                        td class="num" { (p.cut_pieces.len()) }
                        td class="num" { (p.added_pieces.len()) }
                        td { (if p.exceeds.is_empty() { "-".to_string() } else { p.exceeds.join(", ") }) }
                    }
                }
            }
            @if !split.site_pieces.is_empty() {
                p { (format!("Fixed on site, in no panel: {} stretches of lapped plates across the joints (a cap plate is held back from each break, so its joints lie clear of the top plate's): {}.", split.site_pieces.len(), split.site_pieces.iter().map(|s| format!("{} (u {:.3} to {:.3} m, over {})", s.id, s.u_start, s.u_end, s.laps.join(" and "))).collect::<Vec<_>>().join("; "))) }
            }
            @for note in &split.notes { p class="note" { (note) } }
        }
    }
}

fn validation(report: &SimReport) -> Markup {
    let v = &report.nailing_validation;
    html! {
        h2 { "Nailing validation" }
        p { (format!("{} of {} nails driven and checked against the as-built pieces; largest error {:.2} mm ({:.2} %); ", v.checked, v.planned, v.max_error_mm, v.max_error_pct))
            (if v.all_inside_members { "every nail runs into its member." } else { "some nails miss their member." }) }
        table class="nails" {
            tr { th { "wall" } th { "plate" } th { "member" } th { "k" } th { "planned u, v, w (m)" } th { "as built (m)" } th { "error (mm)" } th { "lean (°)" } th { "status" } }
            @for t in &v.targets {
                tr {
                    td { (t.wall_id) } td { (t.plate) } td { (t.member) } td class="num" { (t.k) }
                    td class="num" { (format!("{:.4}, {:.4}, {:.4}", t.planned[0], t.planned[1], t.planned[2])) }
                    td class="num" { @if let Some(b) = t.as_built { (format!("{:.4}, {:.4}, {:.4}", b[0], b[1], b[2])) } @else { "–" } }
                    td class="num" { @if let Some(e) = t.error_mm { (format!("{e:.2}")) } @else { "–" } }
                    td class="num" { @if let Some(l) = t.lean_deg { (format!("{l:.0}")) } @else { "–" } }
                    td { (t.status) }
                }
            }
        }
    }
}

/// Swaps two folders in one step, so a reader of `b` sees the old report or the new one,
/// never none (Linux's renameat2 with RENAME_EXCHANGE).
#[cfg(target_os = "linux")]
fn exchange(a: &Path, b: &Path) -> std::io::Result<()> {
    use rustix::fs::{CWD, RenameFlags, renameat_with};
    renameat_with(CWD, a, CWD, b, RenameFlags::EXCHANGE).map_err(std::io::Error::from)
}

#[cfg(not(target_os = "linux"))]
fn exchange(_: &Path, _: &Path) -> std::io::Result<()> {
    Err(std::io::Error::from(std::io::ErrorKind::Unsupported))
}

/// Removes the staging folders (`.NAME.PID.tmp`, `.NAME.PID.old`) that runs killed while
/// writing this report left beside it: those of processes no longer running. Only where the
/// system lists its processes (`/proc`); a folder whose process may still run is kept.
fn remove_dead_staging(parent: &Path, name: &str) {
    let processes = Path::new("/proc");
    if !processes.join("self").exists() {
        return;
    }
    let Ok(entries) = std::fs::read_dir(parent) else {
        return;
    };
    let prefix = format!(".{name}.");
    for entry in entries.flatten() {
        let file_name = entry.file_name().to_string_lossy().into_owned();
        let Some(rest) = file_name.strip_prefix(&prefix) else {
            continue;
        };
        let Some(pid) = rest
            .strip_suffix(".tmp")
            .or_else(|| rest.strip_suffix(".old"))
            .and_then(|pid| pid.parse::<u32>().ok())
        else {
            continue;
        };
        let dead = pid != std::process::id() && !processes.join(pid.to_string()).exists();
        if dead && entry.file_type().is_ok_and(|t| t.is_dir()) {
            let _ = std::fs::remove_dir_all(entry.path());
        }
    }
}

/// Writes the report's files into `dir`: built in a fresh temporary folder beside it, then
/// swapped into place (an existing `dir` is replaced only once the new one is complete). Its
/// files may add up to `max_bytes` (`DEFAULT_MAX_REPORT_BYTES` by default).
pub fn write_report(dir: &Path, input: &ReportInput, max_bytes: u64) -> std::io::Result<()> {
    let files = report_files_within(input, max_bytes)?;
    write_folder(dir, &files)
}

/// Writes `files` (name, bytes) as the folder `dir`: built in a fresh temporary folder beside
/// it, then swapped into place. An existing `dir` is replaced only when it holds an earlier
/// report (an `index.html`) or nothing.
pub fn write_folder(dir: &Path, files: &[(String, Vec<u8>)]) -> std::io::Result<()> {
    let parent = match dir.parent() {
        Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
        _ => PathBuf::from("."),
    };
    let name = dir
        .file_name()
        .ok_or_else(|| std::io::Error::other("the report path names no folder"))?
        .to_string_lossy()
        .into_owned();
    remove_dead_staging(&parent, &name);
    let tmp = parent.join(format!(".{name}.{}.tmp", std::process::id()));
    let old = parent.join(format!(".{name}.{}.old", std::process::id()));
    let _ = std::fs::remove_dir_all(&tmp);
    let result = (|| {
        std::fs::create_dir(&tmp)?;
        for (file, bytes) in files {
            // Synced before the folder is renamed into place, so a crash cannot expose empty files.
            let mut f = std::fs::File::create(tmp.join(file))?;
            std::io::Write::write_all(&mut f, bytes)?;
            f.sync_all()?;
        }
        if dir.exists() {
            // Replace only an earlier report (or an empty folder), never other files.
            let empty = std::fs::read_dir(dir)?.next().is_none();
            if !empty && !dir.join("index.html").exists() {
                return Err(std::io::Error::other(
                    "the folder exists and holds no earlier report; name a new folder",
                ));
            }
            if exchange(&tmp, dir).is_ok() {
                // `dir` is the new report at once; `tmp` now holds the earlier one.
                return std::fs::remove_dir_all(&tmp);
            }
            // Where the filesystem cannot exchange two folders, `dir` is briefly absent.
            std::fs::rename(dir, &old)?;
            std::fs::rename(&tmp, dir)?;
            std::fs::remove_dir_all(&old)
        } else {
            std::fs::rename(&tmp, dir)
        }
    })();
    if result.is_err() {
        let _ = std::fs::remove_dir_all(&tmp);
    }
    result
}
