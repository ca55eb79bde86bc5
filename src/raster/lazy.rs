//! Deferred clears ([`crate::LazyClear`]) in the rasterizer: the hull a
//! strip keeps per row, the flat `Less` spans that extend it span by span
//! and may skip the depth reads, and the box extension every other
//! triangle takes first (see the design note of [`super`]). Built only
//! with the `lazy-clear` feature, so other renders link none of it.

use super::{
    edges_at, DepthBuffer, DepthFunc, Edge, EdgeInt, PixelFormat, Real, RowSpans, SetupTriangle,
    Shader, Strip, HULL_EMPTY, SMALL_WIDTH,
};

/// The state of a deferred clear ([`crate::LazyClear`]) while a render
/// draws: per row of the window, the columns `lo | hi << 16` (window
/// columns, `lo > hi` for none) that hold the clear or a draw.
pub(crate) struct Lazy<'b, C> {
    pub hull: &'b mut [u32],
    pub color: C,
    pub z32: u32,
}

/// Where a deferred clear is on (the caller has checked): draws a triangle of the flat `Less`
/// path (`Some(pixels written)`), or extends the hull over the box of any
/// other triangle on each of its rows `row_first..=row_last`, clearing
/// what that adds, and leaves the drawing to the usual paths (`None`).
#[inline(never)]
pub(super) fn enter<
    const S: u32,
    const N: usize,
    C: PixelFormat,
    D: DepthBuffer + ?Sized,
    R: Real,
    T: EdgeInt,
>(
    t: &SetupTriangle<N>,
    (row_first, row_last): (u32, u32),
    strip: &mut Strip<'_, C, D>,
    flat: C,
) -> Option<u32> {
    let smooth = C::SHADED && t.smooth;
    let crosses = (t.min_x as u32) < strip.x0 || (t.max_x as u32) >= strip.x1;
    // The `u16` and `u32` `Less` flat spans keep the hull themselves;
    // every other triangle has it extended over its box first, so that
    // it reads only the clear or earlier draws.
    if !smooth
        && !crosses
        && t.max_x - t.min_x >= SMALL_WIDTH
        && D::ENABLED
        && strip.depth_write
        && strip.depth_func == DepthFunc::Less
    {
        return Some(flat_rows_lazy::<S, N, C, D, R, T>(
            t,
            (row_first, row_last),
            strip,
            flat,
        ));
    }
    let a = (t.min_x as u32).max(strip.x0) - strip.x0;
    let b = (t.max_x as u32).min(strip.x1 - 1) - strip.x0;
    for row in row_first..=row_last {
        lazy_extend(strip, (row - strip.y0) as usize, a, b);
    }
    None
}

/// Clears columns `a..=b` of row `r` of the strip's buffers (window
/// columns; nothing where `a > b`).
#[inline]
fn clear_run<C: PixelFormat, D: DepthBuffer + ?Sized>(
    strip: &mut Strip<'_, C, D>,
    r: usize,
    a: u32,
    b: u32,
) {
    let Some(lazy) = &strip.lazy else {
        return;
    };
    if a > b {
        return;
    }
    let start = r * strip.width + a as usize;
    let len = (b - a) as usize + 1;
    let (color, z32) = (lazy.color, lazy.z32);
    if let Some(c) = strip.color.get_mut(start..start.saturating_add(len)) {
        c.fill(color);
    }
    strip.depth.fill_z32(start, len, z32);
}

/// Row `r`'s hull (`HULL_EMPTY` past the hull, which
/// `LazyClear::new` sized to the rectangle's rows).
#[inline]
fn hull_of<C, D: ?Sized>(strip: &Strip<'_, C, D>, r: usize) -> u32 {
    strip
        .lazy
        .as_ref()
        .and_then(|l| l.hull.get(r).copied())
        .unwrap_or(HULL_EMPTY)
}

/// Sets row `r`'s hull, `h`, to its union with window columns `a..=b`.
#[inline]
fn join_hull<C, D: ?Sized>(strip: &mut Strip<'_, C, D>, r: usize, h: u32, a: u32, b: u32) {
    let (lo, hi) = (h & 0xFFFF, h >> 16);
    let (lo, hi) = if lo > hi {
        (a, b)
    } else {
        (lo.min(a), hi.max(b))
    };
    if let Some(slot) = strip.lazy.as_mut().and_then(|l| l.hull.get_mut(r)) {
        *slot = lo | hi << 16;
    }
}

