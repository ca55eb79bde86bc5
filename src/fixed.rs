//! Fixed-point formats and snapping: where floats end.
//!
//! Design note: the vertex stage hands over `f32` clip-space positions; this
//! module is the single place they become integers. After it, coverage,
//! culling and depth interpolation are decided by exact integer arithmetic
//! only. Every format is named after its layout and carries its range:
//!
//! | name | type | meaning | range |
//! |---|---|---|---|
//! | `Sub<S>` | `i32` | window coordinate in units of `2^-S` pixel (S = [`SUBPIXEL_BITS`] 8 by default, or 4) | `|v| <= COORD_LIMIT = 2^28` |
//! | edge value | `i64` | twice the signed area of (edge, point) in `Sub<S>^2` units | `|e| < 2^59` |
//! | `Z32` | `u32` | window depth `[0, 1]` scaled by `2^32`, saturated to `u32::MAX` | `0 ..= 2^32 - 1` |
//! | `Z32.F` | `i64` | interpolated depth: `Z32` with `F` more fraction bits (`F` = 16 for `u32` depth buffers, 0 for `u16`) | `0 ..= 2^(32+F) - 1` at covered pixels |
//!
//! Ranges and why they hold:
//! - The frame is at most [`MAX_DIMENSION`] = 16384 pixels a side, so a pixel
//!   centre is at most `2^14 * 2^8 = 2^22` in `Sub<8>`.
//! - Triangles are clipped to a guard band of `|v| <= GUARD_BAND = 2^27`
//!   (in NDC: `|x| <= g_x w` with `g_x` from [`guard_band_ndc`]). Float
//!   rounding in the clipper can overshoot that by far less than a factor of
//!   two, and snapping rejects anything beyond `COORD_LIMIT = 2^28`, so
//!   every stored coordinate obeys `|v| <= 2^28` whatever the input was.
//! - Edge function: `dx * (py - ay) - dy * (px - ax)` with `|dx|, |dy| <=
//!   2^29` and `|p - a| < 2^29` gives `|e| < 2^59`, and the per-pixel step
//!   `dy << S` is below `2^37`: `i64` never overflows.
//! - Twice the triangle area is bounded the same way: `< 2^59`.
//!
//! Largest frame and guard band per subpixel precision:
//!
//! | S | subpixel | largest frame | guard band (pixels from the origin) |
//! |---|---|---|---|
//! | 8 | 1/256 px | 16384 x 16384 | ±2^19 = ±524,288 |
//! | 4 | 1/16 px | 16384 x 16384 | ±2^23 = ±8,388,608 |

/// The default number of subpixel bits (1/256 pixel).
pub const SUBPIXEL_BITS: u32 = 8;

/// The largest frame width or height, in pixels.
pub const MAX_DIMENSION: u32 = 1 << 14;

/// The guard band: clipping keeps window coordinates within `±GUARD_BAND`
/// `Sub<S>` units.
pub const GUARD_BAND: i32 = 1 << 27;

/// The hard limit on a snapped coordinate, `Sub<S>` units: twice the guard
/// band, so float rounding in the clipper can never reach it by accident.
pub const COORD_LIMIT: i32 = 1 << 28;

/// A vertex snapped to window space.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct SnappedVertex {
    /// Window x in `Sub<S>` units (pixel centre of column `i` is at
    /// `(i << S) + (1 << (S - 1))`).
    pub x: i32,
    /// Window y in `Sub<S>` units, rows counted from the top.
    pub y: i32,
    /// Window depth in `Z32`.
    pub z: u32,
}

/// The guard band in NDC units for a frame of `width x height` pixels at
/// `S` subpixel bits: clipping keeps `|x| <= gx * w` and `|y| <= gy * w`.
///
/// Chosen so that `(gx + 1) * width / 2 * 2^S <= GUARD_BAND`.
///
/// `S` must be 4 or 8: any other value fails to compile.
///
/// ```compile_fail
/// let _ = microraster::fixed::guard_band_ndc::<32>(64, 64);
/// ```
pub fn guard_band_ndc<const S: u32>(width: u32, height: u32) -> (f32, f32) {
    const { check_subpixel_bits::<S>() };
    let limit = (GUARD_BAND >> S) as f32; // pixels
    let gx = 2.0 * limit / width as f32 - 1.0;
    let gy = 2.0 * limit / height as f32 - 1.0;
    (gx, gy)
}

