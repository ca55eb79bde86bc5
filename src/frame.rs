//! The frame: triangles in, set-up triangles stored, any rows out.
//!
//! Design note: a [`Frame`] owns nothing. It borrows the caller's setup
//! storage (`&mut [SetupTriangle]`), takes triangles (clip-space, or meshes
//! with a matrix) and runs them through the one-way pipeline
//! `transform -> object cull -> outcodes -> clip -> snap/setup -> store`.
//! [`Frame::render_rows`] then draws rows `y0..y1` into colour and depth
//! slices that hold exactly those rows; it takes `&self`, so threads can
//! render disjoint strips of one frame at the same time. Triangles are drawn
//! in submission order in every strip, so the result of any split into
//! strips is the same frame, bit for bit.
//!
//! Errors: a wrong buffer size, a bad row range or full storage returns a
//! typed [`Error`] and writes nothing. Bad triangles are not errors: they
//! are counted in [`Stats`] by the reason they were dropped.

use crate::clip::{clip_triangle, outcode, ClipVertex};
use crate::color::Pixel;
use crate::depth::{DepthBuffer, DepthFunc};
use crate::fixed::{guard_band_ndc, MAX_DIMENSION};
use crate::math::{Mat4, Vec3, Vec4};
use crate::raster::{draw, Strip};
use crate::setup::{setup, Rejected, SetupTriangle};
use embedded_graphics_core::pixelcolor::{Rgb888, RgbColor};

/// Which faces to cull.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum CullMode {
    /// Cull back faces (the default).
    #[default]
    Back,
    /// Cull front faces.
    Front,
    /// Cull nothing.
    None,
}

/// Which winding, in NDC (y up), is a front face.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum FrontFace {
    /// Counter-clockwise is front (the default, as in OpenGL).
    #[default]
    Ccw,
    /// Clockwise is front.
    Cw,
}

/// Per-frame settings.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Config {
    /// Frame width in pixels, `1..=16384`.
    pub width: u32,
    /// Frame height in pixels, `1..=16384`.
    pub height: u32,
    /// Face culling.
    pub cull: CullMode,
    /// Front-face winding.
    pub front_face: FrontFace,
    /// Depth comparison.
    pub depth_func: DepthFunc,
    /// Whether passing fragments write their depth.
    pub depth_write: bool,
}

impl Config {
    /// A `width x height` frame with back-face culling, CCW front faces,
    /// depth test `Less` and depth writes on.
    pub const fn new(width: u32, height: u32) -> Self {
        Config {
            width,
            height,
            cull: CullMode::Back,
            front_face: FrontFace::Ccw,
            depth_func: DepthFunc::Less,
            depth_write: true,
        }
    }
}

/// What went wrong; nothing is written when an error is returned.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Error {
    /// Width or height is 0 or above [`MAX_DIMENSION`].
    InvalidFrameSize {
        /// The width asked for.
        width: u32,
        /// The height asked for.
        height: u32,
    },
    /// The setup storage cannot hold the triangle (or mesh); nothing of it
    /// was stored.
    StorageFull {
        /// The storage's capacity in set-up triangles.
        capacity: usize,
        /// How many more set-up triangles were needed.
        needed: usize,
    },
    /// The row range is empty, reversed or beyond the frame.
    InvalidRows {
        /// First row asked for.
        y0: u32,
        /// One past the last row asked for.
        y1: u32,
        /// The frame height.
        height: u32,
    },
    /// The colour slice does not hold exactly the rows asked for.
    ColorBufferSize {
        /// `width * (y1 - y0)`.
        expected: usize,
        /// The slice length.
        actual: usize,
    },
    /// The depth slice does not hold exactly the rows asked for.
    DepthBufferSize {
        /// `width * (y1 - y0)`.
        expected: usize,
        /// The slice length.
        actual: usize,
    },
}

