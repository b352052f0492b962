//! Decoding of entity parameters with nom. Called on demand for the byte
//! range the index recorded, so untouched entities cost nothing.

use super::error::StepErrorKind;
use nom::{
    IResult, Parser,
    branch::alt,
    bytes::complete::{tag, take_while, take_while1},
    character::complete::{char, digit1, one_of},
    combinator::{opt, recognize},
    error::{ErrorKind, ParseError},
    sequence::{delimited, pair},
};
use std::borrow::Cow;

/// One parameter value of an entity instance.
#[derive(Debug, Clone, PartialEq)]
pub enum Param<'a> {
    /// `$`: the value is not given.
    Null,
    /// `*`: the value is derived (redeclared attribute).
    Derived,
    Int(i64),
    Real(f64),
    /// The raw bytes between the quotes; see [`Param::text`].
    Str(&'a [u8]),
    /// `.NAME.` without the dots.
    Enum(&'a str),
    Ref(u64),
    /// `"..."` hex-encoded binary, without the quotes.
    Binary(&'a [u8]),
    List(Vec<Param<'a>>),
    /// A typed value such as `IFCLENGTHMEASURE(1.)`.
    Typed(&'a str, Box<Param<'a>>),
}

impl<'a> Param<'a> {
    /// Numeric value of `Int`, `Real` or a typed number such as `IFCREAL(1.)`.
    pub fn as_f64(&self) -> Option<f64> {
        match self {
            Param::Int(i) => Some(*i as f64),
            Param::Real(r) => Some(*r),
            Param::Typed(_, inner) => inner.as_f64(),
            _ => None,
        }
    }

    pub fn as_ref_id(&self) -> Option<u64> {
        match self {
            Param::Ref(id) => Some(*id),
            _ => None,
        }
    }

    pub fn as_list(&self) -> Option<&[Param<'a>]> {
        match self {
            Param::List(items) => Some(items),
            _ => None,
        }
    }

    pub fn as_enum(&self) -> Option<&'a str> {
        match self {
            Param::Enum(e) => Some(e),
            _ => None,
        }
    }

    /// Decoded text of a string (or of a typed string such as `IFCLABEL('x')`).
    /// The flag is true when invalid bytes were replaced.
    pub fn text(&self) -> Option<(Cow<'a, str>, bool)> {
        match self {
            Param::Str(raw) => Some(super::strings::decode_step_string(raw)),
            Param::Typed(_, inner) => inner.text(),
            _ => None,
        }
    }

    pub fn is_null(&self) -> bool {
        matches!(self, Param::Null | Param::Derived)
    }
}

/// A decoded entity instance.
#[derive(Debug, Clone)]
pub struct Entity<'a> {
    pub id: u64,
    /// Upper-case type name, e.g. `IFCCOLUMN`.
    pub type_name: &'a str,
    pub params: Vec<Param<'a>>,
}

impl<'a> Entity<'a> {
    /// The `i`-th parameter; `Null` when the instance has fewer.
    pub fn get(&self, i: usize) -> &Param<'a> {
        self.params.get(i).unwrap_or(&Param::Null)
    }
}

type Res<'a, T> = IResult<&'a [u8], T, DepthError<'a>>;

/// nom error that can also say "nested too deep".
#[derive(Debug)]
pub(crate) struct DepthError<'a> {
    pub input: &'a [u8],
    pub too_deep: bool,
}

impl<'a> ParseError<&'a [u8]> for DepthError<'a> {
    fn from_error_kind(input: &'a [u8], _kind: ErrorKind) -> Self {
        DepthError {
            input,
            too_deep: false,
        }
    }
    fn append(_input: &'a [u8], _kind: ErrorKind, other: Self) -> Self {
        other
    }
}

/// Skips white space (including CR-only line ends) and `/* */` comments.
pub(crate) fn skip_ws(mut input: &[u8]) -> &[u8] {
    loop {
        let trimmed = input.trim_ascii_start();
        if let Some(rest) = trimmed.strip_prefix(b"/*") {
            input = match memchr::memmem::find(rest, b"*/") {
                Some(end) => &rest[end + 2..],
                None => &rest[rest.len()..],
            };
        } else {
            return trimmed;
        }
    }
}

