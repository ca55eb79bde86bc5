//! Command-line definitions for the `microraster` binary (clap derive).
//!
//! Design: every option is validated while parsing (value parsers below), so
//! the renderer receives only well-formed settings and the user gets clap's
//! usual error message and exit status for bad input: sizes within
//! 1..=16384, a positive thread and strip count, a field of view strictly
//! between 0° and 180°, finite camera vectors, an output path whose extension
//! names a supported format. `--obj`, `--clip-tris` and an explicit `--scene`
//! are mutually exclusive; [`RenderArgs::source`] says which one to use.
//! Vectors are written `X,Y,Z`; negative values work both as `--eye -1,2,3`
//! and `--eye=-1,2,3`, and `--fov -5` reaches the range check instead of
//! being taken for an option.
//!
//! Every subcommand's options are defined here ([`RenderArgs`],
//! [`BenchArgs`], [`ReportArgs`]), so data flows one way: this module
//! parses, and the command modules (`render_cmd`, `bench`, `report`) take
//! what it made; it imports none of them. Checks that need the scene (a
//! camera for a scene without one, eye equal to target) are the command's.

use std::path::PathBuf;

use clap::builder::PossibleValuesParser;
use clap::{Args, Parser, Subcommand, ValueEnum};

use crate::image_out::{image_format, MAX_DIMENSION};

/// Names accepted by `--scene`.
/// (`crate::bench_scenes` builds them; see there for what each one is.)
pub const SCENES: [&str; 7] = [
    "cubes",
    "sphere",
    "bunny",
    "bunny-subdiv",
    "quad",
    "spots",
    "house",
];

/// The scenes of `report speed-vs-error`, in order.
pub const REPORT_SCENES: [&str; 5] = ["cubes", "spot", "teapot", "bunny", "layers"];

/// Largest `--threads` value accepted.
pub const MAX_THREADS: usize = 1024;

/// An exact fixed-point triangle rasterizer, desktop front end.
#[derive(Parser, Debug, Clone)]
#[command(name = "microraster", version, about, long_about = None)]
pub struct Cli {
    /// What to do.
    #[command(subcommand)]
    pub command: Command,
}

/// Subcommands of `microraster`.
#[derive(Subcommand, Debug, Clone)]
pub enum Command {
    /// Render a built-in scene, an OBJ mesh or clip-space triangles to an image.
    #[command(after_help = RENDER_SOURCES_HELP)]
    Render(RenderArgs),
    /// Render a scene repeatedly and print timings as JSON (see `bench --help`).
    #[command(after_help = BENCH_PROGRESS_HELP)]
    Bench(BenchArgs),
    /// Write reports, e.g. `report speed-vs-error OUT_DIR` (needs the
    /// `report` feature).
    Report(ReportArgs),
    /// Bake an OBJ model into Rust source for firmware (`include!`).
    #[command(after_help = BAKE_HELP)]
    Bake(BakeArgs),
    /// Measure cluster culling (culling volumes, normal cones, flat and as a
    /// tree) against per-triangle culling on meshes from many cameras.
    Cull(CullArgs),
    /// Bake the generated house of `cull --portals` (rooms, cells,
    /// portals, a camera) into Rust source for the firmware (`include!`).
    BakeHouse(BakeHouseArgs),
}

/// The end of `render --help`: which options each source uses.
pub const RENDER_SOURCES_HELP: &str = "\
Which options each source uses:
  --scene cubes         --eye, --target, --fov (default: eye 0,3.75,6.5, target 0,0,0, 60°)
  --scene sphere        --eye, --target, --fov (default: eye at the origin looking down -z, 45°)
  --scene bunny, --scene bunny-subdiv
                        --eye, --target, --fov (default: framed to fit, 60°)
  --obj FILE            --eye, --target, --fov (default: framed to fit from +z, 60°), and
                        --shading, --light, --texture, --no-texture, --texture-filter (default: lit
                        per pixel by a key light, the .mtl colours and texture)
  --scene spots         --eye, --target, --fov (default: eye height outside the 10x10 grid, 60°);
                        objects front to back for that camera
  --scene quad          no camera: clip-space triangles; --eye, --target, --fov are refused
  --clip-tris FILE      no camera: clip-space triangles; --eye, --target, --fov are refused
Every source uses --size, --threads, --strip-rows, --cull, --depth, --subpixel and the
outputs (--out [default: named after the scene or model], --id-out, --depth-out, --stats,
--checksum). A camera looking straight
up or down gets -z or +z as its up vector. A render that draws no pixel, or drops
triangles, says so on stderr with the core's counters.";

/// The end of `bench --help`: progress output.
pub const BENCH_PROGRESS_HELP: &str = "\
Progress: runs that take over a few seconds report progress on stderr, on one
updating line on a terminal and as plain lines otherwise (every
MICRORASTER_PROGRESS_MS milliseconds, default 2000). The JSON on stdout is unchanged.";

/// `--cull-clusters`: the cluster test.
#[derive(ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum ClusterCullArg {
    /// Culling volumes at the leaves.
    Volumes,
    /// Culling volumes, the tree top-down.
    VolumesTree,
    /// Normal cones at the leaves.
    Cones,
    /// Normal cones, the tree top-down.
    ConesTree,
}

