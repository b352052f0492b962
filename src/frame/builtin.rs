//! The compiled built-in rule base with typed access: its inputs are filled from `Value`
//! tuples as the generated wrapper does, but only the relations a caller names are turned
//! back into `Value` tuples (the wrapper converts and sorts all of them, most of which
//! `plan` never reads), and the program's own tables are dropped right after. A caller that
//! wants only relations `plan` reads gets them from `builtin_plan`, the rule base cut down to
//! the rules those depend on (`build.rs`, `frame::rule_reads`). It lives beside the
//! framing rule base it names, not in `logic::compiled`, which is the generic engine.

use crate::logic::compiled::{
    BUILTIN_PLAN_RELATIONS, CompiledError, Relations, builtin_placed, builtin_plan,
    builtin_plan_placed, builtin_rules, rt,
};
use crate::logic::value::{Column, F64, OBox, Sym, Value, Vec3};

/// What one run gives: the named relations (each sorted, no duplicates) and how many tuples
/// the program's declared relations held in all.
pub struct SelectedRun {
    pub relations: Relations,
    pub tuples: u64,
}

macro_rules! inputs {
    (@fill $prog:path, $f:ident; $($name:literal => $field:ident ($($i:tt : $t:ty),*);)*) => {
        fn $f(p: &mut $prog, edb: &Relations) {
            $(
                if let Some(ts) = edb.get($name) {
                    p.$field = ts
                        .iter()
                        .map(|t| ($(<$t as Column>::from_value(&t[$i]),)*))
                        .collect();
                }
            )*
        }
    };
    (@names $($name:literal => $field:ident ($($i:tt : $t:ty),*);)*) => {
        /// Every input relation this runner fills.
        pub const INPUTS: &[&str] = &[$($name),*];
    };
    // Both compiled copies declare every relation, so one list serves both.
    ($($list:tt)*) => {
        inputs!(@names $($list)*);
        inputs!(@fill builtin_rules::Prog, fill_whole; $($list)*);
        inputs!(@fill builtin_plan::Prog, fill_plan; $($list)*);
    };
}

macro_rules! outputs {
    (@read $prog:path, $f:ident; $($name:literal => $field:ident ($($i:tt),*);)*) => {
        fn $f(p: &$prog, wanted: &[&str], out: &mut Relations) {
            $(
                if wanted.contains(&$name) {
                    // Sorted as typed tuples, whose order is the `Value` tuples' (each
                    // column's type orders as its `Value` variant, tuples and vectors of
                    // one length lexicographically), so no `Value` is compared. Equal
                    // tuples are identical and deduplicated: the unstable sort gives the
                    // stable order.
                    let mut typed: Vec<_> = p.$field.iter().collect();
                    typed.sort_unstable();
                    typed.dedup();
                    let v: Vec<Vec<Value>> = typed
                        .into_iter()
                        .map(|t| vec![$(t.$i.clone().into_value()),*])
                        .collect();
                    out.insert($name.to_string(), v);
                }
            )*
        }
    };
    (@names $($name:literal => $field:ident ($($i:tt),*);)*) => {
        /// Every relation this runner can read back.
        pub const OUTPUTS: &[&str] = &[$($name),*];
    };
    ($($list:tt)*) => {
        outputs!(@names $($list)*);
        outputs!(@read builtin_rules::Prog, read_whole; $($list)*);
        outputs!(@read builtin_plan::Prog, read_plan; $($list)*);
    };
}

/// The typed tables of one compiled copy of the rule base.
trait Tables: Default {
    fn fill_inputs(&mut self, edb: &Relations);
    fn read_outputs(&self, wanted: &[&str], out: &mut Relations);
    fn run_rules(&mut self);
    fn sizes_summary(&self) -> String;
    /// Runs the rules the placement facts reach (the copy's placement slice).
    fn finish_placed(&mut self);
}

macro_rules! tables {
    ($prog:path, $fill:ident, $read:ident, $placed:path) => {
        impl Tables for $prog {
            fn fill_inputs(&mut self, edb: &Relations) {
                $fill(self, edb)
            }
            fn read_outputs(&self, wanted: &[&str], out: &mut Relations) {
                $read(self, wanted, out)
            }
            fn run_rules(&mut self) {
                self.run()
            }
            fn sizes_summary(&self) -> String {
                self.relation_sizes_summary()
            }
            fn finish_placed(&mut self) {
                <$placed>::finish(self)
            }
        }
    };
}

