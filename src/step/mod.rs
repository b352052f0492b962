//! step (being built).
