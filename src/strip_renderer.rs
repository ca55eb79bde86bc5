//! Immediate strip rendering: no setup storage at all.
//!
//! Design note: [`Frame`](crate::Frame) sets every triangle up once and
//! keeps the result, which costs about a hundred bytes a triangle. Where RAM
//! is scarcer than cycles (a microcontroller drawing through a 16-row
//! buffer) [`StripRenderer`] instead runs each submitted triangle through
//! the same pipeline ([`Submit`](crate::Submit): transform, cull, clip, setup) and draws it
//! straight into the one strip it holds. The caller submits the scene once
//! per strip. The pixels are bit-identical to
//! [`Frame::render_rows`](crate::Frame::render_rows) for the same rows: it
//! is the same code in the same order, only without the store. Triangles
//! wholly above or below the strip are skipped before clipping and setup
//! (counted in [`Stats::outside_strip`]), so each strip pays the full
//! pipeline only for the triangles that reach it; a mesh whose bounding
//! sphere lies wholly above or below the strip is skipped before any of
//! its vertices is transformed (conservatively: no triangle of it could
//! be stored there).

use crate::color::PixelFormat;
use crate::config::{check_rect, check_size, Config, Error};
use crate::depth::DepthBuffer;
use crate::fixed::check_subpixel_bits;
use crate::pipeline::{__private::Sink, impl_submit, Stage};
use crate::raster::{draw, Strip, Touched};
use crate::setup::SetupTriangle;
use crate::shade::{FragmentShader, VertexColor};
use crate::stats::{RenderStats, Stats};

/// A strip renderer's sink: its rows, its fragment shader, and the pixels
/// written so far.
pub struct StripSink<'b, C, D: ?Sized, const S: u32, F = VertexColor> {
    pub(crate) strip: Strip<'b, C, D>,
    fragment: F,
    render: RenderStats,
}

impl<C, D: ?Sized, const S: u32, F> core::fmt::Debug for StripSink<'_, C, D, S, F> {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.debug_struct("StripSink")
            .field("rows", &(self.strip.y0..self.strip.y1))
            .field("render", &self.render)
            .finish()
    }
}

impl<
        C: PixelFormat,
        D: DepthBuffer + ?Sized,
        const S: u32,
        const N: usize,
        F: FragmentShader<N>,
    > Sink<N> for StripSink<'_, C, D, S, F>
{
    fn room(&self) -> usize {
        usize::MAX
    }
    fn capacity(&self) -> usize {
        usize::MAX
    }
    #[inline]
    fn take(&mut self, t: &SetupTriangle<N>) {
        self.render.pixels_written +=
            draw::<S, N, C, D, F>(t, &mut self.strip, &self.fragment) as u64;
    }
    #[inline]
    fn take_clipless(&mut self, t: &crate::clipless::ClipLessTriangle<N>) {
        self.render.pixels_written +=
            crate::clipless::draw::<N, C, D, F>(t, &mut self.strip, &self.fragment) as u64;
    }
}

/// Draws triangles straight into rows `y0..y1` of a frame, at `S` subpixel
/// bits, without storing them, with `N` varyings per vertex shaded by `F`
/// (by default a colour, [`VertexColor`]; see
/// [`StripRenderer::with_shader`]). Submit with
/// [`Submit`](crate::Submit)'s methods; they never return
/// [`Error::StorageFull`].
///
/// ```
/// use microraster::prelude::*;
/// use microraster::{Config, CullMode, NoDepth, StripRenderer, Vec4};
///
/// let mut config = Config::new(16, 16);
/// config.cull = CullMode::None;
/// let mut rows = [Rgb888::BLACK; 16 * 4];
/// let mut no_depth = NoDepth;
/// // Rows 8..12 of a 16x16 frame, no depth buffer.
/// let mut strip = StripRenderer::new(config, 8, 12, &mut rows, &mut no_depth).unwrap();
/// let v = |x, y| Vec4::new(x, y, 0.0, 1.0);
/// strip
///     .submit_clip_triangle([v(-1.0, -1.0), v(1.0, -1.0), v(-1.0, 1.0)], [Rgb888::RED; 3], 0)
///     .unwrap();
/// assert!(strip.render_stats().pixels_written > 0);
/// ```
pub struct StripRenderer<'b, C, D: ?Sized, const S: u32 = 8, const N: usize = 3, F = VertexColor> {
    pub(crate) stage: Stage,
    pub(crate) sink: StripSink<'b, C, D, S, F>,
    pub(crate) stats: Stats,
}

