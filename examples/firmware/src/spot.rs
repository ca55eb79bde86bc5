//! The Spot frame (`--features spot-*`): baked, textured, lit Spot at
//! 320x240 `Rgb565` with a `u16` depth buffer, in immediate mode.
//!
//! The model and its texture are statics in flash (`baked/spot.rs`, or the
//! decimated `baked/small/spot.rs` on the micro:bit: build.rs says which);
//! RAM holds only the strip's colour and depth rows. Every strip gets a
//! `StripRenderer::with_shader` with the variant's fragment shader and the
//! mesh submitted again, as runs of `CHUNK_TRIANGLES` triangles in Morton
//! order, each with its bounding sphere (build.rs writes both to flash):
//! the renderer skips a run whose sphere lies outside the strip before
//! transforming anything (`submit_mesh`: each triangle's vertices are
//! transformed as it is submitted, no vertex cache, which would not fit).
//! Then the strip is pushed to the display stand-in as one
//! `StripSink::push_strip`, as `StripDrawer` does for unshaded frames.
//!
//! The split is measured as in the cubes' immediate mode: geometry is the
//! mesh submitted to a one-row strip, times the strips (so it includes one
//! row's pixels; the middle row's runs, so with chunks an overestimate of
//! the strips' average), the clears one strip's clear times the strips,
//! and rasterization (with shading) the rest of the render.

use crate::clock::Clock;
#[cfg(any(feature = "clusters", feature = "herd-occlusion"))]
use crate::display::Saved;
use crate::display::{push, HashDisplay};
#[cfg(any(feature = "clusters", feature = "herd", feature = "cull-masks"))]
use crate::ratio;
use crate::spot_scene::{self, Draw, Model};
use crate::{
    exit, finish, print_counts, ram_use, Counts, BOARD, CORE, HEIGHT, STRIP_LEN, STRIP_ROWS, WIDTH,
};
use cortex_m_rt::entry;
use cortex_m_semihosting::hprintln;
#[cfg(feature = "clusters")]
use microraster::cull::{Eye, Visit};
use microraster::pixelcolor::{Rgb565, RgbColor};
#[cfg(feature = "cull-masks")]
use microraster::NormalClasses;
use microraster::{Attributes, Config, FragmentShader, Mat4, Mesh, StripRenderer, Submit};
#[cfg(feature = "clusters")]
use microraster::{ClusterCull, ClusterSet, ClusterTest};

/// The baked model (`microraster bake`, see docs/embedded.md).
#[cfg(not(small_spot))]
#[allow(dead_code)]
mod baked {
    include!("../baked/spot.rs");
}
#[cfg(small_spot)]
#[allow(dead_code)]
mod baked {
    include!("../baked/small/spot.rs");
}
/// `COLORS`: the `spot-gouraud` colours, one per vertex (build.rs).
#[allow(dead_code)]
mod colors {
    include!(concat!(env!("OUT_DIR"), "/spot_colors.rs"));
}

/// Spot's triangles in runs with bounding spheres (build.rs).
mod chunks {
    include!(concat!(env!("OUT_DIR"), "/spot_chunks.rs"));
}

/// The cluster set of Spot (`microraster bake --clusters`); `chunks`
/// holds the same triangle order and one sphere per cluster.
#[cfg(feature = "clusters")]
#[allow(dead_code)]
mod clustered {
    include!("../baked/spot_clusters.rs");
}

#[cfg(all(feature = "clusters", small_spot))]
compile_error!("the `clusters` features are for the MPS2 boards (all of Spot)");
#[cfg(all(feature = "cull-masks", feature = "clusters"))]
compile_error!("`cull-masks` draws the Morton order, not the clusters");
#[cfg(all(feature = "herd", any(feature = "clusters", feature = "cull-masks")))]
compile_error!("`herd` draws the Morton runs with the occlusion test, not clusters or masks");
#[cfg(all(feature = "herd", small_spot))]
compile_error!("the `herd` features are for the MPS2 boards (all of Spot)");

/// Spot's normal classes (`microraster bake --normal-masks 16`): the
/// direction cube and the classes' size bounds and spheres; `chunks`
/// holds each triangle's class in the order drawn.
#[cfg(feature = "cull-masks")]
#[allow(dead_code)]
mod masks {
    include!("../baked/spot_classes.rs");
}

#[cfg(feature = "cull-masks")]
fn normal_classes() -> NormalClasses<'static> {
    NormalClasses {
        partitions: masks::PARTITIONS,
        classes: &chunks::CLASSES,
        sizes: &masks::CLASS_SIZES,
        spheres: &masks::CLASS_SPHERES,
    }
}

#[cfg(feature = "clusters")]
const _: () = assert!(
    cfg!(feature = "cull-volumes") as u8
        + cfg!(feature = "cull-volumes-tree") as u8
        + cfg!(feature = "cull-cones") as u8
        <= 1,
    "pick one cluster test: cull-volumes, cull-volumes-tree or cull-cones"
);

/// The cluster test of the build: `None` with `clusters` alone (every
/// cluster drawn, each triangle culled on its own: the baseline).
#[cfg(feature = "clusters")]
const CULL: Option<ClusterCull> = if cfg!(feature = "cull-volumes") {
    Some(ClusterCull {
        test: ClusterTest::Volumes,
        hierarchy: false,
    })
} else if cfg!(feature = "cull-volumes-tree") {
    Some(ClusterCull {
        test: ClusterTest::Volumes,
        hierarchy: true,
    })
} else if cfg!(feature = "cull-cones") {
    Some(ClusterCull {
        test: ClusterTest::Cones,
        hierarchy: false,
    })
} else {
    None
};

