//! The cell and a wall's simulated run as a glTF 2.0 binary (`.glb`): floor, conveyors, touch
//! sensor, tool table, the robot's links and tool (their collision primitives, meshed) and the
//! lumber coloured by verdict, with an animation of every moving node sampled from the
//! executor's pose trace (20 Hz; keys dropped where the motion between their neighbours is
//! linear to within 0.1 mm and 0.2 mrad).
//!
//! The document is built with `gltf-json`; the cell is Z-up, glTF Y-up: one root node turns
//! the one into the other. Node names: `link <name>`, `tool`, `piece <id>`, `floor`, … A
//! piece's node rests at its framing target (the report's viewer draws it there, faint, while
//! it is not in the world).

use super::simulate::SimReport;
use super::verdict;
use crate::cell::{Cell, PlacedShape, Shape};
use crate::sim::record::{LumberTrack, WallRecord};
use crate::world::Scene;
use gltf_json as json;
use json::validation::Checked::Valid;
use json::validation::USize64;
use nalgebra::{Isometry3, Point3, UnitQuaternion, Vector3, Vector4};
use std::collections::BTreeMap;

/// Belt slab thickness drawn under a conveyor's top (m), as in the physics world.
const BELT_SLAB: f64 = 0.10;
/// Largest position and angle error a dropped key may cause (m, rad).
const KEY_TOLERANCE: (f64, f64) = (1e-4, 2e-4);
/// Longest run of samples one pair of keys may span (bounds the reduction's work).
const MAX_SPAN: usize = 32;

/// The static world: cell, robot at home, every piece at its framing target (grey).
pub fn world_glb(cell: &Cell, scene: &Scene) -> Vec<u8> {
    let mut g = Builder::new();
    let mut top = g.cell_nodes(cell);
    let links = g.robot_nodes(cell, &cell.robot.fk_all(&cell.robot.home()));
    top.extend(links.iter().map(|(_, n)| *n));
    for p in &scene.pieces {
        let m = g.material(&format!("lumber {}", p.wall), [0.55, 0.40, 0.22]);
        top.push(g.piece_node(&p.id, &p.size, m, Some(&p.target_cell), false));
    }
    g.finish(top, None)
}

/// One wall's run: the cell, the robot and its lumber, animated over the wall's simulated
/// time, from the parts of a simulation it reads (they can be shared between threads).
/// `None` when the simulation has no record of the wall (by its key).
pub fn scene_wall_glb(
    cell: &Cell,
    scene: &Scene,
    records: &[WallRecord],
    report: &SimReport,
    wall_key: &str,
) -> Option<Vec<u8>> {
    let record = records.iter().find(|r| r.wall == wall_key)?;
    let wall = scene.walls.iter().find(|w| w.id == wall_key)?;
    let end = record.nailing_end;
    let trace = &record.trace;
    let mut g = Builder::new();
    let mut top = g.cell_nodes(cell);
    let home = cell.robot.fk_all(&cell.robot.home());
    let links = g.robot_nodes(cell, &home);
    top.extend(links.iter().map(|(_, n)| *n));
    let mut animation = Animation::default();

    // The robot: every link's pose from the sampled joint values.
    let kept: Vec<usize> = (0..trace.times.len())
        .filter(|&i| trace.times[i] <= end + 1e-9)
        .collect();
    let times: Vec<f64> = kept.iter().map(|&i| trace.times[i]).collect();
    if !times.is_empty() {
        let fk: Vec<Vec<Isometry3<f64>>> = kept
            .iter()
            .map(|&i| cell.robot.fk_all(&trace.joints[i]))
            .collect();
        // The base where the sample had it (a carriage on a track moves it): tool0 as the
        // executor computed it, less the arm's own forward kinematics.
        let bases: Vec<Isometry3<f64>> = kept
            .iter()
            .zip(&fk)
            .map(|(&i, f)| trace.tool[i] * f[cell.robot.tip].inverse())
            .collect();
        for (link, node) in &links {
            let poses: Vec<Isometry3<f64>> =
                fk.iter().zip(&bases).map(|(f, b)| b * f[*link]).collect();
            let (t, p) = until(&times, &poses, end);
            animation.pose(&mut g, *node, &t, &p);
        }
    }

    // The lumber, coloured by verdict and role, shown from its first key until it is gone.
    let rows: BTreeMap<&str, &super::simulate::ElementRow> =
        report.elements.iter().map(|e| (e.id.as_str(), e)).collect();
    for id in &wall.pieces {
        let Some(piece) = scene.pieces.iter().find(|p| &p.id == id) else {
            continue;
        };
        let (class, role) = rows
            .get(id.as_str())
            .map_or(("not-attempted", ""), |e| (verdict::of(e), e.role.as_str()));
        let m = g.material(&format!("{class} {role}"), verdict::linear_rgb(class, role));
        match trace
            .lumber
            .get(id)
            .filter(|t| t.keys.first().is_some_and(|k| k.0 <= end))
        {
            Some(track) => {
                let node = g.piece_node(id, &piece.size, m, Some(&piece.target_cell), true);
                animation.lumber(&mut g, node, track, end);
                top.push(node);
            }
            // Never in the world during the run: shown where it should have gone, hidden.
            None => top.push(g.piece_node(id, &piece.size, m, Some(&piece.target_cell), true)),
        }
    }
    Some(g.finish(top, Some(animation)))
}

