//! What every run starts from: the model and the cell reasoned, the walls placed on the
//! assembly surface, the scene and the plan, with long walls cut into the panels the cell
//! builds (`frame::panelize`).

use super::SimError;
use crate::cell::{Cell, PanelMode};
use crate::frame::panelize::panelize;
use crate::frame::placement::add_placement_facts;
use crate::frame::plan::Plan;
use crate::frame::{Facts, RuleEngine, cell_facts, model_facts, reason};
use crate::geom::ContactOptions;
use crate::ifc::Model;
use crate::world::Scene;

/// A model and cell reasoned for a run.
pub struct Prepared {
    /// The facts reasoned: the model's (cut into panels when a wall was split), the cell's and
    /// the placement's. A run's verdicts are reasoned over these and its records' facts.
    pub facts: Facts,
    pub scene: Scene,
    /// One wall per panel the cell builds (a wall that fits is one).
    pub plan: Plan,
    /// The model cut into panels, when the plan split a wall: the model every stage after
    /// the split ran on (cut plates and added studs are its pieces).
    pub panelized: Option<Model>,
}

/// Reasons `model` in `cell` for a run.
pub fn prepare(
    model: &Model,
    model_name: &str,
    cell: &Cell,
    engine: &RuleEngine,
) -> Result<Prepared, SimError> {
    prepare_facts(
        model,
        model_name,
        cell,
        engine,
        whole_facts(model, cell),
        &|f| f,
    )
}

/// The model's and the cell's facts.
pub fn whole_facts(model: &Model, cell: &Cell) -> Facts {
    let mut facts = model_facts(model, &ContactOptions::default());
    facts.extend(cell_facts(cell));
    facts
}

/// `prepare` from the model's and the cell's `facts`, possibly cut down by `restrict` (which
/// cuts the panelized model's facts the same way).
pub fn prepare_facts(
    model: &Model,
    model_name: &str,
    cell: &Cell,
    engine: &RuleEngine,
    mut facts: Facts,
    restrict: &dyn Fn(Facts) -> Facts,
) -> Result<Prepared, SimError> {
    add_placement_facts(&mut facts, cell, engine)?;
    let reasoned = reason(&facts, engine, false)?;
    let plan = Plan::from_reasoned(model, &reasoned);
    let Some(cut) = panelize(model, &plan) else {
        let scene = Scene::build(model_name, model, cell, &reasoned)?;
        return Ok(Prepared {
            facts,
            scene,
            plan,
            panelized: None,
        });
    };
    // The panels are walls that fit: the second pass splits nothing.
    let mut whole_panels = cell.clone();
    whole_panels.panel_mode = PanelMode::Off;
    let mut facts = whole_facts(&cut.model, &whole_panels);
    facts.extend(cut.facts);
    let mut facts = restrict(facts);
    add_placement_facts(&mut facts, &whole_panels, engine)?;
    let reasoned = reason(&facts, engine, false)?;
    let mut panels = Plan::from_reasoned(&cut.model, &reasoned);
    panels.name_after_panels(&plan);
    // What the split said about the whole walls (limits dropped, panels over a limit).
    let mut warnings = plan.panel_warnings();
    warnings.append(&mut panels.warnings);
    panels.warnings = warnings;
    let scene = Scene::build(model_name, &cut.model, cell, &reasoned)?;
    Ok(Prepared {
        facts,
        scene,
        plan: panels,
        panelized: Some(cut.model),
    })
}
