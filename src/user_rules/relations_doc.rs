//! `docs/RELATIONS.md`: every relation of the built-in rule base with its
//! declaration and the comment above it, generated from the rule files so
//! the reference cannot drift from the rules (`framewright rules relations`).

use super::FINDINGS_SOURCE;
use crate::logic::Program;
use crate::logic::front::ast::RelDecl;
use std::fmt::Write as _;

/// The command that regenerates the committed file.
pub const REGENERATE: &str = "cargo run -- rules relations > docs/RELATIONS.md";

/// The Markdown reference of the relations of `base` (the built-in rule base)
/// and of the findings relations user rules derive.
pub fn relations_markdown(base: &Program) -> String {
    let mut s = String::new();
    s.push_str("# Built-in relations\n\n");
    let _ = writeln!(
        s,
        "Generated from the `.decl`s of `rules/*.dl` and the comments above them; do not edit.\n\
         A test fails when this file is stale; regenerate it with `{REGENERATE}`.\n\n\
         User rule files (`framewright check --rules FILE.dl`, docs/RULES.md) may read every\n\
         relation below and derive `violation` and `warning` (last section). Units are SI\n\
         (metres, kilograms, seconds, radians). *input* relations are filled from the IFC model,\n\
         the robot cell (`cell_value`/`cell_choice`) or, after a simulation, the executor\n\
         (`sim_*`); the others are derived by the rules of the file named.\n"
    );
    for (k, source) in base.sources.iter().enumerate() {
        let decls: Vec<&RelDecl> = base
            .relations
            .iter()
            .filter(|r| r.span.file as usize == k)
            .collect();
        if decls.is_empty() {
            continue;
        }
        let _ = writeln!(s, "## {}\n", source.name);
        let header = header_comment(&source.text);
        if !header.is_empty() {
            let _ = writeln!(s, "{header}\n");
        }
        let mut decls = decls;
        decls.sort_by_key(|r| r.span.line);
        for r in decls {
            write_relation(&mut s, r, &source.name, &source.text);
        }
        s.push('\n');
    }
    let _ = writeln!(s, "## Outputs of user rules ({})\n", FINDINGS_SOURCE.0);
    if let Ok(findings) = Program::parse_str(FINDINGS_SOURCE.0, FINDINGS_SOURCE.1) {
        let header = header_comment(FINDINGS_SOURCE.1);
        let _ = writeln!(s, "{header}\n");
        for r in &findings.relations {
            write_relation(&mut s, r, FINDINGS_SOURCE.0, FINDINGS_SOURCE.1);
        }
    }
    s.truncate(s.trim_end().len());
    s.push('\n');
    s
}

fn write_relation(s: &mut String, r: &RelDecl, file: &str, text: &str) {
    let attrs: Vec<String> = r
        .attrs
        .iter()
        .map(|a| format!("{}: {}", a.name, a.ty_name))
        .collect();
    let kind = if r.input.is_some() { ", input" } else { "" };
    let _ = writeln!(
        s,
        "- `{}({})` ({file}:{}{kind})",
        r.name,
        attrs.join(", "),
        r.span.line
    );
    let comment = comment_above(text, r.span.line as usize);
    if !comment.is_empty() {
        let _ = writeln!(s, "  {}", comment.replace('\n', "\n  "));
    }
}

/// The first comment block of a file (up to the first line that is not a comment).
fn header_comment(text: &str) -> String {
    let lines: Vec<&str> = text
        .lines()
        .map(str::trim)
        .take_while(|l| l.starts_with("//"))
        .map(strip_comment)
        .collect();
    join_paragraphs(&lines)
}

/// The comment lines just above line `line` (1-based), without rule labels.
fn comment_above(text: &str, line: usize) -> String {
    let all: Vec<&str> = text.lines().collect();
    let mut block = Vec::new();
    let mut k = line.saturating_sub(1);
    while k > 0 {
        let l = all.get(k - 1).map_or("", |l| l.trim());
        if !l.starts_with("//") {
            break;
        }
        if !l.contains("@rule") {
            block.push(strip_comment(l));
        }
        k -= 1;
    }
    // A comment right after the file header belongs to the header, not the relation.
    if k == 0 {
        return String::new();
    }
    block.reverse();
    join_paragraphs(&block)
}

fn strip_comment(l: &str) -> &str {
    l.trim_start_matches('/').trim()
}

/// Comment lines joined into paragraphs (an empty comment line separates them).
fn join_paragraphs(lines: &[&str]) -> String {
    let mut out = String::new();
    for l in lines {
        if l.is_empty() {
            out.push_str("\n\n");
        } else {
            if !out.is_empty() && !out.ends_with('\n') {
                out.push(' ');
            }
            out.push_str(l);
        }
    }
    out.trim().replace("\n\n\n", "\n\n")
}
