//! What a wall's split into panels is: its panels with their members, cut plate segments and
//! added end studs, the breaks, the site pieces across the joints; and the panel a piece of
//! the panelized model is built in. `panels` decides the split, `panelize` cuts the model.

/// The wall and panel a piece of the panelized model is built in.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct PanelOf {
    /// The whole wall's plan id (`W1`, or its group's GlobalId).
    pub wall_id: String,
    pub wall_name: String,
    /// The whole wall's key piece (the rules' name for it).
    pub wall_key: String,
    /// `W1-P2`; a wall that fits is its one panel `W1-P1`.
    pub panel_id: String,
    /// The panel's number along the wall (from 1); 0 for a wall that fits.
    pub index: usize,
}

impl PanelOf {
    /// What the cell builds, as every command names it: the panel of a split wall (`W1-P2`),
    /// or the wall that fits (`W1`).
    pub fn unit_id(&self) -> &str {
        if self.index > 0 {
            &self.panel_id
        } else {
            &self.wall_id
        }
    }

    /// `Wall 1, panel 2` or `Wall 1`.
    pub fn unit_name(&self) -> String {
        if self.index > 0 {
            format!("{}, panel {}", self.wall_name, self.index)
        } else {
            self.wall_name.clone()
        }
    }

    /// `Wall 1, panel 2 (W1-P2)`, `Wall 1 (W1)`: as `simulate` prints it.
    pub fn label(&self) -> String {
        format!("{} ({})", self.unit_name(), self.unit_id())
    }
}

/// A panel of a wall: the part between two breaks (or the wall's ends).
#[derive(Debug, Clone, PartialEq)]
pub struct Panel {
    /// `WALL-P1`, `WALL-P2`, … along u.
    pub id: String,
    /// 1-based, along u.
    pub index: usize,
    pub u_start: f64,
    pub u_end: f64,
    /// Its pieces' extent up the wall, m.
    pub height: f64,
    /// Its pieces' mass, kg (cut plates by their share of the length).
    pub mass: f64,
    /// The wall's members that lie whole in this panel, in the wall's member order.
    pub member_ids: Vec<String>,
    pub cut_pieces: Vec<CutPiece>,
    pub added_pieces: Vec<AddedPiece>,
    /// The limits this panel breaks, in words (empty when it fits).
    pub exceeds: Vec<String>,
}

impl Panel {
    pub fn length(&self) -> f64 {
        self.u_end - self.u_start
    }
}

/// A segment of a plate cut at a break.
#[derive(Debug, Clone, PartialEq)]
pub struct CutPiece {
    /// `PLATE~k`.
    pub id: String,
    /// The plate it is cut from.
    pub of: String,
    pub u_start: f64,
    pub u_end: f64,
    pub mass: f64,
}

/// An end stud a break adds: a copy of `of` moved along u to `u_start..u_end`.
#[derive(Debug, Clone, PartialEq)]
pub struct AddedPiece {
    /// `STUD~endK`.
    pub id: String,
    pub of: String,
    pub role: String,
    pub u_start: f64,
    pub u_end: f64,
    pub mass: f64,
}

/// The stretch of a lapped plate across a panel joint: fixed on site, in no panel.
#[derive(Debug, Clone, PartialEq)]
pub struct SitePiece {
    /// `PLATE~lapK`.
    pub id: String,
    pub of: String,
    pub u_start: f64,
    pub u_end: f64,
    pub mass: f64,
    /// The panels it laps over, along u.
    pub laps: Vec<String>,
}

/// A break the split made.
#[derive(Debug, Clone, PartialEq)]
pub struct PanelBreak {
    pub u: f64,
    /// Why here, in words.
    pub reason: String,
}

/// The split of one wall.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct WallPanels {
    pub panels: Vec<Panel>,
    pub breaks: Vec<PanelBreak>,
    /// Pieces fixed on site across the joints (lapped plates), along u.
    pub site_pieces: Vec<SitePiece>,
    /// What the split could not do (limits dropped, wanted breaks not made).
    pub notes: Vec<String>,
}
