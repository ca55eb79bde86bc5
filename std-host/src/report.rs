//! `microraster report speed-vs-error OUT_DIR`: what each configuration
//! costs in time and in accuracy.
//!
//! Design note: the report sweeps the eight compile-time configurations of
//! the core (subpixel bits 4 / 8, depth `u16` / `u32`, matrices built with
//! `libm` / `micromath`) over four scenes (the four cubes, Spot, the teapot
//! and the Stanford bunny from `assets/models/`), every one with per-vertex
//! colours from its normals so that Gouraud interpolation is exercised.
//!
//! For each configuration and scene it measures
//! - the frame time: median of repeated single-threaded frames, each one
//!   building the matrices with the configuration's float backend, setting
//!   up every triangle into a [`Frame`] and rendering all rows into an
//!   `Rgb888` buffer and a depth buffer (buffers allocated beforehand);
//! - the error against [`crate::reference`], which renders the same scene
//!   from `f64` vertices and `f64` matrices with no snapping:
//!   pixels whose triangle id differs, those among them where only coverage
//!   differs (background in one, a triangle in the other), the depth error
//!   in LSB of the buffer at pixels drawn by the same triangle in both
//!   (against `floor(z * 2^bits)` of the exact depth), and the colour error
//!   per channel (against the exact colour rounded to nearest);
//! - the error the `f32` vertex stage brings in before snapping: the largest
//!   matrix-entry error (relative to the matrix's largest entry) and the
//!   largest window-space vertex error (pixels, and window depth), both
//!   against `f64`. For `micromath` this is what its approximations cost.
//!
//! Every difference is also checked against what snapping and the measured
//! vertex error explain: a pixel whose triangle differs must lie within the
//! snapping tolerance (half a subpixel per axis plus the vertex error) of an
//! edge of one of the two triangles, or be a depth tie within the depth
//! tolerance; a depth or colour error must be within the error that moving
//! the vertices by that tolerance causes, plus the documented 1 LSB of
//! interpolation and 1 LSB of rounding. Whatever is left is counted as
//! "unexplained" and would be a bug in the core.
//!
//! Output: `OUT_DIR/speed-vs-error.md` (tables) and
//! `OUT_DIR/speed-vs-error.png` (time against error, one point per
//! configuration, the Pareto front marked), drawn with `plotters`; text in
//! the plot is drawn with embedded-graphics' built-in mono font, so no
//! system font is needed.

use crate::cli::parse_size;
use crate::cubes;
use crate::obj;
use crate::reference::{self, mat, Prepared, RefImage, RefOptions, RefTriangle, RefVertex};
use clap::Args;
use microraster::math::{radians, FloatFns, Libm, Micromath};
use microraster::pixelcolor::{Rgb888, RgbColor};
use microraster::prelude::Submit;
use microraster::{
    BoundingSphere, Config, CullMode, DepthBuffer, Error, Frame, FrontFace, Mat4, Mesh, MeshColors,
    SetupTriangle, TriangleId, Vec3,
};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// Options of `microraster report`.
#[derive(Args, Debug, Clone, PartialEq)]
pub struct ReportArgs {
    /// Which report: `speed-vs-error`.
    #[arg(value_parser = clap::builder::PossibleValuesParser::new(["speed-vs-error"]))]
    pub which: String,

    /// Folder for the report's files (created if missing).
    #[arg(value_name = "OUT_DIR")]
    pub out_dir: PathBuf,

    /// A quick run for CI: 160x120, 3 repetitions.
    #[arg(long)]
    pub quick: bool,

    /// Image size (default 800x600, or 160x120 with --quick).
    #[arg(long, value_name = "WxH", value_parser = parse_size)]
    pub size: Option<(u32, u32)>,

    /// Timed frames per configuration and scene; the median is reported
    /// (default 7, or 3 with --quick).
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u32).range(1..=1000))]
    pub reps: Option<u32>,

    /// Scenes to run, comma-separated (default: all of cubes, spot, teapot,
    /// bunny).
    #[arg(long, value_name = "LIST", value_delimiter = ',',
          value_parser = clap::builder::PossibleValuesParser::new(SCENE_NAMES))]
    pub scenes: Option<Vec<String>>,

    /// Folder holding spot.obj, teapot.obj and stanford-bunny.obj (default:
    /// the repository's assets/models).
    #[arg(long, value_name = "DIR")]
    pub models: Option<PathBuf>,

    /// Do not show the progress bar.
    #[arg(long)]
    pub no_progress: bool,
}

/// The scenes of the report, in order.
pub const SCENE_NAMES: [&str; 4] = ["cubes", "spot", "teapot", "bunny"];

/// Writes the report.
pub fn run(args: &ReportArgs) -> Result<(), String> {
    match args.which.as_str() {
        "speed-vs-error" => speed_vs_error(args),
        other => Err(format!("unknown report {other:?} (known: speed-vs-error)")),
    }
}

// ---------------------------------------------------------------------------
// Configurations

/// The float backend the matrices are built with.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum MathBackend {
    /// `libm`: accurate.
    Libm,
    /// `micromath`: fast approximations.
    Micromath,
}

impl MathBackend {
    /// The cargo feature's name.
    pub fn name(self) -> &'static str {
        match self {
            MathBackend::Libm => "libm",
            MathBackend::Micromath => "micromath",
        }
    }
}

/// One compile-time configuration of the core.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Configuration {
    /// Subpixel bits: 4 or 8.
    pub subpixel: u32,
    /// Depth buffer bits: 16 or 32.
    pub depth_bits: u32,
    /// Float backend of the matrices.
    pub math: MathBackend,
}

impl Configuration {
    /// A short name, e.g. `S8 u16 libm`.
    pub fn label(&self) -> String {
        format!(
            "S{} u{} {}",
            self.subpixel,
            self.depth_bits,
            self.math.name()
        )
    }
}

/// Every configuration the report compares.
pub const CONFIGURATIONS: [Configuration; 8] = {
    let mut out = [Configuration {
        subpixel: 8,
        depth_bits: 16,
        math: MathBackend::Libm,
    }; 8];
    let mut i = 0;
    while i < 8 {
        out[i] = Configuration {
            subpixel: if i & 4 == 0 { 4 } else { 8 },
            depth_bits: if i & 2 == 0 { 16 } else { 32 },
            math: if i & 1 == 0 {
                MathBackend::Libm
            } else {
                MathBackend::Micromath
            },
        };
        i += 1;
    }
    out
};

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
        },
    }
}

fn op_matrix<F: FloatFns>(op: cubes::Op) -> Mat4 {
    match op {
        cubes::Op::Translate(t) => Mat4::translation(Vec3::from_array(t)),
        cubes::Op::RotateXDeg(a) => Mat4::rotation_x_with::<F>(radians(a)),
        cubes::Op::RotateYDeg(a) => Mat4::rotation_y_with::<F>(radians(a)),
        cubes::Op::RotateZDeg(a) => Mat4::rotation_z_with::<F>(radians(a)),
    }
}

