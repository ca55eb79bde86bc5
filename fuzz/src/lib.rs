//! Fuzz inputs and checks for microraster, shared by the targets in
//! `fuzz_targets/`.
//!
//! Design note: each target turns the fuzzer's bytes into a structured
//! input ([`FrameInput`]: frame settings, setup storage size, a list of
//! clip-space triangles and meshes with arbitrary matrices, a row window,
//! ways to split it, and deliberately wrong buffers) and runs it through
//! the public API at both subpixel precisions. Floats are drawn from a mix
//! that hits the edge cases often: raw bit patterns (NaN payloads,
//! infinities, subnormals), a table of specials (`±1e38`, `f32::MAX`,
//! guard-band limits, `30000`, `1e5`, ...), small grid values and wide
//! ranges. Besides "no panic" (the fuzz profile has overflow checks and
//! debug assertions on), the checks are the core's documented promises:
//!
//! - every submitted triangle is stored or counted in exactly one culled /
//!   rejected counter, and `StorageFull` stores and counts nothing;
//! - stored triangles have their rows inside the frame;
//! - any split of a row window into strips gives the same pixels as the
//!   window rendered at once, and nothing outside the slices given is
//!   touched (guard regions around every buffer);
//! - a wrong row range or buffer size is an error that writes nothing;
//! - `draw_mesh_cached` stores exactly what `draw_mesh` stores;
//! - binned strips (`Frame::bin` + `render_strip`) equal `render_rows`;
//! - `StripRenderer` draws exactly what `Frame::render_rows` draws.

#![forbid(unsafe_code)]

use libfuzzer_sys::arbitrary::{self, Arbitrary, Unstructured};
use microraster::math::{FloatFns, Libm, Micromath};
use microraster::pixelcolor::{Rgb888, RgbColor};
use microraster::{
    BoundingSphere, ClipVertex, Config, CullMode, DepthBuffer, DepthFunc, Error, Frame, FrontFace,
    Mat4, Mesh, MeshColors, NoDepth, Pixel, ProcessedVertex, SetupTriangle, Stats, StripRenderer,
    TriangleId, Vec3, Vec4,
};

/// At most this many pixels are rendered per buffer, to keep an execution
/// fast; larger windows are cut down to fit.
pub const PIXEL_BUDGET: usize = 1 << 16;

/// Largest number of triangles or meshes submitted per input.
pub const MAX_OPS: usize = 24;

/// Also check that the depth written does not depend on the pixel type
/// (`TriangleId` against `Rgb888`), i.e. on whether colour is shaded (a
/// bug this target found: see `std-host/tests/fuzz_regressions.rs`,
/// `depth_does_not_depend_on_the_pixel_type`).
pub const STRICT_DEPTH: bool = true;

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
}

impl Tri {
    /// As the core's vertices.
    pub fn vertices(&self) -> [ClipVertex; 3] {
        [0, 1, 2].map(|k| ClipVertex {
            pos: Vec4::new(
                self.pos[k][0].0,
                self.pos[k][1].0,
                self.pos[k][2].0,
                self.pos[k][3].0,
            ),
            color: self.color[k].map(|c| c as f32),
        })
    }
}

/// A model-view-projection matrix: raw entries, or built by the core's
/// constructors from arbitrary camera values with either float backend.
#[derive(Arbitrary, Clone, Copy, Debug)]
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
        /// Build with micromath (else libm).
        micromath: bool,
    },
}

fn camera<M: FloatFns>(
    fov: f32,
    aspect: f32,
    near: f32,
    far: f32,
    e: Vec3,
    t: Vec3,
    a: [f32; 2],
) -> Mat4 {
    Mat4::perspective_with::<M>(fov, aspect, near, far)
        * Mat4::look_at_with::<M>(e, t, Vec3::new(0.0, 1.0, 0.0))
        * Mat4::rotation_y_with::<M>(a[0])
        * Mat4::rotation_x_with::<M>(a[1])
}

