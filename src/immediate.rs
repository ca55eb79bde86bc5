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
    check_rows, check_size, process, process_vertices, rgb_f32, triangles_processed, Config, Error,
    Mesh, ProcessedVertex, RenderStats, Stats,
};
use crate::math::{Mat4, Vec3, Vec4};
use crate::raster::{draw, Strip};
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
        let strip = &mut self.strip;
        let render = &mut self.render;
        process::<S>(&self.config, self.guard, &tri, id, &mut self.stats, |t| {
            render.pixels_written += draw::<S, C, D>(&t, strip) as u64;
            true
        });
    }

    /// The vertex stage for [`StripRenderer::draw_mesh_processed`]: like
    /// [`Frame::process_vertices`](crate::Frame::process_vertices). The
    /// result depends on the frame, not the strip: process a mesh once per
    /// frame and draw it into every strip.
    pub fn process_vertices(&self, mvp: &Mat4, positions: &[Vec3], out: &mut [ProcessedVertex]) {
        process_vertices::<S>(&self.config, self.guard, mvp, positions, out);
    }

    /// Draws the triangles of `mesh` from vertices processed once per frame
    /// (entry `i` for `mesh.positions[i]`), skipping those wholly above or
    /// below the strip: the cheap way to draw a frame strip by strip.
    pub fn draw_mesh_processed(
        &mut self,
        mesh: &Mesh<'_>,
        first_id: u32,
        cache: &[ProcessedVertex],
    ) {
        let (top, bottom) = self.slab;
        let whole = self.strip.y0 == 0 && self.strip.y1 == self.config.height;
        let strip = &mut self.strip;
        let render = &mut self.render;
        let _ = triangles_processed::<S>(
            &self.config,
            self.guard,
            mesh,
            first_id,
            cache,
            &mut self.stats,
            |p| {
                !whole
                    && p.iter().all(|v| v.w > 0.0)
                    && (p.iter().all(|v| v.y > v.w * top) || p.iter().all(|v| v.y < v.w * bottom))
            },
            |t| {
                render.pixels_written += draw::<S, C, D>(&t, strip) as u64;
                true
            },
        );
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::color::TriangleId;
    use crate::frame::{Frame, MeshColors};
    use crate::math::Mat4;
    use crate::setup::SetupTriangle;

    #[test]
    fn processed_mesh_through_strips_equals_the_frame() {
        let positions: [Vec3; 8] = core::array::from_fn(|i| {
            let b = |k: usize| if i >> k & 1 == 1 { 1.0 } else { -1.0 };
            Vec3::new(b(0), b(1), b(2))
        });
        let indices = [
            [0, 2, 1],
            [1, 2, 3],
            [4, 5, 6],
            [5, 7, 6],
            [0, 1, 4],
            [1, 5, 4],
            [2, 6, 3],
            [3, 6, 7],
            [0, 4, 2],
            [2, 4, 6],
            [1, 3, 5],
            [3, 7, 5],
        ];
        let colors: [Rgb888; 8] = core::array::from_fn(|i| Rgb888::new(30 * i as u8, 200, 90));
        let mesh = Mesh {
            positions: &positions,
            indices: &indices,
            colors: MeshColors::PerVertex(&colors),
            bounds: None,
        };
        let mut config = Config::new(40, 30);
        config.cull = crate::CullMode::None;
        for angle in [0.3f32, 1.1, 2.6] {
            let mvp = Mat4::perspective(1.0, 40.0 / 30.0, 0.5, 9.0)
                * Mat4::translation(Vec3::new(0.2, -0.1, -3.5))
                * Mat4::rotation_y(angle)
                * Mat4::rotation_x(0.4);
            let mut st = [SetupTriangle::EMPTY; 64];
            let mut frame: Frame = Frame::new(config, &mut st).unwrap();
            frame.draw_mesh(&mesh, &mvp, 3).unwrap();
            let mut whole = [Rgb888::new(0, 0, 0); 40 * 30];
            let mut wz = [u16::MAX; 40 * 30];
            frame.render_rows(0, 30, &mut whole, &mut wz[..]).unwrap();
            let mut ids = [TriangleId(0); 40 * 30];
            frame
                .render_rows(0, 30, &mut ids, &mut crate::NoDepth)
                .unwrap();
            let mut cache = [ProcessedVertex::EMPTY; 8];
            for rows in [1u32, 4, 7, 30] {
                for y0 in (0..30).step_by(rows as usize) {
                    let y1 = (y0 + rows).min(30);
                    let n = (40 * (y1 - y0)) as usize;
                    let r = (40 * y0) as usize..(40 * y0) as usize + n;
                    let mut c = [Rgb888::new(0, 0, 0); 40 * 30];
                    let mut z = [u16::MAX; 40 * 30];
                    let mut s: StripRenderer<'_, _, _> =
                        StripRenderer::new(config, y0, y1, &mut c[..n], &mut z[..n]).unwrap();
                    s.process_vertices(&mvp, &positions, &mut cache);
                    s.draw_mesh_processed(&mesh, 3, &cache);
                    assert_eq!(&c[..n], &whole[r.clone()], "rows {y0}..{y1}");
                    assert_eq!(&z[..n], &wz[r], "rows {y0}..{y1}");
                }
            }
        }
    }
}
