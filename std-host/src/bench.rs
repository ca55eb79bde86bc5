//! `microraster bench`: render a scene N times and print timings as JSON.
//!
//! Design: the scene is built once (built-in scenes from
//! [`crate::bench_scenes`], or `--obj` framed like `render --obj`); then
//! every frame goes through one [`FramePipeline`] (see [`crate::pipeline`]:
//! the same setup, binning and strip drawing as [`crate::render::render`],
//! which builds a fresh pipeline per image), kept for the whole run so its
//! vertex caches, setup storage and bins, and the colour and depth buffers
//! here, are reused from one frame to the next; the final RGB8 conversion is
//! skipped. With one thread nothing is spawned. Spinning scenes get the
//! matrix of frame `k` before the frame's clock starts. Only the frame
//! itself is timed, with [`Instant`]; the report gives median, min, mean and
//! max over `--frames` frames after `--warmup` untimed ones, and the medians
//! of the stages (vertex, triangles, binning, raster). `--render-fn` also
//! times `render::render` itself, as a cross-check (same checksum) and to
//! show the cost of its allocations and RGB8 output.
//!
//! Extra sections, each in the same run and the same JSON object:
//!
//! - `scaling`: with `--threads 1,2,4` (a list) or `--scaling` (1..=cores),
//!   one run per thread count, the speedup over the first, and whether
//!   every run's last frame has the same checksum (it must).
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
//!   microraster measured alongside and the time ratios (see
//!   [`crate::peers`]).
//!
//! Nothing here changes what is drawn: the checksum is the FNV-1a of the
//! last frame's RGB8 bytes, the same function `render --checksum` uses.

use crate::bench_scenes::{self, BenchScene, Spin, View};
use crate::cli::{
    check_camera, default_threads, parse_fov, parse_image_path, parse_size, parse_strip_rows,
    parse_subpixel, parse_vec3, CullArg, DepthArg, SCENES,
};
use crate::image_out;
use crate::json::JsonObject;
use crate::obj;
use crate::peers::{self, EucScene, Framebuffer, PackedPixel};
use crate::pipeline::{draw_layers, for_each_strip, DepthFormat, FramePipeline};
use crate::render::{self, fnv1a64, DepthKind, RenderOptions, Scene, BACKGROUND};
use clap::builder::PossibleValuesParser;
use clap::{Args, ValueEnum};
use microraster::pixelcolor::{Rgb565, Rgb888, RgbColor};
use microraster::{Config, CullMode, Error, PixelFormat, Stats, TriangleId, Vec4};
use std::hint::black_box;
use std::path::PathBuf;
use std::time::Instant;

/// Most iterations of each measurement of the `split` section.
pub const SPLIT_MAX_ITERATIONS: u32 = 20;

/// Colour format of the benchmark's frame buffer.
#[derive(ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum ColorArg {
    /// 24-bit RGB (`Rgb888`), as `render` draws.
    Rgb888,
    /// 16-bit RGB565 (`Rgb565`), as small displays take.
    Rgb565,
}

/// A list of thread counts, `N[,N...]`.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ThreadList(pub Vec<usize>);

/// Parses `--threads`: one count or a comma-separated list, each in
/// 1..=[`crate::cli::MAX_THREADS`].
pub fn parse_thread_list(s: &str) -> Result<ThreadList, String> {
    let list = s
        .split(',')
        .map(crate::cli::parse_threads)
        .collect::<Result<Vec<_>, _>>()?;
    Ok(ThreadList(list))
}

fn parse_frames(s: &str) -> Result<u32, String> {
    match s.trim().parse::<u32>() {
        Ok(n) if (1..=1_000_000).contains(&n) => Ok(n),
        _ => Err(format!(
            "frames must be a whole number in 1..=1000000, got {s:?}"
        )),
    }
}

fn parse_warmup(s: &str) -> Result<u32, String> {
    match s.trim().parse::<u32>() {
        Ok(n) if n <= 1_000_000 => Ok(n),
        _ => Err(format!(
            "warm-up frames must be a whole number in 0..=1000000, got {s:?}"
        )),
    }
}

fn parse_spin(s: &str) -> Result<f32, String> {
    match s.trim().parse::<f32>() {
        Ok(d) if d.is_finite() && d.abs() <= 360.0 => Ok(d),
        _ => Err(format!(
            "spin must be degrees per frame in -360..=360, got {s:?}"
        )),
    }
}

