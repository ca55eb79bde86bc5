//! `microraster report speed-vs-error OUT_DIR`: what each configuration
//! costs in time and in accuracy.
//!
//! Design note: the report sweeps the eight compile-time configurations of
//! the core (subpixel bits 4 / 8, depth `u16` / `u32`, matrices built with
//! `libm` / `micromath`), and on `S8 libm` the run-time choices of issue
//! 12 ([`Variant`]: immediate mode, the clipless mode, 1/w depth in
//! `u16`, `u32` and `f32`, tiles of 16, 32 and 64 pixels; the 1/w
//! configurations are measured against a reference drawn with the same
//! projection and depth test), over five scenes: the four cubes, Spot, the
//! teapot and the Stanford bunny from `assets/models/`, every one with
//! per-vertex colours from its normals so that Gouraud interpolation is
//! exercised, and `layers` ([`layers_spec`]), pairs of parallel surfaces
//! 10^-3, 10^-5 and 10^-7 of their distance apart at distances 0.5 to 32,
//! where the depth buffer's resolution shows as depth-test flips.
//!
//! For each configuration and scene it measures
//! - the frame time: median of repeated single-threaded frames, each one
//!   building the matrices with the configuration's float backend, setting
//!   up every triangle into a [`Frame`] and rendering all rows into an
//!   `Rgb888` buffer and a depth buffer (buffers allocated beforehand);
//! - the error against [`reference`](mod@reference), which renders the same scene
//!   from `f64` vertices and `f64` matrices with no snapping:
//!   pixels whose triangle id differs, those among them where only coverage
//!   differs (background in one, a triangle in the other), the depth error
//!   in LSB of the buffer at pixels drawn by the same triangle in both
//!   (against `floor(z * 2^bits)` of the exact depth), and the colour error
//!   per channel (against the exact colour rounded to nearest);
//! - the error the `f32` vertex stage brings in before snapping: the largest
//!   matrix-entry error (relative to the matrix's largest entry) and the
//!   largest window-space vertex error (pixels, and window depth), both
//!   against `f64`. For `micromath` this is what its approximations cost.
//!
//! Every difference is also checked against what snapping and the measured
//! vertex error explain: a pixel whose triangle differs must lie within the
//! snapping tolerance (half a subpixel per axis plus the vertex error) of an
//! edge of one of the two triangles, or be a depth tie within the depth
//! tolerance; a depth or colour error must be within the error that moving
//! the vertices by that tolerance causes, plus the documented 1 LSB of
//! interpolation and 1 LSB of rounding. Whatever is left is counted as
//! "unexplained" and would be a bug in the core.
//!
//! The speed axis of record is not the host's time but the firmware's:
//! the instructions the four-cubes frame takes on the Cortex-M4F and the
//! Cortex-M0 under QEMU (`-icount shift=0`, deterministic) in the same
//! configuration, from `docs/embedded.md`'s configuration table, which
//! `.ci/firmware.sh` measures and holds every run to ([`firmware`]). The
//! host time stays as a second axis, with its spread (the fastest and the
//! slowest of the repetitions).
//!
//! Stars: a configuration is starred (on the Pareto front of speed
//! against pixels differing) only where its lead is larger than the
//! noise: it must be faster, by more than the noise, than every
//! configuration at least as accurate ([`significant_front`]). For
//! instruction counts the noise is taken as 1 % ([`firmware::COUNT_NOISE`],
//! well over the SysTick granularity); for host time the ranges (min to
//! max over the repetitions) must not overlap. The errors are
//! deterministic, so any lead in accuracy is real.
//!
//! Output: `OUT_DIR/speed-vs-error.md` (tables) and
//! `OUT_DIR/speed-vs-error.png` (error against M4F render instructions,
//! and against host time with its spread as error bars, one point per
//! configuration, the starred front marked), drawn with `plotters`; text
//! in the plot is drawn with embedded-graphics' built-in mono font, so no
//! system font is needed, and point labels are placed so that they do not
//! overlap.
//!
//! The code is split by concern: [`scenes`] (the scenes and their matrices),
//! `core_run` (the timed core frames), [`reference`](mod@reference) (the `f64` renderer),
//! `compare` (errors and what explains them), `markdown` and `plot` (the
//! output). The whole module is built only with the `report` feature.