impl MatIn {
    /// The matrix.
    pub fn matrix(&self) -> Mat4 {
        match *self {
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
                micromath,
            } => {
                let v = |a: [F; 3]| Vec3::new(a[0].0, a[1].0, a[2].0);
                let a = [angles[0].0, angles[1].0];
                if micromath {
                    camera::<Micromath>(fov.0, aspect.0, near.0, far.0, v(eye), v(target), a)
                } else {
                    camera::<Libm>(fov.0, aspect.0, near.0, far.0, v(eye), v(target), a)
                }
            }
        }
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
}

/// A mesh in the core's types.
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

impl OwnedMesh {
    /// Converts the fuzz input.
    pub fn new(m: &MeshIn) -> Self {
        let positions: Vec<Vec3> = m
            .positions
            .iter()
            .take(48)
            .map(|p| Vec3::new(p[0].0, p[1].0, p[2].0))
            .collect();
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
        let colors: Vec<Rgb888> = if m.colors.is_empty() {
            vec![Rgb888::WHITE; n]
        } else {
            (0..n)
                .map(|i| {
                    let c = m.colors[i % m.colors.len()];
                    Rgb888::new(c[0], c[1], c[2])
                })
                .collect()
        };
        OwnedMesh {
            bounds: if m.bounds {
                BoundingSphere::from_points(&positions)
            } else {
                None
            },
            positions,
            indices,
            colors,
            mode,
            mvp: m.mvp.matrix(),
            first_id: m.first_id,
        }
    }

    /// As the core's mesh.
    pub fn mesh(&self) -> Mesh<'_> {
        Mesh {
            positions: &self.positions,
            indices: &self.indices,
            colors: match self.mode {
                0 => MeshColors::Uniform(self.colors.first().copied().unwrap_or(Rgb888::RED)),
                1 => MeshColors::PerTriangle(&self.colors),
                _ => MeshColors::PerVertex(&self.colors),
            },
            bounds: self.bounds,
        }
    }
}

/// One submission.
#[derive(Arbitrary, Clone, Debug)]
pub enum Op {
    /// A clip-space triangle.
    Tri(Tri),
    /// A mesh.
    Mesh(MeshIn),
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

/// The whole input of the `frame` and `strip_renderer` targets.
#[derive(Arbitrary, Clone, Debug)]
pub struct FrameInput {
    /// Frame settings.
    pub params: FrameParams,
    /// Setup storage capacity (`% 80`).
    pub storage: u8,
    /// Submissions.
    pub ops: Vec<Op>,
    /// Row window to render: first row and row count (cut to the frame
    /// and the pixel budget).
    pub window: (u16, u16),
    /// Strip heights splitting the window (0 stands for 1).
    pub splits: Vec<u8>,
    /// 0: u16, 1: u32, 2: no depth buffer.
    pub depth_kind: u8,
    /// Triangle ids (else Rgb888).
    pub ids: bool,
    /// Rows per strip for `Frame::bin`.
    pub bin_rows: u16,
    /// Wrong calls.
    pub bad: Vec<BadCall>,
}

impl FrameInput {
    /// The row window `y0..y1` actually rendered, within the frame and the
    /// pixel budget.
    pub fn rows(&self) -> (u32, u32) {
        let (w, h) = (self.params.width.0.max(1), self.params.height.0.max(1));
        let y0 = self.window.0 as u32 % h;
        let max_rows = ((PIXEL_BUDGET / w as usize).max(1) as u32).min(h - y0);
        let n = 1 + self.window.1 as u32 % max_rows;
        (y0, y0 + n)
    }
}

const GUARD: usize = 16;

/// A buffer with guard regions on both sides, filled with `fill` and the
/// guards with `guard`.
struct Guarded<T> {
    v: Vec<T>,
    len: usize,
    guard: T,
}

impl<T: Copy + PartialEq + core::fmt::Debug> Guarded<T> {
    fn new(len: usize, fill: T, guard: T) -> Self {
        let mut v = vec![guard; len + 2 * GUARD];
        v[GUARD..GUARD + len].fill(fill);
        Guarded { v, len, guard }
    }
    fn inner(&mut self) -> &mut [T] {
        &mut self.v[GUARD..GUARD + self.len]
    }
    fn get(&self) -> &[T] {
        &self.v[GUARD..GUARD + self.len]
    }
    fn check_guards(&self) {
        assert!(
            self.v[..GUARD].iter().all(|&g| g == self.guard)
                && self.v[GUARD + self.len..].iter().all(|&g| g == self.guard),
            "a guard region was written"
        );
    }
}

/// The depth word types.
pub trait DepthWord: Copy + PartialEq + core::fmt::Debug + 'static {
    /// The far plane (clear value).
    const FAR: Self;
    /// A guard value.
    const GUARD: Self;
}
impl DepthWord for u16 {
    const FAR: Self = u16::MAX;
    const GUARD: Self = 0x5a5a;
}
impl DepthWord for u32 {
    const FAR: Self = u32::MAX;
    const GUARD: Self = 0x5a5a_5a5a;
}

