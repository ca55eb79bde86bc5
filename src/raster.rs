//! Strip traversal: exact spans, depth, colour.
//!
//! Design note: a set-up triangle is drawn into rows `y0..y1` of its frame
//! (a "strip"); the caller's buffers hold only those rows. Per triangle and
//! strip the three edge functions are derived from the snapped vertices:
//!
//! `E_k(p) = (xb - xa) * (py - ya) - (yb - ya) * (px - xa)` for the edge
//! `a -> b` opposite vertex `k`, in `i64` (`|E| < 2^59`, see
//! [`crate::fixed`]). A pixel is covered when its centre has
//! `E_k + bias_k >= 0` for all `k`, where `bias_k` is 0 for a top or left
//! edge and -1 otherwise: the top-left fill rule, exactly, with no float
//! anywhere.
//!
//! Per row, each edge is linear in the column, so the covered columns are
//! found by one exact floor division per edge: a span `[lo, hi]` (on cores
//! without a divide instruction the quotients are walked from row to row
//! instead, exactly: `SpanWalk`). The inner loop then visits only covered
//! pixels; it never divides and never tests coverage.
//!
//! Small triangles (box at most `SMALL_WIDTH` pixels wide) skip the
//! divisions and test the sign of the three edge values at every pixel of
//! their box instead; both paths cover exactly the same pixels.
//!
//! Depth is the plane through the three `Z32` vertex depths, evaluated from
//! the exact edge values as `Z0 + (Z1 - Z0) E1 / area + (Z2 - Z0) E2 / area`
//! at the start of each run of pixels (a row's first covered pixel for
//! small triangles, every `RESYNC` pixels of a span) and stepped by its
//! gradient in between; spans step it in `Z32.F` integers: `Z32` with
//! `F` = [`DepthBuffer::FRAC`] fraction bits, 16 for `u32` buffers and 0
//! for `u16` buffers (whole `Z32` units are 2^-16 of their LSB; either way
//! the stepping error stays below 1/8 LSB over 2^14 pixels). The float
//! is `f64` for `u32` buffers: each term is at most `2^32` at a covered
//! pixel, so the error is far below one `Z32` LSB and the written value is
//! the floor of the exact plane value, or one off only where that value
//! lies that close to an integer. `u16` buffers use `f32` (error about
//! `2^-8` of a `Z16` LSB; no software `f64` on single-precision FPUs).
//! Runs start where the triangle's geometry says (its box, its exact
//! spans), never where a strip starts, so the result does not depend on the
//! strip split (IEEE arithmetic is deterministic, in software on FPU-less
//! cores too). A tile (a window of columns `x0..x1` as well as rows) cuts
//! runs on the left and right: a triangle whose box crosses a window side
//! takes `window_rows`, which finds and starts each run as the whole row
//! does and enters it at the window's first column (depth `z0 + k dz` in
//! `Z32.F`, varyings from the last re-synchronisation point), so tiles of
//! any size give the pixels of strips. Triangles inside the window, and
//! every triangle of a strip, take the paths above unchanged.
//!
//! A flat triangle's span rows run in a loop of their own (`flat_rows`),
//! out of line so that only the depth state is live in it. For a `u16`
//! buffer under an ordered test (`Less`, `LessEqual`, `Greater` for 1/w
//! depth, `GreaterEqual`) with writes, a triangle whose vertex
//! depths keep `2^14 + width` `Z32` units from both planes
//! (`z_never_clamps`, with its error bound) provably never steps a span
//! out of `[0, 2^32)`: its spans skip the per-span range check and the
//! clamp, and step one `u32` (`flat_rows_in_range`). The words are the
//! ones the checked path writes (a property test compares the two on
//! depths a few `f32` steps from the planes). On cores that divide, with
//! `i32` edges, those rows go in batches (`ROW_BATCH`): each row's span
//! and depth start first (`batch_spans`, a copy per pattern of edge
//! sides, so no branch on a side), then the whole batch in one call to
//! the buffer's loop: the spans of `Edge::clip_span` and the same depth
//! starts (the coverage properties compare both paths with the `i128`
//! reference, and the `u16` depths with the `u32` path's).
//!
//! Varyings, when they vary, are perspective-correct: `sum(E_k v_k / w_k)
//! / sum(E_k / w_k)` with the exact edge values converted to `f32` at the
//! start of each run and the `N + 1` sums stepped in `f32` along it; one
//! division per pixel, then the fragment shader
//! ([`FragmentShader`]) makes the colour. A triangle whose vertices carry
//! equal varyings is shaded once per strip.
//!
//! A deferred clear ([`crate::LazyClear`], `Strip::lazy`) draws into
//! buffers that hold anything: per row it keeps the columns `[lo, hi]`
//! that hold the clear or a draw (the hull), and outside them nothing is
//! read. A triangle of the `u16` or `u32` `Less` flat path extends the hull span by
//! span: a span beyond the hull whose depth is nearer than the clear
//! everywhere is written without reading the buffers (every pixel would
//! pass against the clear), the gap up to the hull cleared; any other
//! span has its columns outside the hull cleared first and is then
//! drawn as usual. Every other triangle first extends the hull over its
//! box on each of its rows, clearing what that adds. What no row's hull
//! holds at the end is cleared by `LazyClear::finish`: the same pixels as
//! a clear before the draws.

use crate::color::PixelFormat;
use crate::depth::{cmp, DepthBuffer, DepthFunc};
use crate::setup::SetupTriangle;
use crate::shade::FragmentShader;

#[cfg(feature = "lazy-clear")]
pub(crate) mod lazy;

/// The integer type edge functions are evaluated in: `i64` always works
/// (`|E| < 2^59`); `i32` is exact for triangles whose vertices span at most
/// [`EDGE32_SPAN`] subpixel units in x and in y (see `fits_i32`), which
/// is most triangles of a small frame, and costs a single register (and a
/// hardware division) on a 32-bit core.
trait EdgeInt:
    Copy
    + Ord
    + core::ops::Add<Output = Self>
    + core::ops::Sub<Output = Self>
    + core::ops::Mul<Output = Self>
    + core::ops::Div<Output = Self>
    + core::ops::Neg<Output = Self>
    + core::ops::AddAssign
    + core::ops::BitOr<Output = Self>
{
    const ZERO: Self;
    const ONE: Self;
    /// `i64`: the type of the rare triangles too wide for `i32`.
    const WIDE: bool;
    /// `v`, which the caller has proved to fit.
    fn narrow(v: i64) -> Self;
    fn widen(self) -> i64;
    fn from_usize(v: usize) -> Self;
    /// `self - bias` (the unbiased edge value, which fits `Self`: see
    /// [`EDGE32_SPAN`]) as `R`, converted from `i32` where `Self` is
    /// (one instruction on an FPU, where `i64` takes a library call).
    fn unbiased<R: Real>(self, bias: i32) -> R;
    /// `self - bias` as `f32`.
    fn unbiased_f32(self, bias: i32) -> f32;
    /// `self` as `R` (from `i32` where `Self` is: the same value, rounded
    /// the same way, without `i64`'s library call on 32-bit cores).
    fn real<R: Real>(self) -> R;
    /// `a b - c d + bias`, which the caller has proved to fit: in
    /// `Self`'s wrapping arithmetic, exact because the result is in range.
    fn edge_value(a: Self, b: Self, c: Self, d: Self, bias: i32) -> Self;
    /// All ones if `self < 0`, else 0.
    fn sign_mask(self) -> Self;
    /// `a - b`, which the caller has proved to fit (for `i32`: coordinates
    /// of one triangle, see [`EDGE32_SPAN`]), without `i64` arithmetic.
    fn diff(a: i32, b: i32) -> Self;
    /// `p - a` for a pixel centre `p` of the triangle's box (which fits
    /// `i32` wherever `Self` is `i32`), as `diff`.
    fn diff_wide(p: i64, a: i32) -> Self;
}

macro_rules! impl_edge_int {
    ($t:ty, $from:ident) => {
        impl EdgeInt for $t {
            const ZERO: $t = 0;
            const ONE: $t = 1;
            const WIDE: bool = <$t>::BITS > 32;
            #[inline(always)]
            fn narrow(v: i64) -> $t {
                debug_assert!(<$t>::try_from(v).is_ok(), "{v} does not fit");
                v as $t
            }
            #[inline(always)]
            fn widen(self) -> i64 {
                self as i64
            }
            #[inline(always)]
            fn sign_mask(self) -> $t {
                self >> (<$t>::BITS - 1)
            }
            #[inline(always)]
            fn diff(a: i32, b: i32) -> $t {
                <$t>::narrow(a as i64 - b as i64);
                (a as $t).wrapping_sub(b as $t)
            }
            #[inline(always)]
            fn diff_wide(p: i64, a: i32) -> $t {
                <$t>::narrow(p - a as i64);
                (p as $t).wrapping_sub(a as $t)
            }
            #[inline(always)]
            fn from_usize(v: usize) -> $t {
                v as $t
            }
            #[inline(always)]
            fn unbiased<R: Real>(self, bias: i32) -> R {
                R::$from(self - bias as $t)
            }
            #[inline(always)]
            fn unbiased_f32(self, bias: i32) -> f32 {
                (self - bias as $t) as f32
            }
            #[inline(always)]
            fn real<R: Real>(self) -> R {
                R::$from(self)
            }
            #[inline(always)]
            fn edge_value(a: $t, b: $t, c: $t, d: $t, bias: i32) -> $t {
                let e = a
                    .wrapping_mul(b)
                    .wrapping_sub(c.wrapping_mul(d))
                    .wrapping_add(bias as $t);
                debug_assert_eq!(
                    e as i64,
                    a as i64 * b as i64 - c as i64 * d as i64 + bias as i64
                );
                e
            }
        }
    };
}

impl_edge_int!(i32, from_i32);
impl_edge_int!(i64, from_i64);

