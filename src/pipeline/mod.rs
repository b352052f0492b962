//! The stages wired once. A run loads nothing itself: the CLI opens the model and the cell and
//! builds the options and bounds; `prepare` reasons the model once (the placement search
//! between the passes of that run), plans and builds the scene; each wall is one job,
//! simulated or taken from the one cache under one key; the verdicts are reasoned once over
//! the prepared facts and every record. Commands differ only in what they read of the result.

mod plan;
mod prepare;
mod run;

pub use plan::{Planned, plan};
pub use prepare::{Prepared, prepare, prepare_facts, prepare_named_walls, whole_facts};
pub use run::{FromCache, Progress, Run, simulate};
