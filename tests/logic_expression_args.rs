//! Expression arguments of body atoms, as Soufflé evaluates them: the atom is matched and the
//! expression compared after, whichever atom binds the variables it reads. Random programs
//! `r(X, Y) :- p(E1, Y), q(E2, X).` (E1, E2 linear in X and Y) and `s(N) :- p(E3, N).` (E3 in N,
//! bound by the same atom), in every body order and with the expressions moved into equality
//! constraints, must all give the answer enumerated here from the facts.

use framewright::logic::{Engine, Options, Origin, Program, Value};
use proptest::prelude::*;
use std::collections::BTreeSet;
use std::sync::Arc;

/// `a*X + b*Y + c` as text and as a function.
#[derive(Clone, Debug)]
struct Linear {
    a: i64,
    b: i64,
    c: i64,
}

impl Linear {
    fn text(&self, x: &str, y: &str) -> String {
        format!("({} * {x} + {} * {y} + {})", self.a, self.b, self.c)
    }
    fn at(&self, x: i64, y: i64) -> i64 {
        self.a * x + self.b * y + self.c
    }
}

fn linear() -> impl Strategy<Value = Linear> {
    (-2i64..=2, -2i64..=2, -3i64..=3).prop_map(|(a, b, c)| Linear { a, b, c })
}

fn run(text: &str, p: &[(i64, i64)], q: &[(i64, i64)], rel: &str) -> BTreeSet<Vec<i64>> {
    let program =
        Arc::new(Program::parse_str("args.dl", text).unwrap_or_else(|e| panic!("{e}\n{text}")));
    let mut e = Engine::new(program, Options::default());
    for (name, facts) in [("p", p), ("q", q)] {
        for &(a, b) in facts {
            e.insert(name, vec![Value::Number(a), Value::Number(b)], Origin::Rust)
                .unwrap();
        }
    }
    e.run().unwrap();
    e.relation(rel)
        .unwrap()
        .into_iter()
        .map(|t| t.iter().map(|v| v.as_number().unwrap()).collect())
        .collect()
}

const DECLS: &str = ".decl p(a: number, b: number)\n.decl q(a: number, b: number)\n.input p\n.input q\n.decl r(x: number, y: number)\n.decl s(n: number)\n";

fn facts() -> impl Strategy<Value = Vec<(i64, i64)>> {
    proptest::collection::vec((-4i64..=4, -4i64..=4), 0..12)
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 2000, ..ProptestConfig::default() })]
    #[test]
    fn expression_arguments_match_then_compare(
        e1 in linear(), e2 in linear(), e3 in linear(), p in facts(), q in facts(),
    ) {
        // By enumeration: r(x, y) for (a, y) in p and (b, x) in q with a = E1, b = E2.
        let mut want_r = BTreeSet::new();
        for &(a, y) in &p {
            for &(b, x) in &q {
                if a == e1.at(x, y) && b == e2.at(x, y) {
                    want_r.insert(vec![x, y]);
                }
            }
        }
        let want_s: BTreeSet<Vec<i64>> = p
            .iter()
            .filter(|&&(a, n)| a == e3.at(n, n))
            .map(|&(_, n)| vec![n])
            .collect();
        let (t1, t2, t3) = (e1.text("X", "Y"), e2.text("X", "Y"), e3.text("N", "N"));
        let bodies = [
            format!("p({t1}, Y), q({t2}, X)"),
            format!("q({t2}, X), p({t1}, Y)"),
            format!("p(A, Y), A = {t1}, q(B, X), B = {t2}"),
            format!("B = {t2}, q(B, X), A = {t1}, p(A, Y)"),
        ];
        for body in &bodies {
            let text = format!("{DECLS}r(X, Y) :- {body}.\ns(N) :- p({t3}, N).\n");
            prop_assert_eq!(&run(&text, &p, &q, "r"), &want_r, "{}", text);
            prop_assert_eq!(&run(&text, &p, &q, "s"), &want_s, "{}", text);
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 2000, ..ProptestConfig::default() })]
    // An expression in the head or in a negated atom is the same expression moved into an
    // equality constraint: `r(E4, Y) :- p(X, Y), !q(E5, X).` gives, by enumeration, (E4, y)
    // for each (x, y) in p with no (E5, x) in q; so do its rewrites.
    #[test]
    fn expressions_in_heads_and_negations_are_equality_constraints(
        e4 in linear(), e5 in linear(), p in facts(), q in facts(),
    ) {
        let q_set: BTreeSet<(i64, i64)> = q.iter().copied().collect();
        let want: BTreeSet<Vec<i64>> = p
            .iter()
            .filter(|&&(x, y)| !q_set.contains(&(e5.at(x, y), x)))
            .map(|&(x, y)| vec![e4.at(x, y), y])
            .collect();
        let (t4, t5) = (e4.text("X", "Y"), e5.text("X", "Y"));
        for rule in [
            format!("r({t4}, Y) :- p(X, Y), !q({t5}, X)."),
            format!("r(H, Y) :- p(X, Y), H = {t4}, !q({t5}, X)."),
            format!("r({t4}, Y) :- p(X, Y), W = {t5}, !q(W, X)."),
            format!("r(H, Y) :- W = {t5}, !q(W, X), H = {t4}, p(X, Y)."),
        ] {
            let text = format!("{DECLS}{rule}\n");
            prop_assert_eq!(&run(&text, &p, &q, "r"), &want, "{}", text);
        }
    }
}

/// IEEE equality in a comparison: 0.0 = -0.0, whichever side binds the variable.
#[test]
fn a_float_comparison_with_negative_zero_holds_for_zero() {
    for body in [
        "a(x), x = -0.0",
        "x = -0.0, a(x)",
        "a(x), -0.0 = x",
        "a(x), x <= -0.0, x >= -0.0",
    ] {
        let text = format!(".decl a(x: float)\na(0.0).\n.decl b(x: float)\nb(x + 1) :- {body}.\n");
        let program = Arc::new(Program::parse_str("z.dl", &text).unwrap());
        let mut e = Engine::new(program, Options::default());
        e.run().unwrap();
        let got: Vec<f64> = e
            .relation("b")
            .unwrap()
            .into_iter()
            .map(|t| t[0].as_float().unwrap())
            .collect();
        assert_eq!(got, vec![1.0], "{body}");
    }
}
