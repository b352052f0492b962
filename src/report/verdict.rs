//! One word per element for drawings and scenes: what became of it in the simulation.

use super::simulate::ElementRow;

/// The verdict classes, in the order a legend lists them.
pub const CLASSES: [&str; 4] = [
    "framed",
    "nailing-failed",
    "framing-failed",
    "not-attempted",
];

/// `framed` (placed, and every nail of it driven or it has none), `nailing-failed` (placed,
/// a nail of it not driven or off), `framing-failed` (worked on but not placed on target),
/// `not-attempted` (the executor never got to it).
pub fn class(framing: &str, nailing: &str) -> &'static str {
    match (framing, nailing) {
        ("framed", "nailed" | "none") => "framed",
        ("framed", _) => "nailing-failed",
        ("failed", _) => "framing-failed",
        _ => "not-attempted",
    }
}

pub fn of(e: &ElementRow) -> &'static str {
    class(&e.framing.status, &e.nailing.status)
}

/// sRGB colour of a class (drawings) as `#rrggbb`.
pub fn colour(class: &str) -> &'static str {
    match class {
        "framed" => "#4caf50",
        "nailing-failed" => "#ffb300",
        "framing-failed" => "#e53935",
        _ => "#9e9e9e",
    }
}

/// Linear RGB of a class for the 3D scene; plates a shade darker than studs so roles read.
pub fn linear_rgb(class: &str, role: &str) -> [f32; 3] {
    let base = match class {
        "framed" => [0.09, 0.42, 0.10],
        "nailing-failed" => [1.0, 0.45, 0.0],
        "framing-failed" => [0.78, 0.05, 0.04],
        _ => [0.34, 0.34, 0.34],
    };
    let shade = if role.contains("plate") { 0.6 } else { 1.0 };
    base.map(|c| c * shade)
}
