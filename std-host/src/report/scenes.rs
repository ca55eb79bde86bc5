//! The report's scenes and their matrices, in `f32` (each float backend)
//! and in `f64`, and the error of the `f32` vertex stage against `f64`.
//!
//! Design note: a [`SceneSpec`] is plain data (positions, indices, colours,
//! model ops and camera), so the core's runs and the `f64` reference are
//! built from the same numbers and differ only in the arithmetic.

use super::*;

// ---------------------------------------------------------------------------
// Scenes

/// The camera of a scene.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Camera {
    /// Eye position.
    pub eye: [f32; 3],
    /// Point looked at.
    pub target: [f32; 3],
    /// Up direction.
    pub up: [f32; 3],
    /// Vertical field of view, degrees.
    pub fov_y_deg: f32,
    /// Near plane distance.
    pub near: f32,
    /// Far plane distance.
    pub far: f32,
    /// 1/w depth: `Mat4::perspective_inv_w` (no far plane) instead of
    /// `Mat4::perspective`.
    pub inv_w: bool,
}

/// One mesh of a scene, with the model transform applied to it.
#[derive(Clone, Debug)]
pub struct SpecObject {
    /// Object-space positions.
    pub positions: Vec<[f32; 3]>,
    /// Triangles.
    pub indices: Vec<[u32; 3]>,
    /// One colour per vertex.
    pub colors: Vec<Rgb888>,
    /// Model transform steps, first applied first.
    pub model: Vec<cubes::Op>,
}

/// A scene as plain data, from which both the core's `f32` pipeline (with
/// either float backend) and the `f64` reference are built.
#[derive(Clone, Debug)]
pub struct SceneSpec {
    /// Name.
    pub name: String,
    /// Meshes, drawn in order; triangle ids count up across them.
    pub objects: Vec<SpecObject>,
    /// Camera.
    pub camera: Camera,
}

impl SceneSpec {
    /// The number of triangles.
    pub fn triangle_count(&self) -> usize {
        self.objects.iter().map(|o| o.indices.len()).sum()
    }
}

/// Per-vertex colours from area-weighted vertex normals: `(n + 1) / 2`
/// scaled to 0..=255 per axis.
pub fn normal_colors(positions: &[[f32; 3]], indices: &[[u32; 3]]) -> Vec<Rgb888> {
    let mut normals = vec![[0.0f64; 3]; positions.len()];
    for t in indices {
        let Some(p) = t
            .iter()
            .map(|&i| positions.get(i as usize).map(|p| p.map(f64::from)))
            .collect::<Option<Vec<_>>>()
        else {
            continue;
        };
        let a = [0, 1, 2].map(|k| p[1][k] - p[0][k]);
        let b = [0, 1, 2].map(|k| p[2][k] - p[0][k]);
        let n = [
            a[1] * b[2] - a[2] * b[1],
            a[2] * b[0] - a[0] * b[2],
            a[0] * b[1] - a[1] * b[0],
        ];
        for &i in t {
            for k in 0..3 {
                normals[i as usize][k] += n[k];
            }
        }
    }
    normals
        .iter()
        .map(|n| {
            let l = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
            let c = |v: f64| {
                let u = if l > 0.0 { v / l } else { 0.0 };
                ((u + 1.0) * 0.5 * 255.0).round().clamp(0.0, 255.0) as u8
            };
            Rgb888::new(c(n[0]), c(n[1]), c(n[2]))
        })
        .collect()
}

/// The four cubes of the default scene, with per-vertex colours.
pub fn cubes_spec() -> SceneSpec {
    let positions = cubes::CUBE_VERTICES.to_vec();
    let indices = cubes::CUBE_INDICES.to_vec();
    let colors = normal_colors(&positions, &indices);
    SceneSpec {
        name: "cubes".into(),
        objects: cubes::CUBE_MODELS
            .iter()
            .map(|ops| SpecObject {
                positions: positions.clone(),
                indices: indices.clone(),
                colors: colors.clone(),
                model: ops.to_vec(),
            })
            .collect(),
        camera: Camera {
            eye: cubes::CUBES_EYE,
            target: cubes::CUBES_TARGET,
            up: cubes::CUBES_UP,
            fov_y_deg: cubes::CUBES_FOV_Y_DEG,
            near: cubes::CUBES_NEAR,
            far: cubes::CUBES_FAR,
            inv_w: false,
        },
    }
}

