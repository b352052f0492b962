//! Every program in tests/logic/ and benches/logic/ gives identical relations
//! on the interpreter and on its compiled (ascent) form. The built-in rule base
//! (all of rules/*.dl, one program) is compared on every model in tests/frame_*.rs.

use framewright::logic::compiled::{self, Relations};
use framewright::logic::{Engine, Options, Program, io};
use std::path::{Path, PathBuf};
use std::sync::Arc;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn dl_files(dir: &str) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(root().join(dir))
        .map(|rd| {
            rd.filter_map(|e| e.ok())
                .map(|e| e.file_name().to_string_lossy().into_owned())
                .filter(|n| n.ends_with(".dl"))
                .map(|n| format!("{dir}/{n}"))
                .collect()
        })
        .unwrap_or_default();
    v.sort();
    v
}

/// The program's input relations, read from the facts directory beside it (if any).
fn inputs(program: &Arc<Program>, facts: &Path) -> Relations {
    let mut e = Engine::new(program.clone(), Options::default());
    if facts.is_dir() {
        io::load_inputs(&mut e, facts).unwrap();
    }
    program
        .relations
        .iter()
        .filter(|r| r.input.is_some())
        .map(|r| (r.name.clone(), e.relation(&r.name).unwrap()))
        .collect()
}

fn agree(name: &str, program: &Arc<Program>, edb: &Relations) {
    let mut engine = Engine::new(program.clone(), Options::default());
    for (rel, tuples) in edb {
        for t in tuples {
            engine
                .insert(rel, t.clone(), framewright::logic::Origin::Rust)
                .unwrap();
        }
    }
    engine.run().unwrap();
    let run =
        compiled::program(name).unwrap_or_else(|| panic!("{name} was not compiled by build.rs"));
    let got = run(edb).unwrap_or_else(|e| panic!("{name}: {e}"));
    for r in &program.relations {
        let want = engine.relation(&r.name).unwrap();
        assert_eq!(got[&r.name], want, "{name}: relation {}", r.name);
    }
    println!("{name}: {} relations agree", program.relations.len());
}

#[test]
fn interpreter_and_compiled_agree_on_every_program() {
    let mut files = dl_files("tests/logic");
    files.extend(dl_files("benches/logic"));
    assert!(files.len() >= 5);
    for rel in files {
        let path = root().join(&rel);
        let program = Arc::new(Program::parse_files(&[&path]).unwrap());
        let edb = inputs(&program, &path.with_extension(""));
        agree(&rel, &program, &edb);
    }
}

#[test]
fn builtin_rules_agree() {
    let sources = compiled::BUILTIN_SOURCES;
    assert_eq!(
        sources.len(),
        dl_files("rules").len(),
        "build.rs embeds every rules/*.dl"
    );
    if sources.is_empty() {
        assert!(compiled::program("rules").is_none());
        println!("rules/ is empty: no built-in rules yet");
        return;
    }
    let program = Arc::new(Program::builtin().unwrap_or_else(|e| panic!("{e}")));
    // Without fixtures the built-in rules run on their own facts; later issues add EDB fixtures.
    agree("rules", &program, &Relations::new());
}
