//! The frame: triangles in, set-up triangles stored, any rows out.
//!
//! Design note: a [`Frame`] owns nothing. It borrows the caller's setup
//! storage (`&mut [SetupTriangle]`) and takes triangles through [`Submit`](crate::Submit)
//! (clip-space triangles, or meshes with a matrix). [`Frame::render_rows`]
//! then draws rows `y0..y1` into colour and depth buffers that hold exactly
//! those rows; it takes `&self`, so threads can render disjoint strips of
//! one frame at the same time. Triangles are drawn in submission order in
//! every strip, so the result of any split into strips is the same frame,
//! bit for bit. [`Frame::bin`] and [`Frame::render_strip`] do the same
//! touching only the triangles that reach each strip.
//!
//! Errors: a wrong buffer size, a bad row range, bins of another frame or
//! full storage return a typed [`Error`] and write nothing (no buffer, no
//! storage slot, no counter). Bad triangles are not errors: they are
//! counted in [`Stats`] by the reason they were dropped.

use crate::bins::{self, Bins};
use crate::color::PixelFormat;
use crate::config::{check_rect, check_size, Config, Error, RasterMode};
use crate::depth::DepthBuffer;
use crate::fixed::check_subpixel_bits;
use crate::pipeline::{__private::Sink, impl_submit, Stage};
use crate::raster::{draw, Strip, Touched, HULL_EMPTY};
use crate::setup::SetupTriangle;
use crate::shade::{FragmentShader, VertexColor};
use crate::stats::{RenderStats, Stats};

/// A deferred clear of one rectangle (a strip or a tile): instead of
/// clearing the buffers and then drawing, [`Frame::render_tile_lazy`]
/// draws into buffers that may hold anything, and [`LazyClear::finish`]
/// then clears what no triangle reached. The pixels are those of a clear
/// followed by the same draws ([`Frame::render_tile`]), for any depth
/// test. Where a flat triangle of a `u16` or `u32` buffer under
/// [`DepthFunc::Less`](crate::DepthFunc::Less) reaches columns nothing
/// has reached yet, nearer than the clear depth throughout, its spans are
/// written without reading the buffers: a full-screen triangle costs one
/// write of each pixel, not a clear, a read and a write.
///
/// The caller's `hull` holds one `u32` per row of the rectangle: the
/// columns of that row that hold the clear or a draw.
#[derive(Debug)]
pub struct LazyClear<'h, C> {
    hull: &'h mut [u32],
    rect: [u32; 4],
    color: C,
    z32: u32,
}

impl<'h, C: PixelFormat> LazyClear<'h, C> {
    /// A deferred clear of the rectangle `[x0, x1, y0, y1]` (columns
    /// `x0..x1`, rows `y0..y1`) to the colour `color` and the depth `z32`
    /// (`Z32`: `u32::MAX` for the far plane, as
    /// [`DepthWord::FAR`](crate::DepthWord::FAR) holds it), with `hull`
    /// holding at least one value per row ([`Error::HullSize`] otherwise).
    pub fn new(hull: &'h mut [u32], rect: [u32; 4], color: C, z32: u32) -> Result<Self, Error> {
        let rows = rect[3].saturating_sub(rect[2]) as usize;
        let width = rect[1].saturating_sub(rect[0]);
        if hull.len() < rows || width > 1 << 16 {
            return Err(Error::HullSize {
                expected: rows,
                actual: hull.len(),
            });
        }
        hull.fill(HULL_EMPTY);
        Ok(LazyClear {
            hull,
            rect,
            color,
            z32,
        })
    }

    /// The rectangle it clears.
    pub fn rect(&self) -> [u32; 4] {
        self.rect
    }

