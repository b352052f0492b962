//! `framewright check MODEL.ifc --rules FILE.dl [--rules …] [--cell C] [--json]`:
//! user shop rules over the relations of the rule base. Exit code 1 when a
//! rule found a violation, 2 for bad input (model, cell, rule files).

use super::{CmdResult, Failure, print_stdout};
use framewright::cell::{Cell, PanelMode};
use framewright::frame::cell_facts::cell_facts;
use framewright::frame::{Ask, Facts, RuleEngine, model_facts};
use framewright::geom::ContactOptions;
use framewright::ifc::Model;
use framewright::pipeline::Run;
use framewright::sim::SimOptions;
use framewright::user_rules::{Finding, Findings, UserRules, engine_for};
use serde::Serialize;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

#[derive(clap::Args)]
pub struct CheckArgs {
    /// The IFC model.
    pub model: PathBuf,
    /// A user rule file deriving violation(id, rule, message) or warning(...). Repeatable.
    #[arg(long = "rules", value_name = "FILE.dl", required = true)]
    pub rules: Vec<PathBuf>,
    #[command(flatten)]
    pub inputs: ReasoningInputs,
    /// Print JSON instead of one line per finding.
    #[arg(long)]
    pub json: bool,
    /// Simulate the walls first, so rules can read the executor's facts (sim_*) and verdicts.
    #[arg(long)]
    pub simulate: bool,
    /// With --simulate: only this wall (id or name); repeat for more.
    #[arg(long = "wall", value_name = "W", requires = "simulate")]
    pub walls: Vec<String>,
}

/// The options every command that reasons a model shares (plan, check, why).
#[derive(clap::Args)]
pub struct ReasoningInputs {
    /// The robot cell: a built-in name (study-abb, study-kuka, study-abb-track, framing-line) or a TOML file.
    #[arg(long, default_value = "study-abb")]
    pub cell: String,
    /// Replace the built-in rule base with every .dl file of this directory.
    #[arg(long, value_name = "DIR")]
    pub rules_dir: Option<PathBuf>,
    /// Largest gap between two pieces still taken as touching, millimetres.
    #[arg(long, value_name = "MM", default_value_t = DEFAULT_CONTACT_TOLERANCE_MM)]
    pub contact_tolerance: f64,
    /// Where walls lie along the robot's x axis, overriding the cell: metres from the base
    /// to the wall's bottom edge, or `auto` (each wall where the arm reaches most of it).
    #[arg(long, value_name = "M|auto")]
    pub offset_x: Option<String>,
    /// Split walls into panels the cell builds (`auto`, rules/panels.dl, a wall that fits is
    /// one panel) or keep every wall one panel (`off`).
    #[arg(long, value_name = "auto|off", default_value = "auto", value_parser = PanelMode::parse)]
    pub panels: PanelMode,
}

impl ReasoningInputs {
    /// Refuses a contact tolerance other than the default where the executor runs: it plans
    /// the walls itself, with the default tolerance, and would answer for other contacts
    /// than the ones reasoned here. `instead` says what the user can do.
    pub fn tolerance_for_executor(&self, instead: &str) -> Result<(), Failure> {
        if self.contact_tolerance == DEFAULT_CONTACT_TOLERANCE_MM {
            return Ok(());
        }
        Err(Failure::bad_input(format!(
            "--contact-tolerance cannot be combined with a simulation (the executor plans with the default tolerance, {DEFAULT_CONTACT_TOLERANCE_MM} mm); {instead}"
        )))
    }
}

/// `--contact-tolerance`'s default, millimetres (`ContactOptions::default`).
const DEFAULT_CONTACT_TOLERANCE_MM: f64 = 3.0;

/// Loads a cell and applies a command-line `--offset-x`.
/// `--panels` for the commands that simulate or build a world.
#[derive(clap::Args, Clone, Copy)]
pub struct PanelsArg {
    /// Split walls into panels the cell builds (`auto`, rules/panels.dl, a wall that fits is
    /// one panel; each panel is framed and simulated on its own) or keep every wall one panel
    /// (`off`).
    #[arg(long, value_name = "auto|off", default_value = "auto", value_parser = PanelMode::parse)]
    pub panels: PanelMode,
}

pub fn load_cell(name: &str, offset_x: Option<&str>) -> Result<Cell, Failure> {
    let mut cell = Cell::load(name)?;
    if let Some(text) = offset_x {
        cell.set_offset_x(text)
            .map_err(|m| Failure::bad_input(format!("--offset-x: {m}")))?;
    }
    Ok(cell)
}

/// The model, the cell and their facts (what plan, check and why start from).
pub fn load_inputs(
    model: &Path,
    inputs: &ReasoningInputs,
    engine: &RuleEngine,
) -> Result<(Model, Cell, Facts), Failure> {
    let (model, cell, mut facts) = load_model_facts(model, inputs)?;
    Ask::new(engine)
        .within(super::rule_limits()?)
        .place(&mut facts, &cell)?;
    Ok((model, cell, facts))
}

/// The model, the cell and their facts, before the placement search.
pub fn load_model_facts(
    model: &Path,
    inputs: &ReasoningInputs,
) -> Result<(Model, Cell, Facts), Failure> {
    let contact_tolerance_mm = inputs.contact_tolerance;
    if !(contact_tolerance_mm.is_finite() && (0.0..=100.0).contains(&contact_tolerance_mm)) {
        return Err(Failure::bad_input(format!(
            "--contact-tolerance {contact_tolerance_mm} mm is out of range; give 0 to 100 mm"
        )));
    }
    let model = super::open_model(model)?;
    let mut cell = load_cell(&inputs.cell, inputs.offset_x.as_deref())?;
    cell.panel_mode = inputs.panels;
    let facts = model_and_cell_facts(&model, &cell, inputs);
    Ok((model, cell, facts))
}

