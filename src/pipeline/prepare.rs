//! What every run starts from: the model and the cell reasoned once, the walls placed on
//! the assembly surface (the placement search between the passes of that one run), the
//! scene and the plan, with long walls cut into the panels the cell builds
//! (`frame::panelize`, which reasons the panelized model once more).

use crate::cell::{Cell, PanelMode};
use crate::frame::containers::{containers_of, restrict_to_containers};
use crate::frame::panelize::panelize;
use crate::frame::plan::Plan;
use crate::frame::{Ask, Facts, RuleEngine, RuleLimits, cell_facts, model_facts};
use crate::geom::ContactOptions;
use crate::ifc::Model;
use crate::sim::{SimError, SimOptions, check_options};
use crate::world::Scene;
use std::collections::BTreeSet;

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
    /// The plan of the model's own walls, each with its panels, when the plan split a wall
    /// (otherwise `plan` is that plan).
    pub model_plan: Option<Plan>,
}

/// Reasons `model` in `cell` for a run.
pub fn prepare(
    model: &Model,
    model_name: &str,
    cell: &Cell,
    engine: &RuleEngine,
    limits: &RuleLimits,
) -> Result<Prepared, SimError> {
    prepare_facts(
        model,
        model_name,
        cell,
        engine,
        limits,
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
    limits: &RuleLimits,
    facts: Facts,
    restrict: &dyn Fn(Facts) -> Facts,
) -> Result<Prepared, SimError> {
    let ask = Ask::new(engine).within(*limits);
    let (reasoned, facts) = ask.placing(facts, cell)?;
    let plan = Plan::from_reasoned(model, &reasoned)?;
    let Some(cut) = panelize(model, &plan) else {
        let scene = Scene::build(model_name, model, cell, &reasoned)?;
        return Ok(Prepared {
            facts,
            scene,
            plan,
            panelized: None,
            model_plan: None,
        });
    };
    // The panels are walls that fit: the second pass splits nothing.
    let mut whole_panels = cell.clone();
    whole_panels.panel_mode = PanelMode::Off;
    let mut facts = whole_facts(&cut.model, &whole_panels);
    facts.extend(cut.facts);
    let facts = restrict(facts);
    let (reasoned, facts) = ask.placing(facts, &whole_panels)?;
    let mut panels = Plan::from_reasoned(&cut.model, &reasoned)?;
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
        model_plan: Some(plan),
    })
}

/// A run prepared for the walls `options.walls` names. Walls named by their key pieces (as
/// `wall_of` names them) are planned from their spatial containers' facts alone (no rule
/// relates pieces of two containers, see `frame::containers`), so one wall of a big model
/// costs its storey's reasoning, not the model's; their records are those `simulate` gives.
/// `whole`, when given, are the model's and the cell's facts (`whole_facts`) the caller built
/// already.
pub fn prepare_named_walls(
    model: &Model,
    cell: &Cell,
    options: &SimOptions,
    limits: &RuleLimits,
    whole: Option<&Facts>,
) -> Result<Prepared, SimError> {
    check_options(options)?;
    let built;
    let facts = match whole {
        Some(facts) => facts,
        None => {
            built = whole_facts(model, cell);
            &built
        }
    };
    // A wall named otherwise (by name, or by no piece) keeps the whole model.
    let mut containers = BTreeSet::new();
    let mut each_in_one = !options.walls.is_empty();
    for wall in &options.walls {
        let of_wall = containers_of(facts, &BTreeSet::from([wall.as_str()]));
        each_in_one &= !of_wall.is_empty();
        containers.extend(of_wall);
    }
    // The model's facts and, when a wall is split, the panelized model's are cut alike.
    let restrict = |facts: &Facts| -> Option<Facts> {
        each_in_one.then(|| restrict_to_containers(facts, &containers))
    };
    let facts = restrict(facts).unwrap_or_else(|| facts.clone());
    let restrict = |facts: Facts| restrict(&facts).unwrap_or(facts);
    prepare_facts(
        model,
        "model",
        cell,
        &options.engine,
        limits,
        facts,
        &restrict,
    )
}
