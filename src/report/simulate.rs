//! The report of `framewright simulate`: per wall the row of the study's results table
//! (material feeding, framing, nailing), per element its verdicts and reasons, the nailing
//! validation (planned targets against the as-built pieces), and the contacts. Everything
//! comes from the verdict relations (`rules/verdicts.dl`) and the executor's records; no
//! wall-clock figures, so the JSON is byte-identical run to run.

use crate::frame::rows::{
    ElementFraming, ElementNailing, ElementReason, RowError, WallFailedComponent, WallFeeding,
    WallStage,
};
use crate::sim::Simulation;
use crate::sim::record::NailOutcome;
use serde::Serialize;
use std::collections::BTreeMap;

/// Rounds to the micro-unit (µm, µs, µrad) and turns -0 into 0.
fn r6(x: f64) -> f64 {
    let r = (x * 1e6).round() / 1e6;
    if r == 0.0 { 0.0 } else { r }
}

#[derive(Debug, Serialize)]
pub struct SimReport {
    pub schema: &'static str,
    pub model: String,
    pub cell: String,
    /// One row per wall of the model: a wall split into panels sums its panels (statuses:
    /// Completed when every panel's is, Failed when every panel's is, else Partial).
    pub walls: Vec<WallRow>,
    /// One row per panel the cell built, the unit the cell builds (a wall that fits is one).
    pub panels: Vec<PanelRow>,
    pub elements: Vec<ElementRow>,
    pub nailing_validation: NailingValidation,
    pub contacts: Vec<ContactRow>,
    pub sim: SimFigures,
}

#[derive(Debug, Serialize)]
pub struct WallRow {
    pub wall_id: String,
    pub name: String,
    pub material_feeding: String,
    pub framing: Stage,
    pub nailing: Stage,
}

#[derive(Debug, Serialize)]
pub struct PanelRow {
    pub panel_id: String,
    pub wall_id: String,
    pub name: String,
    pub material_feeding: String,
    pub framing: Stage,
    pub nailing: Stage,
}

#[derive(Debug, Clone, Serialize)]
pub struct Stage {
    pub status: String,
    pub time_s: f64,
    /// Components at fault, comma-separated ("" when none).
    pub failed_component: String,
}

#[derive(Debug, Serialize)]
pub struct ElementRow {
    pub id: String,
    pub wall_id: String,
    /// The panel it is built in (`W1-P2`; `W1-P1` when the wall is one panel).
    pub panel_id: String,
    pub role: String,
    /// Where the gripper held it as it was placed: m along the member from its centre,
    /// positive towards the `axis_end` that `plan` prints (absent when it was not placed).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub grip_offset: Option<f64>,
    pub framing: ElementStage,
    pub nailing: ElementStage,
    /// Violations and warnings of the user's rules (`simulate --rules`) about this element.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub rule_findings: Vec<RuleFinding>,
}

#[derive(Debug, Clone, Serialize)]
pub struct RuleFinding {
    /// violation | warning
    pub kind: String,
    pub rule: String,
    pub message: String,
}

#[derive(Debug, Serialize)]
pub struct ElementStage {
    pub status: String,
    pub reasons: Vec<Reason>,
}

#[derive(Debug, Clone, Serialize)]
pub struct Reason {
    pub component: String,
    pub message: String,
}

#[derive(Debug, Serialize)]
pub struct NailingValidation {
    /// Nails driven and checked against the as-built pieces.
    pub checked: usize,
    pub planned: usize,
    /// Largest distance between a planned target and its as-built point, mm.
    pub max_error_mm: f64,
    /// Largest coordinate error relative to the planned coordinate, percent (coordinates
    /// under 10 mm are left out: a relative error means nothing there).
    pub max_error_pct: f64,
    pub all_inside_members: bool,
    pub targets: Vec<NailRow>,
}

