//! Submission: one path from clip-space triangles (or meshes) to set-up
//! triangles, shared by [`Frame`](crate::Frame) and
//! [`StripRenderer`](crate::StripRenderer).
//!
//! Design note: both types implement [`Submit`], whose provided methods are
//! the only submission code in the crate. A submission runs
//! `object cull -> (vertex stage) -> outcodes -> frustum cull -> strip skip
//! -> clip -> snap -> setup` and hands every set-up piece to the receiver's
//! sink: a [`Frame`](crate::Frame) stores it, a
//! [`StripRenderer`](crate::StripRenderer) draws it into its strip at once.
//!
//! All or nothing: before a submission writes anything it knows it fits.
//! A triangle yields at most [`MAX_PIECES`] set-up pieces (one unless it is
//! clipped); when the free room of a frame's storage is below that bound
//! the submission is first run without storing, to count its pieces, and
//! refused with [`Error::StorageFull`] (the true count in it) if they do not
//! fit. So a failed submission writes no storage slot and no counter.

use crate::clip::{clip_triangle, outcode, ClipVertex};
use crate::config::{Error, RasterMode};
use crate::cull::{traverse, Cluster, ClusterCull, ClusterSet, Detail, Eye, Visit};
use crate::fixed::{snap, SnappedVertex};
use crate::math::{Mat4, Vec3, Vec4};
use crate::mesh::{process_vertices, Mesh, ProcessedVertex, BATCH, NONFINITE};
use crate::normal_mask::{BackMask, NormalClasses};
use crate::setup::{inv_w3, setup, setup_geometry, triangulate, Rejected, SetupTriangle};
use crate::shade::{Attributes, Varyings};
use crate::stats::Stats;

/// The most set-up pieces one submitted triangle can become (a triangle
/// clipped by near, far and four guard-band planes is a polygon of at most
/// nine vertices: seven fan pieces).
pub const MAX_PIECES: usize = 7;

/// Internals of [`Submit`]: not part of the API.
#[doc(hidden)]
pub mod __private {
    use crate::clipless::ClipLessTriangle;
    use crate::config::Config;
    use crate::math::Vec4;
    use crate::setup::SetupTriangle;
    use crate::stats::Stats;

    pub use crate::frame::Store;
    pub use crate::strip_renderer::StripSink;

    /// What a submission needs to know about its receiver that does not change
    /// while it runs.
    #[derive(Clone, Copy, Debug)]
    pub struct Stage {
        /// The frame's settings.
        pub(crate) config: Config,
        /// The guard band in NDC units (see [`crate::fixed::guard_band_ndc`]).
        pub(crate) guard: (f32, f32),
        /// For a strip renderer not covering the whole frame: NDC y above which
        /// (`.0`) and below which (`.1`) a vertex lies beyond the strip, with
        /// a quarter-pixel margin. `None` skips nothing.
        pub(crate) slab: Option<(f32, f32)>,
    }

    impl Stage {
        pub(crate) fn new<const S: u32>(config: Config, slab: Option<(f32, f32)>) -> Stage {
            Stage {
                config,
                guard: crate::fixed::guard_band_ndc::<S>(config.width, config.height),
                slab,
            }
        }

        /// Whether a triangle (in front of the eye, inside no frustum plane's
        /// outside) lies wholly above or below the strip: then no pixel centre
        /// of the strip can be covered. The quarter-pixel margin dwarfs float
        /// rounding and snapping (half a subpixel), so this never decides
        /// coverage.
        #[inline]
        pub(crate) fn outside_strip(&self, p: [Vec4; 3]) -> bool {
            match self.slab {
                None => false,
                Some((top, bottom)) => {
                    p.iter().all(|v| v.w > 0.0)
                        && (p.iter().all(|v| v.y > v.w * top)
                            || p.iter().all(|v| v.y < v.w * bottom))
                }
            }
        }
    }

    /// Where set-up pieces (with `N` varyings) go.
    pub trait Sink<const N: usize> {
        /// Pieces it can still take (`usize::MAX` for no limit).
        fn room(&self) -> usize;
        /// Its total capacity, for [`Error::StorageFull`](crate::Error).
        fn capacity(&self) -> usize;
        /// Takes one piece; called only while `room() > 0`.
        fn take(&mut self, t: &SetupTriangle<N>);
        /// Takes one clipless triangle ([`RasterMode::Clipless`]); called
        /// only while `room() > 0`. Receivers that cannot draw them refuse
        /// the mode when they are made, so by default it is dropped.
        ///
        /// [`RasterMode::Clipless`]: crate::RasterMode::Clipless
        fn take_clipless(&mut self, t: &ClipLessTriangle<N>) {
            let _ = t;
        }
    }

    /// A receiver's parts, borrowed for one submission.
    #[derive(Debug)]
    pub struct Parts<'a, K: ?Sized> {
        pub(crate) stage: &'a Stage,
        pub(crate) stats: &'a mut Stats,
        pub(crate) sink: &'a mut K,
    }
}

pub(crate) use __private::Stage;
use __private::{Parts, Sink};

/// Counts pieces instead of taking them: the dry run of a submission that
/// might not fit.
struct Counter(usize);

impl<const N: usize> Sink<N> for Counter {
    fn room(&self) -> usize {
        usize::MAX
    }
    fn capacity(&self) -> usize {
        usize::MAX
    }
    fn take(&mut self, _: &SetupTriangle<N>) {
        self.0 = self.0.saturating_add(1);
    }
    fn take_clipless(&mut self, _: &crate::clipless::ClipLessTriangle<N>) {
        self.0 = self.0.saturating_add(1);
    }
}

/// Submitting triangles and meshes: implemented by
/// [`Frame`](crate::Frame), which stores the set-up triangles to render
/// any rows later, and by [`StripRenderer`](crate::StripRenderer), which
/// draws them into its strip at once. `S` is the receiver's subpixel
/// precision, `N` the number of varyings per vertex (3 by default: a
/// colour; see [`crate::shade`]).
///
/// Every method is all or nothing: on an error nothing of the submission
/// is stored, drawn or counted. Triangle ids (see
/// [`TriangleId`](crate::TriangleId)) are the caller's: a mesh's triangle
/// `i` gets `first_id + i` (wrapping).
pub trait Submit<const S: u32 = 8, const N: usize = 3> {
    /// The receiver's sink (internal).
    #[doc(hidden)]
    type Sink: Sink<N>;

    /// The receiver's parts (internal).
    #[doc(hidden)]
    fn parts(&mut self) -> Parts<'_, Self::Sink>;

    /// The receiver's stage (internal).
    #[doc(hidden)]
    fn stage(&self) -> &Stage;

    /// Submits one clip-space triangle (positions and varyings).
    fn submit_triangle(&mut self, tri: [ClipVertex<N>; 3], id: u32) -> Result<(), Error> {
        let job = TriangleJob { tri, id };
        run_job::<S, N, _, _>(self.parts(), &job)
    }

    /// Submits one clip-space triangle with varyings per vertex: a colour
    /// ([`Rgb888`](crate::pixelcolor::Rgb888)) for the default shading,
    /// or `[f32; N]`.
    fn submit_clip_triangle<V: Varyings<N>>(
        &mut self,
        pos: [Vec4; 3],
        varyings: [V; 3],
        id: u32,
    ) -> Result<(), Error> {
        let tri = core::array::from_fn(|k| ClipVertex {
            pos: pos[k],
            varyings: varyings[k].varyings(),
        });
        self.submit_triangle(tri, id)
    }

    /// Submits every triangle of `mesh`, transformed by `mvp` (object to
    /// clip space), one triangle at a time. The bounding sphere, if given,
    /// is tested first: an object entirely outside the frustum is counted
    /// in [`Stats::culled_object`] without transforming a vertex.
    fn submit_mesh<A: Attributes<N>>(
        &mut self,
        mesh: &Mesh<'_, A>,
        mvp: &Mat4,
        first_id: u32,
    ) -> Result<(), Error> {
        let n = check_mesh_len(mesh.indices.len())?;
        let mut parts = self.parts();
        if culled_object::<S, N, _, _>(&mut parts, mesh, mvp, n, first_id)? {
            return Ok(());
        }
        let job = MeshJob {
            mesh,
            mvp,
            first_id,
            mask: NoMask,
        };
        run_job::<S, N, _, _>(parts, &job)
    }

