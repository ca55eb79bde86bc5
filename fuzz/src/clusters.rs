//! Cluster culling from arbitrary input (`fuzz_targets/clusters.rs`): a
//! small mesh, a cluster set that is either built honestly from it
//! (`CullVolume::from_triangles`, `NormalCone::from_triangles`, a pairwise
//! tree) or arbitrary (bad ranges, trees that do not tile, NaN and huge
//! geometry), an arbitrary matrix and cull settings, and the mesh's
//! bounds (none, its true sphere, or any floats), which object culling
//! and the clusters' whole-mesh size guard (`Eye::within`) use.
//!
//! Checks: no panic; `validate` refuses exactly what `submit_clusters`
//! refuses, and a refused or failed submission writes no counter and no
//! storage slot; the counters add up (`check_accounting`); a set whose
//! every node never culls ([`CullVolume::NEVER`], [`NormalCone::NEVER`])
//! stores exactly what `submit_mesh_cached` stores (detail culling, which
//! never drops such a node, included); and an honest set stores no piece
//! that `submit_mesh_cached` does not, in its order (detail culling drops
//! whole clusters, so that holds with it too).
//!
//! With a detail fill (`DetailFill`, any floats): the same refusals, a
//! failed submission counts and stores nothing, and a successful one
//! counts what the submission without a fill counts, plus its boxes'
//! pieces, each stored after or among the plain pieces.
//!
//! Normal masks on the same mesh, matrix and settings: classes built
//! honestly (each triangle's class, per class its sizes and sphere) or
//! arbitrary (any partitions, class ids, lengths, NaN and huge sizes and
//! spheres). `validate` refuses exactly what `submit_masked` refuses,
//! with nothing counted or stored; the counters add up; under
//! `CullMode::None` the pieces are the reference's; honest classes store
//! a subsequence of the reference's pieces, in order.

use crate::{check_accounting, MatIn, F};
use libfuzzer_sys::arbitrary::{self, Arbitrary};
use microraster::cull::{ClusterFault, CullVolume, NormalCone};
use microraster::normal_mask::{class_count, classify, ClassFault, NO_CLASS};
use microraster::prelude::Submit;
use microraster::NormalClasses;
use microraster::{
    BoundingSphere, Cluster, ClusterCull, ClusterNode, ClusterSet, ClusterTest, Config, CullMode,
    DetailFill, Error, Frame, FrontFace, Mesh, MeshColors, ProcessedVertex, SetupTriangle, Stats,
    Vec3,
};

/// Raw node data.
#[derive(Arbitrary, Clone, Debug)]
pub struct NodeIn {
    clusters: [u8; 2],
    skip: u8,
    volume: [F; 12],
    cone: [F; 7],
    size: [F; 2],
    sphere: [F; 4],
}

/// The input.
#[derive(Arbitrary, Clone, Debug)]
pub struct ClusterInput {
    positions: Vec<[i8; 3]>,
    indices: Vec<[u8; 3]>,
    /// Triangles per cluster (honest sets), 1..=16.
    per_cluster: u8,
    honest: bool,
    never: bool,
    shared: bool,
    raw_list: Vec<u8>,
    raw_clusters: Vec<[u8; 4]>,
    raw_nodes: Vec<NodeIn>,
    mvp: MatIn,
    cull: u8,
    cw: bool,
    test_cones: bool,
    hierarchy: bool,
    /// Detail culling's threshold in pixels (0: off).
    detail: u8,
    /// Detail culling draws boxes in these varyings (any floats).
    fill: Option<[F; 3]>,
    storage: u8,
    /// Normal masks: partitions a side (honest: 1..=16 from it), and
    /// arbitrary classes, sizes and spheres.
    partitions: u8,
    raw_classes: Vec<u16>,
    raw_sizes: Vec<[F; 2]>,
    raw_spheres: Vec<[F; 4]>,
    /// The mesh's bounds, which the cluster tests try first
    /// (`Eye::within`): 0 none, 1 the true sphere of the positions, else
    /// `raw_bounds` (any floats: then frames may lose pieces, never gain).
    bounds: u8,
    raw_bounds: [F; 4],
}

