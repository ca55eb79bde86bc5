//! Frame settings and errors: what a caller chooses, and what can go wrong.
//!
//! Design note: a [`Config`] is plain data, copied into every frame and
//! strip renderer. Every fallible call returns an [`Error`] and then has
//! written nothing: no buffer, no storage slot, no counter. Triangles the
//! pipeline drops are not errors; they are counted in
//! [`Stats`](crate::Stats).

use crate::depth::DepthFunc;
use crate::fixed::MAX_DIMENSION;

/// Which faces to cull.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum CullMode {
    /// Cull back faces (the default).
    #[default]
    Back,
    /// Cull front faces.
    Front,
    /// Cull nothing.
    None,
}

/// Which winding, in NDC (y up), is a front face.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum FrontFace {
    /// Counter-clockwise is front (the default, as in OpenGL).
    #[default]
    Ccw,
    /// Clockwise is front.
    Cw,
}

/// How triangles become pixels.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum RasterMode {
    /// Clip against near, far and the guard band in homogeneous space,
    /// divide by `w`, snap to `Sub<S>` and rasterize the snapped triangle
    /// (the default).
    #[default]
    Clipping,
    /// Olano and Greer's 2D-homogeneous rasterization
    /// ([`crate::clipless`]): no clipping and no division by `w`; edge
    /// functions are cross products of quantized homogeneous vertices,
    /// near and far are tested exactly per row. Only
    /// [`StripRenderer`](crate::StripRenderer) draws in this mode
    /// ([`Frame`](crate::Frame) refuses it with
    /// [`Error::ModeUnsupported`]).
    Clipless,
}

/// Per-frame settings.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Config {
    /// Frame width in pixels, `1..=16384`.
    pub width: u32,
    /// Frame height in pixels, `1..=16384`.
    pub height: u32,
    /// Face culling.
    pub cull: CullMode,
    /// Front-face winding.
    pub front_face: FrontFace,
    /// Depth comparison.
    pub depth_func: DepthFunc,
    /// Whether passing fragments write their depth.
    pub depth_write: bool,
    /// Detail culling, lossy (0, the default: off): an object whose
    /// [`Mesh::bounds`](crate::Mesh::bounds), or a cluster-tree node whose
    /// [`ClusterNode::sphere`](crate::ClusterNode::sphere), provably
    /// projects to less than `detail` pixels across is dropped before any
    /// of its vertices is transformed, and counted in
    /// [`Stats::culled_detail`](crate::Stats::culled_detail) (see
    /// [`Detail`](crate::Detail)). Small objects vanish, and small clusters
    /// of a surface leave holes of about that size.
    pub detail: u16,
    /// Clipping (the default) or clipless rasterization.
    pub mode: RasterMode,
}

impl Config {
    /// A `width x height` frame with back-face culling, CCW front faces,
    /// depth test `Less`, depth writes on and no detail culling.
    pub const fn new(width: u32, height: u32) -> Self {
        Config {
            width,
            height,
            cull: CullMode::Back,
            front_face: FrontFace::Ccw,
            depth_func: DepthFunc::Less,
            depth_write: true,
            detail: 0,
            mode: RasterMode::Clipping,
        }
    }
}