/// The samples up to `end`, with a last key at `end` itself (the animation lasts the wall's
/// simulated time).
fn until(times: &[f64], poses: &[Isometry3<f64>], end: f64) -> (Vec<f64>, Vec<Isometry3<f64>>) {
    let mut t: Vec<f64> = Vec::new();
    let mut p = Vec::new();
    for (ti, pi) in times.iter().zip(poses) {
        if *ti <= end + 1e-9 {
            t.push(*ti);
            p.push(*pi);
        }
    }
    if let Some(&last) = p.last()
        && t.last().is_some_and(|l| *l < end - 1e-3)
    {
        t.push(end);
        p.push(last);
    }
    (t, p)
}

/// Indices of the keys to keep: the first, the last, and every key whose drop would move the
/// interpolated pose of a sample between the kept ones by more than the tolerance.
pub fn reduce_keys(times: &[f64], poses: &[Isometry3<f64>]) -> Vec<usize> {
    let n = times.len();
    if n <= 2 {
        return (0..n).collect();
    }
    // Two unit quaternions lie within the angle tolerance of each other exactly when the
    // absolute value of their dot product is at least its half angle's cosine.
    let min_dot = (KEY_TOLERANCE.1 / 2.0).cos();
    let fits = |a: usize, b: usize| {
        let slerp = Slerp::new(&poses[a].rotation, &poses[b].rotation);
        (a + 1..b).all(|k| {
            let s = (times[k] - times[a]) / (times[b] - times[a]);
            let pos = poses[a]
                .translation
                .vector
                .lerp(&poses[b].translation.vector, s);
            (pos - poses[k].translation.vector).norm() <= KEY_TOLERANCE.0
                && slerp.at(s).dot(&poses[k].rotation.coords).abs() >= min_dot
        })
    };
    let mut kept = vec![0];
    let mut anchor = 0;
    let mut j = 2;
    while j < n {
        if j - anchor > MAX_SPAN || !fits(anchor, j) {
            anchor = j - 1;
            kept.push(anchor);
        }
        j += 1;
    }
    kept.push(n - 1);
    kept
}

/// Spherical interpolation between two rotations (the short way, as glTF viewers and
/// nalgebra's `slerp` interpolate), its angle worked out once for many fractions.
struct Slerp {
    a: Vector4<f64>,
    b: Vector4<f64>,
    angle: f64,
    sin_angle: f64,
}