/// The largest vertex span (max - min, in `Sub<S>` units, in x and in y)
/// for which every edge value `draw` computes fits `i32`: 45,000 units,
/// 175 pixels at 8 subpixel bits, 2,812 at 4.
///
/// Proof: `E_k(p) = (b - a) x (p - a)` is twice the signed area of the
/// triangle `a, b, p`. The vertices lie in their bounding box, of spans at
/// most `B`; the edge functions are evaluated at pixel centres of the
/// triangle's pixel box (inside that bounding box) and, after a row's or a
/// span's last pixel, at most one pixel (`2^S <= 256` units) beyond it in x
/// and in y. So `a`, `b` and `p` lie in a square of side `B + 256`, and a
/// triangle in a square of side `L` has at most half its area: `|E| <= L^2
/// = 45,256^2 = 2,048,105,536`. The bias adds at most 1; the steps
/// `|dy| << S, |dx| << S` are at most `B * 256 = 11,520,000`; the span
/// division `clip_span` forms `-E + step - 1` at in-box points, below
/// `2,059,625,537 < 2^31 - 1`. So no `i32` operation overflows (the property
/// tests, which run with overflow checks on, compare triangles on both
/// sides of the limit against the `i128` reference).
pub const EDGE32_SPAN: i64 = 45_000;

/// Whether a triangle's edge values fit `i32` ([`EDGE32_SPAN`]), from
/// its vertices' spans (max - min, in `Sub<S>` units) in x and in y:
/// computed once, at setup, where the box's extremes are at hand. Always
/// `false` with the `no-i32-edges` feature, which exists to measure what
/// the `i32` path saves (`microraster report speed-vs-error`, the firmware's
/// counts); the pixels are the same.
#[inline]
pub(crate) fn fits_i32(span_x: i64, span_y: i64) -> bool {
    !cfg!(feature = "no-i32-edges") && span_x <= EDGE32_SPAN && span_y <= EDGE32_SPAN
}

/// One edge function, set up for stepping in whole pixels.
#[derive(Clone, Copy)]
struct Edge<T> {
    /// `E + bias` at the centre of the first column of the current row.
    row: T,
    /// Change per column (`-(yb - ya) << S`).
    step_x: T,
    /// Change per row (`(xb - xa) << S`).
    step_y: T,
    /// 0 for a top or left edge, -1 otherwise.
    bias: i32,
}

impl<T: EdgeInt> Edge<T> {
    /// Computed exactly in `T`: for `i32` the differences and the value
    /// fit ([`EDGE32_SPAN`]), so its wrapping products give the exact value
    /// without `i64` multiplications (a library call on the Cortex-M0: 3 %
    /// of its four-cubes rasterization).
    fn new<const S: u32>(xa: i32, ya: i32, xb: i32, yb: i32, px: i64, py: i64) -> Edge<T> {
        // In `T`: the differences fit, and for `i32` so do the value and
        // the steps (`EDGE32_SPAN`), so `i32` needs no `i64` arithmetic.
        let dx = T::diff(xb, xa);
        let dy = T::diff(yb, ya);
        // Window y points down; with positive area the interior is on the
        // side where E > 0. Top edge: horizontal with the interior below
        // (dx > 0); left edge: going up (dy < 0).
        let top_left = dy < T::ZERO || (dy == T::ZERO && dx > T::ZERO);
        let bias = if top_left { 0 } else { -1 };
        let unit = T::from_usize(1 << S);
        Edge {
            row: T::edge_value(dx, T::diff_wide(py, ya), dy, T::diff_wide(px, xa), bias),
            step_x: -dy * unit,
            step_y: dx * unit,
            bias,
        }
    }

    /// The biased value `n` columns to the right of the row's start.
    #[inline(always)]
    fn at(&self, n: T) -> T {
        self.row + self.step_x * n
    }

    /// Restricts the column range `[lo, hi]` (offsets from the first column)
    /// to where this edge covers. Returns `false` if nothing remains.
    #[inline]
    fn clip_span(&self, lo: &mut T, hi: &mut T) -> bool {
        let e = self.row;
        let a = self.step_x;
        if a > T::ZERO {
            // e + a n >= 0  <=>  n >= ceil(-e / a)
            if e < T::ZERO {
                let n = (-e + a - T::ONE) / a;
                if n > *lo {
                    *lo = n;
                }
            }
        } else if a < T::ZERO {
            // e + a n >= 0  <=>  n <= floor(e / -a)
            if e < T::ZERO {
                return false;
            }
            let n = e / -a;
            if n < *hi {
                *hi = n;
            }
        } else if e < T::ZERO {
            return false;
        }
        *lo <= *hi
    }
}

/// `(floor(x / d), x mod d)` for `d > 0` (the remainder in `[0, d)`).
#[inline(always)]
fn floor_div<T: EdgeInt>(x: T, d: T) -> (T, T) {
    let q = x / d;
    let r = x - q * d;
    if r < T::ZERO {
        (q - T::ONE, r + d)
    } else {
        (q, r)
    }
}

/// What bound an edge puts on a row's span.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Side {
    /// `step_x > 0`: covered from `ceil(-E / step_x)` on.
    Left,
    /// `step_x < 0`: covered up to `floor(E / -step_x)`.
    Right,
    /// `step_x == 0`: the whole row or none of it.
    Flat,
}

/// The three edges' span bounds walked from row to row without a division
/// (the exact incremental form of [`Edge::clip_span`], which divides per
/// edge and row: a library call on cores without a divide instruction).
///
/// For an edge with `d = |step_x| > 0` it keeps `f = floor(E / d)` and `r
/// = E mod d` of the row's biased value `E` at column 0: a left edge covers
/// columns `n >= -f`, a right edge `n <= f` (for `E < 0` that is below 0:
/// nothing, as `clip_span` says). With `step_y = d q + rq` (`0 <= rq <
/// d`), the next row has `f' = f + q + c`, `r' = r + rq - c d`, where `c =
/// 1` exactly when `r + rq >= d`. A flat edge keeps `f = E` itself (`q =
/// step_y`, `rq = 0`). All of it stays within the bounds [`EDGE32_SPAN`]
/// proves for `clip_span` (`|f| <= |E|`, `r + rq < 2 d <= 2^25`).
#[derive(Clone, Copy)]
struct SpanWalk<T> {
    f: [T; 3],
    r: [T; 3],
    d: [T; 3],
    q: [T; 3],
    rq: [T; 3],
    side: [Side; 3],
}

impl<T: EdgeInt> SpanWalk<T> {
    /// No edges: every row whole (a placeholder, never walked).
    const IDLE: SpanWalk<T> = SpanWalk {
        f: [T::ZERO; 3],
        r: [T::ZERO; 3],
        d: [T::ONE; 3],
        q: [T::ZERO; 3],
        rq: [T::ZERO; 3],
        side: [Side::Flat; 3],
    };

    /// The walk from the edges' current row (one division per edge).
    fn new(edges: &[Edge<T>; 3]) -> SpanWalk<T> {
        let mut w = SpanWalk::IDLE;
        for (k, e) in edges.iter().enumerate() {
            let a = e.step_x;
            if a == T::ZERO {
                w.f[k] = e.row;
                w.q[k] = e.step_y;
                continue;
            }
            let (d, side) = if a > T::ZERO {
                (a, Side::Left)
            } else {
                (-a, Side::Right)
            };
            (w.f[k], w.r[k]) = floor_div(e.row, d);
            (w.q[k], w.rq[k]) = floor_div(e.step_y, d);
            w.d[k] = d;
            w.side[k] = side;
        }
        w
    }

    /// The covered columns `[lo, hi]` of the current row within `[0,
    /// max_n]`, or `None`: what the three `clip_span`s give.
    #[inline(always)]
    fn span(&self, max_n: T) -> Option<(T, T)> {
        let (mut lo, mut hi) = (T::ZERO, max_n);
        for k in 0..3 {
            match self.side[k] {
                Side::Left => lo = lo.max(-self.f[k]),
                Side::Right => hi = hi.min(self.f[k]),
                Side::Flat => {
                    if self.f[k] < T::ZERO {
                        return None;
                    }
                }
            }
        }
        (lo <= hi).then_some((lo, hi))
    }

    /// One row down.
    #[inline(always)]
    fn next(&mut self) {
        for k in 0..3 {
            self.f[k] += self.q[k];
            self.r[k] += self.rq[k];
            if self.r[k] >= self.d[k] {
                self.r[k] = self.r[k] - self.d[k];
                self.f[k] += T::ONE;
            }
        }
    }
}

/// Whether integer division is a library call on this target (Armv6-M and
/// older Arm cores, which also lack 32-bit atomics; RISC-V without `M`):
/// there rows walk their spans ([`SpanWalk`]) instead of dividing three
/// times a row. Elsewhere a divide is one instruction and the walk's
/// bookkeeping costs more (on the Cortex-M4F the four-cubes frame takes
/// 44 k more instructions walked; on the Cortex-M0 6 % fewer). The spans
/// are the same either way (a property test compares the two).
const DIVIDE_IS_SLOW: bool = cfg!(any(
    all(target_arch = "arm", not(target_has_atomic = "32")),
    all(
        any(target_arch = "riscv32", target_arch = "riscv64"),
        not(target_feature = "m")
    )
));

/// A row's covered span, by [`Edge::clip_span`] or, where
/// [`DIVIDE_IS_SLOW`], by [`SpanWalk`].
struct RowSpans<T> {
    max_n: T,
    /// Walked only where [`DIVIDE_IS_SLOW`] (otherwise never set up).
    walk: SpanWalk<T>,
}

impl<T: EdgeInt> RowSpans<T> {
    #[inline(always)]
    fn new(edges: &[Edge<T>; 3], max_n: usize) -> RowSpans<T> {
        RowSpans {
            max_n: T::from_usize(max_n),
            walk: if DIVIDE_IS_SLOW {
                SpanWalk::new(edges)
            } else {
                SpanWalk::IDLE
            },
        }
    }

    /// The covered columns `[lo, hi]` of the row `edges` are at.
    #[inline(always)]
    fn span(&self, edges: &[Edge<T>; 3]) -> Option<(T, T)> {
        if DIVIDE_IS_SLOW {
            return self.walk.span(self.max_n);
        }
        let (mut lo, mut hi) = (T::ZERO, self.max_n);
        let covered = edges[0].clip_span(&mut lo, &mut hi)
            && edges[1].clip_span(&mut lo, &mut hi)
            && edges[2].clip_span(&mut lo, &mut hi);
        covered.then_some((lo, hi))
    }

