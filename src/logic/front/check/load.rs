//! Loading rule files and program text, with their `.include`s (confined to
//! a root folder, cycles refused), into items for the checker.

use super::super::ast::*;
use super::super::confine::Refusal;
use super::super::diag::{Diagnostic, Diagnostics, Source};
use super::super::lex::lex;
use super::super::parse::{Item, Parser};
use super::checker::Checker;
use super::program::{FunctorSig, Program};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

pub struct Loader<'f> {
    functors: &'f [FunctorSig],
    sources: Vec<Source>,
    items: Vec<(u32, Item)>,
    loading: Vec<PathBuf>,
    /// `--rules-dir`: the folder every `.include` must stay in, if given.
    include_root: Option<PathBuf>,
    /// The folder the file being loaded may include from (canonical); one per nesting level.
    roots: Vec<PathBuf>,
}

impl<'f> Loader<'f> {
    pub fn new(functors: &'f [FunctorSig]) -> Self {
        Loader {
            functors,
            sources: Vec::new(),
            items: Vec::new(),
            loading: Vec::new(),
            include_root: None,
            roots: Vec::new(),
        }
    }

    /// Confine every `.include` to `root` instead of the top-level file's own folder.
    pub fn set_include_root(&mut self, root: Option<&Path>) {
        self.include_root = root.map(Path::to_path_buf);
    }

    fn one(&self, span: Span, msg: impl Into<String>, hint: impl Into<String>) -> Diagnostics {
        Diagnostics(vec![Diagnostic::at(&self.sources, span, msg, hint)])
    }

    /// An error about a file given on the command line (no span to quote).
    fn file_error(path: &Path, message: String, hint: &str) -> Diagnostics {
        Diagnostics(vec![Diagnostic {
            file: path.display().to_string(),
            line: 0,
            col: 0,
            len: 1,
            source_line: String::new(),
            message,
            hint: hint.into(),
        }])
    }

    /// The folder `.include`s of a top-level source in `dir` must stay in.
    fn top_level_root(&self, dir: &Path) -> Result<PathBuf, Refusal> {
        let root = self.include_root.as_deref().unwrap_or(dir);
        super::super::confine::canonical_root(root)
    }

    /// Load a top-level rule file: its `.include`s stay under its folder (or `--rules-dir`).
    pub fn load_file(&mut self, path: &Path, from: Option<Span>) -> Result<(), Diagnostics> {
        if let Some(span) = from {
            return self.load_included(path, span);
        }
        let dir = path.parent().map(Path::to_path_buf).unwrap_or_default();
        let root = self
            .top_level_root(&dir)
            .map_err(|m| Self::file_error(path, m.0, "check the path"))?;
        self.roots.push(root);
        let r = self.read_and_load(path, None);
        self.roots.pop();
        r
    }

    /// Load program text that stands for a file in `dir`.
    pub fn load_text(&mut self, name: &str, text: &str, dir: &Path) -> Result<(), Diagnostics> {
        // Embedded sources name folders that need not exist here: fall back to the name as given.
        let root = self
            .top_level_root(dir)
            .unwrap_or_else(|_| self.include_root.clone().unwrap_or(dir.to_path_buf()));
        self.roots.push(root);
        let r = self.load_text_in(name, text, dir);
        self.roots.pop();
        r
    }

    /// An `.include`: refused before it is opened unless it resolves (symlinks
    /// followed) under the current root, so a refused file is never read or quoted.
    fn load_included(&mut self, path: &Path, span: Span) -> Result<(), Diagnostics> {
        let root = self.roots.last().cloned().unwrap_or_default();
        let canonical = match path.canonicalize() {
            Ok(c) => c,
            Err(e) => {
                return Err(self.one(
                    span,
                    format!("`.include`: cannot read rule file {}: {e}", path.display()),
                    "check the path (relative to the including file)",
                ));
            }
        };
        if !canonical.starts_with(&root) {
            return Err(self.one(
                span,
                format!(
                    "`.include` refused: {} is outside the folder {} that included rule files must stay in",
                    path.display(),
                    root.display()
                ),
                format!(
                    "copy the file under {} (symbolic links out of it are refused too), or pass --rules-dir with a folder that holds both",
                    root.display()
                ),
            ));
        }
        self.read_and_load(path, Some(span))
    }

    fn read_and_load(&mut self, path: &Path, from: Option<Span>) -> Result<(), Diagnostics> {
        let canonical = path.canonicalize().unwrap_or_else(|_| path.to_path_buf());
        if self.loading.contains(&canonical) {
            let span = from.unwrap_or_default();
            return Err(self.one(
                span,
                format!("`.include` cycle: {} includes itself", path.display()),
                "remove one of the `.include` directives",
            ));
        }
        let text = match std::fs::read_to_string(path) {
            Ok(t) => t,
            Err(e) => {
                let msg = format!("cannot read rule file {}: {e}", path.display());
                return Err(match from {
                    Some(span) => {
                        self.one(span, msg, "check the path (relative to the including file)")
                    }
                    None => Self::file_error(path, msg, "check the path"),
                });
            }
        };
        self.loading.push(canonical);
        let dir = path.parent().map(Path::to_path_buf).unwrap_or_default();
        let r = self.load_text_in(&path.display().to_string(), &text, &dir);
        self.loading.pop();
        r
    }

    fn load_text_in(&mut self, name: &str, text: &str, dir: &Path) -> Result<(), Diagnostics> {
        let file = self.sources.len() as u32;
        self.sources.push(Source {
            name: name.to_string(),
            text: text.to_string(),
        });
        let (toks, labels) = lex(file, text).map_err(|e| self.one(e.span, e.message, e.hint))?;
        let items = Parser::new(&toks, &labels)
            .items()
            .map_err(|e| self.one(e.span, e.message, e.hint))?;
        for item in items {
            if let Item::Include { path, span } = &item {
                let p = dir.join(path);
                self.load_included(&p, *span)?;
            } else {
                self.items.push((file, item));
            }
        }
        Ok(())
    }

    pub fn finish(self) -> Result<Program, Diagnostics> {
        Checker {
            sources: self.sources,
            functors: self.functors,
            errors: Vec::new(),
            types: BTreeMap::new(),
            agg_counter: 0,
            inline_counter: 0,
            arg_counter: 0,
            atom_types: BTreeMap::new(),
        }
        .run(self.items)
    }
}
