//! Multi-storey blocks (`synth block`): the reader finds every member on the storey the
//! layout put it on, each framing product carries one property set, and every rough
//! opening of a grouped wall gets an opening element and a door or window.
use framewright::ifc::Model;
use framewright::synth::building::{BlockSpec, blocks};
use framewright::synth::{Grouping, WriteOptions, models, write_ifc};
use std::collections::BTreeMap;

fn spec() -> BlockSpec {
    BlockSpec::new(models::default_building_spec(), 2, 3, 1, 2)
}

fn count(text: &str, entity: &str) -> usize {
    text.matches(&format!("={entity}(")).count()
}

#[test]
fn every_member_stands_on_its_storey_with_one_property_set() {
    let spec = spec();
    let layout = blocks(&spec, "blocks").expect("layout");
    let opts = WriteOptions {
        grouping: Grouping::Wall,
        property_sets: true,
        openings: true,
        ..WriteOptions::default()
    };
    let written = write_ifc(&layout, &opts).expect("write");
    let truth = &written.truth;
    // 2 blocks x 3 storeys x 2 units x 4 walls.
    assert_eq!(truth.counts.walls, 48);
    assert_eq!(truth.counts.buildings, 2);
    let text = &written.ifc;
    assert_eq!(count(text, "IFCBUILDINGSTOREY"), 6);
    assert_eq!(
        count(text, "IFCRELDEFINESBYPROPERTIES"),
        truth.counts.members
    );
    assert_eq!(count(text, "IFCPROPERTYSET"), truth.counts.members);
    let openings: usize = truth.walls.iter().map(|w| w.openings.len()).sum();
    assert!(openings > 0);
    assert_eq!(count(text, "IFCOPENINGELEMENT"), openings);
    assert_eq!(count(text, "IFCRELVOIDSELEMENT"), openings);
    assert_eq!(count(text, "IFCRELFILLSELEMENT"), openings);
    assert_eq!(count(text, "IFCDOOR") + count(text, "IFCWINDOW"), openings);

    let dir = tempfile::tempdir().expect("temp dir");
    let path = dir.path().join("blocks.ifc");
    std::fs::write(&path, text).expect("write model");
    let model = Model::open(&path).expect("read");
    assert_eq!(model.pieces().len(), truth.counts.members);
    let storey_height = spec.unit.height + spec.floor_depth;
    let truth_storey: BTreeMap<&str, &str> = truth
        .members
        .iter()
        .map(|m| (m.global_id.as_str(), m.storey.as_str()))
        .collect();
    for p in model.pieces() {
        let storey = p
            .container
            .and_then(|c| model.groups.get(&c))
            .expect("every member is contained");
        assert_eq!(storey.ifc_type, "IfcBuildingStorey");
        let name = storey.name.as_deref().expect("storey name");
        assert_eq!(truth_storey.get(p.global_id.as_str()), Some(&name));
        let level: f64 = name
            .strip_prefix("Level ")
            .and_then(|n| n.parse().ok())
            .expect("Level N");
        let floor = (level - 1.0) * storey_height;
        let z = p.obox.centre.z;
        assert!(
            z > floor && z < floor + spec.unit.height,
            "{} at z = {z} is not on {name} ({floor}..{})",
            p.id,
            floor + spec.unit.height
        );
    }
}

#[test]
fn bad_block_sizes_are_refused() {
    let mut s = spec();
    s.storeys = 0;
    assert!(blocks(&s, "b").is_err());
    let mut s = spec();
    s.floor_depth = 0.0;
    assert!(blocks(&s, "b").is_err());
}
