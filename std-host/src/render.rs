//! Scenes and threaded strip rendering on top of the core.
//!
//! Design note: a [`Scene`] is plain owned data (meshes with their
//! model-view-projection matrix, or raw clip-space triangles). [`render`]
//! hands it to a fresh [`FramePipeline`], which sets every triangle up once
//! into binned core frames (see [`crate::pipeline`]: one frame per setup
//! thread from 20,000 triangles up, storage sized from the triangle count
//! and grown only on `Error::StorageFull`), then draws strips of
//! `strip_rows` rows on `std::thread::scope` workers that take them from one
//! shared queue, so more strips than threads balance the load; each worker
//! owns its `&mut` rows and clears them before drawing. The triangle-id
//! image, if asked for, is drawn from the same set-up frames. The core draws
//! triangles in submission order in every strip, so the image is
//! byte-identical for any thread count and any strip height.

use crate::cliptris::ClipTri;
use crate::pipeline::{draw_layers, DepthFormat, FramePipeline, Layer};
use microraster::pixelcolor::{Rgb888, RgbColor};
use microraster::{
    BoundingSphere, Config, CullMode, Mat4, Mesh, MeshColors, PixelFormat, Stats, TriangleId, Vec3,
};
use std::time::Instant;

/// The background colour of rendered images.
pub const BACKGROUND: Rgb888 = Rgb888::new(0, 0, 0);

/// One mesh to draw, with its own transform to clip space.
#[derive(Clone, Debug)]
pub struct Object {
    /// Object-space positions.
    pub positions: Vec<Vec3>,
    /// Triangles.
    pub indices: Vec<[u32; 3]>,
    /// Colours: per triangle (flat) or per vertex (Gouraud).
    pub colors: ObjectColors,
    /// Bounding sphere for whole-object culling.
    pub bounds: Option<BoundingSphere>,
    /// Object to clip space.
    pub mvp: Mat4,
}

/// The colours of an [`Object`].
#[derive(Clone, Debug)]
pub enum ObjectColors {
    /// One colour per triangle (flat shading).
    PerTriangle(Vec<Rgb888>),
    /// One colour per vertex (Gouraud shading, perspective-correct).
    PerVertex(Vec<Rgb888>),
}

impl ObjectColors {
    /// As the core's [`MeshColors`].
    pub fn as_mesh_colors(&self) -> MeshColors<'_> {
        match self {
            ObjectColors::PerTriangle(c) => MeshColors::PerTriangle(c),
            ObjectColors::PerVertex(c) => MeshColors::PerVertex(c),
        }
    }
}

impl Object {
    /// As the core's [`Mesh`].
    pub fn mesh(&self) -> Mesh<'_> {
        Mesh {
            positions: &self.positions,
            indices: &self.indices,
            colors: self.colors.as_mesh_colors(),
            bounds: self.bounds,
        }
    }
}

/// Everything to draw in one frame, in drawing order: objects first, then
/// clip-space triangles. Triangle ids count from 0 in that order.
#[derive(Clone, Debug, Default)]
pub struct Scene {
    /// Meshes.
    pub objects: Vec<Object>,
    /// Raw clip-space triangles.
    pub clip_tris: Vec<ClipTri>,
}

impl Scene {
    /// The number of input triangles.
    pub fn triangle_count(&self) -> usize {
        self.objects.iter().map(|o| o.indices.len()).sum::<usize>() + self.clip_tris.len()
    }
}

fn v3(a: [f32; 3]) -> Vec3 {
    Vec3::from_array(a)
}

/// The default scene: four cubes, a colour per face, camera at
/// (0, 3.75, 6.5) looking at the origin, 60° vertical field of view (see
/// [`crate::cubes`]).
pub fn cubes_scene(width: u32, height: u32) -> Scene {
    let mut objects = Vec::new();
    crate::cubes::for_each_cube(width, height, |mesh, mvp, _| {
        let colors = match mesh.colors {
            MeshColors::PerTriangle(c) => ObjectColors::PerTriangle(c.to_vec()),
            MeshColors::PerVertex(c) => ObjectColors::PerVertex(c.to_vec()),
            MeshColors::Uniform(c) => ObjectColors::PerTriangle(vec![c; mesh.indices.len()]),
        };
        objects.push(Object {
            positions: mesh.positions.to_vec(),
            indices: mesh.indices.to_vec(),
            colors,
            bounds: mesh.bounds,
            mvp: *mvp,
        });
    });
    Scene {
        objects,
        clip_tris: Vec::new(),
    }
}

