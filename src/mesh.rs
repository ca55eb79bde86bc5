//! Meshes and the vertex stage: object space to processed vertices.
//!
//! Design note: a [`Mesh`] borrows the caller's arrays (positions, index
//! triples, colours) and is never copied. The vertex stage transforms each
//! position by the model-view-projection matrix (`f32`, fixed order, no
//! fused multiply-add), computes its outcode and, where no clipping can
//! touch it, snaps it to window space: a [`ProcessedVertex`] in a cache the
//! caller provides, so a vertex shared by six triangles is transformed once.
//! A [`BoundingSphere`] lets a whole object be skipped before any of that.

use crate::clip::{outcode, ClipVertex};
use crate::math::{Mat4, Vec3, Vec4};
use crate::shade::Attributes;
use embedded_graphics_core::pixelcolor::{Rgb888, RgbColor};

/// A sphere bounding an object in its own coordinates.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct BoundingSphere {
    /// Centre.
    pub center: Vec3,
    /// Radius.
    pub radius: f32,
}

impl BoundingSphere {
    /// A sphere around everything (an infinite radius): bounds nothing
    /// usefully, so nothing is culled or dropped by it.
    pub const EVERYWHERE: BoundingSphere = BoundingSphere {
        center: Vec3::new(0.0, 0.0, 0.0),
        radius: f32::INFINITY,
    };

    /// A sphere around every point (centre of the bounding box); `None`
    /// for no points or a non-finite coordinate.
    pub fn from_points(points: &[Vec3]) -> Option<BoundingSphere> {
        let first = points.first()?;
        let (mut lo, mut hi) = (*first, *first);
        for p in points {
            if !p.is_finite() {
                return None;
            }
            lo = Vec3::new(lo.x.min(p.x), lo.y.min(p.y), lo.z.min(p.z));
            hi = Vec3::new(hi.x.max(p.x), hi.y.max(p.y), hi.z.max(p.z));
        }
        let center = (lo + hi) * 0.5;
        let mut r2 = 0.0f32;
        for p in points {
            let d = *p - center;
            r2 = r2.max(d.dot(d));
        }
        // A relative margin covers rounding in the distance computation.
        let radius = crate::math::fx::sqrt(r2) * 1.0001 + f32::MIN_POSITIVE;
        Some(BoundingSphere { center, radius })
    }

    /// Whether the sphere lies entirely outside one frustum plane of the
    /// clip-space transform `mvp`, so that no vertex inside it can be seen.
    ///
    /// Conservative for every finite input, in `f32` (no software `f64`
    /// on single-precision FPUs: a chunked mesh tests a sphere per chunk
    /// and strip). A vertex `p` goes to clip space in `f32` as `c_r = Σ_j
    /// m_rj p_j` (with `p_3 = 1`), three roundings per row, so the
    /// computed plane value `w ± x` (or `± y`, `± z`) differs from the
    /// exact one by at most `γ3 M` with `M = Σ_j (|m_3j| + |m_ij|) |p_j|`,
    /// `γ3 = 3u / (1 - 3u)`, `u = 2^-24`, and `|p_j| <= |c_j| + r` inside
    /// the sphere. This test's own `f32` evaluation errs by at most `u M`
    /// (the plane's coefficients `m_3j ± m_ij`, rounded), `γ4 M` (the
    /// distance of the centre) and a few `u` of the comparison, which
    /// compares squares with a relative margin of `2^-18`; the object is
    /// culled only if the plane value at the centre, plus `16 u M` (more
    /// than all of those), stays below minus the sphere's reach. Then
    /// every vertex's computed outcode has that plane's bit set and the
    /// per-triangle frustum test would have culled every triangle anyway.
    /// An overflow makes the bound infinite or the comparison false:
    /// nothing is culled.
    pub fn outside_frustum(&self, mvp: &Mat4) -> bool {
        let m = mvp.rows();
        let Some((c, r, p_abs)) = self.in_f32(mvp) else {
            return false;
        };
        for i in 0..3 {
            for sign in [1.0f32, -1.0] {
                // Plane: row3 + sign * row_i (Gribb-Hartmann).
                let plane: [f32; 4] = core::array::from_fn(|j| m[3][j] + sign * m[i][j]);
                let mag: f32 = (0..4)
                    .map(|j| (m[3][j].abs() + m[i][j].abs()) * p_abs[j])
                    .sum();
                // Outside when dist + err < -r |n|.
                if beyond(plane.map(|a| -a), c, r, mag * GAMMA) {
                    return true;
                }
            }
        }
        false
    }
}

/// The rounding bound, relative to the magnitudes `M` of
/// [`BoundingSphere::outside_frustum`] and
/// [`BoundingSphere::outside_slab`]: the vertex stage's `γ3` plus this
/// test's own `f32` evaluation, with room to spare.
const GAMMA: f32 = 16.0 / 16_777_216.0;

