//! Slices of a program: the relations downstream of others and the rules that derive them.

use super::super::load_str;
use std::collections::BTreeSet;

const TEXT: &str = r#"
.decl seed(x: symbol)
.input seed
.decl other(x: symbol)
.input other
.decl a(x: symbol)
.decl b(x: symbol)
.decl c(x: symbol)
.decl d(x: symbol)
.output d
a(x) :- seed(x).
b(x) :- a(x).
c(x) :- other(x).
b(x) :- c(x).
d(x) :- c(x), !b(x).
"#;

#[test]
fn downstream_follows_atoms_and_negations_transitively() {
    let program = load_str("slice.dl", TEXT, &[]).expect("program");
    let reached = program.downstream_of(&["seed"]);
    let names: BTreeSet<&str> = reached.iter().map(String::as_str).collect();
    // c reads only `other`; d reads b through a negation.
    assert_eq!(names, BTreeSet::from(["seed", "a", "b", "d"]));
}

#[test]
fn a_slice_keeps_every_rule_of_its_heads_and_reads_the_rest() {
    let program = load_str("slice.dl", TEXT, &[]).expect("program");
    let slice = program.restricted_to(&program.downstream_of(&["seed"]));
    let heads: Vec<&str> = slice.rules.iter().map(|r| r.head.rel.as_str()).collect();
    // Both rules for b stay, the one from c included; c's own rule goes.
    assert_eq!(heads, ["a", "b", "b", "d"]);
    let in_strata: usize = slice.strata.iter().map(|s| s.rules.len()).sum();
    assert_eq!(in_strata, 4, "every kept rule sits in its stratum");
    let read: BTreeSet<String> = slice.relations_read();
    let read: BTreeSet<&str> = read.iter().map(String::as_str).collect();
    assert_eq!(read, BTreeSet::from(["seed", "a", "b", "c"]));
}
