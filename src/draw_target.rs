//! embedded-graphics output: a frame through a strip buffer into any
//! [`DrawTarget`].
//!
//! Design note: a display driver wants whole rectangles of pixels, and the
//! firmware has RAM for a few rows, not a frame. [`StripDrawer`] holds the
//! caller's strip buffers (colour, and depth or [`NoDepth`])
//! and walks a frame top to bottom: for each strip it clears the buffers,
//! draws the rows into them, and pushes them to the target with **one**
//! [`DrawTarget::fill_contiguous`] over the strip's rectangle (a display
//! driver turns that into one address window and one burst of pixel data).
//! A display whose driver hands the buffer to a DMA engine implements
//! [`StripSink`] instead and gets each strip as the slice itself (every
//! `DrawTarget` is a `StripSink` through a blanket implementation).
//! The target's error is handed back unchanged in [`DrawError::Target`];
//! the renderer's own errors (a buffer too small for one row, a bad frame
//! size) in [`DrawError::Render`], before anything is drawn.
//!
//! Two ways to feed it, the same pixels either way:
//!
//! - [`StripDrawer::draw`] is immediate mode: a closure submits the scene to
//!   a [`StripRenderer`] once per strip. No setup storage at all: the
//!   RAM-starved path (the Cortex-M0 example renders 320x240 in 16 KB).
//! - [`StripDrawer::draw_frame`] renders an already set-up [`Frame`], which
//!   costs setup storage but sets each triangle up once.
//!
//! Colours: the strip buffer holds pixels of any [`PixelFormat`] type `P` and the
//! target's colour must convert from it (`T::Color: From<P>`). With `P` the
//! target's own colour (`Rgb565`, `Rgb888`, `Gray8`, `BinaryColor`) that is
//! the identity, and each fragment was converted once, from the rasterizer's
//! `Rgb888`, with embedded-graphics' `From<Rgb888>`: `Rgb565` rounds each
//! channel to 5/6/5 bits (`round(v * 31 / 255)`, `round(v * 63 / 255)`),
//! `Gray8` is the BT.601 luma, `BinaryColor` is on when that luma is at
//! least 128. A wider buffer (`Rgb888`) into a narrower target converts at
//! push time with the same `From`, so the pixels are the same.

use crate::color::PixelFormat;
use crate::config::{Config, Error};
use crate::depth::{DepthBuffer, DepthWord, NoDepth};
use crate::fixed::SUBPIXEL_BITS;
use crate::frame::Frame;
use crate::raster::Touched;
use crate::shade::VertexColor;
use crate::stats::RenderStats;
use crate::strip_renderer::StripRenderer;
use embedded_graphics_core::draw_target::DrawTarget;
use embedded_graphics_core::geometry::{Point, Size};
use embedded_graphics_core::primitives::Rectangle;

/// What stopped a [`StripDrawer`]: the renderer, or the target.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum DrawError<E> {
    /// The renderer refused the frame or the buffers; nothing was drawn.
    Render(Error),
    /// The target's own error, from `fill_contiguous`; the strips above
    /// the failing one were pushed, nothing after it.
    Target(E),
}

impl<E> From<Error> for DrawError<E> {
    fn from(e: Error) -> Self {
        DrawError::Render(e)
    }
}

impl<E: core::fmt::Display> core::fmt::Display for DrawError<E> {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            DrawError::Render(e) => write!(f, "render: {e}"),
            DrawError::Target(e) => write!(f, "draw target: {e}"),
        }
    }
}

impl<E: core::error::Error + 'static> core::error::Error for DrawError<E> {
    fn source(&self) -> Option<&(dyn core::error::Error + 'static)> {
        match self {
            DrawError::Render(e) => Some(e),
            DrawError::Target(e) => Some(e),
        }
    }
}

/// Where a [`StripDrawer`] sends each finished strip: any [`DrawTarget`]
/// whose colour converts from the strip's pixels (one `fill_contiguous`
/// per strip, converting each pixel with `From`), or a display of your own
/// that takes the strip buffer as it is.
///
/// Implement it for a driver that hands the buffer to a DMA engine: it
/// gets the strip as a slice, with no per-pixel iterator in between (the
/// Cortex-M firmware's display stand-in checksums the slice two pixels a
/// word, at a third of what the same checksum costs behind
/// `fill_contiguous`). A type that implements `DrawTarget` gets this trait
/// from the blanket implementation, so implement it only for types that
/// are not draw targets.
///
/// ```
/// use embedded_graphics_core::primitives::Rectangle;
/// use microraster::pixelcolor::{IntoStorage, Rgb565, Rgb888, RgbColor};
/// use microraster::{Config, CullMode, StripDrawer, StripSink, Submit, Vec4};
///
/// /// Sums the strips' raw words, as a DMA engine with a CRC unit would.
/// struct DmaDisplay {
///     sum: u32,
///     next_row: u32,
/// }
///
/// impl StripSink<Rgb565> for DmaDisplay {
///     type Error = &'static str;
///     fn push_strip(&mut self, area: &Rectangle, pixels: &[Rgb565]) -> Result<(), Self::Error> {
///         if area.top_left.y != self.next_row as i32 {
///             return Err("out of order");
///         }
///         for p in pixels {
///             self.sum = self.sum.wrapping_add(p.into_storage() as u32);
///         }
///         self.next_row += area.size.height;
///         Ok(())
///     }
/// }
///
/// let mut color = [Rgb565::BLACK; 24 * 4];
/// let mut depth = [0u16; 24 * 4];
/// let mut display = DmaDisplay { sum: 0, next_row: 0 };
/// let mut config = Config::new(24, 16);
/// config.cull = CullMode::None;
/// StripDrawer::new(&mut color, &mut depth, Rgb565::BLACK)
///     .draw(&mut display, config, |strip| {
///         let v = |x, y| Vec4::new(x, y, 0.5, 1.0);
///         let tri = [v(-1.0, -1.0), v(1.0, -1.0), v(-1.0, 1.0)];
///         strip.submit_clip_triangle(tri, [Rgb888::RED; 3], 0).unwrap();
///     })
///     .unwrap();
/// // Four strips arrived in order; half of the 384 pixels are red.
/// assert_eq!(display.next_row, 16);
/// assert_eq!(display.sum, 192 * Rgb565::RED.into_storage() as u32);
/// ```
pub trait StripSink<P> {
    /// What a failed push returns ([`DrawError::Target`]).
    type Error;
    /// Takes the strip `area` of the frame (the frame's rows `y0..y1` at
    /// the drawer's origin: `area.size.width` pixels a row), whose
    /// pixels are `pixels`, row by row, top to bottom.
    fn push_strip(&mut self, area: &Rectangle, pixels: &[P]) -> Result<(), Self::Error>;
}

impl<P: Copy, T: DrawTarget> StripSink<P> for T
where
    T::Color: From<P>,
{
    type Error = T::Error;
    /// One `fill_contiguous` over the strip's rectangle.
    fn push_strip(&mut self, area: &Rectangle, pixels: &[P]) -> Result<(), T::Error> {
        self.fill_contiguous(area, pixels.iter().map(|&p| T::Color::from(p)))
    }
}

