//! What `simulate --report` costs: building the report folder's files (page, drawings, one
//! animated scene per wall, JSON) from a finished simulation of test model 3, against the
//! simulation itself. The ratio the issue asks for (≤ 5 %) is printed once; criterion then
//! times the report alone. Run: `cargo bench --bench report`.

use criterion::{Criterion, criterion_group, criterion_main};
use framewright::cell::Cell;
use framewright::ifc::Model;
use framewright::report::html::{ReportInput, report_files};
use framewright::report::simulate::SimReport;
use framewright::sim::{SimOptions, simulate};
use std::path::Path;
use std::time::Instant;

fn bench(c: &mut Criterion) {
    let model = Model::open(Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/models/tm3.ifc"))
        .expect("bundled model");
    let cell = Cell::load("study-abb").expect("cell");
    let options = SimOptions::default();
    let start = Instant::now();
    let sim = simulate(&model, &cell, &options).expect("simulation");
    let simulating = start.elapsed().as_secs_f64();
    let report = SimReport::new(&sim, options.dt);
    let input = ReportInput {
        model: &model,
        model_name: "tm3.ifc",
        cell: &cell,
        sim: &sim,
        report: &report,
    };
    let start = Instant::now();
    let files = report_files(&input);
    let reporting = start.elapsed().as_secs_f64();
    let bytes: usize = files.iter().map(|f| f.1.len()).sum();
    println!(
        "tm3 study-abb: simulate {simulating:.2} s, report {reporting:.3} s (+{:.1} %), {} files, {bytes} bytes",
        100.0 * reporting / simulating,
        files.len()
    );
    let mut group = c.benchmark_group("report");
    group.sample_size(10);
    group.bench_function("tm3_report_files", |b| b.iter(|| report_files(&input)));
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
