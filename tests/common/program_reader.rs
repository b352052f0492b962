//! An independent, strict reader for the robot programs framewright writes: a small subset of
//! ABB RAPID and KUKA KRL. Anything outside the subset is an Err naming the line and its text,
//! so a test can never pass because something was silently skipped.
#![allow(dead_code)]

/// `line N: why: "text"`, so every error says where it happened.
fn err(line: usize, why: &str, text: &str) -> String {
    match text.trim() {
        "" => format!("line {line}: {why}"),
        text => format!("line {line}: {why}: {text:?}"),
    }
}

/// The identifier at the start of `s` and what follows it; over-long names are errors.
/// RAPID: a letter, then letters, digits, `_`. KRL also allows `_` or `$` first, `$` later.
fn take_ident(s: &str, krl: bool, max: usize) -> Result<(&str, &str), String> {
    let b = s.as_bytes();
    let first = |c: u8| c.is_ascii_alphabetic() || (krl && (c == b'_' || c == b'$'));
    let rest = |c: u8| c.is_ascii_alphanumeric() || c == b'_' || (krl && c == b'$');
    let len = match b.first() {
        Some(&c) if first(c) => 1 + b[1..].iter().take_while(|&&c| rest(c)).count(),
        _ => return Err(format!("expected a name at {s:?}")),
    };
    match len > max {
        true => Err(format!(
            "identifier {:?} is longer than {max} characters",
            &s[..len]
        )),
        false => Ok(s.split_at(len)),
    }
}

/// The number at the start of `s` (sign, digits, decimals, exponent) and its length. A number
/// run straight into a letter or `_` is not a number.
fn lex_number(s: &str) -> Option<(f64, usize)> {
    let b = s.as_bytes();
    let sign_ok = |i: usize| i == 0 || matches!(b[i - 1], b'e' | b'E');
    let len = (0..b.len())
        .take_while(|&i| match b[i] {
            b'0'..=b'9' | b'.' | b'e' | b'E' => true,
            b'+' | b'-' => sign_ok(i),
            _ => false,
        })
        .count();
    let glued = b
        .get(len)
        .is_some_and(|c| c.is_ascii_alphanumeric() || *c == b'_');
    let x: f64 = s[..len].parse().ok().filter(|_| !glued)?;
    Some((x, len))
}

pub mod rapid {
    use super::{err, lex_number, take_ident};

    /// RAPID's identifier limit.
    const MAX_IDENT: usize = 32;

    /// Instructions understood besides calls to the module's own procedures.
    pub const INSTRUCTIONS: &[&str] = &[
        "MoveAbsJ", "MoveJ", "MoveL", "MoveC", "VelSet", "AccSet", "WaitDI", "WaitTime", "SetDO",
        "PulseDO", "Set", "Reset", "ConfL", "ConfJ", "SingArea", "GripLoad", "TPWrite", "Stop",
    ];

    /// One module: declarations and procedures in file order, and every comment's text (after
    /// the `!`, trimmed).
    #[derive(Debug, Clone, PartialEq)]
    pub struct Module {
        pub name: String,
        pub decls: Vec<Decl>,
        pub procs: Vec<Proc>,
        pub comments: Vec<String>,
    }

    /// `CONST|PERS|VAR type name := value;` (storage upper-cased); `line` is where it starts.
    #[derive(Debug, Clone, PartialEq)]
    pub struct Decl {
        pub storage: String,
        pub ty: String,
        pub name: String,
        pub value: Value,
        pub line: usize,
    }

    /// `PROC name() ... ENDPROC`.
    #[derive(Debug, Clone, PartialEq)]
    pub struct Proc {
        pub name: String,
        pub body: Vec<Instr>,
    }

    /// One instruction, e.g. `MoveL p1, v100, fine, tGrip\WObj:=wWall;`.
    #[derive(Debug, Clone, PartialEq)]
    pub struct Instr {
        pub name: String,
        pub args: Vec<Arg>,
        pub line: usize,
    }

    /// A required argument (`switch` None) or an optional one: `\WObj:=wWall` is Some("WObj")
    /// with "wWall", a bare `\On` is Some("On") with "". `value` is the raw text, trimmed.
    #[derive(Debug, Clone, PartialEq)]
    pub struct Arg {
        pub switch: Option<String>,
        pub value: String,
    }

    /// A data value: number, TRUE/FALSE, string (unescaped), `[...]` aggregate, or a name.
    #[derive(Debug, Clone, PartialEq)]
    pub enum Value {
        Num(f64),
        Bool(bool),
        Str(String),
        Agg(Vec<Value>),
        Name(String),
    }

    impl Value {
        /// Every number in the value, depth-first, flattened (booleans and strings skipped).
        pub fn nums(&self) -> Vec<f64> {
            match self {
                Value::Num(x) => vec![*x],
                Value::Agg(items) => items.iter().flat_map(Value::nums).collect(),
                _ => Vec::new(),
            }
        }
    }

    impl Module {
        /// The declaration named `name` (RAPID names are case-insensitive).
        pub fn decl(&self, name: &str) -> Option<&Decl> {
            self.decls
                .iter()
                .find(|d| d.name.eq_ignore_ascii_case(name))
        }
    }