    /// Like [`Submit::submit_mesh`] (no vertex cache: each triangle's
    /// vertices are transformed as it is submitted), with the lecture's
    /// normal masks for a caller that builds the mask itself, once for
    /// many submissions: a triangle whose class (`classes[i]` for
    /// triangle `i`) is in `mask` is counted in [`Stats::culled_mask`]
    /// and nothing of it is read. For firmware that submits a mesh in
    /// runs, each with its sphere, and has no room for a vertex cache.
    ///
    /// `mask` must be this receiver's [`Submit::back_mask`] for the same
    /// `mvp` and class data, or the mask of a sector that holds this
    /// receiver's rows (a [`Frame`](crate::Frame)'s, of the whole
    /// viewport, serves every strip): then the frame is the one
    /// `submit_mesh` draws. `classes` must hold one class per triangle
    /// (else [`Error::InvalidNormalClasses`], nothing done); an id beyond
    /// the mask's classes is never masked. Nothing is masked under
    /// [`CullMode::None`](crate::CullMode) or in the clipless mode, as
    /// with [`Submit::submit_masked`].
    fn submit_mesh_masked<A: Attributes<N>>(
        &mut self,
        mesh: &Mesh<'_, A>,
        mvp: &Mat4,
        classes: &[u16],
        mask: &BackMask,
        first_id: u32,
    ) -> Result<(), Error> {
        let n = check_mesh_len(mesh.indices.len())?;
        if classes.len() != mesh.indices.len() {
            return Err(Error::InvalidNormalClasses(
                crate::normal_mask::ClassFault::Triangles,
            ));
        }
        let config = &self.stage().config;
        let mask = if config.cull == crate::config::CullMode::None
            || config.mode == RasterMode::Clipless
        {
            &BackMask::EMPTY
        } else {
            mask
        };
        let mut parts = self.parts();
        if culled_object::<S, N, _, _>(&mut parts, mesh, mvp, n, first_id)? {
            return Ok(());
        }
        let job = MeshJob {
            mesh,
            mvp,
            first_id,
            mask: ClassMask { classes, mask },
        };
        run_job::<S, N, _, _>(parts, &job)
    }

    /// Like [`Submit::submit_mesh`], with every vertex transformed,
    /// outcoded and snapped once instead of once per triangle that uses it:
    /// the fast path for indexed meshes. `cache` is scratch space of at
    /// least `mesh.positions.len()` entries. The result is identical.
    fn submit_mesh_cached<A: Attributes<N>>(
        &mut self,
        mesh: &Mesh<'_, A>,
        mvp: &Mat4,
        first_id: u32,
        cache: &mut [ProcessedVertex],
    ) -> Result<(), Error> {
        let n = check_mesh_len(mesh.indices.len())?;
        let cache = sized_cache(cache, mesh.positions.len())?;
        if culled_object::<S, N, _, _>(&mut self.parts(), mesh, mvp, n, first_id)? {
            return Ok(());
        }
        self.process_vertices(mvp, mesh.positions, cache);
        self.submit_processed_mesh(mesh, first_id, cache)
    }

    /// Like [`Submit::submit_mesh_cached`], with the mesh's clusters
    /// tested first (see [`crate::cull`]): a cluster that is wholly
    /// back-facing is counted in [`Stats::culled_cluster`] (or
    /// [`Stats::culled_hierarchy`], skipped by an inner node of the tree
    /// when `cull.hierarchy` is set) without transforming any of its
    /// vertices; the others are processed into `cache` (at their vertex
    /// ranges) and submitted as by `submit_mesh_cached`. For set data that
    /// bounds its triangles the frame is the one `submit_mesh_cached`
    /// draws: the margin and size guard of [`Eye::for_frame`] skip only
    /// triangles it culls by winding (see [`crate::cull`]); data that does
    /// not fit the mesh is refused with
    /// [`Error::InvalidClusters`] before anything is done. Nothing is
    /// culled by facing under [`CullMode::None`](crate::CullMode).
    /// Detail culling ([`Config::detail`](crate::Config::detail), lossy,
    /// off by default) drops nodes too small on screen in any cull mode
    /// (see [`Detail`]), counted in [`Stats::culled_detail`]; the frame is
    /// then no longer the per-triangle one.
    fn submit_clusters<A: Attributes<N>>(
        &mut self,
        mesh: &Mesh<'_, A>,
        mvp: &Mat4,
        set: &ClusterSet<'_>,
        cull: ClusterCull,
        first_id: u32,
        cache: &mut [ProcessedVertex],
    ) -> Result<(), Error> {
        let n = check_mesh_len(mesh.indices.len())?;
        let cache = sized_cache(cache, mesh.positions.len())?;
        set.validate(mesh.indices.len(), mesh.positions.len())?;
        if culled_object::<S, N, _, _>(&mut self.parts(), mesh, mvp, n, first_id)? {
            return Ok(());
        }
        // Facing is decided by snapped areas in the clipping mode, which
        // the size guard bounds; the clipless mode's determinants are not
        // bounded so, so there clusters are culled by detail only.
        let eye = match self.stage().config.mode {
            RasterMode::Clipping => Eye::for_frame::<S>(mvp, &self.stage().config),
            RasterMode::Clipless => None,
        };
        let eye = eye.map(|e| mesh.bounds.map_or(e, |b| e.within(&b)));
        let detail = Detail::for_frame(mvp, &self.stage().config);
        let list = set.vertices;
        if !list.is_empty() && detail.is_none() {
            let parts = self.parts();
            // Room for every piece the mesh could make: no dry run, so the
            // tree is walked once (see `submit_clusters_in_one_walk`).
            if parts.sink.room() >= mesh.indices.len().saturating_mul(MAX_PIECES) {
                submit_clusters_in_one_walk::<S, N, _, _>(
                    parts, mesh, mvp, set, eye, cull, first_id, cache,
                );
                return Ok(());
            }
        }
        // The walk's visits, recorded (where they fit) so that drawing
        // replays them instead of testing every node again.
        let mut record = WalkRecord::new();
        let mut drawn = |f: &mut dyn FnMut(&Cluster)| {
            traverse(set, eye.as_ref(), detail.as_ref(), cull, |v| {
                record.push(v);
                if let Visit::Draw(a, b) = v {
                    set.clusters
                        .get(a..b)
                        .unwrap_or(&[])
                        .iter()
                        .for_each(&mut *f);
                }
            })
        };
        if list.is_empty() {
            drawn(&mut |k| {
                let [v0, v1] = k.vertices.map(|v| v as usize);
                if let (Some(p), Some(out)) = (mesh.positions.get(v0..v1), cache.get_mut(v0..v1)) {
                    self.process_vertices(mvp, p, out);
                }
            });
        } else {
            // The drawn clusters' vertices marked stale in one walk, then
            // every stale entry processed, in runs, by one pass over the
            // cache (no second walk of the tree). An entry found stale is
            // one marked now or a non-finite vertex of an earlier frame
            // (processing it again gives the same entry); no other entry
            // is read (a triangle using one the list misses meets a stale
            // or old entry: see `Cluster::vertices`).
            drawn(&mut |k| {
                let ids = list.get(k.vertices[0] as usize..k.vertices[1] as usize);
                for &id in ids.unwrap_or(&[]) {
                    if let Some(out) = cache.get_mut(id as usize) {
                        *out = ProcessedVertex::STALE;
                    }
                }
            });
            process_stale(self, mvp, mesh.positions, cache);
        }
        let job = ClusterJob {
            inner: ProcessedJob {
                mesh,
                first_id,
                cache,
            },
            set,
            eye,
            detail,
            cull,
            record: record.complete(),
        };
        run_job::<S, N, _, _>(self.parts(), &job)
    }

    /// The [`BackMask`] that [`Submit::submit_masked`] applies to a mesh
    /// drawn with `mvp` and classified by `classes`: of the receiver's
    /// rows for a strip renderer (its sector), of the whole viewport for
    /// a [`Frame`](crate::Frame); empty in the clipless mode. For firmware
    /// that submits a mesh in runs without a vertex cache: a triangle of a
    /// class in the mask may be left out of the runs, and the frame is the
    /// same (as `submit_masked` leaves it out). Its classes are not
    /// checked against a mesh here ([`NormalClasses::validate`]).
    fn back_mask(&self, mvp: &Mat4, classes: &NormalClasses<'_>) -> BackMask {
        let stage = self.stage();
        match stage.config.mode {
            RasterMode::Clipping => {
                BackMask::for_frame::<S>(mvp, &stage.config, stage.slab, classes)
            }
            RasterMode::Clipless => BackMask::EMPTY,
        }
    }

