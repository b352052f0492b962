//! The scale row of `plan`: a generated model shaped like a real project (3 blocks x 5
//! storeys, members aggregated in IfcWall, doors and windows, a property set per member:
//! `framewright synth block --grouping wall --psets --openings`, 1,620 walls, 49,410
//! members, 46 MB), planned with the study's cell (placement search on) the way
//! `framewright plan --json` does it, phase by phase (one rule pass per part, the search,
//! the placement slice: `reason_placed`); then the rule base run twice (a full pass for the
//! search, another with its facts: the path before `reason_placed`) and the oldest path (one
//! search per target, every offset a placement candidate, every relation converted to
//! `Value` tuples), each with its ratio. Then `plan` as it runs by default, through the cache: a first run into an
//! empty cache folder and a second, warm run, each with its ratio to the uncached run
//! measured here (the JSON checked equal to it but for the `cache` block).
//!
//! `cargo bench --bench plan_scale` (`-- --storeys 1` for a quick run; `-- --skip-old` to
//! time only the current path; `PLAN_SCALE_SIZES=1` also prints the largest relations).
//! Peak memory: `/usr/bin/time -v framewright plan --json M.ifc`.

use framewright::cache::Cache;
use framewright::cell::Cell;
use framewright::frame::placement::SearchOptions;
use framewright::frame::plan::Plan;
use framewright::frame::{Ask, RuleEngine, RuleLimits, cell_facts, model_facts};
use framewright::ifc::Model;
use framewright::report::plan::PlanReport;
use framewright::synth::building::{BlockSpec, blocks};
use framewright::synth::units::feet;
use framewright::synth::{Grouping, WriteOptions, models, write_ifc};
use std::path::Path;
use std::time::Instant;

// The allocator the command line uses (src/main.rs), so the figures are `plan`'s.
#[global_allocator]
static ALLOCATOR: mimalloc::MiMalloc = mimalloc::MiMalloc;

/// How `plan` reasons: fused (one pass, the search, the placement slice) or in two passes
/// with these search options.
enum Reasoning {
    Fused,
    TwoPasses(SearchOptions),
}

/// The report's JSON as `plan --json` writes it (through a buffer), hashed as it is written:
/// a growing buffer of the whole document would cost reallocations `plan` does not pay.
fn json_digest(report: &PlanReport) -> blake3::Hash {
    let mut hasher = blake3::Hasher::new();
    let mut out = std::io::BufWriter::with_capacity(1 << 16, &mut hasher);
    report.write_json(&mut out).expect("json");
    drop(out);
    hasher.finalize()
}

/// Runs `plan --json` on `path`, printing each phase; returns the total seconds and the
/// JSON's digest.
fn plan(path: &Path, reasoning: &Reasoning, label: &str) -> (f64, blake3::Hash) {
    let start = Instant::now();
    let mut last = start;
    let mut lap = |what: &str| {
        let now = Instant::now();
        eprintln!("  {label} {what:<28} {:7.3} s", (now - last).as_secs_f64());
        last = now;
    };
    let model = Model::open(path).expect("read");
    lap("read");
    let cell = Cell::load("study-abb").expect("cell");
    let mut facts = model_facts(&model, &Default::default());
    facts.extend(cell_facts(&cell));
    lap("facts and contacts");
    let reasoned = match reasoning {
        Reasoning::Fused => {
            let ask = Ask::new(&RuleEngine::Compiled).only(Plan::RELATIONS);
            ask.placed(facts, &cell).expect("reason")
        }
        Reasoning::TwoPasses(options) => {
            let ask = Ask::new(&RuleEngine::Compiled).search(*options);
            ask.place(&mut facts, &cell).expect("placement");
            lap("placement search (1st pass)");
            // The oldest path (`every_offset`) converted every relation; `plan` reads its own.
            if options.every_offset {
                ask.over(&facts)
            } else {
                ask.only(Plan::RELATIONS).over(&facts)
            }
            .expect("reason")
        }
    };
    lap("rule base");
    if std::env::var_os("PLAN_SCALE_SIZES").is_some() {
        let mut sizes: Vec<(usize, &String)> = reasoned
            .relations
            .iter()
            .map(|(n, t)| (t.len(), n))
            .collect();
        sizes.sort();
        for (n, name) in sizes.iter().rev().take(15) {
            eprintln!("    {name} {n}");
        }
    }
    let plan = Plan::from_reasoned(&model, &reasoned).expect("plan");
    let report = PlanReport::new(&model, &plan);
    lap("typed plan");
    let json = json_digest(&report);
    lap("JSON");
    (start.elapsed().as_secs_f64(), json)
}

