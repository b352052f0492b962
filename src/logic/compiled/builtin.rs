//! The compiled built-in rule base with typed access: its inputs are filled from `Value`
//! tuples as the generated wrapper does, but only the relations a caller names are turned
//! back into `Value` tuples (the wrapper converts and sorts all of them, most of which
//! `plan` never reads), and the program's own tables are dropped right after.

use super::builtin_rules::Prog;
use super::{Relations, rt};
use crate::logic::value::{Column, F64, OBox, Sym, Value, Vec3};

/// What one run gives: the named relations (each sorted, no duplicates) and how many tuples
/// the program's declared relations held in all.
pub struct SelectedRun {
    pub relations: Relations,
    pub tuples: u64,
}

macro_rules! inputs {
    ($($name:literal => $field:ident ($($i:tt : $t:ty),*);)*) => {
        /// Every input relation this runner fills.
        pub const INPUTS: &[&str] = &[$($name),*];
        fn fill_inputs(p: &mut Prog, edb: &Relations) {
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
}

macro_rules! outputs {
    ($($name:literal => $field:ident ($($i:tt),*);)*) => {
        /// Every relation this runner can read back.
        pub const OUTPUTS: &[&str] = &[$($name),*];
        fn read_outputs(p: &Prog, wanted: &[&str], out: &mut Relations) {
            $(
                if wanted.contains(&$name) {
                    let mut v: Vec<Vec<Value>> = p
                        .$field
                        .iter()
                        .map(|t| vec![$(t.$i.clone().into_value()),*])
                        .collect();
                    v.sort();
                    v.dedup();
                    out.insert($name.to_string(), v);
                }
            )*
        }
    };
}

inputs! {
    "piece" => r_piece(0: Sym, 1: i64, 2: Sym, 3: Sym);
    "piece_box" => r_piece_box(0: Sym, 1: OBox);
    "piece_size" => r_piece_size(0: Sym, 1: F64, 2: F64, 3: F64);
    "piece_index" => r_piece_index(0: Sym, 1: i64);
    "piece_type" => r_piece_type(0: Sym, 1: Sym, 2: Sym);
    "piece_group" => r_piece_group(0: Sym, 1: Sym, 2: Sym, 3: Sym);
    "piece_container" => r_piece_container(0: Sym, 1: Sym);
    "piece_material" => r_piece_material(0: Sym, 1: Sym, 2: F64);
    "contact" => r_contact(0: Sym, 1: Sym, 2: Sym, 3: Sym, 4: Sym, 5: F64, 6: Vec3, 7: Vec3);
    "cell_value" => r_cell_value(0: Sym, 1: F64);
    "cell_choice" => r_cell_choice(0: Sym, 1: Sym);
    "placement_candidate" => r_placement_candidate(0: Sym, 1: F64);
    "placement_reaches" => r_placement_reaches(0: Sym, 1: F64, 2: F64);
    "placement_nail_reaches" => r_placement_nail_reaches(0: Sym, 1: Sym, 2: F64, 3: F64, 4: F64, 5: F64, 6: F64);
}

// What `plan` (frame::plan::Plan::RELATIONS), the placement search and the plan cache's
// storey check (`storey_reach`) read.
outputs! {
    "wall" => r_wall(0);
    "wall_of" => r_wall_of(0, 1);
    "role" => r_role(0, 1);
    "piece_material" => r_piece_material(0, 1, 2);
    "piece_size" => r_piece_size(0, 1, 2, 3);
    "wall_group" => r_wall_group(0, 1, 2, 3);
    "wall_frame" => r_wall_frame(0, 1);
    "wall_size" => r_wall_size(0, 1, 2, 3);
    "assembly_rank" => r_assembly_rank(0, 1);
    "precedence" => r_precedence(0, 1, 2);
    "nailing_target" => r_nailing_target(0, 1, 2, 3, 4, 5, 6, 7);
    "framing_target" => r_framing_target(0, 1);
    "frame_warning" => r_frame_warning(0, 1);
    "lumber" => r_lumber(0);
    "across" => r_across(0, 1);
    "coplanar" => r_coplanar(0, 1);
    "storey_reach" => r_storey_reach(0, 1, 2, 3);
    "placement_target_at_zero" => r_placement_target_at_zero(0, 1);
    "placement_nail_at_zero" => r_placement_nail_at_zero(0, 1, 2, 3, 4, 5, 6);
}

/// Whether `run_selected` takes these inputs and can give these relations.
pub fn handles(edb: &Relations, wanted: &[&str]) -> bool {
    edb.keys().all(|k| INPUTS.contains(&k.as_str())) && wanted.iter().all(|w| OUTPUTS.contains(w))
}

/// Runs the built-in rule base on `edb` and returns the relations named in `wanted` (callers
/// check `handles` first; others are left out).
pub fn run_selected(edb: &Relations, wanted: &[&str]) -> Result<SelectedRun, String> {
    rt::reset_error();
    let mut p = Prog::default();
    fill_inputs(&mut p, edb);
    p.run();
    if let Some(e) = rt::take_error() {
        return Err(e);
    }
    let tuples = declared_tuples(&p.relation_sizes_summary());
    let mut relations = Relations::new();
    read_outputs(&p, wanted, &mut relations);
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
}
