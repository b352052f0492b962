//! Skipping a test so that it shows. A test that cannot check what it is for (an oracle is not
//! installed, the shared test data is absent) calls one of these and returns.
//!
//! - With `FRAMEWRIGHT_REQUIRE_ORACLES=1` (`.ci/run` sets it) a missing tool fails the test,
//!   naming the command that installs it: the CI set-up promised the tool, so a green run must
//!   have used it. Absent shared data never fails (a checkout may come without `../shared`).
//! - Otherwise the skip is written to the terminal at once (past libtest's output capture) and
//!   recorded; `tests/zz_skipped_summary.rs`, the last test binary `cargo test` runs, prints
//!   every skip of the run in one summary.
//!
//! The record is one file per `cargo test` run: every test binary of a run is a child of the
//! same cargo process, so the parent's process id names the run.
#![allow(dead_code)]

use std::io::Write;
use std::path::PathBuf;

/// The variable under which a missing oracle is a failure.
pub const REQUIRE_ORACLES: &str = "FRAMEWRIGHT_REQUIRE_ORACLES";

/// Whether this run requires every oracle (`FRAMEWRIGHT_REQUIRE_ORACLES` set to anything but
/// empty or `0`).
pub fn oracles_required() -> bool {
    std::env::var(REQUIRE_ORACLES).is_ok_and(|v| !v.is_empty() && v != "0")
}

/// The folder holding one record file per `cargo test` run.
pub fn records_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("skipped-tests")
}

/// This run's record file.
pub fn record_file() -> PathBuf {
    records_dir().join(format!("{}.tsv", std::os::unix::process::parent_id()))
}

/// The running test: the test binary and libtest's name of the test thread.
fn test_name() -> String {
    let binary = std::env::current_exe()
        .ok()
        .and_then(|p| p.file_stem().map(|s| s.to_string_lossy().into_owned()))
        .map(|s| {
            s.rsplit_once('-')
                .map_or(s.clone(), |(name, _hash)| name.to_string())
        })
        .unwrap_or_default();
    let thread = std::thread::current();
    match thread.name() {
        Some(name) if name != "main" => format!("{binary}::{name}"),
        _ => binary,
    }
}

/// Says `line` on the terminal past libtest's capture and appends it to this run's record.
fn record(what: &str, remedy: &str) {
    let test = test_name();
    let _ = writeln!(
        std::io::stderr().lock(),
        "SKIPPED {test}: {what} ({remedy})"
    );
    let clean = |s: &str| s.replace(['\t', '\n'], " ");
    let line = format!("{}\t{}\t{}\n", clean(&test), clean(what), clean(remedy));
    let _ = std::fs::create_dir_all(records_dir());
    // One short write with O_APPEND: lines from parallel tests do not interleave.
    if let Ok(mut f) = std::fs::OpenOptions::new()
        .create(true)
        .append(true)
        .open(record_file())
    {
        let _ = f.write_all(line.as_bytes());
    }
}

/// The oracle `tool` is absent. Fails the test under `FRAMEWRIGHT_REQUIRE_ORACLES`, saying to
/// run `install`; otherwise records the skip. The caller returns after it.
pub fn missing_tool(tool: &str, install: &str) {
    if oracles_required() {
        panic!(
            "not found: {tool}; this run requires every oracle ({REQUIRE_ORACLES} is set): \
             install it with `{install}`"
        );
    }
    record(
        &format!("not found: {tool}"),
        &format!("install: {install}"),
    );
}

/// Shared test data (`../shared/...`) is absent: recorded, never a failure.
pub fn missing_data(path: &std::path::Path) {
    record(
        &format!("not found: {}", path.display()),
        "the shared test data beside the checkout",
    );
}