/// Rounds `v` to the nearest integer (halves up) and checks the result is
/// within `±COORD_LIMIT`. `None` for NaN, infinities and out-of-range values.
///
/// No float function is involved and no float rounding either: the
/// integer part comes from truncation, the fraction `v - trunc(v)` is exact
/// in `f32`, and it decides the rounding.
/// (`floor(v + 0.5)` would not do: for odd `v` in `[2^23, 2^24)` the sum is
/// a tie that `f32` rounds to even.)
#[inline]
fn round_to_coord(v: f32) -> Option<i32> {
    if !in_coord_range(v) {
        return None;
    }
    Some(round_in_range(v))
}

/// `v` is finite and within `±COORD_LIMIT` (NaN is not).
#[inline(always)]
pub(crate) fn in_coord_range(v: f32) -> bool {
    v.is_finite() && v.abs() <= COORD_LIMIT as f32
}

/// [`round_to_coord`] of a `v` that [`in_coord_range`] accepted; for any
/// other `v` some `i32`, never a panic.
#[inline(always)]
pub(crate) fn round_in_range(v: f32) -> i32 {
    round_from(v, v as i32)
}

/// `v` rounded to nearest, halves up, from `i`, `v` truncated toward zero.
/// For `|v| <= 2^28`, `i as f32` is exact (below 2^24 every integer is
/// representable; above it `v` is an integer), and so is the fraction `f
/// = v - i`, in (-1, 1).
#[inline(always)]
fn round_from(v: f32, i: i32) -> i32 {
    let f = v - i as f32;
    let up = (f >= 0.5) as i32;
    let down = (f < -0.5) as i32;
    // (Wrapping: beyond the range, where `i` saturated, some `i32`.)
    i.wrapping_add(up).wrapping_sub(down)
}

/// `v as i32` for a finite `v` with `|v| < 2^31` (more than
/// [`in_coord_range`] accepts), from the bits of `v` by shifts alone: the vertex stage's
/// batches (`mesh::process_batch`) convert eight lanes at once this way,
/// where the compiler keeps `as`'s saturation per lane, six scalar
/// instructions each. Outside that range some `i32`, never a panic.
/// (Tests: every exponent, the boundaries, random bit patterns.)
#[inline(always)]
pub(crate) fn trunc_in_range(v: f32) -> i32 {
    let (mag, _) = trunc_magnitude(v);
    let sign = (v.to_bits() as i32) >> 31;
    (mag as i32 ^ sign).wrapping_sub(sign)
}

/// [`round_in_range`] by [`trunc_in_range`]: the same `i32` for every `v`
/// [`in_coord_range`] accepts.
#[inline(always)]
pub(crate) fn round_in_range_by_bits(v: f32) -> i32 {
    round_from(v, trunc_in_range(v))
}

/// [`z01_to_z32`] (`as u32`: saturating, NaN 0) by shifts alone, as
/// [`trunc_in_range`], for every `f32`.
#[inline(always)]
pub(crate) fn z01_to_z32_by_bits(z: f32) -> u32 {
    let s = z * 4_294_967_296.0;
    let (mag, exp) = trunc_magnitude(s);
    let negative = s.to_bits() >> 31 != 0;
    // At or above 2^32 (infinity too) the most; NaN and below 0 nothing.
    let v = if exp >= 32 { u32::MAX } else { mag };
    if negative | s.is_nan() {
        0
    } else {
        v
    }
}

/// The magnitude of `v` truncated toward zero, for `|v| < 2^32` (beyond,
/// some `u32`), and the unbiased exponent of `v`: the significand with its
/// implicit bit shifted into place.
#[inline(always)]
fn trunc_magnitude(v: f32) -> (u32, i32) {
    let bits = v.to_bits();
    let exp = ((bits >> 23) & 0xff) as i32 - 127;
    let m = (bits & 0x7f_ffff) | 0x80_0000;
    // One shift or the other is 0; below 1 the right shift (at least 24)
    // leaves nothing of `m < 2^24`.
    let left = (exp - 23).clamp(0, 8) as u32;
    let right = (23 - exp).clamp(0, 31) as u32;
    ((m << left) >> right, exp)
}

