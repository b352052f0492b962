//! The truth sidecar: what a generated file contains, in the field names of the
//! shared truth files (world coordinates, metres).
use serde::Serialize;
use std::collections::BTreeMap;

/// Round to 1e-9 m so float noise from unit arithmetic does not show.
pub fn q(x: f64) -> f64 {
    let r = (x * 1e9).round() / 1e9;
    if r == 0.0 { 0.0 } else { r }
}

pub fn q3(v: &nalgebra::Vector3<f64>) -> [f64; 3] {
    [q(v[0]), q(v[1]), q(v[2])]
}

#[derive(Debug, Clone, Serialize)]
pub struct UnitInfo {
    pub name: &'static str,
    pub metres_per_unit: f64,
    pub kind: &'static str,
}

#[derive(Debug, Clone, Serialize)]
pub struct OptionsInfo {
    pub products: &'static str,
    pub grouping: &'static str,
    pub mapped: bool,
    pub placement: &'static str,
}

#[derive(Debug, Clone, Serialize)]
pub struct Conventions {
    pub units: &'static str,
    pub wall_frame: &'static str,
    pub member_axis: &'static str,
    pub section: &'static str,
    pub global_id: &'static str,
}

pub const CONVENTIONS: Conventions = Conventions {
    units: "lengths and coordinates in metres, volumes in cubic metres, world frame",
    wall_frame: "origin at the bottom outer corner of the wall start; u along the wall, v up, w = u x v across the thickness from the outer face; frame_matrix is 4x4 row-major with columns u, v, w, origin",
    member_axis: "centre line of the cross-section; axis_start is the bottom end of a vertical member or the smaller-u end of a horizontal one",
    section: "width is the larger and thickness the smaller cross-section dimension; section_w is the dimension across the wall thickness",
    global_id: "a piece of a many-piece product (mapped items) is GLOBALID/k, k counting from 0 in item order",
};

#[derive(Debug, Clone, Serialize)]
pub struct Counts {
    pub members: usize,
    pub walls: usize,
    pub buildings: usize,
    pub by_role: BTreeMap<String, usize>,
    pub by_ifc_type: BTreeMap<String, usize>,
}

#[derive(Debug, Clone, Serialize)]
pub struct BoxInfo {
    pub u: [f64; 2],
    pub v: [f64; 2],
    pub w: [f64; 2],
}

#[derive(Debug, Clone, Serialize)]
pub struct TruthMember {
    pub global_id: String,
    pub name: String,
    pub ifc_type: &'static str,
    pub predefined_type: Option<&'static str>,
    pub wall_id: String,
    pub wall_global_id: Option<String>,
    pub building: String,
    pub storey: String,
    pub role: &'static str,
    pub role_detail: String,
    pub nominal: String,
    pub orientation: &'static str,
    pub axis_start: [f64; 3],
    pub axis_end: [f64; 3],
    pub width: f64,
    pub thickness: f64,
    pub section_w: f64,
    pub length: f64,
    pub volume: f64,
    pub wall_local_box: BoxInfo,
}

#[derive(Debug, Clone, Serialize)]
pub struct TruthOpening {
    pub kind: &'static str,
    pub rough_opening_u: [f64; 2],
    pub rough_opening_v: [f64; 2],
    pub header: String,
}

#[derive(Debug, Clone, Serialize)]
pub struct TruthPrecedence {
    pub before: String,
    pub after: String,
    pub reason: &'static str,
}

#[derive(Debug, Clone, Serialize)]
pub struct TruthNail {
    pub pair: [String; 2],
    pub plate: String,
    pub member: String,
    pub kind: &'static str,
    pub u: f64,
    pub v: f64,
    pub w: f64,
    pub world: [f64; 3],
    pub direction_world: [f64; 3],
}

#[derive(Debug, Clone, Serialize)]
pub struct TruthWall {
    pub wall_id: String,
    pub wall_global_id: Option<String>,
    pub container_type: Option<&'static str>,
    pub name: String,
    pub building: String,
    pub storey: String,
    pub length: f64,
    pub height: f64,
    pub thickness: f64,
    pub frame_matrix: [[f64; 4]; 4],
    pub member_global_ids: Vec<String>,
    /// One valid order (the layout's piece order).
    pub assembly_order: Vec<String>,
    pub assembly_order_roles: Vec<&'static str>,
    pub precedence_constraints: Vec<TruthPrecedence>,
    pub nailing_targets: Vec<TruthNail>,
    /// Through a sill into the cripple studs below it.
    pub secondary_nailing_targets: Vec<TruthNail>,
    pub openings: Vec<TruthOpening>,
    pub role_counts: BTreeMap<String, usize>,
}

#[derive(Debug, Clone, Serialize)]
pub struct Truth {
    pub generator: &'static str,
    pub model: String,
    pub file: String,
    pub description: String,
    pub schema: &'static str,
    pub length_unit: UnitInfo,
    pub seed: u64,
    pub options: OptionsInfo,
    pub conventions: Conventions,
    pub counts: Counts,
    pub members: Vec<TruthMember>,
    pub walls: Vec<TruthWall>,
}

impl Truth {
    /// Pretty JSON with a trailing newline (stable: struct field order, BTreeMaps).
    pub fn to_json(&self) -> String {
        let mut text = serde_json::to_string_pretty(self).expect("truth is plain data");
        text.push('\n');
        text
    }
}
