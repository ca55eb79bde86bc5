//! Occlusion culling: objects hidden behind what a strip already holds are
//! skipped before any of their vertices is transformed.
//!
//! Design note: a [`StripRenderer`] draws each object into its strip at
//! once, so when the next object comes the strip's depth buffer already
//! says how near the nearest drawn surface is at every pixel. An
//! [`Occluder`] keeps a coarse copy of it: the largest depth word
//! ("hi-z") of every [`HIZ_TILE`] x [`HIZ_TILE`] tile of the strip, in a
//! slice of [`HiZTile`]s the caller owns ([`tiles_for`] of them: 80 for a
//! 320x16 strip, 640 bytes). Before an object is submitted its bounding
//! sphere is projected to a conservative [`ScreenBound`]: a pixel
//! rectangle holding every pixel centre any of its triangles can cover,
//! and a depth `near` below every depth any of those pixels can get. If
//! that depth fails the depth test against the largest stored depth of
//! every tile the rectangle touches, no pixel of the object can pass it:
//! the object is counted in [`Stats::culled_occlusion`] and nothing of it
//! is transformed. Where a tile's largest depth lets it pass and the
//! rectangle covers only part of the tile, that part is tested pixel by
//! pixel against the depth buffer itself (the tile's far pixels may lie
//! outside the rectangle: a silhouette's background; on the herd of
//! Spots this hides 63.5 % of the triangles instead of 53.3 %).
//! Otherwise it is drawn, and the tiles its rectangle
//! touches are marked stale; a stale tile is read again from the depth
//! buffer the next time a test needs it. So a test costs the tiles it
//! touches, and the buffer is read only where something was drawn since
//! or where a tile's maximum did not decide.
//!
//! Conservative, so the frame is the one the plain submissions draw
//! (a property test compares them byte for byte, `tests/occlusion.rs`):
//! - the bound is computed from the sphere's bounding box's eight corners
//!   in `f64` (in `f32` with wider margins on 32-bit targets, where `f64`
//!   is software: [`ScreenBound::of_box_f32`], tested to hold the `f64`
//!   bound), where a projection's extremes over a box in front of the eye
//!   lie (`x / w`, `y / w` and `z / w` are linear-fractional: monotone
//!   along every segment where `w > 0`). The vertex stage's `f32` error
//!   (`γ` times the magnitudes, as [`BoundingSphere::outside_frustum`]
//!   bounds it) widens the rectangle, with one more pixel for snapping
//!   and pixel centres, and lowers `near`, with 2^18 `Z32` units (four
//!   `u16` LSBs) more for the depth plane's interpolation and stepping,
//!   whose error stays below a quarter of a `u16` LSB at a covered pixel
//!   (see [`crate::raster`]). Clipped vertices lie on the edges of the
//!   triangles they cut, so inside the same box;
//! - a sphere not wholly in front of the eye (with margin), or not finite,
//!   has no bound: its object is drawn and marks every tile stale;
//! - only [`DepthFunc::Less`] and [`DepthFunc::LessEqual`] hide; under any
//!   other test nothing is culled.
//!
//! The caller keeps two promises, as for [`Mesh::bounds`]: the sphere
//! bounds the object, and whatever [`Occluder::submit_with`]'s closure
//! draws is the object the sphere bounds. The occluder borrows the
//! renderer, so nothing else draws into the strip while it lives. Objects
//! submitted front to back hide the most.

use crate::color::PixelFormat;
use crate::config::{Config, Error};
use crate::depth::{DepthFunc, DepthWord};
use crate::math::{Mat4, Vec3};
use crate::mesh::{BoundingSphere, Mesh, ProcessedVertex};
use crate::pipeline::Submit;
use crate::shade::{Attributes, FragmentShader};
use crate::stats::Stats;
use crate::strip_renderer::StripRenderer;

/// The side of a hi-z tile, in pixels.
pub const HIZ_TILE: u32 = 8;

/// One tile's largest depth key, and whether it is up to date. The
/// default is stale.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct HiZTile {
    max: u32,
    fresh: bool,
}

/// The hi-z tiles a strip of `width` columns and `rows` rows needs.
pub const fn tiles_for(width: u32, rows: u32) -> usize {
    (width.div_ceil(HIZ_TILE) as usize) * (rows.div_ceil(HIZ_TILE) as usize)
}

/// The vertex stage's `f32` error relative to the magnitudes, with room
/// to spare (as [`BoundingSphere::outside_frustum`] uses).
pub(crate) const GAMMA: f64 = 16.0 / 16_777_216.0;

