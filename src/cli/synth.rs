//! `framewright synth MODEL`: write a generated wood-frame IFC model (and its truth sidecar).
use super::{CmdResult, Failure, print_stdout};
use framewright::synth::building::{
    BlockSpec, BuildingSpec, DEFAULT_FLOOR_DEPTH, DEFAULT_GAP, frame_building, grid,
};
use framewright::synth::layout::{Layout, Vec3};
use framewright::synth::models;
use framewright::synth::units::{Lumber, parse_length};
use framewright::synth::wall::{
    CornerStyle, FramingDetail, HeaderStyle, OpeningKind, OpeningSpec, PartitionSpec,
    PartitionStyle, SillStyle, StudLayout, WallSpec,
};
use framewright::synth::{
    Grouping, LengthUnit, PlacementBase, ProductClasses, Schema, SynthError, WriteOptions,
    write_ifc,
};
use std::path::PathBuf;

#[derive(Clone, Copy, clap::ValueEnum)]
pub enum ProductsArg {
    Member,
    ColumnBeam,
}

#[derive(Clone, Copy, clap::ValueEnum)]
pub enum GroupingArg {
    None,
    Wall,
    Assembly,
}

#[derive(Clone, Copy, clap::ValueEnum)]
pub enum PlacementArg {
    Storey,
    Parent,
}

#[derive(Clone, Copy, clap::ValueEnum)]
pub enum HeaderArg {
    BuiltUp,
    Solid,
    /// One flat piece of the wall's lumber between the king studs, no jack studs.
    Flat,
}

#[derive(Clone, Copy, clap::ValueEnum)]
pub enum CornerArg {
    /// One end stud.
    Single,
    /// The end stud and a stud turned flat beside it at the inner face (California corner).
    Backer,
    /// The end stud and a second stud with spacer blocks between (three-stud corner).
    ThreeStud,
    /// The end stud and a second stud one bay in, ladder blocks between.
    Ladder,
}

#[derive(Clone, Copy, clap::ValueEnum)]
pub enum SillArg {
    /// Between the jack studs, which run down to the bottom plate.
    BetweenJacks,
    /// From king stud to king stud, the jacks standing on it.
    KingToKing,
}

#[derive(clap::Args)]
pub struct SynthArgs {
    /// Which model to write: tm1, tm2, tm3 (the study's test models), wall, building,
    /// block (multi-storey blocks of units: --blocks, --storeys, --grid).
    pub model: String,
    /// Output IFC file (default: standard output).
    #[arg(short, long)]
    pub output: Option<PathBuf>,
    /// Length unit of the file: m, mm, ft, in.
    #[arg(long, default_value = "m")]
    pub unit: String,
    /// IFC schema: IFC4, IFC2X3, IFC4X3.
    #[arg(long, default_value = "IFC4")]
    pub schema: String,
    /// IFC classes of framing pieces.
    #[arg(long, value_enum, default_value = "member")]
    pub products: ProductsArg,
    /// Aggregate each wall's members into an IfcWall or IfcElementAssembly.
    #[arg(long, value_enum, default_value = "none")]
    pub grouping: GroupingArg,
    /// Write pieces as IfcMappedItems, one product per wall and direction.
    #[arg(long)]
    pub mapped: bool,
    /// Member placements relative to the storey or to their wall (default: wall when grouped).
    #[arg(long, value_enum)]
    pub placement: Option<PlacementArg>,
    /// For `building`: a grid of N x M buildings, e.g. 20x30. For `block`: the units on
    /// each storey of a block (default 3x9).
    #[arg(long)]
    pub grid: Option<String>,
    /// For `block`: how many blocks, side by side along x (default 3).
    #[arg(long)]
    pub blocks: Option<usize>,
    /// For `block`: storeys per block (default 5).
    #[arg(long)]
    pub storeys: Option<usize>,
    /// A property set (Pset_MemberCommon, …) for every framing product.
    #[arg(long)]
    pub psets: bool,
    /// With --grouping: an IfcOpeningElement voiding the wall and an IfcDoor or IfcWindow
    /// filling it for every rough opening.
    #[arg(long)]
    pub openings: bool,
    /// Gap between buildings of a grid (default 3m).
    #[arg(long)]
    pub gap: Option<String>,
    /// Also write the truth JSON sidecar here.
    #[arg(long)]
    pub truth: Option<PathBuf>,
    /// Seed of the GlobalId hash.
    #[arg(long, default_value_t = 20_240_101)]
    pub seed: u64,
    /// Geometry of `wall` and `building` (boxed: keeps the command enum small).
    #[command(flatten)]
    pub geometry: Box<GeometryArgs>,
}

