//! Rule tuples as bytes and back, exactly: floats as their bits, a symbol as UTF-8 with its
//! length the first time and as a back-reference after. The same bytes feed the plan cache's
//! keys (what a part's rules read) and its entries (what they derived).

use crate::logic::Value;
use crate::logic::compiled::Relations;
use crate::logic::value::{F64, Iso, OBox, Sym, Vec3};
use nalgebra::{Isometry3, Quaternion, Translation3, UnitQuaternion, Vector3};
use rustc_hash::FxHashMap;
use std::collections::hash_map::Entry;
use std::sync::Arc;

/// Writes rule tuples. Each distinct symbol is written as text once and afterwards as the
/// index of that first time: a part's few dozen pieces name themselves hundreds of times, and
/// two thirds of an entry were their names written out again.
#[derive(Default)]
pub struct Writer {
    pub bytes: Vec<u8>,
    seen: FxHashMap<Sym, u32>,
}

/// Value tags.
const NUMBER: u8 = 0;
const UNSIGNED: u8 = 1;
const FLOAT: u8 = 2;
const SYMBOL: u8 = 3;
const VEC3: u8 = 4;
const ISO: u8 = 5;
const BOX: u8 = 6;
/// A symbol written before: the u32 index of its first writing.
const SYMBOL_AGAIN: u8 = 7;

impl Writer {
    /// A writer appending to `bytes`.
    pub fn new(bytes: Vec<u8>) -> Writer {
        Writer {
            bytes,
            seen: FxHashMap::default(),
        }
    }

    /// A relation set: count, then each relation as `relation` writes it.
    pub fn relations(&mut self, relations: &Relations) {
        self.u64(relations.len() as u64);
        for (name, tuples) in relations {
            self.relation(name, tuples.iter().map(Vec::as_slice));
        }
    }

    /// One relation of a set: its name, tuple count and tuples.
    pub fn relation<'t>(&mut self, name: &str, tuples: impl ExactSizeIterator<Item = &'t [Value]>) {
        self.str(name);
        self.u64(tuples.len() as u64);
        for t in tuples {
            self.tuple(t);
        }
    }

    /// One tuple: its arity and values.
    pub fn tuple(&mut self, t: &[Value]) {
        self.u64(t.len() as u64);
        for v in t {
            self.value(v);
        }
    }

    pub fn u64(&mut self, n: u64) {
        self.bytes.extend_from_slice(&n.to_le_bytes());
    }

    fn f64(&mut self, x: f64) {
        self.u64(x.to_bits());
    }

    pub fn str(&mut self, s: &str) {
        self.u64(s.len() as u64);
        self.bytes.extend_from_slice(s.as_bytes());
    }

    fn iso(&mut self, pose: &Isometry3<f64>) {
        let t = pose.translation.vector;
        let q = pose.rotation.quaternion();
        for x in [t.x, t.y, t.z, q.w, q.i, q.j, q.k] {
            self.f64(x);
        }
    }

    pub fn value(&mut self, v: &Value) {
        match v {
            Value::Number(n) => {
                self.bytes.push(NUMBER);
                self.u64(*n as u64);
            }
            Value::Unsigned(n) => {
                self.bytes.push(UNSIGNED);
                self.u64(*n);
            }
            Value::Float(x) => {
                self.bytes.push(FLOAT);
                self.f64(x.0);
            }
            Value::Symbol(s) => {
                let next = self.seen.len() as u32;
                match self.seen.entry(*s) {
                    Entry::Occupied(first) => {
                        self.bytes.push(SYMBOL_AGAIN);
                        self.bytes.extend_from_slice(&first.get().to_le_bytes());
                    }
                    Entry::Vacant(slot) => {
                        slot.insert(next);
                        self.bytes.push(SYMBOL);
                        self.str(s);
                    }
                }
            }
            Value::Vec3(v) => {
                self.bytes.push(VEC3);
                for x in v.0.iter() {
                    self.f64(*x);
                }
            }
            Value::Iso(i) => {
                self.bytes.push(ISO);
                self.iso(&i.0);
            }
            Value::Box(b) => {
                self.bytes.push(BOX);
                self.iso(&b.pose);
                for x in b.half.iter() {
                    self.f64(*x);
                }
            }
        }
    }
}

/// Reads what a `Writer` wrote; every read fails softly (None) on short or malformed input.
pub struct Reader<'a> {
    bytes: &'a [u8],
    /// The symbols read so far, in order: what `SYMBOL_AGAIN` refers to.
    seen: Vec<Sym>,
}

impl<'a> Reader<'a> {
    pub fn new(bytes: &'a [u8]) -> Self {
        Reader {
            bytes,
            seen: Vec::new(),
        }
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
            NUMBER => Value::Number(self.u64()? as i64),
            UNSIGNED => Value::Unsigned(self.u64()?),
            FLOAT => Value::Float(F64(self.f64()?)),
            SYMBOL => {
                let s = Sym::from(self.str()?);
                self.seen.push(s);
                Value::Symbol(s)
            }
            SYMBOL_AGAIN => {
                let index = u32::from_le_bytes(self.take(4)?.try_into().ok()?);
                Value::Symbol(*self.seen.get(index as usize)?)
            }
            VEC3 => Value::Vec3(Vec3::new(self.f64()?, self.f64()?, self.f64()?)),
            ISO => Value::Iso(Arc::new(Iso(self.iso()?))),
            BOX => {
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
            // The shortest value is a symbol written before: its tag and index.
            let arity = self.count(5)?;
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
        let mut w = Writer::default();
        w.relations(&relations);
        let bytes = w.bytes;
        let back = Reader::new(&bytes).relations().unwrap();
        assert_eq!(back, relations);
        // Equality of F64 is by bits, so -0.0 and the subnormal survived exactly.
        for cut in [0, 1, 9, bytes.len() / 2, bytes.len() - 1] {
            let mut r = Reader::new(&bytes[..cut]);
            assert!(r.relations().is_none(), "cut at {cut}");
        }
    }

    #[test]
    fn a_repeated_symbol_is_written_once_and_a_reference_to_none_fails() {
        let name = "2O2Fr$t4X7Zf8NOew3FLOH";
        let tuples = vec![
            vec![Value::sym(name), Value::sym("stud")],
            vec![Value::sym("stud"), Value::sym(name), Value::sym(name)],
        ];
        let mut relations = Relations::new();
        relations.insert("r".into(), tuples);
        let mut w = Writer::default();
        w.relations(&relations);
        let bytes = w.bytes;
        let text = |t: &str| {
            bytes
                .windows(t.len())
                .filter(|x| *x == t.as_bytes())
                .count()
        };
        assert_eq!((text(name), text("stud")), (1, 1));
        assert_eq!(Reader::new(&bytes).relations().unwrap(), relations);

        // One tuple holding a reference to symbol 5, of which none was read.
        let mut w = Writer::default();
        w.u64(1);
        w.str("r");
        w.u64(1);
        w.u64(1);
        w.bytes.push(SYMBOL_AGAIN);
        w.bytes.extend_from_slice(&5u32.to_le_bytes());
        assert!(Reader::new(&w.bytes).relations().is_none());
    }
}
