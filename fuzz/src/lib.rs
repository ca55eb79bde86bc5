//! Fuzz inputs and checks for microraster, shared by the targets in
//! `fuzz_targets/`.
//!
//! Design note: each target turns the fuzzer's bytes into a structured
//! input ([`Input`]: an optional real mesh of up to thousands of triangles
//! in a compact layout (see [`big`]), then [`FrameInput`] through
//! `arbitrary`: frame settings, setup storage, a list of submissions
//! (clip-space triangles, meshes with arbitrary matrices, processed meshes
//! with mismatched vertex caches, `Frame::clear`), a row window, ways to
//! split it, pixel and depth formats, bin settings, deliberately wrong
//! calls, and a `StripDrawer` set-up) and runs it through the public API
//! at both subpixel precisions. Floats are drawn from a mix that hits the
//! edge cases often: raw bit patterns (NaN payloads, infinities,
//! subnormals), a table of specials (`±1e38`, `f32::MAX`, guard-band
//! limits, `30000`, `1e5`, ...), small grid values and wide ranges. The
//! checks are the core's documented promises (README "The strip API",
//! `src/config.rs`, `src/stats.rs`, `src/pipeline.rs`):
//!
//! - no panic (the fuzz profile has overflow checks and debug assertions);
//! - every submitted triangle is stored or counted in exactly one culled /
//!   rejected counter;
//! - on any error nothing is written: no storage slot, no counter, no
//!   buffer (guarded, sentinel-filled buffers and bin storage, counters
//!   and stored triangles compared before and after); `StorageFull`'s
//!   `needed` is the submission's true piece count;
//! - stored triangles have their rows inside the frame, even from a vertex
//!   cache processed for another frame;
//! - nothing outside the rows asked for is written (guard regions around
//!   every buffer, `StripDrawer` areas inside the frame's rows);
//! - output independent of the strip split: `render_rows` over any split,
//!   `Frame::bin` + `render_strip` at any strip height, `StripRenderer`
//!   per strip, `StripDrawer` in both modes, all equal one `render_rows`;
//! - object culling is conservative: a mesh with its bounding sphere
//!   stores exactly what it stores without;
//! - the alternative paths agree: `submit_mesh_cached` and
//!   `process_vertices` + `submit_processed_mesh` store what `submit_mesh`
//!   stores (with a short cache: what the mesh cut to the cache stores; a
//!   long one: the mesh extended), `submit_clip_triangle` what
//!   `submit_triangle` stores, a cleared frame what a fresh one stores;
//! - every pixel format agrees with `Rgb888` through embedded-graphics'
//!   `From`, and depth does not depend on the pixel format;
//! - `Mat4` builders fed NaN, infinities and zeros do not panic, and
//!   `row`, `rows` and `from_rows` agree.

#![forbid(unsafe_code)]

pub mod big;
pub mod clipless;
pub mod clusters;
mod drawer;
pub mod occlusion;
pub mod portal;
pub mod shading;

pub use clusters::{run_clusters, ClusterInput};
pub use occlusion::{run_occlusion, OcclusionInput};
pub use portal::{run_portal, PortalInput};
pub use shading::{run_shading, ShadeInput};

use big::BigMesh;
use embedded_graphics_core::pixelcolor::{BinaryColor, Gray8, Rgb565, Rgb888, RgbColor};
use libfuzzer_sys::arbitrary::{self, Arbitrary, Unstructured};
#[cfg(feature = "libm")]
use microraster::math::Libm;
use microraster::math::{FloatFns, Micromath};
use microraster::prelude::{DepthWord, PixelFormat, Submit};
use microraster::{
    BoundingSphere, ClipVertex, Config, CullMode, DepthFunc, Error, Frame, FrontFace, LazyClear,
    Mat4, Mesh, MeshColors, NoDepth, ProcessedVertex, SetupTriangle, Stats, StripRenderer,
    TriangleId, Vec3, Vec4,
};

/// At most this many pixels are rendered per buffer, to keep an execution
/// fast; larger windows are cut down to fit.
pub const PIXEL_BUDGET: usize = 1 << 16;

/// Largest number of small submissions per input.
pub const MAX_OPS: usize = 24;

/// Floats worth hitting often.
pub const SPECIAL: [f32; 34] = [
    0.0,
    -0.0,
    1.0,
    -1.0,
    0.5,
    -0.5,
    2.0,
    f32::NAN,
    f32::INFINITY,
    f32::NEG_INFINITY,
    f32::MIN_POSITIVE,
    -f32::MIN_POSITIVE,
    1e-45, // the smallest subnormal
    -1e-45,
    1.0e-40, // a subnormal
    1e38,
    -1e38,
    f32::MAX,
    f32::MIN,
    f32::EPSILON,
    30000.0,
    -30000.0,
    1e5,
    -1e5,
    1e-7,
    524288.0,   // the guard band at S = 8, in pixels
    8388608.0,  // ... at S = 4
    16384.0,    // the largest frame
    16777216.0, // 2^24
    268435456.0,
    0.999_999_94,
    1.000_000_1,
    -0.999_999_94,
    1e10,
];

/// An `f32` that is often an edge case.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct F(pub f32);

impl<'a> Arbitrary<'a> for F {
    fn arbitrary(u: &mut Unstructured<'a>) -> arbitrary::Result<Self> {
        let tag: u8 = u.arbitrary()?;
        let v = match tag % 8 {
            0 => f32::from_bits(u.arbitrary()?),
            1 => SPECIAL[u.choose_index(SPECIAL.len())?],
            2 | 3 => u.arbitrary::<i16>()? as f32 / 64.0,
            4 => u.arbitrary::<i8>()? as f32 / 4.0,
            5 => u.arbitrary::<i32>()? as f32 * 1e-3,
            6 => u.arbitrary::<i16>()? as f32 / 16384.0,
            _ => {
                // sign * (1 + m / 2^8) * 2^e over the whole exponent range.
                let m: u8 = u.arbitrary()?;
                let e: u8 = u.arbitrary()?;
                let sign = if tag & 0x80 != 0 { -1.0f64 } else { 1.0 };
                (sign * (1.0 + m as f64 / 256.0) * 2f64.powi(e as i32 - 150)) as f32
            }
        };
        Ok(F(v))
    }
}

/// A frame side, often an edge case (0 and 16385 are invalid).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Dim(pub u32);

impl<'a> Arbitrary<'a> for Dim {
    fn arbitrary(u: &mut Unstructured<'a>) -> arbitrary::Result<Self> {
        let tag: u8 = u.arbitrary()?;
        let v: u16 = u.arbitrary()?;
        Ok(Dim(match tag % 5 {
            0 => 1 + v as u32 % 64,
            1 => [0, 1, 2, 3, 16383, 16384, 16385, u32::MAX][v as usize % 8],
            2 => 1 + v as u32 % 16384,
            3 => 1 + v as u32 % 512,
            _ => 1 + v as u32 % 8,
        }))
    }
}

/// Frame settings.
#[derive(Arbitrary, Clone, Copy, Debug)]
pub struct FrameParams {
    /// 8 subpixel bits (else 4).
    pub s8: bool,
    /// Width.
    pub width: Dim,
    /// Height.
    pub height: Dim,
    /// Culling: back, front, none.
    pub cull: u8,
    /// Clockwise front faces.
    pub front_cw: bool,
    /// Depth function index.
    pub depth_func: u8,
    /// Depth writes.
    pub depth_write: bool,
}

impl FrameParams {
    /// The core's configuration.
    pub fn config(&self) -> Config {
        let mut c = Config::new(self.width.0, self.height.0);
        c.cull = [CullMode::Back, CullMode::Front, CullMode::None][self.cull as usize % 3];
        c.front_face = if self.front_cw {
            FrontFace::Cw
        } else {
            FrontFace::Ccw
        };
        c.depth_func = [
            DepthFunc::Never,
            DepthFunc::Less,
            DepthFunc::Equal,
            DepthFunc::LessEqual,
            DepthFunc::Greater,
            DepthFunc::NotEqual,
            DepthFunc::GreaterEqual,
            DepthFunc::Always,
        ][self.depth_func as usize % 8];
        c.depth_write = self.depth_write;
        c
    }
}

/// One clip-space triangle.
#[derive(Arbitrary, Clone, Copy, Debug)]
pub struct Tri {
    /// Positions.
    pub pos: [[F; 4]; 3],
    /// Vertex colours.
    pub color: [[u8; 3]; 3],
    /// Id.
    pub id: u32,
    /// Submit with `submit_clip_triangle` (the twin takes the other one).
    pub clip: bool,
}

impl Tri {
    fn positions(&self) -> [Vec4; 3] {
        self.pos.map(|p| Vec4::new(p[0].0, p[1].0, p[2].0, p[3].0))
    }
    fn colors(&self) -> [Rgb888; 3] {
        self.color.map(|c| Rgb888::new(c[0], c[1], c[2]))
    }
    fn vertices(&self) -> [ClipVertex; 3] {
        let p = self.positions();
        [0, 1, 2].map(|k| ClipVertex {
            pos: p[k],
            varyings: self.color[k].map(|c| c as f32),
        })
    }
}

/// Which float functions build a matrix.
#[derive(Clone, Copy, Debug)]
pub enum Backend {
    /// The plain constructors (`Mat4::perspective`): the crate's default
    /// backend, micromath in the `--no-default-features` build.
    Default,
    /// `*_with::<Micromath>`.
    Micromath,
    /// `*_with::<Libm>` (micromath without the `libm` feature).
    Libm,
}