fn op_matrix64(op: cubes::Op) -> mat::DMat4 {
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
    let proj = Mat4::perspective_with::<F>(radians(c.fov_y_deg), aspect, c.near, c.far);
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
    let proj = mat::perspective(
        (c.fov_y_deg as f64).to_radians(),
        aspect,
        c.near as f64,
        c.far as f64,
    );
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

// ---------------------------------------------------------------------------
// The core's pipeline

/// One mesh in the core's types.
struct CoreObject {
    positions: Vec<Vec3>,
    indices: Vec<[u32; 3]>,
    colors: Vec<Rgb888>,
    bounds: Option<BoundingSphere>,
}

impl CoreObject {
    fn new(o: &SpecObject) -> Self {
        let positions: Vec<Vec3> = o.positions.iter().map(|&p| Vec3::from_array(p)).collect();
        CoreObject {
            bounds: BoundingSphere::from_points(&positions),
            positions,
            indices: o.indices.clone(),
            colors: o.colors.clone(),
        }
    }

    fn mesh(&self) -> Mesh<'_> {
        Mesh {
            positions: &self.positions,
            indices: &self.indices,
            colors: MeshColors::PerVertex(&self.colors),
            bounds: self.bounds,
        }
    }
}

/// A depth buffer word.
trait DepthWord: Copy + 'static {
    const FAR: Self;
    fn value(self) -> u64;
}

impl DepthWord for u16 {
    const FAR: Self = u16::MAX;
    fn value(self) -> u64 {
        self as u64
    }
}

impl DepthWord for u32 {
    const FAR: Self = u32::MAX;
    fn value(self) -> u64 {
        self as u64
    }
}

/// What the core drew.
struct CoreRun {
    /// Triangle id + 1 per pixel.
    ids: Vec<u32>,
    /// Colour per pixel.
    color: Vec<Rgb888>,
    /// Depth per pixel.
    depth: Vec<u64>,
}

struct CoreInput<'a> {
    spec: &'a SceneSpec,
    objects: &'a [CoreObject],
    math: MathBackend,
    width: u32,
    height: u32,
}

/// One whole frame: matrices, setup, clear, all rows.
fn frame_once<const S: u32, C, T>(
    input: &CoreInput<'_>,
    storage: &mut [SetupTriangle],
    color: &mut [C],
    clear: C,
    depth: &mut [T],
) -> Result<(), Error>
where
    C: microraster::PixelFormat,
    T: DepthWord,
    [T]: DepthBuffer,
{
    let (w, h) = (input.width, input.height);
    let mvps = mvps(input.spec, input.math, w, h);
    let mut frame = Frame::<S>::with_subpixel_bits(Config::new(w, h), storage)?;
    let mut id = 0u32;
    for (o, m) in input.objects.iter().zip(&mvps) {
        frame.submit_mesh(&o.mesh(), m, id)?;
        id = id.wrapping_add(o.indices.len() as u32);
    }
    color.fill(clear);
    depth.fill(T::FAR);
    frame.render_rows(0, h, color, depth)?;
    Ok(())
}

/// Renders one configuration's frames. The report times the
/// configurations round-robin (one frame of each in turn), so that a burst
/// of load on the machine spreads over all of them instead of skewing one.
trait Runner {
    /// Renders one frame; returns its time in milliseconds.
    fn frame(&mut self) -> Result<f64, String>;
    /// The colour and depth of the last frame, and the triangle-id image.
    fn finish(&mut self) -> Result<CoreRun, String>;
}

struct TypedRunner<'a, const S: u32, T> {
    input: CoreInput<'a>,
    storage: Vec<SetupTriangle>,
    color: Vec<Rgb888>,
    depth: Vec<T>,
}

impl<'a, const S: u32, T> TypedRunner<'a, S, T>
where
    T: DepthWord,
    [T]: DepthBuffer,
{
    /// Allocates everything and renders one frame to warm up (growing the
    /// setup storage until the frame fits).
    fn new(input: CoreInput<'a>) -> Result<Self, String> {
        let len = input.width as usize * input.height as usize;
        let n: usize = input.objects.iter().map(|o| o.indices.len()).sum();
        let mut r = TypedRunner {
            input,
            storage: vec![SetupTriangle::EMPTY; n + n / 8 + 64],
            color: vec![Rgb888::BLACK; len],
            depth: vec![T::FAR; len],
        };
        loop {
            match frame_once::<S, _, T>(
                &r.input,
                &mut r.storage,
                &mut r.color,
                Rgb888::BLACK,
                &mut r.depth,
            ) {
                Ok(()) => return Ok(r),
                Err(Error::StorageFull { needed, .. }) => {
                    let grow = needed.max(r.storage.len() / 2);
                    r.storage
                        .resize(r.storage.len() + grow, SetupTriangle::EMPTY);
                }
                Err(e) => return Err(e.to_string()),
            }
        }
    }
}

impl<const S: u32, T> Runner for TypedRunner<'_, S, T>
where
    T: DepthWord,
    [T]: DepthBuffer,
{
    fn frame(&mut self) -> Result<f64, String> {
        let t = Instant::now();
        frame_once::<S, _, T>(
            &self.input,
            &mut self.storage,
            &mut self.color,
            Rgb888::BLACK,
            &mut self.depth,
        )
        .map_err(|e| e.to_string())?;
        std::hint::black_box((&self.color, &self.depth));
        Ok(t.elapsed().as_secs_f64() * 1e3)
    }

    fn finish(&mut self) -> Result<CoreRun, String> {
        let len = self.color.len();
        let mut ids = vec![TriangleId(0); len];
        let mut id_depth = vec![T::FAR; len];
        frame_once::<S, _, T>(
            &self.input,
            &mut self.storage,
            &mut ids,
            TriangleId(0),
            &mut id_depth,
        )
        .map_err(|e| e.to_string())?;
        Ok(CoreRun {
            ids: ids.into_iter().map(|t| t.0).collect(),
            color: self.color.clone(),
            depth: self.depth.iter().map(|d| d.value()).collect(),
        })
    }
}

/// A warmed-up runner for configuration `c`.
fn runner<'a>(input: CoreInput<'a>, c: Configuration) -> Result<Box<dyn Runner + 'a>, String> {
    Ok(match (c.subpixel, c.depth_bits) {
        (4, 16) => Box::new(TypedRunner::<4, u16>::new(input)?),
        (4, 32) => Box::new(TypedRunner::<4, u32>::new(input)?),
        (8, 16) => Box::new(TypedRunner::<8, u16>::new(input)?),
        (8, 32) => Box::new(TypedRunner::<8, u32>::new(input)?),
        (s, d) => return Err(format!("unsupported configuration S={s} depth u{d}")),
    })
}

