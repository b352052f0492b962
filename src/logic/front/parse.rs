//! Recursive-descent parser: tokens → items (declarations, directives,
//! clauses). Disjunctions are expanded into one clause per branch, as Soufflé
//! does; unsupported Soufflé features are rejected by name.

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

const BITWISE: [&str; 11] = [
    "band", "bor", "bxor", "bshl", "bshr", "bshru", "bnot", "land", "lor", "lxor", "lnot",
];

/// Bounds on one item's expression tree: the parser, the checker, the engines and dropping the
/// tree all recurse over it, so a hostile file (`((((…`, `----…`, `1+1+…+1`) must not be able
/// to make it deep enough to overflow a thread's stack.
const MAX_NESTING: usize = 100;
const MAX_OPERATORS: usize = 1000;

/// Clauses a negated compound condition may expand into (De Morgan's laws).
const MAX_NEGATED_CLAUSES: usize = 64;

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

    fn directive(&mut self, d: &str, items: &mut Vec<Item>) -> Result<(), ParseError> {
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
                loop {
                    match self.peek().clone() {
                        Tok::Ident(q)
                            if [
                                "btree",
                                "brie",
                                "inline",
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

    fn label_for(&self, line: u32) -> Option<String> {
        self.labels
            .iter()
            .rfind(|l| l.span.line > self.prev_end_line && l.span.line < line)
            .map(|l| l.name.clone())
    }

    fn clause(&mut self, items: &mut Vec<Item>) -> Result<(), ParseError> {
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
    fn disjunction(&mut self) -> Result<Vec<Vec<Literal>>, ParseError> {
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

    fn term(&mut self) -> Result<Vec<Vec<Literal>>, ParseError> {
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
                    && !["autoinc", "range", "as"].contains(&name.as_str())
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
                if ["autoinc", "range", "as"].contains(&name.as_str())
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

fn is_agg_name(n: &str) -> bool {
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