/// The pixel types.
pub trait PixelWord: Pixel + PartialEq + core::fmt::Debug + 'static {
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

fn stats_sum_dropped(s: &Stats) -> u32 {
    s.culled_object
        + s.culled_frustum
        + s.culled_backface
        + s.culled_degenerate
        + s.rejected_nonfinite
        + s.rejected_index
}

/// `b - a` for the counters a frame keeps (a counter that went down
/// overflows: a finding).
fn diff(a: &Stats, b: &Stats) -> Stats {
    let mut d = *b;
    d.submitted = b.submitted - a.submitted;
    d.culled_object = b.culled_object - a.culled_object;
    d.culled_frustum = b.culled_frustum - a.culled_frustum;
    d.culled_backface = b.culled_backface - a.culled_backface;
    d.culled_degenerate = b.culled_degenerate - a.culled_degenerate;
    d.rejected_nonfinite = b.rejected_nonfinite - a.rejected_nonfinite;
    d.rejected_index = b.rejected_index - a.rejected_index;
    d.clipped = b.clipped - a.clipped;
    d.stored = b.stored - a.stored;
    d
}

/// Checks the counters one submission of `n` triangles added.
fn check_accounting(before: &Stats, after: &Stats, n: u32) {
    let d = diff(before, after);
    assert_eq!(d.submitted, n, "{d:?}");
    let dropped = stats_sum_dropped(&d);
    assert!(dropped <= n, "{d:?}");
    let kept = n - dropped;
    // Every kept triangle stores 1..=7 pieces.
    assert!(d.stored >= kept && d.stored <= 7 * kept, "{d:?}");
    assert!(d.clipped <= n, "{d:?}");
}

/// Submits one op to a frame, checking the bookkeeping. `cached` sends
/// meshes through `draw_mesh_cached`.
fn submit<const S: u32>(frame: &mut Frame<'_, S>, op: &Op, cached: bool) -> Result<(), Error> {
    let (len0, stats0) = (frame.triangles().len(), frame.stats());
    let (r, n) = match op {
        Op::Tri(t) => (frame.push_triangle(t.vertices(), t.id), 1),
        Op::Mesh(m) => {
            let m = OwnedMesh::new(m);
            let n = m.indices.len() as u32;
            let r = if cached {
                let mut cache = vec![ProcessedVertex::EMPTY; m.positions.len()];
                frame.draw_mesh_cached(&m.mesh(), &m.mvp, m.first_id, &mut cache)
            } else {
                frame.draw_mesh(&m.mesh(), &m.mvp, m.first_id)
            };
            (r, n)
        }
    };
    match r {
        Ok(()) => {
            check_accounting(&stats0, &frame.stats(), n);
            assert_eq!(
                frame.triangles().len() - len0,
                diff(&stats0, &frame.stats()).stored as usize
            );
        }
        Err(Error::StorageFull { .. }) => {
            assert_eq!(
                frame.triangles().len(),
                len0,
                "StorageFull stored something"
            );
            assert_eq!(frame.stats(), stats0, "StorageFull counted something");
        }
        Err(e) => panic!("unexpected error from a submission: {e:?}"),
    }
    r
}

