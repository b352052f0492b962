//! Geometry shared by the stages: oriented boxes (one per lumber piece) and
//! box fitting from points.

mod contact;
mod obox;

pub use contact::{
    Contact, ContactKind, ContactOptions, Crossing, Face, contacts, contacts_and_crossings,
};
pub use obox::{OrientedBox, fit_points};

pub type Point3 = nalgebra::Point3<f64>;
pub type Vector3 = nalgebra::Vector3<f64>;
pub type Affine = nalgebra::Matrix4<f64>;

/// True for finite values above `min`; false for NaN (geometry checks rely on it).
pub fn above(x: f64, min: f64) -> bool {
    x.is_finite() && x > min
}
