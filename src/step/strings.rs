//! Decoding of STEP string literals (ISO 10303-21 §6.4.3): `''`, `\\`,
//! `\S\`, `\P?\`, `\X\hh`, `\X2\…\X0\` (UTF-16) and `\X4\…\X0\` (UTF-32).
//!
//! Raw non-ASCII bytes are not allowed by the standard but many tools write
//! UTF-8 directly: valid UTF-8 is kept, anything else becomes U+FFFD and the
//! caller is told (so it can warn with the entity id).

use std::borrow::Cow;

/// Offset of the quote that closes a string, in `body` (the bytes after the
/// opening quote). `''` is an escaped quote; so is the byte after `\S\`,
/// which some exporters leave undoubled when it is a quote.
pub(crate) fn string_end(body: &[u8]) -> Option<usize> {
    let mut at = 0;
    loop {
        let i = at + memchr::memchr2(b'\'', b'\\', &body[at..])?;
        if body[i] == b'\'' {
            if body.get(i + 1) == Some(&b'\'') {
                at = i + 2;
                continue;
            }
            return Some(i);
        }
        at = match body.get(i + 1..i + 3) {
            Some(b"S\\") => i + 4,
            _ if body.get(i + 1) == Some(&b'\\') => i + 2,
            _ => i + 1,
        };
        if at > body.len() {
            return None;
        }
    }
}

/// Decodes the bytes between the quotes of a STEP string.
/// Returns the text and whether invalid bytes had to be replaced.
pub fn decode_step_string(raw: &[u8]) -> (Cow<'_, str>, bool) {
    if raw
        .iter()
        .all(|&b| b.is_ascii() && b != b'\\' && b != b'\'')
    {
        // SAFETY-free fast path: ASCII is valid UTF-8.
        return (
            Cow::Borrowed(std::str::from_utf8(raw).unwrap_or_default()),
            false,
        );
    }
    let mut out = String::with_capacity(raw.len());
    let mut lossy = false;
    let mut i = 0;
    while i < raw.len() {
        let b = raw[i];
        match b {
            b'\'' => {
                // `''` is one quote; a lone quote cannot occur inside a scanned string.
                out.push('\'');
                i += if raw.get(i + 1) == Some(&b'\'') { 2 } else { 1 };
            }
            b'\\' => i = decode_escape(raw, i, &mut out),
            0x00..=0x7f => {
                out.push(b as char);
                i += 1;
            }
            _ => {
                // Raw non-ASCII: take the longest valid UTF-8 run.
                let end = raw[i..]
                    .iter()
                    .position(|&c| c.is_ascii())
                    .map_or(raw.len(), |p| i + p);
                let chunk = String::from_utf8_lossy(&raw[i..end]);
                lossy |= matches!(chunk, Cow::Owned(_)) && chunk.contains('\u{FFFD}');
                out.push_str(&chunk);
                i = end;
            }
        }
    }
    (Cow::Owned(out), lossy)
}

/// Decodes one escape starting at `raw[i] == b'\\'`; returns the next index.
/// A malformed escape is kept literally (the text stays readable).
fn decode_escape(raw: &[u8], i: usize, out: &mut String) -> usize {
    let rest = &raw[i..];
    if rest.starts_with(b"\\\\") {
        out.push('\\');
        return i + 2;
    }
    if rest.len() >= 4 && rest.starts_with(b"\\S\\") {
        out.push(char::from(rest[3].wrapping_add(128)));
        return i + 4;
    }
    if rest.len() >= 4 && rest.starts_with(b"\\P") && rest[3] == b'\\' {
        // Code page switch: pages other than A (Latin-1) are mapped as Latin-1.
        return i + 4;
    }
    if rest.starts_with(b"\\X\\")
        && let Some(v) = rest.get(3..5).and_then(hex_value)
    {
        out.push(char::from(v as u8));
        return i + 5;
    }
    for (escape, width) in [(&b"\\X2\\"[..], 4), (&b"\\X4\\"[..], 8)] {
        if rest.starts_with(escape)
            && let Some((text, used)) = decode_wide(&rest[4..], width)
        {
            out.push_str(&text);
            return i + 4 + used;
        }
    }
    out.push('\\');
    i + 1
}

/// Decodes hex groups of `width` digits up to `\X0\`; returns text and bytes used.
fn decode_wide(rest: &[u8], width: usize) -> Option<(String, usize)> {
    let end = rest.windows(4).position(|w| w == b"\\X0\\")?;
    let digits = &rest[..end];
    if !digits.len().is_multiple_of(width) {
        return None;
    }
    let units = digits
        .chunks(width)
        .map(hex_value)
        .collect::<Option<Vec<u32>>>()?;
    let text = if width == 4 {
        let utf16: Vec<u16> = units.iter().map(|&u| u as u16).collect();
        String::from_utf16_lossy(&utf16)
    } else {
        units
            .iter()
            .map(|&u| char::from_u32(u).unwrap_or('\u{FFFD}'))
            .collect()
    };
    Some((text, end + 4))
}

fn hex_value(digits: &[u8]) -> Option<u32> {
    let text = std::str::from_utf8(digits).ok()?;
    u32::from_str_radix(text, 16).ok()
}

#[cfg(test)]
mod tests {
    use super::decode_step_string as d;

    #[test]
    fn plain_and_quotes() {
        assert_eq!(d(b"Stud 2x4").0, "Stud 2x4");
        assert_eq!(d(b"it''s").0, "it's");
        assert_eq!(d(b"C:\\\\DEV").0, "C:\\DEV");
    }

    #[test]
    fn escapes() {
        assert_eq!(d(b"Gr\\X\\FC\\X\\DFe").0, "Grüße");
        assert_eq!(d(b"\\X2\\30D730ED\\X0\\").0, "プロ");
        assert_eq!(d(b"\\X4\\0001F600\\X0\\").0, "😀");
        assert_eq!(d(b"\\S\\|").0, "ü");
        assert_eq!(d(b"\\PA\\x").0, "x");
        // UTF-16 surrogate pair through \X2\.
        assert_eq!(d(b"\\X2\\D83DDE00\\X0\\").0, "😀");
    }

    #[test]
    fn malformed_escape_is_kept() {
        assert_eq!(d(b"a\\X2\\12").0, "a\\X2\\12");
    }

    #[test]
    fn string_ends() {
        use super::string_end as e;
        assert_eq!(e(b"abc',"), Some(3));
        assert_eq!(e(b"a''b'"), Some(4));
        assert_eq!(e(b"a\\S\\'b'"), Some(6));
        assert_eq!(e(b"a\\\\'"), Some(3));
        assert_eq!(e(b"open"), None);
        assert_eq!(e(b"x\\S\\"), None);
    }

    #[test]
    fn raw_bytes() {
        assert_eq!(d("Fläche".as_bytes()), ("Fläche".into(), false));
        let (text, lossy) = d(b"A\xff\xfe\xc3(B");
        assert!(lossy);
        assert!(text.starts_with('A') && text.ends_with("(B"));
    }
}