fn ws<'a, O>(
    inner: impl Parser<&'a [u8], Output = O, Error = DepthError<'a>>,
) -> impl Parser<&'a [u8], Output = O, Error = DepthError<'a>> {
    delimited(|i| Ok((skip_ws(i), ())), inner, |i| Ok((skip_ws(i), ())))
}

pub(crate) fn keyword(input: &[u8]) -> Res<'_, &str> {
    let (rest, word) = recognize(pair(
        take_while1(|c: u8| c.is_ascii_alphabetic() || c == b'_'),
        take_while(|c: u8| c.is_ascii_alphanumeric() || c == b'_' || c == b'-'),
    ))
    .parse(input)?;
    // Only ASCII bytes were accepted above.
    Ok((rest, std::str::from_utf8(word).unwrap_or_default()))
}

fn number(input: &[u8]) -> Res<'_, Param<'_>> {
    let (rest, text) = recognize((
        opt(one_of("+-")),
        digit1,
        opt(pair(char('.'), take_while(|c: u8| c.is_ascii_digit()))),
        opt((one_of("eE"), opt(one_of("+-")), digit1)),
    ))
    .parse(input)?;
    let text = std::str::from_utf8(text).unwrap_or_default();
    let is_real = text.contains(['.', 'e', 'E']);
    let value = if is_real {
        text.parse::<f64>().ok().map(Param::Real)
    } else {
        text.parse::<i64>()
            .ok()
            .map(Param::Int)
            .or_else(|| text.parse::<f64>().ok().map(Param::Real))
    };
    match value {
        Some(v) => Ok((rest, v)),
        None => Err(nom::Err::Failure(DepthError {
            input,
            too_deep: false,
        })),
    }
}

/// The bytes of a string literal between its quotes (`''` stays doubled).
fn string(input: &[u8]) -> Res<'_, &[u8]> {
    let (body, _) = char('\'').parse(input)?;
    match super::strings::string_end(body) {
        Some(end) => Ok((&body[end + 1..], &body[..end])),
        None => Err(nom::Err::Failure(DepthError {
            input,
            too_deep: false,
        })),
    }
}

fn reference(input: &[u8]) -> Res<'_, u64> {
    let (rest, digits) = nom::sequence::preceded(char('#'), digit1).parse(input)?;
    match std::str::from_utf8(digits)
        .ok()
        .and_then(|d| d.parse().ok())
    {
        Some(id) => Ok((rest, id)),
        None => Err(nom::Err::Failure(DepthError {
            input,
            too_deep: false,
        })),
    }
}

fn enumeration(input: &[u8]) -> Res<'_, &str> {
    delimited(char('.'), keyword, char('.')).parse(input)
}

fn binary(input: &[u8]) -> Res<'_, &[u8]> {
    delimited(
        char('"'),
        take_while(|c: u8| c.is_ascii_hexdigit()),
        char('"'),
    )
    .parse(input)
}

fn param(input: &[u8], depth: usize, max_depth: usize) -> Res<'_, Param<'_>> {
    let input = skip_ws(input);
    let (rest, value) = match input.first() {
        Some(b'$') => (&input[1..], Param::Null),
        Some(b'*') => (&input[1..], Param::Derived),
        Some(b'#') => {
            let (r, id) = reference(input)?;
            (r, Param::Ref(id))
        }
        Some(b'\'') => {
            let (r, s) = string(input)?;
            (r, Param::Str(s))
        }
        Some(b'.') => {
            let (r, e) = enumeration(input)?;
            (r, Param::Enum(e))
        }
        Some(b'"') => {
            let (r, b) = binary(input)?;
            (r, Param::Binary(b))
        }
        Some(b'(') => {
            let (r, items) = list(input, depth + 1, max_depth)?;
            (r, Param::List(items))
        }
        Some(c) if c.is_ascii_alphabetic() => {
            let (r, name) = keyword(input)?;
            let (r, mut items) = list(skip_ws(r), depth + 1, max_depth)?;
            let inner = if items.len() == 1 {
                items.pop().unwrap_or(Param::Null)
            } else {
                Param::List(items)
            };
            (r, Param::Typed(name, Box::new(inner)))
        }
        _ => number(input)?,
    };
    Ok((skip_ws(rest), value))
}