    /// Like [`Submit::submit_mesh_cached`], with the lecture's normal
    /// masks (see [`crate::normal_mask`]): a triangle whose normal class
    /// is in this frame's [`BackMask`] (of the receiver's strip, for a
    /// strip renderer) is counted in [`Stats::culled_mask`] without being
    /// looked at further, and only the vertices of the others are
    /// processed. For class data that fits the triangles the frame is the
    /// one `submit_mesh_cached` draws (the mask's margin and size guard
    /// skip only triangles it culls by winding, or that show nothing in
    /// the sector); data that does not fit the mesh is refused with
    /// [`Error::InvalidNormalClasses`] before anything is done. Nothing is
    /// masked under [`CullMode::None`](crate::CullMode) or in the
    /// clipless mode.
    fn submit_masked<A: Attributes<N>>(
        &mut self,
        mesh: &Mesh<'_, A>,
        mvp: &Mat4,
        classes: &NormalClasses<'_>,
        first_id: u32,
        cache: &mut [ProcessedVertex],
    ) -> Result<(), Error> {
        let n = check_mesh_len(mesh.indices.len())?;
        let cache = sized_cache(cache, mesh.positions.len())?;
        classes.validate(mesh.indices.len())?;
        if culled_object::<S, N, _, _>(&mut self.parts(), mesh, mvp, n, first_id)? {
            return Ok(());
        }
        let mask = self.back_mask(mvp, classes);
        if mask.is_empty() {
            self.process_vertices(mvp, mesh.positions, cache);
            return self.submit_processed_mesh(mesh, first_id, cache);
        }
        // The kept triangles' vertices marked stale, then processed in
        // runs (as `submit_clusters` does with a vertex list; an old
        // non-finite entry is processed again, to the same entry): a kept
        // triangle reads only entries processed now.
        for (idx, &c) in mesh.indices.iter().zip(classes.classes) {
            if !mask.contains(c) {
                for &k in idx {
                    if let Some(out) = cache.get_mut(k as usize) {
                        *out = ProcessedVertex::STALE;
                    }
                }
            }
        }
        process_stale(self, mvp, mesh.positions, cache);
        let job = MaskJob {
            inner: ProcessedJob {
                mesh,
                first_id,
                cache,
            },
            classes: classes.classes,
            mask,
        };
        run_job::<S, N, _, _>(self.parts(), &job)
    }

    /// The vertex stage of [`Submit::submit_mesh_cached`] alone: transforms,
    /// outcodes and snaps `positions` into `out` (pairwise; extra entries of
    /// either are left alone). The result depends only on the frame's
    /// configuration, so chunks of one mesh can be processed in parallel,
    /// and a strip renderer can process a mesh once per frame and draw it
    /// into every strip.
    fn process_vertices(&self, mvp: &Mat4, positions: &[Vec3], out: &mut [ProcessedVertex]) {
        let st = self.stage();
        process_vertices::<S>(
            st.config.width,
            st.config.height,
            st.guard,
            mvp,
            positions,
            out,
        );
    }

    /// The triangle stage of [`Submit::submit_mesh_cached`]: submits the
    /// triangles of `mesh` whose vertices `cache` holds, processed by
    /// [`Submit::process_vertices`] for a frame of this configuration
    /// (entry `i` for `mesh.positions[i]`; a triangle indexing past the
    /// cache is counted in [`Stats::rejected_index`]; `mesh.bounds` is not
    /// tested here).
    fn submit_processed_mesh<A: Attributes<N>>(
        &mut self,
        mesh: &Mesh<'_, A>,
        first_id: u32,
        cache: &[ProcessedVertex],
    ) -> Result<(), Error> {
        check_mesh_len(mesh.indices.len())?;
        let job = ProcessedJob {
            mesh,
            first_id,
            cache,
        };
        run_job::<S, N, _, _>(self.parts(), &job)
    }
}

/// Implements [`Submit`] for a receiver with the fields `stage: Stage`,
/// `stats: Stats` and a sink field: `impl_submit!([generics] Type, Sink,
/// sink_field)`.
macro_rules! impl_submit {
    ([$($g:tt)*] $ty:ty, $sink:ty, $field:ident) => {
        impl<$($g)*> $crate::pipeline::Submit<S, N> for $ty {
            type Sink = $sink;

            fn parts(&mut self) -> $crate::pipeline::__private::Parts<'_, $sink> {
                $crate::pipeline::__private::Parts {
                    stage: &self.stage,
                    stats: &mut self.stats,
                    sink: &mut self.$field,
                }
            }

            fn stage(&self) -> &$crate::pipeline::Stage {
                &self.stage
            }
        }
    };
}
pub(crate) use impl_submit;

/// The first `n` entries of a vertex cache, or the error for a short one.
#[inline]
fn sized_cache(cache: &mut [ProcessedVertex], n: usize) -> Result<&mut [ProcessedVertex], Error> {
    let actual = cache.len();
    cache.get_mut(..n).ok_or(Error::VertexCacheSize {
        expected: n,
        actual,
    })
}

/// Triangle counts per submission fit `u32` (ids are 32-bit).
fn check_mesh_len(n: usize) -> Result<u64, Error> {
    if n as u64 > u32::MAX as u64 {
        Err(Error::MeshTooLarge { triangles: n })
    } else {
        Ok(n as u64)
    }
}

/// The bounding-sphere test of a mesh: against the frustum, by detail
/// culling, and for a strip renderer against its strip; counts the whole
/// mesh (as `culled_object`, `culled_detail` or `outside_strip`) and
/// returns `true` if it is skipped. A mesh dropped by detail culling whose
/// attributes give a fill is drawn as its box ([`BoxJob`]): the only
/// error, [`Error::StorageFull`] for the box, leaves everything as it was.
fn culled_object<const S: u32, const N: usize, K: Sink<N> + ?Sized, A: Attributes<N>>(
    parts: &mut Parts<'_, K>,
    mesh: &Mesh<'_, A>,
    mvp: &Mat4,
    n: u64,
    first_id: u32,
) -> Result<bool, Error> {
    let Some(b) = mesh.bounds else {
        return Ok(false);
    };
    if b.outside_frustum(mvp) {
        *parts.stats += Stats {
            submitted: n,
            culled_object: n,
            ..Stats::default()
        };
        return Ok(true);
    }
    if let Some(d) = Detail::for_frame(mvp, &parts.stage.config) {
        if d.drops(&b) {
            let fill = match A::DETAIL_FILL {
                true => mesh.attributes.detail_fill(0..mesh.indices.len()),
                false => None,
            };
            if let Some(fill) = fill {
                let job = BoxJob {
                    quad: d.screen_box(&b),
                    fill,
                    id: first_id,
                };
                run_job::<S, N, _, _>(
                    Parts {
                        stage: parts.stage,
                        stats: &mut *parts.stats,
                        sink: &mut *parts.sink,
                    },
                    &job,
                )?;
            }
            *parts.stats += Stats {
                submitted: n,
                culled_detail: n,
                ..Stats::default()
            };
            return Ok(true);
        }
    }
    // A strip renderer skips an object wholly above or below its strip.
    if let Some((top, bottom)) = parts.stage.slab {
        if b.outside_slab(mvp, top, bottom) {
            *parts.stats += Stats {
                submitted: n,
                outside_strip: n,
                ..Stats::default()
            };
            return Ok(true);
        }
    }
    Ok(false)
}

/// The two triangles of a detail box ([`Detail::screen_box`]) with
/// constant varyings `fill`, wound to pass the frame's face culling.
fn box_triangles<const N: usize>(
    quad: [Vec4; 4],
    fill: [f32; N],
    stage: &Stage,
) -> [[ClipVertex<N>; 3]; 2] {
    let c = &stage.config;
    // `quad` is counter-clockwise in NDC: kept as it is where that is the
    // face drawn.
    let ccw = (c.front_face == crate::FrontFace::Ccw) != (c.cull == crate::CullMode::Front);
    let v = |k: usize| ClipVertex {
        pos: quad[k],
        varyings: fill,
    };
    if ccw {
        [[v(0), v(1), v(2)], [v(0), v(2), v(3)]]
    } else {
        [[v(0), v(2), v(1)], [v(0), v(3), v(2)]]
    }
}

/// Draws the box of one object or cluster node dropped by detail culling
/// (counted in `Stats::detail_boxes`, not as triangles submitted or
/// stored). No box (`quad` `None`) or a fill that is not finite draws
/// nothing.
fn draw_box<const S: u32, const N: usize, K: Sink<N> + ?Sized>(
    stage: &Stage,
    quad: Option<[Vec4; 4]>,
    fill: [f32; N],
    id: u32,
    stats: &mut Stats,
    sink: &mut K,
) {
    let Some(quad) = quad else {
        return;
    };
    let mut boxed = Stats::default();
    for tri in &box_triangles(quad, fill, stage) {
        process::<S, N, K>(stage, tri, id, &mut boxed, sink);
    }
    stats.detail_boxes += boxed.stored;
}

/// The box of an object dropped by detail culling, as a submission of its
/// own (so a frame's storage is checked for it first).
struct BoxJob<const N: usize> {
    quad: Option<[Vec4; 4]>,
    fill: [f32; N],
    id: u32,
}

