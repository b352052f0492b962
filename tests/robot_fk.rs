//! FK of the shipped robots against the reference matrices in ../shared/robot-reference/README.md
//! and against the reference URDFs there.

mod common;

use framewright::cell::{Robot, RobotMeta, matrix_rows};
use std::f64::consts::FRAC_PI_2;
use std::path::{Path, PathBuf};

fn shared() -> Option<PathBuf> {
    common::shared_path("robot-reference")
}

struct Reference {
    robot: String,
    q: Vec<f64>,
    link: String,
    matrix: [[f64; 4]; 4],
}

/// Reads blocks like "`abb_irb4600_40_255` q = zero = [..], base_link -> tool0:" + ``` 4 rows ```.
fn references(readme: &str) -> Vec<Reference> {
    let lines: Vec<&str> = readme.lines().collect();
    let mut out = vec![];
    for (i, line) in lines.iter().enumerate() {
        let Some(rest) = line.strip_prefix('`') else {
            continue;
        };
        let Some((robot, rest)) = rest.split_once('`') else {
            continue;
        };
        let Some((_, rest)) = rest.split_once(" q = ") else {
            continue;
        };
        let Some((_, rest)) = rest.split_once('[') else {
            continue;
        };
        let Some((qs, rest)) = rest.split_once(']') else {
            continue;
        };
        let Some(link) = rest
            .trim()
            .strip_prefix(", base_link -> ")
            .and_then(|l| l.strip_suffix(':'))
        else {
            continue;
        };
        // The README prints joints with 6 decimals; ±1.570796 there is ±π/2 (the wrist_down and
        // kuka_home vectors), restored exactly so the comparison tests FK, not the rounding.
        let q: Vec<f64> = qs
            .split(',')
            .map(|v| v.trim().parse::<f64>().unwrap())
            .map(|v| {
                if (v.abs() - FRAC_PI_2).abs() < 1e-6 {
                    FRAC_PI_2.copysign(v)
                } else {
                    v
                }
            })
            .collect();
        assert_eq!(lines[i + 1].trim(), "```");
        let mut matrix = [[0.0; 4]; 4];
        for (r, row) in matrix.iter_mut().enumerate() {
            let text = lines[i + 2 + r]
                .trim()
                .trim_start_matches('[')
                .trim_end_matches(']');
            for (c, v) in text.split(',').enumerate() {
                row[c] = v.trim().parse().unwrap();
            }
        }
        out.push(Reference {
            robot: robot.to_string(),
            q,
            link: link.to_string(),
            matrix,
        });
    }
    out
}

#[test]
#[allow(clippy::needless_range_loop)]
fn fk_matches_every_reference_matrix() {
    let Some(dir) = shared() else { return };
    let readme = std::fs::read_to_string(dir.join("README.md")).unwrap();
    let refs = references(&readme);
    let mut checked = 0;
    for (reference_name, ours) in [
        ("abb_irb4600_40_255", "abb-irb4600-40-255"),
        ("kuka_kr150_2", "kuka-kr150-2"),
    ] {
        let robot = Robot::load(ours).unwrap();
        let mine: Vec<&Reference> = refs.iter().filter(|r| r.robot == reference_name).collect();
        assert!(
            mine.len() >= 8,
            "expected the README's matrices for {reference_name}, found {}",
            mine.len()
        );
        for r in mine {
            let pose = robot
                .fk_link(&r.q, &r.link)
                .unwrap_or_else(|| panic!("no link {}", r.link));
            let m = matrix_rows(&pose);
            for row in 0..4 {
                for col in 0..4 {
                    let d = (m[row][col] - r.matrix[row][col]).abs();
                    // The README prints 6 decimals: round-off is at most 5e-7.
                    assert!(
                        d <= 1e-6,
                        "{ours} q={:?} {}: entry ({row},{col}) = {} vs reference {} (diff {d:.2e})",
                        r.q,
                        r.link,
                        m[row][col],
                        r.matrix[row][col]
                    );
                }
            }
            checked += 1;
        }
    }
    assert_eq!(checked, 16);
}

fn strip_visuals(urdf: &str) -> String {
    let mut out = String::new();
    let mut rest = urdf;
    while let Some(start) = rest.find("<visual") {
        out.push_str(&rest[..start]);
        let end =
            rest[start..].find("</visual>").expect("closed visual") + start + "</visual>".len();
        rest = &rest[end..];
    }
    out.push_str(rest);
    out
}

struct Lcg(u64);
impl Lcg {
    fn next(&mut self) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }
}