impl<'a> Arbitrary<'a> for Backend {
    fn arbitrary(u: &mut Unstructured<'a>) -> arbitrary::Result<Self> {
        Ok(Backend::from_u8(u.arbitrary()?))
    }
}

impl Backend {
    fn from_u8(b: u8) -> Backend {
        match b % 3 {
            0 => Backend::Default,
            1 => Backend::Micromath,
            _ => Backend::Libm,
        }
    }
}

/// One `Mat4` builder call.
#[derive(Arbitrary, Clone, Copy, Debug)]
pub enum Builder {
    /// `translation`.
    Translation([F; 3]),
    /// `scale`.
    Scale([F; 3]),
    /// `rotation_x`.
    RotX(F),
    /// `rotation_y`.
    RotY(F),
    /// `rotation_z`.
    RotZ(F),
    /// `perspective(fov, aspect, near, far)`.
    Perspective([F; 4]),
    /// `look_at(eye, target, up)`.
    LookAt([F; 3], [F; 3], [F; 3]),
    /// `from_rows`.
    FromRows([F; 16]),
    /// `radians(deg)` as a rotation about y.
    Degrees(F),
}

fn v3(a: [F; 3]) -> Vec3 {
    Vec3::new(a[0].0, a[1].0, a[2].0)
}

fn build_with<M: FloatFns>(b: &Builder) -> Mat4 {
    match *b {
        Builder::Translation(t) => Mat4::translation(v3(t)),
        Builder::Scale(s) => Mat4::scale(v3(s)),
        Builder::RotX(a) => Mat4::rotation_x_with::<M>(a.0),
        Builder::RotY(a) => Mat4::rotation_y_with::<M>(a.0),
        Builder::RotZ(a) => Mat4::rotation_z_with::<M>(a.0),
        Builder::Perspective(p) => Mat4::perspective_with::<M>(p[0].0, p[1].0, p[2].0, p[3].0),
        Builder::LookAt(e, t, up) => Mat4::look_at_with::<M>(v3(e), v3(t), v3(up)),
        Builder::FromRows(r) => Mat4::from_rows(core::array::from_fn(|i| {
            core::array::from_fn(|j| r[4 * i + j].0)
        })),
        Builder::Degrees(d) => Mat4::rotation_y_with::<M>(microraster::math::radians(d.0)),
    }
}

fn build_default(b: &Builder) -> Mat4 {
    match *b {
        Builder::RotX(a) => Mat4::rotation_x(a.0),
        Builder::RotY(a) => Mat4::rotation_y(a.0),
        Builder::RotZ(a) => Mat4::rotation_z(a.0),
        Builder::Perspective(p) => Mat4::perspective(p[0].0, p[1].0, p[2].0, p[3].0),
        Builder::LookAt(e, t, up) => Mat4::look_at(v3(e), v3(t), v3(up)),
        Builder::Degrees(d) => Mat4::rotation_y(microraster::math::radians(d.0)),
        _ => build_with::<Micromath>(b),
    }
}

fn build(b: &Builder, backend: Backend) -> Mat4 {
    match backend {
        Backend::Default => build_default(b),
        Backend::Micromath => build_with::<Micromath>(b),
        #[cfg(feature = "libm")]
        Backend::Libm => build_with::<Libm>(b),
        #[cfg(not(feature = "libm"))]
        Backend::Libm => build_with::<Micromath>(b),
    }
}

/// `row`, `rows` and `from_rows` agree bit for bit; `row(4..)` is `None`.
fn check_matrix(m: &Mat4, k: usize) {
    let rows = m.rows();
    for (i, r) in rows.iter().enumerate() {
        let got = m.row(i).expect("row 0..4");
        assert!(
            got.map(f32::to_bits) == r.map(f32::to_bits),
            "row({i}) differs from rows()[{i}]"
        );
    }
    assert!(m.row(4 + k % 8).is_none() && m.row(usize::MAX).is_none());
    let back = Mat4::from_rows(rows);
    assert!(
        back.cols.map(|c| c.map(f32::to_bits)) == m.cols.map(|c| c.map(f32::to_bits)),
        "from_rows(rows()) differs"
    );
    let finite = m.cols.iter().flatten().all(|v| v.is_finite());
    assert_eq!(m.is_finite(), finite);
}

/// A model-view-projection matrix: raw entries, the core's constructors
/// from arbitrary camera values, or a product of builder calls.
#[derive(Arbitrary, Clone, Debug)]
pub enum MatIn {
    /// Sixteen arbitrary entries, column-major.
    Raw([F; 16]),
    /// `perspective * look_at * rotation_y * rotation_x`.
    Camera {
        /// Field of view, radians.
        fov: F,
        /// Aspect ratio.
        aspect: F,
        /// Near plane.
        near: F,
        /// Far plane.
        far: F,
        /// Eye.
        eye: [F; 3],
        /// Target.
        target: [F; 3],
        /// Model rotation angles.
        angles: [F; 2],
        /// Float backend.
        backend: Backend,
    },
    /// A product of up to six builder calls.
    Builders(Vec<Builder>, Backend),
}

/// `perspective * look_at * rotation_y * rotation_x` on one backend.
pub fn camera(c: [f32; 10], aspect: f32, angle_x: f32, backend: Backend) -> Mat4 {
    let b = [
        Builder::Perspective([F(c[6]), F(aspect), F(c[7]), F(c[8])]),
        Builder::LookAt(
            [F(c[0]), F(c[1]), F(c[2])],
            [F(c[3]), F(c[4]), F(c[5])],
            [F(0.0), F(1.0), F(0.0)],
        ),
        Builder::RotY(F(c[9])),
        Builder::RotX(F(angle_x)),
    ];
    let ms = b.map(|b| build(&b, backend));
    for (k, m) in ms.iter().enumerate() {
        check_matrix(m, k);
    }
    ms[0] * ms[1] * ms[2] * ms[3]
}

impl MatIn {
    /// The matrix.
    pub fn matrix(&self) -> Mat4 {
        let m = match self {
            MatIn::Raw(e) => {
                let mut cols = [[0.0; 4]; 4];
                for (i, v) in e.iter().enumerate() {
                    cols[i / 4][i % 4] = v.0;
                }
                Mat4 { cols }
            }
            MatIn::Camera {
                fov,
                aspect,
                near,
                far,
                eye,
                target,
                angles,
                backend,
            } => {
                let c = [
                    eye[0].0,
                    eye[1].0,
                    eye[2].0,
                    target[0].0,
                    target[1].0,
                    target[2].0,
                    fov.0,
                    near.0,
                    far.0,
                    angles[0].0,
                ];
                camera(c, aspect.0, angles[1].0, *backend)
            }
            MatIn::Builders(bs, backend) => {
                let mut m = Mat4::IDENTITY;
                for (k, b) in bs.iter().take(6).enumerate() {
                    let x = build(b, *backend);
                    check_matrix(&x, k);
                    m = m * x;
                }
                m
            }
        };
        check_matrix(&m, 0);
        m
    }
}

/// A mesh with a matrix.
#[derive(Arbitrary, Clone, Debug)]
pub struct MeshIn {
    /// Positions (at most 48 are used).
    pub positions: Vec<[F; 3]>,
    /// Triangles (at most 96 are used); indices may be out of range.
    pub indices: Vec<[u8; 3]>,
    /// Per-vertex colours (else per-triangle, else uniform), cycled.
    pub colors: Vec<[u8; 3]>,
    /// 0: uniform, 1: per triangle, 2: per vertex.
    pub color_mode: u8,
    /// The matrix.
    pub mvp: MatIn,
    /// Give the mesh its bounding sphere.
    pub bounds: bool,
    /// First triangle id.
    pub first_id: u32,
    /// Extra vertex-cache entries for `submit_mesh_cached` (a longer cache
    /// is allowed).
    pub extra_cache: u8,
}

/// A vertex cache for `submit_processed_mesh`, right or wrong.
#[derive(Arbitrary, Clone, Debug)]
pub enum CacheKind {
    /// Processed by this frame for this mesh.
    Exact,
    /// Cut short by `1 + n % len` entries: the triangles reaching past it
    /// are bad indices (as for the mesh cut to the cache).
    Short(u8),
    /// Longer, the extra entries processed from these positions (as for
    /// the mesh with them appended).
    Long(Vec<[F; 3]>),
    /// Processed with another matrix (as for the mesh under it).
    OtherMvp(MatIn),
    /// Processed by a frame of another size and precision: no oracle, only
    /// the invariants (rows inside the frame, counters, no panic).
    OtherFrame {
        /// Width.
        width: Dim,
        /// Height.
        height: Dim,
        /// The other precision.
        other_s: bool,
    },
    /// Stale entries (`ProcessedVertex::EMPTY`) after the first `n`.
    Stale(u8),
}

/// One submission.
#[derive(Arbitrary, Clone, Debug)]
pub enum Op {
    /// A clip-space triangle.
    Tri(Tri),
    /// A mesh (`submit_mesh`; the twin `submit_mesh_cached`).
    Mesh(MeshIn),
    /// A mesh through `process_vertices` + `submit_processed_mesh`.
    Processed(MeshIn, CacheKind),
    /// `Frame::clear` (ignored by strip renderers, which get only what
    /// follows the last one).
    Clear,
}

/// A wrong (or accidentally right) `render_rows` call.
#[derive(Arbitrary, Clone, Copy, Debug)]
pub struct BadCall {
    /// First row.
    pub y0: u16,
    /// One past the last row.
    pub y1: u16,
    /// Colour length change.
    pub dc: i8,
    /// Depth length change.
    pub dd: i8,
}

