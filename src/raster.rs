//! Strip traversal: exact spans, depth, colour.
//!
//! Design note: a set-up triangle is drawn into rows `y0..y1` of its frame
//! (a "strip"); the caller's buffers hold only those rows. Per triangle and
//! strip the three edge functions are derived from the snapped vertices:
//!
//! `E_k(p) = (xb - xa) * (py - ya) - (yb - ya) * (px - xa)` for the edge
//! `a -> b` opposite vertex `k`, in `i64` (`|E| < 2^59`, see
//! [`crate::fixed`]). A pixel is covered when its centre has
//! `E_k + bias_k >= 0` for all `k`, where `bias_k` is 0 for a top or left
//! edge and -1 otherwise: the top-left fill rule, exactly, with no float
//! anywhere.
//!
//! Per row, each edge is linear in the column, so the covered columns are
//! found by one exact floor division per edge: a span `[lo, hi]`. The inner
//! loop then visits only covered pixels; it never divides and never tests
//! coverage.
//!
//! Depth is the plane through the three `Z32` vertex depths. At the start of
//! each span it is evaluated exactly (`i128`, floor) in `Z32.16`; along the
//! span it steps by the rounded gradient in wrapping `i64`. With at most
//! `2^14` steps the accumulated error is below `2^13` units of `2^-16`, so
//! the written `Z32` is within 1 LSB of the exact plane's floor. Where the
//! gradient is huge (slivers) wrapping arithmetic keeps covered pixels exact
//! modulo `2^64`, and their true values are in range.
//!
//! Colour, when it varies, is perspective-correct: the barycentric weights
//! are the exact edge values converted to `f32` at each pixel, so the result
//! at a pixel does not depend on where traversal started.

use crate::color::Pixel;
use crate::depth::{DepthBuffer, DepthFunc};
use crate::setup::SetupTriangle;
use embedded_graphics_core::pixelcolor::Rgb888;

/// One edge function, set up for stepping in whole pixels.
#[derive(Clone, Copy)]
struct Edge {
    /// `E + bias` at the centre of the first column of the current row.
    row: i64,
    /// Change per column (`-(yb - ya) << S`).
    step_x: i64,
    /// Change per row (`(xb - xa) << S`).
    step_y: i64,
    /// 0 for a top or left edge, -1 otherwise.
    bias: i64,
}

impl Edge {
    fn new<const S: u32>(xa: i32, ya: i32, xb: i32, yb: i32, px: i64, py: i64) -> Edge {
        let dx = xb as i64 - xa as i64;
        let dy = yb as i64 - ya as i64;
        // Window y points down; with positive area the interior is on the
        // side where E > 0. Top edge: horizontal with the interior below
        // (dx > 0); left edge: going up (dy < 0).
        let top_left = dy < 0 || (dy == 0 && dx > 0);
        let bias = if top_left { 0 } else { -1 };
        let e = dx * (py - ya as i64) - dy * (px - xa as i64);
        Edge {
            row: e + bias,
            step_x: -dy << S,
            step_y: dx << S,
            bias,
        }
    }

    /// Restricts the column range `[lo, hi]` (offsets from the first column)
    /// to where this edge covers. Returns `false` if nothing remains.
    #[inline]
    fn clip_span(&self, lo: &mut i64, hi: &mut i64) -> bool {
        let e = self.row;
        let a = self.step_x;
        if a > 0 {
            // e + a n >= 0  <=>  n >= ceil(-e / a)
            if e < 0 {
                let n = (-e + a - 1) / a;
                if n > *lo {
                    *lo = n;
                }
            }
        } else if a < 0 {
            // e + a n >= 0  <=>  n <= floor(e / -a)
            if e < 0 {
                return false;
            }
            let n = e / -a;
            if n < *hi {
                *hi = n;
            }
        } else if e < 0 {
            return false;
        }
        *lo <= *hi
    }
}

/// Per-draw state shared by every triangle of one `render_rows` call.
pub(crate) struct Strip<'b, C, D: ?Sized> {
    pub width: usize,
    pub y0: u32,
    pub y1: u32,
    pub color: &'b mut [C],
    pub depth: &'b mut D,
    pub depth_func: DepthFunc,
    pub depth_write: bool,
}

