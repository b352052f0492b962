//! Shared by the integration tests: the test data in `../shared` beside the checkout, which
//! a test uses when present and skips (saying so) when absent; reading BCF archives back; the
//! Python oracles.
#![allow(dead_code)]

pub mod arm;
pub mod bcf;
pub mod browser;
pub mod ifc_edit;
pub mod page_scripts;
pub mod python;
pub mod skip;

use std::path::{Path, PathBuf};

/// Every role a framing piece can have (`other` aside).
pub const FRAMING_ROLES: [&str; 11] = [
    "bottom_plate",
    "top_plate",
    "cap_plate",
    "stud",
    "king_stud",
    "jack_stud",
    "header",
    "sill",
    "cripple_stud",
    "blocking",
    "brace",
];

/// `../shared/<relative>` when it exists; otherwise None, after saying what is skipped.
pub fn shared_path(relative: &str) -> Option<PathBuf> {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../shared")
        .join(relative);
    if path.exists() {
        Some(path)
    } else {
        skip::missing_data(&path);
        None
    }
}

/// `framewright ARGS…`, which must succeed: its standard output.
pub fn framewright_ok(args: &[&str]) -> String {
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_framewright"))
        .args(args)
        .output()
        .expect("framewright runs");
    assert!(
        out.status.success(),
        "{args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8(out.stdout).expect("UTF-8 output")
}

/// `framewright synth block ARGS… -o DIR/block.ifc`: a generated model for a test.
pub fn synth_block(dir: &Path, args: &[&str]) -> PathBuf {
    let path = dir.join("block.ifc");
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_framewright"))
        .args(["synth", "block"])
        .args(args)
        .arg("-o")
        .arg(&path)
        .output()
        .expect("framewright runs");
    assert!(
        out.status.success(),
        "synth block {args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    path
}

/// The wall of `plan --json` whose members include `member` (a piece id or GlobalId).
pub fn wall_holding<'p>(plan: &'p serde_json::Value, member: &str) -> &'p serde_json::Value {
    plan["walls"]
        .as_array()
        .expect("the plan's walls")
        .iter()
        .find(|w| {
            w["member_ids"]
                .as_array()
                .expect("a wall's members")
                .iter()
                .any(|m| m == member)
        })
        .expect("a wall holds the member")
}
