//! Comparing the core's images with the `f64` reference, and summarising.
//!
//! Design note: every differing pixel is checked against what snapping and
//! the measured vertex error can explain (see the report's design note);
//! what remains is counted as unexplained, which would be a core bug.

use super::*;

// ---------------------------------------------------------------------------
// Comparison

/// How far snapping and the `f32` vertex stage may move things.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Tolerance {
    /// How far an edge may move, pixels (per axis and in distance).
    pub xy: f64,
    /// How far a vertex depth may move, window-depth units.
    pub z: f64,
}

impl Tolerance {
    /// The clipless mode's: its quantization moves a vertex by at most
    /// `D 2^-21` pixels (`D` the frame's larger side, 22-bit mantissas of
    /// coordinates up to `2 w D`) and its window depth by `2^-21`, plus the
    /// measured vertex error.
    pub fn clipless(width: u32, height: u32, v: &VertexError) -> Self {
        let d = width.max(height) as f64;
        Tolerance {
            xy: std::f64::consts::SQRT_2 * (d * 2f64.powi(-21) + v.window_px) + 1e-6,
            z: v.window_z + 2f64.powi(-21) + 1e-9,
        }
    }

    /// Half a subpixel per axis (√2 of that as a distance), plus the
    /// measured vertex error, plus a little slack for `f64` rounding.
    pub fn new(subpixel: u32, v: &VertexError) -> Self {
        let half = 0.5 / (1u64 << subpixel) as f64;
        Tolerance {
            xy: std::f64::consts::SQRT_2 * (half + v.window_px) + 1e-6,
            z: v.window_z + 1e-9,
        }
    }
}

/// The error of one configuration on one scene.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ErrorStats {
    /// Pixels the reference covers.
    pub covered: usize,
    /// Pixels whose triangle id differs from the reference.
    pub id_diff: usize,
    /// Of those, pixels where one is background and the other is not.
    pub coverage_diff: usize,
    /// Differing pixels that snapping and depth ties do not explain.
    pub unexplained: usize,
    /// Depth-test flips: differing pixels that both triangles cover away
    /// from their edges (beyond the tolerance), so the depth test, not
    /// coverage, chose another surface than the exact depths do.
    pub depth_flips: usize,
    /// A few unexplained pixels: `(x, y, core id + 1, reference id + 1)`.
    pub unexplained_examples: Vec<(u32, u32, u32, u32)>,
    /// Pixels compared for depth and colour (same triangle in both).
    pub same: usize,
    /// Largest depth error, LSB of the buffer.
    pub depth_max_lsb: f64,
    /// Mean depth error, LSB.
    pub depth_mean_lsb: f64,
    /// Pixels whose depth error exceeds the explained bound.
    pub depth_beyond: usize,
    /// Largest `|stored / 2^bits - exact depth|` (window-depth units):
    /// the buffer's own quantisation included.
    pub depth_abs_max: f64,
    /// Mean of the same.
    pub depth_abs_mean: f64,
    /// Largest colour error over channels, LSB of 8 bits.
    pub color_max: f64,
    /// Mean colour error over pixels and channels.
    pub color_mean: f64,
    /// Pixels whose colour error exceeds the explained bound.
    pub color_beyond: usize,
    /// A few depth and colour errors beyond the bound:
    /// `(x, y, id + 1, what, stored, exact)`.
    pub beyond_examples: Vec<(u32, u32, u32, &'static str, String, String)>,
}