// ---------------------------------------------------------------------------
// Comparison

/// How far snapping and the `f32` vertex stage may move things.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Tolerance {
    /// How far an edge may move, pixels (per axis and in distance).
    pub xy: f64,
    /// How far a vertex depth may move, window-depth units.
    pub z: f64,
}

impl Tolerance {
    /// Half a subpixel per axis (√2 of that as a distance), plus the
    /// measured vertex error, plus a little slack for `f64` rounding.
    pub fn new(subpixel: u32, v: &VertexError) -> Self {
        let half = 0.5 / (1u64 << subpixel) as f64;
        Tolerance {
            xy: std::f64::consts::SQRT_2 * (half + v.window_px) + 1e-6,
            z: v.window_z + 1e-9,
        }
    }
}

/// The error of one configuration on one scene.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ErrorStats {
    /// Pixels the reference covers.
    pub covered: usize,
    /// Pixels whose triangle id differs from the reference.
    pub id_diff: usize,
    /// Of those, pixels where one is background and the other is not.
    pub coverage_diff: usize,
    /// Differing pixels that snapping and depth ties do not explain.
    pub unexplained: usize,
    /// A few unexplained pixels: `(x, y, core id + 1, reference id + 1)`.
    pub unexplained_examples: Vec<(u32, u32, u32, u32)>,
    /// Pixels compared for depth and colour (same triangle in both).
    pub same: usize,
    /// Largest depth error, LSB of the buffer.
    pub depth_max_lsb: f64,
    /// Mean depth error, LSB.
    pub depth_mean_lsb: f64,
    /// Pixels whose depth error exceeds the explained bound.
    pub depth_beyond: usize,
    /// Largest `|stored / 2^bits - exact depth|` (window-depth units):
    /// the buffer's own quantisation included.
    pub depth_abs_max: f64,
    /// Mean of the same.
    pub depth_abs_mean: f64,
    /// Largest colour error over channels, LSB of 8 bits.
    pub color_max: f64,
    /// Mean colour error over pixels and channels.
    pub color_mean: f64,
    /// Pixels whose colour error exceeds the explained bound.
    pub color_beyond: usize,
    /// A few depth and colour errors beyond the bound:
    /// `(x, y, id + 1, what, stored, exact)`.
    pub beyond_examples: Vec<(u32, u32, u32, &'static str, String, String)>,
}

/// Compares a core image with the reference.
fn compare(
    core: &CoreRun,
    depth_bits: u32,
    reference: &RefImage,
    prepared: &[Option<Prepared>],
    tol: Tolerance,
) -> ErrorStats {
    let (ids, color, depth) = (&core.ids, &core.color, &core.depth);
    let scale = (1u64 << depth_bits) as f64;
    let lsb = 1.0 / scale;
    let w = reference.width as usize;
    let mut s = ErrorStats {
        covered: reference.covered(),
        ..ErrorStats::default()
    };
    let mut depth_sum = 0.0;
    let mut depth_abs_sum = 0.0;
    let mut color_sum = 0.0;
    let tri = |id: u32| -> Option<&Prepared> {
        id.checked_sub(1)
            .and_then(|k| prepared.get(k as usize))
            .and_then(|p| p.as_ref())
    };
    for (i, (&a, &b)) in ids.iter().zip(&reference.ids).enumerate() {
        let (px, py) = ((i % w) as f64 + 0.5, (i / w) as f64 + 0.5);
        if a == b {
            let Some(p) = tri(a) else { continue };
            s.same += 1;
            let s0 = p.sample(px, py);
            let sx = p.sample(px + 1.0, py);
            let sy = p.sample(px, py + 1.0);
            // Depth against the exact depth, truncated as the core stores it.
            let z = reference.depth[i];
            let ideal = (z * scale).floor().clamp(0.0, scale - 1.0);
            let err = (depth[i] as f64 - ideal).abs();
            let grad = (sx.depth - s0.depth).abs() + (sy.depth - s0.depth).abs();
            let bound = 2.0 + (grad * tol.xy + tol.z) * scale;
            s.depth_max_lsb = s.depth_max_lsb.max(err);
            depth_sum += err;
            // What the buffer holds against the exact depth.
            let abs = (depth[i] as f64 / scale - z).abs();
            s.depth_abs_max = s.depth_abs_max.max(abs);
            depth_abs_sum += abs;
            if err > bound {
                s.depth_beyond += 1;
                if s.beyond_examples.len() < 5 {
                    s.beyond_examples.push((
                        (i % w) as u32,
                        (i / w) as u32,
                        a,
                        "depth",
                        depth[i].to_string(),
                        format!("{ideal} (bound {bound:.1} LSB)"),
                    ));
                }
            }
            // Colour against the exact colour rounded to nearest.
            let c = color[i];
            let core = [c.r(), c.g(), c.b()].map(f64::from);
            let sxm = p.sample(px - 1.0, py);
            let sym = p.sample(px, py - 1.0);
            let mut beyond = false;
            #[allow(clippy::needless_range_loop)] // ch indexes several arrays
            for ch in 0..3 {
                let exact = reference.color[i][ch];
                let err = (core[ch] - (exact + 0.5).floor()).abs();
                let g = |q: &reference::Sample| (q.color[ch] - s0.color[ch]).abs();
                let grad = g(&sx).max(g(&sxm)) + g(&sy).max(g(&sym));
                // 1 LSB of rounding on each side, plus `f32` shading slack.
                if err > 1.0 + grad * tol.xy + 1e-3 * exact.abs().max(1.0) {
                    beyond = true;
                }
                s.color_max = s.color_max.max(err);
                color_sum += err;
            }
            if beyond {
                s.color_beyond += 1;
                if s.beyond_examples.len() < 5 {
                    s.beyond_examples.push((
                        (i % w) as u32,
                        (i / w) as u32,
                        a,
                        "colour",
                        format!("{:?}", [c.r(), c.g(), c.b()]),
                        format!("{:.2?}", reference.color[i]),
                    ));
                }
            }
            continue;
        }
        s.id_diff += 1;
        if (a == 0) != (b == 0) {
            s.coverage_diff += 1;
        }
        let sa = tri(a).map(|p| (p, p.sample(px, py)));
        let sb = tri(b).map(|p| (p, p.sample(px, py)));
        let near_edge = |t: &Option<(&Prepared, reference::Sample)>| {
            t.as_ref()
                .is_some_and(|(_, q)| q.inv_w > 0.0 && q.edge_distance.abs() <= tol.xy)
        };
        let explained = near_edge(&sa)
            || near_edge(&sb)
            || match (&sa, &sb) {
                (Some((pa, qa)), Some((pb, qb))) => {
                    // Both cover the pixel (within tolerance) and their
                    // depths tie within what snapping and the buffer allow.
                    let ztol = |p: &Prepared, q: &reference::Sample| {
                        let gx = (p.sample(px + 1.0, py).depth - q.depth).abs();
                        let gy = (p.sample(px, py + 1.0).depth - q.depth).abs();
                        (gx + gy) * tol.xy + tol.z
                    };
                    qa.inv_w > 0.0
                        && qb.inv_w > 0.0
                        && qa.edge_distance >= -tol.xy
                        && qb.edge_distance >= -tol.xy
                        && (qa.depth - qb.depth).abs()
                            <= ztol(pa, qa) + ztol(pb, qb) + 2.0 * lsb + 2.0 / 4_294_967_296.0
                }
                _ => false,
            };
        if !explained {
            s.unexplained += 1;
            if s.unexplained_examples.len() < 5 {
                s.unexplained_examples
                    .push(((i % w) as u32, (i / w) as u32, a, b));
            }
        }
    }
    if s.same > 0 {
        s.depth_mean_lsb = depth_sum / s.same as f64;
        s.depth_abs_mean = depth_abs_sum / s.same as f64;
        s.color_mean = color_sum / (3 * s.same) as f64;
    }
    s
}