    /// Reads a file holding exactly one module; only blank lines may precede or follow it.
    pub fn read(text: &str) -> Result<Module, String> {
        let (stmts, comments, last) = statements(text)?;
        let mut it = stmts.iter().map(|(n, s)| (*n, s.as_str()));
        let eof = |what: &str| err(last, &format!("missing {what}"), "");
        let (first, s) = it.next().ok_or_else(|| eof("MODULE"))?;
        let name = header(first, s, "MODULE", "")?;
        let mut m = Module {
            name,
            decls: vec![],
            procs: vec![],
            comments: vec![],
        };
        let end = loop {
            let (n, s) = it.next().ok_or_else(|| eof("ENDMODULE"))?;
            match word(s).as_str() {
                "ENDMODULE" if s.len() == 9 => break n,
                "CONST" | "PERS" | "VAR" | "LOCAL" => {
                    // `LOCAL` keeps a module's data out of the task's other modules.
                    let s = match word(s).as_str() {
                        "LOCAL" => s[5..].trim_start(),
                        _ => s,
                    };
                    let d = parse_decl(n, s)?;
                    if m.decl(&d.name).is_some() {
                        return Err(err(n, "duplicate declaration", s));
                    }
                    m.decls.push(d);
                }
                "PROC" => {
                    let mut p = Proc {
                        name: header(n, s, "PROC", "()")?,
                        body: vec![],
                    };
                    if m.procs.iter().any(|q| q.name.eq_ignore_ascii_case(&p.name)) {
                        return Err(err(n, "duplicate PROC", s));
                    }
                    loop {
                        let (n, s) = it.next().ok_or_else(|| eof("ENDPROC"))?;
                        match word(s).as_str() {
                            "ENDPROC" if s.len() == 7 => break,
                            w if KEYWORDS.contains(&w) => {
                                let why = format!("{w} inside PROC {} (missing ENDPROC?)", p.name);
                                return Err(err(n, &why, s));
                            }
                            _ => p.body.push(parse_instr(n, s)?),
                        }
                    }
                    m.procs.push(p);
                }
                _ => return Err(err(n, "expected a declaration, PROC or ENDMODULE", s)),
            }
        };
        if let Some((n, s)) = it.next() {
            return Err(err(n, "text after ENDMODULE", s));
        }
        if let Some((n, c)) = comments.iter().find(|(n, _)| *n < first || *n > end) {
            return Err(err(*n, "comment outside the module", c));
        }
        // Checked last, since a procedure may be called before it is defined.
        for i in m.procs.iter().flat_map(|p| &p.body) {
            let known = |name: &str| name.eq_ignore_ascii_case(&i.name);
            if !INSTRUCTIONS.iter().any(|x| known(x)) && !m.procs.iter().any(|p| known(&p.name)) {
                return Err(err(i.line, "unknown instruction", &i.name));
            }
        }
        m.comments = comments.into_iter().map(|(_, c)| c).collect();
        Ok(m)
    }

    /// Words that open or close a block or a declaration.
    const KEYWORDS: [&str; 7] = [
        "MODULE",
        "ENDMODULE",
        "PROC",
        "ENDPROC",
        "CONST",
        "PERS",
        "VAR",
    ];

    /// The leading identifier, upper-cased ("" if none).
    fn word(s: &str) -> String {
        take_ident(s, false, usize::MAX).map_or(String::new(), |(w, _)| w.to_ascii_uppercase())
    }

    /// Numbered texts.
    type Lines = Vec<(usize, String)>;

    /// Every statement as (first line, text without its `;`), every comment as (line, text),
    /// and the last line number. Only a declaration may span lines.
    fn statements(text: &str) -> Result<(Lines, Lines, usize), String> {
        const OPEN: &str = "declaration not terminated by ';' (or '[' not closed)";
        let (mut out, mut comments, mut last) = (vec![], vec![], 1);
        let mut pending: Option<(usize, String)> = None;
        for (i, raw) in text.lines().enumerate() {
            let n = i + 1;
            last = n;
            let (code, comment) = split_line(n, raw)?;
            comments.extend(comment.map(|c| (n, c.trim().to_string())));
            let code = code.trim();
            if code.is_empty() {
                continue;
            }
            let (start, stmt) = match pending.take() {
                Some((start, acc)) if KEYWORDS.contains(&word(code).as_str()) => {
                    return Err(err(start, OPEN, &acc));
                }
                Some((start, acc)) => (start, format!("{acc} {code}")),
                None => (n, code.to_string()),
            };
            let w = word(&stmt);
            let is_decl = matches!(w.as_str(), "CONST" | "PERS" | "VAR");
            match top_level(&stmt, &[';']).first() {
                _ if KEYWORDS.contains(&w.as_str()) && !is_decl => out.push((n, stmt)), // no ';'
                None if is_decl => pending = Some((start, stmt)),
                None => return Err(err(n, "missing ';'", raw)),
                Some(&k) if stmt[k + 1..].trim().is_empty() => out.push((start, stmt[..k].into())),
                Some(_) => return Err(err(n, "text after ';' (one statement per line)", raw)),
            }
        }
        match pending {
            Some((start, acc)) => Err(err(start, OPEN, &acc)),
            None => Ok((out, comments, last)),
        }
    }

