//! Errors.

use super::*;

/// Wrong row ranges and buffer sizes return the typed error and leave both
/// buffers untouched.
#[test]
fn render_rows_errors_leave_buffers_untouched() {
    let (w, h) = (8u32, 6u32);
    let mut st = storage(2);
    let mut frame: Frame = Frame::new(config_nocull(w, h), &mut st).unwrap();
    frame
        .submit_clip_triangle(
            [
                v(-1.0, -1.0, 0.0, 1.0),
                v(3.0, -1.0, 0.0, 1.0),
                v(-1.0, 3.0, 0.0, 1.0),
            ],
            RED3,
            0,
        )
        .unwrap();
    let sentinel_c = Rgb888::new(1, 2, 3);
    let sentinel_z = 0x5A5A_5A5Au32;
    // (y0, y1, colour len, depth len, expected error)
    let rows_err = |y0, y1| Error::InvalidRows { y0, y1, height: h };
    let cases: Vec<(u32, u32, usize, usize, Error)> = vec![
        (3, 3, 0, 0, rows_err(3, 3)),
        (4, 3, 8, 8, rows_err(4, 3)),
        (0, 7, 56, 56, rows_err(0, 7)),
        (6, 7, 8, 8, rows_err(6, 7)),
        (
            0,
            6,
            47,
            48,
            Error::ColorBufferSize {
                expected: 48,
                actual: 47,
            },
        ),
        (
            0,
            6,
            49,
            48,
            Error::ColorBufferSize {
                expected: 48,
                actual: 49,
            },
        ),
        (
            2,
            3,
            0,
            8,
            Error::ColorBufferSize {
                expected: 8,
                actual: 0,
            },
        ),
        (
            0,
            6,
            48,
            47,
            Error::DepthBufferSize {
                expected: 48,
                actual: 47,
            },
        ),
        (
            0,
            6,
            48,
            49,
            Error::DepthBufferSize {
                expected: 48,
                actual: 49,
            },
        ),
        (
            1,
            3,
            16,
            0,
            Error::DepthBufferSize {
                expected: 16,
                actual: 0,
            },
        ),
        (
            0,
            6,
            47,
            49,
            Error::ColorBufferSize {
                expected: 48,
                actual: 47,
            },
        ),
    ];
    for (y0, y1, nc, nz, err) in cases {
        let mut c = vec![sentinel_c; nc];
        let mut z = vec![sentinel_z; nz];
        assert_eq!(
            frame.render_rows(y0, y1, &mut c[..], &mut z[..]),
            Err(err),
            "rows {y0}..{y1}, {nc}, {nz}"
        );
        assert!(c.iter().all(|&p| p == sentinel_c) && z.iter().all(|&d| d == sentinel_z));
        let mut z16 = vec![0x5A5Au16; nz];
        let mut ids = vec![TriangleId(77); nc];
        assert_eq!(
            frame.render_rows(y0, y1, &mut ids[..], &mut z16[..]),
            Err(err)
        );
        assert!(ids.iter().all(|&p| p == TriangleId(77)) && z16.iter().all(|&d| d == 0x5A5A));
    }
    // Without a depth buffer only the colour size matters.
    let mut c = [sentinel_c; 9];
    assert_eq!(
        frame.render_rows(0, 1, &mut c[..], &mut NoDepth),
        Err(Error::ColorBufferSize {
            expected: 8,
            actual: 9
        })
    );
    assert!(c.iter().all(|&p| p == sentinel_c));
    // And the right sizes work.
    let mut c = [sentinel_c; 16];
    let mut z = [u32::MAX; 16];
    assert!(frame.render_rows(4, 6, &mut c[..], &mut z[..]).is_ok());
}

/// Zero or oversized frame sizes: `Error::InvalidFrameSize` carrying them.
#[test]
fn invalid_frame_sizes_are_rejected() {
    for (w, h) in [
        (0, 1),
        (1, 0),
        (0, 0),
        (MAX_DIMENSION + 1, 1),
        (1, MAX_DIMENSION + 1),
        (u32::MAX, u32::MAX),
        (65536, 1),
    ] {
        let mut st = storage(1);
        let r8 = Frame::<8>::new(Config::new(w, h), &mut st).err();
        assert_eq!(
            r8,
            Some(Error::InvalidFrameSize {
                width: w,
                height: h
            })
        );
        let r4 = Frame::<4>::with_subpixel_bits(Config::new(w, h), &mut st).err();
        assert_eq!(
            r4,
            Some(Error::InvalidFrameSize {
                width: w,
                height: h
            })
        );
    }
    let mut st = storage(1);
    assert!(Frame::<8>::new(Config::new(MAX_DIMENSION, MAX_DIMENSION), &mut st).is_ok());
    assert!(Frame::<8>::new(Config::new(1, 1), &mut st).is_ok());
}

