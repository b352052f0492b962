//! Every program in tests/logic/ and benches/logic/ gives identical relations
//! on the interpreter and on its compiled (ascent) form; so does the built-in rule base (all of
//! rules/*.dl, one program) on the bundled models' facts with each shipped robot cell.

use framewright::cell::Cell;
use framewright::frame::{cell_facts, model_facts};
use framewright::geom::ContactOptions;
use framewright::ifc::Model;
use framewright::logic::compiled::{self, Relations};
use framewright::logic::{Engine, Options, Program, io};
use std::collections::BTreeMap;
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

/// Runs `program` on `edb` on both engines and compares every relation; the number of tuples
/// of each.
fn agree(name: &str, program: &Arc<Program>, edb: &Relations) -> BTreeMap<String, usize> {
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
    let mut sizes = BTreeMap::new();
    for r in &program.relations {
        let want = engine.relation(&r.name).unwrap();
        assert_eq!(got[&r.name], want, "{name}: relation {}", r.name);
        sizes.insert(r.name.clone(), want.len());
    }
    println!("{name}: {} relations agree", program.relations.len());
    sizes
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
    // On the facts `plan` gives them: the bundled models' pieces and contacts and a shipped
    // cell's values (its walls laid at a fixed offset, so the targets' rules fire without the
    // placement search), on each robot.
    for model in ["tm1.ifc", "tm2.ifc", "tm3.ifc"] {
        let model = Model::open(root().join("examples/models").join(model)).unwrap();
        for cell in ["study-abb", "study-kuka"] {
            let mut cell = Cell::load(cell).unwrap();
            cell.set_offset_x("0.9").unwrap();
            let mut facts = model_facts(&model, &ContactOptions::default());
            facts.extend(cell_facts(&cell));
            let edb = facts.relations();
            let derived = agree("rules", &program, &edb);
            // The comparison covers the rules that matter: roles, walls, order, nailing and
            // framing targets were derived, not left empty on both sides.
            for relation in [
                "role",
                "wall_of",
                "assembly_rank",
                "nailing_target",
                "framing_target",
            ] {
                assert!(
                    derived[relation] > 0,
                    "{}: no {relation}",
                    model.path.display()
                );
            }
        }
    }
}

/// tests/logic/rewrites.dl writes each rewrite two ways, `NAME_a` and `NAME_b`: on both engines
/// the two relations hold the same tuples, and not none (the rewrite is exercised).
#[test]
fn rewrite_pairs_give_equal_relations_on_both_engines() {
    let name = "tests/logic/rewrites.dl";
    let program = Arc::new(Program::parse_files(&[root().join(name)]).unwrap());
    let mut engine = Engine::new(program.clone(), Options::default());
    engine.run().unwrap();
    let compiled = compiled::program(name).expect("compiled by build.rs")(&Relations::new())
        .unwrap_or_else(|e| panic!("{e}"));
    let pairs: Vec<&str> = program
        .relations
        .iter()
        .filter_map(|r| r.name.strip_suffix("_a"))
        .collect();
    assert_eq!(pairs, ["disj", "order", "expr"]);
    for pair in pairs {
        let (a, b) = (format!("{pair}_a"), format!("{pair}_b"));
        let interpreted = engine.relation(&a).unwrap();
        assert!(!interpreted.is_empty(), "{a} is empty");
        assert_eq!(
            interpreted,
            engine.relation(&b).unwrap(),
            "{pair} (interpreter)"
        );
        assert_eq!(compiled[&a], compiled[&b], "{pair} (compiled)");
        assert_eq!(compiled[&a], interpreted, "{pair}: the engines");
    }
}
