//! Cluster culling: skipping groups of triangles before any of their
//! vertices is transformed.
//!
//! Design note: an offline step (the host's `cluster` module, or a build
//! script) splits a mesh into [`Cluster`]s, contiguous runs of its
//! triangles whose vertices are a contiguous range of its positions, and
//! arranges [`ClusterNode`]s over them in a pre-order tree: node `i`
//! covers clusters `clusters[0]..clusters[1]` and its subtree ends at node
//! `skip` (a leaf has `skip == i + 1`; a flat set is all leaves). Every
//! node carries two conservative back-face tests, both evaluated per frame
//! from the eye, found in object space from the model-view-projection
//! matrix alone ([`Eye::from_mvp`]):
//!
//! - a **culling volume** ([`CullVolume`], the lecture's clustered
//!   back-face culling): with unit normals `n_i`, a local origin `c`, the
//!   component-wise bounds `m' <= n_i <= m` and `d_min <= n_i . (p_i - c)
//!   <= d_max`, every triangle's facing value is bounded above by
//!   `comb(m', m; t) . t - d_min` and below by `comb(m, m'; t) . t - d_max`
//!   with `t = e - c`: below zero the node is wholly back-facing, above
//!   zero wholly front-facing (the hierarchy then stops testing);
//! - a **normal cone** ([`NormalCone`], meshoptimizer's meshlet cone):
//!   wholly back-facing when the direction from the eye to the apex lies
//!   within the cone's cutoff of its axis.
//!
//! The rasterizer culls by the sign of the snapped area, in fixed point;
//! these tests decide in `f32` on object-space geometry. So both tests
//! demand a margin: every skipped triangle is seen at least [`MARGIN`] (as
//! the sine of the angle) past edge-on, far beyond the `f32` rounding of
//! the tests (below `2^-20` relatively), and a node with a zero-area
//! triangle (no normal) is never culled. A triangle that far past edge-on
//! can still flip its snapped winding when it is far below a pixel in
//! size, so for a frame ([`Eye::for_frame`]) a size guard culls a node
//! only where no triangle of it can: every skipped triangle is one the
//! per-triangle path culls by winding, the same pieces are set up and the
//! frame is byte-identical (docs/culling.md has the bound and the tests).
//!
//! Bad data (ranges out of order or out of bounds, a tree whose subtrees
//! do not tile the clusters) is refused by [`ClusterSet::validate`] with
//! [`Error::InvalidClusters`] before anything is drawn; geometric data
//! that does not bound its triangles cannot be detected at run time and is
//! the offline step's responsibility (the host checks it when it builds).

// `!(a < b)` is meant: it is true for NaN, which must never cull. The
// loops over the three axes index several arrays in step.
#![allow(clippy::neg_cmp_op_on_partial_ord, clippy::needless_range_loop)]

use crate::config::{CullMode, Error, FrontFace};
use crate::math::{Mat4, Vec3, Vec4};
use crate::mesh::BoundingSphere;

/// The least sine of the angle past edge-on at which a skipped triangle
/// is seen (`2^-8`, about 0.22°).
pub const MARGIN: f32 = 1.0 / 256.0;

/// Relative allowance for the `f32` evaluation of the tests (`2^-18`).
const ROUNDING: f32 = 1.0 / 262_144.0;

/// A run of a mesh's triangles and the positions they use.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct Cluster {
    /// Triangles `triangles[0]..triangles[1]` of the mesh.
    pub triangles: [u32; 2],
    /// The vertices they use: entries `vertices[0]..vertices[1]` of the
    /// set's vertex list ([`ClusterSet::vertices`]), or, where the set has
    /// none, the positions `vertices[0]..vertices[1]` themselves (every
    /// cluster with its own copies). A triangle using a vertex outside is
    /// counted in [`Stats::rejected_index`](crate::Stats) (a range of
    /// positions) or [`Stats::rejected_nonfinite`](crate::Stats) (a list:
    /// the vertex was not processed).
    pub vertices: [u32; 2],
}

/// The lecture's culling volume of a set of triangles (object space).
///
/// `n_min`/`n_max` bound the components of the triangles' unit normals
/// (`(p1 - p0) x (p2 - p0)`, normalized), `d_min`/`d_max` bound
/// `n . (p - origin)` over the triangles' vertices, and `radius` bounds
/// `|p - origin|`. `d_min > d_max` (as in [`CullVolume::NEVER`]) marks a
/// set the test must never cull.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CullVolume {
    /// The local origin `c`.
    pub origin: [f32; 3],
    /// `m'`: component-wise minimum of the unit normals.
    pub n_min: [f32; 3],
    /// `m`: component-wise maximum of the unit normals.
    pub n_max: [f32; 3],
    /// The least `n . (p - c)`.
    pub d_min: f32,
    /// The greatest `n . (p - c)`.
    pub d_max: f32,
    /// The greatest `|p - c|`.
    pub radius: f32,
}

impl CullVolume {
    /// A volume that never culls.
    pub const NEVER: CullVolume = CullVolume {
        origin: [0.0; 3],
        n_min: [-1.0; 3],
        n_max: [1.0; 3],
        d_min: 1.0,
        d_max: -1.0,
        radius: 0.0,
    };

    /// How the triangles face the eye `e` (see [`Eye`]), geometrically
    /// (no size guard).
    pub fn facing(&self, e: &Eye) -> Facing {
        self.facing_bound(e).0
    }

    /// [`CullVolume::facing`], with a lower bound on `|facing value|`
    /// for a back-facing node.
    fn facing_bound(&self, e: &Eye) -> (Facing, f32) {
        let vals = [
            self.origin[0],
            self.origin[1],
            self.origin[2],
            self.n_min[0],
            self.n_min[1],
            self.n_min[2],
            self.n_max[0],
            self.n_max[1],
            self.n_max[2],
            self.d_min,
            self.d_max,
            self.radius,
        ];
        if !(self.d_min <= self.d_max) || !vals.iter().all(|v| v.is_finite()) {
            return (Facing::Mixed, 0.0);
        }
        let k = e.k;
        let mut t = [0.0f32; 3];
        let (mut upper, mut lower, mut t1, mut c1) = (0.0f32, 0.0f32, 0.0f32, 0.0f32);
        for a in 0..3 {
            t[a] = e.sign * (e.xyz[a] - e.w * self.origin[a]);
            let (hi, lo) = if t[a] > 0.0 {
                (self.n_max[a], self.n_min[a])
            } else {
                (self.n_min[a], self.n_max[a])
            };
            upper += hi * t[a];
            lower += lo * t[a];
            t1 += t[a].abs();
            c1 += self.origin[a].abs();
        }
        let (dk_hi, dk_lo) = if k >= 0.0 {
            (k * self.d_min, k * self.d_max)
        } else {
            (k * self.d_max, k * self.d_min)
        };
        upper -= dk_hi;
        lower -= dk_lo;
        let delta = MARGIN * (t1 + k.abs() * self.radius) + ROUNDING * (e.xyz1 + k.abs() * c1);
        if upper < -delta {
            (Facing::Back, -upper)
        } else if lower > delta {
            (Facing::Front, 0.0)
        } else {
            (Facing::Mixed, 0.0)
        }
    }
}

/// meshoptimizer's normal cone of a set of triangles: every triangle is
/// back-facing when `dot(normalize(apex - e), axis) >= cutoff`. A
/// `cutoff` of 1 or more never culls.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NormalCone {
    /// The apex.
    pub apex: [f32; 3],
    /// The unit axis.
    pub axis: [f32; 3],
    /// The sine of the cone's half angle.
    pub cutoff: f32,
}

