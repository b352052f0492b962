//! Objectified relationships the reader needs: aggregation (parents),
//! spatial containment, material association and typing.

use super::context::Ctx;
use super::error::R;
use crate::step::Entity;
use std::collections::HashMap;

#[derive(Default)]
pub(crate) struct Relations {
    /// Part → whole (IfcRelAggregates).
    pub parent: HashMap<u64, u64>,
    /// Element → spatial structure (IfcRelContainedInSpatialStructure).
    pub container: HashMap<u64, u64>,
    /// Object → material select (IfcRelAssociatesMaterial).
    pub material: HashMap<u64, u64>,
    /// Occurrence → type object (IfcRelDefinesByType).
    pub type_object: HashMap<u64, u64>,
}

/// Selects one of the maps of [`Relations`].
type MapOf = fn(&mut Relations) -> &mut HashMap<u64, u64>;

impl Relations {
    pub fn read(ctx: &Ctx<'_>) -> R<Relations> {
        let mut rel = Relations::default();
        // (type, index of the "one" side, index of the "many" side, map to fill)
        let kinds: [(&str, usize, usize, MapOf); 4] = [
            ("IFCRELAGGREGATES", 4, 5, |r| &mut r.parent),
            ("IFCRELCONTAINEDINSPATIALSTRUCTURE", 5, 4, |r| {
                &mut r.container
            }),
            ("IFCRELASSOCIATESMATERIAL", 5, 4, |r| &mut r.material),
            ("IFCRELDEFINESBYTYPE", 5, 4, |r| &mut r.type_object),
        ];
        for (type_name, one, many, map) in kinds {
            for record in ctx.file.of_type(type_name) {
                let e = ctx
                    .file
                    .decode(record)
                    .map_err(|e| super::error::Issue::Fatal(e.into()))?;
                let Some(whole) = e.get(one).as_ref_id() else {
                    continue;
                };
                let target = map(&mut rel);
                for part in ctx.refs(&e, many)? {
                    // The first relationship wins, as the schema allows only one.
                    target.entry(part).or_insert(whole);
                }
            }
        }
        Ok(rel)
    }

    /// Ancestors through aggregation, nearest first (bounded against cycles).
    pub fn ancestors(&self, id: u64) -> Vec<u64> {
        let mut out = Vec::new();
        let mut current = id;
        while let Some(&p) = self.parent.get(&current) {
            if out.contains(&p) || out.len() > 64 {
                break;
            }
            out.push(p);
            current = p;
        }
        out
    }
}

/// The name of a material select (material, layer set usage, profile set usage, list).
pub(crate) fn material_name(ctx: &Ctx<'_>, id: u64, from: u64, depth: usize) -> R<Option<String>> {
    if depth > 8 {
        return Ok(None);
    }
    let e = ctx.get(id, from)?;
    let first_of = |e: &Entity<'_>, list_index: usize| -> R<Option<u64>> {
        Ok(ctx.refs(e, list_index)?.first().copied())
    };
    let next = match e.type_name {
        "IFCMATERIAL" => return Ok(ctx.text(&e, 0)),
        "IFCMATERIALLAYERSETUSAGE"
        | "IFCMATERIALPROFILESETUSAGE"
        | "IFCMATERIALPROFILESETUSAGETAPERING" => e.get(0).as_ref_id(),
        "IFCMATERIALLAYERSET" => first_of(&e, 0)?,
        "IFCMATERIALPROFILESET" => first_of(&e, 2)?,
        "IFCMATERIALCONSTITUENTSET" => first_of(&e, 2)?,
        "IFCMATERIALLIST" => first_of(&e, 0)?,
        "IFCMATERIALLAYER" | "IFCMATERIALLAYERWITHOFFSETS" => e.get(0).as_ref_id(),
        "IFCMATERIALPROFILE" | "IFCMATERIALPROFILEWITHOFFSETS" | "IFCMATERIALCONSTITUENT" => {
            e.get(2).as_ref_id()
        }
        _ => None,
    };
    match next {
        Some(n) => material_name(ctx, n, e.id, depth + 1),
        None => Ok(None),
    }
}
