//! Geometry of the synthetic scenes: 3-vectors, convex faces, polyhedra built
//! from boxes, and the pinhole camera (world → camera → ideal pixels).
//!
//! Units are millimetres in the world; the world's `z` points up from the
//! floor plate, whose top is `z = 0`.

use crate::llv::lens::CameraModel;

pub type V3 = [f64; 3];

pub fn sub(a: V3, b: V3) -> V3 {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}
pub fn add(a: V3, b: V3) -> V3 {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}
pub fn scale(a: V3, s: f64) -> V3 {
    [a[0] * s, a[1] * s, a[2] * s]
}
pub fn dot(a: V3, b: V3) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}
pub fn cross(a: V3, b: V3) -> V3 {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}
pub fn norm(a: V3) -> f64 {
    dot(a, a).sqrt()
}
pub fn unit(a: V3) -> V3 {
    let n = norm(a);
    if n > 0.0 { scale(a, 1.0 / n) } else { a }
}

/// One planar convex face: vertices counter-clockwise seen from outside, so
/// the outward normal is `(v1 - v0) × (v2 - v0)` normalised.
#[derive(Clone, Debug, PartialEq)]
pub struct Face {
    pub vertices: Vec<V3>,
    pub normal: V3,
}

impl Face {
    pub fn new(vertices: Vec<V3>) -> Face {
        // Newell's method: robust for any planar polygon.
        let mut n = [0.0; 3];
        for (i, a) in vertices.iter().enumerate() {
            let b = vertices[(i + 1) % vertices.len()];
            n[0] += (a[1] - b[1]) * (a[2] + b[2]);
            n[1] += (a[2] - b[2]) * (a[0] + b[0]);
            n[2] += (a[0] - b[0]) * (a[1] + b[1]);
        }
        Face {
            vertices,
            normal: unit(n),
        }
    }
}

/// A closed convex polyhedron with one albedo (grey level of a fully lit
/// white-ish surface): its faces differ in brightness only through shading,
/// so an edge between two faces a light lights equally vanishes under it.
#[derive(Clone, Debug, PartialEq)]
pub struct Polyhedron {
    pub name: String,
    pub faces: Vec<Face>,
    /// Grey level the surface would have under unit irradiance (0–255 scale).
    pub albedo: f64,
}

impl Polyhedron {
    /// A box standing on `z = base`, centred at `(x, y)`, of size
    /// `(dx, dy, dz)`, turned by `yaw` radians about the vertical.
    pub fn cuboid(name: &str, centre: V3, size: V3, yaw: f64, albedo: f64) -> Polyhedron {
        let (s, c) = yaw.sin_cos();
        let h = [size[0] / 2.0, size[1] / 2.0];
        let corner = |i: usize| -> V3 {
            // Bit 0: x sign, bit 1: y sign, bit 2: top.
            let lx = if i & 1 == 0 { -h[0] } else { h[0] };
            let ly = if i & 2 == 0 { -h[1] } else { h[1] };
            let z = if i & 4 == 0 { 0.0 } else { size[2] };
            [
                centre[0] + c * lx - s * ly,
                centre[1] + s * lx + c * ly,
                centre[2] + z,
            ]
        };
        // Counter-clockwise from outside.
        let quads: [[usize; 4]; 6] = [
            [0, 2, 3, 1], // bottom (normal -z)
            [4, 5, 7, 6], // top (+z)
            [0, 1, 5, 4], // -y side
            [2, 6, 7, 3], // +y side
            [0, 4, 6, 2], // -x side
            [1, 3, 7, 5], // +x side
        ];
        let faces = quads
            .iter()
            .map(|q| Face::new(q.iter().map(|&i| corner(i)).collect()))
            .collect();
        Polyhedron {
            name: name.to_string(),
            faces,
            albedo,
        }
    }

    /// The distinct edges (vertex pairs) of the faces.
    pub fn edges(&self) -> Vec<(V3, V3)> {
        let mut out: Vec<(V3, V3)> = Vec::new();
        for f in &self.faces {
            for (i, &a) in f.vertices.iter().enumerate() {
                let b = f.vertices[(i + 1) % f.vertices.len()];
                if !out
                    .iter()
                    .any(|&(p, q)| (p == a && q == b) || (p == b && q == a))
                {
                    out.push((a, b));
                }
            }
        }
        out
    }

