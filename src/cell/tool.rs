//! End effectors (`robots/tools/*.toml`): rigid parts with primitive shapes and masses in the
//! robot's `tool0` frame, named TCP frames (`grip`, `nail`) and the gripper's opening.

use super::builtin;
use super::error::CellError;
use super::load::looks_like_path;
use super::shapes::{PlacedShape, Shape, isometry_from_xyz_rpy};
use super::toml_file;
use nalgebra::{Isometry3, Vector3};
use serde::Deserialize;
use std::collections::BTreeMap;
use std::path::Path;

/// The steepest lean a tool file may allow: toe nails are driven at about 30° to the member.
const MAX_LEAN_DEG: f64 = 30.0;
/// The longest nailer slide a tool file may give (m).
const MAX_SLIDE: f64 = 0.5;

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct ToolFile {
    name: Option<String>,
    description: Option<String>,
    tcp: BTreeMap<String, FrameFile>,
    gripper: Option<GripperFile>,
    nailer: Option<NailerFile>,
    parts: Vec<PartFile>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct NailerFile {
    max_lean_deg: f64,
    #[serde(default)]
    slide: Option<f64>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct FrameFile {
    position: [f64; 3],
    #[serde(default)]
    rpy_deg: [f64; 3],
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct GripperFile {
    /// "sides" (the default): jaws close on the piece's side faces; "top": pads hold its top face.
    #[serde(default)]
    holds: Option<String>,
    count: u32,
    spacing: f64,
    stroke: Option<f64>,
    open_width: Option<f64>,
    closed_width: Option<f64>,
    jaw_depth: Option<f64>,
    pad_width: Option<f64>,
    max_mass: Option<f64>,
    max_lumber: String,
    max_lumber_section: [f64; 2],
    #[serde(default)]
    one_gripper_max_mass: Option<f64>,
    #[serde(default)]
    one_gripper_max_moment: Option<f64>,
    #[serde(default)]
    one_gripper_min_length: Option<f64>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct PartFile {
    name: String,
    mass: f64,
    position: [f64; 3],
    #[serde(default)]
    rpy_deg: [f64; 3],
    geometry: GeometryFile,
}

#[derive(Debug, Deserialize)]
#[serde(tag = "shape", rename_all = "snake_case", deny_unknown_fields)]
enum GeometryFile {
    Box { size: [f64; 3] },
    Cylinder { radius: f64, length: f64 },
    Capsule { radius: f64, length: f64 },
    Sphere { radius: f64 },
}

/// One rigid part of a tool.
#[derive(Debug, Clone, serde::Serialize)]
pub struct ToolPart {
    pub name: String,
    /// kg
    pub mass: f64,
    /// Shape placed in tool0.
    pub shape: PlacedShape,
}

/// The grippers of a tool, spaced along the lumber (all lengths in m).
#[derive(Debug, Clone, serde::Serialize)]
pub struct Gripper {
    pub count: u32,
    /// Distance between gripper centres along the lumber's long axis.
    pub spacing: f64,
    /// How each gripper holds the piece.
    pub holds: Hold,
    /// Trade name of the widest lumber taken, e.g. "2x6".
    pub max_lumber: String,
    /// Thickness and width of that lumber.
    pub max_lumber_section: [f64; 2],
    /// What one gripper alone may hold (a piece shorter than the spacing); none: such pieces
    /// are refused.
    pub one_gripper: Option<OneGripper>,
}

/// How a gripper holds lumber.
#[derive(Debug, Clone, Copy, serde::Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum Hold {
    /// Parallel jaws close on the piece's side faces: a finger goes down each side, so the
    /// piece cannot be set against a neighbour face to face.
    Sides(Jaws),
    /// Pads (vacuum or needles) hold the piece's top face: nothing reaches below it.
    Top(TopPads),
}

/// A parallel gripper's jaws (m).
#[derive(Debug, Clone, Copy, serde::Serialize)]
pub struct Jaws {
    /// Travel of each jaw.
    pub stroke: f64,
    pub open_width: f64,
    pub closed_width: f64,
    /// How far the fingers reach below the palm.
    pub jaw_depth: f64,
}

/// Pads holding the top face.
#[derive(Debug, Clone, Copy, serde::Serialize)]
pub struct TopPads {
    /// The pads' width across the piece: the narrowest top face they hold, m.
    pub pad_width: f64,
    /// The heaviest piece all the pads together hold, kg.
    pub max_mass: f64,
}

/// The rated limits of one gripper holding a piece on its own.
#[derive(Debug, Clone, Copy, serde::Serialize)]
pub struct OneGripper {
    /// Heaviest piece, kg.
    pub max_mass: f64,
    /// Largest moment of the piece's weight about the jaws (its centre of mass off the
    /// gripper's centre), N·m.
    pub max_moment: f64,
    /// Shortest piece the jaws hold square, m (about the jaws' length along the piece).
    pub min_length: f64,
}

impl Gripper {
    /// The jaws, when the gripper holds the piece by its sides.
    pub fn jaws(&self) -> Option<&Jaws> {
        match &self.holds {
            Hold::Sides(j) => Some(j),
            Hold::Top(_) => None,
        }
    }
}

impl Jaws {
    /// Whether a lumber cross-section (any way up) fits between the open jaws and is held
    /// when they close.
    pub fn takes(&self, thickness: f64, width: f64) -> bool {
        let (small, large) = (thickness.min(width), thickness.max(width));
        small >= self.closed_width && large <= self.open_width
    }
}

#[derive(Debug, Clone, serde::Serialize)]
pub struct Tool {
    pub name: String,
    pub description: Option<String>,
    pub parts: Vec<ToolPart>,
    /// TCP frames in tool0, by name.
    #[serde(serialize_with = "serialize_frames")]
    pub tcps: BTreeMap<String, Isometry3<f64>>,
    pub gripper: Option<Gripper>,
    /// How far (rad) a nail may lean off the planned line, tipped up or down in the vertical
    /// plane through it, where the square nail is out of reach; 0 drives every nail square.
    pub max_nail_lean: f64,
    /// How far the nailer (the parts named `nailer…`) rides back on a slide towards the
    /// flange while it is not nailing, m; 0: fixed where the file places it (out).
    pub nailer_slide: f64,
    /// Total mass, kg.
    pub mass: f64,
    /// Centre of mass in tool0, m (part shapes' centres weighted by part masses).
    pub centre_of_mass: [f64; 3],
}

fn serialize_frames<S: serde::Serializer>(
    frames: &BTreeMap<String, Isometry3<f64>>,
    s: S,
) -> Result<S::Ok, S::Error> {
    use serde::ser::SerializeMap;
    let mut map = s.serialize_map(Some(frames.len()))?;
    for (k, v) in frames {
        map.serialize_entry(k, &super::matrix_rows(v))?;
    }
    map.end()
}

impl Tool {
    /// A built-in tool (`study-gripper-nailer`) or a tool TOML file.
    pub fn load(name_or_path: &str) -> Result<Tool, CellError> {
        if let Some(&(_, file, text)) = builtin::TOOLS.iter().find(|t| t.0 == name_or_path) {
            return Tool::parse(Path::new(file), text);
        }
        if !looks_like_path(name_or_path) && !Path::new(name_or_path).exists() {
            return Err(CellError::UnknownName {
                what: "tool",
                name: name_or_path.to_string(),
                known: builtin::tool_names().join(", "),
            });
        }
        let path = Path::new(name_or_path);
        let text = std::fs::read_to_string(path).map_err(|source| CellError::Read {
            path: path.to_path_buf(),
            source,
        })?;
        Tool::parse(path, &text)
    }

    /// The study's end effector.
    pub fn study() -> Tool {
        Tool::load("study-gripper-nailer").expect("the built-in tool parses")
    }

    /// TCP frame in tool0.
    pub fn tcp(&self, name: &str) -> Option<&Isometry3<f64>> {
        self.tcps.get(name)
    }

    pub fn parse(path: &Path, text: &str) -> Result<Tool, CellError> {
        let file: ToolFile = toml_file::parse(path, text)?;
        let bad = |section: &str, key: &str, msg: String| {
            toml_file::value_error(path, text, section, key, msg)
        };
        let positive = |v: f64| v.is_finite() && v > 0.0;
        let sane_len = |v: f64| v.is_finite() && v.abs() <= 10.0;
        let mut tcps = BTreeMap::new();
        for (name, f) in &file.tcp {
            if !(f.position.iter().all(|v| sane_len(*v)) && f.rpy_deg.iter().all(|v| v.is_finite()))
            {
                return Err(bad(
                    &format!("tcp.{name}"),
                    "position",
                    "expected finite numbers within 10 m".into(),
                ));
            }
            tcps.insert(
                name.clone(),
                isometry_from_xyz_rpy(f.position, f.rpy_deg.map(f64::to_radians)),
            );
        }
        if file.parts.is_empty() {
            return Err(bad(
                "",
                "parts",
                "a tool needs at least one [[parts]] entry".into(),
            ));
        }
        let mut parts = vec![];
        let mut mass = 0.0;
        let mut moment = Vector3::zeros();
        for p in &file.parts {
            let section = "parts";
            if !(p.mass.is_finite() && p.mass >= 0.0 && p.mass <= 1000.0) {
                return Err(bad(
                    section,
                    "mass",
                    format!(
                        "part `{}`: expected a mass in kg between 0 and 1000, got {}",
                        p.name, p.mass
                    ),
                ));
            }
            if !p.position.iter().all(|v| sane_len(*v)) {
                return Err(bad(
                    section,
                    "position",
                    format!("part `{}`: expected finite numbers within 10 m", p.name),
                ));
            }
            let shape = match p.geometry {
                GeometryFile::Box { size } if size.iter().all(|v| positive(*v) && *v <= 10.0) => {
                    Shape::Box {
                        half_extents: size.map(|v| v / 2.0),
                    }
                }
                GeometryFile::Cylinder { radius, length }
                    if positive(radius) && positive(length) && radius <= 5.0 && length <= 10.0 =>
                {
                    Shape::Cylinder { radius, length }
                }
                GeometryFile::Capsule { radius, length }
                    if positive(radius) && positive(length) && radius <= 5.0 && length <= 10.0 =>
                {
                    Shape::Capsule { radius, length }
                }
                GeometryFile::Sphere { radius } if positive(radius) && radius <= 5.0 => {
                    Shape::Sphere { radius }
                }
                _ => {
                    return Err(bad(
                        section,
                        "geometry",
                        format!("part `{}`: sizes must be positive and at most 10 m", p.name),
                    ));
                }
            };
            let origin = isometry_from_xyz_rpy(p.position, p.rpy_deg.map(f64::to_radians));
            mass += p.mass;
            moment += origin.translation.vector * p.mass;
            parts.push(ToolPart {
                name: p.name.clone(),
                mass: p.mass,
                shape: PlacedShape { origin, shape },
            });
        }
        let gripper = match file.gripper {
            None => None,
            Some(g) => Some(parse_gripper(g, &bad)?),
        };
        let nailer_slide = match file.nailer.as_ref().and_then(|n| n.slide) {
            None => 0.0,
            Some(s) if s.is_finite() && (0.0..=MAX_SLIDE).contains(&s) => s,
            Some(s) => {
                return Err(bad(
                    "nailer",
                    "slide",
                    format!(
                        "expected how far the nailer rides back, in m from 0 to {MAX_SLIDE}, got {s}"
                    ),
                ));
            }
        };
        let max_nail_lean = match file.nailer {
            None => 0.0,
            Some(n)
                if n.max_lean_deg.is_finite() && (0.0..=MAX_LEAN_DEG).contains(&n.max_lean_deg) =>
            {
                n.max_lean_deg.to_radians()
            }
            Some(n) => {
                return Err(bad(
                    "nailer",
                    "max_lean_deg",
                    format!(
                        "expected an angle from 0 to {MAX_LEAN_DEG} degrees (a nail leaning farther is a toe nail), got {}",
                        n.max_lean_deg
                    ),
                ));
            }
        };
        let com = if mass > 0.0 {
            moment / mass
        } else {
            Vector3::zeros()
        };
        Ok(Tool {
            name: file.name.unwrap_or_else(|| {
                path.file_stem()
                    .map_or("tool".into(), |s| s.to_string_lossy().into_owned())
            }),
            description: file.description,
            parts,
            tcps,
            gripper,
            max_nail_lean,
            nailer_slide,
            mass,
            centre_of_mass: [com.x, com.y, com.z],
        })
    }
}

/// The kinds of gripper, as the messages about their keys name them.
const SIDES: &str = "sides (holds = \"sides\", the default)";
const TOP: &str = "top face (holds = \"top\")";

/// The `[gripper]` table: jaws on the sides (`holds = "sides"`, the default) or pads on the top
/// face (`holds = "top"`), each with its own keys.
fn parse_gripper(
    g: GripperFile,
    bad: &dyn Fn(&str, &str, String) -> CellError,
) -> Result<Gripper, CellError> {
    let positive = |v: f64| v.is_finite() && v > 0.0;
    let length = |key: &str, v: f64| {
        if positive(v) && v <= 10.0 {
            Ok(v)
        } else {
            Err(bad(
                "gripper",
                key,
                format!("expected a length in m, positive and at most 10 m, got {v}"),
            ))
        }
    };
    // A key the kind of gripper needs (`holds` says which, for the message).
    let needed = |key: &str, v: Option<f64>, holds: &str| {
        v.ok_or_else(|| {
            bad(
                "gripper",
                key,
                format!("`{key}` is missing: a gripper holding the {holds} needs it"),
            )
        })
    };
    let spacing = length("spacing", g.spacing)?;
    if !g
        .max_lumber_section
        .iter()
        .all(|v| positive(*v) && *v <= 10.0)
    {
        return Err(bad(
            "gripper",
            "max_lumber_section",
            "expected two lengths in m, positive and at most 10 m".into(),
        ));
    }
    let unused =
        |keys: &[(&str, Option<f64>)], holds: &str| match keys.iter().find(|(_, v)| v.is_some()) {
            Some((key, _)) => Err(bad(
                "gripper",
                key,
                format!("`{key}` does not apply to a gripper holding the {holds}: remove it"),
            )),
            None => Ok(()),
        };
    let holds = match g.holds.as_deref().unwrap_or("sides") {
        "sides" => {
            unused(
                &[("pad_width", g.pad_width), ("max_mass", g.max_mass)],
                "sides",
            )?;
            let jaws = Jaws {
                stroke: length("stroke", needed("stroke", g.stroke, SIDES)?)?,
                open_width: length("open_width", needed("open_width", g.open_width, SIDES)?)?,
                closed_width: length(
                    "closed_width",
                    needed("closed_width", g.closed_width, SIDES)?,
                )?,
                jaw_depth: length("jaw_depth", needed("jaw_depth", g.jaw_depth, SIDES)?)?,
            };
            if jaws.closed_width >= jaws.open_width {
                return Err(bad(
                    "gripper",
                    "closed_width",
                    format!(
                        "closed width {} must be smaller than the open width {}",
                        jaws.closed_width, jaws.open_width
                    ),
                ));
            }
            let [t, w] = g.max_lumber_section;
            if !jaws.takes(t, w) {
                return Err(bad(
                    "gripper",
                    "max_lumber_section",
                    format!(
                        "{t} x {w} m does not fit the jaws ({} to {} m)",
                        jaws.closed_width, jaws.open_width
                    ),
                ));
            }
            Hold::Sides(jaws)
        }
        "top" => {
            unused(
                &[
                    ("stroke", g.stroke),
                    ("open_width", g.open_width),
                    ("closed_width", g.closed_width),
                    ("jaw_depth", g.jaw_depth),
                ],
                "top face",
            )?;
            let pads = TopPads {
                pad_width: length("pad_width", needed("pad_width", g.pad_width, TOP)?)?,
                max_mass: match needed("max_mass", g.max_mass, TOP)? {
                    m if positive(m) && m <= 1e4 => m,
                    m => {
                        return Err(bad(
                            "gripper",
                            "max_mass",
                            format!("expected a mass in kg, positive and at most 10,000, got {m}"),
                        ));
                    }
                },
            };
            Hold::Top(pads)
        }
        other => {
            return Err(bad(
                "gripper",
                "holds",
                format!(
                    "expected \"sides\" (jaws on the piece's side faces) or \"top\" (pads on its top face), got \"{other}\""
                ),
            ));
        }
    };
    let one_gripper = match (
        g.one_gripper_max_mass,
        g.one_gripper_max_moment,
        g.one_gripper_min_length,
    ) {
        (None, None, None) => None,
        (Some(max_mass), Some(max_moment), Some(min_length))
            if [max_mass, max_moment]
                .iter()
                .all(|v| positive(*v) && *v <= 1e4)
                && positive(min_length)
                && min_length < spacing =>
        {
            Some(OneGripper {
                max_mass,
                max_moment,
                min_length,
            })
        }
        _ => {
            return Err(bad(
                "gripper",
                "one_gripper_max_mass",
                "one_gripper_max_mass (kg), one_gripper_max_moment (N m) and one_gripper_min_length (m) go together: give all three, positive, the length below the spacing (or none: pieces shorter than the spacing are refused)".into(),
            ));
        }
    };
    Ok(Gripper {
        count: g.count,
        spacing,
        holds,
        max_lumber: g.max_lumber,
        max_lumber_section: g.max_lumber_section,
        one_gripper,
    })
}
