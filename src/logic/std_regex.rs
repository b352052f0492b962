//! `match(pattern, text)` as Soufflé computes it: `std::regex_match(text, std::regex(pattern))`,
//! that is C++'s ECMAScript grammar as libstdc++ reads it, over bytes, in the "C" locale, the
//! whole text matched. The pattern is parsed here by that grammar and written out for the
//! `regress` crate (JavaScript's grammar, every byte one character), so that both mean the
//! same: each literal byte as `\xHH`, each class as the explicit set of bytes libstdc++ gives it.
//! A pattern libstdc++ refuses is refused; so is one whose meaning `regress` cannot reproduce
//! (`PatternError::Unsupported`, listed in docs/RULES-LANGUAGE.md).

use std::fmt::Write as _;

/// Why a pattern is not matched.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum PatternError {
    /// std::regex throws `regex_error` for it.
    #[error("not a regular expression (C++ std::regex, ECMAScript grammar): {0}")]
    Invalid(String),
    /// std::regex accepts it, but what it means there cannot be reproduced here.
    #[error("not supported: {0}")]
    Unsupported(String),
}

/// A compiled `match` pattern.
pub struct StdRegex {
    re: regress::Regex,
}

impl StdRegex {
    pub fn new(pattern: &str) -> Result<StdRegex, PatternError> {
        let js = translate(pattern.as_bytes())?;
        let re = regress::Regex::from_unicode(js.chars().map(u32::from), regress::Flags::default())
            .map_err(|e| {
                PatternError::Unsupported(format!("its rewriting {js:?} was refused ({e})"))
            })?;
        Ok(StdRegex { re })
    }

    /// Whether the whole of `text` matches (the pattern is anchored at both ends).
    pub fn is_full_match(&self, text: &str) -> bool {
        let bytes: Vec<u16> = text.bytes().map(u16::from).collect();
        self.re.find_from_ucs2(&bytes, 0).next().is_some()
    }
}

/// `pattern` (libstdc++ ECMAScript) as an anchored JavaScript pattern over bytes.
fn translate(pattern: &[u8]) -> Result<String, PatternError> {
    let mut t = Translator {
        p: pattern,
        i: 0,
        out: String::from("^(?:"),
        frames: vec![Frame::default()],
        open_frames: vec![0],
        groups: Vec::new(),
        open_groups: Vec::new(),
        lookaheads: 0,
    };
    t.disjunction()?;
    if let Some(&c) = t.p.get(t.i) {
        return Err(invalid(format!(
            "unexpected {} at byte {}",
            shown(c),
            t.i + 1
        )));
    }
    t.out.push_str(")$");
    Ok(t.out)
}

fn invalid(msg: impl Into<String>) -> PatternError {
    PatternError::Invalid(msg.into())
}
fn unsupported(msg: impl Into<String>) -> PatternError {
    PatternError::Unsupported(msg.into())
}
fn shown(c: u8) -> String {
    format!("{:?}", c as char)
}

/// A group, lookahead or the whole pattern, for deciding whether a back-reference's group
/// surely took part in the match.
#[derive(Default)]
struct Frame {
    /// Alternatives seen so far (`|` + 1).
    alternatives: usize,
    quantified: bool,
    lookahead: bool,
}

/// A capturing group: its frame and the enclosing frames with the alternative it is in.
struct Group {
    frame: usize,
    within: Vec<(usize, usize)>,
}

struct Translator<'p> {
    p: &'p [u8],
    i: usize,
    out: String,
    frames: Vec<Frame>,
    open_frames: Vec<usize>,
    groups: Vec<Group>,
    open_groups: Vec<usize>,
    lookaheads: usize,
}

/// What a piece of the pattern can do, for refusing loops `regress` does not end.
#[derive(Clone, Copy)]
struct Shape {
    /// It can match the empty string.
    nullable: bool,
    /// It holds a quantifier whose operand can match the empty string.
    nullable_loop: bool,
}

impl Shape {
    const CHAR: Shape = Shape {
        nullable: false,
        nullable_loop: false,
    };
    const EMPTY: Shape = Shape {
        nullable: true,
        nullable_loop: false,
    };
}

