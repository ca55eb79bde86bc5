//! Binning: which stored triangles reach which strip.
//!
//! Design note: after a frame's triangles are set up,
//! [`Frame::bin`](crate::Frame::bin) sorts their indices into one list per strip of
//! `strip_rows` rows, in caller storage (`offsets`: strips + 1 entries,
//! `items`: one per (triangle, strip it touches)), with a counting sort
//! that needs no scratch. Each list keeps submission order, so rendering a
//! strip from its list gives the same pixels as rendering it from all
//! triangles. The [`Bins`] remember the frame they were made for (size,
//! strip height, triangle count), and rendering checks that.

use crate::config::{Config, Error};
use crate::setup::SetupTriangle;

/// Per-strip triangle bins of a frame, made by [`Frame::bin`](crate::Frame::bin).
#[derive(Debug)]
pub struct Bins<'b> {
    pub(crate) strip_rows: u32,
    pub(crate) width: u32,
    pub(crate) height: u32,
    pub(crate) triangles: usize,
    pub(crate) offsets: &'b [u32],
    pub(crate) items: &'b [u32],
}

impl Bins<'_> {
    /// Rows per strip.
    pub fn strip_rows(&self) -> u32 {
        self.strip_rows
    }

    /// The number of strips.
    pub fn strips(&self) -> u32 {
        self.offsets.len().saturating_sub(1) as u32
    }

    /// The rows `y0..y1` of strip `strip` (the last one possibly shorter;
    /// empty past the end).
    pub fn rows(&self, strip: u32) -> (u32, u32) {
        let y0 = strip.saturating_mul(self.strip_rows).min(self.height);
        (y0, y0.saturating_add(self.strip_rows).min(self.height))
    }

    /// The indices of the stored triangles that reach strip `strip`, in
    /// submission order (empty past the end).
    pub fn strip_items(&self, strip: u32) -> &[u32] {
        let s = strip as usize;
        match (self.offsets.get(s), self.offsets.get(s.wrapping_add(1))) {
            (Some(&a), Some(&b)) => self.items.get(a as usize..b as usize).unwrap_or(&[]),
            _ => &[],
        }
    }

    /// Whether these bins were made for this frame as it is now.
    pub(crate) fn belong_to(&self, config: &Config, triangles: usize) -> bool {
        self.width == config.width
            && self.height == config.height
            && self.triangles == triangles
            && self.offsets.len() == self.height.div_ceil(self.strip_rows.max(1)) as usize + 1
    }
}

/// The strips (of `r` rows) triangle `t` touches.
#[inline]
fn strip_range<const N: usize>(t: &SetupTriangle<N>, r: u32) -> core::ops::RangeInclusive<u32> {
    t.min_y as u32 / r..=t.max_y as u32 / r
}

/// Bin entries for strips of `r >= 1` rows: one per (triangle, strip it
/// touches); saturates at `usize::MAX` (then no storage can hold them).
pub(crate) fn entries<const N: usize>(triangles: &[SetupTriangle<N>], r: u32) -> usize {
    triangles.iter().fold(0usize, |n, t| {
        let range = strip_range(t, r);
        n.saturating_add((range.end() - range.start()) as usize + 1)
    })
}

/// Sorts `triangles` of a frame of `config` into bins; see
/// [`Frame::bin`](crate::Frame::bin).
pub(crate) fn bin<'b, const N: usize>(
    config: &Config,
    triangles: &[SetupTriangle<N>],
    strip_rows: u32,
    offsets: &'b mut [u32],
    items: &'b mut [u32],
) -> Result<Bins<'b>, Error> {
    if strip_rows == 0 {
        return Err(Error::InvalidStripRows);
    }
    let r = strip_rows;
    let strips = config.height.div_ceil(r) as usize;
    let need_items = entries(triangles, r);
    if offsets.len() < strips + 1 {
        return Err(Error::BinStorageSize {
            expected: strips + 1,
            actual: offsets.len(),
        });
    }
    if items.len() < need_items || need_items > u32::MAX as usize {
        return Err(Error::BinStorageSize {
            expected: need_items,
            actual: items.len(),
        });
    }
    let offsets = &mut offsets[..strips + 1];
    offsets.fill(0);
    // Count into offsets[s + 1], prefix-sum into starts, fill using
    // offsets[s] as the cursor (it ends at the start of s + 1), then shift
    // back: no scratch beyond the two slices. Every sum is at most
    // `need_items <= u32::MAX`.
    for t in triangles {
        for s in strip_range(t, r) {
            if let Some(o) = offsets.get_mut(s as usize + 1) {
                *o += 1;
            }
        }
    }
    for s in 1..offsets.len() {
        offsets[s] += offsets[s - 1];
    }
    for (i, t) in triangles.iter().enumerate() {
        for s in strip_range(t, r) {
            if let Some(o) = offsets.get_mut(s as usize) {
                if let Some(slot) = items.get_mut(*o as usize) {
                    *slot = i as u32;
                }
                *o += 1;
            }
        }
    }
    for s in (1..offsets.len()).rev() {
        offsets[s] = offsets[s - 1];
    }
    offsets[0] = 0;
    Ok(Bins {
        strip_rows: r,
        width: config.width,
        height: config.height,
        triangles: triangles.len(),
        offsets,
        items: &items[..need_items],
    })
}