/// The depth interpolation's margin, in `Z32` units: four `u16` LSBs.
const Z_MARGIN: u32 = 1 << 18;

/// An axis-aligned box in object space, `min` to `max` (each component
/// `min <= max`): a tighter bound than a sphere for long or flat objects.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Aabb {
    /// The smallest corner.
    pub min: Vec3,
    /// The largest corner.
    pub max: Vec3,
}

impl Aabb {
    /// The box from `min` to `max`.
    pub const fn new(min: Vec3, max: Vec3) -> Aabb {
        Aabb { min, max }
    }

    /// The smallest box holding `points` (`None` if empty or not finite).
    pub fn from_points(points: &[Vec3]) -> Option<Aabb> {
        let first = points.first()?;
        let (mut lo, mut hi) = (*first, *first);
        for p in points {
            if !p.is_finite() {
                return None;
            }
            lo = Vec3::new(lo.x.min(p.x), lo.y.min(p.y), lo.z.min(p.z));
            hi = Vec3::new(hi.x.max(p.x), hi.y.max(p.y), hi.z.max(p.z));
        }
        Some(Aabb { min: lo, max: hi })
    }
}

/// A conservative screen bound of an object: every pixel centre one of its
/// triangles covers lies in columns `x0..x1` and rows `y0..y1` (clamped to
/// the frame), and every depth it gets there is at least `near` (`Z32`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ScreenBound {
    /// First column.
    pub x0: u32,
    /// One past the last column.
    pub x1: u32,
    /// First row.
    pub y0: u32,
    /// One past the last row.
    pub y1: u32,
    /// A lower bound of the object's window depths, `Z32`.
    pub near: u32,
}

impl ScreenBound {
    /// The bound of everything the sphere holds under `mvp` in a frame of
    /// `config`'s size, or `None` where there is none: a sphere reaching
    /// behind the eye (or within rounding of it), or anything not finite.
    pub fn of_sphere(sphere: &BoundingSphere, mvp: &Mat4, config: &Config) -> Option<ScreenBound> {
        let r = sphere.radius;
        let c = sphere.center;
        if !(r >= 0.0 && r.is_finite()) {
            return None;
        }
        let rv = Vec3::new(r, r, r);
        ScreenBound::of_box(&Aabb::new(c - rv, c + rv), mvp, config)
    }

    /// The bound of everything the box holds under `mvp` in a frame of
    /// `config`'s size, or `None` where there is none (as
    /// [`ScreenBound::of_sphere`]): [`ScreenBound::of_box_f64`] on 64-bit
    /// targets, [`ScreenBound::of_box_f32`] on 32-bit ones, whose `f64`
    /// is software on most (on the Cortex-M4F the herd of
    /// `docs/culling.md` took 4x the instructions of its plain frame with
    /// `f64` bounds, 0.71x with `f32` ones).
    pub fn of_box(aabb: &Aabb, mvp: &Mat4, config: &Config) -> Option<ScreenBound> {
        if cfg!(target_pointer_width = "64") {
            ScreenBound::of_box_f64(aabb, mvp, config)
        } else {
            ScreenBound::of_box_f32(aabb, mvp, config)
        }
    }

    /// [`ScreenBound::of_box`] in `f32`: the same steps with wider margins
    /// for its own rounding (the corners' projections, `γ4` of their
    /// magnitudes, and the divisions and the viewport's), so that it holds
    /// [`ScreenBound::of_box_f64`]'s bound (a rectangle at least as large,
    /// `near` at most as far, or `None`): a property test compares the
    /// two over random boxes, cameras and frame sizes.
    pub fn of_box_f32(aabb: &Aabb, mvp: &Mat4, config: &Config) -> Option<ScreenBound> {
        bound_of_box::<f32>(aabb, mvp, config)
    }

    /// [`ScreenBound::of_box`] in `f64`: the reference the `f32` path is
    /// tested against, and the bound on 64-bit targets.
    pub fn of_box_f64(aabb: &Aabb, mvp: &Mat4, config: &Config) -> Option<ScreenBound> {
        bound_of_box::<f64>(aabb, mvp, config)
    }
}