    /// One row down (the edges step themselves).
    #[inline(always)]
    fn next(&mut self) {
        if DIVIDE_IS_SLOW {
            self.walk.next();
        }
    }
}

/// Per-draw state shared by every triangle of one `render_rows` call.
pub(crate) struct Strip<'b, C, D: ?Sized> {
    /// Pixels a buffer row holds: `x1 - x0`.
    pub width: usize,
    /// The window's columns `x0..x1` (`0..frame width` for a strip).
    pub x0: u32,
    pub x1: u32,
    pub y0: u32,
    pub y1: u32,
    pub color: &'b mut [C],
    pub depth: &'b mut D,
    pub depth_func: DepthFunc,
    pub depth_write: bool,
    /// The boxes of the triangles that wrote a pixel, so far, kept only
    /// where `track` (for [`crate::StripDrawer`]; the caller's own
    /// renders pay a test a triangle, not the box).
    pub touched: Touched,
    pub track: bool,
    /// A deferred clear: the buffers hold anything outside the hull.
    #[cfg(feature = "lazy-clear")]
    pub lazy: Option<lazy::Lazy<'b, C>>,
    /// The spans of [`flat_rows_in_range`]'s batches (here, not in its
    /// frame: set once a strip, not once a triangle).
    pub spans: [[u32; 3]; ROW_BATCH],
}

/// A hull row holding no column.
pub(crate) const HULL_EMPTY: u32 = 0xFFFF;

/// A box holding every pixel a render wrote: the union of the bounding
/// boxes (frame pixels, inclusive) of the triangles that wrote at least
/// one, not clipped to the window. What [`StripDrawer`] clears before
/// the next strip instead of the whole buffer.
///
/// [`StripDrawer`]: crate::StripDrawer
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct Touched {
    pub min_x: u32,
    pub max_x: u32,
    pub min_y: u32,
    pub max_y: u32,
}

impl Touched {
    /// No pixel.
    pub const NONE: Touched = Touched {
        min_x: u32::MAX,
        max_x: 0,
        min_y: u32::MAX,
        max_y: 0,
    };

    /// Adds the box `min_x..=max_x` by `min_y..=max_y`.
    #[inline(always)]
    pub fn add(&mut self, min_x: u32, max_x: u32, min_y: u32, max_y: u32) {
        self.min_x = self.min_x.min(min_x);
        self.max_x = self.max_x.max(max_x);
        self.min_y = self.min_y.min(min_y);
        self.max_y = self.max_y.max(max_y);
    }

    /// The part inside the window `[x0, x1, y0, y1]` (columns `x0..x1`,
    /// rows `y0..y1`), as columns and rows relative to the window's
    /// corner, `[x0, x1, r0, r1]` half open; all zero when empty.
    pub fn within(self, [x0, x1, y0, y1]: [u32; 4]) -> [usize; 4] {
        let (a, b) = (self.min_x.max(x0), self.max_x.saturating_add(1).min(x1));
        let (c, d) = (self.min_y.max(y0), self.max_y.saturating_add(1).min(y1));
        if a >= b || c >= d {
            return [0; 4];
        }
        [
            (a - x0) as usize,
            (b - x0) as usize,
            (c - y0) as usize,
            (d - y0) as usize,
        ]
    }
}

/// Triangles whose bounding box is narrower than this many pixels are
/// traversed pixel by pixel over the box; wider ones by exact spans. The
/// same on every target, so host and microcontroller draw the same pixels
/// the same way. Measured with exact `i32` spans: on a Cortex-M4F spans
/// win almost everywhere (the four-cubes frame: 638 k instructions with
/// spans only, 639 k at 12 pixels, 677 k at 24, 1,056 k at 64), and on the
/// x86-64 host 8 is no slower than the 24 chosen for `i64` divisions
/// (interleaved runs of the sphere and the bunny).
const SMALL_WIDTH: u16 = 8;

/// Re-evaluate varyings from the exact edge values every this many pixels
/// along a span, so float stepping error stays bounded: every 16 pixels
/// for a colour (`N <= 3`, error far below one 8-bit step), every pixel
/// for more varyings (texture coordinates and normals, which need all the
/// precision `f32` has; stepping them over 16 pixels of a steep
/// perspective costs 2^-17 of their range, see `tests/shading.rs`).
const fn resync(n: usize) -> usize {
    if n <= 3 {
        16
    } else {
        RESYNC_MANY
    }
}

const RESYNC_MANY: usize = 1;

/// The float type depth is interpolated in: `f64` for `Z32` buffers,
/// `f32` where only 16 bits are kept (and on FPU-less or single-precision
/// cores that saves software `f64`): terms up to `2^32` carry an `f32`
/// error of about `2^8` `Z32` units, `2^-8` of a `Z16` LSB.
trait Real: Copy + core::ops::Add<Output = Self> + core::ops::Mul<Output = Self> {
    const ZERO: Self;
    fn from_i64(v: i64) -> Self;
    fn from_i32(v: i32) -> Self;
    fn from_u32(v: u32) -> Self;
    fn recip(self) -> Self;
    /// Saturating, flooring conversion (NaN gives 0).
    fn to_u32(self) -> u32;
    /// `self * 2^frac` (`frac` 0 or 16: `Z32.F` from `Z32`), rounded half
    /// away from zero, saturating.
    fn to_fixed(self, frac: u32) -> i64;
    /// `to_fixed(0)` of a value in `[0, 2^32 - 1)`: `self + 0.5`
    /// truncated, one conversion.
    fn round_in_range(self) -> u32;
}

macro_rules! impl_real {
    ($t:ty, $to_i64:path) => {
        impl Real for $t {
            const ZERO: $t = 0.0;
            #[inline(always)]
            fn from_i64(v: i64) -> $t {
                v as $t
            }
            #[inline(always)]
            fn from_i32(v: i32) -> $t {
                v as $t
            }
            #[inline(always)]
            fn from_u32(v: u32) -> $t {
                v as $t
            }
            #[inline(always)]
            fn recip(self) -> $t {
                1.0 / self
            }
            #[inline(always)]
            fn to_u32(self) -> u32 {
                self as u32
            }
            #[inline(always)]
            fn round_in_range(self) -> u32 {
                (self + 0.5) as u32
            }
            #[inline(always)]
            fn to_fixed(self, frac: u32) -> i64 {
                let q = if frac == 16 { self * 65536.0 } else { self };
                $to_i64(q + if q >= 0.0 { 0.5 } else { -0.5 })
            }
        }
    };
}

impl_real!(f64, f64_as_i64);
impl_real!(f32, crate::fixed::f32_as_i64);

/// `x as i64`, as the macro's conversion for `f64`.
#[inline(always)]
fn f64_as_i64(x: f64) -> i64 {
    x as i64
}

/// The depth key of a small triangle's pixel at interpolated depth `z`
/// (`Z32` units): `Z32` itself, floored, or, for buffers that keep more
/// ([`DepthBuffer::FINE_KEY`]), the key of its `Z32.F` value.
#[inline(always)]
fn small_key<D: DepthBuffer + ?Sized, R: Real>(z: R) -> u32 {
    if D::FINE_KEY {
        D::key_of(z.to_fixed(D::FRAC))
    } else {
        z.to_u32()
    }
}

/// `z1 - z0` (`Z32` units, exact in `i64`) as `R`: converted from `i32`
/// where it fits (most triangles: their depths are close), the same value
/// as the `i64` conversion, which is a library call on 32-bit cores.
#[inline(always)]
fn z_difference<R: Real>(z0: u32, z1: u32) -> R {
    if cfg!(target_pointer_width = "64") {
        // One instruction from `i64` there: no test.
        return R::from_i64(z1 as i64 - z0 as i64);
    }
    z_difference_via_i32(z0, z1)
}

/// [`z_difference`] on 32-bit cores (tested on every target).
#[inline(always)]
fn z_difference_via_i32<R: Real>(z0: u32, z1: u32) -> R {
    let d = z1.wrapping_sub(z0) as i32;
    if (z1 >= z0) == (d >= 0) {
        R::from_i32(d)
    } else {
        R::from_i64(z1 as i64 - z0 as i64)
    }
}

/// Per-triangle constants for shading a covered pixel.
struct Shader<R, const N: usize> {
    /// `Z0`.
    z0: R,
    /// `(Z1 - Z0) / area` and `(Z2 - Z0) / area`.
    k1: R,
    k2: R,
    /// Depth change per pixel.
    dz: R,
    /// The same in `Z32.F` (`F` = [`DepthBuffer::FRAC`]), rounded
    /// (saturating).
    dz_fixed: i64,
    /// Unbiased edge value = biased value - bias.
    bias: [i32; 3],
    /// Varying numerators' and the denominator's change per pixel.
    dv: [f32; N],
    dw: f32,
    smooth: bool,
}

/// Interpolants at one pixel: depth, varying numerators, denominator.
#[derive(Clone, Copy)]
struct Acc<R, const N: usize> {
    z: R,
    v: [f32; N],
    w: f32,
}

/// A triangle's depth plane alone: what the flat rows of a `Z32.0`
/// buffer need ([`flat_rows_in_range`]), without the rest of a
/// [`Shader`]. The same values as the shader's: [`Shader::new`] takes its
/// depth from here, and [`DepthPlane::z_at`] is [`Shader::z_at`]'s sum.
#[derive(Clone, Copy)]
struct DepthPlane<R> {
    z0: R,
    k1: R,
    k2: R,
    dz: R,
    /// The step in `Z32.F` (`F` = [`DepthBuffer::FRAC`]), rounded.
    dz_fixed: i64,
    /// Edges 1 and 2's biases (the unbiased value is the biased one less
    /// its bias).
    bias: [i32; 2],
}