impl NormalCone {
    /// A cone that never culls.
    pub const NEVER: NormalCone = NormalCone {
        apex: [0.0; 3],
        axis: [0.0, 0.0, 1.0],
        cutoff: 2.0,
    };

    /// Whether every triangle faces away from the eye `e` by the margin.
    ///
    /// The cone describes triangles that face away where `n . (e - p) <
    /// 0`; that is the rasterizer's back face only for an eye in front
    /// of the projection (`k > 0`, see [`Eye`]), so other eyes never cull.
    pub fn back_facing(&self, e: &Eye) -> bool {
        self.back_bound(e).is_some()
    }

    /// For a back-facing cone, a lower bound on `|facing value|`: `k` times
    /// a lower bound on `n . (apex - e)`, which bounds `-n . (e - p)` as
    /// the apex lies behind every triangle's plane.
    fn back_bound(&self, e: &Eye) -> Option<f32> {
        let ok = self.apex.iter().chain(&self.axis).all(|v| v.is_finite());
        if !ok || !(self.cutoff < 1.0) || !(e.k > 0.0) {
            return None;
        }
        let p = e.point?;
        let mut g = [0.0f32; 3];
        let (mut d, mut gg, mut p1) = (0.0f32, 0.0f32, 0.0f32);
        for a in 0..3 {
            g[a] = self.apex[a] - p[a];
            d += g[a] * self.axis[a];
            gg += g[a] * g[a];
            p1 += p[a].abs() + self.apex[a].abs();
        }
        // d >= (cutoff + MARGIN) |g|, with d shrunk by the rounding of e.
        let d = d - ROUNDING * p1;
        let c = crate::math::fx::max(self.cutoff, 0.0) + MARGIN;
        if !(d > 0.0 && d * d >= c * c * gg) {
            return None;
        }
        // Every normal is within theta (sin theta = cutoff) of the axis,
        // the axis within acos(beta) of g: n . g >= |g| cos(theta +
        // acos(beta)) = |g| (cos(theta) beta - cutoff sqrt(1 - beta^2)),
        // positive since beta >= cutoff + MARGIN.
        let len = crate::math::fx::sqrt(gg);
        let root = |x: f32| crate::math::fx::sqrt(crate::math::fx::max(x, 0.0));
        let beta = crate::math::fx::min(d / len, 1.0);
        let cut = crate::math::fx::max(self.cutoff, 0.0);
        let lb = root(1.0 - cut * cut) * beta - cut * root(1.0 - beta * beta);
        // Shrunk for the float functions (micromath's sqrt is approximate).
        let lb = lb - 0.05 * MARGIN;
        (lb > 0.0).then_some(e.k * lb * len * (1.0 - 1.0 / 64.0))
    }
}

// ---------------------------------------------------------------------------
// Building (offline: in f64, rounded outward to f32).

/// `sqrt` in `f64` from the float backend's `f32` one and Newton steps
/// (four: from micromath's few per cent to below `2^-40`).
fn sqrt64(x: f64) -> f64 {
    if !(x > 0.0) {
        return 0.0;
    }
    let mut y = f64::from(crate::math::fx::sqrt(x as f32));
    if !(y > 0.0) || !y.is_finite() {
        y = 1.0;
    }
    for _ in 0..4 {
        y = 0.5 * (y + x / y);
    }
    y
}

/// `2^-40` and `2^-30`.
const E40: f64 = 1.0 / (1u64 << 40) as f64;
const E30: f64 = 1.0 / (1u64 << 30) as f64;

fn down(v: f64) -> f32 {
    let f = v as f32;
    if f64::from(f) > v {
        f.next_down()
    } else {
        f
    }
}

fn up(v: f64) -> f32 {
    let f = v as f32;
    if f64::from(f) < v {
        f.next_up()
    } else {
        f
    }
}

type V64 = [f64; 3];

fn sub(a: V64, b: V64) -> V64 {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn dot(a: V64, b: V64) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// The triangles' vertices and unit normals in `f64`; `None` for a bad
/// index, a non-finite position or a zero-area triangle (no normal).
fn unit_triangles<'a>(
    positions: &'a [Vec3],
    indices: &'a [[u32; 3]],
) -> impl Iterator<Item = Option<([V64; 3], V64)>> + 'a {
    indices.iter().map(move |idx| {
        let mut p = [[0.0f64; 3]; 3];
        for k in 0..3 {
            let q = positions.get(idx[k] as usize)?;
            if !q.is_finite() {
                return None;
            }
            p[k] = [q.x, q.y, q.z].map(f64::from);
        }
        let (u, v) = (sub(p[1], p[0]), sub(p[2], p[0]));
        let n = [
            u[1] * v[2] - u[2] * v[1],
            u[2] * v[0] - u[0] * v[2],
            u[0] * v[1] - u[1] * v[0],
        ];
        let len = sqrt64(dot(n, n));
        if !(len > 0.0) || !len.is_finite() {
            return None;
        }
        Some((p, n.map(|c| c / len)))
    })
}

/// The size guard's data of the triangles `indices` ([`ClusterNode::size`]):
/// the least `2A / (|p1 - p0| + |p2 - p0|)` and the least `2A`, in `f64`,
/// rounded down; zeros for no triangles or one that fails (as for
/// [`CullVolume::from_triangles`]).
pub fn triangle_sizes(positions: &[Vec3], indices: &[[u32; 3]]) -> [f32; 2] {
    let (mut q, mut a) = (f64::INFINITY, f64::INFINITY);
    for t in unit_triangles(positions, indices) {
        let Some((p, n)) = t else {
            return [0.0; 2];
        };
        let (u, v) = (sub(p[1], p[0]), sub(p[2], p[0]));
        // |u x v| again, from the unit normal: n . (u x v).
        let cross = [
            u[1] * v[2] - u[2] * v[1],
            u[2] * v[0] - u[0] * v[2],
            u[0] * v[1] - u[1] * v[0],
        ];
        let area2 = dot(n, cross);
        let edges = sqrt64(dot(u, u)) + sqrt64(dot(v, v));
        q = q.min(area2 / edges);
        a = a.min(area2);
    }
    if !(q.is_finite() && a.is_finite() && q > 0.0 && a > 0.0) {
        return [0.0; 2];
    }
    [down(q * (1.0 - E30)), down(a * (1.0 - E30))]
}

/// A sphere around every vertex of the triangles `indices`
/// ([`ClusterNode::sphere`]): about the centre of their box (rounded to
/// `f32`), the radius computed in `f64` and rounded up;
/// [`BoundingSphere::EVERYWHERE`] for no triangles, a bad index or a
/// non-finite position.
pub fn triangle_sphere(positions: &[Vec3], indices: &[[u32; 3]]) -> BoundingSphere {
    let point = |k: u32| -> Option<[f64; 3]> {
        let p = positions.get(k as usize)?;
        let q = [p.x, p.y, p.z].map(f64::from);
        q.iter().all(|v| v.is_finite()).then_some(q)
    };
    let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
    for &k in indices.iter().flatten() {
        let Some(q) = point(k) else {
            return BoundingSphere::EVERYWHERE;
        };
        for a in 0..3 {
            lo[a] = lo[a].min(q[a]);
            hi[a] = hi[a].max(q[a]);
        }
    }
    if indices.is_empty() {
        return BoundingSphere::EVERYWHERE;
    }
    let c = [0, 1, 2].map(|a| (0.5 * (lo[a] + hi[a])) as f32);
    let cf = c.map(f64::from);
    let r2 = indices
        .iter()
        .flatten()
        .filter_map(|&k| point(k))
        .map(|q| {
            let d = sub(q, cf);
            dot(d, d)
        })
        .fold(0.0f64, f64::max);
    let radius = up(sqrt64(r2) * (1.0 + E40));
    if !(c.iter().all(|v| v.is_finite()) && radius.is_finite()) {
        return BoundingSphere::EVERYWHERE;
    }
    BoundingSphere {
        center: Vec3::from_array(c),
        radius,
    }
}

