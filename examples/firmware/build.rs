//! Picks the board for the target, and renders the firmware's frame on the
//! host to embed its checksum.
//!
//! Board: one per target triple (the runner in `.cargo/config.toml` starts
//! the matching QEMU machine). Its `memory/*.x` is copied to `OUT_DIR` as
//! `memory.x` for cortex-m-rt's `link.x`, and the strip height that fits
//! its RAM goes into `board.rs`.
//!
//! Checksum: the same scene, frame size, pixel format and depth buffer as
//! the firmware, rendered here by the same core crate on the host. On
//! purpose by the other path: the whole frame set up once in a [`Frame`]
//! and rendered as one 240-row strip, where the firmware submits the scene
//! strip by strip (set up once into a `Frame`, or submitted to a
//! `StripRenderer` for every strip with `--features immediate`). The hash is the
//! firmware's: `microraster_scenes::checksum::FrameChecksum` over the
//! `Rgb565` pixels, rows top to bottom.
//!
//! The configuration features (`subpixel4`, `depth-u32`, `micromath`,
//! `no-i32-edges`) are mirrored: the host frame is a `Frame::<4>` with
//! `subpixel4`, has a `u32` depth buffer with `depth-u32`, and the core
//! and scenes crates built here have the firmware's float backend and
//! edge path (the crate's features enable the same features of the
//! build-dependencies), so the frame is the same configuration's.
//!
//! With a `spot-*` feature the frame is baked Spot instead
//! (`src/spot_scene.rs`, compiled here too, with the same features): the
//! whole mesh set up once in a `Frame<8, N>` and rendered with
//! `render_rows_shaded`, where the firmware gives every strip a
//! `StripRenderer::with_shader`. The micro:bit gets the decimated bake
//! (`cfg(small_spot)`), and `spot-gouraud`'s per-vertex colours are
//! written here as a static (`spot_colors.rs`) so that they sit in flash.
//! With `clusters` (and `cull-*`) the triangles are in the baked cluster
//! order (`baked/spot_clusters.rs`) and the frame is drawn unculled here:
//! the firmware's cluster tests must leave it unchanged.
//!
//! With `house` the frame is the baked house (`baked/house.rs`) drawn
//! whole, set up once in a `Frame`: the firmware's portal test must leave
//! it unchanged.

use microraster::pixelcolor::{IntoStorage, Rgb565, RgbColor};
#[cfg(not(any(feature = "spot", feature = "house")))]
use microraster::NoDepth;
#[cfg(feature = "spot")]
use microraster::{Attributes, FragmentShader, Mesh};
use microraster::{Config, Frame, SetupTriangle, Submit};
use microraster_scenes::checksum::FrameChecksum;
#[cfg(not(any(feature = "spot", feature = "house")))]
use microraster_scenes::cubes;
use std::env;
use std::fmt::Write as _;
use std::fs;
use std::path::PathBuf;

const WIDTH: u32 = 320;
const HEIGHT: u32 = 240;

/// The Spot frame's shading (the firmware's own file, compiled here with
/// the same features).
#[cfg(feature = "spot")]
#[path = "src/spot_scene.rs"]
mod spot_scene;

/// The baked models: all of Spot (MPS2 boards) and Spot decimated to
/// 1,478 triangles with a 128x128 texture (the micro:bit's 256 KB flash).
#[cfg(feature = "spot")]
#[allow(dead_code)]
mod spot_full {
    include!("baked/spot.rs");
}
#[cfg(feature = "spot")]
#[allow(dead_code)]
mod spot_small {
    include!("baked/small/spot.rs");
}
/// All of Spot's triangles in cluster order, with the cluster set
/// (`microraster bake --clusters`), for the `clusters` features.
#[cfg(feature = "clusters")]
#[allow(dead_code)]
mod spot_clusters {
    include!("baked/spot_clusters.rs");
}

/// Spot's normal classes in the baked order (`microraster bake
/// --normal-masks 16`), for `cull-masks`.
#[cfg(feature = "cull-masks")]
#[allow(dead_code)]
mod spot_classes {
    include!("baked/spot_classes.rs");
}