    /// Clears every pixel of the rectangle that no render reached, in
    /// buffers holding exactly the rectangle (row `y0` first); returns the
    /// pixels cleared. A buffer shorter than the rectangle is
    /// [`Error::ColorBufferSize`] or [`Error::DepthBufferSize`], with
    /// nothing cleared.
    pub fn finish<D: DepthBuffer + ?Sized>(
        self,
        color: &mut [C],
        depth: &mut D,
    ) -> Result<u64, Error> {
        let [x0, x1, y0, y1] = self.rect;
        let width = x1.saturating_sub(x0) as usize;
        let rows = y1.saturating_sub(y0) as usize;
        let len = width * rows;
        if color.len() < len {
            return Err(Error::ColorBufferSize {
                expected: len,
                actual: color.len(),
            });
        }
        if let Some(actual) = depth.depth_len() {
            if actual < len {
                return Err(Error::DepthBufferSize {
                    expected: len,
                    actual,
                });
            }
        }
        let mut cleared = 0u64;
        let mut run = |start: usize, n: usize| {
            if let Some(c) = color.get_mut(start..start + n) {
                c.fill(self.color);
            }
            depth.fill_z32(start, n, self.z32);
            cleared += n as u64;
        };
        for (r, &h) in self.hull.iter().take(rows).enumerate() {
            let (lo, hi) = ((h & 0xFFFF) as usize, (h >> 16) as usize);
            let row = r * width;
            if lo > hi {
                run(row, width);
            } else {
                run(row, lo.min(width));
                run(row + hi + 1, width.saturating_sub(hi + 1));
            }
        }
        Ok(cleared)
    }
}

/// What a render keeps beside its pixels: nothing, the box of what it
/// wrote (for [`crate::StripDrawer`]'s clears), or a deferred clear's
/// hull.
#[cfg_attr(not(feature = "lazy-clear"), allow(dead_code))]
enum Keep<'a, 'h, C> {
    Pixels,
    Touched,
    Lazy(&'a mut LazyClear<'h, C>),
}

/// The caller's setup storage and how much of it is used.
#[derive(Debug)]
pub struct Store<'s, const N: usize = 3> {
    storage: &'s mut [SetupTriangle<N>],
    len: usize,
}

impl<const N: usize> Sink<N> for Store<'_, N> {
    fn room(&self) -> usize {
        self.storage.len().saturating_sub(self.len)
    }
    fn capacity(&self) -> usize {
        self.storage.len()
    }
    #[cfg_attr(target_pointer_width = "64", inline(always))]
    #[cfg_attr(not(target_pointer_width = "64"), inline)]
    fn take(&mut self, t: &SetupTriangle<N>) {
        if let Some(slot) = self.storage.get_mut(self.len) {
            *slot = *t;
            // Once a frame, for every strip that draws it. On 64-bit
            // hosts not for a smooth triangle, which only a pixel type
            // without shading draws by its flat rows: 0, "not found",
            // has those rows find them (`raster::facts`).
            slot.flat_facts = if cfg!(target_pointer_width = "64") && t.smooth {
                0
            } else {
                crate::raster::flat_facts_of(t)
            };
            self.len += 1;
        }
    }
}

/// A frame being built and rendered, at `S` subpixel bits (8 by default;
/// 4 is the other supported value, see [`Frame::with_subpixel_bits`]),
/// with `N` varyings per vertex (3 by default: a colour; see
/// [`crate::shade`] and [`Frame::render_rows_shaded`]).
///
/// ```
/// use microraster::prelude::*;
/// use microraster::{Config, CullMode, Frame, SetupTriangle, Vec4};
///
/// let mut storage = [SetupTriangle::EMPTY; 16];
/// let mut config = Config::new(32, 32);
/// config.cull = CullMode::None;
/// let mut frame = Frame::new(config, &mut storage).unwrap();
/// let v = |x, y| Vec4::new(x, y, 0.0, 1.0);
/// frame
///     .submit_clip_triangle([v(-1.0, -1.0), v(1.0, -1.0), v(0.0, 1.0)], [Rgb888::RED; 3], 0)
///     .unwrap();
///
/// // Render the frame through an 8-row strip buffer.
/// let mut color = [Rgb565::BLACK; 32 * 8];
/// let mut depth = [u16::MAX; 32 * 8];
/// let mut written = 0;
/// for y0 in (0..32).step_by(8) {
///     color.fill(Rgb565::BLACK);
///     depth.fill(u16::MAX);
///     written += frame.render_rows(y0, y0 + 8, &mut color, &mut depth).unwrap().pixels_written;
///     // ... send `color` to the display here ...
/// }
/// assert!(written > 400);
/// ```
#[derive(Debug)]
pub struct Frame<'s, const S: u32 = 8, const N: usize = 3> {
    stage: Stage,
    store: Store<'s, N>,
    stats: Stats,
}

