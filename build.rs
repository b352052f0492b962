//! Compiles the built-in rule base (all `rules/*.dl` as one program, entry `"rules"`) into
//! ascent programs in `OUT_DIR/logic_compiled.rs`, using the same parser and checker as the
//! interpreter. With the feature `logic-test-programs` (on for the crate's own tests and
//! benches only, through its dev-dependency on itself) it also compiles each
//! `tests/logic/*.dl` and `benches/logic/*.dl` and every program of the Soufflé corpus
//! `tests/fixtures/souffle/*.dl` that the generator accepts: the binary users install does
//! not carry them.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

#[allow(dead_code, unused_imports)]
#[path = "src/logic/front/mod.rs"]
mod front;

use front::ast::BaseTy;

#[allow(dead_code)]
#[path = "src/frame/rule_reads.rs"]
mod rule_reads;

/// The functor signatures, read from the same table the crate uses.
trait Ty {
    const TY: BaseTy;
}
#[allow(dead_code)]
struct F64;
#[allow(dead_code)]
struct Sym;
struct Vec3;
struct Iso;
struct OBox;
impl Ty for i64 {
    const TY: BaseTy = BaseTy::Number;
}
impl Ty for u64 {
    const TY: BaseTy = BaseTy::Unsigned;
}
impl Ty for F64 {
    const TY: BaseTy = BaseTy::Float;
}
impl Ty for Sym {
    const TY: BaseTy = BaseTy::Symbol;
}
impl Ty for Vec3 {
    const TY: BaseTy = BaseTy::Vec3;
}
impl Ty for Iso {
    const TY: BaseTy = BaseTy::Iso;
}
impl Ty for OBox {
    const TY: BaseTy = BaseTy::Box;
}