/// The facts of `model` (contacts within `--contact-tolerance`) and of `cell`.
pub fn model_and_cell_facts(model: &Model, cell: &Cell, inputs: &ReasoningInputs) -> Facts {
    let contacts = ContactOptions {
        tolerance: inputs.contact_tolerance / 1000.0,
        ..ContactOptions::default()
    };
    let mut facts = model_facts(model, &contacts);
    facts.extend(cell_facts(cell));
    facts
}

pub fn rule_base(rules_dir: &Option<PathBuf>) -> RuleEngine {
    rules_dir
        .clone()
        .map_or(RuleEngine::Compiled, RuleEngine::Directory)
}

/// The rule base to reason with and the `--rules` files that report findings: a file that
/// feeds the rule base (a shop hook such as `break_forbidden`) joins it
/// (`user_rules::engine_for`).
pub fn rules_in_force(
    rules_dir: &Option<PathBuf>,
    rules: &[PathBuf],
) -> Result<(RuleEngine, Vec<PathBuf>), Failure> {
    Ok(engine_for(rules, &rule_base(rules_dir))?)
}

#[derive(Serialize)]
struct Report<'a> {
    model: String,
    cell: &'a str,
    rule_files: Vec<String>,
    violations: Vec<Row<'a>>,
    warnings: Vec<Row<'a>>,
}

#[derive(Serialize)]
struct Row<'a> {
    id: &'a str,
    /// IFC entity of the piece the id names (absent for other subjects).
    entity: Option<u64>,
    name: Option<&'a str>,
    rule: &'a str,
    message: &'a str,
}

pub fn run(args: CheckArgs) -> CmdResult {
    // Rule files first: a typo fails before the model is read.
    let (base, findings_files) = rules_in_force(&args.inputs.rules_dir, &args.rules)?;
    let user = UserRules::load(&findings_files, &base)?;
    if args.simulate {
        args.inputs
            .tolerance_for_executor("leave out --simulate to check the plan with this tolerance")?;
        // The executor reads the model and reasons itself.
        let model = super::open_model(&args.model)?;
        let mut cell = load_cell(&args.inputs.cell, args.inputs.offset_x.as_deref())?;
        cell.panel_mode = args.inputs.panels;
        let options = SimOptions {
            walls: args.walls.clone(),
            engine: base.clone(),
            ..super::sim_defaults()?
        };
        let (sim, _) = Run::new(&model, &cell, &options)
            .limits(super::rule_limits()?)
            .simulate()?;
        let findings = user.evaluate(&sim.reasoned.relations)?;
        return report(&args, &model, &cell.name, &findings);
    }
    let (model, cell, facts) = load_model_facts(&args.model, &args.inputs)?;
    let reasoned = Ask::new(&base)
        .within(super::rule_limits()?)
        .placed(facts, &cell)?;
    let findings = user.evaluate(&reasoned.relations)?;
    report(&args, &model, &cell.name, &findings)
}

fn report<'a>(
    args: &'a CheckArgs,
    model: &'a Model,
    cell: &'a str,
    findings: &'a Findings,
) -> CmdResult {
    let pieces: BTreeMap<&str, (u64, Option<&str>)> = model
        .pieces()
        .iter()
        .map(|p| (p.id.as_str(), (p.entity, p.name.as_deref())))
        .collect();
    let rows = |list: &'a [Finding]| -> Vec<Row<'a>> {
        list.iter()
            .map(|f| {
                let piece = pieces.get(f.id.as_str());
                Row {
                    id: &f.id,
                    entity: piece.map(|p| p.0),
                    name: piece.and_then(|p| p.1),
                    rule: &f.rule,
                    message: &f.message,
                }
            })
            .collect()
    };
    let report = Report {
        model: args.model.display().to_string(),
        cell,
        rule_files: args.rules.iter().map(|p| p.display().to_string()).collect(),
        violations: rows(&findings.violations),
        warnings: rows(&findings.warnings),
    };
    let text = if args.json {
        let mut s = serde_json::to_string_pretty(&report)
            .map_err(|e| Failure::bad_input(format!("cannot write JSON: {e}")))?;
        s.push('\n');
        s
    } else {
        to_text(&report, findings)
    };
    print_stdout(&text)?;
    Ok(if findings.violations.is_empty() {
        ExitCode::SUCCESS
    } else {
        ExitCode::from(1)
    })
}

fn to_text(report: &Report<'_>, findings: &Findings) -> String {
    let mut s = String::new();
    let width = report
        .violations
        .iter()
        .chain(&report.warnings)
        .map(|r| r.rule.len())
        .max()
        .unwrap_or(0);
    for (kind, rows) in [
        ("violation", &report.violations),
        ("warning", &report.warnings),
    ] {
        for r in rows {
            let who = match (r.entity, r.name) {
                (Some(e), Some(n)) => format!("{} (#{e} '{n}')", r.id),
                (Some(e), None) => format!("{} (#{e})", r.id),
                _ => r.id.to_string(),
            };
            s.push_str(&format!(
                "{kind:<9}  {:<width$}  {who}: {}\n",
                r.rule, r.message
            ));
        }
    }
    let plural = |n: usize, w: &str| format!("{n} {w}{}", if n == 1 { "" } else { "s" });
    s.push_str(&format!(
        "{}, {} from {} ({})\n",
        plural(findings.violations.len(), "violation"),
        plural(findings.warnings.len(), "warning"),
        plural(report.rule_files.len(), "rule file"),
        report.rule_files.join(", ")
    ));
    s
}