impl CullVolume {
    /// The volume of the triangles `indices` (into `positions`) about the
    /// local origin `origin`, computed in `f64` and rounded outward;
    /// [`CullVolume::NEVER`] for no triangles, a bad index, a non-finite
    /// position or a zero-area triangle.
    pub fn from_triangles(
        positions: &[Vec3],
        indices: &[[u32; 3]],
        origin: [f32; 3],
    ) -> CullVolume {
        let c = origin.map(f64::from);
        let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
        let (mut dmin, mut dmax, mut r2) = (f64::INFINITY, f64::NEG_INFINITY, 0.0f64);
        for t in unit_triangles(positions, indices) {
            let Some((p, n)) = t else {
                return CullVolume::NEVER;
            };
            for a in 0..3 {
                lo[a] = lo[a].min(n[a]);
                hi[a] = hi[a].max(n[a]);
            }
            for q in p {
                let d = sub(q, c);
                let v = dot(n, d);
                dmin = dmin.min(v);
                dmax = dmax.max(v);
                r2 = r2.max(dot(d, d));
            }
        }
        if indices.is_empty() || !origin.iter().all(|v| v.is_finite()) {
            return CullVolume::NEVER;
        }
        // Outward by a relative 2^-40 for the f64 rounding, then to f32.
        let slack = |v: f64, s: f64| v + s * E40 * (1.0 + v.abs());
        CullVolume {
            origin,
            n_min: lo.map(|v| down(slack(v, -1.0))),
            n_max: hi.map(|v| up(slack(v, 1.0))),
            d_min: down(slack(dmin, -1.0) - sqrt64(r2) * E40),
            d_max: up(slack(dmax, 1.0) + sqrt64(r2) * E40),
            radius: up(slack(sqrt64(r2), 1.0)),
        }
    }
}

impl NormalCone {
    /// meshoptimizer's cone of the triangles (`meshopt_computeClusterBounds`'
    /// method, in `f64`): the axis is the normalized mean of the unit
    /// normals, the cutoff the sine of the largest angle between a normal
    /// and the axis, and the apex lies behind every triangle's plane
    /// (`apex = centre - axis * max_i ((centre - p_i) . n_i / (axis .
    /// n_i))`, the centre that of the bounding box). [`NormalCone::NEVER`]
    /// where that fails (as `NEVER` for [`CullVolume::from_triangles`]),
    /// or where the cone is wider than meshoptimizer allows (`axis . n <=
    /// 0.1` for some normal).
    pub fn from_triangles(positions: &[Vec3], indices: &[[u32; 3]]) -> NormalCone {
        let mut sum = [0.0f64; 3];
        let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
        for t in unit_triangles(positions, indices) {
            let Some((p, n)) = t else {
                return NormalCone::NEVER;
            };
            for a in 0..3 {
                sum[a] += n[a];
                for q in p {
                    lo[a] = lo[a].min(q[a]);
                    hi[a] = hi[a].max(q[a]);
                }
            }
        }
        let len = sqrt64(dot(sum, sum));
        if indices.is_empty() || !(len > 0.0) {
            return NormalCone::NEVER;
        }
        let axis = sum.map(|v| v / len);
        let centre = [0, 1, 2].map(|a| 0.5 * (lo[a] + hi[a]));
        let (mut mindp, mut maxt) = (1.0f64, 0.0f64);
        for (p, n) in unit_triangles(positions, indices).flatten() {
            let dn = dot(axis, n);
            mindp = mindp.min(dn);
            if dn > 0.1 {
                maxt = maxt.max(dot(sub(centre, p[0]), n) / dn);
            }
        }
        if !(mindp > 0.1) {
            return NormalCone::NEVER;
        }
        let apex = [0, 1, 2].map(|a| (centre[a] - axis[a] * maxt) as f32);
        let cutoff = up(sqrt64(1.0 - mindp * mindp) * (1.0 + E30));
        if !apex.iter().all(|v| v.is_finite()) {
            return NormalCone::NEVER;
        }
        NormalCone {
            apex,
            axis: axis.map(|v| v as f32),
            cutoff,
        }
    }
}

/// A node of a cluster tree (see the module's design note).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ClusterNode {
    /// The clusters `clusters[0]..clusters[1]` it covers.
    pub clusters: [u32; 2],
    /// The index of the node after its subtree (`i + 1` for a leaf).
    pub skip: u32,
    /// The culling volume of all its triangles.
    pub volume: CullVolume,
    /// The normal cone of all its triangles.
    pub cone: NormalCone,
    /// For the size guard ([`Eye::for_frame`]): the least ratio of a
    /// triangle's doubled area to the sum of its edges from its first
    /// vertex, and the least doubled area (object units; see
    /// [`triangle_sizes`]). Zeros never pass the guard.
    pub size: [f32; 2],
    /// A sphere around every vertex of its triangles, about the centre of
    /// their box ([`triangle_sphere`]): the size guard and detail culling
    /// bound the node's projection with it (the culling volume's own
    /// radius is about its origin, which may be a corner of the box, up to
    /// twice as far). [`BoundingSphere::EVERYWHERE`] passes neither.
    pub sphere: BoundingSphere,
}

/// A mesh's clusters and the tree over them, as the offline step wrote
/// them (plain arrays: `static`s in flash, or slices).
#[derive(Clone, Copy, Debug)]
pub struct ClusterSet<'a> {
    /// Contiguous runs of the mesh's triangles, in order, covering all.
    pub clusters: &'a [Cluster],
    /// The tree, in pre-order.
    pub nodes: &'a [ClusterNode],
    /// The positions each cluster uses (indices into the mesh's
    /// positions; shared vertices listed by every cluster that uses
    /// them), or empty for clusters whose vertices are contiguous ranges
    /// of the positions. With a list, every vertex of a drawn cluster is
    /// processed once however many clusters list it; without one, the
    /// vertex cache needs no reset per frame.
    pub vertices: &'a [u32],
}

/// What [`ClusterSet::validate`] found wrong.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum ClusterFault {
    /// The clusters do not tile the mesh's triangles in order, or a
    /// vertex range is reversed or beyond the positions.
    Cluster(usize),
    /// A node whose ranges do not tile the clusters in pre-order.
    Node(usize),
}

