//! # microraster
//!
//! An exact fixed-point triangle rasterizer for microcontrollers and
//! threads: `#![no_std]`, no allocation, no `unsafe`, no panics.
//!
//! Triangles go one way through the pipeline: vertices (`f32`) → clip space
//! → object cull (bounding sphere) → frustum cull (outcodes) → clip (near,
//! far, guard band) → snap to fixed point → exact setup (integer area,
//! culling, bounding box) → strip traversal (integer edge functions, top-left
//! rule, depth, colour) → caller's buffers.
//!
//! ## Conventions
//!
//! - **Clip space** is OpenGL's: visible where `-w <= x, y, z <= w`.
//! - **NDC** y points up; **window** row 0 is the **top** row. Window x =
//!   `(x/w + 1) * width / 2`, window y = `(1 - y/w) * height / 2`, window z
//!   = `(z/w + 1) / 2`.
//! - **Pixel centres** are at `+0.5`: pixel `(i, j)` is sampled at
//!   `(i + 0.5, j + 0.5)`.
//! - **Front faces** are counter-clockwise in NDC ([`FrontFace::Ccw`]);
//!   [`FrontFace::Cw`] selects the other.
//! - **Fill rule**: top-left, in window space with rows counted from the
//!   top. A pixel centre exactly on an edge is covered only if the edge is a
//!   top edge (horizontal, interior below) or a left edge (interior to its
//!   right). Two triangles sharing an edge never both cover, nor both miss,
//!   a pixel centre on it.
//! - **Snapping**: window x and y are rounded to the nearest `1/2^S` pixel
//!   (halves up), `S` = 8 by default or 4 ([`Frame`]'s const parameter).
//!   No float decides coverage after that.
//! - **Depth**: `Z32` (`z * 2^32`, saturated) per vertex, interpolated as an
//!   exact plane to within 1 LSB; buffers of `u16` (top 16 bits), `u32`, or
//!   none ([`NoDepth`]).
//!
//! See [`fixed`] for the fixed-point formats, their ranges, and the largest
//! frame and guard band each precision supports.
//!
//! ## Strip rendering
//!
//! Set up a frame's triangles once with [`Frame`], then render any rows
//! `y0..y1` into buffers that hold only those rows, with
//! [`Frame::render_rows`], or any rectangle into buffers that hold only it,
//! with [`Frame::render_rect`] ([`Frame::bin_tiles`] and
//! [`Frame::render_tile`] for binned tiles). Any split of the frame into
//! strips or tiles gives the same pixels and depths.
//! Where RAM is scarcer than cycles, [`StripRenderer`] draws each submitted
//! triangle straight into the one strip it holds, and [`StripDrawer`]
//! pushes strips to any embedded-graphics `DrawTarget`. Triangles and
//! meshes go to either through the one [`Submit`] trait (in the
//! [`prelude`]).
//!
//! ## From `Vec3` to pixel: the stages and their files
//!
//! The modules are listed here, and declared, in pipeline order; each one's
//! page opens with its design note. Everything a program uses is also
//! re-exported at the crate root.
//!
//! | stage | file | what happens |
//! |---|---|---|
//! | settings | `config.rs` | [`Config`], [`CullMode`], [`FrontFace`], the [`Error`]s |
//! | vertex math | `math.rs` | [`Vec3`], [`Mat4`], the `f32` float backends |
//! | meshes, vertex stage | `mesh.rs` | [`Mesh`], [`BoundingSphere`] (object cull), [`ProcessedVertex`] (transform, outcode, snap once per vertex) |
//! | cluster culling | `cull.rs` | [`ClusterSet`]: back-face tests per cluster and cluster tree (culling volumes, normal cones) before any vertex is transformed |
//! | shading | `shade.rs` | [`Attributes`] (varyings per vertex: colours, lighting per vertex, texture coordinates, normals) and [`FragmentShader`] (varyings to colour: [`VertexColor`], textures, lighting per pixel), both chosen at compile time |
//! | submission | `pipeline.rs` | [`Submit`]: object cull, frustum cull, strip skip, then clip and setup for each triangle |
//! | clipping | `clip.rs` | outcodes; homogeneous clipping against near, far and the guard band |
//! | clipless mode | `clipless.rs` | [`RasterMode::Clipless`]: quantized homogeneous vertices, exact 2D-homogeneous edge functions and spans, no clipping, no division by `w` |
//! | fixed point | `fixed.rs` | snapping to `Sub<S>` window coordinates: where floats end |
//! | setup | `setup.rs` | exact integer area, culling, winding, bounding box: [`SetupTriangle`] |
//! | counters | `stats.rs` | [`Stats`] (per triangle), [`RenderStats`] (per pixel) |
//! | storage | `frame.rs`, `bins.rs` | [`Frame`]: set-up triangles in caller storage, per-strip [`Bins`] |
//! | immediate mode | `strip_renderer.rs` | [`StripRenderer`]: setup straight into one strip |
//! | portal culling | `portal.rs` | [`portal::PortalGraph::visible`]: the pixel rectangle each cell is seen through, narrowed portal by portal from the eye's cell; cells never reached are skipped whole |
//! | occlusion culling | `occlusion.rs` | [`Occluder`]: a strip's max depth per 8x8 tile; objects (and parts) whose conservative [`ScreenBound`] fails the depth test everywhere are skipped before transform |
//! | traversal | `raster.rs` | exact edge functions, top-left rule, spans, depth and colour steps |
//! | depth | `depth.rs` | [`DepthBuffer`], [`DepthWord`] (`u16`, `u32`, [`DepthF32`]), [`NoDepth`], [`DepthFunc`] |
//! | pixels | `color.rs` | [`PixelFormat`]: embedded-graphics colours, [`TriangleId`] |
//! | display | `draw_target.rs` | [`StripDrawer`]: strips into a `DrawTarget` |