impl<const N: usize> Job<N> for BoxJob<N> {
    fn max_pieces(&self) -> usize {
        2 * MAX_PIECES
    }
    fn bound(&self, _: &Stage) -> usize {
        2 * MAX_PIECES
    }
    fn run<const S: u32, K: Sink<N> + ?Sized>(
        &self,
        stage: &Stage,
        stats: &mut Stats,
        sink: &mut K,
    ) {
        draw_box::<S, N, K>(stage, self.quad, self.fill, self.id, stats, sink);
    }
}

/// One submission, run once to count (if it might not fit) and once to
/// deliver.
trait Job<const N: usize> {
    /// The most pieces it can yield, found in O(1).
    fn max_pieces(&self) -> usize;
    /// An upper bound on the pieces it yields, at most `max_pieces`.
    fn bound(&self, stage: &Stage) -> usize;
    /// Runs it, counting into `stats` and handing pieces to `sink`.
    fn run<const S: u32, K: Sink<N> + ?Sized>(
        &self,
        stage: &Stage,
        stats: &mut Stats,
        sink: &mut K,
    );
}

fn run_job<const S: u32, const N: usize, K: Sink<N> + ?Sized, J: Job<N>>(
    parts: Parts<'_, K>,
    job: &J,
) -> Result<(), Error> {
    let room = parts.sink.room();
    if job.max_pieces() > room && job.bound(parts.stage) > room {
        let mut count = Counter(0);
        job.run::<S, _>(parts.stage, &mut Stats::default(), &mut count);
        if count.0 > room {
            return Err(Error::StorageFull {
                capacity: parts.sink.capacity(),
                free: room,
                needed: count.0,
            });
        }
    }
    let mut stats = Stats::default();
    job.run::<S, _>(parts.stage, &mut stats, parts.sink);
    *parts.stats += stats;
    Ok(())
}

struct TriangleJob<const N: usize> {
    tri: [ClipVertex<N>; 3],
    id: u32,
}

impl<const N: usize> Job<N> for TriangleJob<N> {
    fn max_pieces(&self) -> usize {
        MAX_PIECES
    }
    fn bound(&self, _: &Stage) -> usize {
        MAX_PIECES
    }
    fn run<const S: u32, K: Sink<N> + ?Sized>(
        &self,
        stage: &Stage,
        stats: &mut Stats,
        sink: &mut K,
    ) {
        stats.submitted += 1;
        process::<S, N, K>(stage, &self.tri, self.id, stats, sink);
    }
}

struct MeshJob<'m, A, M> {
    mesh: &'m Mesh<'m, A>,
    mvp: &'m Mat4,
    first_id: u32,
    /// Which triangles are skipped unread ([`NoMask`]: none, compiled
    /// out).
    mask: M,
}

/// Which triangles of a [`MeshJob`] are masked by normal class.
trait TriangleMask {
    fn masked(&self, i: usize) -> bool;
}

/// No triangle.
struct NoMask;

impl TriangleMask for NoMask {
    #[inline(always)]
    fn masked(&self, _: usize) -> bool {
        false
    }
}

/// The triangles whose class is in the mask.
struct ClassMask<'m> {
    classes: &'m [u16],
    mask: &'m BackMask,
}

impl TriangleMask for ClassMask<'_> {
    #[inline(always)]
    fn masked(&self, i: usize) -> bool {
        self.classes.get(i).is_some_and(|&c| self.mask.contains(c))
    }
}

impl<const N: usize, A: Attributes<N>, M: TriangleMask> Job<N> for MeshJob<'_, A, M> {
    fn max_pieces(&self) -> usize {
        self.mesh.indices.len().saturating_mul(MAX_PIECES)
    }
    fn bound(&self, _: &Stage) -> usize {
        self.max_pieces()
    }
    fn run<const S: u32, K: Sink<N> + ?Sized>(
        &self,
        stage: &Stage,
        stats: &mut Stats,
        sink: &mut K,
    ) {
        let mesh = self.mesh;
        let (gx, gy) = stage.guard;
        for (i, &idx) in mesh.indices.iter().enumerate() {
            stats.submitted += 1;
            if self.mask.masked(i) {
                stats.culled_mask += 1;
                continue;
            }
            let p = idx.map(|k| mesh.positions.get(k as usize));
            let (Some(p0), Some(p1), Some(p2)) = (p[0], p[1], p[2]) else {
                stats.rejected_index += 1;
                continue;
            };
            if !mesh.attributes.has(i, idx) {
                stats.rejected_index += 1;
                continue;
            }
            // Positions first: the varyings (lighting, say) are evaluated
            // only for triangles that survive the frustum and strip tests.
            let pos = [p0, p1, p2].map(|q| self.mvp.transform_point(*q));
            if !pos.iter().all(|v| v.is_finite()) {
                stats.rejected_nonfinite += 1;
                continue;
            }
            let codes = pos.map(|v| outcode(v, gx, gy));
            if codes[0] & codes[1] & codes[2] & outcode::FRUSTUM != 0 {
                stats.culled_frustum += 1;
                continue;
            }
            if stage.outside_strip(pos) {
                stats.outside_strip += 1;
                continue;
            }
            // Written out, not `array::from_fn`: on the Cortex-M4F the
            // closure form was, after an unrelated change, built in a
            // temporary and moved by `memcpy` (lit Spot: +790 k
            // instructions a frame).
            let vertex = |k: usize| ClipVertex {
                pos: pos[k],
                varyings: mesh.attributes.get(i, idx[k]),
            };
            let tri: [ClipVertex<N>; 3] = [vertex(0), vertex(1), vertex(2)];
            if !A::FINITE && !tri.iter().all(|v| v.varyings.iter().all(|c| c.is_finite())) {
                stats.rejected_nonfinite += 1;
                continue;
            }
            let id = self.first_id.wrapping_add(i as u32);
            process_finite::<S, N, K>(stage, &tri, codes, id, stats, sink);
        }
    }
}

struct ProcessedJob<'m, A> {
    mesh: &'m Mesh<'m, A>,
    first_id: u32,
    cache: &'m [ProcessedVertex],
}

impl<const N: usize, A: Attributes<N>> Job<N> for ProcessedJob<'_, A> {
    fn max_pieces(&self) -> usize {
        self.mesh.indices.len().saturating_mul(MAX_PIECES)
    }

    /// One piece per triangle that needs no clipping, seven for the rest.
    /// Where no vertex needs clipping (most frames), that is one piece per
    /// triangle, found by one sequential pass over the vertices instead
    /// of one over the triangles.
    fn bound(&self, _: &Stage) -> usize {
        let n = self.mesh.indices.len();
        if !self.cache.iter().any(|v| v.code & outcode::CLIP != 0) {
            return n;
        }
        let code = |k: u32| self.cache.get(k as usize).map_or(0, |v| v.code);
        self.mesh.indices.iter().fold(0usize, |n, idx| {
            let or = code(idx[0]) | code(idx[1]) | code(idx[2]);
            n.saturating_add(if or & outcode::CLIP != 0 {
                MAX_PIECES
            } else {
                1
            })
        })
    }

    fn run<const S: u32, K: Sink<N> + ?Sized>(
        &self,
        stage: &Stage,
        stats: &mut Stats,
        sink: &mut K,
    ) {
        let all = 0..self.mesh.indices.len();
        self.run_range::<S, N, K>(stage, stats, sink, all, 0..self.cache.len());
    }
}

