//! The IFC writer: output is well-formed STEP (checked by a small independent
//! parser here), byte-deterministic, schema-correct in attribute counts, and its
//! placements put every piece where the truth sidecar says.
use framewright::ifc::guid;
use framewright::step::text::string;
use framewright::synth::building::grid;
use framewright::synth::models;
use framewright::synth::units::LengthUnit;
use framewright::synth::{
    Grouping, Layout, PlacementBase, ProductClasses, Schema, SynthError, WriteOptions, write_ifc,
};
use nalgebra::{Matrix4, Vector3, Vector4};
use std::collections::BTreeMap;

/// A parsed attribute value.
#[derive(Debug, Clone, PartialEq)]
enum V {
    Ref(usize),
    Num(f64),
    Str(String),
    Enum(String),
    List(Vec<V>),
    Typed(String, Box<V>),
    Unset,
    Derived,
}

struct Parser<'a> {
    s: &'a [u8],
    i: usize,
}

impl Parser<'_> {
    fn list(&mut self) -> Result<Vec<V>, String> {
        let mut out = Vec::new();
        if self.s.get(self.i) != Some(&b'(') {
            return Err(format!("expected ( at {}", self.i));
        }
        self.i += 1;
        if self.s.get(self.i) == Some(&b')') {
            self.i += 1;
            return Ok(out);
        }
        loop {
            out.push(self.value()?);
            match self.s.get(self.i) {
                Some(b',') => self.i += 1,
                Some(b')') => {
                    self.i += 1;
                    return Ok(out);
                }
                other => {
                    return Err(format!(
                        "expected , or ) at {} got {:?}",
                        self.i,
                        other.map(|c| *c as char)
                    ));
                }
            }
        }
    }

    fn value(&mut self) -> Result<V, String> {
        let c = *self.s.get(self.i).ok_or("unexpected end")?;
        let start = self.i;
        match c {
            b'$' => {
                self.i += 1;
                Ok(V::Unset)
            }
            b'*' => {
                self.i += 1;
                Ok(V::Derived)
            }
            b'#' => {
                self.i += 1;
                while self.s.get(self.i).is_some_and(|c| c.is_ascii_digit()) {
                    self.i += 1;
                }
                let n = std::str::from_utf8(&self.s[start + 1..self.i]).unwrap();
                Ok(V::Ref(
                    n.parse().map_err(|_| format!("bad ref at {start}"))?,
                ))
            }
            b'\'' => {
                self.i += 1;
                let mut text = Vec::new();
                loop {
                    match self.s.get(self.i) {
                        None => return Err("unterminated string".into()),
                        Some(b'\'') if self.s.get(self.i + 1) == Some(&b'\'') => {
                            text.push(b'\'');
                            self.i += 2;
                        }
                        Some(b'\'') => {
                            self.i += 1;
                            break;
                        }
                        Some(&b) if !(0x20..=0x7e).contains(&b) => {
                            return Err("non-ASCII byte in a string".into());
                        }
                        Some(&b) => {
                            text.push(b);
                            self.i += 1;
                        }
                    }
                }
                Ok(V::Str(String::from_utf8(text).unwrap()))
            }
            b'.' => {
                let end = self.s[start + 1..]
                    .iter()
                    .position(|&c| c == b'.')
                    .ok_or("unterminated enum")?;
                self.i = start + end + 2;
                Ok(V::Enum(
                    String::from_utf8(self.s[start + 1..start + 1 + end].to_vec()).unwrap(),
                ))
            }
            b'(' => Ok(V::List(self.list()?)),
            b'A'..=b'Z' => {
                while self
                    .s
                    .get(self.i)
                    .is_some_and(|c| c.is_ascii_alphanumeric() || *c == b'_')
                {
                    self.i += 1;
                }
                let name = String::from_utf8(self.s[start..self.i].to_vec()).unwrap();
                let mut inner = self.list()?;
                if inner.len() != 1 {
                    return Err("typed value needs one argument".into());
                }
                Ok(V::Typed(name, Box::new(inner.remove(0))))
            }
            _ => {
                while self
                    .s
                    .get(self.i)
                    .is_some_and(|c| c.is_ascii_digit() || b"+-.E".contains(c))
                {
                    self.i += 1;
                }
                let text = std::str::from_utf8(&self.s[start..self.i]).unwrap();
                if !text.contains('.') && !text.chars().all(|c| c.is_ascii_digit() || c == '-') {
                    return Err(format!("bad number {text}"));
                }
                Ok(V::Num(
                    text.parse()
                        .map_err(|_| format!("bad number '{text}' at {start}"))?,
                ))
            }
        }
    }
}