fn node_from(n: &NodeIn) -> ClusterNode {
    let v = n.volume.map(|f| f.0);
    let c = n.cone.map(|f| f.0);
    ClusterNode {
        clusters: n.clusters.map(u32::from),
        skip: u32::from(n.skip),
        volume: CullVolume {
            origin: [v[0], v[1], v[2]],
            n_min: [v[3], v[4], v[5]],
            n_max: [v[6], v[7], v[8]],
            d_min: v[9],
            d_max: v[10],
            radius: v[11],
        },
        cone: NormalCone {
            apex: [c[0], c[1], c[2]],
            axis: [c[3], c[4], c[5]],
            cutoff: c[6],
        },
        size: n.size.map(|f| f.0),
        sphere: {
            let b = n.sphere.map(|f| f.0);
            BoundingSphere {
                center: Vec3::new(b[0], b[1], b[2]),
                radius: b[3],
            }
        },
    }
}

/// Honest clusters: runs of `per` triangles, each with its own vertices
/// or (`shared`) listing the mesh's, and a pairwise tree over them.
type Honest = (
    Vec<Vec3>,
    Vec<[u32; 3]>,
    Vec<Cluster>,
    Vec<ClusterNode>,
    Vec<u32>,
);

fn honest(
    positions: &[Vec3],
    indices: &[[u32; 3]],
    per: usize,
    never: bool,
    shared: bool,
) -> Honest {
    let (mut p, mut t, mut cl, mut list) = (Vec::new(), Vec::new(), Vec::new(), Vec::new());
    let in_range: Vec<[u32; 3]> = indices
        .iter()
        .filter(|i| i.iter().all(|&k| (k as usize) < positions.len()))
        .copied()
        .collect();
    if shared {
        p = positions.to_vec();
    }
    for run in in_range.chunks(per.max(1)) {
        let t0 = t.len() as u32;
        let v0 = if shared { list.len() } else { p.len() } as u32;
        for tri in run {
            if shared {
                t.push(*tri);
                for &k in tri {
                    if !list[v0 as usize..].contains(&k) {
                        list.push(k);
                    }
                }
                continue;
            }
            let base = p.len() as u32;
            for &k in tri {
                p.push(positions[k as usize]);
            }
            t.push([base, base + 1, base + 2]);
        }
        let v1 = if shared { list.len() } else { p.len() } as u32;
        cl.push(Cluster {
            triangles: [t0, t.len() as u32],
            vertices: [v0, v1],
        });
    }
    let node = |a: usize, b: usize, p: &[Vec3], t: &[[u32; 3]]| {
        let tris = &t[cl[a].triangles[0] as usize..cl[b - 1].triangles[1] as usize];
        let (volume, cone) = if never {
            (CullVolume::NEVER, NormalCone::NEVER)
        } else {
            (
                CullVolume::from_triangles(p, tris, [0.0; 3]),
                NormalCone::from_triangles(p, tris),
            )
        };
        ClusterNode {
            clusters: [a as u32, b as u32],
            skip: 0,
            volume,
            cone,
            size: microraster::cull::triangle_sizes(p, tris),
            sphere: if never {
                BoundingSphere::EVERYWHERE
            } else {
                microraster::cull::triangle_sphere(p, tris)
            },
        }
    };
    let mut nodes = Vec::new();
    let mut a = 0;
    while a < cl.len() {
        if a + 1 < cl.len() {
            let i = nodes.len();
            nodes.push(node(a, a + 2, &p, &t));
            nodes.push(ClusterNode {
                skip: (i + 2) as u32,
                ..node(a, a + 1, &p, &t)
            });
            nodes.push(ClusterNode {
                skip: (i + 3) as u32,
                ..node(a + 1, a + 2, &p, &t)
            });
            nodes[i].skip = (i + 3) as u32;
            a += 2;
        } else {
            let i = nodes.len();
            nodes.push(ClusterNode {
                skip: (i + 1) as u32,
                ..node(a, a + 1, &p, &t)
            });
            a += 1;
        }
    }
    (p, t, cl, nodes, list)
}