impl<A> ProcessedJob<'_, A> {
    /// A bound on the pieces of the triangle runs `runs` hands to its
    /// argument: the mesh's triangle count where no cache entry needs
    /// clipping (one sequential pass, `runs` not called), else one piece
    /// or seven per triangle of the runs.
    fn bound_over(&self, runs: impl FnOnce(&mut dyn FnMut(core::ops::Range<usize>))) -> usize {
        let cache = self.cache;
        if !cache.iter().any(|v| v.code & outcode::CLIP != 0) {
            return self.mesh.indices.len();
        }
        let code = |k: u32| cache.get(k as usize).map_or(0, |v| v.code);
        let mut n = 0usize;
        runs(&mut |tris| {
            for idx in self.mesh.indices.get(tris).unwrap_or(&[]) {
                let or = code(idx[0]) | code(idx[1]) | code(idx[2]);
                let k = if or & outcode::CLIP != 0 {
                    MAX_PIECES
                } else {
                    1
                };
                n = n.saturating_add(k);
            }
        });
        n
    }

    /// Runs triangles `tris` (ids and attributes as in the whole mesh),
    /// which may use only the cache entries `verts`: an index outside
    /// them is counted as a bad index.
    fn run_range<const S: u32, const N: usize, K: Sink<N> + ?Sized>(
        &self,
        stage: &Stage,
        stats: &mut Stats,
        sink: &mut K,
        tris: core::ops::Range<usize>,
        verts: core::ops::Range<usize>,
    ) where
        A: Attributes<N>,
    {
        let mesh = self.mesh;
        let base = verts.start;
        let cache = self.cache.get(verts).unwrap_or(&[]);
        let attrs = &mesh.attributes;
        let c = &stage.config;
        // Attribute lists as long as the mesh need no check per triangle.
        let complete = attrs.complete(mesh.indices.len(), self.cache.len());
        // The clipless mode sets up from clip-space positions, never from
        // the snapped vertices.
        let snapped_setup = c.mode == RasterMode::Clipping;
        let first = tris.start;
        for (j, idx) in mesh.indices.get(tris).unwrap_or(&[]).iter().enumerate() {
            let i = first + j;
            let id = self.first_id.wrapping_add(i as u32);
            stats.submitted += 1;
            let (Some(a), Some(b), Some(d)) = (
                cache.get((idx[0] as usize).wrapping_sub(base)),
                cache.get((idx[1] as usize).wrapping_sub(base)),
                cache.get((idx[2] as usize).wrapping_sub(base)),
            ) else {
                stats.rejected_index += 1;
                continue;
            };
            // A missing attribute counts as a bad index, as in
            // `submit_mesh`.
            if !complete && !attrs.has(i, *idx) {
                stats.rejected_index += 1;
                continue;
            }
            // Evaluated only for triangles that survive culling.
            let var = |k: usize| attrs.get(i, idx[k]);
            let (and, or) = (a.code & b.code & d.code, a.code | b.code | d.code);
            if or & NONFINITE != 0 {
                stats.rejected_nonfinite += 1;
                continue;
            }
            if and & outcode::FRUSTUM != 0 {
                stats.culled_frustum += 1;
                continue;
            }
            if stage.outside_strip([a.pos, b.pos, d.pos]) {
                stats.outside_strip += 1;
                continue;
            }
            // Varyings that may not be finite are checked here, where
            // `submit_mesh` checks them, so both count alike; sources that
            // are always finite (colours, lighting) skip it.
            let checked = if A::FINITE {
                None
            } else {
                let v = [var(0), var(1), var(2)];
                if !v.iter().flatten().all(|c| c.is_finite()) {
                    stats.rejected_nonfinite += 1;
                    continue;
                }
                Some(v)
            };
            let vars = || checked.unwrap_or_else(|| [var(0), var(1), var(2)]);
            if or & outcode::CLIP == 0 && a.snapped && b.snapped && d.snapped && snapped_setup {
                // Fast path: vertices already snapped.
                match setup_geometry::<S>(
                    &[a.snap, b.snap, d.snap],
                    c.width,
                    c.height,
                    c.cull,
                    c.front_face,
                ) {
                    Ok(g) => {
                        // On 64-bit hosts not `vars()`: LLVM kept that
                        // closure out of line there, its varyings passed
                        // through memory and read back wider than written
                        // (the sphere's triangle stage 11 % slower). 32-bit
                        // cores keep the closure, as their recorded split
                        // estimates would move past their 1 % check.
                        let v = match checked {
                            Some(v) => v,
                            None if cfg!(target_pointer_width = "64") => [var(0), var(1), var(2)],
                            None => vars(),
                        };
                        let t = g.finish([a.inv_w, b.inv_w, d.inv_w], v, id);
                        sink.take(&t);
                        stats.stored += 1;
                    }
                    Err(r) => count_rejected(stats, r),
                }
                continue;
            }
            let (v, var) = ([a, b, d], vars());
            let tri: [ClipVertex<N>; 3] = core::array::from_fn(|k| ClipVertex {
                pos: v[k].pos,
                varyings: var[k],
            });
            process_finite::<S, N, K>(stage, &tri, [a.code, b.code, d.code], id, stats, sink);
        }
    }
}

struct ClusterJob<'m, A> {
    inner: ProcessedJob<'m, A>,
    set: &'m ClusterSet<'m>,
    eye: Option<Eye>,
    detail: Option<Detail>,
    cull: ClusterCull,
    /// The visits of a walk with the same eye, detail and test, to
    /// replay instead of walking again (`None`: walk).
    record: Option<&'m [u32]>,
}

/// Visits a [`WalkRecord`] holds: 2048 (8 KB) on 64-bit hosts, enough
/// for the Stanford bunny's 5,788 clusters; none on 32-bit cores, whose
/// stack is small and whose firmware submits clusters through a strip
/// renderer (one walk, no record).
const RECORDED_VISITS: usize = if cfg!(target_pointer_width = "64") {
    2048
} else {
    0
};

/// The visits of one walk of a validated cluster set ([`traverse`]), in
/// order, up to [`RECORDED_VISITS`] of them. The visits of such a walk
/// tile the clusters in order, so each is kept as where it ends (below
/// `2^30`) and its kind in the top two bits: drawn, culled at a leaf or
/// at an inner node. A draw, or a cull of the same kind, that continues
/// the visit before it extends it (the same triangles are drawn, and the
/// same counted as skipped). A walk with more visits, a detail drop (its
/// node is not kept) or a visit that does not start where the one before
/// ended is not recorded ([`WalkRecord::complete`] gives `None`).
struct WalkRecord {
    ends: [u32; RECORDED_VISITS],
    len: usize,
    end: usize,
    overflow: bool,
}

/// [`WalkRecord`]'s kinds of visit, in the top two bits.
const DRAWN: u32 = 0;
const CULLED_LEAF: u32 = 1 << 30;
const CULLED_INNER: u32 = 2 << 30;
const KIND: u32 = 3 << 30;

impl WalkRecord {
    fn new() -> Self {
        WalkRecord {
            ends: [0; RECORDED_VISITS],
            len: 0,
            end: 0,
            overflow: false,
        }
    }

    fn push(&mut self, v: Visit) {
        let (a, b, kind) = match v {
            Visit::Draw(a, b) => (a, b, DRAWN),
            Visit::Cull(a, b, inner) => (a, b, if inner { CULLED_INNER } else { CULLED_LEAF }),
            Visit::Detail(..) => {
                self.overflow = true;
                return;
            }
        };
        let fits = u32::try_from(b).ok().filter(|&b| b & KIND == 0);
        let (Some(b32), false, true) = (fits, self.overflow, a == self.end && a <= b) else {
            self.overflow = true;
            return;
        };
        self.end = b;
        if let Some(last) = self.len.checked_sub(1).and_then(|i| self.ends.get_mut(i)) {
            if *last & KIND == kind {
                *last = kind | b32;
                return;
            }
        }
        match self.ends.get_mut(self.len) {
            Some(slot) => {
                *slot = kind | b32;
                self.len += 1;
            }
            None => self.overflow = true,
        }
    }

    /// The visits, if the walk's all fitted.
    fn complete(&self) -> Option<&[u32]> {
        match self.overflow {
            true => None,
            false => self.ends.get(..self.len),
        }
    }
}

/// The visits `record` ([`WalkRecord::complete`]) holds, in order.
fn replay(record: &[u32], mut f: impl FnMut(Visit)) {
    let mut a = 0usize;
    for &r in record {
        let b = (r & !KIND) as usize;
        f(match r & KIND {
            DRAWN => Visit::Draw(a, b),
            CULLED_LEAF => Visit::Cull(a, b, false),
            _ => Visit::Cull(a, b, true),
        });
        a = b;
    }
}

/// Why [`ClusterJob::visit`] skipped a run of clusters.
#[derive(Clone, Copy)]
enum Skipped {
    Leaf,
    Inner,
    /// By detail culling, at this node.
    Detail(usize),
}

/// One step of [`ClusterJob::visit_in_order`].
enum Step {
    /// Draw these triangles, which use these cache entries.
    Draw(core::ops::Range<usize>, core::ops::Range<usize>),
    /// Skip this many triangles, for this reason.
    Skip(u64, Skipped),
}

impl<A> ClusterJob<'_, A> {
    /// Calls `f(triangles, vertices)` for every cluster drawn, in order,
    /// and `g(triangles, why)` for every skipped run of clusters.
    fn visit(
        &self,
        mut f: impl FnMut(core::ops::Range<usize>, core::ops::Range<usize>),
        mut g: impl FnMut(u64, Skipped),
    ) {
        self.visit_in_order(|step| match step {
            Step::Draw(tris, verts) => f(tris, verts),
            Step::Skip(n, why) => g(n, why),
        })
    }

    /// [`ClusterJob::visit`] with one callback, for callers whose two
    /// would borrow the same state.
    fn visit_in_order(&self, mut h: impl FnMut(Step)) {
        let clusters = self.set.clusters;
        let count = |a: usize, b: usize| triangles_of(clusters, a, b);
        let (eye, detail) = (self.eye.as_ref(), self.detail.as_ref());
        let step = |v| match v {
            Visit::Draw(a, b) => {
                for k in clusters.get(a..b).unwrap_or(&[]) {
                    let [t0, t1] = k.triangles.map(|v| v as usize);
                    // With a vertex list, triangles index the whole cache
                    // (entries not processed are stale: non-finite).
                    let verts = if self.set.vertices.is_empty() {
                        k.vertices[0] as usize..k.vertices[1] as usize
                    } else {
                        0..self.inner.cache.len()
                    };
                    h(Step::Draw(t0..t1, verts));
                }
            }
            Visit::Cull(a, b, inner) => h(Step::Skip(
                count(a, b),
                if inner { Skipped::Inner } else { Skipped::Leaf },
            )),
            Visit::Detail(a, b, node) => h(Step::Skip(count(a, b), Skipped::Detail(node))),
        };
        match self.record {
            Some(record) => replay(record, step),
            None => traverse(self.set, eye, detail, self.cull, step),
        }
    }
}

