//! Detail culling (lossy, `Config::detail`): what it drops is what it
//! promises to drop, and only that.
//!
//! - Every run of clusters a frame drops for detail projects, vertex by
//!   vertex (in `f64`, in front of the eye), within a square less than the
//!   threshold wide, centred on the projection of its node's sphere; so
//!   does a whole object dropped by its bounds.
//! - The counters add up: `culled_detail` is the triangles of the dropped
//!   runs, and every piece set up is one the exact cluster path sets up,
//!   in its order (whole clusters are removed, nothing else changes).
//! - At 0 pixels nothing changes; far away, a real share is dropped.
//!
//! Over random cameras on the bunny, the teapot and Spot, in every cull
//! mode.

use microraster::cull::{Detail, Eye, Visit};
use microraster::prelude::*;
use microraster::{
    BoundingSphere, ClusterCull, ClusterTest, Config, CullMode, Frame, Mat4, Mesh, MeshColors,
    ProcessedVertex, SetupTriangle, Stats, Vec3,
};

/// Whether every point of `points` projects under `mvp`, in front of the
/// eye, within the square `pixels` wide about the projection of `centre`.
fn within(mvp: &Mat4, centre: Vec3, points: &[[f32; 3]], pixels: u16) -> bool {
    let ([cx, cy], cw) = project(mvp, [centre.x, centre.y, centre.z]);
    let half = f64::from(pixels) / 2.0;
    cw > 0.0
        && points.iter().all(|&p| {
            let ([x, y], w) = project(mvp, p);
            w > 0.0 && (x - cx).abs() < half && (y - cy).abs() < half
        })
}
mod common;

use common::{cases, models};
use microraster_host::cluster::ClusteredMesh;
use proptest::prelude::*;

const W: u32 = 160;
const H: u32 = 120;

/// A camera `dist` bounding radii from the centre along `dir`, looking at
/// it, the far plane 2 radii behind the mesh (see `common::camera`).
fn camera(m: &ClusteredMesh, dir: [f32; 3], dist: f32) -> Option<Mat4> {
    common::camera(m, dir, dist, [0.0; 3], dist + 2.0, W as f32 / H as f32)
}

fn config(cull: CullMode, detail: u16) -> Config {
    let mut c = Config::new(W, H);
    c.cull = cull;
    c.detail = detail;
    c
}

/// The pixel position of `p` under `mvp`, in `f64`, and its `w`.
fn project(mvp: &Mat4, p: [f32; 3]) -> ([f64; 2], f64) {
    let c = &mvp.cols;
    let r = |i: usize| {
        (0..3)
            .map(|j| f64::from(c[j][i]) * f64::from(p[j]))
            .sum::<f64>()
            + f64::from(c[3][i])
    };
    let (x, y, w) = (r(0), r(1), r(3));
    let (hw, hh) = (f64::from(W) / 2.0, f64::from(H) / 2.0);
    ([hw + x / w * hw, hh - y / w * hh], w)
}

/// Submits the mesh with `cull`; the pieces set up and the counters.
fn submit(
    m: &ClusteredMesh,
    mvp: &Mat4,
    config: Config,
    cull: ClusterCull,
) -> (Vec<SetupTriangle>, Stats) {
    let colors = vec![Rgb888::new(200, 100, 50); m.indices.len()];
    let mesh = Mesh {
        positions: &m.positions,
        indices: &m.indices,
        attributes: MeshColors::PerTriangle(&colors),
        bounds: None,
    };
    let mut storage = vec![SetupTriangle::EMPTY; m.indices.len() * 2 + 64];
    let mut frame = Frame::new(config, &mut storage).unwrap();
    let mut cache = vec![ProcessedVertex::default(); m.positions.len()];
    frame
        .submit_clusters(&mesh, mvp, &m.set(), cull, 0, &mut cache)
        .unwrap();
    (frame.triangles().to_vec(), frame.stats())
}

/// Checks one frame; returns the triangles dropped for detail.
fn check(m: &ClusteredMesh, mvp: &Mat4, mode: CullMode, pixels: u16, hierarchy: bool) -> u64 {
    let config = config(mode, pixels);
    let cull = ClusterCull {
        test: ClusterTest::Volumes,
        hierarchy,
    };
    let detail = Detail::for_frame(mvp, &config);
    assert_eq!(detail.is_none(), pixels == 0);
    let eye = Eye::for_frame::<8>(mvp, &config);
    let mut dropped = 0u64;
    m.set().visit(eye.as_ref(), detail.as_ref(), cull, |v| {
        let Visit::Detail(a, b, node) = v else { return };
        assert_eq!(
            m.nodes[node].clusters,
            [a as u32, b as u32],
            "the node dropped"
        );
        let clusters = &m.clusters[a..b];
        dropped += clusters
            .iter()
            .map(|k| u64::from(k.triangles[1] - k.triangles[0]))
            .sum::<u64>();
        // The vertices of the run, against the sphere of a node covering
        // exactly the run (the one dropped; a node and its only child may
        // share a range).
        let vertices: Vec<[f32; 3]> = clusters
            .iter()
            .flat_map(|k| &m.indices[k.triangles[0] as usize..k.triangles[1] as usize])
            .flatten()
            .map(|&v| {
                let p = m.positions[v as usize];
                [p.x, p.y, p.z]
            })
            .collect();
        let range = [a as u32, b as u32];
        assert!(
            m.nodes
                .iter()
                .any(|n| n.clusters == range && within(mvp, n.sphere.center, &vertices, pixels)),
            "a dropped run of clusters {a}..{b} reaches beyond {pixels} px"
        );
    });
    // The whole object, by its bounds.
    if let (Some(d), Some(b)) = (&detail, BoundingSphere::from_points(&m.positions)) {
        if d.drops(&b) {
            let all: Vec<[f32; 3]> = m.positions.iter().map(|p| [p.x, p.y, p.z]).collect();
            assert!(
                within(mvp, b.center, &all, pixels),
                "a dropped object reaches beyond"
            );
        }
    }
    let (want, base) = submit(
        m,
        mvp,
        Config {
            detail: 0,
            ..config
        },
        cull,
    );
    let (got, stats) = submit(m, mvp, config, cull);
    assert_eq!(
        stats.culled_detail, dropped,
        "the counter is the runs dropped"
    );
    assert_eq!(stats.submitted, base.submitted);
    assert_eq!(stats.dropped() + stats.stored, stats.submitted);
    // Every piece is one the exact path sets up, in order.
    let mut it = want.iter();
    for g in &got {
        assert!(it.any(|w| w == g), "a piece the exact path does not set up");
    }
    dropped
}

