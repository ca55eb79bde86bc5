//! Meshes and the vertex stage: object space to processed vertices.
//!
//! Design note: a [`Mesh`] borrows the caller's arrays (positions, index
//! triples, colours) and is never copied. The vertex stage transforms each
//! position by the model-view-projection matrix (`f32`, fixed order, no
//! fused multiply-add), computes its outcode and, where no clipping can
//! touch it, snaps it to window space: a [`ProcessedVertex`] in a cache the
//! caller provides, so a vertex shared by six triangles is transformed once.
//! On 64-bit hosts the vertices go in batches of eight, each computed lane
//! by lane without a branch (the compiler's vectors) when all eight are
//! in view, and one by one otherwise: the same operations either way, so
//! the same bits (a property test compares the two).
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
    if BATCH == 1 {
        for (p, v) in positions.iter().zip(out.iter_mut()) {
            *v = ProcessedVertex::new::<S>(mvp.transform_point(*p), gx, gy, width, height);
        }
        return;
    }
    let one = |p: &Vec3, v: &mut ProcessedVertex| {
        *v = ProcessedVertex::new::<S>(mvp.transform_point(*p), gx, gy, width, height);
    };
    // Pairwise, as above: both cut to the shorter.
    let n = positions.len().min(out.len());
    let (Some(positions), Some(out)) = (positions.get(..n), out.get_mut(..n)) else {
        return;
    };
    let mut vs = out.chunks_exact_mut(BATCH);
    for (p, v) in positions.chunks_exact(BATCH).zip(&mut vs) {
        if !process_batch::<S>(width, height, guard, mvp, p, v) {
            p.iter().zip(v.iter_mut()).for_each(|(p, v)| one(p, v));
        }
    }
    let ps = positions.chunks_exact(BATCH).remainder();
    (ps.iter().zip(vs.into_remainder())).for_each(|(p, v)| one(p, v));
}

/// Vertices per batch of [`process_batch`]: 8 lanes of `f32` on 64-bit
/// hosts (one AVX register); 1 (no batches) on 32-bit cores, which have
/// no vector unit for it and where the per-vertex branches cost less than
/// the batch's stores.
pub(crate) const BATCH: usize = if cfg!(target_pointer_width = "64") {
    8
} else {
    1
};

/// The vertex stage of [`BATCH`] vertices at once, lane by lane without a
/// branch, for the common case: every vertex finite, inside the near and
/// far planes and the guard band, with `w > 0` and a window position that
/// snaps. Then it writes what [`ProcessedVertex::new`] gives for each
/// (the same `f32` operations in the same order, through the same
/// [`crate::fixed::window_inv`]; the roundings to `Sub<S>` and `Z32` by
/// [`crate::fixed::round_in_range_by_bits`] and
/// [`crate::fixed::z01_to_z32_by_bits`], the same integers by shifts that
/// vectorize) and returns `true`;
/// otherwise it writes nothing and returns `false`, and the caller
/// processes the batch vertex by vertex. (Test:
/// `batches_equal_the_vertex_by_vertex_stage`.)
#[inline(always)]
fn process_batch<const S: u32>(
    width: u32,
    height: u32,
    (gx, gy): (f32, f32),
    mvp: &Mat4,
    positions: &[Vec3],
    out: &mut [ProcessedVertex],
) -> bool {
    use crate::clip::outcode::CLIP;
    use crate::fixed::{in_coord_range, round_in_range_by_bits, window_inv, z01_to_z32_by_bits};
    let (Some(positions), Some(out)) = (positions.get(..BATCH), out.get_mut(..BATCH)) else {
        return false;
    };
    // Lane by lane, each quantity in an array of its own (structure of
    // arrays), one loop a step: the loops become vector code over all
    // `BATCH` lanes. Each lane's operations are `ProcessedVertex::new`'s,
    // in its order: `Mat4::transform_point`, `outcode`, `window_inv`, the
    // rounding.
    let (mut x, mut y, mut z, mut w) = ([0f32; BATCH], [0f32; BATCH], [0f32; BATCH], [0f32; BATCH]);
    for (k, p) in positions.iter().enumerate() {
        let q = mvp.transform_point(*p);
        (x[k], y[k], z[k], w[k]) = (q.x, q.y, q.z, q.w);
    }
    let mut code = [0u16; BATCH];
    for k in 0..BATCH {
        code[k] = outcode(Vec4::new(x[k], y[k], z[k], w[k]), gx, gy);
    }
    let mut inv = [0f32; BATCH];
    for k in 0..BATCH {
        inv[k] = 1.0 / w[k];
    }
    let (mut wx, mut wy, mut zw) = ([0f32; BATCH], [0f32; BATCH], [0f32; BATCH]);
    for k in 0..BATCH {
        (wx[k], wy[k], zw[k]) = window_inv::<S>(x[k], y[k], z[k], inv[k], width, height);
    }
    let mut ok = true;
    for k in 0..BATCH {
        ok &= Vec4::new(x[k], y[k], z[k], w[k]).is_finite()
            & (code[k] & CLIP == 0)
            & (w[k] > 0.0)
            & zw[k].is_finite()
            & in_coord_range(wx[k])
            & in_coord_range(wy[k]);
    }
    if !ok {
        return false;
    }
    let (mut sx, mut sy, mut sz) = ([0i32; BATCH], [0i32; BATCH], [0u32; BATCH]);
    for k in 0..BATCH {
        sx[k] = round_in_range_by_bits(wx[k]);
        sy[k] = round_in_range_by_bits(wy[k]);
        sz[k] = z01_to_z32_by_bits(zw[k]);
    }
    for (k, v) in out.iter_mut().enumerate() {
        *v = ProcessedVertex {
            pos: Vec4::new(x[k], y[k], z[k], w[k]),
            inv_w: inv[k],
            snap: crate::fixed::SnappedVertex {
                x: sx[k],
                y: sy[k],
                z: sz[k],
            },
            code: code[k],
            snapped: true,
        };
    }
    true
}