impl<A> ClusterJob<'_, A> {
    /// The box drawn in place of node `node` dropped by detail culling,
    /// with its varyings and id (that of its first triangle); `None`
    /// where the attributes give no fill.
    fn detail_box<const N: usize>(&self, node: usize) -> Option<(Option<[Vec4; 4]>, [f32; N], u32)>
    where
        A: Attributes<N>,
    {
        if !A::DETAIL_FILL {
            return None;
        }
        let node = self.set.nodes.get(node)?;
        let [a, b] = node.clusters.map(|k| k as usize);
        let clusters = self.set.clusters.get(a..b).unwrap_or(&[]);
        let first = clusters.first().map_or(0, |k| k.triangles[0]);
        let end = clusters.last().map_or(first, |k| k.triangles[1]);
        let fill = (self.inner.mesh.attributes).detail_fill(first as usize..end as usize)?;
        let quad = self.detail.as_ref()?.screen_box(&node.sphere);
        Some((quad, fill, self.inner.first_id.wrapping_add(first)))
    }
}

impl<const N: usize, A: Attributes<N>> Job<N> for ClusterJob<'_, A> {
    /// The mesh's pieces, and two box triangles a node where detail
    /// culling may draw boxes.
    fn max_pieces(&self) -> usize {
        let boxes = if self.detail.is_some() && A::DETAIL_FILL {
            self.set.nodes.len().saturating_mul(2 * MAX_PIECES)
        } else {
            0
        };
        self.inner.max_pieces().saturating_add(boxes)
    }

    /// The mesh's triangle count where no cache entry needs clipping (one
    /// sequential pass), else one piece or seven per triangle of the
    /// clusters drawn; and two box triangles per node dropped by detail
    /// culling where it draws boxes.
    fn bound(&self, _: &Stage) -> usize {
        let mut boxes = 0usize;
        if self.detail.is_some() && A::DETAIL_FILL {
            self.visit(
                |_, _| {},
                |_, why| {
                    if let Skipped::Detail(node) = why {
                        if self.detail_box::<N>(node).is_some() {
                            boxes = boxes.saturating_add(2 * MAX_PIECES);
                        }
                    }
                },
            );
        }
        // Where nothing needs clipping, no walk of the tree (its tests are
        // the costly part).
        self.inner
            .bound_over(|f| self.visit(|tris, _| f(tris), |_, _| {}))
            .saturating_add(boxes)
    }

    fn run<const S: u32, K: Sink<N> + ?Sized>(
        &self,
        stage: &Stage,
        stats: &mut Stats,
        sink: &mut K,
    ) {
        let mut skipped = Stats::default();
        // A box is drawn where its node falls in the cluster order.
        self.visit_in_order(|step| match step {
            Step::Draw(tris, verts) => self
                .inner
                .run_range::<S, N, K>(stage, stats, sink, tris, verts),
            Step::Skip(tris, why) => {
                count_skipped(&mut skipped, tris, why);
                if let Skipped::Detail(node) = why {
                    if let Some((quad, fill, id)) = self.detail_box::<N>(node) {
                        draw_box::<S, N, K>(stage, quad, fill, id, stats, sink);
                    }
                }
            }
        });
        *stats += skipped;
    }
}

/// [`Submit::submit_clusters`] with a vertex list, no detail culling and
/// room for every piece the mesh could make (so nothing needs counting
/// first): one walk of the tree, where the general path walks it twice
/// (once to mark the drawn clusters' vertices, once to draw them), and
/// each walk tests every node it reaches, the size guard included.
///
/// On 64-bit hosts the drawn clusters' vertices are gathered over visits
/// and processed in full batches before their triangles run
/// ([`GatheredWalk`]); a vertex gathered once is not gathered again (a
/// bitset marks it, or, in a mesh of more than [`SEEN`] vertices, its cache
/// entry, all of which are first marked stale). Elsewhere every entry of
/// `cache` is first marked stale (non-finite); then, for each visit of the
/// walk that draws clusters, their listed vertices still stale are
/// processed one by one, cluster by cluster, and their triangles run at
/// once. A triangle whose cluster's list misses one of its vertices (bad
/// data) may read a stale entry, counted as non-finite, or one of an
/// earlier frame, as in the general path; a wrong triangle, never a read
/// out of bounds. For data that passed validation the frame and the counts
/// are those of the general path.
#[allow(clippy::too_many_arguments)]
fn submit_clusters_in_one_walk<const S: u32, const N: usize, K: Sink<N> + ?Sized, A>(
    parts: Parts<'_, K>,
    mesh: &Mesh<'_, A>,
    mvp: &Mat4,
    set: &ClusterSet<'_>,
    eye: Option<Eye>,
    cull: ClusterCull,
    first_id: u32,
    cache: &mut [ProcessedVertex],
) where
    A: Attributes<N>,
{
    let Parts { stage, stats, sink } = parts;
    let c = &stage.config;
    let (clusters, list) = (set.clusters, set.vertices);
    let (mut drawn, mut skipped) = (Stats::default(), Stats::default());
    if BATCH > 1 {
        let mut walk = GatheredWalk::new(cache);
        traverse(set, eye.as_ref(), None, cull, |v| match v {
            Visit::Draw(a, b) => {
                let drawn_now = clusters.get(a..b).unwrap_or(&[]);
                walk.gather::<S>(stage, mvp, mesh.positions, list, drawn_now, cache);
                if walk.hold(a, b) {
                    walk.run::<S, N, K, A>(
                        stage, mvp, mesh, first_id, clusters, cache, &mut drawn, sink,
                    );
                }
            }
            Visit::Cull(a, b, inner) => {
                let why = if inner { Skipped::Inner } else { Skipped::Leaf };
                count_skipped(&mut skipped, triangles_of(clusters, a, b), why);
            }
            // No detail culling here.
            Visit::Detail(..) => {}
        });
        walk.run::<S, N, K, A>(
            stage, mvp, mesh, first_id, clusters, cache, &mut drawn, sink,
        );
        *stats += drawn;
        *stats += skipped;
        return;
    }
    mark_stale(cache);
    traverse(set, eye.as_ref(), None, cull, |v| match v {
        Visit::Draw(a, b) => {
            for k in clusters.get(a..b).unwrap_or(&[]) {
                let ids = list.get(k.vertices[0] as usize..k.vertices[1] as usize);
                for &id in ids.unwrap_or(&[]) {
                    let id = id as usize;
                    let (Some(p), Some(out)) = (mesh.positions.get(id), cache.get_mut(id)) else {
                        continue;
                    };
                    if out.code & NONFINITE != 0 {
                        process_vertices::<S>(
                            c.width,
                            c.height,
                            stage.guard,
                            mvp,
                            core::slice::from_ref(p),
                            core::slice::from_mut(out),
                        );
                    }
                }
                let job = ProcessedJob {
                    mesh,
                    first_id,
                    cache: &*cache,
                };
                let [t0, t1] = k.triangles.map(|v| v as usize);
                job.run_range::<S, N, K>(stage, &mut drawn, sink, t0..t1, 0..cache.len());
            }
        }
        Visit::Cull(a, b, inner) => {
            let why = if inner { Skipped::Inner } else { Skipped::Leaf };
            count_skipped(&mut skipped, triangles_of(clusters, a, b), why);
        }
        // No detail culling here.
        Visit::Detail(..) => {}
    });
    *stats += drawn;
    *stats += skipped;
}

/// Vertices that [`GatheredWalk`] gathers before it processes them:
/// sixteen of the vertex stage's batches.
const GATHER: usize = 16 * BATCH;

/// Runs of clusters (adjacent visits merged) that [`GatheredWalk`] holds
/// back, at most, until their vertices are processed.
const HELD: usize = 32;

/// Vertices of a mesh that [`GatheredWalk`] marks as gathered with a bit
/// each (8 KB); in a larger mesh a cache entry is marked instead.
const SEEN: usize = 65_536;

