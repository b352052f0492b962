//! Error reports for rule files: `file:line:col`, the source line with a
//! caret under the offending text, what is wrong and a hint.

use super::ast::Span;
use std::fmt;

/// One source file of a program (kept so errors can quote the line).
#[derive(Clone, Debug, PartialEq)]
pub struct Source {
    pub name: String,
    pub text: String,
}

#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Diagnostic {
    pub file: String,
    pub line: u32,
    pub col: u32,
    pub len: u32,
    /// The quoted source line (without its newline).
    pub source_line: String,
    pub message: String,
    pub hint: String,
}

impl Diagnostic {
    pub fn at(
        sources: &[Source],
        span: Span,
        message: impl Into<String>,
        hint: impl Into<String>,
    ) -> Self {
        let (file, line_text) = match sources.get(span.file as usize) {
            Some(src) => (
                src.name.clone(),
                src.text
                    .lines()
                    .nth(span.line.saturating_sub(1) as usize)
                    .unwrap_or("")
                    .to_string(),
            ),
            None => ("<unknown>".to_string(), String::new()),
        };
        Diagnostic {
            file,
            line: span.line,
            col: span.col,
            len: span.len.max(1),
            source_line: line_text,
            message: message.into(),
            hint: hint.into(),
        }
    }
}

impl fmt::Display for Diagnostic {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let num = self.line.to_string();
        let pad = " ".repeat(num.len());
        writeln!(
            f,
            "{}:{}:{}: error: {}",
            self.file, self.line, self.col, self.message
        )?;
        writeln!(f, "{pad} |")?;
        writeln!(f, "{num} | {}", self.source_line.replace('\t', " "))?;
        let lead = " ".repeat(self.col.saturating_sub(1) as usize);
        let width = (self.len as usize).min(
            self.source_line
                .chars()
                .count()
                .saturating_sub((self.col as usize).saturating_sub(1))
                .max(1),
        );
        writeln!(f, "{pad} | {lead}{}", "^".repeat(width.max(1)))?;
        write!(f, "{pad} = hint: {}", self.hint)
    }
}

/// All errors found in a program (at least one).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Diagnostics(pub Vec<Diagnostic>);

impl fmt::Display for Diagnostics {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        for (i, d) in self.0.iter().enumerate() {
            if i > 0 {
                f.write_str("\n\n")?;
            }
            write!(f, "{d}")?;
        }
        Ok(())
    }
}

impl std::error::Error for Diagnostics {}
impl std::error::Error for Diagnostic {}

/// The closest name in `candidates` (edit distance ≤ 2), for "did you mean" hints.
pub fn closest<'a>(name: &str, candidates: impl Iterator<Item = &'a str>) -> Option<&'a str> {
    candidates
        .map(|c| (edit_distance(name, c), c))
        .filter(|(d, _)| *d <= 2)
        .min()
        .map(|(_, c)| c)
}

fn edit_distance(a: &str, b: &str) -> usize {
    let b: Vec<char> = b.chars().collect();
    let mut prev: Vec<usize> = (0..=b.len()).collect();
    for (i, ca) in a.chars().enumerate() {
        let mut cur = vec![i + 1];
        for (j, cb) in b.iter().enumerate() {
            let sub = prev[j] + usize::from(ca != *cb);
            cur.push(sub.min(prev[j + 1] + 1).min(cur[j] + 1));
        }
        prev = cur;
    }
    prev[b.len()]
}
