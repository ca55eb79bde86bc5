//! Occlusion culling ([`microraster::occlusion`]) draws the frame the plain
//! submissions draw, byte for byte, colour and depth: a property test over
//! random scenes of boxes (a wall near the eye, many behind it), random
//! cameras, strip heights, both subpixel precisions, `u16` and `u32`
//! depth, `Less` and `LessEqual`; and named cases for what must not be
//! culled.

use microraster::occlusion::{tiles_for, HiZTile};
use microraster::pixelcolor::Rgb888;
use microraster::prelude::*;
use microraster::{
    BoundingSphere, Config, DepthFunc, Error, Mat4, Mesh, MeshColors, ProcessedVertex, Stats,
    StripRenderer, Vec3,
};
use proptest::prelude::*;

const W: u32 = 48;
const H: u32 = 40;

/// A unit box (corners at ±1), outward faces wound counter-clockwise.
const POSITIONS: [Vec3; 8] = {
    let mut p = [Vec3::new(0.0, 0.0, 0.0); 8];
    let mut i = 0;
    while i < 8 {
        p[i] = Vec3::new(
            if i & 1 == 1 { 1.0 } else { -1.0 },
            if i & 2 == 2 { 1.0 } else { -1.0 },
            if i & 4 == 4 { 1.0 } else { -1.0 },
        );
        i += 1;
    }
    p
};

const INDICES: [[u32; 3]; 12] = [
    [0, 2, 1],
    [1, 2, 3],
    [4, 5, 6],
    [5, 7, 6],
    [0, 1, 4],
    [1, 5, 4],
    [2, 6, 3],
    [3, 6, 7],
    [0, 4, 2],
    [2, 4, 6],
    [1, 3, 5],
    [3, 7, 5],
];

/// A box object: where it is, how big (per axis), its colour seed.
#[derive(Clone, Copy, Debug)]
struct Object {
    model: Mat4,
    colors: [Rgb888; 8],
}

fn object(pos: [f32; 3], size: [f32; 3], seed: u8) -> Object {
    Object {
        model: Mat4::translation(Vec3::new(pos[0], pos[1], pos[2]))
            * Mat4::scale(Vec3::new(size[0], size[1], size[2])),
        colors: core::array::from_fn(|i| {
            Rgb888::new(seed.wrapping_mul(37), (40 * i) as u8, 255 - seed)
        }),
    }
}

/// The sphere around the unit box, in object space.
const BOUND: BoundingSphere = BoundingSphere {
    center: Vec3::new(0.0, 0.0, 0.0),
    radius: 1.7321,
};

/// Draws `objects` in order through strips of `rows` rows, plainly or
/// through an occluder; returns colour, depth and the summed counters.
fn draw<const S: u32, T: DepthWord>(
    config: Config,
    view_proj: &Mat4,
    objects: &[Object],
    rows: u32,
    occlude: bool,
) -> (Vec<Rgb888>, Vec<T>, Stats) {
    let mut color = vec![Rgb888::new(0, 0, 0); (W * H) as usize];
    let mut depth = vec![T::FAR; (W * H) as usize];
    let mut stats = Stats::default();
    let mut cache = [ProcessedVertex::EMPTY; 8];
    let mut tiles = vec![HiZTile::default(); tiles_for(W, rows)];
    let mut y0 = 0;
    while y0 < H {
        let y1 = (y0 + rows).min(H);
        let span = (W * y0) as usize..(W * y1) as usize;
        let mut r: StripRenderer<'_, Rgb888, [T], S> = StripRenderer::with_subpixel_bits(
            config,
            y0,
            y1,
            &mut color[span.clone()],
            &mut depth[span],
        )
        .unwrap();
        if occlude {
            let mut o = r.occluder(&mut tiles).unwrap();
            for (k, ob) in objects.iter().enumerate() {
                let mesh = Mesh {
                    positions: &POSITIONS,
                    indices: &INDICES,
                    attributes: MeshColors::PerVertex(&ob.colors),
                    bounds: Some(BOUND),
                };
                let mvp = *view_proj * ob.model;
                o.submit_mesh_cached(&mesh, &mvp, 12 * k as u32, &mut cache)
                    .unwrap();
            }
        } else {
            for (k, ob) in objects.iter().enumerate() {
                let mesh = Mesh {
                    positions: &POSITIONS,
                    indices: &INDICES,
                    attributes: MeshColors::PerVertex(&ob.colors),
                    bounds: Some(BOUND),
                };
                let mvp = *view_proj * ob.model;
                r.submit_mesh_cached(&mesh, &mvp, 12 * k as u32, &mut cache)
                    .unwrap();
            }
        }
        stats += r.stats();
        y0 = y1;
    }
    (color, depth, stats)
}

