//! Relation storage: tuples appended to one flat vector (so "the tuples added
//! since iteration k" is an id range, which semi-naive evaluation needs) plus
//! hash indexes on column subsets, built on demand and kept up to date.

use crate::logic::value::Value;
use std::collections::HashMap;
use std::hash::{BuildHasherDefault, Hash, Hasher};

/// A small multiplicative hasher (tuples are hashed many times per derivation;
/// SipHash's DoS resistance is not needed for rule evaluation).
#[derive(Default, Clone, Copy)]
pub struct FastHasher(u64);

impl Hasher for FastHasher {
    fn finish(&self) -> u64 {
        self.0
    }
    fn write(&mut self, bytes: &[u8]) {
        for chunk in bytes.chunks(8) {
            let mut b = [0u8; 8];
            b[..chunk.len()].copy_from_slice(chunk);
            self.write_u64(u64::from_le_bytes(b));
        }
    }
    fn write_u64(&mut self, x: u64) {
        self.0 = (self.0.rotate_left(5) ^ x).wrapping_mul(0x51_7c_c1_b7_27_22_0a_95);
    }
    fn write_u8(&mut self, x: u8) {
        self.write_u64(x as u64)
    }
    fn write_u32(&mut self, x: u32) {
        self.write_u64(x as u64)
    }
    fn write_i64(&mut self, x: i64) {
        self.write_u64(x as u64)
    }
    fn write_usize(&mut self, x: usize) {
        self.write_u64(x as u64)
    }
    fn write_isize(&mut self, x: isize) {
        self.write_u64(x as u64)
    }
}

/// Keys are already hashes: pass them through.
#[derive(Default, Clone, Copy)]
pub struct IdHasher(u64);
impl Hasher for IdHasher {
    fn finish(&self) -> u64 {
        self.0
    }
    fn write(&mut self, _: &[u8]) {
        unreachable!("IdHasher only hashes u64 keys")
    }
    fn write_u64(&mut self, x: u64) {
        self.0 = x;
    }
}

pub fn hash_values<'a>(vals: impl Iterator<Item = &'a Value>) -> u64 {
    let mut h = FastHasher(0x9e37_79b9_7f4a_7c15);
    for v in vals {
        v.hash(&mut h);
    }
    h.finish()
}

#[derive(Clone, Debug)]
enum Bucket {
    One(u32),
    Many(Vec<u32>),
}

/// Tuple ids grouped by the hash of some columns (collisions are resolved by
/// comparing the tuples themselves).
#[derive(Clone, Debug)]
pub struct Index {
    pub cols: Vec<usize>,
    map: HashMap<u64, Bucket, BuildHasherDefault<IdHasher>>,
}

impl Index {
    fn new(cols: Vec<usize>) -> Self {
        Index {
            cols,
            map: HashMap::default(),
        }
    }
    fn add(&mut self, hash: u64, id: u32) {
        match self.map.get_mut(&hash) {
            None => {
                self.map.insert(hash, Bucket::One(id));
            }
            Some(Bucket::Many(v)) => v.push(id),
            Some(b @ Bucket::One(_)) => {
                let Bucket::One(first) = *b else {
                    unreachable!()
                };
                *b = Bucket::Many(vec![first, id]);
            }
        }
    }
    /// Ids with this key hash (ascending).
    pub fn get(&self, hash: u64) -> &[u32] {
        match self.map.get(&hash) {
            None => &[],
            Some(Bucket::One(id)) => std::slice::from_ref(id),
            Some(Bucket::Many(v)) => v,
        }
    }
}

#[derive(Clone, Debug)]
pub struct Relation {
    pub arity: usize,
    data: Vec<Value>,
    len: usize,
    /// Index on all columns: the set membership test.
    full: Index,
    pub indexes: Vec<Index>,
}

impl Relation {
    pub fn new(arity: usize) -> Self {
        Relation {
            arity,
            data: Vec::new(),
            len: 0,
            full: Index::new((0..arity).collect()),
            indexes: Vec::new(),
        }
    }
    pub fn len(&self) -> usize {
        self.len
    }
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }
    pub fn tuple(&self, id: u32) -> &[Value] {
        let a = self.arity;
        &self.data[id as usize * a..(id as usize + 1) * a]
    }
    /// The id of `t` if present.
    pub fn find(&self, t: &[Value]) -> Option<u32> {
        self.find_hashed(t, hash_values(t.iter()))
    }
    /// `find` with the tuple's hash already computed (`hash_values` of all columns).
    pub fn find_hashed(&self, t: &[Value], h: u64) -> Option<u32> {
        if self.arity == 0 {
            return (self.len > 0).then_some(0);
        }
        if self.len == 0 {
            return None;
        }
        self.full
            .get(h)
            .iter()
            .copied()
            .find(|&id| self.tuple(id) == t)
    }
    /// Append `t` unless present; returns its id if it was new.
    pub fn insert(&mut self, t: &[Value]) -> Option<u32> {
        self.insert_hashed(t, hash_values(t.iter()))
    }
    /// `insert` with the tuple's hash already computed.
    pub fn insert_hashed(&mut self, t: &[Value], h: u64) -> Option<u32> {
        debug_assert_eq!(t.len(), self.arity);
        if self.arity == 0 {
            if self.len > 0 {
                return None;
            }
            self.len = 1;
            return Some(0);
        }
        if self.full.get(h).iter().any(|&id| self.tuple(id) == t) {
            return None;
        }
        let id = self.len as u32;
        self.data.extend_from_slice(t);
        self.len += 1;
        self.full.add(h, id);
        for ix in &mut self.indexes {
            let kh = hash_values(ix.cols.iter().map(|&c| &t[c]));
            ix.add(kh, id);
        }
        Some(id)
    }
    /// Make sure an index on `cols` exists; returns its position.
    pub fn ensure_index(&mut self, cols: &[usize]) -> usize {
        if let Some(p) = self.indexes.iter().position(|ix| ix.cols == cols) {
            return p;
        }
        let mut ix = Index::new(cols.to_vec());
        for id in 0..self.len as u32 {
            let t = self.tuple(id);
            let kh = hash_values(cols.iter().map(|&c| &t[c]));
            ix.add(kh, id);
        }
        self.indexes.push(ix);
        self.indexes.len() - 1
    }
    /// All tuples, sorted.
    pub fn sorted(&self) -> Vec<Vec<Value>> {
        let mut v: Vec<Vec<Value>> = (0..self.len as u32)
            .map(|id| self.tuple(id).to_vec())
            .collect();
        v.sort();
        v
    }
}