/// Runs one input.
pub fn run_clusters(input: &ClusterInput) {
    let positions: Vec<Vec3> = input
        .positions
        .iter()
        .take(64)
        .map(|c| Vec3::new(c[0] as f32 / 16.0, c[1] as f32 / 16.0, c[2] as f32 / 16.0))
        .collect();
    let indices: Vec<[u32; 3]> = input
        .indices
        .iter()
        .take(64)
        .map(|t| t.map(u32::from))
        .collect();
    let (p, t, clusters, nodes, list) = if input.honest || input.never {
        let per = usize::from(input.per_cluster % 16) + 1;
        honest(&positions, &indices, per, input.never, input.shared)
    } else {
        let cl = input
            .raw_clusters
            .iter()
            .take(32)
            .map(|c| Cluster {
                triangles: [c[0], c[1]].map(u32::from),
                vertices: [c[2], c[3]].map(u32::from),
            })
            .collect();
        let nodes = input.raw_nodes.iter().take(32).map(node_from).collect();
        let list = input
            .raw_list
            .iter()
            .take(64)
            .map(|&v| u32::from(v))
            .collect();
        (positions, indices, cl, nodes, list)
    };
    let set = ClusterSet {
        clusters: &clusters,
        nodes: &nodes,
        vertices: &list,
    };
    let colors: Vec<_> = (0..t.len())
        .map(|i| microraster::pixelcolor::Rgb888::new(i as u8, 7, 9))
        .collect();
    let mesh = Mesh {
        positions: &p,
        indices: &t,
        attributes: MeshColors::PerTriangle(&colors),
        bounds: match input.bounds % 3 {
            0 => None,
            1 => BoundingSphere::from_points(&p),
            _ => {
                let b = input.raw_bounds.map(|f| f.0);
                Some(BoundingSphere {
                    center: Vec3::new(b[0], b[1], b[2]),
                    radius: b[3],
                })
            }
        },
    };
    let mut config = Config::new(64, 48);
    config.cull = [CullMode::Back, CullMode::Front, CullMode::None][usize::from(input.cull % 3)];
    config.detail = u16::from(input.detail);
    config.front_face = if input.cw {
        FrontFace::Cw
    } else {
        FrontFace::Ccw
    };
    let cull = ClusterCull {
        test: if input.test_cones {
            ClusterTest::Cones
        } else {
            ClusterTest::Volumes
        },
        hierarchy: input.hierarchy,
    };
    let mvp = input.mvp.matrix();
    let valid = set.validate(t.len(), p.len());
    if input.honest || input.never {
        assert_eq!(valid, Ok(()), "an honest set is valid");
    }

    // Reference: per-triangle culling.
    let mut st_ref = vec![SetupTriangle::EMPTY; t.len() * 7 + 1];
    let mut reference = Frame::<8>::with_subpixel_bits(config, &mut st_ref).expect("valid size");
    let mut cache = vec![ProcessedVertex::default(); p.len()];
    reference
        .submit_mesh_cached(&mesh, &mvp, 0, &mut cache)
        .expect("room for every piece");

    let room = usize::from(input.storage) % (t.len() * 7 + 2);
    let mut st = vec![SetupTriangle::EMPTY; room];
    let mut frame = Frame::<8>::with_subpixel_bits(config, &mut st).expect("valid size");
    let before = frame.stats();
    let r = frame.submit_clusters(&mesh, &mvp, &set, cull, 0, &mut cache);
    let after = frame.stats();
    match (r, valid) {
        (Err(Error::InvalidClusters(f)), Err(Error::InvalidClusters(g))) => {
            assert_eq!(f, g);
            assert_eq!(before, after, "a refused set counts nothing");
            assert!(frame.triangles().is_empty());
            let _: ClusterFault = f;
        }
        (Err(Error::StorageFull { .. }), Ok(())) => {
            assert_eq!(before, after, "a failed submission counts nothing");
            assert!(frame.triangles().is_empty());
        }
        (Ok(()), Ok(())) => {
            check_accounting(&before, &after, t.len() as u64);
            let (got, want) = (frame.triangles(), reference.triangles());
            let d = crate::diff(&before, &after);
            if config.cull == CullMode::None {
                assert_eq!(d.culled_cluster + d.culled_hierarchy, 0, "culled by facing");
            }
            // Only a set whose vertex ranges cover its triangles draws
            // what the reference draws: an arbitrary one may leave a
            // triangle's vertex out of its cluster's range, and that
            // triangle is refused (counted as a bad index).
            let covers = input.honest || input.never;
            if input.never || (covers && config.cull == CullMode::None && config.detail == 0) {
                assert_eq!(after, reference.stats(), "nothing culled by clusters");
                assert_eq!(got, want);
            } else if input.honest {
                // Every stored piece is one the reference stores, in order
                // (the size guard makes them equal; the host's property
                // tests check that on real meshes).
                let mut it = want.iter();
                for g in got {
                    assert!(it.any(|w| w == g), "a piece the reference does not store");
                }
            }
        }
        (r, v) => panic!("submit_clusters {r:?} but validate {v:?}"),
    }
    if let Some(fill) = input.fill {
        let filled = Mesh {
            positions: mesh.positions,
            indices: mesh.indices,
            attributes: DetailFill {
                attributes: mesh.attributes,
                fill: fill.map(|f| f.0),
            },
            bounds: mesh.bounds,
        };
        // Without a fill, with room for everything.
        let mut st_plain = vec![SetupTriangle::EMPTY; t.len() * 7 + 1];
        let mut plain = Frame::<8>::with_subpixel_bits(config, &mut st_plain).expect("valid size");
        let plain_result = plain.submit_clusters(&mesh, &mvp, &set, cull, 0, &mut cache);
        let mut st = vec![SetupTriangle::EMPTY; room];
        let mut frame = Frame::<8>::with_subpixel_bits(config, &mut st).expect("valid size");
        let r = frame.submit_clusters(&filled, &mvp, &set, cull, 0, &mut cache);
        let after = frame.stats();
        match (r, plain_result) {
            (Err(Error::InvalidClusters(f)), Err(Error::InvalidClusters(g))) => {
                assert_eq!(f, g);
                assert_eq!(after, Stats::default(), "a refused set counts nothing");
                assert!(frame.triangles().is_empty());
            }
            (Err(Error::StorageFull { .. }), Ok(())) => {
                assert_eq!(
                    after,
                    Stats::default(),
                    "a failed submission counts nothing"
                );
                assert!(frame.triangles().is_empty());
            }
            (Ok(()), Ok(())) => {
                let boxes = after.detail_boxes;
                assert_eq!(
                    Stats {
                        detail_boxes: 0,
                        ..after
                    },
                    plain.stats(),
                    "boxes change no triangle counter"
                );
                assert_eq!(
                    frame.triangles().len() as u64,
                    plain.triangles().len() as u64 + boxes
                );
                if config.detail == 0 {
                    assert_eq!(boxes, 0);
                }
            }
            (r, v) => panic!("with a fill {r:?}, without {v:?}"),
        }
    }
    run_masks(input, &mesh, &mvp, config, &reference);
}

