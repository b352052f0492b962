//! The scene as a Webots world (`.wbt`, R2023b syntax; ENU: z up, x forward).
//!
//! What it holds: WorldInfo, a Viewpoint over the cell, background and light, the floor
//! (`Floor` proto), conveyors, touch sensor and tool table as static Solids (no Physics) with
//! box shapes, every lumber piece as a Solid with box geometry, bounding box and
//! `Physics { density }` in spawn order, and the robot: the `Irb4600-40` proto for the ABB, a
//! static placeholder of the base link's collision shapes otherwise (Webots ships no KUKA KR 150-2).
//! Rotations are axis-angle `x y z angle`. The conveyors are static boxes: moving the lumber
//! along them is the job of a controller (a supervisor), as is the robot's motion.

use super::Scene;
use crate::cell::{PlacedShape, Shape};
use nalgebra::{Isometry3, Translation3, UnitQuaternion, Vector3};
use std::fmt::Write as _;

const PROTO_BASE: &str = "https://raw.githubusercontent.com/cyberbotics/webots/R2023b/projects";

/// A number with at most 9 decimals, trailing zeros dropped, no `-0`.
fn num(x: f64) -> String {
    let s = format!("{x:.9}");
    let s = s.trim_end_matches('0').trim_end_matches('.');
    if s == "-0" || s.is_empty() {
        "0".into()
    } else {
        s.to_string()
    }
}

fn vec(v: &Vector3<f64>) -> String {
    format!("{} {} {}", num(v.x), num(v.y), num(v.z))
}

/// `x y z angle` of a rotation (`0 0 1 0` for none).
fn axis_angle(r: &UnitQuaternion<f64>) -> String {
    match r.axis_angle() {
        Some((axis, angle)) if angle.abs() > 1e-12 => format!("{} {}", vec(&axis), num(angle)),
        _ => "0 0 1 0".into(),
    }
}

/// A string literal: Webots strings are C-like (escape `"` and `\`).
fn string(s: &str) -> String {
    let mut out = String::from("\"");
    for c in s.chars() {
        match c {
            '"' => out.push_str("\\\""),
            '\\' => out.push_str("\\\\"),
            '\n' | '\r' => out.push(' '),
            c => out.push(c),
        }
    }
    out.push('"');
    out
}

/// A comment line's text: one line.
fn comment(s: &str) -> String {
    s.replace(['\n', '\r'], " ")
}

fn pose_fields(out: &mut String, indent: &str, pose: &Isometry3<f64>) {
    let _ = writeln!(out, "{indent}translation {}", vec(&pose.translation.vector));
    let _ = writeln!(out, "{indent}rotation {}", axis_angle(&pose.rotation));
}

/// A static or dynamic Solid with one box shape (also its bounding object).
struct BoxSolid<'a> {
    name: &'a str,
    pose: Isometry3<f64>,
    size: [f64; 3],
    colour: [f64; 3],
    /// `Physics { density }` when set (kg/m³); static otherwise.
    density: Option<f64>,
}

fn box_solid(out: &mut String, s: &BoxSolid) {
    let size = format!("{} {} {}", num(s.size[0]), num(s.size[1]), num(s.size[2]));
    let colour = format!(
        "{} {} {}",
        num(s.colour[0]),
        num(s.colour[1]),
        num(s.colour[2])
    );
    out.push_str("Solid {\n");
    pose_fields(out, "  ", &s.pose);
    let _ = writeln!(out, "  children [");
    let _ = writeln!(out, "    Shape {{");
    let _ = writeln!(
        out,
        "      appearance PBRAppearance {{ baseColor {colour} roughness 1 metalness 0 }}"
    );
    let _ = writeln!(out, "      geometry Box {{ size {size} }}");
    let _ = writeln!(out, "    }}");
    let _ = writeln!(out, "  ]");
    let _ = writeln!(out, "  name {}", string(s.name));
    let _ = writeln!(out, "  boundingObject Box {{ size {size} }}");
    if let Some(d) = s.density {
        let _ = writeln!(out, "  physics Physics {{ density {} mass -1 }}", num(d));
    }
    out.push_str("}\n");
}

fn geometry(shape: &Shape) -> String {
    match *shape {
        Shape::Box { half_extents: h } => format!(
            "Box {{ size {} {} {} }}",
            num(2.0 * h[0]),
            num(2.0 * h[1]),
            num(2.0 * h[2])
        ),
        // Webots cylinders and capsules run along their local z, like framewright's.
        Shape::Cylinder { radius, length } => {
            format!(
                "Cylinder {{ height {} radius {} }}",
                num(length),
                num(radius)
            )
        }
        Shape::Capsule { radius, length } => {
            format!(
                "Capsule {{ height {} radius {} }}",
                num(length),
                num(radius)
            )
        }
        Shape::Sphere { radius } => format!("Sphere {{ radius {} }}", num(radius)),
    }
}

