//! A three-way join over 10^6 input tuples (4·10^5 + 3·10^5 + 3·10^5;
//! 6·10^6 derivations, 3·10^5 distinct results): interpreter vs compiled vs
//! a hand-written ascent program, as in logic_tc.

// Ascent programs are filled field by field after `default()`.
#![allow(clippy::field_reassign_with_default)]

use criterion::{Criterion, criterion_group, criterion_main};
use framewright::logic::compiled::{self, Relations};
use framewright::logic::{Engine, Options, Origin, Program, Value};
use std::sync::Arc;

ascent::ascent! {
    struct HandJoin;
    relation a(i64, i64);
    relation b(i64, i64);
    relation c(i64, i64);
    relation j(i64, i64);
    j(y, w) <-- a(x, y), b(y, z), c(z, w);
}

type Rel = Vec<(i64, i64)>;

fn data() -> (Rel, Rel, Rel) {
    let a = (0..400_000).map(|i| (i, i % 20_000)).collect();
    let b = (0..20_000)
        .flat_map(|y| (0..15).map(move |k| (y, y * 15 + k)))
        .collect();
    let c = (0..300_000).map(|z| (z, z % 100)).collect();
    (a, b, c)
}

fn values(r: &Rel) -> Vec<Vec<Value>> {
    r.iter()
        .map(|&(x, y)| vec![Value::Number(x), Value::Number(y)])
        .collect()
}

fn bench(cr: &mut Criterion) {
    let (a, b, c) = data();
    let (va, vb, vc) = (values(&a), values(&b), values(&c));
    let program = Arc::new(
        Program::parse_files(&[concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/benches/logic/join.dl"
        )])
        .unwrap(),
    );
    let edb: Relations = [
        ("a".to_string(), va.clone()),
        ("b".to_string(), vb.clone()),
        ("c".to_string(), vc.clone()),
    ]
    .into();
    let run = compiled::program("benches/logic/join.dl").expect("compiled by build.rs");
    let interp = |provenance: bool| {
        let mut e = Engine::new(
            program.clone(),
            Options {
                provenance,
                ..Options::default()
            },
        );
        for (name, rel) in [("a", &va), ("b", &vb), ("c", &vc)] {
            for t in rel {
                e.insert(name, t.clone(), Origin::Rust).unwrap();
            }
        }
        e.run().unwrap();
        e.relation("j").unwrap().len()
    };
    let n = interp(false);
    assert_eq!(run(&edb).unwrap()["j"].len(), n);

    let mut g = cr.benchmark_group("join_1e6_tuples");
    g.sample_size(10);
    g.bench_function("interpreter", |bch| bch.iter(|| interp(false)));
    g.bench_function("interpreter_provenance", |bch| bch.iter(|| interp(true)));
    g.bench_function("compiled", |bch| bch.iter(|| run(&edb).unwrap()["j"].len()));
    g.bench_function("compiled_engine_only", |bch| {
        bch.iter(|| {
            let mut p = compiled::benches_logic_join::Prog::default();
            p.r_a = a.clone();
            p.r_b = b.clone();
            p.r_c = c.clone();
            p.run();
            p.r_j.len()
        })
    });
    g.bench_function("handwritten_ascent", |bch| {
        bch.iter(|| {
            let mut p = HandJoin::default();
            p.a = a.clone();
            p.b = b.clone();
            p.c = c.clone();
            p.run();
            p.j.len()
        })
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