/// A mesh framed as `microraster render --obj` frames it (60° field of
/// view, near and far planes hugging the bounding sphere), with
/// per-vertex colours.
pub fn mesh_spec(name: &str, mesh: &obj::LoadedMesh, aspect: f32) -> SceneSpec {
    let fov = 60.0;
    let (eye, target) = obj::frame_camera(mesh, fov, aspect);
    let points: Vec<Vec3> = mesh
        .positions
        .iter()
        .map(|&p| Vec3::from_array(p))
        .collect();
    let radius = BoundingSphere::from_points(&points)
        .map(|b| b.radius as f64)
        .unwrap_or(1.0);
    let dist = (0..3)
        .map(|k| (target[k] as f64 - eye[k] as f64).powi(2))
        .sum::<f64>()
        .sqrt();
    let near = (dist - 2.0 * radius).max(dist * 0.01).max(1e-4);
    let far = (dist + 2.0 * radius).max(near * 2.0);
    SceneSpec {
        name: name.into(),
        objects: vec![SpecObject {
            positions: mesh.positions.clone(),
            indices: mesh.indices.clone(),
            colors: normal_colors(&mesh.positions, &mesh.indices),
            model: Vec::new(),
        }],
        camera: Camera {
            eye,
            target,
            up: [0.0, 1.0, 0.0],
            fov_y_deg: fov,
            near: near as f32,
            far: far as f32,
            inv_w: false,
        },
    }
}

/// The name of the close-surfaces scene ([`layers_spec`]).
pub const LAYERS: &str = "layers";

/// Distances of the `layers` scene's pairs (near plane 0.1, far 100).
pub const LAYER_DISTANCES: [f32; 4] = [0.5, 2.0, 8.0, 32.0];
/// Gaps of the `layers` scene's pairs, relative to their distance.
pub const LAYER_GAPS: [f32; 3] = [1e-3, 1e-5, 1e-7];

/// Close surfaces, for depth-test flips: for each distance of
/// [`LAYER_DISTANCES`] and gap of [`LAYER_GAPS`], a pair of parallel
/// squares (turned 30° about the vertical, so depth varies across them)
/// seen from the origin down -z (60° field of view, near 0.1, far 100),
/// each pair in a cell of a 4x3 grid on screen (a row per gap). The farther square lies
/// the gap behind the nearer one (its centre scaled from the eye by `1 +
/// gap`), is 10 % larger and is drawn first, so wherever both cover a
/// pixel the nearer must win, and a buffer that cannot tell them apart
/// (a tie, under `Less` or `Greater`) keeps the farther: a flip.
pub fn layers_spec(aspect: f32) -> SceneSpec {
    let (fov, near, far) = (60.0f32, 0.1f32, 100.0f32);
    let t = (fov.to_radians() * 0.5).tan();
    let (c, sn) = (30f32.to_radians().cos(), 30f32.to_radians().sin());
    let mut positions = Vec::new();
    let mut indices = Vec::new();
    let mut colors = Vec::new();
    for (j, &gap) in LAYER_GAPS.iter().enumerate() {
        for (i, &d) in LAYER_DISTANCES.iter().enumerate() {
            // The cell's centre in NDC, then on the ray at distance d.
            let (nx, ny) = (-0.75 + 0.5 * i as f32, (1.0 - j as f32) * 2.0 / 3.0);
            let centre = [nx * t * aspect * d, ny * t * d, -d];
            for (scale, half, color) in [
                (1.0 + gap, 0.22f32, Rgb888::new(40, 60, 200)),
                (1.0, 0.2f32, Rgb888::new(230, 200, 40)),
            ] {
                let o = centre.map(|v| v * scale);
                let (hx, hy) = (half * t * aspect * d * scale, half * t * d * scale);
                let base = positions.len() as u32;
                for (u, v) in [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)] {
                    // u along (cos 30°, 0, sin 30°), v up.
                    positions.push([o[0] + u * hx * c, o[1] + v * hy, o[2] + u * hx * sn]);
                    colors.push(color);
                }
                indices.push([base, base + 1, base + 2]);
                indices.push([base, base + 2, base + 3]);
            }
        }
    }
    SceneSpec {
        name: LAYERS.into(),
        objects: vec![SpecObject {
            positions,
            indices,
            colors,
            model: Vec::new(),
        }],
        camera: Camera {
            eye: [0.0, 0.0, 0.0],
            target: [0.0, 0.0, -1.0],
            up: [0.0, 1.0, 0.0],
            fov_y_deg: fov,
            near,
            far,
            inv_w: false,
        },
    }
}

