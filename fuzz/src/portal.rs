//! Portal culling from arbitrary data (`fuzz_targets/portal.rs`): cells
//! whose portal ranges may run past the portals, portals that may lead
//! nowhere or carry NaN, infinite or inverted boxes, any matrix, frame
//! size, start cell and rectangle slice.
//!
//! Checks: no panic; bad data is exactly the `Error::InvalidPortals` the
//! checks name; a walk over good data gives the start cell the whole
//! frame, keeps every rectangle inside the frame, and counts the cells it
//! reached.

use crate::{MatIn, F};
use libfuzzer_sys::arbitrary::{self, Arbitrary};
use microraster::occlusion::Aabb;
use microraster::portal::{Cell, PixelRect, Portal, PortalFault, PortalGraph};
use microraster::{Config, Error, Vec3};

/// One portal.
#[derive(Arbitrary, Clone, Debug)]
pub struct PortalIn {
    to: u8,
    bounds: [F; 6],
}

/// The input.
#[derive(Arbitrary, Clone, Debug)]
pub struct PortalInput {
    cells: Vec<(u8, u8)>,
    portals: Vec<PortalIn>,
    view_proj: MatIn,
    size: [u8; 2],
    start: u8,
    rects_short: bool,
}

/// Runs one input.
pub fn run_portal(input: &PortalInput) {
    let cells: Vec<Cell> = input
        .cells
        .iter()
        .take(64)
        .map(|&(first, count)| Cell {
            first: first as u16,
            count: count as u16 % 16,
        })
        .collect();
    let portals: Vec<Portal> = input
        .portals
        .iter()
        .take(256)
        .map(|p| {
            let b = p.bounds.map(|f| f.0);
            Portal {
                to: p.to as u16,
                bounds: Aabb::new(Vec3::new(b[0], b[1], b[2]), Vec3::new(b[3], b[4], b[5])),
            }
        })
        .collect();
    let bad_cell = cells
        .iter()
        .position(|c| c.first as usize + c.count as usize > portals.len());
    let bad_portal = portals.iter().position(|p| {
        let (lo, hi) = (p.bounds.min, p.bounds.max);
        !((p.to as usize) < cells.len()
            && lo.is_finite()
            && hi.is_finite()
            && lo.x <= hi.x
            && lo.y <= hi.y
            && lo.z <= hi.z)
    });
    let graph = match PortalGraph::new(&cells, &portals) {
        Ok(g) => {
            assert!(bad_cell.is_none() && bad_portal.is_none());
            g
        }
        Err(e) => {
            let want = match bad_cell {
                Some(i) => PortalFault::Cell(i),
                None => PortalFault::Portal(bad_portal.expect("a fault")),
            };
            assert_eq!(e, Error::InvalidPortals(want));
            return;
        }
    };
    let (w, h) = (input.size[0] as u32 + 1, input.size[1] as u32 + 1);
    let config = Config::new(w, h);
    let m = input.view_proj.matrix();
    let len = cells.len() - usize::from(input.rects_short && !cells.is_empty());
    let mut rects = vec![PixelRect::EMPTY; len];
    let start = input.start as usize;
    match graph.visible(&m, &config, start, &mut rects) {
        Ok(n) => {
            assert_eq!(
                rects[start],
                PixelRect {
                    x0: 0,
                    x1: w as u16,
                    y0: 0,
                    y1: h as u16
                }
            );
            for r in &rects {
                assert!(r.is_empty() || (r.x1 as u32 <= w && r.y1 as u32 <= h));
            }
            let reached = rects.iter().filter(|r| !r.is_empty()).count() as u32;
            assert_eq!((n.cells, n.reached), (cells.len() as u32, reached));
        }
        Err(Error::InvalidPortals(PortalFault::Rects { expected, actual })) => {
            assert_eq!((expected, actual), (cells.len(), len));
            assert!(len != cells.len());
        }
        Err(Error::InvalidPortals(PortalFault::Start)) => {
            assert!(len == cells.len() && start >= cells.len());
        }
        Err(e) => panic!("unexpected {e:?}"),
    }
}