/// The build's name for the cluster test, for the first line.
#[cfg(feature = "clusters")]
const CULL_NAME: &str = if cfg!(feature = "cull-volumes") {
    "clusters culled by volumes at the leaves"
} else if cfg!(feature = "cull-volumes-tree") {
    "clusters culled by volumes over the tree"
} else if cfg!(feature = "cull-cones") {
    "clusters culled by normal cones at the leaves"
} else {
    "in cluster order, each triangle culled on its own"
};
#[cfg(not(feature = "clusters"))]
const CULL_NAME: &str = if cfg!(feature = "cull-masks-frame") {
    "in Morton order, one normal mask a frame"
} else if cfg!(feature = "cull-masks") {
    "in Morton order, normal masks of each strip's rows"
} else if cfg!(feature = "herd-occlusion") {
    "a herd of 100 (10x10), in Morton order, occlusion culling"
} else if cfg!(feature = "herd") {
    "a herd of 100 (10x10), in Morton order"
} else {
    "in Morton order"
};

#[cfg(feature = "clusters")]
fn cluster_set() -> ClusterSet<'static> {
    ClusterSet {
        clusters: &clustered::CLUSTERS,
        nodes: &clustered::CLUSTER_NODES,
        vertices: &clustered::CLUSTER_VERTICES,
    }
}

/// The eye the cluster tests use this frame (`Eye::for_frame`, with the
/// size guard, tried first over the whole mesh's sphere: `Eye::within`):
/// `None` draws every cluster.
#[cfg(feature = "clusters")]
fn cluster_eye(mvp: &Mat4, config: &Config) -> Option<Eye> {
    CULL.and_then(|_| Eye::for_frame::<8>(mvp, config))
        .map(|e| e.within(&chunks::WHOLE_SPHERE))
}

/// What the frame's cluster test decided, once for all strips: a bit per
/// cluster, set where it is drawn (64 bytes for Spot's 488 clusters;
/// nothing without `clusters`).
#[cfg(feature = "clusters")]
type Drawn = [u32; clustered::CLUSTER_COUNT.div_ceil(32)];
/// With `cull-masks-frame`: the frame's normal mask, for every strip.
#[cfg(feature = "cull-masks-frame")]
type Drawn = microraster::BackMask;
/// With `herd`: the herd's order front to back, and (in the
/// `herd-occlusion` builds, whose sweep draws each frame both ways)
/// whether the occlusion test is on.
#[cfg(feature = "herd")]
#[derive(Clone, Copy)]
struct Drawn {
    order: [u8; spot_scene::HERD_SPOTS],
    occlude: bool,
}
#[cfg(not(any(feature = "clusters", feature = "cull-masks-frame", feature = "herd")))]
type Drawn = ();

/// Walks the cluster tree once with `eye` (none: every cluster drawn).
#[cfg(feature = "clusters")]
fn drawn_clusters(eye: Option<&Eye>) -> Drawn {
    let mut drawn = [0u32; clustered::CLUSTER_COUNT.div_ceil(32)];
    cluster_set().visit(eye, None, CULL.unwrap_or_default(), |v| {
        if let Visit::Draw(a, b) = v {
            for k in a..b {
                if let Some(w) = drawn.get_mut(k / 32) {
                    *w |= 1 << (k % 32);
                }
            }
        }
    });
    drawn
}

/// The frame's decisions: the eye found and the tree walked (with
/// `clusters`), before the first strip.
fn decide(mvp: &Mat4, config: &Config) -> Drawn {
    #[cfg(feature = "clusters")]
    return drawn_clusters(cluster_eye(mvp, config).as_ref());
    #[cfg(feature = "cull-masks-frame")]
    return microraster::BackMask::for_frame::<8>(mvp, config, None, &normal_classes());
    #[cfg(feature = "herd")]
    {
        let _ = (mvp, config);
        Drawn {
            order: spot_scene::herd_order(spot_scene::HERD_EYE),
            occlude: cfg!(feature = "herd-occlusion"),
        }
    }
    #[cfg(not(any(feature = "clusters", feature = "cull-masks-frame", feature = "herd")))]
    let _ = (mvp, config);
}

/// What a frame took, in SysTick ticks.
struct Measured {
    /// Pixels written, or the error that stopped the frame.
    written: Result<u64, &'static str>,
    /// Camera and lighting set-up before the first strip.
    setup_start: u64,
    /// The first strip began.
    strips_start: u64,
    /// The last strip was pushed.
    end: u64,
    /// One strip's clear.
    one_clear: u64,
    /// The mesh submitted to a one-row strip.
    one_row: u64,
    /// Triangles the strips' occlusion tests hid, and those they were
    /// submitted (each strip's submissions counted: `Stats`); printed by
    /// the `herd` builds.
    #[cfg_attr(not(feature = "herd"), allow(dead_code))]
    hidden: u64,
    #[cfg_attr(not(feature = "herd"), allow(dead_code))]
    submitted: u64,
    /// Of `submitted`, those that reached the strip's triangle tests
    /// (cull, then set up): neither hidden nor skipped as `outside_strip`
    /// or `culled_object`, with their run or one by one.
    #[cfg_attr(not(feature = "herd"), allow(dead_code))]
    reached: u64,
    /// With `clusters`: what the cluster test did (see `ClusterCount`).
    #[cfg(feature = "clusters")]
    clusters: ClusterCount,
    /// With `cull-masks`: what the strips' masks did (see `MaskCount`).
    #[cfg(feature = "cull-masks")]
    masks: MaskCount,
}

