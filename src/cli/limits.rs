//! The bounds a run works within, read from the environment here, at the edge: the library
//! takes them as values (`ReadOptions`, `RuleLimits`, `SimOptions::max_seconds_per_wall`,
//! the report's byte bound) and reads no environment variable itself.

use super::Failure;
use framewright::frame::RuleLimits;
use framewright::frame::limits::{
    DEFAULT_MAX_RULE_TUPLES, DEFAULT_MAX_WALLS, ENV_MAX_RULE_TUPLES, ENV_MAX_WALLS, LimitError,
};
use framewright::ifc::{IfcError, Model};
use framewright::report::html::{DEFAULT_MAX_REPORT_BYTES, ENV_MAX_REPORT_BYTES};
use framewright::sim::{DEFAULT_MAX_SIM_SECONDS_PER_WALL, ENV_MAX_SIM_SECONDS_PER_WALL};
use framewright::step::{
    ENV_MAX_BYTES, ENV_MAX_DEPTH, ENV_MAX_INSTANCES, ENV_MAX_STRING_BYTES, ReadOptions, StepError,
    StepErrorKind,
};
use std::path::Path;

/// A whole number from the environment variable `variable`, None when it is unset; `bad` makes
/// the error for a value that is not one.
fn whole<E>(variable: &'static str, bad: impl FnOnce(String) -> E) -> Result<Option<u64>, E> {
    match std::env::var(variable) {
        Ok(value) => match value.trim().parse::<u64>() {
            Ok(n) => Ok(Some(n)),
            Err(_) => Err(bad(value)),
        },
        Err(_) => Ok(None),
    }
}

/// The rule base's bounds: the defaults, or what `FRAMEWRIGHT_MAX_WALLS` and
/// `FRAMEWRIGHT_MAX_RULE_TUPLES` set.
pub fn rule_limits() -> Result<RuleLimits, Failure> {
    let var = |variable: &'static str, default: u64| -> Result<u64, LimitError> {
        Ok(whole(variable, |value| LimitError::BadValue { variable, value })?.unwrap_or(default))
    };
    Ok(RuleLimits {
        max_walls: var(ENV_MAX_WALLS, DEFAULT_MAX_WALLS)?,
        max_rule_tuples: var(ENV_MAX_RULE_TUPLES, DEFAULT_MAX_RULE_TUPLES)?,
    })
}

/// The IFC reader's bounds: the defaults, or what the `FRAMEWRIGHT_MAX_IFC_*` variables set.
pub fn read_options() -> Result<ReadOptions, StepError> {
    let var = |variable: &'static str| {
        whole(variable, |value| {
            StepError::new(StepErrorKind::BadLimit { variable, value })
        })
    };
    let d = ReadOptions::default();
    let size = |v: Option<u64>, default: usize| v.map_or(default, |v| v as usize);
    Ok(ReadOptions {
        max_bytes: var(ENV_MAX_BYTES)?.unwrap_or(d.max_bytes),
        max_depth: size(var(ENV_MAX_DEPTH)?, d.max_depth),
        max_instances: size(var(ENV_MAX_INSTANCES)?, d.max_instances),
        max_string_bytes: size(var(ENV_MAX_STRING_BYTES)?, d.max_string_bytes),
    })
}

/// Opens a model within the reader's bounds (`read_options`).
pub fn open_model(path: &Path) -> Result<Model, IfcError> {
    let options = read_options().map_err(|e| IfcError {
        path: path.to_path_buf(),
        kind: e.into(),
    })?;
    Model::open_with(path, &options)
}

/// The bound on simulated time per wall (s): `FRAMEWRIGHT_MAX_SIM_SECONDS_PER_WALL` or the
/// default; a value that is not a number of seconds above 0 is refused naming the variable.
pub fn max_sim_seconds_per_wall() -> Result<f64, Failure> {
    match std::env::var(ENV_MAX_SIM_SECONDS_PER_WALL) {
        Err(_) => Ok(DEFAULT_MAX_SIM_SECONDS_PER_WALL),
        Ok(value) => match value.trim().parse::<f64>() {
            Ok(v) if v.is_finite() && v > 0.0 => Ok(v),
            _ => Err(Failure::bad_input(format!(
                "{ENV_MAX_SIM_SECONDS_PER_WALL}={value:?} is not a number of seconds above 0; set it to one (e.g. {ENV_MAX_SIM_SECONDS_PER_WALL}=36000) or unset it for the default {DEFAULT_MAX_SIM_SECONDS_PER_WALL} s"
            ))),
        },
    }
}

/// The bound on a report's size in bytes: `FRAMEWRIGHT_MAX_REPORT_BYTES` or the default.
pub fn max_report_bytes() -> Result<u64, Failure> {
    let bad = |v: String| {
        Failure::bad_input(format!(
            "{ENV_MAX_REPORT_BYTES}={v:?} is not a whole number of bytes"
        ))
    };
    Ok(whole(ENV_MAX_REPORT_BYTES, bad)?.unwrap_or(DEFAULT_MAX_REPORT_BYTES))
}

/// `SimOptions`' defaults within the environment's bound on simulated time per wall.
pub fn sim_defaults() -> Result<framewright::sim::SimOptions, Failure> {
    Ok(framewright::sim::SimOptions {
        max_seconds_per_wall: max_sim_seconds_per_wall()?,
        ..framewright::sim::SimOptions::default()
    })
}
