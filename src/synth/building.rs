//! Rectangular buildings of four walls, and grids of them for big models.
use crate::synth::SynthError;
use crate::synth::layout::{BuildingLayout, Layout, StoreyLayout, Vec3, WallFrame, WallLayout};
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
    Ok(BuildingLayout::one_storey(
        name,
        origin,
        frame_unit(spec, origin, prefix)?,
    ))
}

/// The four walls of one rectangular unit whose outer front-left corner sits at `origin`.
fn frame_unit(
    spec: &BuildingSpec,
    origin: Vec3,
    prefix: &str,
) -> Result<Vec<WallLayout>, SynthError> {
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
            detail: Default::default(),
            openings: spec.openings[k].clone(),
        };
        walls.push(frame_wall(&wall, frame)?);
    }
    Ok(walls)
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

/// Multi-storey blocks: `blocks` IfcBuildings in a row along x, each with `storeys`
/// storeys, each storey holding `rows` x `cols` units of the building spec `gap` metres
/// apart. Storeys stack `floor_depth` above the walls below (the floor structure), so
/// walls of different storeys never touch.
#[derive(Debug, Clone, PartialEq)]
pub struct BlockSpec {
    pub unit: BuildingSpec,
    pub blocks: usize,
    pub storeys: usize,
    pub rows: usize,
    pub cols: usize,
    pub gap: f64,
    pub floor_depth: f64,
}

/// Space between neighbouring units and blocks when none is given, metres.
pub const DEFAULT_GAP: f64 = 3.0;
/// Depth of the floor structure between storeys when none is given, metres.
pub const DEFAULT_FLOOR_DEPTH: f64 = 0.3;

impl BlockSpec {
    /// `blocks` blocks of `storeys` storeys of `rows` x `cols` units of `unit`, the default gap
    /// and floor depth apart (what `synth block` gives without `--gap`).
    pub fn new(
        unit: BuildingSpec,
        blocks: usize,
        storeys: usize,
        rows: usize,
        cols: usize,
    ) -> Self {
        BlockSpec {
            unit,
            blocks,
            storeys,
            rows,
            cols,
            gap: DEFAULT_GAP,
            floor_depth: DEFAULT_FLOOR_DEPTH,
        }
    }
}

/// Refuse block models with more than this many storeys in all (about 10^6 members at 10,000 units).
pub const MAX_STOREYS: usize = 1_000;

/// The layout of `spec`'s blocks; wall ids read `K<block>-L<storey>-U<row>_<col>-<side>`.
pub fn blocks(spec: &BlockSpec, name: &str) -> Result<Layout, SynthError> {
    let units = spec.rows.saturating_mul(spec.cols);
    let storeys = spec.blocks.saturating_mul(spec.storeys);
    if units == 0
        || storeys == 0
        || storeys > MAX_STOREYS
        || units.saturating_mul(storeys) > MAX_BUILDINGS
    {
        return Err(SynthError::Building {
            what: format!(
                "{} blocks x {} storeys x {}x{} units is empty or too big",
                spec.blocks, spec.storeys, spec.rows, spec.cols
            ),
            hint: format!(
                "use at least one of each, at most {MAX_STOREYS} storeys and {MAX_BUILDINGS} units in all"
            ),
        });
    }
    if !(spec.gap.is_finite()
        && spec.gap >= 0.0
        && spec.floor_depth.is_finite()
        && spec.floor_depth > 0.0)
    {
        return Err(SynthError::Building {
            what: format!("gap {} m, floor depth {} m", spec.gap, spec.floor_depth),
            hint: "the gap must be zero or positive and the floor depth positive".into(),
        });
    }
    let u = &spec.unit;
    let block_length = spec.cols as f64 * (u.length + spec.gap);
    let storey_height = u.height + spec.floor_depth;
    let mut buildings = Vec::with_capacity(spec.blocks);
    for k in 0..spec.blocks {
        let block = format!("K{}", k + 1);
        let origin = Vec3::new(k as f64 * (block_length + spec.gap), 0.0, 0.0);
        let mut levels = Vec::with_capacity(spec.storeys);
        for s in 0..spec.storeys {
            let elevation = s as f64 * storey_height;
            let mut walls = Vec::with_capacity(4 * units);
            for r in 0..spec.rows {
                for c in 0..spec.cols {
                    let corner = origin
                        + Vec3::new(
                            c as f64 * (u.length + spec.gap),
                            r as f64 * (u.depth + spec.gap),
                            elevation,
                        );
                    let prefix = format!("{block}-L{}-U{}_{}-", s + 1, r + 1, c + 1);
                    walls.extend(frame_unit(u, corner, &prefix)?);
                }
            }
            levels.push(StoreyLayout {
                name: format!("Level {}", s + 1),
                elevation,
                walls,
            });
        }
        buildings.push(BuildingLayout {
            name: block,
            origin,
            storeys: levels,
        });
    }
    Ok(Layout {
        name: name.to_string(),
        description: format!(
            "{} blocks of {} storeys, {}x{} units of {} m x {} m per storey",
            spec.blocks, spec.storeys, spec.rows, spec.cols, u.length, u.depth
        ),
        buildings,
    })
}
