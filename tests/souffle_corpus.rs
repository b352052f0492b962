//! The Soufflé compatibility corpus (tests/fixtures/souffle/): programs written
//! for Soufflé, each with the output Soufflé's documentation gives for it (or a
//! hand computation from the documented semantics, written in the program's
//! comments). Every program runs on the interpreter and must write exactly the
//! expected files; every program the code generator accepts also runs compiled
//! (ascent) and must give the same relations. A program whose documented
//! behaviour is a runtime error lists the error's text in `expected/error`; one
//! whose documented behaviour is a warning lists it in `expected/warnings`.

use framewright::logic::compiled::{self, Relations};
use framewright::logic::front::codegen;
use framewright::logic::{Engine, LogicError, Options, Origin, Program, io};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;

const CORPUS: &str = "tests/fixtures/souffle";

fn programs() -> Vec<PathBuf> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join(CORPUS);
    let mut v: Vec<PathBuf> = std::fs::read_dir(&dir)
        .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "dl"))
        .collect();
    v.sort();
    v
}

/// `NAME/expected/*` as file name → text.
fn expected(prog: &Path) -> BTreeMap<String, String> {
    let dir = prog.with_extension("").join("expected");
    std::fs::read_dir(&dir)
        .unwrap_or_else(|_| panic!("{} has no expected/ directory", prog.display()))
        .map(|e| {
            let p = e.unwrap().path();
            (
                p.file_name().unwrap().to_string_lossy().into_owned(),
                std::fs::read_to_string(&p).unwrap(),
            )
        })
        .collect()
}

/// The interpreter's run: output files (and `stdout` for `IO=stdout`), the
/// input relations it read, and every relation; or the error.
struct Interpreted {
    files: BTreeMap<String, String>,
    warnings: Vec<String>,
    edb: Relations,
    all: Relations,
}

fn interpret(program: &Arc<Program>, facts: &Path) -> Result<Interpreted, LogicError> {
    let mut engine = Engine::new(program.clone(), Options::default());
    if facts.is_dir() {
        io::load_inputs(&mut engine, facts)?;
    }
    let edb: Relations = program
        .relations
        .iter()
        .filter(|r| r.input.is_some())
        .map(|r| (r.name.clone(), engine.relation(&r.name).unwrap()))
        .collect();
    let warnings = engine.run()?.warnings;
    let out = tempfile::tempdir().unwrap();
    let (written, stdout) = io::write_outputs(&engine, out.path())?;
    let mut files: BTreeMap<String, String> = written
        .iter()
        .map(|f| {
            (
                f.file_name().unwrap().to_string_lossy().into_owned(),
                std::fs::read_to_string(f).unwrap(),
            )
        })
        .collect();
    if !stdout.is_empty() {
        files.insert("stdout".into(), stdout);
    }
    let all = program
        .relations
        .iter()
        .map(|r| (r.name.clone(), engine.relation(&r.name).unwrap()))
        .collect();
    Ok(Interpreted {
        files,
        warnings,
        edb,
        all,
    })
}

/// The input relations as the interpreter reads them (for the compiled run of
/// a program whose interpreted run fails).
fn inputs_only(program: &Arc<Program>, facts: &Path) -> Relations {
    let mut engine = Engine::new(program.clone(), Options::default());
    if facts.is_dir() {
        io::load_inputs(&mut engine, facts).unwrap();
    }
    program
        .relations
        .iter()
        .filter(|r| r.input.is_some())
        .map(|r| (r.name.clone(), engine.relation(&r.name).unwrap()))
        .collect()
}

fn check_error(name: &str, engine: &str, error: &str, want: &str) {
    for line in want.lines().filter(|l| !l.is_empty()) {
        assert!(
            error.contains(line),
            "{name} ({engine}): expected `{line}` in the error:\n{error}"
        );
    }
}

