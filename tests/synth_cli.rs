//! `framewright synth` on the command line: bad input exits 2 with a message that
//! says what to do; good input writes a file and a truth sidecar.
use std::process::Command;

fn synth(args: &[&str]) -> (i32, String, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_framewright"))
        .arg("synth")
        .args(args)
        .output()
        .unwrap();
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

#[test]
fn bad_input_exits_2_with_a_hint() {
    for (args, needle) in [
        (vec!["wall", "--length=-3"], "length"),
        (vec!["wall", "--length", "twelve"], "cannot read length"),
        (vec!["wall", "--door", "1,2"], "U,W,H"),
        (vec!["wall", "--window", "30in,36in,48in,1in"], "sill"),
        (
            vec!["wall", "--length", "6ft", "--door", "10in,60in,80in"],
            "does not fit",
        ),
        (vec!["building", "--grid", "0x3"], "grid"),
        (vec!["building", "--grid", "3by3"], "NxM"),
        (vec!["tm3", "--unit", "yards"], "m, mm, ft or in"),
        (vec!["tm3", "--schema", "IFC5"], "IFC4, IFC2X3 or IFC4X3"),
        (vec!["tm3", "--length", "3"], "fixed geometry"),
        (vec!["tm1", "--placement", "parent"], "needs a parent"),
        (vec!["house"], "unknown model"),
        (vec!["wall", "--lumber", "2x3"], "2x4 or 2x6"),
    ] {
        let (code, _, err) = synth(&args);
        assert_eq!(code, 2, "{args:?}: {err}");
        assert!(err.contains(needle), "{args:?}: '{err}' lacks '{needle}'");
    }
}

#[test]
fn writes_the_model_and_its_truth() {
    let dir = tempfile::tempdir().unwrap();
    let ifc = dir.path().join("b.ifc");
    let truth = dir.path().join("b.truth.json");
    let (code, out, err) = synth(&[
        "building",
        "--grid",
        "2x3",
        "--lumber",
        "2x6",
        "--unit",
        "mm",
        "-o",
        ifc.to_str().unwrap(),
        "--truth",
        truth.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
    assert!(out.contains("24 walls, 6 buildings"), "{out}");
    let t: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&truth).unwrap()).unwrap();
    assert_eq!(t["walls"].as_array().unwrap().len(), 24);
    assert_eq!(t["length_unit"]["name"], "MILLIMETRE");
    let text = std::fs::read_to_string(&ifc).unwrap();
    assert!(text.contains("IFCSIUNIT(*,.LENGTHUNIT.,.MILLI.,.METRE.)"));
    assert_eq!(text.matches("=IFCBUILDING(").count(), 6);
    // Without -o the model goes to standard output.
    let (code, out, _) = synth(&["tm1"]);
    assert_eq!(code, 0);
    assert!(out.starts_with("ISO-10303-21;") && out.ends_with("END-ISO-10303-21;\n"));
}
