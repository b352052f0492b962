//! The typed result of frame reasoning for one model: walls with their frame,
//! members with roles, assembly order, precedence, nailing and framing targets.

use super::panel::{PanelOf, WallPanels};
use crate::cell::PanelLimits;
use crate::geom::Point3;
use nalgebra::{Isometry3, Vector3};
use std::collections::BTreeMap;

#[derive(Debug, Clone)]
pub struct Plan {
    pub walls: Vec<Wall>,
    /// Wall id of each piece that belongs to a wall, by piece id.
    pub wall_of: BTreeMap<String, String>,
    pub roles: BTreeMap<String, String>,
    /// Mass of each piece, kg.
    pub masses: BTreeMap<String, f64>,
    pub warnings: Vec<String>,
    /// The panel limits the rules derived for the cell (`panel_limit`); None when the
    /// relations hold none (a rules directory without `panels.dl`).
    pub panel_limits: Option<PanelLimits>,
}

#[derive(Debug, Clone)]
pub struct Wall {
    /// `W1`, `W2`, … in file order of the walls' first pieces, or the GlobalId
    /// of the IFC group that is exactly this wall.
    pub id: String,
    pub name: String,
    /// The piece the rules name the wall after.
    pub key: String,
    pub group_global_id: Option<String>,
    pub members: Vec<String>,
    /// Wall coordinates (u along, v up, w inward) → world.
    pub frame: Isometry3<f64>,
    pub length: f64,
    pub height: f64,
    pub thickness: f64,
    pub assembly_order: Vec<String>,
    pub precedence: Vec<(String, String, String)>,
    pub nailing_targets: Vec<NailingTarget>,
    pub framing_targets: Vec<(String, Isometry3<f64>)>,
    /// The wall split into the panels the cell builds (one when it fits); a panel of a split
    /// wall (`panel` set, index > 0) holds its whole wall's split.
    pub panels: WallPanels,
    /// In a plan of a model cut into panels (`frame::panelize`): the whole wall and the
    /// panel this wall is. A wall that fits keeps its whole wall's id; a panel of a split
    /// wall is named by its panel id.
    pub panel: Option<PanelOf>,
}

impl Wall {
    /// The id of the whole wall this wall is or is a panel of.
    pub fn whole_id(&self) -> &str {
        self.panel.as_ref().map_or(&self.id, |p| &p.wall_id)
    }

    /// The id of the panel the cell builds: `W1-P2`, or `W1-P1` for a wall that fits.
    pub fn panel_id(&self) -> String {
        match (&self.panel, self.panels.panels.first()) {
            (Some(p), _) => p.panel_id.clone(),
            (None, Some(p)) if self.panels.panels.len() == 1 => p.id.clone(),
            _ => format!("{}-P1", self.id),
        }
    }
}

#[derive(Debug, Clone)]
pub struct NailingTarget {
    pub plate: String,
    pub member: String,
    pub kind: String,
    pub u: f64,
    pub v: f64,
    pub w: f64,
    pub world: Point3,
    pub direction: Vector3<f64>,
}
