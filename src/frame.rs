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
use crate::fixed::{snap, SnappedVertex};
use crate::math::{Mat4, Vec3, Vec4};
use crate::raster::{draw, Strip};
use crate::setup::{setup, setup_geometry, triangulate, Rejected, SetupTriangle};
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
    /// Bin storage too small (offsets: strips + 1; items:
    /// [`Frame::bin_entries`]).
    BinStorageSize {
        /// Entries needed.
        expected: usize,
        /// Entries given.
        actual: usize,
    },
    /// The vertex cache holds fewer entries than the mesh has vertices.
    VertexCacheSize {
        /// The mesh's vertex count.
        expected: usize,
        /// The cache length.
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
            Error::BinStorageSize { expected, actual } => {
                write!(f, "bin storage holds {actual} entries, expected {expected}")
            }
            Error::VertexCacheSize { expected, actual } => {
                write!(
                    f,
                    "vertex cache holds {actual} vertices, expected {expected}"
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
    /// [`StripRenderer`](crate::StripRenderer) only: skipped before any
    /// setup because every vertex lies above or below the strip.
    pub outside_strip: u32,
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
        self.outside_strip += o.outside_strip;
    }
}

/// Per-strip triangle bins of a frame, made by [`Frame::bin`].
#[derive(Debug)]
pub struct Bins<'b> {
    strip_rows: u32,
    offsets: &'b [u32],
    items: &'b [u32],
}

impl Bins<'_> {
    /// Rows per strip.
    pub fn strip_rows(&self) -> u32 {
        self.strip_rows
    }

    /// The number of strips.
    pub fn strips(&self) -> u32 {
        self.offsets.len().saturating_sub(1) as u32
    }

    /// The rows `y0..y1` of strip `strip` in a frame of `height` rows.
    pub fn rows(&self, strip: u32, height: u32) -> (u32, u32) {
        let y0 = strip.saturating_mul(self.strip_rows);
        (y0, y0.saturating_add(self.strip_rows).min(height))
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

/// Outcode bit for a vertex with a NaN or infinite coordinate.
const NONFINITE: u16 = 1 << 15;

/// A vertex after the vertex stage (see [`Frame::draw_mesh_cached`]):
/// clip-space position, outcode and, where no clipping can touch it, its
/// snapped window position.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ProcessedVertex {
    pos: Vec4,
    inv_w: f32,
    snap: crate::fixed::SnappedVertex,
    code: u16,
    snapped: bool,
}

impl ProcessedVertex {
    /// A placeholder to fill a cache with.
    pub const EMPTY: ProcessedVertex = ProcessedVertex {
        pos: Vec4::new(0.0, 0.0, 0.0, 0.0),
        inv_w: 0.0,
        snap: crate::fixed::SnappedVertex { x: 0, y: 0, z: 0 },
        code: 0,
        snapped: false,
    };

    #[inline]
    fn new<const S: u32>(pos: Vec4, gx: f32, gy: f32, width: u32, height: u32) -> Self {
        if !pos.is_finite() {
            return ProcessedVertex {
                pos,
                code: NONFINITE,
                ..ProcessedVertex::EMPTY
            };
        }
        let code = outcode(pos, gx, gy);
        let mut v = ProcessedVertex {
            pos,
            code,
            ..ProcessedVertex::EMPTY
        };
        if code & outcode::CLIP == 0 && pos.w > 0.0 {
            v.inv_w = 1.0 / pos.w;
            if let Some(s) =
                crate::fixed::snap_inv::<S>(pos.x, pos.y, pos.z, v.inv_w, width, height)
            {
                v.snap = s;
                v.snapped = true;
            }
        }
        v
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
        // Pieces go straight into storage; if it fills up, they are taken
        // back (the length is restored) and nothing is counted.
        let start = self.len;
        let storage = &mut *self.storage;
        let len = &mut self.len;
        let mut wanted = 0usize;
        let ok = process::<S>(&self.config, self.guard, &tri, id, &mut stats, |t| {
            wanted += 1;
            match storage.get_mut(*len) {
                Some(slot) => {
                    *slot = t;
                    *len += 1;
                    true
                }
                None => false,
            }
        });
        if !ok {
            self.len = start;
            return Err(Error::StorageFull {
                capacity: self.storage.len(),
                needed: start + wanted - self.storage.len(),
            });
        }
        self.stats.add(&stats);
        Ok(())
    }