    /// Splits a line into code (strings left in) and comment. Strings must close on their line;
    /// code outside strings must be ASCII.
    fn split_line(n: usize, line: &str) -> Result<(&str, Option<&str>), String> {
        let mut in_str = false;
        for (i, c) in line.char_indices() {
            match c {
                _ if in_str => in_str = c != '"', // `""` leaves and re-enters: harmless here
                '"' => in_str = true,
                '!' => return Ok((&line[..i], Some(&line[i + 1..]))),
                _ if !c.is_ascii() => return Err(err(n, "non-ASCII outside a string", line)),
                _ => {}
            }
        }
        match in_str {
            true => Err(err(n, "string not closed on its line", line)),
            false => Ok((line, None)),
        }
    }

    /// Byte positions of `targets` outside strings and brackets.
    fn top_level(code: &str, targets: &[char]) -> Vec<usize> {
        let (mut in_str, mut depth, mut hits) = (false, 0, vec![]);
        for (i, c) in code.char_indices() {
            match c {
                _ if in_str => in_str = c != '"',
                '"' => in_str = true,
                '[' | '(' => depth += 1,
                ']' | ')' => depth -= 1,
                _ if depth == 0 && targets.contains(&c) => hits.push(i),
                _ => {}
            }
        }
        hits
    }

    /// `MODULE name` or `PROC name()`: the name.
    fn header(n: usize, s: &str, kw: &str, tail: &str) -> Result<String, String> {
        let bad = || err(n, &format!("expected `{kw} name{tail}`"), s);
        let rest = s[kw.len()..].strip_prefix([' ', '\t']).ok_or_else(bad)?;
        let (name, r) =
            take_ident(rest.trim_start(), false, MAX_IDENT).map_err(|w| err(n, &w, s))?;
        (r.replace([' ', '\t'], "") == tail)
            .then(|| name.to_string())
            .ok_or_else(bad)
    }

    /// `STORAGE type name := value`.
    fn parse_decl(n: usize, s: &str) -> Result<Decl, String> {
        let bad = |why: String| err(n, &why, s);
        let (mut words, mut rest) = ([""; 3], s);
        for w in &mut words {
            (*w, rest) = take_ident(rest.trim_start(), false, MAX_IDENT).map_err(bad)?;
        }
        let value = rest
            .trim_start()
            .strip_prefix(":=")
            .ok_or_else(|| bad("expected ':='".into()));
        let value = whole_value(value?).map_err(bad)?;
        let [storage, ty, name] = words.map(String::from);
        Ok(Decl {
            storage: storage.to_ascii_uppercase(),
            ty,
            name,
            value,
            line: n,
        })
    }

    /// `Name arg, arg\Switch:=value, \Switch`: required arguments follow the name or ',',
    /// optional ones follow '\'. Argument values must be plain values, not expressions.
    fn parse_instr(n: usize, s: &str) -> Result<Instr, String> {
        let bad = |why: String| err(n, &why, s);
        let (name, rest) = take_ident(s, false, MAX_IDENT).map_err(bad)?;
        let mut args = Vec::new();
        if !rest.trim().is_empty() && !rest.starts_with([' ', '\t', '\\']) {
            return Err(bad("expected arguments after the instruction name".into()));
        }
        let ends = top_level(rest, &[',', '\\'])
            .into_iter()
            .chain([rest.len()]);
        let (mut from, mut optional) = (0, false);
        for end in ends.filter(|_| !rest.trim().is_empty()) {
            let piece = rest[from..end].trim();
            let before_switch = rest[end..].starts_with('\\');
            // Nothing before the first '\' (as in `ConfL\On`) is not a missing argument.
            if !(from == 0 && piece.is_empty() && before_switch) {
                args.push(parse_arg(optional, piece).map_err(bad)?);
            }
            (from, optional) = (end + 1, before_switch);
        }
        Ok(Instr {
            name: name.into(),
            args,
            line: n,
        })
    }

    /// One argument's text, after its ',' or '\'.
    fn parse_arg(optional: bool, piece: &str) -> Result<Arg, String> {
        let (switch, value) = match optional {
            false => (None, Some(piece)),
            true => match take_ident(piece, false, MAX_IDENT)? {
                (sw, "") => (Some(sw.to_string()), None), // a bare switch such as `\On`
                (sw, r) => {
                    let v = r
                        .trim_start()
                        .strip_prefix(":=")
                        .ok_or("expected ':=' after a switch")?;
                    (Some(sw.to_string()), Some(v.trim()))
                }
            },
        };
        let value = value.map_or(Ok(String::new()), |v| whole_value(v).map(|_| v.to_string()))?;
        Ok(Arg { switch, value })
    }

    /// All of `s` as one value.
    fn whole_value(s: &str) -> Result<Value, String> {
        match parse_value(s)? {
            (value, tail) if tail.trim().is_empty() => Ok(value),
            (_, tail) => Err(format!("unexpected {:?} after a value", tail.trim())),
        }
    }

