//! docs/RELATIONS.md is generated from the `.decl`s of rules/*.dl; this test
//! fails when the committed file no longer matches the rules.

use framewright::logic::Program;
use framewright::user_rules::relations_doc::{REGENERATE, relations_markdown};
use std::path::Path;

#[test]
fn committed_relations_reference_matches_the_rules() {
    let base = Program::builtin().expect("built-in rules check");
    let expected = relations_markdown(&base);
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("docs/RELATIONS.md");
    let committed = std::fs::read_to_string(&path).unwrap_or_default();
    assert!(
        committed == expected,
        "docs/RELATIONS.md is stale (the rules' declarations or comments changed); regenerate it with `{REGENERATE}`"
    );
}

#[test]
fn every_builtin_relation_and_the_findings_are_documented() {
    let base = Program::builtin().unwrap();
    let doc = relations_markdown(&base);
    for r in &base.relations {
        assert!(
            doc.contains(&format!("- `{}(", r.name)),
            "{} missing from the reference",
            r.name
        );
    }
    assert!(doc.contains("- `violation(id: symbol, rule: symbol, message: symbol)`"));
    assert!(
        doc.contains(
            "- `sim_ik_solved(p: symbol, op: symbol, reach_margin: float)` (rules/sim.dl:"
        )
    );
    // The comment above a declaration becomes its description.
    assert!(doc.contains("Length, width and thickness (width >= thickness)."));
}