tables!(
    builtin_rules::Prog,
    fill_whole,
    read_whole,
    builtin_placed::Prog
);
tables!(
    builtin_plan::Prog,
    fill_plan,
    read_plan,
    builtin_plan_placed::Prog
);

/// Whether `builtin_plan` derives every one of `names` as the whole rule base does.
fn in_plan_scope(names: &[&str]) -> bool {
    names.iter().all(|n| BUILTIN_PLAN_RELATIONS.contains(n))
}

// The `inputs!` (every input but the simulation's records) and `outputs!` (what `plan`
// (frame::plan::Plan::RELATIONS), the placement search and the plan cache's storey check
// (`storey_reach`) read) lists, generated from the `.decl`s by `build.rs` (`typed_tables`).
include!(concat!(env!("OUT_DIR"), "/framing_tables.rs"));

/// Whether `run_selected` takes these inputs and can give these relations.
pub fn handles(edb: &Relations, wanted: &[&str]) -> bool {
    edb.keys().all(|k| INPUTS.contains(&k.as_str())) && wanted.iter().all(|w| OUTPUTS.contains(w))
}

/// Runs the built-in rule base on `edb` and returns the relations named in `wanted` (callers
/// check `handles` first; others are left out). `tuples` counts what the copy that ran
/// derived (the cut copy derives less).
pub fn run_selected(edb: &Relations, wanted: &[&str]) -> Result<SelectedRun, CompiledError> {
    let no_search = None::<(&[&str], fn(&Relations) -> Relations)>;
    if in_plan_scope(wanted) {
        run_copy::<builtin_plan::Prog>(edb, wanted, no_search)
    } else {
        run_copy::<builtin_rules::Prog>(edb, wanted, no_search)
    }
}

/// `run_selected` for a cell that places walls by search: a first pass over `edb` without
/// placements gives the relations named in `first` to `place`, which returns the placement
/// facts; then only the rules those facts reach run again (the copy's placement slice,
/// generated by `build.rs`), over the first pass's other relations. The result equals one
/// run over `edb` and the placement facts together.
pub fn run_placed(
    edb: &Relations,
    first: &[&str],
    wanted: &[&str],
    place: impl FnOnce(&Relations) -> Relations,
) -> Result<SelectedRun, CompiledError> {
    if in_plan_scope(first) && in_plan_scope(wanted) {
        run_copy::<builtin_plan::Prog>(edb, wanted, Some((first, place)))
    } else {
        run_copy::<builtin_rules::Prog>(edb, wanted, Some((first, place)))
    }
}

/// One run of the copy `P`, with the placement search between its passes when `search`
/// names what the search reads and the search itself.
fn run_copy<P: Tables>(
    edb: &Relations,
    wanted: &[&str],
    search: Option<(&[&str], impl FnOnce(&Relations) -> Relations)>,
) -> Result<SelectedRun, CompiledError> {
    rt::reset_error();
    let mut p = P::default();
    p.fill_inputs(edb);
    p.run_rules();
    if let Some(e) = rt::take_error() {
        return Err(e);
    }
    if let Some((first, place)) = search {
        let mut first_pass = Relations::new();
        p.read_outputs(first, &mut first_pass);
        p.fill_inputs(&place(&first_pass));
        drop(first_pass);
        p.finish_placed();
        if let Some(e) = rt::take_error() {
            return Err(e);
        }
    }
    let tuples = declared_tuples(&p.sizes_summary());
    let mut relations = Relations::new();
    p.read_outputs(wanted, &mut relations);
    Ok(SelectedRun { relations, tuples })
}

