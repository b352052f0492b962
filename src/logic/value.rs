//! Runtime values of the rule language.
//!
//! `number` is a signed 64-bit integer (Soufflé's default build uses 32 bits;
//! 64 bits matches Soufflé built with `-DSOUFFLE_DOMAIN_64BIT` and leaves room
//! for millimetre coordinates and entity ids). Arithmetic wraps on overflow,
//! like Soufflé's C++ arithmetic does in practice. Floats have a total order
//! (`f64::total_cmp`) and hash bitwise, so `0.0` and `-0.0` are different values
//! and `NaN` equals itself: relations are sets and need a lawful `Eq`.

use nalgebra::{Isometry3, Point3, Translation3, UnitQuaternion, Vector3};
use serde::{Serialize, Serializer};
use std::cmp::Ordering;
use std::fmt;
use std::hash::{Hash, Hasher};
use std::sync::Arc;

use super::error::ParseValueError;
pub use super::front::ast::BaseTy;

/// A symbol: interned immutable text. Equal symbols share one address, so equality is a
/// pointer comparison and hashing reads a hash of the text computed once (FxHash, the same on
/// every machine, so hash-ordered work stays deterministic); order is by content, with equal
/// symbols found equal without reading their text. Interned text is never freed: a run holds
/// the names of the models it reads.
#[derive(Clone, Copy, PartialEq, Eq, Hash)]
pub struct Sym(ustr_fxhash::Ustr);

impl Sym {
    pub fn as_str(&self) -> &'static str {
        self.0.as_str()
    }
}

impl From<&str> for Sym {
    fn from(s: &str) -> Sym {
        Sym(ustr_fxhash::Ustr::from(s))
    }
}

impl std::ops::Deref for Sym {
    type Target = str;
    fn deref(&self) -> &str {
        self.0.as_str()
    }
}

impl AsRef<str> for Sym {
    fn as_ref(&self) -> &str {
        self.0.as_str()
    }
}

impl Ord for Sym {
    fn cmp(&self, o: &Self) -> Ordering {
        if self.0 == o.0 {
            Ordering::Equal
        } else {
            self.as_str().cmp(o.as_str())
        }
    }
}

impl PartialOrd for Sym {
    fn partial_cmp(&self, o: &Self) -> Option<Ordering> {
        Some(self.cmp(o))
    }
}

impl fmt::Debug for Sym {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        fmt::Debug::fmt(self.as_str(), f)
    }
}

impl fmt::Display for Sym {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.as_str())
    }
}

/// A float column value with a total order and bitwise hash.
#[derive(Clone, Copy, Debug, Default)]
pub struct F64(pub f64);

impl PartialEq for F64 {
    fn eq(&self, o: &Self) -> bool {
        self.0.to_bits() == o.0.to_bits()
    }
}
impl Eq for F64 {}
impl Hash for F64 {
    fn hash<H: Hasher>(&self, h: &mut H) {
        self.0.to_bits().hash(h)
    }
}
impl PartialOrd for F64 {
    fn partial_cmp(&self, o: &Self) -> Option<Ordering> {
        Some(self.cmp(o))
    }
}
impl Ord for F64 {
    fn cmp(&self, o: &Self) -> Ordering {
        self.0.total_cmp(&o.0)
    }
}

fn cmp_floats(a: &[f64], b: &[f64]) -> Ordering {
    a.iter()
        .zip(b)
        .map(|(x, y)| x.total_cmp(y))
        .find(|o| o.is_ne())
        .unwrap_or(Ordering::Equal)
}

fn hash_floats<H: Hasher>(a: &[f64], h: &mut H) {
    for x in a {
        x.to_bits().hash(h);
    }
}

macro_rules! float_tuple_traits {
    ($t:ty) => {
        impl PartialEq for $t {
            fn eq(&self, o: &Self) -> bool {
                self.cmp(o) == Ordering::Equal
            }
        }
        impl Eq for $t {}
        impl Hash for $t {
            fn hash<H: Hasher>(&self, h: &mut H) {
                hash_floats(&self.floats(), h)
            }
        }
        impl PartialOrd for $t {
            fn partial_cmp(&self, o: &Self) -> Option<Ordering> {
                Some(self.cmp(o))
            }
        }
        impl Ord for $t {
            fn cmp(&self, o: &Self) -> Ordering {
                cmp_floats(&self.floats(), &o.floats())
            }
        }
    };
}