/// The order of Spot's triangles: Morton order of their centroids (see
/// [`morton_order`]), or with `clusters` the baked cluster order.
#[cfg(feature = "spot")]
fn spot_order(positions: &[microraster::Vec3], indices: &[[u32; 3]]) -> Vec<[u32; 3]> {
    #[cfg(feature = "clusters")]
    {
        let _ = (positions, indices);
        spot_clusters::CLUSTER_INDICES.to_vec()
    }
    #[cfg(not(feature = "clusters"))]
    morton_order(positions, indices)
}

/// The runs of Spot's triangles a strip tests by sphere: every
/// `CHUNK_TRIANGLES`, or with `clusters` the clusters.
#[cfg(feature = "spot")]
fn spot_runs(triangles: usize) -> Vec<[usize; 2]> {
    #[cfg(feature = "clusters")]
    {
        let _ = triangles;
        spot_clusters::CLUSTERS
            .iter()
            .map(|c| c.triangles.map(|t| t as usize))
            .collect()
    }
    #[cfg(not(feature = "clusters"))]
    (0..triangles)
        .step_by(spot_scene::CHUNK_TRIANGLES)
        .map(|a| [a, (a + spot_scene::CHUNK_TRIANGLES).min(triangles)])
        .collect()
}

/// Spot's rows per strip (immediate mode, 1,280 B a row of colour and
/// depth; the stack needs 2.5 to 3.5 KB beside them). MPS2 (24 KB): 16
/// rows, 15 strips (17 would fit but still take 15 strips). micro:bit
/// (16 KB): 9 rows, 27 strips (10 would leave `spot-phong` 64 bytes).
const SPOT_ROWS_MPS2: u32 = 16;
/// With `clusters` (baseline included, so that it draws the same
/// strips): the eye and the walk of the cluster tree take 336 B more
/// stack, which at 16 rows would leave `spot-lit` 36 B of the 24 KB and
/// the textured and Phong shadings none. With `herd` too: the occluder's
/// hi-z tiles (640 B) are on the stack.
const SPOT_ROWS_MPS2_CLUSTERS: u32 = 15;
const SPOT_ROWS_MICROBIT: u32 = 9;

struct Board {
    name: &'static str,
    core: &'static str,
    memory: &'static str,
    strip_rows: u32,
}

/// The board for `target`, and its strip height for the mode: immediate
/// mode (`immediate` feature) needs no setup storage, so its strips can
/// be taller; set-up-once mode keeps the frame's set-up triangles
/// (`SETUP_CAPACITY` of them, 112 B each) and pays for them in strip rows.
fn board(target: &str, immediate: bool, spot: bool, depth_u32: bool, clipless: bool) -> Board {
    let rows = |setup_once: u32, immediate_rows: u32| {
        if spot {
            // Spot: immediate mode, the rows that fit beside the stack
            // (the model and texture are in flash).
            match target {
                "thumbv6m-none-eabi" => SPOT_ROWS_MICROBIT,
                _ if cfg!(any(
                    feature = "clusters",
                    feature = "herd",
                    feature = "house"
                )) =>
                {
                    SPOT_ROWS_MPS2_CLUSTERS
                }
                _ => SPOT_ROWS_MPS2,
            }
        } else if depth_u32 {
            // A `u32` depth buffer: 1,920 B a row of colour and depth
            // instead of 1,280, so fewer rows fit the same RAM: 9 on the
            // MPS2 boards (set up once; 11 immediate), 4 on the micro:bit
            // (6 immediate).
            match target {
                "thumbv6m-none-eabi" => {
                    if immediate {
                        6
                    } else {
                        4
                    }
                }
                _ => {
                    if immediate {
                        11
                    } else {
                        9
                    }
                }
            }
        } else if immediate && clipless && target != "thumbv6m-none-eabi" {
            // The clipless mode's stack on the MPS2 boards (4.2 KB) leaves
            // 15 rows 4 bytes short of the 24 KB since `Stats` gained a
            // counter (`culled_occlusion`): one row fewer.
            immediate_rows - 1
        } else if immediate {
            immediate_rows
        } else {
            setup_once
        }
    };
    match target {
        "thumbv7em-none-eabihf" => Board {
            name: "mps2-an386",
            core: "Cortex-M4F",
            // Of the 24 KB budget: 12 rows of colour and depth (15 KB) and
            // the set-up triangles (3.5 KB), or 15 rows (18.75 KB) in
            // immediate mode; both keep the frame's processed vertices
            // (1.1 KB).
            memory: "mps2.x",
            strip_rows: rows(12, 15),
        },
        // The same budget; in immediate mode 14 rows: the batched flat
        // rows' stack (the M3 does `f32` in software, and spills more)
        // left 15 rows 116 B over the 24 KB.
        "thumbv7m-none-eabi" => Board {
            name: "mps2-an385",
            core: "Cortex-M3",
            memory: "mps2.x",
            strip_rows: rows(12, 14),
        },
        // 16 KB of RAM: 5 rows (6.25 KB) and the set-up triangles, or 8
        // rows (10 KB) in immediate mode.
        "thumbv6m-none-eabi" => Board {
            name: "microbit",
            core: "Cortex-M0",
            memory: "microbit.x",
            strip_rows: rows(5, 8),
        },
        other => panic!(
            "no board for target {other}: build with --target thumbv7em-none-eabihf \
             (mps2-an386), thumbv7m-none-eabi (mps2-an385) or thumbv6m-none-eabi (microbit)"
        ),
    }
}