/// Draws one triangle into the strip; returns the number of pixels written.
pub(crate) fn draw<const S: u32, C: Pixel, D: DepthBuffer + ?Sized>(
    t: &SetupTriangle,
    strip: &mut Strip<'_, C, D>,
) -> u32 {
    let row_first = (t.min_y as u32).max(strip.y0);
    let row_last = (t.max_y as u32).min(strip.y1.saturating_sub(1));
    if row_first > row_last || strip.y1 == 0 {
        return 0;
    }
    let half = 1i64 << (S - 1);
    let px = ((t.min_x as i64) << S) + half;
    let py = ((row_first as i64) << S) + half;
    let (x, y) = (t.x, t.y);
    // Edge k is opposite vertex k: from vertex k+1 to vertex k+2.
    let mut edges = [
        Edge::new::<S>(x[1], y[1], x[2], y[2], px, py),
        Edge::new::<S>(x[2], y[2], x[0], y[0], px, py),
        Edge::new::<S>(x[0], y[0], x[1], y[1], px, py),
    ];
    let max_n = (t.max_x - t.min_x) as i64;

    // Depth plane in Z32.16, relative to vertex 0:
    // Z = Z0 + ((Z1 - Z0) E1 + (Z2 - Z0) E2) / area.
    let dz1 = t.z[1] as i128 - t.z[0] as i128;
    let dz2 = t.z[2] as i128 - t.z[0] as i128;
    let area = t.area as i128;
    let z_step: i64 = if D::ENABLED {
        let num = (dz1 * edges[1].step_x as i128 + dz2 * edges[2].step_x as i128) << 16;
        // Round to nearest; `as i64` wraps (see the design note).
        let q = if num >= 0 {
            (num + area / 2) / area
        } else {
            -((-num + area / 2) / area)
        };
        q as i64
    } else {
        0
    };

    let smooth = C::SHADED && t.smooth;
    let mut written = 0u32;
    for row in row_first..=row_last {
        let mut lo = 0i64;
        let mut hi = max_n;
        let covered = edges[0].clip_span(&mut lo, &mut hi)
            && edges[1].clip_span(&mut lo, &mut hi)
            && edges[2].clip_span(&mut lo, &mut hi);
        if covered {
            // Unbiased edge values at the span start.
            let mut e = [
                edges[0].row - edges[0].bias + edges[0].step_x * lo,
                edges[1].row - edges[1].bias + edges[1].step_x * lo,
                edges[2].row - edges[2].bias + edges[2].step_x * lo,
            ];
            let mut z: i64 = if D::ENABLED {
                let num = (dz1 * e[1] as i128 + dz2 * e[2] as i128) << 16;
                (((t.z[0] as i128) << 16) + num.div_euclid(area)) as i64
            } else {
                0
            };
            let base = (row - strip.y0) as usize * strip.width + t.min_x as usize;
            for n in lo..=hi {
                let idx = base + n as usize;
                let pass = if D::ENABLED {
                    let z32 = (z.clamp(0, (1i64 << 48) - 1) >> 16) as u32;
                    strip
                        .depth
                        .test_and_set(idx, z32, strip.depth_func, strip.depth_write)
                } else {
                    true
                };
                if pass {
                    let rgb = if smooth { shade(t, &e) } else { t.flat };
                    if let Some(px) = strip.color.get_mut(idx) {
                        *px = C::from_fragment(rgb, t.id);
                        written += 1;
                    }
                }
                if D::ENABLED {
                    z = z.wrapping_add(z_step);
                }
                if smooth {
                    e[0] += edges[0].step_x;
                    e[1] += edges[1].step_x;
                    e[2] += edges[2].step_x;
                }
            }
        }
        for edge in edges.iter_mut() {
            edge.row += edge.step_y;
        }
    }
    written
}

/// Perspective-correct colour from the exact edge values at a pixel.
#[inline]
fn shade(t: &SetupTriangle, e: &[i64; 3]) -> Rgb888 {
    let f = [e[0] as f32, e[1] as f32, e[2] as f32];
    let den = f[0] * t.inv_w[0] + f[1] * t.inv_w[1] + f[2] * t.inv_w[2];
    let inv = 1.0 / den;
    let cw = &t.color_w;
    let ch = |c: usize| {
        let v = (f[0] * cw[0][c] + f[1] * cw[1][c] + f[2] * cw[2][c]) * inv;
        (v + 0.5) as u8
    };
    Rgb888::new(ch(0), ch(1), ch(2))
}