impl core::fmt::Display for Error {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match *self {
            Error::InvalidFrameSize { width, height } => write!(
                f,
                "invalid frame size {width}x{height} (each side must be 1..={MAX_DIMENSION})"
            ),
            Error::StorageFull { capacity, needed } => write!(
                f,
                "setup storage full: capacity {capacity}, {needed} more needed"
            ),
            Error::InvalidRows { y0, y1, height } => {
                write!(f, "invalid rows {y0}..{y1} for a frame of height {height}")
            }
            Error::ColorBufferSize { expected, actual } => {
                write!(
                    f,
                    "colour buffer holds {actual} pixels, expected {expected}"
                )
            }
            Error::DepthBufferSize { expected, actual } => {
                write!(f, "depth buffer holds {actual} values, expected {expected}")
            }
        }
    }
}

impl core::error::Error for Error {}

/// Per-frame counters. Every submitted triangle is either stored (possibly
/// as several after clipping) or counted in exactly one `culled_*` /
/// `rejected_*` field.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct Stats {
    /// Triangles submitted.
    pub submitted: u32,
    /// Skipped with their whole object by the bounding-sphere test.
    pub culled_object: u32,
    /// All vertices outside one frustum plane, or the box misses the frame.
    pub culled_frustum: u32,
    /// Culled by winding.
    pub culled_backface: u32,
    /// Zero area, or no pixel centre in the bounding box.
    pub culled_degenerate: u32,
    /// A vertex with NaN or infinity, or `w <= 0` where it cannot be clipped.
    pub rejected_nonfinite: u32,
    /// A vertex index out of range.
    pub rejected_index: u32,
    /// Triangles that crossed the near, far or guard-band planes and were
    /// clipped.
    pub clipped: u32,
    /// Set-up triangles stored (what the rasterizer will draw).
    pub stored: u32,
}

impl Stats {
    pub(crate) fn add(&mut self, o: &Stats) {
        self.submitted += o.submitted;
        self.culled_object += o.culled_object;
        self.culled_frustum += o.culled_frustum;
        self.culled_backface += o.culled_backface;
        self.culled_degenerate += o.culled_degenerate;
        self.rejected_nonfinite += o.rejected_nonfinite;
        self.rejected_index += o.rejected_index;
        self.clipped += o.clipped;
        self.stored += o.stored;
    }
}

/// Counters of one [`Frame::render_rows`] call.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct RenderStats {
    /// Pixels written (passed the depth test).
    pub pixels_written: u64,
}

/// A sphere bounding an object in its own coordinates.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct BoundingSphere {
    /// Centre.
    pub center: Vec3,
    /// Radius.
    pub radius: f32,
}

impl BoundingSphere {
    /// A sphere around every point (centre of the bounding box); `None`
    /// for no points or a non-finite coordinate.
    pub fn from_points(points: &[Vec3]) -> Option<BoundingSphere> {
        let first = points.first()?;
        let (mut lo, mut hi) = (*first, *first);
        for p in points {
            if !p.is_finite() {
                return None;
            }
            lo = Vec3::new(lo.x.min(p.x), lo.y.min(p.y), lo.z.min(p.z));
            hi = Vec3::new(hi.x.max(p.x), hi.y.max(p.y), hi.z.max(p.z));
        }
        let center = (lo + hi) * 0.5;
        let mut r2 = 0.0f32;
        for p in points {
            let d = *p - center;
            r2 = r2.max(d.dot(d));
        }
        // A relative margin covers rounding in the distance computation.
        let radius = crate::math::fx::sqrt(r2) * 1.0001 + f32::MIN_POSITIVE;
        Some(BoundingSphere { center, radius })
    }

    /// Whether the sphere lies entirely outside one frustum plane of the
    /// clip-space transform `mvp` (so nothing of the object can be seen).
    pub fn outside_frustum(&self, mvp: &Mat4) -> bool {
        let r3 = mvp.row(3);
        for i in 0..3 {
            let ri = mvp.row(i);
            for sign in [1.0f32, -1.0] {
                // Plane: row3 + sign * row_i (Gribb-Hartmann).
                let a = r3[0] + sign * ri[0];
                let b = r3[1] + sign * ri[1];
                let c = r3[2] + sign * ri[2];
                let d = r3[3] + sign * ri[3];
                let dist = a * self.center.x + b * self.center.y + c * self.center.z + d;
                let n2 = a * a + b * b + c * c;
                // Outside when dist < -radius * |n| (compared squared). A
                // small relative margin keeps float rounding conservative.
                let r = self.radius * 1.001;
                if dist < 0.0 && dist * dist > r * r * n2 * 1.001 {
                    return true;
                }
            }
        }
        false
    }
}