/// The frame's normal masks, built again on their own after the frame.
#[cfg(feature = "cull-masks")]
struct MaskCount {
    /// Triangles of a class in its strip's mask, summed over the strips.
    masked: u64,
    /// Ticks of building the masks: every strip's (`Submit::back_mask`),
    /// or with `cull-masks-frame` the frame's one.
    build: u64,
}

/// The frame's cluster test, measured again on its own.
#[cfg(feature = "clusters")]
struct ClusterCount {
    /// Triangles skipped before transform (in every strip).
    skipped: u64,
    /// Decisions made (with the flat test, one per leaf: the nodes
    /// tested; top-down, the settled nodes, fewer than tested).
    tested: u64,
    /// Ticks of `Eye::for_frame`.
    eye: u64,
    /// Ticks of the traversal into the bits of the drawn clusters.
    traversal: u64,
    /// Ticks of the whole mesh, unchunked and untested, submitted to a
    /// one-row strip (every triangle's vertices transformed).
    all_triangles: u64,
    /// Whether the second walk decided as the frame's did.
    same: bool,
}

/// The firmware's strip loop.
struct Strips<'a> {
    config: Config,
    mvp: Mat4,
    color: &'a mut [Rgb565],
    depth: &'a mut [u16],
    display: &'a mut HashDisplay,
    t0: u64,
}

impl Draw for Strips<'_> {
    type Out = Measured;

    fn draw<const N: usize, A: Attributes<N> + Copy, F: FragmentShader<N> + Copy>(
        self,
        mesh: &Mesh<'_, A>,
        fragment: F,
    ) -> Measured {
        let Strips {
            config,
            mvp,
            color,
            depth,
            display,
            t0,
        } = self;
        // `()` without `clusters`: nothing is decided.
        #[allow(clippy::let_unit_value)]
        let drawn = decide(&mvp, &config);
        let strips_start = display.clock.now();
        let drawn_frame = frame(config, &mvp, &drawn, color, depth, display, mesh, fragment);
        let end = display.clock.now();
        let (hidden, submitted, reached) = drawn_frame.map_or((0, 0, 0), |f| f.1);
        let written = drawn_frame.map(|f| f.0);

        let clock = &mut display.clock;
        let t = clock.now();
        color.fill(Rgb565::BLACK);
        depth.fill(u16::MAX);
        let one_clear = clock.now() - t;

        let t = clock.now();
        let w = WIDTH as usize;
        let one = StripRenderer::<_, _, 8, N, _>::with_shader(
            config,
            HEIGHT / 2,
            HEIGHT / 2 + 1,
            &mut color[..w],
            &mut depth[..w],
            fragment,
        );
        if let Ok(mut one) = one {
            let _ = submit_chunks(&mut one, mesh, &mvp, &drawn);
        }
        let one_row = clock.now() - t;
        #[cfg(feature = "clusters")]
        let clusters = {
            let (mut skipped, mut tested) = (0u64, 0u64);
            let t = clock.now();
            let eye = cluster_eye(&mvp, &config);
            let t_eye = clock.now() - t;
            let t = clock.now();
            let again = drawn_clusters(eye.as_ref());
            let traversal = clock.now() - t;
            // The decisions, counted apart so that the traversal's time is
            // its own: at the leaves, one per node tested.
            let set = cluster_set();
            set.visit(eye.as_ref(), None, CULL.unwrap_or_default(), |v| {
                tested += 1;
                if let Visit::Cull(a, b, _) = v {
                    skipped += triangles(a, b);
                }
            });
            let t = clock.now();
            let one = StripRenderer::<_, _, 8, N, _>::with_shader(
                config,
                HEIGHT / 2,
                HEIGHT / 2 + 1,
                &mut color[..w],
                &mut depth[..w],
                fragment,
            );
            if let Ok(mut one) = one {
                let _ = one.submit_mesh(mesh, &mvp, 0);
            }
            let all_triangles = clock.now() - t;
            ClusterCount {
                skipped,
                tested: if eye.is_some() { tested } else { 0 },
                eye: t_eye,
                traversal,
                all_triangles,
                same: again == drawn,
            }
        };

        #[cfg(feature = "cull-masks")]
        let masks = {
            let (mut masked, mut build) = (0u64, 0u64);
            let classes = normal_classes();
            let mut y0 = 0;
            while y0 < HEIGHT {
                let y1 = (y0 + STRIP_ROWS as u32).min(HEIGHT);
                let len = WIDTH as usize * (y1 - y0) as usize;
                let strip = StripRenderer::<_, _, 8, N, _>::with_shader(
                    config,
                    y0,
                    y1,
                    &mut color[..len],
                    &mut depth[..len],
                    fragment,
                );
                if let Ok(strip) = strip {
                    let t = clock.now();
                    #[cfg(not(feature = "cull-masks-frame"))]
                    let mask = strip.back_mask(&mvp, &classes);
                    #[cfg(feature = "cull-masks-frame")]
                    let mask = {
                        let _ = strip;
                        decide(&mvp, &config)
                    };
                    let ticks = clock.now() - t;
                    // The frame's one mask is built once a frame.
                    if !cfg!(feature = "cull-masks-frame") || y0 == 0 {
                        build += ticks;
                    }
                    masked += classes
                        .classes
                        .iter()
                        .filter(|&&c| mask.contains(c))
                        .count() as u64;
                }
                y0 = y1;
            }
            MaskCount { masked, build }
        };

        Measured {
            written,
            setup_start: t0,
            strips_start,
            end,
            one_clear,
            one_row,
            hidden,
            submitted,
            reached,
            #[cfg(feature = "clusters")]
            clusters,
            #[cfg(feature = "cull-masks")]
            masks,
        }
    }
}

