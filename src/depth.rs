//! Depth buffers: `u16`, `u32`, `f32` ([`DepthF32`]) or none at all.
//!
//! Design note: the rasterizer is generic over [`DepthBuffer`], so a scene
//! drawn with [`NoDepth`] compiles to a loop with no depth arithmetic in it
//! ([`DepthBuffer::ENABLED`] is a constant). Depth values are window depth
//! in `[0, 1]`: `Z32` (`u32`, `z * 2^32` saturated) or `Z16` (`u16`, the top
//! 16 bits of `Z32`). Clear a buffer to `u16::MAX` / `u32::MAX` (the far
//! plane) before drawing with [`DepthFunc::Less`].
//!
//! [`DepthF32`] stores an IEEE `f32` in `[0, 1)`, made from the stepped
//! `Z32.16` value (48 fraction bits) with integer operations only (no
//! float rounding mode or FPU is involved, so it is the same on every
//! core): the value truncated to 24 significant bits. Non-negative floats
//! order as their bit patterns, so the buffer compares those bits as a
//! `u32` ([`DepthWord::key`]). Its precision is relative, `2^-24` of the
//! value down to `2^-24`, where a `u32` buffer keeps `2^-32` absolute: less
//! near 1, far more near 0, which is where a reversed 1/w depth
//! (`Mat4::perspective_inv_w`) puts distant surfaces. That is its storage
//! only: the vertex depths it interpolates are `Z32`, made from an `f32`
//! window depth rounded to `2^-25` absolute, so measured against the exact
//! depth it is no more accurate than `u32` (`docs/accuracy.md`).

/// The depth comparison: a fragment passes when `func(new, stored)` holds.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum DepthFunc {
    /// Never passes.
    Never,
    /// `new < stored` (the default).
    #[default]
    Less,
    /// `new == stored`.
    Equal,
    /// `new <= stored`.
    LessEqual,
    /// `new > stored`.
    Greater,
    /// `new != stored`.
    NotEqual,
    /// `new >= stored`.
    GreaterEqual,
    /// Always passes.
    Always,
}

/// The ordered comparisons the span fast paths are built for, as a const
/// parameter: `Less`, `LessEqual`, `Greater`, `GreaterEqual`.
pub(crate) mod cmp {
    pub const LESS: u8 = 0;
    pub const LESS_EQUAL: u8 = 1;
    pub const GREATER: u8 = 2;
    pub const GREATER_EQUAL: u8 = 3;
}

/// Marks the path it is on as rarely taken, so the span loops keep their
/// common case (a pixel written) as straight-line code: `core::hint::cold_path`
/// where the compiler has it (Rust 1.95 on, `build.rs`), nothing before.
/// On the Cortex-M4F the four-cubes frame takes 9 k fewer instructions
/// with it.
#[inline(always)]
fn cold() {
    // Only compiled where `build.rs` found Rust 1.95 or later.
    #[cfg(microraster_cold_path)]
    #[allow(clippy::incompatible_msrv)]
    core::hint::cold_path();
}

/// `new CMP old` for a [`cmp`] constant (resolved at compile time).
#[inline(always)]
pub(crate) fn passes<const CMP: u8, T: Ord>(new: T, old: T) -> bool {
    match CMP {
        cmp::LESS => new < old,
        cmp::LESS_EQUAL => new <= old,
        cmp::GREATER => new > old,
        _ => new >= old,
    }
}

impl DepthFunc {
    /// Whether a fragment at depth `new` passes against `stored`.
    #[inline]
    pub fn test<T: Ord>(self, new: T, stored: T) -> bool {
        match self {
            DepthFunc::Never => false,
            DepthFunc::Less => new < stored,
            DepthFunc::Equal => new == stored,
            DepthFunc::LessEqual => new <= stored,
            DepthFunc::Greater => new > stored,
            DepthFunc::NotEqual => new != stored,
            DepthFunc::GreaterEqual => new >= stored,
            DepthFunc::Always => true,
        }
    }
}

/// Depth storage for the rows being rendered.
///
/// Implemented for slices and arrays of [`DepthWord`]s (`u16`, `u32`) and
/// for [`NoDepth`]. Pass `&mut depth` (or `&mut NoDepth`) to
/// [`Frame::render_rows`](crate::Frame::render_rows).
pub trait DepthBuffer {
    /// `false` only for [`NoDepth`]: no depth value is computed at all.
    const ENABLED: bool;

    /// Whether the buffer keeps more than 24 bits, so depth is interpolated
    /// in `f64` (`u32`); `u16` buffers use `f32`, which is exact enough for
    /// 16 bits and cheap on cores without a double-precision FPU.
    const WIDE: bool;

    /// `F`, the fraction bits of the fixed-point depth `Z32.F` that spans
    /// step ([`DepthBuffer::flat_span`]): 16 by default and for `u32`
    /// buffers, 0 for `u16` buffers, whose 16 kept bits leave whole `Z32`
    /// units 16 bits to spare (the stepping error stays below 1/8 of a
    /// `u16` LSB over 2^14 pixels) and which then step in one 32-bit
    /// register on a 32-bit core. (No default: a buffer that forwards
    /// [`DepthBuffer::flat_span`] to another must state the same `F`.)
    const FRAC: u32;

    /// The number of depth values held, or `None` without a buffer.
    fn depth_len(&self) -> Option<usize>;

    /// The key [`test_and_set`](DepthBuffer::test_and_set) takes for the
    /// `Z32.F` depth `z` (`F` = [`DepthBuffer::FRAC`], clamped to `[0, 1]`):
    /// its `Z32` by default and for `u16` and `u32` buffers, the `f32`'s
    /// bits for [`DepthF32`] buffers (which keep more than `Z32` near 0).
    #[inline(always)]
    fn key_of(z: i64) -> u32 {
        z32_of(z, Self::FRAC)
    }

    /// Whether [`key_of`](DepthBuffer::key_of) keeps more than `Z32`
    /// ([`DepthF32`] buffers): then every pixel's key is made from its
    /// `Z32.F` depth, where otherwise small triangles take their `Z32`
    /// straight from the interpolated float.
    const FINE_KEY: bool = false;

    /// Tests `z` against the value at `index` and, if it passes and `write`
    /// is set, stores it. `z` is the buffer's key for the depth
    /// ([`DepthBuffer::key_of`]): `Z32` for `u16` and `u32` buffers. An
    /// index out of range fails the test.
    fn test_and_set(&mut self, index: usize, z: u32, func: DepthFunc, write: bool) -> bool;