#[cfg(test)]
mod tests {
    extern crate std;
    use super::*;
    use proptest::prelude::*;
    use std::vec::Vec;

    /// Every bit of a processed vertex, but a NaN's payload: Rust leaves
    /// it unspecified (Miri picks one at random), and nothing reads it.
    fn bits(v: &ProcessedVertex) -> ([u32; 5], crate::fixed::SnappedVertex, u16, bool) {
        let p = v.pos;
        let bits = |x: f32| if x.is_nan() { f32::NAN } else { x }.to_bits();
        let f = [p.x, p.y, p.z, p.w, v.inv_w].map(bits);
        (f, v.snap, v.code, v.snapped)
    }

    /// The vertex stage one vertex at a time, as before batches.
    fn one_by_one<const S: u32>(w: u32, h: u32, mvp: &Mat4, p: &[Vec3]) -> Vec<ProcessedVertex> {
        let (gx, gy) = crate::fixed::guard_band_ndc::<S>(w, h);
        let t = |p: &Vec3| ProcessedVertex::new::<S>(mvp.transform_point(*p), gx, gy, w, h);
        p.iter().map(t).collect()
    }

    fn batched<const S: u32>(w: u32, h: u32, mvp: &Mat4, p: &[Vec3]) -> Vec<ProcessedVertex> {
        batched_into::<S>(w, h, mvp, p, p.len())
    }

    /// Into a cache of `len` entries (pairwise: the rest stays `EMPTY`).
    fn batched_into<const S: u32>(
        w: u32,
        h: u32,
        mvp: &Mat4,
        p: &[Vec3],
        len: usize,
    ) -> Vec<ProcessedVertex> {
        let guard = crate::fixed::guard_band_ndc::<S>(w, h);
        let mut out = std::vec![ProcessedVertex::EMPTY; len];
        process_vertices::<S>(w, h, guard, mvp, p, &mut out);
        out
    }

    /// A coordinate: mostly ordinary, sometimes one that fails the batch
    /// (NaN, infinities, huge, tiny, zero).
    fn coord() -> impl Strategy<Value = f32> {
        prop_oneof![
            12 => -2.0f32..2.0,
            1 => prop::sample::select(std::vec![
                f32::NAN,
                f32::INFINITY,
                f32::NEG_INFINITY,
                0.0,
                -0.0,
                1e-30,
                -1e30,
                3e38,
                f32::MIN_POSITIVE,
            ]),
            1 => any::<f32>(),
        ]
    }

    /// Up to 40 positions: in two cases of three all within the unit
    /// cube (most batches in view, the batch path), otherwise any
    /// [`coord`]s.
    fn positions() -> impl Strategy<Value = Vec<(f32, f32, f32)>> {
        let near = -1.0f32..1.0;
        prop_oneof![
            2 => prop::collection::vec((near.clone(), near.clone(), near), 0..40),
            1 => prop::collection::vec((coord(), coord(), coord()), 0..40),
        ]
    }

    /// The property's cases do exercise the batch path: of the batches of
    /// 256 cases drawn as it draws them, at least a quarter are batched.
    /// (Not under Miri: it tests the test's cases, and takes minutes
    /// there.)
    #[test]
    #[cfg_attr(miri, ignore)]
    fn the_property_draws_batches_in_view() {
        use proptest::strategy::ValueTree;
        use proptest::test_runner::TestRunner;
        let mut runner = TestRunner::deterministic();
        let (mut batches, mut batched) = (0, 0);
        for _ in 0..256 {
            let mvp = camera().new_tree(&mut runner).unwrap().current();
            let p = positions().new_tree(&mut runner).unwrap().current();
            let p: Vec<Vec3> = p.into_iter().map(|(x, y, z)| Vec3::new(x, y, z)).collect();
            let guard = crate::fixed::guard_band_ndc::<8>(320, 240);
            let mut out = std::vec![ProcessedVertex::EMPTY; BATCH];
            for b in p.chunks_exact(BATCH) {
                batches += 1;
                batched += process_batch::<8>(320, 240, guard, &mvp, b, &mut out) as u32;
            }
        }
        assert!(batched * 4 >= batches, "{batched} of {batches} batched");
    }

