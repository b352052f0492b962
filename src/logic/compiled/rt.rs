//! Runtime support for generated ascent programs: the same operations as the
//! interpreter (`logic::ops`), with runtime errors recorded in a thread-local
//! slot (ascent rules cannot return errors) and typed aggregators.

use crate::logic::error::{CompiledError, EvalError};
use crate::logic::ops;
use crate::logic::value::{F64, Sym};
use std::cell::RefCell;

thread_local! {
    static ERROR: RefCell<Option<CompiledError>> = const { RefCell::new(None) };
}

pub fn reset_error() {
    ERROR.with(|e| *e.borrow_mut() = None);
}

pub fn take_error() -> Option<CompiledError> {
    ERROR.with(|e| e.borrow_mut().take())
}

/// Keep the first error; the caller discards the run's results.
fn fail<T>(rule: &str, msg: EvalError, fallback: T) -> T {
    ERROR.with(|e| {
        let mut e = e.borrow_mut();
        if e.is_none() {
            *e = Some(CompiledError {
                rule: rule.to_string(),
                message: msg,
            });
        }
    });
    fallback
}

fn or_fail<T>(r: ops::OpResult<T>, rule: &str, fallback: T) -> T {
    match r {
        Ok(v) => v,
        Err(m) => fail(rule, m, fallback),
    }
}

pub fn sym(s: &str) -> Sym {
    Sym::from(s)
}
pub fn div_i64(a: i64, b: i64, rule: &str) -> i64 {
    or_fail(ops::div_i64(a, b), rule, 0)
}
pub fn rem_i64(a: i64, b: i64, rule: &str) -> i64 {
    or_fail(ops::rem_i64(a, b), rule, 0)
}
pub fn div_u64(a: u64, b: u64, rule: &str) -> u64 {
    or_fail(ops::div_u64(a, b), rule, 0)
}
pub fn rem_u64(a: u64, b: u64, rule: &str) -> u64 {
    or_fail(ops::rem_u64(a, b), rule, 0)
}
pub fn substr(s: &str, start: i64, len: i64, rule: &str) -> Sym {
    or_fail(ops::substr(s, start, len), rule, sym(""))
}
pub fn to_number(s: &str, rule: &str) -> i64 {
    or_fail(ops::to_number(s), rule, 0)
}
pub fn to_unsigned(s: &str, rule: &str) -> u64 {
    or_fail(ops::to_unsigned(s), rule, 0)
}
pub fn to_float(s: &str, rule: &str) -> F64 {
    or_fail(ops::to_float(s), rule, F64(0.0))
}
/// `match` (`!match` when `negated`); see `ops::match_test`.
pub fn match_test(pattern: &str, text: &str, negated: bool) -> bool {
    ops::match_test(pattern, text, negated)
}
/// `min(a, b)` on floats as the interpreter computes it (IEEE `<`).
pub fn min2_f64(acc: F64, x: F64) -> F64 {
    if x.0 < acc.0 { x } else { acc }
}
pub fn max2_f64(acc: F64, x: F64) -> F64 {
    if x.0 > acc.0 { x } else { acc }
}

// Aggregators (ascent calls them with the matching tuples of the aggregated relation).

pub fn count(inp: impl Iterator<Item = ()>) -> impl Iterator<Item = i64> {
    std::iter::once(inp.count() as i64)
}
pub fn sum_i64<'a>(inp: impl Iterator<Item = (&'a i64,)>) -> impl Iterator<Item = i64> {
    std::iter::once(inp.fold(0i64, |a, (x,)| a.wrapping_add(*x)))
}
pub fn sum_u64<'a>(inp: impl Iterator<Item = (&'a u64,)>) -> impl Iterator<Item = u64> {
    std::iter::once(inp.fold(0u64, |a, (x,)| a.wrapping_add(*x)))
}
pub fn sum_f64<'a>(inp: impl Iterator<Item = (&'a F64,)>) -> impl Iterator<Item = F64> {
    std::iter::once(F64(inp.fold(0.0, |a, (x,)| a + x.0)))
}
fn mean(it: impl Iterator<Item = f64>) -> impl Iterator<Item = F64> {
    let (s, n) = it.fold((0.0, 0usize), |(s, n), x| (s + x, n + 1));
    (n > 0).then(|| F64(s / n as f64)).into_iter()
}
pub fn mean_i64<'a>(inp: impl Iterator<Item = (&'a i64,)>) -> impl Iterator<Item = F64> {
    mean(inp.map(|(x,)| *x as f64))
}
pub fn mean_u64<'a>(inp: impl Iterator<Item = (&'a u64,)>) -> impl Iterator<Item = F64> {
    mean(inp.map(|(x,)| *x as f64))
}
pub fn mean_f64<'a>(inp: impl Iterator<Item = (&'a F64,)>) -> impl Iterator<Item = F64> {
    mean(inp.map(|(x,)| x.0))
}
pub fn min_ord<'a, T: Ord + Clone + 'a>(
    inp: impl Iterator<Item = (&'a T,)>,
) -> impl Iterator<Item = T> {
    inp.map(|(x,)| x).min().cloned().into_iter()
}
pub fn max_ord<'a, T: Ord + Clone + 'a>(
    inp: impl Iterator<Item = (&'a T,)>,
) -> impl Iterator<Item = T> {
    inp.map(|(x,)| x).max().cloned().into_iter()
}
/// Floats aggregate in their total order, like the interpreter.
pub fn min_f64<'a>(inp: impl Iterator<Item = (&'a F64,)>) -> impl Iterator<Item = F64> {
    min_ord(inp)
}
pub fn max_f64<'a>(inp: impl Iterator<Item = (&'a F64,)>) -> impl Iterator<Item = F64> {
    max_ord(inp)
}
