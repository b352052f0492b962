//! The nails of a wall as the executor drives them: numbered along each plate and member,
//! directions in the wall frame.

use crate::frame::plan::NailingTarget;
use nalgebra::{Isometry3, Vector3};

/// One nail as the executor drives it.
#[derive(Debug, Clone)]
pub struct NailPlan {
    pub plate: String,
    pub member: String,
    pub k: i64,
    /// Wall coordinates of the target and the driving direction in the wall frame.
    pub uvw: [f64; 3],
    pub direction: Vector3<f64>,
}

impl NailPlan {
    /// The executor's nails of a wall from the plan's targets: numbered 1, 2, … along w per
    /// plate and member, in plate order then along the wall.
    pub fn from_targets(targets: &[NailingTarget], wall_frame: &Isometry3<f64>) -> Vec<NailPlan> {
        let mut sorted: Vec<&NailingTarget> = targets.iter().collect();
        sorted.sort_by(|a, b| {
            (&a.plate, &a.member)
                .cmp(&(&b.plate, &b.member))
                .then(a.w.total_cmp(&b.w))
        });
        let mut nails = Vec::new();
        let mut k = 0;
        let mut last: Option<(&str, &str)> = None;
        for t in sorted {
            let key = (t.plate.as_str(), t.member.as_str());
            k = if last == Some(key) { k + 1 } else { 1 };
            last = Some(key);
            nails.push(NailPlan {
                plate: t.plate.clone(),
                member: t.member.clone(),
                k,
                uvw: [t.u, t.v, t.w],
                direction: wall_frame.rotation.inverse() * t.direction,
            });
        }
        nails.sort_by(|a, b| {
            a.plate
                .cmp(&b.plate)
                .then(a.uvw[0].total_cmp(&b.uvw[0]))
                .then(a.k.cmp(&b.k))
        });
        nails
    }
}
