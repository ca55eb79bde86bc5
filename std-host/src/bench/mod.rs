//! `microraster bench`: render a scene N times and print timings as JSON.
//!
//! Design: the scene is built once (built-in scenes from
//! [`crate::bench_scenes`], or `--obj` framed like `render --obj`); then
//! every frame goes through one [`FramePipeline`](crate::pipeline::FramePipeline) (see [`crate::pipeline`]:
//! the same setup, binning and strip drawing as [`crate::render::render`],
//! which builds a fresh pipeline per image), kept for the whole run so its
//! vertex caches, setup storage and bins, and the colour and depth buffers
//! here, are reused from one frame to the next; the final RGB8 conversion is
//! skipped. With one thread nothing is spawned. Spinning scenes get the
//! matrix of frame `k` before the frame's clock starts. Only the frame
//! itself is timed, with [`std::time::Instant`]; the report gives median, min, mean and
//! max over `--frames` frames after `--warmup` untimed ones, and the medians
//! of the stages (vertex, triangles, binning, raster). `--render-fn` also
//! times `render::render` itself, as a cross-check (same checksum) and to
//! show the cost of its allocations and RGB8 output.
//!
//! Extra sections, each in the same run and the same JSON object:
//!
//! - `scaling`: with `--threads 1,2,4` (a list) or `--scaling` (1..=cores),
//!   one run per thread count, the speedup over the first, and whether
//!   every run's last frame has the same checksum (it must). The counts
//!   take turns frame by frame (frame `k` at 1, 2 and 4 threads, then
//!   frame `k + 1`), so that a change in the load of this shared machine
//!   meets them all; `paired_speedup` gives the quartiles of the
//!   frame-by-frame ratios. `--sequential` runs each count's frames
//!   together instead.
//! - `split`: for scenes with meshes (skip with `--no-split`), one thread:
//!   transform, outcodes and snapping, cull/clip/setup, binning, clear,
//!   traversal, depth and shade/write,
//!   each measured alone or as a difference of two measured variants (see
//!   the `method` field).
//! - `floor`: for `--scene quad` (or `--floor`): the memory floor, a plain
//!   fill of the colour and depth buffers over the same strips and threads,
//!   and the ratios of the frame, its raster part and the draw alone
//!   (buffers cleared outside the clock) to it.
//! - `peers` (`--peers`): one thread; euc on the same scene and
//!   embedded-graphics' filled `Triangle` on the same 2D triangles, with
//!   microraster measured alongside and the time ratios (see `peers`).
//!
//! Nothing here changes what is drawn: the checksum is the FNV-1a of the
//! last frame's RGB8 bytes, the same function `render --checksum` uses.

//! The code is split by concern: [`runs`] (the timed loop, one pipeline per
//! thread count), [`sections`] (split and floor), [`stats`] (medians),
//! [`progress`] (stderr progress lines) and, with the `peers` feature,
//! `peers`. Without that feature `--peers` is an error that names it; the
//! rest of `bench` works the same.

pub mod progress;
pub mod runs;
pub mod sections;
pub mod stats;

#[cfg(feature = "peers")]
pub mod peers;

use crate::bench_scenes::{self, BenchScene, Spin};
use crate::cli::{default_threads, BenchArgs, ColorArg, CullArg, DepthArg};
use crate::image_out;
use crate::obj;
use crate::render::Counters;
use crate::scene::{self, View};
use microraster::pixelcolor::{Rgb565, Rgb888};
use microraster::CullMode;
use progress::Progress;
use runs::bench_with;
use serde::Serialize;
use serde_json::{json, Value};
use stats::{median, min, Summary};

/// The error for `--peers` in a build without the `peers` feature.
pub const NO_PEERS: &str = "--peers needs the peer renderers, which this binary was built \
     without: rebuild with `--features peers` (e.g. `cargo run --release -p microraster-host \
     --features peers -- bench --peers`)";

