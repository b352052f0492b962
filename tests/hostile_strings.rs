//! Hostile text from a model in every writer. `tests/fixtures/hostile_strings.ifc` is TM1 whose
//! names, tags, object types and project description hold markup, `&`, both quotes, `]]>`,
//! control characters (STEP `\X\01`, `\X2\000D000A\X0\`), backslashes, right-to-left marks, a
//! character outside the BMP and raw bytes that are not UTF-8. Each output is read back by a
//! real parser: JSON (serde_json), the report's SVG drawings and the BCF documents (roxmltree,
//! which enforces XML 1.0's character rules), the annotated IFC (our reader, and IfcOpenShell
//! when installed), and the CSV of `rules run --out` (read again through `--facts`).

mod common;

use framewright::ifc::Model;
use serde_json::Value;
use std::collections::BTreeSet;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

fn fixture() -> PathBuf {
    root().join("tests/fixtures/hostile_strings.ifc")
}

/// The product names as ISO 10303-21 decodes them (worked out by hand from the fixture's
/// escapes; the raw bytes FF FE C3 are not UTF-8 and read as three U+FFFD).
const NAMES: [&str; 4] = [
    "<script>alert(\"x\")</script> & 'plate'",
    "stud\ttab\u{1}soh\u{1b}esc\r\ncrlf \\back\\slash",
    "\u{202e}right-to-left \u{200f}mark \u{2066}isolate",
    "bad utf-8 \u{fffd}\u{fffd}\u{fffd}( top plate",
];

/// What markup outputs show for a name: characters XML 1.0 forbids become U+FFFD.
fn in_markup(name: &str) -> String {
    name.chars()
        .map(|c| match c {
            '\u{1}' | '\u{1b}' => '\u{fffd}',
            c => c,
        })
        .collect()
}

fn framewright(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_framewright"))
        .args(args)
        .output()
        .unwrap()
}

