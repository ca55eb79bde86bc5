//! The core's side of the report: one frame per configuration, timed.
//!
//! Design note: each configuration of the grid is a distinct
//! monomorphisation (sub-pixel bits and depth word are const and type
//! parameters); [`runner`] erases them behind one trait object, so the sweep
//! is a plain loop. Buffers are allocated before the clock starts, except
//! what only the variants use: the tile bins and tile buffers, and the
//! immediate mode's vertex caches, are allocated inside each frame (part
//! of their cost here).

use super::*;
use microraster::prelude::Submit;
use microraster::DepthWord;

// ---------------------------------------------------------------------------
// The core's pipeline

/// One mesh in the core's types.
pub(crate) struct CoreObject {
    pub(crate) positions: Vec<Vec3>,
    pub(crate) indices: Vec<[u32; 3]>,
    pub(crate) colors: Vec<Rgb888>,
    pub(crate) bounds: Option<BoundingSphere>,
}

impl CoreObject {
    pub(crate) fn new(o: &SpecObject) -> Self {
        let positions: Vec<Vec3> = o.positions.iter().map(|&p| Vec3::from_array(p)).collect();
        CoreObject {
            bounds: BoundingSphere::from_points(&positions),
            positions,
            indices: o.indices.clone(),
            colors: o.colors.clone(),
        }
    }

    pub(crate) fn mesh(&self) -> Mesh<'_> {
        Mesh {
            positions: &self.positions,
            indices: &self.indices,
            attributes: MeshColors::PerVertex(&self.colors),
            bounds: self.bounds,
        }
    }
}

/// What the core drew.
pub(crate) struct CoreRun {
    /// Triangle id + 1 per pixel.
    pub(crate) ids: Vec<u32>,
    /// Colour per pixel.
    pub(crate) color: Vec<Rgb888>,
    /// Depth per pixel, in units of `2^-bits` ([`Configuration::compare_bits`]):
    /// the word itself for `u16` and `u32`, `Z32.16` for `f32` (exact).
    pub(crate) depth: Vec<u64>,
}

/// A depth word the report reads back as an integer of its comparison
/// units ([`Configuration::compare_bits`]).
pub(crate) trait ReportDepth: DepthWord {
    /// The stored depth in units of `2^-bits`.
    fn units(self) -> u64;
}

impl ReportDepth for u16 {
    fn units(self) -> u64 {
        self as u64
    }
}

impl ReportDepth for u32 {
    fn units(self) -> u64 {
        self as u64
    }
}

/// `value * 2^48`: exact, every `f32` the buffer holds is a multiple of
/// `2^-48`.
impl ReportDepth for microraster::DepthF32 {
    fn units(self) -> u64 {
        (self.get() as f64 * (1u64 << 48) as f64) as u64
    }
}

pub(crate) struct CoreInput<'a> {
    pub(crate) spec: &'a SceneSpec,
    pub(crate) objects: &'a [CoreObject],
    pub(crate) math: MathBackend,
    pub(crate) width: u32,
    pub(crate) height: u32,
}