/// Settings for the `StripDrawer` arm.
#[derive(Arbitrary, Clone, Copy, Debug)]
pub struct DrawerIn {
    /// Rows the colour strip holds (cut to the pixel budget).
    pub rows: u16,
    /// Extra colour pixels (less than a row is meaningful).
    pub extra: u16,
    /// Depth length change against the colour strip.
    pub depth_delta: i16,
    /// Origin x and y: 0 near `i32::MIN`, 1 near `i32::MAX`, else small.
    pub origin: [(u8, i16); 2],
    /// Depth clear value: 0 default (far), 1 zero, else `clear_z32`.
    pub clear_kind: u8,
    /// `with_clear_depth` value.
    pub clear_z32: u32,
    /// Background.
    pub background: [u8; 3],
    /// The target fails at this strip (if any).
    pub fail_at: Option<u8>,
    /// Pixel format: Rgb565, Gray8, BinaryColor, Rgb888 into Rgb565,
    /// Rgb888, Rgb888 into Gray8, Rgb888 into BinaryColor.
    pub format: u8,
    /// Immediate mode (`draw`), else `draw_frame`.
    pub immediate: bool,
}

/// The structured part of the `frame` and `strip_renderer` inputs.
#[derive(Arbitrary, Clone, Debug)]
pub struct FrameInput {
    /// Frame settings.
    pub params: FrameParams,
    /// Setup storage: `% 4` picks 0: `(v >> 2) % 80` triangles,
    /// 1: `Frame::storage_for(n)`, 2: 7 per triangle, 3: 1 per triangle.
    pub storage: u16,
    /// Submissions.
    pub ops: Vec<Op>,
    /// Row window to render: first row and row count (cut to the frame
    /// and the pixel budget).
    pub window: (u16, u16),
    /// Strip heights splitting the window (0 stands for 1).
    pub splits: Vec<u8>,
    /// 0: u16, 1: u32, 2: no depth buffer.
    pub depth_kind: u8,
    /// 0: TriangleId, 1: Rgb888, 2: Rgb565, 3: Gray8, 4: BinaryColor.
    pub pixel: u8,
    /// Rows per strip for `Frame::bin`: `% 6` picks 0, 1 + v % h, h,
    /// h + v, u32::MAX, v.
    pub bin_rows: (u8, u32),
    /// Strips past the end for `render_strip`.
    pub past: u32,
    /// Wrong calls.
    pub bad: Vec<BadCall>,
    /// The `StripDrawer` arm.
    pub drawer: Option<DrawerIn>,
}

/// A whole fuzz input: a real mesh ([`big`]) and the rest.
#[derive(Clone, Debug)]
pub struct Input {
    /// The real mesh, if the blob has one.
    pub big: Option<BigMesh>,
    /// Everything else.
    pub rest: FrameInput,
}

impl Input {
    /// Parses a whole fuzz input (see [`big`] for the layout).
    pub fn parse(data: &[u8]) -> arbitrary::Result<Input> {
        let (blob, rest) = big::split_input(data);
        let big = (!blob.is_empty()).then(|| BigMesh::parse(blob));
        let rest = FrameInput::arbitrary_take_rest(Unstructured::new(rest))?;
        Ok(Input { big, rest })
    }
}

impl<'a> Arbitrary<'a> for Input {
    fn arbitrary(u: &mut Unstructured<'a>) -> arbitrary::Result<Self> {
        let n = u.len().min(u.arbitrary::<u32>()? as usize);
        let blob = u.bytes(n)?;
        let big = (!blob.is_empty()).then(|| BigMesh::parse(blob));
        Ok(Input {
            big,
            rest: FrameInput::arbitrary(u)?,
        })
    }
    fn arbitrary_take_rest(u: Unstructured<'a>) -> arbitrary::Result<Self> {
        let r = Input::parse(u.take_rest());
        if let Err(e) = &r {
            debug(|| format!("input rejected: {e}"));
        }
        r
    }
}

// ---------------------------------------------------------------------
// Prepared submissions: the fuzz input in the core's types, built once.

/// A mesh in the core's types.
#[derive(Clone, Debug)]
pub struct OwnedMesh {
    /// Positions.
    pub positions: Vec<Vec3>,
    /// Indices.
    pub indices: Vec<[u32; 3]>,
    /// Colours.
    pub colors: Vec<Rgb888>,
    /// Colour mode.
    pub mode: u8,
    /// Bounding sphere.
    pub bounds: Option<BoundingSphere>,
    /// Matrix.
    pub mvp: Mat4,
    /// First id.
    pub first_id: u32,
}

fn mesh_colors(n: usize, src: &[[u8; 3]]) -> Vec<Rgb888> {
    if src.is_empty() {
        vec![Rgb888::WHITE; n]
    } else {
        (0..n)
            .map(|i| {
                let c = src[i % src.len()];
                Rgb888::new(c[0], c[1], c[2])
            })
            .collect()
    }
}

impl OwnedMesh {
    /// Converts the fuzz input.
    pub fn new(m: &MeshIn) -> Self {
        let positions: Vec<Vec3> = m.positions.iter().take(48).map(|p| v3(*p)).collect();
        let indices: Vec<[u32; 3]> = m
            .indices
            .iter()
            .take(96)
            .map(|t| t.map(|i| i as u32 % (positions.len() as u32 + 2)))
            .collect();
        let mode = m.color_mode % 3;
        let n = match mode {
            1 => indices.len(),
            _ => positions.len(),
        };
        let mut o = OwnedMesh {
            bounds: None,
            colors: mesh_colors(n, &m.colors),
            positions,
            indices,
            mode,
            mvp: m.mvp.matrix(),
            first_id: m.first_id,
        };
        o.set_bounds(m.bounds);
        o
    }

    /// A real mesh from the blob, framed for a `width x height` frame.
    pub fn big(b: &BigMesh, aspect: f32) -> Self {
        let positions: Vec<Vec3> = b
            .positions
            .iter()
            .map(|p| Vec3::new(p[0], p[1], p[2]))
            .collect();
        let mode = b.color_mode() % 3;
        let n = match mode {
            1 => b.indices.len(),
            _ => positions.len(),
        };
        // Colours from the positions, so Gouraud shading varies.
        let colors = (0..n)
            .map(|i| {
                let p = positions.get(i % positions.len().max(1)).copied();
                let p = p.unwrap_or(Vec3::new(0.0, 0.0, 0.0));
                let c = |v: f32| ((v * 0.5 + 0.5).clamp(0.0, 1.0) * 255.0) as u8;
                Rgb888::new(c(p.x), c(p.y), c(p.z))
            })
            .collect();
        let mut o = OwnedMesh {
            bounds: None,
            colors,
            positions,
            indices: b.indices.clone(),
            mode,
            mvp: camera(b.camera, aspect, 0.0, Backend::from_u8(b.backend())),
            first_id: (b.first_id as u32) << 8,
        };
        o.set_bounds(b.bounds());
        o
    }

    fn set_bounds(&mut self, on: bool) {
        self.bounds = if on {
            BoundingSphere::from_points(&self.positions)
        } else {
            None
        };
        if let Some(b) = self.bounds {
            // Every point is inside the sphere it was given.
            for p in &self.positions {
                let d = *p - b.center;
                assert!(
                    d.dot(d).sqrt() <= b.radius || d.dot(d) <= b.radius * b.radius,
                    "a point outside its bounding sphere: {p:?} {b:?}"
                );
            }
        }
    }

    /// As the core's mesh.
    pub fn mesh(&self) -> Mesh<'_> {
        Mesh {
            positions: &self.positions,
            indices: &self.indices,
            attributes: match self.mode {
                0 => MeshColors::Uniform(self.colors.first().copied().unwrap_or(Rgb888::RED)),
                1 => MeshColors::PerTriangle(&self.colors),
                _ => MeshColors::PerVertex(&self.colors),
            },
            bounds: self.bounds,
        }
    }

    /// The same without its bounding sphere.
    pub fn unbounded(&self) -> Mesh<'_> {
        Mesh {
            bounds: None,
            ..self.mesh()
        }
    }
}

/// A submission in the core's types.
#[derive(Debug)]
pub enum Prep {
    /// A triangle.
    Tri(Tri),
    /// A mesh; cached path with this many extra cache entries.
    Mesh(OwnedMesh, usize),
    /// A processed mesh: the cache, and (where there is one) the mesh
    /// `submit_mesh` must treat the same (no bounds).
    Processed {
        /// The mesh.
        mesh: OwnedMesh,
        /// The vertex cache handed to `submit_processed_mesh`.
        cache: Vec<ProcessedVertex>,
        /// The oracle: a mesh `submit_mesh` stores the same for.
        oracle: Option<OwnedMesh>,
    },
    /// `Frame::clear`.
    Clear,
}

impl Prep {
    /// Triangles submitted.
    pub fn triangles(&self) -> usize {
        match self {
            Prep::Tri(_) => 1,
            Prep::Mesh(m, _) | Prep::Processed { mesh: m, .. } => m.indices.len(),
            Prep::Clear => 0,
        }
    }
}

/// The vertex stage of a frame of `config` at `S` bits.
fn process<const S: u32>(config: Config, mvp: &Mat4, positions: &[Vec3]) -> Vec<ProcessedVertex> {
    let mut out = vec![ProcessedVertex::EMPTY; positions.len()];
    if let Ok(f) = Frame::<S>::with_subpixel_bits(config, &mut []) {
        f.process_vertices(mvp, positions, &mut out);
    }
    out
}

