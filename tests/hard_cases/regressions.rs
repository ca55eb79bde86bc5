//! Defects found by hostile-value tests (debug profile, overflow checks
//! on), each reduced to its reproducer. Every test here failed (or
//! panicked) before its fix. The compile-time check of the subpixel
//! precision (`fixed::snap::<32>`, `guard_band_ndc::<32>`,
//! `pixel_center::<0>` and `::<64>` used to panic at run time) is proved
//! by `compile_fail` doctests on those functions instead.

use super::*;

/// A mesh of `n` triangles over three vertices, with a bounding sphere
/// that lies behind the eye (so submitting it costs O(1)).
fn culled_mesh_parts(n: usize) -> (Vec<Vec3>, Vec<[u32; 3]>) {
    let positions = vec![
        Vec3::new(0.0, 0.0, 5.0),
        Vec3::new(1.0, 0.0, 5.0),
        Vec3::new(0.0, 1.0, 5.0),
    ];
    (positions, vec![[0, 1, 2]; n])
}

/// Defect 1: submitting a 2^22-triangle mesh 1024 times without `clear()`
/// overflowed the `u32` counters ("attempt to add with overflow" in a
/// debug build, silent wrapping in release).
#[test]
fn counters_do_not_overflow_past_2_pow_32_triangles() {
    let (positions, indices) = culled_mesh_parts(1 << 22);
    let mesh = Mesh {
        positions: &positions,
        indices: &indices,
        attributes: MeshColors::Uniform(Rgb888::new(1, 2, 3)),
        bounds: BoundingSphere::from_points(&positions),
    };
    // Looking down -z from the origin: the mesh at z = +5 is behind.
    let mvp = Mat4::perspective(1.0, 1.0, 0.1, 100.0);
    let mut st = storage(4);
    let mut frame = Frame::new(config_nocull(16, 16), &mut st).unwrap();
    for _ in 0..1024 {
        frame.submit_mesh(&mesh, &mvp, 0).unwrap();
    }
    assert_eq!(frame.stats().submitted, 1 << 32);
    assert_eq!(frame.stats().culled_object, 1 << 32);

    let mut color = [TriangleId(0); 16 * 4];
    let mut no_depth = NoDepth;
    let mut strip =
        StripRenderer::new(config_nocull(16, 16), 0, 4, &mut color, &mut no_depth).unwrap();
    for _ in 0..1024 {
        strip.submit_mesh(&mesh, &mvp, 0).unwrap();
    }
    assert_eq!(strip.stats().submitted, 1 << 32);
    // Adding counters saturates rather than panicking.
    let big = Stats {
        submitted: u64::MAX,
        ..Stats::default()
    };
    assert_eq!((big + frame.stats()).submitted, u64::MAX);
}

/// Defect 2: `Mat4::row(4)` panicked (index out of bounds).
#[test]
fn mat4_row_out_of_range_is_none() {
    let m = Mat4::translation(Vec3::new(1.0, 2.0, 3.0));
    assert_eq!(m.row(0), Some([1.0, 0.0, 0.0, 1.0]));
    assert_eq!(m.row(4), None);
    assert_eq!(m.row(usize::MAX), None);
    assert_eq!(Mat4::from_rows(m.rows()), m);
}

/// Defect 4: a triangle that clips into three pieces, pushed into storage
/// of capacity 1, returned `StorageFull { needed: 1 }` (it needs 3) and
/// left its first piece in `storage[0]`.
#[test]
fn storage_full_reports_the_true_count_and_writes_no_slot() {
    let mut config = Config::new(16, 16);
    config.cull = CullMode::None;
    let tri = [
        v(0.076, 0.897, 1.106, 1.811),
        v(-0.358, 0.980, -2.353, 1.464),
        v(0.818, -0.841, 2.255, 0.811),
    ];
    // The pieces it really becomes, in roomy storage.
    let mut roomy = storage(16);
    let pieces = {
        let mut frame = Frame::new(config, &mut roomy).unwrap();
        frame.submit_clip_triangle(tri, RED3, 0).unwrap();
        frame.triangles().len()
    };
    assert_eq!(pieces, 3);

    let mut st = [SetupTriangle::EMPTY; 1];
    {
        let mut frame = Frame::new(config, &mut st).unwrap();
        assert_eq!(
            frame.submit_clip_triangle(tri, RED3, 0),
            Err(Error::StorageFull {
                capacity: 1,
                free: 1,
                needed: 3
            })
        );
        assert_eq!(frame.stats(), Stats::default());
        assert!(frame.triangles().is_empty());
    }
    assert_eq!(st[0], SetupTriangle::EMPTY, "the storage was written");

    // The same through a mesh, cached and uncached.
    let positions = [
        Vec3::new(0.076, 0.897, 1.106),
        Vec3::new(-0.358, 0.980, -2.353),
        Vec3::new(0.818, -0.841, 2.255),
    ];
    let ws = [1.811f32, 1.464, 0.811];
    // Per-vertex w through a matrix is not possible; scale x, y, z by 1/w
    // and keep w = 1 instead: the same projective points.
    let positions = positions
        .iter()
        .zip(ws)
        .map(|(p, w)| *p * (1.0 / w))
        .collect::<Vec<_>>();
    let indices = [[0u32, 1, 2]];
    let mesh = Mesh {
        positions: &positions,
        indices: &indices,
        attributes: MeshColors::Uniform(Rgb888::new(9, 9, 9)),
        bounds: None,
    };
    let mut st = [SetupTriangle::EMPTY; 1];
    {
        let mut frame = Frame::new(config, &mut st).unwrap();
        let mut cache = [ProcessedVertex::EMPTY; 3];
        let id = Mat4::IDENTITY;
        let e1 = frame.submit_mesh(&mesh, &id, 0);
        let e2 = frame.submit_mesh_cached(&mesh, &id, 0, &mut cache);
        assert!(
            matches!(e1, Err(Error::StorageFull { needed: 2.., .. })),
            "{e1:?}"
        );
        assert_eq!(e1, e2);
        assert_eq!(frame.stats(), Stats::default());
    }
    assert_eq!(st[0], SetupTriangle::EMPTY, "the storage was written");
}

