//! Rectangular buildings of four walls, and grids of them for big models.
use crate::synth::SynthError;
use crate::synth::layout::{BuildingLayout, Layout, Vec3, WallFrame};
use crate::synth::units::Lumber;
use crate::synth::wall::{HeaderStyle, OpeningSpec, StudLayout, WallSpec, frame_wall};

/// Front and back walls run the full length; left and right fit between them.
#[derive(Debug, Clone, PartialEq)]
pub struct BuildingSpec {
    /// Outer length along x (front and back walls).
    pub length: f64,
    /// Outer depth along y.
    pub depth: f64,
    pub height: f64,
    pub lumber: Lumber,
    pub studs: StudLayout,
    pub double_top_plate: bool,
    pub header_style: HeaderStyle,
    /// Openings of the front, left, back and right walls, in that order.
    pub openings: [Vec<OpeningSpec>; 4],
}

const SIDES: [(&str, &str); 4] = [
    ("F", "Front wall"),
    ("L", "Left wall"),
    ("B", "Back wall"),
    ("R", "Right wall"),
];
/// Refuse grids that would write more than this many buildings (about 10^6 members).
pub const MAX_BUILDINGS: usize = 10_000;

/// Frame one building whose outer corner (front-left) sits at `origin`; wall ids get `prefix`.
pub fn frame_building(
    spec: &BuildingSpec,
    name: &str,
    origin: Vec3,
    prefix: &str,
) -> Result<BuildingLayout, SynthError> {
    let t = spec.lumber.width;
    if !(spec.depth.is_finite() && spec.depth > 2.0 * t) {
        return Err(SynthError::Building {
            what: format!("depth {} m leaves no room for the side walls", spec.depth),
            hint: "depth is the outer size along y, in metres unless given with a unit".into(),
        });
    }
    let (lx, dy) = (spec.length, spec.depth);
    let x = Vec3::new(1.0, 0.0, 0.0);
    let y = Vec3::new(0.0, 1.0, 0.0);
    // Each wall's outer face is on the outside of the rectangle, walked clockwise from above.
    let frames = [
        (WallFrame::upright(origin + x * lx, -x), lx),
        (WallFrame::upright(origin + y * t, y), dy - 2.0 * t),
        (WallFrame::upright(origin + y * dy, x), lx),
        (
            WallFrame::upright(origin + x * lx + y * (dy - t), -y),
            dy - 2.0 * t,
        ),
    ];
    let mut walls = Vec::with_capacity(4);
    for (k, ((frame, length), (id, wall_name))) in frames.into_iter().zip(SIDES).enumerate() {
        let wall = WallSpec {
            id: format!("{prefix}{id}"),
            name: wall_name.to_string(),
            length,
            height: spec.height,
            lumber: spec.lumber,
            studs: spec.studs,
            double_top_plate: spec.double_top_plate,
            header_style: spec.header_style,
            openings: spec.openings[k].clone(),
        };
        walls.push(frame_wall(&wall, frame)?);
    }
    Ok(BuildingLayout {
        name: name.to_string(),
        origin,
        storey_name: "Level 1".into(),
        walls,
    })
}

/// `rows` x `cols` copies of the building, `gap` metres apart, each its own IfcBuilding.
pub fn grid(
    spec: &BuildingSpec,
    rows: usize,
    cols: usize,
    gap: f64,
    name: &str,
) -> Result<Layout, SynthError> {
    if rows == 0 || cols == 0 || rows.saturating_mul(cols) > MAX_BUILDINGS {
        return Err(SynthError::Building {
            what: format!("grid {rows}x{cols} is empty or has more than {MAX_BUILDINGS} buildings"),
            hint: "use --grid NxM with 1 <= N*M <= 10000".into(),
        });
    }
    if !(gap.is_finite() && gap >= 0.0) {
        return Err(SynthError::Building {
            what: format!("gap {gap} m"),
            hint: "the gap must be zero or positive".into(),
        });
    }
    let mut buildings = Vec::with_capacity(rows * cols);
    for r in 0..rows {
        for c in 0..cols {
            let origin = Vec3::new(
                c as f64 * (spec.length + gap),
                r as f64 * (spec.depth + gap),
                0.0,
            );
            let label = format!("B{}_{}", r + 1, c + 1);
            buildings.push(frame_building(spec, &label, origin, &format!("{label}-"))?);
        }
    }
    Ok(Layout {
        name: name.to_string(),
        description: format!(
            "{rows}x{cols} grid of {} m x {} m wood-frame buildings",
            spec.length, spec.depth
        ),
        buildings,
    })
}