impl<R: Real> DepthPlane<R> {
    #[inline(always)]
    fn new<const N: usize, D: DepthBuffer + ?Sized, T: EdgeInt>(
        t: &SetupTriangle<N>,
        edges: &[Edge<T>; 3],
    ) -> Self {
        let (mut k1, mut k2, mut dz) = (R::ZERO, R::ZERO, R::ZERO);
        if D::ENABLED {
            // Twice the area fits `T` (for `i32`: it is at most the square
            // of the span bound, as `EDGE32_SPAN` proves), as the steps do;
            // converted from `T`, they are the same values as from `i64`.
            let inv_area = T::narrow(t.area).real::<R>().recip();
            k1 = z_difference::<R>(t.z[0], t.z[1]) * inv_area;
            k2 = z_difference::<R>(t.z[0], t.z[2]) * inv_area;
            dz = k1 * edges[1].step_x.real::<R>() + k2 * edges[2].step_x.real::<R>();
        }
        DepthPlane {
            z0: R::from_u32(t.z[0]),
            k1,
            k2,
            dz,
            dz_fixed: dz.to_fixed(D::FRAC),
            bias: [edges[1].bias, edges[2].bias],
        }
    }

    /// Depth at the pixel whose biased edge values 1 and 2 are `e1`, `e2`.
    #[inline(always)]
    fn z_at<T: EdgeInt>(&self, e1: T, e2: T) -> R {
        self.z0
            + self.k1 * e1.unbiased::<R>(self.bias[0])
            + self.k2 * e2.unbiased::<R>(self.bias[1])
    }
}

impl<R: Real, const N: usize> Shader<R, N> {
    #[cfg_attr(target_pointer_width = "32", inline(always))]
    fn new<C: PixelFormat, D: DepthBuffer + ?Sized, T: EdgeInt>(
        t: &SetupTriangle<N>,
        edges: &[Edge<T>; 3],
    ) -> Self {
        let plane = DepthPlane::<R>::new::<N, D, T>(t, edges);
        let smooth = C::SHADED && t.smooth;
        let mut dv = [0.0f32; N];
        let mut dw = 0.0f32;
        // (Unused where every pixel re-synchronises: see `step`.)
        if smooth && resync(N) > 1 {
            let st = [
                edges[0].step_x.widen() as f32,
                edges[1].step_x.widen() as f32,
                edges[2].step_x.widen() as f32,
            ];
            let cw = &t.var_w;
            for (c, d) in dv.iter_mut().enumerate() {
                *d = st[0] * cw[0][c] + st[1] * cw[1][c] + st[2] * cw[2][c];
            }
            dw = st[0] * t.inv_w[0] + st[1] * t.inv_w[1] + st[2] * t.inv_w[2];
        }
        Shader {
            z0: plane.z0,
            k1: plane.k1,
            k2: plane.k2,
            dz: plane.dz,
            dz_fixed: plane.dz_fixed,
            bias: [edges[0].bias, edges[1].bias, edges[2].bias],
            dv,
            dw,
            smooth,
        }
    }

    /// The depth plane it holds.
    #[cfg(not(target_pointer_width = "32"))]
    fn plane(&self) -> DepthPlane<R> {
        DepthPlane {
            z0: self.z0,
            k1: self.k1,
            k2: self.k2,
            dz: self.dz,
            dz_fixed: self.dz_fixed,
            bias: [self.bias[1], self.bias[2]],
        }
    }

    /// Depth at the pixel whose biased edge values 1 and 2 are `e1`, `e2`
    /// (0 without a depth buffer).
    #[inline(always)]
    fn z_at<D: DepthBuffer + ?Sized, T: EdgeInt>(&self, e1: T, e2: T) -> R {
        if D::ENABLED {
            self.z0
                + self.k1 * e1.unbiased::<R>(self.bias[1])
                + self.k2 * e2.unbiased::<R>(self.bias[2])
        } else {
            R::ZERO
        }
    }

    /// The interpolants at the pixel whose biased edge values are `e`,
    /// evaluated from the exact edge values.
    #[inline(always)]
    fn start<D: DepthBuffer + ?Sized, T: EdgeInt>(
        &self,
        t: &SetupTriangle<N>,
        e: [T; 3],
    ) -> Acc<R, N> {
        let z = self.z_at::<D, T>(e[1], e[2]);
        let mut v = [0.0f32; N];
        let mut w = 0.0f32;
        if self.smooth {
            let f = [
                e[0].unbiased_f32(self.bias[0]),
                e[1].unbiased_f32(self.bias[1]),
                e[2].unbiased_f32(self.bias[2]),
            ];
            let cw = &t.var_w;
            for (ch, v) in v.iter_mut().enumerate() {
                *v = f[0] * cw[0][ch] + f[1] * cw[1][ch] + f[2] * cw[2][ch];
            }
            w = f[0] * t.inv_w[0] + f[1] * t.inv_w[1] + f[2] * t.inv_w[2];
        }
        Acc { z, v, w }
    }

    /// The varyings (not depth) at the pixel whose biased edge values are
    /// `e`, evaluated from the exact edge values.
    #[inline(always)]
    fn resync<T: EdgeInt>(&self, t: &SetupTriangle<N>, e: [T; 3], a: &mut Acc<R, N>) {
        let f = [
            e[0].unbiased_f32(self.bias[0]),
            e[1].unbiased_f32(self.bias[1]),
            e[2].unbiased_f32(self.bias[2]),
        ];
        let cw = &t.var_w;
        for (ch, v) in a.v.iter_mut().enumerate() {
            *v = f[0] * cw[0][ch] + f[1] * cw[1][ch] + f[2] * cw[2][ch];
        }
        a.w = f[0] * t.inv_w[0] + f[1] * t.inv_w[1] + f[2] * t.inv_w[2];
    }

    /// Moves the interpolants one pixel to the right. (Varyings that are
    /// re-synchronised at every pixel, `resync(N) == 1`, are not stepped:
    /// the steps would be overwritten unread, and their registers are
    /// better spent across the fragment shader's call.)
    #[inline(always)]
    fn step<D: DepthBuffer + ?Sized>(&self, a: &mut Acc<R, N>) {
        if D::ENABLED {
            a.z = a.z + self.dz;
        }
        if self.smooth && resync(N) > 1 {
            for k in 0..N {
                a.v[k] += self.dv[k];
            }
            a.w += self.dw;
        }
    }

    /// Depth-tests and writes the pixel at `idx` with interpolants `a`.
    /// Returns 1 if written.
    #[allow(clippy::too_many_arguments)]
    #[inline(always)]
    fn pixel<C: PixelFormat, D: DepthBuffer + ?Sized, F: FragmentShader<N>, const LESS: bool>(
        &self,
        t: &SetupTriangle<N>,
        strip: &mut Strip<'_, C, D>,
        fragment: &F,
        idx: usize,
        a: &Acc<R, N>,
        z32: u32,
        flat: C,
    ) -> u32 {
        // `LESS`: the caller found `Less` with writes on (see `draw`).
        let (func, write) = match LESS {
            true => (DepthFunc::Less, true),
            false => (strip.depth_func, strip.depth_write),
        };
        if D::ENABLED && !strip.depth.test_and_set(idx, z32, func, write) {
            return 0;
        }
        let value = if self.smooth {
            let inv = 1.0 / a.w;
            let v = a.v.map(|c| c * inv);
            C::from_fragment(fragment.shade(&v, t.id), t.id)
        } else {
            // Converted once per triangle.
            flat
        };
        match strip.color.get_mut(idx) {
            Some(px) => {
                *px = value;
                1
            }
            None => 0,
        }
    }
}

/// Draws one triangle into the strip; returns the number of pixels written.
#[inline]
pub(crate) fn draw<
    const S: u32,
    const N: usize,
    C: PixelFormat,
    D: DepthBuffer + ?Sized,
    F: FragmentShader<N>,
>(
    t: &SetupTriangle<N>,
    strip: &mut Strip<'_, C, D>,
    fragment: &F,
) -> u32 {
    // On 64-bit hosts the common depth test (`Less`, writes on) gets
    // its own copy of the pixel loops, so that no pixel dispatches on the
    // test (a jump table a pixel: the tgx sphere's smooth spans). 32-bit
    // cores keep one copy (flash).
    let less = cfg!(not(target_pointer_width = "32"))
        && D::ENABLED
        && C::SHADED
        && t.smooth
        && strip.depth_func == DepthFunc::Less
        && strip.depth_write;
    let written = match (D::WIDE, t.edge32, less) {
        (true, true, false) => draw_in::<S, N, C, D, F, f64, i32, false>(t, strip, fragment),
        (true, false, false) => draw_in::<S, N, C, D, F, f64, i64, false>(t, strip, fragment),
        (false, true, false) => draw_in::<S, N, C, D, F, f32, i32, false>(t, strip, fragment),
        (false, false, false) => draw_in::<S, N, C, D, F, f32, i64, false>(t, strip, fragment),
        (true, true, true) => draw_in::<S, N, C, D, F, f64, i32, true>(t, strip, fragment),
        (true, false, true) => draw_in::<S, N, C, D, F, f64, i64, true>(t, strip, fragment),
        (false, true, true) => draw_in::<S, N, C, D, F, f32, i32, true>(t, strip, fragment),
        (false, false, true) => draw_in::<S, N, C, D, F, f32, i64, true>(t, strip, fragment),
    };
    if strip.track && written != 0 {
        // Every pixel `draw_in` writes lies in the triangle's box.
        let (x, y) = (t.min_x as u32, t.min_y as u32);
        strip.touched.add(x, t.max_x as u32, y, t.max_y as u32);
    }
    written
}

/// [`draw`] with depth interpolated in `R` and edge values in `T`.
fn draw_in<
    const S: u32,
    const N: usize,
    C: PixelFormat,
    D: DepthBuffer + ?Sized,
    F: FragmentShader<N>,
    R: Real,
    T: EdgeInt,
    const LESS: bool,
