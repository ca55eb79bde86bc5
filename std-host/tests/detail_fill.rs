//! Detail culling's boxes (`DetailFill`): what detail culling drops is
//! drawn as a screen-aligned box in the fill's varyings, the lecture's
//! "bounding-box colour", instead of leaving a hole.
//!
//! - Every dropped node's box holds the projection (in `f64`) of every
//!   vertex of its clusters: the box covers what it replaces.
//! - Against the frame where dropped things are not drawn, only fill
//!   pixels appear (one mesh colour, depth `Less`), and every fill pixel's
//!   centre lies within a box, up to snapping.
//! - The triangle counters are those of plain detail culling; the boxes'
//!   pieces are counted in `detail_boxes` alone.
//! - Any strip height draws the frame the whole frame draws.
//! - A box that does not fit a frame's storage is refused whole.
//! - On the bunny far away, boxes change fewer pixels than holes.
//!
//! Over random cameras on the bunny, the teapot and Spot.

use microraster::cull::{Detail, Eye, Visit};
use microraster::prelude::*;
use microraster::{
    Attributes, BoundingSphere, ClusterCull, ClusterTest, Config, CullMode, DetailFill, Error,
    Frame, Mat4, Mesh, MeshColors, ProcessedVertex, SetupTriangle, Stats, StripRenderer, Vec4,
};
mod common;

use common::{cases, models};
use microraster_host::cluster::ClusteredMesh;
use proptest::prelude::*;

const W: u32 = 160;
const H: u32 = 120;
const MESH: Rgb888 = Rgb888::new(200, 100, 50);
const FILL: Rgb888 = Rgb888::new(0, 255, 0);
/// Half a subpixel at 8 bits (snapping), and a little for `f32`.
const SNAP: f64 = 1.0 / 256.0;

fn camera(m: &ClusteredMesh, dir: [f32; 3], dist: f32) -> Option<Mat4> {
    common::camera(m, dir, dist, [0.0; 3], dist + 2.0, W as f32 / H as f32)
}

fn config(cull: CullMode, detail: u16) -> Config {
    let mut c = Config::new(W, H);
    c.cull = cull;
    c.detail = detail;
    c
}

fn rgb(c: Rgb888) -> [f32; 3] {
    [c.r(), c.g(), c.b()].map(f32::from)
}

/// A clip-space point in pixels (`f64`; y down, as rows).
fn pixel(p: Vec4) -> [f64; 2] {
    let (hw, hh) = (f64::from(W) / 2.0, f64::from(H) / 2.0);
    let w = f64::from(p.w);
    [hw + f64::from(p.x) / w * hw, hh - f64::from(p.y) / w * hh]
}

/// The pixel rectangle `[x0, x1, y0, y1]` of a box.
fn rect(quad: [Vec4; 4]) -> [f64; 4] {
    let p = quad.map(pixel);
    let xs = p.map(|q| q[0]);
    let ys = p.map(|q| q[1]);
    let min = |v: [f64; 4]| v.iter().copied().fold(f64::INFINITY, f64::min);
    let max = |v: [f64; 4]| v.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    [min(xs), max(xs), min(ys), max(ys)]
}

/// The projection of object point `p` in pixels, and its `w`.
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

fn inside(r: &[f64; 4], [x, y]: [f64; 2], margin: f64) -> bool {
    x >= r[0] - margin && x <= r[1] + margin && y >= r[2] - margin && y <= r[3] + margin
}

/// The whole frame drawn at once (a `Frame`), or strip by strip (a
/// `StripRenderer` a strip of `rows`); its pixels and the counters.
fn draw<A: Attributes<3>>(
    m: &ClusteredMesh,
    mesh: &Mesh<'_, A>,
    mvp: &Mat4,
    config: Config,
    cull: ClusterCull,
    rows: Option<u32>,
) -> (Vec<Rgb888>, Stats) {
    let n = (W * H) as usize;
    let (mut color, mut depth) = (vec![Rgb888::BLACK; n], vec![u16::MAX; n]);
    let mut cache = vec![ProcessedVertex::default(); m.positions.len()];
    let mut stats = Stats::default();
    match rows {
        None => {
            let mut storage = vec![SetupTriangle::EMPTY; m.indices.len() * 2 + 4096];
            let mut frame = Frame::new(config, &mut storage).unwrap();
            frame
                .submit_clusters(mesh, mvp, &m.set(), cull, 0, &mut cache)
                .unwrap();
            frame.render_rows(0, H, &mut color, &mut depth[..]).unwrap();
            stats = frame.stats();
        }
        Some(rows) => {
            for y0 in (0..H).step_by(rows as usize) {
                let y1 = (y0 + rows).min(H);
                let span = (y0 * W) as usize..(y1 * W) as usize;
                let (c, d) = (&mut color[span.clone()], &mut depth[span]);
                let mut r = StripRenderer::new(config, y0, y1, c, d).unwrap();
                r.submit_clusters(mesh, mvp, &m.set(), cull, 0, &mut cache)
                    .unwrap();
                stats += r.stats();
            }
        }
    }
    (color, stats)
}

