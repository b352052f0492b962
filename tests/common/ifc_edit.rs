//! Small edits of the synthetic models' IFC text: the tests move a stud and see what follows.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// Writes a 20 m wall with a window at 5 m, its members grouped in an IfcWall: three panels on
/// a cell that carries 7.5 m.
pub fn long_wall(path: &Path) {
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_framewright"))
        .args(["synth", "wall", "--length", "20", "--grouping", "wall"])
        .args(["--window", "5.0,1.2,1.2,0.9", "-o"])
        .arg(path)
        .output()
        .expect("framewright runs");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

/// `text` with the IfcCartesianPoint `point` (`#id`) moved by `du` along x: in a
/// `--grouping wall` model, which places members in their wall's frame, along the wall.
pub fn move_point(text: &str, point: &str, du: f64) -> String {
    let line = text
        .lines()
        .find(|l| l.starts_with(&format!("{point}=")))
        .unwrap();
    let body = &line[line.find("((").unwrap() + 2..line.find("))").unwrap()];
    let xyz: Vec<f64> = body.split(',').map(|c| c.trim().parse().unwrap()).collect();
    let new = format!(
        "{point}=IFCCARTESIANPOINT(({:?},{:?},{:?}));",
        xyz[0] + du,
        xyz[1],
        xyz[2]
    );
    text.replacen(line, &new, 1)
}

/// The placement points of the model's studs (IfcMember .STUD.), in file order.
pub fn stud_points(text: &str) -> Vec<String> {
    let lines: BTreeMap<&str, &str> = text
        .lines()
        .filter_map(|l| l.split_once('='))
        .filter(|(id, _)| id.starts_with('#'))
        .collect();
    let inside = |id: &str| {
        let body = lines[id.trim()];
        body[body.find('(').unwrap() + 1..body.rfind(')').unwrap()].to_string()
    };
    text.lines()
        .filter(|l| l.contains("IFCMEMBER(") && l.contains(".STUD."))
        .map(|l| {
            let body = l.split_once('=').unwrap().1;
            let placement = body.split(',').nth(5).unwrap().trim().to_string();
            let local = inside(&placement);
            let axis = local.split_once(',').unwrap().1.to_string();
            inside(&axis).split(',').next().unwrap().trim().to_string()
        })
        .collect()
}

/// TM3 (`examples/models/tm3.ifc`) with stud F-016 (#145) modelled `dy` m across the wall from
/// where it is, written into `dir`.
pub fn tm3_stud_moved(dir: &Path, dy: f64) -> PathBuf {
    let tm3 = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/models/tm3.ifc");
    let text = std::fs::read_to_string(tm3).unwrap();
    let at = "#139=IFCCARTESIANPOINT((1.1684,0.04445,0.0381));";
    assert!(text.contains(at), "TM3's stud F-016 moved in the model");
    let moved = text.replace(
        at,
        &format!("#139=IFCCARTESIANPOINT((1.1684,{},0.0381));", 0.04445 + dy),
    );
    let path = dir.join("tm3_stud_moved.ifc");
    std::fs::write(&path, moved).unwrap();
    path
}
