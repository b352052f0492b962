//! cell (being built).