/// Whether the plane `a` exceeds `err` everywhere in the sphere (centre
/// `c`, radius `r`): `a(c) - err > r |n|`, compared squared (no square
/// root in `no_std`) with a relative margin of `2^-18` for the rounding of
/// both sides. `false` on any NaN (an overflow).
///
/// The relative margins hold only while the squares stay in `f32`'s
/// normal range: a square below it (a plane with coefficients near
/// `1e-20`, say) is rounded to a multiple of `2^-149` and can lose every
/// digit, and an absolute error of `2^-150` per product in the vertex
/// stage is no longer small against the plane's value. So a verdict of
/// "beyond" stands only where `t^2` and `|n|^2` are at least
/// [`NORMAL_SQ`]; otherwise nothing is culled. (`r^2` is not checked: a
/// radius below `1e-15` errs in its square by at most `2^-150`, which
/// matters only for a sphere that grazes the plane with `|n|` beyond
/// `1e9`; left as is, since the checks cost the Cortex-M4F per test.) (The fuzz
/// target `occlusion` found a frame whose matrix rows were near
/// `5e-22`: the squares underflowed and a visible object was culled.)
#[inline]
fn beyond(a: [f32; 4], c: [f32; 4], r: f32, err: f32) -> bool {
    let at_c: f32 = (0..4).map(|j| a[j] * c[j]).sum();
    let n2 = a[0] * a[0] + a[1] * a[1] + a[2] * a[2];
    let t = at_c - err;
    let t2 = t * t;
    t > 0.0 && t2 > r * r * n2 * (1.0 + 1.0 / 262_144.0) && t2 >= NORMAL_SQ && n2 >= NORMAL_SQ
}

/// The least square [`beyond`] trusts: `1e-30`, about `2^-100`, far
/// above `f32`'s smallest normal number (`2^-126`), so these squares carry
/// their full relative precision, and an absolute error of `2^-150` per
/// product is below `2^-50` of the plane value `t >= 1e-15`.
const NORMAL_SQ: f32 = 1.0e-30;

impl BoundingSphere {
    /// The centre (homogeneous), the radius and the bound `|p_j| <= |c_j| +
    /// r` on the coordinates of the sphere's points (rounded up by the
    /// margin of [`GAMMA`]); `None` unless the sphere and `mvp` are finite
    /// (then nothing is culled).
    fn in_f32(&self, mvp: &Mat4) -> Option<([f32; 4], f32, [f32; 4])> {
        let c = [self.center.x, self.center.y, self.center.z, 1.0];
        let r = self.radius;
        if !(r >= 0.0 && c.iter().all(|v| v.is_finite()) && mvp.is_finite()) {
            return None;
        }
        Some((c, r, [c[0].abs() + r, c[1].abs() + r, c[2].abs() + r, 1.0]))
    }

    /// Whether every point of the sphere lies in front of the eye and
    /// wholly above the NDC row `top` or wholly below `bottom` (a strip
    /// renderer's slab), so that the per-triangle strip test would skip
    /// every triangle of the object: the object is skipped before any
    /// vertex is transformed.
    ///
    /// Conservative for every finite input, as
    /// [`BoundingSphere::outside_frustum`]: a vertex's computed `y` and
    /// `w` each err by at most `γ3 Σ_j |m_rj| |p_j|`, the per-triangle
    /// test's product `w * top` adds one rounding, and this test's plane
    /// `±(m_1j - t m_3j)` two more per coefficient; the object is skipped
    /// only if the plane value at the centre, minus `16 u` times the sum
    /// of those magnitudes, exceeds the sphere's reach (and likewise `w`
    /// stays positive).
    pub fn outside_slab(&self, mvp: &Mat4, top: f32, bottom: f32) -> bool {
        let m = mvp.rows();
        let Some((c, r, p_abs)) = self.in_f32(mvp) else {
            return false;
        };
        if !(top.is_finite() && bottom.is_finite()) {
            return false;
        }
        let row_mag = |i: usize| -> f32 { (0..4).map(|j| m[i][j].abs() * p_abs[j]).sum() };
        let (mw, my) = (row_mag(3), row_mag(1));
        // In front of the eye everywhere (the per-triangle test needs w > 0).
        if !beyond(m[3], c, r, mw * GAMMA) {
            return false;
        }
        for (t, sign) in [(top, 1.0f32), (bottom, -1.0)] {
            // sign * (y - t w) > 0 everywhere, beyond the rounding bound.
            let plane: [f32; 4] = core::array::from_fn(|j| sign * (m[1][j] - t * m[3][j]));
            let err = (my + 2.0 * t.abs() * mw) * GAMMA;
            if beyond(plane, c, r, err) {
                return true;
            }
        }
        false
    }
}