fn prep_processed<const S: u32>(config: Config, mesh: OwnedMesh, kind: &CacheKind) -> Prep {
    let exact = || process::<S>(config, &mesh.mvp, &mesh.positions);
    let plain = |m: &OwnedMesh| OwnedMesh {
        bounds: None,
        ..m.clone()
    };
    let (cache, oracle) = match kind {
        CacheKind::Exact => (exact(), Some(plain(&mesh))),
        CacheKind::Short(n) => {
            let len = mesh.positions.len();
            let keep = len.saturating_sub(1 + *n as usize % len.max(1));
            let mut c = exact();
            c.truncate(keep);
            let mut o = plain(&mesh);
            o.positions.truncate(keep);
            (c, Some(o))
        }
        CacheKind::Long(extra) => {
            let mut o = plain(&mesh);
            o.positions.extend(extra.iter().take(8).map(|p| v3(*p)));
            (process::<S>(config, &o.mvp, &o.positions), Some(o))
        }
        CacheKind::OtherMvp(m) => {
            let mut o = plain(&mesh);
            o.mvp = m.matrix();
            (process::<S>(config, &o.mvp, &o.positions), Some(o))
        }
        CacheKind::OtherFrame {
            width,
            height,
            other_s,
        } => {
            let mut c2 = config;
            c2.width = width.0;
            c2.height = height.0;
            let c = match (*other_s, S) {
                (true, 8) => process::<4>(c2, &mesh.mvp, &mesh.positions),
                (true, _) => process::<8>(c2, &mesh.mvp, &mesh.positions),
                _ => process::<S>(c2, &mesh.mvp, &mesh.positions),
            };
            (c, None)
        }
        CacheKind::Stale(n) => {
            let mut c = exact();
            for v in c.iter_mut().skip(*n as usize % 8) {
                *v = ProcessedVertex::EMPTY;
            }
            (c, None)
        }
    };
    debug(|| {
        format!(
            "arm: processed {}",
            format!("{kind:?}").split(['(', ' ']).next().unwrap_or("")
        )
    });
    Prep::Processed {
        mesh,
        cache,
        oracle,
    }
}

/// The input's submissions, big mesh first, for a frame of `config`.
pub fn prepare<const S: u32>(input: &Input, config: Config) -> Vec<Prep> {
    let mut out = Vec::new();
    if let Some(b) = &input.big {
        let aspect = config.width as f32 / config.height.max(1) as f32;
        let m = OwnedMesh::big(b, aspect);
        out.push(match b.path() {
            0 => Prep::Mesh(m, 0),
            1 => Prep::Mesh(m, 3),
            2 => prep_processed::<S>(config, m, &CacheKind::Exact),
            _ => prep_processed::<S>(config, m, &CacheKind::Short(b.first_id)),
        });
    }
    for op in input.rest.ops.iter().take(MAX_OPS) {
        out.push(match op {
            Op::Tri(t) => Prep::Tri(*t),
            Op::Mesh(m) => Prep::Mesh(OwnedMesh::new(m), m.extra_cache as usize % 4),
            Op::Processed(m, k) => prep_processed::<S>(config, OwnedMesh::new(m), k),
            Op::Clear => Prep::Clear,
        });
    }
    out
}

/// The frame size an input asks for (the blob's override first).
pub fn frame_config(input: &Input) -> Config {
    let mut c = input.rest.params.config();
    if let Some((w, h)) = input.big.as_ref().and_then(|b| b.size) {
        c.width = w;
        c.height = h;
    }
    c
}

// ---------------------------------------------------------------------
// Submission through `Submit`, with the bookkeeping checks.

/// How a submission is sent: the main way, or the twin's alternative.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Way {
    /// `submit_triangle` / `submit_clip_triangle` as the op says,
    /// `submit_mesh`, `submit_processed_mesh`.
    Main,
    /// The other triangle call, `submit_mesh_cached`, `submit_mesh` on the
    /// processed mesh's oracle.
    Twin,
    /// As `Main`, without bounding spheres.
    Unbounded,
}

/// Submits one prepared op to any receiver. `Clear` is the caller's.
pub fn submit_prep<const S: u32, R: Submit<S>>(r: &mut R, p: &Prep, way: Way) -> Result<(), Error> {
    match p {
        Prep::Tri(t) => {
            if t.clip == (way == Way::Twin) {
                r.submit_triangle(t.vertices(), t.id)
            } else {
                r.submit_clip_triangle(t.positions(), t.colors(), t.id)
            }
        }
        Prep::Mesh(m, extra) => match way {
            Way::Main => r.submit_mesh(&m.mesh(), &m.mvp, m.first_id),
            Way::Unbounded => r.submit_mesh(&m.unbounded(), &m.mvp, m.first_id),
            Way::Twin => {
                let mut cache = vec![ProcessedVertex::EMPTY; m.positions.len() + extra];
                r.submit_mesh_cached(&m.mesh(), &m.mvp, m.first_id, &mut cache)
            }
        },
        Prep::Processed {
            mesh,
            cache,
            oracle,
        } => match (way, oracle) {
            (Way::Twin, Some(o)) => r.submit_mesh(&o.mesh(), &o.mvp, o.first_id),
            _ => r.submit_processed_mesh(&mesh.mesh(), mesh.first_id, cache),
        },
        Prep::Clear => Ok(()),
    }
}

/// `b - a` field by field (a counter that went down overflows: a finding).
pub(crate) fn diff(a: &Stats, b: &Stats) -> Stats {
    Stats {
        submitted: b.submitted - a.submitted,
        culled_object: b.culled_object - a.culled_object,
        culled_frustum: b.culled_frustum - a.culled_frustum,
        culled_backface: b.culled_backface - a.culled_backface,
        culled_degenerate: b.culled_degenerate - a.culled_degenerate,
        rejected_nonfinite: b.rejected_nonfinite - a.rejected_nonfinite,
        rejected_index: b.rejected_index - a.rejected_index,
        clipped: b.clipped - a.clipped,
        stored: b.stored - a.stored,
        outside_strip: b.outside_strip - a.outside_strip,
        culled_cluster: b.culled_cluster - a.culled_cluster,
        culled_hierarchy: b.culled_hierarchy - a.culled_hierarchy,
        culled_detail: b.culled_detail - a.culled_detail,
        culled_mask: b.culled_mask - a.culled_mask,
        culled_occlusion: b.culled_occlusion - a.culled_occlusion,
        culled_portal: b.culled_portal - a.culled_portal,
        detail_boxes: b.detail_boxes - a.detail_boxes,
    }
}

/// Checks the counters one successful submission of `n` triangles added.
pub fn check_accounting(before: &Stats, after: &Stats, n: u64) {
    let d = diff(before, after);
    assert_eq!(*before + d, *after, "Stats + differs from the difference");
    let mut x = *before;
    x += d;
    assert_eq!(x, *after, "Stats += differs from +");
    assert_eq!(d.submitted, n, "{d:?}");
    let dropped = d.dropped();
    assert!(dropped <= n, "{d:?}");
    let kept = n - dropped;
    // Every kept triangle stores 1..=7 pieces.
    assert!(
        d.stored >= kept && d.stored <= microraster::MAX_PIECES as u64 * kept,
        "{d:?}"
    );
    assert!(d.clipped <= n, "{d:?}");
}

/// Submits to a frame, checking the bookkeeping (all or nothing,
/// `StorageFull`'s numbers).
pub fn submit_frame<const S: u32>(
    frame: &mut Frame<'_, S>,
    p: &Prep,
    way: Way,
) -> Result<(), Error> {
    if let Prep::Clear = p {
        frame.clear();
        assert!(frame.triangles().is_empty(), "clear left triangles");
        assert_eq!(frame.stats(), Stats::default(), "clear left counters");
        return Ok(());
    }
    // A cache too short for the mesh is refused and writes nothing.
    if let (Prep::Mesh(m, _), Way::Twin) = (p, way) {
        if !m.positions.is_empty() {
            let (len0, stats0) = (frame.triangles().len(), frame.stats());
            let mut short = vec![ProcessedVertex::EMPTY; m.positions.len() - 1];
            let r = frame.submit_mesh_cached(&m.mesh(), &m.mvp, m.first_id, &mut short);
            assert_eq!(
                r,
                Err(Error::VertexCacheSize {
                    expected: m.positions.len(),
                    actual: m.positions.len() - 1
                })
            );
            assert_eq!(frame.triangles().len(), len0, "an error stored");
            assert_eq!(frame.stats(), stats0, "an error counted");
        }
    }
    let (len0, stats0) = (frame.triangles().len(), frame.stats());
    let before: Vec<SetupTriangle> = frame.triangles().to_vec();
    let r = submit_prep::<S, _>(frame, p, way);
    let n = p.triangles() as u64;
    match r {
        Ok(()) => {
            check_accounting(&stats0, &frame.stats(), n);
            let d = diff(&stats0, &frame.stats());
            assert_eq!(d.outside_strip, 0, "a frame skipped a triangle as outside");
            assert_eq!(frame.triangles().len() - len0, d.stored as usize);
            assert!(
                frame.triangles()[..len0] == before[..],
                "a submission rewrote storage"
            );
        }
        Err(Error::StorageFull {
            capacity,
            free,
            needed,
        }) => {
            assert_eq!(
                frame.triangles().len(),
                len0,
                "StorageFull stored something"
            );
            assert!(
                frame.triangles() == &before[..],
                "StorageFull rewrote storage"
            );
            assert_eq!(frame.stats(), stats0, "StorageFull counted something");
            assert_eq!(capacity, frame.capacity());
            assert_eq!(free, capacity - len0);
            assert!(needed > free, "StorageFull with {needed} <= {free}");
            debug(|| format!("arm: StorageFull {capacity} {free} {needed}"));
            // `needed` is the submission's piece count: what an empty frame
            // with room for all of it stores.
            let mut st = vec![SetupTriangle::EMPTY; needed];
            let mut scratch =
                Frame::<S>::with_subpixel_bits(*frame.config(), &mut st).expect("same config");
            submit_prep::<S, _>(&mut scratch, p, way).expect("room for `needed`");
            assert_eq!(
                scratch.triangles().len(),
                needed,
                "StorageFull's needed is wrong"
            );
        }
        Err(e) => panic!("unexpected error from a submission: {e:?}"),
    }
    r
}