impl<'s> Frame<'s> {
    /// A new, empty frame at the default 8 subpixel bits, storing set-up
    /// triangles in `storage` (see [`Frame::storage_for`] for a size).
    pub fn new(config: Config, storage: &'s mut [SetupTriangle]) -> Result<Self, Error> {
        Frame::with_subpixel_bits(config, storage)
    }
}

impl<'s, const S: u32, const N: usize> Frame<'s, S, N> {
    /// A new, empty frame at `S` subpixel bits (4 or 8; anything else does
    /// not compile), e.g. `Frame::<4>::with_subpixel_bits(config, storage)`;
    /// the storage's type sets the number of varyings.
    ///
    /// ```compile_fail
    /// let mut storage = [microraster::SetupTriangle::EMPTY; 4];
    /// let _ = microraster::Frame::<'_, 5>::with_subpixel_bits(microraster::Config::new(8, 8), &mut storage);
    /// ```
    pub fn with_subpixel_bits(
        config: Config,
        storage: &'s mut [SetupTriangle<N>],
    ) -> Result<Self, Error> {
        const { check_subpixel_bits::<S>() };
        check_size(&config)?;
        if config.mode != RasterMode::Clipping {
            return Err(Error::ModeUnsupported);
        }
        Ok(Frame {
            stage: Stage::new::<S>(config, None),
            store: Store { storage, len: 0 },
            stats: Stats::default(),
        })
    }

    /// A storage size that holds a frame of `triangles` submitted
    /// triangles in all but extreme views: each one plus an eighth for the
    /// pieces of clipped ones, and 64 more. (A triangle can become up to
    /// [`MAX_PIECES`](crate::MAX_PIECES) pieces; full storage is a typed
    /// error, never a lost triangle.)
    pub const fn storage_for(triangles: usize) -> usize {
        triangles.saturating_add(triangles / 8).saturating_add(64)
    }

    /// The frame's settings.
    pub fn config(&self) -> &Config {
        &self.stage.config
    }

    /// The counters so far.
    pub fn stats(&self) -> Stats {
        self.stats
    }

    /// The stored set-up triangles, in drawing order.
    pub fn triangles(&self) -> &[SetupTriangle<N>] {
        self.store.storage.get(..self.store.len).unwrap_or(&[])
    }

    /// The storage capacity in set-up triangles.
    pub fn capacity(&self) -> usize {
        self.store.storage.len()
    }

    /// Empties the frame (triangles and counters) to build the next one.
    pub fn clear(&mut self) {
        self.store.len = 0;
        self.stats = Stats::default();
    }

    /// The number of bin entries [`Frame::bin`] needs for strips of
    /// `strip_rows` rows (0 counts as 1): one per (triangle, strip it
    /// touches), saturating at `usize::MAX`.
    pub fn bin_entries(&self, strip_rows: u32) -> usize {
        bins::entries(self.triangles(), self.stage.config.width, strip_rows.max(1))
    }

    /// The number of bin entries [`Frame::bin_tiles`] needs for tiles of
    /// `tile_w x tile_h` (0 counts as 1): one per (triangle, tile its box
    /// touches), saturating at `usize::MAX`.
    pub fn tile_bin_entries(&self, tile_w: u32, tile_h: u32) -> usize {
        let w = tile_w.clamp(1, self.stage.config.width);
        bins::entries(self.triangles(), w, tile_h.max(1))
    }

    /// The number of tiles of `tile_w x tile_h` (0 counts as 1) in the
    /// frame: [`Frame::bin_tiles`] needs one more `offsets` entry.
    pub fn tiles(&self, tile_w: u32, tile_h: u32) -> usize {
        let c = &self.stage.config;
        c.width.div_ceil(tile_w.clamp(1, c.width)) as usize
            * c.height.div_ceil(tile_h.max(1)) as usize
    }

