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

use embedded_graphics_core::pixelcolor::raw::RawU16;
use embedded_graphics_core::pixelcolor::{BinaryColor, Gray8, Rgb565, Rgb888, RgbColor};

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
    /// embedded-graphics' `Rgb565::from(rgb)`, bit for bit (every channel
    /// value is checked in the tests), by three table lookups: no
    /// multiplication per channel.
    #[inline]
    fn from_fragment(rgb: Rgb888, _: u32) -> Self {
        let word =
            RGB565_R[rgb.r() as usize] | RGB565_G[rgb.g() as usize] | RGB565_B[rgb.b() as usize];
        Rgb565::from(RawU16::new(word))
    }
}

/// `round(v * max / 255)` for a channel of `bits` bits, shifted to `pos`,
/// for every 8-bit `v`: `Rgb565`'s channels of an `Rgb888` (1.5 KB).
const fn channel_table(bits: u32, pos: u32) -> [u16; 256] {
    let max = (1u32 << bits) - 1;
    let mut t = [0u16; 256];
    let mut v = 0;
    while v < 256 {
        // Round half up, as the conversion of embedded-graphics does.
        t[v] = (((v as u32 * max * 2 + 255) / 510) << pos) as u16;
        v += 1;
    }
    t
}

// On 64-bit hosts the three tables are one static, so that a pixel loop
// holds one address for them (a position-independent binary loads each
// static's address from its global offset table: the tgx sphere's smooth
// spans had loaded three a pixel). 32-bit cores keep three statics (their
// recorded instruction counts and split estimates).
#[cfg(not(target_pointer_width = "32"))]
static RGB565: [[u16; 256]; 3] = [
    channel_table(5, 11),
    channel_table(6, 5),
    channel_table(5, 0),
];
#[cfg(not(target_pointer_width = "32"))]
const RGB565_R: &[u16; 256] = &RGB565[0];
#[cfg(not(target_pointer_width = "32"))]
const RGB565_G: &[u16; 256] = &RGB565[1];
#[cfg(not(target_pointer_width = "32"))]
const RGB565_B: &[u16; 256] = &RGB565[2];
#[cfg(target_pointer_width = "32")]
static RGB565_R: [u16; 256] = channel_table(5, 11);
#[cfg(target_pointer_width = "32")]
static RGB565_G: [u16; 256] = channel_table(6, 5);
#[cfg(target_pointer_width = "32")]
static RGB565_B: [u16; 256] = channel_table(5, 0);

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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rgb565_tables_equal_embedded_graphics_conversion() {
        for v in 0..=255u8 {
            for c in [
                Rgb888::new(v, 0, 0),
                Rgb888::new(0, v, 0),
                Rgb888::new(0, 0, v),
                Rgb888::new(v, 255 - v, v / 3),
            ] {
                let want = Rgb565::from(c);
                let got = <Rgb565 as PixelFormat>::from_fragment(c, 0);
                assert_eq!(got, want, "{c:?}");
                assert_eq!((got.r(), got.g(), got.b()), (want.r(), want.g(), want.b()));
            }
        }
    }
}