/// Indices of the points on the Pareto front when both coordinates are to
/// be minimised (no other point is at most as large in both and smaller in
/// one), ordered by `x`, then `y`. Points with a NaN are never on it.
pub fn pareto_front(points: &[(f64, f64)]) -> Vec<usize> {
    let mut front: Vec<usize> = (0..points.len())
        .filter(|&i| {
            let (x, y) = points[i];
            !x.is_nan()
                && !y.is_nan()
                && !points
                    .iter()
                    .any(|&(u, v)| u <= x && v <= y && (u < x || v < y))
        })
        .collect();
    front.sort_by(|&i, &j| {
        let (a, b) = (points[i], points[j]);
        a.0.total_cmp(&b.0).then(a.1.total_cmp(&b.1))
    });
    front
}

fn median(v: &[f64]) -> f64 {
    let mut s = v.to_vec();
    s.sort_by(f64::total_cmp);
    match s.len() {
        0 => f64::NAN,
        n if n % 2 == 1 => s[n / 2],
        n => 0.5 * (s[n / 2 - 1] + s[n / 2]),
    }
}

// ---------------------------------------------------------------------------
// The report

/// One configuration on one scene.
#[derive(Clone, Debug)]
pub struct Row {
    /// Scene name.
    pub scene: String,
    /// Configuration.
    pub config: Configuration,
    /// Median frame time, milliseconds.
    pub time_ms: f64,
    /// Errors against the reference.
    pub errors: ErrorStats,
    /// Vertex-stage error.
    pub vertex: VertexError,
}

/// One configuration over every scene.
#[derive(Clone, Debug)]
pub struct Summary {
    /// Configuration.
    pub config: Configuration,
    /// Sum of the scenes' median frame times, milliseconds.
    pub time_ms: f64,
    /// Pixels whose triangle differs, percent of the reference's covered
    /// pixels (all scenes together).
    pub id_diff_pct: f64,
    /// Coverage-only differences, percent of covered pixels.
    pub coverage_diff_pct: f64,
    /// Unexplained differences (all scenes).
    pub unexplained: usize,
    /// Largest depth error, LSB.
    pub depth_max_lsb: f64,
    /// Mean `|stored / 2^bits - exact|` depth, window-depth units.
    pub depth_mean_abs: f64,
    /// Largest of the same.
    pub depth_max_abs: f64,
    /// Depth errors beyond the explained bound.
    pub depth_beyond: usize,
    /// Largest colour error, LSB.
    pub color_max: f64,
    /// Colour errors beyond the explained bound.
    pub color_beyond: usize,
    /// Largest relative matrix error.
    pub matrix_rel: f64,
    /// Largest vertex error, pixels.
    pub vertex_px: f64,
}

/// Sums rows into one summary per configuration, in [`CONFIGURATIONS`]
/// order.
pub fn summarize(rows: &[Row]) -> Vec<Summary> {
    let mut out = Vec::new();
    for c in CONFIGURATIONS {
        let rs: Vec<&Row> = rows.iter().filter(|r| r.config == c).collect();
        if rs.is_empty() {
            continue;
        }
        let covered: usize = rs.iter().map(|r| r.errors.covered).sum::<usize>().max(1);
        let same: usize = rs.iter().map(|r| r.errors.same).sum::<usize>().max(1);
        let fmax = |f: &dyn Fn(&Row) -> f64| rs.iter().map(|r| f(r)).fold(0.0, f64::max);
        let sum = |f: &dyn Fn(&Row) -> usize| rs.iter().map(|r| f(r)).sum::<usize>();
        out.push(Summary {
            config: c,
            time_ms: rs.iter().map(|r| r.time_ms).sum(),
            id_diff_pct: 100.0 * sum(&|r| r.errors.id_diff) as f64 / covered as f64,
            coverage_diff_pct: 100.0 * sum(&|r| r.errors.coverage_diff) as f64 / covered as f64,
            unexplained: sum(&|r| r.errors.unexplained),
            depth_max_lsb: fmax(&|r| r.errors.depth_max_lsb),
            depth_mean_abs: rs
                .iter()
                .map(|r| r.errors.depth_abs_mean * r.errors.same as f64)
                .sum::<f64>()
                / same as f64,
            depth_max_abs: fmax(&|r| r.errors.depth_abs_max),
            depth_beyond: sum(&|r| r.errors.depth_beyond),
            color_max: fmax(&|r| r.errors.color_max),
            color_beyond: sum(&|r| r.errors.color_beyond),
            matrix_rel: fmax(&|r| r.vertex.matrix_rel),
            vertex_px: fmax(&|r| r.vertex.window_px),
        });
    }
    out
}

/// The settings a report ran with.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct RunInfo {
    /// Width.
    pub width: u32,
    /// Height.
    pub height: u32,
    /// Timed repetitions.
    pub reps: u32,
}

fn default_models_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("..")
        .join("assets")
        .join("models")
}

/// Loads the named scene.
pub fn load_scene(name: &str, models: &Path, aspect: f32) -> Result<SceneSpec, String> {
    let file = match name {
        "cubes" => return Ok(cubes_spec()),
        "spot" => "spot.obj",
        "teapot" => "teapot.obj",
        "bunny" => "stanford-bunny.obj",
        other => return Err(format!("unknown scene {other:?}")),
    };
    let mesh = obj::load_obj(&models.join(file))?;
    Ok(mesh_spec(name, &mesh, aspect))
}

