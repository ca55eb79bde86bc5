//! The frame pipeline shared by [`crate::render`] and [`crate::bench`]: a
//! [`Scene`] set up into binned core frames, then drawn strip by strip.
//!
//! Design note: [`FramePipeline::with_layers`] runs three stages. The vertex
//! stage processes every object inside the frustum once, in parallel chunks
//! of at least [`VERTEX_CHUNK_MIN`] vertices. The triangle stage splits the
//! scene's triangle sequence into up to `threads` contiguous [`Piece`]s of
//! about equal estimated work ([`partition_by`] with a sample of which
//! triangles culling keeps, a kept one weighed by a cost that each frame
//! retunes from its chunks' times; one chunk below
//! [`PARALLEL_SETUP_MIN_TRIANGLES`])
//! and [`fill`]s each chunk into its own [`Frame`] and setup storage; the
//! same worker then bins its frame, sorting its triangles by strip into
//! bins grown to what it counts ([`Frame::bin_tiles_with`]). Each parallel
//! stage runs one worker on the calling thread (`each_on_threads`).
//! Every frame is set up exactly once:
//! storage is sized from the triangle count, and only when a chunk reports
//! [`Error::StorageFull`] (clipping made more triangles than the guess) are
//! the full storages grown and the chunks built again. The pipeline keeps its
//! vertex caches, storages and bins from one call to the next, so a benchmark
//! loop stops allocating after its first frame; `render::render` uses a fresh
//! one per image. [`draw_layers`] clears and draws strips on `threads`
//! workers that each take a contiguous run of them first, then help with
//! the longest run left (`Runs`; inline for one thread),
//! or, binned by tile ([`FramePipeline::with_tile_width`]), tiles drawn
//! into each worker's own tile buffers and copied into the image
//! ([`for_each_tile`]).
//! [`FramePipeline::render`] into strips, with the triangle stage split
//! over several threads, runs that stage and the drawing in one thread
//! scope (`render_fused`): each worker sets up and bins its chunk,
//! publishes its frame, waits at a gate for the others', then draws strips
//! of every frame, in runs of about equal cost estimated from the bins
//! (`Runs::weigh`); a frame starts one thread fewer, and drawing begins as
//! the last frame is binned.
//! Every strip draws the frames in order and the core draws triangles in
//! submission order, so the image is byte-identical for any thread count and
//! any strip height.

use crate::scene::{ObjectColors, Scene};
use microraster::prelude::Submit;
use microraster::{
    Bins, ClipVertex, Config, CullMode, DepthWord, Error, Frame, FrontFace, LazyClear, MeshColors,
    NoDepth, PixelFormat, ProcessedVertex, SetupTriangle, Stats, Vec4,
};
use std::ops::Range;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::{Condvar, Mutex, OnceLock};
use std::time::Instant;

/// Triangle counts at and above which the triangle stage is split over the
/// threads.
pub const PARALLEL_SETUP_MIN_TRIANGLES: usize = 20_000;

/// Vertices per vertex-stage chunk, at least.
pub const VERTEX_CHUNK_MIN: usize = 4096;

/// Vertex-stage chunks per thread, at most: workers take them as `Runs`
/// deals them, so a worker that starts late takes fewer.
pub const VERTEX_CHUNKS_PER_THREAD: usize = 4;

/// One piece of a scene's triangle sequence: triangles `range` of object
/// `object`, or clip-space triangles `range`.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Piece {
    /// Triangles of `scene.objects[object]`.
    Object(usize, Range<usize>),
    /// Triangles of `scene.clip_tris`.
    ClipTris(Range<usize>),
}

impl Piece {
    /// The number of triangles.
    pub fn len(&self) -> usize {
        match self {
            Piece::Object(_, r) | Piece::ClipTris(r) => r.len(),
        }
    }

    /// Whether the piece has no triangles.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

/// Splits the scene's triangle sequence into at most `parts` contiguous
/// chunks of about equal size, in drawing order.
pub fn partition(scene: &Scene, parts: usize) -> Vec<Vec<Piece>> {
    partition_by(
        scene,
        parts,
        |o| vec![(scene.objects[o].indices.len(), 1)],
        1,
    )
}

/// Splits the scene's triangle sequence into at most `parts` contiguous
/// chunks of about equal work, in drawing order. `runs(o)` gives object
/// `o`'s triangles as consecutive runs `(triangles, work of each)`; a
/// clip-space triangle is work `clip_work`. With every triangle's work 1
/// this is [`partition`].
pub fn partition_by(
    scene: &Scene,
    parts: usize,
    runs: impl Fn(usize) -> Vec<(usize, u64)>,
    clip_work: u64,
) -> Vec<Vec<Piece>> {
    partition_led(scene, parts, runs, clip_work, 0)
}

/// [`partition_by`] with the first chunk given `lead` units of work more
/// (fewer, if negative) than an equal share, the others sharing the rest
/// equally: the first chunk is the calling thread's, which starts before
/// the others ([`SetupSplit::rebalance`]).
fn partition_led(
    scene: &Scene,
    parts: usize,
    runs: impl Fn(usize) -> Vec<(usize, u64)>,
    clip_work: u64,
    lead: i64,
) -> Vec<Vec<Piece>> {
    let object_runs: Vec<Vec<(usize, u64)>> = (0..scene.objects.len()).map(&runs).collect();
    let clip_runs = vec![(scene.clip_tris.len(), clip_work)];
    let total: u64 = object_runs
        .iter()
        .chain(std::iter::once(&clip_runs))
        .flatten()
        .map(|&(n, w)| n as u64 * w)
        .sum::<u64>()
        .max(1);
    let per = total.div_ceil(parts.max(1) as u64).max(1);
    // (With no lead every chunk's share is `per`.)
    let (first, per) = if lead == 0 || parts < 2 {
        (per, per)
    } else {
        let first = (per as i64).saturating_add(lead).clamp(1, total as i64) as u64;
        (first, (total - first).div_ceil(parts as u64 - 1).max(1))
    };
    let mut chunks: Vec<Vec<Piece>> = vec![Vec::new()];
    let mut room = first;
    // `whole`: one piece however long (a clustered object is submitted
    // whole: its clusters cover all its triangles).
    let mut push = |runs: &[(usize, u64)], whole: bool, make: &dyn Fn(Range<usize>) -> Piece| {
        let mut start = 0;
        let runs: Vec<(usize, u64)> = if whole {
            // One run of the object's length and its mean work.
            let n = runs.iter().map(|r| r.0).sum::<usize>();
            let work = runs.iter().map(|&(n, w)| n as u64 * w).sum::<u64>();
            match n {
                0 => Vec::new(),
                n => vec![(n, work.div_ceil(n as u64))],
            }
        } else {
            runs.to_vec()
        };
        for (len, w) in runs {
            let mut left = len;
            while left > 0 {
                if room == 0 {
                    chunks.push(Vec::new());
                    room = per;
                }
                let take = if whole {
                    left
                } else {
                    (room.div_ceil(w.max(1)) as usize).min(left)
                };
                if let Some(c) = chunks.last_mut() {
                    // Runs of one source in one chunk are one piece.
                    match (c.last_mut(), make(start..start + take)) {
                        (Some(Piece::Object(i, r)), Piece::Object(j, s))
                            if *i == j && r.end == s.start =>
                        {
                            r.end = s.end
                        }
                        (Some(Piece::ClipTris(r)), Piece::ClipTris(s)) if r.end == s.start => {
                            r.end = s.end
                        }
                        (_, p) => c.push(p),
                    }
                }
                start += take;
                left -= take;
                room = room.saturating_sub(take as u64 * w);
            }
        }
    };
    for (i, o) in scene.objects.iter().enumerate() {
        let whole = o.clusters.is_some() || o.normal_classes.is_some();
        push(&object_runs[i], whole, &|r| Piece::Object(i, r));
    }
    push(&clip_runs, false, &|r| Piece::ClipTris(r));
    chunks
}

/// Triangles per sample of [`setup_work`]. The sample is read on the
/// calling thread between the vertex and triangle stages, mostly from
/// cache entries the other worker wrote (about 45 us for the bunny's 1,086
/// samples of 64): in frames alternating with 64, 128 made two-thread
/// frames of the bunny 29 to 73 us faster (medians of 202 pairs, six runs;
/// the same frames alternated with themselves: -34 to +1 us), 256 16 to 42
/// us slower, its split coarser (2026-12-07).
const WORK_SAMPLE: usize = 128;

/// Setup work of a triangle the core rejects (a back face or one outside
/// the frustum, found from three cached vertices), the unit of the setup
/// split's estimates: a clip-space or unculled triangle counts as one too.
const REJECTED_WORK: u64 = 8;

/// The first estimate of a triangle the core keeps (clips, sets up, stores
/// and bins), in units of [`REJECTED_WORK`]: three rejected ones, from two
/// chunks' times on two threads before the binning moved into the setup
/// workers (the bunny: 21,309 triangles with 17,286 kept in 1.42 ms,
/// 48,142 with 12,974 kept in 1.83 ms; 2026-12-06). Each frame then moves
/// it towards what its own chunks took ([`SetupSplit`]).
const KEPT_WORK: u64 = 3 * REJECTED_WORK;

/// The range [`SetupSplit`] keeps the estimate in: a kept triangle
/// costs from one to sixteen rejected ones.
const KEPT_WORK_RANGE: (u64, u64) = (REJECTED_WORK, 16 * REJECTED_WORK);

/// How much of the setup chunks' measurements a frame keeps of those
/// before it ([`SetupSplit`]): about the last eight frames count.
const FIT_DECAY: f64 = 0.875;

/// [`SetupSplit::rebalance`] moves the first chunk's lead by this fraction
/// of the frame's estimated setup work a frame.
const LEAD_STEPS: u64 = 256;

/// The setup split's estimate of a kept triangle's work, retuned from the
/// times of the chunks that frames with several were set up in.
#[derive(Clone, Copy, Debug)]
struct SetupSplit {
    /// A kept triangle's work in units of [`REJECTED_WORK`]
    /// ([`KEPT_WORK`] at first).
    kept_work: u64,
    /// Least-squares sums over the chunks `(kept k, rejected r, seconds
    /// d)` of the frames so far, each frame's weight [`FIT_DECAY`] times
    /// the next one's: `k k`, `k r`, `r r`, `k d`, `r d`.
    sums: [f64; 5],
    /// Work the first chunk (the calling thread's) takes beyond an equal
    /// share, in the split's units (a rejected triangle is
    /// [`REJECTED_WORK`]; [`SetupSplit::rebalance`]).
    lead: i64,
}

impl SetupSplit {
    fn new() -> Self {
        SetupSplit {
            kept_work: KEPT_WORK,
            sums: [0.0; 5],
            lead: 0,
        }
    }

    /// Moves the first chunk's lead one step ([`LEAD_STEPS`]) towards
    /// the other chunks' ends, from one frame's chunks `(kept, rejected,
    /// seconds)` and when each ended (seconds from the stage's start): up
    /// when the others ended later on average, down when earlier, within a
    /// quarter of the frame's work. The spawned workers start some 30 us
    /// after the calling one and took longer for their estimated work
    /// than it did (the bunny's second chunk ended a median 85-135 us
    /// after the first, 2026-12-07); a step a frame by the sign of the
    /// difference settles where the chunks end first about equally often,
    /// which a frame disturbed by another tenant moves by one step only.
    /// A frame of one chunk, or with an end that is not a finite number,
    /// changes nothing.
    fn rebalance(&mut self, chunks: &[(u64, u64, f64)], ends: &[f64]) {
        if chunks.len() < 2 || ends.len() != chunks.len() || ends.iter().any(|e| !e.is_finite()) {
            return;
        }
        let total: u64 = chunks
            .iter()
            .map(|&(k, r, _)| k * self.kept_work + r * REJECTED_WORK)
            .sum();
        let others = ends[1..].iter().sum::<f64>() / (ends.len() - 1) as f64;
        let late = others - ends[0];
        if late == 0.0 {
            return;
        }
        let step = (total / LEAD_STEPS).max(1) as i64;
        let most = (total / 4) as i64;
        let moved = if late > 0.0 {
            self.lead + step
        } else {
            self.lead - step
        };
        self.lead = moved.clamp(-most, most);
    }

