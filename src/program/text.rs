//! Text a robot program can carry safely: comments from names a model may hold (quotes, `!`,
//! `;`, line breaks, any script), numbers in a fixed form, and generated identifiers.

/// `text` as one comment line: control characters (line breaks included) become spaces and
/// everything outside printable ASCII becomes `<U+XXXX>`, so that no name can end the comment,
/// start a statement or trip a controller's character set.
pub fn comment_text(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    for c in text.chars() {
        match c {
            ' '..='~' => out.push(c),
            c if c.is_control() => out.push(' '),
            c => out.push_str(&format!("<U+{:04X}>", c as u32)),
        }
    }
    out
}

/// `value` with `decimals` digits after the point, without a sign on zero ("-0.000" is
/// "0.000") and without trailing zeros past the first decimal.
pub fn num(value: f64, decimals: usize) -> String {
    let text = format!("{value:.decimals$}");
    let text = if text
        .trim_start_matches('-')
        .chars()
        .all(|c| c == '0' || c == '.')
    {
        text.trim_start_matches('-').to_string()
    } else {
        text
    };
    match text.find('.') {
        Some(dot) => {
            let trimmed = text.trim_end_matches('0');
            if trimmed.len() == dot + 1 {
                format!("{trimmed}0")
            } else {
                trimmed.to_string()
            }
        }
        None => text,
    }
}

/// An identifier from `prefix` and `text`: letters and digits kept, anything else `_`, cut to
/// `max` characters.
pub fn identifier(prefix: &str, text: &str, max: usize) -> String {
    let mut out = prefix.to_string();
    for c in text.chars() {
        out.push(if c.is_ascii_alphanumeric() { c } else { '_' });
    }
    out.chars().take(max).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hostile_names_become_one_plain_line() {
        assert_eq!(
            comment_text("a\"b!c;d\ne\r\tf é 名"),
            "a\"b!c;d e  f <U+00E9> <U+540D>"
        );
    }

    #[test]
    fn numbers_are_fixed_and_unsigned_at_zero() {
        assert_eq!(num(-0.0000001, 3), "0.0");
        assert_eq!(num(12.5, 3), "12.5");
        assert_eq!(num(-3.0, 4), "-3.0");
        assert_eq!(num(1.23456, 3), "1.235");
    }

    #[test]
    fn identifiers_keep_letters_and_digits() {
        assert_eq!(identifier("fw_", "W1-P2", 24), "fw_W1_P2");
        assert_eq!(identifier("fw_", "Wé", 24), "fw_W_");
        assert_eq!(identifier("fw_", &"x".repeat(40), 24).len(), 24);
    }
}
