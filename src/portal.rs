//! Portal culling: the cells of an indoor scene that no chain of openings
//! lets the eye see are skipped whole, before any of their triangles is
//! submitted.
//!
//! Design note: the scene says how it is split. [`Cell`]s (rooms) are
//! closed by opaque walls except at [`Portal`]s (doors, windows), each a
//! one-way opening from the cell that lists it into the cell [`Portal::to`]
//! names, given by a box around the opening's polygon (for an axis-aligned
//! door the box is the door's rectangle itself). [`PortalGraph::visible`]
//! starts from the eye's cell with the whole frame and narrows the view
//! through each portal: the pixel rectangle a cell is seen through is its
//! parent's rectangle intersected with the portal's conservative
//! [`ScreenBound`] (the same bound occlusion culling uses: the box's
//! corners in `f64`, the vertex stage's error, one pixel for snapping).
//! Where several chains reach a cell, its rectangle is their union, and
//! the walk repeats until no rectangle grows: rectangles only grow, on
//! an integer grid inside the frame, so it ends, without recursion or a
//! stack (the graph may have cycles). A portal that reaches behind the
//! eye (no bound) passes its parent's whole rectangle.
//!
//! Conservative, so the frame is the one drawing every cell draws when the
//! scene keeps its promise: every triangle lies inside its cell, the
//! cells' walls are closed meshes with the portals as their only holes
//! (no T-junctions: a hole in a snapped wall is the snapped opening), and
//! the eye's near-plane rectangle lies inside the start cell. Then a pixel
//! centre shows a triangle of another cell only through the snapped
//! openings of every portal on the way, each within its bound's pixel of
//! the exact opening (`std-host/tests/portal.rs` compares the frames byte
//! for byte over random cameras in a generated house).
//!
//! The data are plain slices (flash or RAM); [`PortalGraph::new`] checks
//! them once ([`Error::InvalidPortals`]), and the walk writes one
//! [`PixelRect`] a cell into a slice the caller owns: 8 bytes a cell.

use crate::config::{Config, Error};
use crate::math::Mat4;
use crate::occlusion::{Aabb, ScreenBound};

/// A cell: its portals are `portals[first .. first + count]` of the graph.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Cell {
    /// Index of the first portal out of this cell.
    pub first: u16,
    /// The number of portals out of this cell.
    pub count: u16,
}

/// A one-way opening out of the cell that lists it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Portal {
    /// The cell seen through it.
    pub to: u16,
    /// A world-space box holding the opening's polygon.
    pub bounds: Aabb,
}

/// What is wrong with portal data ([`Error::InvalidPortals`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum PortalFault {
    /// This cell's portal range runs past the portals.
    Cell(usize),
    /// This portal leads to no cell, or its box is not finite or reversed.
    Portal(usize),
    /// The start cell is not a cell.
    Start,
    /// The rectangle slice does not hold one entry a cell.
    Rects {
        /// Cells.
        expected: usize,
        /// Entries given.
        actual: usize,
    },
}

/// A pixel rectangle: columns `x0..x1`, rows `y0..y1`; empty when
/// `x0 >= x1` or `y0 >= y1`. Sides below 65,536 (the frame's, at most
/// [`MAX_DIMENSION`](crate::MAX_DIMENSION)).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct PixelRect {
    /// First column.
    pub x0: u16,
    /// One past the last column.
    pub x1: u16,
    /// First row.
    pub y0: u16,
    /// One past the last row.
    pub y1: u16,
}

impl PixelRect {
    /// The empty rectangle.
    pub const EMPTY: PixelRect = PixelRect {
        x0: 0,
        x1: 0,
        y0: 0,
        y1: 0,
    };

    /// Whether it holds no pixel.
    pub fn is_empty(&self) -> bool {
        self.x0 >= self.x1 || self.y0 >= self.y1
    }

    /// The pixels in both.
    pub fn intersect(&self, o: &PixelRect) -> PixelRect {
        let r = PixelRect {
            x0: self.x0.max(o.x0),
            x1: self.x1.min(o.x1),
            y0: self.y0.max(o.y0),
            y1: self.y1.min(o.y1),
        };
        if r.is_empty() {
            PixelRect::EMPTY
        } else {
            r
        }
    }

