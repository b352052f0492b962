//! Loading robots by built-in name or path.

use super::builtin;
use super::error::CellError;
use super::meta::RobotMeta;
use super::robot::Robot;
use std::path::{Path, PathBuf};

fn read(path: &Path) -> Result<String, CellError> {
    std::fs::read_to_string(path).map_err(|source| CellError::Read {
        path: path.to_path_buf(),
        source,
    })
}

/// Whether `s` should be read as a file path rather than a built-in name.
pub(crate) fn looks_like_path(s: &str) -> bool {
    s.contains('/') || s.contains('\\') || s.contains('.')
}

impl Robot {
    /// A built-in robot (`abb-irb4600-40-255`, `kuka-kr150-2`) or a file: a `.urdf` (with an
    /// optional metadata file of the same stem and `.toml` beside it) or a metadata `.toml`.
    pub fn load(name_or_path: &str) -> Result<Robot, CellError> {
        if let Some(&(_, file, meta, urdf)) = builtin::ROBOTS.iter().find(|r| r.0 == name_or_path) {
            let path = Path::new(file);
            let (meta, _) = RobotMeta::parse(path, meta)?;
            return Robot::from_urdf_str(&path.with_extension("urdf"), urdf, meta);
        }
        if !looks_like_path(name_or_path) && !Path::new(name_or_path).exists() {
            return Err(CellError::UnknownName {
                what: "robot",
                name: name_or_path.to_string(),
                known: builtin::robot_names().join(", "),
            });
        }
        Robot::load_path(Path::new(name_or_path))
    }

    /// A robot from a `.urdf` or metadata `.toml` file.
    pub fn load_path(path: &Path) -> Result<Robot, CellError> {
        let is_toml = path.extension().is_some_and(|e| e == "toml");
        let (meta, urdf_path): (RobotMeta, PathBuf) = if is_toml {
            let (meta, urdf) = RobotMeta::parse(path, &read(path)?)?;
            let urdf_path = path.parent().unwrap_or(Path::new("")).join(urdf);
            (meta, urdf_path)
        } else {
            let sibling = path.with_extension("toml");
            let meta = if sibling.is_file() {
                RobotMeta::parse(&sibling, &read(&sibling)?)?.0
            } else {
                RobotMeta::default()
            };
            (meta, path.to_path_buf())
        };
        let text = read(&urdf_path)?;
        Robot::from_urdf_str(&urdf_path, &text, meta)
    }
}