    /// Draws a span of one flat colour: pixels `start..start + len`, where
    /// pixel `start + n` has depth `Z32 = clamp(z0 + n * dz, 0, top) >> F`
    /// (`z0`, `dz` in `Z32.F`, `F` = [`DepthBuffer::FRAC`], `top = 2^(32 +
    /// F) - 1`; the sum wraps as `i64`). Returns the pixels written. The default tests
    /// pixel by pixel; buffers override it with branch-free loops the
    /// compiler can vectorize.
    #[allow(clippy::too_many_arguments)]
    fn flat_span<C: Copy>(
        &mut self,
        color: &mut [C],
        start: usize,
        len: usize,
        z0: i64,
        dz: i64,
        func: DepthFunc,
        write: bool,
        px: C,
    ) -> u32 {
        flat_span_each(self, color, start, len, z0, dz, func, write, px)
    }

    /// [`flat_span`](DepthBuffer::flat_span) with an ordered `func`
    /// (`Less`, `LessEqual`, `Greater` or `GreaterEqual`, as the crate's
    /// `cmp` constant `cmp`), writes on, `F = 0`, and a depth the caller
    /// has proved to stay in `[0, 2^32)` over the span: `z0 + n * dz`
    /// (wrapping `u32` sums of `dz`'s low half) is then the exact `Z32`,
    /// with no clamp. Only called for buffers with
    /// [`FRAC`](DepthBuffer::FRAC) 0: the rasterizer's fast path for `u16`
    /// buffers.
    #[doc(hidden)]
    #[allow(clippy::too_many_arguments)]
    #[inline(always)]
    fn flat_span_in_range<C: Copy>(
        &mut self,
        color: &mut [C],
        start: usize,
        len: usize,
        z0: u32,
        dz: i64,
        cmp: u8,
        px: C,
    ) -> u32 {
        let func = match cmp {
            cmp::LESS => DepthFunc::Less,
            cmp::LESS_EQUAL => DepthFunc::LessEqual,
            cmp::GREATER => DepthFunc::Greater,
            _ => DepthFunc::GreaterEqual,
        };
        self.flat_span(color, start, len, z0 as i64, dz, func, true, px)
    }

    /// [`flat_span_in_range`](DepthBuffer::flat_span_in_range) for a
    /// batch of spans, each `[start, length, Z32 start]` (a length may be
    /// 0); returns the pixels it wrote. Buffers override it with one loop
    /// over the spans (a call a span, and the arguments it takes, were a
    /// third of a small span's instructions on the Cortex-M4F).
    #[doc(hidden)]
    #[inline(always)]
    fn flat_spans_in_range<C: Copy>(
        &mut self,
        color: &mut [C],
        spans: &[[u32; 3]],
        dz: i64,
        cmp: u8,
        px: C,
    ) -> u32 {
        spans_one_by_one(self, color, spans, dz, cmp, px)
    }

    /// Sets values `start..start + len` (those held) to the depth `z32`
    /// (`Z32`), as a clear would: a deferred clear's
    /// ([`LazyClear`](crate::LazyClear)) fill. The default stores each
    /// through [`test_and_set`](DepthBuffer::test_and_set) under
    /// [`DepthFunc::Always`].
    #[doc(hidden)]
    fn fill_z32(&mut self, start: usize, len: usize, z32: u32) {
        let key = Self::key_of((z32 as i64) << Self::FRAC);
        for index in start..start.saturating_add(len) {
            self.test_and_set(index, key, DepthFunc::Always, true);
        }
    }

    /// [`flat_span`](DepthBuffer::flat_span) under `Less`, with writes,
    /// over pixels whose values do not matter because they are taken to
    /// hold the clear depth `clear_z32` (a deferred clear's columns no
    /// draw has reached): where every depth of the span is in range and
    /// nearer than that, every pixel would pass, and the span is written
    /// without reading the buffer (`Some(pixels written)`); otherwise
    /// nothing is written (`None`). The default writes nothing.
    #[doc(hidden)]
    #[allow(clippy::too_many_arguments)]
    #[inline(always)]
    fn untested_span<C: Copy>(
        &mut self,
        color: &mut [C],
        start: usize,
        len: usize,
        z0: i64,
        dz: i64,
        clear_z32: u32,
        px: C,
    ) -> Option<u32> {
        let _ = (color, start, len, z0, dz, clear_z32, px);
        None
    }
}

/// The pixel-by-pixel span loop behind [`DepthBuffer::flat_span`].
#[allow(clippy::too_many_arguments)]
fn flat_span_each<B: DepthBuffer + ?Sized, C: Copy>(
    buf: &mut B,
    color: &mut [C],
    start: usize,
    len: usize,
    z0: i64,
    dz: i64,
    func: DepthFunc,
    write: bool,
    px: C,
) -> u32 {
    let Some(c) = color.get_mut(start..start.saturating_add(len)) else {
        return 0;
    };
    let mut written = 0;
    let mut z = z0;
    for (n, cp) in c.iter_mut().enumerate() {
        if buf.test_and_set(start + n, B::key_of(z), func, write) {
            *cp = px;
            written += 1;
        }
        z = z.wrapping_add(dz);
    }
    written
}

/// Whether `z0 + n * dz` lies in `[0, 2^(32 + frac))` (the `Z32.F` range,
/// where [`z32_of`] clamps nothing) for every `n < len`, so the stepped
/// values are the exact ones: both ends are in range and the steps are
/// small enough that no sum wraps (`|dz| < 2^40`, `len <= 2^16`: `|n dz| <
/// 2^56`); a linear function in range at both ends is in range between
/// them.
#[inline]
fn in_range_throughout(z0: i64, dz: i64, len: usize, frac: u32) -> bool {
    let top: i64 = 1 << (32 + frac);
    if len == 0 || len > 1 << 16 || dz.unsigned_abs() >= 1 << 40 {
        return false;
    }
    let last = z0 + dz * (len as i64 - 1);
    (0..top).contains(&z0) && (0..top).contains(&last)
}

/// The flat-span loop of [`DepthBuffer::flat_span`] for an ordered
/// comparison (`CMP`, a [`cmp`] constant) with writes, where [`in_range_throughout`] holds:
/// `z` is never clamped, so the word is [`DepthWord::from_fixed_in_range`]
/// of the wrapping sum: a `u64` for `Z32.16` (an add with carry on a 32-bit
/// core), a `u32` for `Z32.0` (`u16` buffers), exact because every value
/// is below `2^32`. Out of line: inlined into the rasterizer, its loop
/// lost its registers to the caller's (on the Cortex-M4F the four-cubes
/// frame takes 19 k more instructions inlined).
#[inline(never)]
fn span_unclamped<W: DepthWord, C: Copy, const CMP: u8>(
    c: &mut [C],
    d: &mut [W],
    z0: u64,
    dz: u64,
    px: C,
) -> u32 {
    let mut written = 0u32;
    if W::FRAC == 0 {
        written = z32_loop::<W, C, CMP>(c, d, z0 as u32, dz as u32, px);
    } else {
        let mut z = z0;
        for (cp, dp) in c.iter_mut().zip(d.iter_mut()) {
            let (key, old) = (W::key_in_range(z), (*dp).key());
            if passes::<CMP, _>(key, old) {
                *dp = W::from_fixed_in_range(z);
                *cp = px;
                written += 1;
            }
            z = z.wrapping_add(dz);
        }
    }
    written
}