/// Defect 5: the bounding-sphere test culled visible objects at large
/// coordinates (a mesh a few ulps across near 1e5, the camera just beside
/// it: 20 pixels without bounds, none with them).
/// The case's camera is computed with `libm` (the backend it was found
/// with; `micromath` gives another matrix, under which nothing is drawn).
#[cfg(feature = "libm")]
#[test]
fn bounding_sphere_keeps_a_tiny_mesh_far_from_the_origin() {
    use microraster::math::Libm;
    let p = |b: [u32; 3]| {
        Vec3::new(
            f32::from_bits(b[0]),
            f32::from_bits(b[1]),
            f32::from_bits(b[2]),
        )
    };
    let positions = [
        p([1199634138, 3337176766, 1209201136]),
        p([1199634144, 3337176766, 1209201136]),
        p([1199634138, 3337176760, 1209201142]),
    ];
    let eye = p([1199634125, 3337176895, 1209201164]);
    let mvp = Mat4::perspective_with::<Libm>(1.0, 1.0, 0.001, 100.0)
        * Mat4::look_at_with::<Libm>(eye, positions[0], Vec3::new(0.0, 1.0, 0.0));
    let indices = [[0u32, 1, 2]];
    let mut mesh = Mesh {
        positions: &positions,
        indices: &indices,
        attributes: MeshColors::Uniform(Rgb888::new(1, 2, 3)),
        bounds: None,
    };
    let draw = |mesh: &Mesh<'_>| {
        let mut st = storage(16);
        let mut frame = Frame::new(config_nocull(64, 64), &mut st).unwrap();
        frame.submit_mesh(mesh, &mvp, 0).unwrap();
        (frame_ids(&frame), frame.stats())
    };
    let (without, _) = draw(&mesh);
    assert!(count(&without) > 0, "the case must draw something");
    mesh.bounds = BoundingSphere::from_points(&positions);
    let (with, stats) = draw(&mesh);
    assert_eq!(stats.culled_object, 0);
    assert_eq!(with, without);
}

/// `render_strip` accepted the bins of a 64-row frame on
/// a 20-row one, and bins made before more triangles were added.
#[test]
fn bins_of_another_frame_are_refused() {
    let tri = [
        v(-0.9, -0.9, 0.0, 1.0),
        v(0.9, -0.9, 0.0, 1.0),
        v(0.0, 0.9, 0.0, 1.0),
    ];
    let mut s64 = storage(8);
    let mut tall = Frame::new(config_nocull(16, 64), &mut s64).unwrap();
    tall.submit_clip_triangle(tri, RED3, 0).unwrap();
    let mut s20 = storage(8);
    let mut short = Frame::new(config_nocull(16, 20), &mut s20).unwrap();
    short.submit_clip_triangle(tri, RED3, 0).unwrap();
    let (mut off, mut items) = ([0u32; 80], [0u32; 80]);
    let bins = tall.bin(4, &mut off, &mut items).unwrap();
    let mut c = [TriangleId(0); 16 * 4];
    assert_eq!(
        short.render_strip(&bins, 0, &mut c, &mut NoDepth),
        Err(Error::BinsMismatch)
    );
    assert!(tall.render_strip(&bins, 0, &mut c, &mut NoDepth).is_ok());
    // Past the end: an error, not a panic.
    assert!(tall.render_strip(&bins, 16, &mut c, &mut NoDepth).is_err());
    assert!(tall
        .render_strip(&bins, u32::MAX, &mut c, &mut NoDepth)
        .is_err());
    // Stale bins: made before another triangle was added.
    let (mut off2, mut items2) = ([0u32; 80], [0u32; 80]);
    let stale = short.bin(4, &mut off2, &mut items2).unwrap();
    assert_eq!(stale.strips(), 5);
    short.submit_clip_triangle(tri, RED3, 1).unwrap();
    assert_eq!(
        short.render_strip(&stale, 0, &mut c, &mut NoDepth),
        Err(Error::BinsMismatch)
    );
    // Strips of 0 rows are an error; any other height works.
    assert_eq!(
        short.bin(0, &mut off2, &mut items2).err(),
        Some(Error::InvalidStripRows)
    );
    for rows in [1u32, 19, 20, 21, u32::MAX] {
        let b = short.bin(rows, &mut off2, &mut items2).unwrap();
        assert_eq!(b.strips(), 20u32.div_ceil(rows));
    }
}

