//! Triangle setup: snapped vertices to a compact, exact triangle record.
//!
//! Design note: setup runs once per (clipped) triangle per frame and decides
//! everything that does not depend on the rows being rendered:
//!
//! 1. snap the three vertices ([`crate::fixed::snap`]); a vertex that
//!    cannot be snapped (the homogeneous origin) makes the triangle
//!    degenerate;
//! 2. twice the signed area, exactly, in `i64` (`|area| < 2^59`): zero area
//!    is rejected, the sign decides back-face culling;
//! 3. the winding is normalised so the area is positive (vertices 1 and 2
//!    swapped with their attributes), which makes every edge function
//!    positive inside;
//! 4. the pixel bounding box of the snapped vertices: pixels whose centres
//!    lie in it. An empty box ("no sample") is rejected; a box that misses
//!    the frame is culled.
//!
//! The record keeps vertices, not edge coefficients: the rasterizer derives
//! those in a handful of integer operations per strip, which keeps the
//! record small for RAM-starved targets.

use crate::clip::ClipVertex;
use crate::config::{CullMode, FrontFace};
use crate::fixed::{snap, SnappedVertex};
use embedded_graphics_core::pixelcolor::Rgb888;

/// A triangle after setup, ready to rasterize into any rows of its frame,
/// with `N` varyings per vertex (3 by default: a colour).
///
/// Frames store these in caller-provided storage (see
/// [`Frame::new`](crate::Frame::new)); [`SetupTriangle::EMPTY`] fills it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SetupTriangle<const N: usize = 3> {
    /// Vertex x in `Sub<S>` units, wound so that `area > 0`.
    pub(crate) x: [i32; 3],
    /// Vertex y in `Sub<S>` units (rows from the top).
    pub(crate) y: [i32; 3],
    /// Vertex depth in `Z32`.
    pub(crate) z: [u32; 3],
    /// Twice the signed area in `Sub<S>^2` units; always `> 0`.
    pub(crate) area: i64,
    /// Inclusive pixel bounding box, clamped to the frame.
    pub(crate) min_x: u16,
    pub(crate) max_x: u16,
    pub(crate) min_y: u16,
    pub(crate) max_y: u16,
    /// For perspective-correct varyings: `1 / w_k`, rescaled if extreme.
    pub(crate) inv_w: [f32; 3],
    /// Where `smooth`: varyings times `inv_w`, per vertex. Otherwise
    /// (all three vertices' varyings equal) entry 0 holds the varyings
    /// themselves.
    pub(crate) var_w: [[f32; N]; 3],
    /// Where not `smooth`: the first three varyings rounded to a colour,
    /// as [`VertexColor`](crate::VertexColor) shades them (once per frame,
    /// not once per strip; black for `N < 3`).
    pub(crate) flat: Rgb888,
    /// Whether the varyings vary over the triangle.
    pub(crate) smooth: bool,
    /// Whether its edge values fit `i32` (`raster::fits_i32`, once per
    /// frame, not once per strip; a byte the struct's padding had).
    pub(crate) edge32: bool,
    /// What its flat rows need to know of it (`raster::flat_facts`: its
    /// edges' sides and whether its depths never clamp), found once a
    /// frame when a [`Frame`](crate::Frame) stores it, not once a strip;
    /// 0 where not found (immediate mode sets a triangle up for the one
    /// strip it draws it in, so `flat_rows` finds them itself). Another
    /// byte of the padding.
    pub(crate) flat_facts: u8,
    /// The caller's triangle index.
    pub(crate) id: u32,
}

impl<const N: usize> SetupTriangle<N> {
    /// A placeholder to fill storage with.
    pub const EMPTY: SetupTriangle<N> = SetupTriangle {
        x: [0; 3],
        y: [0; 3],
        z: [0; 3],
        area: 0,
        min_x: 0,
        max_x: 0,
        min_y: 0,
        max_y: 0,
        inv_w: [0.0; 3],
        var_w: [[0.0; N]; 3],
        flat: Rgb888::new(0, 0, 0),
        smooth: false,
        edge32: false,
        flat_facts: 0,
        id: 0,
    };