/// Stored rows inside the frame, vertices inside the coordinate limit.
fn check_triangles(tris: &[SetupTriangle], height: u32) {
    for t in tris {
        let (a, b) = t.rows();
        assert!(a <= b && (b as u32) < height, "rows {a}..={b} of {height}");
        for (x, y) in t.vertices() {
            assert!(
                x.unsigned_abs() <= 1 << 28 && y.unsigned_abs() <= 1 << 28,
                "vertex {x},{y}"
            );
        }
    }
}

/// With `MICRORASTER_FUZZ_DEBUG` set, prints what an input did.
pub fn debug(f: impl FnOnce() -> String) {
    static ON: std::sync::OnceLock<bool> = std::sync::OnceLock::new();
    if *ON.get_or_init(|| std::env::var_os("MICRORASTER_FUZZ_DEBUG").is_some()) {
        eprintln!("{}", f());
    }
}

// ---------------------------------------------------------------------
// Guarded buffers and rendering.

const GUARD: usize = 16;

/// A buffer with guard regions on both sides.
pub(crate) struct Guarded<T> {
    pub(crate) v: Vec<T>,
    len: usize,
    guard: T,
}

impl<T: Copy + PartialEq + core::fmt::Debug> Guarded<T> {
    pub(crate) fn new(len: usize, fill: T, guard: T) -> Self {
        let mut v = vec![guard; len + 2 * GUARD];
        v[GUARD..GUARD + len].fill(fill);
        Guarded { v, len, guard }
    }
    pub(crate) fn inner(&mut self) -> &mut [T] {
        &mut self.v[GUARD..GUARD + self.len]
    }
    pub(crate) fn get(&self) -> &[T] {
        &self.v[GUARD..GUARD + self.len]
    }
    pub(crate) fn check_guards(&self) {
        assert!(
            self.v[..GUARD].iter().all(|&g| g == self.guard)
                && self.v[GUARD + self.len..].iter().all(|&g| g == self.guard),
            "a guard region was written"
        );
    }
}

/// A depth word with a guard value.
pub trait DepthGuard: DepthWord {
    /// A guard value.
    const GUARD: Self;
}
impl DepthGuard for u16 {
    const GUARD: Self = 0x5a5a;
}
impl DepthGuard for u32 {
    const GUARD: Self = 0x5a5a_5a5a;
}

/// The pixel types.
pub trait PixelWord: PixelFormat + PartialEq + core::fmt::Debug + 'static {
    /// Clear value.
    const CLEAR: Self;
    /// Guard value.
    const GUARD: Self;
}
impl PixelWord for TriangleId {
    const CLEAR: Self = TriangleId(0);
    const GUARD: Self = TriangleId(0xdead_beef);
}
impl PixelWord for Rgb888 {
    const CLEAR: Self = Rgb888::new(1, 2, 3);
    const GUARD: Self = Rgb888::new(0xde, 0xad, 0xbe);
}
impl PixelWord for Rgb565 {
    const CLEAR: Self = Rgb565::new(1, 2, 3);
    const GUARD: Self = Rgb565::new(27, 43, 23);
}
impl PixelWord for Gray8 {
    const CLEAR: Self = Gray8::new(3);
    const GUARD: Self = Gray8::new(0xa5);
}
/// Two values only: guards catch writes of `On` outside the rows.
impl PixelWord for BinaryColor {
    const CLEAR: Self = BinaryColor::Off;
    const GUARD: Self = BinaryColor::Off;
}

/// Renders rows `y0..y1` into fresh guarded buffers cleared to `clear`
/// and `T::FAR`; returns colour, depth (empty without a depth buffer) and
/// the pixels written.
pub(crate) fn render_with<const S: u32, C: PixelWord, T: DepthGuard>(
    frame: &Frame<'_, S>,
    y0: u32,
    y1: u32,
    use_depth: bool,
    clear: C,
) -> (Vec<C>, Vec<T>, u64) {
    let len = frame.config().width as usize * (y1 - y0) as usize;
    let mut c = Guarded::new(len, clear, C::GUARD);
    let mut d = Guarded::new(len, T::FAR, T::GUARD);
    let r = if use_depth {
        frame.render_rows(y0, y1, c.inner(), d.inner())
    } else {
        frame.render_rows(y0, y1, c.inner(), &mut NoDepth)
    };
    let stats = r.unwrap_or_else(|e| panic!("render_rows({y0}, {y1}): {e:?}"));
    c.check_guards();
    d.check_guards();
    if !use_depth {
        assert!(d.get().iter().all(|&z| z == T::FAR));
    }
    // Pixels that changed were written (a write may leave a pixel as it
    // was, so this is a bound, not an equality).
    let changed = c.get().iter().filter(|&&p| p != clear).count() as u64;
    assert!(
        changed <= stats.pixels_written,
        "{changed} changed, {stats:?}"
    );
    let depth = if use_depth {
        d.get().to_vec()
    } else {
        Vec::new()
    };
    (c.get().to_vec(), depth, stats.pixels_written)
}

fn render<const S: u32, C: PixelWord, T: DepthGuard>(
    frame: &Frame<'_, S>,
    y0: u32,
    y1: u32,
    use_depth: bool,
) -> (Vec<C>, Vec<T>) {
    let (c, d, _) = render_with::<S, C, T>(frame, y0, y1, use_depth, C::CLEAR);
    (c, d)
}

/// The row window `y0..y1` actually rendered, within the frame and the
/// pixel budget.
pub fn rows(input: &FrameInput, config: &Config) -> (u32, u32) {
    let (w, h) = (config.width.max(1), config.height.max(1));
    let y0 = input.window.0 as u32 % h;
    let max_rows = ((PIXEL_BUDGET / w as usize).max(1) as u32).min(h - y0);
    let n = 1 + input.window.1 as u32 % max_rows;
    (y0, y0 + n)
}

/// Strip rows for `Frame::bin` from the input.
fn bin_rows(input: &FrameInput, height: u32) -> u32 {
    let (k, v) = input.bin_rows;
    match k % 6 {
        0 => 0,
        1 => 1 + v % height,
        2 => height,
        3 => height.saturating_add(v),
        4 => u32::MAX,
        _ => v,
    }
}