/// Per-triangle or per-vertex colours of a [`Mesh`].
#[derive(Clone, Copy, Debug)]
pub enum MeshColors<'a> {
    /// One colour for everything.
    Uniform(Rgb888),
    /// One colour per triangle (flat shading).
    PerTriangle(&'a [Rgb888]),
    /// One colour per vertex (Gouraud shading, perspective-correct).
    PerVertex(&'a [Rgb888]),
}

/// An indexed triangle mesh in object space, with the source of its
/// varyings: colours by default ([`MeshColors`]), or any
/// [`Attributes`] (normals and lights, texture
/// coordinates: see [`crate::shade`]).
#[derive(Clone, Copy, Debug)]
pub struct Mesh<'a, A = MeshColors<'a>> {
    /// Vertex positions.
    pub positions: &'a [Vec3],
    /// Triangles as three indices into `positions`.
    pub indices: &'a [[u32; 3]],
    /// The varyings per vertex (colours by default).
    pub attributes: A,
    /// A bounding sphere for whole-object culling, if known.
    pub bounds: Option<BoundingSphere>,
}

impl<A> Mesh<'_, A> {
    /// Triangle `i` transformed to clip space by `mvp`, with its varyings;
    /// `None` if an index (or an attribute) is out of range.
    pub fn triangle<const N: usize>(&self, i: usize, mvp: &Mat4) -> Option<[ClipVertex<N>; 3]>
    where
        A: Attributes<N>,
    {
        let idx = *self.indices.get(i)?;
        if !self.attributes.has(i, idx) {
            return None;
        }
        let mut verts = [ClipVertex::default(); 3];
        for k in 0..3 {
            let p = self.positions.get(idx[k] as usize)?;
            verts[k] = ClipVertex {
                pos: mvp.transform_point(*p),
                varyings: self.attributes.get(i, idx[k]),
            };
        }
        Some(verts)
    }
}

/// Outcode bit for a vertex with a NaN or infinite coordinate.
pub(crate) const NONFINITE: u16 = 1 << 15;

/// A vertex after the vertex stage (see
/// [`Submit::submit_mesh_cached`](crate::Submit::submit_mesh_cached)):
/// clip-space position, outcode and, where no clipping can touch it, its
/// snapped window position.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ProcessedVertex {
    pub(crate) pos: Vec4,
    pub(crate) inv_w: f32,
    pub(crate) snap: crate::fixed::SnappedVertex,
    pub(crate) code: u16,
    pub(crate) snapped: bool,
}

impl ProcessedVertex {
    /// A placeholder to fill a cache with.
    pub const EMPTY: ProcessedVertex = ProcessedVertex {
        pos: Vec4::new(0.0, 0.0, 0.0, 0.0),
        inv_w: 0.0,
        snap: crate::fixed::SnappedVertex { x: 0, y: 0, z: 0 },
        code: 0,
        snapped: false,
    };

    /// Its clip-space position, as the vertex stage computed it.
    pub fn clip_position(&self) -> Vec4 {
        self.pos
    }

    /// Not processed this frame: counted as non-finite if a triangle uses
    /// it (a cluster set whose vertex list misses one of its triangles'
    /// vertices).
    pub(crate) const STALE: ProcessedVertex = ProcessedVertex {
        code: NONFINITE,
        ..ProcessedVertex::EMPTY
    };

    #[inline]
    fn new<const S: u32>(pos: Vec4, gx: f32, gy: f32, width: u32, height: u32) -> Self {
        if !pos.is_finite() {
            return ProcessedVertex {
                pos,
                code: NONFINITE,
                ..ProcessedVertex::EMPTY
            };
        }
        let code = outcode(pos, gx, gy);
        let mut v = ProcessedVertex {
            pos,
            code,
            ..ProcessedVertex::EMPTY
        };
        if code & outcode::CLIP == 0 && pos.w > 0.0 {
            v.inv_w = 1.0 / pos.w;
            if let Some(s) =
                crate::fixed::snap_inv::<S>(pos.x, pos.y, pos.z, v.inv_w, width, height)
            {
                v.snap = s;
                v.snapped = true;
            }
        }
        v
    }
}

pub(crate) fn rgb_f32(c: Rgb888) -> [f32; 3] {
    [c.r() as f32, c.g() as f32, c.b() as f32]
}

/// The vertex stage: transform, outcode and (where no clipping can touch
/// the vertex) snap, pairwise from `positions` into `out`.
pub(crate) fn process_vertices<const S: u32>(
    width: u32,
    height: u32,
    guard: (f32, f32),
    mvp: &Mat4,
    positions: &[Vec3],
    out: &mut [ProcessedVertex],
) {
    let (gx, gy) = guard;
    for (p, v) in positions.iter().zip(out.iter_mut()) {
        *v = ProcessedVertex::new::<S>(mvp.transform_point(*p), gx, gy, width, height);
    }
}