/// Parameters of the parametric models.
#[derive(clap::Args)]
pub struct GeometryArgs {
    /// Wall length, or building length along x (number in metres, or with m, mm, ft, in).
    #[arg(long)]
    pub length: Option<String>,
    /// Overall wall height including plates.
    #[arg(long)]
    pub height: Option<String>,
    /// Building depth along y (outer).
    #[arg(long)]
    pub depth: Option<String>,
    /// Lumber size: 2x4 or 2x6.
    #[arg(long)]
    pub lumber: Option<String>,
    /// Stud spacing on centre (default 16in).
    #[arg(long)]
    pub spacing: Option<String>,
    /// One top plate instead of top plate + cap plate.
    #[arg(long)]
    pub single_top_plate: bool,
    /// For `wall`: a door rough opening U,W,H (left edge, width, height); repeatable.
    #[arg(long)]
    pub door: Vec<String>,
    /// For `wall`: a window rough opening U,W,H,SILL; repeatable.
    #[arg(long)]
    pub window: Vec<String>,
    /// Header construction.
    #[arg(long, value_enum, default_value = "built-up")]
    pub header: HeaderArg,
    /// For `wall`: how a window's rough sill meets its studs.
    #[arg(long, value_enum, default_value = "between-jacks")]
    pub sill: SillArg,
    /// For `wall`: a double rough sill (two plies stacked) under every window.
    #[arg(long)]
    pub double_sill: bool,
    /// For `wall`: every opening's king studs doubled.
    #[arg(long)]
    pub double_kings: bool,
    /// For `wall`: a third top plate on the cap plate.
    #[arg(long)]
    pub triple_top_plate: bool,
    /// For `wall`: a row of flat blocking between the studs, its underside this high above
    /// the floor (fire or mid-height blocking); repeatable.
    #[arg(long, value_name = "HEIGHT")]
    pub blocking: Vec<String>,
    /// For `wall`: a let-in 1x4 brace in the outer face rising at 45° from the bottom plate
    /// at this u towards the wall end; repeatable.
    #[arg(long, value_name = "U")]
    pub brace: Vec<String>,
    /// For `wall`: how both wall ends are framed.
    #[arg(long, value_enum, default_value = "single")]
    pub corner: CornerArg,
    /// For `wall`: a partition wall meeting this one, centred U from the wall start, backed
    /// by a flat stud between two studs (`U` or `U:backer`) or by ladder blocking
    /// (`U:ladder`); repeatable.
    #[arg(long, value_name = "U[:STYLE]")]
    pub partition: Vec<String>,
    /// For `building`: leave out the default door and windows.
    #[arg(long)]
    pub no_openings: bool,
}

pub fn run(args: SynthArgs) -> CmdResult {
    let layout = build_layout(&args)?;
    let file_name = args
        .output
        .as_ref()
        .and_then(|p| p.file_name())
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_else(|| format!("{}.ifc", layout.name));
    let opts = WriteOptions {
        schema: Schema::parse(&args.schema)?,
        unit: LengthUnit::parse(&args.unit)?,
        products: match args.products {
            ProductsArg::Member => ProductClasses::Member,
            ProductsArg::ColumnBeam => ProductClasses::ColumnBeam,
        },
        grouping: match args.grouping {
            GroupingArg::None => Grouping::None,
            GroupingArg::Wall => Grouping::Wall,
            GroupingArg::Assembly => Grouping::Assembly,
        },
        mapped: args.mapped,
        placement: args.placement.map(|p| match p {
            PlacementArg::Storey => PlacementBase::Storey,
            PlacementArg::Parent => PlacementBase::Parent,
        }),
        seed: args.seed,
        property_sets: args.psets,
        openings: args.openings,
        file_name,
    };
    let written = write_ifc(&layout, &opts)?;
    if let Some(path) = &args.truth {
        super::write_atomically(path, written.truth.to_json().as_bytes()).map_err(|e| {
            Failure::bad_input(format!("cannot write truth file {}: {e}", path.display()))
        })?;
    }
    match &args.output {
        Some(path) => {
            super::write_atomically(path, written.ifc.as_bytes())
                .map_err(|e| Failure::bad_input(format!("cannot write {}: {e}", path.display())))?;
            let c = &written.truth.counts;
            print_stdout(&format!(
                "wrote {}: {} members, {} walls, {} buildings, {} bytes\n",
                path.display(),
                c.members,
                c.walls,
                c.buildings,
                written.ifc.len()
            ))
        }
        None => print_stdout(&written.ifc),
    }
}

fn refuse(what: String, hint: &str) -> Failure {
    Failure::bad_input(format!("{what} (hint: {hint})"))
}