/// Most iterations of each measurement of the `split` section.
pub const SPLIT_MAX_ITERATIONS: u32 = 20;

/// Settings resolved from [`BenchArgs`] and the scene's defaults.
#[derive(Clone, Debug, PartialEq)]
pub struct Settings {
    /// Frame width.
    pub width: u32,
    /// Frame height.
    pub height: u32,
    /// Thread counts, one run each (the first is the headline run).
    pub threads: Vec<usize>,
    /// Time several thread counts frame by frame in turn (frame `k` at
    /// every count before frame `k + 1`), not one run after another.
    pub interleave: bool,
    /// Rows per strip (or tile).
    pub strip_rows: u32,
    /// Tile width (0: strips).
    pub tile_width: u32,
    /// Face culling.
    pub cull: CullMode,
    /// Detail culling in pixels (0: off).
    pub detail: u16,
    /// Depth format.
    pub depth: DepthArg,
    /// Colour format.
    pub color: ColorArg,
    /// Sub-pixel bits.
    pub subpixel: u32,
    /// Timed frames.
    pub frames: u32,
    /// Warm-up frames.
    pub warmup: u32,
    /// Degrees per frame.
    pub spin: f32,
    /// Run the peers.
    pub peers: bool,
    /// Measure the memory floor.
    pub floor: bool,
    /// Measure the stage split.
    pub split: bool,
    /// Also time `render::render`.
    pub render_fn: bool,
    /// Also time `render::render` with occlusion culling, interleaved with
    /// the plain one (implies `render_fn`).
    pub occlusion: bool,
}

/// Resolves the options against the scene `name` (`None` for `--obj`).
pub fn settings(args: &BenchArgs, name: Option<&str>) -> Settings {
    let (w, h) = args
        .size
        .unwrap_or_else(|| name.map(bench_scenes::default_size).unwrap_or((800, 600)));
    let sphere = name == Some("sphere");
    let threads = if args.scaling {
        (1..=default_threads()).collect()
    } else if let Some(t) = &args.threads {
        t.0.clone()
    } else if sphere {
        vec![1]
    } else {
        vec![default_threads()]
    };
    Settings {
        width: w,
        height: h,
        threads,
        interleave: !args.sequential,
        strip_rows: args.tile.map_or(args.strip_rows, |t| t.1),
        tile_width: args.tile.map_or(0, |t| t.0),
        cull: match args.cull {
            CullArg::Back => CullMode::Back,
            CullArg::Front => CullMode::Front,
            CullArg::None => CullMode::None,
        },
        detail: args.cull_detail,
        depth: args
            .depth
            .unwrap_or(if sphere { DepthArg::U16 } else { DepthArg::U32 }),
        color: args.color.unwrap_or(if sphere {
            ColorArg::Rgb565
        } else {
            ColorArg::Rgb888
        }),
        subpixel: args.subpixel,
        frames: args.frames,
        warmup: args.warmup,
        spin: args.spin.unwrap_or(if sphere { 1.0 } else { 0.0 }),
        peers: args.peers,
        floor: args.floor || name == Some("quad"),
        split: !args.no_split,
        render_fn: args.render_fn || args.occlusion,
        occlusion: args.occlusion,
    }
}