/// The cluster builds' camera sweep, drawn through the firmware's strip
/// loop after the frame of record (its own call of the scene's `draw`, so
/// its stack is not on top of the frame's).
#[cfg(feature = "clusters")]
struct SweepFrames<'a> {
    config: Config,
    color: &'a mut [Rgb565],
    depth: &'a mut [u16],
    display: &'a mut HashDisplay,
}

#[cfg(feature = "clusters")]
impl Draw for SweepFrames<'_> {
    type Out = Sweep;

    fn draw<const N: usize, A: Attributes<N> + Copy, F: FragmentShader<N> + Copy>(
        self,
        mesh: &Mesh<'_, A>,
        fragment: F,
    ) -> Sweep {
        let SweepFrames {
            config,
            color,
            depth,
            display,
        } = self;
        // The sweep's frames go through the same display, the frame of
        // record's checksum set aside.
        let saved = display.save();
        let mut s = Sweep::default();
        for k in 0..spot_scene::SWEEP {
            let mvp = spot_scene::sweep_mvp(WIDTH, HEIGHT, k);
            // Culled: the eye, the walk and every strip; then the same
            // frame with every cluster drawn. Pushes excluded.
            let mut sums = [None; 2];
            let mut ticks = [0; 2];
            let mut skipped = 0;
            for (i, culled) in [true, false].into_iter().enumerate() {
                display.restore(Saved::default());
                let t = display.clock.now();
                let drawn = if culled {
                    drawn_clusters(cluster_eye(&mvp, &config).as_ref())
                } else {
                    drawn_clusters(None)
                };
                let ok = frame(config, &mvp, &drawn, color, depth, display, mesh, fragment);
                ticks[i] = display.clock.now() - t - display.ticks;
                sums[i] = display.checksum().filter(|_| ok.is_ok());
                if culled {
                    // The clusters whose bit the walk left clear.
                    skipped = (0..clustered::CLUSTER_COUNT)
                        .filter(|&c| drawn.get(c / 32).is_some_and(|w| w & 1 << (c % 32) == 0))
                        .map(|c| triangles(c, c + 1))
                        .sum();
                }
            }
            s.identical &= sums[0].is_some() && sums[0] == sums[1];
            s.skipped += skipped;
            s.min_skipped = s.min_skipped.min(skipped);
            s.max_skipped = s.max_skipped.max(skipped);
            s.culled += ticks[0];
            s.unculled += ticks[1];
        }
        display.restore(saved);
        s
    }
}

/// The `herd-occlusion` builds' camera sweep ([`spot_scene::HERD_SWEEP`]
/// cameras round the herd at eye height), drawn through the firmware's
/// strip loop after the frame of record, as the cluster builds' sweep is:
/// each frame with the occlusion test and without, and compared.
#[cfg(feature = "herd-occlusion")]
struct HerdSweepFrames<'a> {
    config: Config,
    color: &'a mut [Rgb565],
    depth: &'a mut [u16],
    display: &'a mut HashDisplay,
}

#[cfg(feature = "herd-occlusion")]
impl Draw for HerdSweepFrames<'_> {
    type Out = HerdSweep;

    fn draw<const N: usize, A: Attributes<N> + Copy, F: FragmentShader<N> + Copy>(
        self,
        mesh: &Mesh<'_, A>,
        fragment: F,
    ) -> HerdSweep {
        let HerdSweepFrames {
            config,
            color,
            depth,
            display,
        } = self;
        let saved = display.save();
        let mut s = HerdSweep {
            hidden: 0,
            submitted: 0,
            min_hidden: u64::MAX,
            max_hidden: 0,
            occluded: 0,
            plain: 0,
            identical: true,
        };
        for j in 0..spot_scene::HERD_SWEEP {
            let eye = spot_scene::herd_sweep_eye(j);
            let vp = spot_scene::herd_view(WIDTH, HEIGHT, eye);
            let order = spot_scene::herd_order(eye);
            // Occluded, then the same frame plain. Pushes excluded.
            let mut sums = [None; 2];
            let mut ticks = [0; 2];
            for (i, occlude) in [true, false].into_iter().enumerate() {
                display.restore(Saved::default());
                let t = display.clock.now();
                let drawn = Drawn { order, occlude };
                let f = frame(config, &vp, &drawn, color, depth, display, mesh, fragment);
                ticks[i] = display.clock.now() - t - display.ticks;
                sums[i] = display.checksum().filter(|_| f.is_ok());
                if let (true, Ok((_, (hidden, submitted, _)))) = (occlude, f) {
                    // Per mille of the camera's submissions, for its range.
                    let share = hidden * 1000 / submitted.max(1);
                    s.hidden += hidden;
                    s.submitted += submitted;
                    s.min_hidden = s.min_hidden.min(share);
                    s.max_hidden = s.max_hidden.max(share);
                }
            }
            s.identical &= sums[0].is_some() && sums[0] == sums[1];
            s.occluded += ticks[0];
            s.plain += ticks[1];
        }
        display.restore(saved);
        s
    }
}

