//! The frame checksum every front end computes, as a display would.
//!
//! Design note: the firmware's display stand-in, the host's tests and the
//! firmware's build script must agree on one value per frame, and the
//! stand-in must cost about what a display push costs, not more than the
//! render. So the checksum is one a DMA engine or a CRC unit would compute
//! on the wire words: a Fletcher-style pair of wrapping `u32` sums over
//! 32-bit words, each word two `Rgb565` pixels (the first in the low half,
//! as a little-endian DMA transfer packs them), rows top to bottom. Two
//! additions a word; order-sensitive through the second sum. An odd pixel
//! count pads the last word with zero.

/// Fletcher-64 (wrapping sums) over pairs of 16-bit pixels.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct FrameChecksum {
    a: u32,
    b: u32,
    /// A first pixel waiting for its pair.
    half: Option<u16>,
}

impl FrameChecksum {
    /// An empty checksum.
    pub const fn new() -> Self {
        FrameChecksum {
            a: 0,
            b: 0,
            half: None,
        }
    }

    /// Adds one 32-bit word (two pixels, the first in the low half).
    #[inline(always)]
    pub fn push_word(&mut self, w: u32) {
        self.a = self.a.wrapping_add(w);
        self.b = self.b.wrapping_add(self.a);
    }

    /// Adds one pixel's raw 16 bits.
    #[inline]
    pub fn push(&mut self, px: u16) {
        match self.half.take() {
            Some(first) => self.push_word(first as u32 | (px as u32) << 16),
            None => self.half = Some(px),
        }
    }

    /// Adds a run of pixels.
    pub fn extend(&mut self, pixels: impl IntoIterator<Item = u16>) {
        for p in pixels {
            self.push(p);
        }
    }

    /// The checksum of everything pushed (an odd last pixel padded with
    /// zero).
    pub fn value(&self) -> u64 {
        let mut c = *self;
        if let Some(first) = c.half.take() {
            c.push_word(first as u32);
        }
        (c.b as u64) << 32 | c.a as u64
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pairs_and_words_agree_and_order_matters() {
        let mut a = FrameChecksum::new();
        a.extend([1u16, 2, 3, 4]);
        let mut b = FrameChecksum::new();
        b.push_word(1 | 2 << 16);
        b.push_word(3 | 4 << 16);
        assert_eq!(a.value(), b.value());
        let mut c = FrameChecksum::new();
        c.extend([3u16, 4, 1, 2]);
        assert_ne!(a.value(), c.value());
        let mut d = FrameChecksum::new();
        d.extend([1u16, 2, 3]);
        let mut e = FrameChecksum::new();
        e.extend([1u16, 2, 3, 0]);
        assert_eq!(d.value(), e.value());
        assert_eq!(FrameChecksum::new().value(), 0);
    }
}
