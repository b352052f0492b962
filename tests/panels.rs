//! Walls split into panels (`rules/panels.dl`, `frame::panels`), checked from `plan --json`
//! against what the members themselves say (their axes, sections, roles and masses in the same
//! report): every member in exactly one panel or cut into segments that cover it exactly; every
//! panel within the cell's limits; breaks only at a stud's face, through no piece but a plate
//! and no opening's framing; end studs added beside the break; the fewest panels; a wall that
//! fits stays whole; moving one stud moves at most the break beside it.

mod common;

use common::ifc_edit::{long_wall, move_point, stud_points};
use serde_json::Value;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

const TOL: f64 = 0.003;

fn framewright(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_framewright"))
        .args(args)
        .output()
        .expect("framewright runs")
}

fn plan(model: &Path, extra: &[&str]) -> Value {
    let m = model.to_str().unwrap();
    let out = framewright(&[&["plan", m, "--json", "--no-cache"][..], extra].concat());
    assert!(
        out.status.success(),
        "plan {m} {extra:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice(&out.stdout).unwrap()
}

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn f(v: &Value) -> f64 {
    v.as_f64().unwrap()
}

fn strs(v: &Value) -> Vec<&str> {
    v.as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_str().unwrap())
        .collect()
}

/// A member as the checks see it: role, extent along its wall (axis end points projected; an
/// upright's axis projects to its centre), section and mass.
struct Member {
    role: String,
    lying: bool,
    u0: f64,
    u1: f64,
    half_thin: f64,
    half_wide: f64,
    mass: f64,
}

fn is_plate(role: &str) -> bool {
    matches!(role, "bottom_plate" | "top_plate" | "cap_plate")
}

fn is_stud(role: &str) -> bool {
    matches!(role, "stud" | "king_stud")
}

/// Members of one wall, by id, in wall coordinates (u along the wall from its start).
fn wall_members<'a>(plan: &'a Value, wall: &Value) -> BTreeMap<&'a str, Member> {
    let m = &wall["frame_matrix"];
    let at = |r: usize, c: usize| f(&m[r][c]);
    let u_axis = [at(0, 0), at(1, 0), at(2, 0)];
    let origin = [at(0, 3), at(1, 3), at(2, 3)];
    let u_of = |p: &Value| {
        (0..3)
            .map(|i| (f(&p[i]) - origin[i]) * u_axis[i])
            .sum::<f64>()
    };
    let wall_id = wall["wall_id"].as_str().unwrap();
    plan["members"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|x| x["wall_id"].as_str() == Some(wall_id))
        .map(|x| {
            let (a, b) = (u_of(&x["axis_start"]), u_of(&x["axis_end"]));
            let s = &x["axis_start"];
            let e = &x["axis_end"];
            let rise = (f(&e[2]) - f(&s[2])).abs();
            (
                x["id"].as_str().unwrap(),
                Member {
                    role: x["role"].as_str().unwrap_or("other").to_string(),
                    lying: rise < 0.1 * f(&x["length"]),
                    u0: a.min(b),
                    u1: a.max(b),
                    half_thin: f(&x["thickness"]) / 2.0,
                    half_wide: f(&x["width"]) / 2.0,
                    mass: f(&x["mass"]),
                },
            )
        })
        .collect()
}