>(
    t: &SetupTriangle<N>,
    strip: &mut Strip<'_, C, D>,
    fragment: &F,
) -> u32 {
    let row_first = (t.min_y as u32).max(strip.y0);
    let row_last = (t.max_y as u32).min(strip.y1.saturating_sub(1));
    if row_first > row_last || strip.y1 == 0 {
        return 0;
    }
    let smooth = C::SHADED && t.smooth;
    // A flat triangle's colour in the output format, once per strip.
    let flat = if smooth {
        C::from_fragment(t.flat, t.id)
    } else {
        C::from_fragment(fragment.shade_flat(&t.var_w[0], t.flat, t.id), t.id)
    };
    let crosses = (t.min_x as u32) < strip.x0 || (t.max_x as u32) >= strip.x1;
    #[cfg(feature = "lazy-clear")]
    if strip.lazy.is_some() {
        let rows = (row_first, row_last);
        if let Some(written) = lazy::enter::<S, N, C, D, R, T>(t, rows, strip, flat) {
            return written;
        }
    }
    if EARLY_FLAT && !smooth && !crosses && t.max_x - t.min_x >= SMALL_WIDTH {
        // Flat spans, the most common case: their loop sets up its own
        // edges and depth plane, so none of it is handed over.
        return flat_rows::<S, N, C, D, R, T>(t, (row_first, row_last), strip, flat);
    }
    let mut edges: [Edge<T>; 3] = edges_at::<S, N, T>(t, row_first);
    let shader = Shader::<R, N>::new::<C, D, T>(t, &edges);
    if crosses {
        // The box crosses the window's left or right side (tiles only).
        return window_rows::<N, C, D, F, R, T>(
            t,
            edges,
            &shader,
            (row_first, row_last),
            strip,
            fragment,
            flat,
        );
    }
    let max_n = (t.max_x - t.min_x) as usize;
    let mut written = 0u32;
    let mut base =
        (row_first - strip.y0) as usize * strip.width + (t.min_x as u32 - strip.x0) as usize;

    if t.max_x - t.min_x < SMALL_WIDTH {
        // Pixel by pixel over the box: a sign test per pixel.
        let step = [edges[0].step_x, edges[1].step_x, edges[2].step_x];
        for _ in row_first..=row_last {
            let mut e = [edges[0].row, edges[1].row, edges[2].row];
            // Skip to the row's first covered pixel; interpolants start
            // there, where every edge value is non-negative (no
            // cancellation).
            let mut n = 0usize;
            while n <= max_n && (e[0] | e[1] | e[2]) < T::ZERO {
                e[0] += step[0];
                e[1] += step[1];
                e[2] += step[2];
                n += 1;
            }
            if n <= max_n {
                // Covered pixels of a row are contiguous (the triangle is
                // convex): draw until the first uncovered one.
                let mut acc = shader.start::<D, T>(t, e);
                for k in n..=max_n {
                    if (e[0] | e[1] | e[2]) < T::ZERO {
                        break;
                    }
                    // (Never, for colours: their period exceeds the box.)
                    if resync(N) <= SMALL_WIDTH as usize
                        && shader.smooth
                        && (k - n).is_multiple_of(resync(N))
                        && k != n
                    {
                        shader.resync(t, e, &mut acc);
                    }
                    written += shader.pixel::<C, D, F, LESS>(
                        t,
                        strip,
                        fragment,
                        base + k,
                        &acc,
                        small_key::<D, R>(acc.z),
                        flat,
                    );
                    e[0] += step[0];
                    e[1] += step[1];
                    e[2] += step[2];
                    shader.step::<D>(&mut acc);
                }
            }
            for edge in edges.iter_mut() {
                edge.row += edge.step_y;
            }
            base += strip.width;
        }
        return written;
    }

    // Flat span triangles, where `EARLY_FLAT` is off (otherwise they
    // returned above), with the edges and depth plane set up here; then
    // the smooth spans.
    // (Compiled only where `EARLY_FLAT` is off.)
    #[cfg(not(target_pointer_width = "32"))]
    if !shader.smooth {
        let rows = (row_first, row_last);
        return flat_rows_given::<N, C, D, R, T>(t, rows, strip, flat, edges, &shader);
    }
    {
        let mut spans = RowSpans::new(&edges, max_n);
        for _ in row_first..=row_last {
            if let Some((lo, hi)) = spans.span(&edges) {
                let mut e = [edges[0].at(lo), edges[1].at(lo), edges[2].at(lo)];
                let mut acc = shader.start::<D, T>(t, e);
                // Depth exactly as on a flat span (the same Z32.F steps from
                // the same start), so the written depth never depends on the
                // pixel type; varyings re-synchronise every `resync(N)` pixels.
                let mut z = acc.z.to_fixed(D::FRAC);
                let (lo, hi) = (lo.widen() as usize, hi.widen() as usize);
                for n in lo..=hi {
                    if (n - lo).is_multiple_of(resync(N)) && n != lo {
                        shader.resync(t, e, &mut acc);
                    }
                    let key = D::key_of(z);
                    written += shader.pixel::<C, D, F, LESS>(
                        t,
                        strip,
                        fragment,
                        base + n,
                        &acc,
                        key,
                        flat,
                    );
                    z = z.wrapping_add(shader.dz_fixed);
                    e[0] += edges[0].step_x;
                    e[1] += edges[1].step_x;
                    e[2] += edges[2].step_x;
                    shader.step::<D>(&mut acc);
                }
            }
            spans.next();
            for edge in edges.iter_mut() {
                edge.row += edge.step_y;
            }
            base += strip.width;
        }
        written
    }
}

/// Whether flat span triangles go to [`flat_rows`] before their edges and
/// depth plane are set up (32-bit cores: nothing is marshalled across the
/// call, M4F four-cubes rasterization -2.4 k, M0 -68 k) or after (64-bit
/// hosts, where the early test made the smooth sphere 2.4 % slower in
/// interleaved runs). The pixels are the same either way.
const EARLY_FLAT: bool = cfg!(target_pointer_width = "32");

/// The triangle's three edge functions at the centre of the first column
/// of its box on row `row`. Edge `k` is opposite vertex `k`: from vertex
/// `k + 1` to vertex `k + 2`.
#[inline(always)]
fn edges_at<const S: u32, const N: usize, T: EdgeInt>(
    t: &SetupTriangle<N>,
    row: u32,
) -> [Edge<T>; 3] {
    let half = 1i64 << (S - 1);
    let px = ((t.min_x as i64) << S) + half;
    let py = ((row as i64) << S) + half;
    let (x, y) = (t.x, t.y);
    [
        Edge::new::<S>(x[1], y[1], x[2], y[2], px, py),
        Edge::new::<S>(x[2], y[2], x[0], y[0], px, py),
        Edge::new::<S>(x[0], y[0], x[1], y[1], px, py),
    ]
}

/// [`draw_in`] for a triangle whose box crosses the window's left or
/// right side: every row's run is found and started exactly where the
/// whole row's is (the same span, the same depth start, the same
/// varying re-synchronisations), then only its columns inside the window
/// are drawn. So a tile's pixels and depths are the ones a strip holding
/// the whole row gets, whatever the tile size. The run is entered at the
/// window's first column in `O(resync)` steps, not walked from its start:
/// depth in `Z32.F` is `z0 + k dz` (wrapping, as stepping is), varyings
/// restart at the last re-synchronisation point before it.
#[allow(clippy::too_many_arguments)]
#[inline(never)]
fn window_rows<
    const N: usize,
    C: PixelFormat,
    D: DepthBuffer + ?Sized,
    F: FragmentShader<N>,
    R: Real,
    T: EdgeInt,
>(
    t: &SetupTriangle<N>,
    mut edges: [Edge<T>; 3],
    shader: &Shader<R, N>,
    (row_first, row_last): (u32, u32),
    strip: &mut Strip<'_, C, D>,
    fragment: &F,
    flat: C,
) -> u32 {
    let (min_x, max_n) = (t.min_x as usize, (t.max_x - t.min_x) as usize);
    let (x0, x1) = (strip.x0 as usize, strip.x1 as usize);
    if x1 <= min_x || x0 > min_x + max_n {
        return 0;
    }
    // The window's columns as offsets from the box's first column; box
    // column `n` in `wlo..=whi` is buffer column `min_x + n - x0`.
    let (wlo, whi) = (x0.saturating_sub(min_x), (x1 - 1 - min_x).min(max_n));
    let at = |row: usize, n: usize| row + (min_x + n - x0);
    let mut row = (row_first - strip.y0) as usize * strip.width;
    let mut written = 0u32;
    let r = resync(N);

    if max_n < SMALL_WIDTH as usize {
        // As `draw_in`'s box loop, stepping over columns outside the window.
        let step = [edges[0].step_x, edges[1].step_x, edges[2].step_x];
        for _ in row_first..=row_last {
            let mut e = [edges[0].row, edges[1].row, edges[2].row];
            let mut n = 0usize;
            while n <= max_n && (e[0] | e[1] | e[2]) < T::ZERO {
                e[0] += step[0];
                e[1] += step[1];
                e[2] += step[2];
                n += 1;
            }
            if n <= max_n {
                let mut acc = shader.start::<D, T>(t, e);
                for k in n..=max_n.min(whi) {
                    if (e[0] | e[1] | e[2]) < T::ZERO {
                        break;
                    }
                    if r <= SMALL_WIDTH as usize
                        && shader.smooth
                        && (k - n).is_multiple_of(r)
                        && k != n
                    {
                        shader.resync(t, e, &mut acc);
                    }
                    if k >= wlo {
                        written += shader.pixel::<C, D, F, false>(
                            t,
                            strip,
                            fragment,
                            at(row, k),
                            &acc,
                            small_key::<D, R>(acc.z),
                            flat,
                        );
                    }
                    e[0] += step[0];
                    e[1] += step[1];
                    e[2] += step[2];
                    shader.step::<D>(&mut acc);
                }
            }
            for edge in edges.iter_mut() {
                edge.row += edge.step_y;
            }
            row += strip.width;
        }
        return written;
    }

    let mut spans = RowSpans::new(&edges, max_n);
    for _ in row_first..=row_last {
        if let Some((lo, hi)) = spans.span(&edges) {
            let (lo_n, hi_n) = (lo.widen() as usize, hi.widen() as usize);
            let (l, h) = (lo_n.max(wlo), hi_n.min(whi));
            if l <= h {
                let e_lo = [edges[0].at(lo), edges[1].at(lo), edges[2].at(lo)];
                if shader.smooth {
                    let acc0 = shader.start::<D, T>(t, e_lo);
                    let mut z = acc0
                        .z
                        .to_fixed(D::FRAC)
                        .wrapping_add(((l - lo_n) as i64).wrapping_mul(shader.dz_fixed));
                    // The last re-synchronisation point at or before `l`.
                    let p = lo_n + (l - lo_n) / r * r;
                    let pt = T::from_usize(p);
                    let mut e = [edges[0].at(pt), edges[1].at(pt), edges[2].at(pt)];
                    let mut acc = acc0;
                    if p != lo_n {
                        shader.resync(t, e, &mut acc);
                    }
                    for _ in p..l {
                        e[0] += edges[0].step_x;
                        e[1] += edges[1].step_x;
                        e[2] += edges[2].step_x;
                        shader.step::<D>(&mut acc);
                    }
                    for n in l..=h {
                        if (n - lo_n).is_multiple_of(r) && n != lo_n && n != p {
                            shader.resync(t, e, &mut acc);
                        }
                        written += shader.pixel::<C, D, F, false>(
                            t,
                            strip,
                            fragment,
                            at(row, n),
                            &acc,
                            D::key_of(z),
                            flat,
                        );
                        z = z.wrapping_add(shader.dz_fixed);
                        e[0] += edges[0].step_x;
                        e[1] += edges[1].step_x;
                        e[2] += edges[2].step_x;
                        shader.step::<D>(&mut acc);
                    }
                } else {
                    let z0 = shader.z_at::<D, T>(e_lo[1], e_lo[2]).to_fixed(D::FRAC);
                    written += strip.depth.flat_span(
                        strip.color,
                        at(row, l),
                        h - l + 1,
                        z0.wrapping_add(((l - lo_n) as i64).wrapping_mul(shader.dz_fixed)),
                        shader.dz_fixed,
                        strip.depth_func,
                        strip.depth_write,
                        flat,
                    );
                }
            }
        }
        spans.next();
        for edge in edges.iter_mut() {
            edge.row += edge.step_y;
        }
        row += strip.width;
    }
    written
}

