//! Scenes and threaded strip rendering on top of the core.
//!
//! Design note: a [`Scene`] is plain owned data (meshes with their
//! model-view-projection matrix, or raw clip-space triangles). [`render`]
//! pushes it into one core [`Frame`] (setup storage sized from the triangle
//! count and grown on [`Error::StorageFull`]), then splits the frame's
//! buffers into strips of `strip_rows` rows with `chunks_mut`. Strips are
//! handed to `std::thread::scope` workers through one shared iterator behind
//! a mutex, so more strips than threads balance the load; each worker owns
//! its `&mut` rows and clears them before drawing. The core draws triangles
//! in submission order in every strip, so the image is byte-identical for
//! any thread count and any strip height.

use crate::cliptris::ClipTri;
use microraster::pixelcolor::{Rgb888, RgbColor};
use microraster::{
    Bins, BoundingSphere, ClipVertex, Config, CullMode, DepthBuffer, Error, Frame, Mat4, Mesh,
    MeshColors, NoDepth, Pixel, ProcessedVertex, SetupTriangle, Stats, TriangleId, Vec3, Vec4,
};
use std::sync::Mutex;
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

/// One piece of a scene's triangle sequence: triangles `range` of object
/// `object`, or clip-space triangles `range`.
#[derive(Clone, Debug)]
enum Piece {
    Object(usize, std::ops::Range<usize>),
    ClipTris(std::ops::Range<usize>),
}

/// Splits the scene's triangle sequence into `parts` contiguous chunks of
/// about equal size, in drawing order.
fn partition(scene: &Scene, parts: usize) -> Vec<Vec<Piece>> {
    let total = scene.triangle_count().max(1);
    let per = total.div_ceil(parts.max(1)).max(1);
    let mut chunks: Vec<Vec<Piece>> = vec![Vec::new()];
    let mut room = per;
    let mut push = |len: usize, make: &dyn Fn(std::ops::Range<usize>) -> Piece| {
        let mut start = 0;
        while start < len {
            if room == 0 {
                chunks.push(Vec::new());
                room = per;
            }
            let take = room.min(len - start);
            if let Some(c) = chunks.last_mut() {
                c.push(make(start..start + take));
            }
            start += take;
            room -= take;
        }
    };
    for (i, o) in scene.objects.iter().enumerate() {
        push(o.indices.len(), &|r| Piece::Object(i, r));
    }
    push(scene.clip_tris.len(), &|r| Piece::ClipTris(r));
    chunks
}

/// The first triangle id of each object, and of the clip-space triangles.
fn first_ids(scene: &Scene) -> (Vec<u32>, u32) {
    let mut ids = Vec::with_capacity(scene.objects.len());
    let mut id = 0u32;
    for o in &scene.objects {
        ids.push(id);
        id = id.wrapping_add(o.indices.len() as u32);
    }
    (ids, id)
}

/// Pushes the triangles of `pieces` into `frame`. Objects use the vertex
/// cache `caches[i]` (already processed), or are skipped whole when their
/// bounding sphere is outside the frustum.
fn fill<const S: u32>(
    frame: &mut Frame<'_, S>,
    scene: &Scene,
    pieces: &[Piece],
    caches: &[Option<Vec<ProcessedVertex>>],
) -> Result<(), Error> {
    let (ids, clip_first) = first_ids(scene);
    for piece in pieces {
        match piece {
            Piece::Object(i, r) => {
                let o = &scene.objects[*i];
                let mut mesh = o.mesh();
                mesh.indices = &o.indices[r.clone()];
                if let ObjectColors::PerTriangle(c) = &o.colors {
                    mesh.colors = MeshColors::PerTriangle(&c[r.clone()]);
                }
                let id = ids[*i].wrapping_add(r.start as u32);
                match &caches[*i] {
                    Some(cache) => frame.draw_mesh_processed(&mesh, id, cache)?,
                    // Culled by its bounding sphere: counted, nothing else.
                    None => frame.draw_mesh(&mesh, &o.mvp, id)?,
                }
            }
            Piece::ClipTris(r) => {
                for (k, t) in scene.clip_tris[r.clone()].iter().enumerate() {
                    let [cr, cg, cb] = t.color.unwrap_or([255, 255, 255]);
                    let color = [cr as f32, cg as f32, cb as f32];
                    let v = t.v.map(|p| ClipVertex {
                        pos: Vec4::from_array(p),
                        color,
                    });
                    let id = clip_first.wrapping_add((r.start + k) as u32);
                    frame.push_triangle(v, id)?;
                }
            }
        }
    }
    Ok(())
}

