//! Contacts between lumber pieces: which pairs touch within a tolerance,
//! through which faces, over what region, with what gap.
//!
//! Broad phase: a uniform grid over axis-aligned bounds (cell size from the
//! pieces' typical size), so that 50 000 pieces stay fast. Narrow phase: the
//! separating-axis test on the two oriented boxes.

use super::{OrientedBox, Point3, Vector3};
use rustc_hash::{FxHashMap, FxHashSet};
use serde::Serialize;

/// Which face of a piece takes part in a contact.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Face {
    /// A face across the length axis (the piece's end).
    End,
    /// A face whose normal runs along the width axis: the narrow edge face.
    Narrow,
    /// A face whose normal runs along the thickness axis: the wide face.
    Wide,
}

impl Face {
    pub fn name(self) -> &'static str {
        match self {
            Face::End => "end",
            Face::Narrow => "narrow",
            Face::Wide => "wide",
        }
    }
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum ContactKind {
    /// The end of one piece against a side face of the other.
    EndToFace,
    /// Side faces against each other.
    FaceToFace,
    EndToEnd,
}

impl ContactKind {
    pub fn name(self) -> &'static str {
        match self {
            ContactKind::EndToFace => "end_to_face",
            ContactKind::FaceToFace => "face_to_face",
            ContactKind::EndToEnd => "end_to_end",
        }
    }
}

/// Two pieces touching. Indices refer to the slice given to [`contacts`]; `a < b`.
#[derive(Debug, Clone, PartialEq)]
pub struct Contact {
    pub a: usize,
    pub b: usize,
    pub kind: ContactKind,
    pub face_a: Face,
    pub face_b: Face,
    /// Distance between the faces; negative when the pieces overlap.
    pub gap: f64,
    /// Unit normal of the contact plane, pointing from `a` to `b`.
    pub normal: Vector3,
    /// Centre of the contact region (midway between the faces).
    pub centre: Point3,
    /// Extent of the contact region along its two in-plane directions.
    pub size: [f64; 2],
}

/// Options of the contact search.
#[derive(Debug, Clone, Copy)]
pub struct ContactOptions {
    /// Largest gap (and deepest overlap) still counted as touching, metres.
    pub tolerance: f64,
    /// Smallest extent of the shared region in both in-plane directions.
    pub min_overlap: f64,
}

impl Default for ContactOptions {
    fn default() -> Self {
        ContactOptions {
            tolerance: 0.003,
            min_overlap: 0.005,
        }
    }
}

/// Two pieces passing through each other deeper than the contact tolerance (a let-in brace
/// crosses studs modelled without their notches). Indices as in [`Contact`]; `a < b`.
#[derive(Debug, Clone, PartialEq)]
pub struct Crossing {
    pub a: usize,
    pub b: usize,
    /// How deep they overlap along the direction that separates them least, metres.
    pub depth: f64,
}

/// All touching pairs, sorted by `(a, b)`.
pub fn contacts(boxes: &[OrientedBox], options: &ContactOptions) -> Vec<Contact> {
    contacts_and_crossings(boxes, options).0
}

/// All touching pairs and all crossing pairs, each sorted by `(a, b)`.
pub fn contacts_and_crossings(
    boxes: &[OrientedBox],
    options: &ContactOptions,
) -> (Vec<Contact>, Vec<Crossing>) {
    use rayon::prelude::*;
    let found: Vec<Meeting> = candidate_pairs(boxes, options.tolerance)
        .into_par_iter()
        .filter_map(|(a, b)| touch(boxes, a, b, options))
        .collect();
    let (mut touching, mut crossing) = (Vec::new(), Vec::new());
    for m in found {
        match m {
            Meeting::Touch(c) => touching.push(c),
            Meeting::Cross(c) => crossing.push(c),
        }
    }
    touching.sort_by_key(|c| (c.a, c.b));
    crossing.sort_by_key(|c| (c.a, c.b));
    (touching, crossing)
}

/// How two boxes meet.
enum Meeting {
    Touch(Contact),
    Cross(Crossing),
}

fn aabb(b: &OrientedBox, pad: f64) -> (Point3, Point3) {
    let r =
        Vector3::from_fn(|i, _| (0..3).map(|k| b.half[k] * b.axes[k][i].abs()).sum::<f64>() + pad);
    (b.centre - r, b.centre + r)
}

/// A box covering more grid cells than this skips the grid (see `candidate_pairs`).
const MAX_GRID_CELLS_PER_BOX: f64 = 4096.0;

