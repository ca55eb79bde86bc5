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

    /// Adds word `index` of a frame of `words` words, in any order: after
    /// every word of the frame has been added once, the value is the one
    /// [`push_word`](FrameChecksum::push_word) gives in order. (The second
    /// sum of words `w_0 .. w_{n-1}` in order is `sum (n - i) w_i`, so a
    /// word's share depends only on its place.) For a display that takes
    /// windowed writes, e.g. tiles; do not mix with the in-order methods.
    #[inline(always)]
    pub fn add_word_at(&mut self, w: u32, index: u32, words: u32) {
        self.a = self.a.wrapping_add(w);
        self.b = self
            .b
            .wrapping_add(words.wrapping_sub(index).wrapping_mul(w));
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

    #[test]
    fn words_at_their_places_in_any_order_give_the_in_order_value() {
        let words: [u32; 7] = [1, 0xdead_beef, 3, u32::MAX, 0x8000_0000, 42, 7];
        let mut in_order = FrameChecksum::new();
        for &w in &words {
            in_order.push_word(w);
        }
        for order in [
            [0, 1, 2, 3, 4, 5, 6],
            [6, 5, 4, 3, 2, 1, 0],
            [3, 0, 6, 1, 5, 2, 4],
        ] {
            let mut c = FrameChecksum::new();
            for i in order {
                c.add_word_at(words[i], i as u32, words.len() as u32);
            }
            assert_eq!(c.value(), in_order.value());
        }
        // A word at another place gives another value.
        let mut c = FrameChecksum::new();
        for (i, &w) in words.iter().enumerate() {
            c.add_word_at(w, (i as u32 + 1) % 7, 7);
        }
        assert_ne!(c.value(), in_order.value());
    }
}