pub(crate) fn op_matrix<F: FloatFns>(op: cubes::Op) -> Mat4 {
    match op {
        cubes::Op::Translate(t) => Mat4::translation(Vec3::from_array(t)),
        cubes::Op::RotateXDeg(a) => Mat4::rotation_x_with::<F>(radians(a)),
        cubes::Op::RotateYDeg(a) => Mat4::rotation_y_with::<F>(radians(a)),
        cubes::Op::RotateZDeg(a) => Mat4::rotation_z_with::<F>(radians(a)),
    }
}

pub(crate) fn op_matrix64(op: cubes::Op) -> mat::DMat4 {
    let rad = |a: f32| (a as f64).to_radians();
    match op {
        cubes::Op::Translate(t) => mat::translation(t.map(f64::from)),
        cubes::Op::RotateXDeg(a) => mat::rotation_x(rad(a)),
        cubes::Op::RotateYDeg(a) => mat::rotation_y(rad(a)),
        cubes::Op::RotateZDeg(a) => mat::rotation_z(rad(a)),
    }
}

/// The model-view-projection matrix of every object, in `f32` with the
/// float backend `F` (the same formulas and order as the scenes crate).
pub fn mvps_with<F: FloatFns>(spec: &SceneSpec, width: u32, height: u32) -> Vec<Mat4> {
    let c = &spec.camera;
    let aspect = width as f32 / height as f32;
    let v = Vec3::from_array;
    let proj = if c.inv_w {
        Mat4::perspective_inv_w_with::<F>(radians(c.fov_y_deg), aspect, c.near)
    } else {
        Mat4::perspective_with::<F>(radians(c.fov_y_deg), aspect, c.near, c.far)
    };
    let vp = proj * Mat4::look_at_with::<F>(v(c.eye), v(c.target), v(c.up));
    spec.objects
        .iter()
        .map(|o| {
            let m = o
                .model
                .iter()
                .fold(Mat4::IDENTITY, |m, &op| op_matrix::<F>(op) * m);
            vp * m
        })
        .collect()
}

/// [`mvps_with`] for a backend chosen at run time.
pub fn mvps(spec: &SceneSpec, math: MathBackend, width: u32, height: u32) -> Vec<Mat4> {
    match math {
        MathBackend::Libm => mvps_with::<Libm>(spec, width, height),
        MathBackend::Micromath => mvps_with::<Micromath>(spec, width, height),
    }
}

/// The exact (`f64`) model-view-projection matrix of every object.
pub fn mvps64(spec: &SceneSpec, width: u32, height: u32) -> Vec<mat::DMat4> {
    let c = &spec.camera;
    let aspect = width as f64 / height as f64;
    let f = |a: [f32; 3]| a.map(f64::from);
    let fov = (c.fov_y_deg as f64).to_radians();
    let proj = if c.inv_w {
        mat::perspective_inv_w(fov, aspect, c.near as f64)
    } else {
        mat::perspective(fov, aspect, c.near as f64, c.far as f64)
    };
    let vp = mat::mul(&proj, &mat::look_at(f(c.eye), f(c.target), f(c.up)));
    spec.objects
        .iter()
        .map(|o| {
            let m = o
                .model
                .iter()
                .fold(mat::IDENTITY, |m, &op| mat::mul(&op_matrix64(op), &m));
            mat::mul(&vp, &m)
        })
        .collect()
}