fn speed_vs_error(args: &ReportArgs) -> Result<(), String> {
    let (width, height) = args
        .size
        .unwrap_or(if args.quick { (160, 120) } else { (800, 600) });
    let reps = args.reps.unwrap_or(if args.quick { 3 } else { 7 });
    let names: Vec<String> = args
        .scenes
        .clone()
        .unwrap_or_else(|| SCENE_NAMES.iter().map(|s| s.to_string()).collect());
    let models = args.models.clone().unwrap_or_else(default_models_dir);
    std::fs::create_dir_all(&args.out_dir)
        .map_err(|e| format!("{}: cannot create folder: {e}", args.out_dir.display()))?;

    let steps = (names.len() * (1 + reps as usize + CONFIGURATIONS.len())) as u64;
    let bar = if args.no_progress {
        indicatif::ProgressBar::hidden()
    } else {
        indicatif::ProgressBar::new(steps)
    };
    if let Ok(style) =
        indicatif::ProgressStyle::with_template("{elapsed_precise} [{bar:40}] {pos}/{len} {msg}")
    {
        bar.set_style(style.progress_chars("=> "));
    }

    let mut rows = Vec::new();
    for name in &names {
        bar.set_message(format!("{name}: loading, f64 reference"));
        let spec = load_scene(name, &models, width as f32 / height as f32)?;
        let tris = reference_triangles(&spec, width, height);
        let reference = reference::render_reference(
            &tris,
            &RefOptions {
                width,
                height,
                cull: CullMode::Back,
                front_face: FrontFace::Ccw,
            },
        );
        let prepared: Vec<Option<Prepared>> = tris
            .iter()
            .map(|t| Prepared::new(t, width, height))
            .collect();
        let objects: Vec<CoreObject> = spec.objects.iter().map(CoreObject::new).collect();
        bar.inc(1);
        let mut runners = Vec::new();
        for config in CONFIGURATIONS {
            let input = CoreInput {
                spec: &spec,
                objects: &objects,
                math: config.math,
                width,
                height,
            };
            runners.push(runner(input, config)?);
        }
        let mut times = vec![Vec::with_capacity(reps as usize); runners.len()];
        for rep in 0..reps {
            bar.set_message(format!("{name}: timing, round {} of {reps}", rep + 1));
            for (r, t) in runners.iter_mut().zip(&mut times) {
                t.push(r.frame()?);
            }
            bar.inc(1);
        }
        for ((config, r), t) in CONFIGURATIONS.iter().zip(&mut runners).zip(&times) {
            bar.set_message(format!("{name}: {} against f64", config.label()));
            let run = r.finish()?;
            let vertex = vertex_error(
                &spec,
                &mvps(&spec, config.math, width, height),
                width,
                height,
            );
            let errors = compare(
                &run,
                config.depth_bits,
                &reference,
                &prepared,
                Tolerance::new(config.subpixel, &vertex),
            );
            rows.push(Row {
                scene: name.clone(),
                config: *config,
                time_ms: median(t),
                errors,
                vertex,
            });
            bar.inc(1);
        }
    }
    bar.finish_and_clear();

    let info = RunInfo {
        width,
        height,
        reps,
    };
    let summary = summarize(&rows);
    let md_path = args.out_dir.join("speed-vs-error.md");
    std::fs::write(&md_path, markdown(&info, &summary, &rows))
        .map_err(|e| format!("{}: cannot write: {e}", md_path.display()))?;
    let png_path = args.out_dir.join("speed-vs-error.png");
    plot::write_png(&png_path, &info, &summary)?;
    eprintln!(
        "microraster: wrote {} and {}",
        md_path.display(),
        png_path.display()
    );
    Ok(())
}

fn sci(v: f64) -> String {
    if v == 0.0 {
        "0".into()
    } else {
        format!("{v:.1e}")
    }
}

/// The report's markdown.
pub fn markdown(info: &RunInfo, summary: &[Summary], rows: &[Row]) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "# Speed against error\n");
    let _ = writeln!(
        s,
        "{}x{} pixels, one thread, median of {} frames per cell; errors against the `f64` \
         reference renderer (`std-host/src/reference.rs`). Written by \
         `microraster report speed-vs-error`.\n",
        info.width, info.height, info.reps
    );
    let _ = writeln!(s, "## By configuration (all scenes together)\n");
    let _ = writeln!(
        s,
        "| configuration | frame time, sum (ms) | pixels differing | coverage only | \
         unexplained | depth max (LSB) | depth beyond bound | depth vs exact, mean | \
         depth vs exact, max | colour max (LSB) | colour beyond bound | matrix error (rel.) | \
         vertex error (px) |"
    );
    let _ = writeln!(s, "|---|--:|--:|--:|--:|--:|--:|--:|--:|--:|--:|--:|--:|");
    let front = pareto_front(
        &summary
            .iter()
            .map(|r| (r.time_ms, r.id_diff_pct))
            .collect::<Vec<_>>(),
    );
    for (i, r) in summary.iter().enumerate() {
        let mark = if front.contains(&i) { " ★" } else { "" };
        let _ = writeln!(
            s,
            "| {}{} | {:.2} | {:.3} % | {:.3} % | {} | {:.0} | {} | {} | {} | {:.0} | {} | {} | {} |",
            r.config.label(),
            mark,
            r.time_ms,
            r.id_diff_pct,
            r.coverage_diff_pct,
            r.unexplained,
            r.depth_max_lsb,
            r.depth_beyond,
            sci(r.depth_mean_abs),
            sci(r.depth_max_abs),
            r.color_max,
            r.color_beyond,
            sci(r.matrix_rel),
            sci(r.vertex_px),
        );
    }
    let _ = writeln!(
        s,
        "\n★ on the Pareto front of frame time against pixels differing.\n"
    );
    let _ = writeln!(s, "## By scene\n");
    let _ = writeln!(
        s,
        "| scene | configuration | time (ms) | covered | differing | coverage only | \
         unexplained | depth max (LSB) | depth mean (LSB) | depth beyond | colour max | \
         colour mean | colour beyond | matrix err | clip err (rel. w) | vertex err (px) | \
         vertex err (z) |"
    );
    let _ = writeln!(
        s,
        "|---|---|--:|--:|--:|--:|--:|--:|--:|--:|--:|--:|--:|--:|--:|--:|--:|"
    );
    for r in rows {
        let e = &r.errors;
        let _ = writeln!(
            s,
            "| {} | {} | {:.3} | {} | {} | {} | {} | {:.0} | {:.2} | {} | {:.0} | {:.3} | {} | \
             {} | {} | {} | {} |",
            r.scene,
            r.config.label(),
            r.time_ms,
            e.covered,
            e.id_diff,
            e.coverage_diff,
            e.unexplained,
            e.depth_max_lsb,
            e.depth_mean_lsb,
            e.depth_beyond,
            e.color_max,
            e.color_mean,
            e.color_beyond,
            sci(r.vertex.matrix_rel),
            sci(r.vertex.clip_rel),
            sci(r.vertex.window_px),
            sci(r.vertex.window_z),
        );
    }
    let examples: Vec<String> = rows
        .iter()
        .filter(|r| r.errors.unexplained + r.errors.depth_beyond + r.errors.color_beyond > 0)
        .map(|r| {
            format!(
                "- {} {}: {} differing pixels unexplained, e.g. (x, y, core id+1, reference \
                 id+1) {:?}; {} depth and {} colour errors beyond the bound, e.g. (x, y, id+1, \
                 what, stored, exact) {:?}",
                r.scene,
                r.config.label(),
                r.errors.unexplained,
                r.errors.unexplained_examples,
                r.errors.depth_beyond,
                r.errors.color_beyond,
                r.errors.beyond_examples,
            )
        })
        .collect();
    let _ = writeln!(s, "\n## Unexplained differences\n");
    if examples.is_empty() {
        let _ = writeln!(
            s,
            "None: every differing pixel lies within the snapping tolerance of an edge or is a \
             depth tie, and every depth and colour error is within the bound that snapping, the \
             measured vertex error and rounding explain."
        );
    } else {
        for e in examples {
            let _ = writeln!(s, "{e}");
        }
    }
    let _ = writeln!(
        s,
        "\n## Columns\n\n\
         - *differing*: pixels whose triangle (the `TriangleId` image) is not the reference's; \
         *coverage only*: of those, pixels that are background in one image and not in the other.\n\
         - *unexplained*: differing pixels that are neither within the snapping tolerance (half a \
         subpixel per axis plus the measured vertex error) of an edge of either triangle, nor a \
         depth tie within the depth tolerance.\n\
         - *depth (LSB)*: `|stored - floor(z·2^bits)|` at pixels drawn by the same triangle in \
         both, in LSB of the buffer (`u16` or `u32`), where `z` is the exact window depth: the \
         error beyond the buffer's own truncation; *beyond bound*: pixels where it exceeds 2 LSB \
         plus the depth change that moving the vertices by the tolerance causes. *depth vs \
         exact*: `|stored / 2^bits - z|` in window-depth units (`[0, 1]`), truncation included: \
         what a depth test actually compares.\n\
         - *colour*: `|core - round(exact)|` per channel (8-bit LSB); *beyond bound*: pixels where \
         it exceeds 1 LSB plus the colour change that moving the vertices by the tolerance causes.\n\
         - *matrix err*: largest `|m32 - m64|` relative to the matrix's largest entry; *clip err*: \
         largest clip-space component error relative to `w`; *vertex err*: largest window-space \
         error of a vertex in pixels (x, y) and in window depth (z), all against `f64`, before \
         snapping.\n\
         - *time*: the whole frame on one thread: matrices, setup of every triangle, clearing and \
         rendering all rows into `Rgb888` and the depth buffer.\n"
    );
    s
}

