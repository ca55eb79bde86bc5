//! The timed runs of `microraster bench`: one [`FramePipeline`] per thread
//! count, kept for the whole run.
//!
//! Design note: [`bench_with`] is monomorphised once per colour format,
//! depth format and sub-pixel precision, so the timed loop has no dynamic
//! dispatch. Each run reuses its pipeline (vertex caches, setup storage,
//! bins) and its colour and depth buffers from frame to frame; spinning
//! scenes get frame `k`'s matrix before the frame's clock starts. The
//! sections after the runs (split, floor, peers) take the same scene as in
//! frame 0. Progress goes to [`Progress`], never to stdout.

use super::progress::Progress;
use super::sections::{floor, split};
use super::stats::{median, ms, Summary};
use super::Settings;
use crate::bench_scenes::BenchScene;
use crate::cli::DepthArg;
use crate::pipeline::FramePipeline;
use crate::render::{self, fnv1a64, DepthKind, RenderOptions, BACKGROUND};
use microraster::pixelcolor::{Rgb565, Rgb888, RgbColor};
use microraster::DepthWord;
use microraster::{Config, PixelFormat, Stats};
use serde_json::{json, Value};
use std::time::Instant;

/// A colour format the benchmark draws into.
pub trait BenchColor: PixelFormat + Send + Sync + PartialEq + 'static {
    /// The background.
    const CLEAR: Self;
    /// The same format packed for euc.
    #[cfg(feature = "peers")]
    type Packed: super::peers::PackedPixel;
    /// As RGB8.
    fn rgb888(self) -> Rgb888;
}

impl BenchColor for Rgb888 {
    const CLEAR: Self = BACKGROUND;
    #[cfg(feature = "peers")]
    type Packed = u32;
    fn rgb888(self) -> Rgb888 {
        self
    }
}

impl BenchColor for Rgb565 {
    const CLEAR: Self = Rgb565::BLACK;
    #[cfg(feature = "peers")]
    type Packed = u16;
    fn rgb888(self) -> Rgb888 {
        Rgb888::from(self)
    }
}

/// The core configuration of `s`.
pub fn config_of(s: &Settings) -> Config {
    let mut c = Config::new(s.width, s.height);
    c.cull = s.cull;
    c.detail = s.detail;
    c
}

/// One run of `frames` frames at one thread count.
#[derive(Clone, Debug)]
pub struct Run {
    /// Worker threads.
    pub threads: usize,
    /// Whole-frame milliseconds, one per timed frame.
    pub total: Vec<f64>,
    /// Setup (vertex + triangles + binning) milliseconds.
    pub setup: Vec<f64>,
    /// Vertex stage milliseconds.
    pub vertex: Vec<f64>,
    /// Triangle stage milliseconds.
    pub triangles: Vec<f64>,
    /// Binning milliseconds.
    pub binning: Vec<f64>,
    /// Clear and draw milliseconds.
    pub raster: Vec<f64>,
    /// Pixels written in the last frame.
    pub pixels_written: u64,
    /// The core's counters of the last frame.
    pub stats: Stats,
    /// FNV-1a of the last frame's RGB8 bytes.
    pub checksum: u64,
    /// Pixels that differ from the background in the last frame.
    pub covered: u64,
    /// The last frame as RGB8, if asked for.
    pub image: Option<Vec<u8>>,
}

/// Everything one format's runs measured.
#[derive(Debug)]
pub struct Formats {
    /// One run per thread count.
    pub runs: Vec<Run>,
    /// The `render_fn` section.
    pub render_fn: Option<Value>,
    /// The `split` section.
    pub split: Option<Value>,
    /// The `floor` section.
    pub floor: Option<Value>,
    /// The `peers` section.
    pub peers: Option<Value>,
    /// The first run's last frame as RGB8.
    pub image: Option<Vec<u8>>,
}