/// Honest normal classes of a mesh: each triangle's class from its `f64`
/// normal, per class its triangles' sizes and sphere.
fn honest_classes(
    p: &[Vec3],
    t: &[[u32; 3]],
    partitions: u8,
) -> (Vec<u16>, Vec<[f32; 2]>, Vec<BoundingSphere>) {
    let n = class_count(partitions);
    let classes: Vec<u16> = t
        .iter()
        .map(|tri| {
            let q = tri.map(|k| p.get(k as usize).copied());
            let [Some(a), Some(b), Some(c)] = q else {
                return NO_CLASS;
            };
            // Differences of f32 values are exact in f64.
            let d = |q: Vec3| {
                [
                    f64::from(q.x) - f64::from(a.x),
                    f64::from(q.y) - f64::from(a.y),
                    f64::from(q.z) - f64::from(a.z),
                ]
            };
            let (u, v) = (d(b), d(c));
            classify(
                [
                    u[1] * v[2] - u[2] * v[1],
                    u[2] * v[0] - u[0] * v[2],
                    u[0] * v[1] - u[1] * v[0],
                ],
                partitions,
            )
        })
        .collect();
    let mut sizes = vec![[0.0f32; 2]; n];
    let mut spheres = vec![BoundingSphere::EVERYWHERE; n];
    for c in 0..n {
        let tris: Vec<[u32; 3]> = t
            .iter()
            .zip(&classes)
            .filter(|(_, &k)| usize::from(k) == c)
            .map(|(tri, _)| *tri)
            .collect();
        if !tris.is_empty() {
            sizes[c] = microraster::cull::triangle_sizes(p, &tris);
            spheres[c] = microraster::cull::triangle_sphere(p, &tris);
        }
    }
    (classes, sizes, spheres)
}

