//! 1/w depth ([`Mat4::perspective_inv_w`]): window depth `near / w`,
//! reversed, in both rasterization modes, against the exact value; and the
//! same visibility as window z where the surfaces are apart by more than
//! the rounding of either.

mod common;

use microraster::pixelcolor::Rgb888;
use microraster::prelude::*;
use microraster::{
    Config, CullMode, DepthF32, DepthFunc, DepthWord, Mat4, NoDepth, RasterMode, StripRenderer,
    TriangleId, Vec3, Vec4,
};

const W: u32 = 64;
const H: u32 = 48;
const NEAR: f32 = 0.1;
const FAR: f32 = 100.0;

/// The modes this build has (the clipless one only with the core's
/// `clipless` feature).
fn modes() -> Vec<RasterMode> {
    let mut m = vec![RasterMode::Clipping];
    if cfg!(feature = "clipless") {
        m.push(RasterMode::Clipless);
    }
    m
}

fn projections() -> (Mat4, Mat4) {
    (
        Mat4::perspective(1.0, W as f32 / H as f32, NEAR, FAR),
        Mat4::perspective_inv_w(1.0, W as f32 / H as f32, NEAR),
    )
}

/// Draws eye-space triangles with `proj` into a `u32` depth buffer (ids
/// too): window z under `Less` from 1.0, 1/w under `Greater` from 0.
fn draw(mode: RasterMode, proj: &Mat4, inv_w: bool, tris: &[[Vec3; 3]]) -> (Vec<u32>, Vec<u32>) {
    draw_with::<u32>(mode, proj, inv_w, tris)
}

/// [`draw`] into a buffer of `W` words.
fn draw_with<Z: DepthWord>(
    mode: RasterMode,
    proj: &Mat4,
    inv_w: bool,
    tris: &[[Vec3; 3]],
) -> (Vec<u32>, Vec<Z>) {
    let mut config = Config::new(W, H);
    config.cull = CullMode::None;
    config.mode = mode;
    config.depth_func = if inv_w {
        DepthFunc::Greater
    } else {
        DepthFunc::Less
    };
    let n = (W * H) as usize;
    let mut ids = vec![TriangleId(0); n];
    let mut depth = vec![if inv_w { Z::NEAR } else { Z::FAR }; n];
    let mut r = StripRenderer::new(config, 0, H, &mut ids, &mut depth[..]).unwrap();
    for (i, t) in tris.iter().enumerate() {
        let c = t.map(|p| proj.transform_point(p));
        r.submit_clip_triangle(c, [Rgb888::WHITE; 3], i as u32)
            .unwrap();
    }
    (ids.iter().map(|t| t.0).collect(), depth)
}

/// `1 / w` at the centre of pixel `(x, y)` on the plane of the eye-space
/// triangle `t`, in `f64` (the ray through the pixel meets the plane).
fn exact_inv_w(t: &[Vec3; 3], x: u32, y: u32) -> f64 {
    exact_inv_w_at(t, x as f64 + 0.5, y as f64 + 0.5)
}