/// One whole frame: matrices, setup, clear, all rows, as `variant` says
/// (1/w depth where the scene's camera asks for it).
pub(crate) fn frame_once<const S: u32, C, T>(
    input: &CoreInput<'_>,
    variant: Variant,
    storage: &mut [SetupTriangle],
    color: &mut [C],
    clear: C,
    depth: &mut [T],
) -> Result<(), Error>
where
    C: microraster::PixelFormat,
    T: ReportDepth,
    [T]: DepthBuffer,
{
    let (w, h) = (input.width, input.height);
    let mvps = mvps(input.spec, input.math, w, h);
    let mut config = Config::new(w, h);
    let far = if input.spec.camera.inv_w {
        config.depth_func = microraster::DepthFunc::Greater;
        T::from_z32(0)
    } else {
        T::FAR
    };
    color.fill(clear);
    depth.fill(far);
    if variant == Variant::Clipless {
        config.mode = microraster::RasterMode::Clipless;
    }
    if matches!(variant, Variant::Clipless | Variant::Immediate) {
        return immediate_frame::<S, C, T>(input, config, &mvps, color, depth);
    }
    let mut frame = Frame::<S>::with_subpixel_bits(config, storage)?;
    let mut id = 0u32;
    for (o, m) in input.objects.iter().zip(&mvps) {
        frame.submit_mesh(&o.mesh(), m, id)?;
        id = id.wrapping_add(o.indices.len() as u32);
    }
    let Variant::Tiles(n) = variant else {
        frame.render_rows(0, h, color, depth)?;
        return Ok(());
    };
    let mut offsets = vec![0u32; frame.tiles(n, n) + 1];
    let mut items = vec![0u32; frame.tile_bin_entries(n, n)];
    let bins = frame.bin_tiles(n, n, &mut offsets, &mut items)?;
    let side = n as usize;
    let (mut tc, mut td) = (vec![clear; side * side], vec![far; side * side]);
    for t in 0..frame.tiles(n, n) as u32 {
        let [x0, x1, y0, y1] = bins.rect(t);
        let tw = (x1 - x0) as usize;
        let len = tw * (y1 - y0) as usize;
        tc[..len].fill(clear);
        td[..len].fill(far);
        frame.render_tile(&bins, t, &mut tc[..len], &mut td[..len])?;
        for (r, y) in (y0..y1).enumerate() {
            let at = y as usize * w as usize + x0 as usize;
            color[at..at + tw].copy_from_slice(&tc[r * tw..(r + 1) * tw]);
            depth[at..at + tw].copy_from_slice(&td[r * tw..(r + 1) * tw]);
        }
    }
    Ok(())
}

/// An immediate-mode frame (either mode): the vertex stage once, then
/// every strip of [`CLIPLESS_STRIP_ROWS`] rows drawn by a strip renderer
/// that submits the scene again (the triangles outside the strip are
/// skipped before setup).
fn immediate_frame<const S: u32, C, T>(
    input: &CoreInput<'_>,
    config: Config,
    mvps: &[microraster::Mat4],
    color: &mut [C],
    depth: &mut [T],
) -> Result<(), Error>
where
    C: microraster::PixelFormat,
    T: ReportDepth,
    [T]: DepthBuffer,
{
    let w = input.width as usize;
    let mut row = vec![TriangleId(0); w];
    let mut none = microraster::NoDepth;
    let probe = microraster::StripRenderer::<_, _, S>::with_subpixel_bits(
        config, 0, 1, &mut row, &mut none,
    )?;
    let caches: Vec<Vec<microraster::ProcessedVertex>> = input
        .objects
        .iter()
        .zip(mvps)
        .map(|(o, m)| {
            let mut c = vec![microraster::ProcessedVertex::EMPTY; o.positions.len()];
            probe.process_vertices(m, &o.positions, &mut c);
            c
        })
        .collect();
    let chunk = w * CLIPLESS_STRIP_ROWS as usize;
    for (k, (c, d)) in color
        .chunks_mut(chunk)
        .zip(depth.chunks_mut(chunk))
        .enumerate()
    {
        let y0 = k as u32 * CLIPLESS_STRIP_ROWS;
        let y1 = y0 + (c.len() / w) as u32;
        let mut r =
            microraster::StripRenderer::<C, [T], S>::with_subpixel_bits(config, y0, y1, c, d)?;
        let mut id = 0u32;
        for (o, cache) in input.objects.iter().zip(&caches) {
            r.submit_processed_mesh(&o.mesh(), id, cache)?;
            id = id.wrapping_add(o.indices.len() as u32);
        }
    }
    Ok(())
}

/// Renders one configuration's frames. The report times the
/// configurations round-robin (one frame of each in turn), so that a burst
/// of load on the machine spreads over all of them instead of skewing one.
pub(crate) trait Runner {
    /// Renders one frame; returns its time in milliseconds.
    fn frame(&mut self) -> Result<f64, String>;
    /// The colour and depth of the last frame, and the triangle-id image.
    fn finish(&mut self) -> Result<CoreRun, String>;
}