/// What went wrong; nothing is written when an error is returned.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Error {
    /// Width or height is 0 or above [`MAX_DIMENSION`].
    InvalidFrameSize {
        /// The width asked for.
        width: u32,
        /// The height asked for.
        height: u32,
    },
    /// The setup storage cannot hold the triangle (or mesh): nothing of it
    /// was stored or counted, and the storage was not written.
    StorageFull {
        /// The storage's capacity in set-up triangles.
        capacity: usize,
        /// Set-up triangles the storage had free before the submission.
        free: usize,
        /// Set-up triangles the submission needs in all (a clipped triangle
        /// can need up to seven).
        needed: usize,
    },
    /// A mesh with more than `u32::MAX` triangles: triangle ids and
    /// counters are 32-bit per submission.
    MeshTooLarge {
        /// The mesh's triangle count.
        triangles: usize,
    },
    /// [`Frame::bin`](crate::Frame::bin) with strips of 0 rows.
    InvalidStripRows,
    /// The [`Bins`](crate::Bins) were made for another frame (size, strip
    /// height or triangle count differ) or before triangles were added.
    BinsMismatch,
    /// The row range is empty, reversed or beyond the frame.
    InvalidRows {
        /// First row asked for.
        y0: u32,
        /// One past the last row asked for.
        y1: u32,
        /// The frame height.
        height: u32,
    },
    /// The column range is empty, reversed or beyond the frame.
    InvalidColumns {
        /// First column asked for.
        x0: u32,
        /// One past the last column asked for.
        x1: u32,
        /// The frame width.
        width: u32,
    },
    /// [`Frame::bin_tiles`](crate::Frame::bin_tiles) with a tile side of 0.
    InvalidTileSize,
    /// The colour slice does not hold exactly the rows (or rectangle) asked for.
    ColorBufferSize {
        /// `(x1 - x0) * (y1 - y0)` (`x0..x1` the full width for rows).
        expected: usize,
        /// The slice length.
        actual: usize,
    },
    /// Bin storage too small (offsets: strips + 1; items:
    /// [`Frame::bin_entries`](crate::Frame::bin_entries)).
    BinStorageSize {
        /// Entries needed.
        expected: usize,
        /// Entries given.
        actual: usize,
    },
    /// The vertex cache holds fewer entries than the mesh has vertices.
    VertexCacheSize {
        /// The mesh's vertex count.
        expected: usize,
        /// The cache length.
        actual: usize,
    },
    /// The depth slice does not hold exactly the rows (or rectangle) asked for.
    DepthBufferSize {
        /// `(x1 - x0) * (y1 - y0)` (`x0..x1` the full width for rows).
        expected: usize,
        /// The slice length.
        actual: usize,
    },
    /// A texture whose texel slice does not hold `width * height` texels,
    /// or with a side of 0 or above
    /// [`MAX_TEXTURE_SIDE`](crate::shade::MAX_TEXTURE_SIDE).
    TextureSize {
        /// The width given.
        width: u32,
        /// The height given.
        height: u32,
        /// The texels given.
        texels: usize,
    },
    /// [`Lighting::new`](crate::shade::Lighting::new) with more than
    /// [`MAX_LIGHTS`](crate::shade::MAX_LIGHTS) lights, a zero or
    /// non-finite direction, or a non-finite intensity.
    InvalidLighting,
    /// Cluster data ([`ClusterSet`](crate::cull::ClusterSet)) that does
    /// not fit the mesh or whose tree does not tile its clusters.
    InvalidClusters(crate::cull::ClusterFault),
    /// Normal classes ([`NormalClasses`](crate::normal_mask::NormalClasses))
    /// that do not fit the mesh.
    InvalidNormalClasses(crate::normal_mask::ClassFault),
    /// Fewer hi-z tiles than the strip needs
    /// ([`tiles_for`](crate::occlusion::tiles_for)).
    HiZSize {
        /// Tiles needed.
        expected: usize,
        /// Tiles given.
        actual: usize,
    },
    /// Portal data ([`PortalGraph`](crate::portal::PortalGraph)) whose
    /// ranges or targets run past its cells or portals, with a bad box, or
    /// a walk given a bad start cell or rectangle slice.
    InvalidPortals(crate::portal::PortalFault),
    /// A [`LazyClear`](crate::LazyClear) given fewer hull values than its
    /// rectangle has rows, or a rectangle wider than `2^16` columns.
    HullSize {
        /// Rows of the rectangle.
        expected: usize,
        /// Hull values given.
        actual: usize,
    },
    /// A render given a [`LazyClear`](crate::LazyClear) made for another
    /// rectangle.
    LazyClearRect,
    /// [`RasterMode::Clipless`] given to a [`Frame`](crate::Frame), whose
    /// setup storage holds snapped triangles only (draw clipless triangles
    /// with a [`StripRenderer`](crate::StripRenderer)), or to any receiver
    /// of a crate built without its `clipless` feature; a deferred clear
    /// ([`LazyClear`](crate::LazyClear)) in a crate built without its
    /// `lazy-clear` feature.
    ModeUnsupported,
}

