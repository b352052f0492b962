//! Framing layouts as plain data: lumber pieces in world coordinates (metres).
use nalgebra::Vector3;

pub type Vec3 = Vector3<f64>;

/// What a piece does in its wall (the same names the truth files and rules use).
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub enum Role {
    BottomPlate,
    TopPlate,
    CapPlate,
    Stud,
    KingStud,
    JackStud,
    Header,
    Sill,
    CrippleStud,
    Blocking,
    Brace,
}

impl Role {
    pub fn as_str(self) -> &'static str {
        match self {
            Role::BottomPlate => "bottom_plate",
            Role::TopPlate => "top_plate",
            Role::CapPlate => "cap_plate",
            Role::Stud => "stud",
            Role::KingStud => "king_stud",
            Role::JackStud => "jack_stud",
            Role::Header => "header",
            Role::Sill => "sill",
            Role::CrippleStud => "cripple_stud",
            Role::Blocking => "blocking",
            Role::Brace => "brace",
        }
    }

    /// Vertical members stand on a plate; the others lie along the wall.
    pub fn is_vertical(self) -> bool {
        matches!(
            self,
            Role::Stud | Role::KingStud | Role::JackStud | Role::CrippleStud
        )
    }
}

/// Axis-aligned box in a wall's (u, v, w) frame, metres.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WallBox {
    pub u: [f64; 2],
    pub v: [f64; 2],
    pub w: [f64; 2],
}

/// Wall frame: origin at the bottom outer corner of the wall start, u along the
/// wall, v up, w = u x v across the thickness from the outer face.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WallFrame {
    pub origin: Vec3,
    pub u: Vec3,
    pub v: Vec3,
    pub w: Vec3,
}

impl WallFrame {
    /// A frame with v up; w follows from u x v.
    pub fn upright(origin: Vec3, u: Vec3) -> WallFrame {
        let v = Vec3::new(0.0, 0.0, 1.0);
        WallFrame {
            origin,
            u,
            v,
            w: u.cross(&v),
        }
    }

    pub fn to_world(&self, u: f64, v: f64, w: f64) -> Vec3 {
        self.origin + self.u * u + self.v * v + self.w * w
    }

    /// 4x4 row-major matrix with columns u, v, w, origin.
    pub fn matrix(&self) -> [[f64; 4]; 4] {
        let c = [self.u, self.v, self.w, self.origin];
        let mut m = [[0.0; 4]; 4];
        for (row, line) in m.iter_mut().enumerate().take(3) {
            for (col, vec) in c.iter().enumerate() {
                line[col] = vec[row];
            }
        }
        m[3][3] = 1.0;
        m
    }
}

/// One lumber piece.
#[derive(Debug, Clone, PartialEq)]
pub struct Piece {
    pub role: Role,
    /// Finer role: "above_header", "below_sill", "segment", "ply 1 (outer face)", or "".
    pub role_detail: String,
    /// Nominal size, e.g. "2x4".
    pub nominal: String,
    /// Where the piece sits in its wall frame.
    pub wall_box: WallBox,
    /// Centre line, world: bottom end first (vertical) or smaller-u end first.
    pub start: Vec3,
    pub end: Vec3,
    /// Larger cross-section dimension and the (unit, world) direction it runs in.
    pub width: f64,
    pub width_dir: Vec3,
    /// Smaller cross-section dimension.
    pub thickness: f64,
    /// Whether it stands (runs along v); it lies along u otherwise.
    pub upright: bool,
}

impl Piece {
    /// Build a piece from its box in the wall frame; it runs along v when its role is
    /// vertical, else along u. The wider of the two other box extents is the width.
    pub fn from_box(
        frame: &WallFrame,
        role: Role,
        detail: &str,
        nominal: &str,
        b: WallBox,
    ) -> Piece {
        Piece::oriented(frame, role, detail, nominal, b, role.is_vertical())
    }

    /// A piece standing along v whatever its role (the spacer blocks of a built-up post).
    pub fn standing(
        frame: &WallFrame,
        role: Role,
        detail: &str,
        nominal: &str,
        b: WallBox,
    ) -> Piece {
        Piece::oriented(frame, role, detail, nominal, b, true)
    }

    fn oriented(
        frame: &WallFrame,
        role: Role,
        detail: &str,
        nominal: &str,
        b: WallBox,
        upright: bool,
    ) -> Piece {
        let mid = |r: [f64; 2]| 0.5 * (r[0] + r[1]);
        // Extents come from differences of positions; drop the float dust so equal
        // sections compare equal.
        let ext = |r: [f64; 2]| ((r[1] - r[0]) * 1e10).round() / 1e10;
        let (start, end, cross) = if upright {
            (
                frame.to_world(mid(b.u), b.v[0], mid(b.w)),
                frame.to_world(mid(b.u), b.v[1], mid(b.w)),
                [(ext(b.u), frame.u), (ext(b.w), frame.w)],
            )
        } else {
            (
                frame.to_world(b.u[0], mid(b.v), mid(b.w)),
                frame.to_world(b.u[1], mid(b.v), mid(b.w)),
                [(ext(b.v), frame.v), (ext(b.w), frame.w)],
            )
        };
        // Ties (square sections) put the width across the wall.
        let (wide, narrow) = if cross[0].0 > cross[1].0 + 1e-12 {
            (cross[0], cross[1])
        } else {
            (cross[1], cross[0])
        };
        Piece {
            role,
            role_detail: detail.to_string(),
            nominal: nominal.to_string(),
            wall_box: b,
            start,
            end,
            width: wide.0,
            width_dir: wide.1,
            thickness: narrow.0,
            upright,
        }
    }

