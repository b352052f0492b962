//! Writer state and the geometry entities it shares: points, directions, placements,
//! profiles and representation maps, cached so equal entities are written once.
use super::options::WriteOptions;
use crate::ifc::guid;
use crate::step::text::{Real, RealList, Ref, StepWriter, string};
use crate::synth::layout::{Vec3, WallLayout};
use std::collections::BTreeMap;

/// Writer state: the entity stream, shared entities and caches.
pub(super) struct Ctx<'a> {
    pub(super) w: StepWriter,
    pub(super) opts: &'a WriteOptions,
    /// File units per metre.
    pub(super) scale: f64,
    pub(super) key_prefix: String,
    pub(super) owner: Ref,
    pub(super) body: Ref,
    pub(super) origin: Ref,
    pub(super) origin2d: Ref,
    pub(super) identity: Ref,
    pub(super) dirs: BTreeMap<String, Ref>,
    pub(super) profiles: BTreeMap<(i64, i64), Ref>,
    pub(super) maps: BTreeMap<(i64, i64), Ref>,
}

impl Ctx<'_> {
    pub(super) fn gid(&self, key: &str) -> String {
        guid::global_id(self.opts.seed, &format!("{}/{key}", self.key_prefix))
    }

    pub(super) fn owner_args(&self, key: &str) -> String {
        format!("{},{}", string(&self.gid(key)), self.owner)
    }

    pub(super) fn dir(&mut self, v: Vec3) -> Ref {
        let text = format!("{}", RealList(&[v[0], v[1], v[2]]));
        if let Some(&r) = self.dirs.get(&text) {
            return r;
        }
        let r = self.w.add("IFCDIRECTION", &text);
        self.dirs.insert(text, r);
        r
    }

    /// A point given in metres, written in file units.
    pub(super) fn point(&mut self, p: Vec3) -> Ref {
        let s = self.scale;
        self.w.add(
            "IFCCARTESIANPOINT",
            RealList(&[p[0] * s, p[1] * s, p[2] * s]),
        )
    }

    /// Axis2Placement3D; default axes (z up, x along x) are written as `$`.
    pub(super) fn placement3d(&mut self, location: Vec3, axis: Vec3, ref_dir: Vec3) -> Ref {
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

    pub(super) fn local_placement(&mut self, relative_to: Option<Ref>, placement: Ref) -> Ref {
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
    pub(super) fn profile(&mut self, x_dim: f64, y_dim: f64) -> Ref {
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
    pub(super) fn box_body(&mut self, size: Vec3) -> Ref {
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
    pub(super) fn unit_map(&mut self, width: f64, thickness: f64) -> Ref {
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
pub(super) fn wall_local_dir(wall: &WallLayout, d: Vec3) -> Vec3 {
    let f = &wall.frame;
    snap(Vec3::new(d.dot(&f.u), -d.dot(&f.w), d.dot(&f.v)))
}

/// Remove float dust from unit directions so equal directions share one entity.
pub(super) fn snap(v: Vec3) -> Vec3 {
    v.map(|c| {
        let r = (c * 1e12).round() / 1e12;
        if r == 0.0 { 0.0 } else { r }
    })
}