/// The scene's triangles in `f64` clip space, ids counting up from 0.
pub fn reference_triangles(spec: &SceneSpec, width: u32, height: u32) -> Vec<RefTriangle> {
    let mut out = Vec::with_capacity(spec.triangle_count());
    let mut id = 0u32;
    for (o, m) in spec.objects.iter().zip(mvps64(spec, width, height)) {
        let clip: Vec<[f64; 4]> = o
            .positions
            .iter()
            .map(|p| mat::transform_point(&m, p.map(f64::from)))
            .collect();
        for t in &o.indices {
            let v = t.map(|i| {
                let c = o.colors.get(i as usize).copied().unwrap_or(Rgb888::WHITE);
                RefVertex {
                    pos: clip.get(i as usize).copied().unwrap_or([f64::NAN; 4]),
                    color: [c.r() as f64, c.g() as f64, c.b() as f64],
                }
            });
            out.push(RefTriangle { v, id });
            id = id.wrapping_add(1);
        }
    }
    out
}

// ---------------------------------------------------------------------------
// The f32 vertex stage against f64

/// What the `f32` vertex stage costs before snapping.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct VertexError {
    /// Largest `|m32 - m64|` over matrix entries, relative to the largest
    /// `|m64|` entry of that matrix.
    pub matrix_rel: f64,
    /// Largest clip-space component error, relative to `|w|`.
    pub clip_rel: f64,
    /// Largest window-space x or y error, pixels.
    pub window_px: f64,
    /// Largest window depth error (units of window depth, `[0, 1]`).
    pub window_z: f64,
}

/// Measures [`VertexError`] for `mvps` against the exact matrices, over
/// every vertex a triangle uses that lies in front of the eye.
pub fn vertex_error(spec: &SceneSpec, mvps: &[Mat4], width: u32, height: u32) -> VertexError {
    let mut e = VertexError::default();
    let (half_w32, half_h32) = (width as f32 * 0.5, height as f32 * 0.5);
    let (half_w, half_h) = (width as f64 * 0.5, height as f64 * 0.5);
    for ((o, m32), m64) in spec
        .objects
        .iter()
        .zip(mvps)
        .zip(mvps64(spec, width, height))
    {
        let big = m64.iter().flatten().fold(0.0f64, |a, &v| a.max(v.abs()));
        for (r, row) in m64.iter().enumerate() {
            for (c, &v) in row.iter().enumerate() {
                let d = (m32.rows()[r][c] as f64 - v).abs() / big.max(f64::MIN_POSITIVE);
                e.matrix_rel = e.matrix_rel.max(d);
            }
        }
        let mut used = vec![false; o.positions.len()];
        for t in &o.indices {
            for &i in t {
                if let Some(u) = used.get_mut(i as usize) {
                    *u = true;
                }
            }
        }
        for (p, _) in o.positions.iter().zip(&used).filter(|(_, &u)| u) {
            let q = m32.transform_point(Vec3::from_array(*p));
            let x = mat::transform_point(&m64, p.map(f64::from));
            if !(x[3] > 0.0 && q.w > 0.0) {
                continue;
            }
            let q4 = [q.x, q.y, q.z, q.w].map(f64::from);
            for k in 0..4 {
                e.clip_rel = e.clip_rel.max((q4[k] - x[k]).abs() / x[3]);
            }
            // Window coordinates as `fixed::snap` computes them, in f32.
            let inv_w = 1.0 / q.w;
            let wx = (q.x * inv_w * half_w32 + half_w32) as f64;
            let wy = (half_h32 - q.y * inv_w * half_h32) as f64;
            let wz = (q.z * inv_w * 0.5 + 0.5) as f64;
            let ex = (x[0] / x[3] + 1.0) * half_w;
            let ey = (1.0 - x[1] / x[3]) * half_h;
            let ez = (x[2] / x[3] + 1.0) * 0.5;
            e.window_px = e.window_px.max((wx - ex).abs()).max((wy - ey).abs());
            e.window_z = e.window_z.max((wz - ez).abs());
        }
    }
    e
}
