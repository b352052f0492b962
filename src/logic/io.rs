//! Soufflé-compatible file I/O: `.input` reads `<rel>.facts` (tab-separated,
//! symbols unquoted) from the facts directory, `.output` writes `<rel>.csv`
//! (tab-separated, sorted) into the output directory; `filename=` and
//! `delimiter=` override the defaults, absolute file names are used as they are.

use super::error::LogicError;
use super::front::ast::IoSpec;
use super::interp::{Engine, Origin};
use super::io_symbols::unwritable_symbol;
use super::value::Value;
use std::path::{Path, PathBuf};

fn file_for(dir: &Path, rel: &str, spec: &IoSpec, ext: &str) -> PathBuf {
    match &spec.filename {
        Some(f) if Path::new(f).is_absolute() => PathBuf::from(f),
        Some(f) => dir.join(f),
        None => dir.join(format!("{rel}.{ext}")),
    }
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
        let path = file_for(facts_dir, &rel, &spec, "facts");
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
        if !spec.stdout
            && let Some((symbol, why)) = unwritable_symbol(&tuples, &spec.delimiter)
        {
            return Err(LogicError::Usage(format!(
                "cannot write `{}` to {}: the symbol {symbol:?} {why}, and .facts/.csv files \
                 hold symbols unquoted; change the rules that derive it (or the delimiter)",
                r.name,
                file_for(out_dir, &r.name, spec, "csv").display()
            )));
        }
        let text = format_tuples(&tuples, &spec.delimiter, r.arity());
        if spec.stdout {
            stdout.push_str(&format!(
                "---------------\n{}\n===============\n{text}===============\n",
                r.name
            ));
            continue;
        }
        let path = file_for(out_dir, &r.name, spec, "csv");
        if let Some(parent) = path.parent() {
            std::fs::create_dir_all(parent).map_err(|source| LogicError::Write {
                path: parent.to_path_buf(),
                source,
            })?;
        }
        std::fs::write(&path, text).map_err(|source| LogicError::Write {
            path: path.clone(),
            source,
        })?;
        written.push(path);
    }
    Ok((written, stdout))
}
