//! Explanations: why an element has its verdicts (the answer first, with the numbers of
//! where, then the derivation trees down to IFC entities, cell keys and rule lines), and why a
//! tuple does not hold.
//!
//! - `why`: the element resolved, the rule base (with user rules) run with provenance;
//! - `report`: what an explanation holds; `answer`: the answer built from the verdicts;
//! - `location`: where a cause happened (poses, touches, releases), from the simulation facts;
//! - `remedy`: what would make a failed place pass, checked;
//! - `render`: the text; `words`: facts, origins and numbers as the text prints them.

pub mod answer;
pub mod location;
pub mod remedy;
pub mod render;
pub mod report;
pub mod why;
mod words;
