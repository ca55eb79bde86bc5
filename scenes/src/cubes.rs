//! The default `cubes` scene: the four cubes of the 2D-homogeneous
//! rasterization tutorial.
//!
//! Design: the scene is one unit cube mesh (corners at ±1) drawn four times
//! with different model transforms, seen by a fixed camera. The geometry is
//! plain arrays (so tests can check it independently of the core), and
//! [`MESH`] wraps them as the core's `Mesh` for the host, the firmware and
//! the simulator alike.
//!
//! Triangles come in coplanar pairs, one pair per cube face; [`TRIANGLE_FACE`]
//! maps a triangle to its face and [`FACE_COLORS`] gives each face a colour
//! (the Okabe–Ito colour-blind-safe palette). Every triangle winds
//! counter-clockwise seen from outside the cube (right-hand-rule normal points
//! away from the centre); see [`CUBE_FRONT_FACE_CCW`].
//!
//! Model transforms are listed in the order they are applied to a vertex: for
//! `[Translate(t), RotateYDeg(a)]` the vertex is translated first and then
//! rotated about the origin, i.e. the model matrix is `M = R * T` acting on
//! column vectors `M * [x, y, z, 1]`. Rotations are right-handed: a positive
//! angle turns counter-clockwise when looking from the positive axis towards
//! the origin (e.g. `RotateZDeg(90)` maps +x to +y).

use microraster::math::radians;
use microraster::pixelcolor::Rgb888;
use microraster::{BoundingSphere, Mat4, Mesh, MeshColors, Vec3};

/// Cube corner positions (model space).
pub const CUBE_VERTICES: [[f32; 3]; 8] = [
    [1.0, -1.0, -1.0],
    [1.0, -1.0, 1.0],
    [-1.0, -1.0, 1.0],
    [-1.0, -1.0, -1.0],
    [1.0, 1.0, -1.0],
    [1.0, 1.0, 1.0],
    [-1.0, 1.0, 1.0],
    [-1.0, 1.0, -1.0],
];

/// Cube triangles as indices into [`CUBE_VERTICES`].
pub const CUBE_INDICES: [[u32; 3]; 12] = [
    [1, 3, 0],
    [7, 5, 4],
    [4, 1, 0],
    [5, 2, 1],
    [2, 7, 3],
    [0, 7, 4],
    [1, 2, 3],
    [7, 6, 5],
    [4, 5, 1],
    [5, 6, 2],
    [2, 6, 7],
    [0, 3, 7],
];

/// Number of cube faces.
pub const FACE_COUNT: usize = 6;

/// Face of each triangle in [`CUBE_INDICES`] (an index into [`FACE_COLORS`],
/// [`FACE_NAMES`] and [`FACE_NORMALS`]). Triangles `i` and `i + 6` share a face.
pub const TRIANGLE_FACE: [usize; 12] = [0, 1, 2, 3, 4, 5, 0, 1, 2, 3, 4, 5];

/// Human-readable plane of each face.
pub const FACE_NAMES: [&str; FACE_COUNT] = ["y=-1", "y=+1", "x=+1", "z=+1", "x=-1", "z=-1"];

/// Outward unit normal of each face (model space).
pub const FACE_NORMALS: [[f32; 3]; FACE_COUNT] = [
    [0.0, -1.0, 0.0],
    [0.0, 1.0, 0.0],
    [1.0, 0.0, 0.0],
    [0.0, 0.0, 1.0],
    [-1.0, 0.0, 0.0],
    [0.0, 0.0, -1.0],
];

/// One colour per face (Okabe–Ito palette).
pub const FACE_COLORS: [[u8; 3]; FACE_COUNT] = [
    [230, 159, 0],   // y=-1: orange
    [86, 180, 233],  // y=+1: sky blue
    [0, 158, 115],   // x=+1: bluish green
    [240, 228, 66],  // z=+1: yellow
    [0, 114, 178],   // x=-1: blue
    [204, 121, 167], // z=-1: reddish purple
];

/// Face of triangle `tri_index` of the cube, or `None` past the 12 triangles.
pub fn triangle_face(tri_index: usize) -> Option<usize> {
    TRIANGLE_FACE.get(tri_index).copied()
}