/// Builds the scene the options ask for.
pub fn load(args: &BenchArgs, s: &Settings) -> Result<BenchScene, String> {
    let view = View {
        width: s.width,
        height: s.height,
        eye: args.eye,
        target: args.target,
        fov: args.fov,
        inv_w: false,
        portals: false,
    };
    let mut bs = match &args.obj {
        Some(path) => {
            let mesh = obj::load_obj(path)?;
            let fov = args.fov.unwrap_or(60.0);
            let (fe, ft) = obj::frame_camera(&mesh, fov, view.aspect());
            let (eye, target) = (args.eye.unwrap_or(fe), args.target.unwrap_or(ft));
            BenchScene {
                name: path.display().to_string(),
                scene: scene::mesh_scene(
                    &mesh.positions,
                    &mesh.indices,
                    eye,
                    target,
                    fov,
                    view.aspect(),
                    view.inv_w,
                )?,
                spin: None,
            }
        }
        None => bench_scenes::builtin(&args.scene, &view)?,
    };
    if let Some(c) = args.cull_clusters {
        let opts = crate::cluster::ClusterOptions::default();
        crate::cluster::cluster_scene(&mut bs.scene, c.cull(), &opts)?;
    }
    if let Some(n) = args.normal_masks {
        crate::normal_mask::mask_scene(&mut bs.scene, n)?;
    }
    if args.cull_detail_boxes {
        crate::scene::detail_boxes(&mut bs.scene);
    }
    if bs.spin.is_some() || s.spin != 0.0 {
        let mut spin = bs
            .spin
            .take()
            .unwrap_or_else(|| Spin::in_place(&bs.scene, 0.0));
        spin.step = s.spin.to_radians();
        bs.spin = Some(spin);
    }
    Ok(bs)
}

/// Runs the benchmark and prints its JSON.
pub fn run(args: &BenchArgs) -> Result<(), String> {
    let name = args.obj.is_none().then_some(args.scene.as_str());
    let s = settings(args, name);
    let mut bs = load(args, &s)?;
    let report = bench(&mut bs, &s)?;
    if let Some(path) = &args.out {
        let rgb = report
            .image
            .as_ref()
            .ok_or_else(|| "no image was kept".to_string())?;
        image_out::write_rgb(path, s.width, s.height, rgb)?;
    }
    let json = report.json;
    let text = if args.compact {
        serde_json::to_string(&json)
    } else {
        serde_json::to_string_pretty(&json)
    };
    println!("{}", text.map_err(|e| e.to_string())?);
    Ok(())
}

/// What [`bench()`] measured.
#[derive(Clone, Debug)]
pub struct Report {
    /// The JSON printed.
    pub json: Value,
    /// The first run's last frame as RGB8.
    pub image: Option<Vec<u8>>,
}

/// The quartiles (25th, 50th, 75th percentile, nearest rank) of
/// `base[k] / other[k]`, the speed-up of frame `k` against the same frame
/// of the base run. For interleaved runs, where frame `k` of every thread
/// count ran one after another and so met the same load.
pub fn paired_speedup(base: &[f64], other: &[f64]) -> [f64; 3] {
    let mut r: Vec<f64> = base.iter().zip(other).map(|(b, o)| b / o).collect();
    if r.is_empty() {
        return [f64::NAN; 3];
    }
    r.sort_by(f64::total_cmp);
    let at = |q: f64| r[((r.len() - 1) as f64 * q).round() as usize];
    [at(0.25), median(&r), at(0.75)]
}

