//! The BCF-XML documents, after buildingSMART's schemas for 2.1 and 3.0 (element order as
//! the schemas' sequences; text and attributes escaped by quick-xml).

use super::topics::{Camera, IssueTopic};
use super::{BcfHeader, BcfVersion};
use quick_xml::Writer;
use quick_xml::events::{BytesDecl, BytesText, Event};
use std::io;

type W = Writer<Vec<u8>>;

fn document(body: impl FnOnce(&mut W) -> io::Result<()>) -> io::Result<Vec<u8>> {
    let mut w = Writer::new_with_indent(Vec::new(), b' ', 2);
    w.write_event(Event::Decl(BytesDecl::new("1.0", Some("UTF-8"), None)))?;
    body(&mut w)?;
    let mut out = w.into_inner();
    out.push(b'\n');
    // Model names may hold characters XML 1.0 forbids even escaped.
    let text = String::from_utf8(out).map_err(io::Error::other)?;
    Ok(crate::report::markup_text::replace_forbidden(text).into_bytes())
}

fn text(w: &mut W, name: &str, value: &str) -> io::Result<()> {
    w.create_element(name)
        .write_text_content(BytesText::new(value))?;
    Ok(())
}

/// Fixed six decimals: the same numbers print the same on every run.
fn number(x: f64) -> String {
    let s = format!("{:.6}", x + 0.0);
    if s == "-0.000000" {
        "0.000000".into()
    } else {
        s
    }
}

fn xyz(w: &mut W, name: &str, v: [f64; 3]) -> io::Result<()> {
    w.create_element(name).write_inner_content(|w| {
        text(w, "X", &number(v[0]))?;
        text(w, "Y", &number(v[1]))?;
        text(w, "Z", &number(v[2]))
    })?;
    Ok(())
}

fn components(w: &mut W, guids: &[String]) -> io::Result<()> {
    for g in guids {
        w.create_element("Component")
            .with_attribute(("IfcGuid", g.as_str()))
            .write_empty()?;
    }
    Ok(())
}

/// `bcf.version`.
pub fn version(v: BcfVersion) -> io::Result<Vec<u8>> {
    document(|w| {
        let el = w
            .create_element("Version")
            .with_attribute(("VersionId", v.id()));
        match v {
            BcfVersion::V3_0 => el.write_empty().map(|_| ()),
            BcfVersion::V2_1 => el
                .write_inner_content(|w| text(w, "DetailedVersion", "2.1"))
                .map(|_| ()),
        }
    })
}

/// `extensions.xml` (3.0): the topic types, statuses and labels the topics use.
pub fn extensions(labels: &[String]) -> io::Result<Vec<u8>> {
    document(|w| {
        w.create_element("Extensions").write_inner_content(|w| {
            w.create_element("TopicTypes")
                .write_inner_content(|w| text(w, "TopicType", "Error"))?;
            w.create_element("TopicStatuses")
                .write_inner_content(|w| text(w, "TopicStatus", "Open"))?;
            w.create_element("TopicLabels").write_inner_content(|w| {
                for l in labels {
                    text(w, "TopicLabel", l)?;
                }
                Ok(())
            })?;
            Ok(())
        })?;
        Ok(())
    })
}