/// The checks on a built frame with pixel type `C` and depth `T`.
fn check_frame_typed<const S: u32, C: PixelWord, T: DepthGuard>(
    input: &FrameInput,
    frame: &Frame<'_, S>,
    use_depth: bool,
) {
    let config = *frame.config();
    let (w, h) = (config.width as usize, config.height);
    let (y0, y1) = rows(input, &config);
    let (whole_c, whole_d) = render::<S, C, T>(frame, y0, y1, use_depth);
    if use_depth {
        // Depth does not depend on the pixel type.
        let (_, ids_d) = render::<S, TriangleId, T>(frame, y0, y1, true);
        let (_, rgb_d) = render::<S, Rgb888, T>(frame, y0, y1, true);
        assert!(
            ids_d == rgb_d,
            "depth differs between TriangleId and Rgb888"
        );
        assert!(ids_d == whole_d, "depth differs between pixel types");
    }

    // Any split of the window gives the same pixels.
    let mut y = y0;
    let mut k = 0;
    while y < y1 {
        let step = input.splits.get(k).map_or(y1 - y, |&s| s.max(1) as u32);
        let e = (y + step).min(y1);
        let (c, d) = render::<S, C, T>(frame, y, e, use_depth);
        let (a, b) = ((y - y0) as usize * w, (e - y0) as usize * w);
        assert!(
            c == whole_c[a..b],
            "strip {y}..{e} of {y0}..{y1}: colour differs"
        );
        if use_depth {
            assert!(
                d == whole_d[a..b],
                "strip {y}..{e} of {y0}..{y1}: depth differs"
            );
        }
        y = e;
        k += 1;
    }

    // Binning at the input's strip height (0, h, beyond h, u32::MAX, ...).
    let r = bin_rows(input, h);
    let entries = frame.bin_entries(r);
    assert_eq!(entries, frame.bin_entries(r.max(1)), "bin_entries(0) is 1");
    const SENT: u32 = 0xa5a5_a5a5;
    if r == 0 {
        let mut offsets = vec![SENT; 4];
        let mut items = vec![SENT; entries.min(1 << 20)];
        let e = frame.bin(0, &mut offsets, &mut items).map(|_| ());
        assert_eq!(e, Err(Error::InvalidStripRows));
        debug(|| "arm: bin 0".into());
        assert!(
            offsets.iter().chain(&items).all(|&v| v == SENT),
            "an error wrote bins"
        );
        return check_formats::<S, T>(input, frame, use_depth);
    }
    let strips = h.div_ceil(r) as usize;
    if r >= h {
        assert_eq!(strips, 1);
    }
    if entries > 1 << 20 || strips > 1 << 15 {
        return check_formats::<S, T>(input, frame, use_depth);
    }
    // Storage one short of either need is an error that writes nothing.
    {
        let mut offsets = vec![SENT; strips + 1];
        let mut items = vec![SENT; entries];
        if entries > 0 {
            let r2 = frame
                .bin(r, &mut offsets, &mut items[..entries - 1])
                .map(|_| ());
            assert!(matches!(r2, Err(Error::BinStorageSize { .. })), "{r2:?}");
        }
        let r2 = frame.bin(r, &mut offsets[..strips], &mut items).map(|_| ());
        assert_eq!(
            r2,
            Err(Error::BinStorageSize {
                expected: strips + 1,
                actual: strips
            })
        );
        assert!(
            offsets.iter().chain(&items).all(|&v| v == SENT),
            "an error wrote bins"
        );
    }
    let mut offsets = vec![SENT; strips + 1];
    let mut items = vec![SENT; entries + 2];
    let bins = frame.bin(r, &mut offsets, &mut items).expect("bin");
    debug(|| format!("arm: bin r={r} h={h} strips={strips} entries={entries}"));
    assert_eq!(bins.strips() as usize, strips);
    assert_eq!(bins.strip_rows(), r);
    // Each bin holds exactly the triangles reaching its strip, in order.
    let mut want: Vec<Vec<u32>> = vec![Vec::new(); strips];
    for (i, t) in frame.triangles().iter().enumerate() {
        let (ta, tb) = t.rows();
        for s in ta as u32 / r..=tb as u32 / r {
            want[s as usize].push(i as u32);
        }
    }
    let mut total = 0;
    for s in 0..bins.strips() {
        let (a, b) = bins.rows(s);
        assert!(a < b && b <= h, "strip {s}: rows {a}..{b}");
        assert_eq!(a, s * r, "strip {s} starts at {a}");
        total += bins.strip_items(s).len();
        assert!(
            bins.strip_items(s) == &want[s as usize][..],
            "bin {s} differs"
        );
    }
    assert_eq!(total, entries);
    // The same bins with the items asked for once counted (a strip is a
    // tile as wide as the frame); one short is the same error.
    {
        let mut offsets = vec![SENT; strips + 1];
        let mut short = vec![SENT; entries.saturating_sub(1)];
        if entries > 0 {
            let e = frame
                .bin_tiles_with(w as u32, r, &mut offsets, |n| {
                    assert_eq!(n, entries, "asked for the wrong count");
                    &mut short[..]
                })
                .map(|_| ());
            assert!(matches!(e, Err(Error::BinStorageSize { .. })), "{e:?}");
            assert!(short.iter().all(|&v| v == SENT), "an error wrote items");
        }
        let mut items = Vec::new();
        let counted = frame
            .bin_tiles_with(w as u32, r, &mut offsets, |n| {
                items.resize(n, SENT);
                &mut items[..]
            })
            .expect("bin_tiles_with");
        assert_eq!(counted.strips(), bins.strips());
        for s in 0..bins.strips() {
            assert!(
                counted.strip_items(s) == bins.strip_items(s),
                "bin_tiles_with: bin {s} differs"
            );
        }
    }
    for s in [
        bins.strips(),
        bins.strips().saturating_add(input.past),
        u32::MAX,
    ] {
        assert!(bins.strip_items(s).is_empty());
        let (a, b) = bins.rows(s);
        assert_eq!((a, b), (h, h), "rows past the end");
        // A strip past the end is an error that writes nothing.
        let mut c = Guarded::new(w, C::CLEAR, C::GUARD);
        let mut d = Guarded::new(w, T::FAR, T::GUARD);
        let res = frame.render_strip(&bins, s, c.inner(), d.inner());
        assert!(matches!(res, Err(Error::InvalidRows { .. })), "{res:?}");
        c.check_guards();
        d.check_guards();
        assert!(
            c.get().iter().all(|&p| p == C::CLEAR),
            "an error wrote colour"
        );
        assert!(d.get().iter().all(|&p| p == T::FAR), "an error wrote depth");
    }
    for s in y0 / r..=(y1 - 1) / r {
        let (a, b) = bins.rows(s);
        if (b - a) as usize * w > PIXEL_BUDGET {
            continue;
        }
        let len = (b - a) as usize * w;
        let mut c = Guarded::new(len, C::CLEAR, C::GUARD);
        let mut d = Guarded::new(len, T::FAR, T::GUARD);
        let res = if use_depth {
            frame.render_strip(&bins, s, c.inner(), d.inner())
        } else {
            frame.render_strip(&bins, s, c.inner(), &mut NoDepth)
        };
        res.unwrap_or_else(|e| panic!("render_strip {s}: {e:?}"));
        c.check_guards();
        d.check_guards();
        let (rc, rd) = render::<S, C, T>(frame, a, b, use_depth);
        assert!(
            c.get() == &rc[..],
            "binned strip {s} ({a}..{b}) colour differs"
        );
        if use_depth {
            assert!(
                d.get() == &rd[..],
                "binned strip {s} ({a}..{b}) depth differs"
            );
        }
    }
    // A deferred clear of each strip, into buffers holding garbage (the
    // guards' value), gives the cleared strip; a hull one short is an
    // error that writes nothing.
    for s in y0 / r..=(y1 - 1) / r {
        let (a, b) = bins.rows(s);
        let len = (b - a) as usize * w;
        if len > PIXEL_BUDGET {
            continue;
        }
        let rect = bins.rect(s);
        let rows = (b - a) as usize;
        let mut c = Guarded::new(len, C::GUARD, C::GUARD);
        let mut d = Guarded::new(len, T::GUARD, T::GUARD);
        let mut hull = vec![SENT; rows + input.past as usize % 3];
        let short = LazyClear::new(&mut hull[..rows - 1], rect, C::CLEAR, T::FAR.to_z32());
        assert!(matches!(short, Err(Error::HullSize { .. })), "{short:?}");
        let mut lazy =
            LazyClear::new(&mut hull, rect, C::CLEAR, T::FAR.to_z32()).expect("hull fits");
        let res = if use_depth {
            frame.render_tile_lazy(&bins, s, c.inner(), d.inner(), &mut lazy)
        } else {
            frame.render_tile_lazy(&bins, s, c.inner(), &mut NoDepth, &mut lazy)
        };
        res.unwrap_or_else(|e| panic!("render_tile_lazy {s}: {e:?}"));
        let done = if use_depth {
            lazy.finish(c.inner(), d.inner())
        } else {
            lazy.finish(c.inner(), &mut NoDepth)
        };
        assert!(done.is_ok_and(|n| n <= len as u64), "{done:?}");
        c.check_guards();
        d.check_guards();
        let (rc, rd) = render::<S, C, T>(frame, a, b, use_depth);
        assert!(c.get() == &rc[..], "deferred strip {s} colour differs");
        if use_depth {
            assert!(d.get() == &rd[..], "deferred strip {s} depth differs");
        }
        debug(|| format!("arm: deferred clear of strip {s}"));
    }

    // Another frame's bins: a mismatch unless they look the same.
    other_frame_bins::<S, C>(input, frame, r);

    // Wrong calls are errors that write nothing.
    for bad in input.bad.iter().take(4) {
        let (by0, by1) = (bad.y0 as u32, bad.y1 as u32);
        let rows = by1.saturating_sub(by0) as usize;
        let expect = w.saturating_mul(rows).min(PIXEL_BUDGET);
        let lc = (expect as i64 + bad.dc as i64).clamp(0, PIXEL_BUDGET as i64) as usize;
        let ld = (expect as i64 + bad.dd as i64).clamp(0, PIXEL_BUDGET as i64) as usize;
        let mut c = Guarded::new(lc, C::CLEAR, C::GUARD);
        let mut d = Guarded::new(ld, T::FAR, T::GUARD);
        let valid = by0 < by1 && by1 <= h && lc == w * rows && (!use_depth || ld == w * rows);
        let res = if use_depth {
            frame.render_rows(by0, by1, c.inner(), d.inner())
        } else {
            frame.render_rows(by0, by1, c.inner(), &mut NoDepth)
        };
        assert_eq!(
            res.is_ok(),
            valid,
            "render_rows({by0}, {by1}) with {lc}/{ld}: {res:?}"
        );
        c.check_guards();
        d.check_guards();
        if !valid {
            assert!(
                c.get().iter().all(|&p| p == C::CLEAR),
                "an error wrote colour"
            );
            assert!(d.get().iter().all(|&p| p == T::FAR), "an error wrote depth");
        }
    }
    check_formats::<S, T>(input, frame, use_depth);
}

/// `render_strip` with the bins of another frame: `BinsMismatch` (and
/// nothing written) unless size, strip height and triangle count match.
fn other_frame_bins<const S: u32, C: PixelWord>(input: &FrameInput, frame: &Frame<'_, S>, r: u32) {
    let config = *frame.config();
    let n = frame.triangles().len();
    let mut c2 = config;
    let (dw, dh) = (input.past & 3, (input.past >> 2) & 3);
    c2.width = (config.width + dw).min(16384);
    c2.height = (config.height + dh).min(16384);
    let mut st = vec![SetupTriangle::EMPTY; 8];
    let mut other = Frame::<S>::with_subpixel_bits(c2, &mut st).expect("valid");
    if input.past & 16 != 0 {
        let v = |x, y| Vec4::new(x, y, 0.0, 1.0);
        let _ = other.submit_clip_triangle(
            [v(-1.0, -1.0), v(1.0, -1.0), v(0.0, 1.0)],
            [Rgb888::RED; 3],
            0,
        );
        let _ = other.submit_clip_triangle(
            [v(-1.0, -1.0), v(0.0, 1.0), v(1.0, -1.0)],
            [Rgb888::RED; 3],
            1,
        );
    }
    let e = other.bin_entries(r);
    let strips = c2.height.div_ceil(r) as usize;
    let mut offsets = vec![0u32; strips + 1];
    let mut items = vec![0u32; e];
    let Ok(bins) = other.bin(r, &mut offsets, &mut items) else {
        panic!("bin of the other frame")
    };
    let s = 0;
    let (a, b) = bins.rows(s);
    let len = config.width as usize * (b - a) as usize;
    if len > PIXEL_BUDGET {
        return;
    }
    let same =
        c2.width == config.width && c2.height == config.height && other.triangles().len() == n;
    let mut col = Guarded::new(len, C::CLEAR, C::GUARD);
    let res = frame.render_strip(&bins, s, col.inner(), &mut NoDepth);
    col.check_guards();
    if same {
        assert!(res.is_ok(), "{res:?}");
    } else {
        assert_eq!(res.map(|_| ()), Err(Error::BinsMismatch));
        debug(|| "arm: other bins mismatch".into());
        assert!(
            col.get().iter().all(|&p| p == C::CLEAR),
            "an error wrote colour"
        );
    }
}

