//! Bad rule programs are rejected with file:line:col, the source line, a caret,
//! what is wrong and a hint; runtime errors name the rule and the values.

use framewright::logic::{Engine, Limits, LogicError, Options, Program};
use std::sync::Arc;

const DECLS: &str =
    ".decl e(x: number, y: number)\n.decl p(x: number, y: number)\n.decl s(n: symbol)\n";

/// Check `body` (appended after DECLS) fails at `line:col` with a message containing `what`.
fn fails(body: &str, line: u32, col: u32, what: &str) -> String {
    let text = format!("{DECLS}{body}");
    let err = Program::parse_str("prog.dl", &text).expect_err("program should be rejected");
    let d = &err.0[0];
    let shown = err.to_string();
    assert!(d.message.contains(what), "expected `{what}` in:\n{shown}");
    assert_eq!((d.line, d.col), (line, col), "position of:\n{shown}");
    assert!(
        shown.starts_with(&format!("prog.dl:{line}:{col}: error: ")),
        "{shown}"
    );
    assert!(shown.contains('^') && shown.contains("hint: "), "{shown}");
    assert!(!d.hint.is_empty());
    shown
}

#[test]
fn syntax_errors() {
    fails("p(x, y) :- e(x, y)\n", 5, 1, "expected `.`");
    fails("p(x, y) :- e(x y).\n", 4, 16, "expected `)`");
    fails("p(x, y) :- e(x, \"y).\n", 4, 17, "unterminated string");
    fails("#include \"x.dl\"\n", 4, 1, "preprocessor");
    // A string may hold line breaks (as in Soufflé): what follows it is placed by the
    // lines it spans.
    fails("p(x, y) :- e(x, y), x = \"a\nb\" y.\n", 5, 4, "expected");
}

#[test]
fn unknown_relation_and_arity() {
    let s = fails("p(x, y) :- ee(x, y).\n", 4, 12, "unknown relation `ee`");
    assert!(s.contains("did you mean `e`"), "{s}");
    fails(
        "p(x, y) :- e(x, y, 1).\n",
        4,
        12,
        "2 attribute(s) but is used with 3",
    );
    fails(".output q\n", 4, 9, "unknown relation `q`");
}

#[test]
fn type_errors() {
    fails("p(x, y) :- e(x, y), s(x).\n", 4, 23, "type mismatch");
    fails("s(x) :- e(x, _).\n", 4, 11, "type mismatch");
    fails("p(x, y) :- e(x, y), y = \"a\".\n", 4, 25, "type mismatch");
    fails(
        ".type A <: symbol\n.type B <: symbol\n.decl a(x: A)\n.decl b(x: B)\na(x) :- b(x).\n",
        8,
        11,
        "neither is a subtype",
    );
    fails(".decl q(x: nubmer)\n", 4, 9, "unknown type `nubmer`");
}

#[test]
fn groundedness() {
    fails(
        "p(x, y) :- e(x, _).\n",
        4,
        6,
        "variable `y` in the head is not grounded",
    );
    fails(
        "p(x, y) :- e(x, x), !e(y, x).\n",
        4,
        22,
        "variable `y` is not grounded",
    );
    fails(
        "p(x, y) :- e(x, x), y < x.\n",
        4,
        23,
        "variable `y` is not grounded",
    );
}

// Found by fuzzing: a `_` inside an expression passed the checker and reached the
// interpreter, which has no value for it. Soufflé rejects these too ("Underscore in
// head of rule", "Underscore in binary relation"); a `_` as a whole atom argument stays.
#[test]
fn wildcards_stand_only_for_whole_atom_arguments() {
    let what = "`_` inside an expression";
    fails("p(_ + 1, y) :- e(_, y).\n", 4, 3, what);
    fails("p(x, y) :- e(x, y), x % 2 = _.\n", 4, 29, what);
    fails("p(x, y) :- e(x, y), y = _ + 1.\n", 4, 25, what);
    fails("p(x, y) :- e(x, y), e(_ - 1, x).\n", 4, 23, what);
    fails("s(n) :- s(n), match(\"a.*\", _).\n", 4, 28, what);
    fails("s(n) :- s(n), !contains(_, n).\n", 4, 25, what);
    fails("p(1, _ + 2).\n", 4, 6, what);
    fails(
        "p(x, m) :- e(x, _), m = min _ + y : { e(a, y), a != x }.\n",
        4,
        29,
        what,
    );
    fails("s(to_string(_)) :- e(_, _).\n", 4, 13, what);
    // Whole arguments of body atoms, negated atoms and aggregate bodies still read.
    Program::parse_str(
        "w.dl",
        &format!("{DECLS}p(x, y) :- e(x, _), e(_, y), !e(y, _), y = count : {{ e(_, x) }}.\n"),
    )
    .unwrap_or_else(|e| panic!("{e}"));
}

