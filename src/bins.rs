//! Binning: which stored triangles reach which strip or tile.
//!
//! Design note: after a frame's triangles are set up,
//! [`Frame::bin`](crate::Frame::bin) sorts their indices into one list per
//! strip of `strip_rows` rows, and [`Frame::bin_tiles`](crate::Frame::bin_tiles)
//! into one list per `tile_w x tile_h` tile (numbered row by row from the
//! top left; a strip is a tile as wide as the frame). The lists live in
//! caller storage (`offsets`: tiles + 1 entries, `items`: one per
//! (triangle, tile its box touches)) and are built by a counting sort that
//! needs no scratch. Each list keeps submission order, so rendering a tile
//! from its list gives the same pixels as rendering it from all triangles.
//! The [`Bins`] remember the frame they were made for (size, tile size,
//! triangle count), and rendering checks that.

use crate::config::{Config, Error};
use crate::setup::SetupTriangle;

/// Per-strip (or per-tile) triangle bins of a frame, made by
/// [`Frame::bin`](crate::Frame::bin) or
/// [`Frame::bin_tiles`](crate::Frame::bin_tiles).
#[derive(Debug)]
pub struct Bins<'b> {
    /// Rows per strip or tile.
    pub(crate) strip_rows: u32,
    /// Columns per tile (the frame width for strips).
    pub(crate) tile_w: u32,
    /// Tiles per row of tiles (1 for strips).
    pub(crate) cols: u32,
    pub(crate) width: u32,
    pub(crate) height: u32,
    pub(crate) triangles: usize,
    pub(crate) offsets: &'b [u32],
    pub(crate) items: &'b [u32],
}

impl Bins<'_> {
    /// Rows per strip (or tile).
    pub fn strip_rows(&self) -> u32 {
        self.strip_rows
    }

    /// Columns per tile (the frame width for strips).
    pub fn tile_width(&self) -> u32 {
        self.tile_w
    }

    /// The number of strips (tiles, for
    /// [`Frame::bin_tiles`](crate::Frame::bin_tiles)).
    pub fn strips(&self) -> u32 {
        self.offsets.len().saturating_sub(1) as u32
    }

    /// The number of tiles (strips, for [`Frame::bin`](crate::Frame::bin)).
    pub fn tiles(&self) -> u32 {
        self.strips()
    }

    /// The rows `y0..y1` of strip (or tile) `strip` (the last ones possibly
    /// shorter; empty past the end).
    pub fn rows(&self, strip: u32) -> (u32, u32) {
        let [_, _, y0, y1] = self.rect(strip);
        (y0, y1)
    }

    /// The rectangle `[x0, x1, y0, y1]` (columns `x0..x1`, rows `y0..y1`)
    /// of tile (or strip) `tile`. Tiles are numbered row by row from the
    /// top left; those on the right and bottom sides may be smaller. Empty
    /// past the end.
    pub fn rect(&self, tile: u32) -> [u32; 4] {
        if tile >= self.tiles() {
            return [0, 0, self.height, self.height];
        }
        let cols = self.cols.max(1);
        let (ty, tx) = (tile / cols, tile % cols);
        let x0 = tx.saturating_mul(self.tile_w).min(self.width);
        let y0 = ty.saturating_mul(self.strip_rows).min(self.height);
        [
            x0,
            x0.saturating_add(self.tile_w).min(self.width),
            y0,
            y0.saturating_add(self.strip_rows).min(self.height),
        ]
    }

    /// The indices of the stored triangles that reach strip (or tile)
    /// `strip`, in submission order (empty past the end).
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
            && tile_count(config, self.tile_w, self.strip_rows) == Some(self.strips() as usize)
            && self.offsets.len() == self.strips() as usize + 1
    }
}

/// Tiles of `tw x th` in a frame: `(per row, rows)`.
fn grid(config: &Config, tw: u32, th: u32) -> (u32, u32) {
    (
        config.width.div_ceil(tw.max(1)),
        config.height.div_ceil(th.max(1)),
    )
}

/// The number of tiles of `tw x th` in a frame (`None` on overflow).
fn tile_count(config: &Config, tw: u32, th: u32) -> Option<usize> {
    let (c, r) = grid(config, tw, th);
    (c as usize).checked_mul(r as usize)
}

