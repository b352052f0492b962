//! User rules and explanations on the shared 4 020-member model (when present)
//! and TM3:
//! - `plan` vs `check` with the five example shop rules (same run, so the
//!   ratio is the cost of the rules: `check` reads, reasons, then evaluates
//!   the user rules over the relations they read; `plan` reasons and builds
//!   the typed plan);
//! - `reason_only`: what `check` does before the user rules, so
//!   `check_5_rules - reason_only` is the cost of the rules themselves;
//! - `why` for one element without simulation (read, facts, rule base with
//!   provenance over the element's storey, explanations).
//!
//! `cargo bench --bench explain`. The command-line times (with a cached
//! simulation) are in docs/RULES.md.

use criterion::{Criterion, criterion_group, criterion_main};
use framewright::cell::Cell;
use framewright::explain::why::{Context, why};
use framewright::frame::plan::Plan;
use framewright::frame::{Ask, Facts, RuleEngine, cell_facts, model_facts};
use framewright::ifc::Model;
use framewright::user_rules::UserRules;
use std::hint::black_box;
use std::path::{Path, PathBuf};

const SHOP_RULES: [&str; 5] = [
    "gripper_spacing.dl",
    "payload.dl",
    "nail_end_distance.dl",
    "two_robot_headers.dl",
    "assembly_table.dl",
];

fn inputs(path: &Path, cell: &Cell) -> (Model, Facts) {
    let model = Model::open(path).expect("read");
    let mut facts = model_facts(&model, &Default::default());
    facts.extend(cell_facts(cell));
    (model, facts)
}

fn plan(path: &Path, cell: &Cell) -> usize {
    let (model, facts) = inputs(path, cell);
    let reasoned = Ask::new(&RuleEngine::Compiled)
        .over(&facts)
        .expect("reason");
    Plan::from_reasoned(&model, &reasoned)
        .expect("plan")
        .walls
        .len()
}

/// What `check` does before the user rules: read, facts, compiled rule base.
fn reason_only(path: &Path, cell: &Cell) -> usize {
    let (_, facts) = inputs(path, cell);
    Ask::new(&RuleEngine::Compiled)
        .over(&facts)
        .expect("reason")
        .get("wall")
        .len()
}

fn check(path: &Path, cell: &Cell, files: &[PathBuf]) -> usize {
    let rules = UserRules::load(files, &RuleEngine::Compiled).expect("rules");
    let (_, facts) = inputs(path, cell);
    let reasoned = Ask::new(&RuleEngine::Compiled)
        .over(&facts)
        .expect("reason");
    let findings = rules.evaluate(&reasoned.relations).expect("evaluate");
    findings.violations.len() + findings.warnings.len()
}

fn explain(path: &Path, cell: &Cell, id: &str) -> usize {
    let (model, facts) = inputs(path, cell);
    let ctx = Context {
        model: &model,
        facts: &facts,
        base: &RuleEngine::Compiled,
        user_files: &[],
        limits: framewright::frame::RuleLimits::default(),
        cell: None,
    };
    why(&ctx, id).expect("why")[0].verdicts.len()
}

fn benches(c: &mut Criterion) {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let cell = Cell::load("study-abb").expect("cell");
    let files: Vec<PathBuf> = SHOP_RULES
        .iter()
        .map(|f| root.join("examples/rules").join(f))
        .collect();
    let mut models = vec![("tm3_62_members", root.join("examples/models/tm3.ifc"))];
    let scale = root.join("../shared/ifc-testcases/g_scale_3storey.ifc");
    if scale.is_file() {
        models.push(("g_scale_4020_members", scale));
    } else {
        eprintln!("skipped g_scale: {} is absent", scale.display());
    }
    let mut group = c.benchmark_group("explain");
    group.sample_size(10);
    for (name, path) in &models {
        group.bench_function(format!("plan/{name}"), |b| {
            b.iter(|| black_box(plan(path, &cell)))
        });
        group.bench_function(format!("reason_only/{name}"), |b| {
            b.iter(|| black_box(reason_only(path, &cell)))
        });
        group.bench_function(format!("check_5_rules/{name}"), |b| {
            b.iter(|| black_box(check(path, &cell, &files)))
        });
        // The middle piece of the file: a stud of a long wall on the scale model.
        let model = Model::open(path).expect("read");
        let id = model.pieces()[model.pieces().len() / 2].id.clone();
        group.bench_function(format!("why/{name}"), |b| {
            b.iter(|| black_box(explain(path, &cell, &id)))
        });
    }
    group.finish();
}

criterion_group!(explain_benches, benches);
criterion_main!(explain_benches);