pub(crate) struct TypedRunner<'a, const S: u32, T> {
    pub(crate) input: CoreInput<'a>,
    pub(crate) variant: Variant,
    pub(crate) storage: Vec<SetupTriangle>,
    pub(crate) color: Vec<Rgb888>,
    pub(crate) depth: Vec<T>,
}

impl<'a, const S: u32, T> TypedRunner<'a, S, T>
where
    T: ReportDepth,
    [T]: DepthBuffer,
{
    /// Allocates everything and renders one frame to warm up (growing the
    /// setup storage until the frame fits).
    fn new(input: CoreInput<'a>, variant: Variant) -> Result<Self, String> {
        let len = input.width as usize * input.height as usize;
        let n: usize = input.objects.iter().map(|o| o.indices.len()).sum();
        let mut r = TypedRunner {
            input,
            variant,
            storage: vec![SetupTriangle::EMPTY; Frame::<8>::storage_for(n)],
            color: vec![Rgb888::BLACK; len],
            depth: vec![T::FAR; len],
        };
        loop {
            match frame_once::<S, _, T>(
                &r.input,
                r.variant,
                &mut r.storage,
                &mut r.color,
                Rgb888::BLACK,
                &mut r.depth,
            ) {
                Ok(()) => return Ok(r),
                Err(Error::StorageFull { needed, .. }) => {
                    let grow = needed.max(r.storage.len() / 2);
                    r.storage
                        .resize(r.storage.len() + grow, SetupTriangle::EMPTY);
                }
                Err(e) => return Err(e.to_string()),
            }
        }
    }
}

impl<const S: u32, T> Runner for TypedRunner<'_, S, T>
where
    T: ReportDepth,
    [T]: DepthBuffer,
{
    fn frame(&mut self) -> Result<f64, String> {
        let t = Instant::now();
        frame_once::<S, _, T>(
            &self.input,
            self.variant,
            &mut self.storage,
            &mut self.color,
            Rgb888::BLACK,
            &mut self.depth,
        )
        .map_err(|e| e.to_string())?;
        std::hint::black_box((&self.color, &self.depth));
        Ok(t.elapsed().as_secs_f64() * 1e3)
    }

    fn finish(&mut self) -> Result<CoreRun, String> {
        let len = self.color.len();
        let mut ids = vec![TriangleId(0); len];
        let mut id_depth = self.depth.clone();
        frame_once::<S, _, T>(
            &self.input,
            self.variant,
            &mut self.storage,
            &mut ids,
            TriangleId(0),
            &mut id_depth,
        )
        .map_err(|e| e.to_string())?;
        Ok(CoreRun {
            ids: ids.into_iter().map(|t| t.0).collect(),
            color: self.color.clone(),
            depth: self.depth.iter().map(|&d| d.units()).collect(),
        })
    }
}

/// A warmed-up runner for configuration `c`.
pub(crate) fn runner<'a>(
    input: CoreInput<'a>,
    c: Configuration,
) -> Result<Box<dyn Runner + 'a>, String> {
    let v = c.variant;
    Ok(match (c.subpixel, c.depth_bits, c.float_depth) {
        (4, 16, false) => Box::new(TypedRunner::<4, u16>::new(input, v)?),
        (4, 32, false) => Box::new(TypedRunner::<4, u32>::new(input, v)?),
        (8, 16, false) => Box::new(TypedRunner::<8, u16>::new(input, v)?),
        (8, 32, false) => Box::new(TypedRunner::<8, u32>::new(input, v)?),
        (8, 32, true) => Box::new(TypedRunner::<8, microraster::DepthF32>::new(input, v)?),
        (s, d, f) => {
            return Err(format!(
                "unsupported configuration S={s} depth {d} bits (float {f})"
            ))
        }
    })
}
