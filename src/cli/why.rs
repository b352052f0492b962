//! `framewright why MODEL.ifc ID` and `framewright why-not MODEL.ifc 'rel(…)'`:
//! an element's verdicts with their derivations down to IFC entities, cell
//! keys and rule lines; or which rule could have derived a tuple and which
//! condition failed.

use super::check::{
    ReasoningInputs, load_inputs, load_model_facts, model_and_cell_facts, rules_in_force,
};
use super::{CmdResult, Failure, print_stdout};
use framewright::cache::Cache;
use framewright::explain::render::{render_answer, render_why, render_why_not};
use framewright::explain::why::{
    Context, WhyError, WhyReport, element_walls_split, name_walls, resolve_element, why, why_not,
};
use framewright::frame::Ask;
use framewright::frame::containers::{containers_of, restrict_to_containers};
use framewright::frame::panel::PanelOf;
use framewright::frame::panel_why;
use framewright::frame::panelize::panels_by_piece;
use framewright::frame::plan::Plan;
use framewright::logic::compiled::Relations;
use framewright::pipeline::{Run, prepare_facts, whole_facts};
use framewright::sim::SimOptions;
use serde::Serialize;
use std::collections::BTreeSet;
use std::path::PathBuf;

#[derive(clap::Args)]
pub struct WhyArgs {
    /// The IFC model.
    pub model: PathBuf,
    /// A piece id, an IFC GlobalId or an entity `#id`; or a panel (`W1-P2`), a plate segment
    /// (`PLATE~2`), an added end stud (`STUD~end2`) or a site piece (`CAP~lap1`) of the plan.
    pub id: String,
    /// Print every verdict's derivation tree, not only the answer and its first cause's tree.
    #[arg(long, alias = "tree")]
    pub verbose: bool,
    #[command(flatten)]
    pub common: Common,
}

#[derive(clap::Args)]
pub struct WhyNotArgs {
    /// The IFC model.
    pub model: PathBuf,
    /// The tuple, e.g. 'role(#47, king_stud)' (`#id` stands for the piece of that entity); or
    /// 'panel_break(W1, 7.0)': why a wall is not split at u = 7.0 m.
    pub tuple: String,
    #[command(flatten)]
    pub common: Common,
}

#[derive(clap::Args)]
pub struct Common {
    #[command(flatten)]
    pub inputs: ReasoningInputs,
    /// Print the complete trees as JSON.
    #[arg(long)]
    pub json: bool,
    /// User rule files whose findings are explained too. Repeatable.
    #[arg(long = "rules", value_name = "FILE.dl")]
    pub rules: Vec<PathBuf>,
    /// Explain the plan only: do not simulate the element's wall.
    #[arg(long)]
    pub no_simulate: bool,
    /// Where simulated walls are cached (default: $FRAMEWRIGHT_CACHE, $XDG_CACHE_HOME/framewright or ~/.cache/framewright); `--cache-dir` is the same option.
    #[arg(long = "cache", alias = "cache-dir", value_name = "DIR")]
    pub cache_dir: Option<PathBuf>,
    /// Neither read nor write the cache: simulate the wall afresh.
    #[arg(long, conflicts_with = "cache_dir")]
    pub no_cache: bool,
}

/// A wall simulated for the explanation.
#[derive(Serialize)]
struct Simulated {
    /// The rules' name for it (its key piece).
    wall: String,
    /// As every command names it: `Wall 1 (W1)`, `Wall 1, panel 2 (W1-P2)`.
    label: Option<String>,
    from_cache: bool,
}