/// A camera at `eye` looking at `target`.
fn camera(eye: [f32; 3], target: [f32; 3], fov: f32, near: f32) -> Mat4 {
    Mat4::perspective(fov, W as f32 / H as f32, near, 60.0)
        * Mat4::look_at(
            Vec3::new(eye[0], eye[1], eye[2]),
            Vec3::new(target[0], target[1], target[2]),
            Vec3::new(0.0, 1.0, 0.0),
        )
}

/// A wall across the view and `behind` boxes scattered behind it, sorted
/// front to back along -z (the cameras look down -z, roughly).
fn scene(wall: [f32; 4], behind: &[([f32; 3], f32)]) -> Vec<Object> {
    let mut v = vec![object(
        [wall[0], wall[1], wall[2]],
        [wall[3], wall[3] * 0.7, 0.2],
        1,
    )];
    for (k, (p, s)) in behind.iter().enumerate() {
        v.push(object(*p, [*s, *s * 1.3, *s * 0.8], k as u8 + 2));
    }
    v[1..].sort_by(|a, b| b.model.rows()[2][3].total_cmp(&a.model.rows()[2][3]));
    v
}

fn check<const S: u32, T: DepthWord>(
    config: Config,
    vp: &Mat4,
    objects: &[Object],
    rows: u32,
) -> Result<Stats, TestCaseError> {
    let plain = draw::<S, T>(config, vp, objects, H, false);
    let occluded = draw::<S, T>(config, vp, objects, rows, true);
    prop_assert!(plain.0 == occluded.0, "colour differs (rows {})", rows);
    prop_assert!(plain.1 == occluded.1, "depth differs (rows {})", rows);
    Ok(occluded.2)
}

fn arb_scene() -> impl Strategy<Value = (Mat4, Vec<Object>)> {
    (
        (-1.0f32..1.0, -1.0f32..1.0, 0.5f32..2.0),
        (0.4f32..1.6, 0.02f32..0.5),
        (-1.5f32..1.5, -1.0f32..1.0, -4.0f32..-1.0, 0.5f32..3.0),
        prop::collection::vec(
            ((-4.0f32..4.0, -3.0f32..3.0, -25.0f32..-3.0), 0.05f32..1.5),
            1..24,
        ),
        // Tiny boxes (tight spheres) across the wall's edges, their front
        // faces within a few u16 LSBs of the wall's, in front or behind:
        // the bound's margins decide them.
        prop::collection::vec(
            (
                (-1.3f32..1.3, -1.3f32..1.3),
                -0.004f32..0.004,
                0.0002f32..0.01,
            ),
            0..16,
        ),
    )
        .prop_map(|(eye, (fov, near), wall, behind, tiny)| {
            let vp = camera([eye.0, eye.1, eye.2], [eye.0 * 0.5, 0.0, -10.0], fov, near);
            let mut behind: Vec<_> = behind
                .into_iter()
                .map(|((x, y, z), s)| ([x, y, z], s))
                .collect();
            let front = wall.2 + 0.2;
            for ((u, v), d, s) in tiny {
                behind.push((
                    [
                        wall.0 + u * wall.3,
                        wall.1 + v * wall.3 * 0.7,
                        front + d - s * 0.8,
                    ],
                    s,
                ));
            }
            (vp, scene([wall.0, wall.1, wall.2, wall.3], &behind))
        })
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 256, ..ProptestConfig::default() })]

    /// Occluded strips draw exactly the plain frame, whatever is hidden.
    #[test]
    fn occluded_frames_are_the_plain_frames(
        (vp, objects) in arb_scene(),
        rows in prop_oneof![Just(H), 1u32..=H],
        less_equal in any::<bool>(),
        cull in any::<bool>(),
    ) {
        let mut config = Config::new(W, H);
        config.depth_func = if less_equal { DepthFunc::LessEqual } else { DepthFunc::Less };
        if !cull {
            config.cull = microraster::CullMode::None;
        }
        check::<8, u16>(config, &vp, &objects, rows)?;
        check::<4, u16>(config, &vp, &objects, rows)?;
        check::<8, u32>(config, &vp, &objects, rows)?;
        check::<4, u32>(config, &vp, &objects, rows)?;
    }
}