/// The depth strip of a [`StripDrawer`]: `&mut [u16]`, `&mut [u32]`
/// (or arrays of them), or [`NoDepth`] by value.
pub trait StripDepth {
    /// What the rasterizer draws into: `[u16]`, `[u32]` or [`NoDepth`].
    type Rows: DepthBuffer + ?Sized;

    /// The number of depth values held, `None` without a buffer.
    fn held(&self) -> Option<usize>;

    /// The first `len` values, each set to the depth `z32` (`Z32`; a `u16`
    /// buffer keeps its top 16 bits), or `None` if fewer are held.
    fn cleared(&mut self, len: usize, z32: u32) -> Option<&mut Self::Rows>;

    /// [`StripDepth::cleared`], and `color` filled with `background`
    /// (all of it; neither is touched where `None` is returned).
    fn cleared_with<P: Copy>(
        &mut self,
        len: usize,
        z32: u32,
        color: &mut [P],
        background: P,
    ) -> Option<&mut Self::Rows> {
        let rows = self.cleared(len, z32)?;
        color.fill(background);
        Some(rows)
    }

    /// The first `len` values, after the rectangle `rect = [x0, x1, r0,
    /// r1]` (columns `x0..x1` of rows `r0..r1`, `width` values a row; it
    /// may reach past `len`) is set to the depth `z32`, and the same
    /// values of `color` to `background`: [`StripDrawer`]'s clear of what
    /// the last strip wrote, where everything else already holds those
    /// values. `None` (nothing cleared) if fewer than `len` are held. The
    /// default ignores the rectangle and clears as
    /// [`StripDepth::cleared_with`], which is always right.
    fn cleared_rect<P: Copy>(
        &mut self,
        len: usize,
        z32: u32,
        color: &mut [P],
        background: P,
        width: usize,
        rect: [usize; 4],
    ) -> Option<&mut Self::Rows> {
        let _ = (width, rect);
        self.cleared_with(len, z32, color, background)
    }
}

/// The runs of the rectangle `[x0, x1, r0, r1]` of a layout `width`
/// values a row, as `(count, first, stride, len)`: one run where it spans
/// whole rows, else one a row.
#[inline]
fn rect_runs(width: usize, [x0, x1, r0, r1]: [usize; 4]) -> (usize, usize, usize, usize) {
    if width == 0 {
        return (0, 0, 0, 0);
    }
    match x0 == 0 && x1 == width {
        true => (
            1,
            r0.saturating_mul(width),
            0,
            r1.saturating_sub(r0).saturating_mul(width),
        ),
        false => (
            r1.saturating_sub(r0),
            r0.saturating_mul(width).saturating_add(x0),
            width,
            x1.saturating_sub(x0),
        ),
    }
}

/// [`StripDepth::cleared_rect`] of both slice impls: the rectangle of
/// `depth` and `color` (in one pass where it spans whole rows).
fn clear_rect_prefix<'a, W: DepthWord, P: Copy>(
    depth: &'a mut [W],
    len: usize,
    z32: u32,
    (color, background): (&mut [P], P),
    width: usize,
    rect: [usize; 4],
) -> Option<&'a mut [W]> {
    if depth.len() < len {
        return None;
    }
    let z = W::from_z32(z32);
    let (n, first, stride, run) = rect_runs(width, rect);
    let end = depth.len().max(color.len());
    let mut a = first;
    for _ in 0..n {
        if a >= end {
            break;
        }
        let b = a.saturating_add(run);
        match (depth.get_mut(a..b), color.get_mut(a..b)) {
            (Some(d), Some(c)) => clear_both(d, z, c, background),
            // Past either buffer (the drawer never asks for that): as far
            // as each reaches.
            _ => {
                let (dl, cl) = (depth.len(), color.len());
                depth[a.min(dl)..b.min(dl)].fill(z);
                color[a.min(cl)..b.min(cl)].fill(background);
            }
        }
        a = a.saturating_add(stride);
    }
    depth.get_mut(..len)
}

/// The first `len` values of `depth` set to `z32` (and `color` filled, in
/// the same pass, when given), or `None` (nothing cleared) if fewer are
/// held: both slice impls of [`StripDepth`].
fn clear_prefix<'a, W: DepthWord, P: Copy>(
    depth: &'a mut [W],
    len: usize,
    z32: u32,
    color: Option<(&mut [P], P)>,
) -> Option<&'a mut [W]> {
    let rows = depth.get_mut(..len)?;
    match color {
        Some((color, background)) => clear_both(rows, W::from_z32(z32), color, background),
        None => rows.fill(W::from_z32(z32)),
    }
    Some(rows)
}

/// Fills `depth` with `z` and `color` with `c` in one pass: a block of
/// eight of each per iteration, so one loop's counting serves both (on
/// the Cortex-M4F the four-cubes frame takes 76 k instructions fewer than
/// with a `fill` and a `memset`: the clears cost 91 k, strip loop
/// included). The same values as two `fill`s.
#[inline]
fn clear_both<W: Copy, P: Copy>(depth: &mut [W], z: W, color: &mut [P], c: P) {
    if depth.len() != color.len() {
        depth.fill(z);
        color.fill(c);
        return;
    }
    let mut d8 = depth.chunks_exact_mut(8);
    let mut c8 = color.chunks_exact_mut(8);
    for (d, p) in (&mut d8).zip(&mut c8) {
        d.fill(z);
        p.fill(c);
    }
    d8.into_remainder().fill(z);
    c8.into_remainder().fill(c);
}

/// The three clears of both slice impls of [`StripDepth`] (a slice and
/// an array), the same code.
macro_rules! slice_clears {
    () => {
        fn cleared(&mut self, len: usize, z32: u32) -> Option<&mut [W]> {
            clear_prefix::<W, ()>(&mut self[..], len, z32, None)
        }
        fn cleared_with<P: Copy>(
            &mut self,
            len: usize,
            z32: u32,
            color: &mut [P],
            background: P,
        ) -> Option<&mut [W]> {
            clear_prefix(&mut self[..], len, z32, Some((color, background)))
        }
        fn cleared_rect<P: Copy>(
            &mut self,
            len: usize,
            z32: u32,
            color: &mut [P],
            background: P,
            width: usize,
            rect: [usize; 4],
        ) -> Option<&mut [W]> {
            clear_rect_prefix(&mut self[..], len, z32, (color, background), width, rect)
        }
    };
}

impl<W: DepthWord> StripDepth for &mut [W] {
    type Rows = [W];
    fn held(&self) -> Option<usize> {
        Some(self.len())
    }
    slice_clears!();
}

impl<W: DepthWord, const N: usize> StripDepth for &mut [W; N] {
    type Rows = [W];
    fn held(&self) -> Option<usize> {
        Some(N)
    }
    slice_clears!();
}

