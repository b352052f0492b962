//! Splits a model's facts into parts finer than its containers: the pieces of one container
//! joined by a contact that can make them coplanar (one wall), a contact of a piece the rules
//! may attach to a wall (turned flat, or touching nothing coplanar) lying within the other's
//! thickness, a crossing of an inclined piece (a let-in brace), or an IFC group. The
//! built-in rules relate two pieces of different walls only through such a contact (walls are
//! connected coplanar contacts; roles, order and nailing read contacts within one wall) or a
//! shared group (`group_split`), so a part's walls, roles, order and targets come from its own
//! facts, with one exception: `storey_reach`, how far the whole container's lumber reaches
//! along a wall's across direction (whether a wall is exterior). Contacts between pieces of
//! two parts (a corner stud against the end of a crossing wall) are read by no rule and left
//! out.
//! A part run on its own therefore also gets the rest of its container as *context pieces*:
//! their boxes, sizes and container only (no index, contact or group, so they form no wall),
//! and everything derived about them is dropped afterwards.

use super::Facts;
use crate::logic::compiled::Relations;
use crate::logic::value::Sym;
use crate::logic::{OBox, Value};
use nalgebra::Vector3;
use rayon::prelude::*;
use rustc_hash::FxHashMap;
use std::borrow::Cow;

/// One independent part of a container.
pub struct Part {
    /// Index into `Partition::containers`.
    pub container: usize,
    /// Its pieces, in file order.
    pub pieces: Vec<String>,
    /// The IFC groups (IfcWall, IfcElementAssembly) its pieces belong to.
    pub groups: Vec<String>,
    /// Its own facts, per relation of the model's (`Partition::names`): the indices of the
    /// tuples about its pieces (a contact only between two of them), in the facts' order.
    /// Indices, not copies: most parts are only hashed. Not sorted: the facts keep the order
    /// of the file's pieces, so a part's rows come in the same order as long as its own
    /// pieces keep theirs (when they do not, its `piece_index` changes anyway).
    own: Vec<Vec<u32>>,
}

/// How `Partition::relations` numbers pieces.
#[derive(Clone, Copy, PartialEq, Eq)]
pub enum Indices {
    /// `piece_index` renumbered from 0 in file order within the parts (the rules only compare
    /// indices of pieces of one wall, and no relation `plan` reads carries one), so that an
    /// edit elsewhere in the file does not change them.
    Renumbered,
    /// The file's indices (the rules take a wall's name from the piece of its least index).
    File,
}

/// A container (storey, building, or "" for none) and its pieces.
pub struct Container {
    pub name: String,
    /// Indices into `Partition::pieces`.
    pub pieces: Vec<usize>,
}

/// The parts of a model, in the order of their first piece in `piece_container`.
pub struct Partition {
    pub containers: Vec<Container>,
    /// Every piece id, in `piece_container` order.
    pub pieces: Vec<String>,
    pub parts: Vec<Part>,
    /// The model's relations, in name order: what `Part::own` and `common` index.
    names: Vec<&'static str>,
    /// Per relation, the indices of the tuples about no piece (the cell's): every part reads
    /// them.
    common: Vec<Vec<u32>>,
}

/// Relations that hold a piece's context facts: what `storey_reach` reads.
pub const CONTEXT_RELATIONS: &[&str] = &["piece_box", "piece_size", "piece_container"];

