//! Explanations: derivation trees of minimal height with rule labels and input
//! origins; why-not names the first failing literal and the closest candidates.

use framewright::logic::provenance::{Failure, How, Premise};
use framewright::logic::{Engine, Options, Origin, Program, Value};
use std::sync::Arc;

const PROG: &str = "\
.decl edge(x: number, y: number)
.decl blocked(x: number)
.decl path(x: number, y: number)
// @rule base
path(x, y) :- edge(x, y), !blocked(y).
// @rule step
path(x, z) :- path(x, y), edge(y, z), !blocked(z).
.decl far(x: number, y: number)
// @rule far
far(x, y) :- path(x, y), x + 2 < y.
";

fn n(v: i64) -> Value {
    Value::Number(v)
}

fn engine(provenance: bool) -> Engine {
    let p = Arc::new(Program::parse_str("prov.dl", PROG).unwrap());
    let mut e = Engine::new(
        p,
        Options {
            provenance,
            ..Options::default()
        },
    );
    // A long way round 1-2-3-4-5 and a shortcut 1-5; 6 is blocked.
    for (i, (a, b)) in [(1, 2), (2, 3), (3, 4), (4, 5), (1, 5), (5, 6)]
        .into_iter()
        .enumerate()
    {
        e.insert("edge", vec![n(a), n(b)], Origin::Entity(100 + i as u64))
            .unwrap();
    }
    e.insert(
        "blocked",
        vec![n(6)],
        Origin::File {
            file: "blocked.facts".into(),
            line: 1,
        },
    )
    .unwrap();
    e.run().unwrap();
    e
}

#[test]
fn explain_gives_a_minimal_height_tree_with_origins() {
    let e = engine(true);
    let x = e.explain("path", &[n(1), n(5)]).unwrap();
    // The shortcut (height 1) wins over the long way (height 4).
    let How::Rule {
        rule,
        label,
        height,
        premises,
        ..
    } = &x.how
    else {
        panic!("derived tuple")
    };
    assert_eq!(label.as_deref(), Some("base"));
    assert_eq!(rule, "base (prov.dl:5)");
    assert_eq!(*height, 1);
    assert_eq!(premises.len(), 2);
    let Premise::Tuple(edge) = &premises[0] else {
        panic!()
    };
    assert!(matches!(
        edge.how,
        How::Input {
            origin: Origin::Entity(104)
        }
    ));
    assert!(matches!(&premises[1], Premise::Absent { atom } if atom == "!blocked(5)"));

    let x = e.explain("far", &[n(1), n(4)]).unwrap();
    let text = x.render();
    assert!(
        text.starts_with("far(1, 4)  [by far (prov.dl:10)]"),
        "{text}"
    );
    assert!(text.contains("path(1, 3)  [by step (prov.dl:7)]"), "{text}");
    assert!(text.contains("edge(1, 2)  [input: IFC #100]"), "{text}");
    assert!(
        text.contains("((1 + 2) < 4)") || text.contains("1 + 2) < 4"),
        "{text}"
    );
    let json = serde_json::to_string(&x).unwrap();
    assert!(
        json.contains("\"kind\":\"rule\"") && json.contains("\"Entity\":100"),
        "{json}"
    );
}

#[test]
fn explain_needs_provenance_and_a_present_tuple() {
    let e = engine(false);
    assert!(
        e.explain("path", &[n(1), n(5)])
            .unwrap_err()
            .to_string()
            .contains("provenance")
    );
    let e = engine(true);
    assert!(
        e.explain("path", &[n(5), n(1)])
            .unwrap_err()
            .to_string()
            .contains("does not hold")
    );
    assert!(e.explain("path", &[n(5)]).is_err());
    assert!(e.explain("nope", &[n(5)]).is_err());
}

#[test]
fn why_not_names_the_failing_literal_and_candidates() {
    let e = engine(false);
    let w = e.explain_not("path", &[n(1), n(6)]).unwrap();
    assert_eq!(w.rules.len(), 2);
    assert!(matches!(&w.rules[0].failure, Failure::NoMatch { atom, .. } if atom == "edge(1, 6)"));
    match &w.rules[1].failure {
        Failure::NegationHolds { atom, existing } => {
            assert_eq!(atom, "!blocked(6)");
            assert_eq!(existing, &vec![n(6)]);
        }
        other => panic!("{other:?}"),
    }
    let w = e.explain_not("path", &[n(5), n(1)]).unwrap();
    match &w.rules[0].failure {
        Failure::NoMatch {
            atom,
            candidates,
            relation_size,
        } => {
            assert_eq!(atom, "edge(5, 1)");
            assert_eq!(*relation_size, 6);
            // Closest first: tuples that agree on a bound column.
            assert!(
                candidates[0] == vec![n(1), n(2)]
                    || candidates[0][0] == n(5)
                    || candidates[0][1] == n(1),
                "{candidates:?}"
            );
        }
        other => panic!("{other:?}"),
    }
    let w = e.explain_not("far", &[n(2), n(3)]).unwrap();
    assert!(
        matches!(&w.rules[0].failure, Failure::ConditionFalse { example, .. } if example.contains("2 + 2") && example.contains("3")),
        "{:?}",
        w.rules[0].failure
    );
    let text = w.render();
    assert!(
        text.contains("far(2, 3) is not derived") && text.contains("condition"),
        "{text}"
    );
    let w = e.explain_not("edge", &[n(9), n(9)]).unwrap();
    assert!(w.reason.unwrap().contains("no rule"));
    assert!(
        e.explain_not("path", &[n(1), n(2)])
            .unwrap_err()
            .to_string()
            .contains("holds")
    );
}