/// `<topic>/markup.bcf`.
pub fn markup(v: BcfVersion, header: &BcfHeader, t: &IssueTopic) -> io::Result<Vec<u8>> {
    document(|w| {
        w.create_element("Markup").write_inner_content(|w| {
            w.create_element("Header").write_inner_content(|w| {
                let file = |w: &mut W| -> io::Result<()> {
                    let mut el = w.create_element("File");
                    if let Some(p) = &header.project_global_id {
                        el = el.with_attribute(("IfcProject", p.as_str()));
                    }
                    // BCF 2.1 spells the attribute with a small i; 3.0 with a capital.
                    let external = match v {
                        BcfVersion::V3_0 => "IsExternal",
                        BcfVersion::V2_1 => "isExternal",
                    };
                    el.with_attribute((external, "true"))
                        .write_inner_content(|w| {
                            text(w, "Filename", &header.model_file)?;
                            text(w, "Date", &header.date)
                        })?;
                    Ok(())
                };
                match v {
                    BcfVersion::V3_0 => {
                        w.create_element("Files").write_inner_content(file)?;
                        Ok(())
                    }
                    BcfVersion::V2_1 => file(w),
                }
            })?;
            w.create_element("Topic")
                .with_attribute(("Guid", t.guid.as_str()))
                .with_attribute(("TopicType", "Error"))
                .with_attribute(("TopicStatus", "Open"))
                .write_inner_content(|w| {
                    text(w, "Title", &t.title)?;
                    match v {
                        BcfVersion::V3_0 => {
                            w.create_element("Labels").write_inner_content(|w| {
                                for l in &t.labels {
                                    text(w, "Label", l)?;
                                }
                                Ok(())
                            })?;
                        }
                        BcfVersion::V2_1 => {
                            for l in &t.labels {
                                text(w, "Labels", l)?;
                            }
                        }
                    }
                    text(w, "CreationDate", &header.date)?;
                    text(w, "CreationAuthor", "framewright")?;
                    text(w, "Description", &t.description)?;
                    if v == BcfVersion::V3_0 {
                        w.create_element("Viewpoints")
                            .write_inner_content(|w| viewpoint_ref(w, "ViewPoint", t))?;
                    }
                    Ok(())
                })?;
            if v == BcfVersion::V2_1 {
                viewpoint_ref(w, "Viewpoints", t)?;
            }
            Ok(())
        })?;
        Ok(())
    })
}

/// The snapshot's file name in its topic's folder.
pub const SNAPSHOT_FILE: &str = "snapshot.png";

fn viewpoint_ref(w: &mut W, name: &str, t: &IssueTopic) -> io::Result<()> {
    w.create_element(name)
        .with_attribute(("Guid", t.viewpoint_guid.as_str()))
        .write_inner_content(|w| {
            text(w, "Viewpoint", "viewpoint.bcfv")?;
            if t.snapshot.is_some() {
                text(w, "Snapshot", SNAPSHOT_FILE)?;
            }
            Ok(())
        })?;
    Ok(())
}

/// `<topic>/viewpoint.bcfv`: failing elements selected and red, only the wall visible,
/// a perspective camera on the wall.
pub fn viewpoint(v: BcfVersion, t: &IssueTopic) -> io::Result<Vec<u8>> {
    document(|w| {
        w.create_element("VisualizationInfo")
            .with_attribute(("Guid", t.viewpoint_guid.as_str()))
            .write_inner_content(|w| {
                w.create_element("Components").write_inner_content(|w| {
                    w.create_element("Selection")
                        .write_inner_content(|w| components(w, &t.failing))?;
                    w.create_element("Visibility")
                        .with_attribute(("DefaultVisibility", "false"))
                        .write_inner_content(|w| {
                            w.create_element("Exceptions")
                                .write_inner_content(|w| components(w, &t.wall_elements))?;
                            Ok(())
                        })?;
                    w.create_element("Coloring").write_inner_content(|w| {
                        let color = w
                            .create_element("Color")
                            .with_attribute(("Color", "FF0000"));
                        match v {
                            BcfVersion::V3_0 => color.write_inner_content(|w| {
                                w.create_element("Components")
                                    .write_inner_content(|w| components(w, &t.failing))?;
                                Ok(())
                            })?,
                            BcfVersion::V2_1 => {
                                color.write_inner_content(|w| components(w, &t.failing))?
                            }
                        };
                        Ok(())
                    })?;
                    Ok(())
                })?;
                camera(w, v, &t.camera)
            })?;
        Ok(())
    })
}

fn camera(w: &mut W, v: BcfVersion, c: &Camera) -> io::Result<()> {
    w.create_element("PerspectiveCamera")
        .write_inner_content(|w| {
            xyz(w, "CameraViewPoint", c.position)?;
            xyz(w, "CameraDirection", c.direction)?;
            xyz(w, "CameraUpVector", c.up)?;
            text(w, "FieldOfView", &number(c.field_of_view))?;
            if v == BcfVersion::V3_0 {
                text(w, "AspectRatio", &number(c.aspect_ratio))?;
            }
            Ok(())
        })?;
    Ok(())
}