/// [`exact_inv_w`] at window point `(px, py)`.
fn exact_inv_w_at(t: &[Vec3; 3], px: f64, py: f64) -> f64 {
    // The projection's own x and y scales (as built, with whichever float
    // backend: micromath's tan is approximate).
    let m = projections().1.rows();
    let (sx, sy) = (m[0][0] as f64, m[1][1] as f64);
    // The eye-space ray direction with z = -1 through the pixel centre.
    let nx = px / W as f64 * 2.0 - 1.0;
    let ny = 1.0 - py / H as f64 * 2.0;
    let d = [nx / sx, ny / sy, -1.0];
    let p = t.map(|v| [v.x as f64, v.y as f64, v.z as f64]);
    let e1 = [p[1][0] - p[0][0], p[1][1] - p[0][1], p[1][2] - p[0][2]];
    let e2 = [p[2][0] - p[0][0], p[2][1] - p[0][1], p[2][2] - p[0][2]];
    let nrm = [
        e1[1] * e2[2] - e1[2] * e2[1],
        e1[2] * e2[0] - e1[0] * e2[2],
        e1[0] * e2[1] - e1[1] * e2[0],
    ];
    let dot = |a: [f64; 3], b: [f64; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    // s d on the plane: s = (n . p0) / (n . d); w = s (the ray's z is -s).
    let s = dot(nrm, p[0]) / dot(nrm, d);
    1.0 / s
}

fn random_tris(seed: u64, n: usize) -> Vec<[Vec3; 3]> {
    let mut rng = common::SplitMix(seed);
    (0..n)
        .map(|_| {
            let depth = rng.range(0.3, 60.0);
            let c = [
                rng.range(-0.5, 0.5) * depth,
                rng.range(-0.4, 0.4) * depth,
                -depth,
            ];
            let mut v = || {
                Vec3::new(
                    (c[0] + rng.range(-0.4, 0.4) * depth) as f32,
                    (c[1] + rng.range(-0.4, 0.4) * depth) as f32,
                    (c[2] + rng.range(-0.3, 0.3) * depth) as f32,
                )
            };
            [v(), v(), v()]
        })
        .collect()
}

/// Every written depth is `near / w` at the pixel to within the rounding
/// of the `f32` vertex stage (a few hundred `Z32` units: `2^-24` of the
/// clip coordinates) plus, in the clipping mode, what moving the vertices
/// by the snapping (half of 1/256 px) changes at the pixel, and in the
/// clipless mode the quantization of the vertex (`2^-22` of the depth
/// range); and nothing is clipped far away.
#[test]
fn depth_is_near_over_w() {
    let (_, inv) = projections();
    for mode in modes() {
        let mut worst = 0f64;
        let mut checked = 0;
        for (k, t) in random_tris(11, 300).iter().enumerate() {
            let (ids, depth) = draw(mode, &inv, true, &[*t]);
            for y in 0..H {
                for x in 0..W {
                    let i = (y * W + x) as usize;
                    if ids[i] == 0 {
                        continue;
                    }
                    let z = |px: f64, py: f64| {
                        exact_inv_w_at(t, px, py) * NEAR as f64 * 4_294_967_296.0
                    };
                    let (cx, cy) = (x as f64 + 0.5, y as f64 + 0.5);
                    let want = z(cx, cy);
                    // The plane's change over the snapping distance.
                    let h = 1.0 / 512.0;
                    let snap = (z(cx + h, cy) - want).abs() + (z(cx, cy + h) - want).abs();
                    let err = (depth[i] as f64 - want).abs();
                    // Clipping: the snapping's change. Clipless: the vertex
                    // quantization, 2^-22 of each vertex's largest
                    // coordinate (about 2 w D, and N = 2 near D): about
                    // 2^-22 of the depth range, 1,024 Z32 units.
                    let bound = 512.0
                        + match mode {
                            RasterMode::Clipping => 2.0 * snap,
                            RasterMode::Clipless => 4096.0,
                        };
                    assert!(
                        err < bound,
                        "{mode:?} triangle {k} ({x}, {y}): {} against {want} (bound {bound})",
                        depth[i]
                    );
                    worst = worst.max(err / bound);
                    checked += 1;
                }
            }
        }
        assert!(checked > 10_000, "{checked}");
        println!("{mode:?}: worst error {worst:.3} of its bound");
    }
    // Far beyond any far plane: drawn, at depth near / w.
    let far = [
        Vec3::new(-1e4, -1e4, -1e5),
        Vec3::new(1e4, -1e4, -1e5),
        Vec3::new(0.0, 1e4, -1e5),
    ];
    for mode in modes() {
        let (ids, depth) = draw(mode, &inv, true, &[far]);
        let i = (H / 2 * W + W / 2) as usize;
        assert_ne!(ids[i], 0, "{mode:?}");
        // 4,295 Z32 units, to within the absolute rounding of the window
        // depth (z/w * 0.5 + 0.5 in f32 in the clipping mode: 2^-25 of
        // the range, 128 units, twice) or of the quantization.
        let want = NEAR as f64 / 1e5 * 4_294_967_296.0;
        assert!(
            (depth[i] as f64 - want).abs() < 512.0,
            "{mode:?}: {} against {want}",
            depth[i]
        );
    }
}

/// Overlapping triangles: 1/w and window z pick the same one wherever the
/// exact depths differ by more than the rounding of both (relative
/// `1e-5`), in both modes.
#[test]
fn same_visibility_as_window_z() {
    let (z, inv) = projections();
    for mode in modes() {
        let tris = random_tris(23, 40);
        let (a, _) = draw(mode, &z, false, &tris);
        let (b, _) = draw(mode, &inv, true, &tris);
        let mut differ = 0;
        for y in 0..H {
            for x in 0..W {
                let i = (y * W + x) as usize;
                if a[i] == b[i] {
                    continue;
                }
                differ += 1;
                assert!(
                    a[i] != 0 && b[i] != 0,
                    "{mode:?} ({x}, {y}): coverage differs"
                );
                let (ta, tb) = (&tris[a[i] as usize - 1], &tris[b[i] as usize - 1]);
                let (da, db) = (exact_inv_w(ta, x, y), exact_inv_w(tb, x, y));
                assert!(
                    (da - db).abs() <= 1e-5 * da.max(db),
                    "{mode:?} ({x}, {y}): z picks {} (1/w {da}), 1/w picks {} ({db})",
                    a[i],
                    b[i]
                );
            }
        }
        assert!(differ < 20, "{mode:?}: {differ} pixels");
    }
    let _ = NoDepth;
    let _ = Vec4::new(0.0, 0.0, 0.0, 1.0);
}

/// An `f32` buffer holds the `u32` buffer's depths to its own precision
/// (24 significant bits, truncated: within `2^-23` of the value, and never
/// more than one `Z32` unit below where the `u32` keeps fewer bits), with
/// the same pixels, in both modes and both depth kinds; far away (1/w
/// near 0) it keeps bits below `Z32`. (Those bits are interpolation, not
/// accuracy: vertex depths are `Z32`, made from an `f32` window depth, so
/// the `f32` buffer is no closer to the exact 1/w than the `u32` one.)
#[test]
fn f32_buffer_holds_the_u32_depths() {
    let (z, inv) = projections();
    for mode in modes() {
        for (proj, inv_w) in [(&z, false), (&inv, true)] {
            let tris = random_tris(5, 60);
            let (ia, a) = draw_with::<u32>(mode, proj, inv_w, &tris);
            let (ib, b) = draw_with::<DepthF32>(mode, proj, inv_w, &tris);
            let mut finer = 0;
            for i in 0..a.len() {
                if ia[i] != ib[i] {
                    // Only where two surfaces tie to within the rounding.
                    let d = (a[i] as f64 - b[i].get() as f64 * 4_294_967_296.0).abs();
                    assert!(
                        d < 1e-5 * a[i] as f64,
                        "{mode:?} {inv_w} pixel {i}: ids {} {} depths {} {:?}",
                        ia[i],
                        ib[i],
                        a[i],
                        b[i]
                    );
                    continue;
                }
                let (u, f) = (a[i] as f64, b[i].get() as f64 * 4_294_967_296.0);
                assert!(
                    (u - f).abs() <= (u / 8_388_608.0).max(1.0),
                    "{mode:?} inv_w {inv_w} pixel {i}: u32 {u}, f32 {f}"
                );
                finer += (f.fract() != 0.0) as u32;
            }
            if inv_w {
                assert!(finer > 10, "{mode:?}: {finer} depths below one Z32 unit");
            }
        }
    }
}