/// The float a [`ScreenBound`] is computed in, with the margins for that
/// computation's own rounding (none beyond the vertex stage's in `f64`,
/// whose rounding is far below the `f32` vertex stage's error it allows
/// for).
trait BoundFloat:
    Copy
    + PartialOrd
    + core::ops::Add<Output = Self>
    + core::ops::Sub<Output = Self>
    + core::ops::Mul<Output = Self>
    + core::ops::Div<Output = Self>
{
    const ZERO: Self;
    const ONE: Self;
    const HALF: Self;
    const INFINITY: Self;
    /// The relative error of a corner's clip coordinates, times their
    /// magnitudes: the vertex stage's `f32` error (`GAMMA`, 16 u), and in
    /// `f32` this evaluation's own (four products summed, under 5 u of
    /// the magnitude, itself rounded): 32 u.
    const GAMMA: Self;
    /// The division `x / w`'s own rounding, relative to `|x / w|` (4 u
    /// in `f32`, 0 in `f64`).
    const DIVISION: Self;
    /// A factor on the NDC error for its own sum's rounding (1 + 2^-10 in
    /// `f32`, 1 in `f64`).
    const SUM: Self;
    /// Pixels added for snapping, the pixel centres and the viewport
    /// transform (and in `f32` a hundredth for this transform's own
    /// rounding, below 2 u of `MAX_DIMENSION`).
    const PIXEL: Self;
    /// Subtracted from the window depth for its `f32` evaluation by the
    /// vertex stage (a few ulps of 1: 2^-20), twice that in `f32`.
    const Z_SLACK: Self;
    /// `2^32`, the scale of `Z32`.
    const Z32: Self;
    fn of_f32(v: f32) -> Self;
    fn of_u32(v: u32) -> Self;
    fn abs(self) -> Self;
    fn is_finite(self) -> bool;
    fn is_nan(self) -> bool;
    /// Truncated, saturating (`as u32`).
    fn to_u32(self) -> u32;
}

impl BoundFloat for f64 {
    const ZERO: f64 = 0.0;
    const ONE: f64 = 1.0;
    const HALF: f64 = 0.5;
    const INFINITY: f64 = f64::INFINITY;
    const GAMMA: f64 = GAMMA;
    const DIVISION: f64 = 0.0;
    const SUM: f64 = 1.0;
    const PIXEL: f64 = 1.0;
    const Z_SLACK: f64 = 1.0 / 1_048_576.0;
    const Z32: f64 = 4_294_967_296.0;
    fn of_f32(v: f32) -> f64 {
        v as f64
    }
    fn of_u32(v: u32) -> f64 {
        v as f64
    }
    fn abs(self) -> f64 {
        f64::abs(self)
    }
    fn is_finite(self) -> bool {
        f64::is_finite(self)
    }
    fn is_nan(self) -> bool {
        f64::is_nan(self)
    }
    fn to_u32(self) -> u32 {
        self as u32
    }
}

impl BoundFloat for f32 {
    const ZERO: f32 = 0.0;
    const ONE: f32 = 1.0;
    const HALF: f32 = 0.5;
    const INFINITY: f32 = f32::INFINITY;
    const GAMMA: f32 = 32.0 / 16_777_216.0;
    const DIVISION: f32 = 4.0 / 16_777_216.0;
    const SUM: f32 = 1.0 + 1.0 / 1024.0;
    const PIXEL: f32 = 1.01;
    const Z_SLACK: f32 = 1.0 / 524_288.0;
    const Z32: f32 = 4_294_967_296.0;
    fn of_f32(v: f32) -> f32 {
        v
    }
    fn of_u32(v: u32) -> f32 {
        v as f32
    }
    fn abs(self) -> f32 {
        f32::abs(self)
    }
    fn is_finite(self) -> bool {
        f32::is_finite(self)
    }
    fn is_nan(self) -> bool {
        f32::is_nan(self)
    }
    fn to_u32(self) -> u32 {
        self as u32
    }
}