/// Every pixel format agrees with `Rgb888` through `From`, and depth is
/// the same for all.
fn check_formats<const S: u32, T: DepthGuard>(
    input: &FrameInput,
    frame: &Frame<'_, S>,
    use_depth: bool,
) {
    let (y0, y1) = rows(input, frame.config());
    let c8 = Rgb888::new(1, 2, 3);
    let (rgb, d888, n888) = render_with::<S, Rgb888, T>(frame, y0, y1, use_depth, c8);
    let (p565, d565, n565) =
        render_with::<S, Rgb565, T>(frame, y0, y1, use_depth, Rgb565::from(c8));
    let (g8, dg8, ng8) = render_with::<S, Gray8, T>(frame, y0, y1, use_depth, Gray8::from(c8));
    let (bin, dbin, nbin) =
        render_with::<S, BinaryColor, T>(frame, y0, y1, use_depth, BinaryColor::from(c8));
    assert!(
        d888 == d565 && d888 == dg8 && d888 == dbin,
        "depth depends on the format"
    );
    assert!(
        n888 == n565 && n888 == ng8 && n888 == nbin,
        "pixels written depend on the format"
    );
    for (i, &p) in rgb.iter().enumerate() {
        assert_eq!(p565[i], Rgb565::from(p), "Rgb565 pixel {i}");
        assert_eq!(g8[i], Gray8::from(p), "Gray8 pixel {i}");
        assert_eq!(bin[i], BinaryColor::from(p), "BinaryColor pixel {i}");
    }
}

fn check_frame<const S: u32>(input: &FrameInput, frame: &Frame<'_, S>) {
    macro_rules! px {
        ($t:ty, $d:expr) => {
            match input.pixel % 5 {
                0 => check_frame_typed::<S, TriangleId, $t>(input, frame, $d),
                1 => check_frame_typed::<S, Rgb888, $t>(input, frame, $d),
                2 => check_frame_typed::<S, Rgb565, $t>(input, frame, $d),
                3 => check_frame_typed::<S, Gray8, $t>(input, frame, $d),
                _ => check_frame_typed::<S, BinaryColor, $t>(input, frame, $d),
            }
        };
    }
    match input.depth_kind % 3 {
        0 => px!(u16, true),
        1 => px!(u32, true),
        _ => px!(u32, false),
    }
}

/// Storage capacity for `n` submitted triangles, as the input asks.
fn capacity<const S: u32>(input: &Input, config: Config, preps: &[Prep], n: usize) -> usize {
    if input.big.as_ref().is_some_and(|b| b.tight_storage()) {
        return Frame::<S>::storage_for(n);
    }
    let v = input.rest.storage as usize;
    match v % 5 {
        0 => (v >> 3) % 80,
        1 => Frame::<S>::storage_for(n),
        2 => 7 * n,
        3 => n,
        _ => {
            // Around the exact need: full at the last piece, or just fits.
            let mut st = vec![SetupTriangle::EMPTY; 7 * n];
            let mut f = Frame::<S>::with_subpixel_bits(config, &mut st).expect("valid");
            let mut most = 0;
            for p in preps {
                match p {
                    Prep::Clear => f.clear(),
                    _ => {
                        let _ = submit_prep::<S, _>(&mut f, p, Way::Main);
                    }
                }
                most = most.max(f.triangles().len());
            }
            most.saturating_sub((v >> 3) % 3)
        }
    }
}

fn valid_size(c: &Config) -> bool {
    (1..=16384).contains(&c.width) && (1..=16384).contains(&c.height)
}

fn run_frame_s<const S: u32>(input: &Input) {
    let config = frame_config(input);
    // The default precision's constructors agree with the generic ones.
    let mut st = [SetupTriangle::EMPTY; 1];
    let f8 = Frame::new(config, &mut st).map(|f| *f.config());
    assert_eq!(f8.is_ok(), valid_size(&config), "Frame::new: {f8:?}");
    let mut c = [Rgb888::BLACK; 4];
    let mut nd = NoDepth;
    let r = StripRenderer::new(config, 0, 1, &mut c, &mut nd).map(|s| *s.config());
    let want_ok = valid_size(&config) && config.width == 4;
    assert_eq!(r.is_ok(), want_ok, "StripRenderer::new: {r:?}");
    if !valid_size(&config) {
        let mut st = [SetupTriangle::EMPTY; 2];
        let e = Frame::<S>::with_subpixel_bits(config, &mut st).map(|_| ());
        assert_eq!(
            e,
            Err(Error::InvalidFrameSize {
                width: config.width,
                height: config.height
            })
        );
        return;
    }
    let preps = prepare::<S>(input, config);
    let n: usize = preps.iter().map(Prep::triangles).sum();
    let cap = capacity::<S>(input, config, &preps, n);
    let mut storage = vec![SetupTriangle::EMPTY; cap];
    let mut twin_storage = vec![SetupTriangle::EMPTY; cap];
    let mut nob_storage = vec![SetupTriangle::EMPTY; cap];
    let mut max_len = 0;
    {
        let mut frame = Frame::<S>::with_subpixel_bits(config, &mut storage).expect("valid");
        assert_eq!(frame.capacity(), cap);
        assert_eq!(frame.config(), &config);
        let mut twin = Frame::<S>::with_subpixel_bits(config, &mut twin_storage).expect("valid");
        let mut nob = Frame::<S>::with_subpixel_bits(config, &mut nob_storage).expect("valid");
        for p in &preps {
            let a = submit_frame(&mut frame, p, Way::Main);
            max_len = max_len.max(frame.triangles().len());
            let b = submit_frame(&mut twin, p, Way::Twin);
            assert_eq!(a, b, "the twin path disagrees on the result ({p:?})");
            assert_eq!(
                frame.stats(),
                twin.stats(),
                "the twin path counts differently"
            );
            assert!(
                frame.triangles() == twin.triangles(),
                "the twin path stores different triangles"
            );
            // Object culling is conservative: without the sphere, the same
            // triangles are stored.
            let c = submit_frame(&mut nob, p, Way::Unbounded);
            assert_eq!(a, c, "the bounding sphere changed the result");
            assert!(
                frame.triangles() == nob.triangles(),
                "the bounding sphere culled a visible triangle"
            );
            let (fs, ns) = (frame.stats(), nob.stats());
            assert_eq!((fs.submitted, fs.stored), (ns.submitted, ns.stored));
        }
        check_triangles(frame.triangles(), config.height);
        debug(|| {
            format!(
                "frame {}x{} S={S} cap {cap}: {} ops, {} stored, {:?}",
                config.width,
                config.height,
                preps.len(),
                frame.triangles().len(),
                frame.stats()
            )
        });

        // A cleared frame is a fresh one.
        if let Some(last) = preps.iter().rposition(|p| matches!(p, Prep::Clear)) {
            let mut st = vec![SetupTriangle::EMPTY; cap];
            let mut fresh = Frame::<S>::with_subpixel_bits(config, &mut st).expect("valid");
            for p in &preps[last + 1..] {
                let _ = submit_frame(&mut fresh, p, Way::Main);
            }
            assert!(
                fresh.triangles() == frame.triangles(),
                "clear is not a fresh frame"
            );
            assert_eq!(fresh.stats(), frame.stats(), "clear is not a fresh frame");
        }

        check_frame(&input.rest, &frame);

        // Bins made before more triangles were stored are refused.
        let r = 1 + input.rest.window.1 as u32 % config.height;
        let entries = twin.bin_entries(r);
        if entries <= 1 << 20 {
            let strips = config.height.div_ceil(r) as usize;
            let mut offsets = vec![0u32; strips + 1];
            let mut items = vec![0u32; entries];
            let bins = twin.bin(r, &mut offsets, &mut items).expect("bin");
            let len0 = twin.triangles().len();
            let v = |x, y| Vec4::new(x, y, 0.5, 1.0);
            let _ = twin.submit_clip_triangle(
                [v(-1.0, -1.0), v(1.0, -1.0), v(0.0, 1.0)],
                [Rgb888::GREEN; 3],
                7,
            );
            let _ = twin.submit_clip_triangle(
                [v(-1.0, -1.0), v(0.0, 1.0), v(1.0, -1.0)],
                [Rgb888::GREEN; 3],
                8,
            );
            let (a, b) = bins.rows(0);
            let len = config.width as usize * (b - a) as usize;
            if len <= PIXEL_BUDGET {
                let mut c = Guarded::new(len, TriangleId(0), TriangleId(9));
                let res = twin.render_strip(&bins, 0, c.inner(), &mut NoDepth);
                c.check_guards();
                if twin.triangles().len() != len0 {
                    assert_eq!(res.map(|_| ()), Err(Error::BinsMismatch));
                    debug(|| "arm: stale bins mismatch".into());
                    assert!(
                        c.get().iter().all(|&p| p == TriangleId(0)),
                        "an error wrote"
                    );
                } else {
                    assert!(res.is_ok(), "{res:?}");
                }
            }
        }
    }
    // No failed submission wrote a storage slot: slots never reached by
    // a successful one are untouched.
    assert!(
        storage[max_len..]
            .iter()
            .all(|t| *t == SetupTriangle::EMPTY),
        "a storage slot past the stored triangles was written"
    );
}