proptest! {
    #![proptest_config(ProptestConfig { cases: cases(32), ..ProptestConfig::default() })]

    #[test]
    fn detail_culling_drops_only_what_projects_below_the_threshold(
        which in 0usize..3,
        dir in prop::array::uniform3(-1.0f32..1.0),
        dist in 1.5f32..60.0,
        pixels in prop::sample::select(vec![1u16, 2, 3, 6, 12]),
        mode in prop::sample::select(vec![CullMode::Back, CullMode::None, CullMode::Front]),
        hierarchy in any::<bool>(),
    ) {
        let m = &models()[which];
        if let Some(mvp) = camera(m, dir, dist) {
            check(m, &mvp, mode, pixels, hierarchy);
        }
    }
}

/// Off (0 pixels) is the exact path; far away a real share goes, in every
/// cull mode (detail needs no back-face culling).
#[test]
fn detail_culling_is_off_at_zero_and_drops_small_far_clusters() {
    let m = &models()[0];
    let n = m.indices.len() as u64;
    for mode in [CullMode::Back, CullMode::None] {
        let near = camera(m, [0.3, 0.4, 1.0], 2.5).unwrap();
        assert_eq!(check(m, &near, mode, 0, true), 0);
        let far = camera(m, [0.3, 0.4, 1.0], 30.0).unwrap();
        let dropped = check(m, &far, mode, 4, true);
        assert!(
            dropped * 2 > n,
            "{dropped} of {n} dropped at 30 radii, 4 px"
        );
        // Smaller thresholds drop less.
        assert!(check(m, &far, mode, 1, true) < dropped);
    }
}

/// A whole object goes by its bounds (`Mesh::bounds`) before anything
/// else: every triangle counted in `culled_detail`, nothing set up; near
/// enough to matter it is drawn as without detail culling.
#[test]
fn detail_culling_drops_a_far_object_whole_by_its_bounds() {
    let m = &models()[2];
    let colors = vec![Rgb888::new(200, 100, 50); m.indices.len()];
    let mesh = Mesh {
        positions: &m.positions,
        indices: &m.indices,
        attributes: MeshColors::PerTriangle(&colors),
        bounds: BoundingSphere::from_points(&m.positions),
    };
    let n = m.indices.len() as u64;
    let run = |mvp: &Mat4, detail: u16, clusters: bool| {
        let mut storage = vec![SetupTriangle::EMPTY; m.indices.len() * 2 + 64];
        let mut frame = Frame::new(config(CullMode::Back, detail), &mut storage).unwrap();
        let mut cache = vec![ProcessedVertex::default(); m.positions.len()];
        if clusters {
            let cull = ClusterCull::default();
            frame
                .submit_clusters(&mesh, mvp, &m.set(), cull, 0, &mut cache)
                .unwrap();
        } else {
            frame.submit_mesh_cached(&mesh, mvp, 0, &mut cache).unwrap();
        }
        (frame.triangles().to_vec(), frame.stats())
    };
    for clusters in [false, true] {
        // About 12 pixels across at 20 radii.
        let far = camera(m, [0.2, 0.5, 1.0], 20.0).unwrap();
        let (pieces, s) = run(&far, 24, clusters);
        assert!(pieces.is_empty());
        assert_eq!((s.submitted, s.culled_detail, s.stored), (n, n, 0));
        // 1 pixel keeps the object (clusters may still go).
        let (_, s) = run(&far, 1, clusters);
        assert!(s.stored > 0 && s.culled_detail < n);
        if !clusters {
            assert_eq!(s.culled_detail, 0);
        }
        // Near, the object stays: drawn as without detail culling (its
        // clusters, a few pixels each, may still go).
        let near = camera(m, [0.2, 0.5, 1.0], 3.0).unwrap();
        let (pieces, s) = run(&near, 4, clusters);
        if clusters {
            assert!(s.culled_detail < n / 2 && s.stored > 0);
        } else {
            assert_eq!(s.culled_detail, 0);
            assert!(pieces == run(&near, 0, false).0, "the same pieces");
        }
    }
}