type Entities = BTreeMap<usize, (String, Vec<V>)>;

/// Entities of a file: id -> (NAME, attributes). Fails on anything malformed.
fn parse_step(text: &str) -> Result<(String, Entities), String> {
    let (header, rest) = text.split_once("DATA;\n").ok_or("no DATA section")?;
    if !header.starts_with("ISO-10303-21;\nHEADER;\n") || !header.ends_with("ENDSEC;\n") {
        return Err("bad header".into());
    }
    let schema = header
        .split("FILE_SCHEMA(('")
        .nth(1)
        .ok_or("no FILE_SCHEMA")?
        .split('\'')
        .next()
        .unwrap()
        .to_string();
    let data = rest
        .strip_suffix("ENDSEC;\nEND-ISO-10303-21;\n")
        .ok_or("bad trailer")?;
    let mut entities = BTreeMap::new();
    for (n, line) in data.lines().enumerate() {
        let err = |m: String| format!("data line {}: {m}: {line:.80}", n + 1);
        let (id, rest) = line
            .strip_prefix('#')
            .and_then(|l| l.split_once('='))
            .ok_or_else(|| err("not #n=".into()))?;
        let id: usize = id.parse().map_err(|_| err("bad id".into()))?;
        let open = rest.find('(').ok_or_else(|| err("no (".into()))?;
        let name = &rest[..open];
        if name.is_empty()
            || !name
                .bytes()
                .all(|c| c.is_ascii_uppercase() || c.is_ascii_digit())
        {
            return Err(err("bad entity name".into()));
        }
        let body = rest[open..]
            .strip_suffix(';')
            .ok_or_else(|| err("no ;".into()))?;
        let mut p = Parser {
            s: body.as_bytes(),
            i: 0,
        };
        let attrs = p.list().map_err(err)?;
        if p.i != body.len() {
            return Err(err("text after the closing parenthesis".into()));
        }
        if entities.insert(id, (name.to_string(), attrs)).is_some() {
            return Err(err("duplicate id".into()));
        }
    }
    fn refs(v: &V, out: &mut Vec<usize>) {
        match v {
            V::Ref(r) => out.push(*r),
            V::List(l) => l.iter().for_each(|x| refs(x, out)),
            V::Typed(_, x) => refs(x, out),
            _ => {}
        }
    }
    for (id, (_, attrs)) in &entities {
        let mut out = Vec::new();
        attrs.iter().for_each(|a| refs(a, &mut out));
        if let Some(r) = out.iter().find(|r| !entities.contains_key(r)) {
            return Err(format!("#{id} refers to undefined #{r}"));
        }
    }
    Ok((schema, entities))
}

fn num(v: &V) -> f64 {
    match v {
        V::Num(x) => *x,
        other => panic!("not a number: {other:?}"),
    }
}

fn nums(e: &Entities, r: &V) -> Vector3<f64> {
    let V::Ref(r) = r else {
        panic!("expected a ref, got {r:?}")
    };
    let V::List(l) = &e[r].1[0] else { panic!() };
    Vector3::new(num(&l[0]), num(&l[1]), l.get(2).map(num).unwrap_or(0.0))
}

/// Matrix of an IfcAxis2Placement3D (defaults for `$` axes).
fn a2p(e: &Entities, r: &V) -> Matrix4<f64> {
    let V::Ref(id) = r else { panic!() };
    let (name, at) = &e[id];
    assert_eq!(name, "IFCAXIS2PLACEMENT3D");
    let o = nums(e, &at[0]);
    let z = if at[1] == V::Unset {
        Vector3::z()
    } else {
        nums(e, &at[1]).normalize()
    };
    let x0 = if at[2] == V::Unset {
        Vector3::x()
    } else {
        nums(e, &at[2])
    };
    let x = (x0 - z * x0.dot(&z)).normalize();
    let y = z.cross(&x);
    let mut m = Matrix4::identity();
    for k in 0..3 {
        m[(k, 0)] = x[k];
        m[(k, 1)] = y[k];
        m[(k, 2)] = z[k];
        m[(k, 3)] = o[k];
    }
    m
}

