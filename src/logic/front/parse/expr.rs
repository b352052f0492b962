//! Expressions: arithmetic, constants, variables, built-in and `@` functor calls,
//! and aggregates.

use super::super::ast::*;
use super::super::lex::Tok;
use super::{ParseError, Parser, err};

const BITWISE: [&str; 11] = [
    "band", "bor", "bxor", "bshl", "bshr", "bshru", "bnot", "land", "lor", "lxor", "lnot",
];

impl<'a> Parser<'a> {
    pub fn expr(&mut self) -> Result<Expr, ParseError> {
        self.nested(Self::sum)
    }

    fn sum(&mut self) -> Result<Expr, ParseError> {
        let mut lhs = self.term_mul()?;
        loop {
            let op = match self.peek() {
                Tok::P("+") => BinOp::Add,
                Tok::P("-") => BinOp::Sub,
                _ => break,
            };
            self.operator()?;
            self.bump();
            let rhs = self.term_mul()?;
            lhs = bin(op, lhs, rhs);
        }
        self.check_bitwise()?;
        Ok(lhs)
    }

    fn check_bitwise(&self) -> Result<(), ParseError> {
        if let Tok::Ident(n) = self.peek() {
            if BITWISE.contains(&n.as_str()) {
                return err(
                    self.span(),
                    format!("the bitwise/logical operator `{n}` is not supported"),
                    "bitwise and logical operators are outside the supported subset",
                );
            }
        }
        Ok(())
    }

    fn term_mul(&mut self) -> Result<Expr, ParseError> {
        let mut lhs = self.unary()?;
        loop {
            let op = match self.peek() {
                Tok::P("*") => BinOp::Mul,
                Tok::P("/") => BinOp::Div,
                Tok::P("%") => BinOp::Rem,
                _ => break,
            };
            self.operator()?;
            self.bump();
            let rhs = self.unary()?;
            lhs = bin(op, lhs, rhs);
        }
        self.check_bitwise()?;
        Ok(lhs)
    }

    fn unary(&mut self) -> Result<Expr, ParseError> {
        if self.is("-") {
            self.operator()?;
            let span = self.bump().span;
            let inner = self.nested(Self::unary)?;
            return Ok(match inner.kind {
                ExprKind::Int(i) => Expr {
                    kind: ExprKind::Int(-i),
                    span,
                    ty: None,
                },
                ExprKind::Float(f) => Expr {
                    kind: ExprKind::Float(-f),
                    span,
                    ty: None,
                },
                _ => Expr {
                    kind: ExprKind::Neg(Box::new(inner)),
                    span,
                    ty: None,
                },
            });
        }
        self.power()
    }

    fn power(&mut self) -> Result<Expr, ParseError> {
        let base = self.primary()?;
        if self.eat("^") {
            self.operator()?;
            let exp = self.nested(Self::unary)?;
            return Ok(bin(BinOp::Pow, base, exp));
        }
        Ok(base)
    }

    fn args(&mut self, what: &str) -> Result<Vec<Expr>, ParseError> {
        self.expect("(", &format!("write `{what}(...)`"))?;
        let mut args = Vec::new();
        if !self.is(")") {
            loop {
                args.push(self.expr()?);
                if !self.eat(",") {
                    break;
                }
            }
        }
        self.expect(")", "close the argument list with `)`")?;
        Ok(args)
    }

