//! synth (being built).
