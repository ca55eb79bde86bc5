//! Bad input.

use super::*;

/// NaN or an infinity in any coordinate of any vertex: nothing drawn,
/// nothing stored, counted once in `rejected_nonfinite`.
#[test]
fn non_finite_coordinates_are_rejected() {
    let good = [
        v(-1.0, -1.0, 0.0, 1.0),
        v(1.0, -1.0, 0.0, 1.0),
        v(0.0, 1.0, 0.0, 1.0),
    ];
    for k in 0..3 {
        for c in 0..4 {
            for bad in [f32::NAN, f32::INFINITY, f32::NEG_INFINITY] {
                let mut t = good;
                match c {
                    0 => t[k].x = bad,
                    1 => t[k].y = bad,
                    2 => t[k].z = bad,
                    _ => t[k].w = bad,
                }
                for (s, ids) in [
                    run::<8>(config_nocull(8, 8), &[t]),
                    run::<4>(config_nocull(8, 8), &[t]),
                ] {
                    assert_eq!(count(&ids), 0);
                    assert_eq!(
                        s,
                        Stats {
                            submitted: 1,
                            rejected_nonfinite: 1,
                            ..Stats::default()
                        },
                        "vertex {k} component {c} = {bad}"
                    );
                }
            }
        }
    }
}

/// Zero area after snapping (collinear, all three equal, two equal,
/// collinear only after snapping): culled as degenerate.
#[test]
fn zero_area_triangles_are_culled_degenerate() {
    let cases = [
        [
            v(-0.5, -0.5, 0.0, 1.0),
            v(0.0, 0.0, 0.0, 1.0),
            v(0.5, 0.5, 0.0, 1.0),
        ],
        [v(0.1, 0.2, 0.0, 1.0); 3],
        [
            v(0.1, 0.2, 0.0, 1.0),
            v(0.1, 0.2, 0.0, 1.0),
            v(0.7, -0.3, 0.0, 1.0),
        ],
        [
            v(-0.9, 0.3, 0.0, 1.0),
            v(0.9, 0.3, 0.0, 1.0),
            v(0.0, 0.3, 0.0, 1.0),
        ],
        // Collinear only after snapping: 1e-6 NDC is far below 1/256 px.
        [
            v(-0.5, -0.5, 0.0, 1.0),
            v(0.0, 1.0e-6, 0.0, 1.0),
            v(0.5, 0.5, 0.0, 1.0),
        ],
        // Collinear in NDC, given at different w.
        [
            v(-1.0, -1.0, 0.0, 2.0),
            v(0.0, 0.0, 0.0, 1.0),
            v(2.0, 2.0, 0.0, 4.0),
        ],
    ];
    for t in cases {
        for (s, ids) in [
            run::<8>(config_nocull(32, 32), &[t]),
            run::<4>(config_nocull(32, 32), &[t]),
        ] {
            assert_eq!(count(&ids), 0);
            assert_eq!(
                s,
                Stats {
                    submitted: 1,
                    culled_degenerate: 1,
                    ..Stats::default()
                },
                "{t:?}"
            );
        }
    }
}

/// A small triangle whose bounding box holds no pixel centre: culled as
/// degenerate (setup rejects it before any rasterization).
#[test]
fn no_pixel_centre_in_bounding_box_is_culled_degenerate() {
    let (w, h) = (16, 16);
    let cases = [
        [(3.6, 3.6), (4.4, 3.6), (3.6, 4.4)],
        [(3.6, 3.1), (4.4, 3.2), (4.0, 3.45)],
        [(0.55, 0.55), (0.95, 0.6), (0.7, 0.99)],
    ];
    for p in cases {
        let t = tri_win(p, w, h);
        for (s, ids) in [
            run::<8>(config_nocull(w, h), &[t]),
            run::<4>(config_nocull(w, h), &[t]),
        ] {
            assert_eq!(count(&ids), 0);
            assert_eq!(
                s,
                Stats {
                    submitted: 1,
                    culled_degenerate: 1,
                    ..Stats::default()
                },
                "{p:?}"
            );
        }
    }
}