use crate::cli::{ReportArgs, REPORT_SCENES};
use crate::cubes;
use crate::obj;
use microraster::math::{radians, FloatFns, Libm, Micromath};
use microraster::pixelcolor::{Rgb888, RgbColor};
use microraster::{
    BoundingSphere, Config, CullMode, DepthBuffer, Error, Frame, FrontFace, Mat4, Mesh, MeshColors,
    SetupTriangle, TriangleId, Vec3,
};
use reference::{mat, Prepared, RefImage, RefOptions, RefTriangle, RefVertex};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::time::Instant;

mod compare;
mod core_run;
pub mod firmware;
mod markdown;
mod plot;
pub mod reference;
pub mod scenes;

pub use compare::*;
pub(crate) use core_run::*;
pub use markdown::*;
pub use scenes::*;

/// Writes the report.
pub fn run(args: &ReportArgs) -> Result<(), String> {
    match args.which.as_str() {
        "speed-vs-error" => speed_vs_error(args),
        other => Err(format!("unknown report {other:?} (known: speed-vs-error)")),
    }
}

// ---------------------------------------------------------------------------
// Configurations

/// The float backend the matrices are built with.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum MathBackend {
    /// `libm`: accurate.
    Libm,
    /// `micromath`: fast approximations.
    Micromath,
}

impl MathBackend {
    /// The cargo feature's name.
    pub fn name(self) -> &'static str {
        match self {
            MathBackend::Libm => "libm",
            MathBackend::Micromath => "micromath",
        }
    }
}

/// The run-time choices beyond the compile-time grid (issue 12's axes):
/// the rasterization mode, what the depth buffer holds, strips or tiles.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Variant {
    /// The clipping mode, window z, set up once, drawn as one strip.
    Base,
    /// The clipping mode in immediate mode: strips of
    /// [`CLIPLESS_STRIP_ROWS`] rows by strip renderers, as the clipless
    /// mode draws (its fair comparison).
    Immediate,
    /// The clipless mode (`RasterMode::Clipless`), drawn in strips of
    /// [`CLIPLESS_STRIP_ROWS`] rows by strip renderers (a frame cannot
    /// store clipless triangles), from vertices processed once.
    Clipless,
    /// 1/w depth (`Mat4::perspective_inv_w`, depth test `Greater`).
    InvW,
    /// Set up once, binned into tiles of `n x n` pixels, each drawn into
    /// its own buffers and copied into the frame.
    Tiles(u32),
}

/// Rows per strip of the clipless runs (the firmware draws 15).
pub const CLIPLESS_STRIP_ROWS: u32 = 16;

/// One configuration of the core: the compile-time grid (subpixel bits,
/// depth word, float backend) and a [`Variant`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Configuration {
    /// Subpixel bits: 4 or 8 (unused by the clipless mode).
    pub subpixel: u32,
    /// Depth buffer bits: 16 or 32.
    pub depth_bits: u32,
    /// A float depth buffer (`f32`, [`microraster::DepthF32`]; 32 bits).
    pub float_depth: bool,
    /// Float backend of the matrices.
    pub math: MathBackend,
    /// Mode, depth kind, tiles.
    pub variant: Variant,
}

impl Configuration {
    /// A short name, e.g. `S8 u16 libm`, `S8 u16 libm clipless`, `S8 u16
    /// libm tiles 32x32`.
    pub fn label(&self) -> String {
        let word = if self.float_depth { "f" } else { "u" };
        let base = format!(
            "S{} {word}{} {}",
            self.subpixel,
            self.depth_bits,
            self.math.name()
        );
        match self.variant {
            Variant::Base => base,
            Variant::Immediate => format!("{base} immediate"),
            Variant::Clipless => format!("{base} clipless"),
            Variant::InvW => format!("{base} inv-w"),
            Variant::Tiles(n) => format!("{base} tiles {n}x{n}"),
        }
    }