/// A 3-vector (a point or a direction), metres.
#[derive(Clone, Copy, Debug)]
pub struct Vec3(pub Vector3<f64>);

impl Vec3 {
    pub fn new(x: f64, y: f64, z: f64) -> Self {
        Vec3(Vector3::new(x, y, z))
    }
    fn floats(&self) -> [f64; 3] {
        [self.0.x, self.0.y, self.0.z]
    }
}
float_tuple_traits!(Vec3);

/// A rigid transform (rotation then translation).
#[derive(Clone, Copy, Debug)]
pub struct Iso(pub Isometry3<f64>);

impl Iso {
    fn floats(&self) -> [f64; 7] {
        let t = self.0.translation.vector;
        let q = self.0.rotation.quaternion();
        [t.x, t.y, t.z, q.w, q.i, q.j, q.k]
    }
    pub fn identity() -> Self {
        Iso(Isometry3::identity())
    }
}
float_tuple_traits!(Iso);

/// An oriented box: pose of its centre (axes = the pose's rotated x, y, z) and
/// half sizes along those axes, metres.
#[derive(Clone, Copy, Debug)]
pub struct OBox {
    pub pose: Isometry3<f64>,
    pub half: Vector3<f64>,
}

impl OBox {
    fn floats(&self) -> [f64; 10] {
        let i = Iso(self.pose).floats();
        [
            i[0],
            i[1],
            i[2],
            i[3],
            i[4],
            i[5],
            i[6],
            self.half.x,
            self.half.y,
            self.half.z,
        ]
    }
    pub fn centre(&self) -> Vector3<f64> {
        self.pose.translation.vector
    }
    /// Unit axis k (0 = x, 1 = y, 2 = z) of the box in world coordinates.
    pub fn axis(&self, k: usize) -> Vector3<f64> {
        self.pose.rotation * Vector3::ith(k, 1.0)
    }
    /// Whether `p` lies inside or on the box (within `tol` metres).
    pub fn contains(&self, p: &Vector3<f64>, tol: f64) -> bool {
        let local = self.pose.inverse_transform_point(&Point3::from(*p));
        (0..3).all(|k| local[k].abs() <= self.half[k] + tol)
    }
}
float_tuple_traits!(OBox);

/// One value of a tuple. Geometry is behind `Arc` to keep the enum small.
#[derive(Clone, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Value {
    Number(i64),
    Unsigned(u64),
    Float(F64),
    Symbol(Sym),
    Vec3(Vec3),
    Iso(Arc<Iso>),
    Box(Arc<OBox>),
}

impl Value {
    pub fn sym(s: &str) -> Value {
        Value::Symbol(Sym::from(s))
    }
    pub fn float(x: f64) -> Value {
        Value::Float(F64(x))
    }
    pub fn ty(&self) -> BaseTy {
        match self {
            Value::Number(_) => BaseTy::Number,
            Value::Unsigned(_) => BaseTy::Unsigned,
            Value::Float(_) => BaseTy::Float,
            Value::Symbol(_) => BaseTy::Symbol,
            Value::Vec3(_) => BaseTy::Vec3,
            Value::Iso(_) => BaseTy::Iso,
            Value::Box(_) => BaseTy::Box,
        }
    }
    pub fn as_number(&self) -> Option<i64> {
        match self {
            Value::Number(n) => Some(*n),
            _ => None,
        }
    }
    pub fn as_float(&self) -> Option<f64> {
        match self {
            Value::Float(f) => Some(f.0),
            _ => None,
        }
    }
    pub fn as_unsigned(&self) -> Option<u64> {
        match self {
            Value::Unsigned(n) => Some(*n),
            _ => None,
        }
    }
    pub fn as_vec3(&self) -> Option<Vector3<f64>> {
        match self {
            Value::Vec3(v) => Some(v.0),
            _ => None,
        }
    }
    pub fn as_iso(&self) -> Option<Isometry3<f64>> {
        match self {
            Value::Iso(i) => Some(i.0),
            _ => None,
        }
    }
    pub fn as_box(&self) -> Option<OBox> {
        match self {
            Value::Box(b) => Some(**b),
            _ => None,
        }
    }
    pub fn vec3(v: Vector3<f64>) -> Value {
        Value::Vec3(Vec3(v))
    }
    pub fn iso(i: Isometry3<f64>) -> Value {
        Value::Iso(Arc::new(Iso(i)))
    }
    pub fn obox(pose: Isometry3<f64>, half: Vector3<f64>) -> Value {
        Value::Box(Arc::new(OBox { pose, half }))
    }
    pub fn as_symbol(&self) -> Option<&str> {
        match self {
            Value::Symbol(s) => Some(s),
            _ => None,
        }
    }
    /// The symbol itself (a copy of its handle), for maps keyed by symbol.
    pub fn as_sym(&self) -> Option<Sym> {
        match self {
            Value::Symbol(s) => Some(*s),
            _ => None,
        }
    }

