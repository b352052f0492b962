//! Placements: IfcAxis2Placement2D/3D and IfcLocalPlacement chains, resolved
//! to world transforms with a cache and cycle detection.

use super::context::Ctx;
use super::error::{IfcErrorKind, Issue, R};
use crate::geom::{Point3, Vector3};
use crate::step::Entity;
use nalgebra::{Isometry3, Matrix3, Rotation3, Translation3, UnitQuaternion};
use std::collections::{HashMap, HashSet};

pub type Iso = Isometry3<f64>;

/// A right-handed frame from a z axis and an x hint; falls back to a
/// perpendicular x when the hint is missing or parallel to z.
pub(crate) fn frame(z: Option<Vector3>, x_hint: Option<Vector3>) -> Matrix3<f64> {
    let z = z.unwrap_or_else(Vector3::z);
    let project = |v: Vector3| {
        let p = v - z * z.dot(&v);
        (p.norm() > 1e-9).then(|| p.normalize())
    };
    let x = x_hint
        .and_then(project)
        .or_else(|| project(Vector3::x()))
        .or_else(|| project(Vector3::y()))
        .unwrap_or_else(Vector3::x);
    let y = z.cross(&x);
    Matrix3::from_columns(&[x, y, z])
}

fn iso(origin: Point3, basis: Matrix3<f64>) -> Iso {
    let rotation = UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix_unchecked(basis));
    Isometry3::from_parts(Translation3::from(origin.coords), rotation)
}

/// IfcAxis2Placement3D or IfcAxis2Placement2D as an isometry (metres).
pub(crate) fn axis2_placement(ctx: &Ctx<'_>, e: &Entity<'_>) -> R<Iso> {
    match e.type_name {
        "IFCAXIS2PLACEMENT3D" => {
            let origin = match ctx.follow(e, 0)? {
                Some(p) => ctx.point(&p)?,
                None => Point3::origin(),
            };
            let z = ctx.direction_attr(e, 1)?;
            let x = ctx.direction_attr(e, 2)?;
            if let (Some(z), Some(x)) = (z, x)
                && z.cross(&x).norm() < 1e-9
            {
                ctx.warn(Some(e.id), format!("#{}: Axis and RefDirection are parallel; a perpendicular RefDirection is used", e.id));
            }
            Ok(iso(origin, frame(z, x)))
        }
        "IFCAXIS2PLACEMENT2D" => {
            let origin = match ctx.follow(e, 0)? {
                Some(p) => ctx.point(&p)?,
                None => Point3::origin(),
            };
            let x = ctx
                .direction_attr(e, 1)?
                .map(|d| Vector3::new(d.x, d.y, 0.0));
            Ok(iso(Point3::new(origin.x, origin.y, 0.0), frame(None, x)))
        }
        other => Err(Issue::unsupported(e.id, format!("{other} as a placement"))),
    }
}

/// Resolves IfcLocalPlacement chains to world placements, caching each link.
#[derive(Default)]
pub(crate) struct Placements {
    cache: HashMap<u64, Iso>,
}

/// Chains longer than this are treated as malformed.
const MAX_CHAIN: usize = 100_000;

impl Placements {
    /// World transform of the object placement `#id`.
    pub fn world(&mut self, ctx: &Ctx<'_>, id: u64, from: u64) -> R<Iso> {
        // Walk up to a cached or root placement without recursion (no stack growth).
        let mut chain: Vec<(u64, Iso)> = Vec::new();
        let mut seen = HashSet::new();
        let mut next = Some((id, from));
        let mut base = Iso::identity();
        while let Some((current, referrer)) = next {
            if let Some(known) = self.cache.get(&current) {
                base = *known;
                break;
            }
            if !seen.insert(current) || chain.len() > MAX_CHAIN {
                let start = chain.iter().position(|(c, _)| *c == current).unwrap_or(0);
                let mut cycle: Vec<u64> = chain[start..].iter().map(|(c, _)| *c).collect();
                cycle.push(current);
                return Err(Issue::Fatal(IfcErrorKind::PlacementCycle {
                    line: ctx.line(current),
                    chain: cycle,
                }));
            }
            let e = ctx.get(current, referrer)?;
            let relative = match e.type_name {
                "IFCLOCALPLACEMENT" => match ctx.follow(&e, 1)? {
                    Some(p) => axis2_placement(ctx, &p)?,
                    None => {
                        return Err(Issue::invalid(
                            e.id,
                            "IfcLocalPlacement has no RelativePlacement",
                        ));
                    }
                },
                other => {
                    return Err(Issue::unsupported(
                        e.id,
                        format!("{other} as an object placement (only IfcLocalPlacement is read)"),
                    ));
                }
            };
            next = e.get(0).as_ref_id().map(|parent| (parent, current));
            chain.push((current, relative));
        }
        for (placement, relative) in chain.into_iter().rev() {
            base *= relative;
            self.cache.insert(placement, base);
        }
        Ok(base)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn frame_is_orthonormal_and_repairs_bad_hints() {
        let f = frame(Some(Vector3::z()), Some(Vector3::z()));
        assert!((f.column(0).into_owned() - Vector3::x()).norm() < 1e-12);
        let f = frame(Some(Vector3::x()), None);
        assert!((f.determinant() - 1.0).abs() < 1e-12);
        assert!(f.column(0).dot(&Vector3::x()).abs() < 1e-12);
    }
}
