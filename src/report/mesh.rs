//! Triangle meshes of the collision primitives (cylinders and capsules along local z), for
//! the 3D scene: positions, normals (flat per box face, smooth elsewhere) and indices.

use crate::cell::Shape;
use std::f64::consts::{PI, TAU};

/// Segments around a round shape; rings from pole to pole of a sphere.
const SEGMENTS: usize = 24;
const RINGS: usize = 12;

#[derive(Default)]
struct Mesh {
    positions: Vec<f32>,
    normals: Vec<f32>,
    indices: Vec<u32>,
}

impl Mesh {
    fn vertex(&mut self, p: [f64; 3], n: [f64; 3]) -> u32 {
        let i = (self.positions.len() / 3) as u32;
        self.positions.extend(p.map(|v| v as f32));
        self.normals.extend(n.map(|v| v as f32));
        i
    }

    /// Two triangles a-b-c, a-c-d (counter-clockwise seen from outside).
    fn quad(&mut self, a: u32, b: u32, c: u32, d: u32) {
        self.indices.extend([a, b, c, a, c, d]);
    }

    fn cuboid(&mut self, h: [f64; 3]) {
        // Each face: its normal axis and sign, and two in-plane axes (u × v = normal).
        for axis in 0..3 {
            for sign in [1.0, -1.0] {
                let (u, v) = ((axis + 1) % 3, (axis + 2) % 3);
                let (u, v) = if sign > 0.0 { (u, v) } else { (v, u) };
                let mut n = [0.0; 3];
                n[axis] = sign;
                let corner = |su: f64, sv: f64| {
                    let mut p = [0.0; 3];
                    p[axis] = sign * h[axis];
                    p[u] = su * h[u];
                    p[v] = sv * h[v];
                    p
                };
                let a = self.vertex(corner(-1.0, -1.0), n);
                let b = self.vertex(corner(1.0, -1.0), n);
                let c = self.vertex(corner(1.0, 1.0), n);
                let d = self.vertex(corner(-1.0, 1.0), n);
                self.quad(a, b, c, d);
            }
        }
    }

    /// A tube of `radius` from z0 to z1 with flat caps.
    fn cylinder(&mut self, radius: f64, z0: f64, z1: f64, caps: bool) {
        let ring = |m: &mut Mesh, z: f64| -> Vec<u32> {
            (0..=SEGMENTS)
                .map(|k| {
                    let a = TAU * k as f64 / SEGMENTS as f64;
                    let (s, c) = a.sin_cos();
                    m.vertex([radius * c, radius * s, z], [c, s, 0.0])
                })
                .collect()
        };
        let bottom = ring(self, z0);
        let top = ring(self, z1);
        for k in 0..SEGMENTS {
            self.quad(bottom[k], bottom[k + 1], top[k + 1], top[k]);
        }
        if caps {
            for (z, n) in [(z0, -1.0), (z1, 1.0)] {
                let centre = self.vertex([0.0, 0.0, z], [0.0, 0.0, n]);
                let rim: Vec<u32> = (0..=SEGMENTS)
                    .map(|k| {
                        let a = TAU * k as f64 / SEGMENTS as f64;
                        self.vertex([radius * a.cos(), radius * a.sin(), z], [0.0, 0.0, n])
                    })
                    .collect();
                for k in 0..SEGMENTS {
                    if n > 0.0 {
                        self.indices.extend([centre, rim[k], rim[k + 1]]);
                    } else {
                        self.indices.extend([centre, rim[k + 1], rim[k]]);
                    }
                }
            }
        }
    }

    /// A sphere of `radius` centred at (0, 0, z).
    fn sphere(&mut self, radius: f64, z: f64) {
        let mut rows: Vec<Vec<u32>> = Vec::new();
        for r in 0..=RINGS {
            let polar = PI * r as f64 / RINGS as f64;
            let (sp, cp) = polar.sin_cos();
            rows.push(
                (0..=SEGMENTS)
                    .map(|k| {
                        let a = TAU * k as f64 / SEGMENTS as f64;
                        let n = [sp * a.cos(), sp * a.sin(), cp];
                        self.vertex([radius * n[0], radius * n[1], z + radius * n[2]], n)
                    })
                    .collect(),
            );
        }
        for r in 0..RINGS {
            for k in 0..SEGMENTS {
                // Rows run from the +z pole down: this winding faces outwards.
                self.quad(
                    rows[r][k],
                    rows[r + 1][k],
                    rows[r + 1][k + 1],
                    rows[r][k + 1],
                );
            }
        }
    }
}

/// (positions xyz, normals xyz, triangle indices) of a primitive in its own frame.
pub fn triangles(shape: &Shape) -> (Vec<f32>, Vec<f32>, Vec<u32>) {
    let mut m = Mesh::default();
    match *shape {
        Shape::Box { half_extents } => m.cuboid(half_extents),
        Shape::Cylinder { radius, length } => m.cylinder(radius, -length / 2.0, length / 2.0, true),
        Shape::Capsule { radius, length } => {
            m.cylinder(radius, -length / 2.0, length / 2.0, false);
            m.sphere(radius, -length / 2.0);
            m.sphere(radius, length / 2.0);
        }
        Shape::Sphere { radius } => m.sphere(radius, 0.0),
    }
    (m.positions, m.normals, m.indices)
}