#[test]
fn fk_matches_the_reference_urdfs_on_random_joints() {
    let Some(dir) = shared() else { return };
    for (file, ours) in [
        ("abb_irb4600_40_255.urdf", "abb-irb4600-40-255"),
        ("kuka_kr150_2.urdf", "kuka-kr150-2"),
    ] {
        // The reference files carry two <material> in some <visual> (urdf-rs refuses that); the
        // visuals do not matter for FK, so they are dropped before parsing.
        let text = strip_visuals(&std::fs::read_to_string(dir.join(file)).unwrap());
        let reference = Robot::from_urdf_str(&dir.join(file), &text, RobotMeta::default()).unwrap();
        let robot = Robot::load(ours).unwrap();
        assert_eq!(reference.dof(), 6);
        let limits = robot.limits();
        for (a, b) in reference.limits().iter().zip(&limits) {
            assert!(
                (a.0 - b.0).abs() < 1e-9 && (a.1 - b.1).abs() < 1e-9,
                "limits {a:?} vs {b:?}"
            );
        }
        for (a, b) in reference.active_joints().zip(robot.active_joints()) {
            assert!(
                (a.velocity - b.velocity).abs() < 1e-9,
                "{}: velocity",
                b.name
            );
        }
        let mut rng = Lcg(7);
        for _ in 0..2000 {
            let q: Vec<f64> = limits
                .iter()
                .map(|&(lo, hi)| lo + (hi - lo) * rng.next())
                .collect();
            let all_ref = reference.fk_all(&q);
            let all_own = robot.fk_all(&q);
            // The IK's FK (fixed joints folded) agrees with the per-link FK.
            let tip = robot.fk_tip(&q);
            let tool0 = all_own[robot.link_index("tool0").unwrap()];
            assert!((tip.translation.vector - tool0.translation.vector).norm() < 1e-12);
            assert!(tip.rotation.angle_to(&tool0.rotation) < 1e-12);
            for name in [
                "link_1", "link_2", "link_3", "link_4", "link_5", "link_6", "tool0",
            ] {
                let a = all_ref[reference.link_index(name).unwrap()];
                let b = all_own[robot.link_index(name).unwrap()];
                assert!(
                    (a.translation.vector - b.translation.vector).norm() < 1e-9,
                    "{ours} {name}"
                );
                assert!(a.rotation.angle_to(&b.rotation) < 1e-9, "{ours} {name}");
            }
        }
    }
}

#[test]
fn links_carry_collision_primitives() {
    for name in ["abb-irb4600-40-255", "kuka-kr150-2"] {
        let robot = Robot::load(name).unwrap();
        assert_eq!(robot.dof(), 6);
        assert!(robot.has_closed_form_ik());
        for link in [
            "base_link",
            "link_1",
            "link_2",
            "link_3",
            "link_4",
            "link_5",
            "link_6",
        ] {
            let l = &robot.links[robot.link_index(link).unwrap()];
            assert!(
                !l.collisions.is_empty(),
                "{name} {link} has no collision shape"
            );
            assert_eq!(
                l.collisions, l.visuals,
                "{name} {link}: visual = collision primitives"
            );
        }
        assert_eq!(robot.fk_all(&robot.home()).len(), robot.links.len());
    }
}

#[test]
fn unknown_robot_name_lists_the_built_ins() {
    let err = Robot::load("abb-irb9999").unwrap_err().to_string();
    assert!(
        err.contains("abb-irb4600-40-255") && err.contains("kuka-kr150-2"),
        "{err}"
    );
}

#[test]
fn urdf_path_with_sibling_metadata_uses_closed_form() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("robots/kuka-kr150-2.urdf");
    let robot = Robot::load(path.to_str().unwrap()).unwrap();
    assert!(robot.has_closed_form_ik());
    assert_eq!(robot.meta.payload, Some(150.0));
}

#[test]
fn wrong_opw_parameters_are_refused_at_load() {
    let dir = tempfile::tempdir().unwrap();
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("robots");
    std::fs::copy(
        root.join("abb-irb4600-40-255.urdf"),
        dir.path().join("r.urdf"),
    )
    .unwrap();
    let meta = std::fs::read_to_string(root.join("abb-irb4600-40-255.toml"))
        .unwrap()
        .replace("abb-irb4600-40-255.urdf", "r.urdf")
        .replace("c3 = 1.270", "c3 = 1.271");
    std::fs::write(dir.path().join("r.toml"), meta).unwrap();
    let err = Robot::load_path(&dir.path().join("r.toml"))
        .unwrap_err()
        .to_string();
    assert!(err.contains("do not match the URDF"), "{err}");
}
