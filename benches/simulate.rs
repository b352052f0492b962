//! Simulated seconds per wall-clock second, event-driven against fixed steps, measured in the
//! same run: every wall of the bundled test model 3 (framing and nailing) on the study's ABB
//! cell, then (when ../shared/ifc-testcases/g_scale_3storey.ifc is present) the 3-storey
//! model's 153 walls. The fixed-step run of the 3-storey model takes minutes: it covers every
//! 7th wall (the event-driven run of the same walls gives the ratio) unless
//! FRAMEWRIGHT_BENCH_FIXED_ALL=1. The figures are printed once; criterion then times the
//! event-driven TM3 run.

use criterion::{Criterion, criterion_group, criterion_main};
use framewright::cell::Cell;
use framewright::ifc::Model;
use framewright::pipeline::simulate;
use framewright::sim::{SimOptions, Stepping};
use std::path::Path;
use std::time::Instant;

/// Wall-clock seconds, simulated seconds and solver steps of one run.
fn measure(model: &Model, cell: &Cell, walls: &[String], stepping: Stepping) -> (f64, f64, u64) {
    let options = SimOptions {
        walls: walls.to_vec(),
        stepping,
        ..SimOptions::default()
    };
    let start = Instant::now();
    let sim = simulate(model, cell, &options).expect("simulation");
    let wall = start.elapsed().as_secs_f64();
    let simulated: f64 = sim.records.iter().map(|r| r.nailing_end).sum();
    let steps: u64 = sim.records.iter().map(|r| r.steps).sum();
    (wall, simulated, steps)
}

fn print(label: &str, fixed: (f64, f64, u64), events: (f64, f64, u64)) {
    let line = |mode: &str, (wall, simulated, steps): (f64, f64, u64)| {
        println!(
            "{label} {mode}: {simulated:.1} simulated s in {wall:.2} s = {:.0}x real time, {steps} solver steps",
            simulated / wall
        )
    };
    line("fixed ", fixed);
    line("events", events);
    println!(
        "{label}: event-driven {:.1}x faster than fixed steps, {:.1}x fewer solver steps",
        fixed.0 / events.0,
        fixed.2 as f64 / events.2.max(1) as f64
    );
}

fn bench(c: &mut Criterion) {
    let cell = Cell::load("study-abb").expect("cell");
    let tm3 = Model::open(Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/models/tm3.ifc"))
        .expect("bundled model");
    let fixed = measure(&tm3, &cell, &[], Stepping::Fixed);
    let events = measure(&tm3, &cell, &[], Stepping::Events);
    print("tm3 study-abb", fixed, events);

    let storeys =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/ifc-testcases/g_scale_3storey.ifc");
    if storeys.exists() {
        let model = Model::open(&storeys).expect("3-storey model");
        let all = measure(&model, &cell, &[], Stepping::Events);
        println!(
            "3-storey study-abb events: all walls in {:.1} s ({:.1} simulated s, {} solver steps)",
            all.0, all.1, all.2
        );
        let sample: Vec<String> = if std::env::var_os("FRAMEWRIGHT_BENCH_FIXED_ALL").is_some() {
            Vec::new()
        } else {
            wall_sample(&model, &cell)
        };
        let label = if sample.is_empty() {
            "3-storey study-abb, all walls".to_string()
        } else {
            format!("3-storey study-abb, {} walls (every 7th)", sample.len())
        };
        let fixed = measure(&model, &cell, &sample, Stepping::Fixed);
        let events = if sample.is_empty() {
            all
        } else {
            measure(&model, &cell, &sample, Stepping::Events)
        };
        print(&label, fixed, events);
    } else {
        println!("3-storey figures skipped: {} is absent", storeys.display());
    }

    let options = SimOptions::default();
    let mut group = c.benchmark_group("simulate");
    group.sample_size(10);
    group.bench_function("tm3_study_abb_events", |b| {
        b.iter(|| simulate(&tm3, &cell, &options).expect("simulation"))
    });
    group.finish();
}

/// Every 7th wall of the model's plan, by id.
fn wall_sample(model: &Model, cell: &Cell) -> Vec<String> {
    use framewright::frame::{Ask, RuleEngine, cell_facts, model_facts, plan};
    let mut facts = model_facts(model, &framewright::geom::ContactOptions::default());
    facts.extend(cell_facts(cell));
    let engine = RuleEngine::Compiled;
    Ask::new(&engine)
        .place(&mut facts, cell)
        .expect("placement");
    let reasoned = Ask::new(&engine).over(&facts).expect("reasoning");
    plan::Plan::from_reasoned(model, &reasoned)
        .expect("plan")
        .walls
        .iter()
        .step_by(7)
        .map(|w| w.id.clone())
        .collect()
}

criterion_group!(benches, bench);
criterion_main!(benches);
