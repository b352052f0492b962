//! Writes a layout as an IFC file (ISO 10303-21 text) and its truth sidecar.
//!
//! Options vary what real authoring tools vary: schema, length unit, product
//! classes, grouping of members under a wall, mapped-item pieces, and what member
//! placements are relative to. Output is deterministic: GlobalIds come from a
//! seeded hash of stable keys, timestamps are fixed, caches are BTreeMaps.
use crate::synth::SynthError;
use crate::synth::guid;
use crate::synth::layout::{BuildingLayout, Layout, Piece, StoreyLayout, Vec3, WallLayout};
use crate::synth::step_text::{Real, RealList, Ref, RefList, StepWriter, string};
use crate::synth::targets::{self, Nail};
use crate::synth::truth::{
    self, BoxInfo, Counts, Truth, TruthMember, TruthNail, TruthOpening, TruthPrecedence, TruthWall,
    q, q3,
};
use crate::synth::units::LengthUnit;
use std::collections::BTreeMap;

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Schema {
    Ifc2x3,
    Ifc4,
    Ifc4x3,
}

impl Schema {
    /// The FILE_SCHEMA identifier.
    pub fn header_name(self) -> &'static str {
        match self {
            Schema::Ifc2x3 => "IFC2X3",
            Schema::Ifc4 => "IFC4",
            Schema::Ifc4x3 => "IFC4X3_ADD2",
        }
    }

    pub fn parse(text: &str) -> Result<Schema, SynthError> {
        match text.to_ascii_uppercase().as_str() {
            "IFC2X3" => Ok(Schema::Ifc2x3),
            "IFC4" => Ok(Schema::Ifc4),
            "IFC4X3" | "IFC4X3_ADD2" => Ok(Schema::Ifc4x3),
            _ => Err(SynthError::Parse {
                what: "schema",
                value: text.into(),
                hint: "use IFC4, IFC2X3 or IFC4X3".into(),
            }),
        }
    }

    /// IFC2X3 has no PredefinedType on IfcMember/IfcColumn/IfcBeam/IfcWall.
    fn has_element_predefined_type(self) -> bool {
        self != Schema::Ifc2x3
    }
}

/// Which IFC classes framing pieces become.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ProductClasses {
    /// IfcMember typed STUD (vertical), PLATE (plates, sills), MEMBER (headers).
    Member,
    /// IfcColumn studs and IfcBeam plates, headers and sills (what Revit writes).
    ColumnBeam,
}

/// What, if anything, the members of one wall are aggregated into.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Grouping {
    None,
    /// IfcWall (ELEMENTEDWALL in IFC4+) via IfcRelAggregates.
    Wall,
    /// IfcElementAssembly via IfcRelAggregates.
    Assembly,
}

/// What member placements are relative to.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PlacementBase {
    Storey,
    /// The wall or assembly the member is aggregated into (needs grouping).
    Parent,
}

#[derive(Debug, Clone, PartialEq)]
pub struct WriteOptions {
    pub schema: Schema,
    pub unit: LengthUnit,
    pub products: ProductClasses,
    pub grouping: Grouping,
    /// One product per wall and direction holding every piece as an IfcMappedItem.
    pub mapped: bool,
    /// `None`: relative to the parent when grouped, else to the storey.
    pub placement: Option<PlacementBase>,
    pub seed: u64,
    /// A property set (`Pset_MemberCommon`, …) for every framing product.
    pub property_sets: bool,
    /// For grouped walls: an IfcOpeningElement and an IfcDoor or IfcWindow per rough opening.
    pub openings: bool,
    /// The file name written into FILE_NAME and the truth file (no directories).
    pub file_name: String,
}

impl Default for WriteOptions {
    fn default() -> Self {
        WriteOptions {
            schema: Schema::Ifc4,
            unit: LengthUnit::Metre,
            products: ProductClasses::Member,
            grouping: Grouping::None,
            mapped: false,
            placement: None,
            seed: 20_240_101,
            property_sets: false,
            openings: false,
            file_name: "model.ifc".into(),
        }
    }
}

impl WriteOptions {
    fn placement_base(&self) -> Result<PlacementBase, SynthError> {
        match (self.placement, self.grouping) {
            (Some(PlacementBase::Parent), Grouping::None) => Err(SynthError::Options {
                what: "placement relative to the parent needs a parent".into(),
                hint: "add --grouping wall or --grouping assembly, or use --placement storey"
                    .into(),
            }),
            (Some(p), _) => Ok(p),
            (None, Grouping::None) => Ok(PlacementBase::Storey),
            (None, _) => Ok(PlacementBase::Parent),
        }
    }
}

/// The written file and what it holds.
#[derive(Debug, Clone)]
pub struct WrittenModel {
    pub ifc: String,
    pub truth: Truth,
}

/// Fixed time stamp (2024-01-01T00:00:00Z) so files are byte-identical across runs.
const TIMESTAMP: u64 = 1_704_067_200;
const MATERIAL: &str = "Spruce-Pine-Fir No.2";

/// A product class with its IFC4 predefined type.
#[derive(Clone, Copy)]
struct ProductKind {
    entity: &'static str,
    ifc_type: &'static str,
    predefined: &'static str,
}