impl Partition {
    /// Splits the facts. Contacts between pieces of two containers are dropped, as the
    /// container split of the rule base's run (`Ask`) drops them.
    pub fn of(facts: &Facts) -> Partition {
        let mut containers: Vec<Container> = Vec::new();
        let mut container_index: FxHashMap<&str, usize> = FxHashMap::default();
        let mut pieces: Vec<String> = Vec::new();
        // Keyed by interned symbols: every tuple below looks its piece up.
        let mut piece_index: FxHashMap<Sym, usize> = FxHashMap::default();
        let mut container_of: Vec<usize> = Vec::new();
        for (t, _) in facts.tuples.get("piece_container").into_iter().flatten() {
            let (Value::Symbol(p), Some(c)) = (&t[0], t[1].as_symbol()) else {
                continue;
            };
            if piece_index.contains_key(p) {
                continue;
            }
            let next = containers.len();
            let k = *container_index.entry(c).or_insert(next);
            if k == next {
                containers.push(Container {
                    name: c.to_string(),
                    pieces: Vec::new(),
                });
            }
            piece_index.insert(*p, pieces.len());
            containers[k].pieces.push(pieces.len());
            container_of.push(k);
            pieces.push(p.to_string());
        }

        let mut sets = UnionFind::new(pieces.len());
        let find = |v: Option<&Value>| {
            v.and_then(Value::as_sym)
                .and_then(|p| piece_index.get(&p).copied())
        };
        let mut across: Vec<Vec<Vector3<f64>>> = vec![Vec::new(); pieces.len()];
        let mut boxes: Vec<Option<&OBox>> = vec![None; pieces.len()];
        for (t, _) in facts.tuples.get("piece_box").into_iter().flatten() {
            if let (Some(p), Some(Value::Box(b))) = (find(t.first()), t.get(1)) {
                across[p] = across_candidates(b);
                boxes[p] = Some(b);
            }
        }
        let inside = |a: usize, b: usize| match (boxes[a], boxes[b]) {
            (Some(ba), Some(bb)) => within_thickness(ba, bb, &across[b]),
            _ => false,
        };
        // (a, b, whether a meets b with its end along a plumb normal), as `turned_flat` reads.
        let contacts: Vec<(usize, usize, bool)> = facts
            .tuples
            .get("contact")
            .into_iter()
            .flatten()
            .filter_map(|(t, _)| {
                let end_on = t.get(3).and_then(Value::as_symbol) == Some("end")
                    && t.get(6)
                        .and_then(Value::as_vec3)
                        .is_some_and(|n| n.z.abs() > 0.9 - MARGIN);
                Some((find(t.first())?, find(t.get(1))?, end_on))
            })
            .filter(|&(a, b, _)| container_of[a] == container_of[b])
            .collect();
        // Pieces the rules may attach to a wall they lie in (rule `may_attach`): turned flat,
        // or with no contact that can make them coplanar with anything.
        let mut coplanar_capable = vec![false; pieces.len()];
        let mut turned = vec![false; pieces.len()];
        for &(a, b, end_on) in &contacts {
            if may_be_coplanar(&across[a], &across[b]) {
                coplanar_capable[a] = true;
            }
            if let (Some(ba), Some(bb)) = (boxes[a], boxes[b])
                && end_on
                && may_be_turned_flat(ba, &across[a], bb, &across[b])
            {
                turned[a] = true;
            }
        }
        let loose = |p: usize| turned[p] || !coplanar_capable[p];
        for &(a, b, _) in &contacts {
            if may_be_coplanar(&across[a], &across[b])
                || (loose(a) && inside(a, b))
                || (loose(b) && inside(b, a))
            {
                sets.join(a, b);
            }
        }
        // A piece crossing another (a let-in brace through the studs) joins its wall when it
        // is inclined (rule `attached_crossing`).
        for (t, _) in facts.tuples.get("crossing").into_iter().flatten() {
            if let (Some(a), Some(b)) = (find(t.first()), find(t.get(1)))
                && container_of[a] == container_of[b]
                && (boxes[a].is_some_and(may_be_inclined) || boxes[b].is_some_and(may_be_inclined))
            {
                sets.join(a, b);
            }
        }
        let mut group_first: FxHashMap<(&str, usize), usize> = FxHashMap::default();
        let mut groups_of: FxHashMap<usize, Vec<String>> = FxHashMap::default();
        for (t, _) in facts.tuples.get("piece_group").into_iter().flatten() {
            if let (Some(p), Some(g)) = (find(t.first()), t.get(1).and_then(Value::as_symbol)) {
                let first = *group_first.entry((g, container_of[p])).or_insert(p);
                sets.join(first, p);
            }
        }

        // Parts numbered by their first piece.
        let mut part_of_root: FxHashMap<usize, usize> = FxHashMap::default();
        let mut part_of: Vec<usize> = Vec::with_capacity(pieces.len());
        let mut parts: Vec<Part> = Vec::new();
        for (i, piece) in pieces.iter().enumerate() {
            let root = sets.find(i);
            let next = parts.len();
            let k = *part_of_root.entry(root).or_insert(next);
            if k == next {
                parts.push(Part {
                    container: container_of[i],
                    pieces: Vec::new(),
                    groups: Vec::new(),
                    own: Vec::new(),
                });
            }
            parts[k].pieces.push(piece.clone());
            part_of.push(k);
        }
        for ((g, _), first) in &group_first {
            groups_of
                .entry(part_of[*first])
                .or_default()
                .push(g.to_string());
        }
        for (k, mut groups) in groups_of {
            groups.sort();
            parts[k].groups = groups;
        }

        // Each relation split into its parts' buckets, relations in parallel.
        let split: Vec<(Vec<Vec<u32>>, Vec<u32>)> = facts
            .tuples
            .par_iter()
            .map(|(name, tuples)| {
                let mut buckets: Vec<Vec<u32>> = vec![Vec::new(); parts.len()];
                let mut common: Vec<u32> = Vec::new();
                for (j, (tuple, _)) in tuples.iter().enumerate() {
                    let j = j as u32;
                    match find(tuple.first()).map(|p| part_of[p]) {
                        Some(k) if super::facts::PAIR_RELATIONS.contains(name) => {
                            if find(tuple.get(1)).map(|p| part_of[p]) == Some(k) {
                                buckets[k].push(j);
                            }
                        }
                        Some(k) => buckets[k].push(j),
                        None => common.push(j),
                    }
                }
                (buckets, common)
            })
            .collect();
        let names: Vec<&'static str> = facts.tuples.keys().copied().collect();
        let mut common = Vec::with_capacity(names.len());
        for (buckets, shared) in split {
            for (part, bucket) in parts.iter_mut().zip(buckets) {
                part.own.push(bucket);
            }
            common.push(shared);
        }
        Partition {
            containers,
            pieces,
            parts,
            names,
            common,
        }
    }

