//! The core's side of the report: one frame per configuration, timed.
//!
//! Design note: each of the eight configurations is a distinct
//! monomorphisation (sub-pixel bits and depth word are const and type
//! parameters); [`runner`] erases them behind one trait object, so the sweep
//! is a plain loop. Buffers are allocated before the clock starts.

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
    /// Depth per pixel.
    pub(crate) depth: Vec<u64>,
}

pub(crate) struct CoreInput<'a> {
    pub(crate) spec: &'a SceneSpec,
    pub(crate) objects: &'a [CoreObject],
    pub(crate) math: MathBackend,
    pub(crate) width: u32,
    pub(crate) height: u32,
}

/// One whole frame: matrices, setup, clear, all rows.
pub(crate) fn frame_once<const S: u32, C, T>(
    input: &CoreInput<'_>,
    storage: &mut [SetupTriangle],
    color: &mut [C],
    clear: C,
    depth: &mut [T],
) -> Result<(), Error>
where
    C: microraster::PixelFormat,
    T: DepthWord + Into<u64>,
    [T]: DepthBuffer,
{
    let (w, h) = (input.width, input.height);
    let mvps = mvps(input.spec, input.math, w, h);
    let mut frame = Frame::<S>::with_subpixel_bits(Config::new(w, h), storage)?;
    let mut id = 0u32;
    for (o, m) in input.objects.iter().zip(&mvps) {
        frame.submit_mesh(&o.mesh(), m, id)?;
        id = id.wrapping_add(o.indices.len() as u32);
    }
    color.fill(clear);
    depth.fill(T::FAR);
    frame.render_rows(0, h, color, depth)?;
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
    pub(crate) storage: Vec<SetupTriangle>,
    pub(crate) color: Vec<Rgb888>,
    pub(crate) depth: Vec<T>,
}

impl<'a, const S: u32, T> TypedRunner<'a, S, T>
where
    T: DepthWord + Into<u64>,
    [T]: DepthBuffer,
{
    /// Allocates everything and renders one frame to warm up (growing the
    /// setup storage until the frame fits).
    fn new(input: CoreInput<'a>) -> Result<Self, String> {
        let len = input.width as usize * input.height as usize;
        let n: usize = input.objects.iter().map(|o| o.indices.len()).sum();
        let mut r = TypedRunner {
            input,
            storage: vec![SetupTriangle::EMPTY; Frame::<8>::storage_for(n)],
            color: vec![Rgb888::BLACK; len],
            depth: vec![T::FAR; len],
        };
        loop {
            match frame_once::<S, _, T>(
                &r.input,
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
    T: DepthWord + Into<u64>,
    [T]: DepthBuffer,
{
    fn frame(&mut self) -> Result<f64, String> {
        let t = Instant::now();
        frame_once::<S, _, T>(
            &self.input,
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
        let mut id_depth = vec![T::FAR; len];
        frame_once::<S, _, T>(
            &self.input,
            &mut self.storage,
            &mut ids,
            TriangleId(0),
            &mut id_depth,
        )
        .map_err(|e| e.to_string())?;
        Ok(CoreRun {
            ids: ids.into_iter().map(|t| t.0).collect(),
            color: self.color.clone(),
            depth: self.depth.iter().map(|&d| d.into()).collect(),
        })
    }
}

/// A warmed-up runner for configuration `c`.
pub(crate) fn runner<'a>(
    input: CoreInput<'a>,
    c: Configuration,
) -> Result<Box<dyn Runner + 'a>, String> {
    Ok(match (c.subpixel, c.depth_bits) {
        (4, 16) => Box::new(TypedRunner::<4, u16>::new(input)?),
        (4, 32) => Box::new(TypedRunner::<4, u32>::new(input)?),
        (8, 16) => Box::new(TypedRunner::<8, u16>::new(input)?),
        (8, 32) => Box::new(TypedRunner::<8, u32>::new(input)?),
        (s, d) => return Err(format!("unsupported configuration S={s} depth u{d}")),
    })
}
