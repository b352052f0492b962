//! The bytes of a file: memory-mapped when possible, owned otherwise.

use super::error::{StepError, StepErrorKind};
use std::fs::File;
use std::path::Path;

/// Limits applied while reading; each bounds memory or time by the input's size.
/// `from_env` raises them through `FRAMEWRIGHT_MAX_IFC_*` environment variables.
#[derive(Debug, Clone, Copy)]
pub struct ReadOptions {
    /// Files larger than this are refused before any work is done.
    pub max_bytes: u64,
    /// Deepest list nesting accepted when decoding parameters.
    pub max_depth: usize,
    /// Most entity instances indexed (each costs a record in memory).
    pub max_instances: usize,
    /// Longest string literal, in bytes of the file.
    pub max_string_bytes: usize,
}

impl Default for ReadOptions {
    fn default() -> Self {
        ReadOptions {
            max_bytes: 4 << 30,
            max_depth: 64,
            max_instances: 100_000_000,
            max_string_bytes: 16 << 20,
        }
    }
}

/// Environment variables that raise (or lower) the reader's limits.
pub const ENV_MAX_BYTES: &str = "FRAMEWRIGHT_MAX_IFC_BYTES";
pub const ENV_MAX_DEPTH: &str = "FRAMEWRIGHT_MAX_IFC_DEPTH";
pub const ENV_MAX_INSTANCES: &str = "FRAMEWRIGHT_MAX_IFC_INSTANCES";
pub const ENV_MAX_STRING_BYTES: &str = "FRAMEWRIGHT_MAX_IFC_STRING_BYTES";

impl ReadOptions {
    /// The defaults, with any limit set in the environment; a value that is not a
    /// whole number is an error naming the variable.
    pub fn from_env() -> Result<ReadOptions, StepError> {
        fn var(name: &'static str) -> Result<Option<u64>, StepError> {
            match std::env::var(name) {
                Ok(v) => v.trim().parse::<u64>().map(Some).map_err(|_| {
                    StepError::new(StepErrorKind::BadLimit {
                        variable: name,
                        value: v,
                    })
                }),
                Err(_) => Ok(None),
            }
        }
        let d = ReadOptions::default();
        let size = |v: Option<u64>, default: usize| v.map_or(default, |v| v as usize);
        Ok(ReadOptions {
            max_bytes: var(ENV_MAX_BYTES)?.unwrap_or(d.max_bytes),
            max_depth: size(var(ENV_MAX_DEPTH)?, d.max_depth),
            max_instances: size(var(ENV_MAX_INSTANCES)?, d.max_instances),
            max_string_bytes: size(var(ENV_MAX_STRING_BYTES)?, d.max_string_bytes),
        })
    }
}

pub enum Source {
    Mapped(memmap2::Mmap),
    Owned(Vec<u8>),
}

impl Source {
    pub fn open(path: &Path, options: &ReadOptions) -> Result<Source, StepError> {
        let io = |e: std::io::Error| StepError::new(StepErrorKind::Io(e.to_string()));
        let file = File::open(path).map_err(io)?;
        let len = file.metadata().map_err(io)?.len();
        if len > options.max_bytes {
            return Err(StepError::new(StepErrorKind::TooLarge {
                bytes: len,
                limit: options.max_bytes,
            }));
        }
        if len == 0 {
            return Ok(Source::Owned(Vec::new()));
        }
        // SAFETY: the map is read-only and lives as long as the model. A file
        // changed by another process while being read may give wrong values
        // (never memory unsafety in our code, which only reads bytes).
        match unsafe { memmap2::Mmap::map(&file) } {
            Ok(map) => Ok(Source::Mapped(map)),
            Err(_) => std::fs::read(path).map(Source::Owned).map_err(io),
        }
    }

    pub fn bytes(&self) -> &[u8] {
        match self {
            Source::Mapped(m) => m,
            Source::Owned(v) => v,
        }
    }
}