    /// Adds one frame's chunks, `(kept, rejected, seconds)` each, and moves
    /// the estimate towards their fit: the chunks' times fitted as `a *
    /// kept + b * rejected` by least squares over the decayed sums, the
    /// estimate moved a quarter of the way to `a / b` rejected units
    /// (rounded away from where it was), by at most an eighth of itself
    /// (a disturbed frame on a shared machine moves it little), within
    /// [`KEPT_WORK_RANGE`]. A frame of one chunk, or with a time that is
    /// not a finite number, adds nothing. The estimate stays where it is
    /// when it is within half a unit of the fit, when the chunks cannot
    /// tell the two costs apart (their mixes of kept and rejected
    /// triangles nearly alike), and when the fit is not positive.
    fn retune(&mut self, chunks: &[(u64, u64, f64)]) {
        if chunks.len() < 2 || chunks.iter().any(|c| !c.2.is_finite()) {
            return;
        }
        let mut sums = self.sums.map(|s| s * FIT_DECAY);
        for &(k, r, d) in chunks {
            let (k, r) = (k as f64, r as f64);
            for (s, v) in sums.iter_mut().zip([k * k, k * r, r * r, k * d, r * d]) {
                *s += v;
            }
        }
        self.sums = sums;
        let [kk, kr, rr, kd, rd] = sums;
        let det = kk * rr - kr * kr;
        // The (kept, rejected) vectors at least some 6 degrees apart.
        if det.partial_cmp(&(0.01 * kk * rr)) != Some(std::cmp::Ordering::Greater) {
            return;
        }
        let (a, b) = ((kd * rr - rd * kr) / det, (rd * kk - kd * kr) / det);
        if !(a.is_finite() && b.is_finite() && a > 0.0 && b > 0.0) {
            return;
        }
        let now = self.kept_work as f64;
        let target = a / b * REJECTED_WORK as f64;
        if (target - now).abs() < 0.5 {
            return;
        }
        let step = (target - now) / 4.0;
        let most = (now / 8.0).max(1.0);
        let moved = now + step.clamp(-most, most);
        // Rounded away from where it was, so that it reaches the target.
        let moved = if step > 0.0 {
            moved.ceil()
        } else {
            moved.floor()
        };
        let (lo, hi) = KEPT_WORK_RANGE;
        self.kept_work = (moved as u64).clamp(lo, hi);
    }
}

/// Object `o`'s triangles as runs of [`WORK_SAMPLE`] with their estimated
/// setup work ([`partition_by`]): each run's first triangle, read from the
/// vertex stage's `cache` (`None`: the object is outside the frustum),
/// stands for the run, kept (work `kept_work`) unless it is culled as a
/// back (front) face or lies outside one side of the view (work
/// [`REJECTED_WORK`]). Only the split among the setup workers depends on
/// it, not the image.
fn setup_work(
    o: &crate::scene::Object,
    config: &Config,
    cache: Option<&[ProcessedVertex]>,
    kept_work: u64,
) -> Vec<(usize, u64)> {
    // (Clustered and masked objects have no cache: they are submitted whole.)
    let Some(cache) = cache.filter(|_| config.cull != CullMode::None) else {
        return vec![(o.indices.len(), REJECTED_WORK)];
    };
    let ccw_front = config.front_face == FrontFace::Ccw;
    let kept = |t: &[u32; 3]| {
        let mut p = [Vec4::new(0.0, 0.0, 0.0, 0.0); 3];
        for (p, &i) in p.iter_mut().zip(t) {
            match cache.get(i as usize) {
                Some(v) => *p = v.clip_position(),
                None => return false,
            }
        }
        if p.iter().any(|p| p.w <= 0.0) {
            return true; // clipped: the most work
        }
        let out = |f: &dyn Fn(&Vec4) -> bool| p.iter().all(f);
        if out(&|p| p.x > p.w)
            || out(&|p| p.x < -p.w)
            || out(&|p| p.y > p.w)
            || out(&|p| p.y < -p.w)
        {
            return false;
        }
        let [a, b, c] = p.map(|p| (p.x / p.w, p.y / p.w));
        let area = (b.0 - a.0) * (c.1 - a.1) - (c.0 - a.0) * (b.1 - a.1);
        let front = (area > 0.0) == ccw_front;
        match config.cull {
            CullMode::Back => front,
            CullMode::Front => !front,
            CullMode::None => true,
        }
    };
    o.indices
        .chunks(WORK_SAMPLE)
        .map(|run| {
            let work = if kept(&run[0]) {
                kept_work
            } else {
                REJECTED_WORK
            };
            (run.len(), work)
        })
        .collect()
}

/// Pushes the triangles of `pieces` into `frame`: objects through their
/// processed vertices `caches[object]` (`None`: outside the frustum, only
/// counted, by `draw_mesh`), clip-space triangles one by one. Triangle ids
/// count from 0 over the whole scene, objects first.
pub fn fill<const S: u32, K: Submit<S>>(
    frame: &mut K,
    scene: &Scene,
    pieces: &[Piece],
    caches: &[Option<&[ProcessedVertex]>],
    scratch: &mut Vec<ProcessedVertex>,
) -> Result<(), Error> {
    let mut first_ids = Vec::with_capacity(scene.objects.len());
    let mut id = 0u32;
    for o in &scene.objects {
        first_ids.push(id);
        id = id.wrapping_add(o.indices.len() as u32);
    }
    let clip_first = id;
    for piece in pieces {
        match piece {
            Piece::Object(i, r) => {
                let o = &scene.objects[*i];
                let mut mesh = o.mesh();
                mesh.indices = &o.indices[r.clone()];
                if let ObjectColors::PerTriangle(c) = &o.colors {
                    mesh.attributes.colors =
                        MeshColors::PerTriangle(c.get(r.clone()).unwrap_or(&[]));
                }
                let id = first_ids[*i].wrapping_add(r.start as u32);
                if let Some(c) = &o.clusters {
                    // The scratch cache: the vertex stage skipped it.
                    let cache = scratch_for(scratch, o.positions.len());
                    // Without a fill, plain colours: no box is bounded.
                    match o.detail_fill {
                        Some(_) => {
                            frame.submit_clusters(&o.mesh(), &o.mvp, &c.set(), c.cull, id, cache)
                        }
                        None => frame.submit_clusters(
                            &o.plain_mesh(),
                            &o.mvp,
                            &c.set(),
                            c.cull,
                            id,
                            cache,
                        ),
                    }?;
                    continue;
                }
                if let Some(c) = &o.normal_classes {
                    let cache = scratch_for(scratch, o.positions.len());
                    frame.submit_masked(&o.mesh(), &o.mvp, &c.set(), id, cache)?;
                    continue;
                }
                // An object split among pieces draws its detail box (if
                // dropped whole) with its first piece only.
                if r.start != 0 {
                    mesh.attributes.fill = None;
                }
                match caches.get(*i).copied().flatten() {
                    Some(cache) => frame.submit_processed_mesh(&mesh, id, cache)?,
                    None => frame.submit_mesh(&mesh, &o.mvp, id)?,
                }
            }
            Piece::ClipTris(r) => {
                for (k, t) in scene.clip_tris[r.clone()].iter().enumerate() {
                    let [cr, cg, cb] = t.color.unwrap_or([255, 255, 255]);
                    let color = [cr as f32, cg as f32, cb as f32];
                    let v = t.v.map(|p| ClipVertex {
                        pos: Vec4::from_array(p),
                        varyings: color,
                    });
                    frame.submit_triangle(v, clip_first.wrapping_add((r.start + k) as u32))?;
                }
            }
        }
    }
    Ok(())
}

/// The first `n` entries of `scratch`, grown to hold them: the cache of
/// a clustered or masked object, kept from one frame to the next. What
/// it holds is never read: the core processes the entries that the
/// triangles it keeps read (its caches are scratch space).
fn scratch_for(scratch: &mut Vec<ProcessedVertex>, n: usize) -> &mut [ProcessedVertex] {
    if scratch.len() < n {
        scratch.resize(n, ProcessedVertex::EMPTY);
    }
    &mut scratch[..n]
}

// ---------------------------------------------------------------------------
// Strips.

/// One strip: its first row and its rows of colour and depth.
type Work<'a, C, T> = (u32, &'a mut [C], Option<&'a mut [T]>);

/// Calls `f(y0, colour rows, depth rows)` for every strip of `rows` rows of
/// `width` pixels on `threads` workers taking strips from a shared queue
/// (`Runs`; inline for one thread) and sums what it returns. A worker's
/// panic goes on in the caller, whichever thread it ran on.
pub fn for_each_strip<C, T, F>(
    color: &mut [C],
    depth: Option<&mut [T]>,
    width: usize,
    rows: usize,
    threads: usize,
    f: F,
) -> Result<u64, Error>
where
    C: Send,
    T: Send,
    F: Fn(u32, &mut [C], Option<&mut [T]>) -> Result<u64, Error> + Sync,
{
    let work = strip_work(color, depth, width, rows);
    drain_on_threads(work, threads, || (), |(y0, c, d), _| f(y0, c, d))
}

/// The strips of `rows` rows (at least 1) of an image `width` pixels wide,
/// in order.
fn strip_work<'a, C, T>(
    color: &'a mut [C],
    depth: Option<&'a mut [T]>,
    width: usize,
    rows: usize,
) -> Vec<Work<'a, C, T>> {
    let rows = rows.max(1);
    let chunk = (width * rows).max(1);
    let mut work: Vec<Work<'_, C, T>> = Vec::new();
    match depth {
        Some(d) => {
            for (i, (c, d)) in color.chunks_mut(chunk).zip(d.chunks_mut(chunk)).enumerate() {
                work.push(((i * rows) as u32, c, Some(d)));
            }
        }
        None => {
            for (i, c) in color.chunks_mut(chunk).enumerate() {
                work.push(((i * rows) as u32, c, None));
            }
        }
    }
    work
}

/// One tile for [`for_each_tile`]: its index, its rectangle `[x0, x1, y0,
/// y1]`, and the rows of the image it lies in (colour, depth).
type TileWork<'a, C, T> = (u32, &'a Band<'a, C, T>);

/// A band of whole image rows (colour, depth) that tiles are copied into.
type Band<'a, C, T> = Mutex<(&'a mut [C], Option<&'a mut [T]>)>;