    /// The bits of the depth units the report compares in: the word's
    /// for `u16` and `u32`, 48 (`Z32.16`, where an `f32` buffer's values
    /// are whole) for `f32`.
    pub fn compare_bits(&self) -> u32 {
        if self.float_depth {
            48
        } else {
            self.depth_bits
        }
    }
}

const fn config(subpixel: u32, depth_bits: u32, variant: Variant) -> Configuration {
    Configuration {
        subpixel,
        depth_bits,
        float_depth: false,
        math: MathBackend::Libm,
        variant,
    }
}

/// Every configuration the report compares: the grid of eight, then the
/// variants on `S8 libm`.
pub const CONFIGURATIONS: [Configuration; 17] = {
    let mut out = [config(8, 16, Variant::Base); 17];
    let mut i = 0;
    while i < 8 {
        out[i] = Configuration {
            subpixel: if i & 4 == 0 { 4 } else { 8 },
            depth_bits: if i & 2 == 0 { 16 } else { 32 },
            float_depth: false,
            math: if i & 1 == 0 {
                MathBackend::Libm
            } else {
                MathBackend::Micromath
            },
            variant: Variant::Base,
        };
        i += 1;
    }
    out[8] = config(8, 16, Variant::Immediate);
    out[9] = config(8, 16, Variant::Clipless);
    out[10] = config(8, 32, Variant::Clipless);
    out[11] = config(8, 16, Variant::InvW);
    out[12] = config(8, 32, Variant::InvW);
    out[13] = config(8, 16, Variant::Tiles(16));
    out[14] = config(8, 16, Variant::Tiles(32));
    out[15] = config(8, 16, Variant::Tiles(64));
    out[16] = Configuration {
        float_depth: true,
        ..config(8, 32, Variant::InvW)
    };
    out
};

// ---------------------------------------------------------------------------
// The report

/// One configuration on one scene.
#[derive(Clone, Debug)]
pub struct Row {
    /// Scene name.
    pub scene: String,
    /// Configuration.
    pub config: Configuration,
    /// Median frame time, milliseconds.
    pub time_ms: f64,
    /// Fastest of the repetitions, milliseconds.
    pub time_min_ms: f64,
    /// Slowest of the repetitions, milliseconds.
    pub time_max_ms: f64,
    /// Errors against the reference.
    pub errors: ErrorStats,
    /// Vertex-stage error.
    pub vertex: VertexError,
}

/// One configuration over every scene.
#[derive(Clone, Debug)]
pub struct Summary {
    /// Configuration.
    pub config: Configuration,
    /// Sum of the scenes' median frame times, milliseconds.
    pub time_ms: f64,
    /// Sum of the scenes' fastest frame times, milliseconds.
    pub time_min_ms: f64,
    /// Sum of the scenes' slowest frame times, milliseconds.
    pub time_max_ms: f64,
    /// The firmware's instruction counts in this configuration (the
    /// cubes at 320x240, from `docs/embedded.md`).
    pub device: firmware::DeviceCounts,
    /// Pixels whose triangle differs, percent of the reference's covered
    /// pixels (all scenes together but [`LAYERS`], which counts in
    /// `depth_flips` only).
    pub id_diff_pct: f64,
    /// Coverage-only differences, percent of covered pixels.
    pub coverage_diff_pct: f64,
    /// Unexplained differences (all scenes).
    pub unexplained: usize,
    /// Depth-test flips (all scenes; see [`ErrorStats::depth_flips`]).
    pub depth_flips: usize,
    /// Largest depth error, LSB.
    pub depth_max_lsb: f64,
    /// Mean `|stored / 2^bits - exact|` depth, window-depth units.
    pub depth_mean_abs: f64,
    /// Largest of the same.
    pub depth_max_abs: f64,
    /// Depth errors beyond the explained bound.
    pub depth_beyond: usize,
    /// Largest colour error, LSB.
    pub color_max: f64,
    /// Colour errors beyond the explained bound.
    pub color_beyond: usize,
    /// Largest relative matrix error.
    pub matrix_rel: f64,
    /// Largest vertex error, pixels.
    pub vertex_px: f64,
}

