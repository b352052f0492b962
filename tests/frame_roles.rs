//! Wall partition and piece roles from the built-in rule base against every
//! truth model, and the compiled and interpreted engines against each other.

mod frame_truth;

use frame_truth::{Case, by_piece, members, own_cases, reasoned, shared_cases, sym, text, walls};
use framewright::frame::RuleEngine;
use std::collections::{BTreeMap, BTreeSet};

/// Walls as sets of pieces, from the rule base and from the truth, must be equal;
/// every member's role must equal the truth's; every wall piece has one role.
fn check_walls_and_roles(case: &Case) {
    let r = reasoned(case, &RuleEngine::Compiled);
    let mut ours: BTreeMap<&str, BTreeSet<&str>> = BTreeMap::new();
    for t in r.get("wall_of") {
        ours.entry(sym(&t[1])).or_default().insert(sym(&t[0]));
    }
    let ours: BTreeSet<BTreeSet<&str>> = ours.into_values().collect();
    let theirs: BTreeSet<BTreeSet<&str>> = walls(&case.truth)
        .iter()
        .map(|w| {
            frame_truth::list(w, "member_global_ids")
                .iter()
                .map(text)
                .collect()
        })
        .collect();
    assert!(
        ours == theirs,
        "{}: the wall partition differs from the truth",
        case.name
    );

    let roles = by_piece(&r, "role");
    let in_wall: BTreeSet<&str> = r.get("wall_of").iter().map(|t| sym(&t[0])).collect();
    let with_role: BTreeSet<&str> = roles.keys().copied().collect();
    assert_eq!(
        in_wall, with_role,
        "{}: wall pieces without a role",
        case.name
    );
    let mut wrong = Vec::new();
    for m in members(&case.truth) {
        let gid = text(&m["global_id"]);
        let want = text(&m["role"]);
        let got = roles.get(gid).map_or("(none)", |v| sym(v));
        if got != want {
            wrong.push(format!("{gid} {} is {got}, truth {want}", m["name"]));
        }
    }
    assert!(
        wrong.is_empty(),
        "{}: {} wrong roles:\n{}",
        case.name,
        wrong.len(),
        wrong.join("\n")
    );
    let warnings: Vec<String> = r
        .get("frame_warning")
        .iter()
        .map(|t| format!("{}: {}", t[0], t[1]))
        .collect();
    assert!(warnings.is_empty(), "{}: {warnings:?}", case.name);
}

#[test]
fn shared_models_walls_and_roles_match_the_truth() {
    let Some(cases) = shared_cases() else { return };
    for case in &cases {
        check_walls_and_roles(case);
    }
}

#[test]
fn own_models_walls_and_roles_match_the_truth() {
    for case in &own_cases() {
        check_walls_and_roles(case);
    }
}

/// Every relation of the rule base is identical on both engines.
fn check_engines_agree(case: &Case) {
    let compiled = reasoned(case, &RuleEngine::Compiled);
    let interpreted = reasoned(case, &RuleEngine::Interpreted);
    let names: BTreeSet<&String> = compiled
        .relations
        .keys()
        .chain(interpreted.relations.keys())
        .collect();
    assert!(
        names.len() > 40,
        "{}: only {} relations",
        case.name,
        names.len()
    );
    for name in names {
        if compiled.get(name) != interpreted.get(name) {
            for (a, b) in compiled.get(name).iter().zip(interpreted.get(name)) {
                if a != b {
                    eprintln!("{name}: {a:?} vs {b:?}");
                }
            }
        }
        assert!(
            compiled.get(name) == interpreted.get(name),
            "{}: relation {name} differs ({} compiled tuples, {} interpreted)",
            case.name,
            compiled.get(name).len(),
            interpreted.get(name).len()
        );
    }
}

/// The 4020-piece model is left to the compiled-vs-truth tests: the
/// interpreter is too slow on it for a test run.
const INTERPRETER_PIECE_LIMIT: usize = 500;

#[test]
fn shared_models_same_relations_on_both_engines() {
    let Some(cases) = shared_cases() else { return };
    for case in &cases {
        if members(&case.truth).len() > INTERPRETER_PIECE_LIMIT {
            eprintln!("{}: engines compared on the smaller models only", case.name);
            continue;
        }
        check_engines_agree(case);
    }
}

#[test]
fn own_models_same_relations_on_both_engines() {
    for case in &own_cases() {
        check_engines_agree(case);
    }
}

/// For iterating on rules without a rebuild: `RULES_DIR=dir DUMP=model.ifc RELS=a,b`.
#[test]
fn dump() {
    let Ok(f) = std::env::var("DUMP") else { return };
    let engine = std::env::var("RULES_DIR")
        .map_or(RuleEngine::Compiled, |d| RuleEngine::Directory(d.into()));
    let case = Case {
        name: f.clone(),
        ifc: f.into(),
        truth: serde_json::Value::Null,
    };
    let r = reasoned(&case, &engine);
    for rel in std::env::var("RELS").unwrap_or_default().split(',') {
        for t in r.get(rel) {
            let s: Vec<String> = t.iter().map(|v| format!("{v}")).collect();
            println!("{rel}({})", s.join(", "));
        }
    }
}