    /// One value at the start of `s` and what follows it.
    fn parse_value(s: &str) -> Result<(Value, &str), String> {
        let s = s.trim_start();
        if let Some(mut rest) = s.strip_prefix('[') {
            let mut items = Vec::new();
            loop {
                let (item, r) = parse_value(rest)?;
                items.push(item);
                let r = r.trim_start();
                match r.as_bytes().first() {
                    Some(b',') => rest = &r[1..],
                    Some(b']') => return Ok((Value::Agg(items), &r[1..])),
                    _ => return Err(format!("expected ',' or ']' in an aggregate at {r:?}")),
                }
            }
        }
        if let Some(rest) = s.strip_prefix('"') {
            return parse_string(rest);
        }
        if let Some((x, len)) = lex_number(s) {
            return Ok((Value::Num(x), &s[len..]));
        }
        let (name, rest) = take_ident(s, false, MAX_IDENT)?;
        let value = match name.to_ascii_uppercase().as_str() {
            "TRUE" => Value::Bool(true),
            "FALSE" => Value::Bool(false),
            _ => Value::Name(name.into()),
        };
        Ok((value, rest))
    }

    /// The rest of a string after its opening quote: `""` is a quote, `\\` a backslash.
    fn parse_string(s: &str) -> Result<(Value, &str), String> {
        let mut out = String::new();
        let mut chars = s.char_indices().peekable();
        while let Some((i, c)) = chars.next() {
            match (c, chars.peek().map(|&(_, c)| c)) {
                ('"', Some('"')) | ('\\', Some('\\')) => {
                    out.push(c);
                    chars.next();
                }
                ('"', _) => return Ok((Value::Str(out), &s[i + 1..])),
                ('\\', _) => return Err("a backslash in a string must be doubled".into()),
                _ => out.push(c),
            }
        }
        Err("string not closed".into())
    }
}

pub mod krl {
    use super::{err, lex_number, take_ident};

    /// KRL's identifier limit.
    const MAX_IDENT: usize = 24;

    /// A `.src` file: `DEF name(params) ... END`, and every comment's text (after `;`, trimmed).
    #[derive(Debug, Clone, PartialEq)]
    pub struct Src {
        pub name: String,
        pub params: String,
        pub body: Vec<Stmt>,
        pub comments: Vec<String>,
    }

    /// One statement of a `.src` body; texts are as written, trimmed.
    #[derive(Debug, Clone, PartialEq)]
    pub enum Stmt {
        Ptp {
            target: String,
            approx: Option<String>,
            line: usize,
        },
        Lin {
            target: String,
            approx: Option<String>,
            line: usize,
        },
        Assign {
            lhs: String,
            rhs: String,
            line: usize,
        },
        WaitFor {
            condition: String,
            line: usize,
        },
        WaitSec {
            seconds: f64,
            line: usize,
        },
        /// `HALT`: the program stops until the operator starts it again.
        Halt {
            line: usize,
        },
    }

    /// A `.dat` file: `DEFDAT name [PUBLIC] ... ENDDAT`.
    #[derive(Debug, Clone, PartialEq)]
    pub struct Dat {
        pub name: String,
        pub decls: Vec<Decl>,
    }

    /// `DECL TYPE NAME=value`: fields in order, nested aggregates flattened as `CM.X`; a scalar
    /// is one `("", value)`.
    #[derive(Debug, Clone, PartialEq)]
    pub struct Decl {
        pub ty: String,
        pub name: String,
        pub fields: Vec<(String, f64)>,
        pub line: usize,
    }

    impl Decl {
        /// The field's value (KRL names are case-insensitive).
        pub fn get(&self, field: &str) -> Option<f64> {
            self.fields
                .iter()
                .find(|(f, _)| f.eq_ignore_ascii_case(field))
                .map(|&(_, v)| v)
        }
    }

    impl Dat {
        /// The declaration named `name`, case-insensitively.
        pub fn decl(&self, name: &str) -> Option<&Decl> {
            self.decls
                .iter()
                .find(|d| d.name.eq_ignore_ascii_case(name))
        }
    }

    /// Reads a `.src` file holding exactly one `DEF name(params) ... END`.
    pub fn read_src(text: &str) -> Result<Src, String> {
        let (mut name, mut params, mut body) = (String::new(), String::new(), vec![]);
        let on_def = |_, rest: &str| {
            let (id, r) = take_ident(rest, true, MAX_IDENT)?;
            let inner = r.trim().strip_prefix('(').and_then(|r| r.strip_suffix(')'));
            let inner = inner
                .filter(|p| !p.contains(['(', ')']))
                .ok_or("expected `DEF name(params)`")?;
            (name, params) = (id.to_string(), inner.trim().to_string());
            Ok(())
        };
        let comments = walk(text, "DEF", "END", on_def, |n, code| {
            statement(n, code).map(|s| body.push(s))
        })?;
        Ok(Src {
            name,
            params,
            body,
            comments,
        })
    }

    /// Reads a `.dat` file: `DEFDAT name [PUBLIC]`, `DECL TYPE NAME=value` lines, `ENDDAT`.
    pub fn read_dat(text: &str) -> Result<Dat, String> {
        let (mut name, mut decls) = (String::new(), Vec::<Decl>::new());
        let on_defdat = |_, rest: &str| {
            let (id, r) = take_ident(rest, true, MAX_IDENT)?;
            let public = r.starts_with([' ', '\t']) && r.trim().eq_ignore_ascii_case("PUBLIC");
            name = id.to_string();
            (r.is_empty() || public)
                .then_some(())
                .ok_or("expected `DEFDAT name [PUBLIC]`".into())
        };
        walk(text, "DEFDAT", "ENDDAT", on_defdat, |n, code| {
            let d = decl(n, code)?;
            if decls.iter().any(|e| e.name.eq_ignore_ascii_case(&d.name)) {
                return Err("duplicate declaration".into());
            }
            decls.push(d);
            Ok(())
        })?;
        Ok(Dat { name, decls })
    }