/// `( p, p, ... )` with a depth guard against stack exhaustion.
pub(crate) fn list(input: &[u8], depth: usize, max_depth: usize) -> Res<'_, Vec<Param<'_>>> {
    if depth > max_depth {
        return Err(nom::Err::Failure(DepthError {
            input,
            too_deep: true,
        }));
    }
    let (mut rest, _) = ws(char('(')).parse(input)?;
    let mut items = Vec::new();
    if let Ok((r, _)) = char::<_, DepthError>(')').parse(rest) {
        return Ok((r, items));
    }
    loop {
        let (r, item) = param(rest, depth, max_depth)?;
        items.push(item);
        let (r, sep) = alt((tag(&b","[..]), tag(&b")"[..]))).parse(r)?;
        rest = r;
        if sep == b")" {
            return Ok((rest, items));
        }
    }
}

/// Decodes a parenthesised parameter list; on failure returns the byte
/// offset (relative to `input`) and what went wrong.
pub(crate) fn decode_list(
    input: &[u8],
    max_depth: usize,
) -> Result<Vec<Param<'_>>, (usize, StepErrorKind)> {
    match list(input, 0, max_depth) {
        Ok((rest, items)) if skip_ws(rest).is_empty() => Ok(items),
        Ok((rest, _)) => Err((
            input.len() - rest.len(),
            StepErrorKind::Syntax("unexpected text after the parameter list".into()),
        )),
        Err(nom::Err::Error(e) | nom::Err::Failure(e)) => {
            let at = input.len() - e.input.len();
            let kind = if e.too_deep {
                StepErrorKind::TooDeep { limit: max_depth }
            } else {
                StepErrorKind::Syntax(format!("cannot read a parameter at `{}`", snippet(e.input)))
            };
            Err((at, kind))
        }
        Err(nom::Err::Incomplete(_)) => Err((
            input.len(),
            StepErrorKind::Syntax("incomplete parameter list".into()),
        )),
    }
}

/// A short printable excerpt for error messages.
pub(crate) fn snippet(bytes: &[u8]) -> String {
    let cut = &bytes[..bytes.len().min(24)];
    String::from_utf8_lossy(cut).replace(['\r', '\n'], " ")
}

#[cfg(test)]
mod tests {
    use super::*;

    fn decode(s: &str) -> Vec<Param<'_>> {
        decode_list(s.as_bytes(), 64).unwrap()
    }

    #[test]
    fn all_kinds() {
        let p = decode("('a''b',$,*,#12,.T.,1.5E-1,-3,(1.,2.),IFCLENGTHMEASURE(2.),\"0FF\",())");
        assert_eq!(p[0], Param::Str(b"a''b"));
        assert_eq!(p[0].text().unwrap().0, "a'b");
        assert_eq!(p[1], Param::Null);
        assert_eq!(p[2], Param::Derived);
        assert_eq!(p[3], Param::Ref(12));
        assert_eq!(p[4], Param::Enum("T"));
        assert_eq!(p[5], Param::Real(0.15));
        assert_eq!(p[6], Param::Int(-3));
        assert_eq!(p[7], Param::List(vec![Param::Real(1.0), Param::Real(2.0)]));
        assert_eq!(p[8].as_f64(), Some(2.0));
        assert_eq!(p[9], Param::Binary(b"0FF"));
        assert_eq!(p[10], Param::List(vec![]));
    }

    #[test]
    fn whitespace_and_comments() {
        let p = decode("( #1 ,\r /* note */ 'x;y' ,\n 2. )");
        assert_eq!(p.len(), 3);
        assert_eq!(p[1], Param::Str(b"x;y"));
    }

    #[test]
    fn depth_is_bounded() {
        let deep = format!("{}{}", "(".repeat(200), ")".repeat(200));
        let err = decode_list(deep.as_bytes(), 64).unwrap_err();
        assert!(matches!(err.1, StepErrorKind::TooDeep { .. }));
    }

    #[test]
    fn garbage_is_an_error() {
        assert!(decode_list(b"(1,,2)", 64).is_err());
        assert!(decode_list(b"(1 2)", 64).is_err());
        assert!(decode_list(b"('open)", 64).is_err());
    }
}
