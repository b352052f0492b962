//! Soufflé-compatible file I/O: `.input` reads `<rel>.facts` (tab-separated,
//! symbols unquoted) from the facts directory, `.output` writes `<rel>.csv`
//! (tab-separated, sorted) into the output directory; `filename=` and
//! `delimiter=` override the defaults. Symbols are written as they are, as Soufflé's
//! writer does: one holding a line break or the delimiter spans lines or fields. A file name must stay inside its folder:
//! no absolute path, no `..`, no symbolic link leading out (a rule file passed
//! around must not read or write elsewhere).

use super::error::LogicError;
use super::front::ast::IoSpec;
use super::front::confine;
use super::interp::{Engine, Origin};
use super::value::Value;
use std::path::{Path, PathBuf};

/// Which directive a file belongs to, for messages.
#[derive(Clone, Copy)]
enum Direction {
    Input,
    Output,
}

impl Direction {
    fn directive(self) -> &'static str {
        match self {
            Direction::Input => ".input",
            Direction::Output => ".output",
        }
    }
    fn flag(self) -> &'static str {
        match self {
            Direction::Input => "--facts",
            Direction::Output => "--out",
        }
    }
    fn ext(self) -> &'static str {
        match self {
            Direction::Input => "facts",
            Direction::Output => "csv",
        }
    }
}

/// The file of relation `rel` under `dir`, refused if its name leaves `dir`.
fn file_for(
    engine: &Engine,
    dir: &Path,
    rel: &str,
    spec: &IoSpec,
    direction: Direction,
) -> Result<PathBuf, LogicError> {
    let name = match &spec.filename {
        Some(f) => f.clone(),
        None => format!("{rel}.{}", direction.ext()),
    };
    let refuse = |why: confine::Refusal| {
        LogicError::Confined(format!(
            "{}: `{}` of `{rel}`: file name {name:?} {why}; it must stay in {}\n  = hint: give a \
             plain relative name (no `..`, no absolute path, no symbolic link out), or choose the \
             folder with {}",
            engine.program().location(spec.span),
            direction.directive(),
            dir.display(),
            direction.flag()
        ))
    };
    confine::check_plain_relative(&name).map_err(refuse)?;
    let root = confine::canonical_root(dir).map_err(refuse)?;
    let path = dir.join(&name);
    confine::check_inside(&root, &path).map_err(refuse)?;
    Ok(path)
}

/// Read every `.input` relation's file from `facts_dir`.
pub fn load_inputs(engine: &mut Engine, facts_dir: &Path) -> Result<(), LogicError> {
    let inputs: Vec<(String, IoSpec, Vec<super::front::ast::BaseTy>)> = engine
        .program()
        .relations
        .iter()
        .filter_map(|r| {
            r.input
                .clone()
                .map(|s| (r.name.clone(), s, r.attrs.iter().map(|a| a.ty).collect()))
        })
        .collect();
    for (rel, spec, types) in inputs {
        let path = file_for(engine, facts_dir, &rel, &spec, Direction::Input)?;
        let text = std::fs::read_to_string(&path).map_err(|source| LogicError::Read {
            path: path.clone(),
            source,
        })?;
        let file = path.display().to_string();
        for (i, line) in text.split('\n').enumerate() {
            let line = line.strip_suffix('\r').unwrap_or(line);
            if line.is_empty() {
                continue;
            }
            let fields: Vec<&str> = if types.is_empty() {
                Vec::new()
            } else {
                line.split(spec.delimiter.as_str()).collect()
            };
            if fields.len() != types.len() {
                return Err(LogicError::Facts {
                    file,
                    line: i + 1,
                    message: format!(
                        "relation `{rel}` has {} attribute(s) but this line has {} field(s)",
                        types.len(),
                        fields.len()
                    ),
                    hint: format!("separate the fields with {:?}", spec.delimiter),
                });
            }
            let mut tuple = Vec::with_capacity(types.len());
            for (k, (f, ty)) in fields.iter().zip(&types).enumerate() {
                tuple.push(Value::parse(*ty, f).map_err(|m| LogicError::Facts {
                    file: file.clone(),
                    line: i + 1,
                    message: format!("field {} of `{rel}`: {m}", k + 1),
                    hint: format!("the attribute is declared as {ty}"),
                })?);
            }
            engine.insert(
                &rel,
                tuple,
                Origin::File {
                    file: file.clone(),
                    line: (i + 1) as u32,
                },
            )?;
        }
    }
    Ok(())
}

/// Text of one relation in Soufflé's output format.
pub fn format_tuples(tuples: &[Vec<Value>], delimiter: &str, arity: usize) -> String {
    let mut s = String::new();
    for t in tuples {
        if arity == 0 {
            s.push_str("()\n");
            continue;
        }
        for (i, v) in t.iter().enumerate() {
            if i > 0 {
                s.push_str(delimiter);
            }
            s.push_str(&v.to_string());
        }
        s.push('\n');
    }
    s
}

/// Write every `.output` relation; returns the files written and the text for `IO=stdout` outputs.
pub fn write_outputs(
    engine: &Engine,
    out_dir: &Path,
) -> Result<(Vec<PathBuf>, String), LogicError> {
    let mut written = Vec::new();
    let mut stdout = String::new();
    for r in &engine.program().relations {
        let Some(spec) = &r.output else { continue };
        let tuples = engine.relation(&r.name)?;
        let text = format_tuples(&tuples, &spec.delimiter, r.arity());
        if spec.stdout {
            stdout.push_str(&format!(
                "---------------\n{}\n===============\n{text}===============\n",
                r.name
            ));
            continue;
        }
        std::fs::create_dir_all(out_dir).map_err(|source| LogicError::Write {
            path: out_dir.to_path_buf(),
            source,
        })?;
        let path = file_for(engine, out_dir, &r.name, spec, Direction::Output)?;
        if let Some(parent) = path.parent() {
            std::fs::create_dir_all(parent).map_err(|source| LogicError::Write {
                path: parent.to_path_buf(),
                source,
            })?;
        }
        crate::atomic::write_atomically(&path, text.as_bytes()).map_err(|source| {
            LogicError::Write {
                path: path.clone(),
                source,
            }
        })?;
        written.push(path);
    }
    Ok((written, stdout))
}