    /// Walks a file: `&` header lines before `open`, then body lines until `close`; blank lines
    /// and `;` comments anywhere. Passes `on_open` the rest of the opening line and `on_body`
    /// each body line; names the line in their errors. Returns the comments.
    fn walk(
        text: &str,
        open: &str,
        close: &str,
        mut on_open: impl FnMut(usize, &str) -> Result<(), String>,
        mut on_body: impl FnMut(usize, &str) -> Result<(), String>,
    ) -> Result<Vec<String>, String> {
        let (mut comments, mut opened, mut closed, mut last) = (vec![], None, false, 1);
        for (i, raw) in text.lines().enumerate() {
            let (n, code) = (
                i + 1,
                raw.split_once(';').map_or(raw, |(code, _)| code).trim(),
            );
            last = n;
            comments.extend(raw.split_once(';').map(|(_, c)| c.trim().to_string()));
            let word = code.split_whitespace().next().unwrap_or("");
            let result = if !code.is_ascii() {
                Err("non-ASCII outside a comment".to_string())
            } else if code.is_empty() || (opened.is_none() && code.starts_with('&')) {
                continue;
            } else if closed {
                Err(format!("text after {close}"))
            } else if opened.is_none() && word.eq_ignore_ascii_case(open) {
                opened = Some(n);
                on_open(n, code[word.len()..].trim())
            } else if opened.is_none() {
                Err(format!("expected {open}"))
            } else if code.eq_ignore_ascii_case(close) {
                closed = true;
                Ok(())
            } else {
                on_body(n, code)
            };
            result.map_err(|why| err(n, &why, raw))?;
        }
        match opened {
            None => Err(err(last, &format!("missing {open}"), "")),
            Some(at) if !closed => Err(err(last, &format!("missing {close} for line {at}"), "")),
            Some(_) => Ok(comments),
        }
    }

    /// One body statement.
    fn statement(n: usize, code: &str) -> Result<Stmt, String> {
        let words: Vec<&str> = code.split_whitespace().collect();
        let upper: Vec<String> = words.iter().map(|w| w.to_ascii_uppercase()).collect();
        let approx = words.get(2).map(|a| a.to_string());
        let point = || check_var(words[1]).map(|()| words[1].to_string());
        match upper.iter().map(String::as_str).collect::<Vec<_>>()[..] {
            // PTP blends with C_PTP (`C_DIS` alone is not PTP's criterion).
            ["PTP", _] | ["PTP", _, "C_PTP"] => Ok(Stmt::Ptp {
                target: point()?,
                approx,
                line: n,
            }),
            ["LIN", _] | ["LIN", _, "C_DIS" | "C_ORI" | "C_VEL"] => Ok(Stmt::Lin {
                target: point()?,
                approx,
                line: n,
            }),
            ["WAIT", "FOR", ..] => {
                // `WAIT FOR [NOT] variable`: the condition is kept as written.
                let condition = code[4..].trim_start()[3..].trim();
                let var = match condition.split_once([' ', '\t']) {
                    Some((not, var)) if not.eq_ignore_ascii_case("NOT") => var.trim(),
                    _ => condition,
                };
                check_var(var).map(|()| Stmt::WaitFor {
                    condition: condition.into(),
                    line: n,
                })
            }
            ["HALT"] => Ok(Stmt::Halt { line: n }),
            ["WAIT", "SEC", _] => match lex_number(words[2]) {
                Some((seconds, len)) if len == words[2].len() && seconds >= 0.0 => {
                    Ok(Stmt::WaitSec { seconds, line: n })
                }
                _ => Err("expected `WAIT SEC seconds`".into()),
            },
            _ => {
                // `variable = number` or `variable = variable`; anything else is unknown.
                let (lhs, rhs) = code.split_once('=').ok_or("unknown statement")?;
                let (lhs, rhs) = (lhs.trim(), rhs.trim());
                check_var(lhs)?;
                if lex_number(rhs).is_none_or(|(_, len)| len != rhs.len()) {
                    check_var(rhs)?;
                }
                Ok(Stmt::Assign {
                    lhs: lhs.into(),
                    rhs: rhs.into(),
                    line: n,
                })
            }
        }
    }

    /// All of `s` as one variable reference: `NAME`, `$NAME[int]`, `$VEL.CP`.
    fn check_var(s: &str) -> Result<(), String> {
        let (_, mut rest) = take_ident(s, true, MAX_IDENT)?;
        if let Some(r) = rest.strip_prefix('[') {
            let digits = r.bytes().take_while(u8::is_ascii_digit).count();
            rest = r[digits..]
                .strip_prefix(']')
                .filter(|_| digits > 0)
                .ok_or("bad index")?;
        }
        while let Some(r) = rest.strip_prefix('.') {
            rest = take_ident(r, true, MAX_IDENT)?.1;
        }
        rest.is_empty()
            .then_some(())
            .ok_or_else(|| format!("{s:?} is not a variable"))
    }

