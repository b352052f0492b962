//! Regeneration after a design edit, measured in one run on the 3-storey model
//! (`../shared/ifc-testcases/g_scale_3storey.ifc`, skipped when absent):
//!
//! 1. one interior stud moved 20 mm along its wall; `plan` of the edited model (read, facts,
//!    placement search, rules, plan) without the cache, and through a plan cache filled
//!    from the original model;
//! 2. the full simulation, filling an empty cache (what a first `simulate` costs);
//! 3. the edited model simulated again through the cache;
//! 4. the edited model simulated without the cache: its report must equal the regenerated
//!    one byte for byte (apart from the cache counts).
//!
//! Run: `cargo bench --bench regenerate` (about three full simulations; run it alone;
//! `-- --plan-only` for the plan rows alone).
//! The full simulation is not repeated: this is a bench command, not a criterion sample.

use framewright::cache::Cache;
use framewright::cell::Cell;
use framewright::frame::{RuleEngine, RuleLimits, cell_facts, model_facts};
use framewright::geom::ContactOptions;
use framewright::ifc::Model;
use framewright::pipeline::Run;
use framewright::report::simulate::SimReport;
use framewright::sim::SimOptions;
use std::collections::BTreeMap;
use std::path::Path;
use std::time::Instant;

fn report_json(sim: &framewright::sim::Simulation, dt: f64) -> String {
    let mut out = Vec::new();
    SimReport::new(sim, dt)
        .expect("report")
        .write_json(&mut out)
        .unwrap();
    String::from_utf8(out).unwrap()
}

/// Moves the middle stud of the wall with the fewest studs 20 mm along its wall. Studs of
/// this model are placed in their wall's frame, x along the wall. Returns the edited text and
/// the stud's GlobalId.
fn move_a_stud(text: &str) -> (String, String) {
    let lines: BTreeMap<&str, &str> = text
        .lines()
        .filter_map(|l| l.split_once('='))
        .filter(|(id, _)| id.starts_with('#'))
        .collect();
    let args = |id: &str| {
        let body = lines[id];
        body[body.find('(').unwrap() + 1..body.rfind(')').unwrap()].to_string()
    };
    let mut by_wall: BTreeMap<String, Vec<(String, String)>> = BTreeMap::new();
    for body in lines.values() {
        if !(body.starts_with("IFCMEMBER(") && body.contains(".STUD.")) {
            continue;
        }
        let a: Vec<&str> = body.split(',').collect();
        let global_id = a[0]
            .trim_start_matches("IFCMEMBER(")
            .trim_matches('\'')
            .to_string();
        let local = args(a[5].trim());
        let (wall, axis) = local.split_once(',').unwrap();
        let point = args(axis.trim())
            .split(',')
            .next()
            .unwrap()
            .trim()
            .to_string();
        by_wall
            .entry(wall.trim().to_string())
            .or_default()
            .push((point, global_id));
    }
    let (_, studs) = by_wall
        .iter()
        .filter(|(_, s)| s.len() >= 3)
        .min_by_key(|(_, s)| s.len())
        .expect("a wall with three studs");
    let (point, global_id) = &studs[studs.len() / 2];
    let old = format!("{point}={}", lines[point.as_str()]);
    let inner = args(point);
    let coords: Vec<f64> = inner
        .trim_matches(|c| c == '(' || c == ')')
        .split(',')
        .map(|c| c.trim().parse().unwrap())
        .collect();
    let new = format!(
        "{point}=IFCCARTESIANPOINT(({:?},{:?},{:?}));",
        coords[0] + 0.02,
        coords[1],
        coords[2]
    );
    assert_eq!(text.matches(&old).count(), 1);
    (text.replacen(&old, &new, 1), global_id.clone())
}

