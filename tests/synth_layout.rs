//! Layouts: counts, dimensions, opening framing, validation, and agreement with
//! the study's geometry facts recorded in the shared truth files.

mod common;
use framewright::synth::building::grid;
use framewright::synth::layout::{Layout, Role, Vec3};
use framewright::synth::models;
use framewright::synth::units::{Lumber, feet, inches};
use framewright::synth::wall::{
    HeaderStyle, OpeningKind, OpeningSpec, StudLayout, WallSpec, frame_wall,
};
use framewright::synth::{SynthError, WriteOptions, write_ifc};
use std::collections::BTreeMap;

const EPS: f64 = 1e-9;

fn count(layout: &Layout, role: Role) -> usize {
    layout
        .walls()
        .flat_map(|w| &w.pieces)
        .filter(|p| p.role == role)
        .count()
}

#[test]
fn tm1_is_a_square_frame_with_39in_plates_and_36in_studs() {
    let l = models::tm1();
    assert_eq!(l.piece_count(), 4);
    let w = &l.buildings[0].storeys[0].walls[0];
    let lengths: Vec<f64> = w.pieces.iter().map(|p| p.length() / inches(1.0)).collect();
    for (got, want) in lengths.iter().zip([39.0, 36.0, 36.0, 39.0]) {
        assert!((got - want).abs() < 1e-9, "{lengths:?}");
    }
    assert_eq!(
        w.pieces.iter().map(|p| p.role).collect::<Vec<_>>(),
        [Role::BottomPlate, Role::Stud, Role::Stud, Role::TopPlate]
    );
    // The clear opening between the studs is 36 in x 36 in.
    let gap = w.pieces[2].wall_box.u[0] - w.pieces[1].wall_box.u[1];
    assert!((gap - inches(36.0)).abs() < EPS);
    assert!(
        (w.pieces[0].width - inches(3.5)).abs() < EPS
            && (w.pieces[0].thickness - inches(1.5)).abs() < EPS
    );
}

#[test]
fn tm2_is_a_2x6_frame_6ft_long_5ft_high() {
    let w = models::tm2().buildings[0].storeys[0].walls[0].clone();
    assert!((w.length - feet(6.0)).abs() < EPS && (w.height - feet(5.0)).abs() < EPS);
    assert!((w.thickness - inches(5.5)).abs() < EPS);
    assert_eq!(w.pieces.len(), 4);
}

#[test]
fn tm3_has_62_members_in_4_walls_16in_on_centre() {
    let l = models::tm3();
    assert_eq!(l.piece_count(), 62);
    let walls: Vec<_> = l.walls().collect();
    assert_eq!(
        walls.iter().map(|w| w.id.as_str()).collect::<Vec<_>>(),
        ["F", "L", "B", "R"]
    );
    assert_eq!(
        (
            count(&l, Role::BottomPlate),
            count(&l, Role::TopPlate),
            count(&l, Role::CapPlate)
        ),
        (4, 4, 4)
    );
    assert_eq!(count(&l, Role::Stud), 50);
    for w in &walls {
        let plates: Vec<_> = w.pieces.iter().filter(|p| !p.role.is_vertical()).collect();
        for p in plates {
            assert!((p.length() - w.length).abs() < EPS);
        }
        let studs: Vec<_> = w.pieces.iter().filter(|p| p.role == Role::Stud).collect();
        for s in &studs {
            assert!((s.length() - inches(92.625)).abs() < EPS, "precut stud");
        }
        // Interior studs sit at multiples of 16 in from the wall start.
        for s in &studs[1..studs.len() - 1] {
            let c = 0.5 * (s.wall_box.u[0] + s.wall_box.u[1]) / inches(16.0);
            assert!((c - c.round()).abs() < 1e-9, "{c}");
        }
    }
    assert!((walls[0].length - feet(22.5)).abs() < EPS);
    assert!((walls[1].length / feet(1.0) - 7.4).abs() < 1e-9);
    assert!((walls[0].height - inches(97.125)).abs() < EPS);
    // Front and back run the full length; the sides butt between them.
    let (f, l_wall) = (walls[0], walls[1]);
    assert!((l_wall.frame.origin - (Vec3::new(0.0, f.thickness, 0.0))).norm() < EPS);
}

