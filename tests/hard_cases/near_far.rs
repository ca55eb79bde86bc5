//! Near and far planes (§9).

use super::*;

/// A full-frame quad (two triangles) with NDC depth z(x); every vertex
/// scaled by its own w.
pub(crate) fn depth_quad(z: impl Fn(f32) -> f32, ws: [f32; 4]) -> [[Vec4; 3]; 2] {
    let c = [(-1.0f32, -1.0f32), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)];
    let p: Vec<Vec4> = (0..4)
        .map(|k| {
            let (x, y) = c[k];
            let w = ws[k];
            v(x * w, y * w, z(x) * w, w)
        })
        .collect();
    [[p[0], p[1], p[2]], [p[0], p[2], p[3]]]
}

/// A quad crossing the near plane (z = x - 1.25 NDC) is drawn only where
/// z >= -w: x >= 0.25, columns 40..64 of 64x64, 24 x 64 = 1536 pixels.
/// One crossing the far plane (z = x + 0.75) only where z <= w: columns
/// 0..40, 2560 pixels. With and without per-vertex w; pieces never overlap.
#[test]
fn near_far_crossing_drawn_only_inside_the_depth_range() {
    let mut rng = SplitMix(31);
    for k in 0..20 {
        let ws = if k == 0 {
            [1.0; 4]
        } else {
            [0; 4].map(|_| rng.range(0.2, 8.0) as f32)
        };
        for (quad, cols) in [
            (depth_quad(|x| x - 1.25, ws), 40..64),
            (depth_quad(|x| x + 0.75, ws), 0..40),
        ] {
            for s4 in [false, true] {
                let cfg = config_nocull(64, 64);
                let counts = if s4 {
                    hit_counts::<4>(cfg, &quad)
                } else {
                    hit_counts::<8>(cfg, &quad)
                };
                for (p, &n) in counts.iter().enumerate() {
                    assert_eq!(n, cols.contains(&(p % 64)) as u32, "w {ws:?}, pixel {p}");
                }
            }
        }
    }
}

/// Vulkan `clip_volume`: primitives at z/w = -1, 0, 1 exactly are drawn
/// (the whole frame); at -1.5 and 1.5 nothing is drawn and they are
/// counted as culled by the frustum.
#[test]
fn clip_volume_depth_planes_exactly() {
    for (z, drawn) in [
        (-1.0f32, true),
        (0.0, true),
        (1.0, true),
        (-1.5, false),
        (1.5, false),
        (-1.0001, false),
        (1.0001, false),
    ] {
        for ws in [[1.0f32; 4], [0.5, 2.0, 3.0, 7.0]] {
            let quad = depth_quad(|_| z, ws);
            let (s, ids) = run::<8>(config_nocull(16, 16), &quad);
            assert_eq!(count(&ids), if drawn { 256 } else { 0 }, "z/w = {z}");
            if !drawn {
                assert_eq!(s.culled_frustum, 2, "z/w = {z}: {s:?}");
            }
        }
    }
}