/// `x as i64` (truncation toward zero, saturating, NaN gives 0) without the
/// library call a 32-bit core makes for it (`__aeabi_f2lz`, about 60
/// instructions with Rust's saturation around it on a Cortex-M4F): below
/// `2^31` the hardware `f32 -> i32` conversion, up to `2^32` the `u32`
/// one (the spans of `u16` depth buffers start in whole `Z32` units),
/// above it the integer significand shifted into place (an `f32` that
/// large is an integer). The rasterizer converts each span's start depth
/// (`Z32.F`, up to `2^48`) this way. Equal to `as` for every `f32` (tests: every exponent, the
/// boundaries, random bit patterns; the exhaustive run is ignored by
/// default).
#[inline(always)]
pub(crate) fn f32_as_i64(x: f32) -> i64 {
    if cfg!(target_pointer_width = "64") {
        // One instruction on a 64-bit host.
        x as i64
    } else {
        f32_as_i64_by_parts(x)
    }
}

/// [`f32_as_i64`] on 32-bit cores, tested on every host.
#[inline(always)]
pub(crate) fn f32_as_i64_by_parts(x: f32) -> i64 {
    let bits = x.to_bits();
    let exp = (bits >> 23) & 0xff;
    // |x| < 2^31 (biased exponent below 127 + 31): exact in i32.
    if exp < 158 {
        return x as i32 as i64;
    }
    // 2^31 <= x < 2^32: exact in u32 (the upper half of `Z32`).
    if exp == 158 && bits >> 31 == 0 {
        return x as u32 as i64;
    }
    // |x| >= 2^63, infinities and NaN: what `as` saturates to.
    if exp >= 190 {
        return x as i64;
    }
    // 2^31 <= |x| < 2^63: the 24-bit significand times 2^(exp - 150),
    // a left shift by 8..=39.
    let mag = (((bits & 0x7f_ffff) | 0x80_0000) as i64) << (exp - 150);
    if bits >> 31 != 0 {
        -mag
    } else {
        mag
    }
}

/// Fails to compile unless `S` is a supported subpixel precision (4 or 8):
/// `const { check_subpixel_bits::<S>() }` in every function generic over
/// `S` turns a bad `S` into a build error, never a run-time shift overflow.
pub(crate) const fn check_subpixel_bits<const S: u32>() {
    assert!(S == 4 || S == 8, "subpixel bits must be 4 or 8");
}

/// Snaps a clip-space position to window space at `S` subpixel bits.
///
/// Window x = `(x/w + 1) * width / 2`, window y = `(1 - y/w) * height / 2`
/// (row 0 is the top), window z = `(z/w + 1) / 2`. Both x and y are then
/// scaled by `2^S` and rounded to the nearest integer, halves up. Returns
/// `None` if `w` is not positive or a result is not finite or beyond
/// [`COORD_LIMIT`]; the caller counts that as rejected.
///
/// The arithmetic is `f32`, as on the vertex stage's fast path. Where that
/// fails for a finite input with `w > 0` (a `1 / w` beyond `f32`'s range,
/// which clipping can produce for `w` near `1e-38`), the same formula is
/// evaluated in `f64` instead, so such a vertex lands where it really is.
/// `S` must be 4 or 8:
///
/// ```compile_fail
/// let _ = microraster::fixed::snap::<32>(0.0, 0.0, 0.0, 1.0, 8, 8);
/// ```
pub fn snap<const S: u32>(
    x: f32,
    y: f32,
    z: f32,
    w: f32,
    width: u32,
    height: u32,
) -> Option<SnappedVertex> {
    const { check_subpixel_bits::<S>() };
    if w.is_nan() || w <= 0.0 {
        return None;
    }
    snap_inv::<S>(x, y, z, 1.0 / w, width, height)
        .or_else(|| snap_f64::<S>(x, y, z, w, width, height))
}

