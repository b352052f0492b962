//! The simulation behind a first `why` on an element of the 4,020-member model
//! (`../shared/ifc-testcases/g_scale_3storey.ifc`, skipped when absent): the element's wall
//! simulated as `why` did before (the whole model planned, the run reasoned over afterwards:
//! `simulate(..).facts`) and as it does now (`pipeline::Run::wall_facts`: the wall's storey alone,
//! no reasoning afterwards), in the same run, with the ratio. Both must give the same facts.
//!
//! `cargo bench --bench why_first [-- ID]` (default `#20002`, a jack stud of a 228-piece wall).

use framewright::cell::Cell;
use framewright::explain::why::{Context, element_walls};
use framewright::frame::{RuleEngine, cell_facts, model_facts};
use framewright::geom::ContactOptions;
use framewright::ifc::Model;
use framewright::pipeline::{Run, simulate};
use framewright::sim::SimOptions;
use std::path::Path;
use std::time::Instant;

fn main() {
    let path =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/ifc-testcases/g_scale_3storey.ifc");
    if !path.exists() {
        println!("why_first: {} is absent, nothing measured", path.display());
        return;
    }
    let id = std::env::args()
        .skip(1)
        .find(|a| !a.starts_with('-'))
        .unwrap_or_else(|| "#20002".into());
    let model = Model::open(&path).expect("3-storey model");
    let cell = Cell::load("study-abb").expect("cell");
    let mut facts = model_facts(&model, &ContactOptions::default());
    facts.extend(cell_facts(&cell));
    let base = RuleEngine::Compiled;
    let ctx = Context {
        model: &model,
        facts: &facts,
        base: &base,
        user_files: &[],
        limits: framewright::frame::RuleLimits::default(),
        cell: None,
    };
    let walls = element_walls(&ctx, &id).expect("the element's wall");
    let options = SimOptions {
        walls: walls.clone(),
        ..SimOptions::default()
    };
    let start = Instant::now();
    let before = simulate(&model, &cell, &options)
        .expect("whole-model run")
        .facts;
    let whole = start.elapsed().as_secs_f64();
    let start = Instant::now();
    let now = Run::new(&model, &cell, &options)
        .wall_facts(None)
        .map(|(facts, _)| facts)
        .expect("one-storey run");
    let alone = start.elapsed().as_secs_f64();
    assert_eq!(format!("{now:?}"), format!("{before:?}"), "same facts");
    println!(
        "why_first {id} (wall {}): whole model {whole:.2} s, its storey alone {alone:.2} s ({:.2}x)",
        walls.join(", "),
        whole / alone
    );
}
