//! The display stand-in: a [`StripSink`] that checksums what it receives.
//!
//! It behaves like a DMA-driven driver for an SPI display that is only
//! ever written whole rows at a time: it takes each finished strip buffer
//! as a slice (no per-pixel iterator, as a DMA engine reads the buffer),
//! each strip must cover full rows and continue where the last one stopped
//! (anything else is an error, which the strip drawer hands back), and its
//! pixels go, two to a 32-bit word as a DMA transfer packs them, into a
//! checksum (`microraster_scenes::checksum`: two additions a word, eight
//! words a loop turn) instead of onto the wire. The checksum of a frame
//! does not depend on how it was cut into strips (rows are an even number
//! of pixels wide). The instructions it spends are counted apart, on
//! their own line.
//!
//! With the `tiles` feature it stands in for a display that takes
//! windowed writes instead: any rectangle inside the frame (an even
//! column and width, so pixels pair into words as they do in rows), in
//! any order, each word added to the checksum at its place in the frame
//! (`FrameChecksum::add_word_at`: the same value as rows in order, one
//! multiply more a word). The frame is complete when its pixel count has
//! arrived; overdraw or gaps change the checksum.

use crate::clock::Clock;
#[cfg(baked)]
use embedded_graphics_core::geometry::Point;
use embedded_graphics_core::geometry::{OriginDimensions, Size};
use embedded_graphics_core::pixelcolor::{IntoStorage, Rgb565};
use embedded_graphics_core::primitives::Rectangle;
use microraster::StripSink;
use microraster_scenes::checksum::FrameChecksum;

/// Why the stand-in refused a write.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum DisplayError {
    /// A rectangle that is not the next full rows of the frame, or pixels
    /// that do not fill it.
    OutOfOrder,
}

/// A frame in progress, set aside ([`HashDisplay::save`]).
#[cfg(any(
    feature = "clusters",
    feature = "house-portals",
    feature = "herd-occlusion"
))]
#[derive(Clone, Copy, Default)]
pub struct Saved {
    next_row: u32,
    sum: FrameChecksum,
    pushes: u32,
    ticks: u64,
}

/// A `width x height` Rgb565 display that checksums the frame it is sent.
pub struct HashDisplay {
    size: Size,
    /// Rows received in order; with `tiles`, pixels received.
    next_row: u32,
    sum: FrameChecksum,
    /// Rectangles received.
    pub pushes: u32,
    /// The clock, shared with the caller, and the ticks spent in here.
    pub clock: Clock,
    /// SysTick ticks spent in the checksum.
    pub ticks: u64,
}

impl HashDisplay {
    pub fn new(width: u32, height: u32, clock: Clock) -> Self {
        HashDisplay {
            size: Size::new(width, height),
            next_row: 0,
            sum: FrameChecksum::new(),
            pushes: 0,
            clock,
            ticks: 0,
        }
    }

    /// The frame received so far (checksum state, rows, pushes, ticks),
    /// to set aside while other frames go through the same display.
    #[cfg(any(
        feature = "clusters",
        feature = "house-portals",
        feature = "herd-occlusion"
    ))]
    pub fn save(&self) -> Saved {
        Saved {
            next_row: self.next_row,
            sum: self.sum,
            pushes: self.pushes,
            ticks: self.ticks,
        }
    }

    /// Puts a saved frame back (a new frame: `Saved::default()`).
    #[cfg(any(
        feature = "clusters",
        feature = "house-portals",
        feature = "herd-occlusion"
    ))]
    pub fn restore(&mut self, s: Saved) {
        (self.next_row, self.sum, self.pushes, self.ticks) = (s.next_row, s.sum, s.pushes, s.ticks);
    }

    /// The hash of the frame, once every row has arrived.
    pub fn checksum(&self) -> Option<u64> {
        let whole = if cfg!(feature = "tiles") {
            self.size.width * self.size.height
        } else {
            self.size.height
        };
        (self.next_row == whole).then(|| self.sum.value())
    }
}

impl OriginDimensions for HashDisplay {
    fn size(&self) -> Size {
        self.size
    }
}

