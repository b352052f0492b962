//! ifc (being built).