    /// The own facts of part `i`, per relation in name order, `piece_index` renumbered
    /// (`Indices::Renumbered`). With `common_rows` they are exactly the part's facts.
    pub fn own_rows<'f>(
        &self,
        facts: &'f Facts,
        i: usize,
    ) -> Vec<(&'static str, Vec<Cow<'f, [Value]>>)> {
        self.names
            .iter()
            .zip(&self.parts[i].own)
            .map(|(name, rows)| {
                let tuples = &facts.tuples[name];
                let mut out: Vec<Cow<[Value]>> = rows
                    .iter()
                    .map(|&j| Cow::Borrowed(tuples[j as usize].0.as_slice()))
                    .collect();
                if *name == "piece_index" {
                    renumber(&mut out);
                }
                (*name, out)
            })
            .collect()
    }

    /// The facts about no piece (the cell's), per relation in name order.
    pub fn common_rows<'f>(&self, facts: &'f Facts) -> Vec<(&'static str, Vec<&'f [Value]>)> {
        self.names
            .iter()
            .zip(&self.common)
            .map(|(name, rows)| {
                let tuples = &facts.tuples[name];
                let out = rows
                    .iter()
                    .map(|&j| tuples[j as usize].0.as_slice())
                    .collect();
                (*name, out)
            })
            .collect()
    }

    /// The facts of `parts` together (each part's own and the common ones), every relation
    /// sorted, without repeats: the input of a run over them.
    pub fn relations(&self, facts: &Facts, parts: &[usize], indices: Indices) -> Relations {
        self.names
            .iter()
            .enumerate()
            .map(|(r, name)| {
                let all = &facts.tuples[name];
                let mut tuples: Vec<Vec<Value>> = parts
                    .iter()
                    .flat_map(|&i| &self.parts[i].own[r])
                    .chain(&self.common[r])
                    .map(|&j| all[j as usize].0.clone())
                    .collect();
                if *name == "piece_index" && indices == Indices::Renumbered {
                    tuples.sort_unstable();
                    tuples.dedup();
                    renumber(&mut tuples);
                }
                tuples.sort_unstable();
                tuples.dedup();
                (name.to_string(), tuples)
            })
            .collect()
    }

    /// The context facts of `part`: the boxes, sizes and container of every other piece of its
    /// container, read from `facts`.
    pub fn context(&self, facts: &Facts, part: usize) -> Relations {
        let own: rustc_hash::FxHashSet<&str> =
            self.parts[part].pieces.iter().map(String::as_str).collect();
        let container = &self.containers[self.parts[part].container];
        let others: rustc_hash::FxHashSet<&str> = container
            .pieces
            .iter()
            .map(|&i| self.pieces[i].as_str())
            .filter(|p| !own.contains(p))
            .collect();
        CONTEXT_RELATIONS
            .iter()
            .map(|name| {
                let tuples = facts
                    .tuples
                    .get(name)
                    .into_iter()
                    .flatten()
                    .filter(|(t, _)| {
                        t.first()
                            .and_then(Value::as_symbol)
                            .is_some_and(|p| others.contains(p))
                    })
                    .map(|(t, _)| t.clone())
                    .collect();
                (name.to_string(), tuples)
            })
            .collect()
    }
}