    /// The smallest rectangle holding both.
    pub fn union(&self, o: &PixelRect) -> PixelRect {
        match (self.is_empty(), o.is_empty()) {
            (true, _) => *o,
            (_, true) => *self,
            _ => PixelRect {
                x0: self.x0.min(o.x0),
                x1: self.x1.max(o.x1),
                y0: self.y0.min(o.y0),
                y1: self.y1.max(o.y1),
            },
        }
    }

    /// Whether it meets rows `y0..y1` (a strip).
    pub fn meets_rows(&self, y0: u32, y1: u32) -> bool {
        !self.is_empty() && (self.y0 as u32) < y1 && y0 < self.y1 as u32
    }
}

/// What one walk found.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct PortalCount {
    /// Cells in the graph.
    pub cells: u32,
    /// Cells reached (a non-empty rectangle), the start cell included.
    pub reached: u32,
    /// Portal bounds projected (a portal is projected once per pass over
    /// the cells that reach it).
    pub projected: u32,
}

/// Cells and portals, checked ([`PortalGraph::new`]).
#[derive(Clone, Copy, Debug)]
pub struct PortalGraph<'a> {
    cells: &'a [Cell],
    portals: &'a [Portal],
}

impl<'a> PortalGraph<'a> {
    /// Checks that every cell's portal range lies in `portals`, that every
    /// portal leads to a cell and that its box is finite with `min <= max`.
    pub fn new(cells: &'a [Cell], portals: &'a [Portal]) -> Result<PortalGraph<'a>, Error> {
        for (i, c) in cells.iter().enumerate() {
            if c.first as usize + c.count as usize > portals.len() {
                return Err(Error::InvalidPortals(PortalFault::Cell(i)));
            }
        }
        for (i, p) in portals.iter().enumerate() {
            let (lo, hi) = (p.bounds.min, p.bounds.max);
            let ok = (p.to as usize) < cells.len()
                && lo.is_finite()
                && hi.is_finite()
                && lo.x <= hi.x
                && lo.y <= hi.y
                && lo.z <= hi.z;
            if !ok {
                return Err(Error::InvalidPortals(PortalFault::Portal(i)));
            }
        }
        Ok(PortalGraph { cells, portals })
    }

    /// The cells.
    pub fn cells(&self) -> &'a [Cell] {
        self.cells
    }

    /// The portals.
    pub fn portals(&self) -> &'a [Portal] {
        self.portals
    }

    /// The portals out of cell `c` (empty for no cell).
    pub fn portals_of(&self, c: usize) -> &'a [Portal] {
        self.cells
            .get(c)
            .and_then(|c| {
                self.portals
                    .get(c.first as usize..c.first as usize + c.count as usize)
            })
            .unwrap_or(&[])
    }

    /// Writes into `rects[c]` the pixels through which cell `c` may be
    /// seen from the eye in cell `start` under `view_proj` (world to clip
    /// space) in a frame of `config`'s size: the whole frame for `start`,
    /// [`PixelRect::EMPTY`] for a cell no chain of portals reaches. Cells
    /// with an empty rectangle can be skipped whole: nothing of them shows.
    pub fn visible(
        &self,
        view_proj: &Mat4,
        config: &Config,
        start: usize,
        rects: &mut [PixelRect],
    ) -> Result<PortalCount, Error> {
        if rects.len() != self.cells.len() {
            return Err(Error::InvalidPortals(PortalFault::Rects {
                expected: self.cells.len(),
                actual: rects.len(),
            }));
        }
        if start >= self.cells.len() {
            return Err(Error::InvalidPortals(PortalFault::Start));
        }
        rects.fill(PixelRect::EMPTY);
        // Config's sides are at most MAX_DIMENSION (< 65,536).
        let side = |v: u32| v.min(u16::MAX as u32) as u16;
        rects[start] = PixelRect {
            x0: 0,
            x1: side(config.width),
            y0: 0,
            y1: side(config.height),
        };
        let mut projected = 0u32;
        loop {
            let mut grew = false;
            for c in 0..self.cells.len() {
                let from = rects[c];
                if from.is_empty() {
                    continue;
                }
                for p in self.portals_of(c) {
                    projected = projected.saturating_add(1);
                    if behind_eye(&p.bounds, view_proj) {
                        continue;
                    }
                    let through = match ScreenBound::of_box(&p.bounds, view_proj, config) {
                        Some(b) => from.intersect(&PixelRect {
                            x0: side(b.x0),
                            x1: side(b.x1),
                            y0: side(b.y0),
                            y1: side(b.y1),
                        }),
                        None => from,
                    };
                    let to = p.to as usize;
                    if let Some(r) = rects.get_mut(to) {
                        let u = r.union(&through);
                        if u != *r {
                            *r = u;
                            grew = true;
                        }
                    }
                }
            }
            if !grew {
                break;
            }
        }
        Ok(PortalCount {
            cells: self.cells.len() as u32,
            reached: rects.iter().filter(|r| !r.is_empty()).count() as u32,
            projected,
        })
    }
}