// ---------------------------------------------------------------------------
// The plot

mod plot {
    use super::{pareto_front, RunInfo, Summary};
    use embedded_graphics::mono_font::{ascii, MonoFont, MonoTextStyle};
    use embedded_graphics::pixelcolor::Rgb888 as EgRgb;
    use embedded_graphics::prelude::{DrawTarget, OriginDimensions, Point, Size};
    use embedded_graphics::text::{Alignment, Baseline, Text, TextStyleBuilder};
    use embedded_graphics::Drawable;
    use plotters::prelude::*;
    use std::path::Path;

    const W: u32 = 1200;
    const H: u32 = 600;

    /// A text label to draw after plotting, at backend pixel coordinates.
    struct Label {
        text: String,
        at: (i32, i32),
        align: Alignment,
        baseline: Baseline,
        big: bool,
    }

    /// An RGB8 buffer as an embedded-graphics draw target.
    struct Canvas<'a> {
        buf: &'a mut [u8],
    }

    impl OriginDimensions for Canvas<'_> {
        fn size(&self) -> Size {
            Size::new(W, H)
        }
    }

    impl DrawTarget for Canvas<'_> {
        type Color = EgRgb;
        type Error = core::convert::Infallible;
        fn draw_iter<I>(&mut self, pixels: I) -> Result<(), Self::Error>
        where
            I: IntoIterator<Item = embedded_graphics::Pixel<EgRgb>>,
        {
            use embedded_graphics::pixelcolor::RgbColor as _;
            for embedded_graphics::Pixel(p, c) in pixels {
                if p.x >= 0 && p.y >= 0 && (p.x as u32) < W && (p.y as u32) < H {
                    let i = 3 * (p.y as usize * W as usize + p.x as usize);
                    self.buf[i] = c.r();
                    self.buf[i + 1] = c.g();
                    self.buf[i + 2] = c.b();
                }
            }
            Ok(())
        }
    }

    fn nice_ticks(lo: f64, hi: f64, n: usize) -> Vec<f64> {
        let span = (hi - lo).max(1e-12);
        let raw = span / n as f64;
        let mag = 10f64.powf(raw.log10().floor());
        let step = [1.0, 2.0, 5.0, 10.0]
            .iter()
            .map(|m| m * mag)
            .find(|s| span / s <= n as f64)
            .unwrap_or(10.0 * mag);
        let mut t = (lo / step).ceil() * step;
        let mut out = Vec::new();
        while t <= hi + step * 1e-9 {
            out.push(t);
            t += step;
        }
        out
    }

    fn fmt_tick(v: f64) -> String {
        if v == 0.0 {
            "0".into()
        } else if v.abs() >= 0.01 && v.abs() < 1e4 {
            let s = format!("{v:.3}");
            s.trim_end_matches('0').trim_end_matches('.').to_string()
        } else {
            format!("{v:.0e}")
        }
    }

    struct Panel<'a> {
        title: &'a str,
        y_label: &'a str,
        log_y: bool,
        ys: Vec<f64>,
    }

    type PResult<T> = Result<T, String>;

    fn err<E: std::fmt::Debug>(e: E) -> String {
        format!("plot: {e:?}")
    }

    #[allow(clippy::too_many_arguments)]
    fn draw_panel(
        area: &DrawingArea<BitMapBackend<'_>, plotters::coord::Shift>,
        panel: &Panel<'_>,
        xs: &[f64],
        names: &[String],
        labels: &mut Vec<Label>,
    ) -> PResult<()> {
        let (x_lo, x_hi) = xs
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &x| {
                (a.min(x), b.max(x))
            });
        let pad = ((x_hi - x_lo) * 0.15).max(x_hi.abs() * 0.02).max(1e-3);
        let (x0, x1) = ((x_lo - pad).max(0.0), x_hi + pad);
        let ys = &panel.ys;
        let (y_lo, y_hi) = ys
            .iter()
            .filter(|v| v.is_finite() && (!panel.log_y || **v > 0.0))
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &y| {
                (a.min(y), b.max(y))
            });
        let (y_lo, y_hi) = if y_lo.is_finite() {
            (y_lo, y_hi)
        } else {
            (1e-9, 1.0)
        };
        let points: Vec<(f64, f64)> = xs.iter().copied().zip(ys.iter().copied()).collect();
        let front = pareto_front(&points);
        let (margin_l, margin_b, margin_t, margin_r) = (80, 64, 50, 20);
        let (aw, ah) = area.dim_in_pixel();
        let (ox, oy) = area.get_base_pixel();
        let plot_area = area.margin(margin_t, margin_b, margin_l, margin_r);
        labels.push(Label {
            text: panel.title.into(),
            at: (ox + aw as i32 / 2, oy + 4),
            align: Alignment::Center,
            baseline: Baseline::Top,
            big: true,
        });
        labels.push(Label {
            text: panel.y_label.into(),
            at: (ox + 8, oy + margin_t - 16),
            align: Alignment::Left,
            baseline: Baseline::Bottom,
            big: false,
        });
        labels.push(Label {
            text: "frame time, sum over scenes (ms)".into(),
            at: (ox + aw as i32 / 2, oy + ah as i32 - 22),
            align: Alignment::Center,
            baseline: Baseline::Bottom,
            big: false,
        });
        let grid = RGBColor(220, 220, 220);
        let axis = RGBColor(60, 60, 60);
        let front_color = RGBColor(213, 94, 0);
        let point_color = RGBColor(0, 114, 178);
        let mut point_px: Vec<((i32, i32), usize)> = Vec::new();
        macro_rules! body {
            ($chart:expr, $y_ticks:expr, $fy:expr) => {{
                let chart = &mut $chart;
                let x_ticks = nice_ticks(x0, x1, 6);
                let y_ticks: Vec<f64> = $y_ticks;
                let (yb, yt) = ($fy.0, $fy.1);
                for &t in &x_ticks {
                    chart
                        .draw_series(LineSeries::new([(t, yb), (t, yt)], grid))
                        .map_err(err)?;
                    let (bx, by) = chart.backend_coord(&(t, yb));
                    labels.push(Label {
                        text: fmt_tick(t),
                        at: (bx, by + 6),
                        align: Alignment::Center,
                        baseline: Baseline::Top,
                        big: false,
                    });
                }
                for &t in &y_ticks {
                    chart
                        .draw_series(LineSeries::new([(x0, t), (x1, t)], grid))
                        .map_err(err)?;
                    let (bx, by) = chart.backend_coord(&(x0, t));
                    labels.push(Label {
                        text: fmt_tick(t),
                        at: (bx - 6, by),
                        align: Alignment::Right,
                        baseline: Baseline::Middle,
                        big: false,
                    });
                }
                chart
                    .draw_series(LineSeries::new(
                        [(x0, yt), (x0, yb), (x1, yb)],
                        axis.stroke_width(2),
                    ))
                    .map_err(err)?;
                let fp: Vec<(f64, f64)> = front
                    .iter()
                    .map(|&i| points[i])
                    .filter(|&(_, y)| !panel.log_y || y > 0.0)
                    .collect();
                chart
                    .draw_series(LineSeries::new(fp, front_color.stroke_width(2)))
                    .map_err(err)?;
                for (i, &(x, y)) in points.iter().enumerate() {
                    if !y.is_finite() || (panel.log_y && y <= 0.0) {
                        continue;
                    }
                    let on = front.contains(&i);
                    let style = if on {
                        front_color.filled()
                    } else {
                        point_color.stroke_width(2)
                    };
                    chart
                        .draw_series(std::iter::once(Circle::new((x, y), 5, style)))
                        .map_err(err)?;
                    point_px.push((chart.backend_coord(&(x, y)), i));
                }
            }};
        }
        if panel.log_y {
            let lo = 10f64.powf(y_lo.log10().floor());
            let hi = 10f64.powf(y_hi.log10().ceil()).max(lo * 10.0);
            let mut chart = ChartBuilder::on(&plot_area)
                .build_cartesian_2d(x0..x1, (lo..hi).log_scale())
                .map_err(err)?;
            let mut ticks = Vec::new();
            let mut t = lo;
            while t <= hi * 1.0001 {
                ticks.push(t);
                t *= 10.0;
            }
            body!(chart, ticks, (lo, hi));
        } else {
            let hi = if y_hi > 0.0 { y_hi * 1.15 } else { 1.0 };
            let mut chart = ChartBuilder::on(&plot_area)
                .build_cartesian_2d(x0..x1, 0.0..hi)
                .map_err(err)?;
            body!(chart, nice_ticks(0.0, hi, 6), (0.0, hi));
        }
        place_point_labels(&point_px, names, (ox, oy, aw as i32, ah as i32), labels);
        Ok(())
    }

    /// Places each point's name next to it where it overlaps no other
    /// name and no point, trying a few positions around the point.
    fn place_point_labels(
        points: &[((i32, i32), usize)],
        names: &[String],
        area: (i32, i32, i32, i32),
        labels: &mut Vec<Label>,
    ) {
        type Rect = (i32, i32, i32, i32);
        let overlaps = |a: &Rect, b: &Rect| a.0 < b.2 && b.0 < a.2 && a.1 < b.3 && b.1 < a.3;
        let mut taken: Vec<Rect> = points
            .iter()
            .map(|&((x, y), _)| (x - 6, y - 6, x + 6, y + 6))
            .collect();
        for &((x, y), i) in points {
            let (w, h) = (names[i].len() as i32 * 6, 10);
            let candidates = [
                (8, -5),
                (8, -16),
                (8, 6),
                (-8 - w, -5),
                (-8 - w, -16),
                (-8 - w, 6),
                (-w / 2, -20),
                (-w / 2, 9),
                (8, -28),
                (8, 18),
                (-8 - w, -28),
                (-8 - w, 18),
                (8, -40),
                (8, 30),
            ];
            let inside = |r: &Rect| {
                r.0 >= area.0 && r.1 >= area.1 && r.2 <= area.0 + area.2 && r.3 <= area.1 + area.3
            };
            let rect_at = |(dx, dy): (i32, i32)| (x + dx, y + dy, x + dx + w, y + dy + h);
            let pick = candidates
                .iter()
                .map(|&c| rect_at(c))
                .find(|r| inside(r) && !taken.iter().any(|t| overlaps(r, t)))
                .unwrap_or_else(|| rect_at(candidates[0]));
            taken.push(pick);
            labels.push(Label {
                text: names[i].clone(),
                at: (pick.0, pick.1),
                align: Alignment::Left,
                baseline: Baseline::Top,
                big: false,
            });
        }
    }

    /// Draws the two panels and writes the PNG.
    pub fn write_png(path: &Path, info: &RunInfo, summary: &[Summary]) -> Result<(), String> {
        let mut buf = vec![255u8; (W * H * 3) as usize];
        let mut labels = Vec::new();
        let xs: Vec<f64> = summary.iter().map(|s| s.time_ms).collect();
        let names: Vec<String> = summary.iter().map(|s| s.config.label()).collect();
        {
            let root = BitMapBackend::with_buffer(&mut buf, (W, H)).into_drawing_area();
            root.fill(&WHITE).map_err(err)?;
            let (left, right) = root.split_horizontally(W / 2);
            draw_panel(
                &left,
                &Panel {
                    title: "Coverage: pixels whose triangle differs from f64",
                    y_label: "% of covered pixels (log scale)",
                    log_y: true,
                    ys: summary.iter().map(|s| s.id_diff_pct).collect(),
                },
                &xs,
                &names,
                &mut labels,
            )?;
            draw_panel(
                &right,
                &Panel {
                    title: "Depth: mean stored-vs-exact error",
                    y_label: "window depth, [0, 1] (log scale)",
                    log_y: true,
                    ys: summary.iter().map(|s| s.depth_mean_abs).collect(),
                },
                &xs,
                &names,
                &mut labels,
            )?;
            root.present().map_err(err)?;
        }
        labels.push(Label {
            text: format!(
                "{}x{}, one thread, median of {} frames; filled points and line: Pareto front",
                info.width, info.height, info.reps
            ),
            at: (W as i32 / 2, H as i32 - 4),
            align: Alignment::Center,
            baseline: Baseline::Bottom,
            big: false,
        });
        let mut canvas = Canvas { buf: &mut buf };
        for l in &labels {
            let font: &MonoFont<'_> = if l.big {
                &ascii::FONT_8X13_BOLD
            } else {
                &ascii::FONT_6X10
            };
            let style = MonoTextStyle::new(font, EgRgb::new(20, 20, 20));
            let ts = TextStyleBuilder::new()
                .alignment(l.align)
                .baseline(l.baseline)
                .build();
            let _ = Text::with_text_style(&l.text, Point::new(l.at.0, l.at.1), style, ts)
                .draw(&mut canvas);
        }
        crate::image_out::write_rgb(path, W, H, &buf)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pareto_front_keeps_only_undominated_points() {
        let pts = [
            (1.0, 5.0), // front
            (2.0, 3.0), // front
            (2.5, 3.0), // dominated by (2, 3)
            (3.0, 1.0), // front
            (4.0, 1.0), // dominated by (3, 1)
            (2.0, 4.0), // dominated by (2, 3)
            (5.0, 0.5), // front
            (f64::NAN, 0.0),
        ];
        assert_eq!(pareto_front(&pts), vec![0, 1, 3, 6]);
        // Equal points do not dominate each other.
        assert_eq!(pareto_front(&[(1.0, 1.0), (1.0, 1.0)]), vec![0, 1]);
        assert!(pareto_front(&[]).is_empty());
        // One point is its own front.
        assert_eq!(pareto_front(&[(3.0, 3.0)]), vec![0]);
    }

    #[test]
    fn configurations_cover_the_grid_once() {
        let mut seen = std::collections::HashSet::new();
        for c in CONFIGURATIONS {
            assert!(seen.insert(c));
            assert!(matches!(c.subpixel, 4 | 8));
            assert!(matches!(c.depth_bits, 16 | 32));
        }
        assert_eq!(seen.len(), 8);
    }

    #[test]
    fn median_of_odd_and_even() {
        assert_eq!(median(&[3.0, 1.0, 2.0]), 2.0);
        assert_eq!(median(&[4.0, 1.0, 2.0, 3.0]), 2.5);
    }

    #[test]
    fn cubes_match_the_reference_up_to_snapping() {
        let spec = cubes_spec();
        let (w, h) = (96, 72);
        let tris = reference_triangles(&spec, w, h);
        let reference = reference::render_reference(
            &tris,
            &RefOptions {
                width: w,
                height: h,
                cull: CullMode::Back,
                front_face: FrontFace::Ccw,
            },
        );
        let prepared: Vec<_> = tris.iter().map(|t| Prepared::new(t, w, h)).collect();
        let objects: Vec<CoreObject> = spec.objects.iter().map(CoreObject::new).collect();
        for config in CONFIGURATIONS {
            let input = CoreInput {
                spec: &spec,
                objects: &objects,
                math: config.math,
                width: w,
                height: h,
            };
            let run = runner(input, config).unwrap().finish().unwrap();
            let v = vertex_error(&spec, &mvps(&spec, config.math, w, h), w, h);
            if config.math == MathBackend::Libm {
                assert!(v.window_px < 1e-3, "{config:?} {v:?}");
            }
            let e = compare(
                &run,
                config.depth_bits,
                &reference,
                &prepared,
                Tolerance::new(config.subpixel, &v),
            );
            assert!(e.covered > 1000);
            assert_eq!(e.unexplained, 0, "{config:?} {e:?}");
            assert_eq!(e.depth_beyond, 0, "{config:?} {e:?}");
            assert_eq!(e.color_beyond, 0, "{config:?} {e:?}");
            // With libm, a handful of edge pixels at most (micromath's
            // vertex error moves edges by a good part of a pixel here).
            if config.math == MathBackend::Libm {
                assert!(e.id_diff * 50 < e.covered, "{config:?} {e:?}");
            }
        }
    }

    #[test]
    fn report_writes_table_and_plot() {
        let dir = crate::test_util::TempDir::new("report");
        let args = ReportArgs {
            which: "speed-vs-error".into(),
            out_dir: dir.path().join("out"),
            quick: true,
            size: Some((64, 48)),
            reps: Some(1),
            scenes: Some(vec!["cubes".into()]),
            models: None,
            no_progress: true,
        };
        run(&args).unwrap();
        let md = std::fs::read_to_string(dir.path().join("out/speed-vs-error.md")).unwrap();
        assert!(md.contains("S8 u16 libm"));
        assert_eq!(md.matches("| cubes |").count(), 8);
        let png = std::fs::read(dir.path().join("out/speed-vs-error.png")).unwrap();
        assert_eq!(&png[1..4], b"PNG");
    }

    #[test]
    fn normal_colours_of_a_cube_corner() {
        let c = normal_colors(&cubes::CUBE_VERTICES, &cubes::CUBE_INDICES);
        // Corner (1, -1, -1): the normal points along +x, -y, -z.
        assert!(
            c[0].r() > 128 && c[0].g() < 127 && c[0].b() < 127,
            "{:?}",
            c[0]
        );
        // Corner (-1, 1, 1): the opposite.
        assert!(
            c[6].r() < 127 && c[6].g() > 128 && c[6].b() > 128,
            "{:?}",
            c[6]
        );
    }
}
