//! The offline step of cluster culling: a mesh split into clusters, with a
//! tree over them, as the core's [`ClusterSet`] reads it.
//!
//! Design note: meshoptimizer (`meshopt::build_meshlets`) splits the mesh
//! into meshlets of at most `max_vertices` vertices and `max_triangles`
//! triangles, in a spatially coherent order. Every meshlet becomes one
//! [`Cluster`], its triangles a contiguous run. Its vertices are either
//! listed (shared, the default: the source's positions, a vertex list
//! entry per meshlet vertex; a vertex is processed once a frame if any
//! cluster using it is drawn) or copied (every cluster its own contiguous
//! range of positions, border vertices repeated: no list, no per-frame
//! reset of the cache, for firmware). A culled cluster's own vertices
//! are never transformed. Each node's culling volume takes as its local origin
//! the centre or one of the eight corners of its box, whichever gives the
//! largest `d_min` (the lecture's choice); its cone is meshoptimizer's.
//!
//! The tree follows the lecture's cost model: a node `A` of `n_A`
//! triangles is culled with probability `P(A)`, estimated as the fraction
//! of [`SAMPLES`] fixed eye positions, spread uniformly over the cube `U`
//! of side six bounding radii around the mesh, from which its culling
//! volume reports it back-facing (a Monte Carlo estimate of `Vol(C) /
//! Vol(U)`, the volume `C` being the eyes the test culls from). Passes over
//! the list of subtrees merge neighbours `A`, `B` into a parent `C` where
//! `P(C) > (P(A) n_A + P(B) n_B - t/r) / (n_A + n_B)`, with `t/r` the
//! cost of one node test in units of one triangle's processing, until a
//! pass merges nothing. What remains is a forest, written in pre-order.

use microraster::cull::{CullVolume, Eye, Facing, NormalCone};
use microraster::{Cluster, ClusterNode, ClusterSet, Vec3};

/// Eye positions sampled per culling-probability estimate.
pub const SAMPLES: usize = 1024;

/// How to build the clusters.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ClusterOptions {
    /// Vertices per meshlet, at most (meshoptimizer: up to 255).
    pub max_vertices: usize,
    /// Triangles per meshlet, at most (meshoptimizer: up to 512, a
    /// multiple of 4).
    pub max_triangles: usize,
    /// meshoptimizer's `cone_weight`: 0 clusters by position alone, up to
    /// 1 favours tight normal cones.
    pub cone_weight: f32,
    /// The cost of a node test over that of one triangle (`t/r`); a
    /// negative value builds no tree (leaves only).
    pub t_over_r: f64,
    /// Share vertices between clusters through a vertex list (the
    /// source's positions, each processed once a frame) instead of giving
    /// every cluster its own copies (contiguous ranges, no list).
    pub shared: bool,
}

impl Default for ClusterOptions {
    fn default() -> Self {
        ClusterOptions {
            max_vertices: 64,
            max_triangles: 12,
            cone_weight: 1.0,
            t_over_r: 1.0,
            shared: true,
        }
    }
}

/// A mesh rebuilt as clusters, owning the arrays a [`ClusterSet`] borrows.
#[derive(Clone, Debug, Default)]
pub struct ClusteredMesh {
    /// Positions: the source's (shared), or each cluster's a contiguous
    /// range (border vertices repeated).
    pub positions: Vec<Vec3>,
    /// Triangles, each cluster's a contiguous run.
    pub indices: Vec<[u32; 3]>,
    /// For each position, the source position it copies.
    pub source_vertex: Vec<u32>,
    /// For each triangle, the source triangle it is.
    pub source_triangle: Vec<u32>,
    /// The clusters.
    pub clusters: Vec<Cluster>,
    /// The tree, in pre-order.
    pub nodes: Vec<ClusterNode>,
    /// With shared vertices: the positions each cluster uses.
    pub vertex_list: Vec<u32>,
}

