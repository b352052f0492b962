//! Walls are grouped by geometry and checked against the model's own groups (members
//! aggregated in an IfcWall). In TM3 written with its walls as IfcWalls, one member is moved
//! into another wall's group and one is taken out of its group (left in the storey). Then:
//! - the group that now reaches into a second wall is reported as split;
//! - the two walls holding pieces of two groups, or grouped and loose pieces, are reported
//!   as mixed;
//! - only the untouched wall keeps its group's id.

mod common;

use common::wall_holding;
use regex::Regex;
use serde_json::Value;
use std::path::Path;
use std::process::Command;

fn framewright(args: &[&str]) -> String {
    let out = Command::new(env!("CARGO_BIN_EXE_framewright"))
        .args(args)
        .output()
        .expect("framewright runs");
    assert!(
        out.status.success(),
        "framewright {args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8(out.stdout).expect("UTF-8")
}

fn plan(path: &Path) -> Value {
    let json = framewright(&["plan", "--no-cache", "--json", path.to_str().unwrap()]);
    serde_json::from_str(&json).expect("plan JSON")
}

/// An IfcWall's aggregation: its whole line, the wall's #id and its members' #ids.
struct Aggregation {
    line: String,
    wall: String,
    members: Vec<String>,
}

fn wall_aggregations(ifc: &str) -> Vec<Aggregation> {
    let rel = Regex::new(r"(?m)^#\d+=IFCRELAGGREGATES\('[^']*',#\d+,\$,\$,(#\d+),\(([^)]*)\)\);$")
        .unwrap();
    rel.captures_iter(ifc)
        .filter(|c| ifc.contains(&format!("\n{}=IFCWALL(", &c[1])))
        .map(|c| Aggregation {
            line: c[0].to_string(),
            wall: c[1].to_string(),
            members: c[2].split(',').map(str::to_string).collect(),
        })
        .collect()
}

fn with_members(a: &Aggregation, members: &[String]) -> String {
    a.line.replace(
        &format!("({})", a.members.join(",")),
        &format!("({})", members.join(",")),
    )
}

/// The GlobalId of entity `#id`.
fn global_id(ifc: &str, id: &str) -> String {
    let re = Regex::new(&format!(r"(?m)^{id}=IFC\w+\('([^']*)'")).unwrap();
    re.captures(ifc).expect("entity")[1].to_string()
}

#[test]
fn split_groups_and_mixed_walls_are_reported() {
    let dir = tempfile::tempdir().unwrap();
    let base = dir.path().join("tm3.ifc");
    framewright(&[
        "synth",
        "tm3",
        "--grouping",
        "wall",
        "-o",
        base.to_str().unwrap(),
    ]);
    let ifc = std::fs::read_to_string(&base).unwrap();

    // As written, every wall is exactly its group.
    let before = plan(&base);
    assert_eq!(before["warnings"], serde_json::json!([]));
    let walls = before["walls"].as_array().unwrap();
    assert_eq!(walls.len(), 4);
    assert!(walls.iter().all(|w| w["group_global_id"].is_string()));

    let groups = wall_aggregations(&ifc);
    assert_eq!(groups.len(), 4, "one aggregation per IfcWall");
    let (a, b, c, d) = (&groups[0], &groups[1], &groups[2], &groups[3]);
    let moved = b.members[0].clone();
    let loose = c.members[0].clone();
    let mut edited = ifc
        .replace(
            &a.line,
            &with_members(a, &[&a.members[..], std::slice::from_ref(&moved)].concat()),
        )
        .replace(&b.line, &with_members(b, &b.members[1..]))
        .replace(&c.line, &with_members(c, &c.members[1..]));
    // The loose member stays in the storey.
    let contained =
        Regex::new(r"(IFCRELCONTAINEDINSPATIALSTRUCTURE\('[^']*',#\d+,\$,\$,\()([^)]*)\)").unwrap();
    edited = contained
        .replace(&edited, |c: &regex::Captures| {
            format!("{}{},{loose})", &c[1], &c[2])
        })
        .into_owned();
    let path = dir.path().join("edited.ifc");
    std::fs::write(&path, &edited).unwrap();

    let after = plan(&path);
    assert_eq!(
        after["walls"].as_array().unwrap().len(),
        4,
        "the same walls"
    );
    let warnings: Vec<&str> = after["warnings"]
        .as_array()
        .unwrap()
        .iter()
        .map(|w| w.as_str().unwrap())
        .collect();

    // Group a reaches into b's wall.
    let a_id = global_id(&ifc, &a.wall);
    let split: Vec<&&str> = warnings
        .iter()
        .filter(|w| w.starts_with(&format!("{a_id}:")) && w.contains("several wall planes"))
        .collect();
    assert_eq!(split.len(), 1, "{warnings:#?}");

    // b's wall holds pieces of a and b; c's wall a loose piece beside grouped ones.
    let mixed = |member: &str| {
        let wall = wall_holding(&after, &global_id(&ifc, member));
        assert!(wall["group_global_id"].is_null(), "{wall}");
        let id = wall["wall_id"].as_str().unwrap();
        warnings
            .iter()
            .filter(|w| w.starts_with(&format!("{id}:")) && w.contains("several IFC groups"))
            .count()
    };
    assert_eq!(mixed(&moved), 1, "{warnings:#?}");
    assert_eq!(mixed(&loose), 1, "{warnings:#?}");
    assert_eq!(warnings.len(), 3, "{warnings:#?}");

    // a's own wall is no longer exactly its group; d's is.
    let a_wall = wall_holding(&after, &global_id(&ifc, &a.members[0]));
    assert!(a_wall["group_global_id"].is_null());
    let d_wall = wall_holding(&after, &global_id(&ifc, &d.members[0]));
    assert_eq!(d_wall["group_global_id"], global_id(&ifc, &d.wall).as_str());
}
