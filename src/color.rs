//! Output pixel formats.
//!
//! Design note: the rasterizer computes a fragment's colour as [`Rgb888`]
//! (8 bits a channel) and hands it with the triangle's index to
//! [`PixelFormat::from_fragment`]. Colour types convert with
//! embedded-graphics' own `From<Rgb888>` conversions, which round each
//! channel to the nearest value of the narrower range: `Rgb565` is
//! `round(v * 31 / 255)`, `round(v * 63 / 255)`, `round(v * 31 / 255)`;
//! `Gray8` is the BT.601 luma; `BinaryColor` is on when that luma is at
//! least 128. [`TriangleId`] ignores colour ([`PixelFormat::SHADED`] is
//! `false`, so no colour is computed) and records which triangle won each
//! pixel.

use embedded_graphics_core::pixelcolor::{BinaryColor, Gray8, Rgb565, Rgb888};

/// A pixel format the rasterizer can write.
pub trait PixelFormat: Copy {
    /// Whether the fragment colour is needed; `false` skips shading.
    const SHADED: bool;

    /// The pixel for a fragment of colour `rgb` from triangle `triangle`.
    fn from_fragment(rgb: Rgb888, triangle: u32) -> Self;
}

impl PixelFormat for Rgb888 {
    const SHADED: bool = true;
    #[inline]
    fn from_fragment(rgb: Rgb888, _: u32) -> Self {
        rgb
    }
}

impl PixelFormat for Rgb565 {
    const SHADED: bool = true;
    #[inline]
    fn from_fragment(rgb: Rgb888, _: u32) -> Self {
        Rgb565::from(rgb)
    }
}

impl PixelFormat for Gray8 {
    const SHADED: bool = true;
    #[inline]
    fn from_fragment(rgb: Rgb888, _: u32) -> Self {
        Gray8::from(rgb)
    }
}

impl PixelFormat for BinaryColor {
    const SHADED: bool = true;
    #[inline]
    fn from_fragment(rgb: Rgb888, _: u32) -> Self {
        BinaryColor::from(rgb)
    }
}

/// A triangle-index pixel: `0` is background, otherwise the index given at
/// submission plus one.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct TriangleId(pub u32);

impl PixelFormat for TriangleId {
    const SHADED: bool = false;
    #[inline]
    fn from_fragment(_: Rgb888, triangle: u32) -> Self {
        TriangleId(triangle.wrapping_add(1))
    }
}
