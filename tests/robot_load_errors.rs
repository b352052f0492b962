//! Bad robot files are refused with the file and what is wrong, never a panic.

use framewright::cell::{Robot, RobotMeta};
use std::path::Path;

fn from_str(urdf: &str) -> String {
    Robot::from_urdf_str(Path::new("bad.urdf"), urdf, RobotMeta::default())
        .map(|r| format!("loaded {}", r.name))
        .unwrap_or_else(|e| e.to_string())
}

const LINKS: &str = r#"<link name="base_link"/><link name="a"/><link name="b"/>"#;

fn joint(name: &str, kind: &str, parent: &str, child: &str) -> String {
    format!(
        r#"<joint name="{name}" type="{kind}"><parent link="{parent}"/><child link="{child}"/><origin xyz="0 0 0.1" rpy="0 0 0"/><axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="0" velocity="1"/></joint>"#
    )
}

#[test]
fn malformed_xml() {
    let msg = from_str("<robot name=\"x\"><link name=\"a\"></robot>");
    assert!(msg.starts_with("bad.urdf: URDF:"), "{msg}");
}

#[test]
fn unknown_link_in_joint() {
    let msg = from_str(&format!(
        r#"<robot name="x">{LINKS}{}</robot>"#,
        joint("j", "revolute", "base_link", "zz")
    ));
    assert!(msg.contains("joint `j`: unknown child link `zz`"), "{msg}");
}

#[test]
fn two_roots() {
    let msg = from_str(&format!(
        r#"<robot name="x">{LINKS}{}</robot>"#,
        joint("j", "revolute", "base_link", "a")
    ));
    assert!(msg.contains("expected one root link"), "{msg}");
}

#[test]
fn cycle() {
    let urdf = format!(
        r#"<robot name="x">{LINKS}{}{}{}</robot>"#,
        joint("j1", "revolute", "a", "b"),
        joint("j2", "revolute", "b", "a"),
        joint("j3", "revolute", "base_link", "b")
    );
    let msg = from_str(&urdf);
    assert!(
        msg.contains("two parent joints") || msg.contains("cycle"),
        "{msg}"
    );
}

#[test]
fn moving_side_branch_is_not_a_serial_chain() {
    let urdf = format!(
        r#"<robot name="x">{LINKS}<link name="tool0"/>{}{}{}</robot>"#,
        joint("j1", "revolute", "base_link", "a"),
        joint("j2", "revolute", "base_link", "b"),
        joint("j3", "fixed", "a", "tool0")
    );
    let msg = from_str(&urdf);
    assert!(
        msg.contains("joint `j2` moves but is not on the chain"),
        "{msg}"
    );
}

#[test]
fn limits_upside_down() {
    let urdf = format!(
        r#"<robot name="x">{LINKS}{}{}</robot>"#,
        joint("j1", "revolute", "base_link", "a")
            .replace(r#"lower="-1" upper="1""#, r#"lower="1" upper="-1""#),
        joint("j2", "revolute", "a", "b")
    );
    let msg = from_str(&urdf);
    assert!(
        msg.contains("joint `j1`: lower limit 1 is above the upper limit -1"),
        "{msg}"
    );
}

#[test]
fn without_tool0_the_single_end_link_is_the_tip() {
    let urdf = format!(
        r#"<robot name="x">{LINKS}{}{}</robot>"#,
        joint("j1", "revolute", "base_link", "a"),
        joint("j2", "revolute", "a", "b")
    );
    assert_eq!(from_str(&urdf), "loaded x");
    let robot = Robot::from_urdf_str(Path::new("x.urdf"), &urdf, RobotMeta::default()).unwrap();
    assert_eq!(robot.links[robot.tip].name, "b");
    assert_eq!(robot.dof(), 2);
}

#[test]
fn bad_metadata_names_file_line_and_key() {
    let dir = tempfile::tempdir().unwrap();
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("robots");
    std::fs::copy(
        root.join("kuka-kr150-2.urdf"),
        dir.path().join("kuka-kr150-2.urdf"),
    )
    .unwrap();
    let text = std::fs::read_to_string(root.join("kuka-kr150-2.toml")).unwrap();
    std::fs::write(
        dir.path().join("k.toml"),
        text.replace("payload = 150.0", "payload = -1.0"),
    )
    .unwrap();
    let msg = Robot::load_path(&dir.path().join("k.toml"))
        .unwrap_err()
        .to_string();
    assert!(
        msg.contains("k.toml:7: key `payload`: expected a positive number"),
        "{msg}"
    );
    std::fs::write(
        dir.path().join("k.toml"),
        text.replace("[opw]", "[opw]\nd7 = 1.0"),
    )
    .unwrap();
    let msg = Robot::load_path(&dir.path().join("k.toml"))
        .unwrap_err()
        .to_string();
    assert!(
        msg.contains("k.toml:") && msg.contains("key `opw.d7`: unknown field"),
        "{msg}"
    );
}

#[test]
fn missing_file() {
    let msg = Robot::load("no/such/robot.urdf").unwrap_err().to_string();
    assert!(msg.starts_with("no/such/robot.urdf: cannot read"), "{msg}");
}