fn local_placement(e: &Entities, r: &V) -> Matrix4<f64> {
    let V::Ref(id) = r else { panic!() };
    let (name, at) = &e[id];
    assert_eq!(name, "IFCLOCALPLACEMENT");
    let parent = if at[0] == V::Unset {
        Matrix4::identity()
    } else {
        local_placement(e, &at[0])
    };
    parent * a2p(e, &at[1])
}

fn apply(m: &Matrix4<f64>, p: Vector3<f64>) -> Vector3<f64> {
    (m * Vector4::new(p[0], p[1], p[2], 1.0)).xyz()
}

/// Every piece's centre line (start, end) in world file units, keyed by piece id.
fn centre_lines(e: &Entities) -> BTreeMap<String, (Vector3<f64>, Vector3<f64>)> {
    let mut out = BTreeMap::new();
    for (_, (name, at)) in e.iter() {
        if !["IFCMEMBER", "IFCCOLUMN", "IFCBEAM"].contains(&name.as_str()) {
            continue;
        }
        let V::Str(gid) = &at[0] else { panic!() };
        let place = local_placement(e, &at[5]);
        let V::Ref(pds) = &at[6] else { panic!() };
        let V::List(reps) = &e[pds].1[2] else {
            panic!()
        };
        let V::Ref(rep) = &reps[0] else { panic!() };
        let V::List(items) = &e[rep].1[3] else {
            panic!()
        };
        for (k, item) in items.iter().enumerate() {
            let V::Ref(item) = item else { panic!() };
            let (kind, ia) = &e[item];
            if kind == "IFCEXTRUDEDAREASOLID" {
                let pos = place * a2p(e, &ia[1]);
                let dir = nums(e, &ia[2]);
                out.insert(
                    gid.clone(),
                    (
                        apply(&pos, Vector3::zeros()),
                        apply(&pos, dir * num(&ia[3])),
                    ),
                );
            } else {
                assert_eq!(kind, "IFCMAPPEDITEM");
                let V::Ref(op) = &ia[1] else { panic!() };
                let oa = &e[op].1;
                let origin = nums(e, &oa[2]);
                let axis3 = nums(e, &oa[4]).normalize();
                let (s1, s3) = (num(&oa[3]), num(&oa[6]));
                assert_eq!(s1, 1.0);
                // The mapped source is a section extruded 1 unit along z.
                // DESIGN §3: a one-piece product's piece id is its GlobalId.
                let id = if items.len() == 1 {
                    gid.clone()
                } else {
                    format!("{gid}/{k}")
                };
                out.insert(
                    id,
                    (apply(&place, origin), apply(&place, origin + axis3 * s3)),
                );
            }
        }
    }
    out
}

fn variants() -> Vec<WriteOptions> {
    let mut v = Vec::new();
    for (schema, unit, products, grouping, mapped, placement) in [
        (
            Schema::Ifc4,
            LengthUnit::Metre,
            ProductClasses::ColumnBeam,
            Grouping::None,
            false,
            None,
        ),
        (
            Schema::Ifc4,
            LengthUnit::Inch,
            ProductClasses::Member,
            Grouping::Wall,
            false,
            None,
        ),
        (
            Schema::Ifc4,
            LengthUnit::Foot,
            ProductClasses::Member,
            Grouping::Assembly,
            true,
            None,
        ),
        (
            Schema::Ifc2x3,
            LengthUnit::Millimetre,
            ProductClasses::Member,
            Grouping::Wall,
            false,
            Some(PlacementBase::Storey),
        ),
        (
            Schema::Ifc2x3,
            LengthUnit::Foot,
            ProductClasses::ColumnBeam,
            Grouping::None,
            true,
            None,
        ),
        (
            Schema::Ifc4x3,
            LengthUnit::Inch,
            ProductClasses::Member,
            Grouping::Assembly,
            false,
            Some(PlacementBase::Storey),
        ),
        (
            Schema::Ifc4x3,
            LengthUnit::Metre,
            ProductClasses::Member,
            Grouping::Wall,
            true,
            Some(PlacementBase::Storey),
        ),
    ] {
        v.push(WriteOptions {
            schema,
            unit,
            products,
            grouping,
            mapped,
            placement,
            ..WriteOptions::default()
        });
    }
    v
}

fn models_to_check() -> Vec<Layout> {
    let mut building = grid(&models::default_building_spec(), 1, 2, 2.5, "pair").unwrap();
    building.description =
        "two buildings with doors and windows; a name with 'quotes', \\ and \u{e9}".into();
    vec![models::tm1(), models::tm3(), building]
}