/// [`span_unclamped`] for `Z32.0` words (`u16` buffers), with the start
/// and step in one register each: the loop behind
/// [`DepthBuffer::flat_span_in_range`] on 32-bit cores.
#[inline(never)]
fn span_z32<W: DepthWord, C: Copy, const CMP: u8>(
    c: &mut [C],
    d: &mut [W],
    z0: u32,
    dz: u32,
    px: C,
) -> u32 {
    z32_loop::<W, C, CMP>(c, d, z0, dz, px)
}

/// [`DepthBuffer::flat_spans_in_range`] as one
/// [`flat_span_in_range`](DepthBuffer::flat_span_in_range) a span: the
/// default, and the slices' on 64-bit hosts (whose span loop is
/// branch-free). Returns the pixels not written.
#[inline(always)]
fn spans_one_by_one<D: DepthBuffer + ?Sized, C: Copy>(
    depth: &mut D,
    color: &mut [C],
    spans: &[[u32; 3]],
    dz: i64,
    cmp: u8,
    px: C,
) -> u32 {
    let mut written = 0;
    for &[start, len, z0] in spans {
        let (at, n) = (start as usize, len as usize);
        written += depth.flat_span_in_range(color, at, n, z0, dz, cmp, px);
    }
    written
}

/// [`span_z32`] for each row of a batch (see
/// [`DepthBuffer::flat_spans_in_range`]), its loop inlined: one call a
/// batch of rows.
#[inline(never)]
#[allow(clippy::type_complexity)]
fn spans_z32<W: DepthWord, C: Copy, const CMP: u8>(
    (c, d, spans): (&mut [C], &mut [W], &[[u32; 3]]),
    dz: u32,
    px: C,
) -> u32 {
    let (mut drawn, mut missed) = (0u32, 0u32);
    for &[start, len, z0] in spans {
        let (start, end) = (start as usize, start as usize + len as usize);
        // (Always: the spans lie in the buffers, or are empty.)
        if let (Some(c), Some(d)) = (c.get_mut(start..end), d.get_mut(start..end)) {
            drawn += len;
            z32_misses::<W, C, CMP>(c, d, z0, dz, px, &mut missed)
        }
    }
    drawn - missed
}

/// The span of [`DepthBuffer::untested_span`], where every pixel passes:
/// each depth word ([`DepthWord::from_fixed_in_range`] of `z` stepped in
/// a `u64`) and colour written without reading the buffer.
#[inline(never)]
fn span_untested<W: DepthWord, C: Copy>(c: &mut [C], d: &mut [W], z0: u64, dz: u64, px: C) -> u32 {
    let n = c.len().min(d.len());
    let mut z = z0;
    for (cp, dp) in c[..n].iter_mut().zip(d[..n].iter_mut()) {
        *dp = W::from_fixed_in_range(z);
        *cp = px;
        z = z.wrapping_add(dz);
    }
    n as u32
}

/// The `Z32.0` span loop itself, shared by [`span_unclamped`] and
/// [`span_z32`]: `z` in one `u32`, the word its top half.
#[inline(always)]
fn z32_loop<W: DepthWord, C: Copy, const CMP: u8>(
    c: &mut [C],
    d: &mut [W],
    z0: u32,
    dz: u32,
    px: C,
) -> u32 {
    let mut failed = 0;
    z32_misses::<W, C, CMP>(c, d, z0, dz, px, &mut failed);
    c.len().min(d.len()) as u32 - failed
}

/// [`z32_loop`] adding the pixels that fail the test to `failed`.
#[inline(always)]
fn z32_misses<W: DepthWord, C: Copy, const CMP: u8>(
    c: &mut [C],
    d: &mut [W],
    z0: u32,
    dz: u32,
    px: C,
    failed: &mut u32,
) {
    let n = c.len().min(d.len());
    let (c, d) = (&mut c[..n], &mut d[..n]);
    // Failures are counted (the rarer case on a front-to-back frame). The
    // first `n mod 4` pixels go one by one, the rest four a turn at
    // constant offsets, `z` stepped by multiples of `dz` (wrapping: the
    // same integers as `z0 + k dz`).
    let mut z = z0;
    let head = n % 4;
    let (ch, c4) = c.split_at_mut(head);
    let (dh, d4) = d.split_at_mut(head);
    for (cp, dp) in ch.iter_mut().zip(dh.iter_mut()) {
        let (key, old) = (W::key_in_range(z as u64), (*dp).key());
        if passes::<CMP, _>(key, old) {
            *dp = W::from_fixed_in_range(z as u64);
            *cp = px;
        } else {
            *failed += 1;
        }
        z = z.wrapping_add(dz);
    }
    let (dz2, dz3, dz4) = (dz.wrapping_mul(2), dz.wrapping_mul(3), dz.wrapping_mul(4));
    for (cq, dq) in c4.chunks_exact_mut(4).zip(d4.chunks_exact_mut(4)) {
        let (z1, z2, z3) = (z.wrapping_add(dz), z.wrapping_add(dz2), z.wrapping_add(dz3));
        for (k, zk) in [z, z1, z2, z3].into_iter().enumerate() {
            let (key, old) = (W::key_in_range(zk as u64), dq[k].key());
            if passes::<CMP, _>(key, old) {
                dq[k] = W::from_fixed_in_range(zk as u64);
                cq[k] = px;
            } else {
                cold();
                *failed += 1;
            }
        }
        z = z.wrapping_add(dz4);
    }
}

/// `Z32` of a `Z32.F` value `z` (`F = frac`, clamped). Spans step `z` by
/// `dz` with wrapping additions: the same integers as `z0 + n * dz`,
/// without the 64-bit multiply.
#[inline(always)]
pub(crate) fn z32_of(z: i64, frac: u32) -> u32 {
    (z.clamp(0, (1i64 << (32 + frac)) - 1) >> frac) as u32
}

