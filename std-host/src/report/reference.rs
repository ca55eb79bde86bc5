//! An `f64` reference renderer: what the core would draw with exact
//! geometry.
//!
//! Design note: this is the yardstick of the speed-vs-error report
//! ([`super`], the speed-vs-error report). It takes clip-space triangles in `f64` (no `f32`
//! vertex stage, no snapping) and follows the core's conventions: OpenGL
//! clip space, window row 0 at the top, pixel centres at `+0.5`,
//! counter-clockwise front faces in NDC, depth test `Less` against a buffer
//! cleared to the far plane (1.0), triangles in submission order.
//!
//! It rasterizes in 2D homogeneous coordinates (Olano and Greer, 1997)
//! rather than by clipping and dividing: with the vertices as columns of
//! `M = [x; y; w]`, the three functions `c = M^-1 (X, Y, 1)` of a point
//! `(X, Y)` in NDC are affine in window space, their zero lines are the
//! projected edges, and a pixel is covered exactly when all three are
//! `>= 0` and their sum (`1 / w` of the point on the triangle) is `> 0`.
//! That is homogeneous clipping against `w > 0`, evaluated per pixel, so a
//! triangle with vertices behind the eye covers what a GPU covers (the
//! wedge test below). Near and far are clipped per pixel too: NDC depth is
//! `Σ c_k z_k`, kept where it lies in `[-1, 1]`. Colour is the
//! perspective-correct `Σ c_k col_k / Σ c_k`. The only polygon clipping is
//! against the four side planes in `f64`, and only to find a bounding box
//! of pixels to visit (grown by a pixel, so its rounding cannot lose one).
//!
//! The top-left rule applies where a `c_k` is exactly zero (rare in `f64`
//! unless the input is built to hit pixel centres): the pixel is kept if
//! the edge is a left edge (interior to its right) or a top edge
//! (horizontal, interior below).

use microraster::{CullMode, FrontFace};

/// A clip-space vertex in `f64`.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct RefVertex {
    /// Clip-space `x, y, z, w`.
    pub pos: [f64; 4],
    /// Red, green, blue in `0.0..=255.0`.
    pub color: [f64; 3],
}

/// A clip-space triangle with the caller's id (the core's
/// [`TriangleId`](microraster::TriangleId) image holds `id + 1`).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct RefTriangle {
    /// The three vertices.
    pub v: [RefVertex; 3],
    /// The caller's index of the triangle.
    pub id: u32,
}

/// Frame settings of the reference renderer.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct RefOptions {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// Face culling.
    pub cull: CullMode,
    /// Front-face winding.
    pub front_face: FrontFace,
    /// Depth test `Greater` from 0 (1/w depth) instead of `Less` from 1.
    pub greater: bool,
}

/// What the reference renderer drew.
#[derive(Clone, Debug, PartialEq)]
pub struct RefImage {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// Triangle id + 1 per pixel, 0 for background; row 0 first.
    pub ids: Vec<u32>,
    /// Window depth in `[0, 1]` per pixel (1.0 where nothing was drawn).
    pub depth: Vec<f64>,
    /// Colour per pixel, unrounded (0 where nothing was drawn).
    pub color: Vec<[f64; 3]>,
    /// Index into the triangle list of the triangle drawn at each pixel.
    pub source: Vec<Option<usize>>,
}

impl RefImage {
    /// Pixels covered by some triangle.
    pub fn covered(&self) -> usize {
        self.ids.iter().filter(|&&i| i != 0).count()
    }
}

/// One triangle prepared for evaluation at any point of the window.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Prepared {
    /// `c_k(x, y) = a[k] x + b[k] y + d[k]` in window coordinates.
    a: [f64; 3],
    b: [f64; 3],
    d: [f64; 3],
    /// NDC depth per vertex.
    z: [f64; 3],
    /// Colour per vertex.
    col: [[f64; 3]; 3],
    /// Signed 2D-homogeneous determinant (> 0: counter-clockwise in NDC).
    det: f64,
}