#![no_std]
#![forbid(unsafe_code)]
#![deny(missing_docs, missing_debug_implementations)]

// The stages, in the order a triangle takes. Each module opens with its
// design note (shown by `cargo doc`); the items are re-exported below.
pub mod config;
pub mod math;
pub mod mesh;
pub mod cull;
pub mod normal_mask;
pub mod shade;
pub mod pipeline;
pub mod clip;
pub mod clipless;
pub mod fixed;
pub mod setup;
pub mod stats;
pub mod bins;
pub mod frame;
pub mod strip_renderer;
pub mod occlusion;
pub mod portal;
pub mod raster;
pub mod depth;
pub mod color;
pub mod draw_target;

pub use bins::Bins;
pub use clip::ClipVertex;
pub use color::{PixelFormat, TriangleId};
pub use config::{Config, CullMode, Error, FrontFace, RasterMode};
pub use cull::{Cluster, ClusterCull, ClusterNode, ClusterSet, ClusterTest, Detail};
pub use depth::{DepthBuffer, DepthF32, DepthFunc, DepthWord, NoDepth};
pub use draw_target::{DrawError, StripDepth, StripDrawer, StripSink};
pub use fixed::{MAX_DIMENSION, SUBPIXEL_BITS};
pub use frame::{Frame, LazyClear};
pub use math::{Mat4, Vec3, Vec4};
pub use mesh::{BoundingSphere, Mesh, MeshColors, ProcessedVertex};
pub use normal_mask::{BackMask, NormalClasses};
pub use occlusion::{HiZTile, Occluder, ScreenBound};
pub use pipeline::{Submit, MAX_PIECES};
pub use setup::SetupTriangle;
pub use shade::{Attributes, DetailFill, FragmentShader, VertexColor};
pub use stats::{RenderStats, Stats};
pub use strip_renderer::StripRenderer;

#[doc(hidden)]
pub use pipeline::__private;

/// The traits a program drawing with microraster needs in scope, and the
/// colour types, as in `embedded_graphics::prelude`.
pub mod prelude {
    pub use crate::color::PixelFormat;
    pub use crate::depth::{DepthBuffer, DepthWord};
    pub use crate::pipeline::Submit;
    pub use crate::shade::{Attributes, FragmentShader};
    pub use embedded_graphics_core::pixelcolor::{
        BinaryColor, Gray8, GrayColor, Rgb565, Rgb888, RgbColor,
    };
}

/// Colour types from embedded-graphics, re-exported for convenience.
pub use embedded_graphics_core::pixelcolor;

/// The README's code examples, compiled and run as doctests.
#[cfg(doctest)]
#[doc = include_str!("../README.md")]
struct ReadmeDoctests;

/// The shading guide's code examples, compiled and run as doctests.
#[cfg(doctest)]
#[doc = include_str!("../docs/shading.md")]
struct ShadingDoctests;