/// Sums rows into one summary per configuration, in [`CONFIGURATIONS`]
/// order, with the firmware's counts from `device` (see [`firmware`]).
pub fn summarize(rows: &[Row], device: &[firmware::FirmwareRow]) -> Vec<Summary> {
    let mut out = Vec::new();
    for c in CONFIGURATIONS {
        let rs: Vec<&Row> = rows.iter().filter(|r| r.config == c).collect();
        if rs.is_empty() {
            continue;
        }
        // Pixels differing pool the scenes that measure coverage; the
        // close surfaces of `layers` count in depth flips only (their
        // ties would swamp every edge pixel).
        let pooled: Vec<&Row> = match rs.iter().any(|r| r.scene != LAYERS) {
            true => rs.iter().copied().filter(|r| r.scene != LAYERS).collect(),
            false => rs.clone(),
        };
        let covered: usize = pooled
            .iter()
            .map(|r| r.errors.covered)
            .sum::<usize>()
            .max(1);
        let pooled_sum = |f: &dyn Fn(&Row) -> usize| pooled.iter().map(|r| f(r)).sum::<usize>();
        let same: usize = rs.iter().map(|r| r.errors.same).sum::<usize>().max(1);
        let fmax = |f: &dyn Fn(&Row) -> f64| rs.iter().map(|r| f(r)).fold(0.0, f64::max);
        let sum = |f: &dyn Fn(&Row) -> usize| rs.iter().map(|r| f(r)).sum::<usize>();
        out.push(Summary {
            config: c,
            time_ms: rs.iter().map(|r| r.time_ms).sum(),
            time_min_ms: rs.iter().map(|r| r.time_min_ms).sum(),
            time_max_ms: rs.iter().map(|r| r.time_max_ms).sum(),
            device: firmware::counts(device, &c),
            id_diff_pct: 100.0 * pooled_sum(&|r| r.errors.id_diff) as f64 / covered as f64,
            coverage_diff_pct: 100.0 * pooled_sum(&|r| r.errors.coverage_diff) as f64
                / covered as f64,
            unexplained: sum(&|r| r.errors.unexplained),
            depth_flips: sum(&|r| r.errors.depth_flips),
            depth_max_lsb: fmax(&|r| r.errors.depth_max_lsb),
            depth_mean_abs: rs
                .iter()
                .map(|r| r.errors.depth_abs_mean * r.errors.same as f64)
                .sum::<f64>()
                / same as f64,
            depth_max_abs: fmax(&|r| r.errors.depth_abs_max),
            depth_beyond: sum(&|r| r.errors.depth_beyond),
            color_max: fmax(&|r| r.errors.color_max),
            color_beyond: sum(&|r| r.errors.color_beyond),
            matrix_rel: fmax(&|r| r.vertex.matrix_rel),
            vertex_px: fmax(&|r| r.vertex.window_px),
        });
    }
    out
}

/// The starred configurations: each point `i` is `(lo, hi, y)`, its speed
/// as a range (lower is faster: the noise around a count, or the fastest
/// and slowest of the repetitions) and its error `y` (lower is better,
/// exact). `i` is starred where it is faster beyond the noise than every
/// other point at least as accurate: `hi_i < lo_j` for every `j` with
/// `y_j <= y_i`. That is a subset of the Pareto front of the midpoints:
/// a configuration that only ties (within the noise) with one at least as
/// accurate is not starred. Points with a NaN are never starred, and do
/// not count against others. Sorted by speed.
pub fn significant_front(points: &[(f64, f64, f64)]) -> Vec<usize> {
    let ok = |&(lo, hi, y): &(f64, f64, f64)| !(lo.is_nan() || hi.is_nan() || y.is_nan());
    let mut front: Vec<usize> = (0..points.len())
        .filter(|&i| {
            let (_, hi, y) = points[i];
            ok(&points[i])
                && points
                    .iter()
                    .enumerate()
                    .all(|(j, p)| j == i || !ok(p) || p.2 > y || hi < p.0)
        })
        .collect();
    front.sort_by(|&i, &j| points[i].0.total_cmp(&points[j].0));
    front
}