impl ClusterCullArg {
    /// As the core's setting.
    pub fn cull(self) -> microraster::ClusterCull {
        use microraster::ClusterTest::{Cones, Volumes};
        let (test, hierarchy) = match self {
            ClusterCullArg::Volumes => (Volumes, false),
            ClusterCullArg::VolumesTree => (Volumes, true),
            ClusterCullArg::Cones => (Cones, false),
            ClusterCullArg::ConesTree => (Cones, true),
        };
        microraster::ClusterCull { test, hierarchy }
    }
}

/// How triangles become pixels (the core's `RasterMode`).
#[derive(ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum ModeArg {
    /// Clip in homogeneous space, divide by w, snap, rasterize (the default).
    Clipping,
    /// No clipping, no division: 2D-homogeneous edge functions of quantized
    /// vertices (Olano and Greer); strips set every triangle up again.
    Clipless,
}

/// What the depth buffer holds.
#[derive(ValueEnum, Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum DepthKindArg {
    /// Window depth z (the default): 0 at the near plane, 1 at the far.
    #[default]
    Z,
    /// 1/w: near / w, reversed (1 at the near plane, towards 0 far away;
    /// depth test greater, cleared to 0), no far plane.
    InvW,
}

/// Which triangles face away and are skipped.
#[derive(ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum CullArg {
    /// Skip back-facing triangles.
    Back,
    /// Skip front-facing triangles.
    Front,
    /// Draw every triangle.
    None,
}

/// Depth buffer format.
#[derive(ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum DepthArg {
    /// 16-bit depth buffer.
    U16,
    /// 32-bit depth buffer.
    U32,
    /// `f32` depth buffer (`DepthF32`: 24 significant bits, finer than
    /// `u32` near 0, where 1/w depth puts distant surfaces).
    F32,
    /// No depth buffer (painter's order).
    None,
}

/// Lighting of an OBJ model (`render --shading`).
#[derive(ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum ShadingArg {
    /// One lit colour per triangle (face normals).
    Flat,
    /// Lit per vertex (the file's or smooth normals), interpolated.
    Gouraud,
    /// Lit per pixel from interpolated normals, with a highlight.
    Phong,
}

/// Texture filtering (`render --texture-filter`).
#[derive(ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum FilterArg {
    /// The nearest texel.
    Nearest,
    /// The four nearest texels, weighted.
    Bilinear,
}

/// Where the triangles to render come from.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Source {
    /// A built-in scene by name (one of [`SCENES`]).
    Scene(String),
    /// A Wavefront OBJ file.
    Obj(PathBuf),
    /// A `--clip-tris` text file.
    ClipTris(PathBuf),
}