/// Colour of triangle `tri_index` of the cube, or `None` past the 12 triangles.
pub fn triangle_color(tri_index: usize) -> Option<[u8; 3]> {
    triangle_face(tri_index).map(|f| FACE_COLORS[f])
}

/// `true`: every cube triangle is counter-clockwise seen from outside, so with
/// a counter-clockwise front-face convention back-face culling removes the
/// hidden faces (verified by a test).
pub const CUBE_FRONT_FACE_CCW: bool = true;

/// One step of a model transform.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Op {
    /// Add the vector to the position.
    Translate([f32; 3]),
    /// Rotate about the x axis by the angle in degrees (right-handed).
    RotateXDeg(f32),
    /// Rotate about the y axis by the angle in degrees (right-handed).
    RotateYDeg(f32),
    /// Rotate about the z axis by the angle in degrees (right-handed).
    RotateZDeg(f32),
}

impl Op {
    /// This step as a matrix (acting on column vectors).
    pub fn matrix(self) -> Mat4 {
        match self {
            Op::Translate(t) => Mat4::translation(Vec3::from_array(t)),
            Op::RotateXDeg(a) => Mat4::rotation_x(radians(a)),
            Op::RotateYDeg(a) => Mat4::rotation_y(radians(a)),
            Op::RotateZDeg(a) => Mat4::rotation_z(radians(a)),
        }
    }

    /// Applies this step to a point.
    pub fn apply(self, p: [f32; 3]) -> [f32; 3] {
        let q = self.matrix().transform_point(Vec3::from_array(p));
        [q.x, q.y, q.z]
    }
}

/// The model matrix of `ops` applied in order (first op first), i.e.
/// `ops[n-1] * ... * ops[1] * ops[0]`.
pub fn model_matrix(ops: &[Op]) -> Mat4 {
    ops.iter().fold(Mat4::IDENTITY, |m, op| op.matrix() * m)
}

/// Applies `ops` to a point in order (first op first).
pub fn transform_point(ops: &[Op], p: [f32; 3]) -> [f32; 3] {
    ops.iter().fold(p, |q, op| op.apply(q))
}

/// The four cube instances: each is translated, then rotated about the origin.
pub const CUBE_MODELS: [[Op; 2]; 4] = [
    [Op::Translate([0.0, 0.0, 2.0]), Op::RotateYDeg(45.0)],
    [Op::Translate([-3.75, 0.0, 0.0]), Op::RotateXDeg(30.0)],
    [Op::Translate([3.75, 0.0, 0.0]), Op::RotateYDeg(60.0)],
    [Op::Translate([0.0, 0.0, -2.0]), Op::RotateZDeg(90.0)],
];

/// Camera position.
pub const CUBES_EYE: [f32; 3] = [0.0, 3.75, 6.5];
/// Point the camera looks at.
pub const CUBES_TARGET: [f32; 3] = [0.0, 0.0, 0.0];
/// Camera up direction.
pub const CUBES_UP: [f32; 3] = [0.0, 1.0, 0.0];
/// Vertical field of view in degrees.
pub const CUBES_FOV_Y_DEG: f32 = 60.0;
/// Near clipping plane distance.
pub const CUBES_NEAR: f32 = 0.1;
/// Far clipping plane distance.
pub const CUBES_FAR: f32 = 100.0;

/// Cube corners as core vectors.
pub const POSITIONS: [Vec3; 8] = {
    let mut out = [Vec3::ZERO; 8];
    let mut i = 0;
    while i < 8 {
        out[i] = Vec3::from_array(CUBE_VERTICES[i]);
        i += 1;
    }
    out
};

/// The colour of each of the 12 triangles (its face's colour).
pub const TRIANGLE_COLORS: [Rgb888; 12] = {
    let mut out = [Rgb888::new(0, 0, 0); 12];
    let mut i = 0;
    while i < 12 {
        let c = FACE_COLORS[TRIANGLE_FACE[i]];
        out[i] = Rgb888::new(c[0], c[1], c[2]);
        i += 1;
    }
    out
};

/// The cube mesh, flat colour per face, with its bounding sphere (centre
/// 0, radius a little over sqrt(3)).
pub const MESH: Mesh<'static> = Mesh {
    positions: &POSITIONS,
    indices: &CUBE_INDICES,
    attributes: MeshColors::PerTriangle(&TRIANGLE_COLORS),
    bounds: Some(BoundingSphere {
        center: Vec3::ZERO,
        radius: 1.7321,
    }),
};