/// Checks every wall's panels; returns the number of walls split.
fn check_panels(plan: &Value, context: &str) -> usize {
    let limits = &plan["panel_limits"];
    let (max_length, max_height, max_mass, min_length) = (
        f(&limits["max_length"]),
        f(&limits["max_height"]),
        f(&limits["max_mass"]),
        f(&limits["min_length"]),
    );
    let mut split = 0;
    for wall in plan["walls"].as_array().unwrap() {
        let id = wall["wall_id"].as_str().unwrap();
        let at = format!("{context} {id}");
        let members = wall_members(plan, wall);
        let panels = wall["panels"].as_array().unwrap();
        assert!(!panels.is_empty(), "{at}: no panels");
        // Contiguous from the wall's start to its end.
        assert!(f(&panels[0]["u_start"]).abs() < 1e-9, "{at}");
        assert!(
            (f(&panels[panels.len() - 1]["u_end"]) - f(&wall["length"])).abs() < 1e-6,
            "{at}"
        );
        for pair in panels.windows(2) {
            assert_eq!(pair[0]["u_end"], pair[1]["u_start"], "{at}");
        }
        let breaks: Vec<f64> = panels[1..].iter().map(|p| f(&p["u_start"])).collect();
        let reported: Vec<f64> = wall["panel_breaks"]
            .as_array()
            .unwrap()
            .iter()
            .map(|b| f(&b["u"]))
            .collect();
        assert_eq!(breaks, reported, "{at}: panel_breaks");
        if panels.len() > 1 {
            split += 1;
        }

        // Every member exactly once: whole in one panel, or cut into segments covering it.
        let mut whole: BTreeMap<&str, usize> = BTreeMap::new();
        let mut segments: BTreeMap<&str, Vec<(f64, f64, f64)>> = BTreeMap::new();
        for p in panels {
            let (a, b) = (f(&p["u_start"]), f(&p["u_end"]));
            for m in strs(&p["member_ids"]) {
                *whole.entry(m).or_default() += 1;
                let x = &members[m];
                let centre = (x.u0 + x.u1) / 2.0;
                assert!(
                    centre >= a - TOL && centre <= b + TOL,
                    "{at}: {m} outside its panel"
                );
            }
            for c in p["cut_pieces"].as_array().unwrap() {
                let of = c["of"].as_str().unwrap();
                let (s, e) = (f(&c["u_start"]), f(&c["u_end"]));
                assert!(
                    s >= a - 1e-9 && e <= b + 1e-9,
                    "{at}: segment {} outside",
                    c["id"]
                );
                segments.entry(of).or_default().push((s, e, f(&c["mass"])));
            }
        }
        // Cap plates lap over the joints: the stretch across each joint is a site piece, in no
        // panel, and every joint of a cap lies at least the lap from every break.
        let lap = f(&plan["panel_limits"]["cap_lap"]);
        for site in wall["site_pieces"].as_array().unwrap() {
            let of = site["of"].as_str().unwrap();
            let (s, e) = (f(&site["u_start"]), f(&site["u_end"]));
            assert_eq!(members[of].role, "cap_plate", "{at}: site piece of {of}");
            assert!(
                breaks.iter().any(|&u| u > s && u < e),
                "{at}: site piece {} spans no joint",
                site["id"]
            );
            segments
                .entry(of)
                .or_default()
                .push((s, e, f(&site["mass"])));
        }
        for (id, segs) in &mut segments {
            segs.sort_by(|a, b| a.0.total_cmp(&b.0));
            let m = &members[id];
            let joints = segs[1..].iter().map(|s| s.0);
            for joint in joints {
                let offset = breaks
                    .iter()
                    .map(|u| (u - joint).abs())
                    .fold(f64::INFINITY, f64::min);
                if m.role == "cap_plate" {
                    assert!(
                        offset >= lap - 1e-6,
                        "{at}: {id} has a joint at u = {joint}, {offset} m from a break"
                    );
                } else {
                    assert!(
                        offset < 1e-6,
                        "{at}: {id} has a joint at u = {joint} off the breaks"
                    );
                }
            }
        }
        for (id, m) in &members {
            match (whole.get(id), segments.get(id)) {
                (Some(1), None) => {}
                (None, Some(segs)) => {
                    assert!(is_plate(&m.role) && m.lying, "{at}: {id} ({}) cut", m.role);
                    assert!(segs.len() >= 2, "{at}: {id} cut into one segment");
                    assert!((segs[0].0 - m.u0).abs() < 1e-6, "{at}: {id} start");
                    assert!(
                        (segs[segs.len() - 1].1 - m.u1).abs() < 1e-6,
                        "{at}: {id} end"
                    );
                    for pair in segs.windows(2) {
                        assert!((pair[0].1 - pair[1].0).abs() < 1e-9, "{at}: {id} gap");
                    }
                    let mass: f64 = segs.iter().map(|s| s.2).sum();
                    assert!((mass - m.mass).abs() < 0.01, "{at}: {id} segment masses");
                }
                other => panic!("{at}: member {id} appears {other:?}"),
            }
        }

        // Breaks: at a stud's face, through no piece but a plate, clear of openings' framing.
        for &u in &breaks {
            let at_face = members.values().any(|m| {
                is_stud(&m.role)
                    && !m.lying
                    && [m.half_thin, m.half_wide]
                        .iter()
                        .any(|h| ((m.u0 - h) - u).abs() <= TOL || ((m.u0 + h) - u).abs() <= TOL)
            });
            assert!(at_face, "{at}: break at u = {u} is at no stud's face");
            for (id, m) in &members {
                if is_plate(&m.role) && m.lying {
                    continue;
                }
                let through = if m.lying {
                    u > m.u0 + TOL && u < m.u1 - TOL
                } else {
                    (m.u0 - u).abs() < m.half_thin.min(m.half_wide) - TOL
                };
                assert!(
                    !through,
                    "{at}: break at u = {u} runs through {id} ({})",
                    m.role
                );
                let opening = match m.role.as_str() {
                    "header" | "sill" => u >= m.u0 - TOL && u <= m.u1 + TOL,
                    "jack_stud" | "cripple_stud" => (m.u0 - u).abs() <= m.half_thin + TOL,
                    _ => false,
                };
                assert!(!opening, "{at}: break at u = {u} in opening framing {id}");
            }
        }

        // Each panel: its mass recomputed, its end studs beside a break, its limits.
        for p in panels {
            let pid = p["panel_id"].as_str().unwrap();
            let (a, b) = (f(&p["u_start"]), f(&p["u_end"]));
            let mut mass: f64 = strs(&p["member_ids"]).iter().map(|m| members[m].mass).sum();
            mass += p["cut_pieces"]
                .as_array()
                .unwrap()
                .iter()
                .map(|c| f(&c["mass"]))
                .sum::<f64>();
            for added in p["added_pieces"].as_array().unwrap() {
                let of = &members[added["of"].as_str().unwrap()];
                assert!(
                    is_stud(&of.role),
                    "{at}: {pid} adds a copy of a {}",
                    of.role
                );
                assert_eq!(added["role"].as_str(), Some(of.role.as_str()));
                let (s, e) = (f(&added["u_start"]), f(&added["u_end"]));
                assert!(
                    ((s - a).abs() < 1e-9 && a > 0.0) || ((e - b).abs() < 1e-9 && panels.len() > 1),
                    "{at}: {pid}: added stud {} not at a break",
                    added["id"]
                );
                // Nothing upright of the panel stands where it is added.
                for id in strs(&p["member_ids"]) {
                    let m = &members[id];
                    if !m.lying {
                        assert!(
                            m.u0 + m.half_thin <= s + TOL || m.u0 - m.half_thin >= e - TOL,
                            "{at}: {pid}: added stud overlaps {id}"
                        );
                    }
                }
                mass += of.mass;
            }
            assert!((mass - f(&p["mass"])).abs() < 0.01, "{at}: {pid} mass");
            if panels.len() > 1 {
                let length = b - a;
                assert!(length <= max_length + 1e-9, "{at}: {pid} {length} m long");
                assert!(length >= min_length - 1e-9, "{at}: {pid} {length} m short");
                assert!(f(&p["height"]) <= max_height + 1e-9, "{at}: {pid} height");
                assert!(f(&p["mass"]) <= max_mass + 1e-9, "{at}: {pid} mass");
                assert_eq!(p["exceeds"], serde_json::json!([]), "{at}: {pid}");
            }
        }
    }
    split
}

