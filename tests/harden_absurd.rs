//! Absurd geometry (a scale of 1e23, a `NAN` direction, a piece kilometres long or
//! away) is a warning naming the entity and a skipped piece; `plan` still finishes.
//! The fixture is `synth wall --length 3m --mapped --grouping assembly` with operator
//! #39's third scale set to 99999999999999999999999 and operator #42's Axis1 pointing
//! at a new `#9001=IFCDIRECTION((NAN,0.,0.))`.

use std::path::PathBuf;
use std::process::Command;

fn bin() -> Command {
    Command::new(env!("CARGO_BIN_EXE_framewright"))
}

fn fixture() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/harden_absurd_scale.ifc")
}

fn inspect(path: &std::path::Path) -> String {
    let o = bin().arg("inspect").arg(path).output().unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    String::from_utf8_lossy(&o.stdout).into_owned()
}

#[test]
fn absurd_scale_and_nan_direction_are_warned_about_and_skipped() {
    let out = inspect(&fixture());
    assert!(
        out.contains("#39: degenerate geometry: scale factor 1e23 is absurd"),
        "{out}"
    );
    assert!(out.contains("#9001: cannot be read"), "{out}");
    // 12 members written, the two corrupted studs skipped.
    assert!(out.contains("pieces       10 in 2 products"), "{out}");
}

#[test]
fn plan_finishes_on_the_absurd_file() {
    let o = bin().arg("plan").arg(fixture()).output().unwrap();
    assert!(o.status.code().is_some(), "plan was killed");
    assert!(!String::from_utf8_lossy(&o.stderr).contains("panicked"));
}

#[test]
fn pieces_too_long_or_too_far_are_skipped() {
    let text = std::fs::read_to_string(fixture()).unwrap();
    let dir = tempfile::tempdir().unwrap();
    // A scale of 500 passes the operator bound but makes a 1.2 km stud.
    let long = text.replace(
        "#36=IFCCARTESIANTRANSFORMATIONOPERATOR3DNONUNIFORM(#33,#34,#35,1.,#29,1.,2.352675);",
        "#36=IFCCARTESIANTRANSFORMATIONOPERATOR3DNONUNIFORM(#33,#34,#35,1.,#29,1.,500.);",
    );
    let far = text.replace(
        "#44=IFCCARTESIANPOINT((1.2192,-0.04445,0.0381));",
        "#44=IFCCARTESIANPOINT((1.2192,-0.04445,1.E7));",
    );
    assert_ne!(long, text);
    assert_ne!(far, text);
    for (name, body, expect) in [
        (
            "long.ifc",
            long,
            "m long, more than the 100 m any lumber can be",
        ),
        ("far.ifc", far, "m from the origin, beyond 10000 m"),
    ] {
        let p = dir.path().join(name);
        std::fs::write(&p, body).unwrap();
        let out = inspect(&p);
        assert!(out.contains(expect), "{name}: {out}");
        assert!(
            out.contains("pieces       9 in 2 products"),
            "{name}: {out}"
        );
    }
}