    /// Sorts the stored triangles into per-tile bins (tiles of `tile_w x
    /// tile_h >= 1x1` from the top-left corner, numbered row by row; those
    /// on the right and bottom sides may be smaller; [`Bins::rect`] gives
    /// each one's rectangle), in caller-provided storage: `offsets` needs
    /// [`Frame::tiles`]` + 1` entries, `items` [`Frame::tile_bin_entries`].
    /// Each bin keeps submission order, so [`Frame::render_tile`] gives the
    /// same pixels as [`Frame::render_rows`] for the tile's rectangle: any
    /// tile size gives the same frame. A tile as wide as the frame is a
    /// strip ([`Frame::bin`]).
    pub fn bin_tiles<'b>(
        &self,
        tile_w: u32,
        tile_h: u32,
        offsets: &'b mut [u32],
        items: &'b mut [u32],
    ) -> Result<Bins<'b>, Error> {
        self.bin_in((tile_w, tile_h), offsets, |_| items, false)
    }

    /// [`Frame::bin_tiles`] with the item storage given once the number of
    /// entries is known: `items(need)` is called once, with
    /// [`Frame::tile_bin_entries`]` (tile_w, tile_h)`, where the tile size
    /// and `offsets` are right, and returns the storage (shorter than
    /// `need` is the same error). The entries are counted into `offsets`
    /// on the way (`bin_tiles` counts them apart first), so it walks the
    /// triangles twice where `tile_bin_entries` and `bin_tiles` walk them
    /// four times, and where the items are too short `offsets` is left
    /// holding the counts (`bin_tiles` writes nothing on any error).
    pub fn bin_tiles_with<'b>(
        &self,
        tile_w: u32,
        tile_h: u32,
        offsets: &'b mut [u32],
        items: impl FnOnce(usize) -> &'b mut [u32],
    ) -> Result<Bins<'b>, Error> {
        self.bin_in((tile_w, tile_h), offsets, items, true)
    }

    /// [`bins::bin`] of the stored triangles.
    fn bin_in<'b>(
        &self,
        tile: (u32, u32),
        offsets: &'b mut [u32],
        items: impl FnOnce(usize) -> &'b mut [u32],
        count_first: bool,
    ) -> Result<Bins<'b>, Error> {
        let (config, triangles) = (&self.stage.config, self.triangles());
        bins::bin(config, triangles, tile, offsets, items, count_first)
    }

    /// Sorts the stored triangles into per-strip bins (strips of
    /// `strip_rows >= 1` rows from row 0), in caller-provided storage:
    /// `offsets` needs one entry per strip plus one, `items`
    /// [`Frame::bin_entries`] entries. Each bin keeps submission order, so
    /// [`Frame::render_strip`] gives the same pixels as
    /// [`Frame::render_rows`] while touching only the triangles that reach
    /// the strip.
    pub fn bin<'b>(
        &self,
        strip_rows: u32,
        offsets: &'b mut [u32],
        items: &'b mut [u32],
    ) -> Result<Bins<'b>, Error> {
        let strip = (self.stage.config.width, strip_rows);
        self.bin_in(strip, offsets, |_| items, false)
    }

    /// [`Frame::render_strip`] with the fragment shader `fragment` (see
    /// [`crate::shade`]): the same pixels as
    /// [`Frame::render_rows_shaded`] for those rows.
    pub fn render_strip_shaded<C: PixelFormat, D: DepthBuffer + ?Sized, F: FragmentShader<N>>(
        &self,
        bins: &Bins<'_>,
        strip: u32,
        color: &mut [C],
        depth: &mut D,
        fragment: &F,
    ) -> Result<RenderStats, Error> {
        self.render_tile_shaded(bins, strip, color, depth, fragment)
    }

    /// [`Frame::render_tile`] with the fragment shader `fragment` (see
    /// [`crate::shade`]): the same pixels as [`Frame::render_rect_shaded`]
    /// for the tile's rectangle.
    pub fn render_tile_shaded<C: PixelFormat, D: DepthBuffer + ?Sized, F: FragmentShader<N>>(
        &self,
        bins: &Bins<'_>,
        tile: u32,
        color: &mut [C],
        depth: &mut D,
        fragment: &F,
    ) -> Result<RenderStats, Error> {
        self.draw_tile(bins, tile, color, depth, fragment, Keep::Pixels)
    }

    /// Draws tile `tile` of `bins` after checking the bins and the
    /// buffers (and a deferred clear's rectangle), keeping what `keep`
    /// says.
    fn draw_tile<C: PixelFormat, D: DepthBuffer + ?Sized, F: FragmentShader<N>>(
        &self,
        bins: &Bins<'_>,
        tile: u32,
        color: &mut [C],
        depth: &mut D,
        fragment: &F,
        keep: Keep<'_, '_, C>,
    ) -> Result<RenderStats, Error> {
        if !bins.belong_to(&self.stage.config, self.store.len) {
            return Err(Error::BinsMismatch);
        }
        let rect = bins.rect(tile);
        check_rect(&self.stage.config, rect, color.len(), depth.depth_len())?;
        if matches!(&keep, Keep::Lazy(lazy) if lazy.rect != rect) {
            return Err(Error::LazyClearRect);
        }
        let tris = self.triangles();
        let items = bins.strip_items(tile).iter();
        let tris = items.filter_map(|&i| tris.get(i as usize));
        Ok(self.draw_each(rect, color, depth, fragment, tris, keep).0)
    }

    /// [`Frame::render_tile_shaded`] under a deferred clear (see
    /// [`LazyClear`]): the buffers may hold anything where `lazy` has not
    /// reached, and [`LazyClear::finish`] clears that after the last
    /// render (several frames may be drawn in turn, as layers).
    /// [`Error::LazyClearRect`] if `lazy` was made for another rectangle
    /// than the tile's; [`Error::ModeUnsupported`] from a crate built
    /// without its `lazy-clear` feature (a default one).
    pub fn render_tile_lazy_shaded<
        C: PixelFormat,
        D: DepthBuffer + ?Sized,
        F: FragmentShader<N>,
    >(
        &self,
        bins: &Bins<'_>,
        tile: u32,
        color: &mut [C],
        depth: &mut D,
        fragment: &F,
        lazy: &mut LazyClear<'_, C>,
    ) -> Result<RenderStats, Error> {
        if !cfg!(feature = "lazy-clear") {
            return Err(Error::ModeUnsupported);
        }
        self.draw_tile(bins, tile, color, depth, fragment, Keep::Lazy(lazy))
    }

    /// Renders rows `y0..y1` of the frame into `color` and `depth`, which
    /// hold exactly those rows, each covered pixel's interpolated varyings
    /// turned into its colour by `fragment` (see [`crate::shade`]; coverage
    /// and depth are the same whatever the shader). Errors and buffers as
    /// for [`Frame::render_rows`].
    pub fn render_rows_shaded<C: PixelFormat, D: DepthBuffer + ?Sized, F: FragmentShader<N>>(
        &self,
        y0: u32,
        y1: u32,
        color: &mut [C],
        depth: &mut D,
        fragment: &F,
    ) -> Result<RenderStats, Error> {
        self.render_rect_shaded([0, self.stage.config.width, y0, y1], color, depth, fragment)
    }

    /// Renders the rectangle `[x0, x1, y0, y1]` (columns `x0..x1`, rows
    /// `y0..y1`) of the frame into `color` and `depth`, which hold exactly
    /// that rectangle (`(x1 - x0) * (y1 - y0)` values, row `y0` first, each
    /// row from column `x0`), with the fragment shader `fragment`: the same
    /// pixels and depths as rendering the whole rows, so any split into
    /// tiles gives the same frame. [`Error::InvalidColumns`] or
    /// [`Error::InvalidRows`] for an empty, reversed or out-of-frame
    /// range; buffer size errors as for [`Frame::render_rows`].
    pub fn render_rect_shaded<C: PixelFormat, D: DepthBuffer + ?Sized, F: FragmentShader<N>>(
        &self,
        rect: [u32; 4],
        color: &mut [C],
        depth: &mut D,
        fragment: &F,
    ) -> Result<RenderStats, Error> {
        check_rect(&self.stage.config, rect, color.len(), depth.depth_len())?;
        let tris = self.triangles().iter();
        Ok(self
            .draw_each(rect, color, depth, fragment, tris, Keep::Pixels)
            .0)
    }

    /// [`Frame::render_rect_shaded`], and the box of what it wrote (for
    /// [`crate::StripDrawer`]'s clears).
    pub(crate) fn render_rect_touched<
        C: PixelFormat,
        D: DepthBuffer + ?Sized,
        F: FragmentShader<N>,
    >(
        &self,
        rect: [u32; 4],
        color: &mut [C],
        depth: &mut D,
        fragment: &F,
    ) -> Result<(RenderStats, Touched), Error> {
        check_rect(&self.stage.config, rect, color.len(), depth.depth_len())?;
        let tris = self.triangles().iter();
        Ok(self.draw_each(rect, color, depth, fragment, tris, Keep::Touched))
    }

    /// Draws `tris` into a checked rectangle, keeping what `keep` says
    /// (the box of what it wrote only for the drawer).
    fn draw_each<'t, C: PixelFormat, D: DepthBuffer + ?Sized, F: FragmentShader<N>>(
        &self,
        [x0, x1, y0, y1]: [u32; 4],
        color: &mut [C],
        depth: &mut D,
        fragment: &F,
        tris: impl Iterator<Item = &'t SetupTriangle<N>>,
        keep: Keep<'_, '_, C>,
    ) -> (RenderStats, Touched) {
        let c = &self.stage.config;
        let mut strip = Strip {
            width: (x1 - x0) as usize,
            x0,
            x1,
            y0,
            y1,
            color,
            depth,
            depth_func: c.depth_func,
            depth_write: c.depth_write,
            touched: Touched::NONE,
            track: matches!(keep, Keep::Touched),
            spans: [[0; 3]; crate::raster::ROW_BATCH],
            #[cfg(feature = "lazy-clear")]
            lazy: match keep {
                Keep::Lazy(l) => Some(crate::raster::lazy::Lazy {
                    hull: &mut *l.hull,
                    color: l.color,
                    z32: l.z32,
                }),
                _ => None,
            },
        };
        let mut stats = RenderStats::default();
        for t in tris {
            // Rows outside the strip cost two compares here, not the
            // dispatch and checks of `draw` (which would draw nothing).
            if (t.max_y as u32) < y0
                || (t.min_y as u32) >= y1
                || (t.max_x as u32) < x0
                || (t.min_x as u32) >= x1
            {
                continue;
            }
            stats.pixels_written += draw::<S, N, C, D, F>(t, &mut strip, fragment) as u64;
        }
        (stats, strip.touched)
    }
}

