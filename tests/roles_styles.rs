//! Roles over the framing styles `framewright synth wall` writes, against the truth sidecars it
//! writes beside them: every header construction (built-up, solid, flat on the kings with no
//! jacks), sills between the jacks or king to king under the jacks, single and double sills,
//! rows of blocking, doubled king studs, double and triple top plates, 2x4 and 2x6, with doors
//! and windows at several places, written as IfcMember or IfcColumn/IfcBeam, one product per
//! piece or mapped items; and the details where walls meet and are braced: California,
//! three-stud and ladder corners, partition backers (a flat stud between two studs, or ladder
//! blocking), windows side by side sharing a king stud, let-in braces. Per role, precision and
//! recall over all of them must be at least 99.5 % (`plan --truth` computes them).

mod common;

use std::collections::BTreeMap;
use std::process::Command;

fn framewright(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_framewright"))
        .args(args)
        .output()
        .expect("framewright runs")
}

/// Per role: labelled, found, right.
type Totals = BTreeMap<String, [u64; 3]>;

/// Writes each case's wall with its truth, plans it and adds its role check to `totals`;
/// returns the walls checked, the pieces, and every piece labelled otherwise. A case the
/// generator refuses must say why (`refusal` in its message); with no `refusal`, none may be.
fn run_cases(
    cases: &[Vec<String>],
    refusal: Option<&str>,
    totals: &mut Totals,
) -> (usize, u64, Vec<String>, Vec<String>) {
    let dir = tempfile::tempdir().unwrap();
    let (mut walls, mut pieces, mut wrong, mut refused) = (0, 0u64, Vec::new(), Vec::new());
    for (case, args) in cases.iter().enumerate() {
        let ifc = dir.path().join(format!("w{case}.ifc"));
        let truth = dir.path().join(format!("w{case}.truth.json"));
        let (ifc_s, truth_s) = (ifc.to_str().unwrap(), truth.to_str().unwrap());
        let mut args: Vec<&str> = args.iter().map(String::as_str).collect();
        args.extend(["-o", ifc_s, "--truth", truth_s]);
        let out = framewright(&args);
        if !out.status.success() {
            let err = String::from_utf8_lossy(&out.stderr).into_owned();
            assert!(refusal.is_some_and(|r| err.contains(r)), "{args:?}: {err}");
            refused.push(err);
            continue;
        }
        let out = framewright(&["plan", ifc_s, "--json", "--no-cache", "--truth", truth_s]);
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        let plan: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        let check = &plan["role_check"];
        assert!(check["not_in_model"].as_array().unwrap().is_empty());
        for m in check["mismatches"].as_array().unwrap() {
            wrong.push(format!("{}: {m}", args.join(" ")));
        }
        for row in check["roles"].as_array().unwrap() {
            let t = totals
                .entry(row["role"].as_str().unwrap().into())
                .or_default();
            for (k, key) in ["truth", "found", "correct"].iter().enumerate() {
                t[k] += row[key].as_u64().unwrap();
            }
        }
        // Nothing is left unsure on a style the generator knows.
        let warnings = plan["warnings"].as_array().unwrap();
        assert!(warnings.is_empty(), "{args:?}: {warnings:?}");
        walls += 1;
        pieces += check["labelled"].as_u64().unwrap();
    }
    (walls, pieces, wrong, refused)
}

/// Every role in `roles` occurs, and every role found reaches 99.5 % precision and recall.
fn assert_every_role_found(totals: &Totals, roles: &[&str], wrong: &[String]) -> String {
    let mut table = String::new();
    for (role, [truth, found, correct]) in totals {
        table.push_str(&format!(
            "{role}: {truth} labelled, {found} found, {correct} right\n"
        ));
    }
    for (role, [truth, found, correct]) in totals {
        let precision = *correct as f64 / (*found).max(1) as f64;
        let recall = *correct as f64 / (*truth).max(1) as f64;
        assert!(
            precision >= 0.995 && recall >= 0.995,
            "{role}: precision {precision}, recall {recall}\n{table}\n{wrong:#?}"
        );
    }
    for role in roles {
        assert!(
            totals.get(*role).is_some_and(|t| t[0] > 0),
            "no {role} in any wall\n{table}"
        );
    }
    table
}

