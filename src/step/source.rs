//! The bytes of a file: memory-mapped when possible, owned otherwise.

use super::error::{StepError, StepErrorKind};
use super::limits::{
    ENV_MAX_BYTES, ENV_MAX_DEPTH, ENV_MAX_INSTANCES, ENV_MAX_STRING_BYTES, ReadOptions,
};
use std::fs::File;
use std::path::Path;

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
