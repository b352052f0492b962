//! Keeping the files a rule program names (`.include`, `.input`, `.output`)
//! inside the folder they must stay in. A name is checked before the file is
//! opened, so a refused file is never read, let alone quoted in an error.

use std::fmt;
use std::path::{Component, Path, PathBuf};

/// Why a name was refused (phrased to follow the name in a message). Std only, as the rest
/// of `front`.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Refusal(pub String);

impl fmt::Display for Refusal {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for Refusal {}

/// `..` or an absolute path in a name given to `.input`/`.output`.
pub fn check_plain_relative(name: &str) -> Result<(), Refusal> {
    for c in Path::new(name).components() {
        match c {
            Component::Prefix(_) | Component::RootDir => {
                return Err(Refusal("is an absolute path".into()));
            }
            Component::ParentDir => return Err(Refusal("contains `..`".into())),
            Component::CurDir | Component::Normal(_) => {}
        }
    }
    Ok(())
}

/// The folder itself, canonicalised (symlinks followed), for `starts_with` checks.
pub fn canonical_root(root: &Path) -> Result<PathBuf, Refusal> {
    let root = if root.as_os_str().is_empty() {
        Path::new(".")
    } else {
        root
    };
    root.canonicalize()
        .map_err(|e| Refusal(format!("cannot resolve the folder {}: {e}", root.display())))
}

/// Checks that `path` (which may not exist yet) stays under `root` (canonical)
/// once every symbolic link on its existing part is followed.
pub fn check_inside(root: &Path, path: &Path) -> Result<(), Refusal> {
    let mut probe = path;
    loop {
        if std::fs::symlink_metadata(probe).is_ok() {
            let real = probe.canonicalize().map_err(|_| {
                Refusal(format!(
                    "goes through {}, a symbolic link that points nowhere",
                    probe.display()
                ))
            })?;
            if real.starts_with(root) {
                return Ok(());
            }
            return Err(Refusal(
                "leaves the folder (through `..` or a symbolic link)".into(),
            ));
        }
        match probe.parent() {
            Some(p) if !p.as_os_str().is_empty() => probe = p,
            // Nothing of it exists yet: the caller's folder is its start, checked already.
            _ => return Ok(()),
        }
    }
}