impl<const S: u32> Frame<'_, S, 3> {
    /// Renders strip `strip` (rows `strip * strip_rows ..`, the last strip
    /// possibly shorter) of a binned frame into buffers that hold exactly
    /// those rows, the varyings taken as colours ([`VertexColor`]). The
    /// same pixels as [`Frame::render_rows`] for those rows.
    /// [`Error::BinsMismatch`] if `bins` were made for another frame, or
    /// before triangles were added to this one.
    pub fn render_strip<C: PixelFormat, D: DepthBuffer + ?Sized>(
        &self,
        bins: &Bins<'_>,
        strip: u32,
        color: &mut [C],
        depth: &mut D,
    ) -> Result<RenderStats, Error> {
        self.render_strip_shaded(bins, strip, color, depth, &VertexColor)
    }

    /// Renders tile `tile` ([`Bins::rect`]) of a frame binned by
    /// [`Frame::bin_tiles`] (or strip `tile` of one binned by
    /// [`Frame::bin`]) into buffers that hold exactly its rectangle, the
    /// varyings taken as colours ([`VertexColor`]). The same pixels as
    /// [`Frame::render_rect`] for that rectangle; [`Error::BinsMismatch`]
    /// as for [`Frame::render_strip`].
    pub fn render_tile<C: PixelFormat, D: DepthBuffer + ?Sized>(
        &self,
        bins: &Bins<'_>,
        tile: u32,
        color: &mut [C],
        depth: &mut D,
    ) -> Result<RenderStats, Error> {
        self.render_tile_shaded(bins, tile, color, depth, &VertexColor)
    }

    /// [`Frame::render_tile`] under a deferred clear: see
    /// [`Frame::render_tile_lazy_shaded`] and [`LazyClear`].
    pub fn render_tile_lazy<C: PixelFormat, D: DepthBuffer + ?Sized>(
        &self,
        bins: &Bins<'_>,
        tile: u32,
        color: &mut [C],
        depth: &mut D,
        lazy: &mut LazyClear<'_, C>,
    ) -> Result<RenderStats, Error> {
        self.render_tile_lazy_shaded(bins, tile, color, depth, &VertexColor, lazy)
    }

    /// Renders the rectangle `[x0, x1, y0, y1]` into buffers that hold
    /// exactly it (see [`Frame::render_rect_shaded`]), the varyings taken
    /// as colours ([`VertexColor`]).
    pub fn render_rect<C: PixelFormat, D: DepthBuffer + ?Sized>(
        &self,
        rect: [u32; 4],
        color: &mut [C],
        depth: &mut D,
    ) -> Result<RenderStats, Error> {
        self.render_rect_shaded(rect, color, depth, &VertexColor)
    }

    /// Renders rows `y0..y1` of the frame into `color` and `depth`, which
    /// hold exactly those rows (`width * (y1 - y0)` values, row `y0`
    /// first), the varyings taken as colours ([`VertexColor`]). Pass
    /// `&mut NoDepth` to draw without a depth buffer; depth may be a slice
    /// or an array of `u16` or `u32`. The buffers are drawn over, not
    /// cleared.
    pub fn render_rows<C: PixelFormat, D: DepthBuffer + ?Sized>(
        &self,
        y0: u32,
        y1: u32,
        color: &mut [C],
        depth: &mut D,
    ) -> Result<RenderStats, Error> {
        self.render_rows_shaded(y0, y1, color, depth, &VertexColor)
    }
}