/// Compare one model's truth with the shared truth file (absent: skip).
fn same_as_shared(layout: &Layout, shared_name: &str) {
    let Some(shared) = common::shared_path(&format!("ifc-testcases/{shared_name}")) else {
        return;
    };
    let text = std::fs::read_to_string(&shared).unwrap();
    let theirs: serde_json::Value = serde_json::from_str(&text).unwrap();
    let ours = write_ifc(layout, &WriteOptions::default()).unwrap().truth;
    let ours: serde_json::Value = serde_json::to_value(&ours).unwrap();
    let key = |m: &serde_json::Value| {
        format!(
            "{} {} {} {}",
            m["wall_id"], m["role"], m["axis_start"], m["wall_local_box"]["w"]
        )
    };
    let mut a: Vec<_> = ours["members"].as_array().unwrap().iter().collect();
    let mut b: Vec<_> = theirs["members"].as_array().unwrap().iter().collect();
    assert_eq!(a.len(), b.len(), "{shared_name}: member count");
    let close = |x: &serde_json::Value, y: &serde_json::Value| -> bool {
        match (x, y) {
            (serde_json::Value::Number(p), serde_json::Value::Number(q)) => {
                (p.as_f64().unwrap() - q.as_f64().unwrap()).abs() < 1e-8
            }
            (serde_json::Value::Array(p), serde_json::Value::Array(q)) => {
                p.len() == q.len()
                    && p.iter()
                        .zip(q)
                        .all(|(p, q)| (p.as_f64().unwrap() - q.as_f64().unwrap()).abs() < 1e-8)
            }
            _ => x == y,
        }
    };
    let order = |x: &&serde_json::Value, y: &&serde_json::Value| {
        let f = |m: &serde_json::Value| {
            (
                m["wall_id"].to_string(),
                m["role"].to_string(),
                m["wall_local_box"]["u"][0].as_f64().unwrap(),
                m["wall_local_box"]["w"][0].as_f64().unwrap(),
            )
        };
        let (p, q) = (f(x), f(y));
        p.0.cmp(&q.0)
            .then(p.1.cmp(&q.1))
            .then(p.2.total_cmp(&q.2))
            .then(p.3.total_cmp(&q.3))
    };
    a.sort_by(order);
    b.sort_by(order);
    for (x, y) in a.iter().zip(&b) {
        for field in [
            "wall_id",
            "role",
            "role_detail",
            "axis_start",
            "axis_end",
            "width",
            "thickness",
            "section_w",
            "length",
            "volume",
        ] {
            assert!(
                close(&x[field], &y[field]),
                "{shared_name} {}: {field} {} vs {}",
                key(x),
                x[field],
                y[field]
            );
        }
        for k in ["u", "v", "w"] {
            assert!(
                close(&x["wall_local_box"][k], &y["wall_local_box"][k]),
                "{shared_name} {}: box {k}",
                key(x)
            );
        }
    }
    let (wa, wb) = (
        ours["walls"].as_array().unwrap(),
        theirs["walls"].as_array().unwrap(),
    );
    assert_eq!(wa.len(), wb.len());
    for (x, y) in wa.iter().zip(wb) {
        for field in ["wall_id", "length", "height", "thickness", "role_counts"] {
            assert!(
                close(&x[field], &y[field]),
                "{shared_name} wall {}: {field}",
                x["wall_id"]
            );
        }
        for r in 0..4 {
            assert!(
                close(&x["frame_matrix"][r], &y["frame_matrix"][r]),
                "{shared_name} frame row {r}"
            );
        }
    }
    same_targets_as_shared(&ours, &theirs, shared_name);
}

