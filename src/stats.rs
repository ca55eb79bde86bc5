//! Counters: what happened to every submitted triangle, and to pixels.
//!
//! Design note: every submitted triangle ends in exactly one place: stored
//! (possibly as several pieces after clipping), or one `culled_*` /
//! `rejected_*` counter. The counters are `u64`: one submission holds at
//! most `u32::MAX` triangles ([`Error::MeshTooLarge`](crate::Error)), and
//! `2^64` triangles would take centuries at a billion a second, so no input
//! can overflow them; adding two [`Stats`] saturates all the same, so even
//! hand-made values cannot panic.

use core::ops::{Add, AddAssign};

/// Per-frame (or per-strip, for [`StripRenderer`](crate::StripRenderer))
/// triangle counters. Every submitted triangle is either stored (possibly
/// as several after clipping) or counted in exactly one `culled_*` /
/// `rejected_*` field.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct Stats {
    /// Triangles submitted.
    pub submitted: u64,
    /// Skipped with their whole object by the bounding-sphere test.
    pub culled_object: u64,
    /// All vertices outside one frustum plane, or the box misses the frame.
    pub culled_frustum: u64,
    /// Culled by winding.
    pub culled_backface: u64,
    /// Zero area, no pixel centre in the bounding box, or a vertex at the
    /// homogeneous origin `(0, 0, 0, 0)`.
    pub culled_degenerate: u64,
    /// A vertex or colour with NaN or infinity.
    pub rejected_nonfinite: u64,
    /// A vertex index (or a colour) out of range.
    pub rejected_index: u64,
    /// Triangles that crossed the near, far or guard-band planes and were
    /// clipped (also counted where the pieces went).
    pub clipped: u64,
    /// Set-up triangles stored or drawn (pieces, after clipping).
    pub stored: u64,
    /// [`StripRenderer`](crate::StripRenderer) only: skipped before any
    /// setup because the triangle lies wholly above or below the strip,
    /// one by one or with its whole mesh (whose bounding sphere does,
    /// [`BoundingSphere::outside_slab`](crate::BoundingSphere::outside_slab):
    /// then no vertex was transformed).
    pub outside_strip: u64,
    /// Skipped with their cluster, before any of its vertices was
    /// transformed, by a leaf's back-face test
    /// ([`Submit::submit_clusters`](crate::Submit::submit_clusters)).
    pub culled_cluster: u64,
    /// Skipped like `culled_cluster`, by an inner node of the cluster
    /// tree (a whole subtree at once).
    pub culled_hierarchy: u64,
    /// Skipped before transform by detail culling (lossy, off by
    /// default): an object, or a cluster-tree node, whose projected bound
    /// is below [`Config::detail`](crate::Config::detail) pixels across.
    pub culled_detail: u64,
    /// Skipped before transform because its normal's class is in the
    /// frame's back mask ([`Submit::submit_masked`](crate::Submit::submit_masked),
    /// [`Submit::submit_mesh_masked`](crate::Submit::submit_mesh_masked)).
    pub culled_mask: u64,
    /// Skipped before transform because the strip's hi-z hides its object
    /// ([`Occluder`](crate::occlusion::Occluder)).
    pub culled_occlusion: u64,
    /// Skipped with their cell, never submitted, because no chain of
    /// portals lets the eye see it ([`portal`](crate::portal); counted by
    /// the caller that skips them).
    pub culled_portal: u64,
    /// Set-up pieces of the boxes drawn in place of what detail culling
    /// dropped, where the mesh's attributes give a fill
    /// ([`DetailFill`](crate::DetailFill)); not counted in `stored`, and
    /// not triangles submitted.
    pub detail_boxes: u64,
}

impl Stats {
    /// The triangles dropped for any reason (every `culled_*` and
    /// `rejected_*` counter, and `outside_strip`).
    pub fn dropped(&self) -> u64 {
        [
            self.culled_object,
            self.culled_frustum,
            self.culled_backface,
            self.culled_degenerate,
            self.rejected_nonfinite,
            self.rejected_index,
            self.outside_strip,
            self.culled_cluster,
            self.culled_hierarchy,
            self.culled_detail,
            self.culled_mask,
            self.culled_occlusion,
            self.culled_portal,
        ]
        .iter()
        .fold(0u64, |a, &b| a.saturating_add(b))
    }

    /// The field-wise saturating sum.
    pub fn saturating_add(self, o: Stats) -> Stats {
        Stats {
            submitted: self.submitted.saturating_add(o.submitted),
            culled_object: self.culled_object.saturating_add(o.culled_object),
            culled_frustum: self.culled_frustum.saturating_add(o.culled_frustum),
            culled_backface: self.culled_backface.saturating_add(o.culled_backface),
            culled_degenerate: self.culled_degenerate.saturating_add(o.culled_degenerate),
            rejected_nonfinite: self.rejected_nonfinite.saturating_add(o.rejected_nonfinite),
            rejected_index: self.rejected_index.saturating_add(o.rejected_index),
            clipped: self.clipped.saturating_add(o.clipped),
            stored: self.stored.saturating_add(o.stored),
            outside_strip: self.outside_strip.saturating_add(o.outside_strip),
            culled_cluster: self.culled_cluster.saturating_add(o.culled_cluster),
            culled_hierarchy: self.culled_hierarchy.saturating_add(o.culled_hierarchy),
            culled_detail: self.culled_detail.saturating_add(o.culled_detail),
            culled_mask: self.culled_mask.saturating_add(o.culled_mask),
            culled_occlusion: self.culled_occlusion.saturating_add(o.culled_occlusion),
            culled_portal: self.culled_portal.saturating_add(o.culled_portal),
            detail_boxes: self.detail_boxes.saturating_add(o.detail_boxes),
        }
    }
}

impl Add for Stats {
    type Output = Stats;
    /// Field-wise, saturating.
    fn add(self, o: Stats) -> Stats {
        self.saturating_add(o)
    }
}

impl AddAssign for Stats {
    fn add_assign(&mut self, o: Stats) {
        *self = self.saturating_add(o);
    }
}

impl core::iter::Sum for Stats {
    fn sum<I: Iterator<Item = Stats>>(iter: I) -> Stats {
        iter.fold(Stats::default(), Add::add)
    }
}

/// Counters of one render call (or of a strip renderer so far).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct RenderStats {
    /// Pixels written (passed the depth test).
    pub pixels_written: u64,
}

impl Add for RenderStats {
    type Output = RenderStats;
    /// Saturating.
    fn add(self, o: RenderStats) -> RenderStats {
        RenderStats {
            pixels_written: self.pixels_written.saturating_add(o.pixels_written),
        }
    }
}

impl AddAssign for RenderStats {
    fn add_assign(&mut self, o: RenderStats) {
        *self = *self + o;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sums_saturate() {
        let big = Stats {
            submitted: u64::MAX - 1,
            culled_object: 3,
            ..Stats::default()
        };
        let s = big + big;
        assert_eq!(s.submitted, u64::MAX);
        assert_eq!(s.culled_object, 6);
        let mut t = s;
        t += s;
        assert_eq!(t.submitted, u64::MAX);
        assert_eq!([big, big, big].into_iter().sum::<Stats>().culled_object, 9);
        assert_eq!(s.dropped(), 6);
    }
}