#[test]
fn corpus_programs_give_their_documented_outputs_on_both_engines() {
    let progs = programs();
    assert!(progs.len() >= 60, "the corpus has {} programs", progs.len());
    let mut compiled_count = 0;
    let mut interpreter_only = Vec::new();
    for prog in &progs {
        let rel = format!("{CORPUS}/{}", prog.file_name().unwrap().to_string_lossy());
        let program = Arc::new(Program::parse_files(&[prog]).unwrap_or_else(|e| panic!("{e}")));
        let facts = prog.with_extension("");
        let mut want = expected(prog);
        let want_error = want.remove("error");
        let want_warnings = want.remove("warnings").unwrap_or_default();
        let interpreted = interpret(&program, &facts);
        let compiled = compiled::program(&rel);
        // build.rs compiles exactly the programs the generator accepts.
        match codegen::generate(&program, "check") {
            Ok(_) => assert!(compiled.is_some(), "{rel} was not compiled by build.rs"),
            Err(why) => {
                assert!(compiled.is_none());
                interpreter_only.push(format!("{rel}: {why}"));
            }
        }
        match (&want_error, interpreted) {
            (Some(err), Err(e)) => {
                check_error(&rel, "interpreter", &e.to_string(), err);
                if let Some(run) = compiled {
                    let edb = inputs_only(&program, &facts);
                    let e = run(&edb).expect_err("the compiled run should fail too");
                    check_error(&rel, "compiled", &e.to_string(), err);
                    compiled_count += 1;
                }
            }
            (Some(_), Ok(_)) => panic!("{rel}: the run should have failed"),
            (None, Err(e)) => panic!("{rel}: {e}"),
            (None, Ok(got)) => {
                let warnings = got.warnings.join("\n");
                for line in want_warnings.lines() {
                    assert!(
                        warnings.contains(line),
                        "{rel}: expected the warning `{line}`, got:\n{warnings}"
                    );
                }
                if want_warnings.is_empty() {
                    assert!(got.warnings.is_empty(), "{rel}: warnings {warnings}");
                }
                assert_eq!(
                    got.files.keys().collect::<Vec<_>>(),
                    want.keys().collect::<Vec<_>>(),
                    "{rel}: output files"
                );
                for (file, text) in &want {
                    assert_eq!(&got.files[file], text, "{rel}: {file}");
                }
                if let Some(run) = compiled {
                    let rels = run(&got.edb).unwrap_or_else(|e| panic!("{rel} compiled: {e}"));
                    for (name, tuples) in &got.all {
                        assert_eq!(&rels[name], tuples, "{rel}: relation {name} compiled");
                    }
                    compiled_count += 1;
                }
            }
        }
    }
    println!(
        "{} programs, {compiled_count} also compiled; interpreter only:\n  {}",
        progs.len(),
        interpreter_only.join("\n  ")
    );
    // Every corpus program runs on both engines, but those using `autoinc()`: its numbers
    // follow the interpreter's evaluation order, and the code generator refuses it by name.
    let unexpected: Vec<&String> = interpreter_only
        .iter()
        .filter(|why| !why.contains("autoinc() is interpreter-only"))
        .collect();
    assert!(
        unexpected.len() < interpreter_only.len() && unexpected.is_empty(),
        "interpreter only:\n{}",
        interpreter_only.join("\n")
    );
}

/// The same facts loaded from a program's directory give the same input
/// relations as the tuples written in it (guards the test's own reading).
#[test]
fn corpus_facts_are_read_as_written() {
    let p = Arc::new(
        Program::parse_str(
            "t.dl",
            ".decl e(x: number, s: symbol)\n.input e()\n.decl o(x: number)\n.output o()\no(x) :- e(x, _).\n",
        )
        .unwrap(),
    );
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("e.facts"), "1\ta b\n2\tc\n").unwrap();
    let got = interpret(&p, dir.path()).unwrap();
    assert_eq!(got.files["o.csv"], "1\n2\n");
    let mut e = Engine::new(p.clone(), Options::default());
    e.insert(
        "e",
        vec![
            framewright::logic::Value::Number(1),
            framewright::logic::Value::sym("a b"),
        ],
        Origin::Rust,
    )
    .unwrap();
    assert_eq!(got.edb["e"][0], e.relation("e").unwrap()[0]);
}