/// Member keys independent of GlobalIds: wall, role and wall-local box.
fn box_keys(doc: &serde_json::Value) -> BTreeMap<String, String> {
    let r = |v: &serde_json::Value| format!("{:.6}", v.as_f64().unwrap());
    doc["members"]
        .as_array()
        .unwrap()
        .iter()
        .map(|m| {
            let b = &m["wall_local_box"];
            let key = format!(
                "{} {} u {} {} v {} {} w {} {}",
                m["wall_id"],
                m["role"],
                r(&b["u"][0]),
                r(&b["u"][1]),
                r(&b["v"][0]),
                r(&b["v"][1]),
                r(&b["w"][0]),
                r(&b["w"][1])
            );
            (m["global_id"].as_str().unwrap().to_string(), key)
        })
        .collect()
}

/// Precedence, nailing targets and assembly-order roles agree with the shared truth.
fn same_targets_as_shared(ours: &serde_json::Value, theirs: &serde_json::Value, shared_name: &str) {
    let r = |v: &serde_json::Value| format!("{:.6}", v.as_f64().unwrap());
    let (ka, kb) = (box_keys(ours), box_keys(theirs));
    let id =
        |keys: &BTreeMap<String, String>, v: &serde_json::Value| keys[v.as_str().unwrap()].clone();
    for (x, y) in ours["walls"]
        .as_array()
        .unwrap()
        .iter()
        .zip(theirs["walls"].as_array().unwrap())
    {
        let prec = |w: &serde_json::Value, keys: &BTreeMap<String, String>| {
            let mut v: Vec<String> = w["precedence_constraints"]
                .as_array()
                .unwrap()
                .iter()
                .map(|p| {
                    format!(
                        "{} < {} {}",
                        id(keys, &p["before"]),
                        id(keys, &p["after"]),
                        p["reason"]
                    )
                })
                .collect();
            v.sort();
            v
        };
        assert_eq!(
            prec(x, &ka),
            prec(y, &kb),
            "{shared_name} wall {}: precedence",
            x["wall_id"]
        );
        for field in ["nailing_targets", "secondary_nailing_targets"] {
            let nails = |w: &serde_json::Value, keys: &BTreeMap<String, String>| {
                let mut v: Vec<String> = w[field]
                    .as_array()
                    .unwrap()
                    .iter()
                    .map(|n| {
                        format!(
                            "{} | {} | {} {} {} {} | {} {} {} | {}",
                            id(keys, &n["plate"]),
                            id(keys, &n["member"]),
                            n["kind"],
                            r(&n["u"]),
                            r(&n["v"]),
                            r(&n["w"]),
                            r(&n["world"][0]),
                            r(&n["world"][1]),
                            r(&n["world"][2]),
                            n["direction_world"]
                        )
                    })
                    .collect();
                v.sort();
                v
            };
            let (a, b) = (nails(x, &ka), nails(y, &kb));
            assert!(!b.is_empty() || field == "secondary_nailing_targets");
            assert_eq!(a, b, "{shared_name} wall {}: {field}", x["wall_id"]);
        }
        assert_eq!(
            x["assembly_order_roles"], y["assembly_order_roles"],
            "{shared_name}: assembly order roles"
        );
    }
}

#[test]
fn study_models_match_the_shared_truth_geometry() {
    same_as_shared(&models::tm1(), "a_paper_tm1.truth.json");
    same_as_shared(&models::tm2(), "a_paper_tm2.truth.json");
    same_as_shared(&models::tm3(), "a_paper_tm3.truth.json");
}

fn twelve_foot_wall(openings: Vec<OpeningSpec>, header_style: HeaderStyle) -> WallSpec {
    WallSpec {
        id: "W1".into(),
        name: "Wall".into(),
        length: feet(12.0),
        height: models::eight_foot_height(),
        lumber: Lumber::L2X4,
        studs: models::sixteen_on_centre(),
        double_top_plate: true,
        header_style,
        openings,
        detail: Default::default(),
    }
}