/// All runs and sections of `s` in one colour, depth and sub-pixel format.
pub fn bench_with<const S: u32, C: BenchColor, T: DepthWord>(
    bs: &mut BenchScene,
    s: &Settings,
    depth_on: bool,
    progress: &mut Progress,
) -> Result<Formats, String> {
    let n = s.threads.len();
    let mut runs = if s.interleave && n > 1 {
        run_interleaved::<S, C, T>(bs, s, depth_on, progress)?
    } else {
        let mut runs = Vec::new();
        for (i, &threads) in s.threads.iter().enumerate() {
            let what = format!("run {}/{n} ({threads} threads)", i + 1);
            runs.push(run_frames::<S, C, T>(
                bs,
                s,
                depth_on,
                threads,
                i == 0,
                &what,
                progress,
            )?);
        }
        runs
    };
    let image = runs.first_mut().and_then(|r| r.image.take());
    let render_fn = if s.render_fn {
        Some(render_fn_section(bs, s, runs[0].threads, progress)?)
    } else {
        None
    };
    bs.set_frame(0);
    let split = if s.split && !bs.scene.objects.is_empty() {
        progress.note("stage split");
        Some(split::<S, C, T>(&bs.scene, s, depth_on)?)
    } else {
        None
    };
    let floor = if s.floor {
        progress.note("memory floor");
        Some(floor::<S, C, T>(&bs.scene, s, depth_on, &runs[0])?)
    } else {
        None
    };
    // Without the feature, `--peers` was refused before any run.
    #[cfg(feature = "peers")]
    let peers = if s.peers {
        peers_of::<S, C, T>(bs, s, depth_on, &runs, progress)?
    } else {
        None
    };
    #[cfg(not(feature = "peers"))]
    let peers = None;
    Ok(Formats {
        runs,
        render_fn,
        split,
        floor,
        peers,
        image,
    })
}

/// The peers section, with microraster's one-thread run beside it.
#[cfg(feature = "peers")]
fn peers_of<const S: u32, C: BenchColor, T: DepthWord>(
    bs: &mut BenchScene,
    s: &Settings,
    depth_on: bool,
    runs: &[Run],
    progress: &mut Progress,
) -> Result<Option<Value>, String> {
    let mr = match runs.iter().find(|r| r.threads == 1) {
        Some(r) => r.clone(),
        None => run_frames::<S, C, T>(bs, s, depth_on, 1, false, "peers: 1 thread", progress)?,
    };
    progress.note("peers");
    let mut o = super::peers::peers_section::<S, C>(bs, s, &mr)?;
    o["tgx_host"] = tgx_host_section::<S, C, T>(bs, s, depth_on, progress)?;
    Ok(Some(o))
}

/// Rounds of the side-by-side run against tgx (`../shared/peers/tgx-host`).
#[cfg(feature = "peers")]
pub const TGX_ROUNDS: usize = 3;

/// The tgx sphere harness, if it is beside the checkout: `MICRORASTER_PEERS`
/// or `../shared/peers` from the repository root.
#[cfg(feature = "peers")]
pub fn tgx_host_script() -> Option<std::path::PathBuf> {
    let dir = match std::env::var_os("MICRORASTER_PEERS") {
        Some(d) => std::path::PathBuf::from(d),
        None => std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../shared/peers"),
    };
    let script = dir.join("tgx-host/run.sh");
    script.is_file().then_some(script)
}

/// `median Y ms` from the tgx harness's summary line.
#[cfg(feature = "peers")]
pub fn parse_tgx_median(out: &str) -> Option<f64> {
    out.lines().find_map(|l| {
        let w: Vec<&str> = l.split_whitespace().collect();
        let i = w.iter().position(|&t| t == "median")?;
        w.get(i + 1)?.parse().ok()
    })
}

/// tgx on the same sphere, side by side: [`TGX_ROUNDS`] rounds, each one
/// microraster run (1 thread, this benchmark's settings) then one tgx run
/// of as many frames (A B A B ...); the ratio is of the medians of the
/// rounds' medians, from this one invocation. Skipped (with the reason)
/// for other scenes or when the harness is absent.
#[cfg(feature = "peers")]
fn tgx_host_section<const S: u32, C: BenchColor, T: DepthWord>(
    bs: &mut BenchScene,
    s: &Settings,
    depth_on: bool,
    progress: &mut Progress,
) -> Result<Value, String> {
    use serde_json::json;
    if bs.name != "sphere" {
        return Ok(json!(
            "skipped: the tgx harness draws the sphere scene only"
        ));
    }
    let Some(script) = tgx_host_script() else {
        return Ok(json!(
            "skipped: ../shared/peers/tgx-host not found (set MICRORASTER_PEERS to its folder)"
        ));
    };
    let (mut ours, mut tgx) = (Vec::new(), Vec::new());
    for round in 0..TGX_ROUNDS {
        let what = format!(
            "tgx side by side, round {}/{TGX_ROUNDS}: microraster",
            round + 1
        );
        let r = run_frames::<S, C, T>(bs, s, depth_on, 1, false, &what, progress)?;
        ours.push(median(&r.total));
        progress.note(&format!(
            "tgx side by side, round {}/{TGX_ROUNDS}: tgx",
            round + 1
        ));
        let out = std::process::Command::new("sh")
            .arg(&script)
            .args(["--frames", &s.frames.to_string()])
            .args(["--warmup", &s.warmup.to_string()])
            .args(["--spin", &s.spin.to_string()])
            .output()
            .map_err(|e| format!("{}: {e}", script.display()))?;
        let text = String::from_utf8_lossy(&out.stdout);
        if !out.status.success() {
            return Ok(json!(format!(
                "skipped: {} failed: {}",
                script.display(),
                String::from_utf8_lossy(&out.stderr)
                    .lines()
                    .last()
                    .unwrap_or("")
            )));
        }
        match parse_tgx_median(&text) {
            Some(m) => tgx.push(m),
            None => return Err(format!("{}: no median in its output", script.display())),
        }
    }
    let (mo, mt) = (median(&ours), median(&tgx));
    Ok(json!({
        "script": script.display().to_string(),
        "rounds": TGX_ROUNDS,
        "microraster_median_ms": ours,
        "tgx_median_ms": tgx,
        "microraster_over_tgx": mo / mt,
        "method": "interleaved rounds (microraster 1 thread, then tgx's harness, same \
             frame count, warm-up and spin); each round's median; the ratio is of the \
             medians of those, all from this one run. tgx clears and draws a Gouraud-lit \
             sphere (it also lights every vertex); ours draws the sphere scene as configured.",
    }))
}