/// A depth-buffer word: `u16` (the top 16 bits of `Z32`) or `u32` (`Z32`).
///
/// The one trait for depth values: buffers of them are [`DepthBuffer`]s
/// (slices and arrays), and [`StripDrawer`](crate::StripDrawer) clears them
/// to [`DepthWord::FAR`] or any `Z32` value.
pub trait DepthWord: Copy + Ord + Default + core::fmt::Debug + Send + Sync + 'static {
    /// The far plane (`Z32` 1.0): the clear value for [`DepthFunc::Less`].
    const FAR: Self;
    /// The near plane (`Z32` 0).
    const NEAR: Self;
    /// Whether the word keeps more than 24 bits, so depth is interpolated
    /// in `f64` (`u32`); `u16` uses `f32`, which is exact enough for 16
    /// bits and cheap on cores without a double-precision FPU.
    const WIDE: bool;
    /// The word for a `Z32` depth.
    fn from_z32(z: u32) -> Self;
    /// The word as `Z32` (a `u16` gives its value times `2^16`).
    fn to_z32(self) -> u32;
    /// `F`, the fraction bits of the depth spans step for buffers of this
    /// word (`Z32.F`, see [`DepthBuffer::FRAC`]): 16, or 0 for `u16`.
    const FRAC: u32 = 16;
    /// The word for a `Z32.F` depth, clamped to `[0, 1]`: the same as
    /// `from_z32` of the clamped `Z32`, in fewer operations.
    #[inline(always)]
    fn from_fixed(z: i64) -> Self {
        Self::from_z32(z32_of(z, Self::FRAC))
    }
    /// [`from_fixed`](DepthWord::from_fixed) of a value already in
    /// `[0, 2^(32 + F))`, which needs no clamp: a shift.
    #[inline(always)]
    fn from_fixed_in_range(z: u64) -> Self {
        Self::from_z32((z >> Self::FRAC) as u32)
    }
    /// A `u32` that orders words as the words order: [`to_z32`] by
    /// default. Span loops compare these in a register.
    ///
    /// [`to_z32`]: DepthWord::to_z32
    #[inline(always)]
    fn key(self) -> u32 {
        self.to_z32()
    }
    /// `key(from_fixed_in_range(z))`, for `z` in `[0, 2^(32 + F))`.
    #[inline(always)]
    fn key_in_range(z: u64) -> u32 {
        Self::from_fixed_in_range(z).key()
    }
    /// The key [`DepthBuffer::key_of`] gives buffers of this word for a
    /// `Z32.F` depth: `Z32` by default (what
    /// [`DepthWord::from_key`] reads back).
    #[inline(always)]
    fn key_of_fixed(z: i64) -> u32 {
        z32_of(z, Self::FRAC)
    }
    /// Whether [`DepthWord::key_of_fixed`] keeps more than `Z32`
    /// ([`DepthBuffer::FINE_KEY`]).
    const FINE: bool = false;
    /// The word for a key of [`DepthWord::key_of_fixed`]: `from_z32` by
    /// default.
    #[inline(always)]
    fn from_key(key: u32) -> Self {
        Self::from_z32(key)
    }
}

impl DepthWord for u16 {
    const FAR: Self = u16::MAX;
    const NEAR: Self = 0;
    const WIDE: bool = false;
    #[inline(always)]
    fn from_z32(z: u32) -> Self {
        (z >> 16) as u16
    }
    #[inline(always)]
    fn to_z32(self) -> u32 {
        (self as u32) << 16
    }
    /// Whole `Z32` units: 16 bits below the kept ones.
    const FRAC: u32 = 0;
    /// `clamp(z, 0, 2^32 - 1) >> 16` is `clamp(z >> 16, 0, 2^16 - 1)`
    /// (flooring is monotone).
    #[inline(always)]
    fn from_fixed(z: i64) -> Self {
        ((z >> 16).clamp(0, 0xffff)) as u16
    }
    /// The top half of `Z32`.
    #[inline(always)]
    fn from_fixed_in_range(z: u64) -> Self {
        (z >> 16) as u16
    }
    /// The word itself, zero-extended (a halfword load makes it).
    #[inline(always)]
    fn key(self) -> u32 {
        self as u32
    }
    /// The top half of `Z32`, already below `2^16` in range: no
    /// extension.
    #[inline(always)]
    fn key_in_range(z: u64) -> u32 {
        (z >> 16) as u32
    }
}

impl DepthWord for u32 {
    const FAR: Self = u32::MAX;
    const NEAR: Self = 0;
    const WIDE: bool = true;
    #[inline(always)]
    fn from_z32(z: u32) -> Self {
        z
    }
    #[inline(always)]
    fn to_z32(self) -> u32 {
        self
    }
}

/// The host's branch-free `Z32.0` span loop (so the compiler can
/// vectorize it) for [`DepthBuffer::flat_span_in_range`]: the same
/// unclamped words as [`z32_loop`].
#[inline(always)]
fn z32_branch_free<W: DepthWord, C: Copy, const CMP: u8>(
    c: &mut [C],
    d: &mut [W],
    z0: u32,
    dz: u32,
    px: C,
) -> u32 {
    let (mut z, mut written) = (z0, 0u32);
    for (cp, dp) in c.iter_mut().zip(d.iter_mut()) {
        let zw = W::from_fixed_in_range(z as u64);
        let pass = passes::<CMP, _>(zw, *dp);
        *dp = if pass { zw } else { *dp };
        *cp = if pass { px } else { *cp };
        written += pass as u32;
        z = z.wrapping_add(dz);
    }
    written
}

/// [`DepthBuffer::flat_span`] of a slice under `Greater` (or
/// `GreaterEqual` when `ge`) with writes, as `Less` spans are drawn:
/// branch-free on the host, the unclamped loop where
/// [`in_range_throughout`] holds on 32-bit cores, else word by word. Out
/// of line, so the `Less` paths inlined into the rasterizer do not grow.
#[allow(clippy::too_many_arguments)]
#[inline(never)]
fn span_greater<W: DepthWord, C: Copy>(
    buf: &mut [W],
    color: &mut [C],
    start: usize,
    len: usize,
    z0: i64,
    dz: i64,
    ge: bool,
    px: C,
) -> u32 {
    let end = start.saturating_add(len);
    let (Some(c), Some(d)) = (color.get_mut(start..end), buf.get_mut(start..end)) else {
        return 0;
    };
    let pass = |zw: W, old: W| {
        if ge {
            passes::<{ cmp::GREATER_EQUAL }, _>(zw, old)
        } else {
            passes::<{ cmp::GREATER }, _>(zw, old)
        }
    };
    let (mut z, mut written) = (z0, 0u32);
    if cfg!(target_pointer_width = "64") {
        for (cp, dp) in c.iter_mut().zip(d.iter_mut()) {
            let zw = W::from_fixed(z);
            let p = pass(zw, *dp);
            *dp = if p { zw } else { *dp };
            *cp = if p { px } else { *cp };
            written += p as u32;
            z = z.wrapping_add(dz);
        }
    } else if in_range_throughout(z0, dz, len, W::FRAC) {
        return if ge {
            span_unclamped::<W, C, { cmp::GREATER_EQUAL }>(c, d, z0 as u64, dz as u64, px)
        } else {
            span_unclamped::<W, C, { cmp::GREATER }>(c, d, z0 as u64, dz as u64, px)
        };
    } else {
        for (cp, dp) in c.iter_mut().zip(d.iter_mut()) {
            let zw = W::from_fixed(z);
            if pass(zw, *dp) {
                *dp = zw;
                *cp = px;
                written += 1;
            }
            z = z.wrapping_add(dz);
        }
    }
    written
}

