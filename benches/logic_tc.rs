//! Transitive closure over 10^5 edges (chains of 10: 5.5·10^5 paths):
//! interpreter (with and without provenance) vs the ascent program build.rs
//! generates from benches/logic/tc.dl vs a hand-written ascent program.
//! All "end-to-end" variants take `Value` tuples in and return sorted `Value` tuples.

// Ascent programs are filled field by field after `default()`.
#![allow(clippy::field_reassign_with_default)]

use criterion::{Criterion, criterion_group, criterion_main};
use framewright::logic::compiled::{self, Relations};
use framewright::logic::{Engine, Options, Origin, Program, Value};
use std::sync::Arc;

ascent::ascent! {
    struct HandTc;
    relation edge(i64, i64);
    relation path(i64, i64);
    path(x, y) <-- edge(x, y);
    path(x, z) <-- edge(x, y), path(y, z);
}

fn chains(n: i64, chain: i64) -> Vec<(i64, i64)> {
    let per = chain + 1;
    (0..n / chain)
        .flat_map(|c| (1..per).map(move |k| (c * per + k - 1, c * per + k)))
        .collect()
}

fn bench(c: &mut Criterion) {
    let edges = chains(100_000, 10);
    let vals: Vec<Vec<Value>> = edges
        .iter()
        .map(|&(a, b)| vec![Value::Number(a), Value::Number(b)])
        .collect();
    let program = Arc::new(
        Program::parse_files(&[concat!(env!("CARGO_MANIFEST_DIR"), "/benches/logic/tc.dl")])
            .unwrap(),
    );
    let edb: Relations = [("edge".to_string(), vals.clone())].into();
    let run = compiled::program("benches/logic/tc.dl").expect("compiled by build.rs");
    let interp = |provenance: bool| {
        let mut e = Engine::new(
            program.clone(),
            Options {
                provenance,
                ..Options::default()
            },
        );
        for t in &vals {
            e.insert("edge", t.clone(), Origin::Rust).unwrap();
        }
        e.run().unwrap();
        e.relation("path").unwrap().len()
    };
    assert_eq!(interp(false), 550_000);
    assert_eq!(run(&edb).unwrap()["path"].len(), 550_000);

    let mut g = c.benchmark_group("tc_1e5_edges");
    g.sample_size(10);
    g.bench_function("interpreter", |b| b.iter(|| interp(false)));
    g.bench_function("interpreter_provenance", |b| b.iter(|| interp(true)));
    g.bench_function("compiled", |b| b.iter(|| run(&edb).unwrap()["path"].len()));
    g.bench_function("compiled_engine_only", |b| {
        b.iter(|| {
            let mut p = compiled::benches_logic_tc::Prog::default();
            p.r_edge = edges.clone();
            p.run();
            p.r_path.len()
        })
    });
    g.bench_function("handwritten_ascent", |b| {
        b.iter(|| {
            let mut p = HandTc::default();
            p.edge = edges.clone();
            p.run();
            p.path.len()
        })
    });
    g.bench_function("handwritten_ascent_values", |b| {
        b.iter(|| {
            let mut p = HandTc::default();
            p.edge = vals
                .iter()
                .map(|t| (t[0].as_number().unwrap(), t[1].as_number().unwrap()))
                .collect();
            p.run();
            let mut out: Vec<Vec<Value>> = p
                .path
                .iter()
                .map(|t| vec![Value::Number(t.0), Value::Number(t.1)])
                .collect();
            out.sort();
            out.len()
        })
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