/// Whether every point of the box lies behind the eye (`w < 0` under
/// `m`, computed in `f64` with the vertex stage's error as margin): then no
/// ray from the eye passes through an opening inside it.
fn behind_eye(b: &Aabb, m: &Mat4) -> bool {
    let row = m.rows()[3];
    let lo = [b.min.x as f64, b.min.y as f64, b.min.z as f64];
    let hi = [b.max.x as f64, b.max.y as f64, b.max.z as f64];
    // The largest w over the box: each term at the end that maximises it.
    let mut w_max = row[3] as f64;
    let mut mag = (row[3] as f64).abs();
    for k in 0..3 {
        let r = row[k] as f64;
        w_max += (r * lo[k]).max(r * hi[k]);
        mag += r.abs() * lo[k].abs().max(hi[k].abs());
    }
    let w_max = w_max + mag * crate::occlusion::GAMMA;
    w_max < 0.0
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::Vec3;

    fn door(to: u16, z: f32) -> Portal {
        Portal {
            to,
            bounds: Aabb::new(Vec3::new(-0.5, -1.0, z), Vec3::new(0.5, 1.0, z)),
        }
    }

    fn view() -> (Mat4, Config) {
        let config = Config::new(64, 48);
        let m = Mat4::perspective(60f32.to_radians(), 64.0 / 48.0, 0.1, 100.0)
            * Mat4::look_at(
                Vec3::new(0.0, 0.0, 0.0),
                Vec3::new(0.0, 0.0, -1.0),
                Vec3::new(0.0, 1.0, 0.0),
            );
        (m, config)
    }

    /// A corridor of cells 0 -> 1 -> 2 along -z with a door behind the
    /// eye into cell 3, a door beside into 4 that the frustum misses, and
    /// from 2 a door reaching behind the eye into 5 (which passes 2's
    /// rectangle).
    fn corridor() -> ([Cell; 6], [Portal; 5]) {
        let portals = [
            door(1, -2.0),
            door(3, 2.0),
            Portal {
                to: 4,
                bounds: Aabb::new(Vec3::new(30.0, -1.0, -1.0), Vec3::new(30.0, 1.0, -0.5)),
            },
            door(2, -6.0),
            Portal {
                to: 5,
                bounds: Aabb::new(Vec3::new(-0.5, -1.0, -6.0), Vec3::new(0.5, 1.0, 1.0)),
            },
        ];
        let cells = [
            Cell { first: 0, count: 3 },
            Cell { first: 3, count: 1 },
            Cell { first: 4, count: 1 },
            Cell::default(),
            Cell::default(),
            Cell::default(),
        ];
        (cells, portals)
    }

    #[test]
    fn narrows_through_doors_and_skips_what_no_door_shows() {
        let (cells, portals) = corridor();
        let g = PortalGraph::new(&cells, &portals).unwrap();
        let (m, config) = view();
        let mut rects = [PixelRect::EMPTY; 6];
        let n = g.visible(&m, &config, 0, &mut rects).unwrap();
        assert_eq!(
            rects[0],
            PixelRect {
                x0: 0,
                x1: 64,
                y0: 0,
                y1: 48
            }
        );
        // The nearer door looks larger, and the far one is inside it.
        let (a, b) = (rects[1], rects[2]);
        assert!(!a.is_empty() && !b.is_empty());
        assert!(a.x0 <= b.x0 && b.x1 <= a.x1 && a.y0 <= b.y0 && b.y1 <= a.y1);
        assert!(b.x1 - b.x0 < a.x1 - a.x0);
        assert!(a.x1 - a.x0 < 64);
        // Behind the eye: nothing through it.
        assert!(rects[3].is_empty());
        // Beside, outside the frustum.
        assert!(rects[4].is_empty());
        // Across the eye's plane: the parent's rectangle.
        assert_eq!(rects[5], rects[2]);
        assert_eq!(n.cells, 6);
        assert_eq!(n.reached, 4);
    }

    #[test]
    fn cycles_end() {
        let portals = [door(1, -2.0), door(0, -2.0)];
        let cells = [Cell { first: 0, count: 1 }, Cell { first: 1, count: 1 }];
        let g = PortalGraph::new(&cells, &portals).unwrap();
        let (m, config) = view();
        let mut rects = [PixelRect::EMPTY; 2];
        let n = g.visible(&m, &config, 0, &mut rects).unwrap();
        assert_eq!(n.reached, 2);
        assert_eq!(rects[0].x1, 64);
    }

    #[test]
    fn bad_data_is_a_typed_error() {
        let (cells, portals) = corridor();
        let fault = |e: Result<PortalGraph<'_>, Error>| match e {
            Err(Error::InvalidPortals(f)) => f,
            other => panic!("{other:?}"),
        };
        let mut c = cells;
        c[1].count = 9;
        assert_eq!(fault(PortalGraph::new(&c, &portals)), PortalFault::Cell(1));
        let mut p = portals;
        p[2].to = 6;
        assert_eq!(fault(PortalGraph::new(&cells, &p)), PortalFault::Portal(2));
        let mut p = portals;
        p[0].bounds.min.x = f32::NAN;
        assert_eq!(fault(PortalGraph::new(&cells, &p)), PortalFault::Portal(0));
        let mut p = portals;
        p[3].bounds.min.y = 5.0;
        assert_eq!(fault(PortalGraph::new(&cells, &p)), PortalFault::Portal(3));
        let g = PortalGraph::new(&cells, &portals).unwrap();
        let (m, config) = view();
        assert_eq!(
            g.visible(&m, &config, 0, &mut [PixelRect::EMPTY; 4]),
            Err(Error::InvalidPortals(PortalFault::Rects {
                expected: 6,
                actual: 4
            }))
        );
        assert_eq!(
            g.visible(&m, &config, 6, &mut [PixelRect::EMPTY; 6]),
            Err(Error::InvalidPortals(PortalFault::Start))
        );
        // A matrix of NaN: every portal passes its parent's rectangle.
        let nan = Mat4::from_rows([[f32::NAN; 4]; 4]);
        let mut rects = [PixelRect::EMPTY; 6];
        assert_eq!(g.visible(&nan, &config, 0, &mut rects).unwrap().reached, 6);
    }

    #[test]
    fn rect_algebra() {
        let a = PixelRect {
            x0: 0,
            x1: 4,
            y0: 0,
            y1: 4,
        };
        let b = PixelRect {
            x0: 2,
            x1: 8,
            y0: 3,
            y1: 9,
        };
        assert_eq!(
            a.intersect(&b),
            PixelRect {
                x0: 2,
                x1: 4,
                y0: 3,
                y1: 4
            }
        );
        assert_eq!(
            a.union(&b),
            PixelRect {
                x0: 0,
                x1: 8,
                y0: 0,
                y1: 9
            }
        );
        let far = PixelRect {
            x0: 5,
            x1: 6,
            y0: 5,
            y1: 6,
        };
        assert_eq!(a.intersect(&far), PixelRect::EMPTY);
        assert_eq!(PixelRect::EMPTY.union(&far), far);
        assert!(b.meets_rows(8, 9) && !b.meets_rows(9, 12) && !b.meets_rows(0, 3));
    }
}