/// What the herd sweep measured.
#[cfg(feature = "herd-occlusion")]
struct HerdSweep {
    /// Triangles hidden before transform and submitted to the strips,
    /// summed over the cameras (the strips' counts, as the frame of
    /// record's), and the fewest and most hidden at one camera, per mille
    /// of its submissions.
    hidden: u64,
    submitted: u64,
    min_hidden: u64,
    max_hidden: u64,
    /// Ticks of the frames with the test (pushes excluded), and of the
    /// same frames without it.
    occluded: u64,
    plain: u64,
    /// Whether every occluded frame's checksum equals its plain one's.
    identical: bool,
}

/// The cluster builds' camera sweep ([`spot_scene::SWEEP`] cameras round
/// Spot), each frame drawn culled and with every cluster, and compared.
#[cfg(feature = "clusters")]
struct Sweep {
    /// Triangles skipped before transform, summed over the cameras, and
    /// the fewest and most at one camera.
    skipped: u64,
    min_skipped: u64,
    max_skipped: u64,
    /// Ticks of the culled frames (eye, walk, strips; pushes excluded)
    /// and of the same frames with every cluster drawn.
    culled: u64,
    unculled: u64,
    /// Whether every culled frame's checksum equals its unculled one's.
    identical: bool,
}

#[cfg(feature = "clusters")]
impl Default for Sweep {
    fn default() -> Self {
        Sweep {
            skipped: 0,
            min_skipped: u64::MAX,
            max_skipped: 0,
            culled: 0,
            unculled: 0,
            identical: true,
        }
    }
}

/// Every strip: clear, submit the mesh to a `StripRenderer` for its rows,
/// push the rows. The pixels written, and the triangles the strips' tests
/// hid, were submitted, and reached the triangle tests
/// (`Stats::culled_occlusion`, `Stats::submitted`, the latter less the
/// hidden, `outside_strip` and `culled_object`).
#[allow(clippy::too_many_arguments)]
// Inlined into each caller (the frame of record and the sweep), so that
// neither's stack sits on top of an out-of-line copy (+650 B measured).
#[inline(always)]
fn frame<const N: usize, A: Attributes<N> + Copy, F: FragmentShader<N> + Copy>(
    config: Config,
    mvp: &Mat4,
    drawn: &Drawn,
    color: &mut [Rgb565],
    depth: &mut [u16],
    display: &mut HashDisplay,
    mesh: &Mesh<'_, A>,
    fragment: F,
) -> Result<(u64, (u64, u64, u64)), &'static str> {
    let mut written = 0;
    #[cfg(feature = "herd")]
    let (mut hidden, mut submitted, mut reached) = (0, 0, 0);
    #[cfg(not(feature = "herd"))]
    let (hidden, submitted, reached) = (0, 0, 0);
    let mut y0 = 0;
    while y0 < HEIGHT {
        let y1 = (y0 + STRIP_ROWS as u32).min(HEIGHT);
        let len = WIDTH as usize * (y1 - y0) as usize;
        let (color, depth) = (&mut color[..len], &mut depth[..len]);
        color.fill(Rgb565::BLACK);
        depth.fill(u16::MAX);
        let mut strip =
            StripRenderer::<_, _, 8, N, _>::with_shader(config, y0, y1, color, depth, fragment)
                .map_err(|_| "strip renderer")?;
        submit_chunks(&mut strip, mesh, mvp, drawn)?;
        written += strip.render_stats().pixels_written;
        // Only where printed (the copy of `Stats` moved the cluster
        // builds' counts by up to 1.7 %).
        #[cfg(feature = "herd")]
        {
            let stats = strip.stats();
            hidden += stats.culled_occlusion;
            submitted += stats.submitted;
            reached += stats.submitted
                - stats.culled_occlusion
                - stats.outside_strip
                - stats.culled_object;
        }
        push(display, y0, y1, color)?;
        y0 = y1;
    }
    Ok((written, (hidden, submitted, reached)))
}

