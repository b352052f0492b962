//! Syntax tree of a rule program, shared by the parser, the checker, the
//! interpreter and the code generator in `build.rs` (std only: no crate deps).

use std::fmt;

/// A position in a source file: index into `Program::sources`, 1-based line
/// and column (in characters), and the length of the marked text.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash, Default)]
pub struct Span {
    pub file: u32,
    pub line: u32,
    pub col: u32,
    pub len: u32,
}

/// The primitive types every declared type resolves to.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum BaseTy {
    Number,
    Unsigned,
    Float,
    Symbol,
    Vec3,
    Iso,
    Box,
}

impl BaseTy {
    pub fn name(self) -> &'static str {
        match self {
            BaseTy::Number => "number",
            BaseTy::Unsigned => "unsigned",
            BaseTy::Float => "float",
            BaseTy::Symbol => "symbol",
            BaseTy::Vec3 => "vec3",
            BaseTy::Iso => "iso",
            BaseTy::Box => "box",
        }
    }
    pub fn from_name(name: &str) -> Option<BaseTy> {
        Some(match name {
            "number" => BaseTy::Number,
            "unsigned" => BaseTy::Unsigned,
            "float" => BaseTy::Float,
            "symbol" => BaseTy::Symbol,
            "vec3" => BaseTy::Vec3,
            "iso" => BaseTy::Iso,
            "box" => BaseTy::Box,
            _ => return None,
        })
    }
    pub fn is_numeric(self) -> bool {
        matches!(self, BaseTy::Number | BaseTy::Unsigned | BaseTy::Float)
    }
}

impl fmt::Display for BaseTy {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BinOp {
    Add,
    Sub,
    Mul,
    Div,
    Rem,
    Pow,
}

impl BinOp {
    pub fn symbol(self) -> &'static str {
        match self {
            BinOp::Add => "+",
            BinOp::Sub => "-",
            BinOp::Mul => "*",
            BinOp::Div => "/",
            BinOp::Rem => "%",
            BinOp::Pow => "^",
        }
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CmpOp {
    Eq,
    Ne,
    Lt,
    Le,
    Gt,
    Ge,
}

impl CmpOp {
    pub fn symbol(self) -> &'static str {
        match self {
            CmpOp::Eq => "=",
            CmpOp::Ne => "!=",
            CmpOp::Lt => "<",
            CmpOp::Le => "<=",
            CmpOp::Gt => ">",
            CmpOp::Ge => ">=",
        }
    }
    /// The operator that holds exactly when this one does not.
    pub fn negate(self) -> CmpOp {
        match self {
            CmpOp::Eq => CmpOp::Ne,
            CmpOp::Ne => CmpOp::Eq,
            CmpOp::Lt => CmpOp::Ge,
            CmpOp::Le => CmpOp::Gt,
            CmpOp::Gt => CmpOp::Le,
            CmpOp::Ge => CmpOp::Lt,
        }
    }
}

/// Soufflé's built-in functors (intrinsics), written without `@`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Builtin {
    Min,
    Max,
    Cat,
    Strlen,
    Substr,
    Ord,
    ToNumber,
    ToString,
    ToFloat,
    ToUnsigned,
    Itof,
    Itou,
    Utoi,
    Utof,
    Ftoi,
    Ftou,
    /// `autoinc()`: the next number of the run's counter (from 0).
    Autoinc,
}