impl<C, D: ?Sized, const S: u32, const N: usize, F> core::fmt::Debug
    for StripRenderer<'_, C, D, S, N, F>
{
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.debug_struct("StripRenderer")
            .field("config", &self.stage.config)
            .field("sink", &self.sink)
            .field("stats", &self.stats)
            .finish()
    }
}

impl<'b, C: PixelFormat, D: DepthBuffer + ?Sized> StripRenderer<'b, C, D> {
    /// A renderer at the default 8 subpixel bits for rows `y0..y1` of a
    /// frame, drawing into `color` and `depth`, which hold exactly those
    /// rows. Buffers are drawn over, not cleared.
    pub fn new(
        config: Config,
        y0: u32,
        y1: u32,
        color: &'b mut [C],
        depth: &'b mut D,
    ) -> Result<Self, Error> {
        StripRenderer::with_subpixel_bits(config, y0, y1, color, depth)
    }
}

impl<'b, C: PixelFormat, D: DepthBuffer + ?Sized, const S: u32> StripRenderer<'b, C, D, S> {
    /// [`StripRenderer::new`] at `S` subpixel bits (4 or 8; anything else
    /// does not compile).
    pub fn with_subpixel_bits(
        config: Config,
        y0: u32,
        y1: u32,
        color: &'b mut [C],
        depth: &'b mut D,
    ) -> Result<Self, Error> {
        StripRenderer::with_shader(config, y0, y1, color, depth, VertexColor)
    }

    /// A renderer for the rectangle `[x0, x1, y0, y1]` (columns `x0..x1`,
    /// rows `y0..y1`) of a frame, drawing into `color` and `depth`, which
    /// hold exactly that rectangle, row by row: a tile. Any split of a
    /// frame into tiles gives the pixels of strips, in either mode.
    ///
    /// ```
    /// use microraster::prelude::*;
    /// use microraster::{Config, NoDepth, StripRenderer, Vec4};
    ///
    /// let mut tile = [Rgb888::BLACK; 4 * 4];
    /// let mut no_depth = NoDepth;
    /// // Columns 0..4 and rows 12..16 (bottom left) of a 16x16 frame.
    /// let mut r =
    ///     StripRenderer::<_, _, 8>::with_rect(Config::new(16, 16), [0, 4, 12, 16], &mut tile, &mut no_depth)
    ///         .unwrap();
    /// let v = |x, y| Vec4::new(x, y, 0.0, 1.0);
    /// r.submit_clip_triangle([v(-1.0, -1.0), v(1.0, -1.0), v(-1.0, 1.0)], [Rgb888::RED; 3], 0)
    ///     .unwrap();
    /// assert_eq!(r.render_stats().pixels_written, 4 * 4);
    /// ```
    pub fn with_rect(
        config: Config,
        rect: [u32; 4],
        color: &'b mut [C],
        depth: &'b mut D,
    ) -> Result<Self, Error> {
        StripRenderer::with_shader_rect(config, rect, color, depth, VertexColor)
    }
}

impl<'b, C: PixelFormat, D: DepthBuffer + ?Sized, const S: u32, const N: usize, F>
    StripRenderer<'b, C, D, S, N, F>