/// Margin on the thresholds of the `across` and `coplanar` rules, so that rounding never
/// makes this module call two pieces apart that the rules join.
const MARGIN: f64 = 1e-6;

/// Every direction the `across` rules (rules/walls.dl) can give a piece with this box, and
/// maybe more: the width axis of an upright; the width axis of a piece lying flat, the
/// thickness axis of one on edge. Lumber sizes are not checked (a piece that is not lumber
/// has no across direction: more candidates only join more).
fn across_candidates(b: &OBox) -> Vec<Vector3<f64>> {
    let z = |k: usize| b.axis(k).z.abs();
    let mut out = Vec::new();
    if z(0) > 0.9 - MARGIN {
        out.push(b.axis(1));
    }
    if z(0) < 0.1 + MARGIN {
        if z(2) > 0.9 - MARGIN {
            out.push(b.axis(1));
        }
        if z(1) > 0.9 - MARGIN {
            out.push(b.axis(2));
        }
    }
    out
}

/// Whether the rule `coplanar_contact` can hold for two touching pieces: their across
/// directions parallel (the overlap condition is not checked).
fn may_be_coplanar(a: &[Vector3<f64>], b: &[Vector3<f64>]) -> bool {
    a.iter()
        .any(|da| b.iter().any(|db| da.dot(db).abs() > 0.99 - MARGIN))
}

/// Whether the rule `attached_inside_thickness` can hold for box `a` touching box `b`: `a`
/// lies within `b`'s extent along one of `b`'s across candidates (a piece turned flat inside
/// a wall joins the wall of a piece it touches).
fn within_thickness(a: &OBox, b: &OBox, b_across: &[Vector3<f64>]) -> bool {
    let radius = |bx: &OBox, d: &Vector3<f64>| -> f64 {
        (0..3).map(|k| bx.half[k] * bx.axis(k).dot(d).abs()).sum()
    };
    b_across.iter().any(|d| {
        (a.centre() - b.centre()).dot(d).abs() + radius(a, d) <= radius(b, d) + 0.003 + MARGIN
    })
}