fn placed_shapes(out: &mut String, indent: &str, shapes: &[PlacedShape], with_appearance: bool) {
    for s in shapes {
        let _ = writeln!(out, "{indent}Pose {{");
        pose_fields(out, &format!("{indent}  "), &s.origin);
        let _ = writeln!(out, "{indent}  children [");
        if with_appearance {
            let _ = writeln!(
                out,
                "{indent}    Shape {{ appearance PBRAppearance {{ baseColor 0.9 0.45 0.05 roughness 0.5 metalness 0 }} geometry {} }}",
                geometry(&s.shape)
            );
        } else {
            let _ = writeln!(out, "{indent}    {}", geometry(&s.shape));
        }
        let _ = writeln!(out, "{indent}  ]");
        let _ = writeln!(out, "{indent}}}");
    }
}

/// A viewpoint behind and above the cell looking at the assembly area (Webots R2022a+:
/// the camera looks along its x, z up).
fn viewpoint(scene: &Scene) -> (Vector3<f64>, UnitQuaternion<f64>) {
    let target = scene.robot.base.translation.vector + Vector3::new(1.5, 2.0, 0.5);
    let position = target + Vector3::new(7.0, -6.0, 6.0);
    let x = (target - position).normalize();
    let y = Vector3::z().cross(&x).normalize();
    let z = x.cross(&y);
    let rot = nalgebra::Rotation3::from_basis_unchecked(&[x, y, z]);
    (position, UnitQuaternion::from_rotation_matrix(&rot))
}

/// The scene as a Webots R2023b world.
pub fn to_wbt(scene: &Scene) -> String {
    let mut out = String::new();
    out.push_str("#VRML_SIM R2023b utf8\n");
    let _ = writeln!(
        out,
        "# Written by framewright {} from the model {} on the cell {} ({}).",
        env!("CARGO_PKG_VERSION"),
        comment(&scene.model),
        comment(&scene.cell),
        comment(&scene.cell_source)
    );
    let _ = writeln!(
        out,
        "# {} lumber pieces in spawn order on conveyor 1 (slot 0 first, {} m gaps). SI units, z up.",
        scene.pieces.len(),
        num(scene.lumber_gap)
    );
    for w in &scene.warnings {
        let _ = writeln!(out, "# warning: {}", comment(w));
    }
    out.push('\n');
    for proto in [
        "objects/backgrounds/protos/TexturedBackground.proto",
        "objects/backgrounds/protos/TexturedBackgroundLight.proto",
        "objects/floors/protos/Floor.proto",
    ] {
        let _ = writeln!(out, "EXTERNPROTO \"{PROTO_BASE}/{proto}\"");
    }
    if let Some((_, url)) = scene.robot.webots_proto {
        let _ = writeln!(out, "EXTERNPROTO \"{url}\"");
    }
    out.push('\n');
    out.push_str("WorldInfo {\n");
    let _ = writeln!(
        out,
        "  info [ {} ]",
        string(&format!(
            "framewright world of {} on {}",
            scene.model, scene.cell
        ))
    );
    let _ = writeln!(
        out,
        "  title {}",
        string(&format!("{} on {}", scene.model, scene.cell))
    );
    out.push_str("  basicTimeStep 8\n");
    out.push_str("}\n");
    let (position, orientation) = viewpoint(scene);
    let _ = writeln!(
        out,
        "Viewpoint {{\n  orientation {}\n  position {}\n}}",
        axis_angle(&orientation),
        vec(&position)
    );
    out.push_str("TexturedBackground {\n}\nTexturedBackgroundLight {\n}\n");
    let _ = writeln!(
        out,
        "Floor {{\n  translation 0 0 {}\n  size {} {}\n}}",
        num(scene.floor.z),
        num(scene.floor.size[0]),
        num(scene.floor.size[1])
    );

    // Conveyors: a box from the floor up to the belt top.
    for c in &scene.conveyors {
        let top = c.conveyor.pose;
        let height = (top.translation.z - scene.floor.z).max(0.01);
        let pose = top * Translation3::new(0.0, 0.0, -height / 2.0);
        let _ = writeln!(
            out,
            "# {}: belt top centre {}, travel {}, {} m/s",
            c.name,
            vec(&top.translation.vector),
            vec(&c.conveyor.direction()),
            num(c.conveyor.speed)
        );
        box_solid(
            &mut out,
            &BoxSolid {
                name: c.name,
                pose,
                size: [c.conveyor.length, c.conveyor.width, height],
                colour: [0.2, 0.2, 0.22],
                density: None,
            },
        );
    }
    let s = &scene.touch_sensor;
    box_solid(
        &mut out,
        &BoxSolid {
            name: "touch sensor",
            pose: s.pose,
            size: s.size,
            colour: [0.8, 0.1, 0.1],
            density: None,
        },
    );
    tool_table(&mut out, scene);
    robot(&mut out, scene);

    // The queue beyond the belt rests on a static support on the same line, so the world
    // starts at rest; the feeding controller moves those pieces on as the belt clears.
    if let Some(support) = queue_support(scene) {
        out.push_str(
            "# Support under the part of the queue beyond conveyor 1 (not part of the cell).\n",
        );
        box_solid(&mut out, &support);
    }

    for p in &scene.pieces {
        let _ = writeln!(
            out,
            "# slot {}: {} {} of wall {}, {} kg{}",
            p.slot,
            comment(&p.ifc_type),
            comment(&p.name),
            comment(&p.wall),
            num(p.mass),
            if p.beyond_belt.is_some() {
                ", beyond conveyor 1"
            } else {
                ""
            }
        );
        box_solid(
            &mut out,
            &BoxSolid {
                name: &p.id,
                pose: p.spawn,
                size: p.size,
                colour: [0.86, 0.7, 0.48],
                density: Some(p.density),
            },
        );
    }
    out
}