/// A mesh seen from `eye` towards `target`, flat-shaded with a head light
/// (Lambert, per triangle, computed here on the host).
pub fn mesh_scene(
    positions: &[[f32; 3]],
    indices: &[[u32; 3]],
    eye: [f32; 3],
    target: [f32; 3],
    fov_y_deg: f32,
    aspect: f32,
) -> Scene {
    let positions: Vec<Vec3> = positions.iter().map(|&p| v3(p)).collect();
    let bounds = BoundingSphere::from_points(&positions);
    let (eye, target) = (v3(eye), v3(target));
    let dist = (target - eye).length();
    let radius = bounds.map(|b| b.radius).unwrap_or(1.0);
    let near = (dist - 2.0 * radius).max(dist * 0.01).max(1e-4);
    let far = (dist + 2.0 * radius).max(near * 2.0);
    let proj = Mat4::perspective(microraster::math::radians(fov_y_deg), aspect, near, far);
    let view = Mat4::look_at(eye, target, Vec3::new(0.0, 1.0, 0.0));
    let light = (eye - target).normalize();
    let colors = indices
        .iter()
        .map(|t| {
            let p = |k: usize| positions.get(t[k] as usize).copied().unwrap_or(Vec3::ZERO);
            let n = (p(1) - p(0)).cross(p(2) - p(0)).normalize();
            let lambert = n.dot(light).max(0.0);
            let shade = |base: f32| ((0.15 + 0.85 * lambert) * base) as u8;
            Rgb888::new(shade(235.0), shade(215.0), shade(190.0))
        })
        .collect();
    Scene {
        objects: vec![Object {
            positions,
            indices: indices.to_vec(),
            colors: ObjectColors::PerTriangle(colors),
            bounds,
            mvp: proj * view,
        }],
        clip_tris: Vec::new(),
    }
}

/// Raw clip-space triangles (white where no colour is given).
pub fn clip_tris_scene(tris: Vec<ClipTri>) -> Scene {
    Scene {
        objects: Vec::new(),
        clip_tris: tris,
    }
}

/// Which depth buffer to render with.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DepthKind {
    /// 16-bit depth.
    U16,
    /// 32-bit depth.
    U32,
    /// No depth buffer: later triangles draw over earlier ones.
    None,
}

/// How to render.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct RenderOptions {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// Face culling.
    pub cull: CullMode,
    /// Depth buffer.
    pub depth: DepthKind,
    /// Subpixel bits: 4 or 8.
    pub subpixel: u32,
    /// Worker threads (at least 1).
    pub threads: usize,
    /// Rows per strip (at least 1).
    pub strip_rows: u32,
    /// Also render the triangle-id image.
    pub ids: bool,
}

/// The depth image of a render.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum DepthImage {
    /// 16-bit values, row 0 first.
    U16(Vec<u16>),
    /// 32-bit values, row 0 first.
    U32(Vec<u32>),
    /// No depth buffer.
    None,
}

impl DepthImage {
    /// Raw little-endian bytes, row 0 first.
    pub fn to_le_bytes(&self) -> Vec<u8> {
        match self {
            DepthImage::U16(v) => v.iter().flat_map(|d| d.to_le_bytes()).collect(),
            DepthImage::U32(v) => v.iter().flat_map(|d| d.to_le_bytes()).collect(),
            DepthImage::None => Vec::new(),
        }
    }
}

/// Wall-clock times of the stages, in milliseconds.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Timings {
    /// Transform, cull, clip and setup of every triangle.
    pub setup_ms: f64,
    /// Clearing and rasterizing the colour image (all strips).
    pub raster_ms: f64,
    /// Rendering the triangle-id image, if asked for.
    pub ids_ms: f64,
}

/// The result of [`render`].
#[derive(Clone, Debug)]
pub struct Rendered {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// RGB8 bytes, row 0 (top) first.
    pub rgb: Vec<u8>,
    /// Triangle index + 1 per pixel (0 = background), if asked for.
    pub ids: Option<Vec<u32>>,
    /// The depth buffer after drawing.
    pub depth: DepthImage,
    /// Core counters.
    pub stats: Stats,
    /// Pixels written into the colour image.
    pub pixels_written: u64,
    /// Stage times.
    pub timings: Timings,
}

impl Rendered {
    /// FNV-1a (64-bit) of the RGB8 bytes: a cheap fingerprint of the image.
    pub fn checksum(&self) -> u64 {
        fnv1a64(&self.rgb)
    }
}

/// FNV-1a, 64-bit.
pub fn fnv1a64(bytes: &[u8]) -> u64 {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for &b in bytes {
        h ^= b as u64;
        h = h.wrapping_mul(0x0000_0100_0000_01b3);
    }
    h
}

/// Renders `scene` as `opts` say.
pub fn render(scene: &Scene, opts: &RenderOptions) -> Result<Rendered, String> {
    match opts.subpixel {
        8 => render_s::<8>(scene, opts),
        4 => render_s::<4>(scene, opts),
        s => Err(format!("unsupported subpixel precision {s} (use 4 or 8)")),
    }
}

