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
//! [`Frame::render_rows`]. Any split of the frame gives the same pixels.

#![no_std]
#![forbid(unsafe_code)]
#![deny(missing_docs, missing_debug_implementations)]

pub mod clip;
mod color;
mod depth;
mod draw_target;
pub mod fixed;
mod frame;
mod immediate;
pub mod math;
mod raster;
mod setup;

pub use clip::ClipVertex;
pub use color::{Pixel, TriangleId};
pub use depth::{DepthBuffer, DepthFunc, NoDepth};
pub use draw_target::{DrawError, StripDepth, StripDrawer};
pub use fixed::{MAX_DIMENSION, SUBPIXEL_BITS};
pub use frame::{
    Bins, BoundingSphere, Config, CullMode, Error, Frame, FrontFace, Mesh, MeshColors,
    ProcessedVertex, RenderStats, Stats,
};
pub use immediate::StripRenderer;
pub use math::{Mat4, Vec3, Vec4};
pub use setup::SetupTriangle;

/// Colour types from embedded-graphics, re-exported for convenience.
pub use embedded_graphics_core::pixelcolor;

/// The README's code examples, compiled and run as doctests.
#[cfg(doctest)]
#[doc = include_str!("../README.md")]
struct ReadmeDoctests;