/// A sill from king to king carries the jack studs, a cripple under each; a blocking row fills
/// every bay it crosses between uprights that cross it, touching both, and never enters an
/// opening's framing; no two pieces overlap.
#[test]
fn king_to_king_sills_and_blocking_rows_fit_the_frame() {
    use framewright::synth::wall::{FramingDetail, SillStyle};
    let window = OpeningSpec {
        kind: OpeningKind::Window { sill: inches(36.0) },
        u: inches(60.0),
        width: inches(48.0),
        height: inches(48.0),
    };
    let door = OpeningSpec {
        kind: OpeningKind::Door,
        u: inches(20.0),
        width: inches(32.0),
        height: inches(82.5),
    };
    let mut spec = twelve_foot_wall(vec![door, window], HeaderStyle::BuiltUp);
    spec.detail = FramingDetail {
        sill: SillStyle::KingToKing,
        blocking_rows: vec![inches(24.0), inches(48.0)],
        ..FramingDetail::default()
    };
    let wall = frame_wall(
        &spec,
        framewright::synth::layout::WallFrame::upright(Vec3::zeros(), Vec3::x()),
    )
    .unwrap();
    let of = |role: Role| -> Vec<&framewright::synth::Piece> {
        wall.pieces.iter().filter(|p| p.role == role).collect()
    };
    let t = Lumber::L2X4.thickness;
    let sill = of(Role::Sill)[0].wall_box;
    let kings = of(Role::KingStud);
    assert!(
        kings
            .iter()
            .any(|k| (k.wall_box.u[1] - sill.u[0]).abs() < 1e-9)
    );
    assert!(
        kings
            .iter()
            .any(|k| (k.wall_box.u[0] - sill.u[1]).abs() < 1e-9)
    );
    let jacks_on_sill: Vec<_> = of(Role::JackStud)
        .into_iter()
        .filter(|j| (j.wall_box.v[0] - sill.v[1]).abs() < 1e-9)
        .collect();
    assert_eq!(jacks_on_sill.len(), 2);
    for j in &jacks_on_sill {
        assert!(of(Role::CrippleStud).iter().any(|c| c.wall_box.u == j.wall_box.u
            && (c.wall_box.v[1] - sill.v[0]).abs() < 1e-9));
    }
    let blocking = of(Role::Blocking);
    assert!(!blocking.is_empty());
    let uprights: Vec<_> = wall
        .pieces
        .iter()
        .filter(|p| p.role.is_vertical())
        .collect();
    for b in &blocking {
        let bb = b.wall_box;
        assert!((bb.v[1] - bb.v[0] - t).abs() < 1e-9);
        for end in [bb.u[0], bb.u[1]] {
            assert!(
                uprights.iter().any(|u| (u.wall_box.u[0] - end).abs() < 1e-9
                    || (u.wall_box.u[1] - end).abs() < 1e-9),
                "{bb:?}: an end meets no upright"
            );
        }
    }
    let overlap = |a: [f64; 2], b: [f64; 2]| a[0] < b[1] - 1e-9 && b[0] < a[1] - 1e-9;
    for (i, a) in wall.pieces.iter().enumerate() {
        for b in &wall.pieces[i + 1..] {
            let (x, y) = (a.wall_box, b.wall_box);
            assert!(
                !(overlap(x.u, y.u) && overlap(x.v, y.v) && overlap(x.w, y.w)),
                "{:?} {x:?} overlaps {:?} {y:?}",
                a.role,
                b.role
            );
        }
    }
    // Across the door and inside the window no row is blocked in.
    for b in &blocking {
        assert!(!overlap(b.wall_box.u, [inches(20.0), inches(52.0)]));
        let in_window = overlap(b.wall_box.u, [inches(60.0), inches(108.0)])
            && overlap(b.wall_box.v, [inches(35.0), inches(84.0)]);
        assert!(!in_window, "{:?}", b.wall_box);
    }
}

