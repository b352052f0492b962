//! The interpreter gives the same outputs, warnings, errors and explanations for the same
//! program whatever ran before it in the process: `ord` once numbered symbols process-wide
//! (a second program saw the first one's numbers) and a bad `match` pattern warned only in
//! the first run of a thread (the compiled pattern was cached with the warning left out).

use framewright::logic::{Engine, Options, Program};
use std::sync::Arc;

/// Everything a run shows: each relation's tuples, the warnings and an explanation.
fn run(text: &str) -> String {
    let p = Arc::new(Program::parse_str("d.dl", text).unwrap_or_else(|e| panic!("{e}")));
    let names: Vec<String> = p.relations.iter().map(|r| r.name.clone()).collect();
    let mut e = Engine::new(
        p,
        Options {
            provenance: true,
            ..Options::default()
        },
    );
    let stats = e.run().unwrap();
    let mut out = format!("warnings: {:?}\n", stats.warnings);
    for n in &names {
        out += &format!("{n}: {:?}\n", e.relation(n).unwrap());
    }
    if names.iter().any(|n| n == "o") {
        let first = e.relation("o").unwrap().remove(0);
        out += &e.explain("o", &first).unwrap().render();
    }
    out
}

const PROGRAM: &str = r#"
.decl w(s: symbol)
w("pear"). w("apple"). w("fig").
.decl o(s: symbol, n: number)
o(s, ord(s)) :- w(s), !match("[0-9]+", s).
.decl bad(s: symbol)
bad(s) :- w(s), match("(", s).
.decl first(n: number)
first(n) :- n = min m : { o(_, m) }.
"#;

/// Uses other symbols (and the same ones in another order) before `PROGRAM` runs again.
const OTHER: &str = r#"
.decl v(s: symbol)
v("zebra"). v("fig"). v("yak").
.decl k(n: number)
k(ord(s)) :- v(s), !match("[0-9]+", s), !match("(", s).
"#;

#[test]
fn a_program_runs_the_same_after_other_programs() {
    // On fresh threads, so no earlier test of this process shares their state.
    // Another program first, on a thread of its own: only process-wide state reaches the next.
    std::thread::spawn(|| run(OTHER)).join().unwrap();
    let alone = std::thread::spawn(|| run(PROGRAM)).join().unwrap();
    let after = std::thread::spawn(|| {
        run(OTHER);
        run(PROGRAM);
        run(OTHER);
        run(PROGRAM)
    })
    .join()
    .unwrap();
    assert_eq!(alone, after);
    // Ordinals count from 0 in order of first use within the run (facts in order).
    assert!(
        alone.contains(r#"o: [[Symbol("apple"), Number(1)], [Symbol("fig"), Number(2)], [Symbol("pear"), Number(0)]]"#),
        "{alone}"
    );
    assert!(
        alone.contains("wrong pattern provided for match"),
        "{alone}"
    );
    // The same on the current thread, after whatever ran on it.
    assert_eq!(run(PROGRAM), alone);
}
