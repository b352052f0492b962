//! Random small programs with recursion, negation and comparisons: the
//! interpreter's result equals a naive fixpoint computed here by enumerating
//! every variable assignment over the (small) domain.

use framewright::logic::{Engine, Options, Origin, Program, Value};
use proptest::prelude::*;
use std::collections::BTreeSet;
use std::sync::Arc;

const DOMAIN: i64 = 4;
const VARS: [&str; 4] = ["x", "y", "z", "w"];

#[derive(Clone, Debug)]
enum Term {
    Var(usize),
    Const(i64),
}

#[derive(Clone, Debug)]
enum Lit {
    Pos(usize, Vec<Term>),
    Neg(usize, Vec<Term>),
    Less(usize, usize),
    NotEq(usize, usize),
}

#[derive(Clone, Debug)]
struct Rule {
    head: usize,
    head_vars: Vec<usize>,
    body: Vec<Lit>,
}

/// Relations: 0, 1 are inputs (arity 2); 2.. are derived; arity by index.
fn arity(r: usize) -> usize {
    if r < 2 { 2 } else { 1 + r % 2 }
}
/// Negation may only look at strictly lower levels (keeps programs stratified).
fn level(r: usize) -> usize {
    if r < 2 { 0 } else { r - 1 }
}

struct Rng(u64);
impl Rng {
    fn next(&mut self, n: usize) -> usize {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        (self.0 % n as u64) as usize
    }
}

fn gen_program(seed: u64) -> (Vec<Rule>, Vec<(usize, i64, i64)>, usize) {
    let mut rng = Rng(seed | 1);
    let n_rel = 3 + rng.next(3);
    let mut rules = Vec::new();
    for _ in 0..2 + rng.next(5) {
        let head = 2 + rng.next(n_rel - 2);
        let mut body = Vec::new();
        let mut bound = BTreeSet::new();
        for _ in 0..1 + rng.next(3) {
            // Positive atoms: any relation up to the head's level (recursion allowed).
            let candidates: Vec<usize> = (0..n_rel).filter(|&r| level(r) <= level(head)).collect();
            let r = candidates[rng.next(candidates.len())];
            let args: Vec<Term> = (0..arity(r))
                .map(|_| {
                    if rng.next(6) == 0 {
                        Term::Const(rng.next(DOMAIN as usize) as i64)
                    } else {
                        Term::Var(rng.next(VARS.len()))
                    }
                })
                .collect();
            for a in &args {
                if let Term::Var(v) = a {
                    bound.insert(*v);
                }
            }
            body.push(Lit::Pos(r, args));
        }
        let bound: Vec<usize> = bound.into_iter().collect();
        if bound.is_empty() {
            continue;
        }
        if rng.next(2) == 0 {
            let lower: Vec<usize> = (0..n_rel).filter(|&r| level(r) < level(head)).collect();
            if !lower.is_empty() {
                let r = lower[rng.next(lower.len())];
                let args = (0..arity(r))
                    .map(|_| Term::Var(bound[rng.next(bound.len())]))
                    .collect();
                body.push(Lit::Neg(r, args));
            }
        }
        match rng.next(4) {
            0 => body.push(Lit::Less(
                bound[rng.next(bound.len())],
                bound[rng.next(bound.len())],
            )),
            1 => body.push(Lit::NotEq(
                bound[rng.next(bound.len())],
                bound[rng.next(bound.len())],
            )),
            _ => {}
        }
        let head_vars = (0..arity(head))
            .map(|_| bound[rng.next(bound.len())])
            .collect();
        rules.push(Rule {
            head,
            head_vars,
            body,
        });
    }
    let facts = (0..rng.next(10) + 2)
        .map(|_| {
            (
                rng.next(2),
                rng.next(DOMAIN as usize) as i64,
                rng.next(DOMAIN as usize) as i64,
            )
        })
        .collect();
    (rules, facts, n_rel)
}

fn term_text(t: &Term) -> String {
    match t {
        Term::Var(v) => VARS[*v].to_string(),
        Term::Const(c) => c.to_string(),
    }
}

