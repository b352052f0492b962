//! serde_json's pretty JSON of a report whose big top-level arrays are rendered in
//! parallel: the same bytes as `serde_json::to_writer_pretty`, written in batches so the
//! whole text is never held at once.
//!
//! serde_json's pretty printer indents by two spaces and, inside JSON text, a line break
//! only ever separates tokens (a string escapes its own). So an element rendered on its
//! own becomes the element inside an array at depth one by indenting every line after its
//! first by four more spaces.

use rayon::prelude::*;
use serde::Serialize;
use std::io::{self, Write};

/// Elements rendered per parallel task.
const PER_TASK: usize = 256;
/// Elements rendered before they are written.
const PER_BATCH: usize = 8192;

/// One top-level array of the document: its key and its elements.
pub struct Array<'a, T> {
    pub key: &'a str,
    pub items: &'a [T],
}

/// Writes `skeleton` (the document with each array of `arrays` left empty) with the
/// arrays filled in, as `to_writer_pretty` would write the whole document.
pub fn write_pretty<A: Serialize + Sync, B: Serialize + Sync>(
    out: &mut dyn Write,
    skeleton: &impl Serialize,
    arrays: (Array<'_, A>, Array<'_, B>),
) -> io::Result<()> {
    let text = serde_json::to_vec_pretty(skeleton)?;
    let (first, second) = arrays;
    let a = empty_array_at(&text, first.key)?;
    let b = empty_array_at(&text, second.key)?;
    if a >= b {
        return Err(io::Error::other(
            "pretty_json: the arrays must be given in document order",
        ));
    }
    out.write_all(&text[..a])?;
    write_elements(out, first.items)?;
    out.write_all(&text[a + 2..b])?;
    write_elements(out, second.items)?;
    out.write_all(&text[b + 2..])?;
    out.write_all(b"\n")
}

/// Where the `[]` of the top-level key `key` starts in a pretty skeleton.
fn empty_array_at(text: &[u8], key: &str) -> io::Result<usize> {
    let needle = format!("\n  {}: []", serde_json::to_string(key)?);
    memchr::memmem::find(text, needle.as_bytes())
        .map(|at| at + needle.len() - 2)
        .ok_or_else(|| {
            io::Error::other(format!(
                "pretty_json: the skeleton has no empty top-level array {key:?}"
            ))
        })
}

/// `[`, the elements at depth one, `]`: `[]` when there are none.
fn write_elements<T: Serialize + Sync>(out: &mut dyn Write, items: &[T]) -> io::Result<()> {
    if items.is_empty() {
        return out.write_all(b"[]");
    }
    out.write_all(b"[")?;
    for (b, batch) in items.chunks(PER_BATCH).enumerate() {
        let rendered: Vec<Vec<u8>> = batch
            .par_chunks(PER_TASK)
            .enumerate()
            .map(|(t, task)| {
                let mut buf = Vec::new();
                for (k, item) in task.iter().enumerate() {
                    if b + t + k > 0 {
                        buf.push(b',');
                    }
                    buf.extend_from_slice(b"\n    ");
                    let element = serde_json::to_vec_pretty(item)?;
                    indent_lines(&mut buf, &element);
                }
                Ok(buf)
            })
            .collect::<io::Result<_>>()?;
        for buf in rendered {
            out.write_all(&buf)?;
        }
    }
    out.write_all(b"\n  ]")
}

/// Appends `element` with four spaces after each of its line breaks.
fn indent_lines(buf: &mut Vec<u8>, element: &[u8]) {
    let mut rest = element;
    while let Some(at) = memchr::memchr(b'\n', rest) {
        buf.extend_from_slice(&rest[..=at]);
        buf.extend_from_slice(b"    ");
        rest = &rest[at + 1..];
    }
    buf.extend_from_slice(rest);
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::collections::BTreeMap;

    #[derive(Serialize, Clone)]
    struct Row {
        id: String,
        at: [f64; 3],
        tags: Vec<String>,
        nested: BTreeMap<String, Vec<u32>>,
        none: Option<u8>,
    }

    #[derive(Serialize)]
    struct Doc {
        name: String,
        rows: Vec<Row>,
        empty_map: BTreeMap<String, u8>,
        others: Vec<u32>,
        notes: Vec<String>,
    }

    fn row(k: usize) -> Row {
        Row {
            id: format!("r{k} \"quoted\"\n line"),
            at: [k as f64 * 0.1, -1.5e-9, 3.0],
            tags: (0..k % 3).map(|t| format!("t{t}")).collect(),
            nested: (0..k % 2)
                .map(|n| (format!("k{n}"), vec![n as u32; k % 4]))
                .collect(),
            none: None,
        }
    }

    fn check(rows: usize, others: usize) {
        let doc = Doc {
            name: "a \"members\": [] inside a string".into(),
            rows: (0..rows).map(row).collect(),
            empty_map: BTreeMap::new(),
            others: (0..others as u32).collect(),
            // A note that looks like a key of the skeleton cannot be taken for it: its
            // quotes are escaped.
            notes: vec!["\n  \"rows\": []".into()],
        };
        let mut expected = serde_json::to_vec_pretty(&doc).unwrap();
        expected.push(b'\n');
        let skeleton = Doc {
            rows: Vec::new(),
            others: Vec::new(),
            name: doc.name.clone(),
            empty_map: BTreeMap::new(),
            notes: doc.notes.clone(),
        };
        let mut got = Vec::new();
        write_pretty(
            &mut got,
            &skeleton,
            (
                Array {
                    key: "rows",
                    items: &doc.rows,
                },
                Array {
                    key: "others",
                    items: &doc.others,
                },
            ),
        )
        .unwrap();
        assert_eq!(
            String::from_utf8(got).unwrap(),
            String::from_utf8(expected).unwrap(),
            "{rows} rows, {others} others"
        );
    }

    #[test]
    fn equals_serde_json_pretty_for_any_array_sizes() {
        for (rows, others) in [(0, 0), (1, 0), (0, 1), (2, 3), (PER_TASK + 1, 5)] {
            check(rows, others);
        }
        check(PER_BATCH * 2 + 3, PER_TASK * 3);
    }

    #[test]
    fn a_key_missing_from_the_skeleton_is_an_error_not_a_wrong_document() {
        let mut out = Vec::new();
        let err = write_pretty(
            &mut out,
            &BTreeMap::from([("rows", Vec::<u8>::new())]),
            (
                Array {
                    key: "rows",
                    items: &[1u8],
                },
                Array {
                    key: "absent",
                    items: &[2u8],
                },
            ),
        )
        .unwrap_err();
        assert!(err.to_string().contains("\"absent\""), "{err}");
        assert!(out.is_empty());
    }
}