#[derive(Debug, Serialize)]
pub struct NailRow {
    pub wall_id: String,
    pub panel_id: String,
    pub plate: String,
    pub member: String,
    pub k: i64,
    /// Planned wall coordinates u, v, w (m).
    pub planned: [f64; 3],
    /// The planned point carried by the as-built plate (m); absent when not driven.
    pub as_built: Option<[f64; 3]>,
    pub error_mm: Option<f64>,
    pub error_pct: Option<f64>,
    pub member_inside: Option<bool>,
    /// How far the nail was driven off its planned line (degrees; 0 when square); absent
    /// when not driven.
    pub lean_deg: Option<f64>,
    pub status: String,
}

#[derive(Debug, Serialize)]
pub struct ContactRow {
    pub wall_id: String,
    pub panel_id: String,
    pub element: String,
    pub op: String,
    pub t: f64,
    pub body_a: String,
    pub body_b: String,
    pub depth_mm: f64,
}

#[derive(Debug, Serialize)]
pub struct SimFigures {
    /// Simulated seconds, summed over the walls.
    pub simulated_s: f64,
    pub steps: u64,
    pub dt: f64,
    /// Walls simulated and walls read from the cache (absent without a cache).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub cache: Option<crate::cache::CacheCounts>,
}

/// One row per whole wall from its panels' rows (in order; a wall's panels are adjacent or
/// not, the first decides the wall's place); `name_of(i)` names the wall of panel row i.
fn whole_walls(panels: &[PanelRow], name_of: impl Fn(usize) -> String) -> Vec<WallRow> {
    let mut order: Vec<&str> = vec![];
    let mut rows: BTreeMap<&str, Vec<usize>> = BTreeMap::new();
    for (i, p) in panels.iter().enumerate() {
        let at = rows.entry(p.wall_id.as_str()).or_default();
        if at.is_empty() {
            order.push(&p.wall_id);
        }
        at.push(i);
    }
    order
        .into_iter()
        .map(|wall| {
            let of = &rows[wall];
            let each = |f: &dyn Fn(&PanelRow) -> &Stage| -> Stage {
                let stages: Vec<&Stage> = of.iter().map(|&i| f(&panels[i])).collect();
                combined(&stages)
            };
            let feeding: Vec<&str> = of
                .iter()
                .map(|&i| panels[i].material_feeding.as_str())
                .collect();
            WallRow {
                wall_id: wall.to_string(),
                name: name_of(of[0]),
                material_feeding: if feeding.iter().all(|f| *f == feeding[0]) {
                    feeding[0].to_string()
                } else {
                    "Failed".to_string()
                },
                framing: each(&|p| &p.framing),
                nailing: each(&|p| &p.nailing),
            }
        })
        .collect()
}

/// Panels' stages as the wall's: Completed when every one is, Failed when every one is, else
/// Partial; times summed (the cell builds the panels one after another); components at fault
/// in order of first mention.
fn combined(stages: &[&Stage]) -> Stage {
    if let [one] = stages {
        return (*one).clone();
    }
    let all = |s: &str| stages.iter().all(|x| x.status == s);
    let status = if all("Completed") {
        "Completed"
    } else if all("Failed") {
        "Failed"
    } else {
        "Partial"
    };
    let mut failed: Vec<&str> = vec![];
    for s in stages {
        for c in s.failed_component.split(", ").filter(|c| !c.is_empty()) {
            if !failed.contains(&c) {
                failed.push(c);
            }
        }
    }
    Stage {
        status: status.to_string(),
        time_s: r6(stages.iter().map(|s| s.time_s).sum()),
        failed_component: failed.join(", "),
    }
}