/// Benchmarks `bs` as `s` says.
pub fn bench(bs: &mut BenchScene, s: &Settings) -> Result<Report, String> {
    if s.threads.is_empty() {
        return Err("no thread count given".into());
    }
    if s.peers && !cfg!(feature = "peers") {
        return Err(NO_PEERS.into());
    }
    let depth_on = s.depth != DepthArg::None;
    let mut p = Progress::from_env();
    let formats = match (s.subpixel, s.color, s.depth) {
        (4, ColorArg::Rgb888, DepthArg::U16) => {
            bench_with::<4, Rgb888, u16>(bs, s, depth_on, &mut p)
        }
        (4, ColorArg::Rgb888, DepthArg::F32) => {
            bench_with::<4, Rgb888, microraster::DepthF32>(bs, s, depth_on, &mut p)
        }
        (4, ColorArg::Rgb888, _) => bench_with::<4, Rgb888, u32>(bs, s, depth_on, &mut p),
        (4, ColorArg::Rgb565, DepthArg::U16) => {
            bench_with::<4, Rgb565, u16>(bs, s, depth_on, &mut p)
        }
        (4, ColorArg::Rgb565, DepthArg::F32) => {
            bench_with::<4, Rgb565, microraster::DepthF32>(bs, s, depth_on, &mut p)
        }
        (4, ColorArg::Rgb565, _) => bench_with::<4, Rgb565, u32>(bs, s, depth_on, &mut p),
        (8, ColorArg::Rgb888, DepthArg::U16) => {
            bench_with::<8, Rgb888, u16>(bs, s, depth_on, &mut p)
        }
        (8, ColorArg::Rgb888, DepthArg::F32) => {
            bench_with::<8, Rgb888, microraster::DepthF32>(bs, s, depth_on, &mut p)
        }
        (8, ColorArg::Rgb888, _) => bench_with::<8, Rgb888, u32>(bs, s, depth_on, &mut p),
        (8, ColorArg::Rgb565, DepthArg::U16) => {
            bench_with::<8, Rgb565, u16>(bs, s, depth_on, &mut p)
        }
        (8, ColorArg::Rgb565, DepthArg::F32) => {
            bench_with::<8, Rgb565, microraster::DepthF32>(bs, s, depth_on, &mut p)
        }
        (8, ColorArg::Rgb565, _) => bench_with::<8, Rgb565, u32>(bs, s, depth_on, &mut p),
        (other, ..) => return Err(format!("unsupported subpixel precision {other}")),
    }?;
    p.finish();
    let runs = &formats.runs;
    let first = &runs[0];
    let triangles = bs.scene.triangle_count();
    let sum = Summary::of(&first.total);
    let secs = sum.median / 1e3;
    let scaling = (runs.len() > 1).then(|| {
        let base = runs.iter().find(|r| r.threads == 1).unwrap_or(first);
        let base_ms = median(&base.total);
        let mut scaling = serde_json::Map::new();
        for r in runs {
            let ms = median(&r.total);
            let mut e = json!({
                "threads": r.threads,
                "median_ms": ms,
                "min_ms": min(&r.total),
                "setup_median_ms": median(&r.setup),
                "vertex_median_ms": median(&r.vertex),
                "triangles_median_ms": median(&r.triangles),
                "binning_median_ms": median(&r.binning),
                "raster_median_ms": median(&r.raster),
                "speedup": base_ms / ms,
                "efficiency": base_ms / ms / (r.threads as f64 / base.threads as f64),
                "checksum": format!("{:016x}", r.checksum),
            });
            if s.interleave {
                let q = paired_speedup(&base.total, &r.total);
                e["paired_speedup"] = json!({"median": q[1], "p25": q[0], "p75": q[2]});
            }
            scaling.insert(r.threads.to_string(), e);
        }
        scaling.insert(
            "method".into(),
            json!(if s.interleave {
                "interleaved: frame k at every thread count in turn, each count with its own \
                 pipeline and buffers; speedup is the ratio of the medians, paired_speedup the \
                 quartiles of the frame-by-frame ratios (base frame k over this count's frame k)"
            } else {
                "sequential (--sequential): each thread count's frames in one run after the \
                 previous count's; speedup is the ratio of the medians"
            }),
        );
        scaling.insert("speedup_base_threads".into(), json!(base.threads));
        scaling.insert("available_cores".into(), json!(default_threads()));
        let identical = runs.iter().all(|r| r.checksum == first.checksum);
        scaling.insert("identical_output".into(), json!(identical));
        Value::Object(scaling)
    });
    let out = BenchJson {
        scene: &bs.name,
        width: s.width,
        height: s.height,
        size: format!("{}x{}", s.width, s.height),
        triangles,
        color: color_name(s.color),
        depth: depth_name(s.depth),
        cull: cull_name(s.cull),
        subpixel_bits: s.subpixel,
        strip_rows: s.strip_rows,
        tile_width: s.tile_width,
        spin_deg_per_frame: s.spin,
        frames: s.frames,
        warmup: s.warmup,
        threads: first.threads,
        summary: sum,
        fps: 1.0 / secs,
        triangles_per_s: triangles as f64 / secs,
        shaded_pixels_per_s: first.pixels_written as f64 / secs,
        pixels_written: first.pixels_written,
        stored: first.stats.stored,
        stages: Stages {
            setup_median_ms: median(&first.setup),
            vertex_median_ms: median(&first.vertex),
            triangles_median_ms: median(&first.triangles),
            binning_median_ms: median(&first.binning),
            raster_median_ms: median(&first.raster),
            setup_min_ms: min(&first.setup),
            raster_min_ms: min(&first.raster),
        },
        counters: Counters::from(&first.stats),
        checksum: format!("{:016x}", first.checksum),
        scaling,
        render_fn: formats.render_fn,
        split: formats.split,
        floor: formats.floor,
        peers: formats.peers,
    };
    Ok(Report {
        json: serde_json::to_value(&out).map_err(|e| e.to_string())?,
        image: formats.image,
    })
}