    /// A camera looking at the unit cube from 2 to 6 units away, or (one
    /// case in four) a matrix of arbitrary entries.
    fn camera() -> impl Strategy<Value = Mat4> {
        let view = (
            0.3f32..2.5,
            0.05f32..1.0,
            2.0f32..6.0,
            -1.0f32..1.0,
            -1.0f32..1.0,
        )
            .prop_map(|(fov, near, d, ex, ey)| {
                let eye = Vec3::new(ex, ey, d);
                Mat4::perspective(fov, 1.3, near, 50.0)
                    * Mat4::look_at(eye, Vec3::new(0.0, 0.0, 0.0), Vec3::new(0.0, 1.0, 0.0))
            });
        let any = prop::array::uniform16(-3.0f32..3.0).prop_map(|e| {
            let mut m = Mat4::IDENTITY;
            for (k, v) in e.into_iter().enumerate() {
                m.cols[k / 4][k % 4] = v;
            }
            m
        });
        prop_oneof![3 => view, 1 => any]
    }

    fn check<const S: u32>(
        w: u32,
        h: u32,
        mvp: &Mat4,
        p: &[Vec3],
        len: usize,
    ) -> Result<(), TestCaseError> {
        let mut want = one_by_one::<S>(w, h, mvp, p);
        want.resize(len, ProcessedVertex::EMPTY);
        let got = batched_into::<S>(w, h, mvp, p, len);
        prop_assert_eq!(got.len(), len);
        for (i, (a, b)) in want.iter().zip(&got).enumerate() {
            prop_assert_eq!(bits(a), bits(b), "vertex {} of {}", i, p.len());
        }
        Ok(())
    }

    proptest! {
        // Few cases under Miri (CI runs these unit tests there too), and no
        // failure file, which Miri's isolation would refuse.
        #![proptest_config(ProptestConfig {
            cases: if cfg!(miri) { 8 } else { 2048 },
            failure_persistence: None,
            ..ProptestConfig::default()
        })]

        /// The batched vertex stage writes exactly what the vertex-by-vertex
        /// one does, bit for bit, at both subpixel precisions, for any
        /// count (a batch and a remainder) and any cache length, in or
        /// out of view, finite or not.
        #[test]
        fn batches_equal_the_vertex_by_vertex_stage(
            mvp in camera(),
            p in positions(),
            (w, h) in (1u32..2048, 1u32..2048),
            extra in -10i32..10,
        ) {
            let p: Vec<Vec3> = p.into_iter().map(|(x, y, z)| Vec3::new(x, y, z)).collect();
            // A cache shorter or longer than the positions: pairwise.
            let len = (p.len() as i32 + extra).max(0) as usize;
            check::<4>(w, h, &mvp, &p, len)?;
            check::<8>(w, h, &mvp, &p, len)?;
        }
    }

    /// Batches of vertices in view take the batch path (so the property
    /// above tests it), and one bad lane sends its batch, only its batch,
    /// vertex by vertex, with the same result.
    #[test]
    fn a_batch_in_view_is_batched_and_one_bad_lane_is_not() {
        let mvp = Mat4::perspective(1.0, 1.0, 0.1, 50.0)
            * Mat4::look_at(
                Vec3::new(0.0, 0.0, 4.0),
                Vec3::new(0.0, 0.0, 0.0),
                Vec3::new(0.0, 1.0, 0.0),
            );
        let mut p: Vec<Vec3> = (0..BATCH * 3)
            .map(|i| Vec3::new(i as f32 * 0.05 - 0.5, 0.3 - i as f32 * 0.02, 0.1))
            .collect();
        let guard = crate::fixed::guard_band_ndc::<8>(320, 240);
        let mut out = std::vec![ProcessedVertex::EMPTY; BATCH];
        assert_eq!(
            process_batch::<8>(320, 240, guard, &mvp, &p[..BATCH], &mut out),
            BATCH > 1
        );
        p[BATCH + 1].z = f32::NAN;
        p[2 * BATCH + 2].z = 100.0; // behind the eye
        assert!(!process_batch::<8>(
            320,
            240,
            guard,
            &mvp,
            &p[BATCH..2 * BATCH],
            &mut out
        ));
        let want = one_by_one::<8>(320, 240, &mvp, &p);
        let got = batched::<8>(320, 240, &mvp, &p);
        assert!(want.iter().zip(&got).all(|(a, b)| bits(a) == bits(b)));
        assert!(!got[BATCH + 1].snapped && got[BATCH + 1].code == NONFINITE);
        assert!(got[..BATCH].iter().all(|v| v.snapped));
        // `w = +inf` with `x`, `y`, `z` finite has no outcode bit and snaps
        // to the centre: only the finiteness test refuses it.
        let mut huge = Mat4::IDENTITY;
        (huge.cols[2][3], huge.cols[3][3]) = (f32::MAX, f32::MAX);
        let p = [Vec3::new(0.0, 0.0, 1.0); BATCH];
        let got = batched::<8>(320, 240, &huge, &p);
        assert!(
            got.iter().all(|v| v.code == NONFINITE && !v.snapped),
            "{got:?}"
        );
    }
}
