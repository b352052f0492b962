//! Nailing targets from the built-in rule base against every truth model:
//! the same count, and every target of the truth (primary and secondary)
//! matched by one of ours within 0.5 mm in wall coordinates and in world.

mod frame_truth;

use frame_truth::{Case, float, list, number, own_cases, reasoned, shared_cases, sym, text, walls};
use framewright::frame::RuleEngine;
use framewright::logic::Value;

const TOLERANCE: f64 = 0.0005;

struct Nail {
    plate: String,
    member: String,
    kind: String,
    local: [f64; 3],
    world: [f64; 3],
    direction: [f64; 3],
}

fn vec3(v: &Value) -> [f64; 3] {
    match v {
        Value::Vec3(v) => [v.0.x, v.0.y, v.0.z],
        other => panic!("not a vec3: {other}"),
    }
}

fn json3(v: &serde_json::Value) -> [f64; 3] {
    let a = v.as_array().expect("a point");
    [0, 1, 2].map(|i| number(&a[i]))
}

fn close(a: [f64; 3], b: [f64; 3], tol: f64) -> bool {
    (0..3).all(|i| (a[i] - b[i]).abs() <= tol)
}

fn check_nailing(case: &Case) {
    let r = reasoned(case, &RuleEngine::Compiled);
    let mut ours: Vec<Option<Nail>> = r
        .get("nailing_target")
        .iter()
        .map(|t| {
            Some(Nail {
                plate: sym(&t[0]).to_string(),
                member: sym(&t[1]).to_string(),
                kind: sym(&t[2]).to_string(),
                local: [float(&t[3]), float(&t[4]), float(&t[5])],
                world: vec3(&t[6]),
                direction: vec3(&t[7]),
            })
        })
        .collect();
    let theirs: Vec<&serde_json::Value> = walls(&case.truth)
        .iter()
        .flat_map(|w| {
            list(w, "nailing_targets")
                .iter()
                .chain(list(w, "secondary_nailing_targets"))
        })
        .collect();
    assert_eq!(
        ours.len(),
        theirs.len(),
        "{}: number of nailing targets",
        case.name
    );
    for t in theirs {
        let local = [number(&t["u"]), number(&t["v"]), number(&t["w"])];
        let world = json3(&t["world"]);
        let direction = json3(&t["direction_world"]);
        let found = ours.iter_mut().find(|n| {
            n.as_ref().is_some_and(|n| {
                n.plate == text(&t["plate"])
                    && n.member == text(&t["member"])
                    && n.kind == text(&t["kind"])
                    && close(n.local, local, TOLERANCE)
            })
        });
        let n = found
            .and_then(Option::take)
            .unwrap_or_else(|| {
                let same_pair: Vec<([f64; 3], [f64; 3])> = ours
                    .iter()
                    .flatten()
                    .filter(|n| n.plate == text(&t["plate"]) && n.member == text(&t["member"]))
                    .map(|n| (n.local, n.world))
                    .collect();
                panic!(
                    "{}: no nailing target matches {t}; ours for this pair (u, v, w; world): {same_pair:?}",
                    case.name
                )
            });
        assert!(
            close(n.world, world, TOLERANCE),
            "{}: world {:?} vs {t}",
            case.name,
            n.world
        );
        assert!(
            close(n.direction, direction, 1e-6),
            "{}: direction {:?} vs {t}",
            case.name,
            n.direction
        );
    }
}

#[test]
fn shared_models_nailing_targets_match_the_truth() {
    let Some(cases) = shared_cases() else { return };
    for case in &cases {
        check_nailing(case);
    }
}

#[test]
fn own_models_nailing_targets_match_the_truth() {
    for case in &own_cases() {
        check_nailing(case);
    }
}

/// Generated buildings the rules were never tuned on.
const SYNTHETIC_MODELS: usize = 40;

#[test]
fn generated_models_nailing_targets_match_their_truth() {
    for case in &frame_truth::synthetic_cases(SYNTHETIC_MODELS).cases {
        check_nailing(case);
    }
}
