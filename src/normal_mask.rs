//! Normal masks: skipping back-facing triangles by a table lookup on
//! their normal's class, before any of their vertices is transformed.
//!
//! Design note (the lecture's "Normal Masks", after Zhang and Hoff): an
//! offline step (the host's `normal_mask` module) puts each triangle's
//! normal in one of `6 N^2` classes, the cells of a direction cube with
//! `N` partitions a side ([`classify`]), and stores one `u16` class id per
//! triangle with, per class, the size bounds of its triangles. Per frame,
//! [`BackMask::for_frame`] finds the classes whose every normal faces away
//! from every visible point, a bit each; a submission
//! ([`Submit::submit_masked`](crate::Submit::submit_masked)) then skips a
//! triangle whose class is in the mask with one lookup, and transforms
//! only the vertices of the triangles it keeps.
//!
//! Why the mask is conservative. A point `p` seen at clip coordinates
//! `(x, y, z, w)` is `(p, 1) = w A^-1 (X, Y, Z, 1)` with `X = x/w`, `Y =
//! y/w`, `Z = z/w`; the triangle's facing value `n . (E_xyz - E_w p)` (see
//! [`Eye`]) is linear in `(p, 1)` and vanishes on the eye `E`, which
//! `A^-1 (0, 0, 1, 0)` is a multiple of. So at a visible point the facing
//! value is `w` times a bilinear blend of its values `g_j . n` at the four
//! corners `(X_j, Y_j, 0, 1)` of the sector (the viewport, or a strip of
//! it, with a margin), and it is the same at every point of the
//! triangle's plane. A cell's normals are non-negative blends of its four
//! corner directions `m_k = +-e_a + u e_b + v e_c` (the cube's face `a`,
//! the cell's corner `(u, v)`). Where every `-sign g_j . m_k` is positive
//! (16 products: "test each class in all four corners of the view
//! frustum"), every triangle of the class that shows in the sector is
//! culled by winding, with a facing value of at least `w_min s delta /
//! |m|` for a unit normal (`delta` the least product, `s` the scale of
//! the `g_j`, `|m|` the longest corner direction of the cell, `w_min` over
//! the class's sphere). The `g_j` come from the matrix's rows alone, in
//! `f64` (`corner_directions`: no inverse, and no cancellation against
//! the eye's position, which a far eye and a near plane would make
//! large); an eye at infinity (an orthographic matrix) masks nothing.
//! That value goes through the
//! clusters' margin ([`MARGIN`]) and size guard: a class is in the mask
//! only where none of its triangles can snap to the other winding. So the
//! frame is byte-identical to per-triangle culling (a skipped triangle
//! that does not show in the sector covers no pixel of it).
//!
//! Sectors: a [`StripRenderer`](crate::StripRenderer) builds the mask of
//! its strip's rows, narrower than the whole frustum ("render the scene
//! sector by sector"); a [`Frame`](crate::Frame) uses the whole viewport.
//!
//! Bad data (a class id beyond the classes, lengths that do not fit the
//! mesh, partitions outside `1..=16`) is refused with
//! [`Error::InvalidNormalClasses`] before anything is drawn; class ids
//! or sizes that do not fit the triangles cannot be detected at run time
//! and are the offline step's responsibility.

// `!(a > b)` is meant: it is true for NaN, which must never cull. The
// 4x4 loops index several arrays in step.
#![allow(clippy::neg_cmp_op_on_partial_ord, clippy::needless_range_loop)]

use crate::config::Error;
use crate::cull::{Eye, MARGIN};
use crate::math::{fx, Mat4};
use crate::mesh::BoundingSphere;

/// The most partitions a side of the direction cube (`N`).
pub const MAX_PARTITIONS: u8 = 16;

/// The most classes: `6 * 16 * 16`.
pub const MAX_CLASSES: usize = 6 * 16 * 16;

/// The class of a triangle without a normal (zero area, non-finite): never
/// skipped.
pub const NO_CLASS: u16 = u16::MAX;

/// Words of a mask.
const WORDS: usize = MAX_CLASSES / 32;

/// Allowance for the `f32` evaluation of the corner products, whose terms
/// are at most 1 in magnitude (`2^-18`).
const ROUNDING: f32 = 1.0 / 262_144.0;