#[test]
fn every_variant_is_well_formed_step_with_pieces_where_the_truth_says() {
    for layout in models_to_check() {
        for opts in variants() {
            let label = format!("{} {:?}", layout.name, opts);
            let written = write_ifc(&layout, &opts).unwrap();
            let (schema, e) = parse_step(&written.ifc).unwrap_or_else(|m| panic!("{label}: {m}"));
            assert_eq!(schema, opts.schema.header_name());
            let lines = centre_lines(&e);
            assert_eq!(lines.len(), layout.piece_count(), "{label}");
            let scale = 1.0 / opts.unit.metres_per_unit();
            for m in &written.truth.members {
                let (s, t) = lines
                    .get(&m.global_id)
                    .unwrap_or_else(|| panic!("{label}: {} not in file", m.global_id));
                let want_s = Vector3::from(m.axis_start) * scale;
                let want_t = Vector3::from(m.axis_end) * scale;
                assert!(
                    (s - want_s).norm() < 1e-6 * scale,
                    "{label} {}: start {s} vs {want_s}",
                    m.name
                );
                assert!(
                    (t - want_t).norm() < 1e-6 * scale,
                    "{label} {}: end {t} vs {want_t}",
                    m.name
                );
            }
        }
    }
}

/// Attribute counts of the entities whose arity differs between schemas.
#[test]
fn attribute_counts_follow_the_schema() {
    let arity = |schema: Schema, grouping: Grouping, mapped: bool| {
        let opts = WriteOptions {
            schema,
            grouping,
            mapped,
            unit: LengthUnit::Foot,
            ..WriteOptions::default()
        };
        let (_, e) = parse_step(&write_ifc(&models::tm3(), &opts).unwrap().ifc).unwrap();
        let mut seen: BTreeMap<String, usize> = BTreeMap::new();
        for (name, at) in e.values() {
            let old = seen.insert(name.clone(), at.len());
            assert!(
                old.is_none() || old == Some(at.len()),
                "{name} with two arities"
            );
        }
        seen
    };
    let a4 = arity(Schema::Ifc4, Grouping::Wall, false);
    let a2 = arity(Schema::Ifc2x3, Grouping::Wall, false);
    let a43 = arity(Schema::Ifc4x3, Grouping::Assembly, true);
    assert_eq!(
        (a4["IFCMEMBER"], a2["IFCMEMBER"], a43["IFCMEMBER"]),
        (9, 8, 9)
    );
    assert_eq!((a4["IFCWALL"], a2["IFCWALL"]), (9, 8));
    assert_eq!((a4["IFCMATERIAL"], a2["IFCMATERIAL"]), (3, 1));
    assert_eq!(a43["IFCELEMENTASSEMBLY"], 10);
    assert_eq!(a43["IFCCARTESIANTRANSFORMATIONOPERATOR3DNONUNIFORM"], 7);
    for a in [&a4, &a2, &a43] {
        assert_eq!(a["IFCCONVERSIONBASEDUNIT"], 4);
        assert_eq!(a["IFCSITE"], 14);
        assert_eq!(a["IFCBUILDING"], 12);
        assert_eq!(a["IFCBUILDINGSTOREY"], 10);
        assert_eq!(a["IFCRECTANGLEPROFILEDEF"], 5);
    }
}

#[test]
fn output_is_byte_deterministic_and_seeded() {
    let layout = models::tm3();
    let opts = WriteOptions {
        mapped: true,
        grouping: Grouping::Assembly,
        ..WriteOptions::default()
    };
    let a = write_ifc(&layout, &opts).unwrap();
    let b = write_ifc(&layout, &opts).unwrap();
    assert_eq!(a.ifc, b.ifc);
    assert_eq!(a.truth.to_json(), b.truth.to_json());
    let c = write_ifc(&layout, &WriteOptions { seed: 7, ..opts }).unwrap();
    assert_ne!(a.ifc, c.ifc);
    let opts = WriteOptions::default();
    let plain = write_ifc(&layout, &opts).unwrap();
    let ids: std::collections::BTreeSet<_> = plain
        .truth
        .members
        .iter()
        .map(|m| m.global_id.clone())
        .collect();
    assert_eq!(ids.len(), 62);
    assert!(ids.iter().all(|g| guid::is_valid(g)));
}