    /// Parse a field of a `.facts` file as a value of type `ty`.
    pub fn parse(ty: BaseTy, text: &str) -> Result<Value, ParseValueError> {
        let t = text.trim();
        let floats = |n: usize| -> Result<Vec<f64>, ParseValueError> {
            let inner = t
                .strip_prefix('[')
                .and_then(|s| s.strip_suffix(']'))
                .ok_or_else(|| ParseValueError::Brackets {
                    n,
                    ty,
                    text: t.to_string(),
                })?;
            let v: Result<Vec<f64>, _> =
                inner.split(',').map(|x| x.trim().parse::<f64>()).collect();
            match v {
                Ok(v) if v.len() == n => Ok(v),
                _ => Err(ParseValueError::Numbers {
                    n,
                    ty,
                    text: t.to_string(),
                }),
            }
        };
        Ok(match ty {
            BaseTy::Number => {
                Value::Number(parse_int(t).ok_or_else(|| ParseValueError::Number(t.to_string()))?)
            }
            BaseTy::Unsigned => Value::Unsigned(
                parse_int(t)
                    .and_then(|v| u64::try_from(v).ok())
                    .ok_or_else(|| ParseValueError::Unsigned(t.to_string()))?,
            ),
            BaseTy::Float => Value::float(
                t.parse::<f64>()
                    .map_err(|_| ParseValueError::Float(t.to_string()))?,
            ),
            BaseTy::Symbol => Value::sym(text),
            BaseTy::Vec3 => {
                let v = floats(3)?;
                Value::Vec3(Vec3::new(v[0], v[1], v[2]))
            }
            BaseTy::Iso => Value::Iso(Arc::new(Iso(iso_from(&floats(7)?)))),
            BaseTy::Box => {
                let v = floats(10)?;
                Value::Box(Arc::new(OBox {
                    pose: iso_from(&v[..7]),
                    half: Vector3::new(v[7], v[8], v[9]),
                }))
            }
        })
    }
}

fn iso_from(v: &[f64]) -> Isometry3<f64> {
    let q = UnitQuaternion::from_quaternion(nalgebra::Quaternion::new(v[3], v[4], v[5], v[6]));
    Isometry3::from_parts(Translation3::new(v[0], v[1], v[2]), q)
}

fn parse_int(t: &str) -> Option<i64> {
    if let Some(h) = t.strip_prefix("0x") {
        return i64::from_str_radix(h, 16).ok();
    }
    if let Some(b) = t.strip_prefix("0b") {
        return i64::from_str_radix(b, 2).ok();
    }
    t.parse().ok()
}

/// Format a float like C++ `ostream << setprecision(17)` (`%.17g`), which is
/// what Soufflé writes: `1.5`, `2`, `0.10000000000000001`, `1e+20`.
pub fn format_float(x: f64) -> String {
    if x.is_nan() {
        return "nan".into();
    }
    if x.is_infinite() {
        return if x > 0.0 { "inf".into() } else { "-inf".into() };
    }
    if x == 0.0 {
        return if x.is_sign_negative() {
            "-0".into()
        } else {
            "0".into()
        };
    }
    const P: i32 = 17;
    let sci = format!("{:.*e}", (P - 1) as usize, x);
    let (mant, exp) = sci.split_once('e').expect("exponent");
    let exp: i32 = exp.parse().expect("exponent digits");
    if !(-4..P).contains(&exp) {
        let mant = strip_zeros(mant);
        let sign = if exp < 0 { '-' } else { '+' };
        format!("{mant}e{sign}{:02}", exp.abs())
    } else {
        let decimals = (P - 1 - exp).max(0) as usize;
        strip_zeros(&format!("{:.*}", decimals, x)).to_string()
    }
}

