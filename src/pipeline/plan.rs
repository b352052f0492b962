//! `plan`'s run: the model's and the cell's facts reasoned with the walls placed (through the
//! plan cache when one is given and the rules are the compiled built-in ones: each part of the
//! model stored under exactly the facts it read), then the plan built.

use crate::cache::{Cache, CacheCounts, reason_plan_cached_with};
use crate::cell::Cell;
use crate::frame::plan::Plan;
use crate::frame::{Ask, Facts, FrameError, Reasoned, RuleEngine, RuleLimits};
use crate::ifc::Model;

/// A planned model.
pub struct Planned {
    /// The relations the plan was built from (`Plan::RELATIONS`).
    pub reasoned: Reasoned,
    pub plan: Plan,
    /// What the plan cache held and computed; None when no cache was used.
    pub cache: Option<CacheCounts>,
}

/// Plans `model` in `cell` from their `facts` (without placement facts: the search runs
/// here). A cache serves the compiled built-in rules only; other engines reason afresh.
pub fn plan(
    model: &Model,
    cell: &Cell,
    facts: Facts,
    engine: &RuleEngine,
    limits: RuleLimits,
    cache: Option<&Cache>,
) -> Result<Planned, FrameError> {
    match cache.filter(|_| matches!(engine, RuleEngine::Compiled)) {
        Some(cache) => {
            // A first run stores its entries while the plan is built.
            let (reasoned, counts, plan) =
                reason_plan_cached_with(facts, cell, cache, &limits, |relations| {
                    Plan::from_relations(model, relations)
                })?;
            Ok(Planned {
                reasoned,
                plan: plan?,
                cache: Some(counts),
            })
        }
        None => {
            let reasoned = Ask::new(engine)
                .within(limits)
                .only(Plan::RELATIONS)
                .placed(facts, cell)?;
            let plan = Plan::from_reasoned(model, &reasoned)?;
            Ok(Planned {
                reasoned,
                plan,
                cache: None,
            })
        }
    }
}