/// Division of a pixel coordinate (`0..=u16::MAX`, as a triangle's box
/// holds it) by a tile side `d >= 1` fixed for a whole binning pass.
///
/// Binning divides each stored triangle's four box sides by the tile
/// size in each of its passes (count, fill, and [`entries`]): a hardware
/// `div` of 12 to 26 cycles on x86-64, most of the bunny's binning time.
/// On 64-bit targets the quotient is a multiply and a shift instead, exact
/// for every such `x` and `d`:
///
/// with `m = floor(2^32 / d) + 1`, `m d = 2^32 + e` for some `0 < e <= d`.
/// For `x = q d + r`, `0 <= r < d`:
/// `x m / 2^32 = q + r / d + x e / (d 2^32)`, which is at least `q` and
/// below `q + (d - 1) / d + x / 2^32 < q + (d - 1) / d + 1 / d = q + 1`
/// wherever `x d < 2^32`, true for `x, d < 2^16`. A divisor of `2^16` or
/// more has quotient 0 for every such `x`, as `m = 0` gives. `x m` fits
/// `u64` (`m <= 2^32 + 1`).
///
/// 32-bit targets keep the division: their `u64` product is a library
/// call on the Cortex-M0, and the M3 and M4F divide in a few cycles.
/// `tests::div16_equals_division` checks the quotients.
#[derive(Clone, Copy, Debug)]
struct Div16 {
    #[cfg(not(target_pointer_width = "64"))]
    d: u32,
    #[cfg(target_pointer_width = "64")]
    m: u64,
}

impl Div16 {
    /// Division by `d` (0 counts as 1).
    fn new(d: u32) -> Self {
        let d = d.max(1);
        #[cfg(target_pointer_width = "64")]
        {
            let m = if d > u16::MAX as u32 {
                0
            } else {
                (1u64 << 32) / d as u64 + 1
            };
            Div16 { m }
        }
        #[cfg(not(target_pointer_width = "64"))]
        {
            Div16 { d }
        }
    }

    /// `floor(x / d)`.
    #[inline(always)]
    fn of(self, x: u16) -> u32 {
        #[cfg(target_pointer_width = "64")]
        {
            ((x as u64 * self.m) >> 32) as u32
        }
        #[cfg(not(target_pointer_width = "64"))]
        {
            x as u32 / self.d
        }
    }
}

/// A binning pass's tile sides, as divisions.
#[derive(Clone, Copy, Debug)]
struct TileSize {
    w: Div16,
    h: Div16,
}

impl TileSize {
    /// Tiles of `tw x th` (0 counts as 1).
    fn new(tw: u32, th: u32) -> Self {
        TileSize {
            w: Div16::new(tw),
            h: Div16::new(th),
        }
    }
}

/// The tile rows and tile columns (of `size` tiles) triangle `t`'s box
/// touches.
#[inline]
fn tile_range<const N: usize>(
    t: &SetupTriangle<N>,
    size: TileSize,
) -> (
    core::ops::RangeInclusive<u32>,
    core::ops::RangeInclusive<u32>,
) {
    (
        size.h.of(t.min_y)..=size.h.of(t.max_y),
        size.w.of(t.min_x)..=size.w.of(t.max_x),
    )
}

/// The indices of the tiles (`cols` a row) triangle `t`'s box touches.
fn tiles_of<const N: usize>(
    t: &SetupTriangle<N>,
    size: TileSize,
    cols: u32,
) -> impl Iterator<Item = usize> {
    let (rows, columns) = tile_range(t, size);
    rows.flat_map(move |r| {
        columns
            .clone()
            .map(move |c| r as usize * cols as usize + c as usize)
    })
}

/// Bin entries for tiles of `tw x th` (0 counts as 1): one per (triangle,
/// tile its box touches); saturates at `usize::MAX` (then no storage can
/// hold them).
pub(crate) fn entries<const N: usize>(triangles: &[SetupTriangle<N>], tw: u32, th: u32) -> usize {
    let size = TileSize::new(tw, th);
    triangles.iter().fold(0usize, |n, t| {
        let (rows, cols) = tile_range(t, size);
        let k = (rows.end() - rows.start()) as usize + 1;
        n.saturating_add(k.saturating_mul((cols.end() - cols.start()) as usize + 1))
    })
}

