//! The display stand-in: a [`DrawTarget`] that hashes what it receives.
//!
//! It behaves like a driver for an SPI display that is only ever written
//! whole rows at a time: each `fill_contiguous` must cover full rows and
//! continue where the last one stopped (anything else is an error, which
//! the strip adapter hands back), and its pixels go, two bytes each, high
//! byte first, into an FNV-1a 64 hash instead of onto the wire. The hash
//! of a frame therefore does not depend on how it was cut into strips.
//! The instructions it spends are counted apart, as a real display's DMA
//! transfer would not be.

use crate::clock::Clock;
use embedded_graphics_core::draw_target::DrawTarget;
use embedded_graphics_core::geometry::{OriginDimensions, Size};
use embedded_graphics_core::pixelcolor::{IntoStorage, Rgb565};
use embedded_graphics_core::primitives::Rectangle;
use embedded_graphics_core::Pixel;

/// FNV-1a 64 offset basis.
const FNV_OFFSET: u64 = 0xcbf2_9ce4_8422_2325;
/// FNV-1a 64 prime.
const FNV_PRIME: u64 = 0x0000_0100_0000_01b3;

/// Why the stand-in refused a write.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum DisplayError {
    /// A single-pixel write (`draw_iter`): this display takes rectangles.
    NotContiguous,
    /// A rectangle that is not the next full rows of the frame.
    OutOfOrder,
}

/// A `width x height` Rgb565 display that hashes the frame it is sent.
pub struct HashDisplay {
    size: Size,
    next_row: u32,
    hash: u64,
    /// Rectangles received.
    pub pushes: u32,
    /// The clock, shared with the caller, and the ticks spent in here.
    pub clock: Clock,
    /// SysTick ticks spent hashing.
    pub ticks: u64,
}

impl HashDisplay {
    pub fn new(width: u32, height: u32, clock: Clock) -> Self {
        HashDisplay {
            size: Size::new(width, height),
            next_row: 0,
            hash: FNV_OFFSET,
            pushes: 0,
            clock,
            ticks: 0,
        }
    }

    /// The hash of the frame, once every row has arrived.
    pub fn checksum(&self) -> Option<u64> {
        (self.next_row == self.size.height).then_some(self.hash)
    }
}

impl OriginDimensions for HashDisplay {
    fn size(&self) -> Size {
        self.size
    }
}

impl DrawTarget for HashDisplay {
    type Color = Rgb565;
    type Error = DisplayError;

    fn draw_iter<I>(&mut self, _: I) -> Result<(), DisplayError>
    where
        I: IntoIterator<Item = Pixel<Rgb565>>,
    {
        Err(DisplayError::NotContiguous)
    }

    fn fill_contiguous<I>(&mut self, area: &Rectangle, colors: I) -> Result<(), DisplayError>
    where
        I: IntoIterator<Item = Rgb565>,
    {
        let start = self.clock.now();
        if area.top_left.x != 0
            || area.top_left.y != self.next_row as i32
            || area.size.width != self.size.width
            || self.next_row + area.size.height > self.size.height
        {
            return Err(DisplayError::OutOfOrder);
        }
        let n = (area.size.width * area.size.height) as usize;
        let mut h = self.hash;
        let mut received = 0;
        for c in colors.into_iter().take(n) {
            let raw: u16 = c.into_storage();
            h = (h ^ u64::from(raw >> 8)).wrapping_mul(FNV_PRIME);
            h = (h ^ u64::from(raw & 0xff)).wrapping_mul(FNV_PRIME);
            received += 1;
        }
        if received != n {
            return Err(DisplayError::OutOfOrder);
        }
        self.hash = h;
        self.next_row += area.size.height;
        self.pushes += 1;
        self.ticks += self.clock.now() - start;
        Ok(())
    }
}