/// The JSON object `bench` prints, fields in this order.
#[derive(Serialize)]
struct BenchJson<'a> {
    scene: &'a str,
    width: u32,
    height: u32,
    size: String,
    triangles: usize,
    color: &'static str,
    depth: &'static str,
    cull: &'static str,
    subpixel_bits: u32,
    strip_rows: u32,
    tile_width: u32,
    spin_deg_per_frame: f32,
    frames: u32,
    warmup: u32,
    threads: usize,
    #[serde(flatten)]
    summary: Summary,
    fps: f64,
    triangles_per_s: f64,
    shaded_pixels_per_s: f64,
    pixels_written: u64,
    stored: u64,
    stages: Stages,
    counters: Counters,
    checksum: String,
    #[serde(skip_serializing_if = "Option::is_none")]
    scaling: Option<Value>,
    #[serde(skip_serializing_if = "Option::is_none")]
    render_fn: Option<Value>,
    #[serde(skip_serializing_if = "Option::is_none")]
    split: Option<Value>,
    #[serde(skip_serializing_if = "Option::is_none")]
    floor: Option<Value>,
    #[serde(skip_serializing_if = "Option::is_none")]
    peers: Option<Value>,
}

/// Medians (and two minima) of the stages of the headline run.
#[derive(Serialize)]
struct Stages {
    setup_median_ms: f64,
    vertex_median_ms: f64,
    triangles_median_ms: f64,
    binning_median_ms: f64,
    raster_median_ms: f64,
    setup_min_ms: f64,
    raster_min_ms: f64,
}

fn color_name(c: ColorArg) -> &'static str {
    match c {
        ColorArg::Rgb888 => "rgb888",
        ColorArg::Rgb565 => "rgb565",
    }
}

fn depth_name(d: DepthArg) -> &'static str {
    match d {
        DepthArg::U16 => "u16",
        DepthArg::U32 => "u32",
        DepthArg::F32 => "f32",
        DepthArg::None => "none",
    }
}