/// Options of `microraster render`.
#[derive(Args, Debug, Clone, PartialEq)]
pub struct RenderArgs {
    /// Built-in scene to render.
    #[arg(
        long,
        value_name = "NAME",
        default_value = "cubes",
        value_parser = PossibleValuesParser::new(SCENES),
        conflicts_with_all = ["obj", "clip_tris"]
    )]
    pub scene: String,

    /// Render this Wavefront OBJ mesh instead of a scene.
    #[arg(long, value_name = "FILE")]
    pub obj: Option<PathBuf>,

    /// Render clip-space triangles from this text file (12 numbers per line,
    /// optional r g b).
    #[arg(long, value_name = "FILE", conflicts_with = "obj")]
    pub clip_tris: Option<PathBuf>,

    /// Camera position (default: the scene's, or framed to fit the OBJ).
    #[arg(long, value_name = "X,Y,Z", value_parser = parse_vec3, allow_hyphen_values = true)]
    pub eye: Option<[f32; 3]>,

    /// Point the camera looks at (default: the scene's, or the OBJ's centre).
    #[arg(long, value_name = "X,Y,Z", value_parser = parse_vec3, allow_hyphen_values = true)]
    pub target: Option<[f32; 3]>,

    /// Vertical field of view in degrees [default: 45 for sphere, else 60].
    #[arg(long, value_name = "DEG", value_parser = parse_fov, allow_hyphen_values = true)]
    pub fov: Option<f32>,

    /// Image size in pixels [default: the scene's, as `bench` takes it
    /// (cubes 800x600, sphere 240x320, spots and house 320x240, the
    /// others 1920x1080); 800x600 for --obj and --clip-tris].
    #[arg(long, value_name = "WxH", value_parser = parse_size)]
    pub size: Option<(u32, u32)>,

    /// Worker threads.
    #[arg(long, value_name = "N", default_value_t = default_threads(), value_parser = parse_threads)]
    pub threads: usize,

    /// Rows per strip.
    #[arg(long, value_name = "R", default_value = "16", value_parser = parse_strip_rows)]
    pub strip_rows: u32,

    /// Draw tiles of WxH pixels (each binned and handed to a thread on its
    /// own) instead of strips of --strip-rows rows; the image is the same.
    #[arg(long, value_name = "WxH", value_parser = parse_size, conflicts_with = "strip_rows")]
    pub tile: Option<(u32, u32)>,

    /// Face culling.
    #[arg(long, value_enum, default_value_t = CullArg::Back)]
    pub cull: CullArg,

    /// Cull back-facing clusters before transform (meshoptimizer meshlets
    /// of 12 triangles; see docs/culling.md): culling volumes or normal
    /// cones, at the leaves or down the tree.
    #[arg(long, value_enum, value_name = "TEST")]
    pub cull_clusters: Option<ClusterCullArg>,

    /// Skip back-facing triangles before transform by normal masks: their
    /// normals in 6·N² classes (N partitions a side, 1 to 16), a frame's
    /// back classes one bit each (see docs/culling.md).
    #[arg(long, value_name = "N", conflicts_with = "cull_clusters",
          value_parser = clap::value_parser!(u8).range(1..=16))]
    pub normal_masks: Option<u8>,

    /// Occlusion culling (see docs/culling.md): strips drawn at once, each
    /// object tested against the strip's max depth per 8x8 tile before its
    /// vertices are transformed. The image is the same; objects drawn
    /// front to back hide the most (the spots scene is). Needs a depth
    /// buffer and --mode clipping.
    #[arg(long)]
    pub occlusion: bool,

    /// Portal culling (see docs/culling.md), for --scene house: only the
    /// rooms the eye can see through chains of doors are submitted. The
    /// image is the same.
    #[arg(long)]
    pub portals: bool,

    /// Detail culling (lossy; 0: off): drop objects, and with
    /// --cull-clusters clusters, whose projection is provably less than PX
    /// pixels across, before transform.
    #[arg(long, value_name = "PX", default_value_t = 0)]
    pub cull_detail: u16,

    /// With --cull-detail: draw what it drops as boxes in each object's
    /// mean colour instead of leaving holes (lossy too).
    #[arg(long, requires = "cull_detail")]
    pub cull_detail_boxes: bool,

    /// Depth buffer format.
    #[arg(long, value_enum, default_value_t = DepthArg::U32)]
    pub depth: DepthArg,

    /// Sub-pixel precision in bits (4 or 8).
    #[arg(long, value_name = "BITS", default_value = "8", value_parser = parse_subpixel)]
    pub subpixel: u32,

    /// Rasterization mode (clipless: not with --obj).
    #[arg(long, value_enum, default_value_t = ModeArg::Clipping)]
    pub mode: ModeArg,

    /// What the depth buffer holds (inv-w: the built-in scenes and --obj
    /// only; not with --clip-tris, whose z is the file's).
    #[arg(long, value_enum, default_value_t = DepthKindArg::Z)]
    pub depth_kind: DepthKindArg,

    /// Output image (.png or .ppm) [default: named after the scene, or the
    /// OBJ file's stem, e.g. spot.png].
    #[arg(long, value_name = "FILE", value_parser = parse_image_path)]
    pub out: Option<PathBuf>,

    /// How an OBJ model is lit: per triangle, per vertex, or per pixel
    /// with a highlight.
    #[arg(long, value_enum, default_value_t = ShadingArg::Phong)]
    pub shading: ShadingArg,

    /// Direction towards the key light in camera space (x right, y up, z
    /// towards the viewer) [default: -0.4,0.6,1, above left of the viewer].
    #[arg(long, value_name = "X,Y,Z", value_parser = parse_vec3, allow_hyphen_values = true)]
    pub light: Option<[f32; 3]>,

    /// Draw an OBJ model without its texture.
    #[arg(long, conflicts_with = "texture")]
    pub no_texture: bool,

    /// Texture an OBJ model with this PNG instead of its materials' (a model
    /// with UVs and no texture named also finds `STEM.png` or
    /// `STEM_texture.png` beside it).
    #[arg(long, value_name = "FILE")]
    pub texture: Option<PathBuf>,

    /// Texture filtering for an OBJ model.
    #[arg(long, value_enum, default_value_t = FilterArg::Bilinear)]
    pub texture_filter: FilterArg,

    /// Also write the triangle-id image (RGBA PNG).
    #[arg(long, value_name = "FILE", value_parser = parse_png_path)]
    pub id_out: Option<PathBuf>,

    /// Also write the raw depth buffer.
    #[arg(long, value_name = "FILE")]
    pub depth_out: Option<PathBuf>,

    /// Print statistics as JSON.
    #[arg(long)]
    pub stats: bool,

    /// Print a checksum of the image.
    #[arg(long)]
    pub checksum: bool,
}

impl RenderArgs {
    /// Where the triangles come from: `--clip-tris`, else `--obj`, else the scene.
    pub fn source(&self) -> Source {
        if let Some(p) = &self.clip_tris {
            Source::ClipTris(p.clone())
        } else if let Some(p) = &self.obj {
            Source::Obj(p.clone())
        } else {
            Source::Scene(self.scene.clone())
        }
    }

    /// The output image: `--out`, else named after the source
    /// (`cubes.png`, `spot.png` for `--obj models/spot.obj`,
    /// `clip-tris.png`).
    pub fn out_path(&self) -> PathBuf {
        if let Some(p) = &self.out {
            return p.clone();
        }
        let name = match self.source() {
            Source::Scene(s) => s,
            Source::Obj(p) => p
                .file_stem()
                .map(|s| s.to_string_lossy().into_owned())
                .filter(|s| !s.is_empty())
                .unwrap_or_else(|| "model".to_string()),
            Source::ClipTris(_) => "clip-tris".to_string(),
        };
        PathBuf::from(format!("{name}.png"))
    }