/// Options of `microraster bench`.
#[derive(Args, Debug, Clone, PartialEq)]
pub struct BenchArgs {
    /// Built-in scene: cubes (800x600), sphere (tgx's 20,000-triangle
    /// sphere, 240x320, 1 thread, u16 depth, RGB565), bunny (69,451
    /// triangles, 1920x1080), bunny-subdiv (1,111,216 triangles, 1920x1080),
    /// quad (two triangles, 1920x1080, with the memory floor).
    #[arg(
        long,
        value_name = "NAME",
        default_value = "cubes",
        value_parser = PossibleValuesParser::new(SCENES),
        conflicts_with = "obj"
    )]
    pub scene: String,

    /// Benchmark this Wavefront OBJ mesh (framed and flat-shaded as by
    /// `render --obj`) instead of a scene.
    #[arg(long, value_name = "FILE")]
    pub obj: Option<PathBuf>,

    /// Camera position (default: the scene's, or framed to fit the mesh).
    #[arg(long, value_name = "X,Y,Z", value_parser = parse_vec3, allow_hyphen_values = true)]
    pub eye: Option<[f32; 3]>,

    /// Point the camera looks at.
    #[arg(long, value_name = "X,Y,Z", value_parser = parse_vec3, allow_hyphen_values = true)]
    pub target: Option<[f32; 3]>,

    /// Vertical field of view in degrees [default: 45 for sphere, else 60].
    #[arg(long, value_name = "DEG", value_parser = parse_fov)]
    pub fov: Option<f32>,

    /// Image size in pixels [default: the scene's; 800x600 for --obj].
    #[arg(long, value_name = "WxH", value_parser = parse_size)]
    pub size: Option<(u32, u32)>,

    /// Worker threads, or a list (`1,2,4`) for a scaling run [default: 1
    /// for sphere, else all cores].
    #[arg(long, value_name = "N[,N...]", value_parser = parse_thread_list)]
    pub threads: Option<ThreadList>,

    /// Thread scaling: one run for each thread count 1..=cores.
    #[arg(long, conflicts_with = "threads")]
    pub scaling: bool,

    /// Rows per strip.
    #[arg(long, value_name = "R", default_value = "16", value_parser = parse_strip_rows)]
    pub strip_rows: u32,

    /// Face culling.
    #[arg(long, value_enum, default_value_t = CullArg::Back)]
    pub cull: CullArg,

    /// Depth buffer format [default: u16 for sphere, else u32].
    #[arg(long, value_enum)]
    pub depth: Option<DepthArg>,

    /// Colour format [default: rgb565 for sphere, else rgb888].
    #[arg(long, value_enum)]
    pub color: Option<ColorArg>,

    /// Sub-pixel precision in bits (4 or 8).
    #[arg(long, value_name = "BITS", default_value = "8", value_parser = parse_subpixel)]
    pub subpixel: u32,

    /// Timed frames per run.
    #[arg(long, value_name = "N", default_value = "50", value_parser = parse_frames)]
    pub frames: u32,

    /// Untimed frames before the timed ones.
    #[arg(long, value_name = "N", default_value = "5", value_parser = parse_warmup)]
    pub warmup: u32,

    /// Turn the model about y by this many degrees per frame [default: 1
    /// for sphere, else 0].
    #[arg(long, value_name = "DEG", value_parser = parse_spin, allow_hyphen_values = true)]
    pub spin: Option<f32>,

    /// Also run the peers (euc, embedded-graphics) on the same scene, one
    /// thread, and print the ratios.
    #[arg(long)]
    pub peers: bool,

    /// Also measure the memory floor (always on for the quad scene).
    #[arg(long)]
    pub floor: bool,

    /// Skip the stage split of mesh scenes.
    #[arg(long)]
    pub no_split: bool,

    /// Print the JSON on one line.
    #[arg(long)]
    pub compact: bool,

    /// Also time `render::render` itself frame by frame (allocations and
    /// RGB8 output included), next to the buffer-reusing loop.
    #[arg(long)]
    pub render_fn: bool,

    /// Write the last frame of the first run to this image (.png or .ppm).
    #[arg(long, value_name = "FILE", value_parser = parse_image_path)]
    pub out: Option<PathBuf>,
}

