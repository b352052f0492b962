use super::*;
use crate::frame::{Ask, cell_facts, model_facts};
use crate::geom::ContactOptions;
use crate::ifc::Model;

/// The mirrored storey extent equals the rules' `storey_reach`, bit for bit, on models
/// with exterior and interior walls, several storeys and openings.
#[test]
fn the_storey_extent_check_computes_what_the_rule_derives() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    let cell = Cell::load("study-abb").unwrap();
    let mut checked = 0;
    for model in [
        Model::open(dir.join("examples/models/tm3.ifc")).unwrap(),
        small_block(),
    ] {
        let mut facts = model_facts(&model, &ContactOptions::default());
        facts.extend(cell_facts(&cell));
        let partition = Partition::of(&facts);
        let extents = Extents::of(&facts, &partition);
        let reasoned = Ask::new(&crate::frame::RuleEngine::Compiled)
            .only(&[REACH])
            .over(&facts)
            .unwrap();
        for row in reasoned.get(REACH) {
            let c = extents.index[row[0].as_symbol().unwrap()];
            let Value::Vec3(k) = &row[1] else { panic!() };
            let want = (row[2].as_float().unwrap(), row[3].as_float().unwrap());
            let got = extents.along(c, *k).unwrap();
            assert_eq!(
                (got.0.0.to_bits(), got.1.0.to_bits()),
                (want.0.to_bits(), want.1.to_bits())
            );
            checked += 1;
        }
    }
    assert!(checked >= 6, "only {checked} storey_reach rows checked");
}

/// Two storeys of two units with openings, members grouped in IfcWall.
fn small_block() -> Model {
    use crate::synth::building::{BlockSpec, blocks};
    use crate::synth::{Grouping, WriteOptions, models, write_ifc};
    let spec = BlockSpec::new(models::default_building_spec(), 1, 2, 1, 2);
    let layout = blocks(&spec, "small").unwrap();
    let written = write_ifc(
        &layout,
        &WriteOptions {
            grouping: Grouping::Wall,
            openings: true,
            file_name: "small.ifc".into(),
            ..WriteOptions::default()
        },
    )
    .unwrap();
    Model::from_bytes("small.ifc", written.ifc.into_bytes(), &Default::default()).unwrap()
}

fn facts_of(model: &Model, cell: &Cell) -> Facts {
    let mut facts = model_facts(model, &ContactOptions::default());
    facts.extend(cell_facts(cell));
    facts
}

/// What `plan` reasons without the cache.
fn uncached(facts: &Facts, cell: &Cell) -> Relations {
    let mut facts = facts.clone();
    let engine = crate::frame::RuleEngine::Compiled;
    Ask::new(&engine).place(&mut facts, cell).unwrap();
    Ask::new(&engine)
        .only(Plan::RELATIONS)
        .over(&facts)
        .unwrap()
        .relations
}

/// Every wall lies in one part, and so does every coplanar pair the rules find.
#[test]
fn parts_hold_whole_walls() {
    let cell = Cell::load("study-abb").unwrap();
    let facts = facts_of(&small_block(), &cell);
    let partition = Partition::of(&facts);
    let part_of: FxHashMap<&str, usize> = partition
        .parts
        .iter()
        .enumerate()
        .flat_map(|(k, p)| p.pieces.iter().map(move |id| (id.as_str(), k)))
        .collect();
    let r = uncached(&facts, &cell);
    let mut walls: FxHashMap<&str, usize> = FxHashMap::default();
    for t in &r["wall_of"] {
        let (p, w) = (t[0].as_symbol().unwrap(), t[1].as_symbol().unwrap());
        assert_eq!(
            *walls.entry(w).or_insert(part_of[p]),
            part_of[p],
            "wall {w}"
        );
    }
    for t in &r["coplanar"] {
        let (a, b) = (t[0].as_symbol().unwrap(), t[1].as_symbol().unwrap());
        assert_eq!(part_of[a], part_of[b]);
    }
    // The units' walls meet at corners, yet most walls are parts of their own.
    assert!(walls.len() >= 16, "{} walls", walls.len());
    assert!(
        partition.parts.len() >= walls.len(),
        "{} parts",
        partition.parts.len()
    );
}

