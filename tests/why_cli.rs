//! `framewright why` and `why-not` on the command line: JSON structure, key
//! text lines, byte-identical output run to run, and bad ids / tuples (exit 2).

mod common;

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

fn tm3() -> PathBuf {
    root().join("examples/models/tm3.ifc")
}

fn run(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_framewright"))
        .args(args)
        .output()
        .unwrap()
}

fn ok(args: &[&str]) -> String {
    let out = run(args);
    assert!(
        out.status.success(),
        "{args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8(out.stdout).unwrap()
}

fn bad(args: &[&str]) -> String {
    let out = run(args);
    assert_eq!(out.status.code(), Some(2), "{args:?}");
    assert!(out.stdout.is_empty());
    String::from_utf8(out.stderr).unwrap()
}

#[test]
fn why_json_has_the_element_its_verdicts_and_complete_trees() {
    let m = tm3();
    let m = m.to_str().unwrap();
    let text = ok(&[
        "why",
        "--offset-x",
        "0.531",
        m,
        "#174",
        "--json",
        "--no-simulate",
    ]);
    assert_eq!(
        text,
        ok(&[
            "why",
            "--offset-x",
            "0.531",
            m,
            "#174",
            "--json",
            "--no-simulate"
        ]),
        "deterministic"
    );
    let v: serde_json::Value = serde_json::from_str(&text).unwrap();
    assert_eq!(v["cell"], "study-abb");
    assert_eq!(v["query"], "#174");
    let el = &v["elements"][0];
    assert_eq!(el["element"]["entity"], 174);
    assert_eq!(el["element"]["ifc_type"], "IfcBeam");
    let verdicts = el["verdicts"].as_array().unwrap();
    let role = verdicts.iter().find(|x| x["relation"] == "role").unwrap();
    assert_eq!(role["tuple"][1], "top_plate");
    assert_eq!(role["explanation"]["how"]["kind"], "rule");
    assert!(
        role["explanation"]["how"]["rule"]
            .as_str()
            .unwrap()
            .starts_with("role_fitted (rules/roles.dl:")
    );
    // The JSON tree is complete: every leaf is an input with its origin, no cuts.
    fn leaves(n: &serde_json::Value, inputs: &mut usize) {
        match n["how"]["kind"].as_str().unwrap() {
            "input" => *inputs += 1,
            "rule" => {
                for p in n["how"]["premises"].as_array().unwrap() {
                    if p["kind"] == "tuple" {
                        leaves(p, inputs);
                    }
                }
            }
            other => panic!("cut tree: {other}"),
        }
    }
    let target = verdicts
        .iter()
        .find(|x| x["relation"] == "framing_target")
        .unwrap();
    let mut inputs = 0;
    leaves(&target["explanation"], &mut inputs);
    assert!(inputs > 20, "{inputs}");
    assert_eq!(target["sources"]["truncated"], false);
    assert!(
        target["sources"]["ifc_entities"]
            .as_array()
            .unwrap()
            .contains(&serde_json::json!(171))
    );
    let keys = target["sources"]["cell_keys"].as_array().unwrap();
    assert!(keys.contains(&serde_json::json!("assembly_offset_x")));
}

#[test]
fn why_text_names_the_element_rules_and_sources() {
    let m = tm3();
    let text = ok(&[
        "why",
        "--offset-x",
        "0.531",
        m.to_str().unwrap(),
        "32H5oapRpM57uELNCcVku8",
        "--no-simulate",
        "--verbose",
    ]);
    assert_eq!(
        text.lines().next().unwrap(),
        "not simulated (--no-simulate): plan verdicts only"
    );
    assert!(
        text.lines()
            .nth(1)
            .unwrap()
            .contains("'2x4 top plate F-020' (IfcBeam #174")
    );
    assert!(text.contains(
        "\nrole(\"32H5oapRpM57uELNCcVku8\", \"top_plate\")  [by role_fitted (rules/roles.dl:"
    ));
    assert!(text.contains("└─ fitted_role(\"32H5oapRpM57uELNCcVku8\", \"top_plate\")  [by role_top_plate (rules/roles.dl:"));
    assert!(text.contains("framing_target(\"32H5oapRpM57uELNCcVku8\", [2.940825,0,0.04445,0.5,0.5,-0.5,-0.5])  [by framing_target (rules/targets.dl:"));
    assert!(text.contains("cell_value(\"assembly_offset_x\", 0.531)  [cell "));
    assert!(text.contains("[IFC #171]"));
    assert!(text.contains("  = "), "summary lines");
}

#[test]
fn why_explains_user_findings() {
    let model = root().join("tests/fixtures/synth_wall_door_window_in.ifc");
    let rules = root().join("examples/rules/gripper_spacing.dl");
    let text = ok(&[
        "why",
        "--offset-x",
        "0.531",
        model.to_str().unwrap(),
        "#213",
        "--rules",
        rules.to_str().unwrap(),
        "--no-simulate",
        "--verbose",
    ]);
    let first = text.lines().nth(3).unwrap();
    assert!(first.starts_with("violation(\"1SLgxFv2F86AyYIFLQqMY1\", \"shorter_than_gripper_spacing\", \"member is 60 mm long, shorter than the gripper spacing (600 mm): both grippers cannot hold it\")  [by shorter_than_gripper_spacing ("), "{first}");
    assert!(
        first.contains("examples/rules/gripper_spacing.dl:5)]"),
        "{first}"
    );
    assert!(
        text.contains("cell_value(\"gripper_spacing\", 0.6)  [cell "),
        "{text}"
    );
    assert!(
        text.contains("piece_size(\"1SLgxFv2F86AyYIFLQqMY1\", 0.06"),
        "{text}"
    );
}

#[test]
fn why_not_says_which_rule_and_condition_failed() {
    let m = tm3();
    let m = m.to_str().unwrap();
    let text = ok(&["why-not", m, "role(#174, king_stud)", "--no-simulate"]);
    assert!(text.starts_with("role(\"32H5oapRpM57uELNCcVku8\", \"king_stud\") is not derived.\n- role_fitted (rules/roles.dl:"), "{text}");
    assert!(text.contains("no fitted_role fact matches fitted_role(\"32H5oapRpM57uELNCcVku8\", \"king_stud\"); closest of 62:"));
    assert!(text.contains(
        "  because:\n    fitted_role(\"32H5oapRpM57uELNCcVku8\", \"king_stud\") is not derived."
    ));
    assert!(text.contains("- king_beside_jack (rules/roles.dl:"));
    assert!(text.contains("no upright fact matches upright(\"32H5oapRpM57uELNCcVku8\")"));
    let json = ok(&[
        "why-not",
        m,
        "role(#174, king_stud)",
        "--json",
        "--no-simulate",
    ]);
    let v: serde_json::Value = serde_json::from_str(&json).unwrap();
    assert_eq!(v["answer"], "not_derived");
    let tree = &v["tree"];
    assert_eq!(tree["why_not"]["relation"], "role");
    let fitted = &tree["why_not"]["rules"][0];
    assert_eq!(fitted["failure"]["kind"], "no_match");
    assert_eq!(tree["because"][0]["why_not"]["relation"], "fitted_role");
    assert_eq!(
        tree["because"][0]["because"][0]["why_not"]["relation"],
        "king_stud"
    );
    // A tuple that holds is explained instead.
    let holds = ok(&[
        "why-not",
        m,
        "role(#174, top_plate)",
        "--json",
        "--no-simulate",
    ]);
    let v: serde_json::Value = serde_json::from_str(&holds).unwrap();
    assert_eq!(v["answer"], "holds");
    assert_eq!(v["explanation"]["relation"], "role");
}

#[test]
fn why_not_shows_the_numbers_of_a_failed_condition() {
    // A member short enough for the user rule is not derived for a long stud:
    // the failing comparison is shown with the stud's length and the spacing.
    let model = root().join("tests/fixtures/synth_wall_door_window_in.ifc");
    let rules = root().join("examples/rules/gripper_spacing.dl");
    let text = ok(&[
        "why-not",
        model.to_str().unwrap(),
        "violation(#105, shorter_than_gripper_spacing, \"x\")",
        "--rules",
        rules.to_str().unwrap(),
        "--no-simulate",
    ]);
    assert!(text.contains("- shorter_than_gripper_spacing ("), "{text}");
    assert!(
        text.contains("condition `l < s` is false, e.g. 2.352675 < 0.6"),
        "{text}"
    );
}

#[test]
fn bad_ids_and_tuples_exit_2_with_a_clear_message() {
    let m = tm3();
    let m = m.to_str().unwrap();
    let err = bad(&["why", m, "#99999", "--no-simulate"]);
    assert!(
        err.contains("no piece of the model has the id `#99999` (nearest: #"),
        "{err}"
    );
    assert!(
        err.contains("`framewright plan MODEL.ifc --json` lists every member"),
        "{err}"
    );
    let err = bad(&["why", m, "#x", "--no-simulate"]);
    assert!(err.contains("`#x` is not an entity id"), "{err}");
    let err = bad(&["why-not", m, "rol(#174, top_plate)", "--no-simulate"]);
    assert!(
        err.contains("unknown relation `rol`") && err.contains("did you mean `role`?"),
        "{err}"
    );
    let err = bad(&["why-not", m, "role(#174)", "--no-simulate"]);
    assert!(err.contains("`role` has 2 attribute(s), found 1"), "{err}");
    let err = bad(&["why-not", m, "piece_index(#174, many)", "--no-simulate"]);
    assert!(err.contains("cannot read the tuple"), "{err}");
    let err = bad(&["why-not", m, "role(#5, stud)", "--no-simulate"]);
    assert!(
        err.contains("no piece of the model has the id `#5`"),
        "{err}"
    );
}

/// The wall of TM3's top plate as `plan` names it: `Wall 1 (W1)` (planned once).
fn top_plate_wall() -> String {
    static LABEL: std::sync::OnceLock<String> = std::sync::OnceLock::new();
    LABEL
        .get_or_init(|| {
            let plan: serde_json::Value =
                serde_json::from_str(&ok(&["plan", tm3().to_str().unwrap(), "--json"])).unwrap();
            let wall = common::wall_holding(&plan, "32H5oapRpM57uELNCcVku8");
            format!(
                "{} ({})",
                wall["name"].as_str().unwrap(),
                wall["wall_id"].as_str().unwrap()
            )
        })
        .clone()
}

#[test]
fn why_simulates_the_wall_of_the_tm3_top_plate_and_caches_it() {
    // The study's finding: TM3's top plate cannot be placed on the ABB cell,
    // its place pose is beyond the arm's reach. The executor simulates only
    // the plate's wall; the second run reads it from the cache.
    let cache = tempfile::tempdir().unwrap();
    let m = tm3();
    let args = [
        "why",
        "--offset-x",
        "0.531",
        m.to_str().unwrap(),
        "#174",
        "--cache-dir",
        cache.path().to_str().unwrap(),
    ];
    let answer = ok(&args);
    let args = [&args[..], &["--verbose"]].concat();
    let first = ok(&args);
    assert!(
        answer.starts_with(&format!("simulated {}\n", top_plate_wall()))
            && first.starts_with(&format!(
                "simulated {} (from the cache)\n",
                top_plate_wall()
            )),
        "{answer}"
    );
    // The answer first: the cause with its numbers, the nails it cost folded, under 30 lines.
    let lines: Vec<&str> = answer.lines().collect();
    assert!(lines.len() < 30, "{answer}");
    // Its wall named as `plan` and `simulate` name it.
    assert!(
        lines[1].ends_with(&format!(", in {}", top_plate_wall())),
        "{answer}"
    );
    assert!(
        lines[4].starts_with(
            "framing failed (Robot): place pose beyond reach: the wrist centre would be "
        ),
        "{answer}"
    );
    assert!(lines[4].contains(" m from the shoulder, the arm reaches 2.377 m ("));
    // Its nails, from the plan: every nailing target with the top plate as plate or member.
    let plan: serde_json::Value = serde_json::from_str(&ok(&[
        "plan",
        m.to_str().unwrap(),
        "--offset-x",
        "0.531",
        "--json",
    ]))
    .unwrap();
    let id = "32H5oapRpM57uELNCcVku8";
    let nails = plan["walls"]
        .as_array()
        .unwrap()
        .iter()
        .flat_map(|w| w["nailing_targets"].as_array().unwrap())
        .filter(|t| t["plate"] == id || t["member"] == id)
        .count();
    assert!(
        lines[2] == format!("framing: failed; nailing: failed (0 of {nails} nails driven)"),
        "{answer}"
    );
    let folded: usize = lines
        .iter()
        .filter_map(|l| l.strip_prefix("  so "))
        .map(|l| l.split(' ').next().unwrap().parse::<usize>().unwrap())
        .sum();
    assert_eq!(folded, nails, "{answer}");
    assert!(
        answer.contains("nails not driven because it was not placed: 32H5oapRpM57uELNCcVku8 -> ")
    );
    let reason = first.lines().nth(3).unwrap();
    assert!(reason.starts_with("element_reason(\"32H5oapRpM57uELNCcVku8\", \"framing\", \"Robot\", \"place pose beyond reach: the wrist centre would be "), "{reason}");
    assert!(
        reason.contains(" m from the shoulder, the arm reaches 2.377 m ("),
        "{reason}"
    );
    // The rule's head is the line after its `@rule` comment.
    let rule_line = include_str!("../rules/verdicts.dl")
        .lines()
        .position(|l| l == "// @rule framing_place_beyond_reach")
        .unwrap()
        + 2;
    assert!(
        reason.ends_with(&format!(
            "[by framing_place_beyond_reach (rules/verdicts.dl:{rule_line})]"
        )),
        "{reason}"
    );
    assert!(
        first.contains(
            "sim_ik_failed(\"32H5oapRpM57uELNCcVku8\", \"place\", \"out_of_reach\", \"\", "
        ),
        "{first}"
    );
    assert!(
        first.contains(
            "[simulation: 07l14Rb8lVjg1i9SI4wpQJ IK for place of 32H5oapRpM57uELNCcVku8]"
        ),
        "{first}"
    );
    assert!(
        first.contains("[by framing_target (rules/targets.dl:"),
        "{first}"
    );
    assert!(
        first.contains("cell_value(\"assembly_offset_x\", 0.531)"),
        "{first}"
    );
    assert!(first.contains("[IFC #171]"), "{first}");
    assert!(
        first.contains("element_framing(\"32H5oapRpM57uELNCcVku8\", \"failed\")"),
        "{first}"
    );
    // The same answer in JSON: the cause, and its consequences with every nail.
    let json: serde_json::Value =
        serde_json::from_str(&ok(&[&args[..args.len() - 1], &["--json"]].concat())).unwrap();
    let a = &json["elements"][0]["answer"];
    assert_eq!(
        a["causes"][0]["rule"].as_str().unwrap().split(' ').next(),
        Some("framing_place_beyond_reach")
    );
    let counted: u64 = a["causes"][0]["consequences"]
        .as_array()
        .unwrap()
        .iter()
        .map(|c| {
            assert_eq!(
                c["ids"].as_array().unwrap().len() as u64,
                c["count"].as_u64().unwrap()
            );
            c["count"].as_u64().unwrap()
        })
        .sum();
    assert_eq!(counted as usize, nails);
    // Afresh, it says the same as from the cache.
    let fresh = ok(&[&args[..args.len() - 3], &["--no-cache", "--verbose"]].concat());
    assert!(fresh.starts_with(&format!("simulated {}\n", top_plate_wall())));
    assert_eq!(
        first.lines().skip(1).collect::<Vec<_>>(),
        fresh.lines().skip(1).collect::<Vec<_>>()
    );
    let json = ok(&[&args[..], &["--json"]].concat());
    let v: serde_json::Value = serde_json::from_str(&json).unwrap();
    assert_eq!(v["simulated"][0]["from_cache"], true);
    let verdicts = v["elements"][0]["verdicts"].as_array().unwrap();
    let reason = verdicts
        .iter()
        .find(|x| x["relation"] == "element_reason")
        .unwrap();
    assert_eq!(reason["sources"]["simulation_facts"], 1);
    assert!(
        reason["sources"]["ifc_entities"]
            .as_array()
            .unwrap()
            .contains(&serde_json::json!(174))
    );
}

#[test]
fn why_takes_the_cache_options_of_the_other_commands() {
    // `--cache DIR` as `plan` and `simulate` take it; `--no-cache` simulates afresh and
    // leaves no entry, not even in the default folder.
    let m = tm3();
    let m = m.to_str().unwrap();
    let named = tempfile::tempdir().unwrap();
    let default = tempfile::tempdir().unwrap();
    let why = |extra: &[&str]| {
        let out = Command::new(env!("CARGO_BIN_EXE_framewright"))
            .args(["why", "--offset-x", "0.531", m, "#174"])
            .args(extra)
            .env("FRAMEWRIGHT_CACHE", default.path())
            .output()
            .unwrap();
        assert!(
            out.status.success(),
            "{extra:?}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
        String::from_utf8(out.stdout).unwrap()
    };
    let entries = |dir: &Path| std::fs::read_dir(dir).unwrap().count();

    let first = why(&["--cache", named.path().to_str().unwrap()]);
    assert!(
        first.starts_with(&format!("simulated {}\n", top_plate_wall())),
        "{first}"
    );
    assert!(entries(named.path()) > 0, "the named folder holds the wall");
    let again = why(&["--cache", named.path().to_str().unwrap()]);
    assert!(again.starts_with(&format!(
        "simulated {} (from the cache)\n",
        top_plate_wall()
    )));

    let fresh = why(&["--no-cache"]);
    assert!(
        fresh.starts_with(&format!("simulated {}\n", top_plate_wall())),
        "{fresh}"
    );
    assert_eq!(entries(default.path()), 0, "--no-cache wrote nothing");
    assert_eq!(
        first.lines().skip(1).collect::<Vec<_>>(),
        fresh.lines().skip(1).collect::<Vec<_>>()
    );

    let err = bad(&["why", m, "#174", "--no-cache", "--cache", "x"]);
    assert!(err.contains("cannot be used with"), "{err}");
}

#[test]
fn a_contact_tolerance_the_simulation_would_not_use_is_refused() {
    // The executor plans with the default tolerance: explaining its verdicts next to facts
    // reasoned with another would mix two sets of contacts.
    let m = tm3();
    let m = m.to_str().unwrap();
    for command in [
        vec!["why", m, "#174", "--contact-tolerance", "5"],
        vec!["why-not", m, "role(#174, stud)", "--contact-tolerance", "5"],
    ] {
        let err = bad(&command);
        assert!(
            err.contains("--contact-tolerance cannot be combined with a simulation")
                && err.contains("add --no-simulate"),
            "{err}"
        );
    }
    // The plan alone takes it.
    let plan_only = ok(&[
        "why",
        m,
        "#174",
        "--contact-tolerance",
        "5",
        "--no-simulate",
    ]);
    assert!(plan_only.contains("32H5oapRpM57uELNCcVku8"), "{plan_only}");
}

#[test]
fn why_answers_first_on_a_real_wall() {
    // A bottom plate of the Constructivity wall whose place pose is past a joint limit on the
    // study cell: the cause first, its nails in one line, the whole answer short.
    let Some(model) =
        common::shared_path("ifc-realworld/timber_constructivity_wall-elemented-case_IFC4.ifc")
    else {
        return;
    };
    let text = ok(&[
        "why",
        model.to_str().unwrap(),
        "3E4igxyD1F5w4vj3LTAREz/4",
        "--no-cache",
    ]);
    let lines: Vec<&str> = text.lines().collect();
    assert!(lines.len() < 30, "{text}");
    let cause = lines
        .iter()
        .position(|l| l.starts_with("framing failed ("))
        .expect("a cause");
    assert!(cause < 10, "{text}");
    // Every nail of the piece is in the folded lines, and each kind is one line.
    let planned = lines[2]
        .split(" (")
        .nth(1)
        .and_then(|r| r.split(" of ").nth(1))
        .and_then(|r| r.split(' ').next())
        .and_then(|n| n.parse::<usize>().ok())
        .expect("nails planned");
    let folded: usize = lines
        .iter()
        .filter_map(|l| l.trim_start().strip_prefix("so "))
        .map(|l| l.split(' ').next().unwrap().parse::<usize>().unwrap())
        .sum();
    assert_eq!(folded, planned, "{text}");
    assert_eq!(
        text.matches("was not placed\")").count(),
        0,
        "no nail's tree: {text}"
    );
}

/// TM3's top plate #174 (wall F) and a stud of another wall (L-008), as the model places them.
const TOP_PLATE_AT: &str = "#167=IFCCARTESIANPOINT((6.858,0.04445,2.409825));";
const TOP_PLATE_RAISED: &str = "#167=IFCCARTESIANPOINT((6.858,0.04445,2.411825));";
const OTHER_STUD_AT: &str = "#234=IFCCARTESIANPOINT((0.04445,2.32537,0.0381));";
const OTHER_STUD_MOVED: &str = "#234=IFCCARTESIANPOINT((0.04445,2.30537,0.0381));";

#[test]
fn why_and_simulate_share_one_cache_entry_per_wall() {
    // One cache, one key: the wall `simulate` stored is the wall `why` reads, an edit to
    // another wall leaves it, and an edit to the element's wall simulates it again, with
    // another answer.
    let dir = tempfile::tempdir().unwrap();
    let cache = dir.path().join("cache");
    let cache = cache.to_str().unwrap();
    let text = std::fs::read_to_string(tm3()).unwrap();
    assert!(
        text.contains(TOP_PLATE_AT) && text.contains(OTHER_STUD_AT),
        "tm3.ifc changed; pick the points again"
    );
    let write = |name: &str, text: &str| {
        let path = dir.path().join(name);
        std::fs::write(&path, text).unwrap();
        path
    };
    let model = write("tm3.ifc", &text);
    let model = model.to_str().unwrap();
    ok(&["simulate", "--offset-x", "0.531", model, "--cache", cache]);
    let why = |model: &str| {
        ok(&[
            "why",
            "--offset-x",
            "0.531",
            model,
            "#174",
            "--cache",
            cache,
        ])
    };
    let answer = why(model);
    let from_cache = format!("simulated {} (from the cache)\n", top_plate_wall());
    assert!(answer.starts_with(&from_cache), "{answer}");
    let fresh = ok(&["why", "--offset-x", "0.531", model, "#174", "--no-cache"]);
    assert_eq!(
        answer.lines().skip(1).collect::<Vec<_>>(),
        fresh.lines().skip(1).collect::<Vec<_>>(),
        "the entry `simulate` stored answers as a fresh simulation does"
    );

    let other = write("other.ifc", &text.replace(OTHER_STUD_AT, OTHER_STUD_MOVED));
    let other_answer = why(other.to_str().unwrap());
    assert!(
        other_answer.starts_with(&from_cache),
        "an edit to another wall keeps this wall's entry: {other_answer}"
    );
    assert_eq!(other_answer, answer);

    let raised = write("raised.ifc", &text.replace(TOP_PLATE_AT, TOP_PLATE_RAISED));
    let raised_answer = why(raised.to_str().unwrap());
    assert!(
        raised_answer.starts_with(&format!("simulated {}\n", top_plate_wall())),
        "the element's own wall edited is simulated again: {raised_answer}"
    );
    // The plate is the wall's far edge from the arm: 2 mm higher in the model, its place
    // pose lies about 2 mm farther out of reach.
    let too_far = |text: &str| -> i64 {
        let (head, _) = text.split_once(" mm too far)").expect(text);
        head.rsplit_once('(').unwrap().1.parse().unwrap()
    };
    let farther = too_far(&raised_answer) - too_far(&answer);
    assert!(
        (1..=3).contains(&farther),
        "{farther} mm: {answer}\n{raised_answer}"
    );
}
