//! Watertightness on a real closed mesh: Keenan Crane's Spot (public
//! domain, `assets/models/spot.obj`; closed, manifold, genus 0).
//!
//! For a closed mesh every ray that enters the volume leaves it again, so
//! at every pixel centre the number of front faces covering it equals the
//! number of back faces covering it, whatever the camera. A crack between
//! two triangles (a pixel missed by both) or an overlap (a pixel taken by
//! both) on any shared edge breaks the equality at that pixel. Counting
//! every fragment (no depth test) from many camera positions and at both
//! subpixel precisions checks every shared edge of the mesh under many
//! projections, including edges through pixel centres.

mod common;

use common::HitCounter;
use microraster::pixelcolor::Rgb888;
use microraster::prelude::*;
use microraster::{
    Config, CullMode, Frame, Mat4, Mesh, MeshColors, SetupTriangle, TriangleId, Vec3,
};
#[cfg(feature = "clipless")]
use microraster::{RasterMode, StripRenderer};

/// Positions and triangles of a Wavefront OBJ (`v` and triangular `f`
/// lines, `f a/b/c` indices taken from the first field).
fn load_obj(text: &str) -> (Vec<Vec3>, Vec<[u32; 3]>) {
    let (mut v, mut f) = (vec![], vec![]);
    for line in text.lines() {
        let mut it = line.split_whitespace();
        match it.next() {
            Some("v") => {
                let c: Vec<f32> = it.take(3).map(|s| s.parse().unwrap()).collect();
                v.push(Vec3::new(c[0], c[1], c[2]));
            }
            Some("f") => {
                let idx: Vec<u32> = it
                    .map(|s| s.split('/').next().unwrap().parse::<u32>().unwrap() - 1)
                    .collect();
                assert_eq!(idx.len(), 3, "spot is triangulated");
                f.push([idx[0], idx[1], idx[2]]);
            }
            _ => {}
        }
    }
    (v, f)
}

/// Fragment counts per pixel of the mesh drawn with culling `cull`.
fn counts<const S: u32>(mesh: &Mesh<'_>, mvp: &Mat4, w: u32, h: u32, cull: CullMode) -> Vec<u32> {
    let mut config = Config::new(w, h);
    config.cull = cull;
    let mut storage = vec![SetupTriangle::EMPTY; mesh.indices.len() * 2];
    let mut frame = Frame::<S>::with_subpixel_bits(config, &mut storage).unwrap();
    frame.submit_mesh(mesh, mvp, 0).unwrap();
    let n = (w * h) as usize;
    let mut hits = vec![0u32; n];
    let mut ids = vec![TriangleId(0); n];
    frame
        .render_rows(0, h, &mut ids, &mut HitCounter(&mut hits))
        .unwrap();
    hits
}

/// The same counts in the clipless mode, drawn by a strip renderer in
/// strips of 11 rows.
#[cfg(feature = "clipless")]
fn counts_clipless(mesh: &Mesh<'_>, mvp: &Mat4, w: u32, h: u32, cull: CullMode) -> Vec<u32> {
    let mut config = Config::new(w, h);
    config.cull = cull;
    config.mode = RasterMode::Clipless;
    let mut hits = vec![0u32; (w * h) as usize];
    for (k, rows) in hits.chunks_mut(11 * w as usize).enumerate() {
        let y0 = k as u32 * 11;
        let y1 = y0 + (rows.len() as u32 / w);
        let mut ids = vec![TriangleId(0); rows.len()];
        let mut counter = HitCounter(rows);
        let mut strip = StripRenderer::new(config, y0, y1, &mut ids, &mut counter).unwrap();
        strip.submit_mesh(mesh, mvp, 0).unwrap();
    }
    hits
}

fn check<const S: u32>(positions: &[Vec3], indices: &[[u32; 3]], cameras: usize) -> usize {
    check_with(positions, indices, cameras, counts::<S>, S)
}

type Counts = fn(&Mesh<'_>, &Mat4, u32, u32, CullMode) -> Vec<u32>;

fn check_with(
    positions: &[Vec3],
    indices: &[[u32; 3]],
    cameras: usize,
    counts: Counts,
    s: u32,
) -> usize {
    let mesh = Mesh {
        positions,
        indices,
        attributes: MeshColors::Uniform(Rgb888::new(200, 200, 200)),
        bounds: None,
    };
    let (w, h) = (96u32, 80u32);
    let centre = Vec3::new(0.0, 0.1, 0.19);
    let proj = Mat4::perspective(0.9, w as f32 / h as f32, 0.5, 10.0);
    let mut covered = 0;
    for k in 0..cameras {
        // Cameras on a spiral round the model, from below to above.
        let t = (k as f32 + 0.5) / cameras as f32;
        let elevation = (t * 2.0 - 1.0) * 1.3;
        let azimuth = k as f32 * 2.399_963; // golden angle
        let dir = Vec3::new(
            libm_cos(elevation) * libm_cos(azimuth),
            libm_sin(elevation),
            libm_cos(elevation) * libm_sin(azimuth),
        );
        let eye = centre + dir * 3.0;
        let mvp = proj * Mat4::look_at(eye, centre, Vec3::new(0.0, 1.0, 0.0));
        let front = counts(&mesh, &mvp, w, h, CullMode::Back);
        let back = counts(&mesh, &mvp, w, h, CullMode::Front);
        let bad: Vec<usize> = (0..front.len()).filter(|&i| front[i] != back[i]).collect();
        assert!(
            bad.is_empty(),
            "S={s} camera {k} (eye {eye:?}): {} pixels where front and back counts differ, e.g. {:?}",
            bad.len(),
            bad.iter()
                .take(5)
                .map(|&i| (i as u32 % w, i as u32 / w, front[i], back[i]))
                .collect::<Vec<_>>()
        );
        let c = front.iter().filter(|&&n| n > 0).count();
        assert!(
            c > 300,
            "camera {k}: the model should fill part of the frame ({c} pixels)"
        );
        covered += c;
    }
    covered
}

fn libm_sin(x: f32) -> f32 {
    (x as f64).sin() as f32
}

fn libm_cos(x: f32) -> f32 {
    (x as f64).cos() as f32
}

#[test]
fn spot_front_and_back_face_counts_match_everywhere() {
    let text = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/assets/models/spot.obj"
    ))
    .expect("assets/models/spot.obj");
    let (p, f) = load_obj(&text);
    assert_eq!(f.len(), 5856);
    let covered = check::<8>(&p, &f, 48) + check::<4>(&p, &f, 16);
    assert!(covered > 64 * 300);
}

/// The clipless mode on the same mesh from 64 cameras (`S` = 0 in the
/// messages: it has no subpixel grid).
#[cfg(feature = "clipless")]
#[test]
fn spot_front_and_back_face_counts_match_everywhere_clipless() {
    let text = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/assets/models/spot.obj"
    ))
    .expect("assets/models/spot.obj");
    let (p, f) = load_obj(&text);
    let covered = check_with(&p, &f, 64, counts_clipless, 0);
    assert!(covered > 64 * 300);
}