    /// Like [`Frame::draw_mesh`], with every vertex transformed, outcoded
    /// and snapped once instead of once per triangle that uses it: the fast
    /// path for indexed meshes. `cache` is scratch space of at least
    /// `mesh.positions.len()` entries. The result is identical to
    /// [`Frame::draw_mesh`]'s.
    pub fn draw_mesh_cached(
        &mut self,
        mesh: &Mesh<'_>,
        mvp: &Mat4,
        first_id: u32,
        cache: &mut [ProcessedVertex],
    ) -> Result<(), Error> {
        let count = mesh.indices.len() as u32;
        let cache = match cache.get_mut(..mesh.positions.len()) {
            Some(c) => c,
            None => {
                return Err(Error::VertexCacheSize {
                    expected: mesh.positions.len(),
                    actual: cache.len(),
                })
            }
        };
        if let Some(b) = mesh.bounds {
            if b.outside_frustum(mvp) {
                self.stats.submitted += count;
                self.stats.culled_object += count;
                return Ok(());
            }
        }
        self.process_vertices(mvp, mesh.positions, cache);
        self.draw_mesh_processed(mesh, first_id, cache)
    }

    /// The vertex stage of [`Frame::draw_mesh_cached`] alone: transforms,
    /// outcodes and snaps `positions` into `out` (pairwise; extra entries of
    /// either are left alone). Chunks of one mesh's vertices can be
    /// processed in parallel, by frames of the same configuration, before
    /// [`Frame::draw_mesh_processed`].
    pub fn process_vertices(&self, mvp: &Mat4, positions: &[Vec3], out: &mut [ProcessedVertex]) {
        process_vertices::<S>(&self.config, self.guard, mvp, positions, out);
    }

