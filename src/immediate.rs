//! Immediate strip rendering: no setup storage at all.
//!
//! Design note: [`Frame`](crate::Frame) sets every triangle up once and
//! keeps the result, which costs about a hundred bytes a triangle. Where RAM
//! is scarcer than cycles (a microcontroller drawing through a 16-row
//! buffer) [`StripRenderer`] instead runs each submitted triangle through
//! the same pipeline (transform, cull, clip, setup) and draws it straight
//! into the one strip it holds. The caller submits the scene once per
//! strip. The pixels are bit-identical to [`Frame::render_rows`]
//! (`crate::Frame::render_rows`) for the same rows: it is the same code in
//! the same order, only without the store. Triangles wholly above or below
//! the strip are skipped before clipping and setup (counted in
//! [`Stats::outside_strip`](crate::Stats::outside_strip)), so each strip
//! pays the full pipeline only for the triangles that reach it.

use crate::clip::ClipVertex;
use crate::color::Pixel;
use crate::depth::DepthBuffer;
use crate::fixed::guard_band_ndc;
use crate::frame::{
    check_rows, check_size, process, rgb_f32, Config, Error, Mesh, RenderStats, Stats,
};
use crate::math::{Mat4, Vec4};
use crate::raster::{draw, Strip};
use crate::setup::SetupTriangle;
use embedded_graphics_core::pixelcolor::Rgb888;

/// Draws triangles straight into rows `y0..y1` of a frame, at `S` subpixel
/// bits, without storing them.
///
/// ```
/// use microraster::pixelcolor::{Rgb888, RgbColor};
/// use microraster::{Config, CullMode, NoDepth, StripRenderer, Vec4};
///
/// let mut config = Config::new(16, 16);
/// config.cull = CullMode::None;
/// let mut rows = [Rgb888::BLACK; 16 * 4];
/// let mut no_depth = NoDepth;
/// // Rows 8..12 of a 16x16 frame, no depth buffer.
/// let mut strip: StripRenderer<_, _> =
///     StripRenderer::new(config, 8, 12, &mut rows, &mut no_depth).unwrap();
/// strip.push_clip_triangle(
///     [Vec4::new(-1.0, -1.0, 0.0, 1.0), Vec4::new(1.0, -1.0, 0.0, 1.0), Vec4::new(-1.0, 1.0, 0.0, 1.0)],
///     [Rgb888::RED; 3],
///     0,
/// );
/// assert!(strip.render_stats().pixels_written > 0);
/// ```
pub struct StripRenderer<'b, C, D: ?Sized, const S: u32 = 8> {
    config: Config,
    guard: (f32, f32),
    /// NDC y above which (and below which) a vertex lies beyond the strip,
    /// with a quarter-pixel margin: `(top, bottom)`.
    slab: (f32, f32),
    strip: Strip<'b, C, D>,
    stats: Stats,
    render: RenderStats,
}

impl<C, D: ?Sized, const S: u32> core::fmt::Debug for StripRenderer<'_, C, D, S> {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.debug_struct("StripRenderer")
            .field("config", &self.config)
            .field("rows", &(self.strip.y0..self.strip.y1))
            .field("stats", &self.stats)
            .field("render", &self.render)
            .finish()
    }
}

impl<'b, C: Pixel, D: DepthBuffer + ?Sized, const S: u32> StripRenderer<'b, C, D, S> {
    const SUBPIXEL_OK: () = assert!(S == 4 || S == 8, "subpixel bits must be 4 or 8");

    /// A renderer for rows `y0..y1` of a frame, drawing into `color` and
    /// `depth`, which hold exactly those rows. Buffers are drawn over, not
    /// cleared.
    pub fn new(
        config: Config,
        y0: u32,
        y1: u32,
        color: &'b mut [C],
        depth: &'b mut D,
    ) -> Result<Self, Error> {
        #[allow(clippy::let_unit_value)]
        let () = Self::SUBPIXEL_OK;
        check_size(&config)?;
        check_rows(&config, y0, y1, color.len(), depth.depth_len())?;
        Ok(StripRenderer {
            config,
            guard: guard_band_ndc::<S>(config.width, config.height),
            slab: {
                let h = config.height as f32;
                (
                    1.0 - 2.0 * (y0 as f32 + 0.25) / h,
                    1.0 - 2.0 * (y1 as f32 - 0.25) / h,
                )
            },
            strip: Strip {
                width: config.width as usize,
                y0,
                y1,
                color,
                depth,
                depth_func: config.depth_func,
                depth_write: config.depth_write,
            },
            stats: Stats::default(),
            render: RenderStats::default(),
        })
    }

    /// Counters of the triangles submitted so far (to this strip).
    pub fn stats(&self) -> Stats {
        self.stats
    }

    /// Pixels written so far.
    pub fn render_stats(&self) -> RenderStats {
        self.render
    }

    /// Submits and draws one clip-space triangle.
    pub fn push_triangle(&mut self, tri: [ClipVertex; 3], id: u32) {
        self.stats.submitted += 1;
        // Every vertex in front of the eye and all above (or all below) the
        // strip: no pixel centre of the strip can be covered. The quarter
        // pixel margin dwarfs float rounding and snapping (half a
        // subpixel), so this never decides coverage.
        // Triangles outside the whole frame are left to the frustum test,
        // so a strip covering the frame counts exactly what a `Frame` does.
        let (top, bottom) = self.slab;
        let whole = self.strip.y0 == 0 && self.strip.y1 == self.config.height;
        if !whole
            && tri.iter().all(|v| v.pos.w > 0.0 && v.pos.is_finite())
            && ((tri.iter().all(|v| v.pos.y > v.pos.w * top)
                && !tri.iter().all(|v| v.pos.y > v.pos.w))
                || (tri.iter().all(|v| v.pos.y < v.pos.w * bottom)
                    && !tri.iter().all(|v| v.pos.y < -v.pos.w)))
        {
            self.stats.outside_strip += 1;
            return;
        }
        let mut out: heapless::Vec<SetupTriangle, 7> = heapless::Vec::new();
        process::<S>(
            &self.config,
            self.guard,
            &tri,
            id,
            &mut self.stats,
            &mut out,
        );
        for t in &out {
            self.render.pixels_written += draw::<S, C, D>(t, &mut self.strip) as u64;
        }
    }

    /// Submits and draws one clip-space triangle with a colour per vertex.
    pub fn push_clip_triangle(&mut self, pos: [Vec4; 3], color: [Rgb888; 3], id: u32) {
        let v = |k: usize| ClipVertex {
            pos: pos[k],
            color: rgb_f32(color[k]),
        };
        self.push_triangle([v(0), v(1), v(2)], id);
    }

    /// Submits and draws every triangle of `mesh` (see
    /// [`Frame::draw_mesh`](crate::Frame::draw_mesh)).
    pub fn draw_mesh(&mut self, mesh: &Mesh<'_>, mvp: &Mat4, first_id: u32) {
        let count = mesh.indices.len() as u32;
        if let Some(b) = mesh.bounds {
            if b.outside_frustum(mvp) {
                self.stats.submitted += count;
                self.stats.culled_object += count;
                return;
            }
        }
        for i in 0..mesh.indices.len() {
            match mesh.triangle(i, mvp) {
                Some(t) => self.push_triangle(t, first_id.wrapping_add(i as u32)),
                None => {
                    self.stats.submitted += 1;
                    self.stats.rejected_index += 1;
                }
            }
        }
    }
}
