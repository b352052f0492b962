//! ISO 10303-21 text: entity numbering, reals, strings.
use std::fmt::{self, Display, Write};

/// An entity instance name `#n`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub struct Ref(pub usize);

impl Display for Ref {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "#{}", self.0)
    }
}

/// A REAL as STEP wants it: always a decimal point ("0.", "6.858", "-1.5").
/// Values are rounded to 1e-10 so unit conversions print as the numbers people wrote.
#[derive(Debug, Clone, Copy)]
pub struct Real(pub f64);

impl Display for Real {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let r = (self.0 * 1e10).round() / 1e10;
        if r == 0.0 || !r.is_finite() {
            // Non-finite values never reach the writer (layouts are validated); "0." keeps the file parseable.
            return f.write_str("0.");
        }
        let mut buf = String::with_capacity(24);
        write!(buf, "{r}")?;
        if !buf.contains('.') {
            buf.push('.');
        }
        f.write_str(&buf)
    }
}

/// A STRING literal: quotes doubled, backslashes doubled, everything outside
/// printable ASCII as \X2\ (BMP) or \X4\ (beyond) hex groups closed by \X0\.
pub fn string(text: &str) -> String {
    let mut out = String::with_capacity(text.len() + 2);
    out.push('\'');
    let mut wide: Vec<char> = Vec::new();
    let flush = |out: &mut String, wide: &mut Vec<char>| {
        if wide.is_empty() {
            return;
        }
        let big = wide.iter().any(|&c| c as u32 > 0xFFFF);
        out.push_str(if big { "\\X4\\" } else { "\\X2\\" });
        for c in wide.drain(..) {
            if big {
                let _ = write!(out, "{:08X}", c as u32);
            } else {
                let _ = write!(out, "{:04X}", c as u32);
            }
        }
        out.push_str("\\X0\\");
    };
    for c in text.chars() {
        if (' '..='~').contains(&c) {
            flush(&mut out, &mut wide);
            match c {
                '\'' => out.push_str("''"),
                '\\' => out.push_str("\\\\"),
                _ => out.push(c),
            }
        } else {
            wide.push(c);
        }
    }
    flush(&mut out, &mut wide);
    out.push('\'');
    out
}

/// Appends numbered entity instances to a DATA section.
pub struct StepWriter {
    out: String,
    next: usize,
}

impl StepWriter {
    pub fn new(capacity: usize) -> StepWriter {
        StepWriter {
            out: String::with_capacity(capacity),
            next: 1,
        }
    }

    /// Write `#n=NAME(args);` and return `#n`.
    pub fn add(&mut self, name: &str, args: impl Display) -> Ref {
        let id = Ref(self.next);
        self.next += 1;
        // Writing into a String cannot fail.
        let _ = writeln!(self.out, "{id}={name}({args});");
        id
    }

    /// The instance name the next `add` will return.
    pub fn peek(&self) -> Ref {
        Ref(self.next)
    }

    pub fn into_text(self) -> String {
        self.out
    }
}

/// `(#1,#2,#3)`.
pub struct RefList<'a>(pub &'a [Ref]);

impl Display for RefList<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_char('(')?;
        for (k, r) in self.0.iter().enumerate() {
            if k > 0 {
                f.write_char(',')?;
            }
            write!(f, "{r}")?;
        }
        f.write_char(')')
    }
}

/// `(x,y,z)` of reals.
pub struct RealList<'a>(pub &'a [f64]);

impl Display for RealList<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_char('(')?;
        for (k, v) in self.0.iter().enumerate() {
            if k > 0 {
                f.write_char(',')?;
            }
            write!(f, "{}", Real(*v))?;
        }
        f.write_char(')')
    }
}