impl Slerp {
    fn new(a: &UnitQuaternion<f64>, b: &UnitQuaternion<f64>) -> Slerp {
        let a = a.coords;
        let b = if a.dot(&b.coords) < 0.0 {
            -b.coords
        } else {
            b.coords
        };
        let cos = a.dot(&b).min(1.0);
        Slerp {
            a,
            b,
            angle: cos.acos(),
            sin_angle: (1.0 - cos * cos).sqrt(),
        }
    }

    /// The interpolated rotation's coordinates at fraction `t`.
    fn at(&self, t: f64) -> Vector4<f64> {
        if self.sin_angle <= f64::EPSILON {
            return self.a;
        }
        self.a * (((1.0 - t) * self.angle).sin() / self.sin_angle)
            + self.b * ((t * self.angle).sin() / self.sin_angle)
    }
}

#[derive(Default)]
struct Animation {
    channels: Vec<json::animation::Channel>,
    samplers: Vec<json::animation::Sampler>,
}

impl Animation {
    fn channel(
        &mut self,
        node: json::Index<json::Node>,
        path: json::animation::Property,
        input: json::Index<json::Accessor>,
        output: json::Index<json::Accessor>,
        interpolation: json::animation::Interpolation,
    ) {
        let sampler = json::Index::new(self.samplers.len() as u32);
        self.samplers.push(json::animation::Sampler {
            extensions: None,
            extras: Default::default(),
            input,
            interpolation: Valid(interpolation),
            output,
        });
        self.channels.push(json::animation::Channel {
            sampler,
            target: json::animation::Target {
                extensions: None,
                extras: Default::default(),
                node,
                path: Valid(path),
            },
            extensions: None,
            extras: Default::default(),
        });
    }

    /// Translation and rotation keys of a node (cell-frame poses), reduced.
    fn pose(
        &mut self,
        g: &mut Builder,
        node: json::Index<json::Node>,
        times: &[f64],
        poses: &[Isometry3<f64>],
    ) {
        if times.is_empty() {
            return;
        }
        let mut keep = reduce_keys(times, poses);
        // Key times must increase strictly in f32 too.
        keep.dedup_by(|b, a| times[*b] as f32 <= times[*a] as f32);
        let t: Vec<f32> = keep.iter().map(|&i| times[i] as f32).collect();
        let input = g.times(&t);
        let mut translations = Vec::with_capacity(keep.len() * 3);
        let mut rotations = Vec::with_capacity(keep.len() * 4);
        let mut previous: Option<UnitQuaternion<f64>> = None;
        for &i in &keep {
            let v = poses[i].translation.vector;
            translations.extend([v.x as f32, v.y as f32, v.z as f32]);
            // Keep neighbouring quaternions on one hemisphere so interpolation takes the short way.
            let mut q = poses[i].rotation;
            if previous.is_some_and(|p| p.coords.dot(&q.coords) < 0.0) {
                q = UnitQuaternion::new_unchecked(-q.into_inner());
            }
            previous = Some(q);
            rotations.extend([q.i as f32, q.j as f32, q.k as f32, q.w as f32]);
        }
        let out_t = g.floats(&translations, json::accessor::Type::Vec3, false);
        let out_r = g.floats(&rotations, json::accessor::Type::Vec4, false);
        use json::animation::{Interpolation::Linear, Property};
        self.channel(node, Property::Translation, input, out_t, Linear);
        self.channel(node, Property::Rotation, input, out_r, Linear);
    }

