//! Portal culling ([`microraster::portal`]) in the generated house: the
//! rooms the walk skips draw nothing, so the frame with them skipped is the
//! frame with every room drawn, colour and depth byte for byte, over random
//! houses and cameras (any room, any direction), both subpixel precisions
//! and both integer depth buffers; and the walk does skip most rooms.

use microraster_host::portal::{house_camera, House, CAMERA_MARGIN, EYE_HEIGHT, ROOM, WALL};
use microraster_host::render::{render, DepthKind, Occlusion, RenderOptions};
use microraster_host::scene::Scene;
use proptest::prelude::*;

fn opts(w: u32, h: u32, subpixel: u32, depth: DepthKind, threads: usize) -> RenderOptions {
    RenderOptions {
        width: w,
        height: h,
        cull: microraster::CullMode::Back,
        detail: 0,
        depth,
        subpixel,
        threads,
        strip_rows: 16,
        tile_width: 0,
        ids: false,
        mode: microraster::RasterMode::Clipping,
        inv_w: false,
        occlusion: Occlusion::Off,
    }
}

/// Renders the house from `eye` to `target` with and without portal
/// culling, asserts the frames equal; returns (rooms reached, rooms).
fn same(
    house: &House,
    eye: [f32; 3],
    target: [f32; 3],
    (w, h): (u32, u32),
    subpixel: u32,
    depth: DepthKind,
) -> (u32, u32) {
    let scene = |portals| {
        house
            .scene(eye, target, 60.0, w, h, false, portals)
            .unwrap()
    };
    let (all, none) = scene(false);
    assert_eq!(none.count, None);
    let (culled, report) = scene(true);
    let count = report.count.expect("the eye is in a room");
    let o = opts(w, h, subpixel, depth, 2);
    let a = render(&all, &o).unwrap();
    let b = render(&culled, &o).unwrap();
    assert!(a.pixels_written > 0);
    assert_eq!(a.rgb, b.rgb, "colour, eye {eye:?} target {target:?}");
    assert_eq!(a.depth, b.depth, "depth, eye {eye:?} target {target:?}");
    let tris = |s: &Scene| s.triangle_count() as u64;
    assert_eq!(tris(&culled) + report.triangles, tris(&all));
    (count.reached, count.cells)
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 32, ..ProptestConfig::default() })]

    #[test]
    fn skipped_rooms_change_no_pixel(
        seed in any::<u64>(),
        n in 2usize..6,
        room in any::<u16>(),
        fx in 0.0f32..1.0,
        fz in 0.0f32..1.0,
        yaw in 0.0f32..std::f32::consts::TAU,
        pitch in -0.4f32..0.4,
        eye_y in 0.5f32..2.1,
        s8 in any::<bool>(),
        u32_depth in any::<bool>(),
    ) {
        let house = House::generate(n, seed);
        let room = room as usize % (n * n);
        let (i, j) = (room / n, room % n);
        let inner = ROOM - WALL - 2.0 * CAMERA_MARGIN;
        let x = i as f32 * ROOM + 0.5 * WALL + CAMERA_MARGIN + fx * inner;
        let z = j as f32 * ROOM + 0.5 * WALL + CAMERA_MARGIN + fz * inner;
        let eye = [x, eye_y, z];
        let target = [x + yaw.cos(), eye_y + pitch, z + yaw.sin()];
        let depth = if u32_depth { DepthKind::U32 } else { DepthKind::U16 };
        same(&house, eye, target, (96, 72), if s8 { 8 } else { 4 }, depth);
    }
}

/// The house's own cameras at 320x240: the same frames, and most rooms
/// skipped.
#[test]
fn house_cameras_skip_most_rooms() {
    let house = House::generate(8, 1);
    let (mut reached, mut cells) = (0, 0);
    for k in 0..8 {
        let (eye, target) = house_camera(k, 8);
        assert!((eye[1] - EYE_HEIGHT).abs() < 1e-6);
        let (r, c) = same(&house, eye, target, (320, 240), 8, DepthKind::U16);
        reached += r;
        cells += c;
    }
    assert!(
        (reached as f64) < 0.3 * cells as f64,
        "{reached} of {cells} rooms reached"
    );
}

/// An eye in a wall or outside the house: nothing is skipped.
#[test]
fn eye_in_no_room_skips_nothing() {
    let house = House::generate(3, 7);
    for eye in [[ROOM, 1.6, 1.0], [-3.0, 1.6, 2.0], [2.0, 5.0, 2.0]] {
        assert_eq!(house.room_of(eye), None);
        let (s, r) = house
            .scene(eye, [2.0, 1.0, 2.5], 60.0, 64, 48, false, true)
            .unwrap();
        assert_eq!((r.count, r.triangles), (None, 0));
        assert_eq!(s.objects.len(), 9 * 4);
    }
    assert_eq!(house.room_of([2.0, 1.6, 6.0]), Some(1));
    assert_eq!(house.room_of([6.0, 1.6, 2.0]), Some(3));
}