/// Per-triangle or per-vertex colours of a [`Mesh`].
#[derive(Clone, Copy, Debug)]
pub enum MeshColors<'a> {
    /// One colour for everything.
    Uniform(Rgb888),
    /// One colour per triangle (flat shading).
    PerTriangle(&'a [Rgb888]),
    /// One colour per vertex (Gouraud shading, perspective-correct).
    PerVertex(&'a [Rgb888]),
}

/// An indexed triangle mesh in object space.
#[derive(Clone, Copy, Debug)]
pub struct Mesh<'a> {
    /// Vertex positions.
    pub positions: &'a [Vec3],
    /// Triangles as three indices into `positions`.
    pub indices: &'a [[u32; 3]],
    /// Colours.
    pub colors: MeshColors<'a>,
    /// A bounding sphere for whole-object culling, if known.
    pub bounds: Option<BoundingSphere>,
}

impl Mesh<'_> {
    /// Triangle `i` transformed to clip space by `mvp`, with its colours;
    /// `None` if an index (or a colour) is out of range.
    pub fn triangle(&self, i: usize, mvp: &Mat4) -> Option<[ClipVertex; 3]> {
        let idx = self.indices.get(i)?;
        let mut verts = [ClipVertex::default(); 3];
        for k in 0..3 {
            let vi = idx[k] as usize;
            let p = self.positions.get(vi)?;
            let color = match self.colors {
                MeshColors::Uniform(c) => c,
                MeshColors::PerTriangle(cs) => *cs.get(i)?,
                MeshColors::PerVertex(cs) => *cs.get(vi)?,
            };
            verts[k] = ClipVertex {
                pos: mvp.transform_point(*p),
                color: rgb_f32(color),
            };
        }
        Some(verts)
    }
}

pub(crate) fn rgb_f32(c: Rgb888) -> [f32; 3] {
    [c.r() as f32, c.g() as f32, c.b() as f32]
}

/// A frame being built and rendered, at `S` subpixel bits (8 by default;
/// 4 is the other supported value).
///
/// ```
/// use microraster::{Config, Frame, SetupTriangle, Vec4, CullMode};
/// use embedded_graphics_core::pixelcolor::{Rgb565, RgbColor};
///
/// let mut storage = [SetupTriangle::EMPTY; 16];
/// let mut config = Config::new(32, 32);
/// config.cull = CullMode::None;
/// let mut frame: Frame = Frame::new(config, &mut storage).unwrap();
/// frame.push_clip_triangle(
///     [Vec4::new(-1.0, -1.0, 0.0, 1.0), Vec4::new(1.0, -1.0, 0.0, 1.0), Vec4::new(0.0, 1.0, 0.0, 1.0)],
///     [Rgb565::RED.into(); 3].map(|c: embedded_graphics_core::pixelcolor::Rgb888| c),
///     0,
/// ).unwrap();
///
/// // Render the frame through an 8-row strip buffer.
/// let mut color = [Rgb565::BLACK; 32 * 8];
/// let mut depth = [u16::MAX; 32 * 8];
/// let mut written = 0;
/// for y0 in (0..32).step_by(8) {
///     color.fill(Rgb565::BLACK);
///     depth.fill(u16::MAX);
///     written += frame.render_rows(y0, y0 + 8, &mut color, &mut depth[..]).unwrap().pixels_written;
///     // ... send `color` to the display here ...
/// }
/// assert!(written > 400);
/// ```
#[derive(Debug)]
pub struct Frame<'s, const S: u32 = 8> {
    config: Config,
    guard: (f32, f32),
    storage: &'s mut [SetupTriangle],
    len: usize,
    stats: Stats,
}

impl<'s, const S: u32> Frame<'s, S> {
    const SUBPIXEL_OK: () = assert!(S == 4 || S == 8, "subpixel bits must be 4 or 8");

    /// A new, empty frame storing set-up triangles in `storage`.
    pub fn new(config: Config, storage: &'s mut [SetupTriangle]) -> Result<Self, Error> {
        #[allow(clippy::let_unit_value)]
        let () = Self::SUBPIXEL_OK;
        check_size(&config)?;
        Ok(Frame {
            config,
            guard: guard_band_ndc::<S>(config.width, config.height),
            storage,
            len: 0,
            stats: Stats::default(),
        })
    }