/// Settings resolved from [`BenchArgs`] and the scene's defaults.
#[derive(Clone, Debug, PartialEq)]
pub struct Settings {
    /// Frame width.
    pub width: u32,
    /// Frame height.
    pub height: u32,
    /// Thread counts, one run each (the first is the headline run).
    pub threads: Vec<usize>,
    /// Rows per strip.
    pub strip_rows: u32,
    /// Face culling.
    pub cull: CullMode,
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
        strip_rows: args.strip_rows,
        cull: match args.cull {
            CullArg::Back => CullMode::Back,
            CullArg::Front => CullMode::Front,
            CullArg::None => CullMode::None,
        },
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
        render_fn: args.render_fn,
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
    };
    let mut bs = match &args.obj {
        Some(path) => {
            let mesh = obj::load_obj(path)?;
            let fov = args.fov.unwrap_or(60.0);
            let (fe, ft) = obj::frame_camera(&mesh, fov, view.aspect());
            let (eye, target) = (args.eye.unwrap_or(fe), args.target.unwrap_or(ft));
            check_camera(eye, target, [0.0, 1.0, 0.0])?;
            BenchScene {
                name: path.display().to_string(),
                scene: render::mesh_scene(
                    &mesh.positions,
                    &mesh.indices,
                    eye,
                    target,
                    fov,
                    view.aspect(),
                ),
                spin: None,
            }
        }
        None => {
            if let (Some(e), Some(t)) = (args.eye, args.target) {
                check_camera(e, t, [0.0, 1.0, 0.0])?;
            }
            bench_scenes::builtin(&args.scene, &view)?
        }
    };
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
    if args.compact {
        println!("{json}");
    } else {
        println!("{}", json.to_pretty_string());
    }
    Ok(())
}

/// What [`bench()`] measured.
#[derive(Clone, Debug)]
pub struct Report {
    /// The JSON printed.
    pub json: JsonObject,
    /// The first run's last frame as RGB8.
    pub image: Option<Vec<u8>>,
}

