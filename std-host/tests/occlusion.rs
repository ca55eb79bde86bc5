//! Occlusion culling on the host (`render::Occlusion`): the spots scene
//! (Spots split into parts, boxes as bounds, front to back) and the cubes
//! (spheres as bounds) draw the frame the binned pipeline draws, colour,
//! depth and ids byte-identical, over random cameras among the herd, both
//! subpixel precisions, strip heights and 1 to 3 threads; and the test
//! does hide most of a herd seen from eye height.

use microraster_host::bench_scenes::{spots_camera, SpotGrid};
use microraster_host::render::{render, DepthKind, Occlusion, RenderOptions};
use microraster_host::scene::{Scene, View};
use proptest::prelude::*;

const W: u32 = 96;
const H: u32 = 72;

fn opts(
    occlusion: Occlusion,
    threads: usize,
    rows: u32,
    subpixel: u32,
    depth: DepthKind,
) -> RenderOptions {
    RenderOptions {
        width: W,
        height: H,
        ..sized(occlusion, threads, rows, subpixel, depth, (W, H))
    }
}

fn sized(
    occlusion: Occlusion,
    threads: usize,
    rows: u32,
    subpixel: u32,
    depth: DepthKind,
    (width, height): (u32, u32),
) -> RenderOptions {
    RenderOptions {
        width,
        height,
        cull: microraster::CullMode::Back,
        detail: 0,
        depth,
        subpixel,
        threads,
        strip_rows: rows,
        tile_width: 0,
        ids: true,
        mode: microraster::RasterMode::Clipping,
        inv_w: false,
        occlusion,
    }
}

/// Renders `scene` plainly and with occlusion culling (and the strips
/// without it); returns the counters of the culled render.
fn same(
    scene: &Scene,
    threads: usize,
    rows: u32,
    subpixel: u32,
    depth: DepthKind,
) -> microraster::Stats {
    same_sized(scene, threads, rows, subpixel, depth, (W, H))
}

fn same_sized(
    scene: &Scene,
    threads: usize,
    rows: u32,
    subpixel: u32,
    depth: DepthKind,
    size: (u32, u32),
) -> microraster::Stats {
    let o = |occ, threads, rows| sized(occ, threads, rows, subpixel, depth, size);
    let want = render(scene, &o(Occlusion::Off, 1, size.1)).unwrap();
    let base = render(scene, &o(Occlusion::Strips, threads, rows)).unwrap();
    let got = render(scene, &o(Occlusion::On, threads, rows)).unwrap();
    for (name, r) in [("strips", &base), ("occlusion", &got)] {
        assert!(
            r.rgb == want.rgb,
            "{name}: colour, {threads} threads, {rows} rows, S {subpixel}"
        );
        assert!(r.depth == want.depth, "{name}: depth");
        assert!(r.ids == want.ids, "{name}: ids");
    }
    assert_eq!(base.stats.culled_occlusion, 0);
    got.stats
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 24, ..ProptestConfig::default() })]

    /// A 4x4 herd from random cameras at random heights among and around
    /// it: identical frames.
    #[test]
    fn occlusion_draws_the_plain_frame(
        k in 0usize..64,
        height in -0.5f32..1.5,
        pull in 0.3f32..1.2,
        threads in 1usize..=3,
        rows in prop_oneof![Just(H), 1u32..=24],
        subpixel in prop_oneof![Just(4u32), Just(8)],
        wide in any::<bool>(),
    ) {
        let spots = SpotGrid::load().unwrap();
        let (eye, target) = spots_camera(k, 64, 4);
        let eye = [eye[0] * pull, height, eye[2] * pull];
        let scene = spots.scene(4, eye, target, 60.0, W as f32 / H as f32, false).unwrap();
        let depth = if wide { DepthKind::U32 } else { DepthKind::U16 };
        same(&scene, threads, rows, subpixel, depth);
    }
}

/// The herd of the measurements at their size (320x240), from eye height:
/// most of what is in the frustum is hidden, whole or by parts.
#[test]
fn a_herd_from_eye_height_is_mostly_hidden() {
    let spots = SpotGrid::load().unwrap();
    let mut hidden = 0.0;
    for k in [0, 13, 29, 45] {
        let (eye, target) = spots_camera(k, 64, 10);
        let scene = spots
            .scene(10, eye, target, 60.0, 320.0 / 240.0, false)
            .unwrap();
        let s = same_sized(&scene, 2, 240, 8, DepthKind::U16, (320, 240));
        let inside = (s.submitted - s.culled_object) as f64;
        hidden += s.culled_occlusion as f64 / inside / 4.0;
    }
    assert!(hidden > 0.5, "{hidden}");
}

/// Objects with spheres only (the cubes, which hide little): identical,
/// and the refusals.
#[test]
fn spheres_only_and_refusals() {
    let scene = microraster_host::bench_scenes::builtin("cubes", &View::new(W, H))
        .unwrap()
        .scene;
    for rows in [H, 5] {
        same(&scene, 2, rows, 8, DepthKind::U16);
        same(&scene, 1, rows, 4, DepthKind::F32);
    }
    let none = opts(Occlusion::On, 1, H, 8, DepthKind::None);
    assert!(render(&scene, &none).unwrap_err().contains("depth buffer"));
    let clipless = RenderOptions {
        mode: microraster::RasterMode::Clipless,
        ..opts(Occlusion::On, 1, H, 8, DepthKind::U16)
    };
    assert!(render(&scene, &clipless).is_err());
}
