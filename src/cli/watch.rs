//! `framewright watch MODEL [--cell C] [--rules F]… [--json] [--out DIR] [--report DIR]`:
//! simulates the model, then waits for saves and simulates again, redoing only the walls whose
//! inputs changed (the rest come from the cache). Each regeneration rewrites DIR/simulate.json
//! and DIR/simulate.txt atomically (and with `--report` the report folder, replaced whole) and
//! prints what changed; a file that does not read (a save in progress, a broken edit) keeps the
//! last results and says why. Ctrl-C ends it.

use super::cache::{CacheArgs, warn_if_unwritable};
use super::diff::file_name;
use super::{CmdResult, Failure};
use framewright::cache::{Cache, CacheCounts, Need};
use framewright::cell::Cell;
use framewright::diff::{ModelDiff, Version, diff};
use framewright::frame::plan::Plan;
use framewright::ifc::Model;
use framewright::pipeline::Run;
use framewright::report::html::{ReportInput, write_report};
use framewright::report::simulate::SimReport;
use framewright::user_rules::UserRules;
use notify_debouncer_full::notify::event::ModifyKind;
use notify_debouncer_full::notify::{EventKind, RecursiveMode};
use notify_debouncer_full::{DebounceEventResult, new_debouncer};
use serde::Serialize;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc;
use std::time::Duration;

#[derive(clap::Args)]
pub struct WatchArgs {
    /// The IFC model to watch.
    pub model: PathBuf,
    /// The robot cell: a built-in name (study-abb, study-kuka, study-abb-track, framing-line) or a TOML file.
    #[arg(long, default_value = "study-abb")]
    pub cell: String,
    /// Your rule file (as for simulate); repeat for more.
    #[arg(long = "rules", value_name = "FILE.dl")]
    pub rules: Vec<PathBuf>,
    /// Print one JSON event per line instead of text.
    #[arg(long)]
    pub json: bool,
    /// Where to write simulate.json and simulate.txt (default: MODEL.framewright/ beside it).
    #[arg(long, value_name = "DIR")]
    pub out: Option<PathBuf>,
    /// Also rewrite a report folder (as `simulate --report`) on every regeneration; the
    /// folder is built beside DIR and swapped in whole.
    #[arg(long, value_name = "DIR")]
    pub report: Option<PathBuf>,
    #[command(flatten)]
    pub panels: super::check::PanelsArg,
    #[command(flatten)]
    pub cache: CacheArgs,
}

/// The last good result: what the next one is compared with.
struct Good {
    model: Model,
    plan: Plan,
    report: SimReport,
}

/// One line of `--json` output.
#[derive(Serialize)]
#[serde(tag = "event", rename_all = "snake_case")]
enum Event<'a> {
    /// The first results are written.
    Ready {
        model: &'a str,
        cache: Option<CacheCounts>,
    },
    /// A save was simulated again.
    Regenerated {
        model: &'a str,
        cache: Option<CacheCounts>,
        changes: &'a ModelDiff,
    },
    /// The file does not read; the last results stay.
    Waiting {
        model: &'a str,
        error: String,
    },
    /// The model reads but cannot be simulated; the last results stay.
    Failed {
        model: &'a str,
        error: String,
    },
    Stopped,
}

struct Watch {
    args: WatchArgs,
    cell: Cell,
    cache: Option<Cache>,
    rules: Option<UserRules>,
    out: PathBuf,
    last: Option<Good>,
    /// blake3 of the bytes last looked at: a save that changes nothing is not redone.
    seen: Option<blake3::Hash>,
}