#[test]
fn door_and_window_walls_match_the_shared_truth_geometry() {
    let door = OpeningSpec {
        kind: OpeningKind::Door,
        u: inches(53.0),
        width: inches(38.0),
        height: inches(82.5),
    };
    let l = models::single_wall(
        "d",
        "door",
        &twelve_foot_wall(vec![door], HeaderStyle::Solid),
    )
    .unwrap();
    same_as_shared(&l, "d_wall_door.truth.json");
    let window = OpeningSpec {
        kind: OpeningKind::Window { sill: inches(32.0) },
        u: inches(54.0),
        width: inches(36.0),
        height: inches(48.0),
    };
    let l = models::single_wall(
        "w",
        "window",
        &twelve_foot_wall(vec![window], HeaderStyle::BuiltUp),
    )
    .unwrap();
    same_as_shared(&l, "d_wall_window.truth.json");
}

#[test]
fn window_is_framed_with_king_jack_header_sill_and_cripples() {
    let window = models::window_at(inches(54.0));
    let l = models::single_wall(
        "w",
        "w",
        &twelve_foot_wall(vec![window], HeaderStyle::BuiltUp),
    )
    .unwrap();
    let roles = |r| count(&l, r);
    assert_eq!(
        (
            roles(Role::KingStud),
            roles(Role::JackStud),
            roles(Role::Header),
            roles(Role::Sill)
        ),
        (2, 2, 2, 1)
    );
    assert_eq!(roles(Role::CrippleStud), 4);
    let w = &l.buildings[0].storeys[0].walls[0];
    let jack = w.pieces.iter().find(|p| p.role == Role::JackStud).unwrap();
    let header = w.pieces.iter().find(|p| p.role == Role::Header).unwrap();
    assert!(
        (jack.wall_box.v[1] - header.wall_box.v[0]).abs() < EPS,
        "header rests on the jacks"
    );
    assert!(
        (header.width - inches(9.25)).abs() < EPS && (header.width_dir - Vec3::z()).norm() < EPS,
        "on edge"
    );
    // No common stud overlaps the opening's framing.
    let zone = [inches(54.0 - 3.0), inches(90.0 + 3.0)];
    for s in w.pieces.iter().filter(|p| p.role == Role::Stud) {
        assert!(s.wall_box.u[1] <= zone[0] + EPS || s.wall_box.u[0] >= zone[1] - EPS);
    }
    // Assembly order: bottom plate, standing members by u, sill and headers, cripples above, plates.
    let order: Vec<Role> = w.pieces.iter().map(|p| p.role).collect();
    assert_eq!(order[0], Role::BottomPlate);
    assert_eq!(&order[order.len() - 2..], &[Role::TopPlate, Role::CapPlate]);
}

#[test]
fn door_cuts_the_bottom_plate() {
    let l = models::single_wall(
        "d",
        "d",
        &twelve_foot_wall(vec![models::door_at(inches(53.0))], HeaderStyle::BuiltUp),
    )
    .unwrap();
    let bottoms: Vec<_> = l.buildings[0].storeys[0].walls[0]
        .pieces
        .iter()
        .filter(|p| p.role == Role::BottomPlate)
        .collect();
    assert_eq!(bottoms.len(), 2);
    assert!((bottoms[0].wall_box.u[1] - inches(53.0)).abs() < EPS);
    assert!((bottoms[1].wall_box.u[0] - inches(91.0)).abs() < EPS);
}