/// Adds the executor's facts of the walls of the pieces in `ids` (each wall
/// simulated once, then cached), unless `--no-simulate`. A wall the rules split is simulated
/// panel by panel on the model cut into panels: `facts` become that model's (the element's
/// containers), and the model is returned, for the explanation to name its pieces. `whole`, when
/// the caller has them, are the model's and the cell's facts (not built again).
fn simulate_walls(
    c: &Common,
    model: &framewright::ifc::Model,
    cell: &framewright::cell::Cell,
    facts: &mut framewright::frame::Facts,
    whole: Option<&framewright::frame::Facts>,
    ids: &[String],
    cache: Option<&Cache>,
) -> Result<(Vec<Simulated>, Option<framewright::ifc::Model>), Failure> {
    if c.no_simulate {
        return Ok((Vec::new(), None));
    }
    let (base, user_files) = rules_in_force(&c.inputs.rules_dir, &c.rules)?;
    let ctx = Context {
        model,
        facts,
        base: &base,
        user_files: &user_files,
        limits: super::rule_limits()?,
        cell: None,
    };
    let mut walls = Vec::new();
    let mut split = false;
    for id in ids {
        let (of, any) = element_walls_split(&ctx, id).map_err(failure)?;
        split |= any;
        for w in of {
            if !walls.contains(&w) {
                walls.push(w);
            }
        }
    }
    let panelized = if split {
        let pieces: BTreeSet<String> = ids
            .iter()
            .filter_map(|id| resolve_element(model, id).ok())
            .flatten()
            .map(|p| p.id.clone())
            .collect();
        let built;
        let whole = match whole {
            Some(facts) => facts,
            None => {
                built = whole_facts(model, cell);
                &built
            }
        };
        let keep = containers_of(whole, &pieces.iter().map(String::as_str).collect());
        let restrict = |f: framewright::frame::Facts| restrict_to_containers(&f, &keep);
        let limits = super::rule_limits()?;
        let prepared = prepare_facts(
            model,
            "model",
            cell,
            &base,
            &limits,
            restrict_to_containers(whole, &keep),
            &restrict,
        )?;
        *facts = prepared.facts;
        prepared.panelized
    } else {
        None
    };
    let mut out = Vec::new();
    for wall in walls {
        let options = SimOptions {
            walls: vec![wall.clone()],
            engine: base.clone(),
            ..super::sim_defaults()?
        };
        let (sim, counts) = Run::new(model, cell, &options)
            .limits(super::rule_limits()?)
            .cache(cache)
            .wall_facts(whole)?;
        facts.extend(sim);
        out.push(Simulated {
            wall,
            label: None,
            from_cache: counts.computed == 0,
        });
    }
    Ok((out, panelized))
}

#[derive(Serialize)]
struct Envelope<'a, T: Serialize> {
    model: String,
    cell: &'a str,
    query: &'a str,
    #[serde(flatten)]
    answer: T,
}

fn json<T: Serialize>(value: &T) -> Result<String, Failure> {
    let mut s = serde_json::to_string_pretty(value)
        .map_err(|e| Failure::bad_input(format!("cannot write JSON: {e}")))?;
    s.push('\n');
    Ok(s)
}

fn failure(e: WhyError) -> Failure {
    Failure::from(e)
}

impl Common {
    /// The cache of simulated walls, none with `--no-cache`.
    fn cache(&self) -> Option<Cache> {
        if self.no_cache {
            return None;
        }
        self.cache_dir
            .clone()
            .or_else(super::cache::default_dir)
            .map(Cache::new)
    }

    /// What the wall's simulation cannot take, refused before the model is read.
    fn check_simulation(&self) -> Result<(), Failure> {
        if self.no_simulate {
            return Ok(());
        }
        self.inputs
            .tolerance_for_executor("add --no-simulate to explain the plan with this tolerance")
    }
}