/// Submits `mesh` as its runs of `CHUNK_TRIANGLES` triangles, each with
/// its sphere from `chunks::CHUNKS` (build.rs): the strip renderer skips
/// the runs whose sphere lies outside its rows (or the view) before it
/// transforms their vertices. Triangle ids and order are the whole mesh's.
/// Inlined: out of line, its frame and `submit_mesh`'s took 860 bytes more
/// stack (`spot-phong` on the Cortex-M3 overflowed its 24 KB).
#[cfg(not(any(feature = "clusters", feature = "cull-masks", feature = "herd")))]
#[inline(always)]
fn submit_chunks<S: Submit<8, N>, const N: usize, A: Attributes<N> + Copy>(
    strip: &mut S,
    mesh: &Mesh<'_, A>,
    mvp: &Mat4,
    _drawn: &Drawn,
) -> Result<(), &'static str> {
    let runs = mesh.indices.chunks(spot_scene::CHUNK_TRIANGLES);
    for (k, (indices, bounds)) in runs.zip(chunks::CHUNKS.iter()).enumerate() {
        let run = Mesh {
            indices,
            bounds: Some(*bounds),
            ..*mesh
        };
        let first = (k * spot_scene::CHUNK_TRIANGLES) as u32;
        strip.submit_mesh(&run, mvp, first).map_err(|_| "submit")?;
    }
    Ok(())
}

/// With `herd`: the herd's Spots (`spot_scene::HERD`), front to back,
/// each under its own model matrix (`vp` is world to clip), as Morton
/// runs with their spheres, as the single Spot is drawn (the baseline).
/// With `herd-occlusion`, through an `Occluder` over the strip (its hi-z
/// tiles on the stack, 640 bytes): a Spot is tested whole (its sphere and
/// box), then each run with its sphere and box, before anything of it is
/// transformed, and skipped if it lies behind what the strip holds.
/// Conservative, so the frame is the one drawn without it (build.rs's
/// checksum is of the herd drawn plain).
#[cfg(feature = "herd")]
#[inline(always)]
fn submit_chunks<const N: usize, A: Attributes<N> + Copy, F: FragmentShader<N>>(
    strip: &mut StripRenderer<'_, Rgb565, [u16], 8, N, F>,
    mesh: &Mesh<'_, A>,
    vp: &Mat4,
    drawn: &Drawn,
) -> Result<(), &'static str> {
    let n = mesh.indices.len();
    let model = |k: usize| spot_scene::herd_cell_model(drawn.order[k] as usize);
    let run = |k: usize, j: usize, indices, sphere: &microraster::BoundingSphere| {
        let run = Mesh {
            indices,
            bounds: Some(*sphere),
            ..*mesh
        };
        (run, (k * n + j * spot_scene::CHUNK_TRIANGLES) as u32)
    };
    let bounds = chunks::CHUNKS.iter().zip(chunks::BOXES.iter());
    if !(cfg!(feature = "herd-occlusion") && drawn.occlude) {
        for k in 0..spot_scene::HERD_SPOTS {
            let mvp = *vp * model(k);
            let runs = mesh.indices.chunks(spot_scene::CHUNK_TRIANGLES);
            for (j, (indices, (sphere, _))) in runs.zip(bounds.clone()).enumerate() {
                let (run, first) = run(k, j, indices, sphere);
                strip.submit_mesh(&run, &mvp, first).map_err(|_| "submit")?;
            }
        }
        return Ok(());
    }
    #[cfg(feature = "herd-occlusion")]
    {
        use microraster::occlusion::{tiles_for, HiZTile};
        let mut tiles = [HiZTile::default(); tiles_for(WIDTH, STRIP_ROWS as u32)];
        let mut o = strip.occluder(&mut tiles).map_err(|_| "occluder")?;
        for k in 0..spot_scene::HERD_SPOTS {
            let mvp = *vp * model(k);
            let whole = (&chunks::WHOLE_SPHERE, &chunks::WHOLE_BOX);
            if o.skips(Some(whole.0), Some(whole.1), &mvp, n as u64) {
                continue;
            }
            let runs = mesh.indices.chunks(spot_scene::CHUNK_TRIANGLES);
            for (j, (indices, (sphere, aabb))) in runs.zip(bounds.clone()).enumerate() {
                let (run, first) = run(k, j, indices, sphere);
                let count = indices.len() as u64;
                o.submit_bounded(Some(sphere), Some(aabb), &mvp, count, |r| {
                    r.submit_mesh(&run, &mvp, first)
                })
                .map_err(|_| "submit")?;
            }
        }
    }
    Ok(())
}

/// With `cull-masks`: the Morton runs as without it, each through
/// `Submit::submit_mesh_masked` with its classes and the strip's normal
/// mask (`Submit::back_mask`, of the strip's rows; with
/// `cull-masks-frame` the frame's, in `drawn`): a triangle of a class in
/// the mask is skipped unread. A masked triangle is culled by winding
/// wherever it shows in the strip (the mask's guarantee), so the frame is
/// the one drawn without masks.
#[cfg(all(feature = "cull-masks", not(feature = "clusters")))]
#[inline(always)]
fn submit_chunks<S: Submit<8, N>, const N: usize, A: Attributes<N> + Copy>(
    strip: &mut S,
    mesh: &Mesh<'_, A>,
    mvp: &Mat4,
    drawn: &Drawn,
) -> Result<(), &'static str> {
    #[cfg(not(feature = "cull-masks-frame"))]
    let mask = &{
        let _ = drawn;
        strip.back_mask(mvp, &normal_classes())
    };
    #[cfg(feature = "cull-masks-frame")]
    let mask = drawn;
    let runs = mesh
        .indices
        .chunks(spot_scene::CHUNK_TRIANGLES)
        .zip(chunks::CLASSES.chunks(spot_scene::CHUNK_TRIANGLES));
    for (k, ((indices, classes), bounds)) in runs.zip(chunks::CHUNKS.iter()).enumerate() {
        let run = Mesh {
            indices,
            bounds: Some(*bounds),
            ..*mesh
        };
        let first = (k * spot_scene::CHUNK_TRIANGLES) as u32;
        strip
            .submit_mesh_masked(&run, mvp, classes, mask, first)
            .map_err(|_| "submit")?;
    }
    Ok(())
}