/// `sqrt 3` rounded up.
const SQRT_3_UP: f32 = 1.732_051;

/// The classes of `partitions` partitions a side: `6 N^2`, or 0 outside
/// `1..=`[`MAX_PARTITIONS`].
pub fn class_count(partitions: u8) -> usize {
    if (1..=MAX_PARTITIONS).contains(&partitions) {
        6 * usize::from(partitions) * usize::from(partitions)
    } else {
        0
    }
}

/// The class of the normal `n` (any length) on a direction cube of
/// `partitions` a side: face `2a + (n_a < 0)` for the axis `a` of the
/// largest component (the first of equals), then the cell of `(n_b, n_c)
/// / |n_a|` (`b = a + 1`, `c = a + 2`, modulo 3) in the face's `N x N`
/// grid over `[-1, 1]^2`, row `b`: `face N^2 + i N + j`. [`NO_CLASS`] for
/// a zero or non-finite normal, or partitions outside `1..=16`.
pub fn classify(n: [f64; 3], partitions: u8) -> u16 {
    if class_count(partitions) == 0 || !n.iter().all(|v| v.is_finite()) {
        return NO_CLASS;
    }
    let mut a = 0;
    for k in 1..3 {
        if n[k].abs() > n[a].abs() {
            a = k;
        }
    }
    let big = n[a].abs();
    if !(big > 0.0) {
        return NO_CLASS;
    }
    let np = f64::from(partitions);
    let cell = |v: f64| -> u16 {
        let i = ((v / big + 1.0) * 0.5 * np) as i64;
        i.clamp(0, i64::from(partitions) - 1) as u16
    };
    let face = 2 * a as u16 + u16::from(n[a] < 0.0);
    let p = u16::from(partitions);
    face * p * p + cell(n[(a + 1) % 3]) * p + cell(n[(a + 2) % 3])
}

/// A mesh's normal classes, as the offline step wrote them (plain arrays:
/// `static`s in flash, or slices).
#[derive(Clone, Copy, Debug)]
pub struct NormalClasses<'a> {
    /// Partitions a side of the direction cube, `1..=16`.
    pub partitions: u8,
    /// One class per triangle ([`classify`] of its normal), or
    /// [`NO_CLASS`].
    pub classes: &'a [u16],
    /// Per class, the size bounds of its triangles for the size guard:
    /// the least ratio of doubled area to the sum of two edges and the
    /// least doubled area ([`crate::cull::triangle_sizes`]); zeros never
    /// pass it. `6 N^2` entries.
    pub sizes: &'a [[f32; 2]],
    /// Per class, a sphere around every vertex of its triangles
    /// ([`crate::cull::triangle_sphere`]): a class's triangles lie where
    /// the surface faces its way, so the sphere is small on a smooth
    /// mesh. `6 N^2` entries; [`BoundingSphere::EVERYWHERE`] never
    /// passes the size guard.
    pub spheres: &'a [BoundingSphere],
}

/// What [`NormalClasses::validate`] found wrong.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum ClassFault {
    /// Partitions outside `1..=16`.
    Partitions,
    /// Not one class per triangle.
    Triangles,
    /// Not `6 N^2` size or sphere entries.
    Sizes,
    /// The class of this triangle is beyond the classes (and not
    /// [`NO_CLASS`]).
    Class(usize),
}

impl NormalClasses<'_> {
    /// Checks the structure against a mesh of `triangles` triangles, in
    /// O(triangles).
    pub fn validate(&self, triangles: usize) -> Result<(), Error> {
        let err = |f| Err(Error::InvalidNormalClasses(f));
        let n = class_count(self.partitions);
        if n == 0 {
            return err(ClassFault::Partitions);
        }
        if self.classes.len() != triangles {
            return err(ClassFault::Triangles);
        }
        if self.sizes.len() != n || self.spheres.len() != n {
            return err(ClassFault::Sizes);
        }
        match self
            .classes
            .iter()
            .position(|&c| usize::from(c) >= n && c != NO_CLASS)
        {
            Some(i) => err(ClassFault::Class(i)),
            None => Ok(()),
        }
    }
}

/// The classes whose triangles a frame skips: a bit per class.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct BackMask {
    words: [u32; WORDS],
}

impl Default for BackMask {
    fn default() -> BackMask {
        BackMask::EMPTY
    }
}

