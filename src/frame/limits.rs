//! Bounds on what the built-in rule base may derive from a model, so a hostile or absurd
//! model stops with an error naming the bound instead of filling memory: the number of
//! walls, and the tuples the compiled rule base holds after running (counted over its
//! declared relations, part by part, in all). The CLI raises both through environment
//! variables (named in the errors).

/// Environment variable with which the CLI raises the wall bound.
pub const ENV_MAX_WALLS: &str = "FRAMEWRIGHT_MAX_WALLS";
/// Environment variable with which the CLI raises the rule tuple bound.
pub const ENV_MAX_RULE_TUPLES: &str = "FRAMEWRIGHT_MAX_RULE_TUPLES";

/// Default wall bound: a 50,000-member building has about 1,600 walls.
pub const DEFAULT_MAX_WALLS: u64 = 100_000;
/// Default rule tuple bound, as the interpreter's: that building derives about 4 million
/// per pass of the rule base (measured: its largest storey 259,000).
pub const DEFAULT_MAX_RULE_TUPLES: u64 = 50_000_000;

/// The bounds in force.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct RuleLimits {
    pub max_walls: u64,
    pub max_rule_tuples: u64,
}

impl Default for RuleLimits {
    fn default() -> Self {
        RuleLimits {
            max_walls: DEFAULT_MAX_WALLS,
            max_rule_tuples: DEFAULT_MAX_RULE_TUPLES,
        }
    }
}

/// A bound that was hit or could not be read.
#[derive(Debug, thiserror::Error, PartialEq, Eq)]
pub enum LimitError {
    #[error(
        "the model holds {found} wall frames, more than the bound of {limit}; if it is meant to be this large, raise the bound with the environment variable {variable}=N"
    )]
    Walls {
        found: u64,
        limit: u64,
        variable: &'static str,
    },
    #[error(
        "the rule base derived more than {limit} tuples from the model ({found} when it stopped); if the model is meant to be this large, raise the bound with the environment variable {variable}=N"
    )]
    RuleTuples {
        found: u64,
        limit: u64,
        variable: &'static str,
    },
    #[error("{variable}={value:?} is not a whole number; give a count such as {variable}=1000000")]
    BadValue {
        variable: &'static str,
        value: String,
    },
}

impl RuleLimits {
    pub fn check_walls(&self, found: u64) -> Result<(), LimitError> {
        if found > self.max_walls {
            return Err(LimitError::Walls {
                found,
                limit: self.max_walls,
                variable: ENV_MAX_WALLS,
            });
        }
        Ok(())
    }

    pub fn check_tuples(&self, found: u64) -> Result<(), LimitError> {
        if found > self.max_rule_tuples {
            return Err(LimitError::RuleTuples {
                found,
                limit: self.max_rule_tuples,
                variable: ENV_MAX_RULE_TUPLES,
            });
        }
        Ok(())
    }
}