#[test]
fn absurd_walls_and_openings_are_refused_with_typed_errors() {
    let frame = framewright::synth::layout::WallFrame::upright(Vec3::zeros(), Vec3::x());
    let mut spec = twelve_foot_wall(vec![], HeaderStyle::BuiltUp);
    spec.length = -3.0;
    assert!(matches!(
        frame_wall(&spec, frame),
        Err(SynthError::Wall { .. })
    ));
    spec.length = f64::NAN;
    assert!(matches!(
        frame_wall(&spec, frame),
        Err(SynthError::Wall { .. })
    ));
    spec.length = 1000.0;
    assert!(matches!(
        frame_wall(&spec, frame),
        Err(SynthError::Wall { .. })
    ));
    let mut spec = twelve_foot_wall(vec![], HeaderStyle::BuiltUp);
    spec.studs = StudLayout::OnCentre(0.001);
    assert!(matches!(
        frame_wall(&spec, frame),
        Err(SynthError::Wall { .. })
    ));
    let bad = [
        models::door_at(0.0),        // over the end stud
        models::door_at(feet(11.0)), // past the wall end
        OpeningSpec {
            height: inches(95.0),
            ..models::door_at(feet(4.0))
        }, // through the top plate
        OpeningSpec {
            kind: OpeningKind::Window { sill: inches(2.0) },
            ..models::window_at(feet(4.0))
        },
        OpeningSpec {
            width: feet(11.0),
            ..models::door_at(inches(5.0))
        },
    ];
    for o in bad {
        let spec = twelve_foot_wall(vec![o], HeaderStyle::BuiltUp);
        let err = frame_wall(&spec, frame).unwrap_err();
        assert!(matches!(err, SynthError::Opening { .. }), "{o:?}: {err}");
        assert!(err.to_string().contains("hint"), "{err}");
    }
    let overlapping = vec![
        models::door_at(feet(3.0)),
        models::window_at(feet(3.0) + inches(40.0)),
    ];
    let err = frame_wall(&twelve_foot_wall(overlapping, HeaderStyle::BuiltUp), frame).unwrap_err();
    assert!(err.to_string().contains("overlaps"), "{err}");
}

#[test]
fn grids_multiply_buildings_and_refuse_empty_or_huge_ones() {
    let spec = models::default_building_spec();
    let one = grid(&spec, 1, 1, 3.0, "g").unwrap();
    let six = grid(&spec, 2, 3, 3.0, "g").unwrap();
    assert_eq!(six.buildings.len(), 6);
    assert_eq!(six.piece_count(), 6 * one.piece_count());
    let ids: std::collections::BTreeSet<_> = six.walls().map(|w| w.id.clone()).collect();
    assert_eq!(ids.len(), 24, "wall ids are unique");
    assert!(grid(&spec, 0, 3, 3.0, "g").is_err());
    assert!(grid(&spec, 1000, 1000, 3.0, "g").is_err());
}