#[test]
fn negation_and_aggregation_cycles_name_the_cycle() {
    let s = fails(
        "p(x, y) :- e(x, y), !p(y, x).\n",
        4,
        22,
        "inside a recursive cycle: p -> p",
    );
    assert!(s.contains("stratifiable"), "{s}");
    let s = fails(
        ".decl a(x: number)\n.decl b(x: number)\na(x) :- e(x, _), !b(x).\nb(x) :- a(x).\n",
        6,
        19,
        "a -> b -> a",
    );
    assert!(s.contains("negation or aggregation of `b`"), "{s}");
    fails(
        ".decl c(n: number)\nc(n) :- c(m), n = count : { c(m) }.\n",
        5,
        29,
        "recursive cycle",
    );
}

#[test]
fn unknown_functors() {
    let s = fails(
        ".decl f(x: float)\nf(@distt(@vec3(1.0, 2.0, 3.0), @vec3(0.0, 0.0, 0.0))).\n",
        5,
        3,
        "unknown functor `@distt`",
    );
    assert!(s.contains("did you mean `@dist`"), "{s}");
    fails(
        "p(x, y) :- e(x, y), y = foo(x).\n",
        4,
        25,
        "unknown functor `foo`",
    );
    fails(
        ".decl f(x: float)\nf(@dist(1.0)).\n",
        5,
        3,
        "takes 2 argument(s)",
    );
}

#[test]
fn unsupported_soufflé_features_are_named() {
    fails(
        ".type R = [a: number, b: number]\n",
        4,
        11,
        "record types are not supported",
    );
    fails(
        ".type T = A {x: number} | B {}\n",
        4,
        13,
        "algebraic data types are not supported",
    );
    fails(
        ".comp C { }\n",
        4,
        1,
        "components (`.comp`) is not supported",
    );
    fails(".init c = C\n", 4, 1, "component instances");
    fails("p(x, y) <= p(x, z) :- y < z.\n", 4, 9, "subsumption");
    fails(".decl c(x: number) choice-domain x\n", 4, 20, "choice");
    fails(
        ".type U = number | symbol\n",
        4,
        7,
        "union type `U` mixes number and symbol members",
    );
    fails(
        ".functor f(number): number\n",
        4,
        1,
        "user-defined functors",
    );
    fails("p(x, y) :- e(x, y), x = $.\n", 4, 25, "`$`");
    fails(
        ".decl q(x: number) eqrel\n",
        4,
        20,
        "an `eqrel` relation has two attributes",
    );
    fails("p(x, y) :- e(x, y), x = y band 1.\n", 4, 27, "bitwise");
}

#[test]
fn an_aggregate_cannot_export_a_binding() {
    // The witness problem: Soufflé exports witnesses of min and max only ("Witness problem:
    // argument grounded by an aggregator's inner scope is used ungrounded in outer scope in a
    // count/sum/mean aggregate").
    for op in ["sum x", "count"] {
        fails(
            &format!(
                ".decl family(name: symbol, age: number)\n.decl total(name: symbol, age: number)\ntotal(p, n) :- n = {op} : family(p, x).\n"
            ),
            6,
            18,
            "variable `p` is grounded only inside the aggregate",
        );
    }
}

#[test]
fn include_errors_point_at_the_directive() {
    fails(
        ".include \"no/such/file.dl\"\n",
        4,
        10,
        "cannot read rule file",
    );
}

fn run_err(text: &str, limits: Limits) -> LogicError {
    let p = Arc::new(Program::parse_str("rt.dl", text).unwrap_or_else(|e| panic!("{e}")));
    let mut e = Engine::new(
        p,
        Options {
            provenance: false,
            limits,
        },
    );
    e.run().expect_err("run should fail")
}

#[test]
fn runtime_errors_name_the_rule_and_the_values() {
    let err = run_err(
        ".decl a(x: number)\na(0). a(4).\n.decl b(x: number)\n// @rule ratio\nb(8 / x) :- a(x).\n",
        Limits::default(),
    );
    let s = err.to_string();
    assert!(
        s.contains("division by zero") && s.contains("ratio (rt.dl:5)") && s.contains("x = 0"),
        "{s}"
    );
    let err = run_err(
        ".decl a(x: symbol)\na(\"12\"). a(\"twelve\").\n.decl b(x: number)\nb(to_number(x)) :- a(x).\n",
        Limits::default(),
    );
    let s = err.to_string();
    assert!(
        s.contains("to_number(\"twelve\")")
            && s.contains("rt.dl:4")
            && s.contains("x = \"twelve\""),
        "{s}"
    );
}