/// Benchmarks `bs` as `s` says.
pub fn bench(bs: &mut BenchScene, s: &Settings) -> Result<Report, String> {
    if s.threads.is_empty() {
        return Err("no thread count given".into());
    }
    let depth_on = s.depth != DepthArg::None;
    let formats = match (s.subpixel, s.color, s.depth) {
        (4, ColorArg::Rgb888, DepthArg::U16) => bench_with::<4, Rgb888, u16>(bs, s, depth_on),
        (4, ColorArg::Rgb888, _) => bench_with::<4, Rgb888, u32>(bs, s, depth_on),
        (4, ColorArg::Rgb565, DepthArg::U16) => bench_with::<4, Rgb565, u16>(bs, s, depth_on),
        (4, ColorArg::Rgb565, _) => bench_with::<4, Rgb565, u32>(bs, s, depth_on),
        (8, ColorArg::Rgb888, DepthArg::U16) => bench_with::<8, Rgb888, u16>(bs, s, depth_on),
        (8, ColorArg::Rgb888, _) => bench_with::<8, Rgb888, u32>(bs, s, depth_on),
        (8, ColorArg::Rgb565, DepthArg::U16) => bench_with::<8, Rgb565, u16>(bs, s, depth_on),
        (8, ColorArg::Rgb565, _) => bench_with::<8, Rgb565, u32>(bs, s, depth_on),
        (other, ..) => return Err(format!("unsupported subpixel precision {other}")),
    }?;
    let runs = &formats.runs;
    let first = &runs[0];
    let triangles = bs.scene.triangle_count();
    let sum = Summary::of(&first.total);
    let secs = sum.median / 1e3;

    let mut o = JsonObject::new();
    o.field_str("scene", &bs.name)
        .field_u64("width", s.width as u64)
        .field_u64("height", s.height as u64)
        .field_str("size", &format!("{}x{}", s.width, s.height))
        .field_u64("triangles", triangles as u64)
        .field_str("color", color_name(s.color))
        .field_str("depth", depth_name(s.depth))
        .field_str("cull", cull_name(s.cull))
        .field_u64("subpixel_bits", s.subpixel as u64)
        .field_u64("strip_rows", s.strip_rows as u64)
        .field_f64("spin_deg_per_frame", s.spin as f64)
        .field_u64("frames", s.frames as u64)
        .field_u64("warmup", s.warmup as u64)
        .field_u64("threads", first.threads as u64);
    sum.write(&mut o);
    o.field_f64("fps", 1.0 / secs)
        .field_f64("triangles_per_s", triangles as f64 / secs)
        .field_f64("shaded_pixels_per_s", first.pixels_written as f64 / secs)
        .field_u64("pixels_written", first.pixels_written)
        .field_u64("stored", first.stats.stored as u64);
    let mut stages = JsonObject::new();
    stages
        .field_f64("setup_median_ms", median(&first.setup))
        .field_f64("vertex_median_ms", median(&first.vertex))
        .field_f64("triangles_median_ms", median(&first.triangles))
        .field_f64("binning_median_ms", median(&first.binning))
        .field_f64("raster_median_ms", median(&first.raster))
        .field_f64("setup_min_ms", min(&first.setup))
        .field_f64("raster_min_ms", min(&first.raster));
    o.field_obj("stages", &stages)
        .field_obj("counters", &counters(&first.stats))
        .field_str("checksum", &format!("{:016x}", first.checksum));
    if runs.len() > 1 {
        let base = runs.iter().find(|r| r.threads == 1).unwrap_or(first);
        let base_ms = median(&base.total);
        let mut scaling = JsonObject::new();
        for r in runs {
            let ms = median(&r.total);
            let mut e = JsonObject::new();
            e.field_u64("threads", r.threads as u64)
                .field_f64("median_ms", ms)
                .field_f64("min_ms", min(&r.total))
                .field_f64("setup_median_ms", median(&r.setup))
                .field_f64("raster_median_ms", median(&r.raster))
                .field_f64("speedup", base_ms / ms)
                .field_f64(
                    "efficiency",
                    base_ms / ms / (r.threads as f64 / base.threads as f64),
                )
                .field_str("checksum", &format!("{:016x}", r.checksum));
            scaling.field_obj(&r.threads.to_string(), &e);
        }
        scaling
            .field_u64("speedup_base_threads", base.threads as u64)
            .field_u64("available_cores", default_threads() as u64)
            .field_bool(
                "identical_output",
                runs.iter().all(|r| r.checksum == first.checksum),
            );
        o.field_obj("scaling", &scaling);
    }
    if let Some(r) = &formats.render_fn {
        o.field_obj("render_fn", r);
    }
    if let Some(split) = &formats.split {
        o.field_obj("split", split);
    }
    if let Some(floor) = &formats.floor {
        o.field_obj("floor", floor);
    }
    if let Some(p) = &formats.peers {
        o.field_obj("peers", p);
    }
    Ok(Report {
        json: o,
        image: formats.image,
    })
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

/// The core's counters as a JSON object (also `render --stats`).
pub fn counters(s: &Stats) -> JsonObject {
    let mut c = JsonObject::new();
    c.field_u64("submitted", s.submitted)
        .field_u64("culled_object", s.culled_object)
        .field_u64("culled_frustum", s.culled_frustum)
        .field_u64("culled_backface", s.culled_backface)
        .field_u64("culled_degenerate", s.culled_degenerate)
        .field_u64("rejected_nonfinite", s.rejected_nonfinite)
        .field_u64("rejected_index", s.rejected_index)
        .field_u64("clipped", s.clipped)
        .field_u64("stored", s.stored);
    c
}

// ---------------------------------------------------------------------------
// Statistics.

/// Median of `v` (mean of the middle two for an even count); NaN if empty.
pub fn median(v: &[f64]) -> f64 {
    if v.is_empty() {
        return f64::NAN;
    }
    let mut s = v.to_vec();
    s.sort_by(f64::total_cmp);
    let n = s.len();
    if n % 2 == 1 {
        s[n / 2]
    } else {
        (s[n / 2 - 1] + s[n / 2]) * 0.5
    }
}

fn min(v: &[f64]) -> f64 {
    v.iter().copied().fold(f64::INFINITY, f64::min)
}

/// Median, min, mean and max of a list of times in milliseconds.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Summary {
    /// Median.
    pub median: f64,
    /// Minimum.
    pub min: f64,
    /// Mean.
    pub mean: f64,
    /// Maximum.
    pub max: f64,
}

impl Summary {
    /// Summarises `v`.
    pub fn of(v: &[f64]) -> Summary {
        Summary {
            median: median(v),
            min: min(v),
            mean: v.iter().sum::<f64>() / v.len() as f64,
            max: v.iter().copied().fold(f64::NEG_INFINITY, f64::max),
        }
    }

    fn write(&self, o: &mut JsonObject) {
        o.field_f64("median_ms", self.median)
            .field_f64("min_ms", self.min)
            .field_f64("mean_ms", self.mean)
            .field_f64("max_ms", self.max);
    }

