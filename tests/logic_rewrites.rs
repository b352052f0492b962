//! Metamorphic properties of the interpreter: a rewrite that does not change a program's
//! meaning in Soufflé must not change its answer. On random facts: (a) a disjunction in a
//! body gives what the rules it stands for give, one per disjunct; (b) a body's atoms,
//! negations and constraints in any order give the same answer, in a recursive rule too.
//! The third rewrite, an expression argument moved into an equality constraint, is in
//! tests/logic_expression_args.rs; the compiled engine's pairs in tests/logic/rewrites.dl.

use framewright::logic::{Engine, Options, Origin, Program, Value};
use proptest::prelude::*;
use proptest::sample::select;
use std::collections::BTreeSet;
use std::sync::Arc;

const DECLS: &str = ".decl p(a: number, b: number)\n.decl q(a: number, b: number)\n.decl s(a: number, b: number)\n.input p\n.input q\n.input s\n.decl r(x: number, z: number)\n.decl t(x: number, z: number)\n";

type Facts = Vec<(i64, i64)>;

fn facts() -> impl Strategy<Value = Facts> {
    proptest::collection::vec((0i64..5, 0i64..5), 0..10)
}

/// The tuples of `rel` after running `text` on the facts of p, q and s.
fn run(text: &str, facts: [&Facts; 3], rel: &str) -> BTreeSet<Vec<Value>> {
    let program =
        Arc::new(Program::parse_str("rw.dl", text).unwrap_or_else(|e| panic!("{e}\n{text}")));
    let mut e = Engine::new(program, Options::default());
    for (name, tuples) in ["p", "q", "s"].into_iter().zip(facts) {
        for &(a, b) in tuples {
            e.insert(name, vec![Value::Number(a), Value::Number(b)], Origin::Rust)
                .unwrap();
        }
    }
    e.run().unwrap_or_else(|err| panic!("{err}\n{text}"));
    e.relation(rel).unwrap().into_iter().collect()
}

fn relation() -> impl Strategy<Value = &'static str> {
    select(&["p", "q", "s"][..])
}

/// A constraint over X, Y, Z (all bound by the atoms), with a constant.
fn constraint() -> impl Strategy<Value = String> {
    (
        select(
            &[
                "X < Z",
                "X != Z",
                "Y + Z > {k}",
                "X * 2 <= Z + {k}",
                "Y = Z",
                "X >= {k}",
            ][..],
        ),
        0i64..5,
    )
        .prop_map(|(c, k)| c.replace("{k}", &k.to_string()))
}

/// A negated atom over bound variables.
fn negation() -> impl Strategy<Value = String> {
    (
        relation(),
        select(&["X, Z", "Z, X", "Y, _", "_, Y", "X, X"][..]),
    )
        .prop_map(|(r, args)| format!("!{r}({args})"))
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 4000, ..ProptestConfig::default() })]

    // r(X, Z) :- a(X, Y), (b(Y, Z) ; c(Z, Y), C2), C1.  is the two rules
    // r(X, Z) :- a(X, Y), b(Y, Z), C1.  and  r(X, Z) :- a(X, Y), c(Z, Y), C2, C1.
    #[test]
    fn a_disjunction_gives_what_its_rules_give(
        (a, b, c) in (relation(), relation(), relation()),
        c1 in constraint(), c2 in constraint(), n in negation(),
        p in facts(), q in facts(), s in facts(),
    ) {
        let joined = format!(
            "{DECLS}r(X, Z) :- {a}(X, Y), ({b}(Y, Z) ; {c}(Z, Y), {c2}), {c1}, {n}.\n"
        );
        let split = format!(
            "{DECLS}r(X, Z) :- {a}(X, Y), {b}(Y, Z), {c1}, {n}.\nr(X, Z) :- {a}(X, Y), {c}(Z, Y), {c2}, {c1}, {n}.\n"
        );
        let facts = [&p, &q, &s];
        prop_assert_eq!(run(&joined, facts, "r"), run(&split, facts, "r"), "{}", joined);
    }

    // The literals of a recursive rule's body in a random order give what they give in the
    // written one: t(X, Y) :- a(X, Y).  t(X, Z) :- t(X, Y), b(Y, Z), C, N.
    #[test]
    fn a_body_in_any_order_gives_the_same_answer(
        (a, b) in (relation(), relation()),
        c in constraint(), n in negation(),
        order in Just(vec![0usize, 1, 2, 3]).prop_shuffle(),
        p in facts(), q in facts(), s in facts(),
    ) {
        let literals = [
            "t(X, Y)".to_string(),
            format!("{b}(Y, Z)"),
            c,
            n,
        ];
        let program = |body: &[&String]| {
            let body: Vec<&str> = body.iter().map(|l| l.as_str()).collect();
            format!("{DECLS}t(X, Y) :- {a}(X, Y).\nt(X, Z) :- {}.\n", body.join(", "))
        };
        let written = program(&literals.iter().collect::<Vec<_>>());
        let shuffled = program(&order.iter().map(|&i| &literals[i]).collect::<Vec<_>>());
        let facts = [&p, &q, &s];
        prop_assert_eq!(run(&written, facts, "t"), run(&shuffled, facts, "t"), "{}", shuffled);
    }
}
