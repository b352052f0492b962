//! logic (being built).
