//! Shared by the frame reasoning tests: the truth models (the shared test
//! cases when `../shared` is present, and the project's own models), and the
//! rule base's relations over them.
#![allow(dead_code)]

#[path = "../common/skip.rs"]
mod skip;

use framewright::frame::{Ask, Reasoned, RuleEngine, model_facts};
use framewright::geom::ContactOptions;
use framewright::ifc::Model;
use framewright::logic::Value;
use serde_json::Value as Json;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// One model with its truth.
pub struct Case {
    pub name: String,
    pub ifc: PathBuf,
    pub truth: Json,
}

fn truth_files(dir: &Path) -> Vec<PathBuf> {
    let mut files: Vec<PathBuf> = std::fs::read_dir(dir)
        .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
        .map(|e| e.unwrap().path())
        .filter(|p| p.to_string_lossy().ends_with(".truth.json"))
        .collect();
    files.sort();
    assert!(!files.is_empty(), "no truth files in {}", dir.display());
    files
}

fn cases_in(files: Vec<PathBuf>) -> Vec<Case> {
    files
        .into_iter()
        .map(|truth_path| {
            let ifc = PathBuf::from(truth_path.to_string_lossy().replace(".truth.json", ".ifc"));
            let name = ifc.file_name().unwrap().to_string_lossy().into_owned();
            let text = std::fs::read_to_string(&truth_path).unwrap();
            Case {
                name,
                ifc,
                truth: serde_json::from_str(&text).unwrap(),
            }
        })
        .collect()
}

/// The shared truth models, or None (with a message) when `../shared` is absent.
pub fn shared_cases() -> Option<Vec<Case>> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/ifc-testcases");
    if !dir.is_dir() {
        skip::missing_data(&dir);
        return None;
    }
    Some(cases_in(truth_files(&dir)))
}

/// The project's own truth models: bundled examples and `synth` fixtures.
pub fn own_cases() -> Vec<Case> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut files = truth_files(&root.join("examples/models"));
    files.extend(truth_files(&root.join("tests/fixtures")));
    cases_in(files)
}

/// The rule base's relations over a model.
pub fn reasoned(case: &Case, engine: &RuleEngine) -> Reasoned {
    let model = Model::open(&case.ifc).unwrap_or_else(|e| panic!("{}: {e}", case.name));
    let facts = model_facts(&model, &ContactOptions::default());
    Ask::new(engine)
        .over(&facts)
        .unwrap_or_else(|e| panic!("{}: {e}", case.name))
}

pub fn sym(v: &Value) -> &str {
    v.as_symbol().expect("a symbol")
}

pub fn float(v: &Value) -> f64 {
    v.as_float().expect("a float")
}

/// A binary relation `rel(p: symbol, x)` as a map from p to x (panics on a second x).
pub fn by_piece<'a>(r: &'a Reasoned, relation: &str) -> BTreeMap<&'a str, &'a Value> {
    let mut map = BTreeMap::new();
    for t in r.get(relation) {
        if let Some(old) = map.insert(sym(&t[0]), &t[1]) {
            panic!("{relation}: {} has both {old} and {}", sym(&t[0]), t[1]);
        }
    }
    map
}

pub fn members(truth: &Json) -> &Vec<Json> {
    truth["members"].as_array().expect("members")
}

pub fn walls(truth: &Json) -> &Vec<Json> {
    truth["walls"].as_array().expect("walls")
}

/// An array field of a truth object (empty when absent or null).
pub fn list<'a>(v: &'a Json, field: &str) -> &'a [Json] {
    v[field].as_array().map_or(&[], Vec::as_slice)
}

pub fn text(v: &Json) -> &str {
    v.as_str().expect("a string")
}

pub fn number(v: &Json) -> f64 {
    v.as_f64().expect("a number")
}

/// Models nobody tuned the rules on: buildings from the project's generator
/// with pseudo-random sizes, lumber, stud spacing, openings, IFC classes,
/// units and grouping, turned by a random angle about the vertical; written
/// with their truth into a temporary directory.
pub struct Synthetic {
    _dir: tempfile::TempDir,
    pub cases: Vec<Case>,
}

/// A small deterministic generator (64-bit LCG) so failures reproduce.
struct Lcg(u64);

impl Lcg {
    fn next(&mut self) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }
    fn range(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.next()
    }
    fn pick<T: Copy>(&mut self, items: &[T]) -> T {
        items[((self.next() * items.len() as f64) as usize).min(items.len() - 1)]
    }
}