impl SimReport {
    /// The report of `sim`; an error when a verdict tuple does not match its relation's
    /// declaration.
    pub fn new(sim: &Simulation, dt: f64) -> Result<SimReport, RowError> {
        let r = &sim.reasoned;
        let mut reasons: BTreeMap<(String, String), Vec<Reason>> = BTreeMap::new();
        for t in r.rows::<ElementReason>()? {
            reasons
                .entry((t.p.to_string(), t.stage.to_string()))
                .or_default()
                .push(Reason {
                    component: t.component.to_string(),
                    message: t.message.to_string(),
                });
        }
        let status = |of: &str, status: &str| (of.to_string(), status.to_string());
        let framing: BTreeMap<String, String> = r
            .rows::<ElementFraming>()?
            .into_iter()
            .map(|t| status(t.p, t.status))
            .collect();
        let nailing: BTreeMap<String, String> = r
            .rows::<ElementNailing>()?
            .into_iter()
            .map(|t| status(t.p, t.status))
            .collect();
        let mut components: BTreeMap<(String, String), Vec<String>> = BTreeMap::new();
        for t in r.rows::<WallFailedComponent>()? {
            components
                .entry((t.w.to_string(), t.stage.to_string()))
                .or_default()
                .push(t.component.to_string());
        }
        let stages: BTreeMap<(String, String), (String, f64)> = r
            .rows::<WallStage>()?
            .into_iter()
            .map(|t| {
                let key = (t.w.to_string(), t.stage.to_string());
                (key, (t.status.to_string(), t.time))
            })
            .collect();
        let feeding: BTreeMap<String, String> = r
            .rows::<WallFeeding>()?
            .into_iter()
            .map(|t| status(t.w, t.status))
            .collect();

        // Records and relations name a wall by its key piece; the report by the whole wall's
        // id and the panel's.
        let walls_by_key: BTreeMap<&str, &crate::frame::plan::Wall> =
            sim.plan.walls.iter().map(|w| (w.key.as_str(), w)).collect();
        let wall_id = |key: &str| {
            walls_by_key
                .get(key)
                .map_or(key, |w| w.whole_id())
                .to_string()
        };
        let panel_id = |key: &str| {
            walls_by_key
                .get(key)
                .map_or_else(|| key.to_string(), |w| w.panel_id())
        };
        let stage = |wall: &str, which: &str| {
            let key = (wall.to_string(), which.to_string());
            let (status, time) = stages.get(&key).cloned().unwrap_or_default();
            let failed = components
                .get(&key)
                .map(|c| c.join(", "))
                .unwrap_or_default();
            Stage {
                status,
                time_s: r6(time),
                failed_component: failed,
            }
        };
        let panels: Vec<PanelRow> = sim
            .records
            .iter()
            .map(|rec| PanelRow {
                panel_id: panel_id(&rec.wall),
                wall_id: wall_id(&rec.wall),
                name: walls_by_key
                    .get(rec.wall.as_str())
                    .map_or("", |w| w.name.as_str())
                    .to_string(),
                material_feeding: feeding.get(&rec.wall).cloned().unwrap_or_default(),
                framing: stage(&rec.wall, "framing"),
                nailing: stage(&rec.wall, "nailing"),
            })
            .collect();
        let whole_name = |key: &str| {
            walls_by_key.get(key).map_or_else(String::new, |w| {
                w.panel
                    .as_ref()
                    .map_or_else(|| w.name.clone(), |p| p.wall_name.clone())
            })
        };
        let walls = whole_walls(&panels, |i| whole_name(&sim.records[i].wall));

        let mut elements = Vec::new();
        for rec in &sim.records {
            let wall = sim.scene.walls.iter().find(|w| w.id == rec.wall);
            let grips: BTreeMap<&str, f64> =
                rec.grips.iter().map(|(p, g)| (p.as_str(), *g)).collect();
            for id in wall.map(|w| w.pieces.as_slice()).unwrap_or_default() {
                let stage = |which: &str, statuses: &BTreeMap<String, String>| ElementStage {
                    status: statuses.get(id).cloned().unwrap_or_default(),
                    reasons: reasons
                        .get(&(id.clone(), which.to_string()))
                        .cloned()
                        .unwrap_or_default(),
                };
                elements.push(ElementRow {
                    id: id.clone(),
                    wall_id: wall_id(&rec.wall),
                    panel_id: panel_id(&rec.wall),
                    role: sim.plan.roles.get(id).cloned().unwrap_or_default(),
                    grip_offset: grips.get(id.as_str()).map(|g| r6(*g)),
                    framing: stage("framing", &framing),
                    nailing: stage("nailing", &nailing),
                    rule_findings: Vec::new(),
                });
            }
        }

        let mut targets = Vec::new();
        let mut contacts = Vec::new();
        for rec in &sim.records {
            for n in &rec.nails {
                let row = match &n.outcome {
                    NailOutcome::Fired {
                        as_built,
                        position_error,
                        member_inside,
                        lean,
                        ..
                    } => NailRow {
                        wall_id: wall_id(&rec.wall),
                        panel_id: panel_id(&rec.wall),
                        plate: n.plate.clone(),
                        member: n.member.clone(),
                        k: n.k,
                        planned: n.planned.map(r6),
                        as_built: Some(as_built.map(r6)),
                        error_mm: Some(r6(position_error * 1000.0)),
                        error_pct: Some(r6(relative_error(&n.planned, as_built))),
                        member_inside: Some(*member_inside),
                        lean_deg: Some(r6(lean.to_degrees())),
                        status: "fired".into(),
                    },
                    NailOutcome::Skipped { kind, .. } => NailRow {
                        wall_id: wall_id(&rec.wall),
                        panel_id: panel_id(&rec.wall),
                        plate: n.plate.clone(),
                        member: n.member.clone(),
                        k: n.k,
                        planned: n.planned.map(r6),
                        as_built: None,
                        error_mm: None,
                        error_pct: None,
                        member_inside: None,
                        lean_deg: None,
                        status: format!("skipped: {kind}"),
                    },
                };
                targets.push(row);
            }
            for c in &rec.contacts {
                contacts.push(ContactRow {
                    wall_id: wall_id(&rec.wall),
                    panel_id: panel_id(&rec.wall),
                    element: c.piece.clone(),
                    op: c.op.to_string(),
                    t: r6(c.t),
                    body_a: c.body_a.clone(),
                    body_b: c.body_b.clone(),
                    depth_mm: r6(c.depth * 1000.0),
                });
            }
        }
        let fired: Vec<&NailRow> = targets.iter().filter(|t| t.error_mm.is_some()).collect();
        let nailing_validation = NailingValidation {
            checked: fired.len(),
            planned: targets.len(),
            max_error_mm: fired.iter().filter_map(|t| t.error_mm).fold(0.0, f64::max),
            max_error_pct: fired.iter().filter_map(|t| t.error_pct).fold(0.0, f64::max),
            all_inside_members: fired.iter().all(|t| t.member_inside == Some(true)),
            targets,
        };
        Ok(SimReport {
            schema: "framewright.simulate/1",
            model: sim.scene.model.clone(),
            cell: sim.scene.cell.clone(),
            walls,
            panels,
            elements,
            nailing_validation,
            contacts,
            sim: SimFigures {
                simulated_s: r6(sim.records.iter().map(|r| r.nailing_end).sum()),
                steps: sim.records.iter().map(|r| r.steps).sum(),
                dt: r6(dt),
                cache: None,
            },
        })
    }