/// The frame's checksum as the display receives it.
fn frame_checksum(pixels: &[Rgb565]) -> u64 {
    let mut c = FrameChecksum::new();
    c.extend(pixels.iter().map(|p| p.into_storage()));
    c.value()
}

/// The cubes' frame settings and their matrices, with the same callback
/// as `cubes::for_each_cube`: window z, or with `inv-w` 1/w depth
/// (`DepthFunc::Greater`).
#[cfg(not(any(feature = "spot", feature = "house")))]
fn cubes_config(
    mut draw: impl FnMut(&microraster::Mesh<'static>, &microraster::Mat4, u32),
) -> Config {
    let mut config = Config::new(WIDTH, HEIGHT);
    let mvps = if cfg!(feature = "inv-w") {
        config.depth_func = microraster::DepthFunc::Greater;
        cubes::mvps_inv_w(WIDTH, HEIGHT)
    } else {
        cubes::mvps(WIDTH, HEIGHT)
    };
    for (i, mvp) in mvps.iter().enumerate() {
        draw(&cubes::MESH, mvp, (i * cubes::CUBE_INDICES.len()) as u32);
    }
    config
}

/// The depth buffer's clear value as a `Z32` (0 for 1/w depth).
#[cfg(not(any(feature = "spot", feature = "house")))]
const CLEAR_Z32: u32 = if cfg!(feature = "inv-w") { 0 } else { u32::MAX };

#[cfg(not(any(feature = "spot", feature = "house")))]
fn host_checksum(depth: bool) -> u64 {
    if cfg!(feature = "clipless") {
        return clipless_checksum(depth);
    }
    let mut storage = vec![SetupTriangle::EMPTY; cubes::CUBE_INDICES.len() * 4 * 7];
    const S: u32 = if cfg!(feature = "subpixel4") { 4 } else { 8 };
    let config = cubes_config(|_, _, _| {});
    let mut frame = Frame::<S>::with_subpixel_bits(config, &mut storage).unwrap();
    cubes_config(|mesh, mvp, id| frame.submit_mesh(mesh, mvp, id).unwrap());
    let n = (WIDTH * HEIGHT) as usize;
    let mut color = vec![Rgb565::BLACK; n];
    if depth && cfg!(feature = "depth-u32") {
        let mut z = vec![CLEAR_Z32; n];
        frame.render_rows(0, HEIGHT, &mut color, &mut z[..])
    } else if depth {
        let mut z = vec![(CLEAR_Z32 >> 16) as u16; n];
        frame.render_rows(0, HEIGHT, &mut color, &mut z[..])
    } else {
        frame.render_rows(0, HEIGHT, &mut color, &mut NoDepth)
    }
    .unwrap();
    frame_checksum(&color)
}

/// The cubes in the clipless mode, drawn whole by one strip renderer.
#[cfg(not(any(feature = "spot", feature = "house")))]
fn clipless_checksum(depth: bool) -> u64 {
    let mut config = cubes_config(|_, _, _| {});
    config.mode = microraster::RasterMode::Clipless;
    let n = (WIDTH * HEIGHT) as usize;
    let mut color = vec![Rgb565::BLACK; n];
    let mut z = vec![(CLEAR_Z32 >> 16) as u16; n];
    let mut none = NoDepth;
    let draw = |strip: &mut dyn FnMut(&microraster::Mesh<'_>, &microraster::Mat4, u32)| {
        cubes_config(|mesh, mvp, id| strip(mesh, mvp, id));
    };
    if depth {
        let mut r =
            microraster::StripRenderer::new(config, 0, HEIGHT, &mut color, &mut z[..]).unwrap();
        draw(&mut |m, mvp, id| r.submit_mesh(m, mvp, id).unwrap());
    } else {
        let mut r =
            microraster::StripRenderer::new(config, 0, HEIGHT, &mut color, &mut none).unwrap();
        draw(&mut |m, mvp, id| r.submit_mesh(m, mvp, id).unwrap());
    }
    frame_checksum(&color)
}

/// The baked house (`microraster bake-house`), for the `house` features.
#[cfg(feature = "house")]
#[allow(dead_code)]
mod house {
    include!("baked/house.rs");
}

/// The house drawn whole (every room, no portal test) by the other path:
/// every object set up once in a `Frame`, rendered as one 240-row strip.
#[cfg(feature = "house")]
fn house_checksum() -> u64 {
    use microraster::MeshColors;
    assert_eq!((house::WIDTH, house::HEIGHT), (WIDTH, HEIGHT));
    let mut storage = vec![SetupTriangle::EMPTY; 2 * house::INDICES.len()];
    let config = Config::new(WIDTH, HEIGHT);
    let mut frame = Frame::<8>::with_subpixel_bits(config, &mut storage).unwrap();
    for o in &house::OBJECTS {
        let range = |r: [u32; 2]| r[0] as usize..r[1] as usize;
        let colors = &house::COLORS[range(o.colors)];
        let mesh = microraster::Mesh {
            positions: &house::POSITIONS[range(o.positions)],
            indices: &house::INDICES[range(o.triangles)],
            attributes: if o.per_vertex {
                MeshColors::PerVertex(colors)
            } else {
                MeshColors::PerTriangle(colors)
            },
            bounds: Some(o.sphere),
        };
        frame
            .submit_mesh(&mesh, &house::VIEW_PROJ, o.triangles[0])
            .unwrap();
    }
    let n = (WIDTH * HEIGHT) as usize;
    let mut color = vec![Rgb565::BLACK; n];
    let mut z = vec![u16::MAX; n];
    frame
        .render_rows(0, HEIGHT, &mut color, &mut z[..])
        .unwrap();
    frame_checksum(&color)
}

/// Spot's model for the target, with the `spot-gouraud` colours.
#[cfg(feature = "spot")]
fn spot_model(small: bool) -> spot_scene::Model<'static> {
    macro_rules! model {
        ($m:ident) => {
            spot_scene::Model {
                positions: &$m::POSITIONS,
                indices: Vec::leak(spot_order(&$m::POSITIONS, &$m::INDICES)),
                normals: &$m::NORMALS,
                uvs: &$m::UVS,
                texture: &$m::TEXTURE,
                texture_width: $m::TEXTURE_WIDTH,
                texture_height: $m::TEXTURE_HEIGHT,
                diffuse: $m::MATERIAL_DIFFUSE[0],
                colors: Vec::leak(
                    $m::NORMALS
                        .iter()
                        .map(|&n| spot_scene::normal_color(n))
                        .collect(),
                ),
            }
        };
    }
    if small {
        model!(spot_small)
    } else {
        model!(spot_full)
    }
}

