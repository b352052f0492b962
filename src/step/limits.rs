//! The reader's limits: each bounds memory or time by the input's size, and the environment
//! variables that set them.

/// Limits applied while reading; each bounds memory or time by the input's size.
/// The CLI raises them through the `FRAMEWRIGHT_MAX_IFC_*` environment variables.
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