fn cull_name(c: CullMode) -> &'static str {
    match c {
        CullMode::Back => "back",
        CullMode::Front => "front",
        CullMode::None => "none",
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cli::{Cli, Command};
    use crate::render::{self, DepthKind, RenderOptions};
    use clap::Parser;

    fn args(a: &[&str]) -> BenchArgs {
        let mut v = vec!["microraster", "bench"];
        v.extend_from_slice(a);
        match Cli::try_parse_from(v).unwrap().command {
            Command::Bench(b) => b,
            other => panic!("{other:?}"),
        }
    }

    #[test]
    fn defaults_follow_the_scene() {
        let a = args(&[]);
        assert_eq!(a.frames, 50);
        assert_eq!(a.warmup, 5);
        let s = settings(&a, Some("cubes"));
        assert_eq!((s.width, s.height), (800, 600));
        assert_eq!(s.threads, vec![default_threads()]);
        assert_eq!((s.depth, s.color), (DepthArg::U32, ColorArg::Rgb888));
        let s = settings(&args(&["--scene", "sphere"]), Some("sphere"));
        assert_eq!((s.width, s.height, s.threads.clone()), (240, 320, vec![1]));
        assert_eq!(
            (s.depth, s.color, s.spin),
            (DepthArg::U16, ColorArg::Rgb565, 1.0)
        );
        let s = settings(&args(&["--scene", "quad"]), Some("quad"));
        assert!(s.floor && s.split);
        assert_eq!((s.width, s.height), (1920, 1080));
        let s = settings(
            &args(&[
                "--scene",
                "sphere",
                "--threads",
                "1,2,4",
                "--size",
                "64x32",
                "--no-split",
            ]),
            Some("sphere"),
        );
        assert_eq!((s.threads, s.width, s.split), (vec![1, 2, 4], 64, false));
        let s = settings(&args(&["--scaling"]), Some("cubes"));
        assert_eq!(s.threads, (1..=default_threads()).collect::<Vec<_>>());
    }

    #[test]
    fn bad_options_are_rejected() {
        for bad in [
            &["--threads", "0"][..],
            &["--threads", "1,,2"],
            &["--threads", "1,x"],
            &["--frames", "0"],
            &["--warmup", "-1"],
            &["--scene", "teapot"],
            &["--spin", "nan"],
            &["--color", "rgb444"],
            &["--scaling", "--threads", "2"],
            &["--scene", "sphere", "--obj", "a.obj"],
            &["--out", "x.jpg"],
        ] {
            let mut v = vec!["microraster", "bench"];
            v.extend_from_slice(bad);
            assert!(Cli::try_parse_from(v).is_err(), "accepted {bad:?}");
        }
    }

    #[cfg(feature = "peers")]
    fn quick(a: &[&str], name: Option<&str>) -> Report {
        let a = args(a);
        let s = settings(&a, name);
        let mut bs = load(&a, &s).unwrap();
        bench(&mut bs, &s).unwrap()
    }

    #[test]
    #[cfg(feature = "peers")]
    fn sphere_bench_with_everything() {
        let r = quick(
            &[
                "--scene",
                "sphere",
                "--size",
                "60x80",
                "--frames",
                "2",
                "--warmup",
                "1",
                "--threads",
                "1,2",
                "--peers",
                "--floor",
            ],
            Some("sphere"),
        );
        let text = r.json.to_string();
        for key in [
            "\"median_ms\"",
            "\"scaling\"",
            "\"identical_output\":true",
            "\"split\"",
            "\"floor\"",
            "\"euc_over_microraster\"",
            "\"eg_over_microraster\"",
        ] {
            assert!(text.contains(key), "{key} missing in {text}");
        }
        assert_eq!(r.image.map(|i| i.len()), Some(60 * 80 * 3));
    }

    #[test]
    fn bench_draws_what_render_draws() {
        // The last frame (k = warmup + frames - 1) of a spinning scene, in
        // the pipeline with reused buffers and in render::render.
        for (scene, threads) in [("sphere", "1"), ("cubes", "2"), ("sphere", "2")] {
            let a = args(&[
                "--scene",
                scene,
                "--size",
                "96x72",
                "--frames",
                "3",
                "--warmup",
                "1",
                "--threads",
                threads,
                "--color",
                "rgb888",
                "--spin",
                "7",
                "--no-split",
                "--render-fn",
            ]);
            let s = settings(&a, Some(scene));
            let mut bs = load(&a, &s).unwrap();
            let r = bench(&mut bs, &s).unwrap();
            bs.set_frame(3);
            let opts = RenderOptions {
                width: 96,
                height: 72,
                cull: CullMode::Back,
                detail: 0,
                depth: if scene == "sphere" {
                    DepthKind::U16
                } else {
                    DepthKind::U32
                },
                subpixel: 8,
                threads: 1,
                strip_rows: 16,
                tile_width: 0,
                ids: false,
                mode: microraster::RasterMode::Clipping,
                inv_w: false,
                occlusion: crate::render::Occlusion::Off,
            };
            let want = render::render(&bs.scene, &opts).unwrap();
            let sum = format!("\"checksum\":\"{:016x}\"", want.checksum());
            let text = r.json.to_string();
            // Once for the headline run, once for render_fn.
            assert_eq!(text.matches(&sum).count(), 2, "{scene}: {sum} in {text}");
            assert_eq!(r.image.unwrap(), want.rgb);
        }
    }

    #[test]
    fn paired_speedups_are_quartiles_of_frame_ratios() {
        let base = [4.0, 8.0, 6.0, 10.0, 2.0];
        let other = [2.0, 2.0, 3.0, 10.0, 2.0];
        // Ratios 2, 4, 2, 1, 1: sorted 1, 1, 2, 2, 4.
        assert_eq!(paired_speedup(&base, &other), [1.0, 2.0, 2.0]);
        assert!(paired_speedup(&[], &[]).iter().all(|q| q.is_nan()));
    }

    #[test]
    fn interleaved_and_sequential_scaling_draw_the_same_frames() {
        // A spinning scene: every thread count must draw the last frame's
        // matrix whichever way the frames are ordered.
        let mut images = Vec::new();
        for extra in [&[][..], &["--sequential"], &["--threads", "1"]] {
            let mut a: Vec<&str> =
                "--scene cubes --size 96x72 --frames 3 --warmup 1 --spin 7 --no-split"
                    .split(' ')
                    .collect();
            if !extra.contains(&"--threads") {
                a.extend_from_slice(&["--threads", "1,2,3"]);
            }
            a.extend_from_slice(extra);
            let a = args(&a);
            let s = settings(&a, Some("cubes"));
            assert_eq!(s.interleave, !extra.contains(&"--sequential"));
            let mut bs = load(&a, &s).unwrap();
            let r = bench(&mut bs, &s).unwrap();
            if s.threads.len() > 1 {
                let sc = &r.json["scaling"];
                assert_eq!(sc["identical_output"], true, "{sc}");
                assert_eq!(sc["3"]["checksum"], sc["1"]["checksum"], "{sc}");
                assert_eq!(sc["3"]["paired_speedup"].is_object(), s.interleave, "{sc}");
                assert!(sc["method"].as_str().unwrap().starts_with(if s.interleave {
                    "interleaved"
                } else {
                    "sequential"
                }));
            }
            images.push(r.image.unwrap());
        }
        assert!(images.windows(2).all(|w| w[0] == w[1]));
    }

    #[test]
    fn every_format_gives_the_same_coverage() {
        let mut counts = Vec::new();
        for color in ["rgb888", "rgb565"] {
            for depth in ["u16", "u32", "none"] {
                for sub in ["4", "8"] {
                    let a = args(&[
                        "--scene",
                        "cubes",
                        "--size",
                        "80x60",
                        "--frames",
                        "1",
                        "--warmup",
                        "0",
                        "--threads",
                        "1",
                        "--color",
                        color,
                        "--depth",
                        depth,
                        "--subpixel",
                        sub,
                        "--no-split",
                    ]);
                    let s = settings(&a, Some("cubes"));
                    let mut bs = load(&a, &s).unwrap();
                    let f = bench(&mut bs, &s).unwrap();
                    let t = f.json.to_string();
                    assert!(t.contains(&format!("\"depth\":\"{depth}\"")), "{t}");
                    counts.push(t.contains("\"pixels_written\":0"));
                }
            }
        }
        assert!(counts.iter().all(|zero| !zero));
    }
}
