//! Typed operations of the language (arithmetic, string functors), shared by
//! the interpreter and the compiled engine so both compute the same values.
//! `Err` carries the message of a runtime error (the caller names the rule).

use super::error::EvalError;
use super::std_regex::{PatternError, StdRegex};
use super::value::{F64, Sym, format_float};
use std::cell::RefCell;
use std::collections::HashMap;
use std::sync::{Mutex, OnceLock};

pub type OpResult<T> = Result<T, EvalError>;

pub fn div_i64(a: i64, b: i64) -> OpResult<i64> {
    if b == 0 {
        return Err(EvalError(format!("division by zero ({a} / 0)")));
    }
    Ok(a.wrapping_div(b))
}
pub fn rem_i64(a: i64, b: i64) -> OpResult<i64> {
    if b == 0 {
        return Err(EvalError(format!("division by zero ({a} % 0)")));
    }
    Ok(a.wrapping_rem(b))
}
/// Integer power; a negative exponent goes through floating point and
/// truncates (`2 ^ -1 = 0`), as Soufflé computes it.
pub fn pow_i64(a: i64, e: i64) -> i64 {
    if e < 0 {
        return (a as f64).powf(e as f64) as i64;
    }
    pow_wrapping(a as u64, e as u64) as i64
}
pub fn pow_u64(a: u64, e: u64) -> u64 {
    pow_wrapping(a, e)
}
fn pow_wrapping(mut base: u64, mut e: u64) -> u64 {
    let mut acc: u64 = 1;
    while e > 0 {
        if e & 1 == 1 {
            acc = acc.wrapping_mul(base);
        }
        base = base.wrapping_mul(base);
        e >>= 1;
    }
    acc
}
pub fn div_u64(a: u64, b: u64) -> OpResult<u64> {
    if b == 0 {
        return Err(EvalError(format!("division by zero ({a} / 0)")));
    }
    Ok(a / b)
}
pub fn rem_u64(a: u64, b: u64) -> OpResult<u64> {
    if b == 0 {
        return Err(EvalError(format!("division by zero ({a} % 0)")));
    }
    Ok(a % b)
}

/// The longest symbol `cat` may build in the interpreter: a rule that concatenates its own
/// output doubles a string per iteration and would exhaust memory long before other limits.
pub const MAX_SYMBOL_BYTES: usize = 1 << 20;

/// `cat`, refusing results over `MAX_SYMBOL_BYTES`.
pub fn cat_bounded(parts: &[&str]) -> OpResult<Sym> {
    let len: usize = parts.iter().map(|p| p.len()).sum();
    if len > MAX_SYMBOL_BYTES {
        return Err(EvalError(format!(
            "cat would make a symbol of {len} bytes, more than the limit of {MAX_SYMBOL_BYTES} bytes \
             (a rule that concatenates its own output grows without end: bound it, e.g. `strlen(s) < 100`)"
        )));
    }
    Ok(cat(parts))
}
pub fn cat(parts: &[&str]) -> Sym {
    Sym::from(parts.concat().as_str())
}
/// Length in bytes, as Soufflé's `strlen`.
pub fn strlen(s: &str) -> i64 {
    s.len() as i64
}
/// Bytes `[start, start+len)` (len clipped at the end of the string).
pub fn substr(s: &str, start: i64, len: i64) -> OpResult<Sym> {
    if start < 0 || start as usize > s.len() || len < 0 {
        return Err(EvalError(format!(
            "substr({s:?}, {start}, {len}): start or length out of range (string has {} bytes)",
            s.len()
        )));
    }
    let end = (start as usize).saturating_add(len as usize).min(s.len());
    s.get(start as usize..end).map(Sym::from).ok_or_else(|| {
        EvalError(format!(
            "substr({s:?}, {start}, {len}) would split a UTF-8 character"
        ))
    })
}
/// Ordinals handed out by `ord`, in order of first use.
pub type OrdTable = HashMap<String, i64>;

thread_local! {
    /// The ordinals of the interpreter run under way on this thread (see `with_ords`).
    static RUN_ORDS: RefCell<Option<OrdTable>> = const { RefCell::new(None) };
}

/// Run `f` with `table` as the ordinals `ord` hands out on this thread, so a run's
/// ordinals depend on that run only, not on what else ran in the process before.
pub fn with_ords<R>(table: &RefCell<OrdTable>, f: impl FnOnce() -> R) -> R {
    /// Puts the table back into its owner even when `f` unwinds.
    struct Restore<'t>(&'t RefCell<OrdTable>, Option<OrdTable>);
    impl Drop for Restore<'_> {
        fn drop(&mut self) {
            let used = RUN_ORDS.with(|r| std::mem::replace(&mut *r.borrow_mut(), self.1.take()));
            *self.0.borrow_mut() = used.unwrap_or_default();
        }
    }
    let mine = std::mem::take(&mut *table.borrow_mut());
    let outer = RUN_ORDS.with(|r| r.borrow_mut().replace(mine));
    let _restore = Restore(table, outer);
    f()
}

