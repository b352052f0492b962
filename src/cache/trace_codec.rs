//! A wall's pose trace (what the report animates) as a cache entry and back. Kept apart from
//! the record entry: only runs that draw the scene need it, and it is far larger (a 10-minute
//! wall samples its robot and lumber ~12,000 times), so it is stored as the floats' IEEE bits
//! in little-endian binary, deflated. The entry names its key and carries a blake3 digest of
//! the trace's bytes, so a torn or altered file is a miss, never a different animation.
//!
//! Layout: `FWTRACE\0`, format (u32), key length (u32) and key, digest (32 bytes), then the
//! deflated body: sample count n, joints per sample j, n times, n·j joint values, n tool
//! poses, the lumber count, and per piece its id, key count, keys (time and pose) and the
//! time it left (or none). Every number is a little-endian u64; a pose is x, y, z, then the
//! quaternion's i, j, k, w.

use crate::sim::record::{LumberTrack, PoseTrace};
use flate2::Compression;
use flate2::read::ZlibDecoder;
use flate2::write::ZlibEncoder;
use nalgebra::{Isometry3, Quaternion, Translation3, UnitQuaternion};
use std::io::{Read, Write};

/// The trace entry format; entries of another format are misses.
pub const FORMAT: u32 = 1;
const MAGIC: &[u8; 8] = b"FWTRACE\0";
/// A body larger than this is not a trace this program wrote (a day of simulated time).
const MOST_BODY_BYTES: u64 = 1 << 32;

/// The entry's bytes; None for a trace whose samples differ in joint count (none the executor
/// writes), which is then not cached.
pub fn encode(key: &str, trace: &PoseTrace) -> Option<Vec<u8>> {
    let body = body(trace)?;
    let mut out = Vec::with_capacity(body.len() / 2);
    out.extend_from_slice(MAGIC);
    out.extend_from_slice(&FORMAT.to_le_bytes());
    out.extend_from_slice(&u32::try_from(key.len()).ok()?.to_le_bytes());
    out.extend_from_slice(key.as_bytes());
    out.extend_from_slice(blake3::hash(&body).as_bytes());
    // Fast compression: the entry is written on the simulating run's time.
    let mut z = ZlibEncoder::new(out, Compression::fast());
    z.write_all(&body).ok()?;
    z.finish().ok()
}

/// The trace, when the entry is of this format, answers `key` and is intact.
pub fn decode(key: &str, bytes: &[u8]) -> Option<PoseTrace> {
    let mut r = Reader(bytes);
    if r.take(8)? != MAGIC || r.u32()? != FORMAT {
        return None;
    }
    let len = r.u32()? as usize;
    if r.take(len)? != key.as_bytes() {
        return None;
    }
    let digest: [u8; 32] = r.take(32)?.try_into().ok()?;
    let mut body = Vec::new();
    ZlibDecoder::new(r.0)
        .take(MOST_BODY_BYTES)
        .read_to_end(&mut body)
        .ok()?;
    if blake3::hash(&body) != blake3::Hash::from_bytes(digest) {
        return None;
    }
    let trace = parse_body(&body)?;
    Some(trace)
}

fn body(t: &PoseTrace) -> Option<Vec<u8>> {
    let n = t.times.len();
    let j = t.joints.first().map_or(0, Vec::len);
    if t.joints.len() != n || t.tool.len() != n || t.joints.iter().any(|q| q.len() != j) {
        return None;
    }
    let mut out = Vec::with_capacity(8 * (n * (1 + j + 7) + 16));
    let put = |out: &mut Vec<u8>, x: u64| out.extend_from_slice(&x.to_le_bytes());
    let put_pose = |out: &mut Vec<u8>, p: &Isometry3<f64>| {
        pose_bits(p).into_iter().for_each(|x| put(out, x));
    };
    put(&mut out, n as u64);
    put(&mut out, j as u64);
    t.times.iter().for_each(|x| put(&mut out, x.to_bits()));
    t.joints
        .iter()
        .flatten()
        .for_each(|x| put(&mut out, x.to_bits()));
    t.tool.iter().for_each(|p| put_pose(&mut out, p));
    put(&mut out, t.lumber.len() as u64);
    for (id, track) in &t.lumber {
        put(&mut out, id.len() as u64);
        out.extend_from_slice(id.as_bytes());
        put(&mut out, track.keys.len() as u64);
        for (time, p) in &track.keys {
            put(&mut out, time.to_bits());
            put_pose(&mut out, p);
        }
        match track.gone {
            Some(g) => {
                put(&mut out, 1);
                put(&mut out, g.to_bits());
            }
            None => put(&mut out, 0),
        }
    }
    Some(out)
}