    /// The caller's index of the triangle this one came from.
    pub fn id(&self) -> u32 {
        self.id
    }

    /// The first and last pixel row this triangle may cover (inclusive).
    pub fn rows(&self) -> (u16, u16) {
        (self.min_y, self.max_y)
    }

    /// The snapped vertices `(x, y)` in subpixel units, wound so the signed
    /// area is positive.
    pub fn vertices(&self) -> [(i32, i32); 3] {
        [
            (self.x[0], self.y[0]),
            (self.x[1], self.y[1]),
            (self.x[2], self.y[2]),
        ]
    }

    /// The snapped window depths in `Z32`.
    pub fn depths(&self) -> [u32; 3] {
        self.z
    }
}

impl<const N: usize> Default for SetupTriangle<N> {
    fn default() -> Self {
        SetupTriangle::EMPTY
    }
}

/// Why setup produced no triangle.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Rejected {
    /// Culled as a back (or front) face.
    Backface,
    /// Zero area, or no pixel centre inside the bounding box.
    Degenerate,
    /// The bounding box misses the frame.
    Offscreen,
}

/// `1 / w` of three vertices with `w > 0`, for perspective-correct
/// attributes (only their ratios matter). In `f32` as a rule; where that
/// overflows (`w` below about `3e-39`, which clipping can produce) the
/// weights are formed in `f64` relative to the smallest `w`, so they stay
/// finite.
#[inline]
pub(crate) fn inv_w3(w: [f32; 3]) -> [f32; 3] {
    let iw = w.map(|w| 1.0 / w);
    if iw.iter().all(|v| v.is_finite()) {
        return iw;
    }
    let m = (w[0] as f64).min(w[1] as f64).min(w[2] as f64);
    w.map(|w| (m / w as f64) as f32)
}

/// Face culling: `Err(Backface)` where a triangle that is counter-clockwise
/// in NDC (`ccw`) or not is culled by `cull` with `front` faces. Shared by
/// both rasterization modes, which differ only in how they find `ccw`.
#[inline(always)]
pub(crate) fn cull_winding(ccw: bool, cull: CullMode, front: FrontFace) -> Result<(), Rejected> {
    let is_front = match front {
        FrontFace::Ccw => ccw,
        FrontFace::Cw => !ccw,
    };
    match cull {
        CullMode::Back if !is_front => Err(Rejected::Backface),
        CullMode::Front if is_front => Err(Rejected::Backface),
        _ => Ok(()),
    }
}

/// Twice the signed area of a triangle in window space (y down), exactly.
#[inline]
pub(crate) fn area2(x: [i32; 3], y: [i32; 3]) -> i64 {
    let (x0, y0) = (x[0] as i64, y[0] as i64);
    (x[1] as i64 - x0) * (y[2] as i64 - y0) - (x[2] as i64 - x0) * (y[1] as i64 - y0)
}

/// Sets up one clipped triangle for a `width x height` frame at `S`
/// subpixel bits.
pub(crate) fn setup<const S: u32, const N: usize>(
    v: &[ClipVertex<N>; 3],
    width: u32,
    height: u32,
    cull: CullMode,
    front: FrontFace,
    id: u32,
) -> Result<SetupTriangle<N>, Rejected> {
    let mut s = [SnappedVertex::default(); 3];
    for k in 0..3 {
        let p = v[k].pos;
        // Unclipped, finite and inside the guard band, a vertex fails to
        // snap only if it is the homogeneous origin (w = 0 forces x = y =
        // z = 0 there): no point at all, so the triangle is degenerate.
        s[k] = snap::<S>(p.x, p.y, p.z, p.w, width, height).ok_or(Rejected::Degenerate)?;
    }
    let g = setup_geometry::<S>(&s, width, height, cull, front)?;
    Ok(g.finish(
        inv_w3([v[0].pos.w, v[1].pos.w, v[2].pos.w]),
        [v[0].varyings, v[1].varyings, v[2].varyings],
        id,
    ))
}

