//! `framewright robot fk|ik|cell` end to end.

use std::io::Write;
use std::process::{Command, Output, Stdio};

fn run(args: &[&str], stdin: Option<&str>) -> Output {
    let mut child = Command::new(env!("CARGO_BIN_EXE_framewright"))
        .args(args)
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    if let Some(text) = stdin {
        child
            .stdin
            .take()
            .unwrap()
            .write_all(text.as_bytes())
            .unwrap();
    } else {
        drop(child.stdin.take());
    }
    child.wait_with_output().unwrap()
}

fn stdout(o: &Output) -> String {
    String::from_utf8(o.stdout.clone()).unwrap()
}

fn stderr(o: &Output) -> String {
    String::from_utf8(o.stderr.clone()).unwrap()
}

#[test]
fn fk_json_is_tool0_row_major() {
    let o = run(
        &[
            "robot",
            "fk",
            "abb-irb4600-40-255",
            "--joints",
            "0.5,0.3,-0.4,1,0.6,-1.2",
            "--json",
        ],
        None,
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let v: serde_json::Value = serde_json::from_str(&stdout(&o)).unwrap();
    let m = v["tool0"].as_array().unwrap();
    // README reference (qA): row 0 = [0.024991, -0.854032, 0.519621, 1.601336].
    let row0: Vec<f64> = m[0]
        .as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_f64().unwrap())
        .collect();
    for (a, b) in row0.iter().zip([0.024991, -0.854032, 0.519621, 1.601336]) {
        assert!((a - b).abs() < 1e-6, "{row0:?}");
    }
    assert_eq!(m[3], serde_json::json!([0.0, 0.0, 0.0, 1.0]));
}

#[test]
fn ik_solutions_reproduce_the_pose_via_fk() {
    // Pose of tool0 at q = qA, as x,y,z,qw,qx,qy,qz.
    let o = run(
        &[
            "robot",
            "ik",
            "kuka-kr150-2",
            "--pose",
            "1.6,-0.4,1.2,0,0,1,0",
            "--json",
        ],
        None,
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let v: serde_json::Value = serde_json::from_str(&stdout(&o)).unwrap();
    let sols = v["solutions"].as_array().unwrap();
    assert!(sols.len() >= 2);
    for s in sols {
        let q: Vec<String> = s
            .as_array()
            .unwrap()
            .iter()
            .map(|x| x.to_string())
            .collect();
        let f = run(
            &[
                "robot",
                "fk",
                "kuka-kr150-2",
                "--joints",
                &q.join(","),
                "--json",
            ],
            None,
        );
        let m: serde_json::Value = serde_json::from_str(&stdout(&f)).unwrap();
        let t: Vec<f64> = (0..3).map(|r| m["tool0"][r][3].as_f64().unwrap()).collect();
        assert!(
            (t[0] - 1.6).abs() < 1e-6 && (t[1] + 0.4).abs() < 1e-6 && (t[2] - 1.2).abs() < 1e-6,
            "{t:?}"
        );
        // qw=0, qx=0, qy=1, qz=0: rotation of π about y, so tool z points down.
        assert!((m["tool0"][2][2].as_f64().unwrap() + 1.0).abs() < 1e-6);
    }
}

#[test]
fn ik_failure_is_data_with_exit_1() {
    let o = run(
        &[
            "robot",
            "ik",
            "abb-irb4600-40-255",
            "--pose",
            "4,0,1,1,0,0,0",
            "--json",
        ],
        None,
    );
    assert_eq!(o.status.code(), Some(1));
    let text = stdout(&o);
    assert!(
        text.starts_with(r#"{"error":{"kind":"out_of_reach","distance":"#),
        "{text}"
    );
}

#[test]
fn poses_from_stdin_answer_one_line_each_in_order() {
    let input = "1.5 0.2 1.0 0 0 1 0\n4 0 1 1 0 0 0\n1.2 -0.3 0.8 0 0 1 0\n";
    let o = run(
        &[
            "robot",
            "ik",
            "abb-irb4600-40-255",
            "--poses",
            "-",
            "--tool",
            "grip",
            "--json",
        ],
        Some(input),
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let text = stdout(&o);
    let lines: Vec<&str> = text.lines().collect();
    assert_eq!(lines.len(), 3, "{lines:?}");
    assert!(lines[0].starts_with(r#"{"solutions":[["#));
    assert!(lines[1].starts_with(r#"{"error":{"kind":"out_of_reach""#));
    assert!(lines[2].starts_with(r#"{"solutions":[["#));
}

#[test]
fn bad_pose_line_exits_2_with_file_and_line() {
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("poses.txt");
    std::fs::write(&file, "1.5 0.2 1.0 0 0 1 0\n1.5 0.2 1.0 0 0 2 0\n").unwrap();
    // A blank line is not a pose either (answers must line up with input lines).
    let blank = dir.path().join("blank.txt");
    std::fs::write(&blank, "1.5 0.2 1.0 0 0 1 0\n\n").unwrap();
    let o = run(
        &[
            "robot",
            "ik",
            "abb-irb4600-40-255",
            "--poses",
            blank.to_str().unwrap(),
        ],
        None,
    );
    assert_eq!(o.status.code(), Some(2));
    assert!(
        stderr(&o).contains("blank.txt:2: expected 7 numbers"),
        "{}",
        stderr(&o)
    );
    let o = run(
        &[
            "robot",
            "ik",
            "abb-irb4600-40-255",
            "--poses",
            file.to_str().unwrap(),
        ],
        None,
    );
    assert_eq!(o.status.code(), Some(2));
    let err = stderr(&o);
    assert!(
        err.contains("poses.txt:2:") && err.contains("unit quaternion"),
        "{err}"
    );
}

#[test]
fn wrong_joint_count_and_unknown_robot_exit_2() {
    let o = run(&["robot", "fk", "kuka-kr150-2", "--joints", "0,0,0"], None);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("expected 6 joint values"));
    let o = run(
        &["robot", "fk", "kuka-kr15", "--joints", "0,0,0,0,0,0"],
        None,
    );
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("kuka-kr150-2"));
}

#[test]
fn bad_cell_exits_2_with_file_line_and_key() {
    let file = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/tests/fixtures/cells/unknown_key.toml"
    );
    let o = run(&["robot", "cell", file], None);
    assert_eq!(o.status.code(), Some(2));
    let err = stderr(&o);
    assert!(
        err.contains("unknown_key.toml:34:1: key `conveyor1.speeed`"),
        "{err}"
    );
    let o = run(&["robot", "cell", "study-kuka", "--json"], None);
    assert!(o.status.success(), "{}", stderr(&o));
    let v: serde_json::Value = serde_json::from_str(&stdout(&o)).unwrap();
    assert_eq!(v["robot"], "kuka-kr150-2");
}
