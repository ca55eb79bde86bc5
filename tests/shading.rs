//! Shading properties (proptest; `PROPTEST_CASES` sets the case count).
//!
//! - Coverage and depth do not depend on shading: the id and depth buffers
//!   are identical for colour (`N = 3`), textured (`N = 5`) and lit
//!   textured (`N = 8`) triangles, clipped ones included, at S = 4 and 8,
//!   in a frame and in a strip renderer.
//! - Texture coordinates at every covered pixel are within 1/256 texel of
//!   an `f64` perspective-correct reference (evaluated at the pixel centre
//!   on the snapped vertices) for a 1024-texel texture.
//! - Lit colours (per vertex and per pixel) are within 1 LSB per channel
//!   of an `f64` reference of the same lighting model.

use microraster::pixelcolor::Rgb888;
use microraster::prelude::*;
use microraster::shade::Lighting;
use microraster::shade::{
    ColorUvNormal, DirectionalLight, Filter, LitColors, Material, Phong, Texture, Textured, Wrap,
};
use microraster::{
    Config, CullMode, FragmentShader, Frame, Mesh, MeshColors, NoDepth, SetupTriangle,
    StripRenderer, TriangleId, Vec3, Vec4,
};
use proptest::prelude::*;
use std::cell::RefCell;

const W: u32 = 48;
const H: u32 = 40;

/// A clip-space vertex: mostly in view, sometimes behind the eye or past
/// the near plane (clipped), with perspective `w` over a wide range.
fn vertex(clipped: bool) -> impl Strategy<Value = Vec4> {
    let w = if clipped { -3.0f32..20.0 } else { 0.3f32..20.0 };
    (w, -1.2f32..1.2, -1.2f32..1.2, -0.99f32..0.99).prop_map(move |(w, x, y, z)| {
        let s = if clipped { w.abs().max(0.1) } else { w };
        Vec4::new(x * s, y * s, if clipped { z * s * 1.5 } else { z * w }, w)
    })
}

fn triangle(clipped: bool) -> impl Strategy<Value = [Vec4; 3]> {
    [vertex(clipped), vertex(clipped), vertex(clipped)]
}

/// Varyings `[r, g, b, u, v, nx, ny, nz]` per vertex. The normals are
/// those of a smooth surface: within about 30 degrees of a common
/// direction, so their interpolation never nears zero (where its
/// direction, and so the lighting, is undefined).
fn varyings() -> impl Strategy<Value = [[f32; 8]; 3]> {
    let one = (
        prop::array::uniform3(0.0f32..255.0),
        prop::array::uniform2(-2.0f32..2.0),
        prop::array::uniform3(-0.5f32..0.5),
    );
    (
        prop::array::uniform3(-1.0f32..1.0),
        [one.clone(), one.clone(), one],
    )
        .prop_map(|(d, vs)| {
            let l = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
            let d = if l > 0.5 {
                d.map(|c| c / l)
            } else {
                [0.0, 0.0, 1.0]
            };
            vs.map(|(c, uv, e)| {
                let n = [d[0] + e[0], d[1] + e[1], d[2] + e[2]];
                [c[0], c[1], c[2], uv[0], uv[1], n[0], n[1], n[2]]
            })
        })
}

fn config() -> Config {
    let mut c = Config::new(W, H);
    c.cull = CullMode::None;
    c
}

fn lighting() -> Lighting {
    let lights = [
        DirectionalLight {
            direction: Vec3::new(0.3, 0.8, 0.5),
            color: [0.9, 0.85, 0.8],
        },
        DirectionalLight {
            direction: Vec3::new(-0.6, -0.2, 0.4),
            color: [0.2, 0.25, 0.4],
        },
    ];
    Lighting::new([0.15, 0.15, 0.2], &lights, Vec3::new(0.1, 0.2, 1.0)).unwrap()
}

const SHINY: Material = Material {
    specular: [0.4, 0.4, 0.4],
    shininess: 24,
};