/// Projection times view for a `width x height` frame.
pub fn view_projection(width: u32, height: u32) -> Mat4 {
    let aspect = width as f32 / height as f32;
    let proj = Mat4::perspective(radians(CUBES_FOV_Y_DEG), aspect, CUBES_NEAR, CUBES_FAR);
    let v = Vec3::from_array;
    proj * Mat4::look_at(v(CUBES_EYE), v(CUBES_TARGET), v(CUBES_UP))
}

/// The model-view-projection matrix of each of the four cubes.
pub fn mvps(width: u32, height: u32) -> [Mat4; 4] {
    let vp = view_projection(width, height);
    CUBE_MODELS.map(|ops| vp * model_matrix(&ops))
}

/// [`view_projection`] with 1/w depth (`Mat4::perspective_inv_w`: window
/// depth `near / w`, draw with `DepthFunc::Greater` into a depth buffer
/// cleared to 0; no far plane).
pub fn view_projection_inv_w(width: u32, height: u32) -> Mat4 {
    let aspect = width as f32 / height as f32;
    let proj = Mat4::perspective_inv_w(radians(CUBES_FOV_Y_DEG), aspect, CUBES_NEAR);
    let v = Vec3::from_array;
    proj * Mat4::look_at(v(CUBES_EYE), v(CUBES_TARGET), v(CUBES_UP))
}

/// [`mvps`] with 1/w depth ([`view_projection_inv_w`]).
pub fn mvps_inv_w(width: u32, height: u32) -> [Mat4; 4] {
    let vp = view_projection_inv_w(width, height);
    CUBE_MODELS.map(|ops| vp * model_matrix(&ops))
}