/// Times `s.warmup + s.frames` frames at `threads` threads.
#[allow(clippy::too_many_arguments)]
pub fn run_frames<const S: u32, C: BenchColor, T: DepthWord>(
    bs: &mut BenchScene,
    s: &Settings,
    depth_on: bool,
    threads: usize,
    keep_image: bool,
    what: &str,
    progress: &mut Progress,
) -> Result<Run, String> {
    let mut t = Timed::<S, C, T>::new(s, depth_on, threads);
    for k in 0..s.warmup + s.frames {
        progress.tick(what, k, s.warmup + s.frames);
        t.frame(bs, k, k >= s.warmup)?;
    }
    Ok(t.finish(keep_image))
}

/// Times `s.warmup + s.frames` frames at each of `s.threads`, interleaved:
/// frame `k` at every thread count, in the list's order, before frame
/// `k + 1` at any. Each count keeps its own pipeline and buffers, as in
/// [`run_frames`]; the first run keeps its image.
pub fn run_interleaved<const S: u32, C: BenchColor, T: DepthWord>(
    bs: &mut BenchScene,
    s: &Settings,
    depth_on: bool,
    progress: &mut Progress,
) -> Result<Vec<Run>, String> {
    let mut timed: Vec<Timed<S, C, T>> = s
        .threads
        .iter()
        .map(|&threads| Timed::new(s, depth_on, threads))
        .collect();
    let what = format!("{} thread counts, interleaved", s.threads.len());
    for k in 0..s.warmup + s.frames {
        progress.tick(&what, k, s.warmup + s.frames);
        for t in &mut timed {
            t.frame(bs, k, k >= s.warmup)?;
        }
    }
    Ok(timed
        .into_iter()
        .enumerate()
        .map(|(i, t)| t.finish(i == 0))
        .collect())
}

/// One thread count's pipeline, buffers and measurements, frame by frame.
struct Timed<const S: u32, C: BenchColor, T: DepthWord> {
    pipe: FramePipeline<S>,
    color: Vec<C>,
    depth: Vec<T>,
    depth_on: bool,
    run: Run,
}

impl<const S: u32, C: BenchColor, T: DepthWord> Timed<S, C, T> {
    fn new(s: &Settings, depth_on: bool, threads: usize) -> Self {
        let len = s.width as usize * s.height as usize;
        Timed {
            pipe: FramePipeline::<S>::new(config_of(s), threads, s.strip_rows)
                .with_tile_width(s.tile_width),
            color: vec![C::CLEAR; len],
            depth: vec![T::FAR; if depth_on { len } else { 0 }],
            depth_on,
            run: Run {
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
            },
        }
    }

    /// Renders frame `k` (the scene's matrix set before the clock starts),
    /// keeping its times if `timed`.
    fn frame(&mut self, bs: &mut BenchScene, k: u32, timed: bool) -> Result<(), String> {
        bs.set_frame(k);
        let t0 = Instant::now();
        let d = self.depth_on.then_some(&mut self.depth[..]);
        let (setup, raster_ms, px) = self.pipe.render(&bs.scene, &mut self.color, d, C::CLEAR)?;
        let frame_ms = ms(t0);
        let run = &mut self.run;
        if timed {
            run.total.push(frame_ms);
            run.setup.push(setup.total_ms());
            run.vertex.push(setup.vertex_ms);
            run.triangles.push(setup.triangles_ms);
            run.binning.push(setup.binning_ms);
            run.raster.push(raster_ms);
        }
        (run.pixels_written, run.stats) = (px, setup.stats);
        Ok(())
    }