/// `is_member`: a lying piece that is not a plate (a header or blocking).
fn product_kind(products: ProductClasses, piece_vertical: bool, is_member: bool) -> ProductKind {
    match (products, piece_vertical) {
        (ProductClasses::Member, true) => ProductKind {
            entity: "IFCMEMBER",
            ifc_type: "IfcMember",
            predefined: "STUD",
        },
        (ProductClasses::Member, false) if is_member => ProductKind {
            entity: "IFCMEMBER",
            ifc_type: "IfcMember",
            predefined: "MEMBER",
        },
        (ProductClasses::Member, false) => ProductKind {
            entity: "IFCMEMBER",
            ifc_type: "IfcMember",
            predefined: "PLATE",
        },
        (ProductClasses::ColumnBeam, true) => ProductKind {
            entity: "IFCCOLUMN",
            ifc_type: "IfcColumn",
            predefined: "COLUMN",
        },
        (ProductClasses::ColumnBeam, false) => ProductKind {
            entity: "IFCBEAM",
            ifc_type: "IfcBeam",
            predefined: "BEAM",
        },
    }
}

/// Writer state: the entity stream, shared entities and caches.
struct Ctx<'a> {
    w: StepWriter,
    opts: &'a WriteOptions,
    /// File units per metre.
    scale: f64,
    key_prefix: String,
    owner: Ref,
    body: Ref,
    origin: Ref,
    origin2d: Ref,
    identity: Ref,
    dirs: BTreeMap<String, Ref>,
    profiles: BTreeMap<(i64, i64), Ref>,
    maps: BTreeMap<(i64, i64), Ref>,
}

impl Ctx<'_> {
    fn gid(&self, key: &str) -> String {
        guid::global_id(self.opts.seed, &format!("{}/{key}", self.key_prefix))
    }

    fn owner_args(&self, key: &str) -> String {
        format!("{},{}", string(&self.gid(key)), self.owner)
    }

    fn dir(&mut self, v: Vec3) -> Ref {
        let text = format!("{}", RealList(&[v[0], v[1], v[2]]));
        if let Some(&r) = self.dirs.get(&text) {
            return r;
        }
        let r = self.w.add("IFCDIRECTION", &text);
        self.dirs.insert(text, r);
        r
    }

    /// A point given in metres, written in file units.
    fn point(&mut self, p: Vec3) -> Ref {
        let s = self.scale;
        self.w.add(
            "IFCCARTESIANPOINT",
            RealList(&[p[0] * s, p[1] * s, p[2] * s]),
        )
    }

    /// Axis2Placement3D; default axes (z up, x along x) are written as `$`.
    fn placement3d(&mut self, location: Vec3, axis: Vec3, ref_dir: Vec3) -> Ref {
        let loc = if location.norm() < 1e-12 {
            self.origin
        } else {
            self.point(location)
        };
        if (axis - Vec3::z()).norm() < 1e-12 && (ref_dir - Vec3::x()).norm() < 1e-12 {
            if loc == self.origin {
                return self.identity;
            }
            return self.w.add("IFCAXIS2PLACEMENT3D", format_args!("{loc},$,$"));
        }
        let (a, r) = (self.dir(axis), self.dir(ref_dir));
        self.w
            .add("IFCAXIS2PLACEMENT3D", format_args!("{loc},{a},{r}"))
    }

    fn local_placement(&mut self, relative_to: Option<Ref>, placement: Ref) -> Ref {
        match relative_to {
            Some(p) => self
                .w
                .add("IFCLOCALPLACEMENT", format_args!("{p},{placement}")),
            None => self
                .w
                .add("IFCLOCALPLACEMENT", format_args!("$,{placement}")),
        }
    }

    /// Rectangle profile centred on its position; shared by every piece of that section.
    fn profile(&mut self, x_dim: f64, y_dim: f64) -> Ref {
        let key = (nano(x_dim), nano(y_dim));
        if let Some(&r) = self.profiles.get(&key) {
            return r;
        }
        let pos = self
            .w
            .add("IFCAXIS2PLACEMENT2D", format_args!("{},$", self.origin2d));
        let s = self.scale;
        let r = self.w.add(
            "IFCRECTANGLEPROFILEDEF",
            format_args!(".AREA.,$,{pos},{},{}", Real(x_dim * s), Real(y_dim * s)),
        );
        self.profiles.insert(key, r);
        r
    }

    /// A box from the placement's origin to `size` (metres): its x by y rectangle extruded along z.
    fn box_body(&mut self, size: Vec3) -> Ref {
        let centre = self.point2d(size[0] / 2.0, size[1] / 2.0);
        let profile_pos = self
            .w
            .add("IFCAXIS2PLACEMENT2D", format_args!("{centre},$"));
        let s = self.scale;
        let profile = self.w.add(
            "IFCRECTANGLEPROFILEDEF",
            format_args!(
                ".AREA.,$,{profile_pos},{},{}",
                Real(size[0] * s),
                Real(size[1] * s)
            ),
        );
        let z = self.dir(Vec3::z());
        let solid = self.w.add(
            "IFCEXTRUDEDAREASOLID",
            format_args!("{profile},{},{z},{}", self.identity, Real(size[2] * s)),
        );
        let rep = self.w.add(
            "IFCSHAPEREPRESENTATION",
            format_args!("{},'Body','SweptSolid',({solid})", self.body),
        );
        self.w
            .add("IFCPRODUCTDEFINITIONSHAPE", format_args!("$,$,({rep})"))
    }

    /// A 2D point given in metres.
    fn point2d(&mut self, x: f64, y: f64) -> Ref {
        let s = self.scale;
        self.w.add("IFCCARTESIANPOINT", RealList(&[x * s, y * s]))
    }

    /// A representation map of a section extruded one file unit along z.
    fn unit_map(&mut self, width: f64, thickness: f64) -> Ref {
        let key = (nano(width), nano(thickness));
        if let Some(&r) = self.maps.get(&key) {
            return r;
        }
        let profile = self.profile(width, thickness);
        let z = self.dir(Vec3::z());
        let solid = self.w.add(
            "IFCEXTRUDEDAREASOLID",
            format_args!("{profile},{},{z},1.", self.identity),
        );
        let rep = self.w.add(
            "IFCSHAPEREPRESENTATION",
            format_args!("{},'Body','SweptSolid',({solid})", self.body),
        );
        let r = self.w.add(
            "IFCREPRESENTATIONMAP",
            format_args!("{},{rep}", self.identity),
        );
        self.maps.insert(key, r);
        r
    }
}