/// Ids and depth of `tris` rendered in a frame of `N` varyings; the
/// colour buffer is also drawn (through `fragment`) to exercise shading.
fn ids_and_depth<const S: u32, const N: usize, F: FragmentShader<N>>(
    tris: &[([Vec4; 3], [[f32; N]; 3])],
    fragment: &F,
) -> (Vec<TriangleId>, Vec<u32>, Vec<Rgb888>) {
    let mut storage = vec![SetupTriangle::<N>::EMPTY; tris.len() * 7];
    let mut frame = Frame::<S, N>::with_subpixel_bits(config(), &mut storage).unwrap();
    for (i, (p, v)) in tris.iter().enumerate() {
        frame.submit_clip_triangle(*p, *v, i as u32).unwrap();
    }
    let n = (W * H) as usize;
    let mut ids = vec![TriangleId(0); n];
    let mut z = vec![u32::MAX; n];
    frame
        .render_rows_shaded(0, H, &mut ids, &mut z[..], fragment)
        .unwrap();
    let mut rgb = vec![Rgb888::new(0, 0, 0); n];
    let mut z2 = vec![u32::MAX; n];
    frame
        .render_rows_shaded(0, H, &mut rgb, &mut z2[..], fragment)
        .unwrap();
    assert_eq!(z, z2, "depth depends on the pixel format");
    (ids, z, rgb)
}

fn texels() -> Vec<Rgb888> {
    (0..64 * 32)
        .map(|i| Rgb888::new((i * 7 % 256) as u8, (i * 13 % 256) as u8, (i % 256) as u8))
        .collect()
}

fn coverage_is_independent_of_shading<const S: u32>(tris: &[([Vec4; 3], [[f32; 8]; 3])]) {
    let t = texels();
    let tex = Texture::new(&t, 64, 32)
        .unwrap()
        .with_sampling(Filter::Bilinear, Wrap::Repeat);
    let light = lighting();
    let t3: Vec<_> = tris
        .iter()
        .map(|(p, v)| (*p, v.map(|v| [v[0], v[1], v[2]])))
        .collect();
    let t5: Vec<_> = tris
        .iter()
        .map(|(p, v)| (*p, v.map(|v| [v[0], v[1], v[2], v[3], v[4]])))
        .collect();
    let (ids3, z3, _) = ids_and_depth::<S, 3, _>(&t3, &microraster::VertexColor);
    let (ids5, z5, _) = ids_and_depth::<S, 5, _>(&t5, &Textured { texture: tex });
    let phong = Phong {
        lighting: &light,
        material: SHINY,
        texture: tex,
    };
    let (ids8, z8, _) = ids_and_depth::<S, 8, _>(tris, &phong);
    assert_eq!(ids3, ids5);
    assert_eq!(ids3, ids8);
    assert_eq!(z3, z5);
    assert_eq!(z3, z8);

    // The strip renderer, strip by strip, gives the same ids.
    let rows = 7;
    for y0 in (0..H).step_by(rows) {
        let y1 = (y0 + rows as u32).min(H);
        let n = (W * (y1 - y0)) as usize;
        let mut ids = vec![TriangleId(0); n];
        let mut z = vec![u32::MAX; n];
        let mut s = StripRenderer::<_, _, S, 8, _>::with_shader(
            config(),
            y0,
            y1,
            &mut ids,
            &mut z[..],
            phong,
        )
        .unwrap();
        for (i, (p, v)) in tris.iter().enumerate() {
            s.submit_clip_triangle(*p, *v, i as u32).unwrap();
        }
        let r = (W * y0) as usize..(W * y0) as usize + n;
        assert_eq!(ids, ids3[r.clone()], "rows {y0}..{y1}");
        assert_eq!(z, z3[r], "rows {y0}..{y1}");
    }
}

/// Records every shaded pixel's varyings, in shading order (row by row,
/// left to right, for one triangle).
struct Recorder<const N: usize>(RefCell<Vec<[f32; N]>>);

impl<const N: usize> FragmentShader<N> for Recorder<N> {
    fn shade(&self, v: &[f32; N], _: u32) -> Rgb888 {
        self.0.borrow_mut().push(*v);
        Rgb888::new(0, 0, 0)
    }
}

/// Window position of a clip-space vertex in `Sub<S>` units (`f64`).
fn window<const S: u32>(p: Vec4) -> (f64, f64) {
    let (x, y, w) = (p.x as f64, p.y as f64, p.w as f64);
    let sub = (1u64 << S) as f64;
    (
        (x / w + 1.0) * W as f64 / 2.0 * sub,
        (1.0 - y / w) * H as f64 / 2.0 * sub,
    )
}