/// The `frame` target: setup, strip splits, bins, wrong calls, pixel
/// formats, alternative submission paths, at S = 4 and 8.
pub fn run_frame(input: &Input) {
    if input.rest.params.s8 {
        run_frame_s::<8>(input)
    } else {
        run_frame_s::<4>(input)
    }
}

// ---------------------------------------------------------------------
// The strip-renderer target.

/// Submits to a strip renderer, checking the bookkeeping.
fn submit_strip<const S: u32, C: PixelWord, D: microraster::DepthBuffer + ?Sized>(
    sr: &mut StripRenderer<'_, C, D, S>,
    p: &Prep,
    way: Way,
) {
    if let (Prep::Mesh(m, _), Way::Twin) = (p, way) {
        if !m.positions.is_empty() {
            let (s0, r0) = (sr.stats(), sr.render_stats());
            let mut short = vec![ProcessedVertex::EMPTY; m.positions.len() - 1];
            let r = sr.submit_mesh_cached(&m.mesh(), &m.mvp, m.first_id, &mut short);
            assert!(matches!(r, Err(Error::VertexCacheSize { .. })), "{r:?}");
            assert_eq!(
                (sr.stats(), sr.render_stats()),
                (s0, r0),
                "an error counted"
            );
        }
    }
    let s0 = sr.stats();
    let r = submit_prep::<S, _>(sr, p, way);
    assert_eq!(r, Ok(()), "a strip renderer refused a submission");
    check_accounting(&s0, &sr.stats(), p.triangles() as u64);
}

fn strip_typed<const S: u32, C: PixelWord, T: DepthGuard>(
    input: &Input,
    frame: &Frame<'_, S>,
    preps: &[Prep],
    use_depth: bool,
) {
    let config = *frame.config();
    let w = config.width as usize;
    let (y0, y1) = rows(&input.rest, &config);
    let (want_c, want_d) = render::<S, C, T>(frame, y0, y1, use_depth);
    // The vertex stage of a strip renderer is the frame's.
    for p in preps {
        if let Prep::Processed { mesh, .. } = p {
            let mut a = vec![ProcessedVertex::EMPTY; mesh.positions.len()];
            let mut b = a.clone();
            frame.process_vertices(&mesh.mvp, &mesh.positions, &mut a);
            let mut cc = vec![C::CLEAR; w];
            let mut nd = NoDepth;
            let sr =
                StripRenderer::<C, NoDepth, S>::with_subpixel_bits(config, 0, 1, &mut cc, &mut nd)
                    .expect("one row");
            sr.process_vertices(&mesh.mvp, &mesh.positions, &mut b);
            assert_eq!(
                format!("{a:?}"),
                format!("{b:?}"),
                "process_vertices differs"
            );
        }
    }
    // Whole window, then the input's split, each through strip renderers
    // (the twin path for the split).
    let mut split = vec![(y0, y1, Way::Main)];
    let mut y = y0;
    let mut k = 0;
    while y < y1 && !input.rest.splits.is_empty() {
        let step = input
            .rest
            .splits
            .get(k)
            .map_or(y1 - y, |&s| s.max(1) as u32);
        let e = (y + step).min(y1);
        split.push((y, e, Way::Twin));
        y = e;
        k += 1;
    }
    let fstats = frame.stats();
    for (i, &(a, b, way)) in split.iter().enumerate() {
        let len = w * (b - a) as usize;
        let off = (a - y0) as usize * w;
        let mut c = Guarded::new(len, C::CLEAR, C::GUARD);
        let mut d = Guarded::new(len, T::FAR, T::GUARD);
        let mut no_depth = NoDepth;
        let stats = {
            let (cs, ds) = (&mut c.v[GUARD..GUARD + len], &mut d.v[GUARD..GUARD + len]);
            // Wrong sizes are refused.
            if i == 0 && len > 0 {
                let short = len - 1;
                if use_depth {
                    let r = StripRenderer::<C, [T], S>::with_subpixel_bits(
                        config,
                        a,
                        b,
                        &mut cs[..short],
                        ds,
                    );
                    assert!(matches!(r, Err(Error::ColorBufferSize { .. })));
                    let r = StripRenderer::<C, [T], S>::with_subpixel_bits(
                        config,
                        a,
                        b,
                        cs,
                        &mut ds[..short],
                    );
                    assert!(matches!(r, Err(Error::DepthBufferSize { .. })));
                }
                let r = StripRenderer::<C, NoDepth, S>::with_subpixel_bits(
                    config,
                    b,
                    a,
                    &mut cs[..0],
                    &mut no_depth,
                );
                assert!(matches!(r, Err(Error::InvalidRows { .. })));
            }
            let run = |sr: &mut dyn FnMut(&Prep)| {
                for p in preps {
                    sr(p)
                }
            };
            if use_depth {
                let mut sr = StripRenderer::<C, [T], S>::with_subpixel_bits(config, a, b, cs, ds)
                    .expect("strip renderer");
                run(&mut |p| submit_strip(&mut sr, p, way));
                assert_eq!(sr.config(), &config);
                (sr.stats(), sr.render_stats())
            } else {
                let mut sr = StripRenderer::<C, NoDepth, S>::with_subpixel_bits(
                    config,
                    a,
                    b,
                    cs,
                    &mut no_depth,
                )
                .expect("strip renderer");
                run(&mut |p| submit_strip(&mut sr, p, way));
                (sr.stats(), sr.render_stats())
            }
        };
        c.check_guards();
        d.check_guards();
        let (st, rs) = stats;
        assert_eq!(
            st.submitted, fstats.submitted,
            "StripRenderer counts differently"
        );
        assert!(st.stored <= fstats.stored, "{st:?} vs {fstats:?}");
        if a == 0 && b == config.height {
            assert_eq!(st.outside_strip, 0, "the whole frame skipped a triangle");
            assert_eq!(
                st, fstats,
                "a whole-frame strip renderer counts differently"
            );
        }
        let (_, _, pw) = render_with::<S, C, T>(frame, a, b, use_depth, C::CLEAR);
        assert_eq!(
            rs.pixels_written, pw,
            "pixels written differ from the frame"
        );
        assert!(
            c.get() == &want_c[off..off + len],
            "StripRenderer {a}..{b} colour differs from Frame"
        );
        if use_depth {
            assert!(
                d.get() == &want_d[off..off + len],
                "StripRenderer {a}..{b} depth differs from Frame"
            );
        }
    }
}

fn run_strip_s<const S: u32>(input: &Input) {
    let config = frame_config(input);
    if !valid_size(&config) {
        let mut c = [TriangleId(0); 4];
        let mut nd = NoDepth;
        let r = StripRenderer::<_, NoDepth, S>::with_subpixel_bits(config, 0, 1, &mut c, &mut nd);
        assert!(matches!(r, Err(Error::InvalidFrameSize { .. })));
        if let Some(d) = &input.rest.drawer {
            drawer::invalid_size::<S>(d, config);
        }
        return;
    }
    let mut preps = prepare::<S>(input, config);
    // A strip renderer has no clear: it gets what follows the last one.
    if let Some(last) = preps.iter().rposition(|p| matches!(p, Prep::Clear)) {
        preps.drain(..=last);
    }
    let n: usize = preps.iter().map(Prep::triangles).sum();
    let mut storage = vec![SetupTriangle::EMPTY; 7 * n];
    let mut frame = Frame::<S>::with_subpixel_bits(config, &mut storage).expect("valid size");
    for p in &preps {
        submit_frame(&mut frame, p, Way::Main).expect("storage for everything");
    }
    debug(|| {
        format!(
            "strip {}x{} S={S} rows {:?}: {} ops, {} stored, {:?}",
            config.width,
            config.height,
            rows(&input.rest, &config),
            preps.len(),
            frame.triangles().len(),
            frame.stats()
        )
    });
    macro_rules! px {
        ($t:ty, $d:expr) => {
            match input.rest.pixel % 5 {
                0 => strip_typed::<S, TriangleId, $t>(input, &frame, &preps, $d),
                1 => strip_typed::<S, Rgb888, $t>(input, &frame, &preps, $d),
                2 => strip_typed::<S, Rgb565, $t>(input, &frame, &preps, $d),
                3 => strip_typed::<S, Gray8, $t>(input, &frame, &preps, $d),
                _ => strip_typed::<S, BinaryColor, $t>(input, &frame, &preps, $d),
            }
        };
    }
    match input.rest.depth_kind % 3 {
        0 => px!(u16, true),
        1 => px!(u32, true),
        _ => px!(u32, false),
    }
    if let Some(d) = &input.rest.drawer {
        drawer::run::<S>(d, input.rest.depth_kind, &frame, &preps);
    }
}

/// The `strip_renderer` target: `StripRenderer` (whole window and any
/// split) against `Frame::render_rows`, and `StripDrawer` in both modes,
/// at S = 4 and 8.
pub fn run_strip_renderer(input: &Input) {
    if input.rest.params.s8 {
        run_strip_s::<8>(input)
    } else {
        run_strip_s::<4>(input)
    }
}