/// Runs the vertex stage of every visible object, `threads` workers per
/// object; `None` for an object outside the frustum.
fn process_objects<const S: u32>(
    scene: &Scene,
    config: Config,
    threads: usize,
) -> Result<Vec<Option<Vec<ProcessedVertex>>>, String> {
    let probe = Frame::<S>::new(config, &mut []).map_err(|e| e.to_string())?;
    let mut caches = Vec::with_capacity(scene.objects.len());
    for o in &scene.objects {
        if o.bounds.is_some_and(|b| b.outside_frustum(&o.mvp)) {
            caches.push(None);
            continue;
        }
        let mut cache = vec![ProcessedVertex::EMPTY; o.positions.len()];
        let chunk = o.positions.len().div_ceil(threads.max(1)).max(4096);
        std::thread::scope(|s| {
            for (p, c) in o.positions.chunks(chunk).zip(cache.chunks_mut(chunk)) {
                let probe = &probe;
                s.spawn(move || probe.process_vertices(&o.mvp, p, c));
            }
        });
        caches.push(Some(cache));
    }
    Ok(caches)
}

/// Builds one frame per chunk of the scene (in parallel), each in its own
/// storage; drawn in order they are the scene.
fn build_frames<'s, const S: u32>(
    scene: &Scene,
    config: Config,
    chunks: &[Vec<Piece>],
    caches: &[Option<Vec<ProcessedVertex>>],
    storages: &'s mut [Vec<SetupTriangle>],
) -> Result<Vec<Frame<'s, S>>, String> {
    std::thread::scope(|s| {
        let handles: Vec<_> = storages
            .iter_mut()
            .zip(chunks)
            .map(|(storage, pieces)| {
                s.spawn(move || -> Result<Frame<'s, S>, String> {
                    // Grow the storage until the chunk fits (clipping can
                    // turn one triangle into several; the first guess
                    // almost always suffices).
                    loop {
                        let needed = {
                            let mut f =
                                Frame::<S>::new(config, storage).map_err(|e| e.to_string())?;
                            match fill(&mut f, scene, pieces, caches) {
                                Ok(()) => 0,
                                Err(Error::StorageFull { needed, .. }) => needed,
                                Err(e) => return Err(e.to_string()),
                            }
                        };
                        if needed == 0 {
                            break;
                        }
                        let grow = needed.max(storage.len() / 2);
                        storage.resize(storage.len() + grow, SetupTriangle::EMPTY);
                    }
                    let mut f = Frame::<S>::new(config, storage).map_err(|e| e.to_string())?;
                    fill(&mut f, scene, pieces, caches).map_err(|e| e.to_string())?;
                    Ok(f)
                })
            })
            .collect();
        handles
            .into_iter()
            .map(|h| {
                h.join()
                    .unwrap_or_else(|_| Err("setup worker failed".into()))
            })
            .collect()
    })
}

fn render_s<const S: u32>(scene: &Scene, opts: &RenderOptions) -> Result<Rendered, String> {
    let (w, h) = (opts.width, opts.height);
    let mut config = Config::new(w, h);
    config.cull = opts.cull;
    let threads = opts.threads.max(1);
    let t0 = Instant::now();
    // Set up in parallel only where there is enough work to share.
    let parts = if scene.triangle_count() >= 20_000 {
        threads
    } else {
        1
    };
    let caches = process_objects::<S>(scene, config, threads)?;
    let chunks = partition(scene, parts);
    let mut storages: Vec<Vec<SetupTriangle>> = chunks
        .iter()
        .map(|pieces| {
            let n: usize = pieces
                .iter()
                .map(|p| match p {
                    Piece::Object(_, r) | Piece::ClipTris(r) => r.len(),
                })
                .sum();
            vec![SetupTriangle::EMPTY; n + n / 8 + 64]
        })
        .collect();
    let frames = build_frames::<S>(scene, config, &chunks, &caches, &mut storages)?;
    let mut stats = Stats::default();
    for f in &frames {
        let s = f.stats();
        stats.submitted += s.submitted;
        stats.culled_object += s.culled_object;
        stats.culled_frustum += s.culled_frustum;
        stats.culled_backface += s.culled_backface;
        stats.culled_degenerate += s.culled_degenerate;
        stats.rejected_nonfinite += s.rejected_nonfinite;
        stats.rejected_index += s.rejected_index;
        stats.clipped += s.clipped;
        stats.stored += s.stored;
    }
    // Bin every frame's triangles by strip.
    let strip_rows = opts.strip_rows.max(1);
    let strips = h.div_ceil(strip_rows) as usize;
    let mut bin_store: Vec<(Vec<u32>, Vec<u32>)> = frames
        .iter()
        .map(|f| {
            (
                vec![0u32; strips + 1],
                vec![0u32; f.bin_entries(strip_rows)],
            )
        })
        .collect();
    let bins = frames
        .iter()
        .zip(bin_store.iter_mut())
        .map(|(f, (o, i))| f.bin(strip_rows, o, i))
        .collect::<Result<Vec<_>, _>>()
        .map_err(|e| e.to_string())?;
    let layers: Vec<(&Frame<'_, S>, &Bins<'_>)> = frames.iter().zip(bins.iter()).collect();
    let setup_ms = t0.elapsed().as_secs_f64() * 1e3;

    let len = w as usize * h as usize;
    let mut color = vec![BACKGROUND; len];
    let t1 = Instant::now();
    let (depth, pixels_written) = match opts.depth {
        DepthKind::U16 => {
            let mut d = vec![u16::MAX; len];
            let px = render_strips(
                &layers,
                &mut color,
                Some(&mut d[..]),
                BACKGROUND,
                u16::MAX,
                opts,
            )?;
            (DepthImage::U16(d), px)
        }
        DepthKind::U32 => {
            let mut d = vec![u32::MAX; len];
            let px = render_strips(
                &layers,
                &mut color,
                Some(&mut d[..]),
                BACKGROUND,
                u32::MAX,
                opts,
            )?;
            (DepthImage::U32(d), px)
        }
        DepthKind::None => {
            let px = render_strips::<S, _, u32>(&layers, &mut color, None, BACKGROUND, 0, opts)?;
            (DepthImage::None, px)
        }
    };
    let raster_ms = t1.elapsed().as_secs_f64() * 1e3;

    let t2 = Instant::now();
    let ids = if opts.ids {
        let mut ids = vec![TriangleId(0); len];
        match opts.depth {
            DepthKind::U16 => {
                let mut d = vec![u16::MAX; len];
                render_strips(
                    &layers,
                    &mut ids,
                    Some(&mut d[..]),
                    TriangleId(0),
                    u16::MAX,
                    opts,
                )?
            }
            DepthKind::U32 => {
                let mut d = vec![u32::MAX; len];
                render_strips(
                    &layers,
                    &mut ids,
                    Some(&mut d[..]),
                    TriangleId(0),
                    u32::MAX,
                    opts,
                )?
            }
            DepthKind::None => {
                render_strips::<S, _, u32>(&layers, &mut ids, None, TriangleId(0), 0, opts)?
            }
        };
        Some(ids.into_iter().map(|t| t.0).collect())
    } else {
        None
    };
    let ids_ms = t2.elapsed().as_secs_f64() * 1e3;

    let rgb = color.iter().flat_map(|c| [c.r(), c.g(), c.b()]).collect();
    Ok(Rendered {
        width: w,
        height: h,
        rgb,
        ids,
        depth,
        stats,
        pixels_written,
        timings: Timings {
            setup_ms,
            raster_ms,
            ids_ms,
        },
    })
}