/// The part of setup that needs only the snapped vertices: area, culling,
/// winding and bounding box. Cheap, so culled triangles cost little.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Geometry {
    x: [i32; 3],
    y: [i32; 3],
    z: [u32; 3],
    area: i64,
    swapped: bool,
    bbox: [u16; 4],
    /// `raster::fits_i32` of the vertices, from the box's extremes.
    edge32: bool,
}

/// Area, culling, winding and bounding box of a snapped triangle.
#[cfg_attr(target_pointer_width = "64", inline(always))]
#[cfg_attr(not(target_pointer_width = "64"), inline)]
pub(crate) fn setup_geometry<const S: u32>(
    s: &[SnappedVertex; 3],
    width: u32,
    height: u32,
    cull: CullMode,
    front: FrontFace,
) -> Result<Geometry, Rejected> {
    let sx = [s[0].x, s[1].x, s[2].x];
    let sy = [s[0].y, s[1].y, s[2].y];
    let area = area2(sx, sy);
    if area == 0 {
        return Err(Rejected::Degenerate);
    }
    // Window y points down, so a counter-clockwise triangle in NDC has a
    // negative window-space area.
    cull_winding(area < 0, cull, front)?;
    let swapped = area < 0;
    let (x, y, z, area) = if swapped {
        (
            [sx[0], sx[2], sx[1]],
            [sy[0], sy[2], sy[1]],
            [s[0].z, s[2].z, s[1].z],
            -area,
        )
    } else {
        (sx, sy, [s[0].z, s[1].z, s[2].z], area)
    };

    // Pixels whose centre (i << S) + half lies in [min, max].
    let half = 1i64 << (S - 1);
    let one = 1i64 << S;
    let min_x = x[0].min(x[1]).min(x[2]) as i64;
    let max_x = x[0].max(x[1]).max(x[2]) as i64;
    let min_y = y[0].min(y[1]).min(y[2]) as i64;
    let max_y = y[0].max(y[1]).max(y[2]) as i64;
    let px0 = (min_x - half + one - 1) >> S;
    let px1 = (max_x - half) >> S;
    let py0 = (min_y - half + one - 1) >> S;
    let py1 = (max_y - half) >> S;
    if px0 > px1 || py0 > py1 {
        return Err(Rejected::Degenerate);
    }
    let (w, h) = (width as i64, height as i64);
    if px1 < 0 || py1 < 0 || px0 >= w || py0 >= h {
        return Err(Rejected::Offscreen);
    }
    // On 64-bit hosts `max` then `min`, not `Ord::clamp`: `hi` is at
    // least 0 here, and `clamp`'s check of its bounds kept it out of line
    // there (the sphere's triangle stage 4 % slower). The same on 32-bit
    // cores saves the M4F's four cubes 3,320 instructions but moves the
    // firmware's recorded split estimates past their 1 % check: left for
    // a re-recording.
    let clamp = |v: i64, hi: i64| {
        (if cfg!(target_pointer_width = "64") {
            v.max(0).min(hi)
        } else {
            v.clamp(0, hi)
        }) as u16
    };
    let edge32 = crate::raster::fits_i32(max_x - min_x, max_y - min_y);
    Ok(Geometry {
        x,
        y,
        z,
        area,
        swapped,
        bbox: [
            clamp(px0, w - 1),
            clamp(px1, w - 1),
            clamp(py0, h - 1),
            clamp(py1, h - 1),
        ],
        edge32,
    })
}