/// The fewest panels any split can have: the wall's length over the longest panel, rounded up.
fn at_least(wall: &Value, plan: &Value) -> usize {
    (f(&wall["length"]) / f(&plan["panel_limits"]["max_length"]) - 1e-9).ceil() as usize
}

/// The study cells carry 7.5 m (conveyor 2 is 7.5 m long and conveyor 1's deck 7.5 m wide in
/// robots/cells/study-abb*.toml), below the default 12 m of `[panels]`.
const STUDY_CARRY: f64 = 7.5;

#[test]
fn real_framed_walls_are_split_within_the_limits() {
    let Some(model) = common::shared_path(
        "ifc-realworld/timber_autotimber-xbim-generated_outer-walls-5-framed_IFC4_feet.ifc",
    ) else {
        return;
    };
    for cell in ["study-abb", "study-abb-track"] {
        let plan = plan(&model, &["--cell", cell]);
        assert_eq!(f(&plan["panel_limits"]["max_length"]), STUDY_CARRY);
        assert_eq!(check_panels(&plan, cell), 4, "{cell}: every wall split");
        // Studs every 0.2 m leave a break within reach of every ideal: the fewest possible.
        for wall in plan["walls"].as_array().unwrap() {
            assert_eq!(
                wall["panels"].as_array().unwrap().len(),
                at_least(wall, &plan),
                "{cell} {}",
                wall["wall_id"]
            );
        }
    }
}