fn strip_zeros(s: &str) -> &str {
    if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.')
    } else {
        s
    }
}

impl fmt::Display for Value {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let list = |f: &mut fmt::Formatter<'_>, v: &[f64]| {
            let parts: Vec<String> = v.iter().map(|x| format_float(*x)).collect();
            write!(f, "[{}]", parts.join(","))
        };
        match self {
            Value::Number(n) => write!(f, "{n}"),
            Value::Unsigned(n) => write!(f, "{n}"),
            Value::Float(x) => f.write_str(&format_float(x.0)),
            Value::Symbol(s) => f.write_str(s),
            Value::Vec3(v) => list(f, &v.floats()),
            Value::Iso(i) => list(f, &i.floats()),
            Value::Box(b) => list(f, &b.floats()),
        }
    }
}

/// Values serialise as their text form (symbols as strings, numbers as numbers).
impl Serialize for Value {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        match self {
            Value::Number(n) => s.serialize_i64(*n),
            Value::Unsigned(n) => s.serialize_u64(*n),
            Value::Float(x) => s.serialize_f64(x.0),
            other => s.serialize_str(&other.to_string()),
        }
    }
}

/// A Rust type that can be a relation column in the compiled engine and a
/// functor parameter: conversion to and from `Value`.
pub trait Column: Sized + Clone {
    const TY: BaseTy;
    /// Panics on a value of another type: callers have type-checked the program.
    fn from_value(v: &Value) -> Self;
    fn into_value(self) -> Value;
}

macro_rules! column {
    ($t:ty, $base:ident, $var:ident, |$x:ident| $from:expr, |$y:ident| $into:expr) => {
        impl Column for $t {
            const TY: BaseTy = BaseTy::$base;
            fn from_value(v: &Value) -> Self {
                match v {
                    Value::$var($x) => $from,
                    other => panic!(
                        "type-checked program saw a {} where a {} was expected",
                        other.ty(),
                        BaseTy::$base
                    ),
                }
            }
            fn into_value(self) -> Value {
                let $y = self;
                Value::$var($into)
            }
        }
    };
}

column!(i64, Number, Number, |x| *x, |y| y);
column!(u64, Unsigned, Unsigned, |x| *x, |y| y);
column!(F64, Float, Float, |x| *x, |y| y);
column!(Sym, Symbol, Symbol, |x| *x, |y| y);
column!(Vec3, Vec3, Vec3, |x| *x, |y| y);
column!(Iso, Iso, Iso, |x| **x, |y| Arc::new(y));
column!(OBox, Box, Box, |x| **x, |y| Arc::new(y));

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn floats_print_like_soufflé() {
        assert_eq!(format_float(1.5), "1.5");
        assert_eq!(format_float(2.0), "2");
        assert_eq!(format_float(0.1), "0.10000000000000001");
        assert_eq!(format_float(1e20), "1e+20");
        assert_eq!(format_float(-2.5e-7), "-2.4999999999999999e-07");
        assert_eq!(format_float(123456.0), "123456");
    }

    #[test]
    fn geometry_round_trips_through_text() {
        let v = Value::Vec3(Vec3::new(1.0, -2.5, 0.1));
        assert_eq!(Value::parse(BaseTy::Vec3, &v.to_string()).unwrap(), v);
        let b = Value::parse(BaseTy::Box, "[1,2,3,1,0,0,0,0.5,0.5,1]").unwrap();
        assert_eq!(Value::parse(BaseTy::Box, &b.to_string()).unwrap(), b);
        assert!(Value::parse(BaseTy::Iso, "[1,2]").is_err());
    }

    #[test]
    fn typed_accessors() {
        let b = Value::obox(Isometry3::identity(), Vector3::new(1.0, 2.0, 3.0));
        assert_eq!(b.as_box().unwrap().half, Vector3::new(1.0, 2.0, 3.0));
        assert_eq!(Value::vec3(Vector3::x()).as_vec3(), Some(Vector3::x()));
        assert!(Value::iso(Isometry3::identity()).as_iso().is_some());
        assert_eq!(Value::Unsigned(3).as_unsigned(), Some(3));
        assert_eq!(Value::Number(3).as_unsigned(), None);
    }

    #[test]
    fn float_order_is_total() {
        assert!(F64(-0.0) < F64(0.0));
        assert_eq!(F64(f64::NAN), F64(f64::NAN));
    }
}