/// A count's range under [`firmware::COUNT_NOISE`]: half the noise either
/// side, so that two ranges are apart only where one count leads the other
/// by more than the noise.
pub fn count_range(n: Option<u64>) -> (f64, f64) {
    match n {
        Some(n) => {
            let x = n as f64;
            (
                x * (1.0 - firmware::COUNT_NOISE / 2.0),
                x * (1.0 + firmware::COUNT_NOISE / 2.0),
            )
        }
        None => (f64::NAN, f64::NAN),
    }
}

/// The settings a report ran with.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct RunInfo {
    /// Width.
    pub width: u32,
    /// Height.
    pub height: u32,
    /// Timed repetitions.
    pub reps: u32,
}

fn default_models_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("..")
        .join("assets")
        .join("models")
}

/// Loads the named scene.
pub fn load_scene(name: &str, models: &Path, aspect: f32) -> Result<SceneSpec, String> {
    let file = match name {
        "cubes" => return Ok(cubes_spec()),
        "layers" => return Ok(layers_spec(aspect)),
        "spot" => "spot.obj",
        "teapot" => "teapot.obj",
        "bunny" => "stanford-bunny.obj",
        other => return Err(format!("unknown scene {other:?}")),
    };
    let mesh = obj::load_obj(&models.join(file))?;
    Ok(mesh_spec(name, &mesh, aspect))
}

/// A scene, the same scene with 1/w depth, and the `f64` reference of
/// each: what every configuration is measured against.
pub struct SceneRefs {
    spec: SceneSpec,
    spec_inv: SceneSpec,
    refs: [(RefImage, Vec<Option<Prepared>>); 2],
}

impl SceneRefs {
    /// Renders both references of `spec` at `width x height`.
    pub fn new(spec: SceneSpec, width: u32, height: u32) -> SceneRefs {
        let mut spec_inv = spec.clone();
        spec_inv.camera.inv_w = true;
        let refs = [&spec, &spec_inv].map(|s| {
            let tris = reference_triangles(s, width, height);
            let reference = reference::render_reference(
                &tris,
                &RefOptions {
                    width,
                    height,
                    cull: CullMode::Back,
                    front_face: FrontFace::Ccw,
                    greater: s.camera.inv_w,
                },
            );
            let prepared = tris
                .iter()
                .map(|t| Prepared::new(t, width, height))
                .collect();
            (reference, prepared)
        });
        SceneRefs {
            spec,
            spec_inv,
            refs,
        }
    }

    /// The scene configuration `c` draws (1/w depth or not).
    pub fn spec(&self, c: &Configuration) -> &SceneSpec {
        if c.variant == Variant::InvW {
            &self.spec_inv
        } else {
            &self.spec
        }
    }

    /// The errors of `run`, drawn in configuration `c`, against the
    /// reference, with the tolerance of its mode, and its vertex error.
    pub(crate) fn errors(
        &self,
        c: &Configuration,
        run: &CoreRun,
        width: u32,
        height: u32,
    ) -> (ErrorStats, VertexError) {
        let s = self.spec(c);
        let vertex = vertex_error(s, &mvps(s, c.math, width, height), width, height);
        let (reference, prepared) = &self.refs[s.camera.inv_w as usize];
        let tolerance = match c.variant {
            Variant::Clipless => Tolerance::clipless(width, height, &vertex),
            _ => Tolerance::new(c.subpixel, &vertex),
        };
        let errors = compare(run, c.compare_bits(), reference, prepared, tolerance);
        (errors, vertex)
    }
}