/// The `f64` perspective-correct reference for every pixel the frame
/// shaded, and the recorded values, for one unclipped triangle.
fn reference_and_recorded<const S: u32, const N: usize>(
    p: [Vec4; 3],
    v: [[f32; N]; 3],
) -> Vec<([f64; N], [f32; N])> {
    let mut storage = [SetupTriangle::<N>::EMPTY; 8];
    let mut frame = Frame::<S, N>::with_subpixel_bits(config(), &mut storage).unwrap();
    frame.submit_clip_triangle(p, v, 0).unwrap();
    let Some(t) = frame.triangles().first() else {
        return Vec::new();
    };
    // Match each snapped vertex to the submitted one nearest to it.
    let snapped = t.vertices();
    let order: Vec<usize> = snapped
        .iter()
        .map(|&(sx, sy)| {
            (0..3)
                .min_by(|&a, &b| {
                    let d = |k: usize| {
                        let (wx, wy) = window::<S>(p[k]);
                        (wx - sx as f64).powi(2) + (wy - sy as f64).powi(2)
                    };
                    d(a).total_cmp(&d(b))
                })
                .unwrap()
        })
        .collect();
    if v[0] == v[1] && v[0] == v[2] {
        // Flat: shaded once, not per pixel.
        return Vec::new();
    }
    let rec = Recorder::<N>(RefCell::new(Vec::new()));
    // The covered pixels, in the order they are shaded.
    let mut ids = vec![TriangleId(0); (W * H) as usize];
    frame
        .render_rows_shaded(0, H, &mut ids, &mut NoDepth, &rec)
        .unwrap();
    let covered: Vec<(u32, u32)> = (0..W * H)
        .filter(|&i| ids[i as usize] != TriangleId(0))
        .map(|i| (i % W, i / W))
        .collect();
    rec.0.borrow_mut().clear();
    let mut rgb = vec![Rgb888::new(0, 0, 0); (W * H) as usize];
    frame
        .render_rows_shaded(0, H, &mut rgb, &mut NoDepth, &rec)
        .unwrap();
    let out = rec.0.into_inner();
    assert_eq!(out.len(), covered.len(), "one shading per covered pixel");
    let half = 1i64 << (S - 1);
    covered
        .into_iter()
        .zip(out)
        .map(|((x, y), got)| {
            let (px, py) = (((x as i64) << S) + half, ((y as i64) << S) + half);
            // Edge function opposite vertex k, exactly.
            let e = |k: usize| {
                let (a, b) = (snapped[(k + 1) % 3], snapped[(k + 2) % 3]);
                let (xa, ya, xb, yb) = (a.0 as i64, a.1 as i64, b.0 as i64, b.1 as i64);
                ((xb - xa) * (py - ya) - (yb - ya) * (px - xa)) as f64
            };
            let mut num = [0.0f64; N];
            let mut den = 0.0f64;
            for (k, &src) in order.iter().enumerate() {
                let wk = e(k) / p[src].w as f64;
                den += wk;
                for (n, x) in num.iter_mut().zip(v[src]) {
                    *n += wk * x as f64;
                }
            }
            (num.map(|n| n / den), got)
        })
        .collect()
}

