//! `match` patterns read as Soufflé's C++ std::regex (libstdc++, ECMAScript grammar) reads
//! them, over bytes, the whole text matched. Each answer is worked out by hand from that
//! grammar (comments); the refused ones are valid in std::regex but cannot be reproduced.

use framewright::logic::std_regex::{PatternError, StdRegex};

fn matches(pattern: &str, text: &str) -> bool {
    StdRegex::new(pattern)
        .unwrap_or_else(|e| panic!("{pattern:?}: {e}"))
        .is_full_match(text)
}

fn invalid(pattern: &str) -> bool {
    matches!(StdRegex::new(pattern), Err(PatternError::Invalid(_)))
}

fn unsupported(pattern: &str) -> bool {
    matches!(StdRegex::new(pattern), Err(PatternError::Unsupported(_)))
}

#[test]
fn the_whole_text_must_match() {
    assert!(matches("a.*c", "abc"));
    assert!(!matches("b", "abc"));
    // Alternatives are tried until one spans the text: `a|ab` matches "ab" whole.
    assert!(matches("a|ab", "ab"));
    assert!(matches("", ""));
    assert!(!matches("", "a"));
}

#[test]
fn ecmascript_features_std_regex_has() {
    assert!(matches("(a|b)\\1", "bb") && !matches("(a|b)\\1", "ab"));
    assert!(matches("(?:ab)+", "abab"));
    assert!(matches("a(?!b)c", "ac") && !matches("a(?!b).", "ab"));
    assert!(matches("a+?b", "aab"));
    assert!(matches("a{2,3}", "aaa") && !matches("a{2,3}", "aaaa"));
    // Quantifiers may follow each other in libstdc++: `a**` is `(a*)*`.
    assert!(matches("a**", "aaa"));
    assert!(matches("\\bab\\b", "ab"));
    assert!(matches("[\\d.]+", "1.5"));
    assert!(matches("\\w+\\s\\W", "ab -"));
}

#[test]
fn posix_class_names_inside_brackets() {
    assert!(matches("[[:alpha:]]+", "abcXYZ"));
    assert!(!matches("[[:alpha:]]", "1"));
    // Names are read in lower case; the "C" locale's classes are ASCII.
    assert!(matches("[[:UPPER:][:digit:]_]+", "A1_"));
    assert!(matches("[^[:space:]]+", "a,b"));
    assert!(matches("[[:punct:]]", "!") && !matches("[[:punct:]]", "a"));
    assert!(invalid("[[:letter:]]"));
}

#[test]
fn bytes_not_characters() {
    // é is the two bytes C3 A9.
    assert!(!matches(".", "é"));
    assert!(matches("..", "é"));
    // `é+` repeats its last byte only: C3 A9+, not "éé".
    assert!(!matches("é+", "éé") && matches("(?:é)+", "éé"));
    // `[^a]` is one byte: it cannot match both bytes of é.
    assert!(!matches("[^a]", "é"));
    // \s is C's isspace: the byte A0 (inside à, C3 A0) is no space.
    assert!(matches("\\S+", "à"));
    // \u0041 keeps its low byte.
    assert!(matches("\\u0141", "A"));
}

#[test]
fn escapes_as_libstdcxx_reads_them() {
    // An unknown escape is the character itself: `\p` is "p", `\k` is "k".
    assert!(matches("\\pL", "pL") && !matches("\\pL", "x"));
    // `\cJ` is "J" (libstdc++ does not make the control character).
    assert!(matches("\\cJ", "J") && !matches("\\cJ", "\n"));
    assert!(matches("\\x41\\t\\0", "A\t\0"));
    // Inside brackets `\b` is a backspace.
    assert!(matches("[\\b]", "\u{8}"));
    // `.` is any byte but \n and \r.
    assert!(!matches(".", "\n") && !matches(".", "\r") && matches(".", "\t"));
}

#[test]
fn patterns_std_regex_refuses() {
    for p in [
        "(",
        "a)",
        "(?i)x",
        "(?<n>a)",
        "(?<=a)b",
        "a{",
        "a{,2}",
        "a{3,1}",
        "*a",
        "a|*",
        "^*",
        "(?=a)*",
        "\\",
        "[a",
        "[z-a]",
        "[a-\\d]",
        "[\\d-z]",
        // Bytes compare as signed chars: 0xff comes before 'a'.
        "[a-\\xff]",
        "\\1(a)",
        "(a\\1)",
        "\\x4",
        "[\\1]",
    ] {
        assert!(invalid(p), "{p:?} should be invalid");
    }
}

#[test]
fn valid_patterns_whose_meaning_cannot_be_reproduced() {
    for p in [
        // std::regex fails a back-reference to a group that did not take part; JavaScript
        // matches the empty string there.
        "(a)?b\\1",
        "(?:(a)|b)\\1",
        "(a)*\\1",
        // In a lookahead std::regex restarts: `^` holds where the lookahead starts.
        "a(?=^b)b",
        "(?=\\bx)x",
        "[[.a.]]",
        "[[=a=]]",
        // regress 0.12 does not end on these.
        "(?:a?)++",
        "a?{1}*",
    ] {
        assert!(unsupported(p), "{p:?} should be refused as unsupported");
    }
    // A group that always takes part before its back-reference is fine.
    assert!(matches("((a)|b)c\\1", "aca"));
    assert!(matches("(a)(?:x|\\1)", "aa"));
}