fn build_layout(args: &SynthArgs) -> Result<Layout, Failure> {
    let model = args.model.as_str();
    let wall_params = args.geometry.length.is_some()
        || args.geometry.height.is_some()
        || args.geometry.lumber.is_some()
        || args.geometry.spacing.is_some()
        || args.geometry.single_top_plate;
    if matches!(model, "tm1" | "tm2" | "tm3") && (wall_params || args.geometry.depth.is_some()) {
        return Err(refuse(
            format!("{model} has fixed geometry"),
            "use `wall` or `building` for parametric models",
        ));
    }
    if model != "wall" && (!args.geometry.door.is_empty() || !args.geometry.window.is_empty()) {
        return Err(refuse(
            "--door and --window apply to `wall` only".into(),
            "`building` has default openings; --no-openings removes them",
        ));
    }
    if !matches!(model, "building" | "block")
        && (args.grid.is_some()
            || args.geometry.depth.is_some()
            || args.geometry.no_openings
            || args.gap.is_some())
    {
        return Err(refuse(
            "--grid, --gap, --depth and --no-openings apply to `building` and `block` only".into(),
            "see framewright synth --help",
        ));
    }
    if model != "block" && (args.blocks.is_some() || args.storeys.is_some()) {
        return Err(refuse(
            "--blocks and --storeys apply to `block` only".into(),
            "see framewright synth --help",
        ));
    }
    if args.openings && matches!(args.grouping, GroupingArg::None) {
        return Err(refuse(
            "--openings needs walls to void".into(),
            "add --grouping wall or --grouping assembly",
        ));
    }
    match model {
        "tm1" => Ok(models::tm1()),
        "tm2" => Ok(models::tm2()),
        "tm3" => Ok(models::tm3()),
        "wall" => Ok(wall_layout(args)?),
        "building" => Ok(building_layout(args)?),
        "block" => Ok(block_layout(args)?),
        other => Err(refuse(
            format!("unknown model '{other}'"),
            "use tm1, tm2, tm3, wall, building or block",
        )),
    }
}

fn opt_length(text: &Option<String>, default: f64) -> Result<f64, SynthError> {
    text.as_deref().map(parse_length).unwrap_or(Ok(default))
}

fn studs(args: &SynthArgs) -> Result<StudLayout, SynthError> {
    Ok(StudLayout::OnCentre(opt_length(
        &args.geometry.spacing,
        framewright::synth::units::inches(16.0),
    )?))
}

fn header_style(args: &SynthArgs) -> HeaderStyle {
    match args.geometry.header {
        HeaderArg::BuiltUp => HeaderStyle::BuiltUp,
        HeaderArg::Solid => HeaderStyle::Solid,
        HeaderArg::Flat => HeaderStyle::Flat,
    }
}

/// Read `U,W,H` (door) or `U,W,H,SILL` (window).
fn opening(text: &str, window: bool) -> Result<OpeningSpec, SynthError> {
    let parts: Vec<&str> = text.split(',').collect();
    let want = if window { 4 } else { 3 };
    if parts.len() != want {
        return Err(SynthError::Parse {
            what: if window { "window" } else { "door" },
            value: text.into(),
            hint: if window {
                "write U,W,H,SILL, e.g. 54in,36in,48in,32in"
            } else {
                "write U,W,H, e.g. 53in,38in,82.5in"
            }
            .into(),
        });
    }
    let v: Vec<f64> = parts
        .iter()
        .map(|p| parse_length(p))
        .collect::<Result<_, _>>()?;
    let kind = if window {
        OpeningKind::Window { sill: v[3] }
    } else {
        OpeningKind::Door
    };
    Ok(OpeningSpec {
        kind,
        u: v[0],
        width: v[1],
        height: v[2],
    })
}

/// Read `U` or `U:backer` / `U:ladder`.
fn partition(text: &str) -> Result<PartitionSpec, SynthError> {
    let (u, style) = text.split_once(':').unwrap_or((text, "backer"));
    let style = match style {
        "backer" => PartitionStyle::Backer,
        "ladder" => PartitionStyle::Ladder,
        _ => {
            return Err(SynthError::Parse {
                what: "partition",
                value: text.into(),
                hint: "write U, U:backer or U:ladder, e.g. 8ft:ladder".into(),
            });
        }
    };
    Ok(PartitionSpec {
        u: parse_length(u)?,
        style,
    })
}