/// The boxes of the nodes `mvp` drops, as pixel rectangles, each checked
/// to hold the projection of its clusters' vertices.
fn boxes(m: &ClusteredMesh, mvp: &Mat4, config: &Config, cull: ClusterCull) -> Vec<[f64; 4]> {
    let detail = Detail::for_frame(mvp, config).unwrap();
    let eye = Eye::for_frame::<8>(mvp, config);
    let mut out = Vec::new();
    m.set().visit(eye.as_ref(), Some(&detail), cull, |v| {
        let Visit::Detail(a, b, node) = v else { return };
        let node = &m.nodes[node];
        assert_eq!(node.clusters, [a as u32, b as u32], "the node dropped");
        let Some(quad) = detail.screen_box(&node.sphere) else {
            return;
        };
        let r = rect(quad);
        for k in &m.clusters[a..b] {
            for idx in &m.indices[k.triangles[0] as usize..k.triangles[1] as usize] {
                for &v in idx {
                    let p = m.positions[v as usize];
                    let (q, w) = project(mvp, [p.x, p.y, p.z]);
                    assert!(
                        w > 0.0 && inside(&r, q, 1e-9),
                        "{q:?} outside the box {r:?}"
                    );
                }
            }
        }
        out.push(r);
    });
    out
}

fn check(m: &ClusteredMesh, mvp: &Mat4, mode: CullMode, pixels: u16, hierarchy: bool, rows: u32) {
    let config = config(mode, pixels);
    let cull = ClusterCull {
        test: ClusterTest::Volumes,
        hierarchy,
    };
    let colors = vec![MESH; m.indices.len()];
    let plain = Mesh {
        positions: &m.positions,
        indices: &m.indices,
        attributes: MeshColors::PerTriangle(&colors),
        bounds: None,
    };
    let filled = Mesh {
        attributes: DetailFill {
            attributes: MeshColors::PerTriangle(&colors),
            fill: rgb(FILL),
        },
        positions: plain.positions,
        indices: plain.indices,
        bounds: plain.bounds,
    };
    let rects = boxes(m, mvp, &config, cull);
    let (holes, s0) = draw(m, &plain, mvp, config, cull, None);
    let (got, s1) = draw(m, &filled, mvp, config, cull, None);
    for (i, (&g, &h)) in got.iter().zip(&holes).enumerate() {
        if g != h {
            assert_eq!(g, FILL, "pixel {i}: only boxes are added");
        }
        if g == FILL {
            let c = [f64::from(i as u32 % W) + 0.5, f64::from(i as u32 / W) + 0.5];
            assert!(
                rects.iter().any(|r| inside(r, c, SNAP)),
                "fill pixel {c:?} outside every box"
            );
        }
    }
    assert_eq!(
        Stats {
            detail_boxes: 0,
            ..s1
        },
        s0,
        "the triangle counters are plain detail culling's"
    );
    assert!(s1.detail_boxes <= 2 * rects.len() as u64 * microraster::MAX_PIECES as u64);
    if rects.is_empty() {
        assert_eq!(got, holes);
    }
    let (strips, _) = draw(m, &filled, mvp, config, cull, Some(rows));
    assert!(strips == got, "strips of {rows} rows draw another frame");
}

proptest! {
    #![proptest_config(ProptestConfig { cases: cases(24), ..ProptestConfig::default() })]

    #[test]
    fn detail_boxes_cover_what_they_replace_and_draw_only_there(
        which in 0usize..3,
        dir in prop::array::uniform3(-1.0f32..1.0),
        dist in 2.0f32..40.0,
        pixels in prop::sample::select(vec![1u16, 2, 3, 6, 12]),
        mode in prop::sample::select(vec![CullMode::Back, CullMode::None, CullMode::Front]),
        hierarchy in any::<bool>(),
        rows in prop::sample::select(vec![1u32, 7, 16, 120]),
    ) {
        let m = &models()[which];
        if let Some(mvp) = camera(m, dir, dist) {
            check(m, &mvp, mode, pixels, hierarchy, rows);
        }
    }
}