    /// `DECL TYPE NAME=value`, the value a number or an aggregate of numbers.
    fn decl(n: usize, code: &str) -> Result<Decl, String> {
        let rest = match code.split_once([' ', '\t']) {
            Some((kw, rest)) if kw.eq_ignore_ascii_case("DECL") => rest.trim_start(),
            _ => return Err("unknown statement (expected `DECL TYPE NAME=value`)".into()),
        };
        let (ty, rest) = take_ident(rest, true, MAX_IDENT)?;
        let rest = rest
            .strip_prefix([' ', '\t'])
            .ok_or("expected a space after the type")?;
        let (name, rest) = take_ident(rest.trim_start(), true, MAX_IDENT)?;
        let value = rest
            .trim_start()
            .strip_prefix('=')
            .ok_or("expected '=' after the name")?;
        let (value, mut fields) = (value.trim(), vec![]);
        let tail = match lex_number(value) {
            Some((x, len)) => {
                fields.push((String::new(), x));
                &value[len..]
            }
            None => parse_agg(value, "", &mut fields)?,
        };
        match tail.trim() {
            "" => Ok(Decl {
                ty: ty.into(),
                name: name.into(),
                fields,
                line: n,
            }),
            tail => Err(format!("unexpected {tail:?} after the value")),
        }
    }