fn render_s<const S: u32>(scene: &Scene, opts: &RenderOptions) -> Result<Rendered, String> {
    let (w, h) = (opts.width, opts.height);
    let mut config = Config::new(w, h);
    config.cull = opts.cull;
    let (threads, rows) = (opts.threads.max(1), opts.strip_rows.max(1));
    let len = w as usize * h as usize;
    let t0 = Instant::now();
    let mut pipe = FramePipeline::<S>::new(config, threads, rows);
    let ((color, depth, pixels_written, ids, timings), setup) =
        pipe.with_layers(scene, |layers| {
            let setup_ms = t0.elapsed().as_secs_f64() * 1e3;
            let mut color = vec![BACKGROUND; len];
            let t1 = Instant::now();
            let (depth, px) =
                draw_image(layers, &mut color, opts.depth, BACKGROUND, rows, threads)?;
            let raster_ms = t1.elapsed().as_secs_f64() * 1e3;
            let t2 = Instant::now();
            let ids = if opts.ids {
                let mut ids = vec![TriangleId(0); len];
                draw_image(layers, &mut ids, opts.depth, TriangleId(0), rows, threads)?;
                Some(ids.into_iter().map(|t| t.0).collect())
            } else {
                None
            };
            let ids_ms = t2.elapsed().as_secs_f64() * 1e3;
            let timings = Timings {
                setup_ms,
                raster_ms,
                ids_ms,
            };
            Ok((color, depth, px, ids, timings))
        })?;
    let rgb = color.iter().flat_map(|c| [c.r(), c.g(), c.b()]).collect();
    Ok(Rendered {
        width: w,
        height: h,
        rgb,
        ids,
        depth,
        stats: setup.stats,
        pixels_written,
        timings,
    })
}

/// Draws the binned frames `layers` into `color` with a new depth buffer
/// `kind`, every strip cleared to `clear` first. Returns the depth buffer
/// after drawing and the pixels written.
fn draw_image<const S: u32, C: PixelFormat + Send + Sync>(
    layers: &[Layer<'_, '_, S>],
    color: &mut [C],
    kind: DepthKind,
    clear: C,
    rows: u32,
    threads: usize,
) -> Result<(DepthImage, u64), String> {
    let len = color.len();
    let (depth, px) = match kind {
        DepthKind::U16 => {
            let mut d = vec![u16::CLEAR; len];
            let px = draw_layers(layers, color, Some(&mut d[..]), rows, threads, Some(clear));
            (DepthImage::U16(d), px)
        }
        DepthKind::U32 => {
            let mut d = vec![u32::CLEAR; len];
            let px = draw_layers(layers, color, Some(&mut d[..]), rows, threads, Some(clear));
            (DepthImage::U32(d), px)
        }
        DepthKind::None => {
            let px = draw_layers::<S, C, u32>(layers, color, None, rows, threads, Some(clear));
            (DepthImage::None, px)
        }
    };
    Ok((depth, px.map_err(|e| e.to_string())?))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn opts(threads: usize, strip_rows: u32, depth: DepthKind) -> RenderOptions {
        RenderOptions {
            width: 160,
            height: 120,
            cull: CullMode::Back,
            depth,
            subpixel: 8,
            threads,
            strip_rows,
            ids: true,
        }
    }

    #[test]
    fn cubes_identical_for_any_threads_and_strips() {
        let scene = cubes_scene(160, 120);
        for depth in [DepthKind::U16, DepthKind::U32, DepthKind::None] {
            let base = render(&scene, &opts(1, 120, depth)).unwrap();
            assert!(base.pixels_written > 1000);
            for (t, r) in [(1, 1), (2, 7), (3, 16), (2, 1000), (4, 3)] {
                let other = render(&scene, &opts(t, r, depth)).unwrap();
                assert_eq!(base.rgb, other.rgb, "threads {t} strip {r}");
                assert_eq!(base.ids, other.ids);
                assert_eq!(base.depth, other.depth);
                assert_eq!(base.pixels_written, other.pixels_written);
            }
        }
    }

    #[test]
    fn cubes_draws_every_cube_and_culls_back_faces() {
        let r = render(&cubes_scene(160, 120), &opts(2, 16, DepthKind::U32)).unwrap();
        let ids = r.ids.unwrap();
        for cube in 0..4u32 {
            assert!(
                ids.iter().any(|&i| i > 0 && (i - 1) / 12 == cube),
                "cube {cube} not visible"
            );
        }
        assert_eq!(r.stats.submitted, 48);
        // Back faces, counted independently in f64 world space: a triangle
        // faces away when the eye is behind its plane.
        use crate::cubes::*;
        let mut back = 0;
        for ops in &CUBE_MODELS {
            for t in &CUBE_INDICES {
                let p = t.map(|i| transform_point(ops, CUBE_VERTICES[i as usize]).map(f64::from));
                let (a, b) = (sub(p[1], p[0]), sub(p[2], p[0]));
                let n = [
                    a[1] * b[2] - a[2] * b[1],
                    a[2] * b[0] - a[0] * b[2],
                    a[0] * b[1] - a[1] * b[0],
                ];
                let to_eye = sub(CUBES_EYE.map(f64::from), p[0]);
                if n[0] * to_eye[0] + n[1] * to_eye[1] + n[2] * to_eye[2] < 0.0 {
                    back += 1;
                }
            }
        }
        assert_eq!(r.stats.culled_backface, back);
        assert_eq!(r.stats.stored, 48 - back);
    }

    fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
        [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
    }
}