    fn json(&self) -> JsonObject {
        let mut o = JsonObject::new();
        self.write(&mut o);
        o
    }
}

/// Runs `warmup` untimed and `frames` timed calls of `f(k)` (k counting
/// from 0 over both) and returns the timed ones' milliseconds.
fn time_frames<F: FnMut(u32) -> Result<(), String>>(
    warmup: u32,
    frames: u32,
    mut f: F,
) -> Result<Vec<f64>, String> {
    let mut out = Vec::with_capacity(frames as usize);
    for k in 0..warmup + frames {
        let t = Instant::now();
        f(k)?;
        if k >= warmup {
            out.push(ms(t));
        }
    }
    Ok(out)
}

fn ms(t: Instant) -> f64 {
    t.elapsed().as_secs_f64() * 1e3
}

// ---------------------------------------------------------------------------
// Formats and strips.

/// A colour format the benchmark draws into.
pub trait BenchColor: PixelFormat + Send + Sync + PartialEq + 'static {
    /// The background.
    const CLEAR: Self;
    /// The same format packed for euc.
    type Packed: PackedPixel;
    /// As RGB8.
    fn rgb888(self) -> Rgb888;
}

impl BenchColor for Rgb888 {
    const CLEAR: Self = BACKGROUND;
    type Packed = u32;
    fn rgb888(self) -> Rgb888 {
        self
    }
}

impl BenchColor for Rgb565 {
    const CLEAR: Self = Rgb565::BLACK;
    type Packed = u16;
    fn rgb888(self) -> Rgb888 {
        Rgb888::from(self)
    }
}

fn config_of(s: &Settings) -> Config {
    let mut c = Config::new(s.width, s.height);
    c.cull = s.cull;
    c
}

// ---------------------------------------------------------------------------
// The runs.

/// One run of `frames` frames at one thread count.
#[derive(Clone, Debug)]
struct Run {
    threads: usize,
    total: Vec<f64>,
    setup: Vec<f64>,
    vertex: Vec<f64>,
    triangles: Vec<f64>,
    binning: Vec<f64>,
    raster: Vec<f64>,
    pixels_written: u64,
    stats: Stats,
    checksum: u64,
    covered: u64,
    image: Option<Vec<u8>>,
}

struct Formats {
    runs: Vec<Run>,
    render_fn: Option<JsonObject>,
    split: Option<JsonObject>,
    floor: Option<JsonObject>,
    peers: Option<JsonObject>,
    image: Option<Vec<u8>>,
}

fn bench_with<const S: u32, C: BenchColor, T: DepthFormat>(
    bs: &mut BenchScene,
    s: &Settings,
    depth_on: bool,
) -> Result<Formats, String> {
    let mut runs = Vec::new();
    for (i, &threads) in s.threads.iter().enumerate() {
        runs.push(run_frames::<S, C, T>(bs, s, depth_on, threads, i == 0)?);
    }
    let image = runs.first_mut().and_then(|r| r.image.take());
    let render_fn = if s.render_fn {
        Some(render_fn_section(bs, s, runs[0].threads)?)
    } else {
        None
    };
    bs.set_frame(0);
    let split = if s.split && !bs.scene.objects.is_empty() {
        Some(split::<S, C, T>(&bs.scene, s, depth_on)?)
    } else {
        None
    };
    let floor = if s.floor {
        Some(floor::<S, C, T>(&bs.scene, s, depth_on, &runs[0])?)
    } else {
        None
    };
    let peers = if s.peers {
        let mr = match runs.iter().find(|r| r.threads == 1) {
            Some(r) => r.clone(),
            None => run_frames::<S, C, T>(bs, s, depth_on, 1, false)?,
        };
        Some(peers_section::<S, C>(bs, s, &mr)?)
    } else {
        None
    };
    Ok(Formats {
        runs,
        render_fn,
        split,
        floor,
        peers,
        image,
    })
}

