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
    // Compared as sets: the compiled run concatenates per-storey parts.
    let sorted = |r: &framewright::frame::Reasoned, name: &str| {
        let mut v = r.get(name).to_vec();
        v.sort();
        v
    };
    for name in names {
        let (c, i) = (sorted(&compiled, name), sorted(&interpreted, name));
        if c != i {
            for (a, b) in c.iter().zip(&i) {
                if a != b {
                    eprintln!("{name}: {a:?} vs {b:?}");
                }
            }
        }
        assert!(
            c == i,
            "{}: relation {name} differs ({} compiled tuples, {} interpreted)",
            case.name,
            compiled.get(name).len(),
            interpreted.get(name).len()
        );
    }
}

#[test]
fn shared_models_same_relations_on_both_engines() {
    let Some(cases) = shared_cases() else { return };
    for case in &cases {
        check_engines_agree(case);
    }
}

#[test]
fn own_models_same_relations_on_both_engines() {
    for case in &own_cases() {
        check_engines_agree(case);
    }
}

/// Generated buildings the rules were never tuned on.
const SYNTHETIC_MODELS: usize = 40;

#[test]
fn generated_models_walls_and_roles_match_their_truth() {
    for case in &frame_truth::synthetic_cases(SYNTHETIC_MODELS).cases {
        check_walls_and_roles(case);
    }
}

#[test]
fn generated_models_same_relations_on_both_engines() {
    for case in &frame_truth::synthetic_cases(SYNTHETIC_MODELS).cases {
        check_engines_agree(case);
    }
}

/// Pieces the truth models do not have: blocking between studs (flat and on
/// edge) and a doubled stud. Blocking is end-nailed through the studs it
/// sits between; a doubled stud is a stud, nailed to both plates.
#[test]
fn blocking_and_doubled_studs() {
    use framewright::synth::layout::{Role, WallBox};
    use framewright::synth::models::single_wall;
    use framewright::synth::wall::{HeaderStyle, StudLayout, WallSpec};
    use framewright::synth::{Lumber, Piece, WriteOptions, write_ifc};
    let spec = WallSpec {
        id: "W".into(),
        name: "Wall".into(),
        length: 3.6576,
        height: 2.4669,
        lumber: Lumber::L2X4,
        studs: StudLayout::OnCentre(0.4064),
        double_top_plate: true,
        header_style: HeaderStyle::BuiltUp,
        openings: vec![],
        detail: Default::default(),
    };
    let mut layout = single_wall("blocking", "blocking and a doubled stud", &spec).unwrap();
    let wall = &mut layout.buildings[0].storeys[0].walls[0];
    let (t, depth) = (Lumber::L2X4.thickness, Lumber::L2X4.width);
    let mut studs: Vec<WallBox> = wall
        .pieces
        .iter()
        .filter(|p| p.role == Role::Stud)
        .map(|p| p.wall_box)
        .collect();
    studs.sort_by(|a, b| a.u[0].total_cmp(&b.u[0]));
    let extra = [
        // Flat blocking in the second bay, on edge in the third (flush with the outer face).
        (
            studs[1].u[1],
            studs[2].u[0],
            [1.2, 1.2 + t],
            [0.0, depth],
            "blocking flat",
        ),
        (
            studs[2].u[1],
            studs[3].u[0],
            [1.0, 1.0 + depth],
            [0.0, t],
            "blocking on edge",
        ),
    ];
    for (u0, u1, v, w, detail) in extra {
        let b = WallBox { u: [u0, u1], v, w };
        wall.pieces
            .push(Piece::from_box(&wall.frame, Role::Sill, detail, "2x4", b));
    }
    let s = studs[5];
    let doubled = WallBox {
        u: [s.u[1], s.u[1] + t],
        v: s.v,
        w: s.w,
    };
    wall.pieces.push(Piece::from_box(
        &wall.frame,
        Role::Stud,
        "doubled",
        "2x4",
        doubled,
    ));

    let written = write_ifc(&layout, &WriteOptions::default()).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let ifc = dir.path().join("blocking.ifc");
    std::fs::write(&ifc, &written.ifc).unwrap();
    let case = Case {
        name: "blocking".into(),
        ifc,
        truth: serde_json::to_value(&written.truth).unwrap(),
    };
    let r = reasoned(&case, &RuleEngine::Compiled);
    let roles = by_piece(&r, "role");
    let rank: BTreeMap<&str, i64> = by_piece(&r, "assembly_rank")
        .into_iter()
        .map(|(p, k)| (p, k.as_number().unwrap()))
        .collect();
    let precedence: BTreeSet<(&str, &str, &str)> = r
        .get("precedence")
        .iter()
        .map(|t| (sym(&t[0]), sym(&t[1]), sym(&t[2])))
        .collect();
    for &(a, b, _) in &precedence {
        assert!(rank[a] < rank[b], "{a} must precede {b}");
    }
    let mut seen = 0;
    for m in members(&case.truth) {
        let gid = text(&m["global_id"]);
        let detail = text(&m["role_detail"]);
        let want = match detail {
            "blocking flat" | "blocking on edge" => {
                let nailed_through = precedence
                    .iter()
                    .filter(|(_, b, why)| *b == gid && *why == "end_nailed_through")
                    .count();
                assert_eq!(nailed_through, 2, "{detail}: end-nailed through both studs");
                seen += 1;
                "blocking"
            }
            "doubled" => {
                let nails = r
                    .get("nailing_target")
                    .iter()
                    .filter(|t| sym(&t[1]) == gid)
                    .count();
                assert_eq!(nails, 4, "a doubled stud is nailed to both plates");
                seen += 1;
                "stud"
            }
            _ => text(&m["role"]),
        };
        assert_eq!(sym(roles[gid]), want, "{gid} ({detail})");
    }
    assert_eq!(seen, 3);
}