#[test]
fn the_three_storey_model_has_no_piece_longer_than_the_conveyors() {
    let Some(model) = common::shared_path("ifc-testcases/g_scale_3storey.ifc") else {
        return;
    };
    let plan = plan(&model, &[]);
    assert!(check_panels(&plan, "3-storey") >= 6);
    // Its walls have cap plates: every split wall ties its panels with site pieces.
    for wall in plan["walls"].as_array().unwrap() {
        let joints = wall["panels"].as_array().unwrap().len() - 1;
        let sites = wall["site_pieces"].as_array().unwrap().len();
        assert!(
            sites >= joints.min(1),
            "{}: {sites} site pieces",
            wall["wall_id"]
        );
    }
    let lengths: BTreeMap<&str, f64> = plan["members"]
        .as_array()
        .unwrap()
        .iter()
        .map(|m| (m["id"].as_str().unwrap(), f(&m["length"])))
        .collect();
    let mut longest: f64 = 0.0;
    for wall in plan["walls"].as_array().unwrap() {
        let panels = wall["panels"].as_array().unwrap();
        assert!(panels.len() >= at_least(wall, &plan));
        for p in panels {
            for m in strs(&p["member_ids"]) {
                longest = longest.max(lengths[m]);
            }
            for c in p["cut_pieces"].as_array().unwrap() {
                longest = longest.max(f(&c["length"]));
            }
        }
    }
    assert!(longest <= STUDY_CARRY, "longest piece {longest} m");
}

#[test]
fn walls_that_fit_stay_whole() {
    for tm in ["tm1", "tm2", "tm3"] {
        let model = root().join(format!("examples/models/{tm}.ifc"));
        let plan = plan(&model, &[]);
        assert_eq!(check_panels(&plan, tm), 0, "{tm}");
        for wall in plan["walls"].as_array().unwrap() {
            let panel = &wall["panels"][0];
            assert_eq!(panel["member_ids"], wall["member_ids"], "{tm}");
            assert_eq!(
                panel["panel_id"],
                format!("{}-P1", wall["wall_id"].as_str().unwrap())
            );
        }
        assert!(
            !plan["warnings"].to_string().contains("panel"),
            "{tm}: {}",
            plan["warnings"]
        );
    }
}