/// Pairs whose padded bounds share a grid cell and overlap.
fn candidate_pairs(boxes: &[OrientedBox], pad: f64) -> Vec<(usize, usize)> {
    if boxes.len() < 2 {
        return Vec::new();
    }
    let bounds: Vec<(Point3, Point3)> = boxes.iter().map(|b| aabb(b, pad)).collect();
    // Cell size: the median of the pieces' largest extent, so a typical piece spans few cells.
    let mut extents: Vec<f64> = bounds.iter().map(|(lo, hi)| (hi - lo).max()).collect();
    extents.sort_by(f64::total_cmp);
    let cell = extents[extents.len() / 2].max(0.05);
    let key = |v: f64| (v / cell).floor() as i64;
    let mut grid: FxHashMap<(i64, i64, i64), Vec<u32>> = FxHashMap::default();
    // Boxes spanning very many cells (or non-finite ones) are compared with every box
    // instead, so the grid's memory never grows with a piece's size or position.
    let mut large = Vec::new();
    for (i, (lo, hi)) in bounds.iter().enumerate() {
        let span = |k: usize| (key(hi[k]) as f64 - key(lo[k]) as f64 + 1.0).max(1.0);
        let cells = span(0) * span(1) * span(2);
        if cells > MAX_GRID_CELLS_PER_BOX || !cells.is_finite() {
            large.push(i);
            continue;
        }
        for x in key(lo.x)..=key(hi.x) {
            for y in key(lo.y)..=key(hi.y) {
                for z in key(lo.z)..=key(hi.z) {
                    grid.entry((x, y, z)).or_default().push(i as u32);
                }
            }
        }
    }
    let overlaps = |a: usize, b: usize| {
        let ((la, ha), (lb, hb)) = (&bounds[a], &bounds[b]);
        (0..3).all(|k| la[k] <= hb[k] && lb[k] <= ha[k])
    };
    let mut pairs = FxHashSet::default();
    for members in grid.values() {
        for (n, &i) in members.iter().enumerate() {
            for &j in &members[n + 1..] {
                let (a, b) = (i.min(j) as usize, i.max(j) as usize);
                if overlaps(a, b) {
                    pairs.insert((a, b));
                }
            }
        }
    }
    for &i in &large {
        for j in 0..boxes.len() {
            if j != i && overlaps(i.min(j), i.max(j)) {
                pairs.insert((i.min(j), i.max(j)));
            }
        }
    }
    let mut pairs: Vec<(usize, usize)> = pairs.into_iter().collect();
    pairs.sort_unstable();
    pairs
}

/// Radius of a box projected on a unit direction.
fn radius(b: &OrientedBox, dir: &Vector3) -> f64 {
    (0..3).map(|k| b.half[k] * b.axes[k].dot(dir).abs()).sum()
}