/// A finite input is never counted as non-finite. The triangle
/// below lies at y = -1e38 (drawn as nothing), and all-zero vertices are no
/// points at all (degenerate).
#[test]
fn finite_inputs_are_never_counted_as_nonfinite() {
    let cfg = config_nocull(64, 64);
    let far_below = [
        v(-1.0, -1.0, 0.0, 1e-38),
        v(1.0, -1.0, 0.0, 1e-38),
        v(0.0, 1.0, 0.0, -1e-38),
    ];
    let (s, ids) = run::<8>(cfg, &[far_below]);
    assert_eq!(count(&ids), 0);
    assert_eq!(s.rejected_nonfinite, 0, "{s:?}");
    assert_eq!(s.submitted, s.dropped(), "{s:?}");

    let zero = [v(0.0, 0.0, 0.0, 0.0); 3];
    let (s, ids) = run::<8>(cfg, &[zero]);
    assert_eq!(count(&ids), 0);
    assert_eq!(s.culled_degenerate, 1, "{s:?}");

    let one_zero = [
        v(0.0, 0.0, 0.0, 0.0),
        v(1.0, 0.0, 0.0, 1.0),
        v(0.0, 1.0, 0.0, 1.0),
    ];
    let (s, _) = run::<8>(cfg, &[one_zero]);
    assert_eq!(s.rejected_nonfinite, 0, "{s:?}");

    // A tiny but valid triangle: w near 1e-39 (1/w overflows f32) still
    // lands where it is.
    let tiny = [
        v(-0.5e-39, -0.5e-39, 0.0, 1e-39),
        v(0.5e-39, -0.5e-39, 0.0, 1e-39),
        v(0.0, 0.5e-39, 0.0, 1e-39),
    ];
    let big = [
        v(-0.5, -0.5, 0.0, 1.0),
        v(0.5, -0.5, 0.0, 1.0),
        v(0.0, 0.5, 0.0, 1.0),
    ];
    let (s, ids_tiny) = run::<8>(cfg, &[tiny]);
    assert_eq!(s.rejected_nonfinite, 0, "{s:?}");
    let (_, ids_big) = run::<8>(cfg, &[big]);
    assert_eq!(ids_tiny, ids_big);
    // Real NaN and infinity still are.
    let nan = [
        v(f32::NAN, 0.0, 0.0, 1.0),
        v(1.0, 0.0, 0.0, 1.0),
        v(0.0, 1.0, 0.0, 1.0),
    ];
    let (s, _) = run::<8>(cfg, &[nan]);
    assert_eq!(s.rejected_nonfinite, 1);
}

/// Depth buffers can be arrays as well as slices, and frames need no type
/// annotation.
#[test]
fn arrays_are_depth_buffers() {
    let tri = [
        v(-0.9, -0.9, 0.5, 1.0),
        v(0.9, -0.9, 0.5, 1.0),
        v(0.0, 0.9, 0.5, 1.0),
    ];
    let mut st = [SetupTriangle::EMPTY; 4];
    let mut frame = Frame::new(config_nocull(8, 8), &mut st).unwrap();
    frame.submit_clip_triangle(tri, RED3, 0).unwrap();
    let mut c1 = [TriangleId(0); 64];
    let mut c2 = [TriangleId(0); 64];
    let mut z_array = [u16::MAX; 64];
    let mut z_vec = [u16::MAX; 64];
    frame.render_rows(0, 8, &mut c1, &mut z_array).unwrap();
    frame.render_rows(0, 8, &mut c2, &mut z_vec[..]).unwrap();
    assert_eq!(c1, c2);
    assert_eq!(&z_array[..], &z_vec[..]);
    let mut short = [0u32; 63];
    assert!(matches!(
        frame.render_rows(0, 8, &mut c1, &mut short),
        Err(Error::DepthBufferSize { .. })
    ));
    assert_eq!(Frame::<8>::storage_for(1000), 1000 + 125 + 64);
}