pub fn run(args: WatchArgs) -> CmdResult {
    let mut cell = Cell::load(&args.cell)?;
    cell.panel_mode = args.panels.panels;
    let mut options = super::sim_defaults()?;
    let (engine, findings_files) = super::check::rules_in_force(&None, &args.rules)?;
    options.engine = engine;
    let rules = if findings_files.is_empty() {
        None
    } else {
        Some(UserRules::load(&findings_files, &options.engine)?)
    };
    let out = args.out.clone().unwrap_or_else(|| {
        let mut name = args.model.as_os_str().to_owned();
        name.push(".framewright");
        PathBuf::from(name)
    });
    std::fs::create_dir_all(&out).map_err(|e| {
        Failure::bad_input(format!(
            "{}: cannot create the output folder: {e}",
            out.display()
        ))
    })?;
    // Editors save by renaming a new file over the old one, so the folder is watched.
    let folder = match args.model.parent() {
        Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
        _ => PathBuf::from("."),
    };
    let folder = folder.canonicalize().map_err(|e| {
        Failure::bad_input(format!(
            "{}: cannot watch this folder: {e}",
            folder.display()
        ))
    })?;
    let target = folder.join(args.model.file_name().unwrap_or_default());

    let stop = Arc::new(AtomicBool::new(false));
    let flag = stop.clone();
    ctrlc::set_handler(move || flag.store(true, Ordering::SeqCst))
        .map_err(|e| Failure::bad_input(format!("cannot handle Ctrl-C: {e}")))?;
    let (tx, rx) = mpsc::channel::<DebounceEventResult>();
    let mut debouncer = new_debouncer(Duration::from_millis(300), None, tx)
        .map_err(|e| Failure::bad_input(format!("cannot watch files: {e}")))?;
    debouncer
        .watch(&folder, RecursiveMode::NonRecursive)
        .map_err(|e| Failure::bad_input(format!("{}: cannot watch: {e}", folder.display())))?;

    let mut w = Watch {
        cache: args.cache.open(),
        args,
        cell,
        rules,
        out,
        last: None,
        seen: None,
    };
    w.regenerate();
    while !stop.load(Ordering::SeqCst) {
        match rx.recv_timeout(Duration::from_millis(200)) {
            Ok(Ok(events)) => {
                // Creations, writes and renames; not reads (reading the model is an event too).
                let saved = events.iter().any(|e| {
                    matches!(e.kind, EventKind::Create(_) | EventKind::Modify(_))
                        && !matches!(e.kind, EventKind::Modify(ModifyKind::Metadata(_)))
                        && e.paths.iter().any(|p| p == &target)
                });
                if saved {
                    w.regenerate();
                }
            }
            Ok(Err(errors)) => {
                for e in errors {
                    eprintln!("warning: watching {}: {e}", folder.display());
                }
            }
            Err(mpsc::RecvTimeoutError::Timeout) => {}
            Err(mpsc::RecvTimeoutError::Disconnected) => break,
        }
    }
    w.emit(&Event::Stopped, "stopped");
    Ok(std::process::ExitCode::SUCCESS)
}

impl Watch {
    fn emit(&self, event: &Event, text: &str) {
        let mut out = std::io::stdout().lock();
        let line = if self.args.json {
            serde_json::to_string(event).unwrap_or_default()
        } else {
            text.trim_end().to_string()
        };
        // A closed stdout only loses the messages; the outputs are still written.
        let _ = writeln!(out, "{line}");
        let _ = out.flush();
    }

    fn regenerate(&mut self) {
        let name = self.args.model.display().to_string();
        if let Ok(bytes) = std::fs::read(&self.args.model) {
            let hash = blake3::hash(&bytes);
            if self.seen == Some(hash) {
                return;
            }
            self.seen = Some(hash);
        }
        let model = match super::open_model(&self.args.model) {
            Ok(m) => m,
            Err(e) => {
                let error = e.to_string();
                let text = format!("waiting for a complete file: {error}");
                self.emit(
                    &Event::Waiting {
                        model: &name,
                        error,
                    },
                    &text,
                );
                return;
            }
        };
        match self.simulate(&model) {
            Ok((plan, report, cache)) => {
                let text = summary(&cache);
                match &self.last {
                    None => self.emit(
                        &Event::Ready {
                            model: &name,
                            cache,
                        },
                        &text,
                    ),
                    Some(last) => {
                        let changes = diff(
                            &Version {
                                name: &name,
                                model: &last.model,
                                plan: &last.plan,
                                report: Some(&last.report),
                            },
                            &Version {
                                name: &name,
                                model: &model,
                                plan: &plan,
                                report: Some(&report),
                            },
                        );
                        let text = format!("{text}\n{}", changes_text(&changes));
                        self.emit(
                            &Event::Regenerated {
                                model: &name,
                                cache,
                                changes: &changes,
                            },
                            &text,
                        );
                    }
                }
                self.last = Some(Good {
                    model,
                    plan,
                    report,
                });
            }
            Err(error) => {
                let text = format!("cannot simulate this version: {error}; the last results stay");
                self.emit(
                    &Event::Failed {
                        model: &name,
                        error,
                    },
                    &text,
                );
            }
        }
    }