impl StripDepth for NoDepth {
    type Rows = NoDepth;
    fn held(&self) -> Option<usize> {
        None
    }
    fn cleared(&mut self, _: usize, _: u32) -> Option<&mut NoDepth> {
        Some(self)
    }
    /// The colour in blocks of eight, as `clear_both` clears: a loop of
    /// its own, not the `fill` a `NoDepth` span shares (on the Cortex-M4F
    /// the shared, general `fill` made the four-cubes clears 33 k
    /// instructions dearer). The same values as `fill`.
    fn cleared_with<P: Copy>(
        &mut self,
        _: usize,
        _: u32,
        color: &mut [P],
        background: P,
    ) -> Option<&mut NoDepth> {
        let mut c8 = color.chunks_exact_mut(8);
        for p in &mut c8 {
            p.fill(background);
        }
        c8.into_remainder().fill(background);
        Some(self)
    }
    fn cleared_rect<P: Copy>(
        &mut self,
        _: usize,
        _: u32,
        color: &mut [P],
        background: P,
        width: usize,
        rect: [usize; 4],
    ) -> Option<&mut NoDepth> {
        // Each run by `cleared_with`'s loop (a shared `fill` costs more).
        let (n, first, stride, run) = rect_runs(width, rect);
        let cl = color.len();
        for k in 0..n {
            let a = first.saturating_add(k.saturating_mul(stride));
            if a >= cl {
                break;
            }
            let b = a.saturating_add(run);
            self.cleared_with(0, 0, &mut color[a.min(cl)..b.min(cl)], background);
        }
        Some(self)
    }
}

/// Draws frames into a [`DrawTarget`] (or any [`StripSink`]) through a
/// strip buffer of `P` pixels
/// and a depth strip `D` (`&mut [u16]`, `&mut [u32]` or [`NoDepth`]).
///
/// The strip holds `color.len() / width` rows of a frame `width` pixels
/// wide (the last strip of a frame may be shorter); the depth strip must
/// hold at least as many values as the colour strip uses. Both are cleared
/// before each strip: colour to the background, depth to the far plane
/// (`u32::MAX` in `Z32`, see [`StripDrawer::with_clear_depth`]).
///
/// ```
/// use embedded_graphics::{mock_display::MockDisplay, prelude::Point};
/// use microraster::pixelcolor::{Rgb565, Rgb888, RgbColor};
/// use microraster::{Config, CullMode, StripDrawer, Submit, Vec4};
///
/// // A 24x16 frame drawn 4 rows at a time: the strip buffers hold 4 rows.
/// let mut color = [Rgb565::BLACK; 24 * 4];
/// let mut depth = [0u16; 24 * 4];
/// let mut drawer = StripDrawer::new(&mut color, &mut depth, Rgb565::BLACK);
///
/// let mut display = MockDisplay::<Rgb565>::new(); // fails on overdraw
/// let mut config = Config::new(24, 16);
/// config.cull = CullMode::None;
/// let stats = drawer
///     .draw(&mut display, config, |strip| {
///         // Called once per strip: submit the whole scene each time.
///         let v = |x, y| Vec4::new(x, y, 0.5, 1.0);
///         strip.submit_clip_triangle([v(-1.0, -1.0), v(1.0, -1.0), v(-1.0, 1.0)], [Rgb888::RED; 3], 0)
///             .unwrap();
///     })
///     .unwrap();
///
/// // The lower-left half is red; every pixel was pushed exactly once.
/// assert_eq!(stats.pixels_written, 24 * 16 / 2);
/// assert_eq!(display.get_pixel(Point::new(0, 15)), Some(Rgb565::RED));
/// assert_eq!(display.get_pixel(Point::new(23, 0)), Some(Rgb565::BLACK));
/// ```
pub struct StripDrawer<'b, P, D> {
    color: &'b mut [P],
    depth: D,
    background: P,
    clear_z32: u32,
    origin: Point,
    /// `Some((width, rect))`: laid out `width` pixels a row, both buffers
    /// hold their clear values everywhere but in `rect` (`[x0, x1, r0,
    /// r1]`, what the last strip wrote); `None`: unknown.
    clean: Option<(usize, [usize; 4])>,
    /// Pixels cleared so far.
    cleared: u64,
}

impl<P, D> core::fmt::Debug for StripDrawer<'_, P, D> {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.debug_struct("StripDrawer")
            .field("color_len", &self.color.len())
            .field("clear_z32", &self.clear_z32)
            .field("origin", &self.origin)
            .finish()
    }
}

impl<'b, P: PixelFormat, D: StripDepth> StripDrawer<'b, P, D> {
    /// A drawer with the strip buffers `color` and `depth` (pass
    /// `&mut depth` or [`NoDepth`]), clearing colour to
    /// `background`. Frames land at the target's `(0, 0)`.
    pub fn new(color: &'b mut [P], depth: D, background: P) -> Self {
        StripDrawer {
            color,
            depth,
            background,
            clear_z32: u32::MAX,
            origin: Point::zero(),
            clean: None,
            cleared: 0,
        }
    }

    /// Places the frame's top-left pixel at `origin` of the target (what
    /// falls outside the target is the target's to clip).
    pub fn with_origin(mut self, origin: Point) -> Self {
        self.origin = origin;
        self
    }

    /// Clears depth to `z32` (`Z32`) instead of the far plane, e.g. `0`
    /// for [`DepthFunc::Greater`](crate::DepthFunc::Greater).
    pub fn with_clear_depth(mut self, z32: u32) -> Self {
        self.clear_z32 = z32;
        self.clean = None;
        self
    }

    /// Pixels cleared so far (colour and depth, each pixel once). A strip
    /// is cleared where the strip before it wrote, not whole: the buffers
    /// are the drawer's alone, so everything else still holds the
    /// background and the far depth. The first strip after
    /// [`StripDrawer::new`], [`StripDrawer::with_clear_depth`], a change of
    /// frame width or [`StripDrawer::draw_frame_tiles`] clears every row
    /// the buffers hold.
    pub fn pixels_cleared(&self) -> u64 {
        self.cleared
    }

    /// The rows per strip for a frame `width` pixels wide (0 if the colour
    /// buffer cannot hold one row).
    pub fn strip_rows(&self, width: u32) -> u32 {
        match width {
            0 => 0,
            w => (self.color.len() / w as usize).min(u32::MAX as usize) as u32,
        }
    }

