//! `plan` end to end (read, facts with contacts, compiled rule base, typed
//! plan) on the study's TM3, the shared 4 020-member model (when present) and
//! a generated model of 52 142 members (the TM3 building on a 29 x 29 grid).
//! `cargo bench --bench plan`; peak memory: `/usr/bin/time -v framewright plan …`.

use criterion::{Criterion, criterion_group, criterion_main};
use framewright::frame::plan::Plan;
use framewright::frame::{Ask, RuleEngine, model_facts};
use framewright::ifc::Model;
use framewright::synth::{WriteOptions, building, models, write_ifc};
use std::hint::black_box;
use std::path::Path;

fn plan(path: &Path) -> usize {
    let model = Model::open(path).expect("read");
    let facts = model_facts(&model, &Default::default());
    let reasoned = Ask::new(&RuleEngine::Compiled)
        .over(&facts)
        .expect("reason");
    Plan::from_reasoned(&model, &reasoned)
        .expect("plan")
        .walls
        .len()
}

fn benches(c: &mut Criterion) {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut group = c.benchmark_group("plan");
    group.sample_size(10);
    let tm3 = root.join("examples/models/tm3.ifc");
    group.bench_function("tm3_62_members", |b| b.iter(|| black_box(plan(&tm3))));
    let scale = root.join("../shared/ifc-testcases/g_scale_3storey.ifc");
    if scale.is_file() {
        group.bench_function("g_scale_4020_members", |b| {
            b.iter(|| black_box(plan(&scale)))
        });
    } else {
        eprintln!("skipped g_scale: {} is absent", scale.display());
    }
    let layout = building::grid(&models::tm3_spec(), 29, 29, 3.0, "bench grid").expect("grid");
    let written = write_ifc(
        &layout,
        &WriteOptions {
            file_name: "grid.ifc".into(),
            ..WriteOptions::default()
        },
    )
    .expect("write");
    let dir = tempfile::tempdir().expect("temp dir");
    let big = dir.path().join("grid.ifc");
    std::fs::write(&big, &written.ifc).expect("write model");
    assert!(layout.piece_count() >= 50_000);
    group.bench_function("grid_52142_members", |b| b.iter(|| black_box(plan(&big))));
    group.finish();
}

criterion_group!(plan_benches, benches);
criterion_main!(plan_benches);