/// A length in whole nanometres: cache key for sections equal up to float noise.
fn nano(x: f64) -> i64 {
    (x * 1e9).round() as i64
}

/// Coordinates of world vector `d` in a wall-aligned frame (x = u, y = -w, z = v).
fn wall_local_dir(wall: &WallLayout, d: Vec3) -> Vec3 {
    let f = &wall.frame;
    snap(Vec3::new(d.dot(&f.u), -d.dot(&f.w), d.dot(&f.v)))
}

/// Remove float dust from unit directions so equal directions share one entity.
fn snap(v: Vec3) -> Vec3 {
    v.map(|c| {
        let r = (c * 1e12).round() / 1e12;
        if r == 0.0 { 0.0 } else { r }
    })
}

/// Write `layout` with `opts`.
pub fn write_ifc(layout: &Layout, opts: &WriteOptions) -> Result<WrittenModel, SynthError> {
    let base = opts.placement_base()?;
    if layout.piece_count() == 0 {
        return Err(SynthError::Options {
            what: "the layout has no pieces".into(),
            hint: "frame at least one wall".into(),
        });
    }
    let schema = opts.schema;
    let mut ctx = Ctx {
        w: StepWriter::new(512 * layout.piece_count() + 8192),
        opts,
        scale: 1.0 / opts.unit.metres_per_unit(),
        key_prefix: layout.name.clone(),
        owner: Ref(0),
        body: Ref(0),
        origin: Ref(0),
        origin2d: Ref(0),
        identity: Ref(0),
        dirs: BTreeMap::new(),
        profiles: BTreeMap::new(),
        maps: BTreeMap::new(),
    };
    let w = &mut ctx.w;
    let person = w.add("IFCPERSON", "$,'synth','framewright',$,$,$,$,$");
    let org = w.add("IFCORGANIZATION", "$,'framewright',$,$,$");
    let pando = w.add("IFCPERSONANDORGANIZATION", format_args!("{person},{org},$"));
    let app = w.add(
        "IFCAPPLICATION",
        format_args!("{org},'1.0','framewright synth','framewright-synth'"),
    );
    ctx.owner = w.add(
        "IFCOWNERHISTORY",
        format_args!("{pando},{app},$,.ADDED.,{TIMESTAMP},$,$,{TIMESTAMP}"),
    );
    ctx.origin = ctx.w.add("IFCCARTESIANPOINT", "(0.,0.,0.)");
    ctx.origin2d = ctx.w.add("IFCCARTESIANPOINT", "(0.,0.)");
    ctx.identity = ctx
        .w
        .add("IFCAXIS2PLACEMENT3D", format_args!("{},$,$", ctx.origin));
    let north = ctx.w.add("IFCDIRECTION", "(0.,1.)");
    let context = ctx.w.add(
        "IFCGEOMETRICREPRESENTATIONCONTEXT",
        format_args!(
            "$,'Model',3,{},{},{north}",
            Real(1e-5 * ctx.scale),
            ctx.identity
        ),
    );
    ctx.body = ctx.w.add(
        "IFCGEOMETRICREPRESENTATIONSUBCONTEXT",
        format_args!("'Body','Model',*,*,*,*,{context},$,.MODEL_VIEW.,$"),
    );
    let units = write_units(&mut ctx.w, opts.unit);
    let project = format!(
        "{},{},{},$,$,$,({context}),{units}",
        ctx.owner_args("project"),
        string(&layout.name),
        string(&layout.description)
    );
    let project = ctx.w.add("IFCPROJECT", project);
    let site_lp = ctx.local_placement(None, ctx.identity);
    let site_args = format!(
        "{},'Site',$,$,{site_lp},$,$,.ELEMENT.,$,$,$,$,$",
        ctx.owner_args("site")
    );
    let site = ctx.w.add("IFCSITE", site_args);
    let material = match schema {
        Schema::Ifc2x3 => ctx.w.add("IFCMATERIAL", string(MATERIAL)),
        _ => ctx
            .w
            .add("IFCMATERIAL", format_args!("{},$,'Wood'", string(MATERIAL))),
    };

    let mut truth_members = Vec::with_capacity(layout.piece_count());
    let mut truth_walls = Vec::new();
    let mut buildings = Vec::new();
    for b in &layout.buildings {
        let b_ref = write_building(
            &mut ctx,
            b,
            site_lp,
            base,
            material,
            &mut truth_members,
            &mut truth_walls,
        )?;
        buildings.push(b_ref);
    }
    let agg = ctx.owner_args("rel:project-site");
    ctx.w.add(
        "IFCRELAGGREGATES",
        format_args!("{agg},$,$,{project},({site})"),
    );
    let agg = ctx.owner_args("rel:site-buildings");
    ctx.w.add(
        "IFCRELAGGREGATES",
        format_args!("{agg},$,$,{site},{}", RefList(&buildings)),
    );

    let header = format!(
        "ISO-10303-21;\nHEADER;\nFILE_DESCRIPTION(({}),'2;1');\nFILE_NAME({},'2024-01-01T00:00:00',('framewright'),('framewright'),'framewright synth','framewright synth','');\nFILE_SCHEMA(('{}'));\nENDSEC;\nDATA;\n",
        string(match schema {
            Schema::Ifc2x3 => "ViewDefinition [CoordinationView_V2.0]",
            _ => "ViewDefinition [DesignTransferView]",
        }),
        string(&opts.file_name),
        schema.header_name()
    );
    let body = ctx.w.into_text();
    let mut ifc = String::with_capacity(header.len() + body.len() + 32);
    ifc.push_str(&header);
    ifc.push_str(&body);
    ifc.push_str("ENDSEC;\nEND-ISO-10303-21;\n");

    let truth = build_truth(layout, opts, base, truth_members, truth_walls);
    Ok(WrittenModel { ifc, truth })
}