/// [`snap`] in `f64`, for the rare finite vertex whose `f32` evaluation
/// overflows.
fn snap_f64<const S: u32>(
    x: f32,
    y: f32,
    z: f32,
    w: f32,
    width: u32,
    height: u32,
) -> Option<SnappedVertex> {
    let (x, y, z, w) = (x as f64, y as f64, z as f64, w as f64);
    let half_w = width as f64 * 0.5;
    let half_h = height as f64 * 0.5;
    let scale = (1u32 << S) as f64;
    let wx = (x / w * half_w + half_w) * scale;
    let wy = (half_h - y / w * half_h) * scale;
    let zw = z / w * 0.5 + 0.5;
    if !(zw.is_finite() && wx.is_finite() && wy.is_finite()) {
        return None;
    }
    let limit = COORD_LIMIT as f64;
    if wx.abs() > limit || wy.abs() > limit {
        return None;
    }
    // Nearest, halves up; exact in f64 for |v| <= 2^28.
    let round = |v: f64| {
        let i = v as i64;
        let f = v - i as f64;
        (i + (f >= 0.5) as i64 - (f < -0.5) as i64) as i32
    };
    Some(SnappedVertex {
        x: round(wx),
        y: round(wy),
        z: z01_to_z32(zw as f32),
    })
}

/// The window position of clip-space `(x, y, z)` with `inv_w = 1 / w`,
/// before rounding: `Sub<S>` x and y as `f32`, depth in `[0, 1]` for a
/// point inside the near and far planes. The one formula of [`snap_inv`]
/// and of the vertex stage's batches.
#[inline(always)]
pub(crate) fn window_inv<const S: u32>(
    x: f32,
    y: f32,
    z: f32,
    inv_w: f32,
    width: u32,
    height: u32,
) -> (f32, f32, f32) {
    const { check_subpixel_bits::<S>() };
    let half_w = width as f32 * 0.5;
    let half_h = height as f32 * 0.5;
    let scale = (1u32 << S) as f32;
    let wx = (x * inv_w * half_w + half_w) * scale;
    let wy = (half_h - y * inv_w * half_h) * scale;
    let zw = z * inv_w * 0.5 + 0.5;
    (wx, wy, zw)
}

/// [`snap`] with `1 / w` already computed (and `w > 0` already checked).
#[inline]
pub(crate) fn snap_inv<const S: u32>(
    x: f32,
    y: f32,
    z: f32,
    inv_w: f32,
    width: u32,
    height: u32,
) -> Option<SnappedVertex> {
    let (wx, wy, zw) = window_inv::<S>(x, y, z, inv_w, width, height);
    if !zw.is_finite() {
        return None;
    }
    Some(SnappedVertex {
        x: round_to_coord(wx)?,
        y: round_to_coord(wy)?,
        z: z01_to_z32(zw),
    })
}

/// Window depth in `[0, 1]` to `Z32` (saturating; values outside `[0, 1]`
/// clamp, NaN gives 0).
#[inline]
pub fn z01_to_z32(z: f32) -> u32 {
    // `as` from float saturates and maps NaN to 0: no panic, no UB.
    (z * 4_294_967_296.0) as u32
}

/// The `Sub<S>` coordinate of the centre of pixel column (or row) `i`.
/// `S` must be 4 or 8:
///
/// ```compile_fail
/// let _ = microraster::fixed::pixel_center::<0>(1);
/// ```
/// ```compile_fail
/// let _ = microraster::fixed::pixel_center::<64>(1);
/// ```
#[inline]
pub const fn pixel_center<const S: u32>(i: i32) -> i64 {
    const { check_subpixel_bits::<S>() };
    ((i as i64) << S) + (1i64 << (S - 1))
}

#[cfg(test)]
mod tests {
    /// Calls `f` with seven values of every binade: both ends, the middle,
    /// the neighbours of the ends, both signs (NaNs and infinities among
    /// them).
    fn at_every_exponent(mut f: impl FnMut(f32)) {
        for sign in [0u32, 1] {
            for exp in 0u32..=255 {
                for mant in [0u32, 1, 2, 0x40_0000, 0x55_5555, 0x7f_fffe, 0x7f_ffff] {
                    f(f32::from_bits(sign << 31 | exp << 23 | mant));
                }
            }
        }
    }