    /// Whether any OBJ-only shading option differs from its default.
    pub fn has_shading_options(&self) -> bool {
        self.shading != ShadingArg::Phong
            || self.light.is_some()
            || self.no_texture
            || self.texture.is_some()
            || self.texture_filter != FilterArg::Bilinear
    }

    /// Image width in pixels.
    pub fn width(&self) -> u32 {
        self.image_size().0
    }

    /// Image height in pixels.
    pub fn height(&self) -> u32 {
        self.image_size().1
    }

    /// Width / height.
    pub fn aspect(&self) -> f32 {
        let (w, h) = self.image_size();
        w as f32 / h as f32
    }

    /// `--size`, or the scene's default size (800x600 for a file).
    pub fn image_size(&self) -> (u32, u32) {
        match (self.size, self.obj.is_some() || self.clip_tris.is_some()) {
            (Some(size), _) => size,
            (None, true) => (800, 600),
            (None, false) => crate::bench_scenes::default_size(&self.scene),
        }
    }
}

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
/// 1..=[`MAX_THREADS`].
pub fn parse_thread_list(s: &str) -> Result<ThreadList, String> {
    let list = s
        .split(',')
        .map(parse_threads)
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
    /// quad (two triangles, 1920x1080, with the memory floor), spots (a
    /// 10x10 grid of Spot, 585,600 triangles, 320x240).
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
    #[arg(long, value_name = "DEG", value_parser = parse_fov, allow_hyphen_values = true)]
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

    /// Time the thread counts of a scaling run one after another, each
    /// count's frames together, instead of interleaved frame by frame (the
    /// default, so that a change in the machine's load meets every count).
    #[arg(long)]
    pub sequential: bool,

    /// Rows per strip.
    #[arg(long, value_name = "R", default_value = "16", value_parser = parse_strip_rows)]
    pub strip_rows: u32,

    /// Draw tiles of WxH pixels (each binned and handed to a thread on its
    /// own) instead of strips of --strip-rows rows; the image is the same.
    #[arg(long, value_name = "WxH", value_parser = parse_size, conflicts_with = "strip_rows")]
    pub tile: Option<(u32, u32)>,

    /// Face culling.
    #[arg(long, value_enum, default_value_t = CullArg::Back)]
    pub cull: CullArg,

    /// Cull back-facing clusters before transform (meshoptimizer meshlets
    /// of 12 triangles; see docs/culling.md): culling volumes or normal
    /// cones, at the leaves or down the tree.
    #[arg(long, value_enum, value_name = "TEST")]
    pub cull_clusters: Option<ClusterCullArg>,

    /// Skip back-facing triangles before transform by normal masks: their
    /// normals in 6·N² classes (N partitions a side, 1 to 16), a frame's
    /// back classes one bit each (see docs/culling.md).
    #[arg(long, value_name = "N", conflicts_with = "cull_clusters",
          value_parser = clap::value_parser!(u8).range(1..=16))]
    pub normal_masks: Option<u8>,

    /// Detail culling (lossy; 0: off): drop objects, and with
    /// --cull-clusters clusters, whose projection is provably less than PX
    /// pixels across, before transform.
    #[arg(long, value_name = "PX", default_value_t = 0)]
    pub cull_detail: u16,

    /// With --cull-detail: draw what it drops as boxes in each object's
    /// mean colour instead of leaving holes (lossy too).
    #[arg(long, requires = "cull_detail")]
    pub cull_detail_boxes: bool,

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
    /// thread, and print the ratios (needs the `peers` feature).
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

    /// Occlusion culling (see docs/culling.md): also time `render::render`
    /// drawing strips at once with every object tested against its strip's
    /// hi-z before transform, interleaved frame by frame with the same
    /// strips without the test (implies --render-fn); the JSON's
    /// `render_fn.occlusion` gives both medians, the ratio, the triangles
    /// culled and whether the images match the plain one.
    #[arg(long)]
    pub occlusion: bool,

    /// Write the last frame of the first run to this image (.png or .ppm).
    #[arg(long, value_name = "FILE", value_parser = parse_image_path)]
    pub out: Option<PathBuf>,
}

/// Options of `microraster report` (needs the `report` feature).
#[derive(Args, Debug, Clone, PartialEq)]
pub struct ReportArgs {
    /// Which report: `speed-vs-error`.
    #[arg(value_parser = clap::builder::PossibleValuesParser::new(["speed-vs-error"]))]
    pub which: String,

    /// Folder for the report's files (created if missing).
    #[arg(value_name = "OUT_DIR")]
    pub out_dir: PathBuf,

    /// A quick run for CI: 160x120, 3 repetitions.
    #[arg(long)]
    pub quick: bool,

    /// Image size (default 800x600, or 160x120 with --quick).
    #[arg(long, value_name = "WxH", value_parser = parse_size)]
    pub size: Option<(u32, u32)>,

    /// Timed frames per configuration and scene; the median is reported
    /// (default 7, or 3 with --quick).
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u32).range(1..=1000))]
    pub reps: Option<u32>,

    /// Scenes to run, comma-separated (default: all of cubes, spot, teapot,
    /// bunny, layers: pairs of close parallel surfaces, for depth-test
    /// flips).
    #[arg(long, value_name = "LIST", value_delimiter = ',',
          value_parser = clap::builder::PossibleValuesParser::new(REPORT_SCENES))]
    pub scenes: Option<Vec<String>>,

    /// Folder holding spot.obj, teapot.obj and stanford-bunny.obj (default:
    /// the repository's assets/models).
    #[arg(long, value_name = "DIR")]
    pub models: Option<PathBuf>,

    /// Do not show the progress bar.
    #[arg(long)]
    pub no_progress: bool,
}