fn write_units(w: &mut StepWriter, unit: LengthUnit) -> Ref {
    let length = match unit {
        LengthUnit::Metre => w.add("IFCSIUNIT", "*,.LENGTHUNIT.,$,.METRE."),
        LengthUnit::Millimetre => w.add("IFCSIUNIT", "*,.LENGTHUNIT.,.MILLI.,.METRE."),
        LengthUnit::Foot | LengthUnit::Inch => {
            let dims = w.add("IFCDIMENSIONALEXPONENTS", "1,0,0,0,0,0,0");
            let metre = w.add("IFCSIUNIT", "*,.LENGTHUNIT.,$,.METRE.");
            let factor = w.add(
                "IFCMEASUREWITHUNIT",
                format_args!("IFCLENGTHMEASURE({}),{metre}", Real(unit.metres_per_unit())),
            );
            w.add(
                "IFCCONVERSIONBASEDUNIT",
                format_args!("{dims},.LENGTHUNIT.,{},{factor}", string(unit.ifc_name())),
            )
        }
    };
    let area = w.add("IFCSIUNIT", "*,.AREAUNIT.,$,.SQUARE_METRE.");
    let volume = w.add("IFCSIUNIT", "*,.VOLUMEUNIT.,$,.CUBIC_METRE.");
    let angle = w.add("IFCSIUNIT", "*,.PLANEANGLEUNIT.,$,.RADIAN.");
    w.add(
        "IFCUNITASSIGNMENT",
        format_args!("({length},{area},{volume},{angle})"),
    )
}

/// Building, storeys, walls and their relationships; returns the IfcBuilding.
fn write_building(
    ctx: &mut Ctx,
    b: &BuildingLayout,
    site_lp: Ref,
    base: PlacementBase,
    material: Ref,
    members: &mut Vec<TruthMember>,
    walls: &mut Vec<TruthWall>,
) -> Result<Ref, SynthError> {
    let a2p = ctx.placement3d(b.origin, Vec3::z(), Vec3::x());
    let b_lp = ctx.local_placement(Some(site_lp), a2p);
    let args = format!(
        "{},{},$,$,{b_lp},$,$,.ELEMENT.,$,$,$",
        ctx.owner_args(&format!("building:{}", b.name)),
        string(&b.name)
    );
    let building = ctx.w.add("IFCBUILDING", args);
    let mut storeys = Vec::with_capacity(b.storeys.len());
    let mut framing = Vec::new();
    for (k, s) in b.storeys.iter().enumerate() {
        // The first storey keeps the keys one-storey buildings always had.
        let key = if k == 0 {
            b.name.clone()
        } else {
            format!("{}:{}", b.name, s.name)
        };
        storeys.push(write_storey(
            ctx,
            b,
            s,
            &key,
            b_lp,
            base,
            members,
            walls,
            &mut framing,
        ));
    }
    let rel = ctx.owner_args(&format!("rel:material:{}", b.name));
    ctx.w.add(
        "IFCRELASSOCIATESMATERIAL",
        format_args!("{rel},$,$,{},{material}", RefList(&framing)),
    );
    let rel = ctx.owner_args(&format!("rel:building:{}", b.name));
    ctx.w.add(
        "IFCRELAGGREGATES",
        format_args!("{rel},$,$,{building},{}", RefList(&storeys)),
    );
    Ok(building)
}