/// An ordinal per distinct symbol (first use gets the next number): per interpreter run
/// inside `with_ords`, else process-wide (the compiled path).
pub fn ord(s: &str) -> i64 {
    let next = |t: &mut OrdTable| {
        let n = t.len() as i64;
        *t.entry(s.to_string()).or_insert(n)
    };
    if let Some(n) = RUN_ORDS.with(|r| r.borrow_mut().as_mut().map(next)) {
        return n;
    }
    static TABLE: OnceLock<Mutex<OrdTable>> = OnceLock::new();
    let mut t = TABLE
        .get_or_init(Default::default)
        .lock()
        .unwrap_or_else(|e| e.into_inner());
    next(&mut t)
}
pub fn to_number(s: &str) -> OpResult<i64> {
    s.trim()
        .parse()
        .map_err(|_| EvalError(format!("to_number({s:?}): not a number")))
}
pub fn to_unsigned(s: &str) -> OpResult<u64> {
    s.trim()
        .parse()
        .map_err(|_| EvalError(format!("to_unsigned({s:?}): not an unsigned number")))
}
pub fn to_float(s: &str) -> OpResult<F64> {
    s.trim()
        .parse()
        .map(F64)
        .map_err(|_| EvalError(format!("to_float({s:?}): not a float")))
}
pub fn i64_to_string(n: i64) -> Sym {
    Sym::from(n.to_string().as_str())
}
pub fn u64_to_string(n: u64) -> Sym {
    Sym::from(n.to_string().as_str())
}
pub fn f64_to_string(x: F64) -> Sym {
    Sym::from(format_float(x.0).as_str())
}
pub fn contains(needle: &str, hay: &str) -> bool {
    hay.contains(needle)
}

thread_local! {
    /// Warnings of the current run on this thread (sorted, each once).
    static WARNINGS: RefCell<std::collections::BTreeSet<String>> = const { RefCell::new(std::collections::BTreeSet::new()) };
}

/// Take the warnings recorded on this thread since the last call.
pub fn take_warnings() -> Vec<String> {
    WARNINGS.with(|w| std::mem::take(&mut *w.borrow_mut()).into_iter().collect())
}

/// `match(pattern, text)`, or `!match(pattern, text)` when `negated`, as Soufflé evaluates
/// them (`std::regex_match`, see `std_regex`). A pattern that is not a regular expression
/// makes both false, as in Soufflé, and leaves a warning ("wrong pattern provided for match").
pub fn match_test(pattern: &str, text: &str, negated: bool) -> bool {
    thread_local! {
        /// Compiled patterns, or why one is refused. Only a cache: the warning is recorded
        /// on every use, so a run warns whatever ran before it.
        static CACHE: RefCell<HashMap<String, Result<StdRegex, PatternError>>> = RefCell::new(HashMap::new());
    }
    CACHE.with(|c| {
        let mut c = c.borrow_mut();
        if !c.contains_key(pattern) {
            if c.len() > 1024 {
                c.clear();
            }
            c.insert(pattern.to_string(), StdRegex::new(pattern));
        }
        match &c[pattern] {
            Ok(re) => re.is_full_match(text) != negated,
            Err(e) => {
                let not = if negated { "!" } else { "" };
                let warning = format!(
                    "wrong pattern provided for {not}match({pattern:?}, ...): {e}; it holds for no text"
                );
                WARNINGS.with(|w| w.borrow_mut().insert(warning));
                false
            }
        }
    })
}

/// IEEE comparison for floats (NaN compares false, -0 equals 0), as in Soufflé.
pub fn float_cmp(op: super::front::ast::CmpOp, a: f64, b: f64) -> bool {
    use super::front::ast::CmpOp::*;
    match op {
        Eq => a == b,
        Ne => a != b,
        Lt => a < b,
        Le => a <= b,
        Gt => a > b,
        Ge => a >= b,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn arithmetic_edges() {
        assert!(div_i64(1, 0).is_err());
        assert_eq!(div_i64(i64::MIN, -1).unwrap(), i64::MIN);
        assert_eq!(pow_i64(2, 10), 1024);
        assert_eq!(pow_i64(2, -1), 0);
        assert_eq!(rem_i64(-7, 3).unwrap(), -1);
    }

    #[test]
    fn strings() {
        assert_eq!(&*substr("hello", 1, 3).unwrap(), "ell");
        assert_eq!(&*substr("hello", 3, 10).unwrap(), "lo");
        assert!(substr("hello", 6, 1).is_err());
        assert!(match_test("a.*c", "abc", false));
        assert!(!match_test("b", "abc", false));
        assert!(match_test("b", "abc", true));
        assert!(!match_test("(", "x", false));
        assert!(!match_test("(", "x", true));
        assert_eq!(take_warnings().len(), 2);
        assert_eq!(to_number(" 42 ").unwrap(), 42);
        assert!(to_number("4x").is_err());
    }
}