/// The triangle at one point of the window.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sample {
    /// Whether the point is covered (fill rule and near/far included).
    pub inside: bool,
    /// Window depth `(z_ndc + 1) / 2` (meaningful where `1/w > 0`).
    pub depth: f64,
    /// Perspective-correct colour.
    pub color: [f64; 3],
    /// The smallest signed distance, in pixels, from the point to the
    /// three projected edge lines (positive inside). Meaningful only where
    /// the point is in front of the eye.
    pub edge_distance: f64,
    /// `1 / w` of the point on the triangle's plane (> 0 in front).
    pub inv_w: f64,
}

fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

impl Prepared {
    /// Prepares `t` for a `width x height` window; `None` when it is
    /// degenerate in 2D homogeneous space (edge-on, zero area) or not
    /// finite.
    pub fn new(t: &RefTriangle, width: u32, height: u32) -> Option<Prepared> {
        if !t
            .v
            .iter()
            .all(|v| v.pos.iter().chain(v.color.iter()).all(|c| c.is_finite()))
        {
            return None;
        }
        let h = t.v.map(|v| [v.pos[0], v.pos[1], v.pos[3]]);
        let det = {
            let c = cross(h[1], h[2]);
            h[0][0] * c[0] + h[0][1] * c[1] + h[0][2] * c[2]
        };
        if det == 0.0 || !det.is_finite() {
            return None;
        }
        let (sw, sh) = (2.0 / width as f64, 2.0 / height as f64);
        let mut a = [0.0; 3];
        let mut b = [0.0; 3];
        let mut d = [0.0; 3];
        for k in 0..3 {
            // Row k of M^-1: (V_{k+1} x V_{k+2}) / det. In NDC,
            // c_k = r0 X + r1 Y + r2 with X = x sw - 1, Y = 1 - y sh.
            let r = cross(h[(k + 1) % 3], h[(k + 2) % 3]).map(|e| e / det);
            a[k] = r[0] * sw;
            b[k] = -r[1] * sh;
            d[k] = r[2] - r[0] + r[1];
        }
        Some(Prepared {
            a,
            b,
            d,
            z: t.v.map(|v| v.pos[2]),
            col: t.v.map(|v| v.color),
            det,
        })
    }

    /// Whether the triangle faces the viewer as a front face.
    pub fn is_front(&self, front: FrontFace) -> bool {
        let ccw = self.det > 0.0;
        match front {
            FrontFace::Ccw => ccw,
            FrontFace::Cw => !ccw,
        }
    }

    /// Evaluates the triangle at window point `(x, y)`.
    pub fn sample(&self, x: f64, y: f64) -> Sample {
        let c = [0, 1, 2].map(|k| self.a[k] * x + self.b[k] * y + self.d[k]);
        let sum = c[0] + c[1] + c[2];
        let mut inside = sum > 0.0;
        let mut edge_distance = f64::INFINITY;
        #[allow(clippy::needless_range_loop)] // k indexes four arrays
        for k in 0..3 {
            let (a, b) = (self.a[k], self.b[k]);
            if c[k] < 0.0 {
                inside = false;
            } else if c[k] == 0.0 {
                // Top-left rule: keep a left edge (interior to the right)
                // or a top edge (horizontal, interior below).
                let top_left = a > 0.0 || (a == 0.0 && b > 0.0);
                inside &= top_left;
            }
            let g = (a * a + b * b).sqrt();
            if g > 0.0 {
                edge_distance = edge_distance.min(c[k] / g);
            }
        }
        let z_ndc = c[0] * self.z[0] + c[1] * self.z[1] + c[2] * self.z[2];
        if !(-1.0..=1.0).contains(&z_ndc) {
            inside = false;
        }
        let color = [0, 1, 2].map(|ch| {
            (c[0] * self.col[0][ch] + c[1] * self.col[1][ch] + c[2] * self.col[2][ch]) / sum
        });
        Sample {
            inside,
            depth: (z_ndc + 1.0) * 0.5,
            color,
            edge_distance,
            inv_w: sum,
        }
    }
}