/// One storey with its walls; `framing` collects the framing products. Returns the storey.
#[allow(clippy::too_many_arguments)]
fn write_storey(
    ctx: &mut Ctx,
    b: &BuildingLayout,
    s: &StoreyLayout,
    key: &str,
    building_lp: Ref,
    base: PlacementBase,
    members: &mut Vec<TruthMember>,
    walls: &mut Vec<TruthWall>,
    framing: &mut Vec<Ref>,
) -> Ref {
    let opts = ctx.opts;
    let level = Vec3::new(0.0, 0.0, s.elevation);
    let a2p = ctx.placement3d(level, Vec3::z(), Vec3::x());
    let s_lp = ctx.local_placement(Some(building_lp), a2p);
    let args = format!(
        "{},{},$,$,{s_lp},$,$,.ELEMENT.,{}",
        ctx.owner_args(&format!("storey:{key}")),
        string(&s.name),
        Real(s.elevation * ctx.scale)
    );
    let storey = ctx.w.add("IFCBUILDINGSTOREY", args);
    let storey_origin = b.origin + level;
    let place_names = PlaceNames {
        building: &b.name,
        storey: &s.name,
    };
    let mut contained = Vec::new();
    for wall in &s.walls {
        let parent = write_parent(ctx, storey_origin, wall, s_lp);
        let (parent_ref, parent_lp, parent_gid) = match parent {
            Some((r, lp, gid)) => (Some(r), Some(lp), Some(gid)),
            None => (None, None, None),
        };
        let place = WallPlacement {
            wall,
            storey_origin,
            storey_lp: s_lp,
            parent_lp,
            base,
        };
        let products = if opts.mapped {
            write_mapped_wall(ctx, &place, &place_names, parent_gid.clone(), members)
        } else {
            write_piece_products(ctx, &place, &place_names, parent_gid.clone(), members)
        };
        if opts.property_sets {
            for (k, &product) in products.iter().enumerate() {
                write_property_set(ctx, wall, k, product);
            }
        }
        let first = members.len() - wall.pieces.len();
        walls.push(truth_wall(
            wall,
            &place_names,
            parent_gid,
            opts.grouping,
            &members[first..],
        ));
        match (parent_ref, parent_lp) {
            (Some(p), Some(lp)) => {
                let rel = ctx.owner_args(&format!("rel:wall:{}", wall.id));
                ctx.w.add(
                    "IFCRELAGGREGATES",
                    format_args!("{rel},$,$,{p},{}", RefList(&products)),
                );
                contained.push(p);
                if opts.openings {
                    contained.extend(write_openings(ctx, wall, p, lp));
                }
            }
            _ => contained.extend_from_slice(&products),
        }
        framing.extend(products);
    }
    let rel = ctx.owner_args(&format!("rel:contain:{key}"));
    ctx.w.add(
        "IFCRELCONTAINEDINSPATIALSTRUCTURE",
        format_args!("{rel},$,$,{},{storey}", RefList(&contained)),
    );
    storey
}

/// The building and storey names the truth file gives each wall and member.
struct PlaceNames<'a> {
    building: &'a str,
    storey: &'a str,
}

/// A property set of the product's common set (`Pset_MemberCommon`, …) for the k-th
/// product of a wall: its reference tag, load bearing, exterior.
fn write_property_set(ctx: &mut Ctx, wall: &WallLayout, k: usize, product: Ref) {
    let pset_name = match ctx.opts.products {
        ProductClasses::Member => "Pset_MemberCommon",
        ProductClasses::ColumnBeam if wall.pieces.get(k).is_some_and(|p| p.upright) => {
            "Pset_ColumnCommon"
        }
        ProductClasses::ColumnBeam => "Pset_BeamCommon",
    };
    let tag = if ctx.opts.mapped {
        format!("{}-{}", wall.id, ["studs", "plates"][k.min(1)])
    } else {
        format!("{}-{:03}", wall.id, k + 1)
    };
    let reference = ctx.w.add(
        "IFCPROPERTYSINGLEVALUE",
        format_args!("'Reference',$,IFCIDENTIFIER({}),$", string(&tag)),
    );
    let load = ctx.w.add(
        "IFCPROPERTYSINGLEVALUE",
        "'LoadBearing',$,IFCBOOLEAN(.T.),$",
    );
    let external = ctx
        .w
        .add("IFCPROPERTYSINGLEVALUE", "'IsExternal',$,IFCBOOLEAN(.T.),$");
    let key = format!("pset:{}:{k}", wall.id);
    let pset = ctx.w.add(
        "IFCPROPERTYSET",
        format_args!(
            "{},{},$,({reference},{load},{external})",
            ctx.owner_args(&key),
            string(pset_name)
        ),
    );
    let rel = ctx.owner_args(&format!("rel:{key}"));
    ctx.w.add(
        "IFCRELDEFINESBYPROPERTIES",
        format_args!("{rel},$,$,({product}),{pset}"),
    );
}

/// Depth of a door leaf or window unit across the wall, metres.
const FILLING_DEPTH: f64 = 0.05;

/// For each rough opening of a grouped wall: an IfcOpeningElement voiding the wall and the
/// IfcDoor or IfcWindow filling it, both boxes in the wall's placement. Returns the fillings
/// (contained in the storey).
fn write_openings(ctx: &mut Ctx, wall: &WallLayout, wall_ref: Ref, wall_lp: Ref) -> Vec<Ref> {
    let mut fillings = Vec::with_capacity(wall.openings.len());
    for (k, o) in wall.openings.iter().enumerate() {
        let (u, v) = (o.rough_opening_u, o.rough_opening_v);
        let (width, height) = (u[1] - u[0], v[1] - v[0]);
        // Wall placement axes: x = u, y = -w (the outer face at y = 0, inside at -thickness), z = v.
        let corner = Vec3::new(u[0], -wall.thickness, v[0]);
        let key = format!("opening:{}:{k}", wall.id);
        let body = ctx.box_body(Vec3::new(width, wall.thickness, height));
        let a2p = ctx.placement3d(corner, Vec3::z(), Vec3::x());
        let lp = ctx.local_placement(Some(wall_lp), a2p);
        let opening = ctx.w.add(
            "IFCOPENINGELEMENT",
            format_args!(
                "{},'Rough opening',$,$,{lp},{body},$,.OPENING.",
                ctx.owner_args(&key)
            ),
        );
        let rel = ctx.owner_args(&format!("rel:void:{key}"));
        ctx.w.add(
            "IFCRELVOIDSELEMENT",
            format_args!("{rel},$,$,{wall_ref},{opening}"),
        );
        let inset = Vec3::new(0.0, (wall.thickness - FILLING_DEPTH) / 2.0, 0.0);
        let a2p = ctx.placement3d(inset, Vec3::z(), Vec3::x());
        let f_lp = ctx.local_placement(Some(lp), a2p);
        let f_body = ctx.box_body(Vec3::new(width, FILLING_DEPTH, height));
        let f_key = format!("filling:{}:{k}", wall.id);
        let head = format!(
            "{},{},$,$,{f_lp},{f_body},$",
            ctx.owner_args(&f_key),
            string(o.kind)
        );
        let size = format!("{},{}", Real(height * ctx.scale), Real(width * ctx.scale));
        let filling = match (o.kind, ctx.opts.schema) {
            ("door", Schema::Ifc2x3) => ctx.w.add("IFCDOOR", format_args!("{head},{size}")),
            ("door", _) => ctx.w.add(
                "IFCDOOR",
                format_args!("{head},{size},.DOOR.,.SINGLE_SWING_LEFT.,$"),
            ),
            (_, Schema::Ifc2x3) => ctx.w.add("IFCWINDOW", format_args!("{head},{size}")),
            _ => ctx.w.add(
                "IFCWINDOW",
                format_args!("{head},{size},.WINDOW.,.SINGLE_PANEL.,$"),
            ),
        };
        let rel = ctx.owner_args(&format!("rel:fill:{key}"));
        ctx.w.add(
            "IFCRELFILLSELEMENT",
            format_args!("{rel},$,$,{opening},{filling}"),
        );
        fillings.push(filling);
    }
    fillings
}

