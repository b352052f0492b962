//! What defines a wall frame: its size, lumber, stud layout, header style, openings and
//! framing details.
use crate::synth::units::Lumber;

/// Where the common studs go.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum StudLayout {
    /// Only the two end studs (the study's small test frames).
    EndsOnly,
    /// End studs plus studs whose centres sit at multiples of this spacing (metres) from the wall start.
    OnCentre(f64),
}

/// How headers are made.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum HeaderStyle {
    /// Plies of 2x lumber on edge, flush with both faces, 1/2 in spacers between.
    BuiltUp,
    /// One solid piece as thick as the wall (e.g. a 4x10 in a 2x4 wall).
    Solid,
    /// One piece of the wall's lumber laid flat across the opening between the king studs,
    /// with no jack studs: the opening's head is carried by the kings (as Constructivity
    /// frames its example wall).
    Flat,
}

/// How a window's rough sill meets the opening's studs.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum SillStyle {
    /// Between the jack studs, which run down to the bottom plate.
    #[default]
    BetweenJacks,
    /// From king stud to king stud: the jack studs stand on it, and cripples (one under each
    /// jack) carry it.
    KingToKing,
}

/// How both ends of a wall are framed, where another wall meets it at a corner.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum CornerStyle {
    /// One end stud.
    #[default]
    Single,
    /// The end stud and a stud turned flat beside it at the inner face, to nail the other
    /// wall's board to (a California corner).
    Backer,
    /// The end stud and a second stud with three spacer blocks between them (a three-stud
    /// corner post).
    ThreeStud,
    /// The end stud and a second stud one bay in, with flat blocks between them every
    /// 24 in up the wall (ladder blocking).
    Ladder,
}

/// How the place where a partition wall meets this one mid-length is backed.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PartitionStyle {
    /// Two studs with a stud turned flat between them at the inner face.
    Backer,
    /// Two studs one bay apart with flat blocks between them every 24 in (ladder blocking).
    Ladder,
}

/// A partition wall meeting this wall's inner face, centred `u` from the wall start.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PartitionSpec {
    pub u: f64,
    pub style: PartitionStyle,
}

/// Framing details beyond the studs on centre and the openings.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct FramingDetail {
    pub sill: SillStyle,
    /// A double rough sill: two plies stacked under every window.
    pub double_sill: bool,
    /// Each opening's king studs doubled: a second full-height stud outside each king.
    pub double_kings: bool,
    /// A third top plate on the cap plate (with a cap plate only).
    pub triple_top_plate: bool,
    /// Rows of flat blocking between the uprights (fire or mid-height blocking): the height of
    /// each row's underside above the floor (m). A row skips the bays an opening's framing
    /// crosses.
    pub blocking_rows: Vec<f64>,
    /// Let-in 1x4 braces in the outer face, each rising at 45° from the bottom plate at
    /// this u (m from the wall start) towards the wall end, up to the top plate.
    pub braces: Vec<f64>,
    /// How both wall ends are framed.
    pub corners: CornerStyle,
    /// Partition walls meeting this one.
    pub partitions: Vec<PartitionSpec>,
}

#[derive(Debug, Clone, Copy, PartialEq)]
pub enum OpeningKind {
    Door,
    /// Height of the rough opening's bottom above the floor (metres).
    Window {
        sill: f64,
    },
}

impl OpeningKind {
    pub fn name(self) -> &'static str {
        match self {
            OpeningKind::Door => "door",
            OpeningKind::Window { .. } => "window",
        }
    }
}

/// A rough opening: left edge `u` from the wall start, clear width and height (metres).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct OpeningSpec {
    pub kind: OpeningKind,
    pub u: f64,
    pub width: f64,
    pub height: f64,
}

/// Everything that defines one wall frame.
#[derive(Debug, Clone, PartialEq)]
pub struct WallSpec {
    pub id: String,
    pub name: String,
    pub length: f64,
    /// Overall height, bottom of the bottom plate to top of the top (or cap) plate.
    pub height: f64,
    pub lumber: Lumber,
    pub studs: StudLayout,
    pub double_top_plate: bool,
    pub header_style: HeaderStyle,
    pub openings: Vec<OpeningSpec>,
    pub detail: FramingDetail,
}