    /// The frame's settings.
    pub fn config(&self) -> &Config {
        &self.config
    }

    /// The counters so far.
    pub fn stats(&self) -> Stats {
        self.stats
    }

    /// The stored set-up triangles, in drawing order.
    pub fn triangles(&self) -> &[SetupTriangle] {
        self.storage.get(..self.len).unwrap_or(&[])
    }

    /// The storage capacity in set-up triangles.
    pub fn capacity(&self) -> usize {
        self.storage.len()
    }

    /// Empties the frame (triangles and counters) to build the next one.
    pub fn clear(&mut self) {
        self.len = 0;
        self.stats = Stats::default();
    }

    /// Submits one clip-space triangle with a colour per vertex; `id` is
    /// the caller's index for it (see [`TriangleId`](crate::TriangleId)).
    pub fn push_clip_triangle(
        &mut self,
        pos: [Vec4; 3],
        color: [Rgb888; 3],
        id: u32,
    ) -> Result<(), Error> {
        self.push_triangle(
            [
                ClipVertex {
                    pos: pos[0],
                    color: rgb_f32(color[0]),
                },
                ClipVertex {
                    pos: pos[1],
                    color: rgb_f32(color[1]),
                },
                ClipVertex {
                    pos: pos[2],
                    color: rgb_f32(color[2]),
                },
            ],
            id,
        )
    }

    /// Submits one clip-space triangle. On [`Error::StorageFull`] nothing
    /// of it is stored or counted.
    pub fn push_triangle(&mut self, tri: [ClipVertex; 3], id: u32) -> Result<(), Error> {
        let mut stats = Stats {
            submitted: 1,
            ..Stats::default()
        };
        let mut out: heapless::Vec<SetupTriangle, 7> = heapless::Vec::new();
        process::<S>(&self.config, self.guard, &tri, id, &mut stats, &mut out);
        let free = self.storage.len() - self.len;
        if out.len() > free {
            return Err(Error::StorageFull {
                capacity: self.storage.len(),
                needed: out.len() - free,
            });
        }
        for t in out {
            if let Some(slot) = self.storage.get_mut(self.len) {
                *slot = t;
                self.len += 1;
            }
        }
        self.stats.add(&stats);
        Ok(())
    }

    /// Submits every triangle of `mesh`, transformed by `mvp` (object to
    /// clip space). Triangle `i` gets the id `first_id + i`. The bounding
    /// sphere, if given, is tested first: an object entirely outside the
    /// frustum is skipped without transforming a vertex. On
    /// [`Error::StorageFull`] nothing of the mesh is stored or counted.
    pub fn draw_mesh(&mut self, mesh: &Mesh<'_>, mvp: &Mat4, first_id: u32) -> Result<(), Error> {
        let count = mesh.indices.len() as u32;
        if let Some(b) = mesh.bounds {
            if b.outside_frustum(mvp) {
                self.stats.submitted += count;
                self.stats.culled_object += count;
                return Ok(());
            }
        }
        let start_len = self.len;
        let start_stats = self.stats;
        for i in 0..mesh.indices.len() {
            let id = first_id.wrapping_add(i as u32);
            let Some(verts) = mesh.triangle(i, mvp) else {
                self.stats.submitted += 1;
                self.stats.rejected_index += 1;
                continue;
            };
            if let Err(e) = self.push_triangle(verts, id) {
                self.len = start_len;
                self.stats = start_stats;
                return Err(match e {
                    Error::StorageFull { capacity, .. } => Error::StorageFull {
                        capacity,
                        needed: mesh.indices.len().saturating_sub(i),
                    },
                    other => other,
                });
            }
        }
        Ok(())
    }