    /// Simulates (through the cache) and writes the outputs.
    fn simulate(&self, model: &Model) -> Result<(Plan, SimReport, Option<CacheCounts>), String> {
        let options = super::sim_defaults().map_err(|e| e.message)?;
        let name = file_name(&self.args.model);
        // The report animates every wall: its pose traces must come back from the cache too.
        let need = if self.args.report.is_some() {
            Need::Traces
        } else {
            Need::Records
        };
        let limits = super::rule_limits().map_err(|e| e.message)?;
        let (sim, counts) = Run::new(model, &self.cell, &options)
            .named(&name)
            .limits(limits)
            .cache(self.cache.as_ref())
            .need(need)
            .simulate()
            .map_err(|e| e.to_string())?;
        warn_if_unwritable(self.cache.as_ref());
        let mut report = SimReport::new(&sim, options.dt).map_err(|e| e.to_string())?;
        if let Some(rules) = &self.rules {
            report.add_findings(
                &rules
                    .evaluate(&sim.reasoned.relations)
                    .map_err(|e| e.to_string())?,
            );
        }
        report.sim.cache = counts;
        let mut json = Vec::new();
        report.write_json(&mut json).map_err(|e| e.to_string())?;
        write_atomically(&self.out.join("simulate.json"), &json)?;
        write_atomically(&self.out.join("simulate.txt"), report.to_text().as_bytes())?;
        if let Some(dir) = &self.args.report {
            let input = ReportInput {
                model,
                model_name: &name,
                cell: &self.cell,
                sim: &sim,
                report: &report,
            };
            let bound = super::limits::max_report_bytes().map_err(|e| e.message)?;
            write_report(dir, &input, bound)
                .map_err(|e| format!("{}: cannot write the report: {e}", dir.display()))?;
        }
        Ok((sim.plan, report, counts))
    }
}

fn summary(cache: &Option<CacheCounts>) -> String {
    match cache {
        Some(c) => format!(
            "simulated {} walls, {} from the cache",
            c.computed, c.cached
        ),
        None => "simulated every wall (no cache)".to_string(),
    }
}

/// "Wall 1: framing Partial → Completed; 3TLs… nailing Failed → Completed", then moved pieces.
fn changes_text(d: &ModelDiff) -> String {
    let verdicts: Vec<String> = d
        .verdicts
        .iter()
        .flatten()
        .map(|c| format!("{} {} {} → {}", c.subject, c.stage, c.old, c.new))
        .collect();
    let mut lines = vec![if verdicts.is_empty() {
        "no verdict changed".to_string()
    } else {
        verdicts.join("; ")
    }];
    for e in &d.elements {
        let mut line = format!("{} ({}) {}", e.id, e.name, e.change);
        if let Some(mm) = e.moved_mm {
            line.push_str(&format!(" {mm:.1} mm"));
        }
        lines.push(line);
    }
    lines.join("\n")
}

/// Writes through the library's atomic writer: readers see the old or the new file.
fn write_atomically(path: &Path, bytes: &[u8]) -> Result<(), String> {
    framewright::atomic::write_atomically(path, bytes)
        .map_err(|e| format!("{}: cannot write: {e}", path.display()))
}