impl Geometry {
    /// Completes setup with the vertices' `1 / w` (all positive) and
    /// varyings, in input order (the winding swap is applied here).
    #[cfg_attr(target_pointer_width = "64", inline(always))]
    #[cfg_attr(not(target_pointer_width = "64"), inline)]
    pub(crate) fn finish<const N: usize>(
        self,
        inv_w: [f32; 3],
        var: [[f32; N]; 3],
        id: u32,
    ) -> SetupTriangle<N> {
        let (iw, c) = if self.swapped {
            ([inv_w[0], inv_w[2], inv_w[1]], [var[0], var[2], var[1]])
        } else {
            (inv_w, var)
        };
        // Flat when all three vertices' varyings are equal.
        let smooth = c[0] != c[1] || c[0] != c[2];
        let mut inv_w = [1.0f32; 3];
        let mut var_w = [[0.0f32; N]; 3];
        let mut flat = Rgb888::new(0, 0, 0);
        if !smooth {
            var_w[0] = c[0];
            if N >= 3 {
                let to_u8 = |f: f32| (f + 0.5) as u8;
                flat = Rgb888::new(to_u8(c[0][0]), to_u8(c[0][1]), to_u8(c[0][2]));
            }
        } else {
            // Perspective weights `E_k / w_k` only matter in ratio. Within
            // 2^-32..2^32 they are used as they are (products with edge
            // values stay below 2^91, far from f32 overflow); otherwise
            // they are rescaled so the largest is 1.
            let (lo, hi) = (1.0 / 4_294_967_296.0f32, 4_294_967_296.0f32);
            if iw.iter().all(|&v| v >= lo && v <= hi) {
                inv_w = iw;
            } else {
                let m = iw[0].max(iw[1]).max(iw[2]);
                inv_w = [iw[0] / m, iw[1] / m, iw[2] / m];
            }
            for k in 0..3 {
                for ch in 0..N {
                    var_w[k][ch] = c[k][ch] * inv_w[k];
                }
            }
        }
        SetupTriangle {
            x: self.x,
            y: self.y,
            z: self.z,
            area: self.area,
            min_x: self.bbox[0],
            max_x: self.bbox[1],
            min_y: self.bbox[2],
            max_y: self.bbox[3],
            inv_w,
            var_w,
            flat,
            smooth,
            edge32: self.edge32,
            flat_facts: 0,
            id,
        }
    }
}

/// Twice the signed area of `(a, b, c)` in window space, exactly.
#[inline]
fn orient(a: SnappedVertex, b: SnappedVertex, c: SnappedVertex) -> i64 {
    area2([a.x, b.x, c.x], [a.y, b.y, c.y])
}

