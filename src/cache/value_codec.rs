//! Rule tuples as bytes and back, exactly: floats as their bits, symbols as UTF-8 with their
//! length. The same bytes feed the plan cache's keys (what a part's rules read) and its
//! entries (what they derived).

use crate::logic::Value;
use crate::logic::compiled::Relations;
use crate::logic::value::{F64, Iso, OBox, Vec3};
use nalgebra::{Isometry3, Quaternion, Translation3, UnitQuaternion, Vector3};
use std::sync::Arc;

/// Appends a relation set: count, then each relation's name, tuple count and tuples.
pub fn put_relations(out: &mut Vec<u8>, relations: &Relations) {
    put_u64(out, relations.len() as u64);
    for (name, tuples) in relations {
        put_str(out, name);
        put_tuples(out, tuples);
    }
}

/// Appends tuples: count, then each tuple.
pub fn put_tuples(out: &mut Vec<u8>, tuples: &[Vec<Value>]) {
    put_u64(out, tuples.len() as u64);
    for t in tuples {
        put_tuple(out, t);
    }
}

/// Appends one tuple: its arity and values.
pub fn put_tuple(out: &mut Vec<u8>, t: &[Value]) {
    put_u64(out, t.len() as u64);
    for v in t {
        put_value(out, v);
    }
}

pub fn put_u64(out: &mut Vec<u8>, n: u64) {
    out.extend_from_slice(&n.to_le_bytes());
}

pub fn put_f64(out: &mut Vec<u8>, x: f64) {
    put_u64(out, x.to_bits());
}

pub fn put_str(out: &mut Vec<u8>, s: &str) {
    put_u64(out, s.len() as u64);
    out.extend_from_slice(s.as_bytes());
}

fn put_iso(out: &mut Vec<u8>, pose: &Isometry3<f64>) {
    let t = pose.translation.vector;
    let q = pose.rotation.quaternion();
    for x in [t.x, t.y, t.z, q.w, q.i, q.j, q.k] {
        put_f64(out, x);
    }
}

pub fn put_value(out: &mut Vec<u8>, v: &Value) {
    match v {
        Value::Number(n) => {
            out.push(0);
            put_u64(out, *n as u64);
        }
        Value::Unsigned(n) => {
            out.push(1);
            put_u64(out, *n);
        }
        Value::Float(x) => {
            out.push(2);
            put_f64(out, x.0);
        }
        Value::Symbol(s) => {
            out.push(3);
            put_str(out, s);
        }
        Value::Vec3(v) => {
            out.push(4);
            for x in v.0.iter() {
                put_f64(out, *x);
            }
        }
        Value::Iso(i) => {
            out.push(5);
            put_iso(out, &i.0);
        }
        Value::Box(b) => {
            out.push(6);
            put_iso(out, &b.pose);
            for x in b.half.iter() {
                put_f64(out, *x);
            }
        }
    }
}

/// Reads what the `put_` functions wrote; every read fails softly (None) on short or
/// malformed input.
pub struct Reader<'a> {
    bytes: &'a [u8],
}

impl<'a> Reader<'a> {
    pub fn new(bytes: &'a [u8]) -> Self {
        Reader { bytes }
    }

    pub fn is_empty(&self) -> bool {
        self.bytes.is_empty()
    }

    fn take(&mut self, n: usize) -> Option<&'a [u8]> {
        if self.bytes.len() < n {
            return None;
        }
        let (head, rest) = self.bytes.split_at(n);
        self.bytes = rest;
        Some(head)
    }

    pub fn u64(&mut self) -> Option<u64> {
        Some(u64::from_le_bytes(self.take(8)?.try_into().ok()?))
    }

    /// A count that cannot exceed what is left (each counted item takes at least `min` bytes).
    fn count(&mut self, min: usize) -> Option<usize> {
        let n = usize::try_from(self.u64()?).ok()?;
        (n <= self.bytes.len() / min.max(1)).then_some(n)
    }

    pub fn f64(&mut self) -> Option<f64> {
        Some(f64::from_bits(self.u64()?))
    }

    pub fn str(&mut self) -> Option<&'a str> {
        let n = self.count(1)?;
        std::str::from_utf8(self.take(n)?).ok()
    }

    fn iso(&mut self) -> Option<Isometry3<f64>> {
        let mut f = [0.0; 7];
        for x in &mut f {
            *x = self.f64()?;
        }
        Some(Isometry3::from_parts(
            Translation3::new(f[0], f[1], f[2]),
            UnitQuaternion::new_unchecked(Quaternion::new(f[3], f[4], f[5], f[6])),
        ))
    }

    pub fn value(&mut self) -> Option<Value> {
        let tag = *self.take(1)?.first()?;
        Some(match tag {
            0 => Value::Number(self.u64()? as i64),
            1 => Value::Unsigned(self.u64()?),
            2 => Value::Float(F64(self.f64()?)),
            3 => Value::sym(self.str()?),
            4 => Value::Vec3(Vec3::new(self.f64()?, self.f64()?, self.f64()?)),
            5 => Value::Iso(Arc::new(Iso(self.iso()?))),
            6 => {
                let pose = self.iso()?;
                let half = Vector3::new(self.f64()?, self.f64()?, self.f64()?);
                Value::Box(Arc::new(OBox { pose, half }))
            }
            _ => return None,
        })
    }

    pub fn tuples(&mut self) -> Option<Vec<Vec<Value>>> {
        let n = self.count(8)?;
        let mut tuples = Vec::with_capacity(n);
        for _ in 0..n {
            let arity = self.count(9)?;
            let mut t = Vec::with_capacity(arity);
            for _ in 0..arity {
                t.push(self.value()?);
            }
            tuples.push(t);
        }
        Some(tuples)
    }

    pub fn relations(&mut self) -> Option<Relations> {
        let n = self.count(16)?;
        let mut relations = Relations::new();
        for _ in 0..n {
            let name = self.str()?.to_string();
            relations.insert(name, self.tuples()?);
        }
        Some(relations)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_kind_of_value_comes_back_bit_for_bit_and_short_input_fails() {
        let pose = Isometry3::from_parts(
            Translation3::new(0.1, -2.5e-9, 1e300),
            UnitQuaternion::from_euler_angles(0.3, -1.2, 2.9),
        );
        let tuple = vec![
            Value::Number(-7),
            Value::Unsigned(u64::MAX),
            Value::float(-0.0),
            Value::float(f64::MIN_POSITIVE / 3.0),
            Value::sym("é ' \" \u{0}"),
            Value::Vec3(Vec3::new(1.0 / 3.0, -0.0, 7.0)),
            Value::Iso(Arc::new(Iso(pose))),
            Value::Box(Arc::new(OBox {
                pose,
                half: Vector3::new(0.02, 0.045, 1.2),
            })),
        ];
        let mut relations = Relations::new();
        relations.insert("r".into(), vec![tuple.clone(), vec![]]);
        relations.insert("empty".into(), vec![]);
        let mut bytes = Vec::new();
        put_relations(&mut bytes, &relations);
        let back = Reader::new(&bytes).relations().unwrap();
        assert_eq!(back, relations);
        // Equality of F64 is by bits, so -0.0 and the subnormal survived exactly.
        for cut in [0, 1, 9, bytes.len() / 2, bytes.len() - 1] {
            let mut r = Reader::new(&bytes[..cut]);
            assert!(r.relations().is_none(), "cut at {cut}");
        }
    }
}
