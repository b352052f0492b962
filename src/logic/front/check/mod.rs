//! Semantic checks: relations, arities, types, groundedness (which also fixes
//! each rule's evaluation order) and stratification of negation/aggregation.

mod checker;
mod desugar;
mod ground;
mod inline;
mod load;
mod pipeline;
mod program;
mod strata;
mod types;
mod walk;
mod witness;

pub use load::Loader;
pub use program::{FunctorSig, Program, Stratum};
pub use types::builtin_sig;
pub use walk::{expr_free_vars, expr_vars, lit_exprs_mut, walk_expr};

#[cfg(test)]
mod slice_tests;