impl ClusterSet<'_> {
    /// Checks the structure against a mesh of `triangles` triangles and
    /// `vertices` positions, in O(clusters + nodes) (the entries of a
    /// vertex list are checked as they are used): the clusters tile
    /// `0..triangles` in order, and every traversal (stopping at any node,
    /// or descending into any inner one) meets each cluster exactly once.
    pub fn validate(&self, triangles: usize, vertices: usize) -> Result<(), Error> {
        let err = |f| Err(Error::InvalidClusters(f));
        let mut next = 0usize;
        for (i, c) in self.clusters.iter().enumerate() {
            let [t0, t1] = c.triangles.map(|v| v as usize);
            let [v0, v1] = c.vertices.map(|v| v as usize);
            let limit = if self.vertices.is_empty() {
                vertices
            } else {
                self.vertices.len()
            };
            if t0 != next || t1 < t0 || v1 < v0 || v1 > limit {
                return err(ClusterFault::Cluster(i));
            }
            next = t1;
        }
        if next != triangles {
            return err(ClusterFault::Cluster(self.clusters.len()));
        }
        let n = self.nodes.len();
        let start = |j: usize| -> usize {
            match self.nodes.get(j) {
                Some(node) => node.clusters[0] as usize,
                None => self.clusters.len(),
            }
        };
        if n == 0 {
            return if self.clusters.is_empty() {
                Ok(())
            } else {
                err(ClusterFault::Node(0))
            };
        }
        if start(0) != 0 {
            return err(ClusterFault::Node(0));
        }
        for (i, node) in self.nodes.iter().enumerate() {
            let [a, b] = node.clusters.map(|v| v as usize);
            let skip = node.skip as usize;
            let ok = a < b
                && b <= self.clusters.len()
                && skip > i
                && skip <= n
                && start(skip) == b
                && (skip == i + 1 || start(i + 1) == a);
            if !ok {
                return err(ClusterFault::Node(i));
            }
        }
        Ok(())
    }
}

/// How a node's triangles face the eye.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Facing {
    /// Every triangle would be culled by winding.
    Back,
    /// No triangle would be culled by winding.
    Front,
    /// Not known.
    Mixed,
}

/// Which test a cluster submission runs.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum ClusterTest {
    /// Culling volumes ([`CullVolume`]).
    #[default]
    Volumes,
    /// Normal cones ([`NormalCone`]).
    Cones,
}

/// The settings of a cluster submission.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct ClusterCull {
    /// The back-face test.
    pub test: ClusterTest,
    /// Test the tree top-down, stopping at a wholly back- or front-facing
    /// node; otherwise only the leaves are tested.
    pub hierarchy: bool,
}

/// The eye of a projection in object space, with the sign that makes its
/// facing values positive for the triangles the rasterizer keeps.
///
/// For the rows `x`, `y`, `w` of the model-view-projection matrix `A`
/// (a 3x4 matrix), `E` is the homogeneous point with `A E = 0`: `E_j =
/// (-1)^j det(A without column j)`, `j = 1..4`, in `f64`. By
/// Cauchy-Binet, three points `q_k = (p_k, 1)` project to window
/// coordinates whose doubled signed NDC area is `det[A q0, A q1, A q2] /
/// (w0 w1 w2) = -n . (E_xyz - E_w p0) / (w0 w1 w2)`, `n = (p1 - p0) x (p2 -
/// p0)`. So with `sign` folding in the front face and the cull mode, a
/// triangle in front of the eye is culled by winding exactly when `sign *
/// n . (E_xyz - E_w p) < 0`; clipped pieces lie in the same plane and
/// wind alike.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Eye {
    /// `E_xyz`, scaled so its largest component of `E` is 1 in magnitude.
    pub xyz: [f32; 3],
    /// `E_w`, scaled alike.
    pub w: f32,
    /// `+1` or `-1`.
    pub sign: f32,
    /// `sign * E_w`.
    pub k: f32,
    /// `|E_xyz|_1`.
    xyz1: f32,
    /// `E_xyz / E_w`, the eye as a point, when finite.
    pub point: Option<[f32; 3]>,
    /// The scale of `E`: the cofactors are `big` times the stored values.
    pub(crate) big: f32,
    /// The frame, for the size guard ([`Eye::for_frame`]); `None` for a
    /// geometric eye ([`Eye::from_mvp`], [`Eye::at`]).
    pub(crate) screen: Option<Screen>,
    /// The size guard of a ball around every node tested
    /// ([`Eye::within`]), tried before a node's own.
    outer: Option<WindingFloor>,
}

/// The rows `x`, `y`, `w` of a model-view-projection matrix as linear
/// forms on the object-space point `(p, 1)`, each with `|l_xyz|`, and
/// half the viewport: how object space maps to pixels.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Projection {
    /// Rows `x`, `y`, `w`.
    rows: [Form; 3],
    /// `W / 2`, `H / 2`.
    half: [f32; 2],
}

/// What the size guard needs of a frame: the projection, the clip planes
/// as linear forms (with `|l_xyz|`) and the snapping step.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Screen {
    view: Projection,
    /// Near, far and the four guard-band planes.
    planes: [Form; 6],
    /// Half a subpixel, pixels.
    snap: f32,
}

/// [`Projection::reach`]: over a ball, the least and greatest `w`, bounds
/// on `|x/w|` and `|y/w|`, the most pixels per object length (`m`; `axis`
/// for the pixel `x` and `y` alone).
struct Reach {
    w_min: f32,
    w_max: f32,
    gx: f32,
    gy: f32,
    m: f32,
    axis: [f32; 2],
}

impl Eye {
    /// The eye of `mvp` for a frame culling `cull` with front face
    /// `front`; `None` where no cluster can be culled: `CullMode::None`, a
    /// non-finite matrix, or rows `x`, `y`, `w` of rank below 3.
    pub fn from_mvp(mvp: &Mat4, cull: CullMode, front: FrontFace) -> Option<Eye> {
        let sign = match (cull, front) {
            (CullMode::None, _) => return None,
            (CullMode::Back, FrontFace::Ccw) | (CullMode::Front, FrontFace::Cw) => -1.0f32,
            (CullMode::Back, FrontFace::Cw) | (CullMode::Front, FrontFace::Ccw) => 1.0f32,
        };
        if !mvp.is_finite() {
            return None;
        }
        let r = [0usize, 1, 3].map(|i| {
            let c = &mvp.cols;
            [c[0][i], c[1][i], c[2][i], c[3][i]].map(f64::from)
        });
        let minor = |skip: usize| -> f64 {
            let cols: heapless::Vec<usize, 3> = (0..4).filter(|&c| c != skip).collect();
            let m = |i: usize, j: usize| r[i][cols[j]];
            m(0, 0) * (m(1, 1) * m(2, 2) - m(1, 2) * m(2, 1))
                - m(0, 1) * (m(1, 0) * m(2, 2) - m(1, 2) * m(2, 0))
                + m(0, 2) * (m(1, 0) * m(2, 1) - m(1, 1) * m(2, 0))
        };
        // (-1)^j for j = 1..4: -, +, -, +.
        let e = [-minor(0), minor(1), -minor(2), minor(3)];
        let big = e.iter().fold(0.0f64, |a, v| a.max(v.abs()));
        if !(big > 0.0) || !big.is_finite() {
            return None;
        }
        let e = e.map(|v| (v / big) as f32);
        let xyz = [e[0], e[1], e[2]];
        let point = if e[3] != 0.0 {
            let p = xyz.map(|v| v / e[3]);
            p.iter().all(|v| v.is_finite()).then_some(p)
        } else {
            None
        };
        Some(Eye {
            xyz,
            w: e[3],
            sign,
            k: sign * e[3],
            xyz1: xyz.iter().map(|v| v.abs()).sum(),
            point,
            big: big as f32,
            screen: None,
            outer: None,
        })
    }

