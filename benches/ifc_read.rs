//! IFC reader throughput on a ≥ 40 MB model written by the project's own
//! generator (the TM3 building repeated on a grid). Reports bytes/s.
//! `cargo bench --bench ifc_read`; the IfcOpenShell peer is `bench/ifc_read_peer.py`.

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use framewright::ifc::Model;
use framewright::synth::{WriteOptions, building, models, write_ifc};
use std::hint::black_box;

fn big_model() -> (tempfile::TempDir, std::path::PathBuf, u64) {
    let layout = building::grid(&models::tm3_spec(), 27, 27, 2.0, "bench grid").expect("grid");
    let written = write_ifc(
        &layout,
        &WriteOptions {
            file_name: "bench.ifc".into(),
            ..WriteOptions::default()
        },
    )
    .expect("write");
    let dir = tempfile::tempdir().expect("temp dir");
    let path = dir.path().join("bench.ifc");
    std::fs::write(&path, &written.ifc).expect("write model");
    let bytes = written.ifc.len() as u64;
    assert!(
        bytes >= 40 << 20,
        "the bench model must be at least 40 MB ({bytes} bytes)"
    );
    (dir, path, bytes)
}

fn read(c: &mut Criterion) {
    let (_dir, path, bytes) = big_model();
    let mut group = c.benchmark_group("ifc_read");
    group.sample_size(10);
    group.throughput(Throughput::Bytes(bytes));
    group.bench_function("open_and_read_every_piece_47MB", |b| {
        b.iter(|| {
            let model = Model::open(black_box(&path)).expect("read");
            let total: f64 = model.pieces().iter().map(|p| p.obox.length()).sum();
            black_box(total)
        })
    });
    group.finish();
}

criterion_group!(benches, read);
criterion_main!(benches);
