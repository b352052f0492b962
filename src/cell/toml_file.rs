//! Reading TOML files with errors that point at `file:line:column` and the offending key.

use super::error::CellError;
use serde::de::DeserializeOwned;
use std::path::Path;

/// Parse `text` (the contents of `path`) into `T`; syntax and schema errors carry line:column.
pub fn parse<T: DeserializeOwned>(path: &Path, text: &str) -> Result<T, CellError> {
    toml::from_str(text).map_err(|err| {
        let (line, column) = err
            .span()
            .map(|span| line_col(text, span.start))
            .unwrap_or((1, 1));
        let message = err.message().trim();
        CellError::Toml {
            path: path.to_path_buf(),
            line,
            column,
            message: match key_at(text, line) {
                Some(key) => format!("key `{key}`: {message}"),
                None => message.to_string(),
            },
        }
    })
}

/// The dotted key written on 1-based `line` (`section.key`), if that line is `key = value`.
fn key_at(text: &str, line: usize) -> Option<String> {
    let lines: Vec<&str> = text.lines().collect();
    let here = lines.get(line.checked_sub(1)?)?.trim();
    let (key, _) = here.split_once('=')?;
    let key = key.trim();
    if key.is_empty() || key.starts_with('#') || key.starts_with('[') {
        return None;
    }
    let section = lines[..line - 1]
        .iter()
        .rev()
        .map(|l| l.trim())
        .find(|l| l.starts_with('['))
        .map(|l| l.trim_matches(|c| c == '[' || c == ']').trim().to_string());
    Some(match section {
        Some(s) if !s.is_empty() => format!("{s}.{key}"),
        _ => key.to_string(),
    })
}

/// 1-based line and column of byte `offset` in `text`.
pub fn line_col(text: &str, offset: usize) -> (usize, usize) {
    let offset = offset.min(text.len());
    let before = &text[..offset];
    let line = before.matches('\n').count() + 1;
    let column = before.rsplit('\n').next().map_or(0, |s| s.chars().count()) + 1;
    (line, column)
}

/// Line of `key` inside `[section]` (or at top level when `section` is empty), for errors about
/// values that parsed but are not acceptable. Falls back to the section header, then line 1.
pub fn key_line(text: &str, section: &str, key: &str) -> usize {
    let mut in_section = section.is_empty();
    let mut section_line = None;
    for (i, raw) in text.lines().enumerate() {
        let line = raw.trim();
        if line.starts_with('[') {
            let name = line
                .trim_start_matches('[')
                .split(']')
                .next()
                .unwrap_or("")
                .trim();
            in_section = name == section;
            if in_section {
                section_line = Some(i + 1);
            }
            continue;
        }
        if in_section
            && let Some(rest) = line.strip_prefix(key)
            && rest.trim_start().starts_with('=')
        {
            return i + 1;
        }
    }
    section_line.unwrap_or(1)
}

/// A value error at `section.key` of the file.
pub fn value_error(
    path: &Path,
    text: &str,
    section: &str,
    key: &str,
    message: impl Into<String>,
) -> CellError {
    let full_key = if section.is_empty() {
        key.to_string()
    } else {
        format!("{section}.{key}")
    };
    CellError::Value {
        path: path.to_path_buf(),
        line: key_line(text, section, key),
        key: full_key,
        message: message.into(),
    }
}
