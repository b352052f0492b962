//! Shared by the integration tests: the test data in `../shared` beside the checkout, which
//! a test uses when present and skips (saying so) when absent; reading BCF archives back; the
//! Python oracles.
#![allow(dead_code)]

pub mod bcf;
pub mod python;

use std::path::{Path, PathBuf};

/// `../shared/<relative>` when it exists; otherwise None, after saying what is skipped.
pub fn shared_path(relative: &str) -> Option<PathBuf> {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../shared")
        .join(relative);
    if path.exists() {
        Some(path)
    } else {
        eprintln!("skipped: {} is absent", path.display());
        None
    }
}