/// One strip of work: its index and its rows of colour and depth.
type Work<'a, C, T> = (u32, &'a mut [C], Option<&'a mut [T]>);

/// Clears and renders every strip of `color` (and `depth`) on
/// `opts.threads` workers, drawing the binned frames `layers` in order.
/// Returns the pixels written.
fn render_strips<const S: u32, C, T>(
    layers: &[(&Frame<'_, S>, &Bins<'_>)],
    color: &mut [C],
    depth: Option<&mut [T]>,
    clear_color: C,
    clear_depth: T,
    opts: &RenderOptions,
) -> Result<u64, String>
where
    C: Pixel + Send + Sync,
    T: Copy + Send + Sync,
    [T]: DepthBuffer,
{
    let width = opts.width as usize;
    let rows = opts.strip_rows.max(1) as usize;
    let chunk = width * rows;
    let mut work: Vec<Work<'_, C, T>> = Vec::new();
    match depth {
        Some(d) => {
            for (i, (c, d)) in color.chunks_mut(chunk).zip(d.chunks_mut(chunk)).enumerate() {
                work.push((i as u32, c, Some(d)));
            }
        }
        None => {
            for (i, c) in color.chunks_mut(chunk).enumerate() {
                work.push((i as u32, c, None));
            }
        }
    }
    let queue = Mutex::new(work.into_iter());
    let threads = opts.threads.max(1);
    let results: Vec<Result<u64, Error>> = std::thread::scope(|s| {
        let handles: Vec<_> = (0..threads)
            .map(|_| {
                s.spawn(|| -> Result<u64, Error> {
                    let mut written = 0u64;
                    loop {
                        let item = match queue.lock() {
                            Ok(mut q) => q.next(),
                            Err(poisoned) => poisoned.into_inner().next(),
                        };
                        let Some((strip, c, mut d)) = item else { break };
                        c.fill(clear_color);
                        if let Some(d) = d.as_deref_mut() {
                            d.fill(clear_depth);
                        }
                        for (frame, bins) in layers {
                            written += match d.as_deref_mut() {
                                Some(d) => frame.render_strip(bins, strip, c, d)?,
                                None => frame.render_strip(bins, strip, c, &mut NoDepth)?,
                            }
                            .pixels_written;
                        }
                    }
                    Ok(written)
                })
            })
            .collect();
        handles
            .into_iter()
            .map(|h| h.join().unwrap_or(Ok(0)))
            .collect()
    });
    let mut total = 0;
    for r in results {
        total += r.map_err(|e| e.to_string())?;
    }
    Ok(total)
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
