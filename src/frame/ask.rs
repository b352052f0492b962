//! The one way to run the rule base: an `Ask` says which engine, within which bounds, which
//! relations the caller reads and whether provenance is kept; its methods say what it runs
//! over (the facts as they are, or with the cell's placement search placing the walls first).

use super::builtin;
use super::placement::{
    FIRST_PASS, SearchMemo, SearchOptions, placement_facts, placement_relations,
};
use super::{
    Facts, FrameError, Reasoned, RuleEngine, RuleLimits, count_run, reason_compiled_placing,
    reason_unchecked,
};
use crate::cell::{Cell, OffsetX};
use crate::logic::compiled::Relations;

/// A question to the rule base. `Ask::new(&engine)` asks for every relation within the
/// default bounds; the builder methods narrow it.
#[derive(Debug, Clone, Copy)]
pub struct Ask<'a> {
    engine: &'a RuleEngine,
    limits: RuleLimits,
    provenance: bool,
    only: Option<&'a [&'a str]>,
    search: SearchOptions,
}

impl<'a> Ask<'a> {
    pub fn new(engine: &'a RuleEngine) -> Ask<'a> {
        Ask {
            engine,
            limits: RuleLimits::default(),
            provenance: false,
            only: None,
            search: SearchOptions::default(),
        }
    }

    /// Bounds on what the run may derive (the CLI builds them from the environment).
    pub fn within(self, limits: RuleLimits) -> Ask<'a> {
        Ask { limits, ..self }
    }

    /// Keeps the interpreter that ran, with its provenance, for explanations (the compiled
    /// engine's rules then run on the interpreter).
    pub fn with_provenance(self) -> Ask<'a> {
        Ask {
            provenance: true,
            ..self
        }
    }

    /// Only these relations are read: the others may be missing from the result, and the
    /// compiled engine turns only these into `Value` tuples.
    pub fn only(self, relations: &'a [&'a str]) -> Ask<'a> {
        Ask {
            only: Some(relations),
            ..self
        }
    }

    /// How the placement search runs (`place`, `placing`, `placed`).
    pub fn search(self, search: SearchOptions) -> Ask<'a> {
        Ask { search, ..self }
    }

    /// The rule base over the facts as they are.
    pub fn over(&self, facts: &Facts) -> Result<Reasoned, FrameError> {
        count_run(self.only.is_some());
        let reasoned =
            reason_unchecked(facts, self.engine, self.provenance, self.only, &self.limits)?;
        self.limits.check_walls(reasoned.get("wall").len() as u64)?;
        Ok(reasoned)
    }

    /// Adds the placement facts when the cell places walls by search (`offset_x = "auto"`):
    /// a first pass of the rules, cut down to what the search reads, gives the pieces' poses
    /// with every wall at offset 0. Nothing to add otherwise.
    pub fn place(&self, facts: &mut Facts, cell: &Cell) -> Result<(), FrameError> {
        let OffsetX::Auto { min, max } = cell.assembly.offset_x else {
            return Ok(());
        };
        let first = Ask {
            provenance: false,
            only: Some(FIRST_PASS),
            ..*self
        }
        .over(facts)?;
        facts.extend(placement_facts(cell, &first, min, max, &self.search));
        Ok(())
    }

    /// `place`, then the rule base over the facts: the reasoned relations and the facts with
    /// the placement facts added (what a run reasons its verdicts over later).
    pub fn placing(&self, mut facts: Facts, cell: &Cell) -> Result<(Reasoned, Facts), FrameError> {
        self.place(&mut facts, cell)?;
        let reasoned = self.over(&facts)?;
        Ok((reasoned, facts))
    }

    /// What `placing` reasons, for a caller done with the facts. With the compiled rules, a
    /// cut-down question (`only`) and a cell that places walls by search, each part of the
    /// model runs the rule base once, the search between its two passes, and then only the
    /// rules the search's facts reach.
    pub fn placed(&self, facts: Facts, cell: &Cell) -> Result<Reasoned, FrameError> {
        let fused = match (self.engine, self.only, cell.assembly.offset_x) {
            (RuleEngine::Compiled, Some(only), OffsetX::Auto { min, max })
                if !self.provenance
                    && facts.tuples.keys().all(|k| builtin::INPUTS.contains(k))
                    && only.iter().all(|w| builtin::OUTPUTS.contains(w)) =>
            {
                Some((only, min, max))
            }
            _ => None,
        };
        let Some((only, min, max)) = fused else {
            return Ok(self.placing(facts, cell)?.0);
        };
        count_run(true);
        let memo = SearchMemo::default();
        let place =
            |first: &Relations| placement_relations(cell, first, (min, max), &self.search, &memo);
        let parts = facts.into_by_container();
        let relations = reason_compiled_placing(parts, Some(only), &self.limits, Some(&place))?;
        let reasoned = Reasoned {
            relations,
            engine: None,
        };
        self.limits.check_walls(reasoned.get("wall").len() as u64)?;
        Ok(reasoned)
    }
}