/// `synth wall` with these arguments, planned on the default cell.
fn synth_plan(dir: &Path, name: &str, args: &[&str], extra: &[&str]) -> Value {
    let ifc = dir.join(format!("{name}.ifc"));
    let out = framewright(
        &[
            &[
                "synth",
                "wall",
                "-o",
                ifc.to_str().unwrap(),
                "--grouping",
                "wall",
            ][..],
            args,
        ]
        .concat(),
    );
    assert!(
        out.status.success(),
        "synth wall {args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    plan(&ifc, extra)
}

#[test]
fn openings_across_every_candidate_break_stay_whole() {
    let dir = tempfile::tempdir().unwrap();
    // Openings where the equal division would break (7.0 of 14 m; 5.0 and 10.0 of 15 m),
    // three windows side by side sharing their kings, a wall just over the limit and one shorter than the minimum.
    let cases: &[&[&str]] = &[
        &["--length", "14", "--window", "6.4,1.2,1.2,0.9"],
        &[
            "--length",
            "14",
            "--door",
            "6.6,0.9,2.1",
            "--header",
            "flat",
        ],
        &[
            "--length",
            "15",
            "--window",
            "4.5,1.0,1.2,0.9",
            "--door",
            "9.6,0.9,2.1",
            "--double-kings",
        ],
        &[
            "--length",
            "15",
            "--window",
            "118in,59in,47in,35in",
            "--window",
            "181.5in,59in,47in,35in",
            "--window",
            "245in,59in,47in,35in",
            "--lumber",
            "2x6",
        ],
        &["--length", "7.6"],
        &[
            "--length",
            "7.6",
            "--window",
            "3.5,0.8,1.0,1.0",
            "--unit",
            "ft",
        ],
        &["--length", "1.0"],
        &["--length", "20", "--spacing", "24in", "--single-top-plate"],
    ];
    for (i, args) in cases.iter().enumerate() {
        let plan = synth_plan(dir.path(), &format!("w{i}"), args, &[]);
        let split = check_panels(&plan, &format!("{args:?}"));
        let wall = &plan["walls"][0];
        let over = f(&wall["length"]) > STUDY_CARRY;
        assert_eq!(split, usize::from(over), "{args:?}");
        if over {
            assert!(wall["panels"].as_array().unwrap().len() >= at_least(wall, &plan));
        }
    }
}

#[test]
fn panels_off_keeps_every_wall_whole() {
    let dir = tempfile::tempdir().unwrap();
    let plan = synth_plan(
        dir.path(),
        "long",
        &["--length", "16"],
        &["--panels", "off"],
    );
    assert_eq!(check_panels_unlimited(&plan), 1);
    let warnings = plan["warnings"].to_string();
    let panel = plan["walls"][0]["panels"][0]["panel_id"].as_str().unwrap();
    assert!(
        warnings.contains(&format!(
            "{panel}: the panel exceeds the cell's panel limits: length 16.000 m > the cell's 7.500 m"
        )),
        "{warnings}"
    );
}

/// The number of panels of a plan whose walls were not split.
fn check_panels_unlimited(plan: &Value) -> usize {
    plan["walls"]
        .as_array()
        .unwrap()
        .iter()
        .map(|w| w["panels"].as_array().unwrap().len())
        .sum()
}

#[test]
fn moving_one_stud_moves_at_most_the_break_beside_it() {
    let dir = tempfile::tempdir().unwrap();
    let base = dir.path().join("long.ifc");
    long_wall(&base);
    let text = std::fs::read_to_string(&base).unwrap();
    let breaks = |plan: &Value| -> Vec<f64> {
        plan["walls"][0]["panel_breaks"]
            .as_array()
            .unwrap()
            .iter()
            .map(|b| f(&b["u"]))
            .collect()
    };
    let before = breaks(&plan(&base, &[]));
    assert_eq!(before.len(), 2, "20 m on a 7.5 m cell: 3 panels");
    let points = stud_points(&text);
    assert!(points.len() > 30);
    let moved = dir.path().join("moved.ifc");
    let mut moved_breaks = 0;
    for point in points.iter().step_by(2) {
        std::fs::write(&moved, move_point(&text, point, 0.02)).unwrap();
        let plan = plan(&moved, &[]);
        check_panels(&plan, point);
        let after = breaks(&plan);
        assert_eq!(after.len(), before.len(), "{point}");
        let changed: Vec<(f64, f64)> = before
            .iter()
            .zip(&after)
            .filter(|(a, b)| (*a - *b).abs() > 1e-9)
            .map(|(a, b)| (*a, *b))
            .collect();
        assert!(changed.len() <= 1, "moving {point} moved {changed:?}");
        moved_breaks += changed.len();
    }
    assert!(
        moved_breaks > 0,
        "no move touched a break: the test moves nothing"
    );
}

#[test]
fn a_cell_whose_shortest_panel_exceeds_what_it_carries_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let cell = dir.path().join("cell.toml");
    let text = std::fs::read_to_string(root().join("robots/cells/study-abb.toml")).unwrap();
    let text = text + "\n[panels]\nmin_length = 8.0\n";
    std::fs::write(&cell, text).unwrap();
    let tm1 = root().join("examples/models/tm1.ifc");
    let out = framewright(&[
        "plan",
        tm1.to_str().unwrap(),
        "--cell",
        cell.to_str().unwrap(),
    ]);
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("panels.min_length") && err.contains("7.50 m"),
        "{err}"
    );
}