pub fn run_why(args: WhyArgs) -> CmdResult {
    let c = &args.common;
    c.check_simulation()?;
    let (base, user_files) = rules_in_force(&c.inputs.rules_dir, &c.rules)?;
    let (model, cell, whole) = load_model_facts(&args.model, &c.inputs)?;
    // The whole model's plan names walls and panels as every other command does.
    let (plan, _) = plan_of(whole.clone(), &cell, &base, &model)?;
    // A panel, a plate segment or an added stud: not a piece of the model but of the plan.
    if panel_why::names_a_panel_part(&args.id) && resolve_element(&model, &args.id).is_err() {
        let answer = panel_why::why(&plan, &cell, &args.id).ok_or_else(|| {
            Failure::bad_input(format!(
                "`{}` names no panel, plate segment, added stud or site piece of the plan (panels are WALL-Pn, segments PLATE~k, added studs STUD~endN, site pieces PLATE~lapK; `framewright plan --json` lists them)",
                args.id
            ))
        })?;
        // A plate segment or an added stud is also a piece the executor framed: its verdicts
        // follow the cut, from its panel's simulation.
        let of = args.id.split_once('~').map(|(of, _)| of);
        if c.no_simulate || of.is_none_or(|of| resolve_element(&model, of).is_err()) {
            return print_panel_answer(c, &args.model, &cell.name, &args.id, &answer);
        }
        let rules = Rules {
            base: &base,
            user_files: &user_files,
        };
        let of = of.unwrap_or_default();
        let (mut simulated, mut reports) = explain_part(
            c,
            &rules,
            &model,
            &cell,
            &whole,
            of,
            &args.id,
            c.cache().as_ref(),
        )?;
        if reports.is_empty() {
            return print_panel_answer(c, &args.model, &cell.name, &args.id, &answer);
        }
        let names = panels_by_piece(&plan);
        name_walls(&mut reports, &names);
        label_simulated(&mut simulated, &names, &reports);
        return print_part_answer(c, &args, &cell.name, &answer, &simulated, &reports);
    }
    let names = panels_by_piece(&plan);
    let rules = Rules {
        base: &base,
        user_files: &user_files,
    };
    let (mut simulated, mut reports) = explain_element(
        c,
        &rules,
        &model,
        &cell,
        &whole,
        &args.id,
        c.cache().as_ref(),
    )?;
    name_walls(&mut reports, &names);
    label_simulated(&mut simulated, &names, &reports);
    check_piece_moves(c, &rules, &model, &cell, &mut reports)?;
    let text = if c.json {
        #[derive(Serialize)]
        struct Elements<'a, T> {
            simulated: &'a [Simulated],
            elements: T,
        }
        json(&Envelope {
            model: args.model.display().to_string(),
            cell: &cell.name,
            query: &args.id,
            answer: Elements {
                simulated: &simulated,
                elements: &reports,
            },
        })?
    } else {
        let mut text = simulated_lines(&simulated);
        if c.no_simulate {
            text.push_str("not simulated (--no-simulate): plan verdicts only\n");
        }
        text.push_str(&if args.verbose {
            render_why(&reports)
        } else {
            render_answer(&reports)
        });
        text
    };
    print_stdout(&text)
}

/// The rule base and user rule files in force.
struct Rules<'a> {
    base: &'a framewright::frame::RuleEngine,
    user_files: &'a [PathBuf],
}

/// The reports on `id` over `whole` (the model's and the cell's facts): only the element's
/// containers matter (see `frame::containers`), so the placement search and the rules run over
/// them alone; its walls simulated through `cache`.
fn explain_element(
    c: &Common,
    rules: &Rules,
    model: &framewright::ifc::Model,
    cell: &framewright::cell::Cell,
    whole: &framewright::frame::Facts,
    id: &str,
    cache: Option<&Cache>,
) -> Result<(Vec<Simulated>, Vec<WhyReport>), Failure> {
    explain_part(c, rules, model, cell, whole, id, id, cache)
}

/// As `explain_element`, for `id` (a piece of the model, or a plate segment or added stud of a
/// split wall) that `of` (a piece of the model: the plate it is cut from) puts in its wall.
#[allow(clippy::too_many_arguments)]
fn explain_part(
    c: &Common,
    rules: &Rules,
    model: &framewright::ifc::Model,
    cell: &framewright::cell::Cell,
    whole: &framewright::frame::Facts,
    of: &str,
    id: &str,
    cache: Option<&Cache>,
) -> Result<(Vec<Simulated>, Vec<WhyReport>), Failure> {
    let pieces = resolve_element(model, of).map_err(failure)?;
    let ids: BTreeSet<&str> = pieces.iter().map(|p| p.id.as_str()).collect();
    let mut facts = restrict_to_containers(whole, &containers_of(whole, &ids));
    Ask::new(rules.base)
        .within(super::rule_limits()?)
        .place(&mut facts, cell)?;
    let (simulated, panelized) = simulate_walls(
        c,
        model,
        cell,
        &mut facts,
        Some(whole),
        &[of.to_string()],
        cache,
    )?;
    let ctx = Context {
        model: panelized.as_ref().unwrap_or(model),
        facts: &facts,
        base: rules.base,
        user_files: rules.user_files,
        limits: super::rule_limits()?,
        cell: Some(cell),
    };
    if of != id && resolve_element(ctx.model, id).is_err() {
        // A part of the plan the executor does not frame (a cap plate's lap, set on site).
        return Ok((simulated, Vec::new()));
    }
    let reports = why(&ctx, id).map_err(failure)?;
    Ok((simulated, reports))
}