/// With `clusters`: submits each cluster the frame's test drew (its bit
/// in `drawn`) as a run with its sphere, as the Morton runs are submitted
/// without clusters. A skipped cluster's vertices are never transformed;
/// the frame is the one drawn with no cluster test (build.rs's checksum
/// is of that frame).
#[cfg(feature = "clusters")]
#[inline(always)]
fn submit_chunks<S: Submit<8, N>, const N: usize, A: Attributes<N> + Copy>(
    strip: &mut S,
    mesh: &Mesh<'_, A>,
    mvp: &Mat4,
    drawn: &Drawn,
) -> Result<(), &'static str> {
    let runs = clustered::CLUSTERS.iter().zip(chunks::CHUNKS.iter());
    for (i, (k, bounds)) in runs.enumerate() {
        if drawn.get(i / 32).is_none_or(|w| w & (1 << (i % 32)) == 0) {
            continue;
        }
        let [t0, t1] = k.triangles.map(|t| t as usize);
        let indices = mesh.indices.get(t0..t1).ok_or("cluster range")?;
        let run = Mesh {
            indices,
            bounds: Some(*bounds),
            ..*mesh
        };
        strip
            .submit_mesh(&run, mvp, t0 as u32)
            .map_err(|_| "submit")?;
    }
    Ok(())
}

/// The triangles of clusters `a..b`.
#[cfg(feature = "clusters")]
fn triangles(a: usize, b: usize) -> u64 {
    cluster_set().clusters.get(a..b).map_or(0, |c| {
        c.iter()
            .map(|k| u64::from(k.triangles[1] - k.triangles[0]))
            .sum()
    })
}