where
    F: FragmentShader<N>,
{
    /// A renderer like [`StripRenderer::with_subpixel_bits`] whose pixels
    /// are coloured by the fragment shader `fragment` from `N` varyings
    /// per vertex (see [`crate::shade`]), e.g.
    /// `StripRenderer::<_, _, 8, 5, _>::with_shader(.., Textured { texture })`.
    pub fn with_shader(
        config: Config,
        y0: u32,
        y1: u32,
        color: &'b mut [C],
        depth: &'b mut D,
        fragment: F,
    ) -> Result<Self, Error> {
        StripRenderer::with_shader_rect(config, [0, config.width, y0, y1], color, depth, fragment)
    }

    /// [`StripRenderer::with_rect`] with the fragment shader `fragment`.
    pub fn with_shader_rect(
        config: Config,
        rect: [u32; 4],
        color: &'b mut [C],
        depth: &'b mut D,
        fragment: F,
    ) -> Result<Self, Error> {
        const { check_subpixel_bits::<S>() };
        check_size(&config)?;
        if config.mode == crate::config::RasterMode::Clipless && !cfg!(feature = "clipless") {
            return Err(Error::ModeUnsupported);
        }
        check_rect(&config, rect, color.len(), depth.depth_len())?;
        let [x0, x1, y0, y1] = rect;
        let whole = y0 == 0 && y1 == config.height;
        let h = config.height as f32;
        let slab = (!whole).then(|| {
            (
                1.0 - 2.0 * (y0 as f32 + 0.25) / h,
                1.0 - 2.0 * (y1 as f32 - 0.25) / h,
            )
        });
        Ok(StripRenderer {
            stage: Stage::new::<S>(config, slab),
            sink: StripSink {
                strip: Strip {
                    width: (x1 - x0) as usize,
                    x0,
                    x1,
                    y0,
                    y1,
                    color,
                    depth,
                    depth_func: config.depth_func,
                    depth_write: config.depth_write,
                    touched: Touched::NONE,
                    track: false,
                    #[cfg(feature = "lazy-clear")]
                    lazy: None,
                    spans: [[0; 3]; crate::raster::ROW_BATCH],
                },
                fragment,
                render: RenderStats::default(),
            },
            stats: Stats::default(),
        })
    }

    /// The frame's settings.
    pub fn config(&self) -> &Config {
        &self.stage.config
    }

    /// Counters of the triangles submitted so far (to this strip).
    pub fn stats(&self) -> Stats {
        self.stats
    }

    /// Pixels written so far.
    pub fn render_stats(&self) -> RenderStats {
        self.sink.render
    }

    /// Keeps the box of the pixels written from now on (for
    /// [`crate::StripDrawer`]'s clears).
    pub(crate) fn track_touched(&mut self) {
        self.sink.strip.track = true;
    }

    /// The box of the pixels written since [`StripRenderer::track_touched`].
    pub(crate) fn touched(&self) -> Touched {
        self.sink.strip.touched
    }
}

impl_submit!(
    ['b, C: PixelFormat, D: DepthBuffer + ?Sized, const S: u32, const N: usize, F: FragmentShader<N>]
    StripRenderer<'b, C, D, S, N, F>,
    StripSink<'b, C, D, S, F>,
    sink
);

#[cfg(test)]
mod tests {
    use super::*;
    use crate::color::TriangleId;
    use crate::frame::Frame;
    use crate::math::{Mat4, Vec3};
    use crate::mesh::{Mesh, MeshColors, ProcessedVertex};
    use crate::pipeline::Submit;
    use embedded_graphics_core::pixelcolor::Rgb888;

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
            attributes: MeshColors::PerVertex(&colors),
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
            frame.submit_mesh(&mesh, &mvp, 3).unwrap();
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
                    let mut s =
                        StripRenderer::new(config, y0, y1, &mut c[..n], &mut z[..n]).unwrap();
                    s.process_vertices(&mvp, &positions, &mut cache);
                    s.submit_processed_mesh(&mesh, 3, &cache).unwrap();
                    assert_eq!(&c[..n], &whole[r.clone()], "rows {y0}..{y1}");
                    assert_eq!(&z[..n], &wz[r], "rows {y0}..{y1}");
                }
            }
        }
    }
}
