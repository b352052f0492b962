//! Primitive collision and visual shapes, placed in the frame of the link (or tool) they belong to.

use nalgebra::{Isometry3, Translation3, UnitQuaternion, Vector3};
use serde::Serialize;

/// A primitive shape centred on its own origin. Cylinders and capsules run along their local z.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(tag = "shape", rename_all = "snake_case")]
pub enum Shape {
    Box { half_extents: [f64; 3] },
    Cylinder { radius: f64, length: f64 },
    Capsule { radius: f64, length: f64 },
    Sphere { radius: f64 },
}

impl Shape {
    /// Volume in m³ (capsule = cylinder + sphere).
    pub fn volume(&self) -> f64 {
        use std::f64::consts::PI;
        match *self {
            Shape::Box { half_extents: h } => 8.0 * h[0] * h[1] * h[2],
            Shape::Cylinder { radius, length } => PI * radius * radius * length,
            Shape::Capsule { radius, length } => {
                PI * radius * radius * length + 4.0 / 3.0 * PI * radius.powi(3)
            }
            Shape::Sphere { radius } => 4.0 / 3.0 * PI * radius.powi(3),
        }
    }

    /// The shape with every length multiplied by `k`.
    pub fn scaled(&self, k: f64) -> Shape {
        match *self {
            Shape::Box { half_extents: h } => Shape::Box {
                half_extents: h.map(|v| v * k),
            },
            Shape::Cylinder { radius, length } => Shape::Cylinder {
                radius: radius * k,
                length: length * k,
            },
            Shape::Capsule { radius, length } => Shape::Capsule {
                radius: radius * k,
                length: length * k,
            },
            Shape::Sphere { radius } => Shape::Sphere { radius: radius * k },
        }
    }
}

/// A shape and where it sits in its owner's frame.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PlacedShape {
    #[serde(serialize_with = "super::serialize_isometry")]
    pub origin: Isometry3<f64>,
    #[serde(flatten)]
    pub shape: Shape,
}

/// URDF-style origin: translation and fixed-axis roll, pitch, yaw (rotation Rz·Ry·Rx).
pub fn isometry_from_xyz_rpy(xyz: [f64; 3], rpy: [f64; 3]) -> Isometry3<f64> {
    Isometry3::from_parts(
        Translation3::from(Vector3::from(xyz)),
        UnitQuaternion::from_euler_angles(rpy[0], rpy[1], rpy[2]),
    )
}