impl BackMask {
    /// No class.
    pub const EMPTY: BackMask = BackMask { words: [0; WORDS] };

    /// Whether class `c` is in the mask ([`NO_CLASS`] and ids beyond the
    /// classes never are).
    #[inline]
    pub fn contains(&self, c: u16) -> bool {
        let c = usize::from(c);
        self.words
            .get(c / 32)
            .is_some_and(|w| (w >> (c % 32)) & 1 != 0)
    }

    /// The number of classes in the mask.
    pub fn len(&self) -> usize {
        self.words.iter().map(|w| w.count_ones() as usize).sum()
    }

    /// Whether no class is in the mask.
    pub fn is_empty(&self) -> bool {
        self.words.iter().all(|&w| w == 0)
    }

    /// The mask of a frame of `config` at `S` subpixel bits drawn with
    /// `mvp`, for the triangles showing within the rows of NDC `y` in
    /// `sector` (`(top, bottom)`, as a strip renderer's slab) or, for
    /// `None`, in the whole viewport (with a pixel's margin): every class
    /// whose triangles are all culled by winding there, with the margin
    /// and size guard of the clusters ([`Eye::for_frame`]). Empty where
    /// nothing can be culled: [`CullMode::None`](crate::CullMode), a
    /// non-finite or singular matrix, or a sphere not wholly inside near,
    /// far and the guard band.
    pub fn for_frame<const S: u32>(
        mvp: &Mat4,
        config: &crate::Config,
        sector: Option<(f32, f32)>,
        set: &NormalClasses<'_>,
    ) -> BackMask {
        BackMask::build::<S>(mvp, config, sector, set, true)
    }

    /// The lecture's mask alone, without the size guard: the classes
    /// whose every normal faces away from every corner of the sector, by
    /// the margin. Not byte-exact (a skipped triangle far below a pixel
    /// may snap to the other winding); for measuring what the guard of
    /// [`BackMask::for_frame`] costs.
    pub fn geometric<const S: u32>(
        mvp: &Mat4,
        config: &crate::Config,
        sector: Option<(f32, f32)>,
        set: &NormalClasses<'_>,
    ) -> BackMask {
        BackMask::build::<S>(mvp, config, sector, set, false)
    }

    fn build<const S: u32>(
        mvp: &Mat4,
        config: &crate::Config,
        sector: Option<(f32, f32)>,
        set: &NormalClasses<'_>,
        guard: bool,
    ) -> BackMask {
        let n = class_count(set.partitions);
        if n == 0 || set.sizes.len() != n || set.spheres.len() != n {
            return BackMask::EMPTY;
        }
        let Some(eye) = Eye::for_frame::<S>(mvp, config) else {
            return BackMask::EMPTY;
        };
        let Some(screen) = eye.screen else {
            return BackMask::EMPTY;
        };
        let mx = 1.0 + 2.0 / config.width as f32;
        let my = 1.0 + 2.0 / config.height as f32;
        let (top, bottom) = sector.unwrap_or((my, -my));
        let Some((dirs, s)) = corner_directions(mvp, &eye, [-mx, mx, bottom, top]) else {
            return BackMask::EMPTY;
        };
        // The margin: every skipped normal at least MARGIN (as a sine)
        // past edge-on against each corner's direction.
        let gmax = dirs.iter().fold(0.0f32, |m, d| {
            fx::max(m, fx::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]))
        });
        let least = SQRT_3_UP * MARGIN * gmax * (1.0 + ROUNDING);
        let mut mask = BackMask::EMPTY;
        let p = usize::from(set.partitions);
        let step = 2.0 / p as f32;
        for face in 0..6 {
            let a = face / 2;
            let sa = if face % 2 == 0 { 1.0f32 } else { -1.0 };
            let (ib, ic) = ((a + 1) % 3, (a + 2) % 3);
            // At grid point (i, j): the least corner product, and
            // `|m|^2 = 1 + u^2 + v^2`. Rows kept one at a time.
            let at = |i: usize, j: usize| -> (f32, f32) {
                let (u, v) = (-1.0 + step * i as f32, -1.0 + step * j as f32);
                let least = dirs.iter().fold(f32::INFINITY, |m, d| {
                    fx::min(m, sa * d[a] + u * d[ib] + v * d[ic])
                });
                (least - 4.0 * ROUNDING, 1.0 + u * u + v * v)
            };
            let mut prev = [(0.0f32, 0.0f32); MAX_PARTITIONS as usize + 1];
            for i in 0..=p {
                let mut row = [(0.0f32, 0.0f32); MAX_PARTITIONS as usize + 1];
                for (j, r) in row.iter_mut().enumerate().take(p + 1) {
                    *r = at(i, j);
                }
                if i > 0 {
                    for j in 0..p {
                        let corners = [prev[j], prev[j + 1], row[j], row[j + 1]];
                        let delta = corners.iter().fold(f32::INFINITY, |m, c| fx::min(m, c.0));
                        if !(delta > least) {
                            continue;
                        }
                        let c = face * p * p + (i - 1) * p + j;
                        // A unit normal of the cell is `m / |m|` with `m`
                        // in its rectangle, `|m|` at most the largest
                        // corner's.
                        let m2 = corners.iter().fold(0.0f32, |m, c| fx::max(m, c.1));
                        let len = fx::sqrt(m2) * (1.0 + ROUNDING);
                        if !guard || class_keeps_winding(set, c, &screen, eye.big, s * delta / len)
                        {
                            if let Some(w) = mask.words.get_mut(c / 32) {
                                *w |= 1 << (c % 32);
                            }
                        }
                    }
                }
                prev = row;
            }
        }
        mask
    }
}