/// Extends the hull of row `r` over window columns `a..=b`, clearing the
/// columns that adds.
#[inline]
fn lazy_extend<C: PixelFormat, D: DepthBuffer + ?Sized>(
    strip: &mut Strip<'_, C, D>,
    r: usize,
    a: u32,
    b: u32,
) {
    let h = hull_of(strip, r);
    let (lo, hi) = (h & 0xFFFF, h >> 16);
    if lo > hi {
        clear_run(strip, r, a, b);
    } else {
        // What the hull gains: on the left up to it, on the right from it.
        if a < lo {
            clear_run(strip, r, a, lo - 1);
        }
        if b > hi {
            clear_run(strip, r, hi + 1, b);
        }
    }
    join_hull(strip, r, h, a, b);
}

/// The flat span rows of a triangle under a deferred clear
/// ([`Strip::lazy`]) with a depth buffer, writes and `Less`: [`flat_rows`]'
/// generic loop (the same depths, from the same `Z32.F` starts), each span
/// through [`lazy_span`] first.
fn flat_rows_lazy<
    const S: u32,
    const N: usize,
    C: PixelFormat,
    D: DepthBuffer + ?Sized,
    R: Real,
    T: EdgeInt,
>(
    t: &SetupTriangle<N>,
    (row_first, row_last): (u32, u32),
    strip: &mut Strip<'_, C, D>,
    px: C,
) -> u32 {
    let mut edges: [Edge<T>; 3] = edges_at::<S, N, T>(t, row_first);
    let shader = &Shader::<R, N>::new::<C, D, T>(t, &edges);
    let max_n = (t.max_x - t.min_x) as usize;
    let r0 = (row_first - strip.y0) as usize;
    let col0 = t.min_x as u32 - strip.x0;
    let mut base = r0 * strip.width + col0 as usize;
    let mut written = 0u32;
    let mut spans = RowSpans::new(&edges, max_n);
    for r in r0..=r0 + (row_last - row_first) as usize {
        if let Some((lo, hi)) = spans.span(&edges) {
            let z0 = shader.z_at::<D, T>(edges[1].at(lo), edges[2].at(lo));
            let z0 = z0.to_fixed(D::FRAC);
            let (lo, hi) = (lo.widen() as usize, hi.widen() as usize);
            let (start, len) = (base + lo, hi - lo + 1);
            let (a, b) = (col0 + lo as u32, col0 + hi as u32);
            written += match lazy_span(strip, r, a, b, (start, len, z0, shader.dz_fixed), px) {
                Some(n) => n,
                None => strip.depth.flat_span(
                    strip.color,
                    start,
                    len,
                    z0,
                    shader.dz_fixed,
                    DepthFunc::Less,
                    true,
                    px,
                ),
            };
        }
        spans.next();
        for edge in edges.iter_mut() {
            edge.row += edge.step_y;
        }
        base += strip.width;
    }
    written
}

/// One span of a deferred clear's flat `Less` path: row `r`, window
/// columns `a..=b`, pixels `start..start + len` stepping from `z0` by
/// `dz`. A span beyond the row's hull whose every depth is nearer than
/// the clear is written without reading the buffers (the gap between it
/// and the hull cleared): `Some(pixels written)`. Otherwise the hull is
/// extended over it (what that adds cleared) and `None` leaves the span
/// to the depth-tested loop.
#[inline]
fn lazy_span<C: PixelFormat, D: DepthBuffer + ?Sized>(
    strip: &mut Strip<'_, C, D>,
    r: usize,
    a: u32,
    b: u32,
    (start, len, z0, dz): (usize, usize, i64, i64),
    px: C,
) -> Option<u32> {
    let h = hull_of(strip, r);
    let (lo, hi) = (h & 0xFFFF, h >> 16);
    if lo > hi || b < lo || a > hi {
        let z32 = strip.lazy.as_ref().map_or(0, |l| l.z32);
        if let Some(n) = strip
            .depth
            .untested_span(strip.color, start, len, z0, dz, z32, px)
        {
            if lo <= hi {
                if b < lo {
                    clear_run(strip, r, b + 1, lo - 1);
                } else {
                    clear_run(strip, r, hi + 1, a - 1);
                }
            }
            join_hull(strip, r, h, a, b);
            return Some(n);
        }
    }
    lazy_extend(strip, r, a, b);
    None
}
