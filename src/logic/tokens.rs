//! One scanner for rule-language text as the explanations rewrite it: identifiers, numbers,
//! quoted strings and the characters between them. `provenance` puts values in place of
//! variables, `explain` shortens long numbers; both rebuild the text token by token.

/// What a token is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Kind {
    /// A name: a letter or `_`, then letters, digits, `_` or `?`, not glued to a name before it.
    Ident,
    /// A number: digits (after a `-` that starts it), `.`, an exponent; not glued to a name.
    Number,
    /// A string in double quotes (`\"` inside does not end it), quotes included.
    Quoted,
    /// Any other character.
    Other,
}

/// `text` rebuilt with `map` applied to each token (its kind, its text, the character after
/// it); a token `map` returns None for stays as it was.
pub fn map_tokens(
    text: &str,
    mut map: impl FnMut(Kind, &str, Option<char>) -> Option<String>,
) -> String {
    let chars: Vec<(usize, char)> = text.char_indices().collect();
    let at = |k: usize| chars.get(k).map(|&(_, c)| c);
    let byte = |k: usize| chars.get(k).map_or(text.len(), |&(b, _)| b);
    let glued = |k: usize, extra: &[char]| {
        k > 0 && at(k - 1).is_some_and(|p| p.is_alphanumeric() || p == '_' || extra.contains(&p))
    };
    let mut out = String::with_capacity(text.len());
    let mut i = 0;
    while let Some(c) = at(i) {
        let (kind, end) = if c == '"' {
            let mut j = i + 1;
            while let Some(d) = at(j) {
                j += 1;
                if d == '"' && at(j - 2) != Some('\\') {
                    break;
                }
            }
            (Kind::Quoted, j)
        } else if (c.is_alphabetic() || c == '_') && !glued(i, &['@']) {
            let mut j = i + 1;
            while at(j).is_some_and(|d| d.is_alphanumeric() || d == '_' || d == '?') {
                j += 1;
            }
            (Kind::Ident, j)
        } else if (c.is_ascii_digit()
            || (c == '-' && at(i + 1).is_some_and(|d| d.is_ascii_digit())))
            && !glued(i, &[])
        {
            let mut j = i + 1;
            while at(j).is_some_and(|d| {
                d.is_ascii_digit()
                    || d == '.'
                    || d == 'e'
                    || ((d == '-' || d == '+') && at(j - 1) == Some('e'))
            }) {
                j += 1;
            }
            (Kind::Number, j)
        } else {
            (Kind::Other, i + 1)
        };
        let token = &text[byte(i)..byte(end)];
        match map(kind, token, at(end)) {
            Some(replaced) => out.push_str(&replaced),
            None => out.push_str(token),
        }
        i = end;
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn kinds(text: &str) -> Vec<(Kind, String)> {
        let mut seen = Vec::new();
        map_tokens(text, |k, t, _| {
            seen.push((k, t.to_string()));
            None
        });
        seen.retain(|(k, _)| *k != Kind::Other);
        seen
    }

    #[test]
    fn tokens_rebuild_the_text_and_tell_names_from_numbers_and_strings() {
        for text in [
            "p_2(-1e-17, 12)",
            "x(0.1, \"a \\\" b\", y?)",
            "é1 + @f(x)",
            "",
            "\"open",
        ] {
            assert_eq!(map_tokens(text, |_, _, _| None), text);
        }
        assert_eq!(
            kinds("p_2(-1e-17, x1.5, \"a, 2\") @f"),
            vec![
                (Kind::Ident, "p_2".into()),
                (Kind::Number, "-1e-17".into()),
                (Kind::Ident, "x1".into()),
                (Kind::Number, "5".into()),
                (Kind::Quoted, "\"a, 2\"".into()),
            ]
        );
        // A name after `@` is a functor's, not a variable.
        assert_eq!(kinds("@f"), vec![]);
    }
}