    /// The eye [`Submit::submit_clusters`](crate::Submit::submit_clusters)
    /// uses for a frame of `config` at `S` subpixel bits: that of
    /// [`Eye::from_mvp`] with the size guard, which culls a node only
    /// where every triangle's projected area exceeds what snapping (half a
    /// subpixel) and rounding can change, so no skipped triangle can snap
    /// to the other winding: then the frame is byte-identical to
    /// per-triangle culling. `None` where that cannot be set up.
    pub fn for_frame<const S: u32>(mvp: &Mat4, config: &crate::Config) -> Option<Eye> {
        let mut e = Eye::from_mvp(mvp, config.cull, config.front_face)?;
        let screen = Screen::new::<S>(mvp, config)?;
        if !e.big.is_finite() {
            return None;
        }
        e.screen = Some(screen);
        Some(e)
    }

    /// This eye with the size guard of the ball `sphere` found once, for
    /// a frame's eye ([`Eye::for_frame`]; others are returned as they
    /// are): a back-facing node is then first tried against that ball,
    /// and its own sphere's guard is found only where the ball's fails.
    /// Any ball around a node's triangles bounds what the guard needs of
    /// them (their `w`, pixels per object length and rounding), so a node
    /// it passes passes with its own sphere, and the decisions are at
    /// least those without it: for a `sphere` around every vertex of the
    /// nodes tested (a mesh's bounding sphere, as
    /// [`Submit::submit_clusters`](crate::Submit::submit_clusters) passes
    /// its mesh's bounds) the frame is still the per-triangle one. The
    /// guard of each back-facing node is most of the cost of a tree walk;
    /// this is a few multiplications instead where the ball is not much
    /// larger than the mesh on screen.
    pub fn within(mut self, sphere: &BoundingSphere) -> Eye {
        let c = [sphere.center.x, sphere.center.y, sphere.center.z];
        if let Some(sc) = &self.screen {
            self.outer = sc.winding_floor(c, sphere.radius, self.big);
        }
        self
    }
}

/// A linear form on `(p, 1)` with `|l_xyz|` and `|l|_1`, both found once
/// a frame (the size guard of every node uses them).
#[derive(Clone, Copy, Debug, PartialEq)]
struct Form {
    l: [f32; 4],
    /// `|l_xyz|`.
    n: f32,
    /// `|l|_1`.
    l1: f32,
}

impl Form {
    fn new(l: [f32; 4]) -> Form {
        Form {
            l,
            n: crate::math::fx::sqrt(l[0] * l[0] + l[1] * l[1] + l[2] * l[2]),
            l1: l.iter().map(|v| v.abs()).sum::<f32>(),
        }
    }

    /// Whether the form and its norm are finite.
    fn finite(&self) -> bool {
        self.l.iter().all(|v| v.is_finite()) && self.n.is_finite()
    }

    /// Its value at `p`.
    fn at(&self, p: [f32; 3]) -> f32 {
        let l = &self.l;
        l[0] * p[0] + l[1] * p[1] + l[2] * p[2] + l[3]
    }

    /// How far it can range from its value at the centre over a ball of
    /// `radius`, with the `f32` rounding of its evaluation (`c1`:
    /// `|origin|_1 + radius + 1`).
    fn spread(&self, radius: f32, c1: f32) -> f32 {
        self.n * radius * (1.0 + ROUNDING) + ROUNDING * self.l1 * c1
    }
}

/// `|origin|_1 + radius + 1`: a bound on `|(p, 1)|_inf` over the ball, for
/// rounding bounds.
fn ball_c1(origin: [f32; 3], radius: f32) -> f32 {
    origin.iter().map(|v| v.abs()).sum::<f32>() + radius + 1.0
}

impl Projection {
    /// The projection of a frame of `config` drawn with `mvp`; `None` for
    /// a non-finite matrix. Not inlined: [`Detail::for_frame`] is inlined
    /// into every submission, where detail culling is mostly off.
    #[inline(never)]
    fn new(mvp: &Mat4, config: &crate::Config) -> Option<Projection> {
        let c = &mvp.cols;
        let row = |i: usize| [c[0][i], c[1][i], c[2][i], c[3][i]];
        let view = Projection {
            rows: [row(0), row(1), row(3)].map(Form::new),
            half: [config.width as f32 * 0.5, config.height as f32 * 0.5],
        };
        view.rows.iter().all(Form::finite).then_some(view)
    }

    /// How the projection behaves over the ball of `radius` around
    /// `origin` (object units), with the `f32` rounding of these bounds
    /// allowed for; `None` unless the whole ball has `w > 0`.
    fn reach(&self, origin: [f32; 3], radius: f32) -> Option<Reach> {
        self.reach_c1(origin, radius, ball_c1(origin, radius))
    }

    /// [`Projection::reach`] with `c1` ([`ball_c1`]) found by the caller.
    /// Inlined, so that the size guard ([`Screen::winding_floor`]), which
    /// has no use for `axis`, does not divide for it.
    #[inline(always)]
    fn reach_c1(&self, origin: [f32; 3], radius: f32, c1: f32) -> Option<Reach> {
        // A form's range over the ball: centre value +- spread.
        let [rx, ry, rw] = &self.rows;
        let (nx, ny, nw) = (rx.n, ry.n, rw.n);
        let (wc, wr) = (rw.at(origin), rw.spread(radius, c1));
        let (w_min, w_max) = (wc - wr, wc + wr);
        if !(w_min > 0.0) {
            return None;
        }
        // |x/w| and |y/w| over the ball.
        let gx = (rx.at(origin).abs() + rx.spread(radius, c1)) / w_min;
        let gy = (ry.at(origin).abs() + ry.spread(radius, c1)) / w_min;
        let [hw, hh] = self.half;
        let (mx, my) = (hw * (nx + gx * nw), hh * (ny + gy * nw));
        let m = crate::math::fx::sqrt(mx * mx + my * my) * (1.0 + ROUNDING) / w_min;
        let axis = [mx, my].map(|v| v * (1.0 + ROUNDING) / w_min);
        Some(Reach {
            w_min,
            w_max,
            gx,
            gy,
            m,
            axis,
        })
    }
}

impl Screen {
    /// The screen of a frame of `config` at `S` subpixel bits drawn with
    /// `mvp`; `None` for a non-finite matrix.
    fn new<const S: u32>(mvp: &Mat4, config: &crate::Config) -> Option<Screen> {
        let view = Projection::new(mvp, config)?;
        let (gx, gy) = crate::fixed::guard_band_ndc::<S>(config.width, config.height);
        let c = &mvp.cols;
        let row = |i: usize| [c[0][i], c[1][i], c[2][i], c[3][i]];
        let (rx, ry, rz, rw) = (row(0), row(1), row(2), row(3));
        let comb = |a: [f32; 4], sa: f32, b: [f32; 4], sb: f32| -> [f32; 4] {
            core::array::from_fn(|j| sa * a[j] + sb * b[j])
        };
        let planes = [
            comb(rw, 1.0, rz, 1.0),
            comb(rw, 1.0, rz, -1.0),
            comb(rw, gx, rx, -1.0),
            comb(rw, gx, rx, 1.0),
            comb(rw, gy, ry, -1.0),
            comb(rw, gy, ry, 1.0),
        ]
        .map(Form::new);
        let screen = Screen {
            view,
            planes,
            snap: 1.0 / (1u32 << (S + 1)) as f32,
        };
        screen.planes.iter().all(Form::finite).then_some(screen)
    }