/// An `f32` depth word in `[0, 1)`, kept as its IEEE bits (see the module
/// note): `Z32.16` truncated to 24 significant bits, made and compared
/// with integer operations only. [`DepthF32::get`] (or `f32::from`) reads
/// the float; [`DepthF32::new`] makes one from a float (clamped to
/// `[0, 1)`, NaN as 0), e.g. to clear to a depth of your own.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, PartialOrd, Ord, Hash)]
#[repr(transparent)]
pub struct DepthF32(u32);

impl DepthF32 {
    /// The largest value, the largest `f32` below 1: [`DepthWord::FAR`].
    const MAX_BITS: u32 = 0x3f7f_ffff;

    /// The word for `z`, clamped to `[0, 1)` (1 and above give the
    /// largest `f32` below 1, the far plane; NaN gives 0).
    pub fn new(z: f32) -> Self {
        if z > 0.0 {
            DepthF32(z.to_bits().min(Self::MAX_BITS))
        } else {
            DepthF32(0)
        }
    }

    /// The depth as a float.
    pub fn get(self) -> f32 {
        f32::from_bits(self.0)
    }

    /// The IEEE bits (which order as the values do).
    pub fn to_bits(self) -> u32 {
        self.0
    }

    /// The word for a `Z32.16` value `z < 2^48` (`z / 2^48`), truncated to
    /// 24 significant bits: the leading one found with a count of leading
    /// zeros, the next 23 bits the mantissa, the exponent from its place.
    #[inline(always)]
    fn of_fixed(z: u64) -> Self {
        if z == 0 {
            return DepthF32(0);
        }
        let lz = z.leading_zeros(); // 16..=63 for 0 < z < 2^48
        let mantissa = ((z << lz) >> 40) as u32 & 0x7f_ffff;
        // z = 1.m * 2^(63 - lz), so z / 2^48 = 1.m * 2^(15 - lz): biased
        // exponent 127 + 15 - lz, in 79..=126.
        DepthF32((142 - lz) << 23 | mantissa)
    }
}

impl From<DepthF32> for f32 {
    fn from(d: DepthF32) -> f32 {
        d.get()
    }
}

/// `f32` depth: 16 fraction bits below `Z32` in the spans (as `u32`), all
/// of them kept where the value is small.
impl DepthWord for DepthF32 {
    const FAR: Self = DepthF32(DepthF32::MAX_BITS);
    const NEAR: Self = DepthF32(0);
    const WIDE: bool = true;
    /// `Z32 / 2^32`, truncated to 24 significant bits.
    #[inline(always)]
    fn from_z32(z: u32) -> Self {
        Self::of_fixed((z as u64) << 16)
    }
    /// `value * 2^32`, truncated (exact for every word made from a `Z32`).
    fn to_z32(self) -> u32 {
        if self.0 == 0 {
            return 0;
        }
        let exp = (self.0 >> 23) as i32; // 79..=126 for words made here
        let m = (self.0 & 0x7f_ffff | 0x80_0000) as u64;
        // value = m * 2^(exp - 150), so value * 2^32 = m * 2^(exp - 118).
        let s = exp - 118;
        let z = if s >= 0 {
            m.checked_shl(s as u32).unwrap_or(u64::MAX)
        } else {
            m.checked_shr((-s) as u32).unwrap_or(0)
        };
        z.min(u32::MAX as u64) as u32
    }
    #[inline(always)]
    fn from_fixed(z: i64) -> Self {
        Self::of_fixed(z.clamp(0, (1i64 << 48) - 1) as u64)
    }
    #[inline(always)]
    fn from_fixed_in_range(z: u64) -> Self {
        Self::of_fixed(z)
    }
    /// The bits.
    #[inline(always)]
    fn key(self) -> u32 {
        self.0
    }
    /// The bits of [`DepthWord::from_fixed`]: more than `Z32` near 0.
    #[inline(always)]
    fn key_of_fixed(z: i64) -> u32 {
        Self::from_fixed(z).0
    }
    const FINE: bool = true;
    #[inline(always)]
    fn from_key(key: u32) -> Self {
        DepthF32(key)
    }
}

/// Slices of depth words. Flat spans under `Less` / `LessEqual` with depth
/// writes take a branch-free loop the compiler can vectorize; everything
/// else goes pixel by pixel.
impl<W: DepthWord> DepthBuffer for [W] {
    const ENABLED: bool = true;
    const WIDE: bool = W::WIDE;
    const FRAC: u32 = W::FRAC;

    #[inline(always)]
    fn flat_span<C: Copy>(
        &mut self,
        color: &mut [C],
        start: usize,
        len: usize,
        z0: i64,
        dz: i64,
        func: DepthFunc,
        write: bool,
        px: C,
    ) -> u32 {
        if write && matches!(func, DepthFunc::Greater | DepthFunc::GreaterEqual) {
            let ge = func == DepthFunc::GreaterEqual;
            return span_greater(self, color, start, len, z0, dz, ge, px);
        }
        if !(write && matches!(func, DepthFunc::Less | DepthFunc::LessEqual)) {
            return flat_span_each(self, color, start, len, z0, dz, func, write, px);
        }
        let end = start.saturating_add(len);
        let (Some(c), Some(d)) = (color.get_mut(start..end), self.get_mut(start..end)) else {
            return 0;
        };
        let le = func == DepthFunc::LessEqual;
        let mut written = 0u32;
        let mut z = z0;
        if cfg!(target_pointer_width = "64") {
            // Branch-free, so the compiler can vectorize it (SSE/AVX).
            for (cp, dp) in c.iter_mut().zip(d.iter_mut()) {
                let zw = W::from_fixed(z);
                let pass = zw < *dp || (le && zw == *dp);
                *dp = if pass { zw } else { *dp };
                *cp = if pass { px } else { *cp };
                written += pass as u32;
                z = z.wrapping_add(dz);
            }
        } else if in_range_throughout(z0, dz, len, W::FRAC) {
            // Microcontrollers have no vectors to fill: store only where
            // the test passes (the same results, fewer instructions). The
            // span's depth never leaves [0, 2^(32 + F)), so no clamp: the
            // word is a shift of `z` (one 32-bit register for `u16`).
            return if le {
                span_unclamped::<W, C, { cmp::LESS_EQUAL }>(c, d, z0 as u64, dz as u64, px)
            } else {
                span_unclamped::<W, C, { cmp::LESS }>(c, d, z0 as u64, dz as u64, px)
            };
        } else {
            for (cp, dp) in c.iter_mut().zip(d.iter_mut()) {
                let zw = W::from_fixed(z);
                if zw < *dp || (le && zw == *dp) {
                    *dp = zw;
                    *cp = px;
                    written += 1;
                }
                z = z.wrapping_add(dz);
            }
        }
        written
    }