fn wall_layout(args: &SynthArgs) -> Result<Layout, SynthError> {
    let mut openings = Vec::new();
    for d in &args.geometry.door {
        openings.push(opening(d, false)?);
    }
    for w in &args.geometry.window {
        openings.push(opening(w, true)?);
    }
    let spec = WallSpec {
        id: "W1".into(),
        name: "Wall".into(),
        length: opt_length(&args.geometry.length, framewright::synth::units::feet(12.0))?,
        height: opt_length(&args.geometry.height, models::eight_foot_height())?,
        lumber: args
            .geometry
            .lumber
            .as_deref()
            .map(Lumber::parse_wall)
            .unwrap_or(Ok(Lumber::L2X4))?,
        studs: studs(args)?,
        double_top_plate: !args.geometry.single_top_plate,
        header_style: header_style(args),
        openings,
        detail: FramingDetail {
            sill: match args.geometry.sill {
                SillArg::BetweenJacks => SillStyle::BetweenJacks,
                SillArg::KingToKing => SillStyle::KingToKing,
            },
            double_sill: args.geometry.double_sill,
            double_kings: args.geometry.double_kings,
            triple_top_plate: args.geometry.triple_top_plate,
            blocking_rows: args
                .geometry
                .blocking
                .iter()
                .map(|h| parse_length(h.as_str()))
                .collect::<Result<_, _>>()?,
            braces: args
                .geometry
                .brace
                .iter()
                .map(|u| parse_length(u.as_str()))
                .collect::<Result<_, _>>()?,
            corners: match args.geometry.corner {
                CornerArg::Single => CornerStyle::Single,
                CornerArg::Backer => CornerStyle::Backer,
                CornerArg::ThreeStud => CornerStyle::ThreeStud,
                CornerArg::Ladder => CornerStyle::Ladder,
            },
            partitions: args
                .geometry
                .partition
                .iter()
                .map(|p| partition(p))
                .collect::<Result<_, _>>()?,
        },
    };
    models::single_wall("wall", "Parametric wood-frame wall", &spec)
}

/// The building (or block unit) of the arguments; `size` overrides the default length and depth.
fn building_spec(args: &SynthArgs, size: Option<(f64, f64)>) -> Result<BuildingSpec, SynthError> {
    let d = models::default_building_spec();
    let (length, depth) = size.unwrap_or((d.length, d.depth));
    Ok(BuildingSpec {
        length: opt_length(&args.geometry.length, length)?,
        depth: opt_length(&args.geometry.depth, depth)?,
        height: opt_length(&args.geometry.height, d.height)?,
        lumber: args
            .geometry
            .lumber
            .as_deref()
            .map(Lumber::parse_wall)
            .unwrap_or(Ok(d.lumber))?,
        studs: studs(args)?,
        double_top_plate: !args.geometry.single_top_plate,
        header_style: header_style(args),
        openings: if args.geometry.no_openings {
            Default::default()
        } else {
            d.openings
        },
    })
}

/// Defaults of `block`: three blocks of five storeys, 3 x 9 units of 24 ft x 14 ft on each:
/// 1,620 walls, 49,410 members (about 46 MB with --grouping wall --psets --openings).
const BLOCK_DEFAULTS: (usize, usize, (usize, usize)) = (3, 5, (3, 9));
const BLOCK_UNIT_FEET: (f64, f64) = (24.0, 14.0);

fn block_layout(args: &SynthArgs) -> Result<Layout, SynthError> {
    let (blocks, storeys, grid) = BLOCK_DEFAULTS;
    let (rows, cols) = match &args.grid {
        Some(text) => parse_grid(text)?,
        None => grid,
    };
    let spec = BlockSpec {
        unit: building_spec(
            args,
            Some((
                framewright::synth::units::feet(BLOCK_UNIT_FEET.0),
                framewright::synth::units::feet(BLOCK_UNIT_FEET.1),
            )),
        )?,
        blocks: args.blocks.unwrap_or(blocks),
        storeys: args.storeys.unwrap_or(storeys),
        rows,
        cols,
        gap: opt_length(&args.gap, DEFAULT_GAP)?,
        floor_depth: DEFAULT_FLOOR_DEPTH,
    };
    framewright::synth::building::blocks(
        &spec,
        &format!("blocks_{}x{}_{rows}x{cols}", spec.blocks, spec.storeys),
    )
}

fn building_layout(args: &SynthArgs) -> Result<Layout, SynthError> {
    let spec = building_spec(args, None)?;
    match &args.grid {
        None => {
            let b = frame_building(&spec, "Building", Vec3::zeros(), "")?;
            Ok(Layout {
                name: "building".into(),
                description: "Rectangular wood-frame building of four walls".into(),
                buildings: vec![b],
            })
        }
        Some(text) => {
            let (rows, cols) = parse_grid(text)?;
            grid(
                &spec,
                rows,
                cols,
                opt_length(&args.gap, DEFAULT_GAP)?,
                &format!("building_grid_{rows}x{cols}"),
            )
        }
    }
}

fn parse_grid(text: &str) -> Result<(usize, usize), SynthError> {
    let bad = || SynthError::Parse {
        what: "grid",
        value: text.into(),
        hint: "write NxM, e.g. 20x30".into(),
    };
    let (a, b) = text.split_once(['x', 'X']).ok_or_else(bad)?;
    Ok((
        a.trim().parse().map_err(|_| bad())?,
        b.trim().parse().map_err(|_| bad())?,
    ))
}