    /// Whether the ball of `radius` around `origin` lies inside near, far
    /// and the guard band (`c1`: [`ball_c1`]).
    fn contains_c1(&self, origin: [f32; 3], radius: f32, c1: f32) -> bool {
        self.planes
            .iter()
            .all(|p| p.at(origin) > p.spread(radius, c1))
    }

    /// Whether every triangle of a node (within `radius` of `origin`;
    /// least doubled area `a_min`, least ratio `q` of doubled area to the
    /// sum of two edges, object units) whose facing values are at least
    /// `phi` (for unit normals and `E` scaled by `big`) keeps its winding
    /// when snapped. The node must lie inside near, far and the guard band
    /// (so no triangle is clipped) and in front of the eye (`w_min > 0`).
    /// With `X = phi big (W/2)(H/2) / w_max^3` (pixel area per object
    /// area, at least, since `2 A_ndc = |n . (E_xyz - E_w p)| / (w0 w1
    /// w2)`), `M` the most pixels per object length (from `|d(x/w)/dp| <=
    /// (|r_x| + |x/w| |r_w|) / w` with `|x/w|` bounded over the node) and
    /// `rho` half a subpixel plus the `f32` rounding of transform and
    /// projection, it demands `X q > 4 sqrt 2 rho M` and `X a_min > 16
    /// rho^2`: then the snapped doubled area `2A'` of every triangle keeps
    /// its sign, as `|2A' - 2A| <= 2 rho (|e1|_1 + |e2|_1) + 8 rho^2 <=
    /// 2 sqrt 2 rho M (|e1| + |e2|) + 8 rho^2 < |2A|`.
    fn keeps_winding(
        &self,
        origin: [f32; 3],
        radius: f32,
        size: [f32; 2],
        phi: f32,
        big: f32,
    ) -> bool {
        self.winding_floor(origin, radius, big)
            .is_some_and(|f| f.keeps(size, phi))
    }

    /// What [`Screen::keeps_winding`] asks of the ball of `radius` around
    /// `origin`, found once for many facing values and sizes; `None` where
    /// it holds for none (the ball is not inside near, far and the guard
    /// band, or not wholly in front of the eye).
    pub(crate) fn winding_floor(
        &self,
        origin: [f32; 3],
        radius: f32,
        big: f32,
    ) -> Option<WindingFloor> {
        let c1 = ball_c1(origin, radius);
        if !self.contains_c1(origin, radius, c1) {
            return None;
        }
        let Reach {
            w_min,
            w_max,
            gx,
            gy,
            m,
            ..
        } = self.view.reach_c1(origin, radius, c1)?;
        let [hw, hh] = self.view.half;
        let [rx, ry, rw] = &self.view.rows;
        // Rounding: the transform (3 roundings a row, 2^-22 relative to
        // |row|_1 |(p, 1)|_inf, through the division by w) and NDC to
        // pixels (a few ulps of the pixel coordinate).
        let transform = (hw * (rx.l1 + gx * rw.l1) + hh * (ry.l1 + gy * rw.l1)) * c1 / w_min;
        let pixels = hw * (1.0 + gx) + hh * (1.0 + gy);
        let rho = self.snap + (transform + pixels) / 1_048_576.0;
        Some(WindingFloor {
            big,
            half: [hw, hh],
            w3: w_max * w_max * w_max,
            w_min,
            need: [
                4.0 * core::f32::consts::SQRT_2 * rho * m * (1.0 + MARGIN),
                16.0 * rho * rho,
            ],
        })
    }
}

/// [`Screen::winding_floor`]: the size guard of one ball, for any facing
/// value and triangle sizes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct WindingFloor {
    big: f32,
    half: [f32; 2],
    /// `w_max^3` over the ball.
    w3: f32,
    /// The least `w` over the ball (positive).
    pub(crate) w_min: f32,
    /// What `X q` and `X a_min` must exceed.
    need: [f32; 2],
}

impl WindingFloor {
    /// Whether triangles of the ball with sizes `size` (as
    /// [`ClusterNode::size`]) and facing values at least `phi` keep their
    /// winding when snapped (see [`Screen::keeps_winding`]).
    pub(crate) fn keeps(&self, size: [f32; 2], phi: f32) -> bool {
        let [q, a_min] = size;
        let [hw, hh] = self.half;
        let x = phi * self.big * hw * hh / self.w3;
        x * q > self.need[0] && x * a_min > self.need[1]
    }
}

impl Eye {
    /// An eye at the object-space point `p` of a projection that does not
    /// mirror, culling back faces with counter-clockwise front faces (the
    /// defaults): for offline estimates such as a node's culling
    /// probability. `None` for a non-finite point.
    pub fn at(p: [f32; 3]) -> Option<Eye> {
        if !p.iter().all(|v| v.is_finite()) {
            return None;
        }
        Some(Eye {
            xyz: p,
            w: 1.0,
            sign: 1.0,
            k: 1.0,
            xyz1: p.iter().map(|v| v.abs()).sum(),
            point: Some(p),
            big: 1.0,
            screen: None,
            outer: None,
        })
    }
}

impl ClusterNode {
    /// How the node's triangles face `e` under `test`: cones tell only
    /// back-facing from not.
    /// With an eye for a frame ([`Eye::for_frame`]) a back-facing node
    /// is reported only where the size guard holds as well.
    pub fn facing(&self, e: &Eye, test: ClusterTest) -> Facing {
        let (f, phi) = match test {
            ClusterTest::Volumes => self.volume.facing_bound(e),
            ClusterTest::Cones => match self.cone.back_bound(e) {
                Some(phi) => (Facing::Back, phi),
                None => (Facing::Mixed, 0.0),
            },
        };
        match (f, &e.screen) {
            (Facing::Back, Some(sc)) => {
                if e.outer.is_some_and(|f| f.keeps(self.size, phi)) {
                    return Facing::Back;
                }
                let b = &self.sphere;
                let centre = [b.center.x, b.center.y, b.center.z];
                let sized = sc.keeps_winding(centre, b.radius, self.size, phi, e.big);
                if sized {
                    Facing::Back
                } else {
                    Facing::Mixed
                }
            }
            (f, _) => f,
        }
    }
}

/// Detail culling for a frame (lossy, [`Config::detail`](crate::Config::detail)
/// pixels): a sphere wholly in front of the eye (`w > 0`) is dropped
/// where its projection provably fits in a square less than `detail`
/// pixels wide and high. The bound is the sphere's radius times the most
/// pixels per object length along each axis over the sphere (the
/// derivative of `x/w` and `y/w`, bounded as the size guard bounds it,
/// with `f32` rounding allowed for), so every point of a dropped sphere,
/// and every vertex of a dropped node, projects within that square about
/// the centre's projection. [`BoundingSphere::EVERYWHERE`] (no bounds)
/// is never dropped.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Detail {
    view: Projection,
    pixels: f32,
    /// The frame's matrix, for the centre of [`Detail::screen_box`].
    mvp: Mat4,
}

impl Detail {
    /// Detail culling for a frame of `config` drawn with `mvp`; `None`
    /// where `config.detail` is 0 (off) or the matrix is not finite.
    pub fn for_frame(mvp: &Mat4, config: &crate::Config) -> Option<Detail> {
        if config.detail == 0 {
            return None;
        }
        Some(Detail {
            view: Projection::new(mvp, config)?,
            pixels: f32::from(config.detail),
            mvp: *mvp,
        })
    }