/// The span rows of a flat triangle (one colour, so only depth varies):
/// per row the exact span, its depth start from the exact edge values,
/// then the depth buffer's flat-span loop. The same pixels and depths as
/// the smooth path's spans (the same `Z32.F` steps from the same start).
///
/// Out of line, with only the depth state live in its rows (not the
/// smooth path's registers), and it sets up the edges and the depth plane
/// itself from the triangle: nothing but the triangle, its rows and its
/// colour is handed over.
#[inline(never)]
fn flat_rows<
    const S: u32,
    const N: usize,
    C: PixelFormat,
    D: DepthBuffer + ?Sized,
    R: Real,
    T: EdgeInt,
>(
    t: &SetupTriangle<N>,
    (row_first, row_last): (u32, u32),
    strip: &mut Strip<'_, C, D>,
    px: C,
) -> u32 {
    let mut edges: [Edge<T>; 3] = edges_at::<S, N, T>(t, row_first);
    let rows = row_last - row_first + 1;
    let max_n = (t.max_x - t.min_x) as usize;
    let mut base =
        (row_first - strip.y0) as usize * strip.width + (t.min_x as u32 - strip.x0) as usize;
    let facts = if D::ENABLED && D::FRAC == 0 && strip.depth_write {
        facts(t)
    } else {
        0
    };
    if facts & Z_IN_RANGE != 0 {
        let cmp = match strip.depth_func {
            DepthFunc::Less => Some(cmp::LESS),
            DepthFunc::LessEqual => Some(cmp::LESS_EQUAL),
            DepthFunc::Greater => Some(cmp::GREATER),
            DepthFunc::GreaterEqual => Some(cmp::GREATER_EQUAL),
            _ => None,
        };
        // (The depth plane alone: the rest of a `Shader` is not needed.)
        let args = (
            edges,
            &DepthPlane::new::<N, D, T>(t, &edges),
            rows,
            base,
            max_n,
        );
        let sides = facts & SIDES;
        // `Less`, the default, with its test folded in; the others share
        // one copy that picks each span's loop (flash over a few
        // instructions a span).
        match cmp {
            Some(cmp::LESS) => {
                return flat_rows_in_range::<N, C, D, R, T, true>(args, sides, strip, cmp::LESS, px)
            }
            Some(cmp) => {
                return flat_rows_in_range::<N, C, D, R, T, false>(args, sides, strip, cmp, px)
            }
            None => {}
        }
    }
    let shader = &Shader::<R, N>::new::<C, D, T>(t, &edges);
    let mut written = 0u32;
    let mut spans = RowSpans::new(&edges, max_n);
    for _ in 0..rows {
        if let Some((lo, hi)) = spans.span(&edges) {
            // Depth stepped in Z32.F from the span's exact start (error
            // below 1/8 LSB over 2^14 pixels), in the depth buffer's
            // branch-free loop.
            let z0 = shader.z_at::<D, T>(edges[1].at(lo), edges[2].at(lo));
            let (lo, hi) = (lo.widen() as usize, hi.widen() as usize);
            written += strip.depth.flat_span(
                strip.color,
                base + lo,
                hi - lo + 1,
                z0.to_fixed(D::FRAC),
                shader.dz_fixed,
                strip.depth_func,
                strip.depth_write,
                px,
            );
        }
        spans.next();
        for edge in edges.iter_mut() {
            edge.row += edge.step_y;
        }
        base += strip.width;
    }
    written
}

/// [`flat_rows`] for a triangle whose edges (at the first row) and depth
/// plane its caller has set up already: 64-bit hosts, where `EARLY_FLAT`
/// is off (4 interleaved rounds of `bench --scene cubes`: 1.7 % less
/// time than setting them up again in `flat_rows`). The same rows as
/// `flat_rows`, in a copy of its text: `flat_rows` calling a shared
/// `#[inline(always)]` body cost the Cortex-M0 7.8 k instructions a frame.
#[cfg(not(target_pointer_width = "32"))]
#[inline(never)]
fn flat_rows_given<const N: usize, C: PixelFormat, D: DepthBuffer + ?Sized, R: Real, T: EdgeInt>(
    t: &SetupTriangle<N>,
    (row_first, row_last): (u32, u32),
    strip: &mut Strip<'_, C, D>,
    px: C,
    mut edges: [Edge<T>; 3],
    shader: &Shader<R, N>,
) -> u32 {
    let rows = row_last - row_first + 1;
    let max_n = (t.max_x - t.min_x) as usize;
    let mut base =
        (row_first - strip.y0) as usize * strip.width + (t.min_x as u32 - strip.x0) as usize;
    let facts = if D::ENABLED && D::FRAC == 0 && strip.depth_write {
        facts(t)
    } else {
        0
    };
    if facts & Z_IN_RANGE != 0 {
        let cmp = match strip.depth_func {
            DepthFunc::Less => Some(cmp::LESS),
            DepthFunc::LessEqual => Some(cmp::LESS_EQUAL),
            DepthFunc::Greater => Some(cmp::GREATER),
            DepthFunc::GreaterEqual => Some(cmp::GREATER_EQUAL),
            _ => None,
        };
        let (args, sides) = ((edges, &shader.plane(), rows, base, max_n), facts & SIDES);
        // `Less`, the default, with its test folded in; the others share
        // one copy that picks each span's loop (flash over a few
        // instructions a span).
        match cmp {
            Some(cmp::LESS) => {
                return flat_rows_in_range::<N, C, D, R, T, true>(args, sides, strip, cmp::LESS, px)
            }
            Some(cmp) => {
                return flat_rows_in_range::<N, C, D, R, T, false>(args, sides, strip, cmp, px)
            }
            None => {}
        }
    }
    let mut written = 0u32;
    let mut spans = RowSpans::new(&edges, max_n);
    for _ in 0..rows {
        if let Some((lo, hi)) = spans.span(&edges) {
            // Depth stepped in Z32.F from the span's exact start (error
            // below 1/8 LSB over 2^14 pixels), in the depth buffer's
            // branch-free loop.
            let z0 = shader.z_at::<D, T>(edges[1].at(lo), edges[2].at(lo));
            let (lo, hi) = (lo.widen() as usize, hi.widen() as usize);
            written += strip.depth.flat_span(
                strip.color,
                base + lo,
                hi - lo + 1,
                z0.to_fixed(D::FRAC),
                shader.dz_fixed,
                strip.depth_func,
                strip.depth_write,
                px,
            );
        }
        spans.next();
        for edge in edges.iter_mut() {
            edge.row += edge.step_y;
        }
        base += strip.width;
    }
    written
}

/// Whether every depth the rows of a triangle with vertex depths `z`
/// (`Z32`) and a box `max_n + 1` pixels wide step through stays in `[0,
/// 2^32)`, for `Z32.0` spans started in `f32` ([`Shader::z_at`]): then no
/// span needs [`in_range_throughout`](crate::depth) or a clamp.
///
/// Proof. At a covered pixel the exact plane is `Z0 + (Z1 - Z0) b1 + (Z2 -
/// Z0) b2` with barycentrics `b` in `[0, 1]`, so it lies in `[min Z, max
/// Z]`. In `f32` (unit roundoff `u = 2^-24`) `k1 = fl(fl(Z1 - Z0) fl(1 /
/// area))` carries a relative error below `3u`, the edge value's
/// conversion `u` and the product `u`: the term `k1 e1` is off by at most
/// `5u |Z1 - Z0| < 5u 2^32 = 1280`, and so is `k2 e2`; `Z0`'s conversion
/// adds 256 and the two sums at most 512 each (their values stay below
/// `2^33`): the span's start is within 3,840 of the plane. Adding `0.5`
/// and truncating adds at most 257. The step `dz = fl(fl(k1 sx1) + fl(k2
/// sx2))` is off by at most `5u (|k1 sx1| + |k2 sx2|) + u |dz|`; over a
/// span of `n` steps between two covered pixels `n |k1 sx1| = |Z1 - Z0|
/// |Δb1| < 2^32` (both ends have `b1` in `[0, 1]`), so the drift is below
/// `6u 2^33 = 3,072`, plus `n / 2 <= max_n / 2` from rounding `dz` to an
/// integer. Every stepped value is within `7,169 + max_n / 2 < 2^13 +
/// max_n` of a value in `[min Z, max Z]`, and a margin of `2^14 + max_n`
/// on both sides leaves it in range (the debug assertion in
/// `flat_span_in_range` checks every span of the property tests).
#[inline]
fn z_never_clamps(z: [u32; 3], max_n: usize) -> bool {
    let margin = (1u64 << 14) + max_n as u64;
    let lo = z[0].min(z[1]).min(z[2]) as u64;
    let hi = z[0].max(z[1]).max(z[2]) as u64;
    lo >= margin && hi + margin < 1 << 32
}