fn tool_table(out: &mut String, scene: &Scene) {
    let t = &scene.tool_table;
    let top = Isometry3::translation(
        t.top_centre.x,
        t.top_centre.y,
        t.top_centre.z - t.size[2] / 2.0,
    );
    out.push_str("# tool table\n");
    out.push_str("Solid {\n");
    pose_fields(out, "  ", &top);
    out.push_str("  children [\n");
    let leg = 0.05_f64.min(t.size[0] / 4.0).min(t.size[1] / 4.0);
    let mut shapes = vec![PlacedShape {
        origin: Isometry3::identity(),
        shape: Shape::Box {
            half_extents: [t.size[0] / 2.0, t.size[1] / 2.0, t.size[2] / 2.0],
        },
    }];
    for (sx, sy) in [(-1.0, -1.0), (-1.0, 1.0), (1.0, -1.0), (1.0, 1.0)] {
        shapes.push(PlacedShape {
            origin: Isometry3::translation(
                sx * (t.size[0] - leg) / 2.0,
                sy * (t.size[1] - leg) / 2.0,
                -(t.size[2] + t.leg_height) / 2.0,
            ),
            shape: Shape::Box {
                half_extents: [leg / 2.0, leg / 2.0, t.leg_height / 2.0],
            },
        });
    }
    placed_shapes(out, "    ", &shapes, true);
    out.push_str("  ]\n  name \"tool table\"\n  boundingObject Group {\n    children [\n");
    placed_shapes(out, "      ", &shapes, false);
    out.push_str("    ]\n  }\n}\n");
}

fn robot(out: &mut String, scene: &Scene) {
    let r = &scene.robot;
    let label = r.description.as_deref().unwrap_or(&r.name);
    match r.webots_proto {
        Some((proto, _)) => {
            let _ = writeln!(
                out,
                "# {}: Webots proto {proto}, static base, no controller",
                comment(label)
            );
            let _ = writeln!(out, "{proto} {{");
            pose_fields(out, "  ", &r.base);
            let _ = writeln!(out, "  name {}", string(label));
            out.push_str("  controller \"<none>\"\n  staticBase TRUE\n}\n");
        }
        None => {
            let _ = writeln!(
                out,
                "# {}: Webots ships no proto of this robot; a static placeholder of its base link.",
                comment(label)
            );
            out.push_str("Solid {\n");
            pose_fields(out, "  ", &r.base);
            out.push_str("  children [\n");
            placed_shapes(out, "    ", &r.base_shapes, true);
            let _ = writeln!(
                out,
                "  ]\n  name {}",
                string(&format!("{label} base (placeholder)"))
            );
            if !r.base_shapes.is_empty() {
                out.push_str("  boundingObject Group {\n    children [\n");
                placed_shapes(out, "      ", &r.base_shapes, false);
                out.push_str("    ]\n  }\n");
            }
            out.push_str("}\n");
        }
    }
}

/// A static box under the queued pieces that lie beyond the upstream end of conveyor 1.
fn queue_support(scene: &Scene) -> Option<BoxSolid<'static>> {
    let reach = scene
        .pieces
        .iter()
        .filter_map(|p| p.beyond_belt)
        .fold(None, |m: Option<f64>, x| Some(m.map_or(x, |m| m.max(x))))?;
    let c = scene.conveyors.first()?.conveyor;
    let top = c.pose;
    let height = (top.translation.z - scene.floor.z).max(0.01);
    let centre_x = -c.length / 2.0 - reach / 2.0;
    Some(BoxSolid {
        name: "queue support beyond conveyor 1",
        pose: top * Translation3::new(centre_x, 0.0, -height / 2.0),
        size: [reach, c.width, height],
        colour: [0.45, 0.45, 0.45],
        density: None,
    })
}
