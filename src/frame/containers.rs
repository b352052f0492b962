//! Facts cut down to some spatial containers (storeys, buildings): no rule relates pieces of
//! different containers (walls never span one), so what the rules derive about a piece from
//! its container's facts is what they derive from the whole model's. `why` and the
//! single-wall simulation reason over the element's container alone.

use super::Facts;
use crate::logic::Value;
use std::collections::{BTreeMap, BTreeSet};

/// The facts of the given containers only: tuples about a piece of another
/// container are left out (contacts need both pieces inside); facts about no
/// piece (the cell) are kept.
pub fn restrict_to_containers(facts: &Facts, containers: &BTreeSet<String>) -> Facts {
    let container_of: BTreeMap<&str, &str> = facts
        .tuples
        .get("piece_container")
        .into_iter()
        .flatten()
        .filter_map(|(t, _)| Some((t[0].as_symbol()?, t[1].as_symbol()?)))
        .collect();
    let inside = |v: Option<&Value>| match v
        .and_then(Value::as_symbol)
        .and_then(|s| container_of.get(s))
    {
        Some(c) => containers.contains(*c),
        None => true,
    };
    let mut out = Facts::default();
    for (name, tuples) in &facts.tuples {
        for (t, origin) in tuples {
            let keep = inside(t.first())
                && (!super::facts::PAIR_RELATIONS.contains(name) || inside(t.get(1)));
            if keep {
                out.add(name, t.clone(), origin.clone());
            }
        }
    }
    out
}

/// The spatial containers (`piece_container`) of the pieces `ids` (empty when none is a
/// piece).
pub fn containers_of(facts: &Facts, ids: &BTreeSet<&str>) -> BTreeSet<String> {
    facts
        .tuples
        .get("piece_container")
        .into_iter()
        .flatten()
        .filter(|(t, _)| t[0].as_symbol().is_some_and(|p| ids.contains(p)))
        .filter_map(|(t, _)| t[1].as_symbol().map(str::to_string))
        .collect()
}