/// [`flat_rows`] where [`z_never_clamps`] holds for a `Z32.0` buffer
/// under an ordered test (`cmp`, a `depth::cmp` constant; `LESS` folds
/// in `Less`, the default, and otherwise one copy serves the other three,
/// each span's loop picked by `cmp`) with writes: the span's start is converted
/// straight to `u32` (`to_fixed` gives the same integer for a value in
/// range) and every span goes to the unclamped loop.
fn flat_rows_in_range<
    const N: usize,
    C: PixelFormat,
    D: DepthBuffer + ?Sized,
    R: Real,
    T: EdgeInt,
    const LESS: bool,
>(
    (mut edges, plane, rows, mut base, max_n): ([Edge<T>; 3], &DepthPlane<R>, u32, usize, usize),
    sides: u8,
    strip: &mut Strip<'_, C, D>,
    cmp: u8,
    px: C,
) -> u32 {
    let cmp = if LESS { cmp::LESS } else { cmp };
    let mut written = 0u32;
    // Batched only for `i32` edges: the rare wider triangles take the
    // row loop (their own copies of the span finder were 6.5 KB of flash
    // on the Cortex-M4F).
    if DIVIDE_IS_SLOW || T::WIDE {
        let mut spans = RowSpans::new(&edges, max_n);
        for _ in 0..rows {
            if let Some((lo, hi)) = spans.span(&edges) {
                let z0 = plane.z_at(edges[1].at(lo), edges[2].at(lo));
                let (lo, hi) = (lo.widen() as usize, hi.widen() as usize);
                written += strip.depth.flat_span_in_range(
                    strip.color,
                    base + lo,
                    hi - lo + 1,
                    z0.round_in_range(),
                    plane.dz_fixed,
                    cmp,
                    px,
                );
            }
            spans.next();
            for edge in edges.iter_mut() {
                edge.row += edge.step_y;
            }
            base += strip.width;
        }
        return written;
    }
    // A horizontal edge covers whole rows or none: the rows it covers are
    // a run, and cut to it, the edge bounds no span ([`FLAT`], below).
    let (mut first, mut end) = (0i64, rows as i64);
    for e in edges.iter() {
        if e.step_x == T::ZERO {
            let (e0, sy) = (e.row.widen(), e.step_y.widen());
            // Rows r with e0 + r sy >= 0.
            if sy > 0 {
                if e0 < 0 {
                    first = first.max((-e0 + sy - 1) / sy);
                }
            } else if sy < 0 {
                end = end.min(if e0 < 0 { 0 } else { e0 / -sy + 1 });
            } else if e0 < 0 {
                end = 0;
            }
        }
    }
    if first >= end {
        return 0;
    }
    if first > 0 {
        for e in edges.iter_mut() {
            e.row = T::narrow(e.row.widen() + first * e.step_y.widen());
        }
        base += first as usize * strip.width;
    }
    let rows = (end - first) as usize;
    // Each edge's side, two bits an edge ([`RIGHT`], [`LEFT`] or [`FLAT`],
    // found at setup: [`flat_facts`]): a triangle has a left and a right
    // edge, the third any of the three, so twelve patterns.
    debug_assert_eq!(
        sides,
        edges.iter().enumerate().fold(0u8, |b, (k, e)| {
            let side = match e.step_x.cmp(&T::ZERO) {
                core::cmp::Ordering::Greater => LEFT,
                core::cmp::Ordering::Less => RIGHT,
                core::cmp::Ordering::Equal => FLAT,
            };
            b | side << (2 * k)
        })
    );
    let max_n = T::from_usize(max_n);
    let mut left = rows;
    while left > 0 {
        let n = left.min(ROW_BATCH);
        let out = (&mut strip.spans, n, base, strip.width);
        // One copy of the span finder a pattern.
        macro_rules! by_sides {
            ($($p:ident),*) => {
                match sides {
                    $($p => batch_spans::<R, T, $p>(&mut edges, plane, max_n, out),)*
                    // (No other pattern has positive area.)
                    _ => 0,
                }
            };
        }
        let k = by_sides!(
            P_LLR, P_LRL, P_RLL, P_RRL, P_RLR, P_LRR, P_FLR, P_FRL, P_LFR, P_RFL, P_LRF, P_RLF
        );
        let spans = &strip.spans[..k];
        written += strip
            .depth
            .flat_spans_in_range(strip.color, spans, plane.dz_fixed, cmp, px);
        base += n * strip.width;
        left -= n;
    }
    written
}

/// [`SetupTriangle::flat_facts`](crate::SetupTriangle) of a triangle with
/// vertex rows `y` (`Sub<S>`, wound as set up), depths `z` (`Z32`) and a
/// box `max_n + 1` pixels wide: the sides of edges 0, 1 and 2 ([`sides3`];
/// edge `k` runs from vertex `k + 1` to vertex `k + 2`, and its `step_x`
/// is `-(y_b - y_a)` times the subpixel unit, so its side is the sign of
/// `y_a - y_b`) in the [`SIDES`] bits, and [`Z_IN_RANGE`] where
/// [`z_never_clamps`]. Both depend on the triangle alone, so setup finds
/// them once a frame (when a [`Frame`](crate::Frame) stores the
/// triangle) rather than [`flat_rows`] once a strip. A box narrower than
/// [`SMALL_WIDTH`] never reaches `flat_rows` and gets 0, as do triangles
/// set up in immediate mode (`flat_rows` finds those itself: 0 is never
/// a pattern of sides). Spot's triangles, mostly that small and set up
/// again every strip in immediate mode, paid 3-4 % of the M4F's frame
/// for facts found at every setup.
pub(crate) fn flat_facts(y: [i32; 3], z: [u32; 3], max_n: usize) -> u8 {
    if max_n < SMALL_WIDTH as usize {
        return 0;
    }
    let side = |ya: i32, yb: i32| match ya.cmp(&yb) {
        core::cmp::Ordering::Greater => LEFT,
        core::cmp::Ordering::Less => RIGHT,
        core::cmp::Ordering::Equal => FLAT,
    };
    let sides = sides3(side(y[1], y[2]), side(y[2], y[0]), side(y[0], y[1]));
    sides
        | if z_never_clamps(z, max_n) {
            Z_IN_RANGE
        } else {
            0
        }
}

/// [`flat_facts`] of a set-up triangle.
#[inline]
pub(crate) fn flat_facts_of<const N: usize>(t: &SetupTriangle<N>) -> u8 {
    flat_facts(t.y, t.z, (t.max_x - t.min_x) as usize)
}

/// The triangle's flat facts: the stored ones, or (immediate mode) found
/// now.
#[inline(always)]
fn facts<const N: usize>(t: &SetupTriangle<N>) -> u8 {
    match t.flat_facts {
        0 => flat_facts_of(t),
        f => f,
    }
}

/// The bits of [`flat_facts`] that hold the sides pattern.
const SIDES: u8 = 0x3f;
/// The bit of [`flat_facts`] set where [`z_never_clamps`] holds.
const Z_IN_RANGE: u8 = 0x80;

/// An edge that bounds spans on the right (`step_x < 0`), on the left
/// (`step_x > 0`), or neither (horizontal): [`batch_spans`]'s sides, two
/// bits an edge ([`sides3`]).
const RIGHT: u8 = 0;
const LEFT: u8 = 1;
const FLAT: u8 = 2;

/// The sides of edges 0, 1 and 2 as one pattern.
const fn sides3(a: u8, b: u8, c: u8) -> u8 {
    a | b << 2 | c << 4
}

// The twelve patterns with area, edges 0, 1 and 2 in order (L left, R
// right, F flat): two sides of three, or a flat edge and one of each.
const P_LLR: u8 = sides3(LEFT, LEFT, RIGHT);
const P_LRL: u8 = sides3(LEFT, RIGHT, LEFT);
const P_RLL: u8 = sides3(RIGHT, LEFT, LEFT);
const P_RRL: u8 = sides3(RIGHT, RIGHT, LEFT);
const P_RLR: u8 = sides3(RIGHT, LEFT, RIGHT);
const P_LRR: u8 = sides3(LEFT, RIGHT, RIGHT);
const P_FLR: u8 = sides3(FLAT, LEFT, RIGHT);
const P_FRL: u8 = sides3(FLAT, RIGHT, LEFT);
const P_LFR: u8 = sides3(LEFT, FLAT, RIGHT);
const P_RFL: u8 = sides3(RIGHT, FLAT, LEFT);
const P_LRF: u8 = sides3(LEFT, RIGHT, FLAT);
const P_RLF: u8 = sides3(RIGHT, LEFT, FLAT);

/// Rows whose spans [`flat_rows_in_range`] finds before it draws them:
/// each loop then keeps its own values in registers (one loop doing both
/// spilled a third of them every row). Their storage is the `Strip`'s
/// (144 bytes). On the Cortex-M4F, four cubes in 12-row strips (when this
/// was chosen): 409,560 instructions a frame with 12, 410,240 with 16,
/// 413,160 with 10, 422,720 with 8; with 16 the house's firmware
/// (`house-portals`) outgrew its 24 KB of RAM. Where division is slow the
/// rows are not batched (the `Strip` keeps one slot, unused).
pub(crate) const ROW_BATCH: usize = if DIVIDE_IS_SLOW { 1 } else { 12 };

