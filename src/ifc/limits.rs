//! Sizes beyond which geometry is taken as corrupt rather than as lumber. A
//! piece outside them is skipped with a warning naming its entity, so nothing
//! downstream (contacts, rules, the simulated world) sees kilometre-long or
//! non-finite boxes whose cost would grow with their coordinates.

/// Longest piece accepted, in metres: sawn and engineered lumber stays far below.
pub const MAX_PIECE_LENGTH_M: f64 = 100.0;

/// Farthest a piece's centre may be from the model origin, in metres.
pub const MAX_DISTANCE_FROM_ORIGIN_M: f64 = 10_000.0;

/// Largest scale factor of an IfcCartesianTransformationOperator.
pub const MAX_OPERATOR_SCALE: f64 = 1_000.0;