/// A token inside `[...]`.
enum BracketToken {
    Char(u8),
    Class(ByteSet),
    Dash,
    End,
}

impl Translator<'_> {
    fn peek(&self) -> Option<u8> {
        self.p.get(self.i).copied()
    }
    fn peek_at(&self, k: usize) -> Option<u8> {
        self.p.get(self.i + k).copied()
    }

    fn disjunction(&mut self) -> Result<Shape, PatternError> {
        let frame = *self.open_frames.last().expect("a frame is open");
        self.frames[frame].alternatives = 1;
        let mut shape = self.alternative()?;
        while self.peek() == Some(b'|') {
            self.i += 1;
            self.out.push('|');
            self.frames[frame].alternatives += 1;
            let next = self.alternative()?;
            shape.nullable |= next.nullable;
            shape.nullable_loop |= next.nullable_loop;
        }
        Ok(shape)
    }

    fn alternative(&mut self) -> Result<Shape, PatternError> {
        let mut shape = Shape::EMPTY;
        while let Some(term) = self.term()? {
            shape.nullable &= term.nullable;
            shape.nullable_loop |= term.nullable_loop;
        }
        Ok(shape)
    }

    /// One assertion, or one atom with its quantifiers; None at `|`, `)`, the end, or a
    /// quantifier with nothing to repeat (the caller then reports what it expected).
    fn term(&mut self) -> Result<Option<Shape>, PatternError> {
        let Some(c) = self.peek() else {
            return Ok(None);
        };
        match c {
            b'|' | b')' | b'*' | b'+' | b'?' | b'{' => return Ok(None),
            b'^' | b'$' => {
                self.position_assertion(c)?;
                self.i += 1;
                self.out.push(c as char);
                return Ok(Some(Shape::EMPTY));
            }
            b'\\' if matches!(self.peek_at(1), Some(b'b' | b'B')) => {
                let b = self.peek_at(1).unwrap_or(b'b');
                self.position_assertion(b)?;
                self.i += 2;
                self.out.push('\\');
                self.out.push(b as char);
                return Ok(Some(Shape::EMPTY));
            }
            b'(' if self.peek_at(1) == Some(b'?')
                && matches!(self.peek_at(2), Some(b'=' | b'!')) =>
            {
                let kind = if self.peek_at(2) == Some(b'=') {
                    "(?="
                } else {
                    "(?!"
                };
                self.i += 3;
                self.out.push_str(kind);
                self.lookaheads += 1;
                let (_, inner) = self.group_body(Frame {
                    lookahead: true,
                    ..Frame::default()
                })?;
                self.lookaheads -= 1;
                return Ok(Some(Shape {
                    nullable: true,
                    nullable_loop: inner.nullable_loop,
                }));
            }
            _ => {}
        }
        let start = self.out.len();
        let (group, mut shape) = self.atom()?;
        let mut quantified = false;
        while let Some((q, min)) = self.quantifier()? {
            // regress 0.12 loops without end (growing memory) on a quantifier over a piece
            // that holds a quantifier of an operand matching the empty string, e.g.
            // `(?:(?:a?)+)+` against "ab"; std::regex ends.
            if shape.nullable_loop {
                return Err(unsupported(
                    "a quantifier over a piece that holds a quantifier of something that can \
                     match the empty string (e.g. `(a?)+*`)",
                ));
            }
            if quantified {
                self.out.insert_str(start, "(?:");
                self.out.push(')');
            }
            self.out.push_str(&q);
            quantified = true;
            shape = Shape {
                nullable: shape.nullable || min == 0,
                nullable_loop: shape.nullable,
            };
        }
        if let (true, Some(f)) = (quantified, group) {
            self.frames[f].quantified = true;
        }
        Ok(Some(shape))
    }

    /// In a lookahead libstdc++ starts a new search whose beginning is where the lookahead
    /// stands: `^` holds there and `\b` ignores the byte before. JavaScript does not.
    fn position_assertion(&self, c: u8) -> Result<(), PatternError> {
        if self.lookaheads > 0 && c != b'$' {
            let what = if c == b'^' {
                "`^`".to_string()
            } else {
                format!("`\\{}`", c as char)
            };
            return Err(unsupported(format!(
                "{what} inside a lookahead (std::regex reads it relative to where the lookahead starts)"
            )));
        }
        Ok(())
    }

    /// An atom, with the frame it opened if it is a group.
    fn atom(&mut self) -> Result<(Option<usize>, Shape), PatternError> {
        let c = self.peek().ok_or_else(|| invalid("pattern ends early"))?;
        self.i += 1;
        match c {
            b'.' => {
                let mut set = ByteSet::all();
                set.remove(b'\n');
                set.remove(b'\r');
                self.out.push_str(&set.to_class());
                Ok((None, Shape::CHAR))
            }
            b'(' => {
                if self.peek() == Some(b'?') {
                    if self.peek_at(1) != Some(b':') {
                        return Err(invalid(
                            "`(?` must be followed by `:`, `=` or `!` (no named groups, lookbehind or flags)",
                        ));
                    }
                    self.i += 2;
                    self.out.push_str("(?:");
                    let (f, shape) = self.group_body(Frame::default())?;
                    return Ok((Some(f), shape));
                }
                let within = self
                    .open_frames
                    .iter()
                    .map(|&f| (f, self.frames[f].alternatives))
                    .collect();
                self.groups.push(Group { frame: 0, within });
                let n = self.groups.len();
                self.open_groups.push(n);
                self.out.push('(');
                let f = self.frames.len();
                self.groups[n - 1].frame = f;
                let (f, shape) = self.group_body(Frame::default())?;
                self.open_groups.pop();
                Ok((Some(f), shape))
            }
            b'[' => {
                let set = self.bracket()?;
                self.out.push_str(&set.to_class());
                Ok((None, Shape::CHAR))
            }
            b'\\' => self.escape().map(|shape| (None, shape)),
            _ => {
                push_byte(&mut self.out, c);
                Ok((None, Shape::CHAR))
            }
        }
    }

    /// The inside of a group or lookahead whose opening was written, up to and with `)`.
    fn group_body(&mut self, frame: Frame) -> Result<(usize, Shape), PatternError> {
        let f = self.frames.len();
        self.frames.push(frame);
        self.open_frames.push(f);
        let shape = self.disjunction()?;
        if self.peek() != Some(b')') {
            return Err(invalid("a `(` is not closed"));
        }
        self.i += 1;
        self.out.push(')');
        self.open_frames.pop();
        Ok((f, shape))
    }

    /// An escape outside brackets (the `\` is read).
    fn escape(&mut self) -> Result<Shape, PatternError> {
        let c = self
            .peek()
            .ok_or_else(|| invalid("`\\` at the end of the pattern"))?;
        if c.is_ascii_digit() && c != b'0' {
            let n = self.number(10, usize::MAX)?;
            self.back_reference(n)?;
            // The group may have matched the empty string.
            return Ok(Shape::EMPTY);
        }
        match self.escaped()? {
            BracketToken::Char(b) => push_byte(&mut self.out, b),
            BracketToken::Class(set) => self.out.push_str(&set.to_class()),
            BracketToken::Dash | BracketToken::End => unreachable!("escapes give chars or classes"),
        }
        Ok(Shape::CHAR)
    }

    /// The character or class of an escape other than `\b`, `\B` and a back-reference, at
    /// `self.i` (after the `\`). Inside brackets `\b` is a backspace.
    fn escaped(&mut self) -> Result<BracketToken, PatternError> {
        let c = self
            .peek()
            .ok_or_else(|| invalid("`\\` at the end of the pattern"))?;
        self.i += 1;
        Ok(match c {
            b'0' => BracketToken::Char(0),
            b'b' => BracketToken::Char(8),
            b'f' => BracketToken::Char(12),
            b'n' => BracketToken::Char(b'\n'),
            b'r' => BracketToken::Char(b'\r'),
            b't' => BracketToken::Char(b'\t'),
            b'v' => BracketToken::Char(11),
            b'd' | b'D' | b's' | b'S' | b'w' | b'W' => {
                let set = ByteSet::class(&[c.to_ascii_lowercase()]).expect("d, s, w are classes");
                BracketToken::Class(if c.is_ascii_uppercase() {
                    set.complement()
                } else {
                    set
                })
            }
            // libstdc++ takes the byte after `\c` itself, not its control character.
            b'c' => {
                let x = self
                    .peek()
                    .ok_or_else(|| invalid("`\\c` at the end of the pattern"))?;
                self.i += 1;
                BracketToken::Char(x)
            }
            b'x' | b'u' => {
                let digits = if c == b'x' { 2 } else { 4 };
                let mut v: u32 = 0;
                for _ in 0..digits {
                    let d = self
                        .peek()
                        .and_then(|d| (d as char).to_digit(16))
                        .ok_or_else(|| {
                            invalid(format!("`\\{}` needs {digits} hex digits", c as char))
                        })?;
                    self.i += 1;
                    v = v * 16 + d;
                }
                // A C++ `char` keeps the low byte of `\uHHHH`.
                BracketToken::Char((v & 0xff) as u8)
            }
            other => BracketToken::Char(other),
        })
    }

    /// Decimal digits at `self.i` (at least one), refused past `max` as libstdc++ refuses
    /// past `int`.
    fn number(&mut self, radix: u32, max: usize) -> Result<usize, PatternError> {
        let start = self.i;
        let mut v: usize = 0;
        while let Some(d) = self.peek().and_then(|d| (d as char).to_digit(radix)) {
            v = v
                .checked_mul(radix as usize)
                .and_then(|v| v.checked_add(d as usize))
                .filter(|&v| v <= max.min(i32::MAX as usize))
                .ok_or_else(|| invalid("a number in the pattern is too large"))?;
            self.i += 1;
        }
        if self.i == start {
            return Err(invalid("a number is expected"));
        }
        Ok(v)
    }

    /// `\n`: libstdc++ accepts only a group closed before it; a group that may not have
    /// taken part fails the match there, while JavaScript matches the empty string, so only
    /// a group sure to have taken part is accepted.
    fn back_reference(&mut self, n: usize) -> Result<(), PatternError> {
        if n > self.groups.len() {
            return Err(invalid(format!(
                "back-reference \\{n} to a group not opened before it"
            )));
        }
        if self.open_groups.contains(&n) {
            return Err(invalid(format!(
                "back-reference \\{n} inside its own group"
            )));
        }
        let group = &self.groups[n - 1];
        let here: Vec<(usize, usize)> = self
            .open_frames
            .iter()
            .map(|&f| (f, self.frames[f].alternatives))
            .collect();
        let common = group
            .within
            .iter()
            .zip(&here)
            .take_while(|(a, b)| a.0 == b.0)
            .count();
        let same_alternative = common > 0 && group.within[common - 1] == here[common - 1];
        let closed_between = group.within[common..].iter().all(|&(f, _)| {
            let fr = &self.frames[f];
            !fr.quantified && !fr.lookahead && fr.alternatives == 1
        });
        let own = &self.frames[group.frame];
        if !(same_alternative && closed_between && !own.quantified) {
            return Err(unsupported(format!(
                "back-reference \\{n} to a group that may not take part in the match (under a \
                 quantifier, in another alternative or in a lookahead): std::regex then fails \
                 where JavaScript-style engines match the empty string"
            )));
        }
        let _ = write!(self.out, "\\{n}");
        Ok(())
    }

    /// `*`, `+`, `?`, `{n}`, `{n,}`, `{n,m}`, each maybe followed by `?` (lazy), with its
    /// least count.
    fn quantifier(&mut self) -> Result<Option<(String, usize)>, PatternError> {
        let min;
        let mut q = match self.peek() {
            Some(c @ (b'*' | b'+' | b'?')) => {
                self.i += 1;
                min = usize::from(c == b'+');
                (c as char).to_string()
            }
            Some(b'{') => {
                self.i += 1;
                min = self.number(10, usize::MAX).map_err(|_| {
                    invalid("`{` must be followed by a count (a literal `{` is written `\\{`)")
                })?;
                let mut q = format!("{{{min}");
                if self.peek() == Some(b',') {
                    self.i += 1;
                    q.push(',');
                    if self.peek().is_some_and(|d| d.is_ascii_digit()) {
                        let max = self.number(10, usize::MAX)?;
                        if max < min {
                            return Err(invalid(format!(
                                "`{{{min},{max}}}`: the bounds are reversed"
                            )));
                        }
                        let _ = write!(q, "{max}");
                    }
                }
                if self.peek() != Some(b'}') {
                    return Err(invalid("`{` of a count is not closed by `}`"));
                }
                self.i += 1;
                q.push('}');
                q
            }
            _ => return Ok(None),
        };
        if self.peek() == Some(b'?') {
            self.i += 1;
            q.push('?');
        }
        Ok(Some((q, min)))
    }

    /// A bracket expression after its `[`: the bytes it matches.
    fn bracket(&mut self) -> Result<ByteSet, PatternError> {
        let negated = self.peek() == Some(b'^');
        if negated {
            self.i += 1;
        }
        let mut set = ByteSet::default();
        // The last single character, kept back because a `-` may make it a range start.
        enum Last {
            None,
            Char(u8),
            Class,
        }
        let mut last = Last::None;
        let mut pending = None;
        match self.bracket_token()? {
            BracketToken::Char(c) => last = Last::Char(c),
            BracketToken::Dash => last = Last::Char(b'-'),
            other => pending = Some(other),
        }
        loop {
            let token = match pending.take() {
                Some(t) => t,
                None => self.bracket_token()?,
            };
            match token {
                BracketToken::End => break,
                BracketToken::Class(class) => {
                    if let Last::Char(c) = last {
                        set.insert(c);
                    }
                    last = Last::Class;
                    set.union(&class);
                }
                BracketToken::Char(c) => {
                    if let Last::Char(p) = last {
                        set.insert(p);
                    }
                    last = Last::Char(c);
                }
                BracketToken::Dash => {
                    let next = self.bracket_token()?;
                    match (&last, next) {
                        (_, BracketToken::End) => {
                            if let Last::Char(p) = last {
                                set.insert(p);
                            }
                            last = Last::Char(b'-');
                            break;
                        }
                        (Last::Class, _) => {
                            return Err(invalid("a class cannot start a range `[x-y]`"));
                        }
                        (Last::Char(from), BracketToken::Char(to)) => {
                            set.insert_range(*from, to)?;
                            last = Last::None;
                        }
                        (Last::Char(from), BracketToken::Dash) => {
                            set.insert_range(*from, b'-')?;
                            last = Last::None;
                        }
                        (Last::Char(_), BracketToken::Class(_)) => {
                            return Err(invalid("a class cannot end a range `[x-y]`"));
                        }
                        (Last::None, next) => {
                            last = Last::Char(b'-');
                            pending = Some(next);
                        }
                    }
                }
            }
        }
        if let Last::Char(c) = last {
            set.insert(c);
        }
        Ok(if negated { set.complement() } else { set })
    }

    fn bracket_token(&mut self) -> Result<BracketToken, PatternError> {
        let c = self
            .peek()
            .ok_or_else(|| invalid("a `[` is not closed by `]`"))?;
        self.i += 1;
        match c {
            b'-' => Ok(BracketToken::Dash),
            b']' => Ok(BracketToken::End),
            b'[' => match self.peek() {
                None => Err(invalid("a `[` is not closed by `]`")),
                Some(kind @ (b':' | b'.' | b'=')) => {
                    self.i += 1;
                    let start = self.i;
                    while self.peek().is_some_and(|x| x != kind) {
                        self.i += 1;
                    }
                    let name = &self.p[start..self.i];
                    if self.peek() != Some(kind) || self.peek_at(1) != Some(b']') {
                        return Err(invalid(format!(
                            "`[{}` is not closed by `{}]`",
                            kind as char, kind as char
                        )));
                    }
                    self.i += 2;
                    if kind != b':' {
                        return Err(unsupported(format!(
                            "collating elements and equivalence classes (`[{k}...{k}]`)",
                            k = kind as char
                        )));
                    }
                    let lower: Vec<u8> = name.iter().map(u8::to_ascii_lowercase).collect();
                    ByteSet::class(&lower)
                        .map(BracketToken::Class)
                        .ok_or_else(|| {
                            invalid(format!(
                                "`[:{}:]` is not a character class",
                                String::from_utf8_lossy(name)
                            ))
                        })
                }
                Some(_) => Ok(BracketToken::Char(b'[')),
            },
            b'\\' => match self.peek() {
                None => Err(invalid("`\\` at the end of the pattern")),
                Some(b'B') => Err(invalid("`\\B` inside `[...]`")),
                Some(d) if d.is_ascii_digit() && d != b'0' => {
                    Err(invalid("a back-reference inside `[...]`"))
                }
                Some(_) => self.escaped(),
            },
            other => Ok(BracketToken::Char(other)),
        }
    }
}

