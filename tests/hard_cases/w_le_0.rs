//! w <= 0.

use super::*;

/// (-0.5,-0.5,0,1), (0.5,-0.5,0,1), (0,-0.5,0,-1) on 64x64, culling off:
/// the part with w > 0 is the wedge below NDC y = -0.5 (window row 48),
/// widening downwards: row j covers the columns whose centre is within
/// (j - 15.5) / 2 px of x = 32, i.e. 32, 34, 34, ..., 46, 46, 48 pixels:
/// 640 in all, nothing above row 48 (not an upright mirrored triangle).
#[test]
fn w_le_0_wedge_covers_640_pixels() {
    let tri = [
        v(-0.5, -0.5, 0.0, 1.0),
        v(0.5, -0.5, 0.0, 1.0),
        v(0.0, -0.5, 0.0, -1.0),
    ];
    let expected: Vec<u32> = (0..64 * 64)
        .map(|k| {
            let (i, j) = ((k % 64) as f64, (k / 64) as f64);
            (j >= 48.0 && (i + 0.5 - 32.0).abs() <= (j - 15.5) / 2.0) as u32
        })
        .collect();
    assert_eq!(expected.iter().sum::<u32>(), 640);
    for order in [tri, [tri[2], tri[0], tri[1]], [tri[1], tri[0], tri[2]]] {
        let (_, ids8) = run::<8>(config_nocull(64, 64), &[order]);
        let (_, ids4) = run::<4>(config_nocull(64, 64), &[order]);
        for ids in [ids8, ids4] {
            assert_eq!(count(&ids), 640);
            assert_eq!(count(&ids[..48 * 64]), 0, "nothing above row 48");
            assert_eq!(ids, expected);
        }
        let counts = hit_counts::<8>(config_nocull(64, 64), &[order]);
        assert!(counts.iter().all(|&n| n <= 1), "clipped pieces overlap");
    }
}

/// A triangle with all three vertices behind the eye (w < 0) draws
/// nothing, whatever x, y, z are, and stores nothing.
#[test]
fn all_vertices_behind_the_eye_draw_nothing() {
    let mut rng = SplitMix(11);
    for _ in 0..2000 {
        let mut tri = [v(0.0, 0.0, 0.0, 1.0); 3];
        for t in tri.iter_mut() {
            let w = -rng.range(0.05, 4.0) as f32;
            let r = |rng: &mut SplitMix| rng.range(-3.0, 3.0) as f32 * w.abs();
            *t = v(r(&mut rng), r(&mut rng), r(&mut rng), w);
        }
        // Also the mirror image of a visible triangle.
        let mirror = [
            v(0.5, 0.5, 0.0, -1.0),
            v(-0.5, 0.5, 0.0, -1.0),
            v(0.0, -0.5, 0.0, -1.0),
        ];
        for t in [tri, mirror] {
            let (s8, ids8) = run::<8>(config_nocull(32, 32), &[t]);
            let (s4, ids4) = run::<4>(config_nocull(32, 32), &[t]);
            assert_eq!((count(&ids8), count(&ids4)), (0, 0), "{t:?}");
            assert_eq!((s8.stored, s4.stored), (0, 0), "{t:?}");
        }
    }
}
