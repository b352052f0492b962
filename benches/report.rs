//! What `simulate --report` costs. On test model 3: building the report folder's files (page,
//! drawings, one animated scene per wall, JSON) and storing the walls' pose traces in the
//! cache, against the simulation itself (the goal: ≤ 5 %). On the 4,020-member
//! 3-storey building (`../shared/ifc-testcases/g_scale_3storey.ifc`, when present): the
//! report's files from its simulation (goal ≤ 2 s). The building's simulation (several
//! minutes) goes through a cache in `target/report-bench-cache`, so only the first run pays
//! for it. The figures are printed once; criterion then times TM3's report alone.
//! Run: `cargo bench --bench report`.

use criterion::{Criterion, criterion_group, criterion_main};
use framewright::cache::{Cache, Need};
use framewright::cell::Cell;
use framewright::ifc::Model;
use framewright::pipeline::Run;
use framewright::pipeline::simulate;
use framewright::report::html::{ReportInput, report_files};
use framewright::report::simulate::SimReport;
use framewright::sim::SimOptions;
use std::path::Path;
use std::time::Instant;

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

fn tm3(c: &mut Criterion) {
    let model = Model::open(root().join("examples/models/tm3.ifc")).expect("bundled model");
    let cell = Cell::load("study-abb").expect("cell");
    let options = SimOptions::default();
    let start = Instant::now();
    let sim = simulate(&model, &cell, &options).expect("simulation");
    let simulating = start.elapsed().as_secs_f64();
    let report = SimReport::new(&sim, options.dt).expect("report");
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
    // What a cached run adds for the report: each wall's trace encoded and stored.
    let dir = tempfile::tempdir().expect("temporary folder");
    let cache = Cache::new(dir.path());
    let start = Instant::now();
    for (i, r) in sim.records.iter().enumerate() {
        cache.put_trace(&format!("{i:064x}"), &r.trace);
    }
    let storing = start.elapsed().as_secs_f64();
    let bytes: usize = files.iter().map(|f| f.1.len()).sum();
    println!(
        "tm3 study-abb: simulate {simulating:.2} s; report {reporting:.3} s (+{:.1} %), {} files, \
         {bytes} bytes; traces to the cache {storing:.3} s (+{:.1} %); together +{:.1} %",
        100.0 * reporting / simulating,
        files.len(),
        100.0 * storing / simulating,
        100.0 * (reporting + storing) / simulating,
    );
    let mut group = c.benchmark_group("report");
    group.sample_size(10);
    group.bench_function("tm3_report_files", |b| b.iter(|| report_files(&input)));
    group.finish();
}

fn building() {
    let path = root().join("../shared/ifc-testcases/g_scale_3storey.ifc");
    if !path.exists() {
        println!("building: skipped, {} is absent", path.display());
        return;
    }
    let model = Model::open(&path).expect("building model");
    let cell = Cell::load("study-abb").expect("cell");
    let options = SimOptions::default();
    let cache = Cache::new(root().join("target/report-bench-cache"));
    let start = Instant::now();
    let (sim, counts) = Run::new(&model, &cell, &options)
        .named("g_scale_3storey.ifc")
        .cache(Some(&cache))
        .need(Need::Traces)
        .simulate()
        .expect("simulation");
    let counts = counts.expect("a cached run counts");
    let simulating = start.elapsed().as_secs_f64();
    let report = SimReport::new(&sim, options.dt).expect("report");
    let input = ReportInput {
        model: &model,
        model_name: "g_scale_3storey.ifc",
        cell: &cell,
        sim: &sim,
        report: &report,
    };
    let mut times = Vec::new();
    let mut files = Vec::new();
    for _ in 0..3 {
        let start = Instant::now();
        files = report_files(&input);
        times.push(start.elapsed().as_secs_f64());
    }
    times.sort_by(f64::total_cmp);
    // And onto the disk: the folder as `simulate --report` leaves it (page cache, no fsync).
    let dir = tempfile::tempdir().expect("temporary folder");
    let start = Instant::now();
    for (name, bytes) in &files {
        std::fs::write(dir.path().join(name), bytes).expect("report file written");
    }
    let writing = start.elapsed().as_secs_f64();
    let bytes: usize = files.iter().map(|f| f.1.len()).sum();
    let largest = files.iter().map(|f| f.1.len()).max().unwrap_or(0);
    println!(
        "building g_scale_3storey ({} members, {} walls): simulation {simulating:.1} s \
         ({} walls computed, {} from the cache); report files median of 3: {:.2} s \
         (min {:.2} s), written in {writing:.2} s, together {:.2} s (goal 2 s), {} files, \
         {bytes} bytes, largest file {largest} bytes",
        model.pieces.len(),
        sim.records.len(),
        counts.computed,
        counts.cached,
        times[1],
        times[0],
        times[1] + writing,
        files.len(),
    );
}

fn bench(c: &mut Criterion) {
    tm3(c);
    building();
}

criterion_group!(benches, bench);
criterion_main!(benches);