/// The host's path for Spot: the whole mesh set up once in one `Frame`
/// and rendered as one 240-row strip with `render_rows_shaded`.
#[cfg(feature = "spot")]
struct HostFrame;

#[cfg(feature = "spot")]
impl spot_scene::Draw for HostFrame {
    type Out = u64;
    fn draw<const N: usize, A: Attributes<N> + Copy, F: FragmentShader<N> + Copy>(
        self,
        mesh: &Mesh<'_, A>,
        fragment: F,
    ) -> u64 {
        // With `herd`, every Spot of the herd in its order (ids on from
        // the one before), as the firmware's strips submit them.
        let spots = if cfg!(feature = "herd") {
            spot_scene::HERD_SPOTS
        } else {
            1
        };
        // Room for every triangle clipped into up to seven (one Spot), or
        // into two (the herd: its nearest Spot is 1.5 from the eye, far
        // behind the 0.5 near plane; a full storage fails the build).
        let per_triangle = if spots == 1 { 7 } else { 2 };
        let mut storage =
            vec![SetupTriangle::<N>::EMPTY; mesh.indices.len() * per_triangle * spots];
        let config = Config::new(WIDTH, HEIGHT);
        let mut frame = Frame::<8, N>::with_subpixel_bits(config, &mut storage).unwrap();
        let vp = spot_scene::mvp(WIDTH, HEIGHT);
        for k in 0..spots {
            let mvp = if cfg!(feature = "herd") {
                vp * spot_scene::herd_model(k)
            } else {
                vp
            };
            let first = (k * mesh.indices.len()) as u32;
            frame.submit_mesh(mesh, &mvp, first).unwrap();
        }
        let n = (WIDTH * HEIGHT) as usize;
        let mut color = vec![Rgb565::BLACK; n];
        let mut z = vec![u16::MAX; n];
        frame
            .render_rows_shaded(0, HEIGHT, &mut color, &mut z[..], &fragment)
            .unwrap();
        // To look at the frame: MICRORASTER_FIRMWARE_PPM=/path/spot.ppm.
        if let Some(path) = env::var_os("MICRORASTER_FIRMWARE_PPM") {
            let mut ppm = format!("P6\n{WIDTH} {HEIGHT}\n255\n").into_bytes();
            for &c in &color {
                let c = microraster::pixelcolor::Rgb888::from(c);
                ppm.extend([c.r(), c.g(), c.b()]);
            }
            fs::write(path, ppm).unwrap();
        }
        frame_checksum(&color)
    }
}

