//! Read access to a STEP file with IFC meaning: typed attribute getters that
//! turn dangling references and wrong kinds into [`Issue`]s, coordinates in
//! metres, and the warnings collected along the way.

use super::error::{Issue, R, Warning};
use super::schema::Schema;
use crate::geom::{Point3, Vector3};
use crate::step::{Entity, Param, StepFile};
use std::cell::RefCell;

pub(crate) struct Ctx<'f> {
    pub file: &'f StepFile,
    pub schema: Schema,
    /// Metres per model length unit.
    pub scale: f64,
    warnings: RefCell<Vec<Warning>>,
}

impl<'f> Ctx<'f> {
    pub fn new(file: &'f StepFile, schema: Schema, scale: f64) -> Self {
        Ctx {
            file,
            schema,
            scale,
            warnings: RefCell::new(Vec::new()),
        }
    }

    pub fn warn(&self, entity: Option<u64>, message: impl Into<String>) {
        self.warnings.borrow_mut().push(Warning {
            entity,
            message: message.into(),
        });
    }

    pub fn take_warnings(&self) -> Vec<Warning> {
        std::mem::take(&mut self.warnings.borrow_mut())
    }

    pub fn line(&self, id: u64) -> usize {
        self.file
            .record(id)
            .map_or(0, |r| self.file.line_col(r.start).0)
    }

    /// The entity `#id`, referenced from `#from`.
    pub fn get(&self, id: u64, from: u64) -> R<Entity<'f>> {
        match self.file.entity(id) {
            None => Err(Issue::Missing {
                entity: from,
                missing: id,
            }),
            Some(Ok(e)) => Ok(e),
            // An unreadable instance (a `NAN` where a number belongs, say) costs the
            // product or piece that uses it, named in a warning, not the whole model.
            Some(Err(step)) => Err(Issue::invalid(id, format!("cannot be read: {step}"))),
        }
    }

    /// The entity that attribute `i` of `e` refers to; `None` for `$`.
    pub fn follow(&self, e: &Entity<'_>, i: usize) -> R<Option<Entity<'f>>> {
        match e.get(i) {
            Param::Null | Param::Derived => Ok(None),
            Param::Ref(id) => self.get(*id, e.id).map(Some),
            other => Err(Issue::invalid(
                e.id,
                format!("attribute {} should be a reference, found {other:?}", i + 1),
            )),
        }
    }

    /// Like [`Ctx::follow`] but the attribute is required.
    pub fn follow_required(&self, e: &Entity<'_>, i: usize, what: &str) -> R<Entity<'f>> {
        self.follow(e, i)?
            .ok_or_else(|| Issue::invalid(e.id, format!("{what} is not given ($)")))
    }

    /// The references of a list attribute (non-references are reported).
    pub fn refs(&self, e: &Entity<'_>, i: usize) -> R<Vec<u64>> {
        match e.get(i) {
            Param::Null | Param::Derived => Ok(Vec::new()),
            Param::List(items) => items
                .iter()
                .map(|p| {
                    p.as_ref_id().ok_or_else(|| {
                        Issue::invalid(e.id, format!("attribute {} should list references", i + 1))
                    })
                })
                .collect(),
            Param::Ref(id) => Ok(vec![*id]),
            _ => Err(Issue::invalid(
                e.id,
                format!("attribute {} should be a list of references", i + 1),
            )),
        }
    }

    pub fn number(&self, e: &Entity<'_>, i: usize, what: &str) -> R<f64> {
        match e.get(i).as_f64() {
            Some(v) if v.is_finite() => Ok(v),
            _ => Err(Issue::invalid(
                e.id,
                format!("{what} (attribute {}) is not a number", i + 1),
            )),
        }
    }

    /// A length attribute converted to metres.
    pub fn length(&self, e: &Entity<'_>, i: usize, what: &str) -> R<f64> {
        Ok(self.number(e, i, what)? * self.scale)
    }

    /// Decoded text of a string attribute; warns once when bytes were replaced.
    pub fn text(&self, e: &Entity<'_>, i: usize) -> Option<String> {
        let (text, lossy) = e.get(i).text()?;
        if lossy {
            self.warn(
                Some(e.id),
                format!(
                    "#{} (line {}): attribute {} holds bytes that are neither ISO 10303-21 escapes nor UTF-8; they were replaced by U+FFFD",
                    e.id,
                    self.line(e.id),
                    i + 1
                ),
            );
        }
        Some(text.into_owned())
    }

    /// An IfcCartesianPoint in metres (2D points get z = 0).
    pub fn point(&self, e: &Entity<'_>) -> R<Point3> {
        self.expect_type(e, &["IFCCARTESIANPOINT"])?;
        let coords = e
            .get(0)
            .as_list()
            .ok_or_else(|| Issue::invalid(e.id, "Coordinates is not a list"))?;
        let mut xyz = [0.0; 3];
        if coords.is_empty() || coords.len() > 3 {
            return Err(Issue::invalid(
                e.id,
                format!("a point needs 1 to 3 coordinates, found {}", coords.len()),
            ));
        }
        for (slot, c) in xyz.iter_mut().zip(coords) {
            *slot = c
                .as_f64()
                .filter(|v| v.is_finite())
                .ok_or_else(|| Issue::invalid(e.id, "a coordinate is not a number"))?
                * self.scale;
        }
        Ok(Point3::new(xyz[0], xyz[1], xyz[2]))
    }

    /// An IfcDirection as given (not normalised); `None` when it is empty or zero.
    pub fn direction(&self, e: &Entity<'_>) -> R<Option<Vector3>> {
        self.expect_type(e, &["IFCDIRECTION"])?;
        let ratios = e.get(0).as_list().unwrap_or(&[]);
        let mut v = [0.0; 3];
        for (slot, c) in v.iter_mut().zip(ratios) {
            *slot = c.as_f64().unwrap_or(f64::NAN);
        }
        let v = Vector3::from(v);
        Ok((ratios.len() >= 2 && v.norm().is_finite() && v.norm() > 1e-12).then_some(v))
    }

    /// A direction attribute, normalised; `None` for `$`, an empty or a zero vector
    /// (the latter two are warned about: real exporters write them).
    pub fn direction_attr(&self, e: &Entity<'_>, i: usize) -> R<Option<Vector3>> {
        let Some(d) = self.follow(e, i)? else {
            return Ok(None);
        };
        match self.direction(&d)? {
            Some(v) => Ok(Some(v.normalize())),
            None => {
                self.warn(
                    Some(d.id),
                    format!("#{} (line {}): zero-length or empty IfcDirection used by #{}; the default direction is used instead", d.id, self.line(d.id), e.id),
                );
                Ok(None)
            }
        }
    }

    pub fn expect_type(&self, e: &Entity<'_>, types: &[&str]) -> R<()> {
        if types.contains(&e.type_name) {
            Ok(())
        } else {
            Err(Issue::invalid(
                e.id,
                format!("expected {}, found {}", types.join(" or "), e.type_name),
            ))
        }
    }
}
