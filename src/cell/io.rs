//! `[io]` of a cell file: the controller signals a robot program drives and waits on (the
//! gripper's jaws, the nailer's trigger, the touch sensor). ABB controllers name their
//! signals, KUKA controllers number them; a key holds either, and the program writer of each
//! language takes the kind it needs (`framewright program`).

use serde::Deserialize;

/// A digital signal: a RAPID signal name or a KRL `$OUT`/`$IN` number.
#[derive(Debug, Clone, PartialEq, Eq, Deserialize, serde::Serialize)]
#[serde(untagged)]
pub enum Signal {
    Name(String),
    Number(i64),
}

/// The signals of a cell; a key left out takes the writer's default (see `docs/PROGRAMS.md`).
#[derive(Debug, Clone, Default, PartialEq, Eq, Deserialize, serde::Serialize)]
#[serde(deny_unknown_fields)]
pub struct Io {
    /// Output that closes the grippers' jaws.
    pub gripper_close: Option<Signal>,
    /// Output that opens them.
    pub gripper_open: Option<Signal>,
    /// Output that fires the nailer.
    pub nailer_fire: Option<Signal>,
    /// Output that runs the nailer out on its slide (a tool with `[nailer] slide`).
    pub nailer_slide: Option<Signal>,
    /// Input the touch sensor sets while a piece rests against it.
    pub part_present: Option<Signal>,
}

/// The longest RAPID identifier.
pub const RAPID_NAME_MAX: usize = 32;
/// The highest `$OUT`/`$IN` index of a KUKA KR C4 controller.
pub const KRL_SIGNAL_MAX: i64 = 4096;

impl Io {
    /// The keys with their signals, in file order.
    pub fn signals(&self) -> [(&'static str, Option<&Signal>); 5] {
        [
            ("gripper_close", self.gripper_close.as_ref()),
            ("gripper_open", self.gripper_open.as_ref()),
            ("nailer_fire", self.nailer_fire.as_ref()),
            ("nailer_slide", self.nailer_slide.as_ref()),
            ("part_present", self.part_present.as_ref()),
        ]
    }

    /// Every name a RAPID identifier (a letter, then letters, digits and `_`, at most 32
    /// characters) and every number a signal index 1..=4096. Err: the key and what is wrong.
    pub(super) fn check(&self) -> Result<(), (&'static str, String)> {
        for (key, signal) in self.signals() {
            match signal {
                Some(Signal::Name(name)) if !is_rapid_name(name) => {
                    return Err((
                        key,
                        format!(
                            "expected a RAPID signal name (a letter, then letters, digits or _, at most {RAPID_NAME_MAX} characters) or a KRL signal number, got {name:?}"
                        ),
                    ));
                }
                Some(Signal::Number(n)) if !(1..=KRL_SIGNAL_MAX).contains(n) => {
                    return Err((
                        key,
                        format!(
                            "expected a KRL signal number from 1 to {KRL_SIGNAL_MAX} (or a RAPID signal name), got {n}"
                        ),
                    ));
                }
                _ => {}
            }
        }
        Ok(())
    }
}

/// Whether `name` is a RAPID identifier.
pub fn is_rapid_name(name: &str) -> bool {
    let mut chars = name.chars();
    chars.next().is_some_and(|c| c.is_ascii_alphabetic())
        && chars.all(|c| c.is_ascii_alphanumeric() || c == '_')
        && name.len() <= RAPID_NAME_MAX
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_and_numbers_are_checked() {
        let io = |s: Signal| Io {
            nailer_fire: Some(s),
            ..Io::default()
        };
        assert!(io(Signal::Name("doNail_1".into())).check().is_ok());
        assert!(io(Signal::Number(7)).check().is_ok());
        for bad in [
            Signal::Name("1do".into()),
            Signal::Name("do nail".into()),
            Signal::Name("x".repeat(33)),
            Signal::Number(0),
            Signal::Number(5000),
        ] {
            let err = io(bad).check().expect_err("refused");
            assert_eq!(err.0, "nailer_fire");
        }
    }
}