fn program_text(rules: &[Rule], n_rel: usize) -> String {
    let mut s = String::new();
    for r in 0..n_rel {
        let attrs: Vec<String> = (0..arity(r)).map(|i| format!("a{i}: number")).collect();
        s.push_str(&format!(".decl r{r}({})\n", attrs.join(", ")));
    }
    for rule in rules {
        let head: Vec<&str> = rule.head_vars.iter().map(|v| VARS[*v]).collect();
        let body: Vec<String> = rule
            .body
            .iter()
            .map(|l| match l {
                Lit::Pos(r, a) => format!(
                    "r{r}({})",
                    a.iter().map(term_text).collect::<Vec<_>>().join(", ")
                ),
                Lit::Neg(r, a) => format!(
                    "!r{r}({})",
                    a.iter().map(term_text).collect::<Vec<_>>().join(", ")
                ),
                Lit::Less(a, b) => format!("{} < {}", VARS[*a], VARS[*b]),
                Lit::NotEq(a, b) => format!("{} != {}", VARS[*a], VARS[*b]),
            })
            .collect();
        s.push_str(&format!(
            "r{}({}) :- {}.\n",
            rule.head,
            head.join(", "),
            body.join(", ")
        ));
    }
    s
}

/// Level by level, apply every rule to every assignment until nothing changes.
fn naive(rules: &[Rule], facts: &[(usize, i64, i64)], n_rel: usize) -> Vec<BTreeSet<Vec<i64>>> {
    let mut rels: Vec<BTreeSet<Vec<i64>>> = vec![BTreeSet::new(); n_rel];
    for &(r, a, b) in facts {
        rels[r].insert(vec![a, b]);
    }
    let max_level = (0..n_rel).map(level).max().unwrap();
    for lv in 1..=max_level {
        loop {
            let mut new = Vec::new();
            for rule in rules.iter().filter(|r| level(r.head) == lv) {
                for code in 0..DOMAIN.pow(VARS.len() as u32) {
                    let env: Vec<i64> = (0..VARS.len())
                        .map(|i| (code / DOMAIN.pow(i as u32)) % DOMAIN)
                        .collect();
                    let val = |t: &Term| match t {
                        Term::Var(v) => env[*v],
                        Term::Const(c) => *c,
                    };
                    let holds = rule.body.iter().all(|l| match l {
                        Lit::Pos(r, a) => rels[*r].contains(&a.iter().map(val).collect::<Vec<_>>()),
                        Lit::Neg(r, a) => {
                            !rels[*r].contains(&a.iter().map(val).collect::<Vec<_>>())
                        }
                        Lit::Less(a, b) => env[*a] < env[*b],
                        Lit::NotEq(a, b) => env[*a] != env[*b],
                    });
                    if holds {
                        let t: Vec<i64> = rule.head_vars.iter().map(|v| env[*v]).collect();
                        if !rels[rule.head].contains(&t) {
                            new.push((rule.head, t));
                        }
                    }
                }
            }
            if new.is_empty() {
                break;
            }
            for (r, t) in new {
                rels[r].insert(t);
            }
        }
    }
    rels
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 300, ..ProptestConfig::default() })]
    #[test]
    fn interpreter_matches_naive_fixpoint(seed in any::<u64>()) {
        let (rules, facts, n_rel) = gen_program(seed);
        let text = program_text(&rules, n_rel);
        let program = Arc::new(Program::parse_str("random.dl", &text).unwrap_or_else(|e| panic!("{e}\n{text}")));
        for provenance in [false, true] {
            let mut e = Engine::new(program.clone(), Options { provenance, ..Options::default() });
            for &(r, a, b) in &facts {
                e.insert(&format!("r{r}"), vec![Value::Number(a), Value::Number(b)], Origin::Rust).unwrap();
            }
            e.run().unwrap();
            let want = naive(&rules, &facts, n_rel);
            for (r, w) in want.iter().enumerate() {
                let got: BTreeSet<Vec<i64>> = e.relation(&format!("r{r}")).unwrap().into_iter().map(|t| t.iter().map(|v| v.as_number().unwrap()).collect()).collect();
                prop_assert_eq!(&got, w, "relation r{} of\n{}", r, text);
            }
            // Every derived tuple has an explanation whose root is itself.
            if provenance {
                for r in 2..n_rel {
                    for t in e.relation(&format!("r{r}")).unwrap() {
                        let x = e.explain(&format!("r{r}"), &t).unwrap();
                        prop_assert_eq!(&x.tuple, &t);
                    }
                }
            }
        }
    }
}