/// The property has teeth: on its own kind of scene the occluder does
/// hide boxes (most of those behind a wide wall).
#[test]
fn a_wall_hides_most_boxes_behind_it() {
    let vp = camera([0.0, 0.0, 1.0], [0.0, 0.0, -10.0], 1.0, 0.1);
    let behind: Vec<_> = (0..20)
        .map(|k| {
            let k = k as f32;
            (
                [
                    (k % 5.0 - 2.0) * 0.8,
                    (k / 5.0).floor() * 0.5 - 1.0,
                    -6.0 - k,
                ],
                0.3,
            )
        })
        .collect();
    let objects = scene([0.0, 0.0, -2.0, 4.0], &behind);
    let config = Config::new(W, H);
    for rows in [H, 16, 7] {
        let s = check::<8, u16>(config, &vp, &objects, rows).unwrap();
        let strips = H.div_ceil(rows) as u64;
        // Every box behind the wall is hidden in every strip it reaches.
        assert!(
            s.culled_occlusion >= 12 * 15,
            "rows {rows}: {} of {} culled",
            s.culled_occlusion,
            12 * 21 * strips
        );
    }
}

/// A box straddling the eye plane has no bound: never culled, whatever is
/// in front.
#[test]
fn a_box_through_the_eye_plane_is_drawn() {
    let vp = camera([0.0, 0.0, 1.0], [0.0, 0.0, -10.0], 1.0, 0.1);
    let objects = vec![
        object([0.0, 0.0, -2.0], [5.0, 5.0, 0.2], 1),
        object([0.0, 0.0, 1.0], [0.5, 0.5, 0.5], 2),
    ];
    let s = check::<8, u16>(Config::new(W, H), &vp, &objects, H).unwrap();
    assert_eq!(s.culled_occlusion, 0);
}

/// Only `Less` and `LessEqual` hide: under `Greater` (and the rest)
/// nothing is culled, and the frame is the plain one.
#[test]
fn other_depth_tests_cull_nothing() {
    let vp = camera([0.0, 0.0, 1.0], [0.0, 0.0, -10.0], 1.0, 0.1);
    let objects = scene([0.0, 0.0, -2.0, 4.0], &[([0.0, 0.0, -8.0], 0.5)]);
    for func in [
        DepthFunc::Greater,
        DepthFunc::Equal,
        DepthFunc::NotEqual,
        DepthFunc::Always,
    ] {
        let mut config = Config::new(W, H);
        config.depth_func = func;
        let s = check::<8, u16>(config, &vp, &objects, 8).unwrap();
        assert_eq!(s.culled_occlusion, 0, "{func:?}");
    }
}

/// Too few tiles is a typed error; more are fine, and stale contents do
/// not matter (every tile starts stale).
#[test]
fn wrong_tile_counts() {
    let config = Config::new(W, H);
    let mut color = vec![Rgb888::new(0, 0, 0); (W * 10) as usize];
    let mut depth = vec![0u16; (W * 10) as usize];
    let mut r = StripRenderer::new(config, 5, 15, &mut color, &mut depth[..]).unwrap();
    let need = tiles_for(W, 10);
    assert_eq!(need, 6 * 2);
    let mut few = vec![HiZTile::default(); need - 1];
    assert_eq!(
        r.occluder(&mut few).map(|_| ()),
        Err(Error::HiZSize {
            expected: need,
            actual: need - 1
        })
    );
    let mut many = vec![HiZTile::default(); need + 5];
    assert!(r.occluder(&mut many).is_ok());
}

