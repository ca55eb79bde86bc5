//! Threaded strip rendering of a [`Scene`] into owned images.
//!
//! Design note: [`render`]
//! hands it to a fresh [`FramePipeline`], which sets every triangle up once
//! into binned core frames (see [`crate::pipeline`]: one frame per setup
//! thread from 20,000 triangles up, storage sized from the triangle count
//! and grown only on `Error::StorageFull`), then draws strips of
//! `strip_rows` rows on `std::thread::scope` workers that take them from a
//! shared queue (each its own contiguous run first), so more strips than
//! threads balance the load; each worker
//! owns its `&mut` rows and clears them before drawing. The triangle-id
//! image, if asked for, is drawn from the same set-up frames. The core draws
//! triangles in submission order in every strip, so the image is
//! byte-identical for any thread count and any strip height.

use crate::pipeline::{
    draw_layers, draw_layers_cleared, fill, for_each_tile, FramePipeline, Layer,
};
use crate::scene::Scene;
use microraster::occlusion::{tiles_for, HiZTile, Occluder};
use microraster::pixelcolor::{Rgb888, RgbColor};
use microraster::prelude::{DepthWord, Submit};
use microraster::{
    Config, CullMode, DepthF32, DepthFunc, NoDepth, PixelFormat, ProcessedVertex, RasterMode,
    Stats, StripRenderer, TriangleId,
};
use serde::Serialize;
use std::sync::OnceLock;
use std::time::Instant;

/// The background colour of rendered images.
pub const BACKGROUND: Rgb888 = Rgb888::new(0, 0, 0);

/// Which depth buffer to render with.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DepthKind {
    /// 16-bit depth.
    U16,
    /// 32-bit depth.
    U32,
    /// `f32` depth ([`microraster::DepthF32`]).
    F32,
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
    /// Detail culling in pixels (`Config::detail`; 0: off).
    pub detail: u16,
    /// Depth buffer.
    pub depth: DepthKind,
    /// Subpixel bits: 4 or 8.
    pub subpixel: u32,
    /// Worker threads (at least 1).
    pub threads: usize,
    /// Rows per strip (at least 1), or per tile.
    pub strip_rows: u32,
    /// Draw tiles this many pixels wide and `strip_rows` high instead of
    /// strips (0, or the width and more: strips). The image is the same.
    pub tile_width: u32,
    /// Also render the triangle-id image.
    pub ids: bool,
    /// Clipping or clipless rasterization.
    pub mode: RasterMode,
    /// 1/w depth (the scene built with `View::inv_w`): depth test
    /// `Greater`, depth cleared to 0 instead of the far plane.
    pub inv_w: bool,
    /// Occlusion culling ([`microraster::occlusion`]).
    pub occlusion: Occlusion,
}

/// Whether to cull by occlusion.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Occlusion {
    /// No: set up into frames, binned, drawn strip by strip.
    #[default]
    Off,
    /// Strips drawn at once by strip renderers (each strip submits the
    /// scene), the vertex stage once per object by the first strip that
    /// draws it, objects and their parts skipped where their bounds miss
    /// the strip, but without the hi-z test
    /// ([`Occluder::set_hiding`]): what `On` is measured against.
    Strips,
    /// As `Strips`, each object (and each part of it, see
    /// [`crate::scene::Object::parts`]) tested against the strip's hi-z
    /// before its vertices are transformed. The image is the same; it
    /// hides the most with objects in front-to-back order. Needs a depth
    /// buffer and the clipping mode.
    On,
}

/// The depth image of a render.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum DepthImage {
    /// 16-bit values, row 0 first.
    U16(Vec<u16>),
    /// 32-bit values, row 0 first.
    U32(Vec<u32>),
    /// `f32` values, row 0 first.
    F32(Vec<microraster::DepthF32>),
    /// No depth buffer.
    None,
}

impl DepthImage {
    /// Raw little-endian bytes, row 0 first.
    pub fn to_le_bytes(&self) -> Vec<u8> {
        match self {
            DepthImage::U16(v) => v.iter().flat_map(|d| d.to_le_bytes()).collect(),
            DepthImage::U32(v) => v.iter().flat_map(|d| d.to_le_bytes()).collect(),
            DepthImage::F32(v) => v.iter().flat_map(|d| d.get().to_le_bytes()).collect(),
            DepthImage::None => Vec::new(),
        }
    }
}