/// Any strip pixel the display's `Rgb565` converts from (the identity for
/// `Rgb565` itself).
impl<P: Copy> StripSink<P> for HashDisplay
where
    Rgb565: From<P>,
{
    type Error = DisplayError;

    /// Takes the strip buffer itself, as a DMA-driven driver does: no
    /// per-pixel iterator, two pixels loaded and summed a word.
    #[cfg(feature = "tiles")]
    #[inline(never)]
    fn push_strip(&mut self, area: &Rectangle, pixels: &[P]) -> Result<(), DisplayError> {
        let start = self.clock.now();
        let (w, h) = (area.size.width, area.size.height);
        let (x0, y0) = (area.top_left.x as u32, area.top_left.y as u32);
        if area.top_left.x < 0
            || area.top_left.y < 0
            || x0 % 2 != 0
            || w % 2 != 0
            || x0 + w > self.size.width
            || y0 + h > self.size.height
            || pixels.len() != (w * h) as usize
        {
            return Err(DisplayError::OutOfOrder);
        }
        let words = self.size.width * self.size.height / 2;
        let mut sum = self.sum;
        for (r, row) in pixels.chunks_exact(w as usize).enumerate() {
            let first = ((y0 + r as u32) * self.size.width + x0) / 2;
            for (index, p) in (first..).zip(row.chunks_exact(2)) {
                let (lo, hi): (u16, u16) = (
                    Rgb565::from(p[0]).into_storage(),
                    Rgb565::from(p[1]).into_storage(),
                );
                sum.add_word_at(lo as u32 | (hi as u32) << 16, index, words);
            }
        }
        self.sum = sum;
        self.next_row += w * h;
        self.pushes += 1;
        self.ticks += self.clock.now() - start;
        Ok(())
    }

    #[cfg(not(feature = "tiles"))]
    #[inline(never)]
    fn push_strip(&mut self, area: &Rectangle, pixels: &[P]) -> Result<(), DisplayError> {
        let start = self.clock.now();
        if area.top_left.x != 0
            || area.top_left.y != self.next_row as i32
            || area.size.width != self.size.width
            || self.next_row + area.size.height > self.size.height
            || pixels.len() != (area.size.width * area.size.height) as usize
        {
            return Err(DisplayError::OutOfOrder);
        }
        let mut sum = self.sum;
        // Two pixels a word, as a 32-bit DMA transfer moves them (rows of
        // an even width: no half word is left over), eight words a turn:
        // the loop the compiler made of one word a turn took four, and
        // its counting 0.5 instructions a word (M4F four cubes: push
        // 135,600 -> 118,960; sixteen words a turn, 118,880).
        let word = |p: &[P]| {
            let (lo, hi): (u16, u16) = (
                Rgb565::from(p[0]).into_storage(),
                Rgb565::from(p[1]).into_storage(),
            );
            lo as u32 | (hi as u32) << 16
        };
        let blocks = pixels.chunks_exact(16);
        let words = blocks.remainder().chunks_exact(2);
        let rest = words.remainder();
        for b in blocks {
            for w in b.chunks_exact(2) {
                sum.push_word(word(w));
            }
        }
        for w in words {
            sum.push_word(word(w));
        }
        for &c in rest {
            sum.push(Rgb565::from(c).into_storage());
        }
        self.sum = sum;
        self.next_row += area.size.height;
        self.pushes += 1;
        self.ticks += self.clock.now() - start;
        Ok(())
    }
}

/// Pushes rows `y0..y1` of a `WIDTH`-wide frame to `display` as one strip
/// (the buffer itself, as `StripDrawer` does), for the baked scenes' strip
/// loops. Out of line, so that the push compiles (and counts) the same
/// whatever the shading around it.
#[cfg(baked)]
#[inline(never)]
pub fn push(
    display: &mut HashDisplay,
    y0: u32,
    y1: u32,
    rows: &[Rgb565],
) -> Result<(), &'static str> {
    let area = Rectangle::new(Point::new(0, y0 as i32), Size::new(crate::WIDTH, y1 - y0));
    display.push_strip(&area, rows).map_err(|_| "display")
}