fn speed_vs_error(args: &ReportArgs) -> Result<(), String> {
    let (width, height) = args
        .size
        .unwrap_or(if args.quick { (160, 120) } else { (800, 600) });
    let reps = args.reps.unwrap_or(if args.quick { 3 } else { 7 });
    let names: Vec<String> = args
        .scenes
        .clone()
        .unwrap_or_else(|| REPORT_SCENES.iter().map(|s| s.to_string()).collect());
    let models = args.models.clone().unwrap_or_else(default_models_dir);
    std::fs::create_dir_all(&args.out_dir)
        .map_err(|e| format!("{}: cannot create folder: {e}", args.out_dir.display()))?;

    let steps = (names.len() * (1 + reps as usize + CONFIGURATIONS.len())) as u64;
    let bar = if args.no_progress {
        indicatif::ProgressBar::hidden()
    } else {
        indicatif::ProgressBar::new(steps)
    };
    if let Ok(style) =
        indicatif::ProgressStyle::with_template("{elapsed_precise} [{bar:40}] {pos}/{len} {msg}")
    {
        bar.set_style(style.progress_chars("=> "));
    }

    let mut rows = Vec::new();
    for name in &names {
        bar.set_message(format!("{name}: loading, f64 reference"));
        let scene = SceneRefs::new(
            load_scene(name, &models, width as f32 / height as f32)?,
            width,
            height,
        );
        let objects: Vec<CoreObject> = scene.spec.objects.iter().map(CoreObject::new).collect();
        bar.inc(1);
        let mut runners = Vec::new();
        for config in CONFIGURATIONS {
            let input = CoreInput {
                spec: scene.spec(&config),
                objects: &objects,
                math: config.math,
                width,
                height,
            };
            runners.push(runner(input, config)?);
        }
        let mut times = vec![Vec::with_capacity(reps as usize); runners.len()];
        for rep in 0..reps {
            bar.set_message(format!("{name}: timing, round {} of {reps}", rep + 1));
            for (r, t) in runners.iter_mut().zip(&mut times) {
                t.push(r.frame()?);
            }
            bar.inc(1);
        }
        for ((config, r), t) in CONFIGURATIONS.iter().zip(&mut runners).zip(&times) {
            bar.set_message(format!("{name}: {} against f64", config.label()));
            let run = r.finish()?;
            let (errors, vertex) = scene.errors(config, &run, width, height);
            rows.push(Row {
                scene: name.clone(),
                config: *config,
                time_ms: median(t),
                time_min_ms: t.iter().copied().fold(f64::INFINITY, f64::min),
                time_max_ms: t.iter().copied().fold(f64::NEG_INFINITY, f64::max),
                errors,
                vertex,
            });
            bar.inc(1);
        }
    }
    bar.finish_and_clear();

    let info = RunInfo {
        width,
        height,
        reps,
    };
    let device = firmware::table()?;
    let summary = summarize(&rows, &device);
    let md_path = args.out_dir.join("speed-vs-error.md");
    std::fs::write(&md_path, markdown(&info, &summary, &rows, &device))
        .map_err(|e| format!("{}: cannot write: {e}", md_path.display()))?;
    let png_path = args.out_dir.join("speed-vs-error.png");
    plot::write_png(&png_path, &info, &summary)?;
    eprintln!(
        "microraster: wrote {} and {}",
        md_path.display(),
        png_path.display()
    );
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pareto_front_keeps_only_undominated_points() {
        let pts = [
            (1.0, 5.0), // front
            (2.0, 3.0), // front
            (2.5, 3.0), // dominated by (2, 3)
            (3.0, 1.0), // front
            (4.0, 1.0), // dominated by (3, 1)
            (2.0, 4.0), // dominated by (2, 3)
            (5.0, 0.5), // front
            (f64::NAN, 0.0),
        ];
        assert_eq!(pareto_front(&pts), vec![0, 1, 3, 6]);
        // Equal points do not dominate each other.
        assert_eq!(pareto_front(&[(1.0, 1.0), (1.0, 1.0)]), vec![0, 1]);
        assert!(pareto_front(&[]).is_empty());
        // One point is its own front.
        assert_eq!(pareto_front(&[(3.0, 3.0)]), vec![0]);
    }

    #[test]
    fn stars_need_a_lead_over_the_noise() {
        // (lo, hi, y): speed range and error.
        let pts = [
            (0.5, 0.6, 5.0),  // 0: fastest by far, least accurate: starred
            (1.1, 1.3, 3.0),  // 1: more accurate, slower than 0: starred
            (2.0, 2.1, 3.0),  // 2: as accurate as 1 and slower: no star
            (1.25, 1.4, 5.0), // 3: as accurate as 0 and slower: no star
            (3.0, 3.1, 1.0),  // 4: the most accurate: starred
            (2.5, 3.05, 1.0), // 5: as accurate as 4, ranges overlap: neither leads
            (f64::NAN, f64::NAN, 0.0),
        ];
        // 1 is starred: everything at least as accurate (2, 4, 5) is
        // slower beyond the noise. 4 and 5 tie: neither is starred.
        assert_eq!(significant_front(&pts), vec![0, 1]);
        // A lead within the noise over a more accurate point is no lead.
        let tie = [(1.0, 1.2, 5.0), (1.1, 1.3, 3.0)];
        assert_eq!(significant_front(&tie), vec![1]);
        // Apart, the faster of two equally accurate points is starred.
        let apart = [(1.0, 1.1, 2.0), (1.2, 1.3, 2.0)];
        assert_eq!(significant_front(&apart), vec![0]);
        // With no noise it is the Pareto front (less ties).
        let exact: Vec<(f64, f64, f64)> = [(1.0, 5.0), (2.0, 3.0), (2.5, 3.0), (3.0, 1.0)]
            .iter()
            .map(|&(x, y)| (x, x, y))
            .collect();
        assert_eq!(significant_front(&exact), vec![0, 1, 3]);
        // Counts: a 0.5 % lead is noise, a 2 % lead is not.
        let (a, b, c) = (
            count_range(Some(100_000)),
            count_range(Some(100_500)),
            count_range(Some(102_000)),
        );
        assert!(a.1 >= b.0 && b.1 >= a.0);
        assert!(a.1 < c.0);
        assert!(count_range(None).0.is_nan());
    }

    #[test]
    fn configurations_cover_the_grid_once() {
        let mut seen = std::collections::HashSet::new();
        let mut labels = std::collections::HashSet::new();
        for c in CONFIGURATIONS {
            assert!(seen.insert(c));
            assert!(labels.insert(c.label()));
            assert!(matches!(c.subpixel, 4 | 8));
            assert!(matches!(c.depth_bits, 16 | 32));
        }
        let grid = CONFIGURATIONS.iter().filter(|c| c.variant == Variant::Base);
        assert_eq!(grid.count(), 8);
        for v in [
            Variant::Immediate,
            Variant::Clipless,
            Variant::InvW,
            Variant::Tiles(32),
        ] {
            assert!(CONFIGURATIONS.iter().any(|c| c.variant == v), "{v:?}");
        }
    }

    #[test]
    fn median_of_odd_and_even() {
        assert_eq!(median(&[3.0, 1.0, 2.0]), 2.0);
        assert_eq!(median(&[4.0, 1.0, 2.0, 3.0]), 2.5);
    }

    #[test]
    fn cubes_match_the_reference_up_to_snapping() {
        let (w, h) = (96, 72);
        let scene = SceneRefs::new(cubes_spec(), w, h);
        let objects: Vec<CoreObject> = scene.spec.objects.iter().map(CoreObject::new).collect();
        let mut frames = std::collections::HashMap::new();
        for config in CONFIGURATIONS {
            let input = CoreInput {
                spec: scene.spec(&config),
                objects: &objects,
                math: config.math,
                width: w,
                height: h,
            };
            let run = runner(input, config).unwrap().finish().unwrap();
            let (e, v) = scene.errors(&config, &run, w, h);
            if config.math == MathBackend::Libm {
                assert!(v.window_px < 1e-3, "{config:?} {v:?}");
            }
            // Tiles and immediate mode draw the frame of strips, bit for
            // bit.
            if matches!(
                config.variant,
                Variant::Base | Variant::Tiles(_) | Variant::Immediate
            ) {
                let key = (
                    config.subpixel,
                    config.depth_bits,
                    config.float_depth,
                    config.math,
                );
                let frame = (run.ids.clone(), run.color.clone(), run.depth.clone());
                assert!(
                    *frames.entry(key).or_insert_with(|| frame.clone()) == frame,
                    "{config:?}"
                );
            }
            assert!(e.covered > 1000);
            assert_eq!(e.unexplained, 0, "{config:?} {e:?}");
            assert_eq!(e.depth_beyond, 0, "{config:?} {e:?}");
            assert_eq!(e.color_beyond, 0, "{config:?} {e:?}");
            // With libm, a handful of edge pixels at most (micromath's
            // vertex error moves edges by a good part of a pixel here).
            if config.math == MathBackend::Libm {
                assert!(e.id_diff * 50 < e.covered, "{config:?} {e:?}");
            }
        }
    }

    /// The close surfaces of `layers`: a `u16` buffer flips many pixels
    /// (window z and 1/w alike), `u32` none at 800x600 (at 400x300 the
    /// snapping's depth error, twice as large a share of a pixel's depth
    /// change, flips thousands in the narrowest gaps), and every difference
    /// is explained (a tie within what snapping and the buffer allow).
    #[test]
    fn layers_count_depth_flips() {
        let (w, h) = (800, 600);
        let scene = SceneRefs::new(layers_spec(w as f32 / h as f32), w, h);
        let objects: Vec<CoreObject> = scene.spec.objects.iter().map(CoreObject::new).collect();
        let flips = |c: Configuration| {
            let input = CoreInput {
                spec: scene.spec(&c),
                objects: &objects,
                math: c.math,
                width: w,
                height: h,
            };
            let run = runner(input, c).unwrap().finish().unwrap();
            let (e, _) = scene.errors(&c, &run, w, h);
            assert_eq!(e.unexplained, 0, "{c:?} {e:?}");
            assert!(e.covered > 5000, "{e:?}");
            e.depth_flips
        };
        let (z16, z32) = (config(8, 16, Variant::Base), config(8, 32, Variant::Base));
        let (inv16, inv32) = (config(8, 16, Variant::InvW), config(8, 32, Variant::InvW));
        let (a, b, c, d) = (flips(z16), flips(inv16), flips(z32), flips(inv32));
        assert!(a > 1000 && b > 1000, "{a} {b}");
        assert_eq!((c, d), (0, 0), "{a} {b}");
        println!("layers at {w}x{h}: flips u16 {a} / {b}, u32 {c} / {d} (z / 1/w)");
        // Both depth kinds are affine in 1/w: the same resolution in an
        // integer buffer, so about the same flips.
        assert!(a.abs_diff(b) * 20 < a, "{a} {b}");
    }

    #[test]
    fn report_writes_table_and_plot() {
        let dir = tempfile::TempDir::new().unwrap();
        let args = ReportArgs {
            which: "speed-vs-error".into(),
            out_dir: dir.path().join("out"),
            quick: true,
            size: Some((64, 48)),
            reps: Some(1),
            scenes: Some(vec!["cubes".into()]),
            models: None,
            no_progress: true,
        };
        run(&args).unwrap();
        let md = std::fs::read_to_string(dir.path().join("out/speed-vs-error.md")).unwrap();
        assert!(md.contains("S8 u16 libm"));
        assert!(md.contains("S8 u16 libm clipless"));
        assert_eq!(md.matches("| cubes |").count(), CONFIGURATIONS.len());
        let png = std::fs::read(dir.path().join("out/speed-vs-error.png")).unwrap();
        assert_eq!(&png[1..4], b"PNG");
    }

    #[test]
    fn normal_colours_of_a_cube_corner() {
        let c = normal_colors(&cubes::CUBE_VERTICES, &cubes::CUBE_INDICES);
        // Corner (1, -1, -1): the normal points along +x, -y, -z.
        assert!(
            c[0].r() > 128 && c[0].g() < 127 && c[0].b() < 127,
            "{:?}",
            c[0]
        );
        // Corner (-1, 1, 1): the opposite.
        assert!(
            c[6].r() < 127 && c[6].g() > 128 && c[6].b() > 128,
            "{:?}",
            c[6]
        );
    }
}
