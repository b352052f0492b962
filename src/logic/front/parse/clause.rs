//! Clauses: head atoms, bodies in disjunctive normal form (disjunctions and
//! negated compound conditions expanded), and body literals.

use super::super::ast::*;
use super::super::lex::Tok;
use super::expr::is_agg_name;
use super::{Group, Item, ParseError, Parser, err};

/// Clauses a negated compound condition may expand into (De Morgan's laws).
const MAX_NEGATED_CLAUSES: usize = 64;

impl<'a> Parser<'a> {
    fn label_for(&self, line: u32) -> Option<String> {
        self.labels
            .iter()
            .rfind(|l| l.span.line > self.prev_end_line && l.span.line < line)
            .map(|l| l.name.clone())
    }

    pub(super) fn clause(&mut self, items: &mut Vec<Item>) -> Result<(), ParseError> {
        let start = self.span();
        let label = self.label_for(start.line);
        let mut heads = vec![self.atom()?];
        while self.eat(",") {
            heads.push(self.atom()?);
        }
        if self.is("<=") {
            return err(
                self.span(),
                "subsumption (`<=` between heads) is not supported",
                "subsumption is an unsupported Soufflé feature; use negation to keep the preferred tuples",
            );
        }
        let bodies = if self.eat(":-") {
            self.disjunction()?
        } else {
            vec![Vec::new()]
        };
        if !self.is(".") {
            if let Tok::Directive(d) = self.peek() {
                if d == "plan" {
                    return err(
                        self.span(),
                        "query plans (`.plan`) are not supported",
                        "remove the `.plan` annotation; the engine chooses the join order",
                    );
                }
            }
            return err(
                self.span(),
                format!(
                    "expected `.` at the end of the clause, found {}",
                    Self::describe(self.peek())
                ),
                "end every fact and rule with `.`; separate body literals with `,` (and) or `;` (or)",
            );
        }
        self.bump();
        for head in heads {
            for body in &bodies {
                items.push(Item::Clause(Rule {
                    head: head.clone(),
                    body: body.clone(),
                    plan: Vec::new(),
                    label: label.clone(),
                    span: Span {
                        len: 1,
                        ..head.span
                    },
                }));
            }
        }
        Ok(())
    }

    fn atom(&mut self) -> Result<Atom, ParseError> {
        let (rel, span) = self.ident("a relation name")?;
        if self.is(".") && matches!(self.peek_at(1), Tok::Ident(_)) {
            return err(
                self.span(),
                "qualified relation names (components) are not supported",
                "components are an unsupported Soufflé feature",
            );
        }
        self.expect(
            "(",
            &format!("write the relation's arguments: `{rel}(x, y)`"),
        )?;
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
        Ok(Atom { rel, args, span })
    }

    /// Disjunctive normal form: a list of conjunctions.
    pub(super) fn disjunction(&mut self) -> Result<Vec<Vec<Literal>>, ParseError> {
        let mut out = self.conjunction()?;
        while self.eat(";") {
            out.extend(self.conjunction()?);
        }
        Ok(out)
    }

    fn conjunction(&mut self) -> Result<Vec<Vec<Literal>>, ParseError> {
        let mut acc: Vec<Vec<Literal>> = vec![Vec::new()];
        loop {
            let term = self.term()?;
            let mut next = Vec::with_capacity(acc.len() * term.len());
            for a in &acc {
                for t in &term {
                    let mut c = a.clone();
                    c.extend(t.iter().cloned());
                    next.push(c);
                }
            }
            if next.len() > 4096 {
                return err(
                    self.span(),
                    "this rule body expands into more than 4096 alternatives",
                    "split the rule: each `;` doubles the number of rules",
                );
            }
            acc = next;
            if !self.eat(",") {
                break;
            }
        }
        Ok(acc)
    }

    /// The disjunction inside the `(` at token `at`: (the position after it, its literals),
    /// or None when none reads there. Remembered (see `groups`): the outcome depends only on
    /// the position and the depth (the nesting bound), and on the operator count, which only
    /// grows, so a failure for too many operators would fail again.
    fn group(&mut self, at: usize) -> Option<Group> {
        let key = (at, self.depth);
        if let Some(known) = self.groups.get(&key) {
            return known.clone();
        }
        self.pos = at + 1;
        let outcome = self.disjunction().ok().map(|d| (self.pos, d));
        self.groups.insert(key, outcome.clone());
        outcome
    }

    pub(super) fn term(&mut self) -> Result<Vec<Vec<Literal>>, ParseError> {
        self.nested(Self::term_inner)
    }