/// Full storage: `StorageFull`, and nothing of the triangle is stored or
/// counted, even when only some of its clipped pieces would fit.
#[test]
fn storage_full_stores_nothing() {
    let mut st = vec![SetupTriangle::EMPTY; 2];
    let mut frame: Frame = Frame::new(config_nocull(16, 16), &mut st).unwrap();
    let small = [
        v(-0.5, -0.5, 0.0, 1.0),
        v(0.5, -0.5, 0.0, 1.0),
        v(0.0, 0.5, 0.0, 1.0),
    ];
    // One vertex behind the near plane: the clipped quad needs 2 pieces.
    let two_pieces = [
        v(-0.5, -0.5, 0.0, 1.0),
        v(0.5, -0.5, 0.0, 1.0),
        v(0.0, 0.5, -3.0, 1.0),
    ];
    frame.submit_clip_triangle(small, RED3, 0).unwrap();
    let before = (frame.stats(), frame.triangles().to_vec());
    assert_eq!(
        frame.submit_clip_triangle(two_pieces, RED3, 1),
        Err(Error::StorageFull {
            capacity: 2,
            free: 1,
            needed: 2
        })
    );
    assert_eq!((frame.stats(), frame.triangles().to_vec()), before);
    frame.submit_clip_triangle(small, RED3, 2).unwrap();
    let before = (frame.stats(), frame.triangles().to_vec());
    assert_eq!(
        frame.submit_clip_triangle(small, RED3, 3),
        Err(Error::StorageFull {
            capacity: 2,
            free: 0,
            needed: 1
        })
    );
    assert_eq!((frame.stats(), frame.triangles().to_vec()), before);
    // Triangles that store nothing are still accepted and counted.
    let culled = [
        v(5.0, 5.0, 0.0, 1.0),
        v(6.0, 5.0, 0.0, 1.0),
        v(5.0, 6.0, 0.0, 1.0),
    ];
    frame.submit_clip_triangle(culled, RED3, 4).unwrap();
    assert_eq!(frame.stats().culled_frustum, 1);
    // The two pieces fit into an empty frame of capacity 2.
    frame.clear();
    frame.submit_clip_triangle(two_pieces, RED3, 1).unwrap();
    assert_eq!(frame.stats().stored, 2);
    assert_eq!(frame.stats().clipped, 1);
}

/// `draw_mesh` is all-or-nothing: a mesh that does not fit leaves the
/// frame exactly as it was; index errors and object culling are counted.
#[test]
fn draw_mesh_is_all_or_nothing() {
    let positions = [
        Vec3::new(-0.5, -0.5, 0.0),
        Vec3::new(0.5, -0.5, 0.0),
        Vec3::new(0.5, 0.5, 0.0),
        Vec3::new(-0.5, 0.5, 0.0),
    ];
    let indices = [[0, 1, 2], [0, 2, 3], [0, 3, 2], [1, 0, 3]];
    let mesh = Mesh {
        positions: &positions,
        indices: &indices,
        attributes: MeshColors::Uniform(Rgb888::new(1, 2, 3)),
        bounds: None,
    };
    let mut st = vec![SetupTriangle::EMPTY; 5];
    let mut frame: Frame = Frame::new(config_nocull(16, 16), &mut st).unwrap();
    frame
        .submit_clip_triangle(
            [
                v(-0.5, -0.5, 0.0, 1.0),
                v(0.5, -0.5, 0.0, 1.0),
                v(0.0, 0.5, 0.0, 1.0),
            ],
            RED3,
            99,
        )
        .unwrap();
    frame
        .submit_clip_triangle(
            [
                v(-0.5, -0.5, 0.0, 1.0),
                v(0.5, -0.5, 0.0, 1.0),
                v(0.0, 0.5, 0.0, 1.0),
            ],
            RED3,
            98,
        )
        .unwrap();
    let before = (frame.stats(), frame.triangles().to_vec(), frame_ids(&frame));
    let err = frame.submit_mesh(&mesh, &Mat4::IDENTITY, 0).unwrap_err();
    assert!(
        matches!(err, Error::StorageFull { capacity: 5, .. }),
        "{err:?}"
    );
    assert_eq!(
        (frame.stats(), frame.triangles().to_vec(), frame_ids(&frame)),
        before
    );
    // The cached path too.
    let mut cache = [ProcessedVertex::EMPTY; 4];
    let err = frame
        .submit_mesh_cached(&mesh, &Mat4::IDENTITY, 0, &mut cache)
        .unwrap_err();
    assert!(
        matches!(err, Error::StorageFull { capacity: 5, .. }),
        "{err:?}"
    );
    assert_eq!(
        (frame.stats(), frame.triangles().to_vec(), frame_ids(&frame)),
        before
    );
    // It fits after a clear.
    frame.clear();
    frame.submit_mesh(&mesh, &Mat4::IDENTITY, 10).unwrap();
    assert_eq!(frame.stats().stored, 4);
    assert_eq!(
        frame.triangles().iter().map(|t| t.id()).collect::<Vec<_>>(),
        vec![10, 11, 12, 13]
    );
    // A bad index is counted, not stored.
    frame.clear();
    let bad = [[0, 1, 2], [0, 1, 9]];
    let m = Mesh {
        indices: &bad,
        ..mesh
    };
    frame.submit_mesh(&m, &Mat4::IDENTITY, 0).unwrap();
    assert_eq!(
        (
            frame.stats().submitted,
            frame.stats().rejected_index,
            frame.stats().stored
        ),
        (2, 1, 1)
    );
    // An object outside the frustum is culled whole, even with full storage.
    frame.clear();
    for i in 0..5 {
        frame
            .submit_clip_triangle(
                [
                    v(-0.5, -0.5, 0.0, 1.0),
                    v(0.5, -0.5, 0.0, 1.0),
                    v(0.0, 0.5, 0.0, 1.0),
                ],
                RED3,
                i,
            )
            .unwrap();
    }
    let far = Mesh {
        bounds: BoundingSphere::from_points(&positions),
        ..mesh
    };
    frame
        .submit_mesh(&far, &Mat4::translation(Vec3::new(10.0, 0.0, 0.0)), 0)
        .unwrap();
    assert_eq!(frame.stats().culled_object, 4);
    assert_eq!(frame.stats().submitted, 9);
}