/// Up to two openings that fit in a wall of `length` and `height` under
/// `top_plates` plates of thickness `t`. Some headers sit tight under the top
/// plate or 10 mm below it (no room for cripples).
fn random_openings(
    rng: &mut Lcg,
    length: f64,
    height: f64,
    top_plates: f64,
    t: f64,
) -> Vec<synth::wall::OpeningSpec> {
    use synth::wall::{OpeningKind, OpeningSpec};
    let mut openings = Vec::new();
    let mut u = 0.3;
    for _ in 0..rng.pick(&[0usize, 1, 1, 2, 2]) {
        let width = rng.range(0.5, 1.6);
        if u + width + 0.35 > length {
            break;
        }
        let start = rng.range(u, (length - width - 0.35).max(u));
        // A 2x10 header (spans up to 6 ft) is 9-1/4 in deep.
        let stud_top = height - top_plates * t;
        let top = match rng.pick(&[0, 0, 1, 2]) {
            0 => height - rng.range(0.45, 0.6),
            1 => stud_top - 0.23495,
            _ => stud_top - 0.23495 - 0.01,
        };
        let kind = if rng.next() < 0.4 {
            OpeningKind::Door
        } else {
            OpeningKind::Window {
                sill: rng.range(0.5, (top - 0.6).min(1.1)),
            }
        };
        let bottom = match kind {
            OpeningKind::Door => 0.0,
            OpeningKind::Window { sill } => sill,
        };
        openings.push(OpeningSpec {
            kind,
            u: start,
            width,
            height: top - bottom,
        });
        u = start + width + 0.5;
    }
    openings
}

use framewright::synth;

/// Turns the whole layout by `angle` about the vertical through the world origin.
fn turn(layout: &mut synth::Layout, angle: f64) {
    let r = nalgebra::Rotation3::from_axis_angle(&nalgebra::Vector3::z_axis(), angle);
    for b in &mut layout.buildings {
        b.origin = r * b.origin;
        for w in b.storeys.iter_mut().flat_map(|s| s.walls.iter_mut()) {
            let f = &mut w.frame;
            (f.origin, f.u, f.v, f.w) = (r * f.origin, r * f.u, r * f.v, r * f.w);
            for p in &mut w.pieces {
                (p.start, p.end, p.width_dir) = (r * p.start, r * p.end, r * p.width_dir);
            }
        }
    }
}

pub fn synthetic_cases(count: usize) -> Synthetic {
    use synth::building::{BuildingSpec, frame_building};
    use synth::wall::{HeaderStyle, StudLayout};
    use synth::{Grouping, LengthUnit, Lumber, ProductClasses, WriteOptions, write_ifc};
    let dir = tempfile::tempdir().expect("a temporary directory");
    let mut rng = Lcg(20_261_121);
    let mut cases = Vec::new();
    let inch = 0.0254;
    while cases.len() < count {
        let n = cases.len();
        let lumber = rng.pick(&[Lumber::L2X4, Lumber::L2X6]);
        let height = rng.range(2.3, 3.0);
        let (length, depth) = (rng.range(3.0, 9.0), rng.range(2.5, 7.0));
        let depth_t = lumber.width;
        let lengths = [length, depth - 2.0 * depth_t, length, depth - 2.0 * depth_t];
        let double_top_plate = rng.next() < 0.7;
        let top_plates = if double_top_plate { 2.0 } else { 1.0 };
        let t = lumber.thickness;
        let spec = BuildingSpec {
            length,
            depth,
            height,
            lumber,
            studs: StudLayout::OnCentre(rng.pick(&[12.0, 16.0, 19.2, 24.0]) * inch),
            double_top_plate,
            header_style: rng.pick(&[HeaderStyle::BuiltUp, HeaderStyle::Solid]),
            openings: lengths.map(|l| random_openings(&mut rng, l, height, top_plates, t)),
        };
        let name = format!("synthetic_{n}");
        let Ok(building) = frame_building(&spec, "Building", nalgebra::Vector3::zeros(), "") else {
            continue; // openings the generator refuses (too close, too tall): draw again
        };
        let mut layout = synth::Layout {
            name: name.clone(),
            description: "random building".into(),
            buildings: vec![building],
        };
        turn(&mut layout, rng.range(-3.1, 3.1));
        let options = WriteOptions {
            unit: rng.pick(&[LengthUnit::Metre, LengthUnit::Millimetre, LengthUnit::Foot]),
            products: rng.pick(&[ProductClasses::Member, ProductClasses::ColumnBeam]),
            grouping: rng.pick(&[Grouping::None, Grouping::Wall, Grouping::Assembly]),
            seed: n as u64,
            file_name: format!("{name}.ifc"),
            ..WriteOptions::default()
        };
        let written = write_ifc(&layout, &options).expect("the generator writes its layout");
        let ifc = dir.path().join(&options.file_name);
        std::fs::write(&ifc, &written.ifc).unwrap();
        cases.push(Case {
            name: format!("{name} ({spec:?}, {options:?})"),
            ifc,
            truth: serde_json::to_value(&written.truth).unwrap(),
        });
    }
    Synthetic { _dir: dir, cases }
}