fn run_frames<const S: u32, C: BenchColor, T: DepthFormat>(
    bs: &mut BenchScene,
    s: &Settings,
    depth_on: bool,
    threads: usize,
    keep_image: bool,
) -> Result<Run, String> {
    let mut pipe = FramePipeline::<S>::new(config_of(s), threads, s.strip_rows);
    let len = s.width as usize * s.height as usize;
    let mut color = vec![C::CLEAR; len];
    let mut depth = vec![T::CLEAR; if depth_on { len } else { 0 }];
    let mut run = Run {
        threads,
        total: Vec::new(),
        setup: Vec::new(),
        vertex: Vec::new(),
        triangles: Vec::new(),
        binning: Vec::new(),
        raster: Vec::new(),
        pixels_written: 0,
        stats: Stats::default(),
        checksum: 0,
        covered: 0,
        image: None,
    };
    for k in 0..s.warmup + s.frames {
        bs.set_frame(k);
        let t0 = Instant::now();
        let d = depth_on.then_some(&mut depth[..]);
        let (setup, raster_ms, px) = pipe.render(&bs.scene, &mut color, d, C::CLEAR)?;
        let frame_ms = ms(t0);
        if k >= s.warmup {
            run.total.push(frame_ms);
            run.setup.push(setup.total_ms());
            run.vertex.push(setup.vertex_ms);
            run.triangles.push(setup.triangles_ms);
            run.binning.push(setup.binning_ms);
            run.raster.push(raster_ms);
        }
        (run.pixels_written, run.stats) = (px, setup.stats);
    }
    let rgb: Vec<u8> = color
        .iter()
        .flat_map(|c| {
            let c = c.rgb888();
            [c.r(), c.g(), c.b()]
        })
        .collect();
    run.checksum = fnv1a64(&rgb);
    run.covered = color.iter().filter(|&&c| c != C::CLEAR).count() as u64;
    run.image = keep_image.then_some(rgb);
    Ok(run)
}

/// `render::render` itself, frame by frame (allocations, RGB8 output and
/// all), as a cross-check of the pipeline above.
fn render_fn_section(
    bs: &mut BenchScene,
    s: &Settings,
    threads: usize,
) -> Result<JsonObject, String> {
    let opts = RenderOptions {
        width: s.width,
        height: s.height,
        cull: s.cull,
        depth: match s.depth {
            DepthArg::U16 => DepthKind::U16,
            DepthArg::U32 => DepthKind::U32,
            DepthArg::None => DepthKind::None,
        },
        subpixel: s.subpixel,
        threads,
        strip_rows: s.strip_rows,
        ids: false,
    };
    let (mut total, mut setup, mut raster) = (Vec::new(), Vec::new(), Vec::new());
    let mut checksum = 0;
    for k in 0..s.warmup + s.frames {
        bs.set_frame(k);
        let t = Instant::now();
        let r = render::render(&bs.scene, &opts)?;
        let frame_ms = ms(t);
        if k >= s.warmup {
            total.push(frame_ms);
            setup.push(r.timings.setup_ms);
            raster.push(r.timings.raster_ms);
        }
        checksum = r.checksum();
    }
    let mut o = Summary::of(&total).json();
    o.field_u64("threads", threads as u64)
        .field_f64("setup_median_ms", median(&setup))
        .field_f64("raster_median_ms", median(&raster))
        .field_str("color", "rgb888")
        .field_str("checksum", &format!("{checksum:016x}"));
    Ok(o)
}