    /// The run, with the last frame's checksum, coverage and (if asked)
    /// image.
    fn finish(self, keep_image: bool) -> Run {
        let mut run = self.run;
        let rgb: Vec<u8> = self
            .color
            .iter()
            .flat_map(|c| {
                let c = c.rgb888();
                [c.r(), c.g(), c.b()]
            })
            .collect();
        run.checksum = fnv1a64(&rgb);
        run.covered = self.color.iter().filter(|&&c| c != C::CLEAR).count() as u64;
        run.image = keep_image.then_some(rgb);
        run
    }
}

/// `render::render` itself, frame by frame (allocations, RGB8 output and
/// all), as a cross-check of the pipeline above.
fn render_fn_section(
    bs: &mut BenchScene,
    s: &Settings,
    threads: usize,
    progress: &mut Progress,
) -> Result<Value, String> {
    let opts = RenderOptions {
        width: s.width,
        height: s.height,
        cull: s.cull,
        detail: s.detail,
        depth: match s.depth {
            DepthArg::U16 => DepthKind::U16,
            DepthArg::U32 => DepthKind::U32,
            DepthArg::F32 => DepthKind::F32,
            DepthArg::None => DepthKind::None,
        },
        subpixel: s.subpixel,
        threads,
        strip_rows: s.strip_rows,
        tile_width: s.tile_width,
        ids: false,
        mode: microraster::RasterMode::Clipping,
        inv_w: false,
        occlusion: crate::render::Occlusion::Off,
    };
    let occluded = RenderOptions {
        occlusion: crate::render::Occlusion::On,
        ..opts
    };
    let (mut total, mut setup, mut raster) = (Vec::new(), Vec::new(), Vec::new());
    let strips = RenderOptions {
        occlusion: crate::render::Occlusion::Strips,
        ..opts
    };
    let (mut occ_total, mut strips_total) = (Vec::new(), Vec::new());
    let mut checksum = 0;
    let (mut identical, mut occ_stats) = (true, None);
    for k in 0..s.warmup + s.frames {
        progress.tick("render_fn", k, s.warmup + s.frames);
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
        if s.occlusion {
            // Interleaved: strips without, strips with occlusion culling.
            let t = Instant::now();
            let p = render::render(&bs.scene, &strips)?;
            let strips_ms = ms(t);
            let t = Instant::now();
            let q = render::render(&bs.scene, &occluded)?;
            if k >= s.warmup {
                strips_total.push(strips_ms);
                occ_total.push(ms(t));
            }
            identical &= q.rgb == r.rgb && q.depth == r.depth && p.rgb == r.rgb;
            occ_stats = Some(q.stats);
        }
    }
    let mut o = Summary::of(&total).json();
    o["threads"] = json!(threads);
    o["setup_median_ms"] = json!(median(&setup));
    o["raster_median_ms"] = json!(median(&raster));
    o["color"] = json!("rgb888");
    o["checksum"] = json!(format!("{checksum:016x}"));
    if let Some(st) = occ_stats {
        let submitted = st.submitted.max(1) as f64;
        let mut q = Summary::of(&occ_total).json();
        q["strips_median_ms"] = json!(median(&strips_total));
        q["speedup"] = json!(median(&strips_total) / median(&occ_total));
        q["culled_occlusion"] = json!(st.culled_occlusion);
        q["culled_occlusion_fraction"] = json!(st.culled_occlusion as f64 / submitted);
        q["reaching_setup"] = json!(st.submitted - st.dropped());
        q["identical"] = json!(identical);
        o["occlusion"] = q;
    }
    Ok(o)
}

#[cfg(all(test, feature = "peers"))]
mod tests {
    use super::*;

    #[test]
    fn tgx_summary_line_is_parsed() {
        let out = "# covered 12345 px\nmean 0.951 ms median 0.9295 ms best 0.88 ms\nmax 1.2 ms\n";
        assert_eq!(parse_tgx_median(out), Some(0.9295));
        assert_eq!(parse_tgx_median("no numbers here"), None);
        assert_eq!(parse_tgx_median("median x ms"), None);
    }
}