impl core::fmt::Display for Error {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match *self {
            Error::InvalidFrameSize { width, height } => write!(
                f,
                "invalid frame size {width}x{height} (each side must be 1..={MAX_DIMENSION})"
            ),
            Error::StorageFull {
                capacity,
                free,
                needed,
            } => write!(
                f,
                "setup storage full: {needed} set-up triangles needed, {free} of {capacity} free"
            ),
            Error::MeshTooLarge { triangles } => write!(
                f,
                "mesh has {triangles} triangles, more than the {} of one submission",
                u32::MAX
            ),
            Error::InvalidStripRows => write!(f, "strips must have at least one row"),
            Error::BinsMismatch => write!(f, "the bins were made for another frame"),
            Error::InvalidRows { y0, y1, height } => {
                write!(f, "invalid rows {y0}..{y1} for a frame of height {height}")
            }
            Error::InvalidColumns { x0, x1, width } => {
                write!(f, "invalid columns {x0}..{x1} for a frame of width {width}")
            }
            Error::InvalidTileSize => write!(f, "tiles must be at least 1x1"),
            Error::ColorBufferSize { expected, actual } => {
                write!(
                    f,
                    "colour buffer holds {actual} pixels, expected {expected}"
                )
            }
            Error::BinStorageSize { expected, actual } => {
                write!(f, "bin storage holds {actual} entries, expected {expected}")
            }
            Error::VertexCacheSize { expected, actual } => {
                write!(
                    f,
                    "vertex cache holds {actual} vertices, expected {expected}"
                )
            }
            Error::DepthBufferSize { expected, actual } => {
                write!(f, "depth buffer holds {actual} values, expected {expected}")
            }
            Error::TextureSize {
                width,
                height,
                texels,
            } => write!(
                f,
                "texture of {width}x{height} texels given {texels} (sides 1..={})",
                crate::shade::MAX_TEXTURE_SIDE
            ),
            Error::InvalidLighting => write!(
                f,
                "lighting needs at most {} lights with finite, non-zero directions and finite colours",
                crate::shade::MAX_LIGHTS
            ),
            Error::InvalidClusters(fault) => match fault {
                crate::cull::ClusterFault::Cluster(i) => write!(
                    f,
                    "cluster {i} does not continue the triangles in order or its vertex range is out of bounds"
                ),
                crate::cull::ClusterFault::Node(i) => {
                    write!(f, "cluster node {i} does not tile its clusters")
                }
            },
            Error::InvalidPortals(fault) => match fault {
                crate::portal::PortalFault::Cell(i) => {
                    write!(f, "portal cell {i}'s portal range runs past the portals")
                }
                crate::portal::PortalFault::Portal(i) => write!(
                    f,
                    "portal {i} leads to no cell or its box is not finite with min <= max"
                ),
                crate::portal::PortalFault::Start => write!(f, "the start cell is not a cell"),
                crate::portal::PortalFault::Rects { expected, actual } => write!(
                    f,
                    "{actual} portal rectangles given for {expected} cells"
                ),
            },
            Error::HiZSize { expected, actual } => {
                write!(f, "{actual} hi-z tiles given, the strip needs {expected}")
            }
            Error::HullSize { expected, actual } => write!(
                f,
                "{actual} hull values given for a deferred clear of {expected} rows"
            ),
            Error::LazyClearRect => {
                write!(f, "the deferred clear was made for another rectangle")
            }
            Error::InvalidNormalClasses(fault) => match fault {
                crate::normal_mask::ClassFault::Partitions => {
                    write!(f, "normal classes need 1 to 16 partitions a side")
                }
                crate::normal_mask::ClassFault::Triangles => {
                    write!(f, "normal classes need one class per triangle")
                }
                crate::normal_mask::ClassFault::Sizes => {
                    write!(f, "normal classes need one size entry per class")
                }
                crate::normal_mask::ClassFault::Class(i) => {
                    write!(f, "triangle {i} has a normal class beyond the classes")
                }
            },
            Error::ModeUnsupported => write!(
                f,
                "the clipless mode needs a StripRenderer (a Frame stores snapped triangles only) and the crate's clipless feature; a deferred clear needs its lazy-clear feature"
            ),
        }
    }
}

impl core::error::Error for Error {}

/// Checks a rectangle `[x0, x1, y0, y1]` (columns `x0..x1`, rows `y0..y1`)
/// and buffer sizes against a frame.
pub(crate) fn check_rect(
    config: &Config,
    [x0, x1, y0, y1]: [u32; 4],
    color_len: usize,
    depth_len: Option<usize>,
) -> Result<(), Error> {
    let Config { width, height, .. } = *config;
    if y0 >= y1 || y1 > height {
        return Err(Error::InvalidRows { y0, y1, height });
    }
    if x0 >= x1 || x1 > width {
        return Err(Error::InvalidColumns { x0, x1, width });
    }
    let expected = (x1 - x0) as usize * (y1 - y0) as usize;
    if color_len != expected {
        return Err(Error::ColorBufferSize {
            expected,
            actual: color_len,
        });
    }
    if let Some(actual) = depth_len {
        if actual != expected {
            return Err(Error::DepthBufferSize { expected, actual });
        }
    }
    Ok(())
}

/// Checks a frame size.
pub(crate) fn check_size(config: &Config) -> Result<(), Error> {
    let ok = |v: u32| (1..=MAX_DIMENSION).contains(&v);
    if ok(config.width) && ok(config.height) {
        Ok(())
    } else {
        Err(Error::InvalidFrameSize {
            width: config.width,
            height: config.height,
        })
    }
}