impl Builtin {
    pub const ALL: [Builtin; 17] = [
        Builtin::Min,
        Builtin::Max,
        Builtin::Cat,
        Builtin::Strlen,
        Builtin::Substr,
        Builtin::Ord,
        Builtin::ToNumber,
        Builtin::ToString,
        Builtin::ToFloat,
        Builtin::ToUnsigned,
        Builtin::Itof,
        Builtin::Itou,
        Builtin::Utoi,
        Builtin::Utof,
        Builtin::Ftoi,
        Builtin::Ftou,
        Builtin::Autoinc,
    ];
    pub fn name(self) -> &'static str {
        match self {
            Builtin::Min => "min",
            Builtin::Max => "max",
            Builtin::Cat => "cat",
            Builtin::Strlen => "strlen",
            Builtin::Substr => "substr",
            Builtin::Ord => "ord",
            Builtin::ToNumber => "to_number",
            Builtin::ToString => "to_string",
            Builtin::ToFloat => "to_float",
            Builtin::ToUnsigned => "to_unsigned",
            Builtin::Itof => "itof",
            Builtin::Itou => "itou",
            Builtin::Utoi => "utoi",
            Builtin::Utof => "utof",
            Builtin::Ftoi => "ftoi",
            Builtin::Ftou => "ftou",
            Builtin::Autoinc => "autoinc",
        }
    }
    pub fn from_name(name: &str) -> Option<Builtin> {
        Builtin::ALL.iter().copied().find(|b| b.name() == name)
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum AggOp {
    Count,
    Sum,
    Min,
    Max,
    Mean,
}

impl AggOp {
    pub fn name(self) -> &'static str {
        match self {
            AggOp::Count => "count",
            AggOp::Sum => "sum",
            AggOp::Min => "min",
            AggOp::Max => "max",
            AggOp::Mean => "mean",
        }
    }
}

#[derive(Clone, Debug, PartialEq)]
pub struct Expr {
    pub kind: ExprKind,
    pub span: Span,
    /// Filled in by the checker.
    pub ty: Option<BaseTy>,
}

#[derive(Clone, Debug, PartialEq)]
pub enum ExprKind {
    Var(String),
    Wild,
    /// An integer literal; its type (number, unsigned, float) follows the context.
    Int(i128),
    Float(f64),
    Str(String),
    Neg(Box<Expr>),
    Bin(BinOp, Box<Expr>, Box<Expr>),
    Builtin(Builtin, Vec<Expr>),
    /// `@name(args)`: a functor from the Rust registry.
    Ext(String, Vec<Expr>),
    Agg(Box<Aggregate>),
}

#[derive(Clone, Debug, PartialEq)]
pub struct Aggregate {
    pub op: AggOp,
    /// The aggregated expression (absent for `count`).
    pub target: Option<Expr>,
    pub body: Vec<Literal>,
    /// Filled in by the checker: the evaluation order of `body`.
    pub plan: Vec<Step>,
    /// Filled in by the checker: variables of the body that are bound outside it.
    pub injected: Vec<String>,
}

#[derive(Clone, Debug, PartialEq)]
pub struct Atom {
    pub rel: String,
    pub args: Vec<Expr>,
    pub span: Span,
}

#[derive(Clone, Debug, PartialEq)]
pub enum Literal {
    Pos(Atom),
    Neg(Atom),
    Cmp(CmpOp, Expr, Expr, Span),
    /// `contains(needle, haystack)`, `match(regex, text)`; `negated` for `!contains(..)`.
    StrTest {
        is_match: bool,
        negated: bool,
        args: Box<[Expr; 2]>,
        span: Span,
    },
}

impl Literal {
    pub fn span(&self) -> Span {
        match self {
            Literal::Pos(a) | Literal::Neg(a) => a.span,
            Literal::Cmp(_, _, _, s) => *s,
            Literal::StrTest { span, .. } => *span,
        }
    }
}

/// One step of a rule's evaluation order, computed by the checker so that
/// every variable is bound before it is read. Indices point into `body`.
#[derive(Clone, Debug, PartialEq)]
pub enum Step {
    /// Scan a positive atom; variables first seen here get bound.
    Scan(usize),
    /// Negated atom; all its variables are bound.
    Negate(usize),
    /// Comparison or string test with all variables bound.
    Filter(usize),
    /// `var = expr` (or `expr = var`) where `var` is not yet bound.
    Assign {
        lit: usize,
        var: String,
        var_on_left: bool,
    },
}

#[derive(Clone, Debug, PartialEq)]
pub struct Rule {
    pub head: Atom,
    pub body: Vec<Literal>,
    pub plan: Vec<Step>,
    pub label: Option<String>,
    pub span: Span,
}