fn parse_body(body: &[u8]) -> Option<PoseTrace> {
    let mut r = Reader(body);
    let n = r.count(8)?;
    let j = r.count(8 * n)?;
    let times = r.floats(n)?;
    let joints = (0..n).map(|_| r.floats(j)).collect::<Option<_>>()?;
    let tool = (0..n).map(|_| r.pose()).collect::<Option<_>>()?;
    let mut trace = PoseTrace {
        times,
        joints,
        tool,
        ..PoseTrace::default()
    };
    let pieces = r.count(16)?;
    for _ in 0..pieces {
        let len = r.count(1)?;
        let id = String::from_utf8(r.take(len)?.to_vec()).ok()?;
        let keys = r.count(64)?;
        let mut track = LumberTrack::default();
        track.keys = (0..keys)
            .map(|_| Some((f64::from_bits(r.u64()?), r.pose()?)))
            .collect::<Option<_>>()?;
        track.gone = match r.u64()? {
            0 => None,
            1 => Some(f64::from_bits(r.u64()?)),
            _ => return None,
        };
        trace.lumber.insert(id, track);
    }
    r.0.is_empty().then_some(trace)
}

struct Reader<'a>(&'a [u8]);

impl Reader<'_> {
    fn take(&mut self, n: usize) -> Option<&[u8]> {
        if self.0.len() < n {
            return None;
        }
        let (head, rest) = self.0.split_at(n);
        self.0 = rest;
        Some(head)
    }
    fn u32(&mut self) -> Option<u32> {
        Some(u32::from_le_bytes(self.take(4)?.try_into().ok()?))
    }
    fn u64(&mut self) -> Option<u64> {
        Some(u64::from_le_bytes(self.take(8)?.try_into().ok()?))
    }
    /// A count of items of at least `each` bytes that the rest can hold (checked before any
    /// allocation, so a corrupt count cannot ask for more memory than the file implies).
    fn count(&mut self, each: usize) -> Option<usize> {
        let n = usize::try_from(self.u64()?).ok()?;
        (n.checked_mul(each.max(1))? <= self.0.len()).then_some(n)
    }
    fn floats(&mut self, n: usize) -> Option<Vec<f64>> {
        (0..n).map(|_| self.u64().map(f64::from_bits)).collect()
    }
    fn pose(&mut self) -> Option<Isometry3<f64>> {
        let mut b = [0u64; 7];
        for x in &mut b {
            *x = self.u64()?;
        }
        Some(pose(&b))
    }
}

fn pose_bits(p: &Isometry3<f64>) -> [u64; 7] {
    let t = p.translation.vector;
    let q = p.rotation.quaternion().coords;
    [t.x, t.y, t.z, q.x, q.y, q.z, q.w].map(f64::to_bits)
}

fn pose(b: &[u64; 7]) -> Isometry3<f64> {
    let [x, y, z, i, j, k, w] = b.map(f64::from_bits);
    // The stored quaternion is the unit one the executor had: rebuilt as is, not renormalised.
    Isometry3::from_parts(
        Translation3::new(x, y, z),
        UnitQuaternion::new_unchecked(Quaternion::new(w, i, j, k)),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample() -> PoseTrace {
        let mut t = PoseTrace::default();
        let a = Isometry3::new(
            nalgebra::Vector3::new(0.1 + 0.2, -1e-300, 3.0),
            nalgebra::Vector3::new(0.3, -0.2, 0.1),
        );
        let b = Isometry3::translation(1.0, 2.0, -0.0);
        t.sample(0.0, &[0.1, 0.2, 0.3, 0.4, 0.5, 0.6], a, &[("p1", a)]);
        t.sample(0.05, &[0.2, 0.2, 0.3, 0.4, 0.5, 0.7], b, &[("p1", b)]);
        t.sample(0.1, &[0.3, 0.2, 0.3, 0.4, 0.5, 0.8], a, &[]);
        t.finish();
        t
    }

    /// Everything of a trace as bits, to compare exactly.
    fn bits(t: &PoseTrace) -> Vec<u64> {
        body(t)
            .unwrap()
            .chunks(8)
            .map(|c| u64::from_le_bytes(c.try_into().unwrap_or([0; 8])))
            .collect()
    }

    #[test]
    fn a_trace_round_trips_bit_for_bit() {
        let t = sample();
        assert_eq!(
            t.lumber["p1"].gone,
            Some(0.1),
            "the sample has a piece that left"
        );
        let bytes = encode("k1", &t).unwrap();
        let back = decode("k1", &bytes).unwrap();
        assert_eq!(bits(&back), bits(&t));
        assert_eq!(
            back.tool[0].rotation.quaternion(),
            t.tool[0].rotation.quaternion()
        );
    }

    #[test]
    fn another_key_a_torn_or_altered_entry_is_refused() {
        let t = sample();
        let bytes = encode("k1", &t).unwrap();
        assert!(decode("k2", &bytes).is_none());
        for cut in [0, 10, bytes.len() / 2, bytes.len() - 1] {
            assert!(decode("k1", &bytes[..cut]).is_none(), "cut at {cut}");
        }
        // A body that deflates fine but differs from the digest: one joint value altered.
        let mut t2 = t.clone();
        t2.joints[0][0] = 0.10000000000000002;
        let other = encode("k1", &t2).unwrap();
        let head = 8 + 4 + 4 + 2;
        let mut mixed = bytes[..head + 32].to_vec();
        mixed.extend_from_slice(&other[head + 32..]);
        assert!(decode("k1", &mixed).is_none());
    }
}
