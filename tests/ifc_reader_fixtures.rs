//! The reader on the project's own fixtures: constructs with known answers,
//! adversarial inputs, and a property test that mutated files never panic.

use framewright::ifc::{IfcErrorKind, Model};
use framewright::step::{ReadOptions, StepErrorKind};
use proptest::prelude::*;
use std::path::{Path, PathBuf};

const FOOT: f64 = 0.3048;

fn fixture(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/fixtures/reader")
        .join(name)
}

fn close(a: [f64; 3], b: [f64; 3], tol: f64) -> bool {
    (0..3).all(|i| (a[i] - b[i]).abs() < tol)
}

fn ends(model: &Model, id: &str) -> ([f64; 3], [f64; 3]) {
    let p = model
        .pieces()
        .iter()
        .find(|p| p.id == id)
        .unwrap_or_else(|| panic!("{id} missing"));
    let (s, e) = p.axis();
    ([s.x, s.y, s.z], [e.x, e.y, e.z])
}

#[test]
fn mapped_items_compose_target_after_origin() {
    let model = Model::open(fixture("mapped_feet.ifc")).unwrap();
    assert_eq!(model.length_unit.name, "FOOT");
    assert_eq!(model.pieces().len(), 2);
    // Origin lifts the map 1 ft, then the target halves z: 0.5 .. 4.5 ft.
    let (s, e) = ends(&model, "0000000000000000000002/0");
    assert!(close(s, [2.0 * FOOT, 0.0, 0.5 * FOOT], 1e-9), "{s:?}");
    assert!(close(e, [2.0 * FOOT, 0.0, 4.5 * FOOT], 1e-9), "{e:?}");
    let (s, e) = ends(&model, "0000000000000000000002/1");
    assert!(
        close(s, [5.0 * FOOT, 0.0, FOOT], 1e-9) && close(e, [5.0 * FOOT, 0.0, 9.0 * FOOT], 1e-9)
    );
    // The turned piece has its wide face along x instead of y.
    let turned = &model.pieces()[1].obox;
    assert!(turned.axes[1].x.abs() > 0.999, "{:?}", turned.axes);
    assert_eq!(model.pieces()[0].predefined_type.as_deref(), Some("STUD"));
}

#[test]
fn clipping_brep_ifc2x3_and_sparse_ids() {
    let model = Model::open(fixture("clipped_brep_ifc2x3.ifc")).unwrap();
    assert!(model.warnings.is_empty(), "{:?}", model.warnings);
    assert_eq!(model.length_unit.metres_per_unit, 0.001);
    let (s, e) = ends(&model, "0000000000000000000011");
    assert!(
        close(s, [0.0, 0.0, 0.0], 1e-9) && close(e, [1.5, 0.0, 0.0], 1e-9),
        "{s:?} {e:?}"
    );
    let brep = model
        .pieces()
        .iter()
        .find(|p| p.id == "0000000000000000000012")
        .unwrap();
    assert!((brep.obox.length() - 1.0).abs() < 1e-5);
    assert!(
        (brep.obox.width() - 0.089).abs() < 1e-5 && (brep.obox.thickness() - 0.038).abs() < 1e-5
    );
    assert!(
        (brep.obox.axes[0].y.atan2(brep.obox.axes[0].x).abs() - 30f64.to_radians()).abs() < 1e-6
    );
    assert_eq!(brep.name.as_deref(), Some("Brep blocking über"));
    // IFC2X3 members carry no PredefinedType; the parent is the assembly.
    assert!(model.pieces().iter().all(|p| p.predefined_type.is_none()));
    let parent = &model.groups[&model.pieces()[0].parent.unwrap()];
    assert_eq!(
        (parent.ifc_type.as_str(), parent.predefined_type.as_deref()),
        ("IfcElementAssembly", Some("BRACED_FRAME"))
    );
}

fn tm1_text() -> String {
    std::fs::read_to_string(fixture("mapped_feet.ifc")).unwrap()
}

#[test]
fn placement_cycle_is_an_error_naming_the_chain() {
    let text = tm1_text().replace(
        "#12=IFCLOCALPLACEMENT($,#11);",
        "#12=IFCLOCALPLACEMENT(#13,#11);\n#13=IFCLOCALPLACEMENT(#12,#11);",
    );
    let err =
        Model::from_bytes("cycle.ifc", text.into_bytes(), &ReadOptions::default()).unwrap_err();
    assert!(
        matches!(err.kind, IfcErrorKind::PlacementCycle { .. }),
        "{err}"
    );
    let message = err.to_string();
    assert!(
        message.starts_with("cycle.ifc: line ")
            && message.contains("#12")
            && message.contains("#13"),
        "{message}"
    );
}

#[test]
fn mapped_item_cycle_skips_the_member() {
    // The map's representation contains a mapped item of the same map.
    let text = tm1_text().replace(
        "#23=IFCSHAPEREPRESENTATION($,'Body','SweptSolid',(#21));",
        "#23=IFCSHAPEREPRESENTATION($,'Body','SweptSolid',(#32));",
    );
    let model =
        Model::from_bytes("mapcycle.ifc", text.into_bytes(), &ReadOptions::default()).unwrap();
    assert!(model.pieces().len() < 2);
    assert!(
        model
            .warnings
            .iter()
            .any(|w| w.message.contains("nested more than")),
        "{:?}",
        model.warnings
    );
}

#[test]
fn deep_nesting_is_refused_without_overflowing_the_stack() {
    let deep = format!(
        "#99=IFCLABEL({}1{});",
        "(".repeat(100_000),
        ")".repeat(100_000)
    );
    let text = tm1_text().replace("ENDSEC;\nEND-ISO", &format!("{deep}\nENDSEC;\nEND-ISO"));
    let model = Model::from_bytes("deep.ifc", text.into_bytes(), &ReadOptions::default());
    // The label is never decoded by the reader; decoding it must fail cleanly.
    let model = model.unwrap();
    let err = model.step().entity(99).unwrap().unwrap_err();
    assert!(matches!(err.kind, StepErrorKind::TooDeep { .. }), "{err}");
}

#[test]
fn size_limit_is_enforced_before_reading() {
    let options = ReadOptions {
        max_bytes: 100,
        ..ReadOptions::default()
    };
    let err = Model::open_with(fixture("mapped_feet.ifc"), &options).unwrap_err();
    assert!(err.to_string().contains("over the limit"), "{err}");
}

#[test]
fn huge_ids_do_not_allocate_tables() {
    let text = tm1_text().replace("#42=IFCMEMBER", "#18446744073709551615=IFCMEMBER");
    let model = Model::from_bytes("ids.ifc", text.into_bytes(), &ReadOptions::default()).unwrap();
    assert_eq!(model.pieces()[0].entity, u64::MAX);
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 300, ..ProptestConfig::default() })]

    /// Truncating, overwriting or deleting bytes anywhere never panics:
    /// the result is a model or a typed error.
    #[test]
    fn mutated_files_never_panic(cut in 0usize..4000, at in 0usize..4000, byte in any::<u8>(), delete in 0usize..40) {
        let mut bytes = tm1_text().into_bytes();
        let n = bytes.len();
        let at = at % n;
        bytes[at] = byte;
        let end = (at + delete).min(n);
        bytes.drain(at..end);
        bytes.truncate(cut.max(1).min(bytes.len()));
        let _ = Model::from_bytes("mutated.ifc", bytes, &ReadOptions::default()).map(|m| m.pieces().len());
    }
}
