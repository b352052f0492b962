//! Assembly precedence and order from the built-in rule base against every
//! truth model: the truth's constraints are ours, and our order satisfies them.

mod frame_truth;

use frame_truth::{Case, by_piece, list, own_cases, reasoned, shared_cases, sym, text, walls};
use framewright::frame::RuleEngine;
use std::collections::{BTreeMap, BTreeSet};

fn check_order(case: &Case) {
    let r = reasoned(case, &RuleEngine::Compiled);
    let rank: BTreeMap<&str, i64> = by_piece(&r, "assembly_rank")
        .into_iter()
        .map(|(p, k)| (p, k.as_number().expect("a rank")))
        .collect();
    let wall_of = by_piece(&r, "wall_of");
    assert!(
        r.get("precedence_cycle").is_empty(),
        "{}: precedence cycle",
        case.name
    );

    // Every wall piece has a rank, and the ranks of a wall are 0..n-1.
    let mut per_wall: BTreeMap<&str, Vec<i64>> = BTreeMap::new();
    for (p, w) in &wall_of {
        let k = *rank
            .get(p)
            .unwrap_or_else(|| panic!("{}: {p} has no rank", case.name));
        per_wall.entry(sym(w)).or_default().push(k);
    }
    for (w, mut ks) in per_wall {
        ks.sort_unstable();
        let want: Vec<i64> = (0..ks.len() as i64).collect();
        assert_eq!(ks, want, "{}: wall {w} ranks are not 0..n-1", case.name);
    }

    // Our precedence graph equals the truth's, and our order satisfies it.
    let ours: BTreeSet<(&str, &str, &str)> = r
        .get("precedence")
        .iter()
        .map(|t| (sym(&t[0]), sym(&t[1]), sym(&t[2])))
        .collect();
    for &(a, b, why) in &ours {
        assert_eq!(
            wall_of[a], wall_of[b],
            "{}: {a} -> {b} across walls",
            case.name
        );
        assert!(
            rank[a] < rank[b],
            "{}: {a} must precede {b} ({why})",
            case.name
        );
    }
    let theirs: BTreeSet<(&str, &str, &str)> = walls(&case.truth)
        .iter()
        .flat_map(|w| list(w, "precedence_constraints"))
        .map(|c| (text(&c["before"]), text(&c["after"]), text(&c["reason"])))
        .collect();
    for &(a, b, why) in &theirs {
        let (ra, rb) = (rank.get(a), rank.get(b));
        assert!(
            ra.is_some() && rb.is_some() && ra < rb,
            "{}: truth constraint {a} before {b} ({why}) broken: ranks {ra:?}, {rb:?}",
            case.name
        );
    }
    let missing: Vec<_> = theirs.difference(&ours).collect();
    let extra: Vec<_> = ours.difference(&theirs).collect();
    assert!(
        missing.is_empty() && extra.is_empty(),
        "{}: precedence differs from the truth: missing {missing:?}, extra {extra:?}",
        case.name
    );
}

#[test]
fn shared_models_order_satisfies_the_truth() {
    let Some(cases) = shared_cases() else { return };
    for case in &cases {
        check_order(case);
    }
}

#[test]
fn own_models_order_satisfies_the_truth() {
    for case in &own_cases() {
        check_order(case);
    }
}

/// Generated buildings the rules were never tuned on.
const SYNTHETIC_MODELS: usize = 40;

#[test]
fn generated_models_order_satisfies_their_truth() {
    for case in &frame_truth::synthetic_cases(SYNTHETIC_MODELS).cases {
        check_order(case);
    }
}