    /// A piece's keys, and its scale stepping 0 → 1 when it appears and → 0 when it goes.
    fn lumber(
        &mut self,
        g: &mut Builder,
        node: json::Index<json::Node>,
        track: &LumberTrack,
        end: f64,
    ) {
        let times: Vec<f64> = track.keys.iter().map(|k| k.0).collect();
        let poses: Vec<Isometry3<f64>> = track.keys.iter().map(|k| k.1).collect();
        let (t, p) = until(&times, &poses, end);
        self.pose(g, node, &t, &p);
        let first = t[0];
        let mut steps: Vec<(f32, f32)> = Vec::new();
        if first > 0.0 {
            steps.push((0.0, 0.0));
        }
        steps.push((first as f32, 1.0));
        if let Some(gone) = track.gone.filter(|g| *g <= end && *g as f32 > first as f32) {
            steps.push((gone as f32, 0.0));
        }
        let input = g.times(&steps.iter().map(|s| s.0).collect::<Vec<_>>());
        let scales: Vec<f32> = steps.iter().flat_map(|s| [s.1; 3]).collect();
        let output = g.floats(&scales, json::accessor::Type::Vec3, false);
        self.channel(
            node,
            json::animation::Property::Scale,
            input,
            output,
            json::animation::Interpolation::Step,
        );
    }
}

/// Builds the document and its binary buffer.
struct Builder {
    root: json::Root,
    bin: Vec<u8>,
    materials: BTreeMap<String, json::Index<json::Material>>,
    meshes: BTreeMap<String, json::Index<json::Mesh>>,
}

impl Builder {
    fn new() -> Builder {
        let root = json::Root {
            asset: json::Asset {
                generator: Some(format!("framewright {}", env!("CARGO_PKG_VERSION"))),
                ..Default::default()
            },
            ..Default::default()
        };
        Builder {
            root,
            bin: Vec::new(),
            materials: BTreeMap::new(),
            meshes: BTreeMap::new(),
        }
    }

    /// A buffer view of `bytes` (4-byte aligned in the buffer).
    fn view(
        &mut self,
        bytes: &[u8],
        target: Option<json::buffer::Target>,
    ) -> json::Index<json::buffer::View> {
        while !self.bin.len().is_multiple_of(4) {
            self.bin.push(0);
        }
        let offset = self.bin.len();
        self.bin.extend_from_slice(bytes);
        self.root.push(json::buffer::View {
            buffer: json::Index::new(0),
            byte_length: USize64::from(bytes.len()),
            byte_offset: Some(USize64::from(offset)),
            byte_stride: None,
            extensions: None,
            extras: Default::default(),
            name: None,
            target: target.map(Valid),
        })
    }

    fn accessor(
        &mut self,
        view: json::Index<json::buffer::View>,
        count: usize,
        component: json::accessor::ComponentType,
        type_: json::accessor::Type,
        bounds: Option<(Vec<f32>, Vec<f32>)>,
    ) -> json::Index<json::Accessor> {
        let (min, max) = bounds.map_or((None, None), |(a, b)| {
            (Some(serde_json::json!(a)), Some(serde_json::json!(b)))
        });
        self.root.push(json::Accessor {
            buffer_view: Some(view),
            byte_offset: Some(USize64(0)),
            count: USize64::from(count),
            component_type: Valid(json::accessor::GenericComponentType(component)),
            extensions: None,
            extras: Default::default(),
            type_: Valid(type_),
            min,
            max,
            name: None,
            normalized: false,
            sparse: None,
        })
    }

    /// f32 data of `type_` (Vec3, Vec4, Scalar); with min/max when `bounds`.
    fn floats(
        &mut self,
        data: &[f32],
        type_: json::accessor::Type,
        bounds: bool,
    ) -> json::Index<json::Accessor> {
        let width = type_.multiplicity();
        let count = data.len() / width;
        let bounds = bounds.then(|| {
            let mut min = vec![f32::INFINITY; width];
            let mut max = vec![f32::NEG_INFINITY; width];
            for chunk in data.chunks(width) {
                for (k, v) in chunk.iter().enumerate() {
                    min[k] = min[k].min(*v);
                    max[k] = max[k].max(*v);
                }
            }
            (min, max)
        });
        let bytes: Vec<u8> = data.iter().flat_map(|v| v.to_le_bytes()).collect();
        // Only vertex positions are vertex data; keyframes have no buffer target.
        let target = (type_ == json::accessor::Type::Vec3 && bounds.is_some())
            .then_some(json::buffer::Target::ArrayBuffer);
        let view = self.view(&bytes, target);
        self.accessor(
            view,
            count,
            json::accessor::ComponentType::F32,
            type_,
            bounds,
        )
    }