/// Calls `f(tile, [x0, x1, y0, y1], colour, depth)` for every tile of
/// `tile_w x tile_h` (numbered row by row, as [`Frame::bin_tiles`] does) of
/// an image `width` pixels wide, with buffers that hold exactly the tile,
/// on `threads` workers taking tiles from a shared queue (`Runs`), and
/// sums what it returns. Tiles at least as wide as the image are strips,
/// handed out as the image's own rows ([`for_each_strip`]); narrower ones
/// are drawn into each worker's own tile buffers (which `f` must clear or draw over: they
/// hold the image's pixels only when `copy_in`), then copied into the
/// image. A worker's panic goes on in the caller, as for
/// [`for_each_strip`].
#[allow(clippy::too_many_arguments)]
pub fn for_each_tile<C, T, F>(
    color: &mut [C],
    depth: Option<&mut [T]>,
    width: usize,
    (tile_w, tile_h): (usize, usize),
    threads: usize,
    copy_in: bool,
    f: F,
) -> Result<u64, Error>
where
    C: Send + Copy,
    T: Send + Copy,
    F: Fn(u32, [u32; 4], &mut [C], Option<&mut [T]>) -> Result<u64, Error> + Sync,
{
    let th = tile_h.max(1);
    if tile_w == 0 || tile_w >= width || width == 0 {
        return for_each_strip(color, depth, width, th, threads, |y0, c, d| {
            let y1 = y0 + (c.len() / width.max(1)) as u32;
            f(y0 / th as u32, [0, width as u32, y0, y1], c, d)
        });
    }
    let tw = tile_w;
    let cols = width.div_ceil(tw);
    let chunk = width * th;
    let bands: Vec<Band<'_, C, T>> = match depth {
        Some(d) => color
            .chunks_mut(chunk)
            .zip(d.chunks_mut(chunk))
            .map(|(c, d)| Mutex::new((c, Some(d))))
            .collect(),
        None => color
            .chunks_mut(chunk)
            .map(|c| Mutex::new((c, None)))
            .collect(),
    };
    let work: Vec<TileWork<'_, C, T>> = bands
        .iter()
        .enumerate()
        .flat_map(|(b, m)| (0..cols).map(move |k| ((b * cols + k) as u32, m)))
        .collect();
    // Draws one tile into the worker's buffers and copies it out.
    let one = |(tile, band): TileWork<'_, C, T>,
               lc: &mut Vec<C>,
               ld: &mut Vec<T>|
     -> Result<u64, Error> {
        let (ty, tx) = (tile as usize / cols, tile as usize % cols);
        // Any value sizes the buffers (`f` or the copy-in sets every one):
        // the band's first.
        let (rows, c0, d0) = {
            let g = lock(band);
            (g.0.len() / width, g.0[0], g.1.as_deref().map(|d| d[0]))
        };
        let (x0, x1) = (tx * tw, (tx * tw + tw).min(width));
        let (y0, y1) = (ty * th, ty * th + rows);
        let (w, n) = (x1 - x0, (x1 - x0) * rows);
        lc.resize(n, c0);
        let has_depth = d0.is_some();
        if let Some(d0) = d0 {
            ld.resize(n, d0);
        }
        if copy_in {
            let mut g = lock(band);
            let (c, d) = &mut *g;
            for r in 0..rows {
                lc[r * w..r * w + w].copy_from_slice(&c[r * width + x0..r * width + x1]);
                if let Some(d) = d.as_deref() {
                    ld[r * w..r * w + w].copy_from_slice(&d[r * width + x0..r * width + x1]);
                }
            }
        }
        let rect = [x0 as u32, x1 as u32, y0 as u32, y1 as u32];
        // (`ld` is empty without depth: not sliced then.)
        let tile_depth = if has_depth { Some(&mut ld[..n]) } else { None };
        let px = f(tile, rect, &mut lc[..n], tile_depth)?;
        let mut g = lock(band);
        let (c, d) = &mut *g;
        for r in 0..rows {
            c[r * width + x0..r * width + x1].copy_from_slice(&lc[r * w..r * w + w]);
            if let Some(d) = d.as_deref_mut() {
                d[r * width + x0..r * width + x1].copy_from_slice(&ld[r * w..r * w + w]);
            }
        }
        Ok(px)
    };
    let buffers = || (Vec::new(), Vec::new());
    drain_on_threads(work, threads, buffers, |item, (lc, ld)| one(item, lc, ld))
}

/// Calls `f(item, state)` for every item of `work` on `threads` workers
/// taking them as [`Runs`] deals them (inline for one thread), each
/// with its own `state()`, and sums what it returns; the first error ends
/// a worker. A worker that panicked left its item half done: the panic
/// goes on in the caller, as one in the worker on the calling thread does.
fn drain_on_threads<W: Send, S>(
    work: Vec<W>,
    threads: usize,
    state: impl Fn() -> S + Sync,
    f: impl Fn(W, &mut S) -> Result<u64, Error> + Sync,
) -> Result<u64, Error> {
    let threads = threads.max(1);
    let queue = Mutex::new(Runs::new(work, threads));
    let worker = |w: usize| drain(&queue, w, &mut state(), &f);
    // Every worker's panic before any worker's error.
    let results: Vec<Result<u64, Error>> = each_on_threads((0..threads).collect(), worker)
        .into_iter()
        .map(|r| r.unwrap_or_else(|e| std::panic::resume_unwind(e)))
        .collect();
    results.into_iter().sum()
}

/// Worker `w`'s share of `queue`: `f(item, state)` for every item it is
/// dealt, summed; the first error ends it.
fn drain<W, S>(
    queue: &Mutex<Runs<W>>,
    w: usize,
    state: &mut S,
    f: impl Fn(W, &mut S) -> Result<u64, Error>,
) -> Result<u64, Error> {
    let mut total = 0;
    loop {
        // (The lock is released before `f` runs.)
        let item = lock(queue).take(w);
        let Some((_, item)) = item else {
            return Ok(total);
        };
        total += f(item, state)?;
    }
}

/// Work items dealt out as one contiguous run per worker: a worker takes
/// the items of its own run from one end and, once that is empty, an item
/// from the other end of the run with the most work left. Neighbouring
/// items (strips that share triangles) thus mostly go to one worker, whose
/// caches hold what they share, while the work still balances: taking
/// strips from one shared queue in order made each worker's strips about
/// 7 % slower than on one thread (the bunny at 1920x1080, 2026-12-06).
/// Unweighed, the runs are of equal length, each taken front to back by
/// its worker and back to front by the others. [`Runs::weigh`] gives each
/// item an estimated cost: the runs are then of about equal cost (where no
/// item is too coarse for that), and each worker starts at its run's
/// heavier end, so that the last items, which decide when the last worker
/// ends, are the light ones (the bunny's strips: 10 us where the bunny is
/// not, up to 300 us where it is).
struct Runs<W> {
    items: Vec<Option<W>>,
    runs: Vec<Range<usize>>,
    /// Each item's estimated cost (empty until weighed: every item 1).
    cost: Vec<u64>,
    /// Whether each run's own worker takes it back to front.
    down: Vec<bool>,
    weighed: bool,
}

impl<W> Runs<W> {
    /// `work` in `workers` runs of about equal length, in order.
    fn new(work: Vec<W>, workers: usize) -> Self {
        let (n, k) = (work.len(), workers.max(1));
        Runs {
            items: work.into_iter().map(Some).collect(),
            runs: (0..k).map(|w| w * n / k..(w + 1) * n / k).collect(),
            cost: Vec::new(),
            down: vec![false; k],
            weighed: false,
        }
    }

    /// Splits the work anew into runs of about equal cost, `cost(i, item)`
    /// each item's, where no item costs more than a quarter of a
    /// worker's share (else the runs keep their equal lengths), and has
    /// each run's worker start at its heavier half's end; once, and only
    /// before any item is taken (else nothing changes).
    fn weigh(&mut self, cost: impl Fn(usize, &W) -> u64) {
        let untouched = self.items.iter().all(Option::is_some);
        if self.weighed || !untouched {
            return;
        }
        self.weighed = true;
        self.cost = (self.items.iter().enumerate())
            .map(|(i, w)| w.as_ref().map_or(0, |w| cost(i, w)))
            .collect();
        let (n, k) = (self.items.len(), self.runs.len() as u64);
        let total: u64 = self.cost.iter().sum();
        let heaviest = self.cost.iter().copied().max().unwrap_or(0);
        // Runs of equal cost only where the items are fine enough for
        // them: no item above a quarter of a worker's share. (The spots
        // scene, one of whose 15 strips holds 45 % of the work, drew 6 %
        // slower with runs split by cost than with equal lengths, both
        // begun at their heavier ends; 2026-12-07.)
        let fine = heaviest.saturating_mul(4 * k) <= total;
        // Run w ends where the running cost comes nearest (w + 1) / k of
        // the total: an item joins it if at least half of it fits.
        if fine {
            let (mut start, mut sum, mut i) = (0, 0u64, 0);
            for w in 0..k {
                let goal = (w + 1) * total / k;
                while i < n && (sum + self.cost[i] / 2 < goal || w + 1 == k) {
                    sum += self.cost[i];
                    i += 1;
                }
                self.runs[w as usize] = start..i;
                start = i;
            }
        }
        for (r, down) in self.runs.iter().zip(&mut self.down) {
            let mid = r.start + r.len() / 2;
            let half = |h: Range<usize>| self.cost[h].iter().sum::<u64>();
            *down = half(mid..r.end) > half(r.start..mid);
        }
    }

    /// Worker `w`'s next item and its index in the work, if any is left.
    fn take(&mut self, w: usize) -> Option<(usize, W)> {
        let own = self.runs.get(w).filter(|r| !r.is_empty()).map(|_| w);
        // (Unweighed, every item costs 1: no sum over the run.)
        let left = |r: &Range<usize>| match self.weighed {
            true => self.cost[r.clone()].iter().sum::<u64>(),
            false => r.len() as u64,
        };
        let v = own.or_else(|| {
            (0..self.runs.len())
                .filter(|&v| !self.runs[v].is_empty())
                .max_by_key(|&v| left(&self.runs[v]))
        })?;
        // The owner from its end, the others from the other.
        let from_back = (v == w) == self.down[v];
        let r = &mut self.runs[v];
        let i = if from_back {
            r.end -= 1;
            r.end
        } else {
            r.start += 1;
            r.start - 1
        };
        Some((i, self.items[i].take()?))
    }
}

/// Runs `f` on every item, the first on the calling thread and each other
/// on a thread of its own, and returns the results in order (`Err` for a
/// worker that panicked). The calling thread works instead of waiting: a
/// scope of two spawned threads took 82 us on this 2-core machine, one
/// spawned and one inline 46 us (2026-12-06). The spawned threads hand
/// their results back through slots, not by being joined, and the calling
/// thread, done first, spins up to [`SPIN_FOR`] until their threads have
/// finished, then drops their handles, so that the scope ends without
/// blocking: joining waited for the thread to exit, and a blocked caller
/// for its core to wake, each some 50 us after the last worker was done (2
/// threads, the bunny at 1920x1080, 2026-12-06). Spinning on a flag the
/// worker set last still let the scope block, until the thread's own end
/// woke it, in about a quarter of the fused frames' ends (some 25 us after
/// the last strip, against 4 us; 2026-12-07).
fn each_on_threads<I: Send, R: Send>(
    items: Vec<I>,
    f: impl Fn(I) -> R + Sync,
) -> Vec<std::thread::Result<R>> {
    let mut items = items.into_iter();
    let Some(first) = items.next() else {
        return Vec::new();
    };
    let f = &f;
    let rest: Vec<I> = items.collect();
    let slots: Vec<Mutex<Option<std::thread::Result<R>>>> =
        rest.iter().map(|_| Mutex::new(None)).collect();
    let first = std::thread::scope(|s| {
        let handles: Vec<_> = slots
            .iter()
            .zip(rest)
            .map(|(slot, i)| {
                s.spawn(move || {
                    let r = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| f(i)));
                    *lock(slot) = Some(r);
                })
            })
            .collect();
        let out = f(first);
        let t = Instant::now();
        while !handles.iter().all(|h| h.is_finished()) && t.elapsed() < SPIN_FOR {
            for _ in 0..64 {
                std::hint::spin_loop();
            }
        }
        // A finished thread's handle, dropped here, ends its part of the
        // scope: the scope then does not wait for the thread to wake it.
        drop(handles);
        out
    });
    std::iter::once(Ok(first))
        .chain(slots.into_iter().map(|m| {
            let r = m.into_inner().unwrap_or_else(|p| p.into_inner());
            // (A spawned thread always fills its slot before the scope ends.)
            r.unwrap_or_else(|| Err(Box::new("worker ended without a result")))
        }))
        .collect()
}

