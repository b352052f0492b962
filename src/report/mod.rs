//! Outputs a person or a program reads. Numbers in JSON are rounded to the
//! nanometre so that output is stable and free of float noise.

pub mod bid;
pub mod bid_html;
pub mod causes;
pub mod failure_class;
pub mod glb;
pub mod html;
pub mod inspect;
pub mod markup_text;
pub mod member;
mod mesh;
pub mod panels;
pub mod plan;
pub mod png;
mod pretty_json;
pub mod role_check;
pub mod simulate;
mod simulate_text;
mod style;
pub mod svg;
pub mod verdict;
pub mod viewer;
pub mod wall_view;

/// Rounds a length to 1e-9 m (and turns -0 into 0).
pub fn round_m(x: f64) -> f64 {
    let r = (x * 1e9).round() / 1e9;
    if r == 0.0 { 0.0 } else { r }
}

pub fn round_point(p: &crate::geom::Point3) -> [f64; 3] {
    [round_m(p.x), round_m(p.y), round_m(p.z)]
}
