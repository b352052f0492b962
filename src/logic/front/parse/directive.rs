//! Declarations and directives: `.type`, `.decl`, `.input`/`.output`, `.include`,
//! and the Soufflé directives refused by name.

use super::super::ast::*;
use super::super::lex::Tok;
use super::{Item, ParseError, Parser, err};

const UNSUPPORTED_DIRECTIVES: [(&str, &str); 10] = [
    ("comp", "components (`.comp`)"),
    ("init", "component instances (`.init`)"),
    (
        "functor",
        "user-defined functors (`.functor`): rule files cannot run code",
    ),
    ("pragma", "`.pragma`"),
    ("plan", "query plans (`.plan`)"),
    ("printsize", "`.printsize`"),
    ("limitsize", "`.limitsize`"),
    ("override", "component overrides (`.override`)"),
    ("lattice", "lattices (`.lattice`)"),
    ("once", "`.once`"),
];

impl<'a> Parser<'a> {
    pub(super) fn directive(&mut self, d: &str, items: &mut Vec<Item>) -> Result<(), ParseError> {
        let dspan = self.bump().span;
        match d {
            "type" | "number_type" | "symbol_type" => {
                let (name, nspan) = self.ident("a type name")?;
                let (parent, is_subtype) = if d == "number_type" {
                    ("number".to_string(), true)
                } else if d == "symbol_type" {
                    ("symbol".to_string(), true)
                } else if self.eat("<:") {
                    (self.ident("a type name")?.0, true)
                } else if self.eat("=") {
                    if self.is("[") {
                        return err(
                            self.span(),
                            "record types are not supported",
                            "records are an unsupported Soufflé feature; flatten the record into relation attributes",
                        );
                    }
                    let (p, _) = self.ident("a type name")?;
                    if self.is("{") {
                        return err(
                            self.span(),
                            "algebraic data types are not supported",
                            "ADTs are an unsupported Soufflé feature; use several relations instead",
                        );
                    }
                    if self.is("|") {
                        let mut members = vec![p.clone()];
                        while self.eat("|") {
                            members.push(self.ident("a type name")?.0);
                        }
                        items.push(Item::Type(TypeDecl {
                            name,
                            parent: p,
                            is_subtype: false,
                            members,
                            span: nspan,
                        }));
                        return Ok(());
                    }
                    (p, false)
                } else {
                    return err(
                        self.span(),
                        format!("expected `<:` or `=` after `.type {name}`"),
                        "write `.type Name <: number` (subtype) or `.type Name = symbol` (alias)",
                    );
                };
                items.push(Item::Type(TypeDecl {
                    name,
                    parent,
                    is_subtype,
                    members: Vec::new(),
                    span: nspan,
                }));
            }
            "decl" => {
                // `.decl a, b(x: number)` declares several relations alike.
                let mut names = vec![self.ident("a relation name")?];
                while self.eat(",") {
                    names.push(self.ident("a relation name")?);
                }
                self.expect(
                    "(",
                    "a declaration looks like `.decl edge(x: number, y: number)`",
                )?;
                let mut attrs = Vec::new();
                if !self.is(")") {
                    loop {
                        let (a, aspan) = self.ident("an attribute name")?;
                        self.expect(":", "give each attribute a type: `x: number`")?;
                        if self.is("[") {
                            return err(
                                self.span(),
                                "record types are not supported",
                                "records are an unsupported Soufflé feature; flatten the record",
                            );
                        }
                        let (t, _) = self.ident("a type name")?;
                        attrs.push((a, t, aspan));
                        if !self.eat(",") {
                            break;
                        }
                    }
                }
                self.expect(")", "close the attribute list with `)`")?;
                // Qualifiers: storage hints are accepted and ignored; the ones that
                // change meaning are refused by name.
                let mut eqrel = false;
                let mut inline = false;
                loop {
                    match self.peek().clone() {
                        Tok::Ident(q) if q == "inline" => {
                            inline = true;
                            self.bump();
                        }
                        Tok::Ident(q)
                            if [
                                "btree",
                                "brie",
                                "no_inline",
                                "magic",
                                "no_magic",
                                "btree_delete",
                                "overridable",
                            ]
                            .contains(&q.as_str()) =>
                        {
                            self.bump();
                        }
                        Tok::Ident(q) if q == "eqrel" => {
                            if attrs.len() != 2 {
                                return err(
                                    self.span(),
                                    format!(
                                        "an `eqrel` relation has two attributes; `{}` has {}",
                                        names[0].0,
                                        attrs.len()
                                    ),
                                    "declare it as `.decl r(x: T, y: T) eqrel`",
                                );
                            }
                            eqrel = true;
                            self.bump();
                        }
                        Tok::Ident(q) if q == "choice" => {
                            return err(
                                self.span(),
                                "choice domains (`choice-domain`) are not supported",
                                "choice is an unsupported Soufflé feature",
                            );
                        }
                        Tok::Ident(q) if q == "input" || q == "output" || q == "printsize" => {
                            return err(
                                self.span(),
                                format!("the `{q}` qualifier is not supported"),
                                format!("use a separate `.{q} {}` directive", names[0].0),
                            );
                        }
                        _ => break,
                    }
                }
                for (name, nspan) in names {
                    items.push(Item::Decl {
                        name,
                        attrs: attrs.clone(),
                        eqrel,
                        inline,
                        span: nspan,
                    });
                }
            }
            "input" | "output" => {
                let mut rels = vec![self.ident("a relation name")?];
                while self.eat(",") {
                    rels.push(self.ident("a relation name")?);
                }
                let mut params = Vec::new();
                // `.output r()` (an empty parameter list) is how Soufflé's docs write it.
                if self.eat("(") {
                    if !self.is(")") {
                        loop {
                            let (k, kspan) =
                                self.ident("a parameter name (IO, filename, delimiter)")?;
                            self.expect("=", "parameters look like `filename=\"x.facts\"`")?;
                            let v = match self.peek().clone() {
                                Tok::Str(s) => s,
                                Tok::Ident(s) => s,
                                other => {
                                    return err(
                                        self.span(),
                                        format!(
                                            "expected a parameter value, found {}",
                                            Self::describe(&other)
                                        ),
                                        "write the value as a string: `delimiter=\",\"`",
                                    );
                                }
                            };
                            self.bump();
                            params.push((k, v, kspan));
                            if !self.eat(",") {
                                break;
                            }
                        }
                    }
                    self.expect(")", "close the parameter list with `)`")?;
                }
                items.push(Item::Io {
                    output: d == "output",
                    rels,
                    params,
                    span: dspan,
                });
            }
            "include" => match self.peek().clone() {
                Tok::Str(path) => {
                    let sp = self.bump().span;
                    items.push(Item::Include { path, span: sp });
                }
                other => {
                    return err(
                        self.span(),
                        format!(
                            "expected a file name after `.include`, found {}",
                            Self::describe(&other)
                        ),
                        "write `.include \"other.dl\"`",
                    );
                }
            },
            other => {
                let msg = UNSUPPORTED_DIRECTIVES
                    .iter()
                    .find(|(k, _)| *k == other)
                    .map(|(_, what)| format!("{what} is not supported"))
                    .unwrap_or_else(|| format!("unknown directive `.{other}`"));
                return err(
                    dspan,
                    msg,
                    "supported directives: .decl, .type, .input, .output, .include (see docs/RULES-LANGUAGE.md)",
                );
            }
        }
        Ok(())
    }
}