#[test]
fn a_shop_rule_forbids_breaks_and_the_interpreter_agrees() {
    let dir = tempfile::tempdir().unwrap();
    let long = dir.path().join("long.ifc");
    let out = framewright(&[
        "synth",
        "wall",
        "--length",
        "14",
        "--window",
        "2.0,1.2,1.2,0.9",
        "-o",
        long.to_str().unwrap(),
    ]);
    assert!(out.status.success());
    // The built-in rules on the interpreter split as the compiled engine does.
    let rules = root().join("rules");
    let compiled = plan(&long, &[]);
    let interpreted = plan(&long, &["--rules-dir", rules.to_str().unwrap()]);
    assert_eq!(
        compiled["walls"][0]["panels"],
        interpreted["walls"][0]["panels"]
    );
    // A shop forbids joints within 1 m of mid-wall: no break lands there, the split holds.
    let shop = dir.path().join("rules");
    std::fs::create_dir(&shop).unwrap();
    for entry in std::fs::read_dir(&rules).unwrap() {
        let path = entry.unwrap().path();
        std::fs::copy(&path, shop.join(path.file_name().unwrap())).unwrap();
    }
    std::fs::write(
        shop.join("shop.dl"),
        "break_forbidden(w, m - 1.0, m + 1.0, \"no joint near mid-wall\") :- wall_size(w, l, _, _), m = l / 2.0.\n",
    )
    .unwrap();
    let shop_plan = plan(&long, &["--rules-dir", shop.to_str().unwrap()]);
    check_panels(&shop_plan, "shop");
    let breaks: Vec<f64> = shop_plan["walls"][0]["panel_breaks"]
        .as_array()
        .unwrap()
        .iter()
        .map(|b| f(&b["u"]))
        .collect();
    assert!(!breaks.is_empty());
    assert!(
        breaks.iter().all(|u| !(6.0..=8.0).contains(u)),
        "{breaks:?}"
    );
    let before: Vec<f64> = compiled["walls"][0]["panel_breaks"]
        .as_array()
        .unwrap()
        .iter()
        .map(|b| f(&b["u"]))
        .collect();
    assert!(
        before.iter().any(|u| (6.0..=8.0).contains(u)),
        "without the rule a break lies near mid-wall ({before:?}): the rule must change something"
    );
    // The same file given with --rules joins the built-in rules: the same panels.
    let with_rules = plan(&long, &["--rules", shop.join("shop.dl").to_str().unwrap()]);
    assert_eq!(with_rules["walls"], shop_plan["walls"]);
    // So it does for simulate: its panels are those breaks' panels.
    let sim = |extra: &[&str]| -> Value {
        let m = long.to_str().unwrap();
        let out = framewright(&[&["simulate", m, "--json", "--no-cache"][..], extra].concat());
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        serde_json::from_slice(&out.stdout).unwrap()
    };
    let ids = |v: &Value| -> Vec<String> {
        v["walls"][0]["panels"]
            .as_array()
            .unwrap()
            .iter()
            .map(|p| format!("{}:{}", p["panel_id"], p["u_start"]))
            .collect()
    };
    let shop_sim = sim(&["--rules", shop.join("shop.dl").to_str().unwrap()]);
    let panel_members = |v: &Value| -> Vec<usize> {
        v["panels"]
            .as_array()
            .unwrap()
            .iter()
            .map(|p| {
                v["elements"]
                    .as_array()
                    .unwrap()
                    .iter()
                    .filter(|e| e["panel_id"] == p["panel_id"])
                    .count()
            })
            .collect()
    };
    let planned: Vec<usize> = shop_plan["walls"][0]["panels"]
        .as_array()
        .unwrap()
        .iter()
        .map(|p| {
            p["member_ids"].as_array().unwrap().len()
                + p["cut_pieces"].as_array().unwrap().len()
                + p["added_pieces"].as_array().unwrap().len()
        })
        .collect();
    assert_eq!(panel_members(&shop_sim), planned, "{:?}", ids(&shop_plan));
    // A file that both feeds the rule base and reports findings is refused, naming both.
    let mixed = dir.path().join("mixed.dl");
    std::fs::write(
        &mixed,
        "break_forbidden(w, 0.0, 1.0, \"no joint at the start\") :- wall_size(w, _, _, _).\nwarning(w, \"w\", \"m\") :- wall_size(w, _, _, _).\n",
    )
    .unwrap();
    let out = framewright(&[
        "plan",
        long.to_str().unwrap(),
        "--rules",
        mixed.to_str().unwrap(),
    ]);
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("break_forbidden") && err.contains("warning") && err.contains("two files"),
        "{err}"
    );
    // With a rule base of one's own, such a file belongs in it.
    let out = framewright(&[
        "plan",
        long.to_str().unwrap(),
        "--rules-dir",
        rules.to_str().unwrap(),
        "--rules",
        shop.join("shop.dl").to_str().unwrap(),
    ]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("put the file in that directory"));
}

