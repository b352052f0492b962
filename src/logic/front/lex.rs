//! Tokens of the rule language. Hand-written so every token carries an exact
//! line and column for error reports.

use super::ast::Span;

#[derive(Clone, Debug, PartialEq)]
pub enum Tok {
    Ident(String),
    /// `.name` at the start of a directive (`.decl`, `.input`, ...).
    Directive(String),
    Int(i128),
    /// An unsigned constant written with Soufflé's `u` suffix (`10u`).
    UInt(i128),
    Float(f64),
    Str(String),
    /// Punctuation and operators, as written (`:-`, `<=`, `(`, ...).
    P(&'static str),
    Eof,
}

#[derive(Clone, Debug)]
pub struct Token {
    pub tok: Tok,
    pub span: Span,
}

/// `// @rule NAME` annotation found in a comment.
#[derive(Clone, Debug)]
pub struct Label {
    pub name: String,
    pub span: Span,
}

#[derive(Debug)]
pub struct LexError {
    pub span: Span,
    pub message: String,
    pub hint: String,
}

const PUNCT: [&str; 27] = [
    ":-", "<=", ">=", "!=", "<:", "(", ")", "{", "}", "[", "]", ",", ".", ":", ";", "!", "=", "<",
    ">", "+", "-", "*", "/", "%", "^", "@", "|",
];

pub fn lex(file: u32, text: &str) -> Result<(Vec<Token>, Vec<Label>), LexError> {
    let chars: Vec<char> = text.chars().collect();
    let mut toks = Vec::new();
    let mut labels = Vec::new();
    let (mut i, mut line, mut col) = (0usize, 1u32, 1u32);
    let span = |line, col, len: usize| Span {
        file,
        line,
        col,
        len: len as u32,
    };
    while i < chars.len() {
        let c = chars[i];
        let start = (i, line, col);
        let advance = |n: usize, i: &mut usize, col: &mut u32| {
            *i += n;
            *col += n as u32;
        };
        if c == '\n' {
            i += 1;
            line += 1;
            col = 1;
            continue;
        }
        if c.is_whitespace() {
            advance(1, &mut i, &mut col);
            continue;
        }
        if c == '/' && chars.get(i + 1) == Some(&'/') {
            let end = chars[i..]
                .iter()
                .position(|&c| c == '\n')
                .map_or(chars.len(), |p| i + p);
            let comment: String = chars[i + 2..end].iter().collect();
            let trimmed = comment.trim();
            if let Some(rest) = trimmed.strip_prefix("@rule") {
                let name = rest.trim();
                let valid = !name.is_empty()
                    && name.chars().all(|c| c.is_alphanumeric() || c == '_')
                    && !name.starts_with(|c: char| c.is_ascii_digit());
                if !valid {
                    return Err(LexError {
                        span: span(line, col, end - i),
                        message: format!("bad rule label `{name}`"),
                        hint: "write `// @rule NAME` with NAME made of letters, digits and `_`"
                            .into(),
                    });
                }
                labels.push(Label {
                    name: name.to_string(),
                    span: span(line, col, end - i),
                });
            }
            col += (end - i) as u32;
            i = end;
            continue;
        }
        if c == '/' && chars.get(i + 1) == Some(&'*') {
            let mut j = i + 2;
            let (mut l, mut cl) = (line, col + 2);
            loop {
                if j + 1 >= chars.len() {
                    return Err(LexError {
                        span: span(start.1, start.2, 2),
                        message: "unterminated `/*` comment".into(),
                        hint: "close the comment with `*/`".into(),
                    });
                }
                if chars[j] == '*' && chars[j + 1] == '/' {
                    j += 2;
                    cl += 2;
                    break;
                }
                if chars[j] == '\n' {
                    l += 1;
                    cl = 1;
                } else {
                    cl += 1;
                }
                j += 1;
            }
            i = j;
            line = l;
            col = cl;
            continue;
        }
        if c == '#'
            && chars[..i]
                .iter()
                .rev()
                .take_while(|&&c| c != '\n')
                .all(|c| c.is_whitespace())
        {
            let end = chars[i..]
                .iter()
                .position(|&c| c == '\n')
                .map_or(chars.len(), |p| i + p);
            return Err(LexError {
                span: span(line, col, end - i),
                message: "C preprocessor directives (`#include`, `#define`, ...) are not supported"
                    .into(),
                hint: "use `.include \"file.dl\"` to include another rule file".into(),
            });
        }
        if c == '"' {
            let mut s = String::new();
            let mut j = i + 1;
            loop {
                match chars.get(j) {
                    None => {
                        // Underlined to the end of its line.
                        let shown = chars[i..].iter().take_while(|&&c| c != '\n').count();
                        return Err(LexError {
                            span: span(line, col, shown),
                            message: "unterminated string".into(),
                            hint: "close the string with `\"`".into(),
                        });
                    }
                    Some('"') => break,
                    Some('\\') => {
                        // Soufflé's lexer: these escapes, any other is an error.
                        let e = chars.get(j + 1).copied().unwrap_or(' ');
                        s.push(match e {
                            '"' | '\'' | '\\' => e,
                            'a' => '\u{7}',
                            'b' => '\u{8}',
                            'f' => '\u{c}',
                            'n' => '\n',
                            'r' => '\r',
                            't' => '\t',
                            'v' => '\u{b}',
                            other => {
                                return Err(LexError {
                                    span: span(line, col + (j - i) as u32, 2),
                                    message: format!("unknown escape sequence `\\{other}` in a string"),
                                    hint: "strings know the escapes \\\" \\' \\\\ \\a \\b \\f \\n \\r \\t \\v (as Soufflé); write a backslash as `\\\\`".into(),
                                });
                            }
                        });
                        j += 2;
                    }
                    Some(&ch) => {
                        s.push(ch);
                        j += 1;
                    }
                }
            }
            let len = j + 1 - i;
            // A string may hold line breaks, as in Soufflé (its scanner's `[^"\\]` takes
            // them): the token's span covers its first line, and the position moves on
            // past the last.
            let literal = &chars[i..=j];
            let breaks = literal.iter().filter(|&&c| c == '\n').count();
            let first_line = literal.iter().take_while(|&&c| c != '\n').count();
            toks.push(Token {
                tok: Tok::Str(s),
                span: span(line, col, first_line),
            });
            if breaks == 0 {
                advance(len, &mut i, &mut col);
            } else {
                let after_last = literal.iter().rev().take_while(|&&c| c != '\n').count();
                i += len;
                line += breaks as u32;
                col = after_last as u32 + 1;
            }
            continue;
        }
        if c.is_ascii_digit() {
            let mut j = i;
            let radix = if c == '0' && matches!(chars.get(i + 1), Some('x') | Some('X')) {
                j += 2;
                16
            } else if c == '0' && matches!(chars.get(i + 1), Some('b') | Some('B')) {
                j += 2;
                2
            } else {
                10
            };
            let digits_start = j;
            while j < chars.len() && chars[j].is_digit(radix) {
                j += 1;
            }
            let mut is_float = false;
            if radix == 10
                && chars.get(j) == Some(&'.')
                && chars.get(j + 1).is_some_and(|c| c.is_ascii_digit())
            {
                is_float = true;
                j += 1;
                while j < chars.len() && chars[j].is_ascii_digit() {
                    j += 1;
                }
                if matches!(chars.get(j), Some('e') | Some('E')) {
                    let mut k = j + 1;
                    if matches!(chars.get(k), Some('+') | Some('-')) {
                        k += 1;
                    }
                    if chars.get(k).is_some_and(|c| c.is_ascii_digit()) {
                        j = k;
                        while j < chars.len() && chars[j].is_ascii_digit() {
                            j += 1;
                        }
                    }
                }
            }
            let text: String = chars[digits_start..j].iter().collect();
            // `10u`: Soufflé's unsigned constant.
            let unsigned = !is_float
                && chars.get(j) == Some(&'u')
                && !chars
                    .get(j + 1)
                    .is_some_and(|c| c.is_alphanumeric() || *c == '_');
            if unsigned {
                j += 1;
            }
            let sp = span(line, col, j - i);
            let tok = if is_float {
                Tok::Float(text.parse().map_err(|_| LexError {
                    span: sp,
                    message: format!("bad float literal `{text}`"),
                    hint: "write floats as `1.5` or `2.0e3`".into(),
                })?)
            } else {
                let value = i128::from_str_radix(&text, radix).map_err(|_| LexError {
                    span: sp,
                    message: format!("bad integer literal `{text}`"),
                    hint: "integers must fit in 64 bits".into(),
                })?;
                if unsigned {
                    Tok::UInt(value)
                } else {
                    Tok::Int(value)
                }
            };
            toks.push(Token { tok, span: sp });
            advance(j - i, &mut i, &mut col);
            continue;
        }
        if c.is_alphabetic() || c == '_' || c == '?' {
            let mut j = i;
            while j < chars.len()
                && (chars[j].is_alphanumeric() || chars[j] == '_' || chars[j] == '?')
            {
                j += 1;
            }
            let name: String = chars[i..j].iter().collect();
            toks.push(Token {
                tok: Tok::Ident(name),
                span: span(line, col, j - i),
            });
            advance(j - i, &mut i, &mut col);
            continue;
        }
        if c == '.' && chars.get(i + 1).is_some_and(|c| c.is_alphabetic()) {
            let mut j = i + 1;
            while j < chars.len() && (chars[j].is_alphanumeric() || chars[j] == '_') {
                j += 1;
            }
            let name: String = chars[i + 1..j].iter().collect();
            toks.push(Token {
                tok: Tok::Directive(name),
                span: span(line, col, j - i),
            });
            advance(j - i, &mut i, &mut col);
            continue;
        }
        if c == '$' {
            return Err(LexError {
                span: span(line, col, 1),
                message: "`$` (auto-increment counter or algebraic data type branch) is not supported".into(),
                hint: "algebraic data types and the `$` counter are unsupported Soufflé features; compute ids in the facts instead".into(),
            });
        }
        let rest: String = chars[i..(i + 2).min(chars.len())].iter().collect();
        if let Some(p) = PUNCT.iter().find(|p| rest.starts_with(**p)) {
            toks.push(Token {
                tok: Tok::P(p),
                span: span(line, col, p.len()),
            });
            advance(p.len(), &mut i, &mut col);
            continue;
        }
        return Err(LexError {
            span: span(line, col, 1),
            message: format!("unexpected character `{c}`"),
            hint: "check the syntax near this character".into(),
        });
    }
    toks.push(Token {
        tok: Tok::Eof,
        span: span(line, col, 1),
    });
    Ok((toks, labels))
}