/// The separating-axis test restricted to the six face normals (the pieces of
/// a frame are boxes whose faces meet, or that share the axis across their wall);
/// returns the contact if they touch, the crossing if they pass through each other.
fn touch(boxes: &[OrientedBox], a: usize, b: usize, options: &ContactOptions) -> Option<Meeting> {
    let (ba, bb) = (&boxes[a], &boxes[b]);
    let d = bb.centre - ba.centre;
    let mut best: Option<(f64, Vector3)> = None;
    for axis in ba.axes.iter().chain(bb.axes.iter()) {
        let separation = d.dot(axis).abs() - radius(ba, axis) - radius(bb, axis);
        if best.is_none_or(|(s, _)| separation > s + 1e-12) {
            best = Some((separation, *axis));
        }
    }
    let (gap, axis) = best?;
    if gap < -options.tolerance {
        return Some(Meeting::Cross(Crossing { a, b, depth: -gap }));
    }
    if gap > options.tolerance {
        return None;
    }
    let normal = if d.dot(&axis) >= 0.0 { axis } else { -axis };
    // The in-plane directions: the other two axes of the box that owns the normal.
    let owner = if ba.axes.iter().any(|x| x.cross(&axis).norm() < 1e-9) {
        ba
    } else {
        bb
    };
    let tangents: Vec<Vector3> = owner
        .axes
        .iter()
        .filter(|x| x.cross(&axis).norm() > 1e-9)
        .copied()
        .collect();
    let mut size = [0.0; 2];
    // Start on the plane midway between the faces, then centre in-plane below.
    let mut centre = ba.centre + normal * (radius(ba, &normal) + gap / 2.0);
    for (k, t) in tangents.iter().take(2).enumerate() {
        let (ca, cb) = (ba.centre.coords.dot(t), bb.centre.coords.dot(t));
        let (ra, rb) = (radius(ba, t), radius(bb, t));
        let lo = (ca - ra).max(cb - rb);
        let hi = (ca + ra).min(cb + rb);
        if hi - lo < options.min_overlap {
            return None;
        }
        size[k] = hi - lo;
        centre += t * ((lo + hi) / 2.0 - centre.coords.dot(t));
    }
    let face = |b: &OrientedBox| {
        let k = (0..3)
            .max_by(|&i, &j| {
                b.axes[i]
                    .dot(&normal)
                    .abs()
                    .total_cmp(&b.axes[j].dot(&normal).abs())
            })
            .unwrap_or(0);
        [Face::End, Face::Narrow, Face::Wide][k]
    };
    let (face_a, face_b) = (face(ba), face(bb));
    let kind = match (face_a == Face::End, face_b == Face::End) {
        (true, true) => ContactKind::EndToEnd,
        (false, false) => ContactKind::FaceToFace,
        _ => ContactKind::EndToFace,
    };
    Some(Meeting::Touch(Contact {
        a,
        b,
        kind,
        face_a,
        face_b,
        gap,
        normal,
        centre,
        size,
    }))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// An axis-aligned piece from its min and max corners.
    fn piece(min: [f64; 3], max: [f64; 3]) -> OrientedBox {
        let half = [0, 1, 2].map(|i| (max[i] - min[i]) / 2.0);
        let centre = Point3::new(
            (min[0] + max[0]) / 2.0,
            (min[1] + max[1]) / 2.0,
            (min[2] + max[2]) / 2.0,
        );
        OrientedBox::new(centre, [Vector3::x(), Vector3::y(), Vector3::z()], half)
    }

    #[test]
    fn stud_on_plate_is_end_to_face() {
        // A bottom plate (2x4 flat) and a stud standing on it.
        let plate = piece([0.0, 0.0, 0.0], [1.0, 0.0889, 0.0381]);
        let stud = piece([0.0, 0.0, 0.0381], [0.0381, 0.0889, 1.0]);
        let away = piece([0.5, 0.0, 0.0401], [0.5381, 0.0889, 1.0]);
        let found = contacts(&[plate, stud, away], &ContactOptions::default());
        assert_eq!(found.len(), 2, "{found:?}");
        let c = &found[0];
        assert_eq!(
            (c.a, c.b, c.kind, c.face_a, c.face_b),
            (0, 1, ContactKind::EndToFace, Face::Wide, Face::End)
        );
        assert!(c.gap.abs() < 1e-12);
        assert!((c.normal - Vector3::z()).norm() < 1e-12);
        assert!(
            (c.centre - Point3::new(0.01905, 0.04445, 0.0381)).norm() < 1e-9,
            "{:?}",
            c.centre
        );
        let mut size = c.size;
        size.sort_by(f64::total_cmp);
        assert!((size[0] - 0.0381).abs() < 1e-9 && (size[1] - 0.0889).abs() < 1e-9);
        // 2 mm gap: still a contact, with its gap.
        assert!((found[1].gap - 0.002).abs() < 1e-9);
    }

    #[test]
    fn far_and_edge_touching_pieces_are_not_contacts() {
        let a = piece([0.0, 0.0, 0.0], [1.0, 0.1, 0.04]);
        let far = piece([0.0, 0.0, 0.1], [1.0, 0.1, 0.14]);
        let edge = piece([1.0, 0.1, 0.0], [2.0, 0.2, 0.04]);
        assert!(contacts(&[a, far, edge], &ContactOptions::default()).is_empty());
    }

    #[test]
    fn a_brace_through_a_stud_is_a_crossing_not_a_contact() {
        // A 1x4 at 45° in the outer 19 mm of a 2x4 stud's depth.
        let stud = piece([0.5, 0.0, 0.0], [0.5381, 0.0889, 2.4]);
        let (c, s) = (
            std::f64::consts::FRAC_1_SQRT_2,
            std::f64::consts::FRAC_1_SQRT_2,
        );
        let brace = OrientedBox::new(
            Point3::new(0.5, 0.0095, 1.0),
            [
                Vector3::new(c, 0.0, s),
                Vector3::new(-s, 0.0, c),
                Vector3::y(),
            ],
            [0.5, 0.0445, 0.0095],
        );
        let (touching, crossing) =
            contacts_and_crossings(&[stud, brace], &ContactOptions::default());
        assert!(touching.is_empty(), "{touching:?}");
        assert_eq!(crossing.len(), 1);
        // It overlaps the stud by its own thickness across the wall.
        assert!((crossing[0].depth - 0.019).abs() < 1e-9, "{crossing:?}");
    }

    #[test]
    fn double_top_plate_is_face_to_face() {
        let top = piece([0.0, 0.0, 2.0], [3.0, 0.0889, 2.0381]);
        let cap = piece([0.0, 0.0, 2.0381], [3.0, 0.0889, 2.0762]);
        let c = &contacts(&[top, cap], &ContactOptions::default())[0];
        assert_eq!(
            (c.kind, c.face_a, c.face_b),
            (ContactKind::FaceToFace, Face::Wide, Face::Wide)
        );
    }

    #[test]
    fn many_pieces_pair_up_like_brute_force() {
        let mut boxes = Vec::new();
        for i in 0..40 {
            let x = i as f64 * 0.4064;
            boxes.push(piece([x, 0.0, 0.0381], [x + 0.0381, 0.0889, 2.4]));
        }
        boxes.push(piece([0.0, 0.0, 0.0], [16.3, 0.0889, 0.0381]));
        boxes.push(piece([0.0, 0.0, 2.4], [16.3, 0.0889, 2.4381]));
        let found = contacts(&boxes, &ContactOptions::default());
        let brute: Vec<(usize, usize)> = (0..boxes.len())
            .flat_map(|a| (a + 1..boxes.len()).map(move |b| (a, b)))
            .filter(|&(a, b)| {
                matches!(
                    touch(&boxes, a, b, &ContactOptions::default()),
                    Some(Meeting::Touch(_))
                )
            })
            .collect();
        assert_eq!(found.iter().map(|c| (c.a, c.b)).collect::<Vec<_>>(), brute);
        assert_eq!(found.len(), 80);
    }
}
