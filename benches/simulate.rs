//! Simulated seconds per wall-clock second: every wall of the bundled test model 3 (framing
//! and nailing) on the study's ABB cell. The figure the issue asks for is printed once;
//! criterion then times the whole run.

use criterion::{Criterion, criterion_group, criterion_main};
use framewright::cell::Cell;
use framewright::ifc::Model;
use framewright::sim::{SimOptions, simulate};
use std::path::Path;
use std::time::Instant;

fn bench(c: &mut Criterion) {
    let model = Model::open(&Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/models/tm3.ifc"))
        .expect("bundled model");
    let cell = Cell::load("study-abb").expect("cell");
    let options = SimOptions::default();
    let start = Instant::now();
    let sim = simulate(&model, &cell, &options).expect("simulation");
    let wall = start.elapsed().as_secs_f64();
    let simulated: f64 = sim.records.iter().map(|r| r.nailing_end).sum();
    let steps: u64 = sim.records.iter().map(|r| r.steps).sum();
    println!(
        "tm3 study-abb: {simulated:.1} simulated s in {wall:.2} wall-clock s = {:.0}x real time ({steps} steps, {:.2} us/step)",
        simulated / wall,
        wall * 1e6 / steps as f64
    );
    let mut group = c.benchmark_group("simulate");
    group.sample_size(10);
    group.bench_function("tm3_study_abb", |b| {
        b.iter(|| simulate(&model, &cell, &options).expect("simulation"))
    });
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