/// The scenes of the report, in order.
pub const SCENE_NAMES: [&str; 4] = ["cubes", "spot", "teapot", "bunny"];

/// Default for `--threads`: the machine's available parallelism, else 1.
pub fn default_threads() -> usize {
    std::thread::available_parallelism()
        .map(|n| n.get())
        .unwrap_or(1)
        .min(MAX_THREADS)
}

/// Parses `X,Y,Z` (three finite numbers, spaces around them allowed).
pub fn parse_vec3(s: &str) -> Result<[f32; 3], String> {
    let parts: Vec<&str> = s.split(',').map(str::trim).collect();
    if parts.len() != 3 {
        return Err(format!(
            "expected three comma-separated numbers X,Y,Z, got {s:?}"
        ));
    }
    let mut v = [0.0f32; 3];
    for (dst, part) in v.iter_mut().zip(&parts) {
        let x: f32 = part
            .parse()
            .map_err(|_| format!("cannot parse {part:?} as a number in {s:?}"))?;
        if !x.is_finite() {
            return Err(format!("{part:?} in {s:?} is not a finite number"));
        }
        *dst = x;
    }
    Ok(v)
}

/// Parses `WxH` (also `WXH`); each side must be in 1..=16384.
pub fn parse_size(s: &str) -> Result<(u32, u32), String> {
    let (w, h) = s
        .split_once(['x', 'X'])
        .ok_or_else(|| format!("expected WIDTHxHEIGHT such as 800x600, got {s:?}"))?;
    let side = |t: &str, name: &str| -> Result<u32, String> {
        let n: u64 = t
            .trim()
            .parse()
            .map_err(|_| format!("{name} {t:?} in {s:?} is not a whole number"))?;
        if n == 0 || n > u64::from(MAX_DIMENSION) {
            return Err(format!("{name} {n} must be in 1..={MAX_DIMENSION}"));
        }
        Ok(n as u32)
    };
    Ok((side(w, "width")?, side(h, "height")?))
}

/// Parses the vertical field of view in degrees: finite, strictly between 0 and 180.
pub fn parse_fov(s: &str) -> Result<f32, String> {
    let f: f32 = s
        .trim()
        .parse()
        .map_err(|_| format!("cannot parse {s:?} as a number of degrees"))?;
    if !(f.is_finite() && f > 0.0 && f < 180.0) {
        return Err(format!(
            "field of view {s} must be between 0 and 180 degrees (exclusive)"
        ));
    }
    Ok(f)
}

/// Parses a positive integer no larger than `max`.
fn parse_count(s: &str, what: &str, max: u64) -> Result<u64, String> {
    let n: u64 = s
        .trim()
        .parse()
        .map_err(|_| format!("{what} {s:?} is not a whole number"))?;
    if n == 0 || n > max {
        return Err(format!("{what} must be in 1..={max}, got {n}"));
    }
    Ok(n)
}

/// Parses `--threads`: 1..=[`MAX_THREADS`].
pub fn parse_threads(s: &str) -> Result<usize, String> {
    parse_count(s, "thread count", MAX_THREADS as u64).map(|n| n as usize)
}

/// Parses `--strip-rows`: 1..=16384.
pub fn parse_strip_rows(s: &str) -> Result<u32, String> {
    parse_count(s, "strip rows", u64::from(MAX_DIMENSION)).map(|n| n as u32)
}

/// Parses `--subpixel`: 4 or 8.
pub fn parse_subpixel(s: &str) -> Result<u32, String> {
    match s.trim() {
        "4" => Ok(4),
        "8" => Ok(8),
        _ => Err(format!("sub-pixel bits must be 4 or 8, got {s:?}")),
    }
}

/// Parses an output image path: the extension must be `.png` or `.ppm`.
pub fn parse_image_path(s: &str) -> Result<PathBuf, String> {
    let p = PathBuf::from(s);
    image_format(&p)?;
    Ok(p)
}

/// Parses a PNG output path: the extension must be `.png`.
pub fn parse_png_path(s: &str) -> Result<PathBuf, String> {
    let p = PathBuf::from(s);
    match image_format(&p) {
        Ok(crate::image_out::ImageFormat::Png) => Ok(p),
        _ => Err(format!(
            "{s}: the triangle-id image is a PNG; use a .png extension"
        )),
    }
}