#[test]
fn unbounded_value_creation_is_stopped_by_the_limits() {
    let prog = ".decl n(x: number)\nn(0).\n// @rule succ\nn(x + 1) :- n(x).\n";
    let err = run_err(
        prog,
        Limits {
            max_tuples: 1_000_000,
            max_iterations: 500,
            ..Limits::default()
        },
    );
    let s = err.to_string();
    assert!(matches!(err, LogicError::Limit { .. }), "{s}");
    assert!(
        s.contains("succ (rt.dl:4)") && s.contains("500 iterations") && s.contains("x < 100"),
        "{s}"
    );
    let err = run_err(
        prog,
        Limits {
            max_tuples: 300,
            max_iterations: 100_000,
            ..Limits::default()
        },
    );
    assert!(err.to_string().contains("more than 300 tuples"), "{err}");
}

fn limits(max_tuples: usize, max_steps: u64) -> Limits {
    Limits {
        max_tuples,
        max_steps,
        ..Limits::default()
    }
}

/// 300 numbers, then a rule over their pairs or triples.
fn product_program(rule: &str) -> String {
    format!(
        ".decl a(x: number)\na(0).\na(x + 1) :- a(x), x < 299.\n.decl b(x: number, y: number)\n.decl c(x: number)\n// @rule product\n{rule}\n"
    )
}

// A join that derives 300 tuples from 300^3 body combinations: only the work bound stops it.
#[test]
fn a_join_that_works_without_deriving_is_stopped_by_the_step_limit() {
    let prog = product_program("c(x) :- a(x), a(y), a(z), y != z.");
    let err = run_err(&prog, limits(1_000_000, 1_000_000));
    let s = err.to_string();
    assert!(matches!(err, LogicError::Limit { .. }), "{s}");
    assert!(
        s.contains("more than 1000000 body tuples visited")
            && s.contains("product (rt.dl:7)")
            && s.contains("--max-steps"),
        "{s}"
    );
    // The same join with room to finish: 300 + 300^2 + 300^3 visits.
    let p = Arc::new(Program::parse_str("rt.dl", &prog).unwrap());
    let mut e = Engine::new(
        p,
        Options {
            provenance: false,
            limits: limits(1_000_000, 28_000_000),
        },
    );
    e.run().unwrap();
    assert_eq!(e.len("c").unwrap(), 300);
}

// 90,000 new pairs in one evaluation of one rule: stopped as they pass the limit, not after.
#[test]
fn the_tuple_limit_stops_a_rule_in_the_middle_of_its_evaluation() {
    let err = run_err(
        &product_program("b(x, y) :- a(x), a(y)."),
        limits(1_000, u64::MAX),
    );
    let s = err.to_string();
    assert!(
        s.contains("more than 1000 tuples") && s.contains("product (rt.dl:7)"),
        "{s}"
    );
}

// A string that doubles every iteration needs 2^k bytes: refused past 1 MiB, with the
// bindings in the message cut to a readable length.
#[test]
fn a_runaway_concatenation_stops_at_the_symbol_limit() {
    let err = run_err(
        ".decl s(x: symbol)\ns(\"ab\").\n// @rule grow\ns(cat(x, x)) :- s(x).\n",
        Limits::default(),
    );
    let s = err.to_string();
    assert!(
        s.contains("grow (rt.dl:4)") && s.contains("more than the limit of 1048576 bytes"),
        "{s}"
    );
    assert!(s.len() < 2_000, "{} bytes: {}", s.len(), &s[..2_000]);
}

#[test]
fn unknown_string_escapes_are_refused_as_soufflé_refuses_them() {
    // Soufflé's lexer knows \" \' \\ \a \b \f \n \r \t \v; "Unknown escape sequence \d"
    // otherwise (a pattern's `\d` is written `\\d`). The error points at the backslash.
    fails("s(\"a\\d\").\n", 4, 5, "unknown escape sequence `\\d`");
}

#[test]
fn autoinc_is_refused_where_soufflé_refuses_it() {
    // Soufflé: "Argument in fact is not constant" and "Auto-increment functor in a recursive rule".
    fails("e(autoinc(), 1).\n", 4, 1, "`autoinc()` in a fact");
    fails(
        "p(1, 2).\np(x, autoinc()) :- p(x, y), y < 10.\n",
        5,
        1,
        "`autoinc()` in a recursive rule",
    );
    fails(
        "p(x, y) :- e(x, y), x = autoinc(1).\n",
        4,
        25,
        "takes 0 argument(s)",
    );
}

// Counting to 10^6 one step at a time takes 10^6 iterations of one stratum: a long program,
// not a runaway one, so the default limits (no iteration bound, as in Soufflé) let it finish
// with n = 0, 1, ..., 1000000: 1,000,001 rows.
#[test]
fn a_long_count_runs_to_its_end_under_the_default_limits() {
    let p = Arc::new(
        Program::parse_str(
            "count.dl",
            ".decl n(x: number)\nn(0).\nn(x + 1) :- n(x), x < 1000000.\n",
        )
        .unwrap(),
    );
    let mut e = Engine::new(p, Options::default());
    e.run().unwrap();
    assert_eq!(e.len("n").unwrap(), 1_000_001);
}