    #[inline(always)]
    fn flat_span_in_range<C: Copy>(
        &mut self,
        color: &mut [C],
        start: usize,
        len: usize,
        z0: u32,
        dz: i64,
        cmp: u8,
        px: C,
    ) -> u32 {
        debug_assert!(W::FRAC == 0);
        debug_assert!(
            len == 0 || (0..1i128 << 32).contains(&(z0 as i128 + dz as i128 * (len as i128 - 1))),
            "span leaves [0, 2^32): z0 {z0} dz {dz} len {len}"
        );
        let end = start.saturating_add(len);
        let (Some(c), Some(d)) = (color.get_mut(start..end), self.get_mut(start..end)) else {
            return 0;
        };
        if cfg!(target_pointer_width = "64") {
            return match cmp {
                cmp::LESS => z32_branch_free::<W, C, { cmp::LESS }>(c, d, z0, dz as u32, px),
                cmp::LESS_EQUAL => {
                    z32_branch_free::<W, C, { cmp::LESS_EQUAL }>(c, d, z0, dz as u32, px)
                }
                cmp::GREATER => z32_branch_free::<W, C, { cmp::GREATER }>(c, d, z0, dz as u32, px),
                _ => z32_branch_free::<W, C, { cmp::GREATER_EQUAL }>(c, d, z0, dz as u32, px),
            };
        }
        match cmp {
            cmp::LESS => span_z32::<W, C, { cmp::LESS }>(c, d, z0, dz as u32, px),
            cmp::LESS_EQUAL => span_z32::<W, C, { cmp::LESS_EQUAL }>(c, d, z0, dz as u32, px),
            cmp::GREATER => span_z32::<W, C, { cmp::GREATER }>(c, d, z0, dz as u32, px),
            _ => span_z32::<W, C, { cmp::GREATER_EQUAL }>(c, d, z0, dz as u32, px),
        }
    }

    #[inline(always)]
    fn flat_spans_in_range<C: Copy>(
        &mut self,
        color: &mut [C],
        spans: &[[u32; 3]],
        dz: i64,
        cmp: u8,
        px: C,
    ) -> u32 {
        debug_assert!(W::FRAC == 0);
        if cfg!(target_pointer_width = "64") {
            return spans_one_by_one(self, color, spans, dz, cmp, px);
        }
        let rows = (color, self, spans);
        match cmp {
            cmp::LESS => spans_z32::<W, C, { cmp::LESS }>(rows, dz as u32, px),
            cmp::LESS_EQUAL => spans_z32::<W, C, { cmp::LESS_EQUAL }>(rows, dz as u32, px),
            cmp::GREATER => spans_z32::<W, C, { cmp::GREATER }>(rows, dz as u32, px),
            _ => spans_z32::<W, C, { cmp::GREATER_EQUAL }>(rows, dz as u32, px),
        }
    }

    #[inline]
    fn fill_z32(&mut self, start: usize, len: usize, z32: u32) {
        let end = start.saturating_add(len).min(self.len());
        if let Some(d) = self.get_mut(start..end) {
            d.fill(W::from_z32(z32));
        }
    }

    #[inline(always)]
    fn untested_span<C: Copy>(
        &mut self,
        color: &mut [C],
        start: usize,
        len: usize,
        z0: i64,
        dz: i64,
        clear_z32: u32,
        px: C,
    ) -> Option<u32> {
        if W::FINE || !in_range_throughout(z0, dz, len, W::FRAC) {
            return None;
        }
        // In range at both ends and linear in between: the farthest depth
        // is at one end, and no value is clamped.
        let last = z0 + dz * (len as i64 - 1);
        let far = W::key_in_range(z0.max(last) as u64);
        if !passes::<{ cmp::LESS }, _>(far, W::from_z32(clear_z32).key()) {
            return None;
        }
        let end = start.saturating_add(len);
        let (Some(c), Some(d)) = (color.get_mut(start..end), self.get_mut(start..end)) else {
            return None;
        };
        // Wrapping `u64` sums of the start and step are the exact depths,
        // all in range (as `span_unclamped` steps them).
        Some(span_untested(c, d, z0 as u64, dz as u64, px))
    }

    fn depth_len(&self) -> Option<usize> {
        Some(self.len())
    }

    #[inline(always)]
    fn key_of(z: i64) -> u32 {
        W::key_of_fixed(z)
    }

    const FINE_KEY: bool = W::FINE;

    #[inline]
    fn test_and_set(&mut self, index: usize, z: u32, func: DepthFunc, write: bool) -> bool {
        let z = W::from_key(z);
        match self.get_mut(index) {
            Some(d) if func.test(z, *d) => {
                if write {
                    *d = z;
                }
                true
            }
            _ => false,
        }
    }
}

/// Arrays of depth words, as their slices: `&mut [u16; N]` works wherever
/// `&mut [u16]` does.
impl<W: DepthWord, const N: usize> DepthBuffer for [W; N] {
    const ENABLED: bool = true;
    const WIDE: bool = W::WIDE;
    const FRAC: u32 = W::FRAC;

    #[inline]
    fn flat_span<C: Copy>(
        &mut self,
        color: &mut [C],
        start: usize,
        len: usize,
        z0: i64,
        dz: i64,
        func: DepthFunc,
        write: bool,
        px: C,
    ) -> u32 {
        self[..].flat_span(color, start, len, z0, dz, func, write, px)
    }

    #[inline(always)]
    fn flat_span_in_range<C: Copy>(
        &mut self,
        color: &mut [C],
        start: usize,
        len: usize,
        z0: u32,
        dz: i64,
        cmp: u8,
        px: C,
    ) -> u32 {
        self[..].flat_span_in_range(color, start, len, z0, dz, cmp, px)
    }

    #[inline(always)]
    fn flat_spans_in_range<C: Copy>(
        &mut self,
        color: &mut [C],
        spans: &[[u32; 3]],
        dz: i64,
        cmp: u8,
        px: C,
    ) -> u32 {
        self[..].flat_spans_in_range(color, spans, dz, cmp, px)
    }

    #[inline]
    fn fill_z32(&mut self, start: usize, len: usize, z32: u32) {
        self[..].fill_z32(start, len, z32)
    }

    #[inline(always)]
    fn untested_span<C: Copy>(
        &mut self,
        color: &mut [C],
        start: usize,
        len: usize,
        z0: i64,
        dz: i64,
        clear_z32: u32,
        px: C,
    ) -> Option<u32> {
        self[..].untested_span(color, start, len, z0, dz, clear_z32, px)
    }

    fn depth_len(&self) -> Option<usize> {
        Some(N)
    }

    #[inline(always)]
    fn key_of(z: i64) -> u32 {
        W::key_of_fixed(z)
    }

    const FINE_KEY: bool = W::FINE;