/// The core's counters as printed by `render --stats` and `bench` (the
/// core's [`Stats`] has no serde; this is its serialisable copy).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
pub struct Counters {
    /// Triangles submitted.
    pub submitted: u64,
    /// Skipped with their whole object by the bounding-sphere test.
    pub culled_object: u64,
    /// Outside the frustum.
    pub culled_frustum: u64,
    /// Culled by winding.
    pub culled_backface: u64,
    /// Zero area, or no pixel centre covered.
    pub culled_degenerate: u64,
    /// Dropped for a non-finite vertex.
    pub rejected_nonfinite: u64,
    /// Dropped for a vertex index out of range.
    pub rejected_index: u64,
    /// Clipped against the near, far or guard-band planes.
    pub clipped: u64,
    /// Set up and stored for drawing.
    pub stored: u64,
    /// Skipped with their cluster before transform (back-facing leaf).
    pub culled_cluster: u64,
    /// Skipped by an inner node of the cluster tree.
    pub culled_hierarchy: u64,
    /// Dropped before transform by detail culling (`--cull-detail`).
    pub culled_detail: u64,
    /// Skipped before transform by the frame's normal mask
    /// (`--normal-masks`).
    pub culled_mask: u64,
    /// Skipped before transform, hidden behind the strip's hi-z
    /// (`--occlusion`; counted once per strip the object reaches).
    pub culled_occlusion: u64,
    /// Skipped with their rooms, never submitted, by portal culling
    /// (`--portals`; counted in `submitted` too).
    pub culled_portal: u64,
    /// Pieces set up for the boxes drawn in place of what detail culling
    /// dropped (`--cull-detail-boxes`; not in `stored`).
    pub detail_boxes: u64,
}

impl From<&Stats> for Counters {
    fn from(s: &Stats) -> Counters {
        Counters {
            submitted: s.submitted,
            culled_object: s.culled_object,
            culled_frustum: s.culled_frustum,
            culled_backface: s.culled_backface,
            culled_degenerate: s.culled_degenerate,
            rejected_nonfinite: s.rejected_nonfinite,
            rejected_index: s.rejected_index,
            clipped: s.clipped,
            stored: s.stored,
            culled_cluster: s.culled_cluster,
            culled_hierarchy: s.culled_hierarchy,
            culled_detail: s.culled_detail,
            culled_mask: s.culled_mask,
            culled_occlusion: s.culled_occlusion,
            culled_portal: s.culled_portal,
            detail_boxes: s.detail_boxes,
        }
    }
}

