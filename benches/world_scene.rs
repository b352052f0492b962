//! The simulation world of a model: reasoning (model + cell facts, compiled rules), the scene
//! from the relations, and the two exporters. tm3 always; the 3-storey scale model of
//! ../shared when present.
use criterion::{Criterion, criterion_group, criterion_main};
use framewright::cell::Cell;
use framewright::frame::{Ask, RuleEngine};
use framewright::ifc::Model;
use framewright::pipeline::whole_facts;
use framewright::world::{Scene, json, wbt};
use std::hint::black_box;
use std::path::Path;
use std::time::Duration;

fn world(c: &mut Criterion) {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let cell = Cell::load("study-abb").expect("built-in cell");
    let mut models = vec![("tm3", root.join("examples/models/tm3.ifc"))];
    let scale = root.join("../shared/ifc-testcases/g_scale_3storey.ifc");
    if scale.is_file() {
        models.push(("g_scale_3storey", scale));
    } else {
        eprintln!("skipped: {} is absent", scale.display());
    }
    let mut group = c.benchmark_group("world");
    group.sample_size(10);
    group.measurement_time(Duration::from_secs(8));
    for (name, path) in models {
        let model = Model::open(&path).expect("model opens");
        let reasoned = Ask::new(&RuleEngine::Compiled)
            .placed(whole_facts(&model, &cell), &cell)
            .expect("reasons");
        let scene = Scene::build(name, &model, &cell, &reasoned).expect("scene");
        group.bench_function(format!("{name}: reason (compiled rules)"), |b| {
            b.iter(|| {
                Ask::new(&RuleEngine::Compiled)
                    .placed(whole_facts(black_box(&model), &cell), &cell)
                    .unwrap()
            })
        });
        group.bench_function(format!("{name}: scene from relations"), |b| {
            b.iter(|| Scene::build(name, black_box(&model), &cell, &reasoned).unwrap())
        });
        group.bench_function(format!("{name}: json"), |b| {
            b.iter(|| json::to_json(black_box(&scene)))
        });
        group.bench_function(format!("{name}: wbt"), |b| {
            b.iter(|| wbt::to_wbt(black_box(&scene)))
        });
    }
    group.finish();
}

criterion_group!(benches, world);
criterion_main!(benches);