/// Normal masks: `validate` refuses exactly what `submit_masked` refuses,
/// with nothing counted or stored; the counters add up; with no culling
/// the pieces are the reference's; honest classes store a subsequence of
/// the reference's pieces, in order.
fn run_masks(
    input: &ClusterInput,
    mesh: &Mesh<'_, MeshColors<'_>>,
    mvp: &microraster::Mat4,
    config: Config,
    reference: &Frame<'_, 8>,
) {
    let (p, t) = (mesh.positions, mesh.indices);
    let honest = input.honest || input.never;
    let partitions = if honest {
        input.partitions % 16 + 1
    } else {
        input.partitions
    };
    let (classes, sizes, spheres) = if honest {
        honest_classes(p, t, partitions)
    } else {
        let sphere = |b: &[F; 4]| BoundingSphere {
            center: Vec3::new(b[0].0, b[1].0, b[2].0),
            radius: b[3].0,
        };
        (
            input
                .raw_classes
                .iter()
                .take(t.len() + 1)
                .copied()
                .collect(),
            input
                .raw_sizes
                .iter()
                .take(1536)
                .map(|s| s.map(|f| f.0))
                .collect(),
            input.raw_spheres.iter().take(1536).map(sphere).collect(),
        )
    };
    let set = NormalClasses {
        partitions,
        classes: &classes,
        sizes: &sizes,
        spheres: &spheres,
    };
    let valid = set.validate(t.len());
    if honest {
        assert_eq!(valid, Ok(()), "honest classes are valid");
    }
    let room = usize::from(input.storage) % (t.len() * 7 + 2);
    let mut st = vec![SetupTriangle::EMPTY; room];
    let mut frame = Frame::<8>::with_subpixel_bits(config, &mut st).expect("valid size");
    let mut cache = vec![ProcessedVertex::default(); p.len()];
    let before = frame.stats();
    let r = frame.submit_masked(mesh, mvp, &set, 0, &mut cache);
    let after = frame.stats();
    match (r, valid) {
        (Err(Error::InvalidNormalClasses(f)), Err(Error::InvalidNormalClasses(g))) => {
            assert_eq!(f, g);
            assert_eq!(before, after, "refused classes count nothing");
            assert!(frame.triangles().is_empty());
        }
        (Err(Error::StorageFull { .. }), Ok(())) => {
            assert_eq!(before, after, "a failed submission counts nothing");
            assert!(frame.triangles().is_empty());
        }
        (Ok(()), Ok(())) => {
            check_accounting(&before, &after, t.len() as u64);
            let (got, want) = (frame.triangles(), reference.triangles());
            if config.cull == CullMode::None && config.detail == 0 {
                assert_eq!(after, reference.stats(), "nothing masked");
                assert_eq!(got, want);
            } else if honest {
                let mut it = want.iter();
                for g in got {
                    assert!(it.any(|w| w == g), "a piece the reference does not store");
                }
            }
        }
        (r, v) => panic!("submit_masked {r:?} but validate {v:?}"),
    }
    run_mesh_masked(
        mesh,
        mvp,
        config,
        reference,
        &frame,
        &set,
        room,
        honest && valid.is_ok(),
    );
}

/// `submit_mesh_masked` with the frame's own `back_mask` (no vertex cache,
/// the firmware's way): classes that are not one a triangle are refused
/// with nothing counted, whatever their ids; otherwise the counters add
/// up; with no culling the pieces are the reference's; with honest
/// classes they are exactly what `submit_masked` stored where it
/// succeeded (`masked`, the frame that `run_masks` drew with the same
/// room).
#[allow(clippy::too_many_arguments)]
fn run_mesh_masked(
    mesh: &Mesh<'_, MeshColors<'_>>,
    mvp: &microraster::Mat4,
    config: Config,
    reference: &Frame<'_, 8>,
    masked: &Frame<'_, 8>,
    set: &NormalClasses<'_>,
    room: usize,
    honest: bool,
) {
    let t = mesh.indices.len();
    let mut st = vec![SetupTriangle::EMPTY; room];
    let mut frame = Frame::<8>::with_subpixel_bits(config, &mut st).expect("valid size");
    let mask = frame.back_mask(mvp, set);
    let before = frame.stats();
    let r = frame.submit_mesh_masked(mesh, mvp, set.classes, &mask, 0);
    let after = frame.stats();
    match r {
        Err(Error::InvalidNormalClasses(ClassFault::Triangles)) => {
            assert_ne!(set.classes.len(), t, "one class a triangle is not refused");
            assert_eq!(before, after, "refused classes count nothing");
            assert!(frame.triangles().is_empty());
        }
        Err(Error::StorageFull { .. }) => {
            assert_eq!(set.classes.len(), t);
            assert_eq!(before, after, "a failed submission counts nothing");
            assert!(frame.triangles().is_empty());
        }
        Ok(()) => {
            assert_eq!(set.classes.len(), t);
            check_accounting(&before, &after, t as u64);
            if config.cull == CullMode::None && config.detail == 0 {
                assert_eq!(after, reference.stats(), "nothing masked");
                assert_eq!(frame.triangles(), reference.triangles());
            } else if honest && masked.stats().submitted == t as u64 {
                assert_eq!(
                    frame.triangles(),
                    masked.triangles(),
                    "not submit_masked's pieces"
                );
            }
        }
        Err(e) => panic!("submit_mesh_masked: {e:?}"),
    }
}