/// Writes `spot_colors.rs` (the `spot-gouraud` colours as a static, for
/// flash) and returns the host's checksum of the Spot frame.
#[cfg(feature = "spot")]
fn spot_frame(out: &std::path::Path, small: bool) -> u64 {
    let model = spot_model(small);
    let mut s = String::from(
        "/// `spot-gouraud`'s colours: each vertex normal `n` as `(n + 1) / 2` (build.rs).\n\
         pub static COLORS: [microraster::pixelcolor::Rgb888; ",
    );
    writeln!(s, "{}] = [", model.colors.len()).unwrap();
    for c in model.colors {
        use microraster::pixelcolor::RgbColor;
        writeln!(
            s,
            "    microraster::pixelcolor::Rgb888::new({}, {}, {}),",
            c.r(),
            c.g(),
            c.b()
        )
        .unwrap();
    }
    s.push_str("];\n");
    fs::write(out.join("spot_colors.rs"), s).unwrap();
    fs::write(out.join("spot_chunks.rs"), spot_chunks(&model)).unwrap();
    spot_scene::draw(&model, HostFrame).unwrap()
}

/// The triangles of `indices` in Morton order of their centroids (10 bits
/// an axis over the model's box), so that runs of consecutive triangles
/// are compact. Stable: ties keep the baked order.
#[cfg(all(feature = "spot", not(feature = "clusters")))]
fn morton_order(positions: &[microraster::Vec3], indices: &[[u32; 3]]) -> Vec<[u32; 3]> {
    let centroid = |t: &[u32; 3]| {
        let p = t.map(|i| positions[i as usize]);
        [
            (p[0].x + p[1].x + p[2].x) / 3.0,
            (p[0].y + p[1].y + p[2].y) / 3.0,
            (p[0].z + p[1].z + p[2].z) / 3.0,
        ]
    };
    let (mut lo, mut hi) = ([f32::MAX; 3], [f32::MIN; 3]);
    for t in indices {
        let c = centroid(t);
        for a in 0..3 {
            lo[a] = lo[a].min(c[a]);
            hi[a] = hi[a].max(c[a]);
        }
    }
    let spread = |v: u32| {
        let mut m = 0u32;
        for b in 0..10 {
            m |= ((v >> b) & 1) << (3 * b);
        }
        m
    };
    let key = |t: &[u32; 3]| {
        let c = centroid(t);
        let q = |a: usize| (((c[a] - lo[a]) / (hi[a] - lo[a]).max(1e-30)) * 1023.0) as u32;
        spread(q(0)) | spread(q(1)) << 1 | spread(q(2)) << 2
    };
    let mut out = indices.to_vec();
    out.sort_by_key(key);
    out
}