/// Calls `draw(mesh, mvp, first_id)` for each cube in drawing order; the
/// triangle ids run 0..48. Works with `Submit::submit_mesh` on a `Frame`
/// and a `StripRenderer` alike.
pub fn for_each_cube(width: u32, height: u32, mut draw: impl FnMut(&Mesh<'static>, &Mat4, u32)) {
    for (i, mvp) in mvps(width, height).iter().enumerate() {
        draw(&MESH, mvp, (i * CUBE_INDICES.len()) as u32);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::vec::Vec;

    fn sub(a: [f32; 3], b: [f32; 3]) -> [f32; 3] {
        [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
    }
    fn cross(a: [f32; 3], b: [f32; 3]) -> [f32; 3] {
        [
            a[1] * b[2] - a[2] * b[1],
            a[2] * b[0] - a[0] * b[2],
            a[0] * b[1] - a[1] * b[0],
        ]
    }
    fn dot(a: [f32; 3], b: [f32; 3]) -> f32 {
        a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
    }
    fn tri(t: usize) -> [[f32; 3]; 3] {
        CUBE_INDICES[t].map(|i| CUBE_VERTICES[i as usize])
    }
    fn close(a: [f32; 3], b: [f32; 3]) -> bool {
        (0..3).all(|k| (a[k] - b[k]).abs() < 1e-5)
    }

    #[test]
    fn triangle_faces_are_coplanar_pairs() {
        for (t, &f) in TRIANGLE_FACE.iter().enumerate() {
            let n = FACE_NORMALS[f];
            // All three vertices lie on the face plane n·p = 1.
            for p in tri(t) {
                assert_eq!(
                    dot(n, p),
                    1.0,
                    "triangle {t} vertex {p:?} not on {}",
                    FACE_NAMES[f]
                );
            }
        }
        // Each face has exactly two triangles, and together they use its 4 corners.
        for f in 0..FACE_COUNT {
            let tris: Vec<usize> = (0..12).filter(|&t| TRIANGLE_FACE[t] == f).collect();
            assert_eq!(tris.len(), 2, "face {f}");
            let mut corners: Vec<u32> = tris.iter().flat_map(|&t| CUBE_INDICES[t]).collect();
            corners.sort_unstable();
            corners.dedup();
            assert_eq!(corners.len(), 4, "face {f}");
        }
        assert_eq!(triangle_face(11), Some(5));
        assert_eq!(triangle_face(12), None);
        assert_eq!(triangle_color(0), Some(FACE_COLORS[0]));
        assert_eq!(triangle_color(99), None);
    }

    #[test]
    fn triangles_wind_ccw_from_outside() {
        let mut all_ccw = true;
        for t in 0..12 {
            let [a, b, c] = tri(t);
            let n = cross(sub(b, a), sub(c, a));
            let centroid = [0, 1, 2].map(|k| (a[k] + b[k] + c[k]) / 3.0);
            // Cube centre is the origin.
            let outward = dot(n, centroid) > 0.0;
            all_ccw &= outward;
            // Normal is along the face normal either way.
            let face_n = FACE_NORMALS[TRIANGLE_FACE[t]];
            assert!(close(cross(n, face_n), [0.0; 3]), "triangle {t}");
        }
        assert_eq!(all_ccw, CUBE_FRONT_FACE_CCW);
    }

    #[test]
    fn face_colors_are_distinct() {
        for (i, a) in FACE_COLORS.iter().enumerate() {
            for b in &FACE_COLORS[i + 1..] {
                assert_ne!(a, b);
            }
        }
    }

    #[test]
    fn rotations_are_right_handed() {
        assert!(close(
            Op::RotateZDeg(90.0).apply([1.0, 0.0, 0.0]),
            [0.0, 1.0, 0.0]
        ));
        assert!(close(
            Op::RotateXDeg(90.0).apply([0.0, 1.0, 0.0]),
            [0.0, 0.0, 1.0]
        ));
        assert!(close(
            Op::RotateYDeg(90.0).apply([0.0, 0.0, 1.0]),
            [1.0, 0.0, 0.0]
        ));
        assert!(close(
            Op::Translate([1.0, 2.0, 3.0]).apply([1.0, 1.0, 1.0]),
            [2.0, 3.0, 4.0]
        ));
    }

    #[test]
    fn translate_then_rotate() {
        // Cube 4: translate (0,0,-2) then rotate 90° about z: the centre stays at
        // (0,0,-2) and the corner (1,-1,-1) goes to (1,-1,-3) then to (1,1,-3).
        let ops = &CUBE_MODELS[3];
        assert!(close(transform_point(ops, [0.0; 3]), [0.0, 0.0, -2.0]));
        assert!(close(
            transform_point(ops, [1.0, -1.0, -1.0]),
            [1.0, 1.0, -3.0]
        ));
        // Cube 1: the centre (0,0,2) rotates 45° about y onto (√2, 0, √2).
        let h = std::f32::consts::SQRT_2;
        assert!(close(
            transform_point(&CUBE_MODELS[0], [0.0; 3]),
            [h, 0.0, h]
        ));
        // Cube 2: the centre stays on the x axis (rotation about x).
        assert!(close(
            transform_point(&CUBE_MODELS[1], [0.0; 3]),
            [-3.75, 0.0, 0.0]
        ));
        // model_matrix agrees with applying the ops in order (M = R * T).
        for ops in &CUBE_MODELS {
            let m = model_matrix(ops);
            assert_eq!(m.row(3), Some([0.0, 0.0, 0.0, 1.0]));
            for p in CUBE_VERTICES {
                let q = m.transform_point(Vec3::from_array(p));
                assert!(close([q.x, q.y, q.z], transform_point(ops, p)));
            }
        }
    }

    #[test]
    fn camera_constants_are_sane() {
        let view = sub(CUBES_TARGET, CUBES_EYE);
        assert!(dot(view, view) > 0.0);
        assert!(cross(view, CUBES_UP) != [0.0; 3]);
        const { assert!(CUBES_NEAR > 0.0 && CUBES_FAR > CUBES_NEAR) };
        const { assert!(CUBES_FOV_Y_DEG > 0.0 && CUBES_FOV_Y_DEG < 180.0) };
        // Every transformed cube lies in front of the camera, between near and far.
        let fwd = {
            let l = dot(view, view).sqrt();
            view.map(|c| c / l)
        };
        for ops in &CUBE_MODELS {
            for p in CUBE_VERTICES {
                let d = dot(sub(transform_point(ops, p), CUBES_EYE), fwd);
                assert!(d > CUBES_NEAR && d < CUBES_FAR);
            }
        }
    }
}