/// A sphere the caller does not give draws the object and reads the
/// whole strip again: nothing stale hides what follows.
#[test]
fn an_unbounded_object_refreshes_every_tile() {
    let vp = camera([0.0, 0.0, 1.0], [0.0, 0.0, -10.0], 1.0, 0.1);
    let config = Config::new(W, H);
    let mut color = vec![Rgb888::new(0, 0, 0); (W * H) as usize];
    let mut depth = vec![u16::MAX; (W * H) as usize];
    let mut cache = [ProcessedVertex::EMPTY; 8];
    let mut tiles = vec![HiZTile::default(); tiles_for(W, H)];
    let mut r = StripRenderer::new(config, 0, H, &mut color, &mut depth[..]).unwrap();
    let mut o = r.occluder(&mut tiles).unwrap();
    let far = object([0.0, 0.0, -8.0], [0.5, 0.5, 0.5], 3);
    let wall = object([0.0, 0.0, -2.0], [5.0, 5.0, 0.2], 1);
    let colors = [Rgb888::new(9, 9, 9); 8];
    let mut mesh = Mesh {
        positions: &POSITIONS,
        indices: &INDICES,
        attributes: MeshColors::PerVertex(&colors),
        bounds: Some(BOUND),
    };
    // The far box is tested against an empty strip (tiles now fresh)...
    assert!(o
        .submit_mesh_cached(&mesh, &(vp * far.model), 0, &mut cache)
        .unwrap());
    // ... then the wall, without a bound, covers it ...
    mesh.bounds = None;
    assert!(o
        .submit_mesh_cached(&mesh, &(vp * wall.model), 12, &mut cache)
        .unwrap());
    // ... so the far box is hidden now.
    mesh.bounds = Some(BOUND);
    assert!(!o
        .submit_mesh_cached(&mesh, &(vp * far.model), 24, &mut cache)
        .unwrap());
    assert_eq!(o.stats().culled_occlusion, 12);
}

/// A tile whose largest depth lets a bound pass, but which the bound's
/// rectangle covers only in part, is decided by the pixels of that part:
/// near ones hide the object, and one far pixel inside the rectangle, or
/// one column more, does not.
#[test]
fn a_tile_covered_in_part_is_read_where_the_bound_lies() {
    use microraster::occlusion::ScreenBound;
    let config = Config::new(W, H);
    let mut color = vec![Rgb888::new(0, 0, 0); (W * 16) as usize];
    // Near (a wall) in columns 0..13, far beyond: tile columns 8..16
    // hold both.
    let fill = |depth: &mut [u16]| {
        for (i, d) in depth.iter_mut().enumerate() {
            *d = if (i as u32 % W) < 13 { 1000 } else { u16::MAX };
        }
    };
    let mut depth = vec![0u16; (W * 16) as usize];
    fill(&mut depth);
    let bound = |x1: u32| ScreenBound {
        x0: 2,
        x1,
        y0: 0,
        y1: 16,
        near: 2000 << 16,
    };
    let mut tiles = vec![HiZTile::default(); tiles_for(W, 16)];
    {
        let mut r = StripRenderer::new(config, 0, 16, &mut color, &mut depth[..]).unwrap();
        let mut o = r.occluder(&mut tiles).unwrap();
        assert!(o.hides(&bound(12)));
        assert!(o.hides(&bound(13)));
        assert!(!o.hides(&bound(14)));
    }
    // One far pixel inside the rectangle, in the straddling tile.
    depth[(5 * W + 10) as usize] = u16::MAX;
    let mut r = StripRenderer::new(config, 0, 16, &mut color, &mut depth[..]).unwrap();
    let mut o = r.occluder(&mut tiles).unwrap();
    assert!(!o.hides(&bound(12)));
    assert!(o.hides(&ScreenBound { y0: 6, ..bound(12) }));
}