/// Cold, warm and after an edit of one stud (recomputed alone, its storey as context),
/// the cached reasoning gives what the uncached one gives, tuple for tuple and in order.
#[test]
fn cached_reasoning_equals_the_uncached() {
    let cell = Cell::load("study-abb").unwrap();
    let mut facts = facts_of(&small_block(), &cell);
    let dir = tempfile::tempdir().unwrap();
    let cache = Cache::new(dir.path());
    let limits = RuleLimits::default();
    let want = uncached(&facts, &cell);
    let (cold, counts) = reason_plan_cached(facts.clone(), &cell, &cache, &limits).unwrap();
    assert_eq!(cold.relations, want);
    let walls = want["wall"].len();
    assert_eq!((counts.computed, counts.cached), (walls, 0));
    let (warm, counts) = reason_plan_cached(facts.clone(), &cell, &cache, &limits).unwrap();
    assert_eq!(warm.relations, want);
    assert_eq!((counts.computed, counts.cached), (0, walls));

    // Move one stud 20 mm along its wall (its box's thickness axis runs along the wall).
    let role = &want["role"];
    let stud = role
        .iter()
        .find(|t| t[1].as_symbol() == Some("stud"))
        .and_then(|t| t[0].as_symbol())
        .unwrap()
        .to_string();
    for (t, _) in facts.tuples.get_mut("piece_box").unwrap() {
        if t[0].as_symbol() == Some(stud.as_str())
            && let Value::Box(b) = &t[1]
        {
            let mut moved = **b;
            moved.pose.translation.vector += moved.axis(2) * 0.02;
            t[1] = Value::Box(std::sync::Arc::new(moved));
        }
    }
    let want = uncached(&facts, &cell);
    let (edited, counts) = reason_plan_cached(facts.clone(), &cell, &cache, &limits).unwrap();
    assert_eq!(edited.relations, want);
    assert_eq!(counts.computed, 1, "only the stud's wall is reasoned again");
    assert_eq!(counts.cached, walls - 1);

    // Half the entries gone: whole storeys are reasoned again, split and stored. (The entries
    // are written behind: wait for them, or a listing may catch one still being renamed.)
    cache.wait_for_writes();
    let mut files: Vec<std::path::PathBuf> = walkdir(&dir.path().join("plans"));
    files.sort();
    for f in files.iter().step_by(2) {
        std::fs::remove_file(f).unwrap();
    }
    let (again, counts) = reason_plan_cached(facts.clone(), &cell, &cache, &limits).unwrap();
    assert_eq!(again.relations, want);
    assert!(
        counts.computed > walls / 4 && counts.cached > 0,
        "{counts:?}"
    );
    let (warm, counts) = reason_plan_cached(facts.clone(), &cell, &cache, &limits).unwrap();
    assert_eq!(warm.relations, want);
    assert_eq!((counts.computed, counts.cached), (0, walls));
}

fn walkdir(dir: &std::path::Path) -> Vec<std::path::PathBuf> {
    let mut out = Vec::new();
    for e in std::fs::read_dir(dir).unwrap().flatten() {
        if e.path().is_dir() {
            out.extend(walkdir(&e.path()));
        } else {
            out.push(e.path());
        }
    }
    out
}

/// A share written in place is the entry its owned copy gives.
#[test]
fn a_share_encodes_as_its_owned_relations() {
    let cell = Cell::load("study-abb").unwrap();
    let facts = facts_of(&small_block(), &cell);
    let partition = Partition::of(&facts);
    let out = uncached(&facts, &cell);
    let parts: Vec<usize> = (0..partition.parts.len()).collect();
    let shares = shares(&partition, &parts, &out);
    let mut walls = 0;
    for (k, share) in shares.iter().enumerate() {
        let owned = owned_share(&out, share);
        walls += owned["wall"].len();
        assert_eq!(
            encode_share("k", &out, share),
            encode("k", &owned),
            "part {k}"
        );
    }
    assert_eq!(walls, out["wall"].len(), "every wall in one part");
}

#[test]
fn entries_come_back_and_torn_altered_or_foreign_ones_do_not() {
    let mut r = Relations::new();
    r.insert("wall".into(), vec![vec![Value::sym("w1")]]);
    let bytes = encode("k1", &r);
    assert_eq!(decode("k1", &bytes), Some(r));
    assert_eq!(decode("k2", &bytes), None);
    assert_eq!(decode("k1", &bytes[..bytes.len() - 1]), None);
    let mut altered = bytes.clone();
    altered[MAGIC.len() + 12] ^= 1;
    assert_eq!(decode("k1", &altered), None);
}