    /// A piece running in the wall's plane from `(u, v)` at `from` to `to` (a brace), its
    /// width in the plane and its thickness across the wall at `w`. Its `wall_box` is the box
    /// around it.
    #[allow(clippy::too_many_arguments)]
    pub fn inclined(
        frame: &WallFrame,
        role: Role,
        detail: &str,
        nominal: &str,
        from: [f64; 2],
        to: [f64; 2],
        width: f64,
        w: [f64; 2],
    ) -> Piece {
        let (du, dv) = (to[0] - from[0], to[1] - from[1]);
        let len = du.hypot(dv);
        // Half the width, across the axis in the plane: (-dv, du) / len.
        let (hu, hv) = (0.5 * width * dv.abs() / len, 0.5 * width * du.abs() / len);
        let mid_w = 0.5 * (w[0] + w[1]);
        Piece {
            role,
            role_detail: detail.to_string(),
            nominal: nominal.to_string(),
            wall_box: WallBox {
                u: [from[0].min(to[0]) - hu, from[0].max(to[0]) + hu],
                v: [from[1].min(to[1]) - hv, from[1].max(to[1]) + hv],
                w,
            },
            start: frame.to_world(from[0], from[1], mid_w),
            end: frame.to_world(to[0], to[1], mid_w),
            width,
            width_dir: (frame.u * (-dv) + frame.v * du) / len,
            thickness: w[1] - w[0],
            upright: false,
        }
    }

    pub fn length(&self) -> f64 {
        (self.end - self.start).norm()
    }

    /// Unit vector from start to end.
    pub fn axis(&self) -> Vec3 {
        (self.end - self.start) / self.length()
    }

    pub fn volume(&self) -> f64 {
        self.length() * self.width * self.thickness
    }
}

/// What an opening in a wall is, as framed.
#[derive(Debug, Clone, PartialEq)]
pub struct OpeningRecord {
    /// "door" or "window".
    pub kind: &'static str,
    pub rough_opening_u: [f64; 2],
    pub rough_opening_v: [f64; 2],
    /// Header lumber, e.g. "2x10x2" (two plies) or "4x10" (solid).
    pub header: String,
}

/// One framed wall.
#[derive(Debug, Clone, PartialEq)]
pub struct WallLayout {
    /// Unique in the layout, e.g. "F" or "B1_2-F".
    pub id: String,
    pub name: String,
    pub frame: WallFrame,
    pub length: f64,
    pub height: f64,
    pub thickness: f64,
    pub pieces: Vec<Piece>,
    pub openings: Vec<OpeningRecord>,
}

/// One storey of a building: its walls (world coordinates) and its floor level.
#[derive(Debug, Clone, PartialEq)]
pub struct StoreyLayout {
    pub name: String,
    /// Height of the storey's floor above the building's origin, metres.
    pub elevation: f64,
    pub walls: Vec<WallLayout>,
}

/// A building: its storeys, and where its own placement sits (world).
#[derive(Debug, Clone, PartialEq)]
pub struct BuildingLayout {
    pub name: String,
    pub origin: Vec3,
    pub storeys: Vec<StoreyLayout>,
}

impl BuildingLayout {
    /// A building whose walls all stand on one storey, "Level 1", at the building's origin.
    pub fn one_storey(name: &str, origin: Vec3, walls: Vec<WallLayout>) -> BuildingLayout {
        BuildingLayout {
            name: name.to_string(),
            origin,
            storeys: vec![StoreyLayout {
                name: "Level 1".into(),
                elevation: 0.0,
                walls,
            }],
        }
    }

    pub fn walls(&self) -> impl Iterator<Item = &WallLayout> {
        self.storeys.iter().flat_map(|s| s.walls.iter())
    }
}

/// Everything one file holds.
#[derive(Debug, Clone, PartialEq)]
pub struct Layout {
    /// Short model name (file stem), used in GlobalId keys and the project name.
    pub name: String,
    pub description: String,
    pub buildings: Vec<BuildingLayout>,
}

impl Layout {
    pub fn walls(&self) -> impl Iterator<Item = &WallLayout> {
        self.buildings.iter().flat_map(BuildingLayout::walls)
    }

    pub fn piece_count(&self) -> usize {
        self.walls().map(|w| w.pieces.len()).sum()
    }
}