/// The IfcWall or IfcElementAssembly a wall's members are aggregated into, if any:
/// (entity, its local placement, GlobalId).
fn write_parent(
    ctx: &mut Ctx,
    storey_origin: Vec3,
    wall: &WallLayout,
    storey_lp: Ref,
) -> Option<(Ref, Ref, String)> {
    let schema = ctx.opts.schema;
    let entity = match ctx.opts.grouping {
        Grouping::None => return None,
        Grouping::Wall => "IFCWALL",
        Grouping::Assembly => "IFCELEMENTASSEMBLY",
    };
    let a2p = ctx.placement3d(
        wall.frame.origin - storey_origin,
        wall.frame.v,
        wall.frame.u,
    );
    let lp = ctx.local_placement(Some(storey_lp), a2p);
    let key = format!("wall:{}", wall.id);
    let gid = ctx.gid(&key);
    let head = format!(
        "{},{},$,'Wood frame wall',{lp},$,{}",
        ctx.owner_args(&key),
        string(&wall.name),
        string(&wall.id)
    );
    let r = match (ctx.opts.grouping, schema.has_element_predefined_type()) {
        (Grouping::Wall, true) => ctx.w.add(entity, format_args!("{head},.ELEMENTEDWALL.")),
        (Grouping::Wall, false) => ctx.w.add(entity, head),
        // IfcElementAssembly has AssemblyPlace and PredefinedType in every schema.
        _ => ctx
            .w
            .add(entity, format_args!("{head},.FACTORY.,.USERDEFINED.")),
    };
    Some((r, lp, gid))
}

/// Where a wall's products are placed.
struct WallPlacement<'a> {
    wall: &'a WallLayout,
    /// World position of the storey's placement.
    storey_origin: Vec3,
    storey_lp: Ref,
    parent_lp: Option<Ref>,
    base: PlacementBase,
}

impl WallPlacement<'_> {
    /// A wall-aligned placement (x = u, y = -w, z = v) at world point `p`.
    fn at(&self, ctx: &mut Ctx, p: Vec3) -> Ref {
        let f = &self.wall.frame;
        match (self.base, self.parent_lp) {
            (PlacementBase::Parent, Some(parent)) => {
                let d = p - f.origin;
                let local = snap_point(Vec3::new(d.dot(&f.u), -d.dot(&f.w), d.dot(&f.v)));
                let a2p = ctx.placement3d(local, Vec3::z(), Vec3::x());
                ctx.local_placement(Some(parent), a2p)
            }
            _ => {
                let a2p = ctx.placement3d(snap_point(p - self.storey_origin), f.v, f.u);
                ctx.local_placement(Some(self.storey_lp), a2p)
            }
        }
    }
}

/// Round to 1e-12 m so -0 and float dust do not reach the file.
fn snap_point(v: Vec3) -> Vec3 {
    snap(v)
}

fn product_line(schema: Schema, kind: ProductKind, head: &str) -> String {
    if schema.has_element_predefined_type() {
        format!("{head},.{}.", kind.predefined)
    } else {
        head.to_string()
    }
}

