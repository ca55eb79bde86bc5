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

/// A house (its seed and rooms a side, 2 to 5) and a camera in one of its
/// rooms, at least `CAMERA_MARGIN` from the walls, 0.5 to 2.1 high,
/// looking in any direction (pitch within 0.4): seed, rooms, eye, target.
fn house_camera_strategy() -> impl Strategy<Value = (u64, usize, [f32; 3], [f32; 3])> {
    (
        (any::<u64>(), 2usize..6, any::<u16>()),
        (0.0f32..1.0, 0.0f32..1.0, 0.5f32..2.1),
        (0.0f32..std::f32::consts::TAU, -0.4f32..0.4),
    )
        .prop_map(|((seed, n, room), (fx, fz, eye_y), (yaw, pitch))| {
            let room = room as usize % (n * n);
            let (i, j) = (room / n, room % n);
            let inner = ROOM - WALL - 2.0 * CAMERA_MARGIN;
            let x = i as f32 * ROOM + 0.5 * WALL + CAMERA_MARGIN + fx * inner;
            let z = j as f32 * ROOM + 0.5 * WALL + CAMERA_MARGIN + fz * inner;
            let eye = [x, eye_y, z];
            (seed, n, eye, [x + yaw.cos(), eye_y + pitch, z + yaw.sin()])
        })
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 32, ..ProptestConfig::default() })]

    #[test]
    fn skipped_rooms_change_no_pixel(
        (seed, n, eye, target) in house_camera_strategy(),
        s8 in any::<bool>(),
        u32_depth in any::<bool>(),
    ) {
        let house = House::generate(n, seed);
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

/// The firmware's house (`examples/firmware/baked/house.rs`) is what
/// `microraster bake-house` writes today: the generator's 4x4 house and
/// camera of record, byte for byte (run `microraster bake-house --out
/// examples/firmware/baked` after changing the generator).
#[test]
fn firmware_house_bake_is_current() {
    use microraster_host::portal::{FIRMWARE_CAMERA, FIRMWARE_ROOMS};
    let baked = include_str!("../../examples/firmware/baked/house.rs");
    let now = House::generate(FIRMWARE_ROOMS, 1)
        .bake_source(FIRMWARE_CAMERA, 320, 240)
        .unwrap();
    assert!(
        now == baked,
        "examples/firmware/baked/house.rs is stale: run microraster bake-house --out examples/firmware/baked"
    );
}

/// The firmware's house frame from the generator itself (its objects,
/// unshared vertices, through `House::scene`), drawn as the firmware
/// draws it (`Rgb565`, `u16` depth, 15-row strips, immediate mode) with
/// every room and with the rooms the walk reaches: both give
/// `examples/firmware/host-checksums.txt`'s `house`, which
/// `.ci/firmware.sh` holds both firmware builds to.
#[test]
fn firmware_house_frame_is_the_checksum_of_record() {
    use microraster::pixelcolor::{IntoStorage, Rgb565, RgbColor};
    use microraster::{Config, Mesh, StripRenderer, Submit};
    use microraster_host::portal::{FIRMWARE_CAMERA, FIRMWARE_ROOMS};
    use microraster_scenes::checksum::FrameChecksum;
    let checksums = include_str!("../../examples/firmware/host-checksums.txt");
    let want = checksums
        .lines()
        .find_map(|l| l.strip_prefix("house "))
        .map(|v| u64::from_str_radix(v.trim().trim_start_matches("0x"), 16).unwrap())
        .expect("a house line in host-checksums.txt");
    let house = House::generate(FIRMWARE_ROOMS, 1);
    let (eye, target) = house_camera(FIRMWARE_CAMERA, FIRMWARE_ROOMS);
    let (w, h) = (320u32, 240u32);
    let config = Config::new(w, h);
    for portals in [false, true] {
        let (scene, report) = house
            .scene(eye, target, 60.0, w, h, false, portals)
            .unwrap();
        assert_eq!(report.count.is_some(), portals);
        let mut sum = FrameChecksum::new();
        for y0 in (0..h).step_by(15) {
            let y1 = (y0 + 15).min(h);
            let n = (w * (y1 - y0)) as usize;
            let (mut color, mut depth) = (vec![Rgb565::BLACK; n], vec![u16::MAX; n]);
            let mut strip = StripRenderer::new(config, y0, y1, &mut color, &mut depth[..]).unwrap();
            for o in &scene.objects {
                let mesh = Mesh {
                    positions: &o.positions,
                    indices: &o.indices,
                    attributes: o.colors.as_mesh_colors(),
                    bounds: o.bounds,
                };
                strip.submit_mesh(&mesh, &o.mvp, 0).unwrap();
            }
            sum.extend(color.iter().map(|p| p.into_storage()));
        }
        assert_eq!(
            sum.value(),
            want,
            "house (portals {portals}): {:#018x}, host-checksums.txt says {want:#018x}",
            sum.value()
        );
    }
}

/// The house drawn strip by strip (`rows` a strip, `Rgb565`), every
/// object through a `StripRenderer` at `S` subpixel bits into a depth
/// buffer of `Z` cleared to `far`; with `rects`, a strip skips the objects
/// of every room whose rectangle from the portal walk misses its rows (as
/// the firmware's `house-portals` does). The colour and depth of the frame.
fn strip_frame<const S: u32, Z: Copy>(
    house: &House,
    view_proj: &microraster::Mat4,
    (w, h): (u32, u32),
    rows: u32,
    rects: Option<&[microraster::portal::PixelRect]>,
    far: Z,
) -> (Vec<u16>, Vec<Z>)
where
    [Z]: microraster::DepthBuffer,
{
    use microraster::pixelcolor::{IntoStorage, Rgb565, RgbColor};
    use microraster::{Config, Mesh, StripRenderer, Submit};
    let config = Config::new(w, h);
    let (mut color, mut depth) = (Vec::new(), Vec::new());
    for y0 in (0..h).step_by(rows as usize) {
        let y1 = (y0 + rows).min(h);
        let n = (w * (y1 - y0)) as usize;
        let (mut c, mut z) = (vec![Rgb565::BLACK; n], vec![far; n]);
        let mut strip =
            StripRenderer::<_, _, S>::with_subpixel_bits(config, y0, y1, &mut c, &mut z[..])
                .unwrap();
        for (room, o) in house.objects() {
            if rects.is_some_and(|r| !r[room].meets_rows(y0, y1)) {
                continue;
            }
            let mesh = Mesh {
                positions: &o.positions,
                indices: &o.indices,
                attributes: o.colors.as_mesh_colors(),
                bounds: o.bounds,
            };
            strip.submit_mesh(&mesh, view_proj, 0).unwrap();
        }
        color.extend(c.iter().map(|p| p.into_storage()));
        depth.extend(z);
    }
    (color, depth)
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 32, ..ProptestConfig::default() })]

    /// The firmware's finer use of the walk: a strip draws a room only if
    /// the room's rectangle meets the strip's rows. Every pixel where a
    /// room is the nearest surface lies in its rectangle (the walk's
    /// claim), so the frame is the one drawn with every room in every
    /// strip, colour and depth, for any strip height.
    #[test]
    fn rooms_outside_a_strip_change_no_pixel(
        (seed, n, eye, target) in house_camera_strategy(),
        rows in 1u32..40,
        s8 in any::<bool>(),
        u32_depth in any::<bool>(),
    ) {
        use microraster::portal::PixelRect;
        let house = House::generate(n, seed);
        let size = (96, 72);
        let vp = house.view_proj(eye, target, 60.0, size.0, size.1, false).unwrap();
        let mut rects = vec![PixelRect::EMPTY; n * n];
        let start = house.room_of(eye).unwrap();
        house
            .graph()
            .unwrap()
            .visible(&vp, &microraster::Config::new(size.0, size.1), start, &mut rects)
            .unwrap();
        let (all, culled) = match (s8, u32_depth) {
            (true, false) => {
                let f = |r| { let (c, z) = strip_frame::<8, u16>(&house, &vp, size, rows, r, u16::MAX); (c, z.into_iter().map(u32::from).collect::<Vec<_>>()) };
                (f(None), f(Some(&rects[..])))
            }
            (false, false) => {
                let f = |r| { let (c, z) = strip_frame::<4, u16>(&house, &vp, size, rows, r, u16::MAX); (c, z.into_iter().map(u32::from).collect::<Vec<_>>()) };
                (f(None), f(Some(&rects[..])))
            }
            (true, true) => {
                let f = |r| strip_frame::<8, u32>(&house, &vp, size, rows, r, u32::MAX);
                (f(None), f(Some(&rects[..])))
            }
            (false, true) => {
                let f = |r| strip_frame::<4, u32>(&house, &vp, size, rows, r, u32::MAX);
                (f(None), f(Some(&rects[..])))
            }
        };
        prop_assert!(all.0 == culled.0, "colour, eye {:?} target {:?} rows {}", eye, target, rows);
        prop_assert!(all.1 == culled.1, "depth, eye {:?} target {:?} rows {}", eye, target, rows);
    }
}
