//! The checked program and what callers ask of it: relations, locations,
//! the relations upstream and downstream of others, and slices of its rules.

use super::super::ast::*;
use super::super::diag::Source;
use super::walk::collect_deps;
use std::collections::{BTreeMap, BTreeSet};

/// Signature of a Rust functor `@name(args) -> ret` (the implementations live
/// in `logic::functors`; the checker and code generator only need this).
#[derive(Clone, Copy, Debug)]
pub struct FunctorSig {
    pub name: &'static str,
    pub params: &'static [BaseTy],
    pub ret: BaseTy,
}

/// A checked program: every relation declared, every rule typed, grounded,
/// planned and assigned to a stratum.
#[derive(Clone, Debug)]
pub struct Program {
    pub sources: Vec<Source>,
    pub types: Vec<TypeDecl>,
    pub relations: Vec<RelDecl>,
    pub rel_index: BTreeMap<String, usize>,
    /// Rules and facts (a fact is a rule with an empty body).
    pub rules: Vec<Rule>,
    /// In evaluation order: a stratum only reads relations of itself and earlier strata.
    pub strata: Vec<Stratum>,
}

#[derive(Clone, Debug)]
pub struct Stratum {
    pub relations: Vec<usize>,
    pub rules: Vec<usize>,
    /// A relation of this stratum depends on itself.
    pub recursive: bool,
}

impl Program {
    pub fn relation(&self, name: &str) -> Option<&RelDecl> {
        self.rel_index.get(name).map(|&i| &self.relations[i])
    }
    /// `file:line` of a span.
    pub fn location(&self, span: Span) -> String {
        let file = self
            .sources
            .get(span.file as usize)
            .map_or("<unknown>", |s| s.name.as_str());
        format!("{file}:{}", span.line)
    }
    /// The relations whose tuples can change with any of `sources`: the sources and every
    /// relation a rule derives from one of them (through atoms, negations or aggregates),
    /// transitively.
    pub fn downstream_of(&self, sources: &[&str]) -> BTreeSet<String> {
        let mut reached: BTreeSet<String> = sources.iter().map(|s| s.to_string()).collect();
        loop {
            let before = reached.len();
            for rule in &self.rules {
                if reached.contains(&rule.head.rel) {
                    continue;
                }
                let mut deps = Vec::new();
                collect_deps(&rule.body, false, &self.rel_index, &mut deps);
                if deps
                    .iter()
                    .any(|(b, _, _)| reached.contains(&self.relations[*b].name))
                {
                    reached.insert(rule.head.rel.clone());
                }
            }
            if reached.len() == before {
                return reached;
            }
        }
    }

    /// The relations `targets` can depend on: the targets and every relation a rule for one
    /// of them reads (through atoms, negations or aggregates), transitively.
    pub fn upstream_of(&self, targets: &[&str]) -> BTreeSet<String> {
        let mut reached: BTreeSet<String> = targets.iter().map(|s| s.to_string()).collect();
        let mut todo: Vec<String> = reached.iter().cloned().collect();
        while let Some(relation) = todo.pop() {
            for rule in self.rules.iter().filter(|r| r.head.rel == relation) {
                let mut deps = Vec::new();
                collect_deps(&rule.body, false, &self.rel_index, &mut deps);
                for (b, _, _) in deps {
                    let name = &self.relations[b].name;
                    if reached.insert(name.clone()) {
                        todo.push(name.clone());
                    }
                }
            }
        }
        reached
    }

    /// The program with only the rules (and facts) whose head is one of `heads`; every
    /// relation stays declared, so the others can be filled as inputs. When `heads` is closed
    /// under `downstream_of`, running this over the other relations' complete tuples gives
    /// `heads` the tuples the whole program gives them (strata below stay as they were).
    pub fn restricted_to(&self, heads: &BTreeSet<String>) -> Program {
        let mut slice = self.clone();
        slice.rules.retain(|r| heads.contains(&r.head.rel));
        for stratum in &mut slice.strata {
            stratum.rules.clear();
        }
        for (i, rule) in slice.rules.iter().enumerate() {
            let head = self.rel_index[&rule.head.rel];
            if let Some(s) = slice
                .strata
                .iter_mut()
                .find(|s| s.relations.contains(&head))
            {
                s.rules.push(i);
            }
        }
        slice
    }

    /// The relations the rules read (in atoms, negations and aggregates).
    pub fn relations_read(&self) -> BTreeSet<String> {
        let mut deps = Vec::new();
        for rule in &self.rules {
            collect_deps(&rule.body, false, &self.rel_index, &mut deps);
        }
        deps.iter()
            .map(|(b, _, _)| self.relations[*b].name.clone())
            .collect()
    }

    /// How explanations cite a rule: `label (file:line)` or `rule (file:line)`.
    pub fn rule_name(&self, rule: usize) -> String {
        let r = &self.rules[rule];
        match &r.label {
            Some(l) => format!("{l} ({})", self.location(r.span)),
            None if r.body.is_empty() => format!("fact ({})", self.location(r.span)),
            None => format!("rule ({})", self.location(r.span)),
        }
    }
}
