//! The per-wall result cache: each wall's simulation record, keyed by a content hash of
//! exactly what that wall's simulation reads (see `key`), in a folder the user can see,
//! share between processes and machines, and clear.

pub mod key;
pub mod plan;
pub mod plan_writer;
pub mod record_codec;
pub mod sim;
pub mod store;
pub mod trace_codec;
pub mod value_codec;

pub(crate) use plan::reason_plan_cached_with;
pub use plan_writer::PlanWriter;
pub use sim::{CacheCounts, Need, Shard, ShardError, ShardRun};
pub(crate) use sim::{look_up, store};
pub use store::{Cache, CacheInfo, clear, info};