#[test]
fn every_role_of_every_generated_style_is_found() {
    let openings: [&[&str]; 4] = [
        &[
            "--door",
            "24in,38in,82.5in",
            "--window",
            "96in,48in,36in,36in",
        ],
        &[
            "--window",
            "20in,30in,24in,44in",
            "--window",
            "80in,60in,48in,30in",
        ],
        &["--door", "100in,32in,80in"],
        &[
            "--window",
            "60in,36in,40in,24in",
            "--door",
            "20in,30in,80in",
        ],
    ];
    let headers = ["built-up", "solid", "flat"];
    let sills = ["between-jacks", "king-to-king"];
    let blocking: [&[&str]; 3] = [
        &[],
        &["--blocking", "30in"],
        &["--blocking", "16in", "--blocking", "60in"],
    ];
    let mut cases: Vec<Vec<String>> = Vec::new();
    for opening in openings {
        for header in headers {
            for sill in sills {
                for double_sill in [false, true] {
                    for rows in blocking {
                        let case = cases.len() + 1;
                        let mut args: Vec<&str> = vec!["synth", "wall", "--length", "14ft"];
                        args.extend(opening);
                        args.extend(["--header", header, "--sill", sill]);
                        args.extend(rows);
                        if double_sill {
                            args.push("--double-sill");
                        }
                        // Vary what the reader sees from case to case.
                        match case % 4 {
                            1 => args.extend(["--lumber", "2x6", "--spacing", "24in"]),
                            2 => args.extend(["--products", "column-beam", "--unit", "mm"]),
                            3 => {
                                args.extend(["--mapped", "--grouping", "assembly", "--unit", "ft"])
                            }
                            _ => args.extend(["--single-top-plate", "--grouping", "wall"]),
                        }
                        // Doubled king studs on every third wall, a triple top plate on
                        // every fifth (not on the single-top-plate ones).
                        if case.is_multiple_of(3) {
                            args.push("--double-kings");
                        }
                        if case.is_multiple_of(5) && !case.is_multiple_of(4) {
                            args.push("--triple-top-plate");
                        }
                        cases.push(args.into_iter().map(String::from).collect());
                    }
                }
            }
        }
    }
    // A combination the generator refuses (an opening that does not fit this lumber) says
    // why; it is no wall to check.
    let mut totals = Totals::new();
    let (walls, pieces, wrong, refused) = run_cases(&cases, Some("opening"), &mut totals);
    assert!(
        walls >= 120,
        "{walls} walls generated; refused: {refused:#?}"
    );
    // Cap plates occur on most of these walls too; braces only in the test below.
    let roles: Vec<&str> = common::FRAMING_ROLES
        .into_iter()
        .filter(|r| *r != "brace")
        .collect();
    let table = assert_every_role_found(&totals, &roles, &wrong);
    println!(
        "{walls} walls, {pieces} pieces, {} wrong\n{table}",
        wrong.len()
    );
}

#[test]
fn corners_partitions_shared_kings_and_braces() {
    let corners = ["single", "backer", "three-stud", "ladder"];
    let partitions: [&[&str]; 4] = [
        &[],
        &["--partition", "12ft"],
        &["--partition", "16ft:ladder"],
        &["--partition", "12ft:backer", "--partition", "16ft:ladder"],
    ];
    let mut cases: Vec<Vec<String>> = Vec::new();
    for corner in corners {
        for partition in partitions {
            for header in ["built-up", "flat"] {
                for shared in [false, true] {
                    for brace in [false, true] {
                        let case = cases.len() + 1;
                        let mut args: Vec<String> = [
                            "synth", "wall", "--length", "20ft", "--corner", corner, "--header",
                        ]
                        .map(String::from)
                        .to_vec();
                        args.push(header.into());
                        args.extend(partition.iter().map(|a| a.to_string()));
                        // Two windows; side by side they share the king between them: jack,
                        // king, jack between the rough openings (just the king with flat
                        // headers, which have no jacks).
                        let gap = match (shared, header) {
                            (false, _) => 6.0,
                            (true, "flat") => 1.5,
                            (true, _) => 4.5,
                        };
                        args.extend([
                            "--window".into(),
                            "34in,30in,24in,44in".into(),
                            "--window".into(),
                            format!("{}in,30in,24in,44in", 64.0 + gap),
                        ]);
                        if brace {
                            args.extend(["--brace".into(), "106in".into()]);
                        }
                        if case.is_multiple_of(3) {
                            args.extend(["--blocking".into(), "48in".into()]);
                        }
                        match case % 4 {
                            1 => args.extend(["--lumber", "2x6"].map(String::from)),
                            2 => args.extend(
                                ["--products", "column-beam", "--unit", "mm"].map(String::from),
                            ),
                            3 => args.extend(
                                ["--mapped", "--grouping", "assembly", "--unit", "ft"]
                                    .map(String::from),
                            ),
                            _ => args.extend(["--grouping", "wall"].map(String::from)),
                        }
                        cases.push(args);
                    }
                }
            }
        }
    }
    let mut totals = Totals::new();
    // Every case here fits: nothing may be refused.
    let (walls, pieces, wrong, _) = run_cases(&cases, None, &mut totals);
    assert_eq!(walls, 128);
    let table = assert_every_role_found(&totals, &common::FRAMING_ROLES, &wrong);
    println!(
        "{walls} walls, {pieces} pieces, {} wrong\n{table}",
        wrong.len()
    );
}
