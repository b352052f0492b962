//! Characters that XML 1.0 forbids even as references, and that HTML parses as errors:
//! C0 controls other than tab, line feed and carriage return, DEL, the C1 controls and
//! U+FFFE/U+FFFF. Model names may hold them (a STEP `\X\01`, a bad export); the page, the
//! SVG drawings and the BCF documents show U+FFFD instead, so every reader parses them.

/// Whether `c` may stand in an XML 1.0 document and in HTML text without a parse error.
fn allowed(c: char) -> bool {
    !matches!(c, '\0'..='\x08' | '\x0b' | '\x0c' | '\x0e'..='\x1f' | '\x7f'..='\u{9f}' | '\u{fffe}' | '\u{ffff}')
}

/// `text` with every forbidden character replaced by U+FFFD (unchanged when there is none).
/// The templates themselves never hold one, so this only touches text from the model.
pub fn replace_forbidden(text: String) -> String {
    if text.chars().all(allowed) {
        return text;
    }
    text.chars()
        .map(|c| {
            if allowed(c) {
                c
            } else {
                char::REPLACEMENT_CHARACTER
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn controls_become_replacement_characters_and_the_rest_stays() {
        let s = "a\tb\nc\rd\u{1}e\u{1b}f\u{7f}g\u{85}h\u{fffe}i\u{202e}j<&>".to_string();
        assert_eq!(
            replace_forbidden(s),
            "a\tb\nc\rd\u{fffd}e\u{fffd}f\u{fffd}g\u{fffd}h\u{fffd}i\u{202e}j<&>"
        );
    }
}
