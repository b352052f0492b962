//! Oriented boxes: a centre, three orthonormal axes and half sizes.
//! `axes[0]` is the lumber's length direction (the longest side unless the
//! geometry says otherwise, e.g. a cripple stud shorter than its section);
//! `axes[1]` and `axes[2]` are the wider and the thinner cross-section side.

use super::{Affine, Point3, Vector3};
use nalgebra::{Matrix3, SymmetricEigen};

#[derive(Debug, Clone, Copy, PartialEq)]
pub struct OrientedBox {
    pub centre: Point3,
    /// Unit axes: length, width, thickness; right-handed.
    pub axes: [Vector3; 3],
    /// Half sizes along `axes`; `half[1] >= half[2]`.
    pub half: [f64; 3],
}

impl OrientedBox {
    /// Builds a box from arbitrary axes and half sizes: sorts them by size
    /// (longest first) and makes the frame right-handed.
    pub fn new(centre: Point3, axes: [Vector3; 3], half: [f64; 3]) -> Self {
        Self::with_length_axis(centre, axes, half, None)
    }

    /// Like [`OrientedBox::new`], but `axes[length]` is the length direction
    /// when given, unless it is the thinnest side (then the piece is a slab
    /// extruded through its thickness and the longest side is the length).
    pub fn with_length_axis(
        centre: Point3,
        axes: [Vector3; 3],
        half: [f64; 3],
        length: Option<usize>,
    ) -> Self {
        let mut order = [0usize, 1, 2];
        // Stable on ties so that equal sizes keep the caller's order.
        order.sort_by(|&a, &b| half[b].total_cmp(&half[a]));
        if let Some(l) = length.filter(|&l| l < 3 && l != order[2]) {
            let rest: Vec<usize> = order.iter().copied().filter(|&i| i != l).collect();
            order = [l, rest[0], rest[1]];
        }
        let mut axes = order.map(|i| axes[i].normalize());
        if axes[0].cross(&axes[1]).dot(&axes[2]) < 0.0 {
            axes[2] = -axes[2];
        }
        OrientedBox {
            centre,
            axes,
            half: order.map(|i| half[i]),
        }
    }

    /// The box of local bounds `min..max` placed by an affine map whose
    /// columns stay orthogonal; `None` when the map shears the box.
    pub fn from_affine_bounds(
        map: &Affine,
        min: &Point3,
        max: &Point3,
        length: Option<usize>,
    ) -> Option<Self> {
        let linear = map.fixed_view::<3, 3>(0, 0).into_owned();
        let edges: [Vector3; 3] = [0, 1, 2].map(|i| linear.column(i) * (max[i] - min[i]));
        let lengths = edges.map(|e| e.norm());
        if lengths.iter().any(|&l| !super::above(l, 0.0)) {
            return None;
        }
        for (a, b) in [(0, 1), (0, 2), (1, 2)] {
            if (edges[a].dot(&edges[b]) / (lengths[a] * lengths[b])).abs() > 1e-9 {
                return None;
            }
        }
        let centre_local = Point3::from((min.coords + max.coords) / 2.0);
        let centre = map.transform_point(&centre_local);
        Some(OrientedBox::with_length_axis(
            centre,
            edges.map(|e| e / e.norm()),
            lengths.map(|l| l / 2.0),
            length,
        ))
    }

    pub fn length(&self) -> f64 {
        2.0 * self.half[0]
    }

    /// The larger cross-section dimension.
    pub fn width(&self) -> f64 {
        2.0 * self.half[1]
    }

    /// The smaller cross-section dimension.
    pub fn thickness(&self) -> f64 {
        2.0 * self.half[2]
    }

    pub fn volume(&self) -> f64 {
        8.0 * self.half[0] * self.half[1] * self.half[2]
    }

    /// End points of the centre line of the cross-section (along the longest axis).
    pub fn axis_ends(&self) -> (Point3, Point3) {
        let d = self.axes[0] * self.half[0];
        (self.centre - d, self.centre + d)
    }

    pub fn corners(&self) -> [Point3; 8] {
        let mut out = [self.centre; 8];
        for (k, corner) in out.iter_mut().enumerate() {
            for (i, axis) in self.axes.iter().enumerate() {
                let sign = if k >> i & 1 == 1 { 1.0 } else { -1.0 };
                *corner += axis * (sign * self.half[i]);
            }
        }
        out
    }
}