/// `f64` Blinn-Phong with the same model as [`Lighting::shade`].
fn lit_f64(base: [f64; 3], n: [f64; 3], material: &Material) -> [f64; 3] {
    let norm = |v: [f64; 3]| {
        let l = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
        if l > 0.0 {
            v.map(|c| c / l)
        } else {
            [0.0; 3]
        }
    };
    let dot = |a: [f64; 3], b: [f64; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    let n = norm(n);
    let view = norm([0.1, 0.2, 1.0]);
    let lights = [
        ([0.3, 0.8, 0.5], [0.9, 0.85, 0.8]),
        ([-0.6, -0.2, 0.4], [0.2, 0.25, 0.4]),
    ];
    let mut diffuse = [0.15f64, 0.15, 0.2];
    let mut spec = [0.0f64; 3];
    for (dir, color) in lights {
        let l = norm(dir);
        let h = norm([l[0] + view[0], l[1] + view[1], l[2] + view[2]]);
        let d = dot(n, l);
        if d > 0.0 {
            for c in 0..3 {
                diffuse[c] += d * color[c];
            }
            let s = dot(n, h);
            if s > 0.0 && material.specular != [0.0; 3] {
                for c in 0..3 {
                    spec[c] += s.powi(material.shininess as i32) * color[c];
                }
            }
        }
    }
    core::array::from_fn(|c| {
        (base[c] * diffuse[c] + 255.0 * material.specular[c] as f64 * spec[c]).clamp(0.0, 255.0)
    })
}

fn close_u8(got: u8, want: f64) -> bool {
    (got as f64 - want).abs() <= 1.5
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(
        std::env::var("PROPTEST_CASES").ok().and_then(|v| v.parse().ok()).unwrap_or(256)))]

    /// The id and depth buffers do not depend on shading, clipped
    /// triangles included.
    #[test]
    fn coverage_and_depth_do_not_depend_on_shading(
        tris in prop::collection::vec((triangle(true), varyings()), 1..6),
        four in any::<bool>(),
    ) {
        if four {
            coverage_is_independent_of_shading::<4>(&tris);
        } else {
            coverage_is_independent_of_shading::<8>(&tris);
        }
    }

    /// Texture coordinates are within 1/256 texel of the `f64`
    /// perspective-correct value for a 1024x1024 texture (`|u|, |v| <= 2`,
    /// `w` ratios up to 67 (`w` in 0.3..20)).
    #[test]
    fn texture_coordinates_are_within_1_256_texel(
        p in triangle(false),
        uv in prop::array::uniform3(prop::array::uniform2(-2.0f32..2.0)),
        four in any::<bool>(),
    ) {
        // The layout of `Textured`: colour, then (u, v).
        let v = uv.map(|t| [255.0, 255.0, 255.0, t[0], t[1]]);
        let pairs = if four {
            reference_and_recorded::<4, 5>(p, v)
        } else {
            reference_and_recorded::<8, 5>(p, v)
        };
        for (want, got) in pairs {
            for c in 3..5 {
                let err = (got[c] as f64 - want[c]).abs() * 1024.0;
                prop_assert!(err <= 1.0 / 256.0, "{got:?} vs {want:?}: {err} texel");
            }
        }
    }

    /// Per-vertex (Gouraud) lighting: within 1 LSB of the `f64` reference
    /// (the lit vertex colours interpolated in `f64`).
    #[test]
    fn gouraud_lighting_is_within_one_lsb(
        p in triangle(false),
        base in prop::array::uniform3(prop::array::uniform3(0u8..=255)),
        normals in prop::array::uniform3(prop::array::uniform3(-1.0f32..1.0)),
    ) {
        let light = lighting();
        let normals: Vec<Vec3> = normals
            .iter()
            .map(|n| {
                let v = Vec3::new(n[0], n[1], n[2]);
                let l = v.dot(v).sqrt().max(1e-3);
                Vec3::new(v.x / l, v.y / l, v.z / l)
            })
            .collect();
        let colors: Vec<Rgb888> = base.iter().map(|c| Rgb888::new(c[0], c[1], c[2])).collect();
        let positions = [Vec3::new(0.0, 0.0, 0.0); 3];
        let attrs = LitColors {
            base: MeshColors::PerVertex(&colors),
            normals: &normals,
            lighting: &light,
            material: SHINY,
        };
        let mesh = Mesh { positions: &positions, indices: &[[0, 1, 2]], attributes: attrs, bounds: None };
        // The vertex colours as the vertex stage computes them, and in f64.
        let lit: Vec<[f32; 3]> = (0..3).map(|k| attrs.get(0, k)).collect();
        let want_vertex: Vec<[f64; 3]> = (0..3)
            .map(|k| {
                let n = normals[k];
                lit_f64(base[k].map(|c| c as f64), [n.x as f64, n.y as f64, n.z as f64], &SHINY)
            })
            .collect();
        for k in 0..3 {
            for c in 0..3 {
                prop_assert!((lit[k][c] as f64 - want_vertex[k][c]).abs() < 0.01);
            }
        }
        let _ = mesh;
        let v: [[f32; 3]; 3] = [lit[0], lit[1], lit[2]];
        for (want, got) in reference_and_recorded::<8, 3>(p, v) {
            let shaded = microraster::VertexColor.shade(&got, 0);
            let px = [shaded.r(), shaded.g(), shaded.b()];
            for c in 0..3 {
                prop_assert!(close_u8(px[c], want[c]), "{px:?} vs {want:?}");
            }
        }
    }

    /// Per-pixel (Phong) lighting: within 1 LSB of the `f64` reference
    /// (normals interpolated and normalised in `f64`).
    #[test]
    fn phong_lighting_is_within_one_lsb(
        p in triangle(false),
        v in varyings(),
    ) {
        let light = lighting();
        let v6 = v.map(|v| [v[0], v[1], v[2], v[5], v[6], v[7]]);
        let phong = Phong { lighting: &light, material: SHINY, texture: microraster::shade::NoTexture };
        for (want, got) in reference_and_recorded::<8, 6>(p, v6) {
            let shaded = phong.shade(&got, 0);
            let n = [want[3], want[4], want[5]];
            let expect = lit_f64([want[0], want[1], want[2]], n, &SHINY);
            let px = [shaded.r(), shaded.g(), shaded.b()];
            for c in 0..3 {
                prop_assert!(close_u8(px[c], expect[c]), "{px:?} vs {expect:?}");
            }
        }
    }
}