    #[inline]
    fn test_and_set(&mut self, index: usize, z: u32, func: DepthFunc, write: bool) -> bool {
        self[..].test_and_set(index, z, func, write)
    }
}

/// No depth buffer: every fragment passes and no depth is computed.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct NoDepth;

impl DepthBuffer for NoDepth {
    const ENABLED: bool = false;
    const WIDE: bool = false;
    const FRAC: u32 = 0;

    fn flat_span<C: Copy>(
        &mut self,
        color: &mut [C],
        start: usize,
        len: usize,
        _: i64,
        _: i64,
        _: DepthFunc,
        _: bool,
        px: C,
    ) -> u32 {
        match color.get_mut(start..start.saturating_add(len)) {
            Some(c) => {
                c.fill(px);
                len as u32
            }
            None => 0,
        }
    }

    fn depth_len(&self) -> Option<usize> {
        None
    }

    #[inline]
    fn test_and_set(&mut self, _: usize, _: u32, _: DepthFunc, _: bool) -> bool {
        true
    }

    #[inline]
    fn fill_z32(&mut self, _: usize, _: usize, _: u32) {}
}

#[cfg(test)]
mod tests {
    use super::*;
    extern crate std;
    use proptest::prelude::*;

    /// The microcontrollers' unclamped span loop (`span_unclamped`, which
    /// the 64-bit host never runs inside `flat_span`) writes what the
    /// pixel-by-pixel loop writes wherever `in_range_throughout` admits a
    /// span, and that test admits only spans whose every value is in
    /// `[0, 2^(32 + F))`.
    fn unclamped_matches<W: DepthWord>(z0: i64, dz: i64, len: usize, seed: u64, k: u8) {
        let stored: std::vec::Vec<W> = (0..len as u64)
            .map(|n| {
                let h = (seed ^ n).wrapping_mul(0x9e37_79b9_7f4a_7c15);
                W::from_z32((h >> 32) as u32)
            })
            .collect();
        let func = [
            DepthFunc::Less,
            DepthFunc::LessEqual,
            DepthFunc::Greater,
            DepthFunc::GreaterEqual,
        ][k as usize % 4];
        let (mut d_ref, mut c_ref) = (stored.clone(), std::vec![0u8; len]);
        let want = flat_span_each(&mut d_ref[..], &mut c_ref, 0, len, z0, dz, func, true, 1u8);
        if !in_range_throughout(z0, dz, len, W::FRAC) {
            return;
        }
        for n in 0..len as i64 {
            assert!(
                (0..1i64 << (32 + W::FRAC)).contains(&(z0 + n * dz)),
                "n {n}"
            );
        }
        let (mut d, mut c) = (stored, std::vec![0u8; len]);
        let (z0, dz) = (z0 as u64, dz as u64);
        let got = match func {
            DepthFunc::Less => span_unclamped::<W, u8, { cmp::LESS }>(&mut c, &mut d, z0, dz, 1),
            DepthFunc::LessEqual => {
                span_unclamped::<W, u8, { cmp::LESS_EQUAL }>(&mut c, &mut d, z0, dz, 1)
            }
            DepthFunc::Greater => {
                span_unclamped::<W, u8, { cmp::GREATER }>(&mut c, &mut d, z0, dz, 1)
            }
            _ => span_unclamped::<W, u8, { cmp::GREATER_EQUAL }>(&mut c, &mut d, z0, dz, 1),
        };
        assert_eq!((got, &d, &c), (want, &d_ref, &c_ref));
    }