impl_submit!(['s, const S: u32, const N: usize] Frame<'s, S, N>, Store<'s, N>, store);

#[cfg(test)]
mod tests {
    use super::*;
    use crate::color::TriangleId;
    use crate::config::CullMode;
    use crate::depth::NoDepth;
    use crate::math::{Mat4, Vec3, Vec4};
    use crate::mesh::{Mesh, MeshColors, ProcessedVertex};
    use crate::pipeline::Submit;
    use embedded_graphics_core::pixelcolor::Rgb888;

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
            frame.submit_clip_triangle(p, [c; 3], i).unwrap();
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
                let (y0, y1) = bins.rows(s);
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
        // Index 9 is out of range, index 5 a NaN vertex.
        let flat = [0u32, 1, 2, 1, 3, 2, 2, 4, 0, 0, 4, 3, 1, 5, 2, 0, 9, 1];
        let indices: [[u32; 3]; 6] =
            core::array::from_fn(|i| [flat[3 * i], flat[3 * i + 1], flat[3 * i + 2]]);
        let colors = [Rgb888::new(200, 10, 10); 6];
        let mesh = Mesh {
            positions: &positions,
            indices: &indices,
            attributes: MeshColors::PerVertex(&colors),
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
            a.submit_mesh(&mesh, &mvp, 7).unwrap();
            let mut s2 = [SetupTriangle::EMPTY; 64];
            let mut b: Frame = Frame::new(config, &mut s2).unwrap();
            let mut cache = [ProcessedVertex::EMPTY; 6];
            b.submit_mesh_cached(&mesh, &mvp, 7, &mut cache).unwrap();
            assert_eq!(a.triangles(), b.triangles(), "angle {angle}");
            assert_eq!(a.stats(), b.stats(), "angle {angle}");
            let mut small = [ProcessedVertex::EMPTY; 5];
            assert!(matches!(
                b.submit_mesh_cached(&mesh, &mvp, 7, &mut small),
                Err(Error::VertexCacheSize {
                    expected: 6,
                    actual: 5
                })
            ));
        }
    }
}
