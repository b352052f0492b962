//! Every program in tests/logic/ runs on the interpreter and writes exactly the
//! expected outputs (tests/logic/NAME/expected/*.csv, written by hand from
//! Soufflé's documented semantics).

use framewright::logic::{Engine, Options, Program, io};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;

fn programs() -> Vec<PathBuf> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/logic");
    let mut v: Vec<PathBuf> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "dl"))
        .collect();
    v.sort();
    v
}

fn run(program: &Path, provenance: bool) -> BTreeMap<String, String> {
    let p = Arc::new(Program::parse_files(&[program]).unwrap_or_else(|e| panic!("{e}")));
    let mut engine = Engine::new(
        p,
        Options {
            provenance,
            ..Options::default()
        },
    );
    let facts = program.with_extension("");
    io::load_inputs(&mut engine, &facts).unwrap();
    engine.run().unwrap();
    let out = tempfile::tempdir().unwrap();
    let (files, _) = io::write_outputs(&engine, out.path()).unwrap();
    files
        .iter()
        .map(|f| {
            (
                f.file_name().unwrap().to_string_lossy().into_owned(),
                std::fs::read_to_string(f).unwrap(),
            )
        })
        .collect()
}

#[test]
fn programs_write_the_expected_outputs() {
    let progs = programs();
    assert!(progs.len() >= 5, "test programs missing");
    for prog in progs {
        let expected_dir = prog.with_extension("").join("expected");
        let mut expected = BTreeMap::new();
        for e in std::fs::read_dir(&expected_dir)
            .unwrap_or_else(|_| panic!("{} has no expected/ directory", prog.display()))
        {
            let p = e.unwrap().path();
            expected.insert(
                p.file_name().unwrap().to_string_lossy().into_owned(),
                std::fs::read_to_string(&p).unwrap(),
            );
        }
        for provenance in [false, true] {
            let got = run(&prog, provenance);
            assert_eq!(
                got.keys().collect::<Vec<_>>(),
                expected.keys().collect::<Vec<_>>(),
                "{}: output files",
                prog.display()
            );
            for (name, text) in &expected {
                assert_eq!(
                    &got[name],
                    text,
                    "{}: {name} (provenance {provenance})",
                    prog.display()
                );
            }
        }
    }
}
