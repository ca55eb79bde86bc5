//! Clip-space culling and clipping, in homogeneous coordinates.
//!
//! Design note: a triangle arrives as three clip-space vertices (OpenGL
//! convention: visible where `-w <= x, y, z <= w`). Each vertex gets an
//! outcode against the six frustum planes and the four guard-band planes.
//!
//! - All three outside one frustum plane (near and far included): culled.
//! - Inside the near, far and guard-band planes: passed on untouched; the
//!   x/y frustum planes are never clipped against, the rasterizer's
//!   scissor (bounding box clamped to the frame) does that exactly.
//! - Otherwise the triangle is clipped (Sutherland-Hodgman) against only the
//!   planes it crosses, in the fixed order near, far, -x, +x, -y, +y guard.
//!   Division by `w` happens only afterwards, and every surviving vertex has
//!   `w > 0` (inside near and guard planes implies `w >= 0`; `w == 0` is
//!   rejected at snapping).
//!
//! Clip distances and intersections are computed in `f64` (a difference of
//! two finite `f32` values, or `g * w`, cannot overflow there) and each new
//! vertex is then put exactly on its plane, so even extreme `w` ratios give
//! a vertex inside the guard band.
//!
//! Watertightness: an edge shared by two triangles is clipped in the same
//! direction in both (always from the inside vertex towards the outside
//! one), so both get bit-identical new vertices. The polygon has at most
//! 3 + 6 = 9 vertices, kept in fixed-capacity storage; a triangle clipped by
//! the near plane alone yields at most two triangles.

use crate::math::Vec4;
use heapless::Vec;

/// A clip-space vertex with its `N` varyings: the values interpolated
/// (perspective-correct) over the triangle and handed to the fragment
/// shader. With the default `N = 3` and [`VertexColor`](crate::VertexColor)
/// they are red, green and blue in `0.0..=255.0`; other shaders document
/// their layout (see [`crate::shade`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ClipVertex<const N: usize = 3> {
    /// Clip-space position.
    pub pos: Vec4,
    /// The varyings.
    pub varyings: [f32; N],
}

impl<const N: usize> Default for ClipVertex<N> {
    fn default() -> Self {
        ClipVertex {
            pos: Vec4::new(0.0, 0.0, 0.0, 0.0),
            varyings: [0.0; N],
        }
    }
}

/// Outcode bits.
pub mod outcode {
    /// `x < -w`.
    pub const LEFT: u16 = 1 << 0;
    /// `x > w`.
    pub const RIGHT: u16 = 1 << 1;
    /// `y < -w`.
    pub const BOTTOM: u16 = 1 << 2;
    /// `y > w`.
    pub const TOP: u16 = 1 << 3;
    /// `z < -w`.
    pub const NEAR: u16 = 1 << 4;
    /// `z > w`.
    pub const FAR: u16 = 1 << 5;
    /// `x < -gx w`.
    pub const GUARD_LEFT: u16 = 1 << 6;
    /// `x > gx w`.
    pub const GUARD_RIGHT: u16 = 1 << 7;
    /// `y < -gy w`.
    pub const GUARD_BOTTOM: u16 = 1 << 8;
    /// `y > gy w`.
    pub const GUARD_TOP: u16 = 1 << 9;
    /// The six frustum planes.
    pub const FRUSTUM: u16 = LEFT | RIGHT | BOTTOM | TOP | NEAR | FAR;
    /// The planes that are clipped against.
    pub const CLIP: u16 = NEAR | FAR | GUARD_LEFT | GUARD_RIGHT | GUARD_BOTTOM | GUARD_TOP;
}

/// The outcode of a clip-space position. `gx`, `gy` are the guard band in
/// NDC units ([`crate::fixed::guard_band_ndc`]). Must only be called with
/// finite positions.
pub fn outcode(p: Vec4, gx: f32, gy: f32) -> u16 {
    use outcode::*;
    let mut c = 0;
    if p.x < -p.w {
        c |= LEFT;
    }
    if p.x > p.w {
        c |= RIGHT;
    }
    if p.y < -p.w {
        c |= BOTTOM;
    }
    if p.y > p.w {
        c |= TOP;
    }
    if p.z < -p.w {
        c |= NEAR;
    }
    if p.z > p.w {
        c |= FAR;
    }
    let (xg, yg) = (gx * p.w, gy * p.w);
    if p.x < -xg {
        c |= GUARD_LEFT;
    }
    if p.x > xg {
        c |= GUARD_RIGHT;
    }
    if p.y < -yg {
        c |= GUARD_BOTTOM;
    }
    if p.y > yg {
        c |= GUARD_TOP;
    }
    c
}

/// The clipped polygon: at most 9 vertices.
pub type Polygon<const N: usize = 3> = Vec<ClipVertex<N>, 9>;

/// Signed distance to the plane `bit` (inside where `>= 0`), in `f64` so
/// that neither `g * w` nor a difference of two finite `f32` values can
/// overflow.
#[inline]
fn distance(bit: u16, p: Vec4, gx: f64, gy: f64) -> f64 {
    use outcode::*;
    let (x, y, z, w) = (p.x as f64, p.y as f64, p.z as f64, p.w as f64);
    match bit {
        NEAR => z + w,
        FAR => w - z,
        GUARD_LEFT => x + gx * w,
        GUARD_RIGHT => gx * w - x,
        GUARD_BOTTOM => y + gy * w,
        _ => gy * w - y, // GUARD_TOP
    }
}