fn ok(out: Output) -> Output {
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    out
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

// Walls laid 3.5 m out: every piece is beyond reach, so failure texts name every piece.
const FAR: [&str; 2] = ["--offset-x", "3.5"];

#[test]
fn json_outputs_parse_and_carry_the_names_exactly() {
    let model = fixture();
    let inspect = ok(framewright(&["inspect", "--json", s(&model)]));
    let json: Value = serde_json::from_slice(&inspect.stdout).unwrap();
    let names: BTreeSet<&str> = json["members"]
        .as_array()
        .unwrap()
        .iter()
        .map(|m| m["name"].as_str().unwrap())
        .collect();
    assert_eq!(names, NAMES.into_iter().collect());
    // The raw bytes are reported, naming the entity.
    assert!(
        json["warnings"]
            .as_array()
            .unwrap()
            .iter()
            .any(|w| w["entity"] == 61)
    );

    for args in [
        vec!["plan", "--json", s(&model)],
        vec![
            "simulate",
            "--json",
            "--no-cache",
            FAR[0],
            FAR[1],
            s(&model),
        ],
    ] {
        let out = ok(framewright(&args));
        let _: Value = serde_json::from_slice(&out.stdout)
            .unwrap_or_else(|e| panic!("{args:?} printed invalid JSON: {e}"));
    }
    let dir = tempfile::tempdir().unwrap();
    let world = dir.path().join("world.json");
    ok(framewright(&[
        "world",
        "--format",
        "json",
        "-o",
        s(&world),
        s(&model),
    ]));
    let text = std::fs::read_to_string(&world).unwrap();
    let _: Value = serde_json::from_str(&text).unwrap();
    for name in NAMES {
        assert!(
            text.contains(&serde_json::to_string(name).unwrap()),
            "{name:?} in the world JSON"
        );
    }
}

/// The texts of every `<title>` of an SVG, which must be a well-formed XML document.
fn svg_titles(svg: &str) -> Vec<String> {
    let doc = roxmltree::Document::parse(svg)
        .unwrap_or_else(|e| panic!("an SVG drawing is not well-formed XML: {e}"));
    doc.descendants()
        .filter(|n| n.has_tag_name("title"))
        .map(|n| n.text().unwrap_or_default().to_string())
        .collect()
}

#[test]
fn report_page_and_its_drawings_are_well_formed() {
    let dir = tempfile::tempdir().unwrap();
    let report = dir.path().join("report");
    let model = fixture();
    ok(framewright(&[
        "simulate",
        "--no-cache",
        FAR[0],
        FAR[1],
        "--report",
        s(&report),
        s(&model),
    ]));
    let page = std::fs::read_to_string(report.join("index.html")).unwrap();
    // Nothing from the model became markup, and nothing HTML parses as an error.
    // Its only scripts are the 3D view's (the scene, base64, and the viewer's own code).
    let (scenes, viewers) = common::page_scripts::viewer_scripts(&page);
    assert_eq!(viewers, usize::from(scenes > 0));
    assert!(page.contains("&lt;script&gt;alert(&quot;x&quot;)&lt;/script&gt; &amp; 'plate'"));
    let bad = page
        .char_indices()
        .find(|&(_, c)| (c.is_control() && !matches!(c, '\t' | '\n' | '\r')) || c == '\u{fffe}');
    assert_eq!(bad, None, "a control character in the page");

    let mut svgs = 0;
    let mut titles = Vec::new();
    for (start, _) in page.match_indices("<svg") {
        let end = start + page[start..].find("</svg>").unwrap() + "</svg>".len();
        titles.extend(svg_titles(&page[start..end]));
        svgs += 1;
    }
    assert!(svgs > 0, "the page has drawings");
    for name in NAMES {
        // XML reads a carriage return before a line feed as a line feed.
        let shown = in_markup(name).replace("\r\n", "\n");
        assert!(
            titles.iter().any(|t| t.starts_with(&shown)),
            "{shown:?} is the tooltip of its piece"
        );
    }
}

#[test]
fn bcf_documents_are_well_formed_xml_with_the_names() {
    let dir = tempfile::tempdir().unwrap();
    let bcf = dir.path().join("out.bcfzip");
    let model = fixture();
    ok(framewright(&[
        "simulate",
        "--no-cache",
        FAR[0],
        FAR[1],
        "--bcf",
        s(&bcf),
        s(&model),
    ]));
    let mut titles = Vec::new();
    // The snapshot images are left out; bcf_export checks them.
    for (name, text) in common::bcf::xml_documents(&bcf) {
        let doc = roxmltree::Document::parse(&text)
            .unwrap_or_else(|e| panic!("{name} is not well-formed XML: {e}"));
        titles.extend(
            doc.descendants()
                .filter(|n| n.has_tag_name("Title"))
                .map(|n| n.text().unwrap_or_default().to_string()),
        );
    }
    assert_eq!(titles.len(), 4, "one topic per piece: {titles:?}");
    for name in NAMES {
        // XML reads a carriage return before a line feed as a line feed.
        let shown = in_markup(name).replace("\r\n", "\n");
        assert!(
            titles.iter().any(|t| t.contains(&shown)),
            "{shown:?} in a topic title: {titles:?}"
        );
    }
}

#[test]
fn annotated_ifc_reads_back_with_the_names() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("annotated.ifc");
    let model = fixture();
    ok(framewright(&[
        "annotate",
        "--simulate",
        FAR[0],
        FAR[1],
        "-o",
        s(&out),
        s(&model),
    ]));
    // Everything framewright added is plain ISO 10303-21: printable ASCII, text escaped.
    let bytes = std::fs::read(&out).unwrap();
    let added = &bytes[bytes.windows(5).position(|w| w == b"\n#67=").unwrap()..];
    assert!(
        added
            .iter()
            .all(|&b| b == b'\n' || (0x20..0x7f).contains(&b)),
        "raw bytes in the added entities"
    );

    let read = Model::open(&out).unwrap();
    let names: BTreeSet<&str> = read
        .pieces
        .iter()
        .filter_map(|p| p.name.as_deref())
        .collect();
    assert_eq!(names, NAMES.into_iter().collect());

    let tasks = |text: &str| -> BTreeSet<String> {
        text.lines()
            .filter(|l| l.contains("=IFCTASK("))
            .map(|l| {
                let at = l.find(",$,'").unwrap() + 4;
                let end = at + framewright_string_end(&l.as_bytes()[at..]);
                framewright::step::decode_step_string(&l.as_bytes()[at..end])
                    .0
                    .into_owned()
            })
            .collect()
    };
    let ours = tasks(&String::from_utf8_lossy(&bytes));
    for name in NAMES {
        assert!(
            ours.iter().any(|t| t.ends_with(name)),
            "a task names {name:?}: {ours:?}"
        );
    }

    let Some(python) = common::python::ifcopenshell() else {
        return;
    };
    let script = "import sys, json, ifcopenshell\nf = ifcopenshell.open(sys.argv[1])\n\
        print(json.dumps([t.Name for t in f.by_type('IfcTask')]))";
    let run = Command::new(python)
        .args(["-c", script])
        .arg(&out)
        .output()
        .unwrap();
    assert!(
        run.status.success(),
        "IfcOpenShell cannot read the annotated model: {}",
        String::from_utf8_lossy(&run.stderr)
    );
    let theirs: BTreeSet<String> = serde_json::from_slice(&run.stdout).unwrap();
    assert_eq!(theirs, ours, "IfcOpenShell reads the task names we wrote");
}