/// Fits an oriented box to points: the long axis by principal components,
/// the cross-section by the minimum-area rectangle of the projected hull
/// (exact for the corners of any cuboid). `None` for fewer than 2 distinct points
/// or a degenerate (flat or zero-length) set.
pub fn fit_points(points: &[Point3]) -> Option<OrientedBox> {
    if points.len() < 4
        || points
            .iter()
            .any(|p| !p.coords.iter().all(|c| c.is_finite()))
    {
        return None;
    }
    let n = points.len() as f64;
    let mean = points.iter().fold(Vector3::zeros(), |a, p| a + p.coords) / n;
    let mut cov = Matrix3::zeros();
    for p in points {
        let d = p.coords - mean;
        cov += d * d.transpose();
    }
    let eig = SymmetricEigen::new(cov / n);
    let mut idx = [0usize, 1, 2];
    idx.sort_by(|&a, &b| eig.eigenvalues[b].total_cmp(&eig.eigenvalues[a]));
    let long = eig.eigenvectors.column(idx[0]).into_owned().normalize();
    let seed = eig.eigenvectors.column(idx[1]).into_owned();
    let u = (seed - long * long.dot(&seed)).normalize();
    let v = long.cross(&u);
    let planar: Vec<(f64, f64)> = points
        .iter()
        .map(|p| (p.coords.dot(&u), p.coords.dot(&v)))
        .collect();
    let (cu, cv) = min_area_rectangle_axes(&planar)?;
    let axes = [long, u * cu.0 + v * cu.1, u * cv.0 + v * cv.1];
    let mut min = [f64::INFINITY; 3];
    let mut max = [f64::NEG_INFINITY; 3];
    for p in points {
        for i in 0..3 {
            let t = p.coords.dot(&axes[i]);
            min[i] = min[i].min(t);
            max[i] = max[i].max(t);
        }
    }
    let half = [0, 1, 2].map(|i| (max[i] - min[i]) / 2.0);
    if half.iter().any(|&h| !super::above(h, 1e-12)) {
        return None;
    }
    let centre = Point3::from(
        axes[0] * (min[0] + max[0]) / 2.0
            + axes[1] * (min[1] + max[1]) / 2.0
            + axes[2] * (min[2] + max[2]) / 2.0,
    );
    Some(OrientedBox::new(centre, axes, half))
}

/// Axes (as unit 2D vectors) of the minimum-area rectangle around 2D points.
fn min_area_rectangle_axes(points: &[(f64, f64)]) -> Option<((f64, f64), (f64, f64))> {
    let hull = convex_hull(points);
    if hull.len() < 3 {
        return None;
    }
    let mut best: Option<(f64, (f64, f64))> = None;
    for i in 0..hull.len() {
        let (a, b) = (hull[i], hull[(i + 1) % hull.len()]);
        let (dx, dy) = (b.0 - a.0, b.1 - a.1);
        let len = (dx * dx + dy * dy).sqrt();
        if len < 1e-15 {
            continue;
        }
        let e = (dx / len, dy / len);
        let (mut lo0, mut hi0, mut lo1, mut hi1) = (
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::INFINITY,
            f64::NEG_INFINITY,
        );
        for p in &hull {
            let s = p.0 * e.0 + p.1 * e.1;
            let t = -p.0 * e.1 + p.1 * e.0;
            lo0 = lo0.min(s);
            hi0 = hi0.max(s);
            lo1 = lo1.min(t);
            hi1 = hi1.max(t);
        }
        let area = (hi0 - lo0) * (hi1 - lo1);
        if best.is_none_or(|(a, _)| area < a - 1e-15) {
            best = Some((area, e));
        }
    }
    best.map(|(_, e)| (e, (-e.1, e.0)))
}

