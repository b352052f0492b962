//! Files written by real authoring tools load with their pieces and honest
//! warnings.

mod common;

use framewright::ifc::Model;
use std::path::PathBuf;

fn realworld(name: &str) -> Option<PathBuf> {
    common::shared_path(&format!("ifc-realworld/{name}"))
}

const INCH: f64 = 0.0254;
const FOOT: f64 = 0.3048;

#[test]
fn every_file_loads() {
    let Some(dir) = common::shared_path("ifc-realworld") else {
        return;
    };
    let entries = std::fs::read_dir(&dir).unwrap();
    let mut files: Vec<PathBuf> = entries
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|x| x == "ifc"))
        .collect();
    files.sort();
    assert!(files.len() >= 10);
    for path in files {
        let model = Model::open(&path).unwrap_or_else(|e| panic!("{e}"));
        for piece in model.pieces() {
            let b = &piece.obox;
            assert!(
                b.length() > 0.0 && b.width() >= b.thickness() && b.thickness() > 0.0,
                "{}: {}",
                path.display(),
                piece.id
            );
        }
        // Warnings always name an entity or say why they cannot.
        for w in &model.warnings {
            assert!(!w.message.is_empty());
        }
    }
}

#[test]
fn constructivity_wall_yields_32_mapped_pieces() {
    for name in [
        "timber_constructivity_wall-elemented-case_IFC4.ifc",
        "timber_constructivity_wall-elemented-case_IFC4X3_ADD2.ifc",
    ] {
        let Some(path) = realworld(name) else { return };
        let model = Model::open(&path).unwrap();
        assert_eq!(model.length_unit.name, "INCH");
        assert!((model.length_unit.metres_per_unit - INCH).abs() < 1e-12);
        assert_eq!(model.pieces().len(), 32, "{name}");
        let tracks = model
            .pieces()
            .iter()
            .filter(|p| p.name.as_deref() == Some("Track"))
            .count();
        assert_eq!(tracks, 12);
        // Every piece is 2x4 lumber (1.5 x 3.5 in), scaled only along its length.
        for p in model.pieces() {
            assert!((p.obox.width() - 3.5 * INCH).abs() < 1e-6, "{}", p.id);
            assert!((p.obox.thickness() - 1.5 * INCH).abs() < 1e-6, "{}", p.id);
            assert!(p.id.starts_with(&p.global_id) && p.piece.is_some());
        }
        // Full-height studs of the 120 in wall: 117 in between 1.5 in tracks.
        let full = model
            .pieces()
            .iter()
            .filter(|p| (p.obox.length() - 117.0 * INCH).abs() < 1e-4)
            .count();
        assert!(full >= 8, "{full} full-height studs");
        // The 4 geometry-less template members are reported, not silently dropped.
        assert_eq!(
            model
                .warnings
                .iter()
                .filter(|w| w.message.contains("template"))
                .count(),
            4
        );
        // Members aggregate into the frame assembly, which belongs to the wall.
        let parent = model
            .groups
            .get(&model.pieces()[0].parent.unwrap())
            .unwrap();
        assert_eq!(parent.ifc_type, "IfcElementAssembly");
        let wall = model.groups.get(&parent.parent.unwrap()).unwrap();
        assert!(wall.ifc_type.starts_with("IfcWall"));
    }
}

#[test]
fn autotimber_building_in_feet() {
    let Some(path) =
        realworld("timber_autotimber-xbim-generated_outer-walls-5-framed_IFC4_feet.ifc")
    else {
        return;
    };
    let model = Model::open(&path).unwrap();
    assert_eq!(model.length_unit.name, "FOOT");
    let studs: Vec<_> = model
        .pieces()
        .iter()
        .filter(|p| p.ifc_type == "IfcColumnStandardCase")
        .collect();
    let plates: Vec<_> = model
        .pieces()
        .iter()
        .filter(|p| p.ifc_type == "IfcBeamStandardCase")
        .collect();
    assert_eq!(studs.len(), 510);
    assert_eq!(plates.len(), 10);
    for s in &studs {
        assert!((s.obox.length() - 10.0 * FOOT).abs() < 1e-6);
        assert!(s.obox.axes[0].z.abs() > 0.999, "studs stand upright");
    }
    for p in &plates {
        // Flat slabs: the wall length, 0.5 ft wide, 2 in thick.
        let len_ft = p.obox.length() / FOOT;
        assert!((36.0..92.0).contains(&len_ft), "{len_ft}");
        assert!((p.obox.width() - 0.5 * FOOT).abs() < 1e-6);
        assert!((p.obox.thickness() - 0.1667 * FOOT).abs() < 1e-6);
        assert!(p.obox.axes[0].z.abs() < 1e-9, "plates lie flat");
    }
    // The zero-vector RefDirections are repaired with a warning naming them.
    assert_eq!(
        model
            .warnings
            .iter()
            .filter(|w| w.message.contains("zero-length"))
            .count(),
        10
    );
}

#[test]
fn cr_only_file_with_undoubled_quote_escape() {
    let Some(path) = realworld("general_vectorworks2013_japanese-S-X-escapes-CRonly_IFC2X3.ifc")
    else {
        return;
    };
    let model = Model::open(&path).unwrap();
    assert_eq!(model.pieces().len(), 8);
    assert!(model.header().file_name.ends_with("AC16_sjis-VW-sjis.ifc"));
}

#[test]
fn x2_escapes_decode() {
    let Some(path) = realworld("general_revit2014_japanese-X2-escapes_IFC2X3.ifc") else {
        return;
    };
    let model = Model::open(&path).unwrap();
    assert_eq!(model.header().file_name, "プロジェクト番号");
    assert_eq!(model.pieces().len(), 8);
    let label = |p: &framewright::ifc::Piece| format!("{:?} {:?}", p.name, p.object_type);
    assert!(
        model.pieces().iter().any(|p| label(p).contains("二階柱")),
        "{:?}",
        model.pieces().iter().map(label).collect::<Vec<_>>()
    );
}

#[test]
fn archicad_rafters_are_read_from_mapped_breps() {
    let Some(path) = realworld("timber_archicad20_FZK-Haus-roof-rafters_IFC4.ifc") else {
        return;
    };
    let model = Model::open(&path).unwrap();
    let rafters = model
        .pieces()
        .iter()
        .filter(|p| p.ifc_type == "IfcMember")
        .count();
    assert_eq!(rafters, 42);
}
