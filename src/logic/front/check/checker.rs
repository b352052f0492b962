//! The checker's state, shared by its passes, and how it reports errors.

use super::super::ast::*;
use super::super::diag::{Diagnostic, Source, closest};
use super::program::FunctorSig;
use std::collections::BTreeMap;

pub(super) struct Checker<'f> {
    pub(super) sources: Vec<Source>,
    pub(super) functors: &'f [FunctorSig],
    pub(super) errors: Vec<Diagnostic>,
    /// User type name → (parent name, is_subtype, span).
    pub(super) types: BTreeMap<String, TypeDecl>,
    pub(super) agg_counter: usize,
    /// Renamings made by inlining (`__inlN_x`).
    pub(super) inline_counter: usize,
    /// Fresh variables standing for expression arguments of body atoms (`__argN`).
    pub(super) arg_counter: usize,
    /// Relation name → attribute base types.
    pub(super) atom_types: BTreeMap<String, Vec<BaseTy>>,
}

pub(super) type Env = BTreeMap<String, BaseTy>;

impl Checker<'_> {
    pub(super) fn error(&mut self, span: Span, msg: impl Into<String>, hint: impl Into<String>) {
        self.errors
            .push(Diagnostic::at(&self.sources, span, msg, hint));
    }

    pub(super) fn loc(&self, span: Span) -> String {
        let file = self
            .sources
            .get(span.file as usize)
            .map_or("<unknown>", |s| s.name.as_str());
        format!("{file}:{}:{}", span.line, span.col)
    }

    pub(super) fn rel_hint(&self, name: &str, rel_index: &BTreeMap<String, usize>) -> String {
        match closest(name, rel_index.keys().map(String::as_str)) {
            Some(c) => format!("did you mean `{c}`? otherwise declare it with `.decl {name}(...)`"),
            None => format!("declare it with `.decl {name}(x: number, ...)`"),
        }
    }
}