/// A mesh with texture coordinates and normals, lit per pixel, renders
/// in a frame and in strips identically, and its ids equal the unlit
/// mesh's.
#[test]
fn textured_lit_mesh_strips_equal_frame() {
    let positions = [
        Vec3::new(-1.0, -1.0, 0.0),
        Vec3::new(1.0, -1.0, 0.0),
        Vec3::new(1.0, 1.0, 0.0),
        Vec3::new(-1.0, 1.0, 0.0),
    ];
    let indices = [[0, 1, 2], [0, 2, 3]];
    let uvs = [[0.0, 1.0], [1.0, 1.0], [1.0, 0.0], [0.0, 0.0]];
    let normals = [Vec3::new(0.0, 0.0, 1.0); 4];
    let t = texels();
    let tex = Texture::new(&t, 64, 32).unwrap();
    let light = lighting();
    let phong = Phong {
        lighting: &light,
        material: SHINY,
        texture: tex,
    };
    let attrs = ColorUvNormal {
        color: MeshColors::Uniform(Rgb888::new(255, 255, 255)),
        uvs: &uvs,
        normals: &normals,
    };
    let mesh = Mesh {
        positions: &positions,
        indices: &indices,
        attributes: attrs,
        bounds: None,
    };
    let mvp = microraster::Mat4::perspective(1.0, W as f32 / H as f32, 0.5, 10.0)
        * microraster::Mat4::translation(Vec3::new(0.0, 0.0, -3.0))
        * microraster::Mat4::rotation_x(-0.7);
    let mut storage = [SetupTriangle::<8>::EMPTY; 16];
    let mut frame = Frame::<8, 8>::with_subpixel_bits(config(), &mut storage).unwrap();
    frame.submit_mesh(&mesh, &mvp, 0).unwrap();
    let n = (W * H) as usize;
    let mut whole = vec![Rgb888::new(0, 0, 0); n];
    frame
        .render_rows_shaded(0, H, &mut whole, &mut NoDepth, &phong)
        .unwrap();
    assert!(whole.iter().filter(|c| **c != Rgb888::new(0, 0, 0)).count() > 200);
    for rows in [1u32, 5, 16] {
        for y0 in (0..H).step_by(rows as usize) {
            let y1 = (y0 + rows).min(H);
            let m = (W * (y1 - y0)) as usize;
            let mut c = vec![Rgb888::new(0, 0, 0); m];
            let mut nd = NoDepth;
            let mut s = StripRenderer::<_, _, 8, 8, _>::with_shader(
                config(),
                y0,
                y1,
                &mut c,
                &mut nd,
                phong,
            )
            .unwrap();
            s.submit_mesh(&mesh, &mvp, 0).unwrap();
            let r = (W * y0) as usize..(W * y0) as usize + m;
            assert_eq!(c, whole[r]);
        }
    }
}