/// How long the calling thread of [`each_on_threads`] spins for the other
/// workers before it blocks.
const SPIN_FOR: std::time::Duration = std::time::Duration::from_micros(200);

/// Locks `m`, whether or not another worker panicked holding it.
fn lock<X>(m: &Mutex<X>) -> std::sync::MutexGuard<'_, X> {
    match m.lock() {
        Ok(g) => g,
        Err(poisoned) => poisoned.into_inner(),
    }
}

/// A set-up, binned frame: the part of the scene one setup worker built.
pub type Layer<'a, 'f, const S: u32> = (&'a Frame<'f, S>, &'a Bins<'a>);

/// Draws every strip or tile of the binned frames `layers` (in order; all
/// binned alike, by [`Frame::bin`] or [`Frame::bin_tiles`]) on `threads`
/// workers, clearing each first (colour to `clear`, depth to
/// [`DepthWord::FAR`]) if `clear` is given. Returns the pixels written.
pub fn draw_layers<const S: u32, C: PixelFormat + Send + Sync, T: DepthWord>(
    layers: &[Layer<'_, '_, S>],
    color: &mut [C],
    depth: Option<&mut [T]>,
    threads: usize,
    clear: Option<C>,
) -> Result<u64, Error> {
    draw_layers_cleared(layers, color, depth, threads, clear, T::FAR)
}

/// A tile defers its clear (`microraster::LazyClear`) when it has at
/// least this many pixels per triangle binned to it, else clears first.
/// Chosen between the quad (about 15,000 pixels a triangle a strip),
/// where deferring saves a pass over memory, and the bunny at 1920x1080
/// (about 30), where it made the raster stage about a quarter slower
/// (interleaved `bench` runs, 2026-12-05).
pub const LAZY_PIXELS_PER_TRIANGLE: usize = 256;

/// [`draw_layers`] clearing depth to `depth_clear` (0 for 1/w depth,
/// whose test is `Greater`) instead of [`DepthWord::FAR`].
pub fn draw_layers_cleared<const S: u32, C: PixelFormat + Send + Sync, T: DepthWord>(
    layers: &[Layer<'_, '_, S>],
    color: &mut [C],
    depth: Option<&mut [T]>,
    threads: usize,
    clear: Option<C>,
    depth_clear: T,
) -> Result<u64, Error> {
    let Some((first, bins)) = layers.first() else {
        return Ok(0);
    };
    let width = first.config().width as usize;
    let tile = (bins.tile_width() as usize, bins.strip_rows() as usize);
    for_each_tile(
        color,
        depth,
        width,
        tile,
        threads,
        clear.is_none(),
        |tile, rect, c, d| draw_tile_cleared(layers, (tile, rect), c, d, clear, depth_clear),
    )
}

/// Draws tile `tile` (`[x0, x1, y0, y1]`: `rect`) of every layer in turn
/// into `c` and `d`, cleared first (colour to `clear`, depth to
/// `depth_clear`) if `clear` is given; returns the pixels written.
fn draw_tile_cleared<const S: u32, C: PixelFormat, T: DepthWord>(
    layers: &[Layer<'_, '_, S>],
    (tile, rect): (u32, [u32; 4]),
    c: &mut [C],
    mut d: Option<&mut [T]>,
    clear: Option<C>,
    depth_clear: T,
) -> Result<u64, Error> {
    // Tiles of few, large triangles (a quad, a few boxes) defer the clear
    // (`LazyClear`): what the layers reach is cleared as they reach it, the
    // rest after them, so a pixel the first layer covers is written once,
    // not cleared first. Tiles of many small triangles (the bunny: about
    // 30 pixels a triangle) clear first: per row, per triangle, the
    // deferred clear's bookkeeping costs more than it saves. The pixels
    // are the same either way (`tests/lazy_clear.rs`).
    let area = (rect[1] - rect[0]) as usize * (rect[3] - rect[2]) as usize;
    let items: usize = layers.iter().map(|(_, b)| b.strip_items(tile).len()).sum();
    let Some(v) = clear else {
        return draw_tile_layers(layers, tile, c, d, None);
    };
    if items * LAZY_PIXELS_PER_TRIANGLE > area {
        c.fill(v);
        if let Some(d) = d.as_deref_mut() {
            d.fill(depth_clear);
        }
        return draw_tile_layers(layers, tile, c, d, None);
    }
    let mut hull = vec![0u32; (rect[3] - rect[2]) as usize];
    let mut lazy = LazyClear::new(&mut hull, rect, v, depth_clear.to_z32())?;
    let written = draw_tile_layers(layers, tile, c, d.as_deref_mut(), Some(&mut lazy))?;
    match d {
        Some(d) => lazy.finish(c, d)?,
        None => lazy.finish(c, &mut NoDepth)?,
    };
    Ok(written)
}

/// Draws tile `tile` of every layer in turn into `c` and `d` (none: no
/// depth buffer), under the deferred clear `lazy` where given; returns the
/// pixels written.
fn draw_tile_layers<const S: u32, C: PixelFormat, T: DepthWord>(
    layers: &[Layer<'_, '_, S>],
    tile: u32,
    c: &mut [C],
    mut d: Option<&mut [T]>,
    mut lazy: Option<&mut LazyClear<'_, C>>,
) -> Result<u64, Error> {
    let mut written = 0;
    for (frame, bins) in layers {
        let stats = match (d.as_deref_mut(), lazy.as_deref_mut()) {
            (Some(d), Some(l)) => frame.render_tile_lazy(bins, tile, c, d, l)?,
            (None, Some(l)) => frame.render_tile_lazy(bins, tile, c, &mut NoDepth, l)?,
            (Some(d), None) => frame.render_tile(bins, tile, c, d)?,
            (None, None) => frame.render_tile(bins, tile, c, &mut NoDepth)?,
        };
        written += stats.pixels_written;
    }
    Ok(written)
}

// ---------------------------------------------------------------------------
// The pipeline.

/// Times of the setup stages of one frame, in milliseconds, and its
/// counters.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SetupTimes {
    /// Vertex stage: transform, outcode, snap (every vertex once).
    pub vertex_ms: f64,
    /// Triangle stage: cull, clip, set up and store, until the last setup
    /// worker's frame is built.
    pub triangles_ms: f64,
    /// Binning by strip: the rest of the triangle stage, where each setup
    /// worker bins its own frame once it is built.
    pub binning_ms: f64,
    /// The core's counters, summed over the setup workers' frames.
    pub stats: Stats,
}

impl SetupTimes {
    /// Vertex + triangle + binning stages.
    pub fn total_ms(&self) -> f64 {
        self.vertex_ms + self.triangles_ms + self.binning_ms
    }
}

/// Frames of one scene set up, binned and drawn with every buffer kept from
/// one frame to the next (see the module documentation): the vertex stage of
/// each visible object in parallel chunks, the triangle stage in `threads`
/// contiguous chunks of the scene (one below
/// [`PARALLEL_SETUP_MIN_TRIANGLES`] triangles), each into its own frame and
/// setup storage, each frame binned by strip (or tile), and the strips
/// drawn on `threads` workers, every strip drawing the frames in order.
#[derive(Debug)]
pub struct FramePipeline<const S: u32> {
    config: Config,
    threads: usize,
    strip_rows: u32,
    /// Tile width; 0 for strips.
    tile_w: u32,
    caches: Vec<Vec<ProcessedVertex>>,
    storages: Vec<Vec<SetupTriangle>>,
    bins: Vec<BinBuffers>,
    /// The setup split's estimate of a kept triangle's work, retuned by
    /// each frame set up in several chunks.
    split: SetupSplit,
}

/// One setup chunk's buffers, kept from frame to frame: its bins'
/// offsets and items (see [`Frame::bin_tiles_with`]), and the vertex
/// cache of the clustered and masked objects it submits ([`fill`]).
#[derive(Debug, Default)]
struct BinBuffers {
    bins: (Vec<u32>, Vec<u32>),
    scratch: Vec<ProcessedVertex>,
}

/// One setup worker's frame, binned, when its building ended (before the
/// binning) and when building began and binning ended: `Ok(Err(needed))`
/// when its storage is full.
type Built<'s, 'b, const S: u32> =
    Result<Result<(Frame<'s, S>, Bins<'b>, Instant, Range<Instant>), usize>, String>;

/// Builds the frame of `pieces` in `storage` and bins it into tiles of
/// `tile` (width, height) in `bins`.
#[allow(clippy::too_many_arguments)]
fn build_chunk<'s, 'b, const S: u32>(
    config: Config,
    storage: &'s mut [SetupTriangle],
    bins: &'b mut BinBuffers,
    tile: (u32, u32),
    scene: &Scene,
    pieces: &[Piece],
    caches: &[Option<&[ProcessedVertex]>],
) -> Built<'s, 'b, S> {
    let start = Instant::now();
    let mut f = Frame::<S>::with_subpixel_bits(config, storage).map_err(|e| e.to_string())?;
    let BinBuffers { bins, scratch } = bins;
    match fill(&mut f, scene, pieces, caches, scratch) {
        Ok(()) => {
            let built = Instant::now();
            let b = bin_growing::<S>(&f, tile.0, tile.1, bins)?;
            Ok(Ok((f, b, built, start..Instant::now())))
        }
        Err(Error::StorageFull { needed, .. }) => Ok(Err(needed)),
        Err(e) => Err(e.to_string()),
    }
}

/// Builds and bins one frame per chunk of the scene, each in its own
/// storage and bins, in parallel when there is more than one chunk: each
/// worker bins its frame as soon as it is built, so a frame on two threads
/// starts one thread scope fewer and waits once for the slower worker, not
/// twice.
fn build_chunks<'s, 'b, const S: u32>(
    config: Config,
    (storages, bins): (&'s mut [Vec<SetupTriangle>], &'b mut [BinBuffers]),
    tile: (u32, u32),
    scene: &Scene,
    chunks: &[Vec<Piece>],
    caches: &[Option<&[ProcessedVertex]>],
) -> Vec<Built<'s, 'b, S>> {
    let build = |storage, bins, pieces| {
        build_chunk::<S>(config, storage, bins, tile, scene, pieces, caches)
    };
    let work = storages.iter_mut().zip(bins.iter_mut()).zip(chunks);
    if chunks.len() == 1 {
        return work.map(|((s, b), p)| build(s, b, p)).collect();
    }
    each_on_threads(work.collect(), |((s, b), p)| build(s, b, p))
        .into_iter()
        .map(|r| r.unwrap_or_else(|_| Err("setup worker failed".into())))
        .collect()
}

/// Bins `f` into tiles of `tile_w x tile_h` in `bins` (offsets, items),
/// each grown to what the frame needs as it is binned (the items to the
/// bins' own count of entries: no pass over the triangles beforehand).
fn bin_growing<'b, const S: u32>(
    f: &Frame<'_, S>,
    tile_w: u32,
    tile_h: u32,
    (offsets, items): &'b mut (Vec<u32>, Vec<u32>),
) -> Result<Bins<'b>, String> {
    let tiles = f.tiles(tile_w, tile_h);
    if offsets.len() < tiles + 1 {
        offsets.resize(tiles + 1, 0);
    }
    f.bin_tiles_with(tile_w, tile_h, offsets, |need| {
        // Over `u32::MAX` entries is an error, not an allocation.
        if items.len() < need && need <= u32::MAX as usize {
            items.resize(need, 0);
        }
        items
    })
    .map_err(|e| e.to_string())
}