/// Offset of the quote that closes a STEP string starting after its opening quote.
fn framewright_string_end(body: &[u8]) -> usize {
    let mut i = 0;
    loop {
        match body[i] {
            b'\'' if body.get(i + 1) == Some(&b'\'') => i += 2,
            b'\'' => return i,
            _ => i += 1,
        }
    }
}

/// Symbols a shop rule file may derive from model names (here written in the program).
const SYMBOLS: [&str; 5] = [
    "<script>alert(1)</script>",
    "O'Brien & \"Sons\", ltd",
    "\u{202e}gnp.exe \u{200f}",
    "back\\\\slash",
    "emoji \u{1f600} ]]> -->",
];

#[test]
fn rules_csv_round_trips_through_facts() {
    let dir = tempfile::tempdir().unwrap();
    let facts: String = SYMBOLS
        .iter()
        .enumerate()
        .map(|(i, s)| format!("s(\"{}\", {i}).\n", s.replace('"', "\\\"")))
        .collect();
    let write = dir.path().join("write.dl");
    std::fs::write(
        &write,
        format!(".decl s(x: symbol, n: number)\n.output s\n{facts}"),
    )
    .unwrap();
    let out = dir.path().join("out");
    ok(framewright(&["rules", "run", s(&write), "--out", s(&out)]));

    let read = dir.path().join("read.dl");
    std::fs::write(
        &read,
        ".decl s(x: symbol, n: number)\n.input s(filename=\"s.csv\")\n\
         .decl t(x: symbol, n: number)\n.output t\nt(x, n) :- s(x, n).\n",
    )
    .unwrap();
    let again = dir.path().join("again");
    ok(framewright(&[
        "rules",
        "run",
        s(&read),
        "--facts",
        s(&out),
        "--out",
        s(&again),
    ]));
    let first = std::fs::read_to_string(out.join("s.csv")).unwrap();
    let second = std::fs::read_to_string(again.join("t.csv")).unwrap();
    assert_eq!(first, second, "the symbols read back as written");
    // The lexer turns `\\` into one backslash; every other symbol is as written.
    for (i, sym) in SYMBOLS.iter().enumerate() {
        let line = format!("{}\t{i}", sym.replace("\\\\", "\\"));
        assert!(first.lines().any(|l| l == line), "{line:?} in {first:?}");
    }
}

// Soufflé writes symbols as they are (WriteStreamCSV without rfc4180): a tab reads as one
// more field, a line break splits the line, the empty symbol of a one-field relation is an
// empty line. Written here the same way, not refused.
#[test]
fn rules_run_writes_symbols_as_souffle_does() {
    for (symbol, line) in [
        ("a\\tb", "a\tb\n"),
        ("line\\nbreak", "line\nbreak\n"),
        ("", "\n"),
    ] {
        let dir = tempfile::tempdir().unwrap();
        let program = dir.path().join("p.dl");
        std::fs::write(
            &program,
            format!(".decl e(x: symbol)\n.output e\ne(\"{symbol}\").\n"),
        )
        .unwrap();
        let out = dir.path().join("out");
        ok(framewright(&[
            "rules",
            "run",
            s(&program),
            "--out",
            s(&out),
        ]));
        assert_eq!(std::fs::read_to_string(out.join("e.csv")).unwrap(), line);
    }
}
