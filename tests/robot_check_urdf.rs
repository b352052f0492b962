//! The shipped URDFs pass `check_urdf` (Debian package liburdfdom-tools; `.ci/run` installs it).

mod common;

use std::path::Path;
use std::process::Command;

#[test]
fn check_urdf_accepts_both_robots() {
    let probe = Command::new("check_urdf").output();
    if probe.is_err() {
        common::skip::missing_tool("check_urdf", "apt-get install liburdfdom-tools");
        return;
    }
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("robots");
    for file in ["abb-irb4600-40-255.urdf", "kuka-kr150-2.urdf"] {
        let out = Command::new("check_urdf")
            .arg(root.join(file))
            .output()
            .unwrap();
        let stdout = String::from_utf8_lossy(&out.stdout);
        assert!(
            out.status.success(),
            "check_urdf {file} failed:\n{stdout}\n{}",
            String::from_utf8_lossy(&out.stderr)
        );
        assert!(stdout.contains("Successfully Parsed XML"), "{stdout}");
        assert!(stdout.contains("root Link: base_link"), "{stdout}");
        // base_link → link_1 … link_6 → flange → tool0, nothing else.
        for link in [
            "link_1", "link_2", "link_3", "link_4", "link_5", "link_6", "flange", "tool0",
        ] {
            assert!(
                stdout.contains(&format!("child(1):  {link}")),
                "{file}: {link}\n{stdout}"
            );
        }
    }
}
