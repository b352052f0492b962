//! The named models: the study's three test models, a default wall and a default building.
use crate::synth::SynthError;
use crate::synth::building::{BuildingSpec, frame_building};
use crate::synth::layout::{BuildingLayout, Layout, Vec3, WallFrame};
use crate::synth::units::{Lumber, feet, inches};
use crate::synth::wall::{
    HeaderStyle, OpeningKind, OpeningSpec, StudLayout, WallSpec, frame_wall, precut_stud,
};

/// Wall with studs 16 in on centre.
pub fn sixteen_on_centre() -> StudLayout {
    StudLayout::OnCentre(inches(16.0))
}

/// An 8 ft wall: precut studs, bottom plate, double top plate.
pub fn eight_foot_height() -> f64 {
    precut_stud() + 3.0 * Lumber::L2X4.thickness
}

/// A layout of one wall standing at the origin, u along +x, outer face at y = 0.
pub fn single_wall(name: &str, description: &str, spec: &WallSpec) -> Result<Layout, SynthError> {
    let frame = WallFrame::upright(Vec3::zeros(), Vec3::new(1.0, 0.0, 0.0));
    let wall = frame_wall(spec, frame)?;
    Ok(Layout {
        name: name.to_string(),
        description: description.to_string(),
        buildings: vec![BuildingLayout::one_storey(
            "Building",
            Vec3::zeros(),
            vec![wall],
        )],
    })
}

fn end_stud_frame(id: &str, name: &str, length: f64, height: f64, lumber: Lumber) -> WallSpec {
    WallSpec {
        id: id.into(),
        name: name.into(),
        length,
        height,
        lumber,
        studs: StudLayout::EndsOnly,
        double_top_plate: false,
        header_style: HeaderStyle::BuiltUp,
        detail: Default::default(),
        openings: vec![],
    }
}

/// TM1: a 2x4 square frame around a 3 ft x 3 ft opening (39 in plates, 36 in studs).
pub fn tm1() -> Layout {
    let spec = end_stud_frame(
        "TM1",
        "Test model 1 frame",
        inches(39.0),
        inches(39.0),
        Lumber::L2X4,
    );
    single_wall(
        "tm1",
        "Test model 1: 2x4 square frame around a 3 ft x 3 ft opening",
        &spec,
    )
    .expect("TM1 constants are valid")
}

/// TM2: a 2x6 frame 6 ft long and 5 ft high.
pub fn tm2() -> Layout {
    let spec = end_stud_frame(
        "TM2",
        "Test model 2 frame",
        feet(6.0),
        feet(5.0),
        Lumber::L2X6,
    );
    single_wall("tm2", "Test model 2: 2x6 frame 6 ft long, 5 ft high", &spec)
        .expect("TM2 constants are valid")
}

/// TM3's walls: 22.5 ft front and back, 88.8 in sides between them, 2x4 at 16 in on centre.
pub fn tm3_spec() -> BuildingSpec {
    BuildingSpec {
        length: feet(22.5),
        depth: inches(88.8) + 2.0 * Lumber::L2X4.width,
        height: eight_foot_height(),
        lumber: Lumber::L2X4,
        studs: sixteen_on_centre(),
        double_top_plate: true,
        header_style: HeaderStyle::BuiltUp,
        openings: Default::default(),
    }
}

/// TM3: four 8 ft walls forming a rectangle (62 members).
pub fn tm3() -> Layout {
    let building = frame_building(&tm3_spec(), "Building", Vec3::zeros(), "")
        .expect("TM3 constants are valid");
    Layout {
        name: "tm3".into(),
        description: "Test model 3: four 8 ft 2x4 walls, 16 in on centre, double top plate".into(),
        buildings: vec![building],
    }
}

/// A 3 ft x 6 ft 10-1/2 in door rough opening at `u`.
pub fn door_at(u: f64) -> OpeningSpec {
    OpeningSpec {
        kind: OpeningKind::Door,
        u,
        width: inches(38.0),
        height: inches(82.5),
    }
}

/// A 3 ft x 4 ft window rough opening at `u`, 32 in above the floor.
pub fn window_at(u: f64) -> OpeningSpec {
    OpeningSpec {
        kind: OpeningKind::Window { sill: inches(32.0) },
        u,
        width: inches(36.0),
        height: inches(48.0),
    }
}

/// The default building: 30 ft x 20 ft, 8 ft walls, a door and windows.
pub fn default_building_spec() -> BuildingSpec {
    BuildingSpec {
        length: feet(30.0),
        depth: feet(20.0),
        height: eight_foot_height(),
        lumber: Lumber::L2X4,
        studs: sixteen_on_centre(),
        double_top_plate: true,
        header_style: HeaderStyle::BuiltUp,
        openings: [
            vec![door_at(feet(6.0)), window_at(feet(18.0))],
            vec![window_at(feet(7.0))],
            vec![window_at(feet(6.0)), window_at(feet(20.0))],
            vec![window_at(feet(7.0))],
        ],
    }
}