    fn primary(&mut self) -> Result<Expr, ParseError> {
        let span = self.span();
        let e = |kind| Expr {
            kind,
            span,
            ty: None,
        };
        match self.peek().clone() {
            Tok::Int(i) => {
                self.bump();
                Ok(e(ExprKind::Int(i)))
            }
            Tok::UInt(i) => {
                // An unsigned constant: the integer converted to unsigned.
                self.bump();
                Ok(e(ExprKind::Builtin(
                    Builtin::Itou,
                    vec![e(ExprKind::Int(i))],
                )))
            }
            Tok::Float(f) => {
                self.bump();
                Ok(e(ExprKind::Float(f)))
            }
            Tok::Str(s) => {
                self.bump();
                Ok(e(ExprKind::Str(s)))
            }
            Tok::P("(") => {
                self.bump();
                let inner = self.expr()?;
                self.expect(")", "close the parenthesis")?;
                Ok(inner)
            }
            Tok::P("[") => err(
                span,
                "records (`[a, b]`) are not supported",
                "records are an unsupported Soufflé feature; use several attributes",
            ),
            Tok::P("@") => {
                self.bump();
                let (name, nspan) = self.ident("a functor name after `@`")?;
                let args = self.args(&format!("@{name}"))?;
                Ok(Expr {
                    kind: ExprKind::Ext(name, args),
                    span: Span {
                        len: nspan.len + 1,
                        ..span
                    },
                    ty: None,
                })
            }
            Tok::Ident(name) => {
                let span = Span {
                    len: name.chars().count() as u32,
                    ..span
                };
                let e = |kind| Expr {
                    kind,
                    span,
                    ty: None,
                };
                if name == "_" {
                    self.bump();
                    return Ok(e(ExprKind::Wild));
                }
                if name == "nil" {
                    return err(
                        span,
                        "`nil` (records) is not supported",
                        "records are an unsupported Soufflé feature",
                    );
                }
                if ["range", "as"].contains(&name.as_str())
                    && matches!(self.peek_at(1), Tok::P("("))
                {
                    return err(
                        span,
                        format!("the functor `{name}` is not supported"),
                        "see docs/RULES-LANGUAGE.md for the supported functors",
                    );
                }
                if let Some(op) = agg_op(&name) {
                    // `min(a, b)` is the functor; `min x : body` the aggregate.
                    let is_functor = matches!(self.peek_at(1), Tok::P("("))
                        && (op == AggOp::Min || op == AggOp::Max)
                        && {
                            let save = self.pos;
                            self.bump();
                            let parsed = self.args(&name);
                            let functor = parsed.is_ok() && !self.is(":");
                            self.pos = save;
                            functor
                        };
                    if !is_functor {
                        self.bump();
                        return self.aggregate(op, span);
                    }
                }
                self.bump();
                if self.is("(") {
                    if let Some(b) = Builtin::from_name(&name) {
                        let args = self.args(&name)?;
                        return Ok(e(ExprKind::Builtin(b, args)));
                    }
                    return err(
                        span,
                        format!("unknown functor `{name}`"),
                        format!(
                            "built-in functors: {}; Rust functors are written `@name(...)`",
                            Builtin::ALL.map(|b| b.name()).join(", ")
                        ),
                    );
                }
                Ok(e(ExprKind::Var(name)))
            }
            other => err(
                span,
                format!("expected an expression, found {}", Self::describe(&other)),
                "expressions are variables, constants, arithmetic, functor calls or aggregates",
            ),
        }
    }

    fn aggregate(&mut self, op: AggOp, span: Span) -> Result<Expr, ParseError> {
        let target = if op == AggOp::Count {
            None
        } else if self.is(":") {
            return err(
                self.span(),
                format!("`{}` needs an expression to aggregate", op.name()),
                format!("write `{} x : {{ rel(x) }}`", op.name()),
            );
        } else {
            Some(self.expr()?)
        };
        self.expect(
            ":",
            &format!("an aggregate looks like `{} : {{ body }}`", op.name()),
        )?;
        let body = if self.eat("{") {
            let d = self.disjunction()?;
            self.expect("}", "close the aggregate body with `}`")?;
            if d.len() != 1 {
                return err(
                    span,
                    "disjunction (`;`) inside an aggregate body is not supported",
                    "use a helper relation for the alternatives",
                );
            }
            d.into_iter().next().unwrap()
        } else {
            let t = self.term()?;
            t.into_iter().next().unwrap_or_default()
        };
        Ok(Expr {
            kind: ExprKind::Agg(Box::new(Aggregate {
                op,
                target,
                body,
                plan: Vec::new(),
                injected: Vec::new(),
            })),
            span: Span {
                len: op.name().len() as u32,
                ..span
            },
            ty: None,
        })
    }
}

pub(super) fn is_agg_name(n: &str) -> bool {
    agg_op(n).is_some()
}

fn agg_op(n: &str) -> Option<AggOp> {
    Some(match n {
        "count" => AggOp::Count,
        "sum" => AggOp::Sum,
        "min" => AggOp::Min,
        "max" => AggOp::Max,
        "mean" => AggOp::Mean,
        _ => return None,
    })
}

fn bin(op: BinOp, a: Expr, b: Expr) -> Expr {
    let span = a.span;
    Expr {
        kind: ExprKind::Bin(op, Box::new(a), Box::new(b)),
        span,
        ty: None,
    }
}
