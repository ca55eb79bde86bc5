//! Named hard cases: w <= 0, slivers, edges through centres, huge
//! coordinates and guard-band clipping (RASTER_TEST_CASES §7, §8), near/far
//! planes (§9), bad input, culling (§5), buffer and frame-size errors,
//! storage limits, extreme frame sizes, depth exactness, perspective-correct
//! colour (§6) and depth functions.

#[path = "../common/mod.rs"]
mod common;

use common::*;
use microraster::fixed::{snap, MAX_DIMENSION};
use microraster::pixelcolor::Rgb888;
use microraster::prelude::*;
use microraster::{
    BoundingSphere, Config, CullMode, DepthFunc, Error, Frame, FrontFace, Mat4, Mesh, MeshColors,
    NoDepth, ProcessedVertex, SetupTriangle, Stats, StripRenderer, TriangleId, Vec3, Vec4,
};

// The sections, one file each.
mod w_le_0;
mod slivers;
mod clipping;
mod near_far;
mod bad_input;
mod culling;
mod errors;
mod frame_sizes;
mod depth;
mod snapping;
mod regressions;

pub(crate) const RED3: [Rgb888; 3] = [Rgb888::new(255, 0, 0); 3];

pub(crate) fn v(x: f32, y: f32, z: f32, w: f32) -> Vec4 {
    Vec4::new(x, y, z, w)
}

/// Pushes `tris` (ids 0..) into a frame at `S` bits and returns its stats
/// and id image.
pub(crate) fn run<const S: u32>(cfg: Config, tris: &[[Vec4; 3]]) -> (Stats, Vec<u32>) {
    with_frame::<S, _>(cfg, tris, |f| (f.stats(), frame_ids(f)))
}

pub(crate) fn count(ids: &[u32]) -> usize {
    ids.iter().filter(|&&i| i != 0).count()
}