    /// An upper bound on the width and height, in pixels, of the
    /// projection of `sphere`; `None` where it is not wholly in front of
    /// the eye or not finite.
    pub fn extent(&self, sphere: &BoundingSphere) -> Option<f32> {
        let c = [sphere.center.x, sphere.center.y, sphere.center.z];
        let r = sphere.radius;
        if !(r >= 0.0) || !c.iter().all(|v| v.is_finite()) {
            return None;
        }
        let [ax, ay] = self.view.reach(c, r)?.axis;
        let d = 2.0 * r * crate::math::fx::max(ax, ay);
        d.is_finite().then_some(d)
    }

    /// Whether `sphere` is dropped.
    pub fn drops(&self, sphere: &BoundingSphere) -> bool {
        self.extent(sphere).is_some_and(|d| d < self.pixels)
    }

    /// The box drawn in place of a dropped `sphere` when the mesh's
    /// attributes give a fill ([`Attributes::detail_fill`]): a
    /// screen-aligned rectangle about the projection of the centre, at the
    /// centre's depth, as wide and as high as the bound of
    /// [`Detail::extent`] along each axis (so it covers the sphere's
    /// projection). Four clip-space corners, counter-clockwise in NDC (y
    /// up); `None` where the sphere is not wholly in front of the eye or a
    /// corner is not finite.
    ///
    /// [`Attributes::detail_fill`]: crate::Attributes::detail_fill
    pub fn screen_box(&self, sphere: &BoundingSphere) -> Option<[Vec4; 4]> {
        let c = [sphere.center.x, sphere.center.y, sphere.center.z];
        let r = sphere.radius;
        if !(r >= 0.0) || !c.iter().all(|v| v.is_finite()) {
            return None;
        }
        let [ax, ay] = self.view.reach(c, r)?.axis;
        let p = self.mvp.transform_point(sphere.center);
        if !(p.is_finite() && p.w > 0.0) {
            return None;
        }
        // Half extents in pixels, to clip units at the centre's `w`.
        let [hw, hh] = self.view.half;
        let (dx, dy) = (r * ax / hw * p.w, r * ay / hh * p.w);
        let corner = |sx: f32, sy: f32| Vec4::new(p.x + sx * dx, p.y + sy * dy, p.z, p.w);
        let quad = [
            corner(-1.0, -1.0),
            corner(1.0, -1.0),
            corner(1.0, 1.0),
            corner(-1.0, 1.0),
        ];
        quad.iter().all(|v| v.is_finite()).then_some(quad)
    }
}

/// What a traversal decided for a run of clusters.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Visit {
    /// Draw clusters `a..b`.
    Draw(usize, usize),
    /// Skip clusters `a..b` (back-facing), at a leaf (`false`) or an inner
    /// node (`true`).
    Cull(usize, usize, bool),
    /// Drop clusters `a..b`, those of node `.2` (an index into
    /// [`ClusterSet::nodes`]): too small on screen ([`Detail`]).
    Detail(usize, usize, usize),
}

impl ClusterSet<'_> {
    /// The decisions [`Submit::submit_clusters`](crate::Submit::submit_clusters)
    /// makes, in cluster order, for a set that passed
    /// [`ClusterSet::validate`] (on any other set: some decisions, never a
    /// panic). With neither an eye nor detail culling everything is drawn.
    pub fn visit(
        &self,
        eye: Option<&Eye>,
        detail: Option<&Detail>,
        cull: ClusterCull,
        f: impl FnMut(Visit),
    ) {
        traverse(self, eye, detail, cull, f);
    }
}