/// The plan rows: `plan` as the command runs it (read, facts, placement search, rules,
/// plan) on the edited model without the cache, then through a plan cache filled from the
/// original model, each once.
fn plan_rows(path: &Path, edited_path: &Path, dir: &Path, cell: &Cell) {
    let plan_once = |model_path: &Path, cache: Option<&Cache>| {
        let t = Instant::now();
        let m = Model::open(model_path).unwrap();
        let mut facts = model_facts(&m, &ContactOptions::default());
        facts.extend(cell_facts(cell));
        let planned = framewright::pipeline::plan(
            &m,
            cell,
            facts,
            &RuleEngine::Compiled,
            RuleLimits::default(),
            cache,
        )
        .unwrap();
        let (plan, counts) = (planned.plan, planned.cache);
        (t.elapsed().as_secs_f64(), plan.walls.len(), counts)
    };
    let plan_cache = Cache::new(dir.join("plan-cache"));
    let (full_plan_s, walls, _) = plan_once(edited_path, None);
    let (fill_s, _, _) = plan_once(path, Some(&plan_cache));
    let (regen_plan_s, _, counts) = plan_once(edited_path, Some(&plan_cache));
    let counts = counts.unwrap();
    println!(
        "plan of the edited model: {:.0} ms without the cache, {walls} walls; first plan into \
         an empty cache {:.0} ms; regenerated through the cache {:.0} ms ({:.1} % of the full \
         plan), {} walls reasoned, {} from the cache",
        full_plan_s * 1000.0,
        fill_s * 1000.0,
        regen_plan_s * 1000.0,
        100.0 * regen_plan_s / full_plan_s,
        counts.computed,
        counts.cached
    );
}

fn main() {
    let path =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/ifc-testcases/g_scale_3storey.ifc");
    if !path.exists() {
        eprintln!("skipped: {} is absent", path.display());
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let cache = Cache::new(dir.path().join("cache"));
    let cell = Cell::load("study-abb").unwrap();
    // `simulate`'s defaults, computed as it computes them (the cache key holds the bits).
    let options = SimOptions {
        dt: (1000.0 / 240.0) / 1000.0,
        ..SimOptions::default()
    };
    let name = "g_scale_3storey.ifc";

    let (edited_text, stud) = move_a_stud(&std::fs::read_to_string(&path).unwrap());
    let edited_path = dir.path().join(name);
    std::fs::write(&edited_path, edited_text).unwrap();
    plan_rows(&path, &edited_path, dir.path(), &cell);
    if std::env::args().any(|a| a == "--plan-only") {
        return;
    }

    let t = Instant::now();
    let model = Model::open(&path).unwrap();
    let (full, counts) = Run::new(&model, &cell, &options)
        .named(name)
        .cache(Some(&cache))
        .simulate()
        .unwrap();
    let counts = counts.expect("a cached run counts");
    let full_s = t.elapsed().as_secs_f64();
    println!(
        "full simulate (empty cache): {full_s:.1} s, {} walls simulated",
        counts.computed
    );
    drop(full);

    let t = Instant::now();
    let edited = Model::open(&edited_path).unwrap();
    let (regen, counts) = Run::new(&edited, &cell, &options)
        .named(name)
        .cache(Some(&cache))
        .simulate()
        .unwrap();
    let counts = counts.expect("a cached run counts");
    let regen_s = t.elapsed().as_secs_f64();
    println!(
        "regenerate after moving stud {stud} 20 mm: {regen_s:.2} s ({:.2} % of the full run), \
         {} walls simulated, {} from the cache",
        100.0 * regen_s / full_s,
        counts.computed,
        counts.cached
    );

    let t = Instant::now();
    let (uncached, _) = Run::new(&edited, &cell, &options)
        .named(name)
        .simulate()
        .unwrap();
    println!(
        "edited model without the cache: {:.1} s",
        t.elapsed().as_secs_f64()
    );
    let same = report_json(&regen, options.dt) == report_json(&uncached, options.dt);
    println!("regenerated report equals the uncached one byte for byte: {same}");
    assert!(same, "the regenerated report differs from an uncached run");
}