/// [`ScreenBound::of_box`] in `F`.
#[inline(always)]
fn bound_of_box<F: BoundFloat>(aabb: &Aabb, mvp: &Mat4, config: &Config) -> Option<ScreenBound> {
    let lo = [aabb.min.x, aabb.min.y, aabb.min.z].map(F::of_f32);
    let hi = [aabb.max.x, aabb.max.y, aabb.max.z].map(F::of_f32);
    if !(lo.iter().chain(&hi).all(|v| v.is_finite())
        && (0..3).all(|k| lo[k] <= hi[k])
        && mvp.is_finite())
    {
        return None;
    }
    // Compared inline, not `f32::min` and `max` (library calls on Armv7-M:
    // a third of this bound's cost there), and without `math::fx`'s NaN
    // test (9 % more of the herd's frame on the M4F): the first argument
    // is never NaN here (the running extremes start infinite and take
    // only what passes a `<` or `>`, and the rest are finite), and a NaN
    // second one is passed over, as `f32::min` passes it over.
    let max = |a: F, b: F| if b > a { b } else { a };
    let min = |a: F, b: F| if b < a { b } else { a };
    let m = mvp.rows().map(|r| r.map(F::of_f32));
    let p_abs = [
        max(lo[0].abs(), hi[0].abs()),
        max(lo[1].abs(), hi[1].abs()),
        max(lo[2].abs(), hi[2].abs()),
        F::ONE,
    ];
    let mag = |i: usize| -> F { (0..4).fold(F::ZERO, |s, j| s + m[i][j].abs() * p_abs[j]) };
    let err = [
        mag(0) * F::GAMMA,
        mag(1) * F::GAMMA,
        mag(2) * F::GAMMA,
        mag(3) * F::GAMMA,
    ];
    let corner = (lo, hi);
    let mut lo = [F::INFINITY; 3];
    let mut hi = [F::ZERO - F::INFINITY; 3];
    let mut w_min = F::INFINITY;
    for k in 0..8 {
        let pick = |axis: usize| {
            if k >> axis & 1 == 0 {
                corner.0[axis]
            } else {
                corner.1[axis]
            }
        };
        let q = [pick(0), pick(1), pick(2), F::ONE];
        let row = |i: usize| -> F { (0..4).fold(F::ZERO, |s, j| s + m[i][j] * q[j]) };
        let w = row(3);
        w_min = min(w_min, w);
        for (i, (l, h)) in lo.iter_mut().zip(hi.iter_mut()).enumerate() {
            let v = row(i) / w;
            *l = min(*l, v);
            *h = max(*h, v);
        }
    }
    // Every computed w stays positive, with a margin.
    let w_low = w_min - err[3];
    if !(w_low > F::ZERO && w_low.is_finite()) {
        return None;
    }
    // |x_f / w_f - x / w| <= (e_x + |x / w| e_w) / (w - e_w), plus the
    // division's own rounding and this sum's.
    let ndc_err = |i: usize| {
        let v = max(lo[i].abs(), hi[i].abs());
        ((err[i] + v * err[3]) / w_low + v * F::DIVISION) * F::SUM
    };
    let (half_w, half_h) = (
        F::of_u32(config.width) * F::HALF,
        F::of_u32(config.height) * F::HALF,
    );
    let ex = ndc_err(0) * half_w + F::PIXEL;
    let ey = ndc_err(1) * half_h + F::PIXEL;
    let px = |v: F| v * half_w + half_w;
    let py = |v: F| half_h - v * half_h;
    // Clamped to [0, n] and truncated: the floor; one more for the
    // ceiling (at most one column or row too many).
    let floor = |v: F, n: u32| -> u32 {
        if v.is_nan() {
            0
        } else {
            min(max(v, F::ZERO), F::of_u32(n)).to_u32()
        }
    };
    let ceil = |v: F, n: u32| -> u32 {
        if v.is_nan() {
            n
        } else {
            (floor(v, n) + 1).min(n)
        }
    };
    let x0 = floor(px(lo[0]) - ex, config.width);
    let x1 = ceil(px(hi[0]) + ex, config.width);
    let y0 = floor(py(hi[1]) - ey, config.height);
    let y1 = ceil(py(lo[1]) + ey, config.height);
    // Window depth z / w / 2 + 1/2, less its errors.
    let z = lo[2] * F::HALF + F::HALF - ndc_err(2) * F::HALF - F::Z_SLACK;
    if !(ex.is_finite() && ey.is_finite() && z.is_finite()) {
        return None;
    }
    let near = if z <= F::ZERO {
        0
    } else {
        (z * F::Z32).to_u32().saturating_sub(Z_MARGIN)
    };
    Some(ScreenBound {
        x0,
        x1,
        y0,
        y1,
        near,
    })
}

/// What [`Occluder::test`] found: skip (counted), or draw with this bound.
enum Test {
    Skipped,
    Draw(Option<ScreenBound>),
}

/// A [`StripRenderer`] with hi-z tiles: submits objects, skipping those
/// hidden behind what the strip holds (see the [module](self)). Made by
/// [`StripRenderer::occluder`].
pub struct Occluder<'r, 'b, C, W, const S: u32, const N: usize, F> {
    renderer: &'r mut StripRenderer<'b, C, [W], S, N, F>,
    tiles: &'r mut [HiZTile],
    /// Tile columns.
    cols: u32,
    /// Whether the hi-z test runs (see [`Occluder::set_hiding`]).
    hiding: bool,
}