    /// Renders rows `y0..y1` of the frame into `color` and `depth`, which
    /// hold exactly those rows (`width * (y1 - y0)` values, row `y0`
    /// first). Pass `&mut NoDepth` to draw without a depth buffer. The
    /// buffers are drawn over, not cleared.
    pub fn render_rows<C: Pixel, D: DepthBuffer + ?Sized>(
        &self,
        y0: u32,
        y1: u32,
        color: &mut [C],
        depth: &mut D,
    ) -> Result<RenderStats, Error> {
        check_rows(&self.config, y0, y1, color.len(), depth.depth_len())?;
        let width = self.config.width;
        let mut strip = Strip {
            width: width as usize,
            y0,
            y1,
            color,
            depth,
            depth_func: self.config.depth_func,
            depth_write: self.config.depth_write,
        };
        let mut stats = RenderStats::default();
        for t in self.triangles() {
            stats.pixels_written += draw::<S, C, D>(t, &mut strip) as u64;
        }
        Ok(stats)
    }
}

fn count_rejected(stats: &mut Stats, r: Rejected) {
    match r {
        Rejected::Backface => stats.culled_backface += 1,
        Rejected::Degenerate => stats.culled_degenerate += 1,
        Rejected::Offscreen => stats.culled_frustum += 1,
        Rejected::NonFinite => stats.rejected_nonfinite += 1,
    }
}

/// Runs one triangle through cull, clip and setup into `out`.
pub(crate) fn process<const S: u32>(
    c: &Config,
    guard: (f32, f32),
    tri: &[ClipVertex; 3],
    id: u32,
    stats: &mut Stats,
    out: &mut heapless::Vec<SetupTriangle, 7>,
) {
    if !tri
        .iter()
        .all(|v| v.pos.is_finite() && v.color.iter().all(|c| c.is_finite()))
    {
        stats.rejected_nonfinite += 1;
        return;
    }
    let (gx, gy) = guard;
    let codes = [
        outcode(tri[0].pos, gx, gy),
        outcode(tri[1].pos, gx, gy),
        outcode(tri[2].pos, gx, gy),
    ];
    if codes[0] & codes[1] & codes[2] & outcode::FRUSTUM != 0 {
        stats.culled_frustum += 1;
        return;
    }
    let crossing = (codes[0] | codes[1] | codes[2]) & outcode::CLIP;
    if crossing == 0 {
        match setup::<S>(tri, c.width, c.height, c.cull, c.front_face, id) {
            Ok(t) => {
                let _ = out.push(t);
                stats.stored += 1;
            }
            Err(r) => count_rejected(stats, r),
        }
        return;
    }
    stats.clipped += 1;
    let poly = clip_triangle(tri, crossing, gx, gy);
    if poly.len() < 3 {
        stats.culled_frustum += 1;
        return;
    }
    // Fan from vertex 0; each piece is culled and set up on its own
    // (all pieces share the winding of the input triangle).
    let mut first_reason = None;
    for i in 1..poly.len() - 1 {
        let piece = [poly[0], poly[i], poly[i + 1]];
        match setup::<S>(&piece, c.width, c.height, c.cull, c.front_face, id) {
            Ok(t) => {
                // At most 7 pieces from a 9-gon: cannot fail.
                let _ = out.push(t);
                stats.stored += 1;
            }
            Err(r) => {
                first_reason.get_or_insert(r);
            }
        }
    }
    if out.is_empty() {
        count_rejected(stats, first_reason.unwrap_or(Rejected::Degenerate));
    }
}

/// Checks a row range and buffer sizes against a frame.
pub(crate) fn check_rows(
    config: &Config,
    y0: u32,
    y1: u32,
    color_len: usize,
    depth_len: Option<usize>,
) -> Result<(), Error> {
    let Config { width, height, .. } = *config;
    if y0 >= y1 || y1 > height {
        return Err(Error::InvalidRows { y0, y1, height });
    }
    let expected = width as usize * (y1 - y0) as usize;
    if color_len != expected {
        return Err(Error::ColorBufferSize {
            expected,
            actual: color_len,
        });
    }
    if let Some(actual) = depth_len {
        if actual != expected {
            return Err(Error::DepthBufferSize { expected, actual });
        }
    }
    Ok(())
}

/// Checks a frame size.
pub(crate) fn check_size(config: &Config) -> Result<(), Error> {
    let ok = |v: u32| (1..=MAX_DIMENSION).contains(&v);
    if ok(config.width) && ok(config.height) {
        Ok(())
    } else {
        Err(Error::InvalidFrameSize {
            width: config.width,
            height: config.height,
        })
    }
}
