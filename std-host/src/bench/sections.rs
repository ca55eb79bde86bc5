//! The extra sections of `microraster bench`: the stage split and the
//! memory floor.
//!
//! Design note: both run on one set-up scene (frame 0) after the timed
//! runs. The split measures each stage alone where the pipeline allows it
//! and as the difference of two measured variants otherwise (its `method`
//! field says which); the floor is a plain fill of the same buffers over the
//! same strips and threads, the least a frame can cost.

use super::runs::{config_of, BenchColor, Run};
use super::stats::{median, min, ms, time_frames};
use super::{Settings, SPLIT_MAX_ITERATIONS};
use crate::pipeline::{draw_layers, for_each_strip, FramePipeline};
use crate::scene::Scene;
use microraster::pixelcolor::Rgb888;
use microraster::DepthWord;
use microraster::{Error, TriangleId, Vec4};
use serde_json::{json, Value};
use std::hint::black_box;
use std::time::Instant;

/// The stage split, one thread, on the scene as in frame 0.
pub fn split<const S: u32, C: BenchColor, T: DepthWord>(
    scene: &Scene,
    s: &Settings,
    depth_on: bool,
) -> Result<Value, String> {
    let iters = s.frames.min(SPLIT_MAX_ITERATIONS);
    let warm = s.warmup.min(2);
    let len = s.width as usize * s.height as usize;
    let rows = s.strip_rows;
    let mut pipe = FramePipeline::<S>::new(config_of(s), 1, rows).with_tile_width(s.tile_width);

    // The transform alone, every vertex once.
    let mut out: Vec<Vec4> = Vec::new();
    let transform = time_frames(warm, iters, |_| {
        out.clear();
        for o in &scene.objects {
            out.extend(o.positions.iter().map(|&p| o.mvp.transform_point(p)));
        }
        black_box(&out);
        Ok(())
    })?;
    // Setup stages as the pipeline times them.
    let (mut vertex, mut triangles, mut binning) = (Vec::new(), Vec::new(), Vec::new());
    for k in 0..warm + iters {
        let ((), t) = pipe.with_layers(scene, |_| Ok(()))?;
        if k >= warm {
            vertex.push(t.vertex_ms);
            triangles.push(t.triangles_ms);
            binning.push(t.binning_ms);
        }
    }
    // Raster variants on one set-up frame, buffers cleared outside the clock.
    let mut color = vec![C::CLEAR; len];
    let mut depth = vec![T::FAR; if depth_on { len } else { 0 }];
    let mut ids = vec![TriangleId(0); len];
    let mut ids_depth = vec![T::FAR; len];
    let w = s.width as usize;
    let clear = time_frames(warm, iters, |_| {
        for_each_strip(
            &mut color,
            depth_on.then_some(&mut depth[..]),
            w,
            rows as usize,
            1,
            |_, c, d| {
                c.fill(C::CLEAR);
                if let Some(d) = d {
                    d.fill(T::FAR);
                }
                Ok(0)
            },
        )
        .map_err(|e| e.to_string())?;
        black_box(&color);
        Ok(())
    })?;
    let ((ids_nodepth, ids_z, full, px), _) = pipe.with_layers(scene, |layers| {
        let err = |e: Error| e.to_string();
        let mut px = [0u64; 3];
        let mut a = Vec::new();
        let mut b = Vec::new();
        let mut c = Vec::new();
        for k in 0..warm + iters {
            let t = Instant::now();
            px[0] =
                draw_layers::<S, TriangleId, T>(layers, &mut ids, None, 1, None).map_err(err)?;
            let ta = ms(t);
            ids_depth.fill(T::FAR);
            let t = Instant::now();
            px[1] =
                draw_layers::<S, TriangleId, T>(layers, &mut ids, Some(&mut ids_depth), 1, None)
                    .map_err(err)?;
            let tb = ms(t);
            depth.fill(T::FAR);
            let t = Instant::now();
            px[2] = draw_layers::<S, C, T>(
                layers,
                &mut color,
                depth_on.then_some(&mut depth[..]),
                1,
                None,
            )
            .map_err(err)?;
            let tc = ms(t);
            if k >= warm {
                a.push(ta);
                b.push(tb);
                c.push(tc);
            }
        }
        Ok((a, b, c, px))
    })?;

    let m = |v: &[f64]| median(v);
    let (t_transform, t_vertex, t_tri, t_bin) =
        (m(&transform), m(&vertex), m(&triangles), m(&binning));
    let (t_clear, t_trav, t_idz, t_full) = (m(&clear), m(&ids_nodepth), m(&ids_z), m(&full));
    let table = json!({
        "transform_ms": t_transform,
        "outcode_snap_ms": t_vertex - t_transform,
        "cull_clip_setup_ms": t_tri,
        "binning_ms": t_bin,
        "clear_ms": t_clear,
        "traversal_ms": t_trav,
        "depth_ms": t_idz - t_trav,
        "shade_write_ms": t_full - t_idz,
        "sum_ms": t_vertex + t_tri + t_bin + t_clear + t_full,
    });
    let measured = json!({
        "transform_ms": t_transform,
        "vertex_stage_ms": t_vertex,
        "triangle_stage_ms": t_tri,
        "binning_ms": t_bin,
        "clear_ms": t_clear,
        "raster_ids_nodepth_ms": t_trav,
        "raster_ids_depth_ms": t_idz,
        "raster_full_ms": t_full,
        "pixels_ids_nodepth": px[0],
        "pixels_ids_depth": px[1],
        "pixels_full": px[2],
    });
    let o = json!({
        "threads": 1,
        "iterations": iters,
        "table": table,
        "measured": measured,
        "method": "medians, one thread, frame 0. transform: Mat4::transform_point of every \
             vertex; outcode_snap: the core's vertex stage (transform, outcodes, snap) minus \
             transform; cull_clip_setup: the core's triangle stage (frustum and back-face \
             cull, clipping, setup, store: one fused loop); binning: Frame::bin; clear: \
             filling colour and depth; traversal: drawing into TriangleId with NoDepth \
             (coverage only, every covered pixel written, no colour, no depth); depth: \
             TriangleId with depth minus traversal; shade_write: the configured colour and \
             depth minus TriangleId with depth.",
    });
    Ok(o)
}