/// Whether the rule `turned_flat` can hold for upright `a` touching `b`: `b` lies level,
/// their across directions are (nearly) square, and `a` lies within `b`'s thickness.
fn may_be_turned_flat(
    a: &OBox,
    a_across: &[Vector3<f64>],
    b: &OBox,
    b_across: &[Vector3<f64>],
) -> bool {
    a.axis(0).z.abs() > 0.9 - MARGIN
        && b.axis(0).z.abs() < 0.1 + MARGIN
        && a_across
            .iter()
            .any(|da| b_across.iter().any(|db| da.dot(db).abs() < 0.1 + MARGIN))
        && within_thickness(a, b, b_across)
}

/// Whether the rule `inclined` (rules/walls.dl) can hold for a piece with this box: its
/// length neither plumb nor level.
fn may_be_inclined(b: &OBox) -> bool {
    let z = b.axis(0).z.abs();
    z > 0.1 - MARGIN && z < 0.9 + MARGIN
}

/// `piece_index` tuples renumbered 0.. in the order of their indices (ties in the order
/// given).
fn renumber<T: AsRef<[Value]> + From<Vec<Value>>>(tuples: &mut [T]) {
    let mut order: Vec<(i64, usize)> = tuples
        .iter()
        .enumerate()
        .map(|(k, t)| {
            let index = t.as_ref().get(1).and_then(Value::as_number);
            (index.unwrap_or(i64::MAX), k)
        })
        .collect();
    order.sort();
    for (rank, (_, k)) in order.into_iter().enumerate() {
        let mut t = tuples[k].as_ref().to_vec();
        if let Some(index) = t.get_mut(1) {
            *index = Value::Number(rank as i64);
        }
        tuples[k] = T::from(t);
    }
}

/// Disjoint sets of piece indices.
struct UnionFind {
    parent: Vec<usize>,
}