/// Andrew's monotone chain; returns the hull counter-clockwise.
fn convex_hull(points: &[(f64, f64)]) -> Vec<(f64, f64)> {
    let mut pts: Vec<(f64, f64)> = points.to_vec();
    pts.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.total_cmp(&b.1)));
    pts.dedup_by(|a, b| (a.0 - b.0).abs() < 1e-12 && (a.1 - b.1).abs() < 1e-12);
    if pts.len() < 3 {
        return pts;
    }
    let cross = |o: (f64, f64), a: (f64, f64), b: (f64, f64)| {
        (a.0 - o.0) * (b.1 - o.1) - (a.1 - o.1) * (b.0 - o.0)
    };
    let mut hull: Vec<(f64, f64)> = Vec::with_capacity(2 * pts.len());
    for pass in 0..2 {
        let start = hull.len();
        let iter: Box<dyn Iterator<Item = &(f64, f64)>> = if pass == 0 {
            Box::new(pts.iter())
        } else {
            Box::new(pts.iter().rev())
        };
        for &p in iter {
            while hull.len() >= start + 2
                && cross(hull[hull.len() - 2], hull[hull.len() - 1], p) <= 0.0
            {
                hull.pop();
            }
            hull.push(p);
        }
        hull.pop();
    }
    hull
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{Rotation3, Unit};

    #[test]
    fn fits_a_rotated_cuboid_exactly() {
        let rot =
            Rotation3::from_axis_angle(&Unit::new_normalize(Vector3::new(0.3, -0.5, 0.8)), 0.7);
        let truth = OrientedBox::new(
            Point3::new(1.0, 2.0, 3.0),
            [rot * Vector3::x(), rot * Vector3::y(), rot * Vector3::z()],
            [1.2, 0.04445, 0.01905],
        );
        let fitted = fit_points(&truth.corners()).unwrap();
        for i in 0..3 {
            assert!((fitted.half[i] - truth.half[i]).abs() < 1e-9, "{fitted:?}");
            assert!(fitted.axes[i].dot(&truth.axes[i]).abs() > 1.0 - 1e-9);
        }
        assert!((fitted.centre - truth.centre).norm() < 1e-9);
    }

    #[test]
    fn square_section_is_fitted() {
        let b = OrientedBox::new(
            Point3::origin(),
            [Vector3::z(), Vector3::x(), Vector3::y()],
            [1.0, 0.05, 0.05],
        );
        let f = fit_points(&b.corners()).unwrap();
        assert!(
            (f.length() - 2.0).abs() < 1e-9
                && (f.width() - 0.1).abs() < 1e-9
                && (f.thickness() - 0.1).abs() < 1e-9
        );
    }

    #[test]
    fn flat_sets_are_refused() {
        let flat = [
            Point3::new(0., 0., 0.),
            Point3::new(1., 0., 0.),
            Point3::new(0., 1., 0.),
            Point3::new(1., 1., 0.),
        ];
        assert!(fit_points(&flat).is_none());
    }

    #[test]
    fn affine_bounds_detect_shear() {
        let mut m = Affine::identity();
        m[(0, 1)] = 0.5;
        assert!(
            OrientedBox::from_affine_bounds(&m, &Point3::origin(), &Point3::new(1., 1., 1.), None)
                .is_none()
        );
        let ok = OrientedBox::from_affine_bounds(
            &Affine::identity(),
            &Point3::origin(),
            &Point3::new(3., 1., 2.),
            None,
        )
        .unwrap();
        assert_eq!(ok.half, [1.5, 1.0, 0.5]);
        assert_eq!(ok.centre, Point3::new(1.5, 0.5, 1.0));
    }

    #[test]
    fn length_axis_wins_unless_thinnest() {
        let o = Point3::origin();
        let axes = [Vector3::x(), Vector3::y(), Vector3::z()];
        // A cripple: 60 mm long (z) with an 89 x 38 mm section.
        let cripple = OrientedBox::with_length_axis(o, axes, [0.0445, 0.019, 0.030], Some(2));
        assert_eq!(cripple.half, [0.030, 0.0445, 0.019]);
        assert!(cripple.axes[0].cross(&Vector3::z()).norm() < 1e-12);
        // A slab extruded through its thickness: the longest side is the length.
        let slab = OrientedBox::with_length_axis(o, axes, [10.0, 0.25, 0.08], Some(2));
        assert_eq!(slab.half, [10.0, 0.25, 0.08]);
    }
}