    /// `f32_as_i64_by_parts` against `as` at every exponent: both ends of each
    /// binade, its middle, its neighbours, both signs, plus NaNs and
    /// infinities.
    #[test]
    fn f32_as_i64_equals_as_at_every_exponent() {
        let mut checked = 0;
        at_every_exponent(|x| {
            assert_eq!(
                super::f32_as_i64_by_parts(x),
                x as i64,
                "{x:e} ({:#x})",
                x.to_bits()
            );
            checked += 1;
        });
        for x in [
            2147483648.0f32,
            -2147483648.0,
            2147483520.0,
            -2147483520.0,
            9.223372e18,
            -9.223372e18,
        ] {
            assert_eq!(super::f32_as_i64_by_parts(x), x as i64, "{x:e}");
        }
        assert_eq!(checked, 2 * 256 * 7);
    }

    /// The conversions by bits against `as` at every exponent (both ends
    /// of each binade, its middle, its neighbours, both signs, NaNs and
    /// infinities): `z01_to_z32_by_bits` for every such `f32`,
    /// `round_in_range_by_bits` and `trunc_in_range` for those within
    /// `COORD_LIMIT` (and `trunc_in_range` up to `2^31`).
    #[test]
    fn conversions_by_bits_equal_as_at_every_exponent() {
        let mut checked = 0;
        at_every_exponent(|x| {
            let z = x / 4_294_967_296.0;
            assert_eq!(super::z01_to_z32_by_bits(z), super::z01_to_z32(z), "{z:e}");
            assert_eq!(super::z01_to_z32_by_bits(x), super::z01_to_z32(x), "{x:e}");
            if x.is_finite() && x.abs() < 2147483648.0 {
                assert_eq!(super::trunc_in_range(x), x as i32, "{x:e}");
                checked += 1;
            }
            if super::in_coord_range(x) {
                let (got, want) = (super::round_in_range_by_bits(x), super::round_in_range(x));
                assert_eq!(got, want, "{x:e}");
            }
        });
        // Biased exponents 0 (zero, subnormals) to 157 (2^30), two signs,
        // seven each.
        assert_eq!(checked, 2 * 158 * 7);
        for x in [
            0.5f32,
            -0.5,
            1.5,
            -1.5,
            2.5,
            -2.5,
            0.49999997,
            -0.49999997,
            8_388_609.0,
        ] {
            assert_eq!(
                super::round_in_range_by_bits(x),
                super::round_in_range(x),
                "{x:e}"
            );
        }
        for z in [
            0.0f32,
            -0.0,
            1.0,
            1.0000001,
            -1e-30,
            0.99999994,
            2.3283064e-10,
        ] {
            assert_eq!(super::z01_to_z32_by_bits(z), super::z01_to_z32(z), "{z:e}");
        }
    }

