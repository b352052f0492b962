//! Roles over the framing styles `framewright synth wall` writes, against the truth sidecars it
//! writes beside them: every header construction (built-up, solid, flat on the kings with no
//! jacks), sills between the jacks or king to king under the jacks, single and double sills,
//! rows of blocking, doubled king studs, double and triple top plates, 2x4 and 2x6, with doors
//! and windows at several places, written as IfcMember or IfcColumn/IfcBeam, one product per
//! piece or mapped items. Per role, precision and recall over all of them must be at least
//! 99.5 % (`plan --truth` computes them).

use std::collections::BTreeMap;
use std::process::Command;

fn framewright(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_framewright"))
        .args(args)
        .output()
        .expect("framewright runs")
}

#[test]
fn every_role_of_every_generated_style_is_found() {
    let dir = tempfile::tempdir().unwrap();
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
    let mut totals: BTreeMap<String, [u64; 3]> = BTreeMap::new();
    let (mut walls, mut refused, mut pieces, mut wrong) = (0, Vec::new(), 0u64, Vec::new());
    let mut case = 0usize;
    for opening in openings {
        for header in headers {
            for sill in sills {
                for double_sill in [false, true] {
                    for rows in blocking {
                        case += 1;
                        let ifc = dir.path().join(format!("w{case}.ifc"));
                        let truth = dir.path().join(format!("w{case}.truth.json"));
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
                        let (ifc_s, truth_s) = (ifc.to_str().unwrap(), truth.to_str().unwrap());
                        args.extend(["-o", ifc_s, "--truth", truth_s]);
                        let out = framewright(&args);
                        if !out.status.success() {
                            // A combination the generator refuses (an opening that does not fit
                            // this lumber) says why; it is no wall to check.
                            let err = String::from_utf8_lossy(&out.stderr).into_owned();
                            assert!(err.contains("opening"), "{args:?}: {err}");
                            refused.push(err);
                            continue;
                        }
                        let out = framewright(&[
                            "plan",
                            ifc_s,
                            "--json",
                            "--no-cache",
                            "--truth",
                            truth_s,
                        ]);
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
                }
            }
        }
    }
    assert!(
        walls >= 120,
        "{walls} walls generated; refused: {refused:#?}"
    );
    let mut table = String::new();
    for (role, [truth, found, correct]) in &totals {
        let precision = *correct as f64 / (*found).max(1) as f64;
        let recall = *correct as f64 / (*truth).max(1) as f64;
        table.push_str(&format!(
            "{role}: {truth} labelled, {found} found, {correct} right\n"
        ));
        assert!(
            precision >= 0.995 && recall >= 0.995,
            "{role}: precision {precision}, recall {recall}\n{table}\n{wrong:#?}"
        );
    }
    for role in [
        "bottom_plate",
        "top_plate",
        "stud",
        "king_stud",
        "jack_stud",
        "header",
        "sill",
        "cripple_stud",
        "blocking",
    ] {
        assert!(
            totals.get(role).is_some_and(|t| t[0] > 0),
            "no {role} in any wall\n{table}"
        );
    }
    println!(
        "{walls} walls, {pieces} pieces, {} wrong\n{table}",
        wrong.len()
    );
}
