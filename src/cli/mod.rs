//! Subcommands. Every `run` returns `CmdResult`; a `Failure` carries the
//! message shown to the user and the exit code (2 = bad input).

pub mod annotate;
pub mod bcf;
pub mod cache;
pub mod check;
pub mod compare;
pub mod diff;
pub mod inspect;
pub mod limits;
pub mod plan;
pub mod program;
pub mod robot;
pub mod rules;
pub mod simulate;
pub mod synth;
pub mod watch;
pub mod why;
pub mod world;

use std::io::Write;
use std::process::ExitCode;

/// Exit code for errors caused by the user's input (model, rules, cell, flags).
pub const EXIT_BAD_INPUT: u8 = 2;

#[derive(Debug)]
pub struct Failure {
    pub code: u8,
    pub message: String,
}

pub type CmdResult = Result<ExitCode, Failure>;

impl Failure {
    pub fn bad_input(message: impl Into<String>) -> Self {
        Failure {
            code: EXIT_BAD_INPUT,
            message: message.into(),
        }
    }

    /// Print the message (with its causes) to stderr and return the exit code.
    pub fn report(self) -> ExitCode {
        let _ = writeln!(std::io::stderr(), "error: {}", self.message);
        ExitCode::from(self.code)
    }
}

/// Any library error becomes a bad-input failure whose message lists its causes.
impl<E: std::error::Error> From<E> for Failure {
    fn from(err: E) -> Self {
        let mut message = err.to_string();
        let mut source = err.source();
        while let Some(cause) = source {
            message.push_str(&format!("\n  caused by: {cause}"));
            source = cause.source();
        }
        Failure::bad_input(message)
    }
}

/// Write `text` to stdout; a closed pipe (e.g. `| head`) is not an error.
pub fn print_stdout(text: &str) -> CmdResult {
    write_stdout(|out| out.write_all(text.as_bytes()))
}

/// Run a writer against buffered stdout; a closed pipe is not an error.
pub fn write_stdout(write: impl FnOnce(&mut dyn Write) -> std::io::Result<()>) -> CmdResult {
    let mut out = std::io::BufWriter::with_capacity(1 << 16, std::io::stdout().lock());
    match write(&mut out).and_then(|_| out.flush()) {
        Ok(()) => Ok(ExitCode::SUCCESS),
        Err(e) if e.kind() == std::io::ErrorKind::BrokenPipe => Ok(ExitCode::SUCCESS),
        Err(e) => Err(Failure {
            code: 1,
            message: format!("cannot write to stdout: {e}"),
        }),
    }
}

/// Leaves a command's large results to the end of the process instead of freeing them: the
/// command returns to `main`, which exits, and the system reclaims the memory at once,
/// where freeing a 50,000-member model's relations one allocation at a time takes a tenth
/// of a second. Only for values that own memory and nothing else (no files, no buffers).
pub fn leave_to_exit<T>(value: T) {
    std::mem::forget(value);
}

/// Every output file goes through the library's one atomic writer.
pub use framewright::atomic::write_atomically;

pub use limits::{open_model, rule_limits, sim_defaults};