/// Whether the triangles of class `c`, whose facing values are at least
/// `w delta_s` at a point of clip `w` (`delta_s` for unit normals and `E`
/// scaled by `big`), keep their winding when snapped: the size guard of
/// the clusters over the class's sphere, with `w >= w_min` there.
fn class_keeps_winding(
    set: &NormalClasses<'_>,
    c: usize,
    screen: &crate::cull::Screen,
    big: f32,
    delta_s: f32,
) -> bool {
    let (Some(b), Some(&size)) = (set.spheres.get(c), set.sizes.get(c)) else {
        return false;
    };
    let centre = [b.center.x, b.center.y, b.center.z];
    screen
        .winding_floor(centre, b.radius, big)
        .is_some_and(|f| f.keeps(size, f.w_min * delta_s * (1.0 - ROUNDING)))
}

/// The directions `-sign g_j` of the sector's corners `(X, Y)` for `X` in
/// `rect[0..2]`, `Y` in `rect[2..4]`, scaled by `1/s` so the largest
/// component is 1; a normal `n` faces away at that corner where
/// `direction . n > 0`.
///
/// `g_j . n` is the facing value per unit clip `w` on the ray of clip
/// points `(X, Y, *, 1)` (the value at `A^-1 (X, Y, 0, 1)`). The ray's
/// points `P` satisfy `(r_x - X r_w) . P = (r_y - Y r_w) . P = 0`; so does
/// its point at infinity `(d, 0)` with `d = (m_x - X m_w) x (m_y - Y m_w)`
/// (`m` the rows' first three columns), where the facing value is `-E_w
/// n . d` and `w = m_w . d`; both vanish on the eye. So `g_j = -E_w d /
/// (m_w . d)`: found in `f64` from the matrix alone, with no inverse and
/// no cancellation against the eye's position (the facing value's scale
/// `E_w` enters as one factor). `None` for an eye at infinity
/// (orthographic: `E_w = 0`), a non-finite matrix, or a degenerate
/// corner ray.
fn corner_directions(mvp: &Mat4, eye: &Eye, rect: [f32; 4]) -> Option<([[f32; 3]; 4], f32)> {
    let c = &mvp.cols;
    let row = |i: usize| [c[0][i], c[1][i], c[2][i]].map(f64::from);
    let (mx, my, mw) = (row(0), row(1), row(3));
    let ew = f64::from(eye.w);
    let sign = f64::from(eye.sign);
    if !(ew != 0.0 && ew.is_finite()) {
        return None;
    }
    let norm2 = |v: [f64; 3]| v[0] * v[0] + v[1] * v[1] + v[2] * v[2];
    let dot = |a: [f64; 3], b: [f64; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    let mut g = [[0.0f64; 3]; 4];
    for (k, gk) in g.iter_mut().enumerate() {
        let (x, y) = (f64::from(rect[k % 2]), f64::from(rect[2 + k / 2]));
        let a: [f64; 3] = core::array::from_fn(|i| mx[i] - x * mw[i]);
        let b: [f64; 3] = core::array::from_fn(|i| my[i] - y * mw[i]);
        let d = [
            a[1] * b[2] - a[2] * b[1],
            a[2] * b[0] - a[0] * b[2],
            a[0] * b[1] - a[1] * b[0],
        ];
        let den = dot(mw, d);
        // Well-conditioned only: the planes far from parallel, the ray
        // far from perpendicular to the view axis (f64 then leaves errors
        // near 2^-30 relative, far inside the allowance).
        let (nd, na, nb, nw) = (norm2(d), norm2(a), norm2(b), norm2(mw));
        if !(nd > 1e-12 * na * nb && den * den > 1e-12 * nw * nd) {
            return None;
        }
        *gk = core::array::from_fn(|i| sign * ew * d[i] / den);
    }
    let s = g.iter().flatten().fold(0.0f64, |m, v| m.max(v.abs()));
    if !(s > 0.0 && s.is_finite()) {
        return None;
    }
    let dirs = g.map(|v| v.map(|x| (x / s) as f32));
    Some((dirs, s as f32))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn classes_cover_the_cube_once() {
        assert_eq!(class_count(0), 0);
        assert_eq!(class_count(17), 0);
        assert_eq!(class_count(16), MAX_CLASSES);
        assert_eq!(classify([0.0, 0.0, 0.0], 4), NO_CLASS);
        assert_eq!(classify([f64::NAN, 0.0, 1.0], 4), NO_CLASS);
        assert_eq!(classify([1.0, 0.0, 0.0], 0), NO_CLASS);
        // +x face, centre: cell (1, 1) of 2.
        assert_eq!(classify([1.0, 0.0, 0.0], 2), 3);
        // -z face (5): u = x/|z|, v = y/|z|.
        assert_eq!(classify([-0.9, 0.9, -1.0], 2), 5 * 4 + 1);
        let mut seen = [false; 6 * 9];
        for f in 0..6 {
            for i in 0..3 {
                for j in 0..3 {
                    let (a, s) = (f / 2, if f % 2 == 0 { 1.0 } else { -1.0 });
                    let mut n = [0.0; 3];
                    n[a] = s;
                    n[(a + 1) % 3] = -1.0 + (2 * i + 1) as f64 / 3.0;
                    n[(a + 2) % 3] = -1.0 + (2 * j + 1) as f64 / 3.0;
                    let c = classify(n, 3);
                    assert_eq!(usize::from(c), f * 9 + i * 3 + j);
                    seen[usize::from(c)] = true;
                }
            }
        }
        assert!(seen.iter().all(|&s| s));
    }

    #[test]
    fn bad_class_data_is_refused() {
        let sizes = [[1.0f32; 2]; 6];
        let spheres = [BoundingSphere::EVERYWHERE; 6];
        let ok = NormalClasses {
            partitions: 1,
            classes: &[0, 5, NO_CLASS],
            sizes: &sizes,
            spheres: &spheres,
        };
        assert_eq!(ok.validate(3), Ok(()));
        let fault = |s: &NormalClasses<'_>, t| match s.validate(t) {
            Err(Error::InvalidNormalClasses(f)) => Some(f),
            _ => None,
        };
        assert_eq!(fault(&ok, 2), Some(ClassFault::Triangles));
        let bad = NormalClasses {
            classes: &[0, 6, 1],
            ..ok
        };
        assert_eq!(fault(&bad, 3), Some(ClassFault::Class(1)));
        let bad = NormalClasses {
            sizes: &sizes[..5],
            ..ok
        };
        assert_eq!(fault(&bad, 3), Some(ClassFault::Sizes));
        let bad = NormalClasses {
            partitions: 17,
            ..ok
        };
        assert_eq!(fault(&bad, 3), Some(ClassFault::Partitions));
    }

    #[test]
    fn masks_hold_what_is_put_in() {
        let mut m = BackMask::EMPTY;
        assert!(m.is_empty() && !m.contains(0) && !m.contains(NO_CLASS));
        m.words[1] = 1 << 3;
        assert!(m.contains(35) && !m.contains(34) && m.len() == 1);
    }
}