/// Whether detail culling (`config.detail`) drops object `o` whole, by its
/// bounds: then no vertex of it is processed, and `submit_mesh` drops it
/// (drawing its box where it has a fill).
pub fn dropped_by_detail(o: &crate::scene::Object, config: &Config) -> bool {
    let detail = microraster::Detail::for_frame(&o.mvp, config);
    matches!((o.bounds, detail), (Some(b), Some(d)) if d.drops(&b))
}

/// Runs the vertex stage of every object of `scene` inside the frustum into
/// `caches` (grown as needed), `threads` workers per object. Returns each
/// object's processed vertices, `None` for one outside the frustum.
fn vertex_stage<'c, const S: u32>(
    config: Config,
    threads: usize,
    scene: &Scene,
    caches: &'c mut Vec<Vec<ProcessedVertex>>,
) -> Result<Vec<Option<&'c [ProcessedVertex]>>, String> {
    let probe = Frame::<S>::with_subpixel_bits(config, &mut []).map_err(|e| e.to_string())?;
    if caches.len() < scene.objects.len() {
        caches.resize_with(scene.objects.len(), Vec::new);
    }
    let mut out = Vec::with_capacity(scene.objects.len());
    for (o, cache) in scene.objects.iter().zip(caches.iter_mut()) {
        // Clustered and masked objects process their vertices as their
        // triangles pass.
        if o.clusters.is_some()
            || o.normal_classes.is_some()
            || o.bounds.is_some_and(|b| b.outside_frustum(&o.mvp))
            || dropped_by_detail(o, &config)
        {
            out.push(None);
            continue;
        }
        if cache.len() < o.positions.len() {
            cache.resize(o.positions.len(), ProcessedVertex::EMPTY);
        }
        let cache = &mut cache[..o.positions.len()];
        // Chunks of a quarter of a thread's share: the spawned workers
        // start some 25 us after the calling one, and take fewer.
        let chunk = o
            .positions
            .len()
            .div_ceil(threads * VERTEX_CHUNKS_PER_THREAD)
            .max(VERTEX_CHUNK_MIN);
        if threads == 1 || o.positions.len() <= chunk {
            probe.process_vertices(&o.mvp, &o.positions, cache);
        } else {
            let work: Vec<_> = o
                .positions
                .chunks(chunk)
                .zip(cache.chunks_mut(chunk))
                .collect();
            drain_on_threads(
                work,
                threads,
                || (),
                |(p, c), _| {
                    probe.process_vertices(&o.mvp, p, c);
                    Ok(0)
                },
            )
            .map_err(|e| e.to_string())?;
        }
        out.push(Some(&*cache));
    }
    Ok(out)
}

/// The vertex stage of `scene` and its triangle sequence split into setup
/// chunks (see the module documentation), each chunk's storage and bins
/// ready: each object's processed vertices (as [`vertex_stage`]), the
/// chunks, and the vertex stage's milliseconds.
fn prepare<'c, const S: u32>(
    config: Config,
    threads: usize,
    scene: &Scene,
    caches: &'c mut Vec<Vec<ProcessedVertex>>,
    (storages, bins): (&mut Vec<Vec<SetupTriangle>>, &mut Vec<BinBuffers>),
    split: &SetupSplit,
) -> Result<VertexStage<'c>, String> {
    let t0 = Instant::now();
    let caches = vertex_stage::<S>(config, threads, scene, caches)?;
    let vertex_ms = ms(t0);

    // Triangle stage, in chunks of the scene.
    let parts = if scene.triangle_count() >= PARALLEL_SETUP_MIN_TRIANGLES {
        threads
    } else {
        1
    };
    // Chunks of about equal work: kept triangles cost several times
    // what rejected ones do, and a mesh seen from one side keeps most
    // of one half (the bunny: 24,744 against 5,516 of 30,260 in two
    // equal halves).
    let chunks = if parts > 1 {
        let runs = |i| setup_work(&scene.objects[i], &config, caches[i], split.kept_work);
        partition_led(scene, parts, runs, REJECTED_WORK, split.lead)
    } else {
        partition(scene, 1)
    };
    storages.resize_with(chunks.len(), Vec::new);
    for (storage, pieces) in storages.iter_mut().zip(&chunks) {
        let n: usize = pieces.iter().map(Piece::len).sum();
        if storage.len() < Frame::<S>::storage_for(n) {
            storage.resize(Frame::<S>::storage_for(n), SetupTriangle::EMPTY);
        }
    }
    bins.resize_with(chunks.len(), Default::default);
    Ok((caches, chunks, vertex_ms))
}

/// A frame after [`FramePipeline::prepare_frame`]: each object's
/// processed vertices, the setup chunks, the vertex stage's milliseconds,
/// and the pipeline's storages, bins and split.
struct Prepared<'p> {
    caches: Vec<Option<&'p [ProcessedVertex]>>,
    chunks: Vec<Vec<Piece>>,
    vertex_ms: f64,
    storages: &'p mut Vec<Vec<SetupTriangle>>,
    bins: &'p mut Vec<BinBuffers>,
    split: &'p mut SetupSplit,
}

/// What [`prepare`] gives.
type VertexStage<'c> = (Vec<Option<&'c [ProcessedVertex]>>, Vec<Vec<Piece>>, f64);

impl<const S: u32> FramePipeline<S> {
    /// A pipeline for frames of `config`, on `threads` threads, binned into
    /// strips of `strip_rows` rows.
    pub fn new(config: Config, threads: usize, strip_rows: u32) -> Self {
        FramePipeline {
            config,
            threads: threads.max(1),
            strip_rows: strip_rows.max(1),
            tile_w: 0,
            caches: Vec::new(),
            storages: Vec::new(),
            bins: Vec::new(),
            split: SetupSplit::new(),
        }
    }

    /// The frame settings.
    pub fn config(&self) -> Config {
        self.config
    }

    /// The worker threads (at least 1).
    pub fn threads(&self) -> usize {
        self.threads
    }

    /// The rows per strip (at least 1).
    pub fn strip_rows(&self) -> u32 {
        self.strip_rows
    }

    /// Bins into tiles `tile_w` pixels wide (and [`strip_rows`](Self::strip_rows)
    /// high) instead of strips: `0`, or the frame width and more, are
    /// strips. The image is the same either way.
    pub fn with_tile_width(mut self, tile_w: u32) -> Self {
        self.tile_w = if tile_w >= self.config.width {
            0
        } else {
            tile_w
        };
        self
    }

    /// The tile width (0: strips).
    pub fn tile_width(&self) -> u32 {
        self.tile_w
    }

    /// [`prepare`] for this pipeline: the vertex stage of `scene` and its
    /// setup chunks, with the buffers and the split the triangle stage
    /// takes on with.
    fn prepare_frame(&mut self, scene: &Scene) -> Result<Prepared<'_>, String> {
        let FramePipeline {
            config,
            threads,
            caches,
            storages,
            bins,
            split,
            ..
        } = self;
        let (caches, chunks, vertex_ms) =
            prepare::<S>(*config, *threads, scene, caches, (storages, bins), split)?;
        Ok(Prepared {
            caches,
            chunks,
            vertex_ms,
            storages,
            bins,
            split,
        })
    }

    /// Sets `scene` up (vertex stage, triangle stage, binning) and hands
    /// the binned frames to `then`.
    pub fn with_layers<R>(
        &mut self,
        scene: &Scene,
        then: impl FnOnce(&[Layer<'_, '_, S>]) -> Result<R, String>,
    ) -> Result<(R, SetupTimes), String> {
        let (config, strip_rows) = (self.config, self.strip_rows);
        // Strips are tiles as wide as the frame.
        let tile_w = if self.tile_w == 0 {
            config.width
        } else {
            self.tile_w
        };
        let p = self.prepare_frame(scene)?;
        let (caches, chunks, vertex_ms) = (&p.caches[..], p.chunks, p.vertex_ms);
        let (storages, bins, split) = (p.storages, p.bins, p.split);
        // Every chunk is built (and binned) once. A chunk whose storage
        // was too small (clipping can turn one triangle into several; the
        // first guess almost always suffices) has its storage grown, and
        // then every chunk is built again: a failed frame cannot hand its
        // storage back. The stages' times are those of the last
        // (successful) attempt: triangles until the last worker's frame
        // was built, binning the rest.
        let tile = (tile_w, strip_rows);
        let (frames, binned, triangles_ms, binning_ms) = loop {
            let t1 = Instant::now();
            let results = build_chunks::<S>(config, (storages, bins), tile, scene, &chunks, caches);
            let mut frames = Vec::with_capacity(results.len());
            let mut binned = Vec::with_capacity(results.len());
            let mut tally = Tally::new(t1);
            let mut grow = vec![0usize; results.len()];
            for (i, r) in results.into_iter().enumerate() {
                match r? {
                    Ok((f, b, t, span)) => {
                        tally.add(f.stats(), t, span);
                        frames.push(f);
                        binned.push(b);
                    }
                    Err(needed) => grow[i] = needed,
                }
            }
            if grow.iter().all(|&g| g == 0) {
                tally.tune(split);
                let triangles = tally.built_at.duration_since(t1).as_secs_f64() * 1e3;
                break (frames, binned, triangles, ms(t1) - triangles);
            }
            drop((frames, binned));
            grow_storages(storages, &grow);
        };
        let layers: Vec<Layer<'_, '_, S>> = frames.iter().zip(binned.iter()).collect();
        let mut stats = Stats::default();
        for f in &frames {
            stats += f.stats();
        }
        let out = then(&layers)?;
        Ok((
            out,
            SetupTimes {
                vertex_ms,
                triangles_ms,
                binning_ms,
                stats,
            },
        ))
    }

    /// Renders one frame of `scene` into `color` and `depth` (cleared
    /// first, strip by strip). Returns the setup times, the raster time in
    /// milliseconds and the pixels written.
    pub fn render<C: PixelFormat + Send + Sync, T: DepthWord>(
        &mut self,
        scene: &Scene,
        color: &mut [C],
        depth: Option<&mut [T]>,
        clear: C,
    ) -> Result<(SetupTimes, f64, u64), String> {
        if self.threads > 1
            && self.tile_w == 0
            && scene.triangle_count() >= PARALLEL_SETUP_MIN_TRIANGLES
        {
            return self.render_fused(scene, color, depth, clear);
        }
        let threads = self.threads;
        let ((raster_ms, px), setup) = self.with_layers(scene, |layers| {
            let t = Instant::now();
            let px = draw_layers(layers, color, depth, threads, Some(clear))
                .map_err(|e| e.to_string())?;
            Ok((ms(t), px))
        })?;
        Ok((setup, raster_ms, px))
    }
}