impl ClusteredMesh {
    /// The set the core reads.
    pub fn set(&self) -> ClusterSet<'_> {
        ClusterSet {
            clusters: &self.clusters,
            nodes: &self.nodes,
            vertices: &self.vertex_list,
        }
    }

    /// The bytes of the precomputed culling data (clusters and nodes, as
    /// laid out in memory).
    pub fn data_bytes(&self) -> usize {
        std::mem::size_of_val(self.clusters.as_slice())
            + std::mem::size_of_val(self.nodes.as_slice())
    }

    /// The number of inner (non-leaf) nodes.
    pub fn inner_nodes(&self) -> usize {
        (0..self.nodes.len())
            .filter(|&i| self.nodes[i].skip as usize != i + 1)
            .count()
    }
}

/// Splits `positions`/`indices` into clusters and builds the tree.
/// Triangles with an index out of range are dropped (the caller's mesh
/// loader reports them).
pub fn build(
    positions: &[Vec3],
    indices: &[[u32; 3]],
    opts: &ClusterOptions,
) -> Result<ClusteredMesh, String> {
    let n = positions.len();
    let flat: Vec<u32> = indices
        .iter()
        .filter(|t| t.iter().all(|&k| (k as usize) < n))
        .flatten()
        .copied()
        .collect();
    let raw: Vec<[f32; 3]> = positions.iter().map(|p| [p.x, p.y, p.z]).collect();
    let bytes = meshopt::typed_to_bytes(&raw);
    let adapter = meshopt::VertexDataAdapter::new(bytes, 12, 0).map_err(|e| e.to_string())?;
    let max_t = opts.max_triangles.clamp(4, 512) / 4 * 4;
    let max_v = opts.max_vertices.clamp(3, 255);
    let meshlets = meshopt::build_meshlets(&flat, &adapter, max_v, max_t, opts.cone_weight);
    // Source triangle of each flat triple, to map meshlet triangles back.
    let mut tri_of: std::collections::HashMap<[u32; 3], Vec<u32>> = Default::default();
    for (i, t) in indices.iter().enumerate() {
        if t.iter().all(|&k| (k as usize) < n) {
            tri_of.entry(canonical(*t)).or_default().push(i as u32);
        }
    }
    let mut out = ClusteredMesh::default();
    if opts.shared {
        out.positions = positions.to_vec();
        out.source_vertex = (0..positions.len() as u32).collect();
    }
    for m in meshlets.iter() {
        let base = if opts.shared {
            out.vertex_list.len()
        } else {
            out.positions.len()
        } as u32;
        let t0 = out.indices.len() as u32;
        for &v in m.vertices {
            if opts.shared {
                out.vertex_list.push(v);
            } else {
                out.positions.push(positions[v as usize]);
                out.source_vertex.push(v);
            }
        }
        for t in m.triangles.chunks_exact(3) {
            let local = [t[0], t[1], t[2]].map(u32::from);
            if opts.shared {
                out.indices.push(local.map(|k| m.vertices[k as usize]));
            } else {
                out.indices.push(local.map(|k| base + k));
            }
            let src = local.map(|k| m.vertices[k as usize]);
            let id = tri_of
                .get_mut(&canonical(src))
                .and_then(|v| v.pop())
                .ok_or("meshoptimizer returned a triangle not in the mesh")?;
            out.source_triangle.push(id);
        }
        let end = if opts.shared {
            out.vertex_list.len()
        } else {
            out.positions.len()
        } as u32;
        out.clusters.push(Cluster {
            triangles: [t0, out.indices.len() as u32],
            vertices: [base, end],
        });
    }
    if opts.shared {
        reorder_by_first_use(&mut out);
    }
    out.nodes = tree(&out, opts.t_over_r);
    out.set()
        .validate(out.indices.len(), out.positions.len())
        .map_err(|e| e.to_string())?;
    Ok(out)
}