/// One product per piece, each an extruded rectangle.
fn write_piece_products(
    ctx: &mut Ctx,
    place: &WallPlacement,
    b: &PlaceNames,
    parent_gid: Option<String>,
    members: &mut Vec<TruthMember>,
) -> Vec<Ref> {
    let wall = place.wall;
    let mut out = Vec::with_capacity(wall.pieces.len());
    for (k, piece) in wall.pieces.iter().enumerate() {
        let vertical = piece.upright;
        let kind = product_kind(
            ctx.opts.products,
            vertical,
            matches!(
                piece.role,
                crate::synth::Role::Header | crate::synth::Role::Blocking
            ),
        );
        let lp = place.at(ctx, piece.start);
        // Vertical pieces extrude along the placement's z with default axes; the
        // profile's x is then whichever section side runs along u.
        let solid_pos;
        let (x_dim, y_dim);
        let along_u = wall_local_dir(wall, piece.width_dir)[0].abs() > 0.5;
        if vertical {
            solid_pos = ctx.identity;
            (x_dim, y_dim) = if along_u {
                (piece.width, piece.thickness)
            } else {
                (piece.thickness, piece.width)
            };
        } else {
            let axis = wall_local_dir(wall, piece.axis());
            let ref_dir = wall_local_dir(wall, piece.width_dir);
            solid_pos = ctx.placement3d(Vec3::zeros(), axis, ref_dir);
            (x_dim, y_dim) = (piece.width, piece.thickness);
        }
        let profile = ctx.profile(x_dim, y_dim);
        let z = ctx.dir(Vec3::z());
        let solid = ctx.w.add(
            "IFCEXTRUDEDAREASOLID",
            format_args!(
                "{profile},{solid_pos},{z},{}",
                Real(piece.length() * ctx.scale)
            ),
        );
        let rep = ctx.w.add(
            "IFCSHAPEREPRESENTATION",
            format_args!("{},'Body','SweptSolid',({solid})", ctx.body),
        );
        let shape = ctx
            .w
            .add("IFCPRODUCTDEFINITIONSHAPE", format_args!("$,$,({rep})"));
        let key = format!("piece:{}:{k}", wall.id);
        let gid = ctx.gid(&key);
        let name = piece_name(wall, piece, k);
        let tag = format!("{}-{:03}", wall.id, k + 1);
        let head = format!(
            "{},{},$,{},{lp},{shape},{}",
            ctx.owner_args(&key),
            string(&name),
            string(&format!("{} SPF", piece.nominal)),
            string(&tag)
        );
        out.push(
            ctx.w
                .add(kind.entity, product_line(ctx.opts.schema, kind, &head)),
        );
        members.push(truth_member(
            gid,
            name,
            kind,
            ctx.opts.schema,
            wall,
            b,
            parent_gid.clone(),
            piece,
        ));
    }
    out
}

fn piece_name(wall: &WallLayout, piece: &Piece, k: usize) -> String {
    format!(
        "{} {} {}-{:03}",
        piece.nominal,
        piece.role.as_str().replace('_', " "),
        wall.id,
        k + 1
    )
}

/// Two products per wall (vertical pieces, horizontal pieces), every piece an
/// IfcMappedItem of a unit-length section scaled along its axis.
fn write_mapped_wall(
    ctx: &mut Ctx,
    place: &WallPlacement,
    b: &PlaceNames,
    parent_gid: Option<String>,
    members: &mut Vec<TruthMember>,
) -> Vec<Ref> {
    let wall = place.wall;
    let mut out = Vec::new();
    // Truth rows must follow the wall's piece order; collect per piece index first.
    let mut rows: Vec<Option<TruthMember>> = vec![None; wall.pieces.len()];
    for (group, vertical) in [("studs", true), ("plates", false)] {
        let indices: Vec<usize> = (0..wall.pieces.len())
            .filter(|&k| wall.pieces[k].upright == vertical)
            .collect();
        if indices.is_empty() {
            continue;
        }
        let kind = product_kind(ctx.opts.products, vertical, false);
        let mut items = Vec::with_capacity(indices.len());
        for &k in &indices {
            let piece = &wall.pieces[k];
            let map = ctx.unit_map(piece.width, piece.thickness);
            let a1 = wall_local_dir(wall, piece.width_dir);
            let a3 = wall_local_dir(wall, piece.axis());
            let a2 = snap(a3.cross(&a1));
            let (d1, d2, d3) = (ctx.dir(a1), ctx.dir(a2), ctx.dir(a3));
            let f = &wall.frame;
            let d = piece.start - f.origin;
            let local = snap_point(Vec3::new(d.dot(&f.u), -d.dot(&f.w), d.dot(&f.v)));
            let o = ctx.point(local);
            let op = ctx.w.add(
                "IFCCARTESIANTRANSFORMATIONOPERATOR3DNONUNIFORM",
                format_args!(
                    "{d1},{d2},{o},1.,{d3},1.,{}",
                    Real(piece.length() * ctx.scale)
                ),
            );
            items.push(ctx.w.add("IFCMAPPEDITEM", format_args!("{map},{op}")));
        }
        let rep = ctx.w.add(
            "IFCSHAPEREPRESENTATION",
            format_args!(
                "{},'Body','MappedRepresentation',{}",
                ctx.body,
                RefList(&items)
            ),
        );
        let shape = ctx
            .w
            .add("IFCPRODUCTDEFINITIONSHAPE", format_args!("$,$,({rep})"));
        let lp = place.at(ctx, wall.frame.origin);
        let key = format!("group:{}:{group}", wall.id);
        let gid = ctx.gid(&key);
        let name = format!("{} {}", wall.id, if vertical { "Studs" } else { "Plates" });
        let nominal = &wall.pieces[indices[0]].nominal;
        let head = format!(
            "{},{},$,{},{lp},{shape},{}",
            ctx.owner_args(&key),
            string(&name),
            string(&format!("{nominal} SPF")),
            string(&format!("{}-{group}", wall.id))
        );
        out.push(
            ctx.w
                .add(kind.entity, product_line(ctx.opts.schema, kind, &head)),
        );
        for (item, &k) in indices.iter().enumerate() {
            // DESIGN §3: a one-piece product's piece id is its GlobalId.
            let piece_id = if indices.len() == 1 {
                gid.clone()
            } else {
                format!("{gid}/{item}")
            };
            rows[k] = Some(truth_member(
                piece_id,
                name.clone(),
                kind,
                ctx.opts.schema,
                wall,
                b,
                parent_gid.clone(),
                &wall.pieces[k],
            ));
        }
    }
    members.extend(rows.into_iter().flatten());
    out
}