    /// The triangle stage of [`Frame::draw_mesh_cached`]: submits the
    /// triangles of `mesh` whose vertices `cache` holds already processed
    /// by [`Frame::process_vertices`] for a frame of this configuration
    /// (entry `i` for `mesh.positions[i]`; `mesh.bounds` is not tested
    /// here). All-or-nothing on [`Error::StorageFull`].
    pub fn draw_mesh_processed(
        &mut self,
        mesh: &Mesh<'_>,
        first_id: u32,
        cache: &[ProcessedVertex],
    ) -> Result<(), Error> {
        let start_len = self.len;
        let mut stats = Stats::default();
        let storage = &mut *self.storage;
        let len = &mut self.len;
        let result = triangles_processed::<S>(
            &self.config,
            self.guard,
            mesh,
            first_id,
            cache,
            &mut stats,
            |_| false,
            |t| match storage.get_mut(*len) {
                Some(slot) => {
                    *slot = t;
                    *len += 1;
                    true
                }
                None => false,
            },
        );
        match result {
            Ok(()) => {
                self.stats.add(&stats);
                Ok(())
            }
            Err(i) => {
                self.len = start_len;
                Err(Error::StorageFull {
                    capacity: self.storage.len(),
                    needed: mesh.indices.len() - i,
                })
            }
        }
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

    /// The number of bin entries [`Frame::bin`] needs for strips of
    /// `strip_rows` rows: one per (triangle, strip it touches).
    pub fn bin_entries(&self, strip_rows: u32) -> usize {
        let r = strip_rows.max(1);
        self.triangles()
            .iter()
            .map(|t| (t.max_y as u32 / r - t.min_y as u32 / r) as usize + 1)
            .sum()
    }

    /// Sorts the stored triangles into per-strip bins (strips of
    /// `strip_rows` rows from row 0), in caller-provided storage: `offsets`
    /// needs one entry per strip plus one, `items` [`Frame::bin_entries`]
    /// entries. Each bin keeps submission order, so
    /// [`Frame::render_strip`] gives the same pixels as
    /// [`Frame::render_rows`] while touching only the triangles that reach
    /// the strip.
    pub fn bin<'b>(
        &self,
        strip_rows: u32,
        offsets: &'b mut [u32],
        items: &'b mut [u32],
    ) -> Result<Bins<'b>, Error> {
        let r = strip_rows.max(1);
        let strips = self.config.height.div_ceil(r) as usize;
        let need_items = self.bin_entries(r);
        if offsets.len() < strips + 1 {
            return Err(Error::BinStorageSize {
                expected: strips + 1,
                actual: offsets.len(),
            });
        }
        if items.len() < need_items || need_items > u32::MAX as usize {
            return Err(Error::BinStorageSize {
                expected: need_items,
                actual: items.len(),
            });
        }
        let offsets = &mut offsets[..strips + 1];
        offsets.fill(0);
        // Count into offsets[s + 1], prefix-sum into starts, fill using
        // offsets[s] as the cursor (it ends at the start of s + 1), then
        // shift back: no scratch beyond the two slices.
        for t in self.triangles() {
            for s in t.min_y as u32 / r..=t.max_y as u32 / r {
                if let Some(o) = offsets.get_mut(s as usize + 1) {
                    *o += 1;
                }
            }
        }
        for s in 1..offsets.len() {
            offsets[s] += offsets[s - 1];
        }
        for (i, t) in self.triangles().iter().enumerate() {
            for s in t.min_y as u32 / r..=t.max_y as u32 / r {
                if let Some(o) = offsets.get_mut(s as usize) {
                    if let Some(slot) = items.get_mut(*o as usize) {
                        *slot = i as u32;
                    }
                    *o += 1;
                }
            }
        }
        for s in (1..offsets.len()).rev() {
            offsets[s] = offsets[s - 1];
        }
        offsets[0] = 0;
        Ok(Bins {
            strip_rows: r,
            offsets,
            items: &items[..need_items],
        })
    }

    /// Renders strip `strip` (rows `strip * strip_rows ..`, the last strip
    /// possibly shorter) of a binned frame into buffers that hold exactly
    /// those rows. The same pixels as [`Frame::render_rows`] for those rows.
    pub fn render_strip<C: Pixel, D: DepthBuffer + ?Sized>(
        &self,
        bins: &Bins<'_>,
        strip: u32,
        color: &mut [C],
        depth: &mut D,
    ) -> Result<RenderStats, Error> {
        let (y0, y1) = bins.rows(strip, self.config.height);
        check_rows(&self.config, y0, y1, color.len(), depth.depth_len())?;
        let (Some(&a), Some(&b)) = (
            bins.offsets.get(strip as usize),
            bins.offsets.get(strip as usize + 1),
        ) else {
            return Err(Error::InvalidRows {
                y0,
                y1,
                height: self.config.height,
            });
        };
        let mut strip = Strip {
            width: self.config.width as usize,
            y0,
            y1,
            color,
            depth,
            depth_func: self.config.depth_func,
            depth_write: self.config.depth_write,
        };
        let mut stats = RenderStats::default();
        let tris = self.triangles();
        for &i in bins.items.get(a as usize..b as usize).unwrap_or(&[]) {
            if let Some(t) = tris.get(i as usize) {
                stats.pixels_written += draw::<S, C, D>(t, &mut strip) as u64;
            }
        }
        Ok(stats)
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

/// Runs one triangle through cull, clip and setup, handing each set-up
/// piece (at most 7) to `sink`, which returns `false` when it cannot take
/// it; then this returns `false` at once (the caller rolls back).
pub(crate) fn process<const S: u32>(
    c: &Config,
    guard: (f32, f32),
    tri: &[ClipVertex; 3],
    id: u32,
    stats: &mut Stats,
    mut sink: impl FnMut(SetupTriangle) -> bool,
) -> bool {
    if !tri
        .iter()
        .all(|v| v.pos.is_finite() && v.color.iter().all(|c| c.is_finite()))
    {
        stats.rejected_nonfinite += 1;
        return true;
    }
    let (gx, gy) = guard;
    let codes = [
        outcode(tri[0].pos, gx, gy),
        outcode(tri[1].pos, gx, gy),
        outcode(tri[2].pos, gx, gy),
    ];
    if codes[0] & codes[1] & codes[2] & outcode::FRUSTUM != 0 {
        stats.culled_frustum += 1;
        return true;
    }
    let crossing = (codes[0] | codes[1] | codes[2]) & outcode::CLIP;
    if crossing == 0 {
        match setup::<S>(tri, c.width, c.height, c.cull, c.front_face, id) {
            Ok(t) => {
                if !sink(t) {
                    return false;
                }
                stats.stored += 1;
            }
            Err(r) => count_rejected(stats, r),
        }
        return true;
    }
    stats.clipped += 1;
    let poly = clip_triangle(tri, crossing, gx, gy);
    if poly.len() < 3 {
        stats.culled_frustum += 1;
        return true;
    }
    // Snap the polygon's vertices once; split it into triangles that all
    // wind the same way (a fan, unless snapping made the polygon slightly
    // non-convex, see `setup::triangulate`); cull and set up each piece.
    let mut snapped: heapless::Vec<Option<SnappedVertex>, 9> = heapless::Vec::new();
    for v in &poly {
        let p = v.pos;
        let _ = snapped.push(snap::<S>(p.x, p.y, p.z, p.w, c.width, c.height));
    }
    let mut first_reason = None;
    let mut stored = 0;
    for [a, b, d] in triangulate(&snapped) {
        let (a, b, d) = (a as usize, b as usize, d as usize);
        let (Some(sa), Some(sb), Some(sd)) = (snapped[a], snapped[b], snapped[d]) else {
            first_reason.get_or_insert(Rejected::NonFinite);
            continue;
        };
        match setup_geometry::<S>(&[sa, sb, sd], c.width, c.height, c.cull, c.front_face) {
            Ok(g) => {
                let (pa, pb, pd) = (&poly[a], &poly[b], &poly[d]);
                if !sink(g.finish(
                    [1.0 / pa.pos.w, 1.0 / pb.pos.w, 1.0 / pd.pos.w],
                    [pa.color, pb.color, pd.color],
                    id,
                )) {
                    return false;
                }
                stored += 1;
                stats.stored += 1;
            }
            Err(r) => {
                first_reason.get_or_insert(r);
            }
        }
    }
    if stored == 0 {
        count_rejected(stats, first_reason.unwrap_or(Rejected::Degenerate));
    }
    true
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

/// The vertex stage: transform, outcode and (where no clipping can touch
/// the vertex) snap, pairwise from `positions` into `out`.
pub(crate) fn process_vertices<const S: u32>(
    c: &Config,
    guard: (f32, f32),
    mvp: &Mat4,
    positions: &[Vec3],
    out: &mut [ProcessedVertex],
) {
    let (gx, gy) = guard;
    for (p, v) in positions.iter().zip(out.iter_mut()) {
        *v = ProcessedVertex::new::<S>(mvp.transform_point(*p), gx, gy, c.width, c.height);
    }
}

/// The triangle stage over processed vertices, shared by [`Frame`] and
/// [`StripRenderer`](crate::StripRenderer): every set-up triangle goes to
/// `sink` (which returns `false` when it cannot take it: then this returns
/// `Err(i)` for the triangle `i` that did not fit). Triangles for which
/// `skip` (given the three clip positions) says so are counted in
/// `outside_strip` after the frustum test.
#[allow(clippy::too_many_arguments)]
pub(crate) fn triangles_processed<const S: u32>(
    c: &Config,
    guard: (f32, f32),
    mesh: &Mesh<'_>,
    first_id: u32,
    cache: &[ProcessedVertex],
    stats: &mut Stats,
    mut skip: impl FnMut([Vec4; 3]) -> bool,
    mut sink: impl FnMut(SetupTriangle) -> bool,
) -> Result<(), usize> {
    // Colour lists as long as the mesh need no check per triangle.
    let colors_complete = match mesh.colors {
        MeshColors::Uniform(_) => true,
        MeshColors::PerTriangle(cs) => cs.len() >= mesh.indices.len(),
        MeshColors::PerVertex(cs) => cs.len() >= cache.len(),
    };
    for (i, idx) in mesh.indices.iter().enumerate() {
        let id = first_id.wrapping_add(i as u32);
        stats.submitted += 1;
        let (Some(a), Some(b), Some(d)) = (
            cache.get(idx[0] as usize),
            cache.get(idx[1] as usize),
            cache.get(idx[2] as usize),
        ) else {
            stats.rejected_index += 1;
            continue;
        };
        // A missing colour counts as a bad index first, as in `draw_mesh`.
        let colors_ok = colors_complete
            || match mesh.colors {
                MeshColors::Uniform(_) => true,
                MeshColors::PerTriangle(cs) => i < cs.len(),
                MeshColors::PerVertex(cs) => idx.iter().all(|&k| (k as usize) < cs.len()),
            };
        if !colors_ok {
            stats.rejected_index += 1;
            continue;
        }
        let color = |k: usize| -> [f32; 3] {
            rgb_f32(match mesh.colors {
                MeshColors::Uniform(c) => c,
                MeshColors::PerTriangle(cs) => cs.get(i).copied().unwrap_or_default(),
                MeshColors::PerVertex(cs) => cs.get(idx[k] as usize).copied().unwrap_or_default(),
            })
        };
        let (and, or) = (a.code & b.code & d.code, a.code | b.code | d.code);
        if or & NONFINITE != 0 {
            stats.rejected_nonfinite += 1;
            continue;
        }
        if and & outcode::FRUSTUM != 0 {
            stats.culled_frustum += 1;
            continue;
        }
        if skip([a.pos, b.pos, d.pos]) {
            stats.outside_strip += 1;
            continue;
        }
        if or & outcode::CLIP == 0 && a.snapped && b.snapped && d.snapped {
            // Fast path: vertices already snapped.
            match setup_geometry::<S>(
                &[a.snap, b.snap, d.snap],
                c.width,
                c.height,
                c.cull,
                c.front_face,
            ) {
                Ok(g) => {
                    let t = g.finish(
                        [a.inv_w, b.inv_w, d.inv_w],
                        [color(0), color(1), color(2)],
                        id,
                    );
                    if !sink(t) {
                        return Err(i);
                    }
                    stats.stored += 1;
                }
                Err(r) => count_rejected(stats, r),
            }
            continue;
        }
        let v = [a, b, d];
        let tri: [ClipVertex; 3] = core::array::from_fn(|k| ClipVertex {
            pos: v[k].pos,
            color: color(k),
        });
        if !process::<S>(c, guard, &tri, id, stats, &mut sink) {
            return Err(i);
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::color::TriangleId;
    use crate::depth::NoDepth;

    /// A deterministic pseudo-random scene of overlapping triangles.
    fn scene(frame: &mut Frame<'_>, n: u32) {
        let mut seed = 0x2545_f491_4f6c_dd1du64;
        let mut rnd = move || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed >> 40) as f32 / (1u64 << 24) as f32 * 2.4 - 1.2
        };
        for i in 0..n {
            let p = [0, 1, 2].map(|_| Vec4::new(rnd(), rnd(), rnd() * 0.9, 1.0));
            let c = Rgb888::new((i * 37) as u8, (i * 91) as u8, (i * 13) as u8);
            frame.push_clip_triangle(p, [c; 3], i).unwrap();
        }
    }

    #[test]
    fn binned_strips_equal_unbinned_rows() {
        let mut storage = [SetupTriangle::EMPTY; 200];
        let mut config = Config::new(40, 37);
        config.cull = CullMode::None;
        let mut frame: Frame = Frame::new(config, &mut storage).unwrap();
        scene(&mut frame, 60);
        let mut whole = [TriangleId(0); 40 * 37];
        let mut zw = [u32::MAX; 40 * 37];
        frame.render_rows(0, 37, &mut whole, &mut zw[..]).unwrap();
        for r in [1u32, 5, 16, 37, 100] {
            let mut offsets = [0u32; 40];
            let mut items = [0u32; 2000];
            assert!(frame.bin_entries(r) <= items.len());
            let bins = frame.bin(r, &mut offsets, &mut items).unwrap();
            let mut out = [TriangleId(0); 40 * 37];
            let mut zo = [u32::MAX; 40 * 37];
            for s in 0..bins.strips() {
                let (y0, y1) = bins.rows(s, 37);
                let range = y0 as usize * 40..y1 as usize * 40;
                frame
                    .render_strip(&bins, s, &mut out[range.clone()], &mut zo[range])
                    .unwrap();
            }
            assert_eq!(out, whole, "strip rows {r}");
            assert_eq!(zo, zw, "strip rows {r}");
        }
    }

    #[test]
    fn bin_storage_too_small_is_an_error() {
        let mut storage = [SetupTriangle::EMPTY; 200];
        let mut config = Config::new(40, 37);
        config.cull = CullMode::None;
        let mut frame: Frame = Frame::new(config, &mut storage).unwrap();
        scene(&mut frame, 20);
        let mut offsets = [0u32; 4];
        let mut items = [0u32; 2000];
        assert!(matches!(
            frame.bin(16, &mut offsets[..3], &mut items),
            Err(Error::BinStorageSize { expected: 4, .. })
        ));
        let need = frame.bin_entries(16);
        assert!(matches!(
            frame.bin(16, &mut offsets, &mut items[..need - 1]),
            Err(Error::BinStorageSize { .. })
        ));
        let bins = frame.bin(16, &mut offsets, &mut items).unwrap();
        let mut c = [TriangleId(0); 40 * 16];
        assert!(frame.render_strip(&bins, 3, &mut c, &mut NoDepth).is_err());
    }

    #[test]
    fn cached_mesh_equals_uncached() {
        let positions: [Vec3; 6] = [
            Vec3::new(-1.0, -1.0, 0.0),
            Vec3::new(1.0, -1.0, 0.5),
            Vec3::new(0.0, 1.0, -0.5),
            Vec3::new(3.0, 0.0, -3.0),
            Vec3::new(-2.0, 2.0, 2.5),
            Vec3::new(0.5, 0.5, f32::NAN),
        ];
        let indices = [
            [0, 1, 2],
            [1, 3, 2],
            [2, 4, 0],
            [0, 4, 3],
            [1, 5, 2],
            [0, 9, 1],
        ];
        let colors = [Rgb888::new(200, 10, 10); 6];
        let mesh = Mesh {
            positions: &positions,
            indices: &indices,
            colors: MeshColors::PerVertex(&colors),
            bounds: None,
        };
        for angle in [0.0f32, 0.7, 1.9, 3.0] {
            let mvp = Mat4::perspective(1.2, 1.0, 0.5, 20.0)
                * Mat4::translation(Vec3::new(0.0, 0.0, -2.2))
                * Mat4::rotation_y(angle);
            let mut config = Config::new(32, 32);
            config.cull = CullMode::None;
            let mut s1 = [SetupTriangle::EMPTY; 64];
            let mut a: Frame = Frame::new(config, &mut s1).unwrap();
            a.draw_mesh(&mesh, &mvp, 7).unwrap();
            let mut s2 = [SetupTriangle::EMPTY; 64];
            let mut b: Frame = Frame::new(config, &mut s2).unwrap();
            let mut cache = [ProcessedVertex::EMPTY; 6];
            b.draw_mesh_cached(&mesh, &mvp, 7, &mut cache).unwrap();
            assert_eq!(a.triangles(), b.triangles(), "angle {angle}");
            assert_eq!(a.stats(), b.stats(), "angle {angle}");
            let mut small = [ProcessedVertex::EMPTY; 5];
            assert!(matches!(
                b.draw_mesh_cached(&mesh, &mvp, 7, &mut small),
                Err(Error::VertexCacheSize {
                    expected: 6,
                    actual: 5
                })
            ));
        }
    }
}
