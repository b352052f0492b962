//! Writer throughput: frame and write a grid of buildings (the benchmark models).
use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use framewright::synth::building::grid;
use framewright::synth::models;
use framewright::synth::{WriteOptions, write_ifc};
use std::hint::black_box;

fn write_grid(c: &mut Criterion) {
    let spec = models::default_building_spec();
    let layout = grid(&spec, 5, 5, 3.0, "bench").expect("valid grid");
    let opts = WriteOptions::default();
    let bytes = write_ifc(&layout, &opts).expect("writes").ifc.len() as u64;
    let mut group = c.benchmark_group("synth");
    group.throughput(Throughput::Bytes(bytes));
    group.sample_size(20);
    group.bench_function("frame 5x5 buildings", |b| {
        b.iter(|| grid(black_box(&spec), 5, 5, 3.0, "bench").unwrap())
    });
    group.bench_function("write 5x5 buildings (IFC4, m)", |b| {
        b.iter(|| write_ifc(black_box(&layout), &opts).unwrap())
    });
    let mapped = WriteOptions {
        mapped: true,
        ..WriteOptions::default()
    };
    group.bench_function("write 5x5 buildings mapped", |b| {
        b.iter(|| write_ifc(black_box(&layout), &mapped).unwrap())
    });
    group.finish();
}

criterion_group!(benches, write_grid);
criterion_main!(benches);