/// The bunny far away (10 radii, 2 px, the `cull --detail` case): drawn
/// in its own colour, the boxes change fewer pixels than the holes do.
#[test]
fn detail_boxes_change_fewer_pixels_than_holes_on_the_far_bunny() {
    let m = &models()[0];
    let config = config(CullMode::Back, 2);
    let cull = ClusterCull {
        test: ClusterTest::Volumes,
        hierarchy: true,
    };
    let colors = vec![MESH; m.indices.len()];
    let plain = Mesh {
        positions: &m.positions,
        indices: &m.indices,
        attributes: MeshColors::PerTriangle(&colors),
        bounds: None,
    };
    let filled = Mesh {
        attributes: DetailFill {
            attributes: MeshColors::PerTriangle(&colors),
            fill: rgb(MESH),
        },
        positions: plain.positions,
        indices: plain.indices,
        bounds: plain.bounds,
    };
    let (mut holes_total, mut boxes_total, mut covered) = (0usize, 0usize, 0usize);
    for dir in [
        [0.3, 0.4, 1.0],
        [-1.0, 0.2, 0.1],
        [0.1, 1.0, -0.5],
        [0.7, -0.3, -1.0],
    ] {
        let mvp = camera(m, dir, 10.0).unwrap();
        let (exact, _) = draw(
            m,
            &plain,
            &mvp,
            Config {
                detail: 0,
                ..config
            },
            cull,
            None,
        );
        let (holes, s) = draw(m, &plain, &mvp, config, cull, None);
        let (boxed, _) = draw(m, &filled, &mvp, config, cull, None);
        assert!(s.culled_detail > 0);
        let diff = |a: &[Rgb888]| a.iter().zip(&exact).filter(|(x, y)| x != y).count();
        holes_total += diff(&holes);
        boxes_total += diff(&boxed);
        covered += exact.iter().filter(|&&c| c != Rgb888::BLACK).count();
    }
    assert!(
        boxes_total * 2 < holes_total,
        "boxes change {boxes_total} pixels, holes {holes_total}, of {covered} covered"
    );
}

/// A far object dropped whole by its bounds is drawn as one box in the
/// fill colour, every fill pixel inside it; without a fill nothing is
/// drawn. A frame whose storage cannot take the box refuses it whole.
#[test]
fn a_far_object_dropped_whole_is_drawn_as_its_box() {
    let m = &models()[2];
    let colors = vec![MESH; m.indices.len()];
    let bounds = BoundingSphere::from_points(&m.positions);
    let plain = Mesh {
        positions: &m.positions,
        indices: &m.indices,
        attributes: MeshColors::PerTriangle(&colors),
        bounds,
    };
    let filled = Mesh {
        attributes: DetailFill {
            attributes: MeshColors::PerTriangle(&colors),
            fill: rgb(FILL),
        },
        positions: plain.positions,
        indices: plain.indices,
        bounds: plain.bounds,
    };
    let n = m.indices.len() as u64;
    // About 12 pixels across at 20 radii.
    let far = camera(m, [0.2, 0.5, 1.0], 20.0).unwrap();
    let config = config(CullMode::Back, 24);
    let quad = Detail::for_frame(&far, &config)
        .unwrap()
        .screen_box(&bounds.unwrap())
        .unwrap();
    let r = rect(quad);
    for mesh_cached in [false, true] {
        let run = |storage: usize| {
            let mut slots = vec![SetupTriangle::EMPTY; storage];
            let mut frame = Frame::new(config, &mut slots).unwrap();
            let mut cache = vec![ProcessedVertex::default(); m.positions.len()];
            let res = if mesh_cached {
                frame.submit_mesh_cached(&filled, &far, 0, &mut cache)
            } else {
                frame.submit_mesh(&filled, &far, 0)
            };
            let mut color = vec![Rgb888::BLACK; (W * H) as usize];
            let mut depth = vec![u16::MAX; (W * H) as usize];
            frame.render_rows(0, H, &mut color, &mut depth[..]).unwrap();
            (res, frame.stats(), color)
        };
        let (res, s, color) = run(64);
        res.unwrap();
        assert_eq!((s.submitted, s.culled_detail, s.stored), (n, n, 0));
        assert_eq!(s.detail_boxes, 2, "one box, two triangles");
        let fill: Vec<usize> = (0..color.len()).filter(|&i| color[i] == FILL).collect();
        assert!(fill.len() >= 50, "{} fill pixels", fill.len());
        assert_eq!(
            fill.len(),
            color.iter().filter(|&&c| c != Rgb888::BLACK).count()
        );
        for i in fill {
            let c = [f64::from(i as u32 % W) + 0.5, f64::from(i as u32 / W) + 0.5];
            assert!(
                inside(&r, c, SNAP),
                "fill pixel {c:?} outside the box {r:?}"
            );
        }
        // No room for the box: refused, nothing stored or counted.
        let (res, s, color) = run(1);
        assert!(matches!(res, Err(Error::StorageFull { .. })), "{res:?}");
        assert_eq!(s, Stats::default());
        assert!(color.iter().all(|&c| c == Rgb888::BLACK));
    }
    // Without a fill: nothing drawn.
    let mut slots = vec![SetupTriangle::EMPTY; 64];
    let mut frame = Frame::new(config, &mut slots).unwrap();
    frame.submit_mesh(&plain, &far, 0).unwrap();
    assert_eq!(frame.stats().detail_boxes, 0);
    assert!(frame.triangles().is_empty());
}