/// `spot_chunks.rs`: the mesh's triangles (in Morton order, see
/// `morton_order`, or in cluster order with `clusters`; the host's frame
/// draws them in the same order) in runs (`spot_runs`: of
/// `spot_scene::CHUNK_TRIANGLES`, or the clusters), each with a sphere
/// around its vertices (`BoundingSphere::from_points`), for flash. A strip
/// renderer skips a run whose sphere lies outside its rows before it
/// transforms a vertex.
#[cfg(feature = "spot")]
fn spot_chunks(model: &spot_scene::Model<'_>) -> String {
    let mut s = String::from(
        "/// Spot's triangles in runs of `CHUNK_TRIANGLES`, each with a sphere\n\
         /// around its vertices (build.rs).\n",
    );
    writeln!(
        s,
        "pub static INDICES: [[u32; 3]; {}] = [",
        model.indices.len()
    )
    .unwrap();
    for t in model.indices {
        writeln!(s, "    [{}, {}, {}],", t[0], t[1], t[2]).unwrap();
    }
    s.push_str("];\n");
    let chunks: Vec<_> = spot_runs(model.indices.len())
        .into_iter()
        .map(|[a, b]| {
            let tris = &model.indices[a..b];
            let points: Vec<_> = tris
                .iter()
                .flatten()
                .map(|&i| model.positions[i as usize])
                .collect();
            microraster::BoundingSphere::from_points(&points).unwrap()
        })
        .collect();
    writeln!(
        s,
        "pub static CHUNKS: [microraster::BoundingSphere; {}] = [",
        chunks.len()
    )
    .unwrap();
    for b in chunks {
        let c = b.center;
        writeln!(
            s,
            "    microraster::BoundingSphere {{ center: microraster::Vec3::new({:?}, {:?}, {:?}), radius: {:?} }},",
            c.x, c.y, c.z, b.radius
        )
        .unwrap();
    }
    s.push_str("];\n");
    // The runs' boxes and the whole model's sphere and box: what the
    // `herd` builds' occlusion test projects.
    let aabb = |points: &mut dyn Iterator<Item = microraster::Vec3>| {
        let (mut lo, mut hi) = ([f32::MAX; 3], [f32::MIN; 3]);
        for p in points {
            for (a, v) in [p.x, p.y, p.z].into_iter().enumerate() {
                lo[a] = lo[a].min(v);
                hi[a] = hi[a].max(v);
            }
        }
        format!(
            "microraster::occlusion::Aabb::new(microraster::Vec3::new({:?}, {:?}, {:?}), microraster::Vec3::new({:?}, {:?}, {:?}))",
            lo[0], lo[1], lo[2], hi[0], hi[1], hi[2]
        )
    };
    let runs = spot_runs(model.indices.len());
    writeln!(
        s,
        "#[allow(dead_code)]\npub static BOXES: [microraster::occlusion::Aabb; {}] = [",
        runs.len()
    )
    .unwrap();
    for [a, b] in runs {
        let tris = &model.indices[a..b];
        let mut points = tris.iter().flatten().map(|&i| model.positions[i as usize]);
        writeln!(s, "    {},", aabb(&mut points)).unwrap();
    }
    s.push_str("];\n");
    let all: Vec<_> = model
        .indices
        .iter()
        .flatten()
        .map(|&i| model.positions[i as usize])
        .collect();
    let b = microraster::BoundingSphere::from_points(&all).unwrap();
    writeln!(
        s,
        "#[allow(dead_code)]\npub static WHOLE_SPHERE: microraster::BoundingSphere = microraster::BoundingSphere {{ center: microraster::Vec3::new({:?}, {:?}, {:?}), radius: {:?} }};",
        b.center.x, b.center.y, b.center.z, b.radius
    )
    .unwrap();
    writeln!(
        s,
        "#[allow(dead_code)]\npub static WHOLE_BOX: microraster::occlusion::Aabb = {};",
        aabb(&mut all.iter().copied())
    )
    .unwrap();
    #[cfg(feature = "cull-masks")]
    s.push_str(&spot_classes_reordered(model.indices));
    s
}