/// Sorts `triangles` of a frame of `config` into bins of `tile_w x
/// tile_h` tiles; see [`Frame::bin_tiles`](crate::Frame::bin_tiles). A
/// tile at least as wide as the frame is a strip. `items` is called once,
/// with the entries needed, after the tile size and `offsets` passed their
/// checks, and returns the item storage.
///
/// `count_first`: the entries are found by counting them into `offsets`
/// (one pass over the triangles fewer), so `offsets` holds those counts
/// where the items then turn out too short; otherwise they are found by a
/// pass of their own, and an error leaves both slices as they were.
pub(crate) fn bin<'b, const N: usize>(
    config: &Config,
    triangles: &[SetupTriangle<N>],
    (tile_w, tile_h): (u32, u32),
    offsets: &'b mut [u32],
    items: impl FnOnce(usize) -> &'b mut [u32],
    count_first: bool,
) -> Result<Bins<'b>, Error> {
    if tile_h == 0 {
        return Err(Error::InvalidStripRows);
    }
    if tile_w == 0 {
        return Err(Error::InvalidTileSize);
    }
    let (tw, th) = (tile_w.min(config.width.max(1)), tile_h);
    let cols = grid(config, tw, th).0;
    // At most MAX_DIMENSION^2 tiles: this never overflows a 32-bit usize.
    let tiles = tile_count(config, tw, th).unwrap_or(usize::MAX);
    if offsets.len() < tiles.saturating_add(1) {
        return Err(Error::BinStorageSize {
            expected: tiles.saturating_add(1),
            actual: offsets.len(),
        });
    }
    let offsets = &mut offsets[..tiles + 1];
    let size = TileSize::new(tw, th);
    // Counts into offsets[s + 1]; returns their sum, saturating (a tile's
    // count wraps only where the sum exceeds `u32::MAX`, an error below).
    let count = |offsets: &mut [u32]| {
        offsets.fill(0);
        let mut n = 0usize;
        for t in triangles {
            for s in tiles_of(t, size, cols) {
                if let Some(o) = offsets.get_mut(s + 1) {
                    *o = o.wrapping_add(1);
                }
                n = n.saturating_add(1);
            }
        }
        n
    };
    let need_items = if count_first {
        count(offsets)
    } else {
        entries(triangles, tw, th)
    };
    let items = items(need_items);
    if items.len() < need_items || need_items > u32::MAX as usize {
        return Err(Error::BinStorageSize {
            expected: need_items,
            actual: items.len(),
        });
    }
    if !count_first {
        count(offsets);
    }
    // Prefix-sum the counts into starts, fill using offsets[s] as the
    // cursor (it ends at the start of s + 1), then shift back: no scratch
    // beyond the two slices. Every sum is at most `need_items <= u32::MAX`.
    for s in 1..offsets.len() {
        offsets[s] += offsets[s - 1];
    }
    for (i, t) in triangles.iter().enumerate() {
        for s in tiles_of(t, size, cols) {
            if let Some(o) = offsets.get_mut(s) {
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
        strip_rows: th,
        tile_w: tw,
        cols,
        width: config.width,
        height: config.height,
        triangles: triangles.len(),
        offsets,
        items: &items[..need_items],
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// Every divisor a tile side can take below `2^16` and beyond, with
    /// the numerators where a quotient steps (`k d - 1`, `k d`) and the
    /// largest coordinate.
    #[test]
    fn div16_equals_division_where_quotients_step() {
        let max = u16::MAX as u32;
        // Under Miri (slow), every 61st divisor below 2^16.
        let stride = if cfg!(miri) { 61 } else { 1 };
        let ds = (1..=max)
            .step_by(stride)
            .chain([max, 1 << 16, (1 << 16) + 1, 1 << 20, u32::MAX]);
        for d in ds {
            let div = Div16::new(d);
            let ends = [0, 1, max - 1, max, d - 1, d, d.saturating_add(1)];
            let steps = (1..=max / d.min(max))
                .step_by(97)
                .flat_map(|k| [k * d - 1, k * d]);
            for x in ends.into_iter().chain(steps).filter(|&x| x <= max) {
                assert_eq!(div.of(x as u16), x / d, "{x} / {d}");
            }
        }
        assert_eq!(Div16::new(0).of(12345), 12345, "0 counts as 1");
    }

    proptest! {
        // Few cases under Miri (CI runs these unit tests there too), and no
        // failure file, which Miri's isolation would refuse.
        #![proptest_config(ProptestConfig {
            cases: if cfg!(miri) { 16 } else { 4096 },
            failure_persistence: None,
            ..ProptestConfig::default()
        })]
        #[test]
        fn div16_equals_division(x in any::<u16>(), d in 1u32..=70_000) {
            prop_assert_eq!(Div16::new(d).of(x), x as u32 / d);
        }
    }
}
