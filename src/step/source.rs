//! The bytes of a file: memory-mapped when possible, owned otherwise.

use super::error::{StepError, StepErrorKind};
use super::limits::ReadOptions;
use std::fs::File;
use std::path::Path;

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