/// The worst texture-coordinate error over 20,000 random triangles, for
/// the record (docs/shading.md): `cargo test --release --test shading
/// measure_uv_error -- --ignored --nocapture`.
#[test]
#[ignore]
fn measure_uv_error() {
    use proptest::strategy::ValueTree;
    let mut rng = proptest::test_runner::TestRunner::deterministic();
    let strat = (
        triangle(false),
        prop::array::uniform3(prop::array::uniform2(-2.0f32..2.0)),
    );
    let mut worst = 0.0f64;
    let mut worst_rel = 0.0f64;
    for _ in 0..20000 {
        let (p, uv) = strat.new_tree(&mut rng).unwrap().current();
        let span = uv.iter().flatten().fold(0.0f32, |m, v| m.max(v.abs())) as f64;
        let v5 = uv.map(|t| [255.0, 255.0, 255.0, t[0], t[1]]);
        for (want, got) in reference_and_recorded::<8, 5>(p, v5) {
            for c in 3..5 {
                let e = (got[c] as f64 - want[c]).abs();
                worst = worst.max(e);
                worst_rel = worst_rel.max(e / span);
            }
        }
    }
    println!(
        "max abs error {worst:e} (x1024 = {} texel), max error / max|uv_k| = {worst_rel:e} = 2^{}",
        worst * 1024.0,
        worst_rel.log2()
    );
}

/// Fuzzing found (fuzz/findings/nonfinite-varyings-*): a NaN texture
/// coordinate was rejected by `submit_mesh` but drawn by
/// `submit_mesh_cached`, and a lit colour could be NaN under lighting
/// `Lighting::new` accepts. Both paths now count a non-finite varying as
/// `rejected_nonfinite`, and lit colours are always finite.
#[test]
fn nonfinite_varyings_count_alike_on_every_mesh_path() {
    let positions = [
        Vec3::new(-1.0, -1.0, 0.0),
        Vec3::new(1.0, -1.0, 0.0),
        Vec3::new(1.0, 1.0, 0.0),
        Vec3::new(-1.0, 1.0, 0.0),
    ];
    let indices = [[0, 1, 2], [0, 2, 3]];
    let uvs = [[0.0, 0.0], [1.0, f32::NAN], [1.0, 1.0], [0.0, 1.0]];
    let t = texels();
    let tex = Texture::new(&t, 64, 32).unwrap();
    let mesh = Mesh {
        positions: &positions,
        indices: &indices,
        attributes: microraster::shade::ColorUv {
            color: MeshColors::Uniform(Rgb888::new(255, 255, 255)),
            uvs: &uvs,
        },
        bounds: None,
    };
    let mvp = microraster::Mat4::translation(Vec3::new(0.0, 0.0, -0.5));
    let mut s1 = [SetupTriangle::<5>::EMPTY; 16];
    let mut s2 = [SetupTriangle::<5>::EMPTY; 16];
    let mut f1 = Frame::<8, 5>::with_subpixel_bits(config(), &mut s1).unwrap();
    let mut f2 = Frame::<8, 5>::with_subpixel_bits(config(), &mut s2).unwrap();
    f1.submit_mesh(&mesh, &mvp, 0).unwrap();
    let mut cache = [microraster::ProcessedVertex::EMPTY; 4];
    f2.submit_mesh_cached(&mesh, &mvp, 0, &mut cache).unwrap();
    assert_eq!(f1.stats(), f2.stats());
    assert_eq!(f1.stats().rejected_nonfinite, 1);
    assert_eq!(f1.stats().stored, 1);
    let n = (W * H) as usize;
    let (mut a, mut b) = (vec![TriangleId(0); n], vec![TriangleId(0); n]);
    let fragment = Textured { texture: tex };
    f1.render_rows_shaded(0, H, &mut a, &mut NoDepth, &fragment)
        .unwrap();
    f2.render_rows_shaded(0, H, &mut b, &mut NoDepth, &fragment)
        .unwrap();
    assert_eq!(a, b);

    // Lighting that overflows: every lit colour is still finite.
    let huge = DirectionalLight {
        direction: Vec3::new(0.0, 0.0, 1.0),
        color: [f32::MAX; 3],
    };
    let light = Lighting::new([f32::MAX; 3], &[huge], Vec3::new(0.0, 0.0, 1.0)).unwrap();
    let normals = [Vec3::new(0.0, 0.0, 1.0); 4];
    let black = [Rgb888::new(0, 0, 0); 4];
    let lit = LitColors {
        base: MeshColors::PerVertex(&black),
        normals: &normals,
        lighting: &light,
        material: SHINY,
    };
    for k in 0..4 {
        assert!(lit.get(0, k).iter().all(|c| (0.0..=255.0).contains(c)));
    }
}
