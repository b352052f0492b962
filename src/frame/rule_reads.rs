//! The relations of the built-in rule base that fixed readers take. `build.rs` includes
//! this file too: it compiles, beside the whole rule base, a copy cut down to the rules
//! these relations depend on (`builtin_plan`), which `frame::builtin` runs whenever a
//! caller wants nothing outside it; and it cuts the rules the placement search's facts reach.

/// What `Plan::from_reasoned` reads.
pub const PLAN: &[&str] = &[
    "wall",
    "wall_of",
    "role",
    "piece_material",
    "wall_group",
    "wall_frame",
    "wall_size",
    "assembly_rank",
    "precedence",
    "nailing_target",
    "framing_target",
    "frame_warning",
    "lumber",
    "across",
    "coplanar",
    "panel_limit",
    "wall_split",
    "local_box",
    "cut_at_break",
    "panel_cap_lap",
    "cut_lapped",
    "break_allowed",
    "break_added",
    "break_wanted",
    "break_blocked",
];

/// A storey's reach (the plan cache checks its entries against it).
pub const STOREY_REACH: &str = "storey_reach";

/// What the placement search reads of a first pass.
pub const PLACEMENT_FIRST_PASS: &[&str] = &[
    "piece_size",
    "wall_of",
    "placement_target_at_zero",
    "placement_nail_at_zero",
];

/// The inputs the placement search fills.
pub const PLACEMENT_INPUTS: &[&str] = &[
    "placement_candidate",
    "placement_reaches",
    "placement_nail_reaches",
];