    proptest! {
        // Few cases under Miri (CI runs these unit tests there too), and no
        // failure file, which Miri's isolation would refuse.
        #![proptest_config(ProptestConfig {
            cases: if cfg!(miri) { 4 } else { 256 },
            failure_persistence: None,
            ..ProptestConfig::default()
        })]
        #[test]
        fn unclamped_span_equals_clamped(
            z0 in prop_oneof![0i64..1 << 48, -(1i64 << 20)..1 << 20, (1i64 << 48) - (1 << 20)..(1i64 << 48) + (1 << 20), any::<i64>()],
            dz in prop_oneof![-(1i64 << 34)..1 << 34, -(1i64 << 42)..1 << 42, -4i64..4, any::<i64>()],
            len in 1usize..300,
            seed in any::<u64>(),
            k in 0u8..4,
        ) {
            // `u32` and `f32` buffers (both `Z32.16`; `f32` keyed by its
            // bits).
            unclamped_matches::<u32>(z0, dz, len, seed, k);
            unclamped_matches::<DepthF32>(z0, dz, len, seed, k);
        }

        /// The `Z32.0` loop (`u16` words: `z32_loop`, `n mod 4` pixels one
        /// by one, then four a turn, failures counted) against the
        /// pixel-by-pixel loop, over every remainder length and every
        /// mix of passing and failing pixels (stored words hashed, or all
        /// near the span's depths so about half pass).
        #[test]
        fn z32_span_loop_equals_pixel_loop(
            z0 in prop_oneof![0i64..1 << 32, (1i64 << 32) - (1 << 20)..1 << 32, 0i64..1 << 20],
            dz in prop_oneof![-(1i64 << 24)..1 << 24, -4i64..4, -(1i64 << 31)..1 << 31],
            len in 1usize..70,
            seed in any::<u64>(),
            k in 0u8..4,
        ) {
            unclamped_matches::<u16>(z0, dz, len, seed, k);
            // Stored words within a few steps of the span's own.
            let near = |n: u64| {
                let h = (seed ^ n).wrapping_mul(0x9e37_79b9_7f4a_7c15) >> 61;
                (z0 + (n as i64 + h as i64 - 4) * dz).clamp(0, u32::MAX as i64) as u32
            };
            if in_range_throughout(z0, dz, len, 0) {
                let stored: std::vec::Vec<u16> = (0..len as u64).map(|n| u16::from_z32(near(n))).collect();
                let (mut d_ref, mut c_ref) = (stored.clone(), std::vec![0u8; len]);
                let func = [DepthFunc::Less, DepthFunc::LessEqual, DepthFunc::Greater, DepthFunc::GreaterEqual][k as usize % 4];
                let want = flat_span_each(&mut d_ref[..], &mut c_ref, 0, len, z0, dz, func, true, 1u8);
                let (mut d, mut c) = (stored, std::vec![0u8; len]);
                let (z, step) = (z0 as u32, dz as u32);
                let got = match func {
                    DepthFunc::Less => span_z32::<u16, u8, { cmp::LESS }>(&mut c, &mut d, z, step, 1),
                    DepthFunc::LessEqual => span_z32::<u16, u8, { cmp::LESS_EQUAL }>(&mut c, &mut d, z, step, 1),
                    DepthFunc::Greater => span_z32::<u16, u8, { cmp::GREATER }>(&mut c, &mut d, z, step, 1),
                    _ => span_z32::<u16, u8, { cmp::GREATER_EQUAL }>(&mut c, &mut d, z, step, 1),
                };
                prop_assert_eq!((got, &d, &c), (want, &d_ref, &c_ref));
            }
        }

        /// `DepthF32` is `z / 2^48` truncated to an `f32` (against the
        /// exact `f64` quotient, `z < 2^53`), orders as its bits, and
        /// reads back through `Z32`.
        #[test]
        fn f32_word_is_the_truncated_quotient(z in prop_oneof![0u64..1 << 48, 0u64..1 << 24, 0u64..1 << 8], y in 0u64..1 << 48) {
            let exact = z as f64 / (1u64 << 48) as f64;
            let mut want = exact as f32;
            if want as f64 > exact {
                want = f32::from_bits(want.to_bits() - 1);
            }
            let d = DepthF32::of_fixed(z);
            prop_assert_eq!(d.get().to_bits(), want.to_bits());
            prop_assert_eq!(DepthF32::from_fixed(z as i64), d);
            prop_assert_eq!(d.key(), d.get().to_bits());
            prop_assert_eq!(d <= DepthF32::of_fixed(y), z <= y || d == DepthF32::of_fixed(y));
            prop_assert!(d <= DepthF32::FAR);
            let z32 = (z >> 16) as u32;
            let w = DepthF32::from_z32(z32);
            prop_assert!(w.to_z32() <= z32);
            prop_assert_eq!(DepthF32::from_z32(w.to_z32()), w);
            prop_assert_eq!(<[DepthF32] as DepthBuffer>::key_of(z as i64), d.key());
        }

        /// The same for `u16` buffers, whose spans step `Z32.0`: starts
        /// around `[0, 2^32)` and its ends.
        #[test]
        fn unclamped_span_equals_clamped_z32(
            z0 in prop_oneof![0i64..1 << 32, -(1i64 << 12)..1 << 12, (1i64 << 32) - (1 << 12)..(1i64 << 32) + (1 << 12), any::<i64>()],
            dz in prop_oneof![-(1i64 << 18)..1 << 18, -(1i64 << 26)..1 << 26, -4i64..4, any::<i64>()],
            len in 1usize..300,
            seed in any::<u64>(),
            k in 0u8..4,
        ) {
            unclamped_matches::<u16>(z0, dz, len, seed, k);
        }
    }

    /// An array buffer reads its span depths as the slice does (the same
    /// `Z32.F`): a forwarding impl with another `FRAC` would write other
    /// depths.
    #[test]
    fn array_and_slice_spans_agree() {
        fn check<W: DepthWord>() {
            let (z0, dz) = (3i64 << (W::FRAC + 28), -(5i64 << (W::FRAC + 20)));
            let mut a = [W::FAR; 64];
            let mut b = [W::FAR; 64];
            let (mut ca, mut cb) = ([0u8; 64], [0u8; 64]);
            let na = a.flat_span(&mut ca, 3, 50, z0, dz, DepthFunc::Less, true, 1);
            let nb = b[..].flat_span(&mut cb, 3, 50, z0, dz, DepthFunc::Less, true, 1);
            assert_eq!((na, a, ca), (nb, b, cb));
            assert_eq!(na, 50);
            assert_eq!(<[W; 64] as DepthBuffer>::FRAC, <[W] as DepthBuffer>::FRAC);
            assert_eq!(a[3].to_z32(), W::from_z32(3 << 28).to_z32());
        }
        check::<u16>();
        check::<u32>();
        check::<DepthF32>();
    }

    #[test]
    fn f32_word_ends_and_clamps() {
        assert_eq!(DepthF32::from_fixed(-5), DepthF32::NEAR);
        assert_eq!(DepthF32::NEAR.get(), 0.0);
        assert_eq!(DepthF32::from_fixed(1 << 48), DepthF32::FAR);
        assert_eq!(DepthF32::from_fixed(i64::MAX), DepthF32::FAR);
        assert_eq!(DepthF32::from_z32(u32::MAX), DepthF32::FAR);
        assert_eq!(DepthF32::FAR.get(), 1.0 - f32::EPSILON / 2.0);
        assert_eq!(DepthF32::from_z32(1 << 31).get(), 0.5);
        assert_eq!(DepthF32::from_z32(1).get(), 1.0 / 4_294_967_296.0);
        assert_eq!(DepthF32::from_fixed(1).get(), 1.0 / 281_474_976_710_656.0);
        assert_eq!(DepthF32::new(0.25).get(), 0.25);
        assert_eq!(DepthF32::new(2.0), DepthF32::FAR);
        assert_eq!(DepthF32::new(f32::NAN), DepthF32::NEAR);
        assert_eq!(DepthF32::new(-1.0), DepthF32::NEAR);
        assert_eq!(f32::from(DepthF32::new(0.75)), 0.75);
        // Keyed by bits: a test through the slice compares floats.
        let mut d = [DepthF32::FAR; 2];
        let k = <[DepthF32] as DepthBuffer>::key_of(3 << 44);
        assert!(d[..].test_and_set(0, k, DepthFunc::Less, true));
        assert_eq!(d[0].get(), 3.0 / 16.0);
        assert!(!d[..].test_and_set(0, k, DepthFunc::Less, true));
        assert!(d[..].test_and_set(0, k, DepthFunc::LessEqual, true));
    }

    #[test]
    fn in_range_edges() {
        for frac in [0, 16] {
            let top = 1i64 << (32 + frac);
            let r = |z0, dz, len| in_range_throughout(z0, dz, len, frac);
            assert!(r(0, 0, 1));
            assert!(r(top - 1, 0, 1));
            assert!(!r(top, 0, 1));
            assert!(!r(-1, 0, 1));
            assert!(r(top - 10, -1, 1 << 16));
            assert!(!r(5, -1, 7));
            assert!(!r(0, 1, (1 << 16) + 1));
            assert!(!r(0, 1 << 40, 2));
            assert!(!r(0, 0, 0));
        }
    }

    #[test]
    fn funcs() {
        assert!(DepthFunc::Less.test(1, 2));
        assert!(!DepthFunc::Less.test(2, 2));
        assert!(DepthFunc::LessEqual.test(2, 2));
        assert!(DepthFunc::Always.test(9, 2));
        assert!(!DepthFunc::Never.test(0, 2));
        assert!(DepthFunc::Greater.test(3, 2));
        assert!(DepthFunc::GreaterEqual.test(2, 2));
        assert!(DepthFunc::Equal.test(2, 2));
        assert!(DepthFunc::NotEqual.test(1, 2));
    }

    #[test]
    fn u16_uses_top_bits_and_out_of_range_fails() {
        let mut d = [u16::MAX; 2];
        assert!(d[..].test_and_set(0, 0x1234_5678, DepthFunc::Less, true));
        assert_eq!(d[0], 0x1234);
        assert!(!d[..].test_and_set(5, 0, DepthFunc::Always, true));
    }
}
