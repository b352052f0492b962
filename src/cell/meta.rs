//! Robot metadata (`robots/<name>.toml`): payload, reach, home pose, acceleration limits and the
//! OPW parameters for closed-form IK.

use super::error::CellError;
use super::toml_file;
use serde::Deserialize;
use std::path::Path;

/// The metadata file as written (angles in degrees).
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct MetaFile {
    pub name: Option<String>,
    pub description: Option<String>,
    /// URDF file, relative to the metadata file.
    pub urdf: String,
    pub tip_link: Option<String>,
    pub payload: Option<f64>,
    pub reach: Option<f64>,
    pub home_deg: Option<Vec<f64>>,
    pub acceleration_deg_s2: Option<Vec<f64>>,
    pub opw: Option<OpwFile>,
}

#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct OpwFile {
    pub a1: f64,
    pub a2: f64,
    pub b: f64,
    pub c1: f64,
    pub c2: f64,
    pub c3: f64,
    pub c4: f64,
    pub offsets_deg: [f64; 6],
    pub sign_corrections: [i8; 6],
}

/// Robot metadata in SI units (radians).
#[derive(Debug, Clone, Default, serde::Serialize)]
pub struct RobotMeta {
    pub name: Option<String>,
    pub description: Option<String>,
    pub tip_link: Option<String>,
    /// Rated payload, kg.
    pub payload: Option<f64>,
    /// Published reach, m.
    pub reach: Option<f64>,
    pub home: Option<Vec<f64>>,
    /// Joint acceleration limits, rad/s² (estimates; see robots/README.md).
    pub acceleration: Option<Vec<f64>>,
    pub opw: Option<OpwParams>,
}

/// OPW parameters (Brandstötter, Angerer & Hofbaur 2014); joint = (internal + offset) · sign.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct OpwParams {
    pub a1: f64,
    pub a2: f64,
    pub b: f64,
    pub c1: f64,
    pub c2: f64,
    pub c3: f64,
    pub c4: f64,
    pub offsets: [f64; 6],
    pub signs: [f64; 6],
}

impl RobotMeta {
    /// Parse a metadata file; returns the metadata and the URDF path it names (relative to `path`).
    pub fn parse(path: &Path, text: &str) -> Result<(RobotMeta, String), CellError> {
        let file: MetaFile = toml_file::parse(path, text)?;
        let bad = |key: &str, msg: String| {
            let (section, key) = key.split_once('.').unwrap_or(("", key));
            toml_file::value_error(path, text, section, key, msg)
        };
        for (key, v) in [("payload", file.payload), ("reach", file.reach)] {
            if let Some(v) = v
                && !(v.is_finite() && v > 0.0)
            {
                return Err(bad(key, format!("expected a positive number, got {v}")));
            }
        }
        if let Some(acc) = &file.acceleration_deg_s2
            && let Some(v) = acc.iter().find(|v| !(v.is_finite() && **v > 0.0))
        {
            {
                return Err(bad(
                    "acceleration_deg_s2",
                    format!("expected positive numbers (deg/s²), got {v}"),
                ));
            }
        }
        let opw = match &file.opw {
            None => None,
            Some(o) => {
                let lengths = [o.a1, o.a2, o.b, o.c1, o.c2, o.c3, o.c4];
                if !lengths
                    .iter()
                    .chain(o.offsets_deg.iter())
                    .all(|v| v.is_finite())
                {
                    return Err(bad(
                        "opw.a1",
                        "OPW parameters must be finite numbers".into(),
                    ));
                }
                if let Some(s) = o.sign_corrections.iter().find(|s| s.abs() != 1) {
                    return Err(bad(
                        "opw.sign_corrections",
                        format!("expected 1 or -1, got {s}"),
                    ));
                }
                if !(o.c2 > 0.0 && (o.a2 * o.a2 + o.c3 * o.c3) > 0.0) {
                    return Err(bad(
                        "opw.c2",
                        "c2 and (a2, c3) must give non-zero arm lengths".into(),
                    ));
                }
                Some(OpwParams {
                    a1: o.a1,
                    a2: o.a2,
                    b: o.b,
                    c1: o.c1,
                    c2: o.c2,
                    c3: o.c3,
                    c4: o.c4,
                    offsets: o.offsets_deg.map(f64::to_radians),
                    signs: o.sign_corrections.map(f64::from),
                })
            }
        };
        let meta = RobotMeta {
            name: file.name,
            description: file.description,
            tip_link: file.tip_link,
            payload: file.payload,
            reach: file.reach,
            home: file
                .home_deg
                .map(|h| h.into_iter().map(f64::to_radians).collect()),
            acceleration: file
                .acceleration_deg_s2
                .map(|a| a.into_iter().map(f64::to_radians).collect()),
            opw,
        };
        Ok((meta, file.urdf))
    }
}