/// The spans of the next `n` rows, the first starting at `base` in the
/// buffers, the rest `width` apart: `[start, length, Z32 start]` each
/// (none for an empty row; a strip's buffers, whose index fits `u32`,
/// hold every start), and the sum of their lengths, for edges whose
/// sides are `SIDES` ([`sides3`]). The same spans as three
/// [`Edge::clip_span`]s, without a branch on a side: a left edge of step
/// `d > 0` covers `n >= ceil(-E / d)`, which is `(d - 1 - E) / d`
/// truncated when `E <= 0` and at most 0 (no bound) otherwise; a right
/// edge of step `-d` covers `n <= floor(E / d)`, which is `E / d` when
/// `E >= 0`, and for `E < 0` nothing: or-ing in the sign (`E >> 31`, all
/// ones) makes the bound -1. A horizontal edge bounds nothing: its
/// caller has cut the rows to where its `E >= 0`. The operands stay in
/// the ranges [`EDGE32_SPAN`] proves; each divisor is at least 1 (no
/// division check).
#[inline(never)]
fn batch_spans<R: Real, T: EdgeInt, const SIDES: u8>(
    edges: &mut [Edge<T>; 3],
    plane: &DepthPlane<R>,
    max_n: T,
    (out, n, base, width): (&mut [[u32; 3]; ROW_BATCH], usize, usize, usize),
) -> usize {
    let side = |k: usize| (SIDES >> (2 * k)) & 3;
    // Each edge's `|step_x|` (at least 1: no division check), and its
    // step as a multiple of it (0 for a horizontal edge).
    let d: [T; 3] = core::array::from_fn(|k| {
        let a = edges[k].step_x;
        if side(k) == LEFT {
            a.max(T::ONE)
        } else {
            (-a).max(T::ONE)
        }
    });
    let step_x = |k: usize| match side(k) {
        LEFT => d[k],
        RIGHT => -d[k],
        _ => T::ZERO,
    };
    let mut e = [edges[0].row, edges[1].row, edges[2].row];
    let mut row = base;
    // A slot every row (`n <= ROW_BATCH`), of length 0 where the row has
    // no span: one count for the loop and the slots, no branch a row.
    let k = n.min(ROW_BATCH);
    for slot in out[..k].iter_mut() {
        let (mut lo, mut hi) = (T::ZERO, max_n);
        for k in 0..3 {
            match side(k) {
                LEFT => lo = lo.max((d[k] - T::ONE - e[k]) / d[k]),
                RIGHT => hi = hi.min(e[k].sign_mask() | (e[k] / d[k])),
                _ => {}
            }
        }
        // An empty row's depth start is computed too, and not used: every
        // row lies in the vertices' vertical extent, where the triangle's
        // slice is an interval (maybe pixel-free) within their horizontal
        // extent, so `lo` is at most one column past the vertices' box
        // (past `max_n` where the box is clamped to the frame), where the
        // edge values and `step_x * lo` still fit `i32` (`EDGE32_SPAN`:
        // at most 177 columns of steps below 11,520,000). The tests'
        // overflow checks exercise it (`tests/lazy_clear.rs` draws rows
        // with `lo` beyond `max_n + 1`).
        let z0 = plane.z_at(e[1] + step_x(1) * lo, e[2] + step_x(2) * lo);
        let start = row.wrapping_add(lo.widen() as usize) as u32;
        let len = if lo <= hi {
            (hi - lo).widen() as u32 + 1
        } else {
            0
        };
        *slot = [start, len, z0.round_in_range()];
        row = row.wrapping_add(width);
        for k in 0..3 {
            e[k] += edges[k].step_y;
        }
        // (An empty barrier: LLVM unrolled the loop by two without it,
        // and spilled half of its values; 4,600 instructions more on the
        // Cortex-M4F's four cubes.)
        core::hint::black_box(());
    }
    for k in 0..3 {
        edges[k].row = e[k];
    }
    k
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// Every row of the triangle's box (and one beyond): the walked span
    /// equals the three `clip_span`s', as `T`.
    fn check_walk<T: EdgeInt + core::fmt::Debug>(
        x: [i32; 3],
        y: [i32; 3],
    ) -> Result<(), TestCaseError> {
        const S: u32 = 8;
        let half = 1i64 << (S - 1);
        let (min_x, max_x) = (x.iter().min().unwrap() >> S, x.iter().max().unwrap() >> S);
        let (min_y, max_y) = (y.iter().min().unwrap() >> S, y.iter().max().unwrap() >> S);
        let px = ((min_x as i64) << S) + half;
        let py = ((min_y as i64) << S) + half;
        let mut edges: [Edge<T>; 3] = [
            Edge::new::<S>(x[1], y[1], x[2], y[2], px, py),
            Edge::new::<S>(x[2], y[2], x[0], y[0], px, py),
            Edge::new::<S>(x[0], y[0], x[1], y[1], px, py),
        ];
        let max_n = (max_x - min_x) as usize;
        let mut walk = SpanWalk::new(&edges);
        for row in 0..=(max_y - min_y + 1) {
            let (mut lo, mut hi) = (T::ZERO, T::from_usize(max_n));
            let covered = edges[0].clip_span(&mut lo, &mut hi)
                && edges[1].clip_span(&mut lo, &mut hi)
                && edges[2].clip_span(&mut lo, &mut hi);
            prop_assert_eq!(
                walk.span(T::from_usize(max_n)),
                covered.then_some((lo, hi)),
                "row {}",
                row
            );
            for e in edges.iter_mut() {
                e.row += e.step_y;
            }
            walk.next();
        }
        Ok(())
    }

    proptest! {
        // Few cases under Miri, and no failure file (as in `depth.rs`).
        #![proptest_config(ProptestConfig {
            cases: if cfg!(miri) { 4 } else { 2048 },
            failure_persistence: None,
            ..ProptestConfig::default()
        })]

        /// `i32` edges: vertices within `EDGE32_SPAN` (both windings; the
        /// walk does not care), including horizontal and vertical edges
        /// from the coarse grid.
        #[test]
        fn span_walk_equals_clip_span_i32(
            x in [0i32..45_000, 0i32..45_000, 0i32..45_000],
            y in [0i32..45_000, 0i32..45_000, 0i32..45_000],
            coarse in any::<bool>(),
        ) {
            let snap = |v: [i32; 3]| if coarse { v.map(|c| c & !0x3ff) } else { v };
            check_walk::<i32>(snap(x), snap(y))?;
        }

        /// The flat facts setup stores are the ones the edges give: each
        /// edge's side from the sign of its `step_x` (as `i32` and `i64`
        /// edges), and [`Z_IN_RANGE`] where `z_never_clamps` holds.
        #[test]
        fn flat_facts_are_the_edges_sides(
            x in [0i32..45_000, 0i32..45_000, 0i32..45_000],
            y in [0i32..45_000, 0i32..45_000, 0i32..45_000],
            coarse in any::<bool>(),
            z in [
                prop_oneof![any::<u32>(), 0u32..1 << 16, u32::MAX - (1 << 16)..=u32::MAX],
                prop_oneof![any::<u32>(), 0u32..1 << 16, u32::MAX - (1 << 16)..=u32::MAX],
                prop_oneof![any::<u32>(), 0u32..1 << 16, u32::MAX - (1 << 16)..=u32::MAX],
            ],
            max_n in prop_oneof![0usize..16, 0usize..4096],
        ) {
            let snap = |v: [i32; 3]| if coarse { v.map(|c| c & !0x3ff) } else { v };
            let (x, y) = (snap(x), snap(y));
            let facts = flat_facts(y, z, max_n);
            let pattern = |steps: [i64; 3]| {
                steps.iter().enumerate().fold(0u8, |b, (k, &s)| {
                    let side = match s.cmp(&0) {
                        core::cmp::Ordering::Greater => LEFT,
                        core::cmp::Ordering::Less => RIGHT,
                        core::cmp::Ordering::Equal => FLAT,
                    };
                    b | side << (2 * k)
                })
            };
            let e32: [Edge<i32>; 3] = [
                Edge::new::<8>(x[1], y[1], x[2], y[2], 128, 128),
                Edge::new::<8>(x[2], y[2], x[0], y[0], 128, 128),
                Edge::new::<8>(x[0], y[0], x[1], y[1], 128, 128),
            ];
            let e64: [Edge<i64>; 3] = [
                Edge::new::<8>(x[1], y[1], x[2], y[2], 128, 128),
                Edge::new::<8>(x[2], y[2], x[0], y[0], 128, 128),
                Edge::new::<8>(x[0], y[0], x[1], y[1], 128, 128),
            ];
            if max_n < SMALL_WIDTH as usize {
                prop_assert_eq!(facts, 0);
            } else {
                // (0 is "not found": never a pattern.)
                prop_assert_ne!(facts, 0);
                prop_assert_eq!(facts & SIDES, pattern(e32.map(|e| e.step_x as i64)));
                prop_assert_eq!(facts & SIDES, pattern(e64.map(|e| e.step_x)));
                prop_assert_eq!(facts & Z_IN_RANGE != 0, z_never_clamps(z, max_n));
                prop_assert_eq!(facts & !(SIDES | Z_IN_RANGE), 0);
            }
        }

        /// `z_difference` converts the exact difference, by either route
        /// (the 32-bit cores' one, `z_difference_via_i32`, tested here too):
        /// the same `f32` and `f64` as from `i64`, on both sides of the
        /// `i32` range.
        #[test]
        fn z_difference_is_the_i64_conversion(
            z0 in prop_oneof![any::<u32>(), 0u32..4, u32::MAX - 3..=u32::MAX, (1u32 << 31) - 2..(1 << 31) + 2],
            z1 in prop_oneof![any::<u32>(), 0u32..4, u32::MAX - 3..=u32::MAX, (1u32 << 31) - 2..(1 << 31) + 2],
        ) {
            let d = z1 as i64 - z0 as i64;
            prop_assert_eq!(z_difference::<f32>(z0, z1).to_bits(), (d as f32).to_bits());
            prop_assert_eq!(z_difference_via_i32::<f32>(z0, z1).to_bits(), (d as f32).to_bits());
            prop_assert_eq!(z_difference::<f64>(z0, z1).to_bits(), (d as f64).to_bits());
            prop_assert_eq!(z_difference_via_i32::<f64>(z0, z1).to_bits(), (d as f64).to_bits());
        }

        /// `i64` edges: vertices spanning up to 2^22 subpixel units.
        #[test]
        fn span_walk_equals_clip_span_i64(
            x in [-(1i32 << 21)..(1 << 21), -(1i32 << 21)..(1 << 21), -(1i32 << 21)..(1 << 21)],
            y in [0i32..(1 << 14), 0i32..(1 << 14), 0i32..(1 << 14)],
        ) {
            check_walk::<i64>(x, y)?;
        }
    }
}