    /// Keyframe times (with the min/max the spec requires of animation inputs).
    fn times(&mut self, t: &[f32]) -> json::Index<json::Accessor> {
        self.floats(t, json::accessor::Type::Scalar, true)
    }

    fn material(&mut self, name: &str, rgb: [f32; 3]) -> json::Index<json::Material> {
        if let Some(m) = self.materials.get(name) {
            return *m;
        }
        let mut material = json::Material {
            name: Some(name.to_string()),
            ..Default::default()
        };
        material.pbr_metallic_roughness.base_color_factor =
            json::material::PbrBaseColorFactor([rgb[0], rgb[1], rgb[2], 1.0]);
        material.pbr_metallic_roughness.metallic_factor = json::material::StrengthFactor(0.0);
        material.pbr_metallic_roughness.roughness_factor = json::material::StrengthFactor(0.8);
        let index = self.root.push(material);
        self.materials.insert(name.to_string(), index);
        index
    }

    /// The mesh of a primitive in one material (shared by every node that shows it).
    fn mesh(
        &mut self,
        shape: &Shape,
        material: json::Index<json::Material>,
    ) -> json::Index<json::Mesh> {
        let key = format!("{shape:?} {}", material.value());
        if let Some(m) = self.meshes.get(&key) {
            return *m;
        }
        let (positions, normals, indices) = super::mesh::triangles(shape);
        let pos = self.floats(&positions, json::accessor::Type::Vec3, true);
        let nor = {
            let bytes: Vec<u8> = normals.iter().flat_map(|v| v.to_le_bytes()).collect();
            let view = self.view(&bytes, Some(json::buffer::Target::ArrayBuffer));
            self.accessor(
                view,
                normals.len() / 3,
                json::accessor::ComponentType::F32,
                json::accessor::Type::Vec3,
                None,
            )
        };
        let idx = {
            let bytes: Vec<u8> = indices.iter().flat_map(|v| v.to_le_bytes()).collect();
            let view = self.view(&bytes, Some(json::buffer::Target::ElementArrayBuffer));
            self.accessor(
                view,
                indices.len(),
                json::accessor::ComponentType::U32,
                json::accessor::Type::Scalar,
                None,
            )
        };
        let mut attributes = BTreeMap::new();
        attributes.insert(Valid(json::mesh::Semantic::Positions), pos);
        attributes.insert(Valid(json::mesh::Semantic::Normals), nor);
        let mesh = self.root.push(json::Mesh {
            extensions: None,
            extras: Default::default(),
            name: None,
            primitives: vec![json::mesh::Primitive {
                attributes,
                extensions: None,
                extras: Default::default(),
                indices: Some(idx),
                material: Some(material),
                mode: Valid(json::mesh::Mode::Triangles),
                targets: None,
            }],
            weights: None,
        });
        self.meshes.insert(key, mesh);
        mesh
    }

    fn node(
        &mut self,
        name: &str,
        pose: Option<&Isometry3<f64>>,
        mesh: Option<json::Index<json::Mesh>>,
        children: Vec<json::Index<json::Node>>,
    ) -> json::Index<json::Node> {
        let (translation, rotation) = pose.map_or((None, None), |p| {
            let v = p.translation.vector;
            let q = p.rotation;
            (
                Some([v.x as f32, v.y as f32, v.z as f32]),
                Some(json::scene::UnitQuaternion([
                    q.i as f32, q.j as f32, q.k as f32, q.w as f32,
                ])),
            )
        });
        self.root.push(json::Node {
            children: (!children.is_empty()).then_some(children),
            mesh,
            name: Some(name.to_string()),
            translation,
            rotation,
            ..Default::default()
        })
    }

