//! The summary of skipped tests. `cargo test` runs the integration test binaries in the order
//! of their names, so this one (`zz_…`) runs after all the others of the run and prints, in one
//! place, every test that skipped because an oracle or the shared test data was absent
//! (`tests/common/skip.rs` records them). It never fails: a user's `cargo test` without the
//! oracles passes, and says what it did not check.

mod common;

use std::io::Write;

#[test]
fn print_the_skipped_tests_of_this_run() {
    let file = common::skip::record_file();
    let text = std::fs::read_to_string(&file).unwrap_or_default();
    let _ = std::fs::remove_file(&file);
    // Records of runs that ended before reaching this binary (a failure, a filter) are old.
    if let Ok(entries) = std::fs::read_dir(common::skip::records_dir()) {
        for e in entries.flatten() {
            let stale = e
                .metadata()
                .and_then(|m| m.modified())
                .ok()
                .and_then(|t| t.elapsed().ok())
                .is_some_and(|age| age.as_secs() > 24 * 3600);
            if stale {
                let _ = std::fs::remove_file(e.path());
            }
        }
    }
    let mut lines: Vec<[&str; 3]> = text
        .lines()
        .filter_map(|l| {
            let mut f = l.splitn(3, '\t');
            Some([f.next()?, f.next()?, f.next()?])
        })
        .collect();
    lines.sort();
    lines.dedup();
    if lines.is_empty() {
        return;
    }
    // Grouped by what was absent.
    let mut groups: std::collections::BTreeMap<(&str, &str), Vec<&str>> = Default::default();
    for [test, what, remedy] in &lines {
        groups.entry((what, remedy)).or_default().push(test);
    }
    let mut out = format!(
        "\n{} test(s) skipped what they check ({} to make a missing tool fail instead):\n",
        lines.len(),
        common::skip::REQUIRE_ORACLES
    );
    for ((what, remedy), tests) in &groups {
        out.push_str(&format!("  {what} ({remedy}):\n"));
        for t in tests {
            out.push_str(&format!("    {t}\n"));
        }
    }
    // Past libtest's capture, so a passing run shows it.
    let _ = std::io::stderr().lock().write_all(out.as_bytes());
}