/// The pixel rectangle `(x0, y0, x1, y1)` (inclusive) that may hold the
/// visible part of `t`, or `None` when no part of it lies inside the four
/// side planes of the frustum.
fn pixel_bounds(t: &RefTriangle, width: u32, height: u32) -> Option<(u32, u32, u32, u32)> {
    // Clip against -w <= x <= w and -w <= y <= w (every point kept has
    // w >= 0), then take the projected bounding box.
    let mut poly: Vec<[f64; 4]> = t.v.iter().map(|v| v.pos).collect();
    let planes: [fn(&[f64; 4]) -> f64; 4] = [
        |p| p[3] + p[0],
        |p| p[3] - p[0],
        |p| p[3] + p[1],
        |p| p[3] - p[1],
    ];
    for dist in planes {
        let mut out = Vec::with_capacity(poly.len() + 1);
        for i in 0..poly.len() {
            let (p, q) = (poly[i], poly[(i + 1) % poly.len()]);
            let (dp, dq) = (dist(&p), dist(&q));
            if dp >= 0.0 {
                out.push(p);
            }
            if (dp >= 0.0) != (dq >= 0.0) {
                let s = dp / (dp - dq);
                out.push([0, 1, 2, 3].map(|k| p[k] + (q[k] - p[k]) * s));
            }
        }
        poly = out;
        if poly.is_empty() {
            return None;
        }
    }
    let (mut lo_x, mut hi_x, mut lo_y, mut hi_y) = (
        f64::INFINITY,
        f64::NEG_INFINITY,
        f64::INFINITY,
        f64::NEG_INFINITY,
    );
    for p in &poly {
        if p[3] <= 0.0 {
            // The polygon touches the eye: any pixel may be covered.
            return Some((0, 0, width - 1, height - 1));
        }
        let x = (p[0] / p[3] + 1.0) * 0.5 * width as f64;
        let y = (1.0 - p[1] / p[3]) * 0.5 * height as f64;
        lo_x = lo_x.min(x);
        hi_x = hi_x.max(x);
        lo_y = lo_y.min(y);
        hi_y = hi_y.max(y);
    }
    // Pixels whose centre may lie in the box, grown by one pixel.
    let clamp = |v: f64, hi: u32| -> u32 { v.clamp(0.0, hi as f64) as u32 };
    let x0 = clamp((lo_x - 0.5).floor() - 1.0, width - 1);
    let x1 = clamp((hi_x - 0.5).ceil() + 1.0, width - 1);
    let y0 = clamp((lo_y - 0.5).floor() - 1.0, height - 1);
    let y1 = clamp((hi_y - 0.5).ceil() + 1.0, height - 1);
    Some((x0, y0, x1, y1))
}

/// Renders `tris` in order with exact (`f64`) geometry.
pub fn render_reference(tris: &[RefTriangle], opts: &RefOptions) -> RefImage {
    let (w, h) = (opts.width.max(1), opts.height.max(1));
    let len = w as usize * h as usize;
    let mut img = RefImage {
        width: w,
        height: h,
        ids: vec![0; len],
        depth: vec![if opts.greater { 0.0 } else { 1.0 }; len],
        color: vec![[0.0; 3]; len],
        source: vec![None; len],
    };
    for (index, t) in tris.iter().enumerate() {
        let Some(p) = Prepared::new(t, w, h) else {
            continue;
        };
        let front = p.is_front(opts.front_face);
        match opts.cull {
            CullMode::Back if !front => continue,
            CullMode::Front if front => continue,
            _ => {}
        }
        let Some((x0, y0, x1, y1)) = pixel_bounds(t, w, h) else {
            continue;
        };
        for py in y0..=y1 {
            for px in x0..=x1 {
                let s = p.sample(px as f64 + 0.5, py as f64 + 0.5);
                let i = py as usize * w as usize + px as usize;
                let nearer = if opts.greater {
                    s.depth > img.depth[i]
                } else {
                    s.depth < img.depth[i]
                };
                if s.inside && nearer {
                    img.depth[i] = s.depth;
                    img.color[i] = s.color;
                    img.ids[i] = t.id.wrapping_add(1);
                    img.source[i] = Some(index);
                }
            }
        }
    }
    img
}