    /// A node showing `shape` at `origin` in its parent.
    fn shape_node(
        &mut self,
        name: &str,
        shape: &PlacedShape,
        material: json::Index<json::Material>,
    ) -> json::Index<json::Node> {
        let mesh = self.mesh(&shape.shape, material);
        self.node(name, Some(&shape.origin), Some(mesh), Vec::new())
    }

    fn boxed(
        &mut self,
        name: &str,
        pose: Isometry3<f64>,
        size: [f64; 3],
        material: json::Index<json::Material>,
    ) -> json::Index<json::Node> {
        let shape = PlacedShape {
            origin: pose,
            shape: Shape::Box {
                half_extents: size.map(|s| s / 2.0),
            },
        };
        self.shape_node(name, &shape, material)
    }

    /// Floor, conveyors (belt and frame), touch sensor and tool table.
    fn cell_nodes(&mut self, cell: &Cell) -> Vec<json::Index<json::Node>> {
        let floor_m = self.material("floor", [0.5, 0.5, 0.5]);
        let belt_m = self.material("conveyor", [0.05, 0.05, 0.06]);
        let frame_m = self.material("conveyor frame", [0.2, 0.25, 0.35]);
        let sensor_m = self.material("touch sensor", [0.9, 0.75, 0.0]);
        let table_m = self.material("tool table", [0.35, 0.22, 0.12]);
        let f = cell.floor;
        let mut nodes = vec![self.boxed(
            "floor",
            Isometry3::translation(0.0, 0.0, f.z - 0.05),
            [f.size[0], f.size[1], 0.1],
            floor_m,
        )];
        for (name, c) in [
            ("conveyor 1", &cell.conveyor1),
            ("conveyor 2", &cell.conveyor2),
        ] {
            let slab = c.pose * Isometry3::translation(0.0, 0.0, -BELT_SLAB / 2.0);
            nodes.push(self.boxed(name, slab, [c.length, c.width, BELT_SLAB], belt_m));
            let h = c.pose.translation.z - BELT_SLAB - f.z;
            if h > 0.01 {
                let frame = c.pose * Isometry3::translation(0.0, 0.0, -BELT_SLAB - h / 2.0);
                nodes.push(self.boxed(
                    &format!("{name} frame"),
                    frame,
                    [c.length, c.width * 0.8, h],
                    frame_m,
                ));
            }
        }
        let s = cell.touch_sensor;
        nodes.push(self.boxed("touch sensor", s.pose, s.size, sensor_m));
        let t = cell.tool_table;
        nodes.push(self.boxed(
            "tool table",
            Isometry3::translation(
                t.top_centre.x,
                t.top_centre.y,
                t.top_centre.z - t.size[2] / 2.0,
            ),
            t.size,
            table_m,
        ));
        let leg = 0.05;
        let h = t.top_centre.z - t.size[2] - f.z;
        if h > 0.01 {
            for (sx, sy) in [(-1.0, -1.0), (-1.0, 1.0), (1.0, -1.0), (1.0, 1.0)] {
                let pose = Isometry3::translation(
                    t.top_centre.x + sx * (t.size[0] / 2.0 - leg),
                    t.top_centre.y + sy * (t.size[1] / 2.0 - leg),
                    f.z + h / 2.0,
                );
                nodes.push(self.boxed("tool table leg", pose, [leg, leg, h], table_m));
            }
        }
        nodes
    }

