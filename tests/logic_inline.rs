//! `inline` relations (Soufflé's inlining): a relation declared `inline` gives every other
//! relation the same tuples as when it is computed, on generated programs (metamorphic, the
//! interpreter); inlining is what makes a selective use of a huge product answer at once;
//! Soufflé's restrictions on inline relations are errors naming them.

use framewright::logic::{Engine, Options, Program, Value};
use proptest::prelude::*;
use std::collections::BTreeMap;
use std::sync::Arc;

fn run(text: &str) -> BTreeMap<String, Vec<Vec<Value>>> {
    let program = Arc::new(Program::parse_str("p.dl", text).unwrap_or_else(|e| panic!("{e}")));
    let mut engine = Engine::new(program.clone(), Options::default());
    engine.run().unwrap_or_else(|e| panic!("{e}\n{text}"));
    program
        .relations
        .iter()
        .map(|r| (r.name.clone(), engine.relation(&r.name).unwrap()))
        .collect()
}

/// `q(x) :- pair(x, y), y = x + 1, x < 3.` where `pair` is the product of two 10 000-row
/// relations: inlined, the rule joins `n` with `n` on `y = x + 1` and never builds the 10^8
/// pairs. n = 0..9999, so q = {0, 1, 2} (x < 3, and x + 1 is in n).
#[test]
fn inline_product_used_selectively_answers() {
    let text = "
        .decl n(x: number)
        n(0).
        n(x + 1) :- n(x), x < 9999.
        .decl m(x: number)
        m(x) :- n(x).
        .decl pair(x: number, y: number) inline
        pair(x, y) :- n(x), m(y).
        .decl q(x: number)
        q(x) :- pair(x, y), y = x + 1, x < 3.
    ";
    let got = run(text);
    assert_eq!(got["n"].len(), 10_000);
    assert_eq!(
        got["q"],
        vec![
            vec![Value::Number(0)],
            vec![Value::Number(1)],
            vec![Value::Number(2)]
        ]
    );
    assert!(
        !got.contains_key("pair"),
        "an inline relation is not computed"
    );
}

fn refused(text: &str, what: &str) {
    let err = Program::parse_str("p.dl", text).expect_err("the program should be refused");
    let shown = err.to_string();
    assert!(shown.contains(what), "expected `{what}` in:\n{shown}");
}

#[test]
fn soufflé_restrictions_on_inline_relations_are_errors() {
    let base = ".decl e(x: number, y: number)\ne(1, 2).\n";
    refused(
        &format!("{base}.decl a(x: number) inline\na(x) :- e(x, _).\n.output a\n"),
        "IO relation `a` cannot be inlined",
    );
    refused(
        &format!("{base}.decl a(x: number) inline\na(x) :- e(x, _).\n.input a\n"),
        "IO relation `a` cannot be inlined",
    );
    refused(
        &format!(
            "{base}.decl a(x: number) inline\n.decl b(x: number) inline\na(x) :- b(x).\nb(x) :- a(x).\nb(x) :- e(x, _).\n"
        ),
        "cannot inline cyclically dependent relations {a, b}",
    );
    refused(
        &format!(
            "{base}.decl a(x: number) inline\na(x) :- e(x, _).\n.decl c(n: number)\nc(n) :- n = count : {{ a(_) }}.\n"
        ),
        "cannot inline relations that appear in an aggregate",
    );
    refused(
        &format!(
            "{base}.decl a(x: number) inline\na(x) :- e(x, y), y > 0.\n.decl c(x: number)\nc(x) :- e(x, _), !a(x).\n"
        ),
        "cannot inline negated relation `a` which may introduce new variables",
    );
    refused(
        &format!(
            "{base}.decl a(x: number, y: number) inline\na(x, y) :- e(x, y).\n.decl c(x: number)\nc(x) :- e(x, _), !a(x, _).\n"
        ),
        "cannot inline negated atom containing an unnamed variable",
    );
    refused(
        &format!("{base}.decl a(x: number, y: number) inline\na(autoinc(), y) :- e(_, y).\n"),
        "cannot inline a clause containing `autoinc()`",
    );
    refused(
        &format!(
            "{base}.decl a(x: number, y: number) inline\na(x, y) :- e(x, y).\n.decl c(x: number)\nc(x) :- e(x, _), a(x, autoinc()).\n"
        ),
        "cannot inline a literal containing `autoinc()`",
    );
    refused(
        &format!("{base}.decl q(x: number, y: number) eqrel inline\nq(x, y) :- e(x, y).\n"),
        "`eqrel` relation `q` cannot be inlined",
    );
    // An inline relation recursive through a computed one is fine (Soufflé: only cycles made
    // of inline relations alone are refused): t(x, z) :- e(x, y), t(y, z) through `step`.
    let text = format!(
        "{base}e(2, 3).\n.decl step(x: number, y: number) inline\n.decl t(x: number, y: number)\nstep(x, z) :- e(x, y), t(y, z).\nt(x, y) :- e(x, y).\nt(x, z) :- step(x, z).\n"
    );
    let t: Vec<Vec<i64>> = run(&text)["t"]
        .iter()
        .map(|r| r.iter().map(|v| v.as_number().unwrap()).collect())
        .collect();
    assert_eq!(t, vec![vec![1, 2], vec![1, 3], vec![2, 3]]);
}