/// The memory floor and the frame's ratios to it.
pub fn floor<const S: u32, C: BenchColor, T: DepthWord>(
    scene: &Scene,
    s: &Settings,
    depth_on: bool,
    first: &Run,
) -> Result<Value, String> {
    let len = s.width as usize * s.height as usize;
    let (w, rows, threads) = (s.width as usize, s.strip_rows, first.threads);
    let mut color = vec![C::CLEAR; len];
    let mut depth = vec![T::FAR; if depth_on { len } else { 0 }];
    let fill_value = C::from_fragment(Rgb888::new(40, 120, 200), 0);
    let floor = time_frames(s.warmup, s.frames, |_| {
        for_each_strip(
            &mut color,
            depth_on.then_some(&mut depth[..]),
            w,
            rows as usize,
            threads,
            |_, c, d| {
                c.fill(fill_value);
                if let Some(d) = d {
                    d.fill(T::FAR);
                }
                Ok(0)
            },
        )
        .map_err(|e| e.to_string())?;
        black_box(&color);
        Ok(())
    })?;
    // The practical floor of a depth-tested frame: one fused pass per
    // strip that clears, depth-tests and writes every pixel once (a bare
    // fill is not stable here: 11-36 GB/s depending on what the shared L3
    // holds). The depth and colour written are opaque to the compiler, so
    // the test stays in the loop.
    let near = black_box(T::from_z32(1 << 31));
    let far = black_box(T::FAR);
    let clear = black_box(C::CLEAR);
    let fused = time_frames(s.warmup, s.frames, |_| {
        for_each_strip(
            &mut color,
            depth_on.then_some(&mut depth[..]),
            w,
            rows as usize,
            threads,
            |_, c, d| {
                match d {
                    Some(d) => {
                        for (c, d) in c.iter_mut().zip(d.iter_mut()) {
                            *d = far;
                            *c = clear;
                            if near < *d {
                                *d = near;
                                *c = fill_value;
                            }
                        }
                    }
                    None => c.fill(fill_value),
                }
                Ok(0)
            },
        )
        .map_err(|e| e.to_string())?;
        black_box(&color);
        black_box(&depth);
        Ok(())
    })?;
    let mut pipe =
        FramePipeline::<S>::new(config_of(s), threads, rows).with_tile_width(s.tile_width);
    let (draw_only, _) = pipe.with_layers(scene, |layers| {
        let mut v = Vec::new();
        for k in 0..s.warmup + s.frames {
            color.fill(C::CLEAR);
            depth.fill(T::FAR);
            let t = Instant::now();
            draw_layers(
                layers,
                &mut color,
                depth_on.then_some(&mut depth[..]),
                threads,
                None,
            )
            .map_err(|e| e.to_string())?;
            if k >= s.warmup {
                v.push(ms(t));
            }
        }
        Ok(v)
    })?;
    let f = median(&floor);
    let (frame_ms, raster_ms, draw_ms) = (
        median(&first.total),
        median(&first.raster),
        median(&draw_only),
    );
    let bytes = len
        * (std::mem::size_of::<C>()
            + if depth_on {
                std::mem::size_of::<T>()
            } else {
                0
            });
    let o = json!({
        "threads": threads,
        "bytes_per_frame": bytes,
        "floor_ms": f,
        "floor_min_ms": min(&floor),
        "floor_gb_per_s": bytes as f64 / (f / 1e3) / 1e9,
        "frame_ms": frame_ms,
        "raster_ms": raster_ms,
        "draw_only_ms": draw_ms,
        "frame_over_floor": frame_ms / f,
        "raster_over_floor": raster_ms / f,
        "draw_only_over_floor": draw_ms / f,
        "fused_floor_ms": median(&fused),
        "fused_floor_min_ms": min(&fused),
        "raster_over_fused_floor": raster_ms / median(&fused),
        "frame_over_fused_floor": frame_ms / median(&fused),
        "method": "floor: fill every colour and depth value once, over the same strips and \
             threads; fused_floor: one pass per strip that clears, depth-tests and writes \
             every pixel once (the practical floor of a depth-tested frame); frame: setup + clear + draw (the headline run); raster: clear + draw; \
             draw_only: the draw with the buffers cleared outside the clock.",
    });
    Ok(o)
}