fn check_triangles(tris: &[SetupTriangle], height: u32) {
    for t in tris {
        let (a, b) = t.rows();
        assert!(a <= b && (b as u32) < height, "rows {a}..={b} of {height}");
        for (x, y) in t.vertices() {
            assert!(x.abs() <= 1 << 28 && y.abs() <= 1 << 28, "vertex {x},{y}");
        }
    }
}

/// Renders rows `y0..y1` into fresh guarded buffers; returns colour and
/// depth (empty without a depth buffer).
fn render<const S: u32, C: PixelWord, T: DepthWord>(
    frame: &Frame<'_, S>,
    y0: u32,
    y1: u32,
    use_depth: bool,
) -> (Vec<C>, Vec<T>)
where
    [T]: DepthBuffer,
{
    let len = frame.config().width as usize * (y1 - y0) as usize;
    let mut c = Guarded::new(len, C::CLEAR, C::GUARD);
    let mut d = Guarded::new(len, T::FAR, T::GUARD);
    let r = if use_depth {
        frame.render_rows(y0, y1, c.inner(), d.inner())
    } else {
        frame.render_rows(y0, y1, c.inner(), &mut NoDepth)
    };
    let stats = r.unwrap_or_else(|e| panic!("render_rows({y0}, {y1}): {e:?}"));
    c.check_guards();
    d.check_guards();
    // Pixels that changed were written (a write may leave a pixel as it
    // was, so this is a bound, not an equality).
    let changed = c.get().iter().filter(|&&p| p != C::CLEAR).count() as u64;
    assert!(
        changed <= stats.pixels_written,
        "{changed} changed, {stats:?}"
    );
    (
        c.get().to_vec(),
        if use_depth {
            d.get().to_vec()
        } else {
            Vec::new()
        },
    )
}