    /// Renders a `config.width x config.height` frame in immediate mode:
    /// for each strip, `scene` submits every triangle to a
    /// [`StripRenderer`] for those rows, then the strip is pushed to
    /// `target`. The scene must submit the same triangles each time.
    /// Draws at the default [`SUBPIXEL_BITS`]; see
    /// [`StripDrawer::draw_subpixel`] for 4.
    pub fn draw<T, F>(
        &mut self,
        target: &mut T,
        config: Config,
        scene: F,
    ) -> Result<RenderStats, DrawError<T::Error>>
    where
        T: StripSink<P>,
        F: FnMut(&mut StripRenderer<'_, P, D::Rows, SUBPIXEL_BITS>),
    {
        self.draw_subpixel::<T, F, SUBPIXEL_BITS>(target, config, scene)
    }

    /// [`StripDrawer::draw`] at `S` subpixel bits (4 or 8).
    pub fn draw_subpixel<T, F, const S: u32>(
        &mut self,
        target: &mut T,
        config: Config,
        mut scene: F,
    ) -> Result<RenderStats, DrawError<T::Error>>
    where
        T: StripSink<P>,
        F: FnMut(&mut StripRenderer<'_, P, D::Rows, S>),
    {
        self.for_each_strip(target, config, |y0, y1, color, depth| {
            let mut strip =
                StripRenderer::<P, D::Rows, S>::with_subpixel_bits(config, y0, y1, color, depth)?;
            strip.track_touched();
            scene(&mut strip);
            Ok((strip.render_stats(), strip.touched()))
        })
    }

    /// [`StripDrawer::draw_subpixel`] with `N` varyings per vertex coloured
    /// by `fragment` (see [`crate::shade`] and
    /// [`StripRenderer::with_shader`]): lit or textured meshes in immediate
    /// mode.
    pub fn draw_shaded<T, F, Sh, const S: u32, const N: usize>(
        &mut self,
        target: &mut T,
        config: Config,
        fragment: Sh,
        mut scene: F,
    ) -> Result<RenderStats, DrawError<T::Error>>
    where
        T: StripSink<P>,
        Sh: crate::shade::FragmentShader<N> + Copy,
        F: FnMut(&mut StripRenderer<'_, P, D::Rows, S, N, Sh>),
    {
        self.for_each_strip(target, config, |y0, y1, color, depth| {
            let mut strip = StripRenderer::<P, D::Rows, S, N, Sh>::with_shader(
                config, y0, y1, color, depth, fragment,
            )?;
            strip.track_touched();
            scene(&mut strip);
            Ok((strip.render_stats(), strip.touched()))
        })
    }

    /// Renders a set-up [`Frame`] strip by strip into `target` (see
    /// [`Frame::render_rows`]).
    pub fn draw_frame<T, const S: u32>(
        &mut self,
        target: &mut T,
        frame: &Frame<'_, S>,
    ) -> Result<RenderStats, DrawError<T::Error>>
    where
        T: StripSink<P>,
    {
        let width = frame.config().width;
        self.for_each_strip(target, *frame.config(), |y0, y1, color, depth| {
            frame.render_rect_touched([0, width, y0, y1], color, depth, &VertexColor)
        })
    }

    /// Renders a set-up [`Frame`] tile by tile into a target that takes
    /// windowed writes: `bins` from [`Frame::bin_tiles`] (or
    /// [`Frame::bin`]), each tile cleared, drawn from its bin
    /// ([`Frame::render_tile`]) and pushed as its own rectangle, in tile
    /// order. The buffers need to hold one tile (`tile_w x tile_h`), not a
    /// strip: less RAM than strips for the same frame, which is the same
    /// pixel for pixel. [`Error::BinsMismatch`] (as
    /// [`DrawError::Render`]) if `bins` were made for another frame.
    ///
    /// (Its buffer checks and clears repeat [`StripDrawer::draw`]'s on
    /// purpose: one shared helper for both cost the Cortex-M4F's four-cubes
    /// frame 37,000 more instructions, through how the whole frame
    /// inlines.)
    pub fn draw_frame_tiles<T, const S: u32>(
        &mut self,
        target: &mut T,
        frame: &Frame<'_, S>,
        bins: &crate::Bins<'_>,
    ) -> Result<RenderStats, DrawError<T::Error>>
    where
        T: StripSink<P>,
    {
        let tile = bins.tile_width() as usize * bins.strip_rows() as usize;
        if self.color.len() < tile {
            return Err(Error::ColorBufferSize {
                expected: tile,
                actual: self.color.len(),
            }
            .into());
        }
        if let Some(actual) = self.depth.held() {
            if actual < tile {
                return Err(Error::DepthBufferSize {
                    expected: tile,
                    actual,
                }
                .into());
            }
        }
        // Tiles lay the buffers out otherwise: cleared whole, as unknown.
        self.clean = None;
        let mut total = RenderStats::default();
        for t in 0..bins.tiles() {
            let [x0, x1, y0, y1] = bins.rect(t);
            let len = (x1 - x0) as usize * (y1 - y0) as usize;
            let color_len = self.color.len();
            let Some((color, depth)) = self.color.get_mut(..len).and_then(|color| {
                let depth = self
                    .depth
                    .cleared_with(len, self.clear_z32, color, self.background)?;
                Some((color, depth))
            }) else {
                // Unreachable: both were checked to hold a whole tile.
                return Err(Error::ColorBufferSize {
                    expected: len,
                    actual: color_len,
                }
                .into());
            };
            self.cleared = self.cleared.saturating_add(len as u64);
            let stats = frame.render_tile(bins, t, color, depth)?;
            total.pixels_written += stats.pixels_written;
            // Tile corners are below 2^14; saturating keeps an absurd
            // origin from overflowing.
            let top = Point::new(
                self.origin.x.saturating_add(x0 as i32),
                self.origin.y.saturating_add(y0 as i32),
            );
            let area = Rectangle::new(top, Size::new(x1 - x0, y1 - y0));
            target.push_strip(&area, color).map_err(DrawError::Target)?;
        }
        Ok(total)
    }

    /// [`StripDrawer::draw_frame`] for a frame of `N` varyings, coloured
    /// by `fragment` (see [`Frame::render_rows_shaded`]).
    pub fn draw_frame_shaded<T, const S: u32, const N: usize, F>(
        &mut self,
        target: &mut T,
        frame: &Frame<'_, S, N>,
        fragment: &F,
    ) -> Result<RenderStats, DrawError<T::Error>>
    where
        T: StripSink<P>,
        F: crate::shade::FragmentShader<N>,
    {
        let width = frame.config().width;
        self.for_each_strip(target, *frame.config(), |y0, y1, color, depth| {
            frame.render_rect_touched([0, width, y0, y1], color, depth, fragment)
        })
    }

    /// The strip loop shared by both modes: check, then per strip clear
    /// (what the last strip wrote), render (`render(y0, y1, color,
    /// depth)`, which returns the box of what it wrote) and push.
    fn for_each_strip<T, R>(
        &mut self,
        target: &mut T,
        config: Config,
        mut render: R,
    ) -> Result<RenderStats, DrawError<T::Error>>
    where
        T: StripSink<P>,
        R: FnMut(u32, u32, &mut [P], &mut D::Rows) -> Result<(RenderStats, Touched), Error>,
    {
        crate::config::check_size(&config)?;
        let (width, height) = (config.width, config.height);
        let rows = self.strip_rows(width).min(height);
        let full = width as usize * rows as usize;
        if rows == 0 {
            return Err(Error::ColorBufferSize {
                expected: width as usize,
                actual: self.color.len(),
            }
            .into());
        }
        if let Some(actual) = self.depth.held() {
            if actual < full {
                return Err(Error::DepthBufferSize {
                    expected: full,
                    actual,
                }
                .into());
            }
        }
        let mut total = RenderStats::default();
        let mut y0 = 0;
        while y0 < height {
            let y1 = y0.saturating_add(rows).min(height);
            let len = width as usize * (y1 - y0) as usize;
            let color_len = self.color.len();
            // What the last strip wrote, or (unknown) every row held.
            let w = width as usize;
            let rect = match self.clean.take() {
                Some((cw, rect)) if cw == w => rect,
                _ => [0, w, 0, color_len / w],
            };
            let depth = self.depth.cleared_rect(
                len,
                self.clear_z32,
                &mut *self.color,
                self.background,
                w,
                rect,
            );
            let (Some(depth), Some(color)) = (depth, self.color.get_mut(..len)) else {
                // Unreachable: both were checked to hold `full >= len`.
                return Err(Error::ColorBufferSize {
                    expected: len,
                    actual: color_len,
                }
                .into());
            };
            let cleared = (rect[1] - rect[0]) as u64 * (rect[3] - rect[2]) as u64;
            self.cleared = self.cleared.saturating_add(cleared);
            let (stats, touched) = render(y0, y1, color, depth)?;
            // Columns widened to multiples of eight (the clears' blocks),
            // so no row ends in a partial block.
            let [x0, x1, r0, r1] = touched.within([0, width, y0, y1]);
            let rect = [x0 & !7, ((x1 + 7) & !7).min(w), r0, r1];
            self.clean = Some((w, rect));
            total.pixels_written += stats.pixels_written;
            // y0 < 2^14; saturating keeps an absurd origin from overflowing.
            let top = Point::new(self.origin.x, self.origin.y.saturating_add(y0 as i32));
            let area = Rectangle::new(top, Size::new(width, y1 - y0));
            target.push_strip(&area, color).map_err(DrawError::Target)?;
            y0 = y1;
        }
        Ok(total)
    }
}

#[cfg(test)]
mod tests {
    extern crate std;

    use super::*;
    use crate::config::CullMode;
    use crate::math::Vec4;
    use crate::pipeline::Submit;
    use crate::setup::SetupTriangle;
    use embedded_graphics::mock_display::{ColorMapping, MockDisplay};
    use embedded_graphics_core::pixelcolor::{
        BinaryColor, Gray8, GrayColor, PixelColor, Rgb565, Rgb888, RgbColor,
    };
    use embedded_graphics_core::Pixel as EgPixel;
    use embedded_graphics_core::{geometry::OriginDimensions, prelude::Dimensions};
    use std::vec;
    use std::vec::Vec;

    /// The one-pass clear sets every value of both buffers, whatever
    /// their lengths (a multiple of eight or not, equal or not).
    #[test]
    fn clear_both_fills_everything() {
        for (nd, nc) in [
            (0, 0),
            (1, 1),
            (7, 7),
            (8, 8),
            (21, 21),
            (64, 64),
            (5, 9),
            (17, 3),
        ] {
            let mut d = vec![1u16; nd];
            let mut c = vec![2u8; nc];
            clear_both(&mut d, 7, &mut c, 9);
            assert!(
                d.iter().all(|&v| v == 7) && c.iter().all(|&v| v == 9),
                "{nd} {nc}"
            );
        }
    }

    const W: u32 = 48;
    const H: u32 = 40;

    fn v(x: f32, y: f32, z: f32) -> Vec4 {
        Vec4::new(x, y, z, 1.0)
    }

    /// Overlapping triangles at different depths, one Gouraud, one leaving
    /// the frame, submitted to anything that takes clip-space triangles.
    fn scene(mut push: impl FnMut([Vec4; 3], [Rgb888; 3], u32)) {
        push(
            [v(-0.9, -0.8, 0.5), v(0.7, -0.9, 0.5), v(-0.2, 0.9, 0.5)],
            [Rgb888::RED, Rgb888::GREEN, Rgb888::BLUE],
            0,
        );
        push(
            [v(-0.3, -1.4, 0.2), v(1.3, 0.1, 0.9), v(0.1, 0.7, -0.3)],
            [Rgb888::YELLOW; 3],
            1,
        );
        push(
            [v(-1.0, 0.6, 0.0), v(-0.6, 0.1, 0.0), v(-0.4, 1.0, 0.0)],
            [Rgb888::WHITE; 3],
            2,
        );
    }

    fn config() -> Config {
        let mut c = Config::new(W, H);
        c.cull = CullMode::None;
        c
    }

    /// The frame rendered in one piece with [`Frame::render_rows`].
    fn reference<P: PixelFormat>(background: P) -> Vec<P> {
        let mut storage = [SetupTriangle::EMPTY; 16];
        let mut frame: Frame = Frame::new(config(), &mut storage).unwrap();
        scene(|p, c, id| frame.submit_clip_triangle(p, c, id).unwrap());
        let mut color = vec![background; (W * H) as usize];
        let mut depth = vec![u16::MAX; (W * H) as usize];
        frame.render_rows(0, H, &mut color, &mut depth[..]).unwrap();
        color
    }

    fn expected_display<C: PixelColor>(pixels: &[C], origin: Point) -> MockDisplay<C> {
        let mut d = MockDisplay::new();
        for (i, &c) in pixels.iter().enumerate() {
            let p = Point::new((i as u32 % W) as i32, (i as u32 / W) as i32);
            d.set_pixel(origin + p, Some(c));
        }
        d
    }

    /// Every strip height, both modes, at an offset: each frame pixel is
    /// written exactly once (MockDisplay panics on overdraw and outside
    /// its 64x64), nothing else is, and the pixels equal the one-piece
    /// render.
    fn every_pixel_once<P>(background: P)
    where
        P: PixelFormat + PixelColor + ColorMapping + core::fmt::Debug,
    {
        let origin = Point::new(5, 11);
        let expected = expected_display(&reference(background), origin);
        let mut storage = [SetupTriangle::EMPTY; 16];
        let mut frame: Frame = Frame::new(config(), &mut storage).unwrap();
        scene(|p, c, id| frame.submit_clip_triangle(p, c, id).unwrap());
        // Miri is slow (these heights took it 140 s a colour): two
        // heights there, one with a ragged last strip.
        let heights: &[u32] = if cfg!(miri) {
            &[7, 40]
        } else {
            &[1, 3, 7, 16, 39, 40, 64]
        };
        for &rows in heights {
            let mut color = vec![background; (W * rows) as usize];
            let mut depth = vec![0u16; (W * rows) as usize];
            let mut drawer =
                StripDrawer::new(&mut color, &mut depth[..], background).with_origin(origin);
            assert_eq!(drawer.strip_rows(W), rows);

            let mut display = MockDisplay::<P>::new();
            drawer
                .draw(&mut display, config(), |strip| {
                    scene(|p, c, id| strip.submit_clip_triangle(p, c, id).unwrap())
                })
                .unwrap();
            display.assert_eq_with_message(&expected, |f| write!(f, "immediate, {rows} rows"));
            assert_eq!(
                display.affected_area(),
                Rectangle::new(origin, Size::new(W, H))
            );

            let mut display = MockDisplay::<P>::new();
            drawer.draw_frame(&mut display, &frame).unwrap();
            display.assert_eq_with_message(&expected, |f| write!(f, "frame, {rows} rows"));

            // The shaded entry points with the default shader: the same
            // (two heights: the loop runs under Miri too).
            if rows != 7 && rows != 40 {
                continue;
            }
            let mut display = MockDisplay::<P>::new();
            drawer
                .draw_shaded::<_, _, _, 8, 3>(&mut display, config(), crate::VertexColor, |strip| {
                    scene(|p, c, id| strip.submit_clip_triangle(p, c, id).unwrap())
                })
                .unwrap();
            display.assert_eq_with_message(&expected, |f| write!(f, "shaded, {rows} rows"));
            let mut display = MockDisplay::<P>::new();
            drawer
                .draw_frame_shaded(&mut display, &frame, &crate::VertexColor)
                .unwrap();
            display.assert_eq_with_message(&expected, |f| write!(f, "shaded frame, {rows} rows"));
        }
    }

    /// Tiles of several sizes (ragged at the right and bottom, one wider
    /// than the frame) through [`StripDrawer::draw_frame_tiles`], at an
    /// offset: every frame pixel written exactly once (MockDisplay panics
    /// on overdraw), the one-piece render's pixels, buffers of one tile;
    /// too small a buffer and bins of another frame are errors, nothing
    /// drawn.
    #[test]
    fn tiles_write_every_pixel_once() {
        let background = Rgb565::BLACK;
        let origin = Point::new(3, 7);
        let expected = expected_display(&reference(background), origin);
        let mut storage = [SetupTriangle::EMPTY; 16];
        let mut frame: Frame = Frame::new(config(), &mut storage).unwrap();
        scene(|p, c, id| frame.submit_clip_triangle(p, c, id).unwrap());
        let sizes: &[(u32, u32)] = if cfg!(miri) {
            // Miri is slow: two sizes (ragged, and wider than the frame).
            &[(16, 16), (64, 64)]
        } else {
            &[(8, 8), (16, 16), (5, 7), (48, 3), (64, 64), (1, 40)]
        };
        for &(tw, th) in sizes {
            let mut offsets = vec![0u32; frame.tiles(tw, th) + 1];
            let mut items = vec![0u32; frame.tile_bin_entries(tw, th)];
            let bins = frame.bin_tiles(tw, th, &mut offsets, &mut items).unwrap();
            let n = (bins.tile_width() * th) as usize;
            let mut color = vec![background; n];
            let mut depth = vec![0u16; n];
            let mut drawer =
                StripDrawer::new(&mut color, &mut depth[..], background).with_origin(origin);
            let mut display = MockDisplay::<Rgb565>::new();
            drawer
                .draw_frame_tiles(&mut display, &frame, &bins)
                .unwrap();
            display.assert_eq_with_message(&expected, |f| write!(f, "tiles {tw}x{th}"));
            let mut small = vec![background; n - 1];
            let mut display = MockDisplay::<Rgb565>::new();
            let r = StripDrawer::new(&mut small, NoDepth, background).draw_frame_tiles(
                &mut display,
                &frame,
                &bins,
            );
            assert!(matches!(
                r,
                Err(DrawError::Render(Error::ColorBufferSize { .. }))
            ));
            assert_eq!(display.affected_area().size, Size::zero());
        }
        let mut other_storage = [SetupTriangle::EMPTY; 4];
        let other: Frame = Frame::new(Config::new(W, H + 1), &mut other_storage).unwrap();
        let (mut offsets, mut items) = (vec![0u32; 64], vec![0u32; 64]);
        let bins = other.bin_tiles(16, 16, &mut offsets, &mut items).unwrap();
        let mut color = vec![background; 256];
        let mut display = MockDisplay::<Rgb565>::new();
        let r = StripDrawer::new(&mut color, NoDepth, background).draw_frame_tiles(
            &mut display,
            &frame,
            &bins,
        );
        assert!(matches!(r, Err(DrawError::Render(Error::BinsMismatch))));
    }

    #[test]
    fn rgb565_every_pixel_once_for_any_strip_height() {
        every_pixel_once(Rgb565::BLACK);
    }

    #[test]
    fn rgb888_every_pixel_once_for_any_strip_height() {
        every_pixel_once(Rgb888::new(1, 2, 3));
    }

    #[test]
    fn gray8_every_pixel_once_for_any_strip_height() {
        every_pixel_once(Gray8::BLACK);
    }

    #[test]
    fn binary_every_pixel_once_for_any_strip_height() {
        every_pixel_once(BinaryColor::Off);
    }

    /// A wider strip buffer converts at push time to the same pixels as a
    /// buffer of the target's colour.
    #[test]
    fn rgb888_buffer_into_narrower_targets_converts_like_from() {
        let rgb = reference(Rgb888::BLACK);
        let mut color = vec![Rgb888::BLACK; (W * 8) as usize];
        let mut depth = vec![0u16; (W * 8) as usize];
        let mut drawer = StripDrawer::new(&mut color, &mut depth[..], Rgb888::BLACK);
        let submit = |strip: &mut StripRenderer<'_, Rgb888, [u16]>| {
            scene(|p, c, id| strip.submit_clip_triangle(p, c, id).unwrap())
        };

        let mut d565 = MockDisplay::<Rgb565>::new();
        drawer.draw(&mut d565, config(), submit).unwrap();
        let want: Vec<Rgb565> = reference(Rgb565::BLACK);
        d565.assert_eq(&expected_display(&want, Point::zero()));
        assert_eq!(
            want,
            rgb.iter().map(|&c| Rgb565::from(c)).collect::<Vec<_>>()
        );

        let mut gray = MockDisplay::<Gray8>::new();
        drawer.draw(&mut gray, config(), submit).unwrap();
        gray.assert_eq(&expected_display(&reference(Gray8::BLACK), Point::zero()));

        let mut bin = MockDisplay::<BinaryColor>::new();
        drawer.draw(&mut bin, config(), submit).unwrap();
        bin.assert_eq(&expected_display(
            &reference(BinaryColor::Off),
            Point::zero(),
        ));
    }

    /// The fill rule through the adapter, as a picture (strips of 4 rows,
    /// so the frame is pushed as 4 + 2): a right triangle whose edges all
    /// run through pixel centres keeps its top edge (row 0) and its
    /// diagonal (a left edge) and drops its vertical right edge (column 6).
    #[test]
    fn binary_pattern() {
        let mut config = Config::new(8, 6);
        config.cull = CullMode::None;
        let mut color = [BinaryColor::Off; 8 * 4];
        let mut drawer = StripDrawer::new(&mut color, NoDepth, BinaryColor::Off);
        let mut display = MockDisplay::<BinaryColor>::new();
        drawer
            .draw(&mut display, config, |strip| {
                // Window (px, py) of an 8x6 frame in NDC: x = -1 + px / 4,
                // y = 1 - py / 3.
                let p = |px: f32, py: f32| v(-1.0 + px / 4.0, 1.0 - py / 3.0, 0.0);
                strip
                    .submit_clip_triangle(
                        [p(0.5, 0.5), p(6.5, 0.5), p(6.5, 6.5)],
                        [Rgb888::WHITE; 3],
                        0,
                    )
                    .unwrap();
            })
            .unwrap();
        display.assert_pattern(&[
            "######..", //
            ".#####..", //
            "..####..", //
            "...###..", //
            "....##..", //
            ".....#..", //
        ]);
    }

    /// A target that fails on its `n`-th strip.
    struct Failing {
        strips: u32,
        fail_at: u32,
    }

    impl OriginDimensions for Failing {
        fn size(&self) -> Size {
            Size::new(W, H)
        }
    }

    impl DrawTarget for Failing {
        type Color = Gray8;
        type Error = &'static str;
        fn draw_iter<I: IntoIterator<Item = EgPixel<Gray8>>>(
            &mut self,
            _: I,
        ) -> Result<(), Self::Error> {
            Err("draw_iter is not used")
        }
        fn fill_contiguous<I: IntoIterator<Item = Gray8>>(
            &mut self,
            area: &Rectangle,
            colors: I,
        ) -> Result<(), Self::Error> {
            assert_eq!(area.size.width, W);
            assert_eq!(
                colors.into_iter().count() as u32,
                area.size.width * area.size.height
            );
            self.strips += 1;
            if self.strips == self.fail_at {
                Err("display unplugged")
            } else {
                Ok(())
            }
        }
    }

    #[test]
    fn target_error_is_passed_through_and_stops_the_frame() {
        let mut color = [Gray8::BLACK; W as usize * 8];
        let mut drawer = StripDrawer::new(&mut color, NoDepth, Gray8::BLACK);
        let mut target = Failing {
            strips: 0,
            fail_at: 2,
        };
        let mut calls = 0;
        let r = drawer.draw(&mut target, config(), |strip| {
            calls += 1;
            scene(|p, c, id| strip.submit_clip_triangle(p, c, id).unwrap());
        });
        assert_eq!(r, Err(DrawError::Target("display unplugged")));
        assert_eq!((target.strips, calls), (2, 2));
        assert_eq!(target.bounding_box().size, Size::new(W, H));

        let mut target = Failing {
            strips: 0,
            fail_at: 0,
        };
        let stats = drawer.draw(&mut target, config(), |_| {}).unwrap();
        assert_eq!((target.strips, stats.pixels_written), (5, 0));
    }

    #[test]
    fn render_errors_come_first_and_draw_nothing() {
        let mut target = Failing {
            strips: 0,
            fail_at: 0,
        };
        // Less than one row of colour.
        let mut color = [Gray8::BLACK; W as usize - 1];
        let mut drawer = StripDrawer::new(&mut color, NoDepth, Gray8::BLACK);
        assert_eq!(
            drawer.draw(&mut target, config(), |_| {}),
            Err(DrawError::Render(Error::ColorBufferSize {
                expected: W as usize,
                actual: W as usize - 1
            }))
        );
        // A depth strip shorter than the colour strip.
        let mut color = [Gray8::BLACK; W as usize * 4];
        let mut depth = [0u32; W as usize * 3];
        let mut drawer = StripDrawer::new(&mut color, &mut depth[..], Gray8::BLACK);
        assert_eq!(
            drawer.draw(&mut target, config(), |_| {}),
            Err(DrawError::Render(Error::DepthBufferSize {
                expected: W as usize * 4,
                actual: W as usize * 3
            }))
        );
        // A bad frame size.
        let mut color = [Gray8::BLACK; 64];
        let mut drawer = StripDrawer::new(&mut color, NoDepth, Gray8::BLACK);
        assert!(matches!(
            drawer.draw(&mut target, Config::new(0, 4), |_| {}),
            Err(DrawError::Render(Error::InvalidFrameSize { .. }))
        ));
        assert_eq!(target.strips, 0);
    }

    /// `with_clear_depth(0)` with `Greater` draws what `Less` with the far
    /// clear draws for mirrored depths.
    #[test]
    fn clear_depth_for_greater() {
        let mut c = config();
        c.depth_func = crate::DepthFunc::Greater;
        let mut color = vec![Rgb565::BLACK; (W * 5) as usize];
        let mut depth = vec![0u32; (W * 5) as usize];
        let mut drawer =
            StripDrawer::new(&mut color, &mut depth[..], Rgb565::BLACK).with_clear_depth(0);
        let mut display = MockDisplay::<Rgb565>::new();
        drawer
            .draw(&mut display, c, |strip| {
                scene(|p, col, id| {
                    // Mirror z about 0 so the nearest stays in front.
                    strip
                        .submit_clip_triangle(p.map(|q| Vec4::new(q.x, q.y, -q.z, q.w)), col, id)
                        .unwrap()
                })
            })
            .unwrap();
        display.assert_eq(&expected_display(&reference(Rgb565::BLACK), Point::zero()));
    }

    #[test]
    fn display_of_errors() {
        let e: DrawError<&str> = Error::InvalidFrameSize {
            width: 0,
            height: 1,
        }
        .into();
        assert!(std::format!("{e}").starts_with("render: invalid frame size"));
        assert_eq!(
            std::format!("{}", DrawError::<&str>::Target("x")),
            "draw target: x"
        );
    }

    /// `cleared_rect` with any rectangle (reversed, past the buffers,
    /// near `usize::MAX`) clears what it reaches of it and nothing else,
    /// and never panics; `None` (nothing cleared) if `len` is not held.
    #[test]
    fn cleared_rect_takes_any_rectangle() {
        let big = usize::MAX;
        for rect in [
            [2, 5, 1, 3],
            [0, 6, 1, 3],
            [5, 2, 0, 3],
            [0, 6, 3, 1],
            [4, 9, 3, 9],
            [0, 6, 2, big],
            [big - 1, big, big - 2, big],
            [0, big, 0, big],
        ] {
            // A layout zero wide has no rows: nothing is cleared.
            let (mut d, mut c) = (vec![7u16; 4], vec![Rgb565::RED; 4]);
            let mut held = &mut d[..];
            assert!(held
                .cleared_rect(4, 0, &mut c, Rgb565::BLUE, 0, rect)
                .is_some());
            assert_eq!((d, c), (vec![7u16; 4], vec![Rgb565::RED; 4]));

            let (mut d, mut c) = (vec![7u16; 24], vec![Rgb565::RED; 20]);
            let mut held = &mut d[..];
            let rows = held.cleared_rect(24, u32::MAX, &mut c, Rgb565::BLUE, 6, rect);
            assert_eq!(rows.map(|r| r.len()), Some(24));
            let [x0, x1, r0, r1] = rect;
            let inside = |i: usize| (r0..r1).contains(&(i / 6)) && (x0..x1).contains(&(i % 6));
            for (i, &v) in d.iter().enumerate() {
                assert_eq!(v == u16::MAX, inside(i), "depth {i} of {rect:?}");
            }
            for (i, &v) in c.iter().enumerate() {
                assert_eq!(v == Rgb565::BLUE, inside(i), "colour {i} of {rect:?}");
            }
            let mut c2 = c.clone();
            let mut none = NoDepth;
            none.cleared_rect(0, 0, &mut c2, Rgb565::GREEN, 6, rect);
            for (i, &v) in c2.iter().enumerate() {
                assert_eq!(v == Rgb565::GREEN, inside(i), "no depth {i} of {rect:?}");
            }
        }
        let (mut d, mut c) = (vec![7u16; 4], vec![Rgb565::RED; 4]);
        assert!((&mut d[..])
            .cleared_rect(5, 0, &mut c, Rgb565::BLUE, 2, [0, 2, 0, 2])
            .is_none());
        assert_eq!((d, c), (vec![7u16; 4], vec![Rgb565::RED; 4]));
    }

    /// What a sequence of draws pushed: the frame's pixels (and how many
    /// times each was pushed).
    struct Capture<P> {
        width: u32,
        pixels: Vec<Option<P>>,
    }

    impl<P: Copy> StripSink<P> for Capture<P> {
        type Error = ();
        fn push_strip(&mut self, area: &Rectangle, pixels: &[P]) -> Result<(), ()> {
            let w = area.size.width as usize;
            for (i, &p) in pixels.iter().enumerate() {
                let x = area.top_left.x as usize + i % w;
                let y = area.top_left.y as usize + i / w;
                let slot = self.pixels.get_mut(y * self.width as usize + x).ok_or(())?;
                *slot = Some(p);
            }
            Ok(())
        }
    }

    /// One frame of [`strip_clears_restore_the_background`]: `n` random
    /// triangles (varied colours, depths, and some off screen) at a seed.
    fn random_scene(seed: u64, n: usize, mut push: impl FnMut([Vec4; 3], [Rgb888; 3], u32)) {
        let mut x = seed | 1;
        let mut rnd = move || {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            ((x >> 11) as f64 / (1u64 << 53) as f64) as f32
        };
        for id in 0..n as u32 {
            let mut p = [Vec4::new(0.0, 0.0, 0.0, 1.0); 3];
            let (cx, cy, r) = (rnd() * 2.4 - 1.2, rnd() * 2.4 - 1.2, rnd() * 0.8);
            for q in p.iter_mut() {
                *q = Vec4::new(
                    cx + (rnd() - 0.5) * r,
                    cy + (rnd() - 0.5) * r,
                    rnd() * 1.6 - 0.8,
                    1.0,
                );
            }
            let c = |k: f32| Rgb888::new((k * 255.0) as u8, 255 - (k * 200.0) as u8, 40);
            push(p, [c(rnd()), c(rnd()), c(rnd())], id);
        }
    }

    /// The drawer clears only what the last strip wrote. One drawer (and
    /// one pair of buffers) draws a sequence of different frames, of
    /// different sizes, in every mode (immediate, set up once, tiles,
    /// shaded, clipless), with the depth buffer cleared to another value
    /// on the way: each frame equals the one-piece render into freshly
    /// cleared buffers, every pixel pushed. (Clearing nothing, or only
    /// the last strip's rows, fails it.)
    fn strip_clears_case<D: DepthWord>(seed: u64, frames: &[(u32, u32, u8, usize)], rows: u32) {
        let mut color = vec![Rgb565::BLACK; 64 * rows as usize];
        let mut depth = vec![D::from_z32(0); 64 * rows as usize];
        let bg = Rgb565::new(3, 9, 27);
        let mut drawer = Some(StripDrawer::new(&mut color, &mut depth[..], bg));
        for (k, &(w, h, mode, n)) in frames.iter().enumerate() {
            // Few widths, so that frames often share one (the drawer
            // starts over at a new width).
            let w = [8, 17, 33, 64][w as usize % 4];
            let seed = seed.wrapping_add(k as u64 * 0x9e37_79b9);
            let mut c = Config::new(w, h);
            c.cull = CullMode::None;
            let greater = mode == 6;
            if greater {
                c.depth_func = crate::DepthFunc::Greater;
            }
            let fc = c;
            let mode = if mode == 5 && !cfg!(feature = "clipless") {
                0
            } else {
                mode
            };
            if mode == 5 {
                c.mode = crate::RasterMode::Clipless;
            }
            if greater {
                drawer = drawer.map(|d| d.with_clear_depth(0));
            } else if k > 0 && frames[k - 1].2 == 6 {
                drawer = drawer.map(|d| d.with_clear_depth(u32::MAX));
            }
            let Some(dr) = drawer.as_mut() else { return };
            let flip = |p: [Vec4; 3]| match greater {
                true => p.map(|q| Vec4::new(q.x, q.y, -q.z, q.w)),
                false => p,
            };
            // The reference: one piece, fresh buffers.
            let mut storage = vec![SetupTriangle::EMPTY; n];
            let mut frame: Frame = Frame::new(fc, &mut storage).unwrap();
            let mut expected = vec![bg; (w * h) as usize];
            if mode != 5 {
                random_scene(seed, n, |p, col, id| {
                    frame.submit_clip_triangle(flip(p), col, id).unwrap()
                });
                let mut z = vec![D::from_z32(if greater { 0 } else { u32::MAX }); (w * h) as usize];
                frame.render_rows(0, h, &mut expected, &mut z[..]).unwrap();
            } else {
                let mut z = vec![D::from_z32(u32::MAX); (w * h) as usize];
                let mut one =
                    StripRenderer::<Rgb565, [D]>::new(c, 0, h, &mut expected, &mut z[..]).unwrap();
                random_scene(seed, n, |p, col, id| {
                    one.submit_clip_triangle(p, col, id).unwrap()
                });
            }
            let mut got = Capture {
                width: w,
                pixels: vec![None; (w * h) as usize],
            };
            match mode {
                0 | 5 | 6 => {
                    dr.draw(&mut got, c, |strip| {
                        random_scene(seed, n, |p, col, id| {
                            strip.submit_clip_triangle(flip(p), col, id).unwrap()
                        })
                    })
                    .unwrap();
                }
                1 => {
                    dr.draw_frame(&mut got, &frame).unwrap();
                }
                2 => {
                    dr.draw_frame_shaded(&mut got, &frame, &crate::VertexColor)
                        .unwrap();
                }
                _ => {
                    let (tw, th) = (8 + (seed % 3) as u32 * 8, rows.min(8));
                    let mut offsets = vec![0u32; frame.tiles(tw, th) + 1];
                    let mut items = vec![0u32; frame.tile_bin_entries(tw, th)];
                    let bins = frame.bin_tiles(tw, th, &mut offsets, &mut items).unwrap();
                    dr.draw_frame_tiles(&mut got, &frame, &bins).unwrap();
                }
            }
            let got: Vec<Rgb565> = got
                .pixels
                .iter()
                .map(|p| p.expect("every pixel pushed"))
                .collect();
            assert!(
                got == expected,
                "frame {k} ({w}x{h}, mode {mode}, {n} triangles, {rows} rows)"
            );
        }
    }

    proptest::proptest! {
        // Few cases under Miri, and no failure file (as in `depth.rs`).
        #![proptest_config(proptest::prelude::ProptestConfig {
            cases: if cfg!(miri) { 2 } else { 256 },
            failure_persistence: None,
            ..proptest::prelude::ProptestConfig::default()
        })]
        #[test]
        fn strip_clears_restore_the_background(
            seed in proptest::prelude::any::<u64>(),
            frames in proptest::collection::vec(
                (0u32..4, 1u32..=40, 0u8..=6, 0usize..=12), 1..=6),
            rows in 1u32..=16,
            wide in proptest::prelude::any::<bool>(),
        ) {
            match wide {
                false => strip_clears_case::<u16>(seed, &frames, rows),
                true => strip_clears_case::<u32>(seed, &frames, rows),
            }
        }
    }
}
