//! Recursive-descent parser: tokens → items (declarations, directives,
//! clauses). Disjunctions are expanded into one clause per branch, as Soufflé
//! does; unsupported Soufflé features are rejected by name.

mod clause;
mod directive;
mod expr;

use super::ast::*;
use super::lex::{Label, Tok, Token};

#[derive(Debug)]
pub struct ParseError {
    pub span: Span,
    pub message: String,
    pub hint: String,
}

fn err<T>(
    span: Span,
    message: impl Into<String>,
    hint: impl Into<String>,
) -> Result<T, ParseError> {
    Err(ParseError {
        span,
        message: message.into(),
        hint: hint.into(),
    })
}

#[derive(Clone, Debug)]
pub enum Item {
    Type(TypeDecl),
    Decl {
        name: String,
        attrs: Vec<(String, String, Span)>,
        /// Declared `eqrel`: the relation is an equivalence relation.
        eqrel: bool,
        /// Declared `inline`: its rules are substituted into every use.
        inline: bool,
        span: Span,
    },
    Io {
        output: bool,
        rels: Vec<(String, Span)>,
        params: Vec<(String, String, Span)>,
        span: Span,
    },
    Include {
        path: String,
        span: Span,
    },
    /// One clause per head atom and per disjunction branch.
    Clause(Rule),
}

/// Bounds on one item's expression tree: the parser, the checker, the engines and dropping the
/// tree all recurse over it, so a hostile file (`((((…`, `----…`, `1+1+…+1`) must not be able
/// to make it deep enough to overflow a thread's stack.
const MAX_NESTING: usize = 100;
const MAX_OPERATORS: usize = 1000;

/// A parenthesised disjunction read: the token position after it and its literals.
type Group = (usize, Vec<Vec<Literal>>);

pub struct Parser<'a> {
    toks: &'a [Token],
    pos: usize,
    labels: &'a [Label],
    /// Line of the end of the previous item: labels must follow it.
    prev_end_line: u32,
    /// Current nesting of expressions and body terms.
    depth: usize,
    /// Operators read in the current item.
    operators: usize,
    /// Outcome of reading a parenthesised disjunction at (token position, nesting depth):
    /// where it ended and what it held, or None when it failed. A `(` is first tried as a
    /// disjunction, then as an expression, which can hold aggregates whose bodies hold the
    /// same `(` again: without this, nested groups would be read 2^depth times.
    groups: std::collections::HashMap<(usize, usize), Option<Group>>,
}

impl<'a> Parser<'a> {
    pub fn new(toks: &'a [Token], labels: &'a [Label]) -> Self {
        Parser {
            toks,
            pos: 0,
            labels,
            prev_end_line: 0,
            depth: 0,
            operators: 0,
            groups: std::collections::HashMap::new(),
        }
    }

    /// Runs `f` one nesting level deeper, refusing past `MAX_NESTING`.
    fn nested<T>(
        &mut self,
        f: impl FnOnce(&mut Self) -> Result<T, ParseError>,
    ) -> Result<T, ParseError> {
        if self.depth >= MAX_NESTING {
            return err(
                self.span(),
                format!("expressions or rule bodies nest more than {MAX_NESTING} levels deep here"),
                "compute inner parts in helper rules (or variables) instead of nesting them",
            );
        }
        self.depth += 1;
        let out = f(self);
        self.depth -= 1;
        out
    }

    /// Counts one operator of the current item, refusing past `MAX_OPERATORS`.
    fn operator(&mut self) -> Result<(), ParseError> {
        self.operators += 1;
        if self.operators > MAX_OPERATORS {
            return err(
                self.span(),
                format!("this rule holds more than {MAX_OPERATORS} operators"),
                "split the computation over several rules with intermediate relations",
            );
        }
        Ok(())
    }

    fn peek(&self) -> &Tok {
        &self.toks[self.pos].tok
    }
    fn peek_at(&self, k: usize) -> &Tok {
        &self.toks[(self.pos + k).min(self.toks.len() - 1)].tok
    }
    fn span(&self) -> Span {
        self.toks[self.pos].span
    }
    fn bump(&mut self) -> Token {
        let t = self.toks[self.pos].clone();
        if self.pos + 1 < self.toks.len() {
            self.pos += 1;
        }
        t
    }
    fn is(&self, p: &str) -> bool {
        matches!(self.peek(), Tok::P(q) if *q == p)
    }
    fn eat(&mut self, p: &str) -> bool {
        if self.is(p) {
            self.bump();
            true
        } else {
            false
        }
    }
    fn describe(tok: &Tok) -> String {
        match tok {
            Tok::Ident(s) => format!("`{s}`"),
            Tok::Directive(s) => format!("`.{s}`"),
            Tok::Int(i) => format!("`{i}`"),
            Tok::UInt(i) => format!("`{i}u`"),
            Tok::Float(f) => format!("`{f}`"),
            Tok::Str(s) => format!("\"{s}\""),
            Tok::P(p) => format!("`{p}`"),
            Tok::Eof => "end of file".into(),
        }
    }
    fn expect(&mut self, p: &str, hint: &str) -> Result<Span, ParseError> {
        if self.is(p) {
            Ok(self.bump().span)
        } else {
            err(
                self.span(),
                format!("expected `{p}`, found {}", Self::describe(self.peek())),
                hint,
            )
        }
    }
    fn ident(&mut self, what: &str) -> Result<(String, Span), ParseError> {
        match self.peek().clone() {
            Tok::Ident(s) => {
                let sp = self.bump().span;
                Ok((s, sp))
            }
            other => err(
                self.span(),
                format!("expected {what}, found {}", Self::describe(&other)),
                format!("write {what} here"),
            ),
        }
    }

    pub fn items(&mut self) -> Result<Vec<Item>, ParseError> {
        let mut items = Vec::new();
        while *self.peek() != Tok::Eof {
            let start = self.span();
            self.operators = 0;
            match self.peek().clone() {
                Tok::Directive(d) => self.directive(&d, &mut items)?,
                _ => self.clause(&mut items)?,
            }
            let _ = start;
            self.prev_end_line = self.toks[self.pos.saturating_sub(1)].span.line;
        }
        Ok(items)
    }
}