/// 4x4 matrices in `f64`, with the formulas of the core's `Mat4` (row
/// major here: `m[r][c]`, acting on column vectors).
pub mod mat {
    /// A row-major 4x4 matrix.
    pub type DMat4 = [[f64; 4]; 4];

    /// The identity.
    pub const IDENTITY: DMat4 = [
        [1.0, 0.0, 0.0, 0.0],
        [0.0, 1.0, 0.0, 0.0],
        [0.0, 0.0, 1.0, 0.0],
        [0.0, 0.0, 0.0, 1.0],
    ];

    /// `a * b`.
    pub fn mul(a: &DMat4, b: &DMat4) -> DMat4 {
        let mut m = [[0.0; 4]; 4];
        for (r, row) in m.iter_mut().enumerate() {
            for (c, v) in row.iter_mut().enumerate() {
                *v = (0..4).map(|k| a[r][k] * b[k][c]).sum();
            }
        }
        m
    }

    /// `m * (p, 1)`.
    pub fn transform_point(m: &DMat4, p: [f64; 3]) -> [f64; 4] {
        [0, 1, 2, 3].map(|r| m[r][0] * p[0] + m[r][1] * p[1] + m[r][2] * p[2] + m[r][3])
    }

    /// A translation.
    pub fn translation(t: [f64; 3]) -> DMat4 {
        let mut m = IDENTITY;
        m[0][3] = t[0];
        m[1][3] = t[1];
        m[2][3] = t[2];
        m
    }

    /// Right-handed rotation about x.
    pub fn rotation_x(rad: f64) -> DMat4 {
        let (s, c) = rad.sin_cos();
        [
            [1.0, 0.0, 0.0, 0.0],
            [0.0, c, -s, 0.0],
            [0.0, s, c, 0.0],
            [0.0, 0.0, 0.0, 1.0],
        ]
    }

    /// Right-handed rotation about y.
    pub fn rotation_y(rad: f64) -> DMat4 {
        let (s, c) = rad.sin_cos();
        [
            [c, 0.0, s, 0.0],
            [0.0, 1.0, 0.0, 0.0],
            [-s, 0.0, c, 0.0],
            [0.0, 0.0, 0.0, 1.0],
        ]
    }

    /// Right-handed rotation about z.
    pub fn rotation_z(rad: f64) -> DMat4 {
        let (s, c) = rad.sin_cos();
        [
            [c, -s, 0.0, 0.0],
            [s, c, 0.0, 0.0],
            [0.0, 0.0, 1.0, 0.0],
            [0.0, 0.0, 0.0, 1.0],
        ]
    }

    /// OpenGL perspective projection (as `gluPerspective`).
    pub fn perspective(fov_y_rad: f64, aspect: f64, near: f64, far: f64) -> DMat4 {
        let f = 1.0 / (fov_y_rad * 0.5).tan();
        let nf = 1.0 / (near - far);
        [
            [f / aspect, 0.0, 0.0, 0.0],
            [0.0, f, 0.0, 0.0],
            [0.0, 0.0, (far + near) * nf, 2.0 * far * near * nf],
            [0.0, 0.0, -1.0, 0.0],
        ]
    }

    /// The core's `Mat4::perspective_inv_w`: window depth `near / w`.
    pub fn perspective_inv_w(fov_y_rad: f64, aspect: f64, near: f64) -> DMat4 {
        let f = 1.0 / (fov_y_rad * 0.5).tan();
        [
            [f / aspect, 0.0, 0.0, 0.0],
            [0.0, f, 0.0, 0.0],
            [0.0, 0.0, 1.0, 2.0 * near],
            [0.0, 0.0, -1.0, 0.0],
        ]
    }

    fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
        [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
    }
    fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
        a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
    }
    fn normalize(a: [f64; 3]) -> [f64; 3] {
        let l = dot(a, a).sqrt();
        if l > 0.0 {
            a.map(|c| c / l)
        } else {
            a
        }
    }

    /// Right-handed view matrix (as `gluLookAt`).
    pub fn look_at(eye: [f64; 3], target: [f64; 3], up: [f64; 3]) -> DMat4 {
        let f = normalize(sub(target, eye));
        let s = normalize(super::cross(f, up));
        let u = super::cross(s, f);
        [
            [s[0], s[1], s[2], -dot(s, eye)],
            [u[0], u[1], u[2], -dot(u, eye)],
            [-f[0], -f[1], -f[2], dot(f, eye)],
            [0.0, 0.0, 0.0, 1.0],
        ]
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use microraster::prelude::Submit;

    fn opts(w: u32, h: u32, cull: CullMode) -> RefOptions {
        RefOptions {
            width: w,
            height: h,
            cull,
            front_face: FrontFace::Ccw,
            greater: false,
        }
    }

    fn tri(p: [[f64; 4]; 3]) -> RefTriangle {
        RefTriangle {
            v: p.map(|pos| RefVertex {
                pos,
                color: [255.0, 255.0, 255.0],
            }),
            id: 0,
        }
    }

    #[test]
    fn axis_aligned_triangle_covers_known_pixels() {
        // Window-space right triangle (0,0), (0,8), (8,0) on 8x8: NDC
        // (-1,1), (-1,-1), (1,1). Pixel (i, j) has its centre at
        // (i + .5, j + .5), inside when i + j + 1 < 8. The centres with
        // i + j = 7 lie exactly on the diagonal, which is neither a top nor
        // a left edge (the interior is up and to the left), so they are
        // not covered: rows 0..7 hold 7, 6, ..., 1 pixels, 28 in all.
        let t = tri([
            [-1.0, 1.0, 0.0, 1.0],
            [-1.0, -1.0, 0.0, 1.0],
            [1.0, 1.0, 0.0, 1.0],
        ]);
        let img = render_reference(&[t], &opts(8, 8, CullMode::None));
        assert_eq!(img.covered(), 28);
        for y in 0..8usize {
            for x in 0..8usize {
                let inside = x + y < 7;
                assert_eq!(img.ids[y * 8 + x] != 0, inside, "pixel {x},{y}");
            }
        }
        // Depth: z = 0 in NDC is window depth 0.5.
        assert!(img
            .depth
            .iter()
            .zip(&img.ids)
            .all(|(&d, &i)| i == 0 || d == 0.5));
    }

    #[test]
    fn top_left_rule_at_exact_ties() {
        // Two triangles splitting the 4x4 square on the diagonal from the
        // top-left to the bottom-right corner: pixel centres (i+.5, i+.5)
        // lie on the shared edge, and each belongs to exactly one of them.
        let c = |x: f64, y: f64| [x / 2.0 - 1.0, 1.0 - y / 2.0, 0.0, 1.0];
        let mut a = tri([c(0.0, 0.0), c(0.0, 4.0), c(4.0, 4.0)]);
        let mut b = tri([c(0.0, 0.0), c(4.0, 4.0), c(4.0, 0.0)]);
        a.id = 0;
        b.id = 1;
        let img = render_reference(&[a, b], &opts(4, 4, CullMode::None));
        assert_eq!(img.covered(), 16);
        let only_a = render_reference(&[a], &opts(4, 4, CullMode::None)).covered();
        let only_b = render_reference(&[b], &opts(4, 4, CullMode::None)).covered();
        assert_eq!(only_a + only_b, 16);
        // The diagonal is a left edge (interior to its right) of the
        // upper-right triangle `b`, which gets the 4 centres on it.
        assert_eq!((only_a, only_b), (6, 10));
    }

    #[test]
    fn vertex_behind_the_eye_gives_the_wedge() {
        let t = tri([
            [-0.5, -0.5, 0.0, 1.0],
            [0.5, -0.5, 0.0, 1.0],
            [0.0, -0.5, 0.0, -1.0],
        ]);
        let img = render_reference(&[t], &opts(64, 64, CullMode::None));
        assert_eq!(img.covered(), 640);
        // Below y = -0.5 in NDC only: window rows 48 and down.
        for (i, &id) in img.ids.iter().enumerate() {
            if id != 0 {
                assert!(i / 64 >= 48, "pixel {i}");
            }
        }
    }

    #[test]
    fn culling_follows_ndc_winding() {
        // Counter-clockwise in NDC (y up): a front face.
        let ccw = tri([
            [-0.5, -0.5, 0.0, 1.0],
            [0.5, -0.5, 0.0, 1.0],
            [0.0, 0.5, 0.0, 1.0],
        ]);
        let mut cw = ccw;
        cw.v.swap(1, 2);
        let o = opts(16, 16, CullMode::Back);
        assert!(render_reference(&[ccw], &o).covered() > 0);
        assert_eq!(render_reference(&[cw], &o).covered(), 0);
        let o = opts(16, 16, CullMode::Front);
        assert_eq!(render_reference(&[ccw], &o).covered(), 0);
    }

    #[test]
    fn near_and_far_clip_per_pixel_and_depth_test_keeps_nearest() {
        // A full-screen quad from z = -2 (left, beyond near) to z = 2
        // (right, beyond far) at w = 1: only the middle half survives.
        let q = |x: f64, y: f64| [x, y, 2.0 * x, 1.0];
        let a = tri([q(-1.0, -1.0), q(1.0, -1.0), q(1.0, 1.0)]);
        let b = tri([q(-1.0, -1.0), q(1.0, 1.0), q(-1.0, 1.0)]);
        let img = render_reference(&[a, b], &opts(16, 16, CullMode::None));
        assert_eq!(img.covered(), 8 * 16);
        // A nearer triangle drawn later wins; a farther one does not.
        let near = RefTriangle {
            id: 7,
            ..tri([
                [-1.0, -1.0, -0.5, 1.0],
                [1.0, -1.0, -0.5, 1.0],
                [0.0, 1.0, -0.5, 1.0],
            ])
        };
        let far = RefTriangle {
            id: 8,
            ..tri([
                [-1.0, -1.0, 0.5, 1.0],
                [1.0, -1.0, 0.5, 1.0],
                [0.0, 1.0, 0.5, 1.0],
            ])
        };
        let img = render_reference(&[near, far], &opts(16, 16, CullMode::None));
        assert!(img.ids.iter().all(|&i| i == 0 || i == 8));
        assert!(img.covered() > 0);
    }

    #[test]
    fn colour_is_perspective_correct() {
        // A triangle with w = 1 at vertex 0 and w = 3 at the others: at the
        // screen midpoint between vertex 0 and vertex 1 the clip-space
        // weight of vertex 0 is 3/4, not 1/2.
        let t = RefTriangle {
            v: [
                RefVertex {
                    pos: [-0.5, 0.0, 0.0, 1.0],
                    color: [0.0; 3],
                },
                RefVertex {
                    pos: [1.5, 0.0, 0.0, 3.0],
                    color: [200.0; 3],
                },
                RefVertex {
                    pos: [0.0, 3.0, 0.0, 3.0],
                    color: [0.0; 3],
                },
            ],
            id: 0,
        };
        let p = Prepared::new(&t, 8, 8).unwrap();
        // NDC x = 0 (midpoint of -0.5 and 0.5), y = 0: window (4, 4).
        let s = p.sample(4.0, 4.0);
        assert!((s.color[0] - 50.0).abs() < 1e-9, "{:?}", s.color);
        // The point is at w = 1 + 2 * 0.25 = 1.5.
        assert!((s.inv_w - 1.0 / 1.5).abs() < 1e-12);
        assert!(s.edge_distance.abs() < 1e-12);
    }

    /// The core's `TriangleId` image at 8 subpixel bits, no depth test.
    fn core_ids(tris: &[RefTriangle], w: u32, h: u32) -> Vec<u32> {
        use microraster::{Config, Frame, NoDepth, SetupTriangle, TriangleId, Vec4};
        let mut storage = vec![SetupTriangle::EMPTY; tris.len() * 7];
        let mut config = Config::new(w, h);
        config.cull = CullMode::None;
        let mut frame: Frame = Frame::new(config, &mut storage).unwrap();
        for t in tris {
            let p = t.v.map(|v| {
                let q = v.pos.map(|c| c as f32);
                Vec4::new(q[0], q[1], q[2], q[3])
            });
            let white = microraster::pixelcolor::Rgb888::new(255, 255, 255);
            frame.submit_clip_triangle(p, [white; 3], t.id).unwrap();
        }
        let mut ids = vec![TriangleId(0); (w * h) as usize];
        frame.render_rows(0, h, &mut ids, &mut NoDepth).unwrap();
        ids.into_iter().map(|t| t.0).collect()
    }

    #[test]
    fn agrees_with_the_core_where_snapping_is_exact() {
        // Vertices on the 1/256-pixel grid (and, for the wedge, behind
        // the eye), including pixel centres exactly on shared edges: the
        // core's exact integer coverage and the reference must agree on
        // every pixel.
        let (w, h) = (32u32, 32u32);
        let c = |x: f64, y: f64| [x / 16.0 - 1.0, 1.0 - y / 16.0, 0.0, 1.0];
        let mut tris = Vec::new();
        // A fan around (16, 16) with rim points on pixel centres and
        // corners, so centres fall on the spokes.
        let rim = [
            (0.5, 0.5),
            (16.0, 0.0),
            (31.5, 2.5),
            (32.0, 16.0),
            (30.5, 30.5),
            (16.5, 32.0),
            (2.0, 28.0),
            (0.0, 16.5),
        ];
        for k in 0..rim.len() {
            let (a, b) = (rim[k], rim[(k + 1) % rim.len()]);
            let mut t = tri([c(16.0, 16.0), c(a.0, a.1), c(b.0, b.1)]);
            t.id = k as u32;
            tris.push(t);
        }
        let reference = render_reference(&tris, &opts(w, h, CullMode::None));
        assert_eq!(reference.ids, core_ids(&tris, w, h));
        // The fan is an octagon inside the frame (932 of the 1024
        // pixels), and the core agrees with it pixel for pixel.
        assert_eq!(reference.covered(), 932);
        // The wedge behind the eye, at 64x64.
        let wedge = [tri([
            [-0.5, -0.5, 0.0, 1.0],
            [0.5, -0.5, 0.0, 1.0],
            [0.0, -0.5, 0.0, -1.0],
        ])];
        let reference = render_reference(&wedge, &opts(64, 64, CullMode::None));
        assert_eq!(reference.ids, core_ids(&wedge, 64, 64));
    }

    #[test]
    fn matrices_match_the_core() {
        let p = mat::perspective(1.0, 1.5, 0.1, 10.0);
        let c = microraster::Mat4::perspective(1.0, 1.5, 0.1, 10.0);
        let v = mat::look_at([1.0, 2.0, 3.0], [0.0, 0.5, 0.0], [0.0, 1.0, 0.0]);
        let cv = microraster::Mat4::look_at(
            microraster::Vec3::new(1.0, 2.0, 3.0),
            microraster::Vec3::new(0.0, 0.5, 0.0),
            microraster::Vec3::new(0.0, 1.0, 0.0),
        );
        for r in 0..4 {
            for k in 0..4 {
                assert!((p[r][k] - c.rows()[r][k] as f64).abs() < 1e-5);
                assert!((v[r][k] - cv.rows()[r][k] as f64).abs() < 1e-5);
            }
        }
        let r = mat::mul(&mat::rotation_z(0.5), &mat::translation([1.0, 0.0, 0.0]));
        let q = mat::transform_point(&r, [0.0; 3]);
        assert!((q[0] - 0.5f64.cos()).abs() < 1e-12 && (q[1] - 0.5f64.sin()).abs() < 1e-12);
        let _ = (mat::rotation_x(0.1), mat::rotation_y(0.1));
    }
}