/// Wall-clock times of the stages, in milliseconds.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
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
    if opts.mode == RasterMode::Clipless || opts.occlusion != Occlusion::Off {
        return render_immediate::<S>(scene, opts);
    }
    let (w, h) = (opts.width, opts.height);
    let mut config = Config::new(w, h);
    config.cull = opts.cull;
    config.detail = opts.detail;
    if opts.inv_w {
        config.depth_func = DepthFunc::Greater;
    }
    let (threads, rows) = (opts.threads.max(1), opts.strip_rows.max(1));
    let len = w as usize * h as usize;
    let t0 = Instant::now();
    let mut pipe = FramePipeline::<S>::new(config, threads, rows).with_tile_width(opts.tile_width);
    let ((color, depth, pixels_written, ids, timings), setup) =
        pipe.with_layers(scene, |layers| {
            let setup_ms = t0.elapsed().as_secs_f64() * 1e3;
            let mut color = vec![BACKGROUND; len];
            let t1 = Instant::now();
            let (depth, px) = draw_image(layers, &mut color, opts, BACKGROUND)?;
            let raster_ms = t1.elapsed().as_secs_f64() * 1e3;
            let t2 = Instant::now();
            let ids = if opts.ids {
                let mut ids = vec![TriangleId(0); len];
                draw_image(layers, &mut ids, opts, TriangleId(0))?;
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

/// The clipless mode: no frame stores set-up triangles
/// ([`Frame`](microraster::Frame) refuses the mode), so every strip (or
/// tile), on the threads, draws the whole scene with a
/// [`StripRenderer`](microraster::StripRenderer), from vertices processed
/// once per frame. The counters are summed over the strips (each one sets
/// up the triangles that reach it).
/// Strips (or tiles) drawn at once by strip renderers: the clipless mode,
/// and occlusion culling ([`RenderOptions::occlusion`]).
fn render_immediate<const S: u32>(scene: &Scene, opts: &RenderOptions) -> Result<Rendered, String> {
    let (w, h) = (opts.width, opts.height);
    let mut config = Config::new(w, h);
    config.cull = opts.cull;
    config.detail = opts.detail;
    let occlusion = opts.occlusion != Occlusion::Off;
    let hiz = opts.occlusion == Occlusion::On;
    if occlusion {
        if opts.mode == RasterMode::Clipless {
            return Err("occlusion culling is built for the clipping mode only".to_string());
        }
        if opts.depth == DepthKind::None {
            return Err("occlusion culling needs a depth buffer".to_string());
        }
    } else {
        config.mode = RasterMode::Clipless;
    }
    if opts.inv_w {
        config.depth_func = DepthFunc::Greater;
    }
    let reversed = opts.inv_w;
    let (threads, rows) = (opts.threads.max(1), opts.strip_rows.max(1));
    let len = w as usize * h as usize;
    let t0 = Instant::now();
    // The vertex stage, once per object (it depends on the configuration
    // only), through a one-row renderer that draws nothing: all at once for
    // the clipless mode, and under occlusion culling by the first strip
    // that draws the object.
    let caches: Vec<OnceLock<Vec<ProcessedVertex>>> =
        scene.objects.iter().map(|_| OnceLock::new()).collect();
    if !occlusion {
        let mut row = vec![TriangleId(0); w as usize];
        let mut none = NoDepth;
        let probe = StripRenderer::<_, _, S>::with_subpixel_bits(config, 0, 1, &mut row, &mut none)
            .map_err(|e| e.to_string())?;
        for (o, cache) in scene.objects.iter().zip(&caches) {
            let mut c = vec![ProcessedVertex::EMPTY; o.positions.len()];
            Submit::<S>::process_vertices(&probe, &o.mvp, &o.positions, &mut c);
            let _ = cache.set(c);
        }
    }
    let cache_refs: Vec<Option<&[ProcessedVertex]>> =
        caches.iter().map(|c| c.get().map(Vec::as_slice)).collect();
    let pieces = crate::pipeline::partition(scene, 1).concat();
    let setup_ms = t0.elapsed().as_secs_f64() * 1e3;
    let stats = std::sync::Mutex::new(Stats::default());
    let tile = (opts.tile_width as usize, rows as usize);
    let draw = |color: &mut [Rgb888],
                ids: Option<&mut [TriangleId]>,
                depth: DepthKind,
                count: bool| {
        macro_rules! strips {
            ($c:expr, $clear:expr, $d:expr) => {
                for_each_tile($c, $d, w as usize, tile, threads, false, |_, rect, c, d| {
                    c.fill($clear);
                    let (written, st) = match d {
                        Some(d) => {
                            d.fill(if reversed {
                                DepthWord::from_z32(0)
                            } else {
                                DepthWord::FAR
                            });
                            let mut r = StripRenderer::<_, _, S>::with_rect(config, rect, c, d)?;
                            if occlusion {
                                let [x0, x1, y0, y1] = rect;
                                let mut tiles =
                                    vec![HiZTile::default(); tiles_for(x1 - x0, y1 - y0)];
                                let mut o = r.occluder(&mut tiles)?;
                                o.set_hiding(hiz);
                                fill_occluded::<S, _, _>(&mut o, scene, &caches, &config)?;
                            } else {
                                fill::<S, _>(&mut r, scene, &pieces, &cache_refs, &mut Vec::new())?;
                            }
                            (r.render_stats().pixels_written, r.stats())
                        }
                        None => {
                            let mut none = NoDepth;
                            let mut r =
                                StripRenderer::<_, _, S>::with_rect(config, rect, c, &mut none)?;
                            fill::<S, _>(&mut r, scene, &pieces, &cache_refs, &mut Vec::new())?;
                            (r.render_stats().pixels_written, r.stats())
                        }
                    };
                    if count {
                        if let Ok(mut s) = stats.lock() {
                            *s += st;
                        }
                    }
                    Ok(written)
                })
            };
        }
        macro_rules! kinds {
            ($c:expr, $clear:expr) => {
                match depth {
                    DepthKind::U16 => {
                        let mut d = vec![if reversed { 0 } else { u16::MAX }; len];
                        strips!($c, $clear, Some(&mut d[..])).map(|px| (DepthImage::U16(d), px))
                    }
                    DepthKind::U32 => {
                        let mut d = vec![if reversed { 0 } else { u32::MAX }; len];
                        strips!($c, $clear, Some(&mut d[..])).map(|px| (DepthImage::U32(d), px))
                    }
                    DepthKind::F32 => {
                        let mut d = vec![
                            if reversed {
                                DepthF32::NEAR
                            } else {
                                DepthF32::FAR
                            };
                            len
                        ];
                        strips!($c, $clear, Some(&mut d[..])).map(|px| (DepthImage::F32(d), px))
                    }
                    DepthKind::None => {
                        strips!($c, $clear, None::<&mut [u32]>).map(|px| (DepthImage::None, px))
                    }
                }
            };
        }
        match ids {
            Some(ids) => kinds!(ids, TriangleId(0)),
            None => kinds!(color, BACKGROUND),
        }
        .map_err(|e| e.to_string())
    };
    let mut color = vec![BACKGROUND; len];
    let t1 = Instant::now();
    let (depth, pixels_written) = draw(&mut color, None, opts.depth, true)?;
    let raster_ms = t1.elapsed().as_secs_f64() * 1e3;
    let t2 = Instant::now();
    let ids = if opts.ids {
        let mut ids = vec![TriangleId(0); len];
        draw(&mut [], Some(&mut ids), opts.depth, false)?;
        Some(ids.into_iter().map(|t| t.0).collect())
    } else {
        None
    };
    let ids_ms = t2.elapsed().as_secs_f64() * 1e3;
    let rgb = color.iter().flat_map(|c| [c.r(), c.g(), c.b()]).collect();
    let stats = stats.into_inner().unwrap_or_default();
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

/// Draws object `ob` (triangles `range` of it) whose first triangle id is
/// `first` into `r`: clusters and normal masks with their own scratch
/// cache, as in [`fill`], else through `cache`, filled by the first strip
/// that needs it.
fn draw_object<const S: u32, C: PixelFormat, W: DepthWord>(
    r: &mut StripRenderer<'_, C, [W], S>,
    ob: &crate::scene::Object,
    range: std::ops::Range<usize>,
    first: u32,
    cache: &OnceLock<Vec<ProcessedVertex>>,
) -> Result<(), microraster::Error> {
    let scratch = || vec![ProcessedVertex::EMPTY; ob.positions.len()];
    let whole = ob.mesh();
    // Dropped whole by detail culling: `submit_mesh` tests the bounds
    // (and draws the box, once: with the object's first triangles).
    if crate::pipeline::dropped_by_detail(ob, r.config()) {
        let mut mesh = whole;
        mesh.indices = ob.indices.get(range.clone()).unwrap_or(&[]);
        if range.start != 0 {
            mesh.attributes.fill = None;
        }
        return r.submit_mesh(&mesh, &ob.mvp, first.wrapping_add(range.start as u32));
    }
    if let Some(c) = &ob.clusters {
        return r.submit_clusters(&whole, &ob.mvp, &c.set(), c.cull, first, &mut scratch());
    }
    if let Some(c) = &ob.normal_classes {
        return r.submit_masked(&whole, &ob.mvp, &c.set(), first, &mut scratch());
    }
    let cache = cache.get_or_init(|| {
        let mut c = scratch();
        Submit::<S>::process_vertices(r, &ob.mvp, &ob.positions, &mut c);
        c
    });
    let mut mesh = whole;
    mesh.indices = ob.indices.get(range.clone()).unwrap_or(&[]);
    if let crate::scene::ObjectColors::PerTriangle(c) = &ob.colors {
        mesh.attributes.colors =
            microraster::MeshColors::PerTriangle(c.get(range.clone()).unwrap_or(&[]));
    }
    r.submit_processed_mesh(&mesh, first.wrapping_add(range.start as u32), cache)
}

/// The clip-space triangles of `scene`, ids from `first`.
fn draw_clip_tris<const S: u32, C: PixelFormat, W: DepthWord>(
    r: &mut StripRenderer<'_, C, [W], S>,
    scene: &Scene,
    first: u32,
) -> Result<(), microraster::Error> {
    for (k, t) in scene.clip_tris.iter().enumerate() {
        let [cr, cg, cb] = t.color.unwrap_or([255, 255, 255]);
        let color = [cr as f32, cg as f32, cb as f32];
        let v = t.v.map(|p| microraster::ClipVertex {
            pos: microraster::Vec4::from_array(p),
            varyings: color,
        });
        r.submit_triangle(v, first.wrapping_add(k as u32))?;
    }
    Ok(())
}

/// Submits `scene` through an occluder in drawing order: each object
/// behind its bounds' occlusion test, and an object split into parts
/// ([`crate::scene::Object::parts`]) tested whole and then part by part;
/// the clip-space triangles without a bound. Triangle ids as in [`fill`].
fn fill_occluded<const S: u32, C: PixelFormat, W: DepthWord>(
    o: &mut Occluder<'_, '_, C, W, S, 3, microraster::VertexColor>,
    scene: &Scene,
    caches: &[OnceLock<Vec<ProcessedVertex>>],
    config: &Config,
) -> Result<(), microraster::Error> {
    let mut id = 0u32;
    for (ob, cache) in scene.objects.iter().zip(caches) {
        let first = id;
        let n = ob.indices.len();
        id = id.wrapping_add(n as u32);
        // A detail box reaches beyond the object's bounds (it covers their
        // projection), so it is drawn unbounded: no test, and the strip's
        // hi-z read again after it.
        if ob.detail_fill.is_some() && crate::pipeline::dropped_by_detail(ob, config) {
            o.submit_with(None, &ob.mvp, n as u64, |r| {
                draw_object(r, ob, 0..n, first, cache)
            })?;
            continue;
        }
        let (sphere, aabb) = (ob.bounds.as_ref(), ob.aabb.as_ref());
        match &ob.parts {
            Some(parts) if ob.clusters.is_none() && ob.normal_classes.is_none() => {
                if o.skips(sphere, aabb, &ob.mvp, n as u64) {
                    continue;
                }
                for p in parts.iter() {
                    let range = p.triangles.clone();
                    let len = range.len() as u64;
                    o.submit_bounded(None, Some(&p.aabb), &ob.mvp, len, |r| {
                        draw_object(r, ob, range, first, cache)
                    })?;
                }
                // What no part holds (triangles without a box), unbounded.
                let rest = parts.last().map_or(0, |p| p.triangles.end).min(n)..n;
                if !rest.is_empty() {
                    let len = rest.len() as u64;
                    o.submit_with(None, &ob.mvp, len, |r| {
                        draw_object(r, ob, rest, first, cache)
                    })?;
                }
            }
            _ => {
                o.submit_bounded(sphere, aabb, &ob.mvp, n as u64, |r| {
                    draw_object(r, ob, 0..n, first, cache)
                })?;
            }
        }
    }
    if scene.clip_tris.is_empty() {
        return Ok(());
    }
    let n = scene.clip_tris.len() as u64;
    o.submit_with(None, &microraster::Mat4::IDENTITY, n, |r| {
        draw_clip_tris(r, scene, id)
    })?;
    Ok(())
}

/// Draws the binned frames `layers` into `color` with a new depth buffer
/// `kind`, every strip cleared to `clear` first. Returns the depth buffer
/// after drawing and the pixels written.
fn draw_image<const S: u32, C: PixelFormat + Send + Sync>(
    layers: &[Layer<'_, '_, S>],
    color: &mut [C],
    opts: &RenderOptions,
    clear: C,
) -> Result<(DepthImage, u64), String> {
    let len = color.len();
    let threads = opts.threads.max(1);
    let (depth, px) = match opts.depth {
        DepthKind::U16 => {
            let z: u16 = if opts.inv_w { 0 } else { u16::MAX };
            let mut d = vec![z; len];
            let px = draw_layers_cleared(layers, color, Some(&mut d[..]), threads, Some(clear), z);
            (DepthImage::U16(d), px)
        }
        DepthKind::U32 => {
            let z: u32 = if opts.inv_w { 0 } else { u32::MAX };
            let mut d = vec![z; len];
            let px = draw_layers_cleared(layers, color, Some(&mut d[..]), threads, Some(clear), z);
            (DepthImage::U32(d), px)
        }
        DepthKind::F32 => {
            let z = if opts.inv_w {
                DepthF32::NEAR
            } else {
                DepthF32::FAR
            };
            let mut d = vec![z; len];
            let px = draw_layers_cleared(layers, color, Some(&mut d[..]), threads, Some(clear), z);
            (DepthImage::F32(d), px)
        }
        DepthKind::None => {
            let px = draw_layers::<S, C, u32>(layers, color, None, threads, Some(clear));
            (DepthImage::None, px)
        }
    };
    Ok((depth, px.map_err(|e| e.to_string())?))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::{cubes_scene, View};

    fn opts(threads: usize, strip_rows: u32, depth: DepthKind) -> RenderOptions {
        RenderOptions {
            width: 160,
            height: 120,
            cull: CullMode::Back,
            detail: 0,
            depth,
            subpixel: 8,
            threads,
            strip_rows,
            tile_width: 0,
            ids: true,
            mode: RasterMode::Clipping,
            inv_w: false,
            occlusion: Occlusion::Off,
        }
    }

    #[test]
    fn cubes_identical_for_any_threads_and_strips() {
        let scene = cubes_scene(&View::new(160, 120)).unwrap();
        for depth in [
            DepthKind::U16,
            DepthKind::U32,
            DepthKind::F32,
            DepthKind::None,
        ] {
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
        let scene = cubes_scene(&View::new(160, 120)).unwrap();
        let r = render(&scene, &opts(2, 16, DepthKind::U32)).unwrap();
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

    /// An `f32` buffer gives the `u32` buffer's image and its depths to
    /// 24 significant bits, set up once or in strips (`--mode clipless`),
    /// for window z and 1/w; `--depth-out` writes them as `f32`.
    #[test]
    fn f32_depth_matches_u32() {
        for inv_w in [false, true] {
            let view = View {
                inv_w,
                ..View::new(160, 120)
            };
            let scene = cubes_scene(&view).unwrap();
            for mode in [RasterMode::Clipping, RasterMode::Clipless] {
                let o = |depth| RenderOptions {
                    mode,
                    inv_w,
                    ..opts(2, 16, depth)
                };
                let a = render(&scene, &o(DepthKind::U32)).unwrap();
                let b = render(&scene, &o(DepthKind::F32)).unwrap();
                assert_eq!((&a.rgb, &a.ids), (&b.rgb, &b.ids), "{mode:?} {inv_w}");
                let (DepthImage::U32(u), DepthImage::F32(f)) = (&a.depth, &b.depth) else {
                    panic!("depth kinds");
                };
                for (&u, &f) in u.iter().zip(f) {
                    let (u, f) = (u as f64, f.get() as f64 * 4_294_967_296.0);
                    assert!((u - f).abs() <= (u / 8_388_608.0).max(1.0), "{u} {f}");
                }
                let bytes = b.depth.to_le_bytes();
                assert_eq!(bytes.len(), 4 * f.len());
                assert_eq!(
                    f32::from_le_bytes([bytes[0], bytes[1], bytes[2], bytes[3]]),
                    f[0].get()
                );
            }
        }
    }

    fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
        [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
    }
}