fn push_byte(out: &mut String, b: u8) {
    let _ = write!(out, "\\x{b:02x}");
}

/// A set of bytes.
#[derive(Clone, Copy, Default)]
struct ByteSet([u64; 4]);

impl ByteSet {
    fn all() -> ByteSet {
        ByteSet([u64::MAX; 4])
    }
    fn contains(&self, b: u8) -> bool {
        self.0[(b >> 6) as usize] & (1 << (b & 63)) != 0
    }
    fn insert(&mut self, b: u8) {
        self.0[(b >> 6) as usize] |= 1 << (b & 63);
    }
    fn remove(&mut self, b: u8) {
        self.0[(b >> 6) as usize] &= !(1 << (b & 63));
    }
    fn union(&mut self, other: &ByteSet) {
        for (a, b) in self.0.iter_mut().zip(other.0) {
            *a |= b;
        }
    }
    fn complement(mut self) -> ByteSet {
        for a in &mut self.0 {
            *a = !*a;
        }
        self
    }
    fn from_fn(f: impl Fn(u8) -> bool) -> ByteSet {
        let mut s = ByteSet::default();
        for b in 0..=255u8 {
            if f(b) {
                s.insert(b);
            }
        }
        s
    }

    /// `[from-to]`: libstdc++ compares C++ `char`s, signed here, so bytes from 0x80 come
    /// before 0x00 and a range from below 0x80 to above it is reversed (refused).
    fn insert_range(&mut self, from: u8, to: u8) -> Result<(), PatternError> {
        let (lo, hi) = (from as i8, to as i8);
        if lo > hi {
            return Err(invalid(format!(
                "the range {}-{} is reversed (bytes compare as signed C++ chars)",
                shown(from),
                shown(to)
            )));
        }
        for b in lo..=hi {
            self.insert(b as u8);
        }
        Ok(())
    }