impl<C, W, const S: u32, const N: usize, F> core::fmt::Debug for Occluder<'_, '_, C, W, S, N, F> {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.debug_struct("Occluder")
            .field("renderer", &self.renderer)
            .field("tiles", &self.tiles.len())
            .finish()
    }
}

impl<'b, C: PixelFormat, W: DepthWord, const S: u32, const N: usize, F: FragmentShader<N>>
    StripRenderer<'b, C, [W], S, N, F>
{
    /// An [`Occluder`] over this renderer's strip, keeping its hi-z in
    /// `tiles` (at least [`tiles_for`] the strip's columns and rows; any
    /// contents: every tile starts stale). Fewer is
    /// [`Error::HiZSize`].
    pub fn occluder<'r>(
        &'r mut self,
        tiles: &'r mut [HiZTile],
    ) -> Result<Occluder<'r, 'b, C, W, S, N, F>, Error> {
        let s = &self.sink.strip;
        let (w, h) = (s.x1 - s.x0, s.y1 - s.y0);
        let needed = tiles_for(w, h);
        if tiles.len() < needed {
            return Err(Error::HiZSize {
                expected: needed,
                actual: tiles.len(),
            });
        }
        let tiles = &mut tiles[..needed];
        tiles.fill(HiZTile::default());
        Ok(Occluder {
            renderer: self,
            tiles,
            cols: w.div_ceil(HIZ_TILE),
            hiding: true,
        })
    }
}