#[entry]
fn main() -> ! {
    static mut COLOR: [Rgb565; STRIP_LEN] = [Rgb565::BLACK; STRIP_LEN];
    static mut DEPTH: [u16; STRIP_LEN] = [0; STRIP_LEN];

    let p = cortex_m::Peripherals::take().unwrap();
    let mut clock = Clock::start(p.SYST);
    let (cal_instr, cal_ticks) = clock.instructions_per_tick();
    let instr = |ticks: u64| ticks * cal_instr / cal_ticks;
    let mut display = HashDisplay::new(WIDTH, HEIGHT, clock);
    let model = Model {
        positions: &baked::POSITIONS,
        indices: &chunks::INDICES,
        normals: &baked::NORMALS,
        uvs: &baked::UVS,
        texture: &baked::TEXTURE,
        texture_width: baked::TEXTURE_WIDTH,
        texture_height: baked::TEXTURE_HEIGHT,
        diffuse: baked::MATERIAL_DIFFUSE[0],
        colors: &colors::COLORS,
    };

    #[cfg(feature = "clusters")]
    if cluster_set()
        .validate(model.indices.len(), model.positions.len())
        .is_err()
    {
        hprintln!("FAIL: the baked cluster set does not fit the mesh");
        exit(false)
    }

    #[cfg(feature = "cull-masks")]
    if normal_classes().validate(model.indices.len()).is_err() {
        hprintln!("FAIL: the baked normal classes do not fit the mesh");
        exit(false)
    }

    let t0 = display.clock.now();
    let config = Config::new(WIDTH, HEIGHT);
    let strips = Strips {
        config,
        mvp: spot_scene::mvp(WIDTH, HEIGHT),
        color: &mut COLOR[..],
        depth: &mut DEPTH[..],
        display: &mut display,
        t0,
    };
    let m = match spot_scene::draw(&model, strips) {
        Ok(m) => m,
        Err(e) => {
            hprintln!("FAIL: scene: {}", e);
            exit(false)
        }
    };
    #[cfg(feature = "clusters")]
    let sweep = {
        let frames = SweepFrames {
            config,
            color: &mut COLOR[..],
            depth: &mut DEPTH[..],
            display: &mut display,
        };
        match spot_scene::draw(&model, frames) {
            Ok(s) => s,
            Err(e) => {
                hprintln!("FAIL: sweep: {}", e);
                exit(false)
            }
        }
    };
    #[cfg(feature = "herd-occlusion")]
    let herd_sweep = {
        let frames = HerdSweepFrames {
            config,
            color: &mut COLOR[..],
            depth: &mut DEPTH[..],
            display: &mut display,
        };
        match spot_scene::draw(&model, frames) {
            Ok(s) => s,
            Err(e) => {
                hprintln!("FAIL: herd sweep: {}", e);
                exit(false)
            }
        }
    };
    let written = match m.written {
        Ok(w) => w,
        Err(e) => {
            hprintln!("FAIL: drawing the frame: {}", e);
            exit(false)
        }
    };
    let checksum = display.checksum();
    let (statics, stack) = ram_use();

    let strips = HEIGHT.div_ceil(STRIP_ROWS as u32) as u64;
    let frame = instr(m.end - m.setup_start);
    let shown = instr(display.ticks);
    let render = frame - shown;
    let clears = instr(m.one_clear * strips);
    let geometry =
        instr(m.one_row * strips + (m.strips_start - m.setup_start)).min(render - clears);
    let raster = render - clears - geometry;

    hprintln!(
        "microraster firmware: {} ({}), {}x{} Rgb565, depth u16, Spot ({} triangles, {}), {}, immediate, {} strips of {} rows",
        BOARD,
        CORE,
        WIDTH,
        HEIGHT,
        model.indices.len(),
        CULL_NAME,
        spot_scene::VARIANT,
        strips,
        STRIP_ROWS,
    );
    print_counts(
        checksum,
        &Counts {
            per_tick: (cal_instr, cal_ticks),
            written,
            frame,
            shown,
            render,
            clears,
            geometry,
            raster,
            strips: Some(strips),
        },
    );
    #[cfg(feature = "clusters")]
    {
        let c = &m.clusters;
        let total = model.indices.len() as u64;
        let (a, b) = ratio(c.skipped * 100, total);
        hprintln!(
            "clusters {} ({} nodes): skipped before transform {} of {} triangles ({}.{} %)",
            clustered::CLUSTERS.len(),
            clustered::CLUSTER_NODES.len(),
            c.skipped,
            total,
            a,
            b
        );
        // t/r of the lecture's cost model: one node test against one
        // triangle's processing (the whole mesh, untested, to one row).
        if c.tested == 0 {
            hprintln!("no cluster test: every cluster drawn");
        }
        let traversal = instr(c.traversal);
        let (ta, tb) = ratio(traversal, c.tested.max(1));
        let (ra, rb) = ratio(instr(c.all_triangles), total);
        let d = instr(c.all_triangles) * c.tested.max(1);
        let q = (traversal * total * 100 + d / 2) / d.max(1);
        let (qa, qb) = (q / 100, q % 100);
        if c.tested > 0 {
            hprintln!(
                "cluster test once a frame: eye {}, traversal {} ({} decisions, {}.{} each)",
                instr(c.eye),
                traversal,
                c.tested,
                ta,
                tb,
            );
            hprintln!(
                "a triangle unculled (whole mesh to one row) {}.{}; t/r {}.{:02}",
                ra,
                rb,
                qa,
                qb
            );
        }
        if !c.same {
            hprintln!("FAIL: the cluster test decided differently the second time");
            exit(false)
        }
        let s = &sweep;
        let n = spot_scene::SWEEP as u64;
        let (a, b) = ratio(s.skipped * 100, total * n);
        let (lo, lb) = ratio(s.min_skipped * 100, total);
        let (hi, hb) = ratio(s.max_skipped * 100, total);
        let (culled, unculled) = (instr(s.culled) / n, instr(s.unculled) / n);
        let q = (culled * 1000 + unculled / 2) / unculled.max(1);
        hprintln!(
            "sweep of {} cameras: skipped before transform {}.{} % ({}.{}-{}.{} %); render a frame {} culled, {} with every cluster ({}.{:03}x)",
            n,
            a,
            b,
            lo,
            lb,
            hi,
            hb,
            culled,
            unculled,
            q / 1000,
            q % 1000
        );
        if !s.identical {
            hprintln!(
                "FAIL: a sweep frame culled differs from the same frame with every cluster drawn"
            );
            exit(false)
        }
    }
    #[cfg(feature = "herd")]
    {
        let (a, b) = ratio(m.hidden * 100, m.submitted);
        hprintln!(
            "herd of {} Spots: hidden by occlusion before transform {} of {} triangles submitted to the strips ({}.{} %); {} reached the strips' triangle tests",
            spot_scene::HERD_SPOTS,
            m.hidden,
            m.submitted,
            a,
            b,
            m.reached
        );
    }
    #[cfg(feature = "herd-occlusion")]
    {
        let s = &herd_sweep;
        let n = spot_scene::HERD_SWEEP as u64;
        let (a, b) = ratio(s.hidden * 100, s.submitted);
        let (occluded, plain) = (instr(s.occluded) / n, instr(s.plain) / n);
        let q = (occluded * 1000 + plain / 2) / plain.max(1);
        hprintln!(
            "herd sweep of {} cameras: hidden by occlusion before transform {}.{} % of the triangles submitted to the strips ({}.{}-{}.{} %); render a frame {} with the test, {} without ({}.{:03}x)",
            n,
            a,
            b,
            s.min_hidden / 10,
            s.min_hidden % 10,
            s.max_hidden / 10,
            s.max_hidden % 10,
            occluded,
            plain,
            q / 1000,
            q % 1000
        );
        if !s.identical {
            hprintln!("FAIL: a herd sweep frame with the occlusion test differs from the same frame without it");
            exit(false)
        }
    }
    #[cfg(feature = "cull-masks")]
    {
        let c = &m.masks;
        let total = model.indices.len() as u64 * strips;
        let (a, b) = ratio(c.masked * 100, total);
        hprintln!(
            "normal masks (N = {}, {} classes, {}): masked {} of {} triangles over the {} strips ({}.{} %), built in {} instructions a frame",
            masks::PARTITIONS,
            masks::CLASS_COUNT,
            if cfg!(feature = "cull-masks-frame") {
                "one a frame"
            } else {
                "one a strip"
            },
            c.masked,
            total,
            strips,
            a,
            b,
            instr(c.build)
        );
    }
    finish(checksum, statics, stack)
}