/// Checks each remedy that moves a piece in the model by simulating its wall again (no cache)
/// with the piece moved: checked when the piece is then framed; otherwise the remedy becomes
/// a search that found none, with the status the new run gave.
fn check_piece_moves(
    c: &Common,
    rules: &Rules,
    model: &framewright::ifc::Model,
    cell: &framewright::cell::Cell,
    reports: &mut [WhyReport],
) -> Result<(), Failure> {
    for report in reports.iter_mut() {
        for cause in report.answer.causes.iter_mut() {
            let mut kept = Vec::new();
            for mut remedy in std::mem::take(&mut cause.remedies) {
                let Some(m) = remedy.piece_move.clone() else {
                    kept.push(remedy);
                    continue;
                };
                let Some(moved) = moved_piece(model, &m.piece, &m.by) else {
                    kept.push(remedy);
                    continue;
                };
                let whole = model_and_cell_facts(&moved, cell, &c.inputs);
                let (_, after) = explain_element(c, rules, &moved, cell, &whole, &m.piece, None)?;
                let status = after
                    .iter()
                    .flat_map(|r| &r.answer.statuses)
                    .find(|s| s.stage == "framing")
                    .map_or("not simulated", |s| s.status.as_str());
                if status == "framed" {
                    remedy.checked_by_simulation();
                    kept.push(remedy);
                } else {
                    cause.no_remedy.push(format!(
                        "moving it {:.1} mm onto the surface beneath it: simulated again, it is {status}",
                        remedy.value.abs() * 1000.0
                    ));
                }
            }
            cause.remedies = kept;
        }
    }
    Ok(())
}

/// The model with `piece` moved by `by` (model coordinates, m); none when the model has no
/// such piece (a plate segment of a cut wall).
fn moved_piece(
    model: &framewright::ifc::Model,
    piece: &str,
    by: &[f64; 3],
) -> Option<framewright::ifc::Model> {
    let mut pieces = model.pieces().to_vec();
    let p = pieces.iter_mut().find(|p| p.id == piece)?;
    p.obox.centre += nalgebra::Vector3::from(*by);
    Some(model.with_pieces(pieces))
}

pub fn run_why_not(args: WhyNotArgs) -> CmdResult {
    let c = &args.common;
    c.check_simulation()?;
    let (base, user_files) = rules_in_force(&c.inputs.rules_dir, &c.rules)?;
    if let Some(query) = panel_why::parse_break_query(&args.tuple) {
        let (wall, u) = query.map_err(|e| Failure::bad_input(e.to_string()))?;
        let (model, cell, facts) = load_model_facts(&args.model, &c.inputs)?;
        let (plan, relations) = plan_of(facts, &cell, &base, &model)?;
        let answer = panel_why::why_no_break(&plan, &relations, &cell, &wall, u)
            .map_err(|e| Failure::bad_input(e.to_string()))?;
        return print_panel_answer(c, &args.model, &cell.name, &args.tuple, &answer);
    }
    let (model, cell, mut facts) = load_inputs(&args.model, &c.inputs, &base)?;
    let ids = piece_ids_in(&model, &args.tuple);
    let (_, panelized) =
        simulate_walls(c, &model, &cell, &mut facts, None, &ids, c.cache().as_ref())?;
    let ctx = Context {
        model: panelized.as_ref().unwrap_or(&model),
        facts: &facts,
        base: &base,
        user_files: &user_files,
        limits: super::rule_limits()?,
        cell: None,
    };
    let report = why_not(&ctx, &args.tuple).map_err(failure)?;
    let text = if c.json {
        json(&Envelope {
            model: args.model.display().to_string(),
            cell: &cell.name,
            query: &args.tuple,
            answer: &report,
        })?
    } else {
        render_why_not(&args.tuple, &report)
    };
    print_stdout(&text)
}