/// The end of `bake --help`: what the file holds.
pub const BAKE_HELP: &str = "\
Writes DIR/<model>.rs (the OBJ's stem, lower case, [a-z0-9_]): VERTEX_COUNT,
TRIANGLE_COUNT, MATERIAL_COUNT; POSITIONS: [microraster::Vec3; N] (f32, exact) or
POSITIONS_I16: [[i16; 3]; N] with POSITION_SCALE, POSITION_OFFSET: [f32; 3]
(position = q * scale + offset); INDICES: [[u32; 3]; M]; NORMALS: [Vec3; N] (unit);
UVS: [[f32; 2]; N] if the model has UVs, as (u, 1 - v) of the file's, so v = 0 is
row 0; if it has a texture, TEXTURE_WIDTH, TEXTURE_HEIGHT: u32, TEXTURE: [u16; W*H]
(Rgb565, row 0 = top of the image, box-filtered) and MATERIAL_TEXTURED: [bool; K];
MATERIAL_DIFFUSE, MATERIAL_SPECULAR: [[u8; 3]; K], MATERIAL_SHININESS: [f32; K],
TRIANGLE_MATERIAL: [u8; M]. The MTL and textures are found beside the OBJ; an OBJ
without an MTL (Spot) takes its texture from --texture. Prints the flash bytes of
f32 and i16 positions, the i16 error (max and RMS, relative to the bounding box
diagonal) and the total. Nothing is written if the bake fails.";

/// Position format of `bake`.
#[derive(ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum PositionsArg {
    /// `POSITIONS: [microraster::Vec3; N]`, exact.
    F32,
    /// `POSITIONS_I16: [[i16; 3]; N]`, quantized over the bounding box.
    I16,
}

/// Parses `--texture-size`: a power of two in 1..=1024.
pub fn parse_texture_size(s: &str) -> Result<u32, String> {
    match s.trim().parse::<u32>() {
        Ok(n) if (1..=1024).contains(&n) && n.is_power_of_two() => Ok(n),
        _ => Err(format!(
            "texture size must be a power of two from 1 to 1024, got {s:?}"
        )),
    }
}

fn parse_max_triangles(s: &str) -> Result<u32, String> {
    match s.trim().parse::<u32>() {
        Ok(n) if n >= 1 => Ok(n),
        _ => Err(format!(
            "max triangles must be a whole number from 1, got {s:?}"
        )),
    }
}

/// Options of `microraster bake`.
#[derive(Args, Debug, Clone, PartialEq)]
pub struct BakeArgs {
    /// The Wavefront OBJ model (its MTL files and textures beside it).
    #[arg(value_name = "MODEL.obj")]
    pub model: PathBuf,

    /// Folder for `<model>.rs` (created if missing).
    #[arg(long, value_name = "DIR")]
    pub out: PathBuf,

    /// Texture side in texels after resampling (a power of two, 1..=1024).
    #[arg(long, value_name = "N", default_value = "64", value_parser = parse_texture_size)]
    pub texture_size: u32,

    /// Position format.
    #[arg(long, value_enum, default_value_t = PositionsArg::F32)]
    pub positions: PositionsArg,

    /// Decimate (vertex clustering) to at most N triangles.
    #[arg(long, value_name = "N", value_parser = parse_max_triangles)]
    pub max_triangles: Option<u32>,

    /// Use this PNG as the texture of every material (for an OBJ with UVs
    /// and no MTL, such as Spot).
    #[arg(long, value_name = "PNG")]
    pub texture: Option<PathBuf>,

    /// Also write `<model>_clusters.rs`: the triangles in cluster order
    /// and the cluster set (clusters, tree, vertex list) of cluster
    /// culling, over the same baked vertices (default cluster options).
    #[arg(long)]
    pub clusters: bool,

    /// Also write `<model>_classes.rs`: each triangle's normal class on a
    /// direction cube of N partitions a side (1 to 16) and the classes'
    /// size bounds and spheres, for normal masks (`BackMask`).
    #[arg(long, value_name = "N")]
    pub normal_masks: Option<u8>,
}

/// Options of `microraster bake-house`.
#[derive(Args, Debug, Clone, PartialEq)]
pub struct BakeHouseArgs {
    /// Folder for `house.rs` (created if missing).
    #[arg(long, value_name = "DIR")]
    pub out: PathBuf,

    /// Rooms a side (1 to 8).
    #[arg(long, value_name = "N", default_value_t = crate::portal::FIRMWARE_ROOMS)]
    pub rooms: usize,

    /// The camera (`cull --portals`'s camera K of this house).
    #[arg(long, value_name = "K", default_value_t = crate::portal::FIRMWARE_CAMERA)]
    pub camera: usize,

    /// Frame size the camera's matrix is for.
    #[arg(long, value_name = "WxH", default_value = "320x240", value_parser = parse_size)]
    pub size: (u32, u32),
}

/// The models `cull` measures by default (in the repository).
pub const CULL_MODELS: [&str; 3] = [
    concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../assets/models/stanford-bunny.obj"
    ),
    concat!(env!("CARGO_MANIFEST_DIR"), "/../assets/models/teapot.obj"),
    concat!(env!("CARGO_MANIFEST_DIR"), "/../assets/models/spot.obj"),
];

/// Options of `microraster cull`.
#[derive(Args, Debug, Clone, PartialEq)]
pub struct CullArgs {
    /// OBJ models (default: the bunny, the teapot and Spot).
    #[arg(value_name = "MODEL.obj", default_values = CULL_MODELS)]
    pub models: Vec<PathBuf>,

    /// Camera directions (a Fibonacci sphere).
    #[arg(long, value_name = "N", default_value = "64")]
    pub cameras: usize,

    /// Camera distance from the model's centre, in bounding radii (> 1).
    #[arg(long, value_name = "R", default_value = "2.5")]
    pub distance: f32,