#[derive(Clone, Debug, PartialEq)]
pub struct Attr {
    pub name: String,
    /// The declared type name (may be a user `.type`).
    pub ty_name: String,
    pub ty: BaseTy,
}

#[derive(Clone, Debug, PartialEq)]
pub struct IoSpec {
    /// `filename=` if given, else the default `<rel>.facts` / `<rel>.csv`.
    pub filename: Option<String>,
    pub delimiter: String,
    /// true for `IO=stdout` on an output.
    pub stdout: bool,
    pub span: Span,
}

#[derive(Clone, Debug, PartialEq)]
pub struct RelDecl {
    pub name: String,
    pub attrs: Vec<Attr>,
    pub input: Option<IoSpec>,
    pub output: Option<IoSpec>,
    pub span: Span,
}

impl RelDecl {
    pub fn arity(&self) -> usize {
        self.attrs.len()
    }
}

/// A user type: `.type T <: base` (subtype), `.type T = other` (alias) or
/// `.type T = A | B | ...` (union: every member is a subtype of `T`).
#[derive(Clone, Debug, PartialEq)]
pub struct TypeDecl {
    pub name: String,
    /// The parent type; for a union, its first member.
    pub parent: String,
    pub is_subtype: bool,
    /// The members of a union type (empty otherwise).
    pub members: Vec<String>,
    pub span: Span,
}

impl fmt::Display for Expr {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match &self.kind {
            ExprKind::Var(v) => f.write_str(v),
            ExprKind::Wild => f.write_str("_"),
            ExprKind::Int(i) => write!(f, "{i}"),
            ExprKind::Float(x) => write!(f, "{x:?}"),
            ExprKind::Str(s) => write!(f, "{s:?}"),
            ExprKind::Neg(e) => write!(f, "-{e}"),
            ExprKind::Bin(op, a, b) => write!(f, "({a} {} {b})", op.symbol()),
            ExprKind::Builtin(b, args) => {
                write!(f, "{}(", b.name())?;
                write_list(f, args)?;
                f.write_str(")")
            }
            ExprKind::Ext(n, args) => {
                write!(f, "@{n}(")?;
                write_list(f, args)?;
                f.write_str(")")
            }
            ExprKind::Agg(a) => {
                write!(f, "{}", a.op.name())?;
                if let Some(t) = &a.target {
                    write!(f, " {t}")?;
                }
                f.write_str(" : { ")?;
                for (i, l) in a.body.iter().enumerate() {
                    if i > 0 {
                        f.write_str(", ")?;
                    }
                    write!(f, "{l}")?;
                }
                f.write_str(" }")
            }
        }
    }
}

fn write_list(f: &mut fmt::Formatter<'_>, args: &[Expr]) -> fmt::Result {
    for (i, a) in args.iter().enumerate() {
        if i > 0 {
            f.write_str(", ")?;
        }
        write!(f, "{a}")?;
    }
    Ok(())
}

impl fmt::Display for Atom {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}(", self.rel)?;
        write_list(f, &self.args)?;
        f.write_str(")")
    }
}

impl fmt::Display for Literal {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Literal::Pos(a) => write!(f, "{a}"),
            Literal::Neg(a) => write!(f, "!{a}"),
            Literal::Cmp(op, a, b, _) => write!(f, "{a} {} {b}", op.symbol()),
            Literal::StrTest {
                is_match,
                negated,
                args,
                ..
            } => write!(
                f,
                "{}{}({}, {})",
                if *negated { "!" } else { "" },
                if *is_match { "match" } else { "contains" },
                args[0],
                args[1]
            ),
        }
    }
}

impl fmt::Display for Rule {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}", self.head)?;
        if !self.body.is_empty() {
            f.write_str(" :- ")?;
            for (i, l) in self.body.iter().enumerate() {
                if i > 0 {
                    f.write_str(", ")?;
                }
                write!(f, "{l}")?;
            }
        }
        f.write_str(".")
    }
}