/// Renumbers the positions in the order the vertex list first uses them
/// (unused ones last), so that each cluster's vertices lie together in
/// the cache: the triangle loop then reads what was just processed.
fn reorder_by_first_use(m: &mut ClusteredMesh) {
    let n = m.positions.len();
    let mut new_of = vec![u32::MAX; n];
    let mut order = Vec::with_capacity(n);
    for &v in m.vertex_list.iter() {
        if new_of[v as usize] == u32::MAX {
            new_of[v as usize] = order.len() as u32;
            order.push(v);
        }
    }
    for v in 0..n as u32 {
        if new_of[v as usize] == u32::MAX {
            new_of[v as usize] = order.len() as u32;
            order.push(v);
        }
    }
    m.positions = order.iter().map(|&v| m.positions[v as usize]).collect();
    m.source_vertex = order.iter().map(|&v| m.source_vertex[v as usize]).collect();
    for v in m.vertex_list.iter_mut() {
        *v = new_of[*v as usize];
    }
    for t in m.indices.iter_mut() {
        *t = t.map(|v| new_of[v as usize]);
    }
}

/// A triangle's indices rotated so the smallest is first (winding kept).
fn canonical(t: [u32; 3]) -> [u32; 3] {
    let k = (0..3).min_by_key(|&k| t[k]).unwrap_or(0);
    [t[k], t[(k + 1) % 3], t[(k + 2) % 3]]
}

/// A node over clusters `a..b` of `mesh`, its skip still unset.
fn node(mesh: &ClusteredMesh, a: usize, b: usize) -> ClusterNode {
    let t0 = mesh.clusters[a].triangles[0] as usize;
    let t1 = mesh.clusters[b - 1].triangles[1] as usize;
    let tris = &mesh.indices[t0..t1];
    let (mut lo, mut hi) = ([f32::INFINITY; 3], [f32::NEG_INFINITY; 3]);
    for t in tris {
        for &k in t {
            let p = mesh.positions[k as usize];
            for (a, v) in [p.x, p.y, p.z].into_iter().enumerate() {
                lo[a] = lo[a].min(v);
                hi[a] = hi[a].max(v);
            }
        }
    }
    let centre = [0, 1, 2].map(|a| 0.5 * (lo[a] + hi[a]));
    let corners = (0..8).map(|c| [0, 1, 2].map(|a| if c >> a & 1 == 0 { lo[a] } else { hi[a] }));
    let volume = std::iter::once(centre)
        .chain(corners)
        .map(|o| CullVolume::from_triangles(&mesh.positions, tris, o))
        .max_by(|x, y| x.d_min.total_cmp(&y.d_min))
        .unwrap_or(CullVolume::NEVER);
    ClusterNode {
        clusters: [a as u32, b as u32],
        skip: 0,
        volume,
        cone: NormalCone::from_triangles(&mesh.positions, tris),
        size: microraster::cull::triangle_sizes(&mesh.positions, tris),
        sphere: microraster::cull::triangle_sphere(&mesh.positions, tris),
    }
}

/// The sample eyes: a fixed low-discrepancy set (Halton bases 2, 3, 5) in
/// the cube of side six bounding radii around the mesh's box centre.
pub fn sample_eyes(positions: &[Vec3]) -> Vec<Eye> {
    let Some(b) = microraster::BoundingSphere::from_points(positions) else {
        return Vec::new();
    };
    let halton = |mut i: usize, base: usize| {
        let (mut f, mut r) = (1.0f64, 0.0f64);
        while i > 0 {
            f /= base as f64;
            r += f * (i % base) as f64;
            i /= base;
        }
        r
    };
    let c = [b.center.x, b.center.y, b.center.z];
    (1..=SAMPLES)
        .filter_map(|i| {
            let u = [halton(i, 2), halton(i, 3), halton(i, 5)];
            Eye::at([0, 1, 2].map(|a| c[a] + ((u[a] * 2.0 - 1.0) * 3.0 * b.radius as f64) as f32))
        })
        .collect()
}

