// The Rust functors callable from rules as `@name(args)`. This file is read
// twice: by `logic::functors` (which turns each entry into a function and a
// registry entry used by both engines) and by `build.rs` (which only needs the
// signatures). Adding a functor = adding one `fn` here. Parameter and return
// types: i64 (number), u64 (unsigned), F64 (float), Sym (symbol), Vec3, Iso,
// OBox (box). Bodies must be total (no panics): rules cannot run other code.
functor_table! {
    /// A vector from its coordinates.
    fn vec3(x: F64, y: F64, z: F64) -> Vec3 { Vec3::new(x.0, y.0, z.0) }
    /// Coordinates of a vector.
    fn x(v: Vec3) -> F64 { F64(v.0.x) }
    fn y(v: Vec3) -> F64 { F64(v.0.y) }
    fn z(v: Vec3) -> F64 { F64(v.0.z) }
    fn add(a: Vec3, b: Vec3) -> Vec3 { Vec3(a.0 + b.0) }
    fn sub(a: Vec3, b: Vec3) -> Vec3 { Vec3(a.0 - b.0) }
    fn scale(a: Vec3, s: F64) -> Vec3 { Vec3(a.0 * s.0) }
    fn dot(a: Vec3, b: Vec3) -> F64 { F64(a.0.dot(&b.0)) }
    fn cross(a: Vec3, b: Vec3) -> Vec3 { Vec3(a.0.cross(&b.0)) }
    fn norm(a: Vec3) -> F64 { F64(a.0.norm()) }
    /// Distance between two points.
    fn dist(a: Vec3, b: Vec3) -> F64 { F64((a.0 - b.0).norm()) }
    /// Angle between two directions, radians (0 for a zero vector).
    fn angle(a: Vec3, b: Vec3) -> F64 {
        let n = a.0.norm() * b.0.norm();
        F64(if n == 0.0 { 0.0 } else { (a.0.dot(&b.0) / n).clamp(-1.0, 1.0).acos() })
    }
    /// A rigid transform from a translation and roll-pitch-yaw angles (radians).
    fn iso(t: Vec3, rpy: Vec3) -> Iso {
        Iso(nalgebra::Isometry3::from_parts(
            nalgebra::Translation3::from(t.0),
            nalgebra::UnitQuaternion::from_euler_angles(rpy.0.x, rpy.0.y, rpy.0.z),
        ))
    }
    /// The translation part of a transform.
    fn translation(a: Iso) -> Vec3 { Vec3(a.0.translation.vector) }
    /// `a` then `b` expressed in `a`'s frame (`a * b`), as IFC placements compose.
    fn compose(a: Iso, b: Iso) -> Iso { Iso(a.0 * b.0) }
    fn inverse(a: Iso) -> Iso { Iso(a.0.inverse()) }
    /// Transform a point.
    fn apply(a: Iso, p: Vec3) -> Vec3 { Vec3(a.0.transform_point(&nalgebra::Point3::from(p.0)).coords) }
    /// Rotate a direction (no translation).
    fn rotate(a: Iso, v: Vec3) -> Vec3 { Vec3(a.0.rotation * v.0) }
    /// A box from the pose of its centre and its half sizes.
    fn obox(pose: Iso, half: Vec3) -> OBox { OBox { pose: pose.0, half: half.0 } }
    fn box_centre(b: OBox) -> Vec3 { Vec3(b.centre()) }
    fn box_pose(b: OBox) -> Iso { Iso(b.pose) }
    fn box_half(b: OBox) -> Vec3 { Vec3(b.half) }
    fn box_axis_x(b: OBox) -> Vec3 { Vec3(b.axis(0)) }
    fn box_axis_y(b: OBox) -> Vec3 { Vec3(b.axis(1)) }
    fn box_axis_z(b: OBox) -> Vec3 { Vec3(b.axis(2)) }
    /// Move a box by a transform.
    fn transform_box(a: Iso, b: OBox) -> OBox { OBox { pose: a.0 * b.pose, half: b.half } }
    /// 1 if the point lies in the box (1 mm tolerance), else 0.
    fn box_contains(b: OBox, p: Vec3) -> i64 { i64::from(b.contains(&p.0, 1e-3)) }
    /// Round to a multiple of `step` (e.g. 0.001 for millimetres); `x` if step <= 0.
    fn round_to(x: F64, step: F64) -> F64 {
        F64(if step.0 > 0.0 { (x.0 / step.0).round() * step.0 } else { x.0 })
    }
    /// `x` written with `decimals` digits after the point (0..=9), for messages: `@fixed(1.23456, 3)` = "1.235".
    fn fixed(x: F64, decimals: i64) -> Sym {
        let d = decimals.clamp(0, 9) as usize;
        let v = if x.0 == 0.0 { 0.0 } else { x.0 };
        Sym::from(format!("{v:.d$}").as_str())
    }
    /// Half the extent of a box along a direction (its projected radius).
    fn box_radius(b: OBox, d: Vec3) -> F64 {
        let n = d.0.norm();
        F64(if n == 0.0 { 0.0 } else { (0..3).map(|k| b.half[k] * b.axis(k).dot(&d.0).abs()).sum::<f64>() / n })
    }
    /// A frame with origin `o`, x axis `u`, y axis `v` and z axis `u × v`
    /// (u and v are orthonormalised; v is kept as given when u is parallel to it).
    fn frame(o: Vec3, u: Vec3, v: Vec3) -> Iso {
        let u = u.0.try_normalize(1e-12).unwrap_or_else(nalgebra::Vector3::x);
        let v = (v.0 - u * u.dot(&v.0)).try_normalize(1e-12).unwrap_or_else(|| u.cross(&nalgebra::Vector3::z()).try_normalize(1e-12).unwrap_or_else(nalgebra::Vector3::y));
        let m = nalgebra::Matrix3::from_columns(&[u, v, u.cross(&v)]);
        let r = nalgebra::UnitQuaternion::from_rotation_matrix(&nalgebra::Rotation3::from_matrix_unchecked(m));
        Iso(nalgebra::Isometry3::from_parts(nalgebra::Translation3::from(o.0), r))
    }
    /// The direction `v` or `-v`, whichever has its largest-magnitude coordinate positive (the
    /// first of equal ones): a sign convention for box axes, whose signs mean nothing.
    fn canonical_dir(v: Vec3) -> Vec3 {
        let a = v.0.map(f64::abs);
        let k = if a.x >= a.y && a.x >= a.z { 0 } else if a.y >= a.z { 1 } else { 2 };
        Vec3(if v.0[k] < 0.0 { -v.0 } else { v.0 })
    }
    fn abs(x: F64) -> F64 { F64(x.0.abs()) }
    fn sqrt(x: F64) -> F64 { F64(x.0.sqrt()) }
}