    proptest::proptest! {
        // Few cases under Miri, and no failure file (as in `depth.rs`).
        #![proptest_config(proptest::prelude::ProptestConfig {
            cases: if cfg!(miri) { 16 } else { 4096 },
            failure_persistence: None,
            ..proptest::prelude::ProptestConfig::default()
        })]
        /// Any bit pattern: the conversions by bits equal `as` (and
        /// `round_in_range`) where they are defined to.
        #[test]
        fn conversions_by_bits_equal_as(bits in proptest::num::u32::ANY) {
            let x = f32::from_bits(bits);
            proptest::prop_assert_eq!(super::z01_to_z32_by_bits(x), super::z01_to_z32(x));
            if x.is_finite() && x.abs() < 2147483648.0 {
                proptest::prop_assert_eq!(super::trunc_in_range(x), x as i32);
            }
            if super::in_coord_range(x) {
                proptest::prop_assert_eq!(super::round_in_range_by_bits(x), super::round_in_range(x));
            }
        }
    }

    /// The conversions by bits for every `f32` bit pattern (half a minute
    /// in release):
    /// `cargo test --release -p microraster --lib conversions_by_bits_exhaustive -- --ignored`.
    #[test]
    #[ignore]
    fn conversions_by_bits_exhaustive() {
        for bits in 0..=u32::MAX {
            let x = f32::from_bits(bits);
            assert_eq!(
                super::z01_to_z32_by_bits(x),
                super::z01_to_z32(x),
                "{bits:#x}"
            );
            if x.is_finite() && x.abs() < 2147483648.0 {
                assert_eq!(super::trunc_in_range(x), x as i32, "{bits:#x}");
            }
            if super::in_coord_range(x) {
                let (got, want) = (super::round_in_range_by_bits(x), super::round_in_range(x));
                assert_eq!(got, want, "{bits:#x}");
            }
        }
    }

    /// Every `f32` bit pattern (4 billion; about a minute in release):
    /// `cargo test --release -p microraster --lib f32_as_i64_exhaustive -- --ignored`.
    #[test]
    #[ignore]
    fn f32_as_i64_exhaustive() {
        for bits in 0..=u32::MAX {
            let x = f32::from_bits(bits);
            assert_eq!(super::f32_as_i64_by_parts(x), x as i64, "{bits:#x}");
        }
    }

    use super::*;

    #[test]
    fn snap_maps_ndc_corners_to_frame_corners() {
        let v = snap::<8>(-1.0, 1.0, -1.0, 1.0, 64, 32).unwrap();
        assert_eq!((v.x, v.y, v.z), (0, 0, 0));
        let v = snap::<8>(1.0, -1.0, 1.0, 1.0, 64, 32).unwrap();
        assert_eq!((v.x, v.y, v.z), (64 << 8, 32 << 8, u32::MAX));
    }

    #[test]
    fn snap_rejects_nonpositive_w_and_nonfinite() {
        assert!(snap::<8>(0.0, 0.0, 0.0, 0.0, 8, 8).is_none());
        assert!(snap::<8>(0.0, 0.0, 0.0, -1.0, 8, 8).is_none());
        assert!(snap::<8>(f32::NAN, 0.0, 0.0, 1.0, 8, 8).is_none());
        assert!(snap::<8>(0.0, f32::INFINITY, 0.0, 1.0, 8, 8).is_none());
        assert!(snap::<8>(1e30, 0.0, 0.0, 1.0, 8, 8).is_none());
    }

    #[test]
    fn guard_band_fits_coord_limit_for_largest_frame() {
        for s in [4u32, 8] {
            let (gx, _) = if s == 8 {
                guard_band_ndc::<8>(MAX_DIMENSION, MAX_DIMENSION)
            } else {
                guard_band_ndc::<4>(MAX_DIMENSION, MAX_DIMENSION)
            };
            assert!(gx >= 1.0);
            let edge = (gx + 1.0) * (MAX_DIMENSION as f32 / 2.0) * (1u32 << s) as f32;
            assert!(edge <= GUARD_BAND as f32 * 1.0001, "s={s} edge={edge}");
        }
    }

    #[test]
    fn rounding_is_exact_near_2_pow_23() {
        assert_eq!(round_to_coord(8_388_609.0), Some(8_388_609));
        assert_eq!(round_to_coord(-8_388_609.0), Some(-8_388_609));
        assert_eq!(round_to_coord(2.5), Some(3));
        assert_eq!(round_to_coord(-2.5), Some(-2));
        assert_eq!(round_to_coord(-2.6), Some(-3));
        assert_eq!(round_to_coord(0.49999997), Some(0));
        assert_eq!(round_to_coord(COORD_LIMIT as f32), Some(COORD_LIMIT));
        assert_eq!(round_to_coord(-(COORD_LIMIT as f32)), Some(-COORD_LIMIT));
        assert_eq!(round_to_coord(COORD_LIMIT as f32 * 1.01), None);
    }

    #[test]
    fn pixel_centers() {
        assert_eq!(pixel_center::<8>(0), 128);
        assert_eq!(pixel_center::<4>(3), 56);
    }
}