    /// `{NAME value, ...}` at the start of `s`, into `out` (a value is a number or a nested
    /// aggregate, flattened as `OUTER.INNER`); returns what follows.
    fn parse_agg<'a>(
        s: &'a str,
        prefix: &str,
        out: &mut Vec<(String, f64)>,
    ) -> Result<&'a str, String> {
        let mut rest = s.strip_prefix('{').ok_or("expected a number or '{'")?;
        loop {
            let (field, r) = take_ident(rest.trim_start(), true, MAX_IDENT)?;
            let field = format!("{prefix}{field}");
            let r = r
                .strip_prefix([' ', '\t'])
                .ok_or_else(|| format!("expected a space after {field}"));
            rest = r?.trim_start();
            if rest.starts_with('{') {
                rest = parse_agg(rest, &format!("{field}."), out)?;
            } else {
                let (x, len) =
                    lex_number(rest).ok_or_else(|| format!("expected a number for {field}"))?;
                if out.iter().any(|(f, _)| f.eq_ignore_ascii_case(&field)) {
                    return Err(format!("duplicate field {field}"));
                }
                out.push((field, x));
                rest = &rest[len..];
            }
            rest = rest.trim_start();
            match rest.as_bytes().first() {
                Some(b',') => rest = &rest[1..],
                Some(b'}') => return Ok(&rest[1..]),
                _ => {
                    return Err(format!(
                        "expected ',' or '}}' at {rest:?} (aggregate not closed?)"
                    ));
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::{krl, rapid};

    const RAPID: &str = r#"
MODULE FW_W1
  ! comment to end of line
  PERS tooldata tGrip := [TRUE,[[0,0,350],[1,0,0,0]],[42.5,[0,0,150],[1,0,0,0],0,0,0]];
  PERS wobjdata wWall := [FALSE,TRUE,"",[[1200,-300.5,0],[0.7071068,0,0,0.7071068]],[[0,0,0],[1,0,0,0]]];
  CONST speeddata vFree := [5000,500,5000,1000];
  CONST zonedata zFree := [FALSE,5,8,8,0.8,8,0.8];
  CONST jointtarget j1 := [[0,-12.5,30,0,45.25,-90],[9E+09,9E+09,9E+09,9E+09,9E+09,9E+09]];
  CONST robtarget p1 := [[100,200.25,-3.5E-01],[0.5,0.5,-0.5,0.5],[0,-1,2,0],

      [1500,9E+09,9E+09,9E+09,9E+09,9E+09]];
  CONST num n1 := 3;
  CONST string s1 := "text with ""escaped"" quotes \\ !;";
  PROC main()
    ! comment
    VelSet 100, 5000;
    MoveAbsJ j1, vFree, zFree, tGrip\WObj:=wWall;
    MoveL p1, vApproach, fine, tGrip\WObj:=wWall;
    WaitDI diPartPresent, 1;
    WaitTime 0.5;
    SetDO doGripClose, 1;
    PulseDO\PLength:=0.2, doNailFire;
    ConfL\On;
    ConfJ\On;
  ENDPROC
ENDMODULE
"#;

    const SRC: &str = "&ACCESS RVP\n&REL 1\nDEF fw_w1( )\n  ; comment\n  $TOOL = TOOL_GRIP
  $LOAD.M = 42.5\n  $LOAD.CM = LOAD_CM\n  $BASE = BASE_WALL\n  $VEL_AXIS[1] = 100
  $ACC_AXIS[1] = 100\n  $VEL_EXTAX[1] = 100\n  $VEL.CP = 0.25\n  $ACC.CP = 1.0\n  $APO.CDIS = 5
  PTP XJ1 C_PTP\n  LIN XP1\n  LIN XP2 C_DIS\n  WAIT FOR $IN[1]\n  WAIT SEC 0.5
  $OUT[2] = FALSE\nEND\n";

    const DAT: &str = "&ACCESS RVP\n&REL 1\nDEFDAT fw_w1\n  ; comment
  DECL FRAME TOOL_GRIP={X 0.0,Y 0.0,Z 350.0,A 0.0,B 0.0,C 0.0}
  DECL E6AXIS XJ1={A1 0.0,A2 -90.0,A3 90.0,A4 0.0,A5 30.0,A6 0.0,E1 0.0,E2 0.0,E3 0.0,E4 0.0,E5 0.0,E6 0.0}
  DECL E6POS XP1={X 1.0,Y 2.0,Z 3.0,A 4.0,B 5.0,C 6.0,S 2,T 35,E1 0.0,E2 0.0,E3 0.0,E4 0.0,E5 0.0,E6 0.0}
  DECL LOAD LOAD_GRIP={M 42.5,CM {X 0.0,Y 0.0,Z 1.5E2,A 0.0,B 0.0,C 0.0},J {X 0.0,Y 0.0,Z 0.0}}
  DECL REAL R1=0.5\nENDDAT\n";

    /// The 1-based number of the first line containing `needle`.
    fn line_of(text: &str, needle: &str) -> usize {
        text.lines().position(|l| l.contains(needle)).expect(needle) + 1
    }

    /// `text` with `from` replaced (which must occur) by `to`.
    fn edit(text: &str, from: &str, to: &str) -> String {
        assert!(text.contains(from), "{from:?} not in the example");
        text.replacen(from, to, 1)
    }

    /// Asserts `result` is an Err starting `line N:`.
    fn assert_err_at<T: std::fmt::Debug>(result: Result<T, String>, line: usize) {
        let e = result.expect_err("expected an error");
        assert!(
            e.starts_with(&format!("line {line}:")),
            "not line {line}: {e}"
        );
    }

    /// An instruction written back as `Name a, b, \Switch:=c` (a ", " before every argument).
    fn render(i: &rapid::Instr) -> String {
        let args = i.args.iter().map(|a| match &a.switch {
            None => a.value.clone(),
            Some(sw) if a.value.is_empty() => format!("\\{sw}"),
            Some(sw) => format!("\\{sw}:={}", a.value),
        });
        format!(
            "{}@{} {}",
            i.name,
            i.line,
            args.collect::<Vec<_>>().join(", ")
        )
    }

    #[test]
    fn rapid_example_parses() {
        let m = rapid::read(RAPID).unwrap();
        assert_eq!((m.name.as_str(), m.decls.len()), ("FW_W1", 8));
        assert_eq!(m.comments, ["comment to end of line", "comment"]);
        let p1 = m.decl("P1").unwrap();
        assert_eq!(
            (p1.storage.as_str(), p1.ty.as_str(), p1.line),
            ("CONST", "robtarget", 9)
        );
        let nums = p1.value.nums();
        assert_eq!(format!("{:?}", &nums[..4]), "[100.0, 200.25, -0.35, 0.5]");
        assert_eq!((nums.len(), nums[13]), (17, 9e9));
        assert_eq!(m.decl("tGrip").unwrap().value.nums()[7], 42.5);
        assert_eq!(m.decl("wWall").unwrap().value.nums()[..2], [1200.0, -300.5]);
        let text = r#"text with "escaped" quotes \ !;"#;
        assert_eq!(m.decl("s1").unwrap().value, rapid::Value::Str(text.into()));
        assert_eq!(m.decl("n1").unwrap().value, rapid::Value::Num(3.0));
        let body: Vec<String> = m.procs[0].body.iter().map(render).collect();
        let expected = [
            "VelSet@16 100, 5000",
            "MoveAbsJ@17 j1, vFree, zFree, tGrip, \\WObj:=wWall",
            "MoveL@18 p1, vApproach, fine, tGrip, \\WObj:=wWall",
            "WaitDI@19 diPartPresent, 1",
            "WaitTime@20 0.5",
            "SetDO@21 doGripClose, 1",
            "PulseDO@22 \\PLength:=0.2, doNailFire",
            "ConfL@23 \\On",
            "ConfJ@24 \\On",
        ];
        assert_eq!(body, expected);
    }

    #[test]
    fn krl_examples_parse() {
        let src = krl::read_src(SRC).unwrap();
        assert_eq!((src.name.as_str(), src.params.as_str()), ("fw_w1", ""));
        assert_eq!((src.comments.len(), src.body.len()), (1, 16));
        let body: Vec<String> = src.body.iter().map(|s| format!("{s:?}")).collect();
        let expected = [
            r#"Assign { lhs: "$VEL_AXIS[1]", rhs: "100", line: 9 }"#,
            r#"Ptp { target: "XJ1", approx: Some("C_PTP"), line: 15 }"#,
            r#"Lin { target: "XP1", approx: None, line: 16 }"#,
            r#"Lin { target: "XP2", approx: Some("C_DIS"), line: 17 }"#,
            r#"WaitFor { condition: "$IN[1]", line: 18 }"#,
            r#"WaitSec { seconds: 0.5, line: 19 }"#,
            r#"Assign { lhs: "$OUT[2]", rhs: "FALSE", line: 20 }"#,
        ];
        assert_eq!(body[4], expected[0]);
        assert_eq!(body[10..], expected[1..]);
        let dat = krl::read_dat(DAT).unwrap();
        assert_eq!((dat.name.as_str(), dat.decls.len()), ("fw_w1", 5));
        let xp1 = dat.decl("xp1").unwrap();
        assert_eq!(
            (xp1.ty.as_str(), xp1.line, xp1.fields.len()),
            ("E6POS", 7, 14)
        );
        assert_eq!(
            (xp1.get("x"), xp1.get("T"), xp1.get("Q")),
            (Some(1.0), Some(35.0), None)
        );
        assert_eq!(dat.decl("XJ1").unwrap().get("A2"), Some(-90.0));
        assert_eq!(dat.decl("LOAD_GRIP").unwrap().get("CM.Z"), Some(150.0));
        assert_eq!(dat.decl("R1").unwrap().fields, [(String::new(), 0.5)]);
    }

    #[test]
    fn comments_are_kept_and_end_nothing() {
        let note = r#"he said "hi"; ENDMODULE ENDPROC END ENDDAT ! é"#;
        let m = rapid::read(&edit(RAPID, "! comment\n", &format!("! {note}\n"))).unwrap();
        assert_eq!((m.comments[1].as_str(), m.procs[0].body.len()), (note, 9));
        let m = rapid::read(&edit(RAPID, "0.5;", &format!("0.5; !{note}"))).unwrap();
        assert_eq!(m.comments[2], note);
        let src = krl::read_src(&edit(SRC, "; comment", &format!(";{note}"))).unwrap();
        assert_eq!((src.comments[0].as_str(), src.body.len()), (note, 16));
        let dat = krl::read_dat(&edit(DAT, "R1=0.5", &format!("R1=0.5 ;{note}"))).unwrap();
        assert_eq!(
            (dat.decls.len(), dat.decl("R1").unwrap().get("")),
            (5, Some(0.5))
        );
    }

    #[test]
    fn rapid_errors_name_the_line() {
        let (p1, wait) = (line_of(RAPID, "robtarget p1"), line_of(RAPID, "WaitTime"));
        let end = line_of(RAPID, "ENDMODULE");
        let long = format!("{} :=", "n".repeat(33));
        let cases = [
            ("]];\n  CONST num", "];\n  CONST num", p1), // unterminated aggregate
            ("n1 := 3;", "n1 := [3,4;", p1 + 3),
            ("n1 :=", long.as_str(), p1 + 3), // identifier over 32 characters
            ("  ENDPROC\n", "", end - 1),
            ("ENDMODULE\n", "", end - 1),
            ("ENDMODULE\n", "ENDMODULE\nMODULE B\n", end + 1),
            ("\nMODULE", "! header\nMODULE", 1),
            ("WaitTime 0.5;", "Frobnicate 1;", wait),
            ("WaitTime 0.5;", "IF x THEN", wait),
            ("WaitTime 0.5;", "WaitTime 0.5", wait),
            ("WaitTime 0.5;", "WaitTime 0.5; Stop;", wait),
            ("WaitTime 0.5;", "WaitTime é;", wait),
            ("WaitTime 0.5;", "WaitTime 0.5 + 1;", wait),
            ("WaitTime 0.5;", "WaitTime 12abc;", wait),
            ("WaitTime 0.5;", "MoveL p1,, fine;", wait),
            ("WaitTime 0.5;", "MoveL p1\\WObj:=;", wait),
            ("WaitTime 0.5;", "CONST num n2 := 1;", wait),
            (r#"""escaped"""#, r#"\"escaped\""#, p1 + 4), // only "" and \\ escapes
            ("PROC main()", "PROC main(num x)", p1 + 5),
        ];
        for (from, to, line) in cases {
            assert_err_at(rapid::read(&edit(RAPID, from, to)), line);
        }
    }

    #[test]
    fn krl_errors_name_the_line() {
        let (xp1, lin) = (line_of(DAT, "DECL E6POS"), line_of(SRC, "LIN XP1"));
        let long = "X".repeat(25);
        let dat_cases = [
            ("E6 0.0}\n  DECL LOAD", "E6 0.0\n  DECL LOAD", xp1), // unterminated aggregate
            ("ENDDAT\n", "", xp1 + 2),
            ("XP1=", &format!("{long}="), xp1), // identifier over 24 characters
            ("DECL REAL R1=0.5", "REAL R1=0.5", xp1 + 2),
            ("DECL REAL R1=0.5", "DECL REAL XP1=0.5", xp1 + 2),
            ("DECL REAL R1=0.5", "DECL BOOL B1=TRUE", xp1 + 2),
            ("S 2,", "S 'B010',", xp1),
        ];
        for (from, to, line) in dat_cases {
            assert_err_at(krl::read_dat(&edit(DAT, from, to)), line);
        }
        let src_cases = [
            ("END\n", "", lin + 4),
            ("LIN XP1\n", &format!("LIN {long}\n"), lin),
            ("LIN XP1\n", "CIRC XP1 XP2\n", lin),
            ("LIN XP1\n", "LIN XP1 C_PTP\n", lin),
            ("LIN XP1\n", "LIN XPé\n", lin),
            ("LIN XP1\n", "&REL 2\n", lin),
            ("LIN XP1\n", "BRAKE\n", lin),
            ("LIN XP1\n", "PTP XP1 C_DIS\n", lin),
            ("$OUT[2] = FALSE", "$OUT[2] == FALSE", lin + 4),
            ("WAIT SEC 0.5", "WAIT SEC x", lin + 3),
            ("END\n", "END\nDEF b()\nEND\n", lin + 6),
        ];
        for (from, to, line) in src_cases {
            assert_err_at(krl::read_src(&edit(SRC, from, to)), line);
        }
    }
}
