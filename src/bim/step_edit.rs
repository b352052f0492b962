//! Byte-level edits of an ISO 10303-21 file that keep every input entity as
//! it was: the FILE_NAME header record is replaced, new entity instances are
//! appended after the last one of the DATA section, numbered from the
//! highest id in use.

use crate::step::StepFile;
use crate::step::text::Ref;
use std::fmt::{Display, Write};
use std::ops::Range;

/// Skips a string (`'…'`, quotes doubled inside) or a comment (`/*…*/`) starting at `at`;
/// returns the offset after it, or `None` when `at` starts neither.
fn skip_literal(bytes: &[u8], at: usize) -> Option<usize> {
    match bytes.get(at) {
        Some(b'\'') => {
            let mut i = at + 1;
            while i < bytes.len() {
                if bytes[i] == b'\'' {
                    if bytes.get(i + 1) == Some(&b'\'') {
                        i += 2;
                        continue;
                    }
                    return Some(i + 1);
                }
                i += 1;
            }
            Some(bytes.len())
        }
        Some(b'/') if bytes.get(at + 1) == Some(&b'*') => Some(
            memchr::memmem::find(&bytes[at + 2..], b"*/").map_or(bytes.len(), |k| at + 2 + k + 2),
        ),
        _ => None,
    }
}

/// Offset of the first `;` at or after `from` outside strings and comments.
fn statement_end(bytes: &[u8], from: usize) -> Option<usize> {
    let mut i = from;
    while i < bytes.len() {
        if let Some(next) = skip_literal(bytes, i) {
            i = next;
        } else if bytes[i] == b';' {
            return Some(i);
        } else {
            i += 1;
        }
    }
    None
}

/// Byte range of the `FILE_NAME(…);` record (keyword to `;` inclusive) before `limit`.
pub fn file_name_span(bytes: &[u8], limit: usize) -> Option<Range<usize>> {
    let limit = limit.min(bytes.len());
    let mut i = 0;
    while i < limit {
        if let Some(next) = skip_literal(bytes, i) {
            i = next;
            continue;
        }
        let starts_word = i == 0 || !(bytes[i - 1].is_ascii_alphanumeric() || bytes[i - 1] == b'_');
        if starts_word
            && bytes[i..limit].len() >= 9
            && bytes[i..i + 9].eq_ignore_ascii_case(b"FILE_NAME")
        {
            let after = bytes.get(i + 9).copied().unwrap_or(b' ');
            if after == b'(' || after.is_ascii_whitespace() {
                let end = statement_end(bytes, i + 9)?;
                return Some(i..end + 1);
            }
        }
        i += 1;
    }
    None
}

/// Where appended entities go: after the `;` (and its line end) of the entity
/// that ends last in the file, with the line end the file uses there.
pub fn insertion_point(file: &StepFile) -> Option<(usize, &'static str)> {
    let bytes = file.bytes();
    let last = file.records().iter().max_by_key(|r| r.params.1)?;
    let semi = statement_end(bytes, last.params.1)?;
    let rest = &bytes[semi + 1..];
    Some(if rest.starts_with(b"\r\n") {
        (semi + 3, "\r\n")
    } else if rest.starts_with(b"\n") {
        (semi + 2, "\n")
    } else if rest.starts_with(b"\r") {
        (semi + 2, "\r")
    } else {
        // Something follows on the same line: start the new entities on a line of their own.
        (semi + 1, "\n")
    })
}

/// Appends numbered entity instances, one per line.
pub struct Appender {
    out: String,
    next: u64,
    eol: &'static str,
    /// True when the text must start with a line end (insertion mid-line).
    lead: bool,
}

impl Appender {
    /// Numbers from `max_id + 1`.
    pub fn new(max_id: u64, eol: &'static str, lead: bool) -> Appender {
        Appender {
            out: String::new(),
            next: max_id + 1,
            eol,
            lead,
        }
    }

    /// Writes `#n=NAME(args);` and returns `#n`.
    pub fn add(&mut self, name: &str, args: impl Display) -> Ref {
        if self.lead {
            self.out.push_str(self.eol);
            self.lead = false;
        }
        let id = Ref(self.next as usize);
        self.next += 1;
        // Writing into a String cannot fail.
        let _ = write!(self.out, "{id}={name}({args});{}", self.eol);
        id
    }

    pub fn into_text(self) -> String {
        self.out
    }
}

/// The input bytes with `replace` put in place of `span` and `insert` at `at` (`at` after `span`).
pub fn splice(bytes: &[u8], span: Range<usize>, replace: &str, at: usize, insert: &str) -> Vec<u8> {
    let mut out = Vec::with_capacity(bytes.len() + replace.len() + insert.len());
    out.extend_from_slice(&bytes[..span.start]);
    out.extend_from_slice(replace.as_bytes());
    out.extend_from_slice(&bytes[span.end..at]);
    out.extend_from_slice(insert.as_bytes());
    out.extend_from_slice(&bytes[at..]);
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::step::ReadOptions;

    const TEXT: &str = "ISO-10303-21;\r\nHEADER;\r\n/* FILE_NAME('x'); */FILE_DESCRIPTION(('FILE_NAME(;'),'2;1');\r\nFILE_NAME ('a;''b','t',(''),(''),'p','o','');\r\nFILE_SCHEMA(('IFC4'));\r\nENDSEC;\r\nDATA;\r\n#7=IFCLABEL('x;');\r\n#3=IFCLABEL('y') ;\r\nENDSEC;\r\nEND-ISO-10303-21;\r\n";

    #[test]
    fn finds_file_name_outside_comments_and_strings() {
        let span = file_name_span(TEXT.as_bytes(), TEXT.len()).unwrap();
        assert_eq!(&TEXT[span], "FILE_NAME ('a;''b','t',(''),(''),'p','o','');");
    }

    #[test]
    fn appends_after_the_last_entity_with_the_files_line_ends() {
        let file = StepFile::from_bytes(TEXT.as_bytes().to_vec(), &ReadOptions::default()).unwrap();
        let (at, eol) = insertion_point(&file).unwrap();
        assert_eq!(eol, "\r\n");
        assert!(TEXT[at..].starts_with("ENDSEC;"));
        let mut app = Appender::new(7, eol, false);
        assert_eq!(app.add("IFCLABEL", "'z'").0, 8);
        let out = splice(TEXT.as_bytes(), 0..0, "", at, &app.into_text());
        let out = String::from_utf8(out).unwrap();
        assert!(out.contains("#3=IFCLABEL('y') ;\r\n#8=IFCLABEL('z');\r\nENDSEC;"));
    }
}