#[test]
fn truth_agrees_with_the_layout() {
    let layout = grid(&models::default_building_spec(), 1, 1, 0.0, "one").unwrap();
    let t = write_ifc(
        &layout,
        &WriteOptions {
            grouping: Grouping::Wall,
            ..WriteOptions::default()
        },
    )
    .unwrap()
    .truth;
    assert_eq!(t.counts.members, layout.piece_count());
    assert_eq!(t.walls.len(), 4);
    let mut k = 0;
    for (wall, tw) in layout.walls().zip(&t.walls) {
        assert_eq!(tw.member_global_ids.len(), wall.pieces.len());
        assert!(tw.wall_global_id.is_some());
        for (p, id) in wall.pieces.iter().zip(&tw.member_global_ids) {
            let m = &t.members[k];
            k += 1;
            assert_eq!(&m.global_id, id);
            assert_eq!(m.role, p.role.as_str());
            assert!((m.length - p.length()).abs() < 1e-8);
            assert!(m.width >= m.thickness);
            assert_eq!(m.wall_global_id, tw.wall_global_id);
            // Start is the bottom end of vertical members, the smaller-u end of horizontal ones.
            let (s, e) = (Vector3::from(m.axis_start), Vector3::from(m.axis_end));
            let d = e - s;
            if p.role.is_vertical() {
                assert!(d.z > 0.0);
            } else {
                assert!(d.dot(&wall.frame.u) > 0.0);
            }
        }
    }
}

#[test]
fn bad_option_combinations_are_refused() {
    let opts = WriteOptions {
        placement: Some(PlacementBase::Parent),
        grouping: Grouping::None,
        ..WriteOptions::default()
    };
    assert!(matches!(
        write_ifc(&models::tm1(), &opts),
        Err(SynthError::Options { .. })
    ));
}

#[test]
fn strings_and_global_ids_are_encoded_per_the_standards() {
    assert_eq!(string("it's"), "'it''s'");
    assert_eq!(string("a\\b"), "'a\\\\b'");
    assert_eq!(
        string("\u{e9}t\u{e9}"),
        "'\\X2\\00E9\\X0\\t\\X2\\00E9\\X0\\'"
    );
    assert_eq!(string("\u{1F600}"), "'\\X4\\0001F600\\X0\\'");
    assert_eq!(guid::encode(0), "0000000000000000000000");
    assert_eq!(guid::encode(u128::MAX), "3$$$$$$$$$$$$$$$$$$$$$");
    assert_ne!(guid::global_id(1, "a"), guid::global_id(1, "b"));
    assert_ne!(guid::global_id(1, "a"), guid::global_id(2, "a"));
}

#[test]
fn assembly_order_respects_every_precedence_and_nails_sit_on_plate_faces() {
    let layout = grid(&models::default_building_spec(), 1, 1, 0.0, "one").unwrap();
    let t = write_ifc(&layout, &WriteOptions::default()).unwrap().truth;
    let members: BTreeMap<_, _> = t.members.iter().map(|m| (m.global_id.clone(), m)).collect();
    let (mut rests, mut ends, mut sill_nails) = (0, 0, 0);
    for w in &t.walls {
        let pos: BTreeMap<_, _> = w
            .assembly_order
            .iter()
            .enumerate()
            .map(|(k, id)| (id.clone(), k))
            .collect();
        for p in &w.precedence_constraints {
            assert!(
                pos[&p.before] < pos[&p.after],
                "{} must precede {}",
                p.before,
                p.after
            );
            match p.reason {
                "rests_on" => rests += 1,
                _ => ends += 1,
            }
        }
        for n in w.nailing_targets.iter().chain(&w.secondary_nailing_targets) {
            let (plate, member) = (members[&n.plate], members[&n.member]);
            let b = &plate.wall_local_box;
            let face = if n.kind == "bottom_plate_to_stud" {
                b.v[0]
            } else {
                b.v[1]
            };
            assert!((n.v - face).abs() < 1e-9, "nail on the plate's outer face");
            let u = &member.wall_local_box.u;
            assert!(
                (n.u - 0.5 * (u[0] + u[1])).abs() < 1e-9,
                "nail at the member's centre"
            );
            assert!(n.w > b.w[0] && n.w < b.w[1]);
            assert_eq!(member.orientation, "vertical");
        }
        // Every standing member gets 2 nails at each end that meets a plate.
        let ends_on_plates: usize = w.nailing_targets.len();
        assert_eq!(ends_on_plates % 2, 0);
        sill_nails += w.secondary_nailing_targets.len();
    }
    assert!(rests > 0 && ends > 0);
    assert!(sill_nails > 0, "the default building has windows");
}