macro_rules! functor_table {
    ($( $(#[$doc:meta])* fn $name:ident ( $($arg:ident : $ty:ident),* ) -> $ret:ident $body:block )*) => {
        const SIGS: &[front::FunctorSig] = &[
            $( front::FunctorSig { name: stringify!($name), params: &[$(<$ty as Ty>::TY),*], ret: <$ret as Ty>::TY }, )*
        ];
    };
}
include!("src/logic/functor_defs.rs");

/// Programs written for Soufflé with their documented outputs.
const SOUFFLE_CORPUS: &str = "tests/fixtures/souffle";

fn dl_files(dir: &Path) -> Vec<PathBuf> {
    let mut v: Vec<PathBuf> = std::fs::read_dir(dir)
        .map(|rd| {
            rd.filter_map(|e| e.ok().map(|e| e.path()))
                .filter(|p| p.extension().is_some_and(|e| e == "dl"))
                .collect()
        })
        .unwrap_or_default();
    v.sort();
    v
}

fn main() {
    let root =
        PathBuf::from(std::env::var("CARGO_MANIFEST_DIR").expect("cargo sets CARGO_MANIFEST_DIR"));
    println!("cargo:rerun-if-changed=src/logic/front");
    println!("cargo:rerun-if-changed=src/logic/functor_defs.rs");
    println!("cargo:rerun-if-changed=src/frame/rule_reads.rs");
    let test_programs = std::env::var_os("CARGO_FEATURE_LOGIC_TEST_PROGRAMS").is_some();
    let test_dirs = ["tests/logic", "benches/logic", SOUFFLE_CORPUS];
    let mut out = String::new();
    let mut table = Vec::new();
    let watched = if test_programs { &test_dirs[..] } else { &[] };
    for dir in std::iter::once("rules").chain(watched.iter().copied()) {
        println!("cargo:rerun-if-changed={dir}");
        // Included fragments live in subdirectories; watch them too.
        if let Ok(rd) = std::fs::read_dir(root.join(dir)) {
            for e in rd.flatten() {
                println!("cargo:rerun-if-changed={}", e.path().display());
            }
        }
    }
    // The built-in rule base: all rules/*.dl form one program, also embedded
    // as text so the interpreter can run it (explanations) without the sources.
    let builtin = dl_files(&root.join("rules"));
    out.push_str("/// The built-in rule base: (path, text) of every `rules/*.dl`.\n");
    out.push_str("pub static BUILTIN_SOURCES: &[(&str, &str)] = &[\n");
    for f in &builtin {
        let name = format!("rules/{}", f.file_name().unwrap().to_string_lossy());
        let _ = writeln!(
            out,
            "    ({name:?}, include_str!({:?})),",
            f.display().to_string()
        );
    }
    out.push_str("];\n");
    if !builtin.is_empty() {
        let program = front::load_files(&builtin, SIGS)
            .unwrap_or_else(|e| panic!("the built-in rules do not check:\n{e}"));
        match front::codegen::generate(&program, "builtin_rules") {
            Ok(code) => out.push_str(&code),
            Err(e) => panic!("the built-in rules cannot be compiled to ascent: {e}"),
        }
        table.push(("rules".to_string(), "builtin_rules".to_string()));
        out.push_str(&placed_slice(&program, "builtin_rules", "builtin_placed"));
        out.push_str(&plan_scope(&program));
        let rows = PathBuf::from(std::env::var("OUT_DIR").expect("cargo sets OUT_DIR"))
            .join("framing_rows.rs");
        std::fs::write(&rows, typed_rows(&program)).expect("write the typed rows");
        let tables = PathBuf::from(std::env::var("OUT_DIR").expect("cargo sets OUT_DIR"))
            .join("framing_tables.rs");
        std::fs::write(&tables, typed_tables(&program)).expect("write the typed tables");
    }
    if test_programs {
        test_and_bench_programs(&root, &mut out, &mut table);
    }
    let _ = writeln!(
        out,
        "/// Every compiled program: (path, entry point).\npub static PROGRAMS: &[(&str, RunFn)] = &["
    );
    for (rel, module) in &table {
        let _ = writeln!(out, "    ({rel:?}, {module}::run),");
    }
    out.push_str("];\n");
    let dest = PathBuf::from(std::env::var("OUT_DIR").expect("cargo sets OUT_DIR"))
        .join("logic_compiled.rs");
    std::fs::write(&dest, out).expect("write generated rules");
}

/// The test and benchmark programs (one program per file) and every program of the Soufflé
/// corpus the code generator accepts (tests/souffle_corpus.rs checks which ones it refuses,
/// and why), appended to `out` and listed in `table`.
fn test_and_bench_programs(root: &Path, out: &mut String, table: &mut Vec<(String, String)>) {
    for dir in ["tests/logic", "benches/logic"] {
        for file in dl_files(&root.join(dir)) {
            let rel = format!("{dir}/{}", file.file_name().unwrap().to_string_lossy());
            let program = match front::load_files(std::slice::from_ref(&file), SIGS) {
                Ok(p) => p,
                Err(e) => panic!("rule program {rel} does not check:\n{e}"),
            };
            let module = rel.trim_end_matches(".dl").replace(['/', '.', '-'], "_");
            match front::codegen::generate(&program, &module) {
                Ok(code) => out.push_str(&code),
                Err(e) => panic!("rule program {rel} cannot be compiled to ascent: {e}"),
            }
            table.push((rel, module));
        }
    }
    for file in dl_files(&root.join(SOUFFLE_CORPUS)) {
        let rel = format!(
            "{SOUFFLE_CORPUS}/{}",
            file.file_name().unwrap().to_string_lossy()
        );
        let Ok(program) = front::load_files(std::slice::from_ref(&file), SIGS) else {
            continue;
        };
        let module = rel.trim_end_matches(".dl").replace(['/', '.', '-'], "_");
        if let Ok(code) = front::codegen::generate(&program, &module) {
            out.push_str(&code);
            table.push((rel, module));
        }
    }
}

/// The rule base cut down to what `plan` asks of it (`rule_reads`): every rule of a relation
/// those depend on, as its own ascent program (`builtin_plan`, with its placement slice
/// `builtin_plan_placed`), and `BUILTIN_PLAN_RELATIONS`, the relations it derives exactly
/// as the whole rule base does (a caller wanting any other must run the whole).
fn plan_scope(program: &front::Program) -> String {
    let scope = program.upstream_of(&typed_targets());
    let cut = program.restricted_to(&scope);
    let mut code = front::codegen::generate(&cut, "builtin_plan")
        .unwrap_or_else(|e| panic!("the rules `plan` reads cannot be compiled: {e}"));
    code.push_str(&placed_slice(&cut, "builtin_plan", "builtin_plan_placed"));
    code.push_str(
        "/// The relations `builtin_plan` derives as the whole rule base does.
",
    );
    code.push_str(
        "pub const BUILTIN_PLAN_RELATIONS: &[&str] = &[
",
    );
    for r in &scope {
        let _ = writeln!(code, "    {r:?},");
    }
    code.push_str(
        "];
",
    );
    code
}

/// The rules of `program` (compiled as module `base`) that depend on the placement search,
/// as their own ascent program (module `name`), and its `finish`, which runs it on a
/// finished first pass of `base` once the placement inputs are filled in: it borrows the
/// relations the slice reads but does not derive, gives them back, and replaces every
/// relation it derives (the first pass derived those without placements).
fn placed_slice(program: &front::Program, base: &str, name: &str) -> String {
    let derived = program.downstream_of(rule_reads::PLACEMENT_INPUTS);
    let slice = program.restricted_to(&derived);
    let heads: std::collections::BTreeSet<&str> =
        slice.rules.iter().map(|r| r.head.rel.as_str()).collect();
    let borrowed: Vec<String> = slice
        .relations_read()
        .into_iter()
        .filter(|r| !heads.contains(r.as_str()))
        .collect();
    let mut code = front::codegen::generate(&slice, name)
        .unwrap_or_else(|e| panic!("the placement-dependent rules cannot be compiled: {e}"));
    let field = |name: &str| format!("r_{}", name.replace('?', "_Q"));
    let _ = writeln!(code, "impl {name}::Prog {{");
    code.push_str("    /// Runs the placement-dependent rules over `base` (see `build.rs`).\n");
    let _ = writeln!(code, "    pub fn finish(base: &mut {base}::Prog) {{");
    code.push_str("        let mut p = Self::default();\n");
    for r in &borrowed {
        let f = field(r);
        let _ = writeln!(code, "        p.{f} = std::mem::take(&mut base.{f});");
    }
    code.push_str("        p.run();\n");
    for r in borrowed
        .iter()
        .map(String::as_str)
        .chain(heads.iter().copied())
    {
        let f = field(r);
        let _ = writeln!(code, "        base.{f} = std::mem::take(&mut p.{f});");
    }
    code.push_str("    }\n}\n");
    code
}

/// What the typed runner (`frame::builtin`) reads back: what `plan`, the placement
/// search's first pass and the plan cache's storey check read (`rule_reads`), each once, in
/// that order. `plan_scope` cuts the rule base to these same relations.
fn typed_targets() -> Vec<&'static str> {
    let mut targets: Vec<&str> = Vec::new();
    let reads = rule_reads::PLAN
        .iter()
        .chain(rule_reads::PLACEMENT_FIRST_PASS)
        .chain([&rule_reads::STOREY_REACH]);
    for r in reads {
        if !targets.contains(r) {
            targets.push(r);
        }
    }
    targets
}

/// The typed runner's tables (`frame::builtin`'s `inputs!` and `outputs!` lists), from
/// the `.decl`s: every `.input` relation in declaration order but the simulation's records
/// (`sim_…`, rules/sim.dl: the runner serves `plan` and the placement search, which never
/// have them; `handles` sends facts holding them to the whole engine), and the outputs
/// (`typed_targets`). Fields are named and typed as the code generator names and types them.
fn typed_tables(program: &front::Program) -> String {
    let targets = typed_targets();
    let mut code = String::from("inputs! {\n");
    for rel in &program.relations {
        if rel.input.is_none() || rel.name.starts_with("sim_") {
            continue;
        }
        let cols: Vec<String> = rel
            .attrs
            .iter()
            .enumerate()
            .map(|(i, a)| format!("{i}: {}", front::codegen::rust_ty(a.ty)))
            .collect();
        let _ = writeln!(
            code,
            "    {:?} => {}({});",
            rel.name,
            front::codegen::rel_name(&rel.name),
            cols.join(", ")
        );
    }
    code.push_str("}\noutputs! {\n");
    for name in &targets {
        let rel = program
            .relation(name)
            .unwrap_or_else(|| panic!("`{name}` (rule_reads) is not declared in rules/"));
        let cols: Vec<String> = (0..rel.attrs.len()).map(|i| i.to_string()).collect();
        let _ = writeln!(
            code,
            "    {name:?} => {}({});",
            front::codegen::rel_name(name),
            cols.join(", ")
        );
    }
    code.push_str("}\n");
    code
}

/// One struct per relation of the built-in rule base, its fields named and typed as its
/// `.decl` says, read from a tuple by `frame::rows::Row::read` (see `src/frame/rows.rs`).
fn typed_rows(program: &front::Program) -> String {
    let mut code = String::new();
    for rel in &program.relations {
        let name: String = rel
            .name
            .split(['_', '?'])
            .filter(|w| !w.is_empty())
            .map(|w| {
                let mut c = w.chars();
                c.next()
                    .map_or(String::new(), |f| f.to_uppercase().chain(c).collect())
            })
            .collect();
        let fields: Vec<(String, &str, &str)> = rel
            .attrs
            .iter()
            .map(|a| {
                let (ty, read) = match a.ty {
                    BaseTy::Number => ("i64", "as_number"),
                    BaseTy::Unsigned => ("u64", "as_unsigned"),
                    BaseTy::Float => ("f64", "as_float"),
                    BaseTy::Symbol => ("&'static str", "as_sym"),
                    BaseTy::Vec3 => ("nalgebra::Vector3<f64>", "as_vec3"),
                    BaseTy::Iso => ("nalgebra::Isometry3<f64>", "as_iso"),
                    BaseTy::Box => ("crate::logic::OBox", "as_box"),
                };
                (field_name(&a.name), ty, read)
            })
            .collect();
        let decl: Vec<String> = rel
            .attrs
            .iter()
            .map(|a| format!("{}: {}", a.name, a.ty_name))
            .collect();
        let _ = writeln!(code, "/// `{}({})`", rel.name, decl.join(", "));
        code.push_str("#[derive(Debug, Clone, PartialEq)]\n");
        let _ = writeln!(code, "pub struct {name} {{");
        for (f, ty, _) in &fields {
            let _ = writeln!(code, "    pub {f}: {ty},");
        }
        code.push_str("}\n");
        let _ = writeln!(code, "impl Row for {name} {{");
        let _ = writeln!(code, "    const RELATION: &'static str = {:?};", rel.name);
        let _ = writeln!(
            code,
            "    const DECL: &'static str = {:?};",
            decl.join(", ")
        );
        code.push_str("    fn read(t: &[Value]) -> Option<Self> {\n");
        let vars: Vec<String> = (0..fields.len()).map(|i| format!("v{i}")).collect();
        let _ = writeln!(
            code,
            "        let [{}] = t else {{ return None }};",
            vars.join(", ")
        );
        let _ = writeln!(code, "        Some({name} {{");
        for ((f, _, read), v) in fields.iter().zip(&vars) {
            let value = match *read {
                "as_sym" => format!("{v}.as_sym()?.as_str()"),
                _ => format!("{v}.{read}()?"),
            };
            let _ = writeln!(code, "            {f}: {value},");
        }
        code.push_str("        })\n    }\n}\n");
    }
    code
}

/// A `.decl` attribute name as a Rust field name.
fn field_name(attr: &str) -> String {
    const KEYWORDS: &[&str] = &[
        "as", "box", "break", "const", "continue", "crate", "else", "enum", "extern", "false",
        "fn", "for", "if", "impl", "in", "let", "loop", "match", "mod", "move", "mut", "pub",
        "ref", "return", "self", "static", "struct", "super", "trait", "true", "type", "unsafe",
        "use", "where", "while", "async", "await", "dyn", "abstract", "become", "do", "final",
        "macro", "override", "priv", "typeof", "unsized", "virtual", "yield", "try", "gen",
    ];
    let snake: String = attr
        .chars()
        .map(|c| {
            if c.is_alphanumeric() {
                c.to_ascii_lowercase()
            } else {
                '_'
            }
        })
        .collect();
    if KEYWORDS.contains(&snake.as_str()) {
        format!("{snake}_")
    } else {
        snake
    }
}