/// `P`: the fraction of `eyes` from which `node`'s volume is back-facing.
fn probability(node: &ClusterNode, eyes: &[Eye]) -> f64 {
    let hits = eyes
        .iter()
        .filter(|e| node.volume.facing(e) == Facing::Back)
        .count();
    hits as f64 / eyes.len().max(1) as f64
}

/// A subtree while the tree is built.
struct Sub {
    node: ClusterNode,
    p: f64,
    tris: f64,
    children: Vec<Sub>,
}

/// Builds the forest by the cost model and writes it in pre-order.
fn tree(mesh: &ClusteredMesh, t_over_r: f64) -> Vec<ClusterNode> {
    let eyes = sample_eyes(&mesh.positions);
    let count = |a: usize, b: usize| {
        (mesh.clusters[b - 1].triangles[1] - mesh.clusters[a].triangles[0]) as f64
    };
    let mut list: Vec<Sub> = (0..mesh.clusters.len())
        .map(|i| {
            let node = node(mesh, i, i + 1);
            Sub {
                p: probability(&node, &eyes),
                node,
                tris: count(i, i + 1),
                children: Vec::new(),
            }
        })
        .collect();
    if t_over_r >= 0.0 {
        loop {
            let mut merged = false;
            let mut next = Vec::with_capacity(list.len());
            let mut it = list.into_iter().peekable();
            while let Some(a) = it.next() {
                let Some(b) = it.peek() else {
                    next.push(a);
                    break;
                };
                let (lo, hi) = (a.node.clusters[0] as usize, b.node.clusters[1] as usize);
                let c = node(mesh, lo, hi);
                let pc = probability(&c, &eyes);
                let worth = pc > (a.p * a.tris + b.p * b.tris - t_over_r) / (a.tris + b.tris);
                if worth {
                    let b = it.next().expect("peeked");
                    next.push(Sub {
                        node: c,
                        p: pc,
                        tris: a.tris + b.tris,
                        children: vec![a, b],
                    });
                    merged = true;
                } else {
                    next.push(a);
                }
            }
            list = next;
            if !merged {
                break;
            }
        }
    }
    let mut out = Vec::new();
    fn emit(s: Sub, out: &mut Vec<ClusterNode>) {
        let i = out.len();
        out.push(s.node);
        for c in s.children {
            emit(c, out);
        }
        out[i].skip = out.len() as u32;
    }
    for s in list {
        emit(s, &mut out);
    }
    out
}

/// Rebuilds every object of `scene` with `opts` clusters tested by `cull`
/// (`render`/`bench --cull-clusters`): positions, triangles and colours
/// in cluster order, each object then submitted whole through
/// `Submit::submit_clusters`. Triangle ids follow the new order.
pub fn cluster_scene(
    scene: &mut crate::scene::Scene,
    cull: microraster::ClusterCull,
    opts: &ClusterOptions,
) -> Result<(), String> {
    use crate::scene::{ObjectClusters, ObjectColors};
    for o in &mut scene.objects {
        let c = build(&o.positions, &o.indices, opts)?;
        o.colors = match &o.colors {
            ObjectColors::PerTriangle(v) => ObjectColors::PerTriangle(
                c.source_triangle.iter().map(|&t| v[t as usize]).collect(),
            ),
            ObjectColors::PerVertex(v) => ObjectColors::PerVertex(
                c.source_vertex
                    .iter()
                    .map(|&k| v.get(k as usize).copied().unwrap_or_default())
                    .collect(),
            ),
        };
        o.clusters = Some(std::sync::Arc::new(ObjectClusters {
            clusters: c.clusters,
            nodes: c.nodes,
            vertex_list: c.vertex_list,
            cull,
        }));
        o.positions = c.positions;
        o.indices = c.indices;
    }
    Ok(())
}