impl UnionFind {
    fn new(n: usize) -> Self {
        UnionFind {
            parent: (0..n).collect(),
        }
    }
    fn find(&mut self, mut i: usize) -> usize {
        while self.parent[i] != i {
            self.parent[i] = self.parent[self.parent[i]];
            i = self.parent[i];
        }
        i
    }
    fn join(&mut self, a: usize, b: usize) {
        let (ra, rb) = (self.find(a), self.find(b));
        // The smaller index stays the root: the parts do not depend on the join order.
        if ra != rb {
            let (lo, hi) = (ra.min(rb), ra.max(rb));
            self.parent[hi] = lo;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::logic::Origin;

    fn facts(rows: &[(&'static str, Vec<Value>)]) -> Facts {
        let mut f = Facts::default();
        for (name, t) in rows {
            f.add(name, t.clone(), Origin::Rust);
        }
        f
    }

    /// An upright's box at the origin: length plumb, width along `width` (horizontal).
    fn upright(width: Vector3<f64>) -> Value {
        upright_at(width, Vector3::zeros())
    }

    fn upright_at(width: Vector3<f64>, centre: Vector3<f64>) -> Value {
        let x = Vector3::z();
        let m = nalgebra::Matrix3::from_columns(&[x, width, x.cross(&width)]);
        let pose = nalgebra::Isometry3::from_parts(
            nalgebra::Translation3::from(centre),
            nalgebra::UnitQuaternion::from_matrix(&m),
        );
        Value::Box(std::sync::Arc::new(OBox {
            pose,
            half: Vector3::new(1.2, 0.045, 0.019),
        }))
    }

    #[test]
    fn coplanar_contacts_and_groups_join_pieces_of_one_container_only() {
        let s = Value::sym;
        let contact = |a: &str, b: &str| {
            (
                "contact",
                vec![s(a), s(b), s("k"), s("end"), s("wide"), Value::float(0.0)],
            )
        };
        let f = facts(&[
            ("piece_container", vec![s("a"), s("S1")]),
            ("piece_container", vec![s("b"), s("S1")]),
            ("piece_container", vec![s("c"), s("S1")]),
            ("piece_container", vec![s("d"), s("S1")]),
            ("piece_container", vec![s("e"), s("S2")]),
            ("piece_container", vec![s("f"), s("S1")]),
            ("piece_box", vec![s("a"), upright(Vector3::x())]),
            ("piece_box", vec![s("b"), upright(-Vector3::x())]),
            ("piece_box", vec![s("e"), upright(Vector3::x())]),
            // f stands beside a, outside a's width (the end of a crossing wall); g, turned
            // flat, stands within a's width (a flat stud in a's wall).
            (
                "piece_box",
                vec![
                    s("f"),
                    upright_at(Vector3::y(), Vector3::new(0.064, 0.0, 0.0)),
                ],
            ),
            ("piece_container", vec![s("g"), s("S1")]),
            (
                "piece_box",
                vec![
                    s("g"),
                    upright_at(Vector3::y(), Vector3::new(0.026, 0.0, 0.0)),
                ],
            ),
            contact("a", "g"),
            ("piece_index", vec![s("a"), Value::Number(4)]),
            ("piece_index", vec![s("c"), Value::Number(9)]),
            ("piece_index", vec![s("d"), Value::Number(7)]),
            contact("a", "b"),
            contact("b", "e"),
            contact("a", "f"),
            ("piece_group", vec![s("c"), s("G"), s("IFCWALL"), s("")]),
            ("piece_group", vec![s("d"), s("G"), s("IFCWALL"), s("")]),
            ("cell_value", vec![s("x"), Value::float(1.0)]),
        ]);
        let p = Partition::of(&f);
        let pieces: Vec<Vec<String>> = p.parts.iter().map(|q| q.pieces.clone()).collect();
        assert_eq!(
            pieces,
            vec![vec!["a", "b", "g"], vec!["c", "d"], vec!["e"], vec!["f"]]
        );
        assert_eq!(p.parts[1].groups, vec!["G"]);
        // The contact across containers and the one across walls (a crossing upright) go
        // nowhere; the cell goes everywhere.
        let of = |k: usize| p.relations(&f, &[k], Indices::Renumbered);
        assert_eq!(of(0)["contact"].len(), 2);
        assert!(of(2)["contact"].is_empty());
        assert!(of(3)["contact"].is_empty());
        assert!((0..p.parts.len()).all(|k| of(k)["cell_value"].len() == 1));
        // Indices renumbered within the part, in file order; or kept.
        let renumbered = vec![
            vec![s("c"), Value::Number(1)],
            vec![s("d"), Value::Number(0)],
        ];
        assert_eq!(of(1)["piece_index"], renumbered);
        let own = p.own_rows(&f, 1);
        let (_, rows) = own.iter().find(|(n, _)| *n == "piece_index").unwrap();
        assert_eq!(
            rows.iter().map(|t| t.to_vec()).collect::<Vec<_>>(),
            renumbered
        );
        let kept = p.relations(&f, &[0, 1], Indices::File);
        assert_eq!(
            kept["piece_index"],
            vec![
                vec![s("a"), Value::Number(4)],
                vec![s("c"), Value::Number(9)],
                vec![s("d"), Value::Number(7)]
            ]
        );
        // The cell's facts are common, not any part's own.
        let common = p.common_rows(&f);
        let (_, rows) = common.iter().find(|(n, _)| *n == "cell_value").unwrap();
        assert_eq!(rows.len(), 1);
        assert!(
            p.own_rows(&f, 0)
                .iter()
                .all(|(n, r)| *n != "cell_value" || r.is_empty())
        );
        // Context of part 0: the other pieces of S1 (c, d, f), never e or a, b.
        let ctx = p.context(&f, 0);
        let ids: Vec<&str> = ctx["piece_container"]
            .iter()
            .filter_map(|t| t[0].as_symbol())
            .collect();
        assert_eq!(ids, vec!["c", "d", "f"]);
    }
}
