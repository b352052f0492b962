//! Walls' records in the cache: what a run asks of each (`Need`), the look-up of a run's
//! walls by their keys, and what hits and misses came to (`CacheCounts`). The run itself
//! (prepare, simulate the misses, reason the verdicts) is `pipeline::Run`'s.

use super::store::{Cache, Lookup};
use crate::sim::WallRecord;
use serde::Serialize;

/// How many walls were simulated and how many came from the cache.
#[derive(Debug, Clone, Copy, Default, Serialize, PartialEq, Eq)]
pub struct CacheCounts {
    pub computed: usize,
    pub cached: usize,
    /// Entries found torn, corrupt or stale, and simulated again (included in `computed`).
    pub rejected: usize,
}

/// Shard `index` of `count` (1-based, as `--shard 2/3` writes it).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Shard {
    pub index: u64,
    pub count: u64,
}

/// A `--shard` value that is not `K/N` with 1 <= K <= N (the text given).
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("`{0}` is not a shard: write K/N with 1 <= K <= N, e.g. 2/3")]
pub struct ShardError(pub String);

impl std::str::FromStr for Shard {
    type Err = ShardError;
    fn from_str(s: &str) -> Result<Shard, ShardError> {
        let bad = || ShardError(s.to_string());
        let (k, n) = s.split_once('/').ok_or_else(bad)?;
        let index: u64 = k.trim().parse().map_err(|_| bad())?;
        let count: u64 = n.trim().parse().map_err(|_| bad())?;
        if index == 0 || index > count {
            return Err(bad());
        }
        Ok(Shard { index, count })
    }
}

impl std::fmt::Display for Shard {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}/{}", self.index, self.count)
    }
}

impl Shard {
    /// Whether a wall with this key belongs to the shard: its key's first 8 bytes, modulo the
    /// shard count. Keys are content hashes, so shards get about equal numbers of walls.
    pub fn holds(&self, key: &str) -> bool {
        let head = u64::from_str_radix(&key[..16.min(key.len())], 16).unwrap_or(0);
        head % self.count == self.index - 1
    }
}

/// What a shard run did.
#[derive(Debug, Serialize)]
pub struct ShardRun {
    pub shard: String,
    /// Wall ids (as the plan names them) of this shard, in plan order.
    pub walls: Vec<String>,
    /// Walls of the other shards.
    pub other_walls: usize,
    pub cache: CacheCounts,
}

/// What a cached run must hand back of each wall.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Need {
    /// The record: verdicts, times, contacts (what `--json` and the rules read).
    Records,
    /// The record and the pose trace the report animates; a wall whose trace the cache lacks
    /// is simulated again, and its trace stored.
    Traces,
}

/// The cached record of each wall (None for a miss), the misses, and the counts so far.
/// With `Need::Traces` a wall counts as cached only when its trace is there too.
pub(crate) fn look_up(
    cache: &Cache,
    walls: &[(String, String)],
    need: Need,
) -> (Vec<Option<WallRecord>>, Vec<(String, String)>, CacheCounts) {
    let mut counts = CacheCounts::default();
    let mut found = Vec::with_capacity(walls.len());
    let mut misses = Vec::new();
    for (key_piece, key) in walls {
        match cache.get_wall(key) {
            // An entry names its wall; one for another wall with equal inputs is not reused.
            Lookup::Hit(r) if &r.wall == key_piece => {
                let mut record = *r;
                if need == Need::Traces {
                    match cache.get_trace(key) {
                        Some(trace) => record.trace = trace,
                        None => {
                            found.push(None);
                            misses.push((key_piece.clone(), key.clone()));
                            continue;
                        }
                    }
                }
                counts.cached += 1;
                found.push(Some(record));
                continue;
            }
            Lookup::Hit(_) | Lookup::Miss => {}
            Lookup::Rejected => counts.rejected += 1,
        }
        found.push(None);
        misses.push((key_piece.clone(), key.clone()));
    }
    (found, misses, counts)
}

/// Stores what a run needs of a wall: its record, and with `Need::Traces` its trace.
pub(crate) fn store(cache: &Cache, key: &str, record: &WallRecord, need: Need) {
    cache.put_wall(key, record);
    if need == Need::Traces {
        cache.put_trace(key, &record.trace);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shards_parse_and_split_keys() {
        assert_eq!("2/3".parse::<Shard>(), Ok(Shard { index: 2, count: 3 }));
        for bad in ["0/3", "4/3", "3", "a/b", "1/0", ""] {
            assert!(bad.parse::<Shard>().is_err(), "{bad}");
        }
        // Every key lies in exactly one shard.
        for i in 0..50u32 {
            let key = blake3::hash(&i.to_le_bytes()).to_hex().to_string();
            let n = (1..=3)
                .filter(|k| {
                    Shard {
                        index: *k,
                        count: 3,
                    }
                    .holds(&key)
                })
                .count();
            assert_eq!(n, 1, "{key}");
        }
    }
}