fn stdout_of(args: &[&str]) -> String {
    let out = framewright(args);
    assert!(
        out.status.success(),
        "{args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8(out.stdout).unwrap()
}

#[test]
fn why_explains_panels_segments_added_studs_and_breaks_not_made() {
    let dir = tempfile::tempdir().unwrap();
    let ifc = dir.path().join("w14.ifc");
    let m = ifc.to_str().unwrap();
    // 14 m with a window across the middle: two panels would need a break in it.
    stdout_of(&[
        "synth",
        "wall",
        "--length",
        "14",
        "--window",
        "6.4,1.2,1.2,0.9",
        "-o",
        m,
    ]);
    let plan = plan(&ifc, &[]);
    let wall = &plan["walls"][0];
    let panels = wall["panels"].as_array().unwrap();
    assert_eq!(panels.len(), 3, "no break allowed between 6.5 and 7.5 m");
    let second = &panels[1];
    let (a, b) = (f(&second["u_start"]), f(&second["u_end"]));

    let text = stdout_of(&["why", m, "W1-P2"]);
    assert!(
        text.starts_with(&format!("panel W1-P2 of wall W1: u = {a:.3} .. {b:.3} m")),
        "{text}"
    );
    assert!(text.contains("split into 3 panels"), "{text}");
    assert!(
        text.contains("at most 7.500 m (what its conveyors carry"),
        "{text}"
    );
    for brk in wall["panel_breaks"].as_array().unwrap() {
        assert!(text.contains(brk["reason"].as_str().unwrap()), "{text}");
    }

    let segment = second["cut_pieces"][0]["id"].as_str().unwrap();
    let text = stdout_of(&["why", m, segment]);
    assert!(
        text.contains("a segment of") && text.contains("in panel W1-P2"),
        "{text}"
    );
    // The cap's stretch across the first joint: a site piece, held back the cell's lap.
    let site = &wall["site_pieces"][0];
    let lap = f(&plan["panel_limits"]["cap_lap"]);
    assert!((f(&site["length"]) - 2.0 * lap).abs() < 1e-6, "{site}");
    let text = stdout_of(&["why", m, site["id"].as_str().unwrap()]);
    assert!(
        text.contains("across the joint of panels W1-P1 and W1-P2")
            && text.contains(&format!("held back {lap:.3} m"))
            && text.contains("cap_plate_laps"),
        "{text}"
    );
    let added = panels
        .iter()
        .flat_map(|p| p["added_pieces"].as_array().unwrap())
        .next()
        .expect("a break beside a single stud adds one");
    let text = stdout_of(&["why", m, added["id"].as_str().unwrap(), "--json"]);
    let answer: Value = serde_json::from_str(&text).unwrap();
    assert_eq!(answer["kind"], "added_piece");
    assert!(
        answer["explanation"][0]
            .as_str()
            .unwrap()
            .contains(added["of"].as_str().unwrap())
    );

    // In the window: the break would run through its header and sill.
    let text = stdout_of(&["why-not", m, "panel_break(W1, 7.0)"]);
    assert!(
        text.contains("would run through") && text.contains("(header,") && text.contains("(sill,"),
        "{text}"
    );
    // At the break made.
    let made = f(&wall["panel_breaks"][0]["u"]);
    let text = stdout_of(&["why-not", m, &format!("panel_break(W1, {made})")]);
    assert!(
        text.starts_with(&format!("W1 is split at u = {made:.3} m")),
        "{text}"
    );
    // Near the king studs: not allowed, the opening's framing stays whole.
    let text = stdout_of(&["why-not", m, "panel_break(W1, 6.45)"]);
    assert!(
        text.contains("not allowed: an opening's framing stays in one panel"),
        "{text}"
    );

    // Unknown ones are refused, naming what exists.
    let out = framewright(&["why", m, "W1-P9"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("names no panel"));
    let out = framewright(&["why-not", m, "panel_break(W7, 1.0)"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("no wall `W7`"));
}

#[test]
fn the_report_shows_each_panel_on_its_own_with_the_walls_panels() {
    let dir = tempfile::tempdir().unwrap();
    let ifc = dir.path().join("w9.ifc");
    let m = ifc.to_str().unwrap();
    stdout_of(&[
        "synth",
        "wall",
        "--length",
        "9",
        "--window",
        "2.0,1.2,1.2,0.9",
        "-o",
        m,
    ]);
    let plan = plan(&ifc, &[]);
    let panels = plan["walls"][0]["panels"].as_array().unwrap();
    assert_eq!(panels.len(), 2, "9 m on a 7.5 m cell");
    let out = dir.path().join("report");
    stdout_of(&[
        "simulate",
        m,
        "--no-cache",
        "--report",
        out.to_str().unwrap(),
    ]);
    let page = std::fs::read_to_string(out.join("index.html")).unwrap();
    // Each panel is built, drawn and reported on its own, with the wall's panels listed.
    assert_eq!(
        page.matches("<table class=\"panels\">").count(),
        panels.len(),
        "one panel table per panel section"
    );
    // Each section draws the whole wall with its breaks where the plan put them, its own panel
    // marked.
    let breaks = plan["walls"][0]["panel_breaks"].as_array().unwrap();
    assert_eq!(
        page.matches("<line class=\"break\"").count(),
        breaks.len() * panels.len()
    );
    for b in breaks {
        assert!(page.contains(&format!("u = {:.3} m", f(&b["u"]))));
    }
    for p in panels {
        let id = p["panel_id"].as_str().unwrap();
        assert!(
            page.contains(&format!("<g class=\"panel this\" data-panel=\"{id}\">")),
            "{id}'s section does not mark its panel on the wall"
        );
        assert!(page.contains(&format!("<td>{id}</td>")), "no row for {id}");
        assert!(
            page.contains(&format!("({id})</h2>")),
            "no section for {id}"
        );
        assert!(
            page.contains(&format!("<tr class=\"this\"><td>{id}</td>")),
            "{id}'s section does not mark its own row"
        );
    }
    // Each section draws exactly its panel's pieces: the plan's members, segments and added
    // studs of that panel.
    let sections: Vec<&str> = page.split("<section class=\"wall\"").skip(1).collect();
    assert_eq!(sections.len(), panels.len());
    for (p, section) in panels.iter().zip(&sections) {
        let mut expected: Vec<&str> = strs(&p["member_ids"]);
        for kind in ["cut_pieces", "added_pieces"] {
            for piece in p[kind].as_array().unwrap() {
                expected.push(piece["id"].as_str().unwrap());
            }
        }
        expected.sort_unstable();
        let mut drawn: Vec<&str> = section
            .split("data-id=\"")
            .skip(1)
            .map(|rest| &rest[..rest.find('"').unwrap()])
            .collect();
        // A piece appears in each drawing (elevation, cell view, timeline).
        drawn.sort_unstable();
        drawn.dedup();
        assert_eq!(drawn, expected, "{}", p["panel_id"]);
    }
    // A wall that fits has neither.
    let one = dir.path().join("w6.ifc");
    stdout_of(&[
        "synth",
        "wall",
        "--length",
        "6",
        "-o",
        one.to_str().unwrap(),
    ]);
    let out = dir.path().join("report6");
    stdout_of(&[
        "simulate",
        one.to_str().unwrap(),
        "--no-cache",
        "--report",
        out.to_str().unwrap(),
    ]);
    let page = std::fs::read_to_string(out.join("index.html")).unwrap();
    assert!(!page.contains("class=\"panels\""));
}