    /// A node per robot link with shapes (posed by `fk`, base frame), the tool under the tip
    /// link. Returns (link index, node).
    fn robot_nodes(
        &mut self,
        cell: &Cell,
        fk: &[Isometry3<f64>],
    ) -> Vec<(usize, json::Index<json::Node>)> {
        // Blue: apart from every verdict's colour (green, amber, red, grey).
        let robot_m = self.material("robot", [0.06, 0.2, 0.55]);
        let tool_m = self.material("tool", [0.25, 0.25, 0.27]);
        let robot = &cell.robot;
        let mut out = Vec::new();
        for (i, link) in robot.links.iter().enumerate() {
            let mut children: Vec<json::Index<json::Node>> = link
                .collisions
                .iter()
                .enumerate()
                .map(|(k, s)| self.shape_node(&format!("{} shape {k}", link.name), s, robot_m))
                .collect();
            if i == robot.tip {
                let parts: Vec<json::Index<json::Node>> = cell
                    .tool
                    .parts
                    .iter()
                    .map(|p| self.shape_node(&format!("tool {}", p.name), &p.shape, tool_m))
                    .collect();
                children.push(self.node("tool", None, None, parts));
            }
            if children.is_empty() {
                continue;
            }
            let pose = cell.robot_base * fk[i];
            out.push((
                i,
                self.node(&format!("link {}", link.name), Some(&pose), None, children),
            ));
        }
        out
    }

    fn piece_node(
        &mut self,
        id: &str,
        size: &[f64; 3],
        material: json::Index<json::Material>,
        pose: Option<&Isometry3<f64>>,
        hidden: bool,
    ) -> json::Index<json::Node> {
        let shape = Shape::Box {
            half_extents: size.map(|s| s / 2.0),
        };
        let mesh = self.mesh(&shape, material);
        let node = self.node(&format!("piece {id}"), pose, Some(mesh), Vec::new());
        if hidden {
            self.root.nodes[node.value()].scale = Some([0.0; 3]);
        }
        node
    }

    /// The GLB bytes: a Y-up root over `top`, one scene, the animation.
    fn finish(
        mut self,
        top: Vec<json::Index<json::Node>>,
        animation: Option<Animation>,
    ) -> Vec<u8> {
        let z_up =
            UnitQuaternion::from_axis_angle(&Vector3::x_axis(), -std::f64::consts::FRAC_PI_2);
        let root = self.node(
            "cell (Z up)",
            Some(&Isometry3::from_parts(Point3::origin().into(), z_up)),
            None,
            top,
        );
        if let Some(a) = animation
            && !a.channels.is_empty()
        {
            self.root.push(json::Animation {
                extensions: None,
                extras: Default::default(),
                channels: a.channels,
                name: Some("run".into()),
                samplers: a.samplers,
            });
        }
        self.root.push(json::Scene {
            extensions: None,
            extras: Default::default(),
            name: Some("cell".into()),
            nodes: vec![root],
        });
        self.root.scene = Some(json::Index::new(0));
        while !self.bin.len().is_multiple_of(4) {
            self.bin.push(0);
        }
        self.root.push(json::Buffer {
            byte_length: USize64::from(self.bin.len()),
            extensions: None,
            extras: Default::default(),
            name: None,
            uri: None,
        });
        let mut text = self.root.to_vec().unwrap_or_default();
        while !text.len().is_multiple_of(4) {
            text.push(b' ');
        }
        container(&text, &self.bin)
    }
}

/// The GLB container: header, JSON chunk, BIN chunk (both 4-byte padded already).
fn container(text: &[u8], bin: &[u8]) -> Vec<u8> {
    let total = 12 + 8 + text.len() + 8 + bin.len();
    let mut out = Vec::with_capacity(total);
    out.extend_from_slice(b"glTF");
    out.extend_from_slice(&2u32.to_le_bytes());
    out.extend_from_slice(&(total as u32).to_le_bytes());
    out.extend_from_slice(&(text.len() as u32).to_le_bytes());
    out.extend_from_slice(b"JSON");
    out.extend_from_slice(text);
    out.extend_from_slice(&(bin.len() as u32).to_le_bytes());
    out.extend_from_slice(b"BIN\0");
    out.extend_from_slice(bin);
    out
}