/// A generated program: inputs `e0`, `e1` (facts), derived `r2`..`r5` each defined by a few
/// rules over relations with a lower index (sometimes itself: recursion), with negations of
/// lower relations, comparisons, head constants and expressions, and facts.
struct Gen(u64);
impl Gen {
    fn next(&mut self, n: usize) -> usize {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        (self.0 % n as u64) as usize
    }
}

const VARS: [&str; 4] = ["x", "y", "z", "w"];

fn arity(r: usize) -> usize {
    if r < 2 { 2 } else { 1 + r % 2 }
}

fn program(seed: u64) -> String {
    let mut g = Gen(seed | 1);
    let mut out = String::new();
    for r in 0..6 {
        let attrs: Vec<String> = (0..arity(r)).map(|i| format!("a{i}: number")).collect();
        out.push_str(&format!(".decl r{r}({})\n", attrs.join(", ")));
    }
    for r in 0..2 {
        for _ in 0..2 + g.next(6) {
            out.push_str(&format!("r{r}({}, {}).\n", g.next(4), g.next(4)));
        }
    }
    for head in 2..6 {
        for _ in 0..1 + g.next(3) {
            if g.next(6) == 0 {
                let args: Vec<String> = (0..arity(head)).map(|_| g.next(4).to_string()).collect();
                out.push_str(&format!("r{head}({}).\n", args.join(", ")));
                continue;
            }
            let mut body = Vec::new();
            let mut bound: Vec<usize> = Vec::new();
            for _ in 0..1 + g.next(3) {
                // Recursion only on the head itself, and not as the first atom.
                let r = if !body.is_empty() && g.next(8) == 0 {
                    head
                } else {
                    g.next(head)
                };
                let args: Vec<String> = (0..arity(r))
                    .map(|_| match g.next(8) {
                        0 => g.next(4).to_string(),
                        1 => "_".to_string(),
                        _ => {
                            let v = g.next(VARS.len());
                            if !bound.contains(&v) {
                                bound.push(v);
                            }
                            VARS[v].to_string()
                        }
                    })
                    .collect();
                body.push(format!("r{r}({})", args.join(", ")));
            }
            if bound.is_empty() {
                continue;
            }
            let pick = |g: &mut Gen| VARS[bound[g.next(bound.len())]];
            for _ in 0..g.next(3) {
                match g.next(4) {
                    0 => {
                        let r = g.next(head);
                        let args: Vec<String> = (0..arity(r))
                            .map(|_| {
                                if g.next(10) == 0 {
                                    "_".to_string()
                                } else {
                                    pick(&mut g).to_string()
                                }
                            })
                            .collect();
                        body.push(format!("!r{r}({})", args.join(", ")));
                    }
                    1 => {
                        let (a, b) = (pick(&mut g), pick(&mut g));
                        body.push(format!("{a} < {b}"));
                    }
                    2 => {
                        let a = pick(&mut g);
                        body.push(format!("{a} != {}", g.next(4)));
                    }
                    _ => {
                        let a = pick(&mut g);
                        body.push(format!("{a} <= 2"));
                    }
                }
            }
            let head_args: Vec<String> = (0..arity(head))
                .map(|_| match g.next(10) {
                    0 => g.next(4).to_string(),
                    // A head expression: bounded, so recursion through it stops.
                    1 => format!("({} + 1) % 4", pick(&mut g)),
                    _ => pick(&mut g).to_string(),
                })
                .collect();
            out.push_str(&format!(
                "r{head}({}) :- {}.\n",
                head_args.join(", "),
                body.join(", ")
            ));
        }
    }
    out
}

fn with_inline(text: &str, rel: usize) -> String {
    let decl = format!(".decl r{rel}(");
    text.lines()
        .map(|l| {
            if l.starts_with(&decl) {
                format!("{l} inline\n")
            } else {
                format!("{l}\n")
            }
        })
        .collect()
}

fn try_run(text: &str) -> Result<BTreeMap<String, Vec<Vec<Value>>>, String> {
    let program = Arc::new(Program::parse_str("p.dl", text).map_err(|e| e.to_string())?);
    let mut engine = Engine::new(program.clone(), Options::default());
    engine.run().map_err(|e| e.to_string())?;
    Ok(program
        .relations
        .iter()
        .map(|r| (r.name.clone(), engine.relation(&r.name).unwrap()))
        .collect())
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 3000, ..ProptestConfig::default() })]
    #[test]
    fn declaring_a_relation_inline_keeps_every_other_answer(seed in any::<u64>(), pick in 2usize..6) {
        let text = program(seed);
        // Programs outside the subset (ungrounded, unstratified) are not the question here.
        let Ok(plain) = try_run(&text) else { return Ok(()); };
        let inlined_text = with_inline(&text, pick);
        match try_run(&inlined_text) {
            Ok(inlined) => {
                let name = format!("r{pick}");
                prop_assert!(!inlined.contains_key(&name));
                for (rel, tuples) in &plain {
                    if rel != &name {
                        prop_assert_eq!(tuples, &inlined[rel], "relation {} of\n{}", rel, inlined_text);
                    }
                }
            }
            // Soufflé's restrictions (a cycle through the relation itself, negated uses that
            // bind variables or hold `_`) are the only acceptable refusals.
            Err(e) => prop_assert!(
                e.contains("cannot inline"),
                "unexpected error {}\n{}", e, inlined_text
            ),
        }
    }
}