    /// Adds the user rules' findings to the elements they are about.
    pub fn add_findings(&mut self, findings: &crate::user_rules::Findings) {
        for e in &mut self.elements {
            e.rule_findings = findings
                .about(&e.id)
                .map(|(kind, f)| RuleFinding {
                    kind: kind.to_string(),
                    rule: f.rule.clone(),
                    message: f.message.clone(),
                })
                .collect();
        }
    }

    /// The JSON document as a string (what `write_json` writes).
    pub fn to_json(&self) -> String {
        let mut out = Vec::new();
        self.write_json(&mut out)
            .expect("writing to memory does not fail");
        String::from_utf8(out).expect("serde_json writes UTF-8")
    }

    pub fn write_json(&self, out: &mut dyn std::io::Write) -> std::io::Result<()> {
        serde_json::to_writer_pretty(&mut *out, self)?;
        writeln!(out)
    }
}

/// The largest coordinate error relative to the planned coordinate, percent, over the
/// coordinates at least 10 mm from zero.
fn relative_error(planned: &[f64; 3], built: &[f64; 3]) -> f64 {
    (0..3)
        .filter(|&i| planned[i].abs() >= 0.01)
        .map(|i| 100.0 * (built[i] - planned[i]).abs() / planned[i].abs())
        .fold(0.0, f64::max)
}