impl<const S: u32> FramePipeline<S> {
    /// [`render`](Self::render) of a frame set up by several workers into
    /// strips, in one thread scope: each worker sets up and bins its chunk
    /// of the scene (a worker beyond the chunks, none), publishes its
    /// frame, waits at a [`Gate`] for the others' and then draws strips of
    /// every frame, as `Runs` deals them once weighed by the bins (the
    /// strips and pixels of [`draw_layers`]). A frame of two threads thus
    /// starts one thread fewer, and its drawing begins when the last
    /// frame is binned, not after that worker's thread has ended and
    /// another has started (some 80 us on this 2-core machine). A worker
    /// that panics or fails still passes the gate; then no strip is drawn
    /// (and a full storage is grown, the frame built again). Setup times
    /// are as in [`with_layers`](Self::with_layers), binning until the
    /// last frame is published; the raster time runs from then.
    fn render_fused<C: PixelFormat + Send + Sync, T: DepthWord>(
        &mut self,
        scene: &Scene,
        color: &mut [C],
        mut depth: Option<&mut [T]>,
        clear: C,
    ) -> Result<(SetupTimes, f64, u64), String> {
        let (config, strip_rows, threads) = (self.config, self.strip_rows, self.threads);
        let p = self.prepare_frame(scene)?;
        let (caches, chunks, vertex_ms) = (&p.caches[..], p.chunks, p.vertex_ms);
        let (storages, bins, split) = (p.storages, p.bins, p.split);
        let tile = (config.width, strip_rows);
        let width = config.width as usize;
        loop {
            let t1 = Instant::now();
            let n = chunks.len();
            // Each worker's frame and when it was published.
            let slots: Vec<OnceLock<(Built<'_, '_, S>, Instant)>> =
                (0..n).map(|_| OnceLock::new()).collect();
            let gate = Gate::new(n);
            let strips = strip_work(color, depth.as_deref_mut(), width, strip_rows as usize);
            // Every thread draws; a scene cut into fewer chunks than threads
            // (a clustered object is one piece) leaves the last ones
            // nothing to set up.
            let workers = threads.max(n);
            let queue = Mutex::new(Runs::new(strips, workers));
            let work: Vec<SetupWork<'_>> = storages
                .iter_mut()
                .map(|s| &mut s[..])
                .zip(bins.iter_mut())
                .zip(chunks.iter().map(|c| &c[..]))
                .map(Some)
                .chain(std::iter::repeat_with(|| None))
                .take(workers)
                .enumerate()
                .collect();
            let worker = |(w, job): (usize, Option<_>)| -> Result<u64, Error> {
                if let Some(((storage, bins), pieces)) = job {
                    let _arrive = gate.arrival();
                    let built =
                        build_chunk::<S>(config, storage, bins, tile, scene, pieces, caches);
                    // (Set once: each slot is this worker's alone.)
                    let _ = slots[w].set((built, Instant::now()));
                }
                gate.wait();
                let layers: Option<Vec<Layer<'_, '_, S>>> = slots
                    .iter()
                    .map(|s| match s.get() {
                        Some((Ok(Ok((f, b, ..))), _)) => Some((f, b)),
                        _ => None,
                    })
                    .collect();
                let Some(layers) = layers else {
                    return Ok(0);
                };
                // The first worker here weighs the strips by their bins.
                lock(&queue).weigh(|i, (_, c, _): &Work<'_, C, T>| {
                    let items: usize = (layers.iter())
                        .map(|(_, b)| b.strip_items(i as u32).len())
                        .sum();
                    strip_cost(items, c.len())
                });
                let draw = |(y0, c, d): Work<'_, C, T>, _: &mut ()| {
                    let y1 = y0 + (c.len() / width.max(1)) as u32;
                    let rect = [0, config.width, y0, y1];
                    draw_tile_cleared(&layers, (y0 / strip_rows, rect), c, d, Some(clear), T::FAR)
                };
                drain(&queue, w, &mut (), draw)
            };
            let drawn: Vec<Result<u64, Error>> = each_on_threads(work, worker)
                .into_iter()
                .map(|r| r.unwrap_or_else(|e| std::panic::resume_unwind(e)))
                .collect();
            let end = Instant::now();
            let mut grow = vec![0usize; n];
            let mut tally = Tally::new(t1);
            let mut stats = Stats::default();
            let mut published_at = t1;
            for (i, slot) in slots.into_iter().enumerate() {
                let Some((built, at)) = slot.into_inner() else {
                    return Err("setup worker failed".into());
                };
                match built? {
                    Ok((f, _, t, span)) => {
                        tally.add(f.stats(), t, span);
                        stats += f.stats();
                        published_at = published_at.max(at);
                    }
                    Err(needed) => grow[i] = needed,
                }
            }
            if grow.iter().any(|&g| g > 0) {
                grow_storages(storages, &grow);
                continue;
            }
            let px: u64 = drawn
                .into_iter()
                .sum::<Result<u64, Error>>()
                .map_err(|e| e.to_string())?;
            tally.tune(split);
            let built_at = tally.built_at;
            let since = |a: Instant, b: Instant| b.duration_since(a).as_secs_f64() * 1e3;
            let setup = SetupTimes {
                vertex_ms,
                triangles_ms: since(t1, built_at),
                binning_ms: since(built_at, published_at),
                stats,
            };
            return Ok((setup, since(published_at, end), px));
        }
    }
}

/// A strip's estimated drawing cost from the triangles binned to it and
/// its pixels, in units of one binned triangle: clearing [`CLEAR_PIXELS`]
/// pixels costs about as much as drawing a triangle of the bunny at
/// 1920x1080 (strips of 16 rows: 10 us empty, 10 us + 0.13 us a triangle,
/// 2026-12-07).
fn strip_cost(triangles: usize, pixels: usize) -> u64 {
    (triangles + pixels / CLEAR_PIXELS) as u64
}

/// Pixels cleared at the cost of one binned triangle drawn ([`strip_cost`]).
const CLEAR_PIXELS: usize = 400;

/// One worker of [`FramePipeline::render_fused`]: its index and, if it
/// sets up a chunk, its storage and bins and its chunk of the scene.
type SetupWork<'a> = (
    usize,
    Option<((&'a mut [SetupTriangle], &'a mut BinBuffers), &'a [Piece])>,
);

/// What the setup split learns from one frame's chunks, as they are
/// gathered: each chunk's `(kept, rejected, seconds)` and when it ended
/// (seconds from `t1`, when the stage began), and when the last chunk's
/// frame was built (before binning).
struct Tally {
    t1: Instant,
    took: Vec<(u64, u64, f64)>,
    ends: Vec<f64>,
    built_at: Instant,
}

impl Tally {
    fn new(t1: Instant) -> Self {
        Tally {
            t1,
            took: Vec::new(),
            ends: Vec::new(),
            built_at: t1,
        }
    }

    /// A chunk with counters `s`, built at `built`, begun and ended at `span`.
    fn add(&mut self, s: Stats, built: Instant, span: Range<Instant>) {
        let rejected = s.submitted.saturating_sub(s.stored);
        let secs = |a: Instant, b: Instant| b.duration_since(a).as_secs_f64();
        self.took
            .push((s.stored, rejected, secs(span.start, span.end)));
        self.ends.push(secs(self.t1, span.end));
        self.built_at = self.built_at.max(built);
    }

    /// Moves `split` by this frame ([`SetupSplit::rebalance`], then
    /// [`SetupSplit::retune`]).
    fn tune(&self, split: &mut SetupSplit) {
        split.rebalance(&self.took, &self.ends);
        split.retune(&self.took);
    }
}

/// Grows each storage whose chunk needed `grow[i]` more entries (0: it
/// sufficed) by that, or by half its size if that is more.
fn grow_storages(storages: &mut [Vec<SetupTriangle>], grow: &[usize]) {
    for (storage, &g) in storages.iter_mut().zip(grow) {
        if g > 0 {
            let by = g.max(storage.len() / 2);
            storage.resize(storage.len() + by, SetupTriangle::EMPTY);
        }
    }
}

/// Where the workers of [`FramePipeline::render_fused`] wait for one
/// another between setup and drawing: each that sets up a chunk arrives
/// once (an [`Arrival`] dropped, also by a worker that panics), and
/// [`Gate::wait`] returns once all have. A waiter spins up to
/// [`SPIN_FOR`] (the others are mostly a few microseconds behind), then
/// sleeps.
struct Gate {
    workers: usize,
    arrived: AtomicUsize,
    lock: Mutex<()>,
    all: Condvar,
}

/// One worker's arrival at a [`Gate`], counted when dropped.
struct Arrival<'g>(&'g Gate);

impl Drop for Arrival<'_> {
    fn drop(&mut self) {
        let g = self.0;
        g.arrived.fetch_add(1, Ordering::Release);
        // Under the lock: a waiter checks the count and sleeps under it,
        // so it cannot miss this.
        let _held = lock(&g.lock);
        g.all.notify_all();
    }
}

impl Gate {
    fn new(workers: usize) -> Self {
        Gate {
            workers,
            arrived: AtomicUsize::new(0),
            lock: Mutex::new(()),
            all: Condvar::new(),
        }
    }

    fn arrival(&self) -> Arrival<'_> {
        Arrival(self)
    }

    fn wait(&self) {
        let all_in = || self.arrived.load(Ordering::Acquire) >= self.workers;
        let t = Instant::now();
        while !all_in() && t.elapsed() < SPIN_FOR {
            for _ in 0..64 {
                std::hint::spin_loop();
            }
        }
        let mut held = lock(&self.lock);
        while !all_in() {
            held = self.all.wait(held).unwrap_or_else(|p| p.into_inner());
        }
    }
}