    /// A class name of the "C" locale (as `[:name:]`, lower case, or `d`, `s`, `w`).
    fn class(name: &[u8]) -> Option<ByteSet> {
        let is: fn(u8) -> bool = match name {
            b"d" | b"digit" => |b| b.is_ascii_digit(),
            b"w" => |b| b.is_ascii_alphanumeric() || b == b'_',
            // C's isspace: \t \n \v \f \r and space (Rust's is_ascii_whitespace has no \v).
            b"s" | b"space" => |b| matches!(b, 9..=13 | b' '),
            b"alnum" => |b| b.is_ascii_alphanumeric(),
            b"alpha" => |b| b.is_ascii_alphabetic(),
            b"blank" => |b| b == b' ' || b == b'\t',
            b"cntrl" => |b| b < 0x20 || b == 0x7f,
            b"graph" => |b| b.is_ascii_graphic(),
            b"print" => |b| b.is_ascii_graphic() || b == b' ',
            b"punct" => |b| b.is_ascii_punctuation(),
            b"lower" => |b| b.is_ascii_lowercase(),
            b"upper" => |b| b.is_ascii_uppercase(),
            b"xdigit" => |b| b.is_ascii_hexdigit(),
            _ => return None,
        };
        Some(ByteSet::from_fn(is))
    }

    /// The set as a JavaScript class of `\xHH` ranges (`[]` matches nothing).
    fn to_class(self) -> String {
        let mut s = String::from("[");
        let mut b: u16 = 0;
        while b < 256 {
            if !self.contains(b as u8) {
                b += 1;
                continue;
            }
            let start = b;
            while b < 256 && self.contains(b as u8) {
                b += 1;
            }
            push_byte(&mut s, start as u8);
            if b - 1 > start {
                s.push('-');
                push_byte(&mut s, (b - 1) as u8);
            }
        }
        s.push(']');
        s
    }
}