/// `render` (and so `render --cull-detail`, `bench --cull-detail`) drops
/// far objects whole, by their bounds, on every path: binned, on threads,
/// strip by strip with occlusion culling. With `scene::detail_boxes` they
/// become boxes in their mean colour, and the frame (colour, depth, ids)
/// is the same on 1 to 3 threads, at any strip height, with or without
/// occlusion culling.
#[test]
fn render_drops_far_objects_and_draws_their_boxes_on_every_path() {
    use microraster_host::bench_scenes::SpotGrid;
    use microraster_host::render::{render, DepthKind, Occlusion, RenderOptions};
    let (w, h) = (160u32, 120u32);
    let spots = SpotGrid::load().unwrap();
    let mut scene = spots
        .scene(
            6,
            [0.0, 8.0, 25.0],
            [0.0; 3],
            60.0,
            w as f32 / h as f32,
            false,
        )
        .unwrap();
    let opts = |detail, threads, rows, occlusion| RenderOptions {
        width: w,
        height: h,
        cull: CullMode::Back,
        detail,
        depth: DepthKind::U16,
        subpixel: 8,
        threads,
        strip_rows: rows,
        tile_width: 0,
        ids: true,
        mode: microraster::RasterMode::Clipping,
        inv_w: false,
        occlusion,
    };
    let exact = render(&scene, &opts(0, 1, h, Occlusion::Off)).unwrap();
    let holes = render(&scene, &opts(12, 1, h, Occlusion::Off)).unwrap();
    let n = scene.triangle_count() as u64;
    assert_eq!(exact.stats.culled_detail, 0);
    assert!(
        holes.stats.culled_detail * 2 > n,
        "{} of {n} dropped",
        holes.stats.culled_detail
    );
    assert_eq!(holes.stats.detail_boxes, 0);
    assert!(holes.rgb != exact.rgb);
    microraster_host::scene::detail_boxes(&mut scene);
    assert!(scene.objects.iter().all(|o| o.detail_fill.is_some()));
    let boxed = render(&scene, &opts(12, 1, h, Occlusion::Off)).unwrap();
    assert_eq!(boxed.stats.culled_detail, holes.stats.culled_detail);
    assert!(boxed.stats.detail_boxes > 0);
    assert!(boxed.rgb != holes.rgb);
    // Off, the fills change nothing.
    let off = render(&scene, &opts(0, 1, h, Occlusion::Off)).unwrap();
    assert!(off.rgb == exact.rgb && off.depth == exact.depth);
    for (threads, rows, occlusion) in [
        (2, h, Occlusion::Off),
        (3, 7, Occlusion::Off),
        (1, 16, Occlusion::Strips),
        (2, 5, Occlusion::On),
    ] {
        let r = render(&scene, &opts(12, threads, rows, occlusion)).unwrap();
        let at = format!("{threads} threads, {rows} rows, {occlusion:?}");
        assert!(r.rgb == boxed.rgb, "colour, {at}");
        assert!(r.depth == boxed.depth, "depth, {at}");
        assert!(r.ids == boxed.ids, "ids, {at}");
    }
}