fn ms(t: Instant) -> f64 {
    t.elapsed().as_secs_f64() * 1e3
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cliptris::ClipTri;
    use crate::scene::{clip_tris_scene, cubes_scene, View};
    use microraster::pixelcolor::{Rgb888, RgbColor};
    use microraster::CullMode;

    /// A strip or tile worker that panics on another thread than the
    /// caller's makes the call panic (it used to count 0 pixels and
    /// return `Ok`, the image half drawn). The caller's own strips take
    /// long enough that the other worker takes some of the 16.
    #[test]
    fn a_panicking_worker_panics_the_call() {
        let caller = std::thread::current().id();
        let f = |_| -> Result<u64, Error> {
            if std::thread::current().id() == caller {
                std::thread::sleep(std::time::Duration::from_millis(20));
                Ok(1)
            } else {
                panic!("worker");
            }
        };
        let (w, h) = (8usize, 16usize);
        let strips = std::panic::catch_unwind(|| {
            let mut color = vec![0u8; w * h];
            for_each_strip::<u8, u16, _>(&mut color, None, w, 1, 2, |y0, _, _| f(y0))
        });
        assert!(strips.is_err(), "strips: {strips:?}");
        let tiles = std::panic::catch_unwind(|| {
            let mut color = vec![0u8; w * h];
            for_each_tile::<u8, u16, _>(&mut color, None, w, (4, 2), 2, false, |t, _, _, _| f(t))
        });
        assert!(tiles.is_err(), "tiles: {tiles:?}");
    }

    /// [`Runs`] deals every item exactly once, whatever order the workers
    /// ask in; a worker's own run comes first, front to back, and then it
    /// takes the back item of the longest run left.
    #[test]
    fn runs_deal_every_item_once_own_run_first() {
        let mut seed = 0x9e37_79b9_u32;
        for n in 0..24usize {
            for workers in 1..6usize {
                let mut runs = Runs::new((0..n).map(|i| i * 10).collect(), workers);
                let mut owner = vec![usize::MAX; n];
                let mut own_runs: Vec<Vec<usize>> = vec![Vec::new(); workers];
                for w in 0..workers {
                    let r = w * n / workers..(w + 1) * n / workers;
                    for i in r {
                        owner[i] = w;
                    }
                }
                let mut seen = vec![false; n];
                let mut left = n;
                while left > 0 {
                    seed ^= seed << 13;
                    seed ^= seed >> 17;
                    seed ^= seed << 5;
                    let w = seed as usize % workers;
                    let longest = (0..workers).map(|v| runs.runs[v].len()).max().unwrap_or(0);
                    let own_left = runs.runs[w].len();
                    let (i, item) = runs.take(w).expect("items are left");
                    assert_eq!(item, i * 10);
                    assert!(!seen[i], "item {i} dealt twice");
                    seen[i] = true;
                    left -= 1;
                    if own_left > 0 {
                        assert_eq!(owner[i], w, "n {n}, {workers} workers");
                        if let Some(&last) = own_runs[w].last() {
                            assert_eq!(i, last + 1, "own run front to back");
                        }
                        own_runs[w].push(i);
                    } else {
                        let v = owner[i];
                        assert_eq!(runs.runs[v].len() + 1, longest, "from the longest run");
                        assert_eq!(runs.runs[v].end, i, "from its back");
                    }
                }
                for w in 0..workers {
                    assert!(runs.take(w).is_none());
                }
            }
        }
    }

    /// Weighed [`Runs`] split the work into runs of about equal cost, in
    /// order; each worker starts at its run's heavier half's end, the
    /// others take from the other end of the run with the most cost left;
    /// every item is dealt once. Weighing after a take changes nothing.
    #[test]
    fn weighed_runs_balance_cost_and_end_light() {
        let mut seed = 0x2545_f491_u32;
        let mut next = move || {
            seed ^= seed << 13;
            seed ^= seed >> 17;
            seed ^= seed << 5;
            seed
        };
        for n in 0..40usize {
            for workers in 1..5usize {
                // Every third case one heavy item, so that runs stay equal.
                let heavy = if n % 3 == 0 { 1000 } else { 0 };
                let cost: Vec<u64> = (0..n)
                    .map(|i| u64::from(next() % 50) + if i == n / 2 { heavy } else { 0 })
                    .collect();
                let mut runs = Runs::new((0..n).collect::<Vec<usize>>(), workers);
                runs.weigh(|i, &item| {
                    assert_eq!(i, item);
                    cost[i]
                });
                let total: u64 = cost.iter().sum();
                let most = cost.iter().copied().max().unwrap_or(0);
                let fine = most * 4 * workers as u64 <= total;
                let mut end = 0;
                for (w, r) in runs.runs.iter().enumerate() {
                    assert_eq!(r.start, end, "runs in order");
                    end = r.end;
                    let c: u64 = cost[r.clone()].iter().sum();
                    if fine {
                        let share = total / workers as u64;
                        assert!(c <= share + most + 1, "run {r:?} costs {c} of {total}");
                    } else {
                        assert_eq!(
                            *r,
                            w * n / workers..(w + 1) * n / workers,
                            "coarse: lengths"
                        );
                    }
                }
                assert_eq!(end, n);
                let own: Vec<Range<usize>> = runs.runs.clone();
                let mut seen = vec![false; n];
                let mut first = vec![true; workers];
                for _ in 0..n {
                    let w = next() as usize % workers;
                    let before = runs.runs.clone();
                    let left = |r: &Range<usize>| cost[r.clone()].iter().sum::<u64>();
                    let (i, item) = runs.take(w).expect("items are left");
                    assert_eq!(i, item);
                    assert!(!seen[i], "item {i} dealt twice");
                    seen[i] = true;
                    let v = (0..workers).find(|&v| own[v].contains(&i)).unwrap();
                    let down = runs.down[v];
                    if !before[w].is_empty() {
                        assert_eq!(v, w, "own run first");
                        let r = &own[w];
                        let mid = r.start + r.len() / 2;
                        let heavier_back = left(&(mid..r.end)) > left(&(r.start..mid));
                        assert_eq!(down, heavier_back);
                        if first[w] {
                            assert_eq!(i, if down { r.end - 1 } else { r.start });
                            first[w] = false;
                        }
                    } else {
                        let most_left = before.iter().map(left).max().unwrap();
                        assert_eq!(left(&before[v]), most_left, "the run with the most left");
                        let far = if down {
                            before[v].start
                        } else {
                            before[v].end - 1
                        };
                        assert_eq!(i, far, "from its other end");
                    }
                }
                assert!(seen.iter().all(|&s| s));
                for w in 0..workers {
                    assert!(runs.take(w).is_none());
                }
            }
        }
        let mut runs = Runs::new(vec![0, 1, 2, 3], 2);
        assert_eq!(runs.take(0).map(|t| t.0), Some(0));
        runs.weigh(|i, _| [0, 0, 0, 9][i]);
        assert_eq!(
            runs.runs,
            [1..2, 2..4],
            "weighing after a take changes nothing"
        );
    }

    /// [`each_on_threads`] gives the results in order, a panicked
    /// worker's as `Err`, and the others' all the same.
    #[test]
    fn each_on_threads_gives_results_in_order() {
        let out = each_on_threads((0..5).collect(), |i: u32| {
            if i == 3 {
                panic!("worker 3");
            }
            i * 2
        });
        assert_eq!(out.len(), 5);
        for (i, r) in out.into_iter().enumerate() {
            assert_eq!(r.is_err(), i == 3, "item {i}");
            if let Ok(v) = r {
                assert_eq!(v, i as u32 * 2);
            }
        }
    }

    /// A [`Gate`] opens once every worker has arrived, also when one
    /// arrived by panicking (its [`Arrival`] dropped as it unwound), and
    /// not before: the fused render's workers never wait for a worker that
    /// is gone, and never draw before every frame is published.
    #[test]
    fn a_gate_opens_when_every_worker_has_arrived_or_panicked() {
        let gate = Gate::new(3);
        let passed = AtomicUsize::new(0);
        let out = each_on_threads((0..3).collect(), |i: u32| {
            {
                let _arrive = gate.arrival();
                if i == 1 {
                    panic!("worker 1");
                }
                if i == 2 {
                    // The others reach the gate first and wait.
                    std::thread::sleep(std::time::Duration::from_millis(20));
                    assert_eq!(passed.load(Ordering::SeqCst), 0, "opened early");
                }
            }
            gate.wait();
            passed.fetch_add(1, Ordering::SeqCst);
        });
        assert!(out[1].is_err());
        assert!(out[0].is_ok() && out[2].is_ok(), "{out:?}");
        assert_eq!(passed.load(Ordering::SeqCst), 2);
    }

    /// `scene` rendered by a fresh 64x48 pipeline on `threads` threads:
    /// the pipeline, and the colour, depth, pixels written and counters.
    fn render_64x48(
        scene: &Scene,
        threads: usize,
    ) -> (FramePipeline<8>, (Vec<Rgb888>, Vec<u32>, u64, Stats)) {
        let mut pipe = FramePipeline::<8>::new(config(), threads, 5);
        let mut color = vec![Rgb888::BLACK; 64 * 48];
        let mut depth = vec![u32::MAX; 64 * 48];
        let (setup, _, px) = pipe
            .render(scene, &mut color, Some(&mut depth[..]), Rgb888::BLACK)
            .unwrap();
        (pipe, (color, depth, px, setup.stats))
    }

    /// A mesh of over [`VERTEX_CHUNK_MIN`] vertices and
    /// [`PARALLEL_SETUP_MIN_TRIANGLES`] triangles (vertex chunks taken by
    /// whichever worker is free, one setup frame per thread, binned by its
    /// worker): the same image, counters and pixels on 1, 2 and 3 threads,
    /// and with any weight of the setup split.
    #[test]
    fn a_mesh_split_over_threads_gives_the_same_image() {
        let view = View::new(64, 48);
        let (scene, _) = crate::bench_scenes::sphere_scene(&view, 100, 100).unwrap();
        assert!(scene.objects[0].positions.len() > 2 * VERTEX_CHUNK_MIN);
        assert!(scene.triangle_count() >= PARALLEL_SETUP_MIN_TRIANGLES);
        let mut images = Vec::new();
        for threads in [1, 2, 3] {
            let (pipe, image) = render_64x48(&scene, threads);
            assert_eq!(pipe.storages.len(), threads);
            images.push(image);
        }
        assert!(images[0].2 > 1000, "the sphere is drawn");
        assert!(images.windows(2).all(|w| w[0] == w[1]));
        // Frames after the first, on a pipeline whose setup split weighs a
        // kept triangle anywhere in its range: other chunks, the same image.
        let (mut pipe, _) = render_64x48(&scene, 2);
        // And with the first chunk's lead anywhere, even beyond the work.
        let weights = [KEPT_WORK_RANGE.0, KEPT_WORK, KEPT_WORK_RANGE.1].map(|k| (k, 0));
        let leads = [-(1 << 40), -5000, 5000, 1 << 40].map(|lead| (KEPT_WORK, lead));
        for (kept_work, lead) in weights.into_iter().chain(leads) {
            pipe.split.kept_work = kept_work;
            pipe.split.lead = lead;
            let mut color = vec![Rgb888::BLACK; 64 * 48];
            let mut depth = vec![u32::MAX; 64 * 48];
            let (setup, _, px) = pipe
                .render(&scene, &mut color, Some(&mut depth[..]), Rgb888::BLACK)
                .unwrap();
            let at = format!("weight {kept_work}, lead {lead}");
            assert_eq!((color, depth, px, setup.stats), images[0], "{at}");
        }
    }

    /// A clustered mesh is one setup chunk (submitted whole), fewer than
    /// the threads: the other threads only draw, and the image is the
    /// one thread's.
    #[test]
    fn fewer_setup_chunks_than_threads_give_the_same_image() {
        let view = View::new(64, 48);
        let (mut scene, _) = crate::bench_scenes::sphere_scene(&view, 100, 100).unwrap();
        let cull = microraster::ClusterCull::default();
        crate::cluster::cluster_scene(&mut scene, cull, &Default::default()).unwrap();
        assert!(scene.triangle_count() >= PARALLEL_SETUP_MIN_TRIANGLES);
        let (_, one) = render_64x48(&scene, 1);
        assert!(one.2 > 1000, "the sphere is drawn");
        for threads in [2, 3] {
            let (pipe, image) = render_64x48(&scene, threads);
            assert_eq!(pipe.storages.len(), 1, "one chunk");
            assert!(image == one, "{threads} threads");
        }
    }

    /// A triangle far beyond the guard band on three sides: clipped into
    /// several, so a run of them overflows the first storage guess.
    fn big() -> ClipTri {
        ClipTri {
            v: [
                [-1e7, -1e6, 0.0, 1.0],
                [1e7, -1e6, 0.0, 1.0],
                [0.0, 1e7, 0.0, 1.0],
            ],
            color: Some([200, 100, 50]),
        }
    }

    fn small(i: usize) -> ClipTri {
        let x = (i % 90) as f32 / 50.0 - 1.0;
        ClipTri {
            v: [
                [x, -0.5, 0.5, 1.0],
                [x + 0.2, -0.5, 0.5, 1.0],
                [x, 0.5, 0.5, 1.0],
            ],
            color: Some([(i % 251) as u8, 7, 9]),
        }
    }

    fn config() -> Config {
        let mut config = Config::new(64, 48);
        config.cull = CullMode::None;
        config
    }

    #[test]
    fn partition_covers_the_scene_in_order() {
        let mut scene = cubes_scene(&View::new(32, 24)).unwrap();
        scene.clip_tris = (0..10).map(small).collect();
        for parts in [1, 2, 3, 7, 100] {
            let chunks = partition(&scene, parts);
            assert!(chunks.len() <= parts.max(1), "{parts}: {chunks:?}");
            let flat: Vec<Piece> = chunks.into_iter().flatten().collect();
            assert!(flat.iter().all(|p| !p.is_empty()));
            assert_eq!(
                flat.iter().map(Piece::len).sum::<usize>(),
                scene.triangle_count()
            );
            // Contiguous: each piece starts where the last one of the same
            // source ended.
            let mut next = vec![0; scene.objects.len() + 1];
            for p in &flat {
                let (k, r) = match p {
                    Piece::Object(i, r) => (*i, r),
                    Piece::ClipTris(r) => (scene.objects.len(), r),
                };
                assert!(next[..k]
                    .iter()
                    .enumerate()
                    .all(|(j, &n)| n == scene.objects[j].indices.len()));
                assert_eq!(r.start, next[k]);
                next[k] = r.end;
            }
        }
    }

    /// Each run's estimate (kept or not) agrees with what the core keeps
    /// of the triangle that stands for it, for every triangle of the cubes
    /// taken in turn as the sample, with back and front faces culled; no
    /// culling counts every triangle as work 1.
    #[test]
    fn setup_work_says_what_the_core_keeps() {
        let scene = cubes_scene(&View::new(64, 48)).unwrap();
        for cull in [CullMode::Back, CullMode::Front, CullMode::None] {
            let mut config = Config::new(64, 48);
            config.cull = cull;
            let mut caches = Vec::new();
            let caches = vertex_stage::<8>(config, 1, &scene, &mut caches).unwrap();
            let mut kept_some = [false; 2];
            for (i, o) in scene.objects.iter().enumerate() {
                let n = o.indices.len();
                for k in 0..n {
                    let mut storage = vec![SetupTriangle::EMPTY; 16];
                    let mut f = Frame::<8>::new(config, &mut storage).unwrap();
                    let piece = [Piece::Object(i, k..k + 1)];
                    fill(&mut f, &scene, &piece, &caches, &mut Vec::new()).unwrap();
                    let core = !f.triangles().is_empty();
                    kept_some[core as usize] = true;
                    // The object with triangle k first.
                    let mut rotated = o.clone();
                    rotated.indices.rotate_left(k);
                    let work = setup_work(&rotated, &config, caches[i], KEPT_WORK);
                    let want = match (cull, core) {
                        (CullMode::None, _) => REJECTED_WORK,
                        (_, true) => KEPT_WORK,
                        (_, false) => REJECTED_WORK,
                    };
                    assert_eq!(work, vec![(n, want)], "{cull:?}: object {i} triangle {k}");
                }
            }
            assert_eq!(kept_some, [cull != CullMode::None, true], "{cull:?}");
        }
    }

    /// The first chunk's lead steps up when the other chunks end later,
    /// down when they end earlier, by the frame's work over
    /// [`LEAD_STEPS`], within a quarter of the work; a frame of one chunk,
    /// a tie, or ends that do not fit or are not finite change nothing.
    /// `partition_led` gives the first chunk that much more work.
    #[test]
    fn setup_split_leads_the_chunk_that_ends_first() {
        let mut split = SetupSplit::new();
        // Work 1000 * 24 + 1000 * 8 + 1000 * 8 = 40,000 units.
        let chunks = [(1000, 1000, 1e-3), (0, 1000, 1e-3)];
        let step = (40_000 / LEAD_STEPS) as i64;
        split.rebalance(&chunks, &[1.0e-3, 1.1e-3]);
        assert_eq!(split.lead, step);
        split.rebalance(&chunks, &[1.0e-3, 0.5e-3]);
        split.rebalance(&chunks, &[1.0e-3, 0.9e-3]);
        assert_eq!(split.lead, -step);
        for nothing in [
            (&chunks[..1], &[1.0e-3][..]),
            (&chunks[..], &[1.0e-3][..]),
            (&chunks[..], &[1.0e-3, 1.0e-3][..]),
            (&chunks[..], &[1.0e-3, f64::NAN][..]),
            (&chunks[..], &[f64::INFINITY, 1.0][..]),
        ] {
            split.rebalance(nothing.0, nothing.1);
            assert_eq!(split.lead, -step, "{nothing:?}");
        }
        for _ in 0..1000 {
            split.rebalance(&chunks, &[0.0, 1.0]);
        }
        assert_eq!(split.lead, 10_000, "a quarter of the work");
        // The lead in the partition: the first chunk's share grows by it.
        let scene = cubes_scene(&View::new(32, 24)).unwrap();
        let unit = |o: usize| vec![(scene.objects[o].indices.len(), 1)];
        let total = scene.triangle_count();
        let first = |lead| -> usize {
            partition_led(&scene, 2, unit, 1, lead)[0]
                .iter()
                .map(Piece::len)
                .sum()
        };
        assert_eq!(first(0), total.div_ceil(2));
        assert_eq!(first(2), total.div_ceil(2) + 2);
        assert_eq!(first(-2), total.div_ceil(2) - 2);
        assert_eq!(first(1 << 40), total);
        assert_eq!(first(-(1 << 40)), 1);
    }

    /// The estimate moves towards the ratio of the costs that made the
    /// chunks' times, a bounded step a frame, and converges on it; it
    /// stays where the chunks cannot tell the costs apart.
    #[test]
    fn setup_split_follows_the_measured_costs() {
        // Times of chunks of (kept, rejected) triangles at `a` and `b`
        // seconds each.
        let times = |a: f64, b: f64, chunks: &[(u64, u64)]| -> Vec<(u64, u64, f64)> {
            chunks
                .iter()
                .map(|&(k, r)| (k, r, a * k as f64 + b * r as f64))
                .collect()
        };
        let bunny = [(17_286, 4_023), (12_974, 35_168)];
        // A kept triangle at 5 rejected ones: 40 units.
        let at_5 = times(100e-9, 20e-9, &bunny);
        let mut split = SetupSplit::new();
        split.retune(&at_5);
        assert_eq!(split.kept_work, KEPT_WORK + 3);
        for _ in 0..40 {
            let k = split.kept_work;
            split.retune(&at_5);
            let next = split.kept_work;
            assert!(next >= k && next - k <= k / 8 + 1, "{k} -> {next}");
        }
        assert_eq!(split.kept_work, 5 * REJECTED_WORK);
        // Then downwards, with three chunks (least squares), as the older
        // frames fade.
        let at_2 = times(40e-9, 20e-9, &[(100, 900), (500, 500), (900, 100)]);
        for _ in 0..100 {
            split.retune(&at_2);
        }
        assert_eq!(split.kept_work, 2 * REJECTED_WORK);
        // Kept within its range.
        let mut split = SetupSplit::new();
        for _ in 0..100 {
            split.retune(&times(1e-6, 1e-9, &bunny));
        }
        assert_eq!(split.kept_work, KEPT_WORK_RANGE.1);
        let mut split = SetupSplit::new();
        for _ in 0..100 {
            split.retune(&times(1e-9, 1e-6, &bunny));
        }
        assert_eq!(split.kept_work, KEPT_WORK_RANGE.0);
        // Unchanged: no chunk or one, alike mixes, nothing rejected, a fit
        // that is not positive, and times that are not numbers (which are
        // not kept either).
        let unchanged: [&[(u64, u64, f64)]; 6] = [
            &[],
            &[(17_286, 4_023, 1e-3)],
            &[(1_000, 1_000, 1e-4), (2_000, 2_010, 2e-4)],
            &[(1_000, 0, 1e-4), (2_000, 0, 3e-4)],
            &[(17_286, 4_023, 1e-3), (12_974, 35_168, 1e-6)],
            &[(17_286, 4_023, f64::NAN), (12_974, 35_168, 1e-3)],
        ];
        for chunks in unchanged {
            let mut split = SetupSplit::new();
            split.retune(chunks);
            assert_eq!(split.kept_work, KEPT_WORK, "{chunks:?}");
        }
        let mut split = SetupSplit::new();
        split.retune(&[(1, 1, f64::INFINITY), (1, 2, 1.0)]);
        assert_eq!(split.sums, [0.0; 5]);
    }

    #[test]
    fn partition_by_work_balances_the_work_in_order() {
        let mut scene = cubes_scene(&View::new(32, 24)).unwrap();
        scene.clip_tris = (0..10).map(small).collect();
        let unit = |o: usize| vec![(scene.objects[o].indices.len(), 1)];
        // Alternating runs of 1 and 7 in every object.
        let uneven = |o: usize| {
            let n = scene.objects[o].indices.len();
            (0..n)
                .step_by(3)
                .map(|s| ((n - s).min(3), if s % 2 == 0 { 7 } else { 1 }))
                .collect::<Vec<_>>()
        };
        let work_of = |chunk: &[Piece]| -> u64 {
            chunk
                .iter()
                .map(|p| match p {
                    Piece::ClipTris(r) => r.len() as u64,
                    Piece::Object(o, r) => {
                        let mut at = 0;
                        let mut w = 0;
                        for (n, k) in uneven(*o) {
                            let (a, b) = (at.max(r.start), (at + n).min(r.end));
                            w += b.saturating_sub(a) as u64 * k;
                            at += n;
                        }
                        w
                    }
                })
                .sum()
        };
        let total = work_of(&partition(&scene, 1).concat());
        for parts in [1, 2, 3, 7, 100] {
            assert_eq!(
                partition_by(&scene, parts, unit, 1),
                partition(&scene, parts)
            );
            let chunks = partition_by(&scene, parts, uneven, 1);
            assert!(chunks.len() <= parts);
            // In order and whole: each piece starts where the one before
            // it ended or, at a new source, at 0 after the last one ended.
            let mut at = (0, 0);
            for p in chunks.concat() {
                let (k, r) = match p {
                    Piece::Object(i, r) => (i, r),
                    Piece::ClipTris(r) => (scene.objects.len(), r),
                };
                assert!(!r.is_empty());
                if k != at.0 {
                    assert_eq!(at.1, scene.objects[at.0].indices.len());
                    at = (k, 0);
                }
                assert_eq!(r.start, at.1, "{parts} parts");
                at.1 = r.end;
            }
            assert_eq!(at, (scene.objects.len(), scene.clip_tris.len()));
            // One piece per source a chunk.
            let source = |p: &Piece| match p {
                Piece::Object(i, _) => *i,
                Piece::ClipTris(_) => scene.objects.len(),
            };
            for c in &chunks {
                assert!(
                    c.windows(2).all(|w| source(&w[0]) != source(&w[1])),
                    "{c:?}"
                );
            }
            let per = total.div_ceil(parts as u64);
            for (k, c) in chunks.iter().enumerate() {
                let w = work_of(c);
                assert!(
                    w < per + 7,
                    "{parts} parts: chunk {k} has work {w} of {per}"
                );
                if k + 1 < chunks.len() {
                    assert!(w >= per, "{parts} parts: chunk {k} has work {w} of {per}");
                }
            }
        }
    }

    #[test]
    fn setup_storage_grows_for_clipped_triangles() {
        let scene = clip_tris_scene(vec![big(); 200]);
        for threads in [1, 2] {
            let mut pipe = FramePipeline::<8>::new(config(), threads, 16);
            let mut color = vec![Rgb888::BLACK; 64 * 48];
            let (setup, _, px) = pipe
                .render::<Rgb888, u32>(&scene, &mut color, None, Rgb888::BLACK)
                .unwrap();
            assert_eq!(setup.stats.clipped, 200);
            assert!(setup.stats.stored > 200 + 200 / 8 + 64, "{:?}", setup.stats);
            assert_eq!(px, 200 * 64 * 48);
            // Again, with the grown storage.
            let (again, _, _) = pipe
                .render::<Rgb888, u32>(&scene, &mut color, None, Rgb888::BLACK)
                .unwrap();
            assert_eq!(again.stats, setup.stats);
        }
    }

    #[test]
    fn one_full_chunk_among_several_gives_the_same_image() {
        // Parallel setup; only the last chunk overflows its storage.
        let mut tris: Vec<ClipTri> = (0..PARALLEL_SETUP_MIN_TRIANGLES).map(small).collect();
        tris.extend(std::iter::repeat_n(big(), 4000));
        tris.extend((0..50).map(small));
        let scene = clip_tris_scene(tris);
        let mut images = Vec::new();
        for threads in [1, 2, 3] {
            let (pipe, image) = render_64x48(&scene, threads);
            assert_eq!(image.3.clipped, 4000);
            // With parallel setup the first chunk kept its first guess and
            // the last one grew.
            let guesses: Vec<usize> = partition(&scene, threads)
                .iter()
                .map(|c| c.iter().map(Piece::len).sum::<usize>())
                .map(Frame::<8>::storage_for)
                .collect();
            assert_eq!(pipe.storages.len(), threads);
            if threads > 1 {
                assert_eq!(pipe.storages[0].len(), guesses[0]);
                assert!(pipe.storages[threads - 1].len() > guesses[threads - 1]);
            }
            images.push(image);
        }
        assert!(images.windows(2).all(|w| w[0] == w[1]));
    }
}
