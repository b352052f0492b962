//! The entities every BIM writer of framewright appends: labels and typed values within
//! IFC's limits, GlobalIds derived from what they name, bodies and properties.

use super::step_edit::Appender;
use crate::ifc::guid;
use crate::step::text::{Real, Ref, string};

/// Name of the property set written on every element.
pub const PSET_NAME: &str = "Framewright_Assembly";

/// Seed of the GlobalIds of everything `annotate` writes.
const GUID_SEED: u64 = 0x6672_616d_6577_7269;

/// IfcLabel and IfcIdentifier hold at most 255 characters.
fn short(text: &str) -> &str {
    text.char_indices()
        .nth(255)
        .map_or(text, |(at, _)| &text[..at])
}

/// A label attribute (names): at most 255 characters.
pub(super) fn label(text: &str) -> String {
    string(short(text))
}

/// `IFCLABEL('…')` and friends.
pub(super) fn typed(kind: &str, text: &str) -> String {
    let text = if kind == "IFCTEXT" { text } else { short(text) };
    format!("{kind}({})", string(text))
}

pub(super) fn guid_for(kind: &str, key: &str) -> String {
    string(&guid::global_id(
        GUID_SEED,
        &format!("framewright/annotate/{kind}/{key}"),
    ))
}

/// A body: `profile` swept `depth` (model units) along its placement's z axis, in the body
/// representation context `context`.
pub(super) fn swept_body(w: &mut Appender, context: u64, profile: Ref, depth: f64) -> Ref {
    let up = w.add("IFCDIRECTION", "(0.,0.,1.)");
    let solid = w.add(
        "IFCEXTRUDEDAREASOLID",
        format!("{profile},$,{up},{}", Real(depth)),
    );
    let rep = w.add(
        "IFCSHAPEREPRESENTATION",
        format!(
            "#{context},{},{},({solid})",
            string("Body"),
            string("SweptSolid")
        ),
    );
    w.add("IFCPRODUCTDEFINITIONSHAPE", format!("$,$,({rep})"))
}

/// One property: a single value for a one-piece product, a list (one value per piece) otherwise.
pub(super) fn property(w: &mut Appender, name: &str, values: &[String]) -> Ref {
    if let [value] = values {
        w.add(
            "IFCPROPERTYSINGLEVALUE",
            format!("{},$,{value},$", string(name)),
        )
    } else {
        w.add(
            "IFCPROPERTYLISTVALUE",
            format!("{},$,({}),$", string(name), values.join(",")),
        )
    }
}