/// The stage split, one thread, on the scene as in frame 0.
fn split<const S: u32, C: BenchColor, T: DepthFormat>(
    scene: &Scene,
    s: &Settings,
    depth_on: bool,
) -> Result<JsonObject, String> {
    let iters = s.frames.min(SPLIT_MAX_ITERATIONS);
    let warm = s.warmup.min(2);
    let len = s.width as usize * s.height as usize;
    let rows = s.strip_rows;
    let mut pipe = FramePipeline::<S>::new(config_of(s), 1, rows);

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
    let mut depth = vec![T::CLEAR; if depth_on { len } else { 0 }];
    let mut ids = vec![TriangleId(0); len];
    let mut ids_depth = vec![T::CLEAR; len];
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
                    d.fill(T::CLEAR);
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
            px[0] = draw_layers::<S, TriangleId, T>(layers, &mut ids, None, rows, 1, None)
                .map_err(err)?;
            let ta = ms(t);
            ids_depth.fill(T::CLEAR);
            let t = Instant::now();
            px[1] = draw_layers::<S, TriangleId, T>(
                layers,
                &mut ids,
                Some(&mut ids_depth),
                rows,
                1,
                None,
            )
            .map_err(err)?;
            let tb = ms(t);
            depth.fill(T::CLEAR);
            let t = Instant::now();
            px[2] = draw_layers::<S, C, T>(
                layers,
                &mut color,
                depth_on.then_some(&mut depth[..]),
                rows,
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
    let mut table = JsonObject::new();
    table
        .field_f64("transform_ms", t_transform)
        .field_f64("outcode_snap_ms", t_vertex - t_transform)
        .field_f64("cull_clip_setup_ms", t_tri)
        .field_f64("binning_ms", t_bin)
        .field_f64("clear_ms", t_clear)
        .field_f64("traversal_ms", t_trav)
        .field_f64("depth_ms", t_idz - t_trav)
        .field_f64("shade_write_ms", t_full - t_idz)
        .field_f64("sum_ms", t_vertex + t_tri + t_bin + t_clear + t_full);
    let mut measured = JsonObject::new();
    measured
        .field_f64("transform_ms", t_transform)
        .field_f64("vertex_stage_ms", t_vertex)
        .field_f64("triangle_stage_ms", t_tri)
        .field_f64("binning_ms", t_bin)
        .field_f64("clear_ms", t_clear)
        .field_f64("raster_ids_nodepth_ms", t_trav)
        .field_f64("raster_ids_depth_ms", t_idz)
        .field_f64("raster_full_ms", t_full)
        .field_u64("pixels_ids_nodepth", px[0])
        .field_u64("pixels_ids_depth", px[1])
        .field_u64("pixels_full", px[2]);
    let mut o = JsonObject::new();
    o.field_u64("threads", 1)
        .field_u64("iterations", iters as u64)
        .field_obj("table", &table)
        .field_obj("measured", &measured)
        .field_str(
            "method",
            "medians, one thread, frame 0. transform: Mat4::transform_point of every vertex; \
             outcode_snap: the core's vertex stage (transform, outcodes, snap) minus \
             transform; cull_clip_setup: the core's triangle stage (frustum and back-face \
             cull, clipping, setup, store: one fused loop); binning: Frame::bin; clear: \
             filling colour and depth; traversal: drawing into TriangleId with NoDepth \
             (coverage only, every covered pixel written, no colour, no depth); depth: \
             TriangleId with depth minus traversal; shade_write: the configured colour and \
             depth minus TriangleId with depth.",
        );
    Ok(o)
}

/// The memory floor and the frame's ratios to it.
fn floor<const S: u32, C: BenchColor, T: DepthFormat>(
    scene: &Scene,
    s: &Settings,
    depth_on: bool,
    first: &Run,
) -> Result<JsonObject, String> {
    let len = s.width as usize * s.height as usize;
    let (w, rows, threads) = (s.width as usize, s.strip_rows, first.threads);
    let mut color = vec![C::CLEAR; len];
    let mut depth = vec![T::CLEAR; if depth_on { len } else { 0 }];
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
                    d.fill(T::CLEAR);
                }
                Ok(0)
            },
        )
        .map_err(|e| e.to_string())?;
        black_box(&color);
        Ok(())
    })?;
    let mut pipe = FramePipeline::<S>::new(config_of(s), threads, rows);
    let (draw_only, _) = pipe.with_layers(scene, |layers| {
        let mut v = Vec::new();
        for k in 0..s.warmup + s.frames {
            color.fill(C::CLEAR);
            depth.fill(T::CLEAR);
            let t = Instant::now();
            draw_layers(
                layers,
                &mut color,
                depth_on.then_some(&mut depth[..]),
                rows,
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
    let mut o = JsonObject::new();
    o.field_u64("threads", threads as u64)
        .field_u64("bytes_per_frame", bytes as u64)
        .field_f64("floor_ms", f)
        .field_f64("floor_min_ms", min(&floor))
        .field_f64("floor_gb_per_s", bytes as f64 / (f / 1e3) / 1e9)
        .field_f64("frame_ms", frame_ms)
        .field_f64("raster_ms", raster_ms)
        .field_f64("draw_only_ms", draw_ms)
        .field_f64("frame_over_floor", frame_ms / f)
        .field_f64("raster_over_floor", raster_ms / f)
        .field_f64("draw_only_over_floor", draw_ms / f)
        .field_str(
            "method",
            "floor: fill every colour and depth value once, over the same strips and \
             threads; frame: setup + clear + draw (the headline run); raster: clear + draw; \
             draw_only: the draw with the buffers cleared outside the clock.",
        );
    Ok(o)
}

/// euc and embedded-graphics against microraster, one thread.
fn peers_section<const S: u32, C: BenchColor>(
    bs: &mut BenchScene,
    s: &Settings,
    mr: &Run,
) -> Result<JsonObject, String> {
    let mut o = JsonObject::new();
    let mr_sum = Summary::of(&mr.total);
    let mut mr_json = mr_sum.json();
    mr_json.field_u64("covered_pixels", mr.covered);
    o.field_u64("threads", 1).field_obj("microraster", &mr_json);

    // euc: same scene, same frames.
    if bs.scene.objects.is_empty() {
        o.field_str("euc", "skipped: the scene has no meshes");
    } else if s.cull == CullMode::Front {
        o.field_str("euc", "skipped: euc cannot cull front faces");
    } else {
        let mut e = EucScene::<C::Packed>::new(&bs.scene, s.width, s.height, s.cull)?;
        let mut times = Vec::new();
        for k in 0..s.warmup + s.frames {
            bs.set_frame(k);
            let t = Instant::now();
            e.draw(&bs.scene);
            if k >= s.warmup {
                times.push(ms(t));
            }
        }
        let sum = Summary::of(&times);
        let mut ej = sum.json();
        ej.field_str("version", peers::EUC_VERSION)
            .field_str("depth", "f32")
            .field_u64("covered_pixels", e.covered());
        o.field_obj("euc", &ej)
            .field_f64("euc_over_microraster", sum.median / mr_sum.median)
            .field_f64("euc_over_microraster_min", sum.min / mr_sum.min);
    }

    // embedded-graphics: the same 2D triangles, flat, no depth, RGB565.
    bs.set_frame(0);
    let tris = peers::project_2d(&bs.scene, s.width, s.height, s.cull);
    let mut fb = Framebuffer::new(s.width, s.height);
    let eg = time_frames(s.warmup, s.frames, |_| {
        use embedded_graphics::prelude::DrawTarget;
        let _ = fb.clear(Rgb565::BLACK);
        let _ = peers::draw_eg(&mut fb, &tris);
        Ok(())
    })?;
    let flat = peers::tris_2d_scene(&tris, s.width, s.height);
    let mut config = Config::new(s.width, s.height);
    config.cull = CullMode::None;
    let len = s.width as usize * s.height as usize;
    let mut color = vec![Rgb565::BLACK; len];
    let mut pipe = FramePipeline::<S>::new(config, 1, s.strip_rows);
    let ours = time_frames(s.warmup, s.frames, |_| {
        pipe.render::<Rgb565, u32>(&flat, &mut color, None, Rgb565::BLACK)?;
        Ok(())
    })?;
    let (eg_sum, ours_sum) = (Summary::of(&eg), Summary::of(&ours));
    let mut g = JsonObject::new();
    let mut gm = ours_sum.json();
    gm.field_u64(
        "covered_pixels",
        color.iter().filter(|&&c| c != Rgb565::BLACK).count() as u64,
    );
    let mut ge = eg_sum.json();
    ge.field_u64("covered_pixels", fb.covered());
    g.field_u64("triangles", tris.len() as u64)
        .field_obj("microraster", &gm)
        .field_obj("embedded_graphics", &ge)
        .field_f64("eg_over_microraster", eg_sum.median / ours_sum.median)
        .field_str(
            "method",
            "the scene's visible triangles (frame 0) projected and rounded to pixel centres \
             outside the clock; flat colour, RGB565, no depth, no culling; both clear a \
             whole-frame buffer and draw every triangle each frame (microraster: setup, \
             binning and drawing of the same triangles as clip-space input).",
        );
    o.field_obj("embedded_graphics_2d", &g);
    Ok(o)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cli::{Cli, Command};
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

    #[test]
    fn median_and_summary() {
        assert_eq!(median(&[3.0, 1.0, 2.0]), 2.0);
        assert_eq!(median(&[4.0, 1.0, 2.0, 3.0]), 2.5);
        assert!(median(&[]).is_nan());
        let s = Summary::of(&[1.0, 2.0, 6.0]);
        assert_eq!((s.median, s.min, s.mean, s.max), (2.0, 1.0, 3.0, 6.0));
    }

    fn quick(a: &[&str], name: Option<&str>) -> Report {
        let a = args(a);
        let s = settings(&a, name);
        let mut bs = load(&a, &s).unwrap();
        bench(&mut bs, &s).unwrap()
    }

    #[test]
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
                depth: if scene == "sphere" {
                    DepthKind::U16
                } else {
                    DepthKind::U32
                },
                subpixel: 8,
                threads: 1,
                strip_rows: 16,
                ids: false,
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