    fn term_inner(&mut self) -> Result<Vec<Vec<Literal>>, ParseError> {
        if self.is("!") {
            let bang = self.bump().span;
            let inner = self.term()?;
            // De Morgan: not (C1 ; C2 ; …) is (not C1) and (not C2) …, and not (l1, l2, …) is
            // (not l1) ; (not l2) ; …: one clause per choice of a literal from each Ci.
            let mut clauses: Vec<Vec<Literal>> = vec![Vec::new()];
            for conjunction in inner {
                let mut next = Vec::new();
                for clause in &clauses {
                    for lit in &conjunction {
                        let mut c = clause.clone();
                        c.push(Self::negated(bang, lit.clone())?);
                        next.push(c);
                    }
                }
                clauses = next;
                if clauses.len() > MAX_NEGATED_CLAUSES {
                    return err(
                        bang,
                        "this negation expands into too many clauses",
                        "introduce a helper relation for the compound condition and negate it",
                    );
                }
            }
            return Ok(clauses);
        }
        self.positive_term()
    }

    /// The negation of one literal.
    fn negated(bang: Span, lit: Literal) -> Result<Literal, ParseError> {
        Ok(match lit {
            Literal::Pos(a) => Literal::Neg(a),
            Literal::Cmp(op, a, b, s) => Literal::Cmp(op.negate(), a, b, s),
            Literal::StrTest {
                is_match,
                negated,
                args,
                span,
            } => Literal::StrTest {
                is_match,
                negated: !negated,
                args,
                span,
            },
            Literal::Neg(_) => {
                return err(bang, "double negation is not supported", "remove both `!`");
            }
        })
    }

    fn positive_term(&mut self) -> Result<Vec<Vec<Literal>>, ParseError> {
        if self.is("(") {
            // A parenthesised disjunction, unless it is the start of an expression
            // in a comparison such as `(x + 1) < y`.
            let save = self.pos;
            if let Some((end, d)) = self.group(save) {
                self.pos = end;
                if self.eat(")") && !self.is_cmp_op() && !self.is_arith_op() {
                    return Ok(d);
                }
            }
            self.pos = save;
        }
        if let Tok::Ident(name) = self.peek().clone() {
            if matches!(self.peek_at(1), Tok::P("(")) {
                if name == "contains" || name == "match" {
                    let span = self.bump().span;
                    self.bump();
                    let a = self.expr()?;
                    self.expect(",", &format!("`{name}` takes two arguments"))?;
                    let b = self.expr()?;
                    self.expect(")", &format!("`{name}` takes two arguments"))?;
                    return Ok(vec![vec![Literal::StrTest {
                        is_match: name == "match",
                        negated: false,
                        args: Box::new([a, b]),
                        span,
                    }]]);
                }
                if Builtin::from_name(&name).is_none()
                    && !["range", "as"].contains(&name.as_str())
                    && !is_agg_name(&name)
                {
                    return Ok(vec![vec![Literal::Pos(self.atom()?)]]);
                }
            }
            if (name == "true" || name == "false") && !matches!(self.peek_at(1), Tok::P("(")) {
                let span = self.bump().span;
                let one = Expr {
                    kind: ExprKind::Int(1),
                    span,
                    ty: None,
                };
                let op = if name == "true" { CmpOp::Eq } else { CmpOp::Ne };
                return Ok(vec![vec![Literal::Cmp(op, one.clone(), one, span)]]);
            }
        }
        let lhs = self.expr()?;
        let op_span = self.span();
        let op = match self.peek() {
            Tok::P("=") => CmpOp::Eq,
            Tok::P("!=") => CmpOp::Ne,
            Tok::P("<") => CmpOp::Lt,
            Tok::P("<=") => CmpOp::Le,
            Tok::P(">") => CmpOp::Gt,
            Tok::P(">=") => CmpOp::Ge,
            other => {
                return err(
                    op_span,
                    format!(
                        "expected an atom or a comparison, found {}",
                        Self::describe(other)
                    ),
                    "body literals are atoms `rel(x)`, negations `!rel(x)` or comparisons `x < y`",
                );
            }
        };
        self.bump();
        let rhs = self.expr()?;
        Ok(vec![vec![Literal::Cmp(
            op,
            lhs,
            rhs,
            Span {
                len: op.symbol().len() as u32,
                ..op_span
            },
        )]])
    }

    fn is_cmp_op(&self) -> bool {
        matches!(self.peek(), Tok::P("=" | "!=" | "<" | "<=" | ">" | ">="))
    }
    fn is_arith_op(&self) -> bool {
        matches!(self.peek(), Tok::P("+" | "-" | "*" | "/" | "%" | "^"))
    }
}