    /// Frame size.
    #[arg(long, value_name = "WxH", default_value = "320x240", value_parser = parse_size)]
    pub size: (u32, u32),

    /// Interleaved timing rounds.
    #[arg(long, value_name = "N", default_value = "5")]
    pub rounds: usize,

    /// Vertices per cluster, at most.
    #[arg(long, value_name = "N", default_value = "64")]
    pub max_vertices: usize,

    /// Triangles per cluster, at most (a multiple of 4).
    #[arg(long, value_name = "N", default_value = "12")]
    pub max_triangles: usize,

    /// meshoptimizer's cone weight (0..1).
    #[arg(long, value_name = "W", default_value = "1.0")]
    pub cone_weight: f32,

    /// The tree's cost of a node test per triangle's cost (negative: no
    /// tree).
    #[arg(
        long,
        value_name = "T",
        default_value = "1.0",
        allow_hyphen_values = true
    )]
    pub t_over_r: f64,

    /// Give every cluster its own copies of its vertices (contiguous
    /// ranges, no vertex list) instead of sharing them.
    #[arg(long)]
    pub copies: bool,

    /// Also measure detail culling at PX pixels (rows "culling volumes,
    /// tree, detail", what it drops left out, and "... boxes for detail",
    /// drawn as boxes in the mesh's colour; lossy: their pixels differing
    /// from the mesh drawn in that one colour are reported; 0: no such
    /// rows).
    #[arg(long, value_name = "PX", default_value_t = 0)]
    pub detail: u16,

    /// Also measure normal masks of these partitions a side (rows "normal
    /// masks, N"; `--normal-masks` with no list, after the models: none).
    #[arg(long, value_name = "N,..", value_delimiter = ',', default_value = "4,8,16",
          num_args = 0..=1, value_parser = clap::value_parser!(u8).range(1..=16))]
    pub normal_masks: Vec<u8>,

    /// Sector heights for the normal masks' sector table: rows per
    /// sector (each strip its own mask; the frame height or more is the
    /// whole frame).
    #[arg(
        long,
        value_name = "ROWS,..",
        value_delimiter = ',',
        default_value = "240,60,16"
    )]
    pub sector_rows: Vec<u32>,

    /// Measure occlusion culling instead, on the spots scene (a grid of
    /// Spots; the models and cluster options are ignored): the table of
    /// docs/culling.md's "Occlusion culling".
    #[arg(long)]
    pub occlusion: bool,

    /// Spots a side of the occlusion scene's grid.
    #[arg(long, value_name = "N", default_value = "10")]
    pub grid: usize,

    /// Measure portal culling instead, on the generated house (rooms and
    /// doors; the models are ignored): the table of docs/culling.md's
    /// "Portal culling".
    #[arg(long, conflicts_with = "occlusion")]
    pub portals: bool,

    /// Rooms a side of the portal scene's house.
    #[arg(long, value_name = "N", default_value = "8")]
    pub rooms: usize,

    /// Strip heights for the occlusion table.
    #[arg(
        long,
        value_name = "ROWS,..",
        value_delimiter = ',',
        default_value = "240,16"
    )]
    pub occlusion_rows: Vec<u32>,

    /// Also write the measurements as JSON.
    #[arg(long, value_name = "FILE")]
    pub json: Option<PathBuf>,
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::CommandFactory;

    fn render(args: &[&str]) -> Result<RenderArgs, clap::Error> {
        let mut argv = vec!["microraster", "render"];
        argv.extend_from_slice(args);
        Cli::try_parse_from(argv).map(|cli| match cli.command {
            Command::Render(r) => r,
            other => panic!("not a render command: {other:?}"),
        })
    }

    #[test]
    fn clap_definition_is_consistent() {
        Cli::command().debug_assert();
    }

    /// `render` draws a scene at its own size unless `--size` says
    /// otherwise (a file at 800x600).
    #[test]
    fn render_size_defaults_to_the_scene() {
        let cases: [(&[&str], (u32, u32)); 6] = [
            (&["--scene", "house"], (320, 240)),
            (&["--scene", "spots"], (320, 240)),
            (&["--scene", "sphere"], (240, 320)),
            (&["--scene", "cubes"], (800, 600)),
            (&["--obj", "m.obj"], (800, 600)),
            (&["--scene", "house", "--size", "64x48"], (64, 48)),
        ];
        for (args, size) in cases {
            let r = render(args).unwrap();
            assert_eq!((r.width(), r.height()), size, "{args:?}");
        }
    }

    #[test]
    fn defaults() {
        let r = render(&[]).unwrap();
        assert_eq!(r.scene, "cubes");
        assert_eq!(r.source(), Source::Scene("cubes".into()));
        assert_eq!(r.obj, None);
        assert_eq!(r.clip_tris, None);
        assert_eq!(r.eye, None);
        assert_eq!(r.target, None);
        assert_eq!(r.fov, None);
        assert_eq!(r.size, None);
        assert_eq!((r.width(), r.height()), (800, 600));
        assert!((r.aspect() - 4.0 / 3.0).abs() < 1e-6);
        assert_eq!(r.threads, default_threads());
        assert!(r.threads >= 1);
        assert_eq!(r.strip_rows, 16);
        assert_eq!(r.cull, CullArg::Back);
        assert_eq!(r.depth, DepthArg::U32);
        assert_eq!(r.subpixel, 8);
        assert_eq!(r.out_path(), PathBuf::from("cubes.png"));
        assert_eq!(r.id_out, None);
        assert_eq!(r.depth_out, None);
        assert!(!r.stats && !r.checksum);
    }

    #[test]
    fn all_options() {
        let r = render(&[
            "--obj",
            "m.obj",
            "--eye",
            "-1,2.5,3",
            "--target=0, 0 ,-1e1",
            "--fov",
            "45.5",
            "--size",
            "640X480",
            "--threads",
            "3",
            "--strip-rows",
            "1",
            "--cull",
            "none",
            "--depth",
            "u16",
            "--subpixel",
            "4",
            "--out",
            "x.PPM",
            "--id-out",
            "ids.png",
            "--depth-out",
            "d.raw",
            "--stats",
            "--checksum",
        ])
        .unwrap();
        assert_eq!(r.source(), Source::Obj("m.obj".into()));
        assert_eq!(r.eye, Some([-1.0, 2.5, 3.0]));
        assert_eq!(r.target, Some([0.0, 0.0, -10.0]));
        assert_eq!(r.fov, Some(45.5));
        assert_eq!(r.size, Some((640, 480)));
        assert_eq!(r.threads, 3);
        assert_eq!(r.strip_rows, 1);
        assert_eq!(r.cull, CullArg::None);
        assert_eq!(r.depth, DepthArg::U16);
        assert_eq!(r.subpixel, 4);
        assert_eq!(r.out_path(), PathBuf::from("x.PPM"));
        assert_eq!(r.id_out, Some("ids.png".into()));
        assert_eq!(r.depth_out, Some("d.raw".into()));
        assert!(r.stats && r.checksum);

        let r = render(&["--clip-tris", "t.txt", "--cull", "front", "--depth", "none"]).unwrap();
        assert_eq!(r.source(), Source::ClipTris("t.txt".into()));
        assert_eq!(r.cull, CullArg::Front);
        assert_eq!(r.depth, DepthArg::None);
        let r = render(&["--scene", "cubes", "--eye=-1,-2,-3"]).unwrap();
        assert_eq!(r.eye, Some([-1.0, -2.0, -3.0]));
    }

    #[test]
    fn bad_options_are_rejected() {
        let bad: &[&[&str]] = &[
            &["--obj", "a.obj", "--clip-tris", "b.txt"],
            &["--scene", "cubes", "--obj", "a.obj"],
            &["--scene", "teapot"],
            &["--size", "0x600"],
            &["--size", "800x0"],
            &["--size", "16385x1"],
            &["--size", "800"],
            &["--size", "800x600x2"],
            &["--size", "-800x600"],
            &["--threads", "0"],
            &["--threads", "-1"],
            &["--threads", "many"],
            &["--strip-rows", "0"],
            &["--cull", "sideways"],
            &["--depth", "f64"],
            &["--subpixel", "6"],
            &["--fov", "0"],
            &["--fov", "180"],
            &["--fov", "nan"],
            &["--eye", "1,2"],
            &["--eye", "1,2,nan"],
            &["--target", "a,b,c"],
            &["--out", "image.jpg"],
            &["--out", "noext"],
            &["--id-out", "ids.ppm"],
            &["--bogus"],
        ];
        for args in bad {
            assert!(render(args).is_err(), "accepted {args:?}");
        }
        assert!(Cli::try_parse_from(["microraster"]).is_err());
        assert!(Cli::try_parse_from(["microraster", "paint"]).is_err());
    }

    #[test]
    fn value_parsers() {
        assert_eq!(parse_vec3("1,2,3"), Ok([1.0, 2.0, 3.0]));
        assert_eq!(parse_vec3(" -1 , 0.5,1e2 "), Ok([-1.0, 0.5, 100.0]));
        assert!(parse_vec3("1,2,3,4").is_err());
        assert!(parse_vec3("").is_err());
        assert!(parse_vec3("1,,3").is_err());
        assert!(parse_vec3("inf,0,0").is_err());
        assert_eq!(parse_size("1x1"), Ok((1, 1)));
        assert_eq!(parse_size("16384x16384"), Ok((16384, 16384)));
        assert!(parse_size("99999999999999999999x1").is_err());
        assert!(parse_size("x").is_err());
        assert!(parse_size("1.5x2").is_err());
        let e = parse_size("0x5").unwrap_err();
        assert!(e.contains("width") && e.contains("16384"), "{e}");
        assert_eq!(parse_threads(&MAX_THREADS.to_string()), Ok(MAX_THREADS));
        assert!(parse_threads(&(MAX_THREADS + 1).to_string()).is_err());
        assert_eq!(parse_strip_rows("16"), Ok(16));
        assert_eq!(parse_subpixel("8"), Ok(8));
        assert!(parse_subpixel("16").is_err());
        assert_eq!(parse_fov("179.9"), Ok(179.9));
        assert!(parse_fov("-10").is_err());
        assert!(parse_image_path("a.png").is_ok());
        assert!(parse_image_path("a.gif").is_err());
        assert!(parse_png_path("a.PNG").is_ok());
        assert!(parse_png_path("a.ppm").is_err());
    }
}