fn check_frame_typed<const S: u32, C: PixelWord, T: DepthWord>(
    input: &FrameInput,
    frame: &Frame<'_, S>,
    use_depth: bool,
) where
    [T]: DepthBuffer,
{
    let config = *frame.config();
    let w = config.width as usize;
    let (y0, y1) = input.rows();
    let (whole_c, whole_d) = render::<S, C, T>(frame, y0, y1, use_depth);
    if STRICT_DEPTH && use_depth {
        let (_, ids_d) = render::<S, TriangleId, T>(frame, y0, y1, true);
        let (_, rgb_d) = render::<S, Rgb888, T>(frame, y0, y1, true);
        assert!(
            ids_d == rgb_d,
            "depth differs between TriangleId and Rgb888 renders"
        );
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

    // Binned strips equal render_rows.
    let r = (input.bin_rows as u32 % config.height).max(1);
    let strips = config.height.div_ceil(r) as usize;
    let entries = frame.bin_entries(r);
    let mut offsets = vec![0u32; strips + 1];
    let mut items = vec![0u32; entries];
    if entries > 0 {
        let mut short = vec![0u32; entries - 1];
        assert!(frame.bin(r, &mut offsets, &mut short).is_err());
    }
    assert!(frame.bin(r, &mut offsets[..strips], &mut items).is_err());
    let bins = frame.bin(r, &mut offsets, &mut items).expect("bin");
    assert_eq!(bins.strips() as usize, strips);
    for s in y0 / r..=(y1 - 1) / r {
        let (a, b) = bins.rows(s, config.height);
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

    // Wrong calls are errors that write nothing.
    for bad in input.bad.iter().take(4) {
        let (by0, by1) = (bad.y0 as u32, bad.y1 as u32);
        let rows = by1.saturating_sub(by0) as usize;
        let expect = w.saturating_mul(rows).min(PIXEL_BUDGET);
        let lc = (expect as i64 + bad.dc as i64).clamp(0, PIXEL_BUDGET as i64) as usize;
        let ld = (expect as i64 + bad.dd as i64).clamp(0, PIXEL_BUDGET as i64) as usize;
        let mut c = Guarded::new(lc, C::CLEAR, C::GUARD);
        let mut d = Guarded::new(ld, T::FAR, T::GUARD);
        let valid =
            by0 < by1 && by1 <= config.height && lc == w * rows && (!use_depth || ld == w * rows);
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
}

fn check_frame<const S: u32>(input: &FrameInput, frame: &Frame<'_, S>) {
    match (input.depth_kind % 3, input.ids) {
        (0, true) => check_frame_typed::<S, TriangleId, u16>(input, frame, true),
        (0, false) => check_frame_typed::<S, Rgb888, u16>(input, frame, true),
        (1, true) => check_frame_typed::<S, TriangleId, u32>(input, frame, true),
        (1, false) => check_frame_typed::<S, Rgb888, u32>(input, frame, true),
        (_, true) => check_frame_typed::<S, TriangleId, u32>(input, frame, false),
        (_, false) => check_frame_typed::<S, Rgb888, u32>(input, frame, false),
    }
}

fn run_frame_s<const S: u32>(input: &FrameInput) {
    let config = input.params.config();
    let cap = input.storage as usize % 80;
    let mut storage = vec![SetupTriangle::EMPTY; cap];
    let mut twin_storage = vec![SetupTriangle::EMPTY; cap];
    let frame = Frame::<S>::new(config, &mut storage);
    let valid_size = (1..=16384).contains(&config.width) && (1..=16384).contains(&config.height);
    let mut frame = match frame {
        Ok(f) => {
            assert!(valid_size);
            f
        }
        Err(e) => {
            assert!(!valid_size, "{e:?}");
            assert!(matches!(e, Error::InvalidFrameSize { .. }));
            return;
        }
    };
    let mut twin = Frame::<S>::new(config, &mut twin_storage).expect("same config");
    for op in input.ops.iter().take(MAX_OPS) {
        let a = submit(&mut frame, op, false);
        let b = submit(&mut twin, op, true);
        assert_eq!(
            a, b,
            "draw_mesh and draw_mesh_cached disagree on the result"
        );
        assert_eq!(
            frame.stats(),
            twin.stats(),
            "draw_mesh_cached counts differently"
        );
        assert_eq!(
            format!("{:?}", frame.triangles()),
            format!("{:?}", twin.triangles()),
            "draw_mesh_cached stores different triangles"
        );
    }
    check_triangles(frame.triangles(), config.height);
    check_frame(input, &frame);
}

/// The `frame` target: setup, strips, bins, wrong calls, at S = 4 and 8.
pub fn run_frame(input: &FrameInput) {
    if input.params.s8 {
        run_frame_s::<8>(input)
    } else {
        run_frame_s::<4>(input)
    }
}

fn strip_typed<const S: u32, C: PixelWord, T: DepthWord>(
    input: &FrameInput,
    frame: &Frame<'_, S>,
    use_depth: bool,
) where
    [T]: DepthBuffer,
{
    let config = *frame.config();
    let (y0, y1) = input.rows();
    let (want_c, want_d) = render::<S, C, T>(frame, y0, y1, use_depth);
    let len = config.width as usize * (y1 - y0) as usize;
    let mut c = Guarded::new(len, C::CLEAR, C::GUARD);
    let mut d = Guarded::new(len, T::FAR, T::GUARD);
    let mut no_depth = NoDepth;
    {
        let (cs, ds) = (&mut c.v[GUARD..GUARD + len], &mut d.v[GUARD..GUARD + len]);
        // Wrong sizes are refused.
        if len > 0 {
            let short = len - 1;
            if use_depth {
                let r = StripRenderer::<C, [T], S>::new(config, y0, y1, &mut cs[..short], ds);
                assert!(r.is_err());
                let r = StripRenderer::<C, [T], S>::new(config, y0, y1, cs, &mut ds[..short]);
                assert!(r.is_err());
            } else {
                assert!(StripRenderer::<C, NoDepth, S>::new(
                    config,
                    y0,
                    y1,
                    &mut cs[..short],
                    &mut no_depth
                )
                .is_err());
            }
        }
        let ops = input.ops.iter().take(MAX_OPS);
        let stats = if use_depth {
            let mut sr =
                StripRenderer::<C, [T], S>::new(config, y0, y1, cs, ds).expect("strip renderer");
            for op in ops {
                submit_strip(&mut sr, op);
            }
            sr.stats()
        } else {
            let mut sr = StripRenderer::<C, NoDepth, S>::new(config, y0, y1, cs, &mut no_depth)
                .expect("strip renderer");
            for op in ops {
                submit_strip(&mut sr, op);
            }
            sr.stats()
        };
        // A strip renderer may skip triangles outside its rows before
        // setup (`outside_strip`), so only the submissions must agree.
        let f = frame.stats();
        assert_eq!(
            stats.submitted, f.submitted,
            "StripRenderer counts differently"
        );
        assert!(stats_sum_dropped(&stats) <= stats.submitted, "{stats:?}");
        assert!(stats.stored <= f.stored, "{stats:?} vs {f:?}");
    }
    c.check_guards();
    d.check_guards();
    assert!(
        c.get() == &want_c[..],
        "StripRenderer colour differs from Frame"
    );
    if use_depth {
        assert!(
            d.get() == &want_d[..],
            "StripRenderer depth differs from Frame"
        );
    }
}

fn submit_strip<C: Pixel, D: DepthBuffer + ?Sized, const S: u32>(
    sr: &mut StripRenderer<'_, C, D, S>,
    op: &Op,
) {
    match op {
        Op::Tri(t) => sr.push_triangle(t.vertices(), t.id),
        Op::Mesh(m) => {
            let m = OwnedMesh::new(m);
            sr.draw_mesh(&m.mesh(), &m.mvp, m.first_id);
        }
    }
}

fn run_strip_s<const S: u32>(input: &FrameInput) {
    let config = input.params.config();
    let valid_size = (1..=16384).contains(&config.width) && (1..=16384).contains(&config.height);
    if !valid_size {
        let mut c = [TriangleId(0); 4];
        assert!(StripRenderer::<_, NoDepth, S>::new(config, 0, 1, &mut c, &mut NoDepth).is_err());
        return;
    }
    // Storage for everything: 7 pieces per triangle at most.
    let n: usize = input
        .ops
        .iter()
        .take(MAX_OPS)
        .map(|op| match op {
            Op::Tri(_) => 1,
            Op::Mesh(m) => m.indices.len().min(96),
        })
        .sum();
    let mut storage = vec![SetupTriangle::EMPTY; 7 * n];
    let mut frame = Frame::<S>::new(config, &mut storage).expect("valid size");
    for op in input.ops.iter().take(MAX_OPS) {
        submit(&mut frame, op, false).expect("storage for everything");
    }
    match (input.depth_kind % 3, input.ids) {
        (0, true) => strip_typed::<S, TriangleId, u16>(input, &frame, true),
        (0, false) => strip_typed::<S, Rgb888, u16>(input, &frame, true),
        (1, true) => strip_typed::<S, TriangleId, u32>(input, &frame, true),
        (1, false) => strip_typed::<S, Rgb888, u32>(input, &frame, true),
        (_, true) => strip_typed::<S, TriangleId, u32>(input, &frame, false),
        (_, false) => strip_typed::<S, Rgb888, u32>(input, &frame, false),
    }
}

/// The `strip_renderer` target: `StripRenderer` against `Frame`, at S = 4
/// and 8.
pub fn run_strip_renderer(input: &FrameInput) {
    if input.params.s8 {
        run_strip_s::<8>(input)
    } else {
        run_strip_s::<4>(input)
    }
}