/// Runs `plan --json` through the cache folder `cache` (the reasoning per part, stored and
/// read back), the plan built beside a first run's storing as `plan` does; returns the total
/// seconds and the digest of the JSON without the `cache` block.
fn plan_cached(path: &Path, cache: &Cache, label: &str) -> (f64, blake3::Hash) {
    let start = Instant::now();
    let model = Model::open(path).expect("read");
    let cell = Cell::load("study-abb").expect("cell");
    let mut facts = model_facts(&model, &Default::default());
    facts.extend(cell_facts(&cell));
    let limits = RuleLimits::default();
    let planned = framewright::pipeline::plan(
        &model,
        &cell,
        facts,
        &RuleEngine::Compiled,
        limits,
        Some(cache),
    )
    .expect("reason");
    let (plan, counts) = (planned.plan, planned.cache.expect("counts"));
    let json = json_digest(&PlanReport::new(&model, &plan));
    let seconds = start.elapsed().as_secs_f64();
    eprintln!(
        "  {label} walls reasoned {}, from the cache {}",
        counts.computed, counts.cached
    );
    (seconds, json)
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let storeys = args
        .iter()
        .position(|a| a == "--storeys")
        .and_then(|i| args.get(i + 1)?.parse().ok())
        .unwrap_or(5);
    let skip_old = args.iter().any(|a| a == "--skip-old");
    let unit = framewright::synth::building::BuildingSpec {
        length: feet(24.0),
        depth: feet(14.0),
        ..models::default_building_spec()
    };
    let spec = BlockSpec::new(unit, 3, storeys, 3, 9);
    let layout = blocks(&spec, "plan_scale").expect("layout");
    let written = write_ifc(
        &layout,
        &WriteOptions {
            grouping: Grouping::Wall,
            property_sets: true,
            openings: true,
            file_name: "plan_scale.ifc".into(),
            ..WriteOptions::default()
        },
    )
    .expect("write");
    let dir = tempfile::tempdir().expect("temp dir");
    let path = dir.path().join("plan_scale.ifc");
    std::fs::write(&path, &written.ifc).expect("write model");
    eprintln!(
        "plan_scale: {} walls, {} members, {:.1} MB",
        written.truth.counts.walls,
        written.truth.counts.members,
        written.ifc.len() as f64 / 1e6
    );
    let (now, json) = plan(&path, &Reasoning::Fused, "fused ");
    println!("plan_scale now: {now:.2} s");
    let cache_dir = tempfile::tempdir().expect("cache dir");
    let cache = Cache::new(cache_dir.path());
    let (first, first_json) = plan_cached(&path, &cache, "cache, first run");
    let (warm, warm_json) = plan_cached(&path, &cache, "cache, warm run ");
    println!(
        "plan_scale through the cache: first run {first:.2} s ({:.2}x the uncached run), warm {warm:.2} s ({:.2}x faster than uncached; same JSON: {})",
        first / now,
        now / warm,
        first_json == json && warm_json == json
    );
    if skip_old {
        return;
    }
    let (two, two_json) = plan(
        &path,
        &Reasoning::TwoPasses(SearchOptions::default()),
        "two passes",
    );
    println!(
        "plan_scale with the rule base run twice: {two:.2} s; fused is {:.2}x faster (same JSON: {})",
        two / now,
        json == two_json
    );
    let (before, old_json) = plan(
        &path,
        &Reasoning::TwoPasses(SearchOptions {
            share_equal_poses: false,
            every_offset: true,
        }),
        "own   ",
    );
    println!("plan_scale before (search per target, every offset, all relations): {before:.2} s");
    println!(
        "plan_scale speed-up: {:.1}x (same JSON: {})",
        before / now,
        json == old_json
    );
}