/// The point where the edge from `vi` (inside, distance `di`) to `vo`
/// (outside, `dout`) crosses plane `bit`, interpolated in `f64` and then put
/// exactly on the plane (so a `t` that rounds to 1 for extreme `w` ratios
/// still yields a point inside the guard band).
fn intersect<const N: usize>(
    bit: u16,
    vi: &ClipVertex<N>,
    vo: &ClipVertex<N>,
    di: f64,
    dout: f64,
    gx: f64,
    gy: f64,
) -> ClipVertex<N> {
    use outcode::*;
    // Weights of the outside and inside vertex, each computed directly (not
    // one as 1 minus the other), so a vertex with a huge `w` keeps its tiny
    // but decisive share.
    let den = di - dout;
    let t = di / den;
    let u = -dout / den;
    let l = |a: f32, b: f32| a as f64 * u + b as f64 * t;
    let (mut x, mut y, mut z) = (
        l(vi.pos.x, vo.pos.x),
        l(vi.pos.y, vo.pos.y),
        l(vi.pos.z, vo.pos.z),
    );
    let w = l(vi.pos.w, vo.pos.w);
    match bit {
        NEAR => z = -w,
        FAR => z = w,
        GUARD_LEFT => x = -gx * w,
        GUARD_RIGHT => x = gx * w,
        GUARD_BOTTOM => y = -gy * w,
        _ => y = gy * w,
    }
    ClipVertex {
        pos: Vec4::new(x as f32, y as f32, z as f32, w as f32),
        varyings: core::array::from_fn(|k| l(vi.varyings[k], vo.varyings[k]) as f32),
    }
}

/// Clips the triangle against the planes in `mask` (a subset of
/// [`outcode::CLIP`]). Returns the convex polygon, possibly empty.
pub fn clip_triangle<const N: usize>(
    tri: &[ClipVertex<N>; 3],
    mask: u16,
    gx: f32,
    gy: f32,
) -> Polygon<N> {
    use outcode::*;
    let (gx, gy) = (gx as f64, gy as f64);
    let mut poly = Polygon::<N>::new();
    for v in tri {
        // Capacity 9 >= 3: cannot fail.
        let _ = poly.push(*v);
    }
    for bit in [NEAR, FAR, GUARD_LEFT, GUARD_RIGHT, GUARD_BOTTOM, GUARD_TOP] {
        if mask & bit == 0 {
            continue;
        }
        let mut out = Polygon::<N>::new();
        let n = poly.len();
        for i in 0..n {
            let a = &poly[i];
            let b = &poly[(i + 1) % n];
            let da = distance(bit, a.pos, gx, gy);
            let db = distance(bit, b.pos, gx, gy);
            let a_in = da >= 0.0;
            let b_in = db >= 0.0;
            if a_in {
                let _ = out.push(*a);
            }
            if a_in != b_in {
                // Always interpolate from the inside vertex to the outside
                // one, so a shared edge gives the same point in both
                // triangles.
                let v = if a_in {
                    intersect(bit, a, b, da, db, gx, gy)
                } else {
                    intersect(bit, b, a, db, da, gx, gy)
                };
                let _ = out.push(v);
            }
        }
        // A convex polygon cut by one plane gains at most one vertex, so
        // 3 + 6 planes never exceed 9: no push above can fail.
        poly = out;
        if poly.len() < 3 {
            poly.clear();
            break;
        }
    }
    poly
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cv(x: f32, y: f32, z: f32, w: f32) -> ClipVertex {
        ClipVertex {
            pos: Vec4::new(x, y, z, w),
            varyings: [0.0; 3],
        }
    }

    #[test]
    fn near_clip_of_one_vertex_gives_quad() {
        let tri = [
            cv(0.0, 0.0, 0.0, 1.0),
            cv(0.5, 0.0, 0.0, 1.0),
            cv(0.0, 0.0, -3.0, 1.0),
        ];
        let p = clip_triangle(&tri, outcode::NEAR, 10.0, 10.0);
        assert_eq!(p.len(), 4);
        for v in &p {
            assert!(v.pos.z >= -v.pos.w - 1e-6);
        }
    }

    #[test]
    fn fully_outside_is_empty() {
        let tri = [
            cv(0.0, 0.0, -2.0, 1.0),
            cv(0.5, 0.0, -2.0, 1.0),
            cv(0.0, 0.5, -3.0, 1.0),
        ];
        assert!(clip_triangle(&tri, outcode::NEAR, 10.0, 10.0).is_empty());
    }

    #[test]
    fn shared_edge_clips_identically_in_both_directions() {
        let a = cv(0.3, 0.1, 0.5, 1.0);
        let b = cv(-0.7, 0.2, -5.0, 1.3);
        let c = cv(0.9, -0.4, 0.0, 2.0);
        let d = cv(-0.9, -0.8, 0.2, 1.0);
        let p1 = clip_triangle(&[a, b, c], outcode::NEAR, 10.0, 10.0);
        let p2 = clip_triangle(&[b, a, d], outcode::NEAR, 10.0, 10.0);
        let on_plane = |p: &Polygon| {
            p.iter()
                .filter(|v| v.pos != a.pos && v.pos != c.pos && v.pos != d.pos)
                .map(|v| v.pos)
                .collect::<Vec<_, 9>>()
        };
        let q1 = on_plane(&p1);
        let q2 = on_plane(&p2);
        // The point on edge ab is in both.
        assert!(q1.iter().any(|v| q2.contains(v)));
    }
}