#[allow(clippy::too_many_arguments)]
fn truth_member(
    global_id: String,
    name: String,
    kind: ProductKind,
    schema: Schema,
    wall: &WallLayout,
    b: &PlaceNames,
    wall_global_id: Option<String>,
    piece: &Piece,
) -> TruthMember {
    let bx = piece.wall_box;
    TruthMember {
        global_id,
        name,
        ifc_type: kind.ifc_type,
        predefined_type: schema
            .has_element_predefined_type()
            .then_some(kind.predefined),
        wall_id: wall.id.clone(),
        wall_global_id,
        building: b.building.to_string(),
        storey: b.storey.to_string(),
        role: piece.role.as_str(),
        role_detail: piece.role_detail.clone(),
        nominal: piece.nominal.clone(),
        orientation: if piece.upright {
            "vertical"
        } else if piece.role == crate::synth::Role::Brace {
            "inclined"
        } else {
            "horizontal"
        },
        axis_start: q3(&piece.start),
        axis_end: q3(&piece.end),
        width: q(piece.width),
        thickness: q(piece.thickness),
        section_w: q(bx.w[1] - bx.w[0]),
        length: q(piece.length()),
        volume: q(piece.volume()),
        wall_local_box: BoxInfo {
            u: [q(bx.u[0]), q(bx.u[1])],
            v: [q(bx.v[0]), q(bx.v[1])],
            w: [q(bx.w[0]), q(bx.w[1])],
        },
    }
}

fn truth_wall(
    wall: &WallLayout,
    b: &PlaceNames,
    wall_global_id: Option<String>,
    grouping: Grouping,
    members: &[TruthMember],
) -> TruthWall {
    let mut role_counts = BTreeMap::new();
    for p in &wall.pieces {
        *role_counts.entry(p.role.as_str().to_string()).or_insert(0) += 1;
    }
    let m = wall.frame.matrix();
    let ids: Vec<String> = members.iter().map(|m| m.global_id.clone()).collect();
    let nail = |n: &Nail| TruthNail {
        pair: [ids[n.plate].clone(), ids[n.member].clone()],
        plate: ids[n.plate].clone(),
        member: ids[n.member].clone(),
        kind: n.kind,
        u: q(n.u),
        v: q(n.v),
        w: q(n.w),
        world: q3(&wall.frame.to_world(n.u, n.v, n.w)),
        direction_world: q3(&(wall.frame.v * n.v_direction)),
    };
    let (primary, secondary) = targets::nailing_targets(wall);
    TruthWall {
        wall_id: wall.id.clone(),
        wall_global_id,
        container_type: match grouping {
            Grouping::None => None,
            Grouping::Wall => Some("IfcWall"),
            Grouping::Assembly => Some("IfcElementAssembly"),
        },
        name: wall.name.clone(),
        building: b.building.to_string(),
        storey: b.storey.to_string(),
        length: q(wall.length),
        height: q(wall.height),
        thickness: q(wall.thickness),
        frame_matrix: m.map(|row| row.map(q)),
        member_global_ids: ids.clone(),
        assembly_order: ids.clone(),
        assembly_order_roles: wall.pieces.iter().map(|p| p.role.as_str()).collect(),
        precedence_constraints: targets::precedence(wall)
            .iter()
            .map(|p| TruthPrecedence {
                before: ids[p.before].clone(),
                after: ids[p.after].clone(),
                reason: p.reason.as_str(),
            })
            .collect(),
        nailing_targets: primary.iter().map(nail).collect(),
        secondary_nailing_targets: secondary.iter().map(nail).collect(),
        openings: wall
            .openings
            .iter()
            .map(|o| TruthOpening {
                kind: o.kind,
                rough_opening_u: o.rough_opening_u.map(q),
                rough_opening_v: o.rough_opening_v.map(q),
                header: o.header.clone(),
            })
            .collect(),
        role_counts,
    }
}

fn build_truth(
    layout: &Layout,
    opts: &WriteOptions,
    base: PlacementBase,
    members: Vec<TruthMember>,
    walls: Vec<TruthWall>,
) -> Truth {
    let mut by_role = BTreeMap::new();
    let mut by_ifc_type = BTreeMap::new();
    for m in &members {
        *by_role.entry(m.role.to_string()).or_insert(0) += 1;
        *by_ifc_type.entry(m.ifc_type.to_string()).or_insert(0) += 1;
    }
    Truth {
        generator: "framewright synth",
        model: layout.name.clone(),
        file: opts.file_name.clone(),
        description: layout.description.clone(),
        schema: opts.schema.header_name(),
        length_unit: truth::UnitInfo {
            name: opts.unit.ifc_name(),
            metres_per_unit: opts.unit.metres_per_unit(),
            kind: opts.unit.ifc_kind(),
        },
        seed: opts.seed,
        options: truth::OptionsInfo {
            products: match opts.products {
                ProductClasses::Member => "member",
                ProductClasses::ColumnBeam => "column-beam",
            },
            grouping: match opts.grouping {
                Grouping::None => "none",
                Grouping::Wall => "wall",
                Grouping::Assembly => "assembly",
            },
            mapped: opts.mapped,
            placement: match base {
                PlacementBase::Storey => "storey",
                PlacementBase::Parent => "parent",
            },
        },
        conventions: truth::CONVENTIONS,
        counts: Counts {
            members: members.len(),
            walls: walls.len(),
            buildings: layout.buildings.len(),
            by_role,
            by_ifc_type,
        },
        members,
        walls,
    }
}