/// Walks a set, calling `f` for every decision in cluster order. Detail
/// is tested before facing; with detail culling on, a wholly
/// front-facing inner node is still descended, so which clusters are
/// dropped does not depend on the tree.
pub(crate) fn traverse(
    set: &ClusterSet<'_>,
    eye: Option<&Eye>,
    detail: Option<&Detail>,
    cull: ClusterCull,
    mut f: impl FnMut(Visit),
) {
    if eye.is_none() && detail.is_none() {
        f(Visit::Draw(0, set.clusters.len()));
        return;
    }
    let mut i = 0usize;
    while let Some(node) = set.nodes.get(i) {
        let [a, b] = node.clusters.map(|v| v as usize);
        // `max`: progress even on a set that was not validated.
        let skip = (node.skip as usize).max(i + 1);
        let leaf = skip == i + 1;
        if !leaf && !cull.hierarchy {
            i += 1;
            continue;
        }
        if detail.is_some_and(|d| d.drops(&node.sphere)) {
            f(Visit::Detail(a, b, i));
            i = skip;
            continue;
        }
        match eye.map_or(Facing::Mixed, |e| node.facing(e, cull.test)) {
            Facing::Back => {
                f(Visit::Cull(a, b, !leaf));
                i = skip;
            }
            Facing::Front | Facing::Mixed if leaf => {
                f(Visit::Draw(a, b));
                i = skip;
            }
            Facing::Front if detail.is_none() => {
                f(Visit::Draw(a, b));
                i = skip;
            }
            Facing::Front | Facing::Mixed => i += 1,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::{Mat4, Vec3};

    fn camera() -> Mat4 {
        Mat4::perspective(1.0, 1.0, 0.5, 50.0)
            * Mat4::look_at(
                Vec3::new(0.0, 0.0, 5.0),
                Vec3::new(0.0, 0.0, 0.0),
                Vec3::new(0.0, 1.0, 0.0),
            )
    }

    /// A volume of one triangle in the plane z = 0 with normal `nz`.
    fn plane(nz: f32) -> CullVolume {
        CullVolume {
            origin: [0.0; 3],
            n_min: [0.0, 0.0, nz],
            n_max: [0.0, 0.0, nz],
            d_min: 0.0,
            d_max: 0.0,
            radius: 1.0,
        }
    }

    #[test]
    fn the_eye_is_the_camera_position() {
        let e = Eye::from_mvp(&camera(), CullMode::Back, FrontFace::Ccw).unwrap();
        let p = e.point.unwrap();
        assert!((p[0]).abs() < 1e-5 && (p[1]).abs() < 1e-5 && (p[2] - 5.0).abs() < 1e-4);
        assert!(e.k > 0.0, "a camera in front of the projection has k > 0");
        // The same facing values as the eye put there directly.
        let at = Eye::at([0.0, 0.0, 5.0]).unwrap();
        for nz in [1.0, -1.0] {
            assert_eq!(plane(nz).facing(&e), plane(nz).facing(&at));
        }
    }

    #[test]
    fn a_plane_facing_the_eye_is_front_and_away_is_back() {
        let e = Eye::from_mvp(&camera(), CullMode::Back, FrontFace::Ccw).unwrap();
        assert_eq!(plane(1.0).facing(&e), Facing::Front);
        assert_eq!(plane(-1.0).facing(&e), Facing::Back);
        let cw = Eye::from_mvp(&camera(), CullMode::Back, FrontFace::Cw).unwrap();
        assert_eq!(plane(1.0).facing(&cw), Facing::Back);
        let front = Eye::from_mvp(&camera(), CullMode::Front, FrontFace::Ccw).unwrap();
        assert_eq!(plane(1.0).facing(&front), Facing::Back);
        assert!(Eye::from_mvp(&camera(), CullMode::None, FrontFace::Ccw).is_none());
    }

    #[test]
    fn an_edge_on_plane_is_mixed() {
        // The eye at z = 5 lies in the plane x = 0 of normal (1, 0, 0).
        let e = Eye::from_mvp(&camera(), CullMode::Back, FrontFace::Ccw).unwrap();
        let v = CullVolume {
            n_min: [1.0, 0.0, 0.0],
            n_max: [1.0, 0.0, 0.0],
            ..plane(0.0)
        };
        assert_eq!(v.facing(&e), Facing::Mixed);
        assert_eq!(CullVolume::NEVER.facing(&e), Facing::Mixed);
    }

    #[test]
    fn a_cone_pointing_away_culls() {
        let e = Eye::from_mvp(&camera(), CullMode::Back, FrontFace::Ccw).unwrap();
        let away = NormalCone {
            apex: [0.0; 3],
            axis: [0.0, 0.0, -1.0],
            cutoff: 0.5,
        };
        assert!(away.back_facing(&e));
        let toward = NormalCone {
            axis: [0.0, 0.0, 1.0],
            ..away
        };
        assert!(!toward.back_facing(&e));
        assert!(!NormalCone::NEVER.back_facing(&e));
    }

    fn node(a: u32, b: u32, skip: u32) -> ClusterNode {
        ClusterNode {
            clusters: [a, b],
            skip,
            volume: CullVolume::NEVER,
            cone: NormalCone::NEVER,
            size: [0.0; 2],
            sphere: BoundingSphere::EVERYWHERE,
        }
    }

    #[test]
    fn validation_refuses_trees_that_do_not_tile() {
        let clusters = [
            Cluster {
                triangles: [0, 2],
                vertices: [0, 4],
            },
            Cluster {
                triangles: [2, 3],
                vertices: [2, 5],
            },
        ];
        let good = [node(0, 2, 3), node(0, 1, 2), node(1, 2, 3)];
        let ok = ClusterSet {
            clusters: &clusters,
            nodes: &good,
            vertices: &[],
        };
        assert_eq!(ok.validate(3, 5), Ok(()));
        assert_eq!(
            ok.validate(4, 5),
            Err(Error::InvalidClusters(ClusterFault::Cluster(2)))
        );
        assert_eq!(
            ok.validate(3, 4),
            Err(Error::InvalidClusters(ClusterFault::Cluster(1)))
        );
        let bad_trees: [&[ClusterNode]; 5] = [
            &[node(0, 2, 3), node(0, 1, 2), node(0, 2, 3)],
            &[node(0, 2, 2), node(1, 2, 3)],
            &[node(0, 1, 1), node(0, 2, 2)],
            &[node(0, 1, 0)],
            &[node(1, 2, 1)],
        ];
        for nodes in bad_trees {
            let s = ClusterSet {
                clusters: &clusters,
                nodes,
                vertices: &[],
            };
            assert!(s.validate(3, 5).is_err(), "{nodes:?}");
        }
    }

    #[test]
    fn detail_drops_small_far_spheres_only() {
        let mut config = crate::Config::new(240, 240);
        let mvp = camera();
        assert!(Detail::for_frame(&mvp, &config).is_none(), "0 is off");
        config.detail = 3;
        let d = Detail::for_frame(&mvp, &config).unwrap();
        // The camera is at z = 5 looking at the origin: along x, about
        // the origin, a unit moves x/w by `r_x[0] / w` (read from the
        // matrix itself, so the approximate `tan` of the micromath
        // backend changes nothing here), times 120 px.
        let c = &mvp.cols;
        let px_per_unit = 120.0 * c[0][0] / c[3][3];
        let ball = |x: f32, radius: f32| BoundingSphere {
            center: Vec3::new(x, 0.0, 0.0),
            radius,
        };
        let r = 1.0 / px_per_unit; // 2 px across at the origin
        let e = d.extent(&ball(0.0, r)).unwrap();
        assert!((2.0..2.0 * 1.01).contains(&e), "{e}");
        // Off the axis the bound grows (|x/w| enters the derivative).
        assert!(d.extent(&ball(1.0, r)).unwrap() > e);
        assert!(d.drops(&ball(0.0, r)), "2 px is below 3");
        assert!(!d.drops(&ball(0.0, 1.5 * r)), "3 px is kept");
        assert!(!d.drops(&ball(0.0, 3.0 * r)), "6 px is kept");
        // No bounds, a sphere reaching behind the eye, NaN: never dropped.
        for b in [
            BoundingSphere::EVERYWHERE,
            BoundingSphere {
                center: Vec3::new(0.0, 0.0, 5.0),
                radius: r,
            },
            ball(f32::NAN, r),
            ball(0.0, -1.0),
            ball(0.0, f32::NAN),
        ] {
            assert!(!d.drops(&b), "{b:?}");
        }
    }

    /// The box drawn for a dropped sphere: about the centre's projection,
    /// at its depth, as wide as the extent along each axis, wound
    /// counter-clockwise; none for the spheres never dropped (no bounds,
    /// reaching behind the eye, NaN, a negative or infinite radius).
    #[test]
    fn detail_box_covers_the_extent_about_the_centre() {
        let mut config = crate::Config::new(240, 120);
        config.detail = 3;
        let mvp = camera();
        let d = Detail::for_frame(&mvp, &config).unwrap();
        let ball = |x: f32, y: f32, radius: f32| BoundingSphere {
            center: Vec3::new(x, y, 0.0),
            radius,
        };
        for b in [ball(0.0, 0.0, 0.01), ball(1.0, -0.5, 0.02)] {
            let q = d.screen_box(&b).unwrap();
            let p = mvp.transform_point(b.center);
            // Pixels: x = (1 + x/w) * 120, y = (1 - y/w) * 60.
            let px = q.map(|v| [(1.0 + v.x / v.w) * 120.0, (1.0 - v.y / v.w) * 60.0]);
            let (cx, cy) = ((1.0 + p.x / p.w) * 120.0, (1.0 - p.y / p.w) * 60.0);
            let (w, h) = (px[1][0] - px[0][0], px[0][1] - px[3][1]);
            let [ax, ay] = d
                .view
                .reach([b.center.x, b.center.y, 0.0], b.radius)
                .unwrap()
                .axis;
            assert!((w - 2.0 * b.radius * ax).abs() < 1e-3, "{w}");
            assert!((h - 2.0 * b.radius * ay).abs() < 1e-3, "{h}");
            assert!(d.extent(&b).unwrap() >= w.max(h) * 0.9999);
            assert!(((px[0][0] + px[1][0]) / 2.0 - cx).abs() < 1e-3);
            assert!(((px[0][1] + px[3][1]) / 2.0 - cy).abs() < 1e-3);
            assert!(
                q.iter().all(|v| v.z == p.z && v.w == p.w),
                "at the centre's depth"
            );
            // Counter-clockwise in NDC (y up): a positive area.
            let ndc = q.map(|v| [v.x / v.w, v.y / v.w]);
            let area = (ndc[1][0] - ndc[0][0]) * (ndc[2][1] - ndc[0][1])
                - (ndc[2][0] - ndc[0][0]) * (ndc[1][1] - ndc[0][1]);
            assert!(area > 0.0, "{area}");
        }
        for b in [
            BoundingSphere::EVERYWHERE,
            BoundingSphere {
                center: Vec3::new(0.0, 0.0, 5.0),
                radius: 0.01,
            },
            ball(f32::NAN, 0.0, 0.01),
            ball(0.0, 0.0, -1.0),
            ball(0.0, 0.0, f32::NAN),
            ball(0.0, 0.0, f32::INFINITY),
            ball(f32::MAX, 0.0, 0.01),
        ] {
            assert!(d.screen_box(&b).is_none(), "{b:?}");
        }
    }
}