/// The tuples of the program's declared relations (named `r_…` by the code generator; its
/// auxiliary relations are not counted, as the wrapper does not return them), from ascent's
/// `relation_sizes_summary` (one `name size: N` line per relation).
pub fn declared_tuples(summary: &str) -> u64 {
    summary
        .lines()
        .filter(|l| l.starts_with("r_"))
        .filter_map(|l| l.rsplit_once("size: ")?.1.trim().parse::<u64>().ok())
        .sum()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn counts_declared_relations_only() {
        let summary = "r_wall size: 3\nr_wall_of size: 40\n__agg2 size: 1000\n";
        assert_eq!(declared_tuples(summary), 43);
    }

    #[test]
    fn plan_runs_on_the_cut_copy_and_the_simulation_on_the_whole() {
        use crate::frame::rule_reads::{PLACEMENT_FIRST_PASS, PLAN, STOREY_REACH};
        assert!(in_plan_scope(PLAN) && in_plan_scope(PLACEMENT_FIRST_PASS));
        assert!(in_plan_scope(&[STOREY_REACH]));
        // What only the simulation reads is left out of the cut copy (so `plan` never pays
        // for the conveyor queue's pairs of pieces).
        for relation in ["spawn_queue", "spawn"] {
            assert!(
                !in_plan_scope(&[relation]),
                "{relation} is outside the cut copy"
            );
        }
    }

    #[test]
    fn both_copies_give_the_plan_relations_alike() {
        use crate::frame::rule_reads::PLAN;
        // TM1 at the study's placement (bottom plate's outer face 0.881 m from the base).
        let path = concat!(env!("CARGO_MANIFEST_DIR"), "/examples/models/tm1.ifc");
        let model = crate::ifc::Model::open(std::path::Path::new(path)).expect("model");
        let mut facts = crate::frame::model_facts(&model, &Default::default());
        let mut cell = crate::cell::Cell::load("study-abb").expect("cell");
        cell.assembly.offset_x = crate::cell::OffsetX::Fixed { x: 0.881 };
        facts.extend(crate::frame::cell_facts(&cell));
        let edb = facts.by_container().into_iter().next().expect("one storey");
        let none = None::<(&[&str], fn(&Relations) -> Relations)>;
        let cut = run_copy::<builtin_plan::Prog>(&edb, PLAN, none).expect("cut copy");
        let whole = run_copy::<builtin_rules::Prog>(&edb, PLAN, none).expect("whole");
        assert!(!cut.relations["framing_target"].is_empty());
        assert_eq!(cut.relations, whole.relations);
        assert!(cut.tuples < whole.tuples, "the cut copy derives less");
    }

    #[test]
    fn typed_tuples_sort_as_their_values() {
        use crate::logic::value::Column;
        // Symbols interned out of their text's order, signed zeros, NaN and vectors that
        // differ only in a later coordinate: the typed order must be the `Value` order.
        let syms: Vec<Sym> = ["m", "b", "z", "a"].iter().map(|s| Sym::from(*s)).collect();
        let floats = [0.0, -0.0, f64::NAN, -1.5, 2.0, f64::INFINITY];
        let vecs = [
            Vec3::new(1.0, 0.0, -0.0),
            Vec3::new(1.0, 0.0, 0.0),
            Vec3::new(-1.0, 2.0, 0.0),
        ];
        let mut typed: Vec<(Sym, F64, Vec3, i64)> = Vec::new();
        for (i, s) in syms.iter().enumerate() {
            for (j, x) in floats.iter().enumerate() {
                for v in &vecs {
                    typed.push((*s, F64(*x), *v, (i as i64 - j as i64) % 3));
                }
            }
        }
        typed.reverse();
        let as_values = |t: &(Sym, F64, Vec3, i64)| {
            vec![
                t.0.into_value(),
                t.1.into_value(),
                t.2.into_value(),
                t.3.into_value(),
            ]
        };
        let mut by_value: Vec<Vec<Value>> = typed.iter().map(as_values).collect();
        by_value.sort();
        typed.sort_unstable();
        assert_eq!(typed.iter().map(as_values).collect::<Vec<_>>(), by_value);
    }
}

#[cfg(test)]
mod reads_are_outputs {
    use super::OUTPUTS;
    use crate::frame::rule_reads::{PLACEMENT_FIRST_PASS, PLAN, STOREY_REACH};

    /// A relation `plan` reads but the typed runner cannot give sends every plan through the
    /// whole rule base (twice as slow on a large model, with the same answer).
    #[test]
    fn every_relation_plan_reads_is_a_typed_output() {
        for name in PLAN
            .iter()
            .chain(PLACEMENT_FIRST_PASS)
            .chain([&STOREY_REACH])
        {
            assert!(OUTPUTS.contains(name), "{name} is not in builtin::OUTPUTS");
        }
    }
}