    /// Every vertex, once.
    pub fn vertices(&self) -> Vec<V3> {
        let mut out: Vec<V3> = Vec::new();
        for f in &self.faces {
            for &v in &f.vertices {
                if !out.contains(&v) {
                    out.push(v);
                }
            }
        }
        out
    }
}

/// A rotation and translation `[R | t]` built so that a camera at `eye` looks
/// at `target`, image `x` to the right and `y` down, the world's `z` up.
pub fn look_at(eye: V3, target: V3) -> [[f64; 4]; 3] {
    let zc = unit(sub(target, eye));
    let mut up = [0.0, 0.0, 1.0];
    if cross(zc, up).iter().all(|c| c.abs() < 1e-9) {
        up = [0.0, 1.0, 0.0];
    }
    let xc = unit(cross(zc, up));
    let yc = cross(zc, xc);
    let r = [xc, yc, zc];
    let mut m = [[0.0; 4]; 3];
    for (row, axis) in m.iter_mut().zip(r) {
        row[..3].copy_from_slice(&axis);
        row[3] = -dot(axis, eye);
    }
    m
}

/// World → camera coordinates with pose `[R | t]`.
pub fn to_camera(pose: &[[f64; 4]; 3], p: V3) -> V3 {
    let r = |i: usize| pose[i][0] * p[0] + pose[i][1] * p[1] + pose[i][2] * p[2] + pose[i][3];
    [r(0), r(1), r(2)]
}

/// Camera → world coordinates (inverse of [`to_camera`], `R` orthonormal).
pub fn to_world(pose: &[[f64; 4]; 3], q: V3) -> V3 {
    let d = [q[0] - pose[0][3], q[1] - pose[1][3], q[2] - pose[2][3]];
    [
        pose[0][0] * d[0] + pose[1][0] * d[1] + pose[2][0] * d[2],
        pose[0][1] * d[0] + pose[1][1] * d[1] + pose[2][1] * d[2],
        pose[0][2] * d[0] + pose[1][2] * d[1] + pose[2][2] * d[2],
    ]
}

/// The ideal (undistorted) pixel of a camera-frame point (`z > 0`).
pub fn project(m: &CameraModel, q: V3) -> (f64, f64) {
    let u = m.f * q[0] / q[2];
    let v = m.f * q[1] / q[2];
    m.to_px(u, v)
}

/// The camera-frame ray direction `(a, b, 1)` through an ideal pixel.
pub fn ray(m: &CameraModel, x: f64, y: f64) -> V3 {
    let (u, v) = m.to_mm(x, y);
    [u / m.f, v / m.f, 1.0]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cuboid_normals_point_outwards() {
        let b = Polyhedron::cuboid("b", [10.0, 20.0, 0.0], [40.0, 60.0, 30.0], 0.3, 200.0);
        let centre = [10.0, 20.0, 15.0];
        for f in &b.faces {
            let out = sub(f.vertices[0], centre);
            assert!(dot(out, f.normal) > 0.0, "{f:?}");
        }
        assert_eq!(b.edges().len(), 12);
        assert_eq!(b.vertices().len(), 8);
    }

    #[test]
    fn look_at_centres_the_target() {
        let pose = look_at([300.0, -400.0, 500.0], [0.0, 0.0, 20.0]);
        let q = to_camera(&pose, [0.0, 0.0, 20.0]);
        assert!(q[0].abs() < 1e-9 && q[1].abs() < 1e-9 && q[2] > 0.0);
        // Up in the world is up in the image (smaller y).
        let up = to_camera(&pose, [0.0, 0.0, 60.0]);
        assert!(up[1] < 0.0);
        let back = to_world(&pose, q);
        assert!(dist3(back, [0.0, 0.0, 20.0]) < 1e-9);
    }

    fn dist3(a: V3, b: V3) -> f64 {
        norm(sub(a, b))
    }
}