/// Compares a core image with the reference.
pub(crate) fn compare(
    core: &CoreRun,
    depth_bits: u32,
    reference: &RefImage,
    prepared: &[Option<Prepared>],
    tol: Tolerance,
) -> ErrorStats {
    let (ids, color, depth) = (&core.ids, &core.color, &core.depth);
    let scale = (1u64 << depth_bits) as f64;
    let lsb = 1.0 / scale;
    let w = reference.width as usize;
    let mut s = ErrorStats {
        covered: reference.covered(),
        ..ErrorStats::default()
    };
    let mut depth_sum = 0.0;
    let mut depth_abs_sum = 0.0;
    let mut color_sum = 0.0;
    let tri = |id: u32| -> Option<&Prepared> {
        id.checked_sub(1)
            .and_then(|k| prepared.get(k as usize))
            .and_then(|p| p.as_ref())
    };
    for (i, (&a, &b)) in ids.iter().zip(&reference.ids).enumerate() {
        let (px, py) = ((i % w) as f64 + 0.5, (i / w) as f64 + 0.5);
        if a == b {
            let Some(p) = tri(a) else { continue };
            s.same += 1;
            let s0 = p.sample(px, py);
            let sx = p.sample(px + 1.0, py);
            let sy = p.sample(px, py + 1.0);
            // Depth against the exact depth, truncated as the core stores it.
            let z = reference.depth[i];
            let ideal = (z * scale).floor().clamp(0.0, scale - 1.0);
            let err = (depth[i] as f64 - ideal).abs();
            let grad = (sx.depth - s0.depth).abs() + (sy.depth - s0.depth).abs();
            let bound = 2.0 + (grad * tol.xy + tol.z) * scale;
            s.depth_max_lsb = s.depth_max_lsb.max(err);
            depth_sum += err;
            // What the buffer holds against the exact depth.
            let abs = (depth[i] as f64 / scale - z).abs();
            s.depth_abs_max = s.depth_abs_max.max(abs);
            depth_abs_sum += abs;
            if err > bound {
                s.depth_beyond += 1;
                if s.beyond_examples.len() < 5 {
                    s.beyond_examples.push((
                        (i % w) as u32,
                        (i / w) as u32,
                        a,
                        "depth",
                        depth[i].to_string(),
                        format!("{ideal} (bound {bound:.1} LSB)"),
                    ));
                }
            }
            // Colour against the exact colour rounded to nearest.
            let c = color[i];
            let core = [c.r(), c.g(), c.b()].map(f64::from);
            let sxm = p.sample(px - 1.0, py);
            let sym = p.sample(px, py - 1.0);
            let mut beyond = false;
            #[allow(clippy::needless_range_loop)] // ch indexes several arrays
            for ch in 0..3 {
                let exact = reference.color[i][ch];
                let err = (core[ch] - (exact + 0.5).floor()).abs();
                let g = |q: &reference::Sample| (q.color[ch] - s0.color[ch]).abs();
                let grad = g(&sx).max(g(&sxm)) + g(&sy).max(g(&sym));
                // 1 LSB of rounding on each side, plus `f32` shading slack.
                if err > 1.0 + grad * tol.xy + 1e-3 * exact.abs().max(1.0) {
                    beyond = true;
                }
                s.color_max = s.color_max.max(err);
                color_sum += err;
            }
            if beyond {
                s.color_beyond += 1;
                if s.beyond_examples.len() < 5 {
                    s.beyond_examples.push((
                        (i % w) as u32,
                        (i / w) as u32,
                        a,
                        "colour",
                        format!("{:?}", [c.r(), c.g(), c.b()]),
                        format!("{:.2?}", reference.color[i]),
                    ));
                }
            }
            continue;
        }
        s.id_diff += 1;
        if (a == 0) != (b == 0) {
            s.coverage_diff += 1;
        }
        let sa = tri(a).map(|p| (p, p.sample(px, py)));
        let sb = tri(b).map(|p| (p, p.sample(px, py)));
        let near_edge = |t: &Option<(&Prepared, reference::Sample)>| {
            t.as_ref()
                .is_some_and(|(_, q)| q.inv_w > 0.0 && q.edge_distance.abs() <= tol.xy)
        };
        let inside = |t: &Option<(&Prepared, reference::Sample)>| {
            t.as_ref()
                .is_some_and(|(_, q)| q.inside && q.inv_w > 0.0 && q.edge_distance > tol.xy)
        };
        if inside(&sa) && inside(&sb) {
            s.depth_flips += 1;
        }
        let explained = near_edge(&sa)
            || near_edge(&sb)
            || match (&sa, &sb) {
                (Some((pa, qa)), Some((pb, qb))) => {
                    // Both cover the pixel (within tolerance) and their
                    // depths tie within what snapping and the buffer allow.
                    let ztol = |p: &Prepared, q: &reference::Sample| {
                        let gx = (p.sample(px + 1.0, py).depth - q.depth).abs();
                        let gy = (p.sample(px, py + 1.0).depth - q.depth).abs();
                        (gx + gy) * tol.xy + tol.z
                    };
                    qa.inv_w > 0.0
                        && qb.inv_w > 0.0
                        && qa.edge_distance >= -tol.xy
                        && qb.edge_distance >= -tol.xy
                        && (qa.depth - qb.depth).abs()
                            <= ztol(pa, qa) + ztol(pb, qb) + 2.0 * lsb + 2.0 / 4_294_967_296.0
                }
                _ => false,
            };
        if !explained {
            s.unexplained += 1;
            if s.unexplained_examples.len() < 5 {
                s.unexplained_examples
                    .push(((i % w) as u32, (i / w) as u32, a, b));
            }
        }
    }
    if s.same > 0 {
        s.depth_mean_lsb = depth_sum / s.same as f64;
        s.depth_abs_mean = depth_abs_sum / s.same as f64;
        s.color_mean = color_sum / (3 * s.same) as f64;
    }
    s
}

/// Indices of the points on the Pareto front when both coordinates are to
/// be minimised (no other point is at most as large in both and smaller in
/// one), ordered by `x`, then `y`. Points with a NaN are never on it.
pub fn pareto_front(points: &[(f64, f64)]) -> Vec<usize> {
    let mut front: Vec<usize> = (0..points.len())
        .filter(|&i| {
            let (x, y) = points[i];
            !x.is_nan()
                && !y.is_nan()
                && !points
                    .iter()
                    .any(|&(u, v)| u <= x && v <= y && (u < x || v < y))
        })
        .collect();
    front.sort_by(|&i, &j| {
        let (a, b) = (points[i], points[j]);
        a.0.total_cmp(&b.0).then(a.1.total_cmp(&b.1))
    });
    front
}

pub(crate) fn median(v: &[f64]) -> f64 {
    let mut s = v.to_vec();
    s.sort_by(f64::total_cmp);
    match s.len() {
        0 => f64::NAN,
        n if n % 2 == 1 => s[n / 2],
        n => 0.5 * (s[n / 2 - 1] + s[n / 2]),
    }
}