/// Corners (a flat backer at the inner face, a three-stud post with spacer blocks, ladder
/// blocking), partition backers, windows side by side sharing a king stud and a let-in
/// brace: each where framing puts it, and no two pieces overlap but the brace, which crosses
/// the studs and plates it is let into.
#[test]
fn corners_partitions_shared_kings_and_braces_fit_the_frame() {
    use framewright::synth::wall::{CornerStyle, FramingDetail, PartitionSpec, PartitionStyle};
    let t = Lumber::L2X4.thickness;
    let depth = Lumber::L2X4.width;
    let window = |u: f64| OpeningSpec {
        kind: OpeningKind::Window { sill: inches(44.0) },
        u,
        width: inches(30.0),
        height: inches(24.0),
    };
    for corners in [
        CornerStyle::Backer,
        CornerStyle::ThreeStud,
        CornerStyle::Ladder,
    ] {
        // Jack, king, jack between the two rough openings: the king is shared.
        let mut spec = twelve_foot_wall(
            vec![window(inches(34.0)), window(inches(64.0) + 3.0 * t)],
            HeaderStyle::BuiltUp,
        );
        spec.length = feet(20.0);
        spec.detail = FramingDetail {
            corners,
            partitions: vec![
                PartitionSpec {
                    u: feet(12.0),
                    style: PartitionStyle::Backer,
                },
                PartitionSpec {
                    u: feet(16.0),
                    style: PartitionStyle::Ladder,
                },
            ],
            braces: vec![inches(106.0)],
            ..FramingDetail::default()
        };
        let wall = frame_wall(
            &spec,
            framewright::synth::layout::WallFrame::upright(Vec3::zeros(), Vec3::x()),
        )
        .unwrap();
        let len = spec.length;
        let of = |role: Role| -> Vec<framewright::synth::layout::WallBox> {
            wall.pieces
                .iter()
                .filter(|p| p.role == role)
                .map(|p| p.wall_box)
                .collect()
        };
        let near = |a: f64, b: f64| (a - b).abs() < 1e-9;
        let full_depth = |b: &framewright::synth::layout::WallBox| near(b.w[1] - b.w[0], depth);
        let posts: Vec<_> = wall
            .pieces
            .iter()
            .filter(|p| p.upright && full_depth(&p.wall_box))
            .map(|p| p.wall_box)
            .collect();
        let touches_post = |u: f64| posts.iter().any(|b| near(b.u[0], u) || near(b.u[1], u));

        // Three kings; the middle one has a jack against each face.
        let kings = of(Role::KingStud);
        assert_eq!(kings.len(), 3, "{corners:?}");
        let middle = kings[1];
        let jacks = of(Role::JackStud);
        assert!(jacks.iter().any(|j| near(j.u[1], middle.u[0])));
        assert!(jacks.iter().any(|j| near(j.u[0], middle.u[1])));

        // Flat studs lie at the inner face with both ends, or one at a corner, on a post.
        let flat: Vec<_> = of(Role::Stud)
            .into_iter()
            .filter(|b| !full_depth(b))
            .collect();
        for b in &flat {
            assert!(near(b.w[0], depth - t) && near(b.w[1], depth), "{b:?}");
            assert!(near(b.u[1] - b.u[0], depth), "{b:?}");
            assert!(touches_post(b.u[0]) || touches_post(b.u[1]), "{b:?}");
        }
        let corner_backers = if corners == CornerStyle::Backer { 2 } else { 0 };
        assert_eq!(flat.len(), 1 + corner_backers, "{corners:?}");

        // Blocks lying (ladder) touch a post at both ends and neither plate.
        let stud_top = spec.height - 2.0 * t;
        let lying_blocks: Vec<_> = wall
            .pieces
            .iter()
            .filter(|p| p.role == Role::Blocking && !p.upright)
            .map(|p| p.wall_box)
            .collect();
        for b in &lying_blocks {
            assert!(touches_post(b.u[0]) && touches_post(b.u[1]), "{b:?}");
            assert!(b.v[0] > t + 1e-3 && b.v[1] < stud_top - 1e-3, "{b:?}");
        }
        // Spacer blocks stand between the end stud and the second stud of the corner post.
        let spacers: Vec<_> = wall
            .pieces
            .iter()
            .filter(|p| p.role == Role::Blocking && p.upright)
            .map(|p| p.wall_box)
            .collect();
        if corners == CornerStyle::ThreeStud {
            assert_eq!(spacers.len(), 6);
            for b in &spacers {
                let at_start = near(b.u[0], t) && near(b.u[1], 2.0 * t);
                let at_end = near(b.u[1], len - t) && near(b.u[0], len - 2.0 * t);
                assert!(at_start || at_end, "{b:?}");
            }
        } else {
            assert!(spacers.is_empty());
        }

        // The brace: 45°, from the bottom plate's top to the top plate's underside, in the
        // outer face, clear of every king stud's u range.
        let brace = wall.pieces.iter().find(|p| p.role == Role::Brace).unwrap();
        let (a, b) = (brace.start, brace.end);
        assert!(near((b.x - a.x).abs(), (b.z - a.z).abs()), "{a:?} {b:?}");
        assert!(near(a.z, t) && near(b.z, stud_top));
        assert!(near(brace.wall_box.w[0], 0.0) && near(brace.wall_box.w[1], 0.75 * 0.0254));
        let overlap = |x: [f64; 2], y: [f64; 2]| x[0] < y[1] - 1e-9 && y[0] < x[1] - 1e-9;
        assert!(kings.iter().all(|k| !overlap(k.u, brace.wall_box.u)));

        for (i, p) in wall.pieces.iter().enumerate() {
            for q in &wall.pieces[i + 1..] {
                let (x, y) = (p.wall_box, q.wall_box);
                let crossing = overlap(x.u, y.u) && overlap(x.v, y.v) && overlap(x.w, y.w);
                let brace = p.role == Role::Brace || q.role == Role::Brace;
                assert!(
                    !crossing || brace,
                    "{corners:?}: {:?} {x:?} overlaps {:?} {y:?}",
                    p.role,
                    q.role
                );
            }
        }
    }
}