/// `CLASSES`: each triangle's normal class (`baked/spot_classes.rs`, in
/// the baked order) for the triangles in the order drawn.
#[cfg(feature = "cull-masks")]
fn spot_classes_reordered(indices: &[[u32; 3]]) -> String {
    let baked: std::collections::HashMap<[u32; 3], u16> = spot_full::INDICES
        .iter()
        .copied()
        .zip(spot_classes::CLASSES.iter().copied())
        .collect();
    let mut s = String::from("/// Each triangle's normal class, in the order drawn (build.rs).\n");
    writeln!(s, "pub static CLASSES: [u16; {}] = [", indices.len()).unwrap();
    for t in indices {
        writeln!(s, "    {},", baked[t]).unwrap();
    }
    s.push_str("];\n");
    s
}

fn main() {
    let out = PathBuf::from(env::var_os("OUT_DIR").unwrap());
    let target = env::var("TARGET").unwrap();
    let immediate = env::var_os("CARGO_FEATURE_IMMEDIATE").is_some();
    let spot = cfg!(feature = "spot");
    // The micro:bit's flash takes the decimated Spot.
    let small = target == "thumbv6m-none-eabi";
    println!("cargo::rustc-check-cfg=cfg(small_spot)");
    if spot && small {
        println!("cargo::rustc-cfg=small_spot");
    }
    if small && cfg!(feature = "cull-masks") {
        panic!("`cull-masks` is for the MPS2 boards (all of Spot)");
    }
    if small && cfg!(feature = "clusters") {
        panic!(
            "the `clusters` features are for the MPS2 boards (all of Spot); \
             the micro:bit's decimated Spot has no cluster bake"
        );
    }
    // A baked scene (Spot or the house) instead of the cubes.
    println!("cargo::rustc-check-cfg=cfg(baked)");
    if spot || cfg!(feature = "house") {
        println!("cargo::rustc-cfg=baked");
    }
    if small && cfg!(feature = "house") {
        panic!("the `house` features are for the MPS2 boards (the house does not fit the micro:bit's flash)");
    }
    let depth_u32 = env::var_os("CARGO_FEATURE_DEPTH_U32").is_some();
    let clipless = env::var_os("CARGO_FEATURE_CLIPLESS").is_some();
    let b = board(
        &target,
        immediate,
        spot || cfg!(feature = "house"),
        depth_u32,
        clipless,
    );
    #[cfg(not(any(feature = "spot", feature = "house")))]
    let depth = env::var_os("CARGO_FEATURE_NO_DEPTH").is_none();

    let memory = fs::read_to_string(format!("memory/{}", b.memory)).unwrap();
    fs::write(out.join("memory.x"), memory).unwrap();
    println!("cargo:rustc-link-search={}", out.display());

    #[cfg(feature = "spot")]
    let checksum = spot_frame(&out, small);
    #[cfg(feature = "house")]
    let checksum = house_checksum();
    #[cfg(not(any(feature = "spot", feature = "house")))]
    let checksum = host_checksum(depth);
    let mut s = String::new();
    writeln!(
        s,
        "/// QEMU machine.\npub const BOARD: &str = {:?};",
        b.name
    )
    .unwrap();
    writeln!(s, "/// Processor.\npub const CORE: &str = {:?};", b.core).unwrap();
    writeln!(
        s,
        "/// Rows per strip.\npub const STRIP_ROWS: usize = {};",
        b.strip_rows
    )
    .unwrap();
    writeln!(
        s,
        "/// The host's checksum of the same frame (build.rs).\npub const HOST_CHECKSUM: u64 = {checksum:#018x};"
    )
    .unwrap();
    fs::write(out.join("board.rs"), s).unwrap();

    println!("cargo:rerun-if-changed=build.rs");
    println!("cargo:rerun-if-changed=memory");
    println!("cargo:rerun-if-changed=baked");
    println!("cargo:rerun-if-changed=src/spot_scene.rs");
    println!("cargo:rerun-if-env-changed=MICRORASTER_FIRMWARE_PPM");
}
