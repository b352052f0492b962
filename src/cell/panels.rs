//! `[panels]` of a cell file: the limits a wall is split to before anything is framed
//! (`rules/panels.dl` chooses the breaks). The conveyors cap the length further: the rules
//! take the smaller of `max_length` and what the conveyors carry.

use super::error::InvalidValue;
use serde::Deserialize;

/// The panel limits of a cell, SI units.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize, serde::Serialize)]
#[serde(deny_unknown_fields, default)]
pub struct PanelLimits {
    /// Longest panel, m. Default 12.0: the longest elements wall lines of this kind build
    /// (lines build elements 1.2 to 12 m long and 1.5 to 3.5 m high).
    pub max_length: f64,
    /// Highest panel, m. Default 3.5 (the same lines' highest element).
    pub max_height: f64,
    /// Heaviest panel, kg. Default 1,000: ESTIMATE, above the heaviest 12 × 3.5 m framed
    /// element of 2x6 lumber (≈ 400 kg framing, ≈ 800 kg sheathed), within the lifting gear of
    /// such a line; set the line's own figure.
    pub max_mass: f64,
    /// Shortest panel a break may leave, m. Default 1.2 (the lines' shortest element).
    pub min_length: f64,
    /// How far a cap plate's joints lie from a panel break, m: the cap is held back this far
    /// on both sides of the break and the piece across the joint is fixed on site (0: the cap
    /// is cut at the break like the other plates). Default 0.61: the least offset of end
    /// joints in double top plates in the International Residential Code (R602.3.2, 24 in).
    pub cap_lap: f64,
}

impl Default for PanelLimits {
    fn default() -> Self {
        PanelLimits {
            max_length: 12.0,
            max_height: 3.5,
            max_mass: 1000.0,
            min_length: 1.2,
            cap_lap: 0.61,
        }
    }
}

/// Whether walls are split into panels (`--panels auto|off`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum PanelMode {
    /// Split every wall longer or heavier than the limits (a wall that fits is one panel).
    #[default]
    Auto,
    /// Every wall is one panel.
    Off,
}

impl PanelMode {
    pub fn parse(text: &str) -> Result<PanelMode, InvalidValue> {
        match text {
            "auto" => Ok(PanelMode::Auto),
            "off" => Ok(PanelMode::Off),
            _ => Err(InvalidValue(format!(
                "expected `auto` or `off`, got `{text}`"
            ))),
        }
    }

    pub fn as_str(self) -> &'static str {
        match self {
            PanelMode::Auto => "auto",
            PanelMode::Off => "off",
        }
    }
}

impl PanelLimits {
    /// Checks the numbers against each other and against `carry`, the longest piece the
    /// conveyors carry (m). Err: the key and what is wrong.
    pub(super) fn check(&self, carry: f64) -> Result<(), (&'static str, String)> {
        for (key, v, max, unit) in [
            ("max_length", self.max_length, 100.0, "m"),
            ("max_height", self.max_height, 20.0, "m"),
            ("max_mass", self.max_mass, 100_000.0, "kg"),
            ("min_length", self.min_length, 100.0, "m"),
        ] {
            if !(v.is_finite() && v > 0.0 && v <= max) {
                return Err((
                    key,
                    format!("expected a value in {unit} above 0 and at most {max}, got {v}"),
                ));
            }
        }
        if !(self.cap_lap.is_finite() && (0.0..=5.0).contains(&self.cap_lap)) {
            return Err((
                "cap_lap",
                format!(
                    "expected a value in m from 0 (no lap) to 5, got {}",
                    self.cap_lap
                ),
            ));
        }
        let longest = self.max_length.min(carry);
        if self.min_length >= longest {
            return Err((
                "min_length",
                format!(
                    "the shortest panel ({:.2} m) must be shorter than the longest this cell builds ({longest:.2} m: the smaller of max_length and what the conveyors carry)",
                    self.min_length
                ),
            ));
        }
        Ok(())
    }
}