/// Splits a clipped polygon into triangles (index triples) that all wind
/// the same way.
///
/// The polygon was convex in clip space, so a fan from vertex 0 almost
/// always works. Snapping can bend three nearly collinear clip vertices
/// into a slightly non-convex (even self-overlapping) polygon; a fan piece
/// across the reflex vertex then winds the other way and would be drawn
/// over its neighbours (or culled, leaving the overlap). Then, with exact
/// integer orientation tests, a fan from another apex whose pieces of the
/// polygon's winding are contiguous is used without the folded slivers at
/// its ends, or failing that the polygon is ear-clipped. Both keep the
/// boundary edges (shared with neighbouring triangles) unchanged. Vertices
/// that could not be snapped (`None`) keep the fan, whose pieces through
/// them are then rejected.
pub(crate) fn triangulate(v: &[Option<SnappedVertex>]) -> heapless::Vec<[u8; 3], 7> {
    let mut out = heapless::Vec::new();
    let n = v.len().min(9);
    let fan = |out: &mut heapless::Vec<[u8; 3], 7>| {
        for i in 1..n.saturating_sub(1) {
            let _ = out.push([0, i as u8, i as u8 + 1]);
        }
    };
    let mut s = [SnappedVertex::default(); 9];
    for (k, slot) in s.iter_mut().enumerate().take(n) {
        match v[k] {
            Some(p) => *slot = p,
            None => {
                fan(&mut out);
                return out;
            }
        }
    }
    // Each fan term is below 2^59 in magnitude; seven of them fit in i64.
    let areas = |i: usize| orient(s[0], s[i], s[i + 1]);
    let total: i64 = (1..n.saturating_sub(1)).map(areas).sum();
    let sign = total.signum();
    if (1..n.saturating_sub(1)).all(|i| areas(i) * sign >= 0) || sign == 0 {
        fan(&mut out);
        return out;
    }
    // A fan from some apex whose pieces of the polygon's winding form one
    // contiguous run: those pieces sweep monotonically round the apex, so
    // they never overlap. The pieces left out (winding the other way, at
    // the ends of the run) are slivers that snapping folded over; drawing
    // them would hit pixels twice.
    for k in 0..n {
        let piece = |i: usize| [k, (k + i) % n, (k + i + 1) % n];
        let turn = |i: usize| {
            let [a, b, c] = piece(i);
            orient(s[a], s[b], s[c]) * sign
        };
        let pos: heapless::Vec<usize, 7> = (1..n - 1).filter(|&i| turn(i) > 0).collect();
        let (Some(&first), Some(&last)) = (pos.first(), pos.last()) else {
            continue;
        };
        if (first..=last).all(|i| turn(i) >= 0) {
            for &i in &pos {
                let [a, b, c] = piece(i);
                let _ = out.push([a as u8, b as u8, c as u8]);
            }
            return out;
        }
    }
    // Otherwise ear clipping on the ring of indices.
    let mut ring: heapless::Vec<u8, 9> = (0..n as u8).collect();
    while ring.len() > 3 {
        let m = ring.len();
        let mut cut = None;
        for i in 0..m {
            let (p, c, q) = (ring[(i + m - 1) % m], ring[i], ring[(i + 1) % m]);
            let (a, b, d) = (s[p as usize], s[c as usize], s[q as usize]);
            let turn = orient(a, b, d) * sign;
            if turn == 0 {
                // Collinear: dropping the vertex changes no coverage.
                cut = Some((i, None));
                break;
            }
            if turn < 0 {
                continue;
            }
            // An ear if no other vertex lies inside or on it.
            let blocked = ring.iter().any(|&r| {
                let e = s[r as usize];
                r != p
                    && r != c
                    && r != q
                    && e != a
                    && e != b
                    && e != d
                    && orient(a, b, e) * sign >= 0
                    && orient(b, d, e) * sign >= 0
                    && orient(d, a, e) * sign >= 0
            });
            if !blocked {
                cut = Some((i, Some([p, c, q])));
                break;
            }
        }
        match cut {
            Some((i, tri)) => {
                if let Some(t) = tri {
                    let _ = out.push(t);
                }
                ring.remove(i);
            }
            None => break,
        }
    }
    if ring.len() >= 3 {
        for i in 1..ring.len() - 1 {
            let _ = out.push([ring[0], ring[i], ring[i + 1]]);
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn v(x: i32, y: i32) -> Option<SnappedVertex> {
        Some(SnappedVertex { x, y, z: 0 })
    }

    #[test]
    fn convex_polygon_is_a_fan() {
        let p = [v(0, 0), v(10, 0), v(10, 10), v(0, 10)];
        assert_eq!(triangulate(&p).as_slice(), &[[0, 1, 2], [0, 2, 3]]);
    }

    #[test]
    fn reflex_vertex_is_ear_clipped_with_one_winding() {
        // Vertex 2 is pushed slightly inwards: the fan piece (0, 2, 3)
        // would wind the other way.
        let p = [v(0, 0), v(100, 0), v(99, 50), v(100, 100), v(0, 100)];
        let tris = triangulate(&p);
        let s: Vec<SnappedVertex> = p.iter().map(|x| x.unwrap()).collect();
        let mut total = 0;
        for t in &tris {
            let a = orient(s[t[0] as usize], s[t[1] as usize], s[t[2] as usize]);
            assert!(a > 0, "{t:?} winds the wrong way");
            total += a;
        }
        // The pieces tile the polygon: their areas add up to its area.
        let poly_area: i64 = (1..4).map(|i| orient(s[0], s[i], s[i + 1])).sum();
        assert_eq!(total, poly_area);
    }

    extern crate std;
    use std::vec::Vec;
}