/// The vertex stage of [`submit_clusters_in_one_walk`] on hosts whose
/// vertex stage takes batches ([`BATCH`] > 1). Each drawn cluster's listed
/// vertices not yet gathered this walk are gathered (their positions and
/// ids, up to [`GATHER`]; a vertex the clusters share is gathered once,
/// marked in a bitset, not in the cache, where the mesh has at most
/// [`SEEN`] vertices) and processed in full batches, then scattered to the
/// cache. The visits' clusters are held (up to [`HELD`] runs, adjacent
/// visits merged) and their triangles run in visit order, each run in one
/// call, once the vertices gathered for them are processed: when half of
/// [`GATHER`] are waiting, when [`HELD`] runs are, and at the end. The
/// entries are those that processing them one by one gives (the batch is
/// the same computation, `process_vertices`); a non-finite vertex is
/// processed once and its entry read as non-finite by every triangle.
struct GatheredWalk {
    ids: [usize; GATHER],
    at: [Vec3; GATHER],
    out: [ProcessedVertex; GATHER],
    /// Entries gathered.
    n: usize,
    /// One bit a vertex, set when it is gathered.
    seen: [u64; SEEN / 64],
    /// Whether `seen` is used: the cache has at most [`SEEN`] entries
    /// (else gathered entries are marked in the cache, all marked stale
    /// first).
    bits: bool,
    /// The held runs of clusters.
    held: [(usize, usize); HELD],
    runs: usize,
}

impl GatheredWalk {
    /// A walk over `cache`, whose entries it marks stale if it has more
    /// than [`SEEN`].
    fn new(cache: &mut [ProcessedVertex]) -> Self {
        let bits = cache.len() <= SEEN;
        if !bits {
            mark_stale(cache);
        }
        GatheredWalk {
            ids: [0; GATHER],
            at: [Vec3::ZERO; GATHER],
            out: [ProcessedVertex::EMPTY; GATHER],
            n: 0,
            seen: [0; SEEN / 64],
            bits,
            held: [(0, 0); HELD],
            runs: 0,
        }
    }

    /// Gathers the vertices `clusters` list that no earlier cluster of the
    /// walk did, processing them whenever [`GATHER`] are waiting. With the
    /// bitset, every listed vertex is written to the next slot and the
    /// count advances only for a fresh one (about half are shared: no
    /// branch on it).
    fn gather<const S: u32>(
        &mut self,
        stage: &Stage,
        mvp: &Mat4,
        positions: &[Vec3],
        list: &[u32],
        clusters: &[Cluster],
        cache: &mut [ProcessedVertex],
    ) {
        let GatheredWalk {
            ids,
            at,
            out,
            n,
            seen,
            bits,
            ..
        } = self;
        let mut m = *n;
        for k in clusters {
            let listed = list.get(k.vertices[0] as usize..k.vertices[1] as usize);
            for &id in listed.unwrap_or(&[]) {
                let id = id as usize;
                let (Some(p), true) = (positions.get(id), id < cache.len()) else {
                    continue;
                };
                let fresh = if *bits {
                    let Some(word) = seen.get_mut(id / 64) else {
                        continue;
                    };
                    let bit = 1u64 << (id % 64);
                    let fresh = *word & bit == 0;
                    *word |= bit;
                    fresh
                } else {
                    match cache.get_mut(id) {
                        // Marked: not gathered again before it is processed.
                        Some(e) if e.code & NONFINITE != 0 => {
                            e.code = 0;
                            true
                        }
                        _ => false,
                    }
                };
                if let (Some(i), Some(a)) = (ids.get_mut(m), at.get_mut(m)) {
                    (*i, *a) = (id, *p);
                }
                m += usize::from(fresh);
                if m == GATHER {
                    process_gathered::<S>(stage, mvp, &ids[..], &at[..], &mut out[..], cache);
                    m = 0;
                }
            }
        }
        *n = m;
    }

    /// Processes the gathered vertices into `cache`.
    fn process<const S: u32>(&mut self, stage: &Stage, mvp: &Mat4, cache: &mut [ProcessedVertex]) {
        let n = self.n;
        self.n = 0;
        if let (Some(ids), Some(at), Some(out)) =
            (self.ids.get(..n), self.at.get(..n), self.out.get_mut(..n))
        {
            process_gathered::<S>(stage, mvp, ids, at, out, cache);
        }
    }

    /// Holds the clusters `a..b` of a visit; whether the held runs should
    /// now be processed and run.
    fn hold(&mut self, a: usize, b: usize) -> bool {
        match self.runs.checked_sub(1).and_then(|i| self.held.get_mut(i)) {
            Some(last) if last.1 == a => last.1 = b,
            _ => {
                if let Some(slot) = self.held.get_mut(self.runs) {
                    *slot = (a, b);
                    self.runs += 1;
                }
            }
        }
        self.runs == HELD || 2 * self.n >= GATHER
    }

    /// Processes the gathered vertices, then runs the held clusters'
    /// triangles, in order.
    #[allow(clippy::too_many_arguments)]
    fn run<const S: u32, const N: usize, K: Sink<N> + ?Sized, A: Attributes<N>>(
        &mut self,
        stage: &Stage,
        mvp: &Mat4,
        mesh: &Mesh<'_, A>,
        first_id: u32,
        clusters: &[Cluster],
        cache: &mut [ProcessedVertex],
        drawn: &mut Stats,
        sink: &mut K,
    ) {
        self.process::<S>(stage, mvp, cache);
        let job = ProcessedJob {
            mesh,
            first_id,
            cache: &*cache,
        };
        let runs = self.runs;
        self.runs = 0;
        for &(a, b) in self.held.get(..runs).unwrap_or(&[]) {
            // Validated clusters tile the triangles in order: a run of
            // them is one range.
            let (Some(first), Some(last)) = (
                clusters.get(a),
                b.checked_sub(1).and_then(|l| clusters.get(l)),
            ) else {
                continue;
            };
            let tris = first.triangles[0] as usize..last.triangles[1] as usize;
            job.run_range::<S, N, K>(stage, drawn, sink, tris, 0..cache.len());
        }
    }
}

/// Marks every entry of `cache` stale (not processed this frame).
fn mark_stale(cache: &mut [ProcessedVertex]) {
    for v in cache.iter_mut() {
        v.code = NONFINITE;
    }
}

/// The vertex stage of gathered positions `at`, scattered to their `ids`
/// in `cache` ([`GatheredWalk`]).
fn process_gathered<const S: u32>(
    stage: &Stage,
    mvp: &Mat4,
    ids: &[usize],
    at: &[Vec3],
    out: &mut [ProcessedVertex],
    cache: &mut [ProcessedVertex],
) {
    let c = &stage.config;
    process_vertices::<S>(c.width, c.height, stage.guard, mvp, at, out);
    for (&id, v) in ids.iter().zip(out.iter()) {
        if let Some(e) = cache.get_mut(id) {
            *e = *v;
        }
    }
}

/// The triangles of clusters `a..b`.
fn triangles_of(clusters: &[Cluster], a: usize, b: usize) -> u64 {
    clusters
        .get(a..b)
        .unwrap_or(&[])
        .iter()
        .map(|k| u64::from(k.triangles[1].saturating_sub(k.triangles[0])))
        .sum()
}

/// Counts `tris` triangles skipped for `why` (a detail box is drawn by
/// the caller).
fn count_skipped(skipped: &mut Stats, tris: u64, why: Skipped) {
    skipped.submitted += tris;
    match why {
        Skipped::Leaf => skipped.culled_cluster += tris,
        Skipped::Inner => skipped.culled_hierarchy += tris,
        Skipped::Detail(_) => skipped.culled_detail += tris,
    }
}

/// Processes every stale entry of `cache` (marked now, or a non-finite
/// vertex of an earlier frame: processing it again gives the same entry),
/// in runs, by one pass.
fn process_stale<const S: u32, const N: usize, T: Submit<S, N> + ?Sized>(
    receiver: &T,
    mvp: &Mat4,
    positions: &[Vec3],
    cache: &mut [ProcessedVertex],
) {
    let stale = |v: &ProcessedVertex| v.code & NONFINITE != 0;
    let mut i = 0;
    while let Some(start) = cache.get(i..).and_then(|c| c.iter().position(stale)) {
        let a = i + start;
        let run = cache
            .get(a..)
            .map_or(0, |c| c.iter().take_while(|v| stale(v)).count());
        let b = a + run;
        if let (Some(p), Some(out)) = (positions.get(a..b), cache.get_mut(a..b)) {
            receiver.process_vertices(mvp, p, out);
        }
        i = b;
    }
}

struct MaskJob<'m, A> {
    inner: ProcessedJob<'m, A>,
    classes: &'m [u16],
    mask: BackMask,
}