impl<C: PixelFormat, W: DepthWord, const S: u32, const N: usize, F: FragmentShader<N>>
    Occluder<'_, '_, C, W, S, N, F>
{
    /// The renderer's counters so far.
    pub fn stats(&self) -> Stats {
        self.renderer.stats()
    }

    /// Turns the hi-z test off (or on again; it is on by default). Off,
    /// the occluder still skips objects whose bounds lie outside the
    /// frustum or miss the strip: the baseline occlusion culling is
    /// measured against, so that the difference is the hi-z test's alone.
    pub fn set_hiding(&mut self, on: bool) {
        self.hiding = on;
    }

    /// The tiles `bound` touches in this strip, as tile columns and rows
    /// (half-open), or `None` if it misses the strip.
    fn tile_range(&self, b: &ScreenBound) -> Option<([u32; 2], [u32; 2])> {
        let s = &self.renderer.sink.strip;
        let (x0, x1) = (b.x0.max(s.x0), b.x1.min(s.x1));
        let (y0, y1) = (b.y0.max(s.y0), b.y1.min(s.y1));
        if x0 >= x1 || y0 >= y1 {
            return None;
        }
        Some((
            [(x0 - s.x0) / HIZ_TILE, (x1 - s.x0).div_ceil(HIZ_TILE)],
            [(y0 - s.y0) / HIZ_TILE, (y1 - s.y0).div_ceil(HIZ_TILE)],
        ))
    }

    /// Whether an object with screen bound `b` would have no pixel pass
    /// the depth test in this strip. `false` where it misses the strip.
    pub fn hides(&mut self, b: &ScreenBound) -> bool {
        let strict = match self.renderer.sink.strip.depth_func {
            DepthFunc::Less => false,
            DepthFunc::LessEqual => true,
            _ => return false,
        };
        let Some(([tx0, tx1], [ty0, ty1])) = self.tile_range(b) else {
            return false;
        };
        let near = W::from_z32(b.near).key();
        let passes = |key: u32| near < key || (strict && near == key);
        for ty in ty0..ty1 {
            for tx in tx0..tx1 {
                if passes(self.tile_max(tx, ty)) && self.part_passes(b, tx, ty, passes) {
                    return false;
                }
            }
        }
        true
    }

    /// Whether `passes` holds for the stored key of a pixel of tile `(tx,
    /// ty)` inside `b`'s rectangle: the exact test where the tile's
    /// maximum failed. A tile wholly inside the rectangle has its
    /// maximum's answer; one the rectangle only touches is read again,
    /// only where it lies.
    fn part_passes(&self, b: &ScreenBound, tx: u32, ty: u32, passes: impl Fn(u32) -> bool) -> bool {
        let s = &self.renderer.sink.strip;
        let (w, h) = (s.x1 - s.x0, s.y1 - s.y0);
        let (tx0, ty0) = (tx * HIZ_TILE, ty * HIZ_TILE);
        let (tx1, ty1) = ((tx0 + HIZ_TILE).min(w), (ty0 + HIZ_TILE).min(h));
        let c0 = b.x0.saturating_sub(s.x0).max(tx0);
        let c1 = b.x1.saturating_sub(s.x0).min(tx1);
        let r0 = b.y0.saturating_sub(s.y0).max(ty0);
        let r1 = b.y1.saturating_sub(s.y0).min(ty1);
        if (c0, c1, r0, r1) == (tx0, tx1, ty0, ty1) {
            return true;
        }
        (r0..r1).any(|y| {
            let row = y as usize * s.width;
            s.depth
                .get(row + c0 as usize..row + c1 as usize)
                .is_none_or(|words| words.iter().any(|v| passes(v.key())))
        })
    }

    /// The largest key of tile `(tx, ty)`, read again if stale.
    fn tile_max(&mut self, tx: u32, ty: u32) -> u32 {
        let i = (ty * self.cols + tx) as usize;
        let Some(t) = self.tiles.get(i).copied() else {
            return u32::MAX;
        };
        if t.fresh {
            return t.max;
        }
        let s = &self.renderer.sink.strip;
        let (w, h) = (s.x1 - s.x0, s.y1 - s.y0);
        let (c0, c1) = (tx * HIZ_TILE, ((tx + 1) * HIZ_TILE).min(w));
        let mut max = 0u32;
        for y in ty * HIZ_TILE..((ty + 1) * HIZ_TILE).min(h) {
            let row = y as usize * s.width;
            let Some(words) = s.depth.get(row + c0 as usize..row + c1 as usize) else {
                return u32::MAX;
            };
            max = words.iter().fold(max, |m, v| m.max(v.key()));
        }
        self.tiles[i] = HiZTile { max, fresh: true };
        max
    }

    /// Marks the tiles `b` touches stale (every tile without a bound).
    fn touched(&mut self, b: Option<&ScreenBound>) {
        match b {
            None => self.tiles.fill(HiZTile::default()),
            Some(b) => {
                if let Some(([tx0, tx1], [ty0, ty1])) = self.tile_range(b) {
                    for ty in ty0..ty1 {
                        let row = (ty * self.cols) as usize;
                        if let Some(ts) = self.tiles.get_mut(row + tx0 as usize..row + tx1 as usize)
                        {
                            ts.fill(HiZTile::default());
                        }
                    }
                }
            }
        }
    }

    /// Submits an object of `triangles` triangles bounded by `sphere`
    /// under `mvp`. It is skipped, counted in [`Stats::submitted`] and
    /// returning `Ok(false)` without calling `draw`, if the sphere lies
    /// outside the frustum ([`Stats::culled_object`]), if it lies wholly
    /// above or below the strip or its bound misses the strip's pixels
    /// ([`Stats::outside_strip`]), or if the strip
    /// hides it ([`Stats::culled_occlusion`]). Otherwise it calls `draw` with the
    /// renderer and returns `Ok(true)` (or `draw`'s error). `draw` must
    /// submit only triangles inside `sphere` under `mvp` (any submission
    /// method: clusters, normal masks, a cached mesh); `sphere: None`
    /// draws and then reads the whole strip's hi-z again before the next
    /// test.
    pub fn submit_with<R>(
        &mut self,
        sphere: Option<&BoundingSphere>,
        mvp: &Mat4,
        triangles: u64,
        draw: R,
    ) -> Result<bool, Error>
    where
        R: FnOnce(&mut StripRenderer<'_, C, [W], S, N, F>) -> Result<(), Error>,
    {
        self.submit_bounded(sphere, None, mvp, triangles, draw)
    }

    /// [`Occluder::submit_with`] with a box as well as (or instead of) the
    /// sphere: the box, tighter for most objects, gives the screen bound;
    /// the sphere, if any, the frustum test and the strip's (tested
    /// first: it is cheaper than the box's projection). `draw` must
    /// submit only triangles inside both.
    pub fn submit_bounded<R>(
        &mut self,
        sphere: Option<&BoundingSphere>,
        aabb: Option<&Aabb>,
        mvp: &Mat4,
        triangles: u64,
        draw: R,
    ) -> Result<bool, Error>
    where
        R: FnOnce(&mut StripRenderer<'_, C, [W], S, N, F>) -> Result<(), Error>,
    {
        let bound = match self.test(sphere, aabb, mvp, triangles) {
            Test::Skipped => return Ok(false),
            Test::Draw(b) => b,
        };
        let result = draw(self.renderer);
        self.touched(bound.as_ref());
        result.map(|()| true)
    }

    /// Whether an object of `triangles` triangles bounded by `sphere` and
    /// `aabb` under `mvp` is skipped, as [`Occluder::submit_bounded`]
    /// would skip it (and counted so), without drawing anything. For
    /// objects split into parts with bounds of their own: the object is
    /// tested whole first, then each part is submitted.
    pub fn skips(
        &mut self,
        sphere: Option<&BoundingSphere>,
        aabb: Option<&Aabb>,
        mvp: &Mat4,
        triangles: u64,
    ) -> bool {
        matches!(self.test(sphere, aabb, mvp, triangles), Test::Skipped)
    }

    fn test(
        &mut self,
        sphere: Option<&BoundingSphere>,
        aabb: Option<&Aabb>,
        mvp: &Mat4,
        triangles: u64,
    ) -> Test {
        let config = self.renderer.stage.config;
        let skip = |stats: Stats| Stats {
            submitted: triangles,
            ..stats
        };
        if sphere.is_some_and(|s| s.outside_frustum(mvp)) {
            self.renderer.stats += skip(Stats {
                culled_object: triangles,
                ..Stats::default()
            });
            return Test::Skipped;
        }
        // Wholly above or below the strip by the sphere (the test
        // `submit_mesh` makes), before the box is projected: most parts
        // of a frame lie outside any one strip, and the slab test costs
        // a few dot products where the box costs eight corners.
        if let (Some(s), Some((top, bottom))) = (sphere, self.renderer.stage.slab) {
            if s.outside_slab(mvp, top, bottom) {
                self.renderer.stats += skip(Stats {
                    outside_strip: triangles,
                    ..Stats::default()
                });
                return Test::Skipped;
            }
        }
        let bound = match aabb {
            Some(b) => ScreenBound::of_box(b, mvp, &config),
            None => sphere.and_then(|s| ScreenBound::of_sphere(s, mvp, &config)),
        };
        if let Some(b) = &bound {
            if self.tile_range(b).is_none() {
                self.renderer.stats += skip(Stats {
                    outside_strip: triangles,
                    ..Stats::default()
                });
                return Test::Skipped;
            }
            if self.hiding && self.hides(b) {
                self.renderer.stats += skip(Stats {
                    culled_occlusion: triangles,
                    ..Stats::default()
                });
                return Test::Skipped;
            }
        }
        Test::Draw(bound)
    }

    /// [`Submit::submit_mesh_cached`] behind the occlusion test of the
    /// mesh's bounding sphere ([`Mesh::bounds`]; a mesh without one is
    /// always drawn). Returns whether it was drawn.
    pub fn submit_mesh_cached<A: Attributes<N>>(
        &mut self,
        mesh: &Mesh<'_, A>,
        mvp: &Mat4,
        first_id: u32,
        cache: &mut [ProcessedVertex],
    ) -> Result<bool, Error> {
        let n = mesh.indices.len() as u64;
        self.submit_with(mesh.bounds.as_ref(), mvp, n, |r| {
            r.submit_mesh_cached(mesh, mvp, first_id, cache)
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sphere(x: f32, y: f32, z: f32, r: f32) -> BoundingSphere {
        BoundingSphere {
            center: Vec3::new(x, y, z),
            radius: r,
        }
    }

    #[test]
    fn tiles_round_up() {
        assert_eq!(tiles_for(320, 16), 80);
        assert_eq!(tiles_for(321, 17), 41 * 3);
        assert_eq!(tiles_for(1, 1), 1);
    }

    #[test]
    fn a_sphere_reaching_behind_the_eye_has_no_bound() {
        let config = Config::new(64, 48);
        let mvp = Mat4::perspective(1.0, 64.0 / 48.0, 0.1, 100.0);
        assert!(ScreenBound::of_sphere(&sphere(0.0, 0.0, -5.0, 1.0), &mvp, &config).is_some());
        assert!(ScreenBound::of_sphere(&sphere(0.0, 0.0, -0.5, 1.0), &mvp, &config).is_none());
        assert!(ScreenBound::of_sphere(&sphere(0.0, 0.0, 3.0, 1.0), &mvp, &config).is_none());
        for bad in [f32::NAN, f32::INFINITY, -1.0] {
            assert!(ScreenBound::of_sphere(&sphere(0.0, 0.0, -5.0, bad), &mvp, &config).is_none());
        }
        for bad in [f32::NAN, f32::INFINITY] {
            assert!(ScreenBound::of_sphere(&sphere(bad, 0.0, -5.0, 1.0), &mvp, &config).is_none());
        }
    }

    #[test]
    fn a_bound_holds_the_projected_sphere() {
        let config = Config::new(64, 48);
        let mvp = Mat4::perspective(1.0, 64.0 / 48.0, 0.1, 100.0);
        let b = ScreenBound::of_sphere(&sphere(0.0, 0.0, -5.0, 1.0), &mvp, &config).unwrap();
        assert!(b.x0 < 32 && b.x1 > 32 && b.y0 < 24 && b.y1 > 24);
        assert!(b.x1 - b.x0 < 40, "{b:?}");
        // The sphere's nearest point, z = -4, at window depth ...
        let near = |d: f64| {
            let (n, f) = (0.1f64, 100.0f64);
            // OpenGL depth: z_ndc = (f + n) / (f - n) - 2 f n / ((f - n) d).
            let ndc = (f + n) / (f - n) - 2.0 * f * n / ((f - n) * d);
            ((ndc * 0.5 + 0.5) * 4_294_967_296.0) as u32
        };
        assert!(b.near <= near(4.0), "{} > {}", b.near, near(4.0));
        assert!(b.near > near(3.9));
    }

    /// The `f32` bound holds the `f64` one: no `f32` bound where the
    /// `f64` path finds none (a box reaching behind the eye), and
    /// otherwise a rectangle at least as large and `near` at most as far.
    fn check_f32_holds_f64(aabb: Aabb, mvp: Mat4, config: Config) -> Result<(), TestCaseError> {
        let wide = ScreenBound::of_box_f64(&aabb, &mvp, &config);
        let narrow = ScreenBound::of_box_f32(&aabb, &mvp, &config);
        match (wide, narrow) {
            (_, None) => {}
            (None, Some(c)) => prop_assert!(false, "f32 {c:?} where f64 has none"),
            (Some(b), Some(c)) => prop_assert!(
                c.x0 <= b.x0 && c.x1 >= b.x1 && c.y0 <= b.y0 && c.y1 >= b.y1 && c.near <= b.near,
                "f32 {c:?} does not hold f64 {b:?}"
            ),
        }
        Ok(())
    }

    use proptest::prelude::*;

    fn arb_box() -> impl Strategy<Value = Aabb> {
        (
            prop::array::uniform3(-20.0f32..20.0),
            prop::array::uniform3(prop_oneof![0.0f32..0.01, 0.0f32..3.0, 0.0f32..40.0]),
        )
            .prop_map(|(c, e)| {
                Aabb::new(
                    Vec3::new(c[0] - e[0], c[1] - e[1], c[2] - e[2]),
                    Vec3::new(c[0] + e[0], c[1] + e[1], c[2] + e[2]),
                )
            })
    }

    proptest! {
        #![proptest_config(ProptestConfig {
            cases: if cfg!(miri) { 4 } else { 4096 },
            failure_persistence: None,
            ..ProptestConfig::default()
        })]

        /// Cameras as scenes make them (a perspective of any field of
        /// view and depth range, looking anywhere), frames up to
        /// `MAX_DIMENSION`.
        #[test]
        fn the_f32_bound_holds_the_f64_bound_under_cameras(
            aabb in arb_box(),
            eye in prop::array::uniform3(-30.0f32..30.0),
            target in prop::array::uniform3(-30.0f32..30.0),
            fov in 0.05f32..3.0,
            near in prop_oneof![0.001f32..0.1, 0.1f32..5.0],
            depth in 1.0f32..1000.0,
            w in 1u32..=crate::MAX_DIMENSION,
            h in 1u32..=crate::MAX_DIMENSION,
        ) {
            let config = Config::new(w, h);
            let mvp = Mat4::perspective(fov, w as f32 / h as f32, near, near + depth)
                * Mat4::look_at(Vec3::from_array(eye), Vec3::from_array(target), Vec3::new(0.0, 1.0, 0.0));
            prop_assume!(mvp.is_finite());
            check_f32_holds_f64(aabb, mvp, config)?;
        }

        /// Any matrix (entries of mixed magnitudes) and boxes.
        #[test]
        fn the_f32_bound_holds_the_f64_bound_under_any_matrix(
            aabb in arb_box(),
            rows in prop::array::uniform4(prop::array::uniform4(prop_oneof![
                Just(0.0f32), -1.0f32..1.0, -100.0f32..100.0
            ])),
            w in 1u32..=crate::MAX_DIMENSION,
            h in 1u32..=crate::MAX_DIMENSION,
        ) {
            check_f32_holds_f64(aabb, Mat4::from_rows(rows), Config::new(w, h))?;
        }
    }
}
