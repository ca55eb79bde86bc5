//! Criterion benchmarks of the core's stages, one at a time, on the sphere
//! (tgx's scene: 20,000 triangles, 240x320, u16 depth, RGB565) and the
//! Stanford bunny (69,451 triangles, 1920x1080, u32 depth, RGB888):
//!
//! - `transform`: `Mat4::transform_point` over every vertex;
//! - `vertex_stage`: `Frame::process_vertices` (transform, outcode, snap);
//! - `setup/draw_mesh`: `Frame::draw_mesh` into setup storage (transform
//!   per corner, cull, clip, setup, store);
//! - `setup/draw_mesh_cached`: the same through the vertex cache;
//! - `bin`: `Frame::bin` into strips of 16 rows;
//! - `raster/render_rows`: every 16-row strip with `Frame::render_rows`
//!   (each strip walks every triangle);
//! - `raster/render_strip`: every strip of the binned frame.
//!
//! Run with `cargo bench -p microraster-host --bench core` (add a filter,
//! e.g. `-- raster`, to run some). One thread throughout; the end-to-end
//! numbers with threads are `microraster bench`'s.

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use microraster::pixelcolor::{Rgb565, Rgb888, RgbColor};
use microraster::prelude::Submit;
use microraster::{Config, Frame, Mesh, ProcessedVertex, SetupTriangle};
use microraster_host::bench_scenes;
use microraster_host::scene::Object;
use microraster_host::scene::View;
use std::hint::black_box;
use std::time::Duration;

const STRIP_ROWS: u32 = 16;

/// A depth format for the raster benchmarks.
trait Depth: Copy {
    const FAR: Self;
}
impl Depth for u16 {
    const FAR: Self = u16::MAX;
}
impl Depth for u32 {
    const FAR: Self = u32::MAX;
}

struct Case {
    name: &'static str,
    object: Object,
    config: Config,
}

fn cases() -> Vec<Case> {
    let mut out = Vec::new();
    let sphere = bench_scenes::builtin("sphere", &View::new(240, 320)).expect("sphere scene");
    out.push(Case {
        name: "sphere",
        object: sphere.scene.objects[0].clone(),
        config: Config::new(240, 320),
    });
    match bench_scenes::builtin("bunny", &View::new(1920, 1080)) {
        Ok(bunny) => out.push(Case {
            name: "bunny",
            object: bunny.scene.objects[0].clone(),
            config: Config::new(1920, 1080),
        }),
        Err(e) => eprintln!("skipping the bunny: {e}"),
    }
    out
}

fn storage_for<A>(mesh: &Mesh<'_, A>) -> Vec<SetupTriangle> {
    let n = mesh.indices.len();
    vec![SetupTriangle::EMPTY; Frame::<8>::storage_for(n)]
}

fn stages(c: &mut Criterion) {
    for case in cases() {
        let o = &case.object;
        let mesh = o.mesh();
        let config = case.config;
        let (w, h) = (config.width as usize, config.height as usize);
        let mut g = c.benchmark_group(case.name);
        g.sample_size(20)
            .warm_up_time(Duration::from_millis(300))
            .measurement_time(Duration::from_secs(2));

        g.throughput(Throughput::Elements(o.positions.len() as u64));
        let mut out = vec![microraster::Vec4::default(); o.positions.len()];
        g.bench_function("transform", |b| {
            b.iter(|| {
                for (p, v) in o.positions.iter().zip(out.iter_mut()) {
                    *v = o.mvp.transform_point(*p);
                }
                black_box(&out);
            })
        });
        let probe = Frame::<8>::new(config, &mut []).expect("frame");
        let mut cache = vec![ProcessedVertex::EMPTY; o.positions.len()];
        g.bench_function("vertex_stage", |b| {
            b.iter(|| probe.process_vertices(&o.mvp, &o.positions, black_box(&mut cache)))
        });

        g.throughput(Throughput::Elements(o.indices.len() as u64));
        let mut storage = storage_for(&mesh);
        g.bench_function("setup/draw_mesh", |b| {
            b.iter(|| {
                let mut f = Frame::<8>::new(config, &mut storage).expect("frame");
                f.submit_mesh(&mesh, &o.mvp, 0).expect("fits");
                black_box(f.stats())
            })
        });
        g.bench_function("setup/draw_mesh_cached", |b| {
            b.iter(|| {
                let mut f = Frame::<8>::new(config, &mut storage).expect("frame");
                f.submit_mesh_cached(&mesh, &o.mvp, 0, &mut cache)
                    .expect("fits");
                black_box(f.stats())
            })
        });

        // One set-up frame for binning and drawing.
        let mut frame = Frame::<8>::new(config, &mut storage).expect("frame");
        frame.submit_mesh(&mesh, &o.mvp, 0).expect("fits");
        let strips = config.height.div_ceil(STRIP_ROWS) as usize;
        let mut offsets = vec![0u32; strips + 1];
        let mut items = vec![0u32; frame.bin_entries(STRIP_ROWS)];
        g.throughput(Throughput::Elements(frame.triangles().len() as u64));
        g.bench_function("bin", |b| {
            b.iter(|| {
                frame
                    .bin(STRIP_ROWS, &mut offsets, &mut items)
                    .map(|bins| bins.strips())
                    .expect("bin storage")
            })
        });

        g.throughput(Throughput::Elements((w * h) as u64));
        if case.name == "sphere" {
            let mut color = vec![Rgb565::BLACK; w * h];
            let mut depth = vec![u16::FAR; w * h];
            raster(
                &mut g,
                &frame,
                &mut color,
                &mut depth,
                &mut offsets,
                &mut items,
            );
        } else {
            let mut color = vec![Rgb888::BLACK; w * h];
            let mut depth = vec![u32::FAR; w * h];
            raster(
                &mut g,
                &frame,
                &mut color,
                &mut depth,
                &mut offsets,
                &mut items,
            );
        }
        g.finish();
    }
}

fn raster<C, T>(
    g: &mut criterion::BenchmarkGroup<'_, criterion::measurement::WallTime>,
    frame: &Frame<'_, 8>,
    color: &mut [C],
    depth: &mut [T],
    offsets: &mut [u32],
    items: &mut [u32],
) where
    C: microraster::PixelFormat + RgbColor,
    T: Depth,
    [T]: microraster::DepthBuffer,
{
    let width = frame.config().width as usize;
    let chunk = width * STRIP_ROWS as usize;
    g.bench_function("raster/render_rows", |b| {
        b.iter(|| {
            let mut px = 0;
            for (i, (c, d)) in color
                .chunks_mut(chunk)
                .zip(depth.chunks_mut(chunk))
                .enumerate()
            {
                c.fill(C::BLACK);
                d.fill(T::FAR);
                let y0 = i as u32 * STRIP_ROWS;
                let y1 = y0 + (c.len() / width) as u32;
                px += frame
                    .render_rows(y0, y1, c, d)
                    .expect("rows")
                    .pixels_written;
            }
            px
        })
    });
    let bins = frame.bin(STRIP_ROWS, offsets, items).expect("bin storage");
    g.bench_function("raster/render_strip", |b| {
        b.iter(|| {
            let mut px = 0;
            for (i, (c, d)) in color
                .chunks_mut(chunk)
                .zip(depth.chunks_mut(chunk))
                .enumerate()
            {
                c.fill(C::BLACK);
                d.fill(T::FAR);
                px += frame
                    .render_strip(&bins, i as u32, c, d)
                    .expect("strip")
                    .pixels_written;
            }
            px
        })
    });
}

criterion_group!(benches, stages);
criterion_main!(benches);