impl<A> MaskJob<'_, A> {
    /// Calls `f(triangles)` for every run of kept triangles, in order, and
    /// returns the count of masked ones.
    fn visit(&self, mut f: impl FnMut(core::ops::Range<usize>)) -> u64 {
        let n = self.classes.len();
        let (mut i, mut masked) = (0usize, 0u64);
        while i < n {
            let rest = self.classes.get(i..).unwrap_or(&[]);
            let skip = rest.iter().take_while(|&&c| self.mask.contains(c)).count();
            masked += skip as u64;
            i += skip;
            let rest = self.classes.get(i..).unwrap_or(&[]);
            let keep = rest.iter().take_while(|&&c| !self.mask.contains(c)).count();
            if keep > 0 {
                f(i..i + keep);
            }
            i += keep;
        }
        masked
    }
}

impl<const N: usize, A: Attributes<N>> Job<N> for MaskJob<'_, A> {
    fn max_pieces(&self) -> usize {
        self.inner.max_pieces()
    }

    /// The mesh's triangle count where no cache entry needs clipping, else
    /// one piece or seven per kept triangle.
    fn bound(&self, _: &Stage) -> usize {
        self.inner.bound_over(|f| {
            self.visit(f);
        })
    }

    fn run<const S: u32, K: Sink<N> + ?Sized>(
        &self,
        stage: &Stage,
        stats: &mut Stats,
        sink: &mut K,
    ) {
        let verts = 0..self.inner.cache.len();
        let masked = self.visit(|tris| {
            self.inner
                .run_range::<S, N, K>(stage, stats, sink, tris, verts.clone())
        });
        *stats += Stats {
            submitted: masked,
            culled_mask: masked,
            ..Stats::default()
        };
    }
}

fn count_rejected(stats: &mut Stats, r: Rejected) {
    match r {
        Rejected::Backface => stats.culled_backface += 1,
        Rejected::Degenerate => stats.culled_degenerate += 1,
        Rejected::Offscreen => stats.culled_frustum += 1,
    }
}

/// Runs one submitted triangle through cull, clip and setup, handing each
/// set-up piece (at most [`MAX_PIECES`]) to `sink` and counting it in
/// `stats` (not `submitted`: the caller counts that).
fn process<const S: u32, const N: usize, K: Sink<N> + ?Sized>(
    stage: &Stage,
    tri: &[ClipVertex<N>; 3],
    id: u32,
    stats: &mut Stats,
    sink: &mut K,
) {
    if !tri
        .iter()
        .all(|v| v.pos.is_finite() && v.varyings.iter().all(|c| c.is_finite()))
    {
        stats.rejected_nonfinite += 1;
        return;
    }
    let (gx, gy) = stage.guard;
    let codes = tri.map(|v| outcode(v.pos, gx, gy));
    if codes[0] & codes[1] & codes[2] & outcode::FRUSTUM != 0 {
        stats.culled_frustum += 1;
        return;
    }
    if stage.outside_strip(tri.map(|v| v.pos)) {
        stats.outside_strip += 1;
        return;
    }
    process_finite::<S, N, K>(stage, tri, codes, id, stats, sink);
}

/// [`process`] after the finiteness, frustum and strip tests.
fn process_finite<const S: u32, const N: usize, K: Sink<N> + ?Sized>(
    stage: &Stage,
    tri: &[ClipVertex<N>; 3],
    codes: [u16; 3],
    id: u32,
    stats: &mut Stats,
    sink: &mut K,
) {
    let c = &stage.config;
    if cfg!(feature = "clipless") && c.mode == RasterMode::Clipless {
        process_clipless::<N, K>(stage, tri, id, stats, sink);
        return;
    }
    let (gx, gy) = stage.guard;
    let crossing = (codes[0] | codes[1] | codes[2]) & outcode::CLIP;
    if crossing == 0 {
        match setup::<S, N>(tri, c.width, c.height, c.cull, c.front_face, id) {
            Ok(t) => {
                sink.take(&t);
                stats.stored += 1;
            }
            Err(r) => count_rejected(stats, r),
        }
        return;
    }
    stats.clipped += 1;
    let poly = clip_triangle(tri, crossing, gx, gy);
    if poly.len() < 3 {
        stats.culled_frustum += 1;
        return;
    }
    // Snap the polygon's vertices once; split it into triangles that all
    // wind the same way (a fan, unless snapping made the polygon slightly
    // non-convex, see `setup::triangulate`); cull and set up each piece.
    let mut snapped: heapless::Vec<Option<SnappedVertex>, 9> = heapless::Vec::new();
    for v in &poly {
        let p = v.pos;
        let _ = snapped.push(snap::<S>(p.x, p.y, p.z, p.w, c.width, c.height));
    }
    let mut first_reason = None;
    let mut stored = 0;
    for [a, b, d] in triangulate(&snapped) {
        let (a, b, d) = (a as usize, b as usize, d as usize);
        let (Some(sa), Some(sb), Some(sd)) = (snapped[a], snapped[b], snapped[d]) else {
            // A finite vertex that cannot be placed: clipping left it at
            // (or, in f32, indistinguishably near) the homogeneous origin.
            first_reason.get_or_insert(Rejected::Degenerate);
            continue;
        };
        match setup_geometry::<S>(&[sa, sb, sd], c.width, c.height, c.cull, c.front_face) {
            Ok(g) => {
                let (pa, pb, pd) = (&poly[a], &poly[b], &poly[d]);
                let t = g.finish(
                    inv_w3([pa.pos.w, pb.pos.w, pd.pos.w]),
                    [pa.varyings, pb.varyings, pd.varyings],
                    id,
                );
                sink.take(&t);
                stored += 1;
                stats.stored += 1;
            }
            Err(r) => {
                first_reason.get_or_insert(r);
            }
        }
    }
    if stored == 0 {
        count_rejected(stats, first_reason.unwrap_or(Rejected::Degenerate));
    }
}

/// [`process_finite`] in the clipless mode: setup without clipping, one
/// piece. Out of line, so that the clipping mode's stack frame does not
/// hold a clipless triangle (immediate-mode firmware sizes its strips by
/// the stack it measured).
#[cold]
#[inline(never)]
fn process_clipless<const N: usize, K: Sink<N> + ?Sized>(
    stage: &Stage,
    tri: &[ClipVertex<N>; 3],
    id: u32,
    stats: &mut Stats,
    sink: &mut K,
) {
    let c = &stage.config;
    match crate::clipless::setup::<N>(tri, c.width, c.height, c.cull, c.front_face, id) {
        Ok(t) => {
            sink.take_clipless(&t);
            stats.stored += 1;
        }
        Err(r) => count_rejected(stats, r),
    }
}

#[cfg(test)]
mod tests {
    extern crate std;
    use super::*;

    fn replayed(r: &WalkRecord) -> Option<std::vec::Vec<Visit>> {
        let mut out = std::vec::Vec::new();
        replay(r.complete()?, |v| out.push(v));
        Some(out)
    }

    #[test]
    #[cfg(target_pointer_width = "64")]
    fn a_walk_record_merges_runs_and_gives_up_where_it_cannot_replay() {
        let mut r = WalkRecord::new();
        for v in [
            Visit::Draw(0, 2),
            Visit::Draw(2, 3),
            Visit::Cull(3, 5, false),
            Visit::Cull(5, 6, false),
            Visit::Cull(6, 9, true),
            Visit::Draw(9, 9),
            Visit::Draw(9, 12),
            Visit::Cull(12, 13, false),
        ] {
            r.push(v);
        }
        let want = [
            Visit::Draw(0, 3),
            Visit::Cull(3, 6, false),
            Visit::Cull(6, 9, true),
            Visit::Draw(9, 12),
            Visit::Cull(12, 13, false),
        ];
        assert_eq!(replayed(&r).as_deref(), Some(&want[..]));
        // A detail drop (its node is not kept), a gap, a visit out of
        // order or an end beyond 2^30: not recorded.
        for bad in [
            Visit::Detail(13, 14, 0),
            Visit::Draw(14, 15),
            Visit::Cull(12, 14, false),
            Visit::Draw(13, 1 << 30),
        ] {
            let mut r2 = WalkRecord::new();
            replay(r.complete().unwrap_or(&[]), |v| r2.push(v));
            assert!(r2.complete().is_some());
            r2.push(bad);
            assert_eq!(replayed(&r2), None, "{bad:?}");
        }
        // More visits than it holds: none.
        let mut r3 = WalkRecord::new();
        for k in 0..=RECORDED_VISITS {
            r3.push(if k % 2 == 0 {
                Visit::Draw(k, k + 1)
            } else {
                Visit::Cull(k, k + 1, false)
            });
        }
        assert_eq!(replayed(&r3), None);
    }

    #[test]
    fn meshes_beyond_u32_triangles_are_refused() {
        assert_eq!(check_mesh_len(u32::MAX as usize), Ok(u32::MAX as u64));
        if usize::BITS > 32 {
            let n = (u32::MAX as u64 + 1) as usize;
            assert_eq!(check_mesh_len(n), Err(Error::MeshTooLarge { triangles: n }));
        }
    }
}