/// The plan of the model on the cell, with the relations it came from.
fn plan_of(
    facts: framewright::frame::Facts,
    cell: &framewright::cell::Cell,
    base: &framewright::frame::RuleEngine,
    model: &framewright::ifc::Model,
) -> Result<(Plan, Relations), Failure> {
    let reasoned = Ask::new(base)
        .within(super::rule_limits()?)
        .only(Plan::RELATIONS)
        .placed(facts, cell)?;
    let plan = Plan::from_reasoned(model, &reasoned)?;
    Ok((plan, reasoned.relations))
}

/// A plate segment's or added stud's answer: how the plan made it, then its verdicts.
fn print_part_answer(
    c: &Common,
    args: &WhyArgs,
    cell: &str,
    panel: &panel_why::PanelWhy,
    simulated: &[Simulated],
    reports: &[WhyReport],
) -> CmdResult {
    let text = if c.json {
        #[derive(Serialize)]
        struct Part<'a> {
            #[serde(flatten)]
            panel: &'a panel_why::PanelWhy,
            simulated: &'a [Simulated],
            elements: &'a [WhyReport],
        }
        json(&Envelope {
            model: args.model.display().to_string(),
            cell,
            query: &args.id,
            answer: Part {
                panel,
                simulated,
                elements: reports,
            },
        })?
    } else {
        let mut text = panel.to_text();
        if !args.verbose {
            // How the cut was decided is the plan's answer: its first line here, all of it
            // with --verbose.
            let first = text.lines().next().unwrap_or_default().to_string();
            text = format!("{first}\n  (how the plan cut it: --verbose)\n");
        }
        text.push('\n');
        text.push_str(&simulated_lines(simulated));
        text.push_str(&if args.verbose {
            render_why(reports)
        } else {
            render_answer(reports)
        });
        text
    };
    print_stdout(&text)
}

/// Names each simulated wall as `plan` does.
fn label_simulated(
    simulated: &mut [Simulated],
    names: &std::collections::BTreeMap<String, PanelOf>,
    reports: &[WhyReport],
) {
    // The one wall simulated for an element is the element's.
    let only = (simulated.len() == 1)
        .then(|| reports.iter().find_map(|r| r.wall_label.clone()))
        .flatten();
    for s in simulated {
        // A panel of a split wall is keyed in the cut model by a piece the plan does not
        // list (a plate's id before the cut): named as the elements it holds are.
        s.label = names
            .get(&s.wall)
            .map(PanelOf::label)
            .or_else(|| {
                reports
                    .iter()
                    .find(|r| r.wall.as_deref() == Some(s.wall.as_str()))
                    .and_then(|r| r.wall_label.clone())
            })
            .or_else(|| only.clone());
    }
}

/// `simulated LABEL [(from the cache)]`, one line per wall.
fn simulated_lines(simulated: &[Simulated]) -> String {
    simulated
        .iter()
        .map(|s| {
            format!(
                "simulated {}{}\n",
                s.label
                    .clone()
                    .unwrap_or_else(|| format!("wall {}", s.wall)),
                if s.from_cache {
                    " (from the cache)"
                } else {
                    ""
                }
            )
        })
        .collect()
}

fn print_panel_answer(
    c: &Common,
    model: &std::path::Path,
    cell: &str,
    query: &str,
    answer: &panel_why::PanelWhy,
) -> CmdResult {
    let text = if c.json {
        json(&Envelope {
            model: model.display().to_string(),
            cell,
            query,
            answer,
        })?
    } else {
        answer.to_text()
    };
    print_stdout(&text)
}

/// The pieces a why-not tuple names (`#entity` or a piece id), as IDs for `why`.
fn piece_ids_in(model: &framewright::ifc::Model, tuple: &str) -> Vec<String> {
    let inner = tuple
        .split_once('(')
        .map_or("", |(_, r)| r)
        .trim_end_matches(')');
    let mut ids = Vec::new();
    for arg in inner.split(',') {
        let arg = arg.trim().trim_matches('"');
        let known = if let Some(n) = arg.strip_prefix('#') {
            n.parse::<u64>()
                .is_ok_and(|n| model.pieces().iter().any(|p| p.entity == n || p.item == n))
        } else {
            model.pieces().iter().any(|p| p.id == arg)
        };
        if known && !ids.iter().any(|i| i == arg) {
            ids.push(arg.to_string());
        }
    }
    ids
}
