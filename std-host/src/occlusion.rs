//! Occlusion culling's offline step: an object split into parts, each a run
//! of triangles with its own box, so that the part of a half-hidden object
//! behind others is skipped too (see [`microraster::occlusion`]).
//!
//! Design note: [`split`] cuts the triangles in two at the median of their
//! centroids along the longest side of the centroids' box, again and again
//! until a part has at most `max_triangles` (a k-d tree's leaves, in
//! order). It returns the triangles reordered so that every part is a
//! contiguous run, and each part's box around its vertices. The runtime
//! tests the object's own bound first, then each part's
//! (`render::Occlusion::On`); the vertex stage still runs once for the
//! whole object, by the first strip that draws any part of it.

use microraster::occlusion::Aabb;
use microraster::Vec3;
use std::ops::Range;

/// A run of an object's triangles and the box around their vertices.
#[derive(Clone, Debug, PartialEq)]
pub struct Part {
    /// Triangles `triangles` of the (reordered) object.
    pub triangles: Range<usize>,
    /// Their box in object space.
    pub aabb: Aabb,
}

/// Triangles per part by default.
pub const PART_TRIANGLES: usize = 128;

/// `indices` reordered into parts of at most `max_triangles` (at least 1)
/// triangles, and the parts. Triangles with an index out of range, or a
/// vertex that is not finite, stay in a part of their own at the end,
/// without a box the runtime could trust: none is made for them, so that
/// part is drawn whenever its object is (its box is the object's).
pub fn split(
    positions: &[Vec3],
    indices: &[[u32; 3]],
    max_triangles: usize,
) -> (Vec<[u32; 3]>, Vec<Part>) {
    let max = max_triangles.max(1);
    let vertex = |i: u32| positions.get(i as usize).copied().filter(|p| p.is_finite());
    let (mut good, mut bad): (Vec<usize>, Vec<usize>) =
        (0..indices.len()).partition(|&t| indices[t].iter().all(|&i| vertex(i).is_some()));
    let centroid = |t: usize| -> [f32; 3] {
        let [a, b, c] = indices[t].map(|i| vertex(i).unwrap_or(Vec3::new(0.0, 0.0, 0.0)));
        [
            (a.x + b.x + c.x) / 3.0,
            (a.y + b.y + c.y) / 3.0,
            (a.z + b.z + c.z) / 3.0,
        ]
    };
    let mut leaves: Vec<Range<usize>> = Vec::new();
    let mut stack: Vec<Range<usize>> = Vec::new();
    stack.push(0..good.len());
    while let Some(r) = stack.pop() {
        if r.len() <= max {
            leaves.push(r);
            continue;
        }
        let cs: Vec<[f32; 3]> = good[r.clone()].iter().map(|&t| centroid(t)).collect();
        let axis = (0..3)
            .max_by(|&a, &b| {
                let ext = |k: usize| {
                    let (lo, hi) = cs
                        .iter()
                        .fold((f32::MAX, f32::MIN), |(l, h), c| (l.min(c[k]), h.max(c[k])));
                    hi - lo
                };
                ext(a).total_cmp(&ext(b))
            })
            .unwrap_or(0);
        let mid = r.len() / 2;
        good[r.clone()].select_nth_unstable_by(mid, |&a, &b| {
            centroid(a)[axis].total_cmp(&centroid(b)[axis])
        });
        // Pushed right first: the left half is split (and listed) first.
        stack.push(r.start + mid..r.end);
        stack.push(r.start..r.start + mid);
    }
    let mut out = Vec::with_capacity(indices.len());
    let mut parts = Vec::with_capacity(leaves.len());
    for r in leaves {
        let start = out.len();
        let mut pts = Vec::with_capacity(3 * r.len());
        for &t in &good[r] {
            out.push(indices[t]);
            pts.extend(indices[t].iter().filter_map(|&i| vertex(i)));
        }
        if let Some(aabb) = Aabb::from_points(&pts) {
            parts.push(Part {
                triangles: start..out.len(),
                aabb,
            });
        }
    }
    bad.sort_unstable();
    out.extend(bad.iter().map(|&t| indices[t]));
    (out, parts)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parts_tile_the_good_triangles_and_bound_them() {
        let positions: Vec<Vec3> = (0..40)
            .map(|i| Vec3::new(i as f32, (i * 7 % 11) as f32, (i * 3 % 5) as f32))
            .collect();
        let mut indices: Vec<[u32; 3]> = (0..38)
            .map(|i| [i as u32, i as u32 + 1, i as u32 + 2])
            .collect();
        indices.push([0, 1, 99]);
        let (out, parts) = split(&positions, &indices, 5);
        assert_eq!(out.len(), indices.len());
        let mut sorted = out.clone();
        sorted.sort_unstable();
        let mut want = indices.clone();
        want.sort_unstable();
        assert_eq!(sorted, want, "a permutation");
        assert_eq!(out.last(), Some(&[0, 1, 99]), "the bad one last, unboxed");
        let mut next = 0;
        for p in &parts {
            assert_eq!(p.triangles.start, next);
            assert!(p.triangles.len() <= 5 && !p.triangles.is_empty());
            next = p.triangles.end;
            for t in &out[p.triangles.clone()] {
                for &i in t {
                    let v = positions[i as usize];
                    assert!(v.x >= p.aabb.min.x && v.x <= p.aabb.max.x);
                    assert!(v.y >= p.aabb.min.y && v.y <= p.aabb.max.y);
                    assert!(v.z >= p.aabb.min.z && v.z <= p.aabb.max.z);
                }
            }
        }
        assert_eq!(next, 38);
    }
}

/// One row of the occlusion table: the spots scene through strips of
/// `rows` rows, from every camera.
#[derive(Clone, Debug, serde::Serialize)]
pub struct OcclusionRow {
    /// Rows per strip.
    pub rows: u32,
    /// Triangles submitted per frame (every strip submits the scene).
    pub submitted: f64,
    /// Of them, skipped outside the frustum (whole objects).
    pub culled_object: f64,
    /// Of them, skipped as hidden (objects and parts), before transform.
    pub culled_occlusion: f64,
    /// Set up per frame without and with occlusion culling.
    pub stored: [f64; 2],
    /// Frame time without and with occlusion culling, ms: median over the
    /// rounds, then the range.
    pub frame_ms: [[f64; 3]; 2],
    /// Whether every camera's image and depth were identical (with
    /// occlusion, without, and the binned pipeline).
    pub identical: bool,
}

/// Measures [`crate::render::Occlusion::On`] against
/// [`crate::render::Occlusion::Strips`] on the `spots` scene (`grid`² Spots)
/// from `cameras` cameras ([`crate::bench_scenes::spots_camera`]), one
/// thread, `u16` depth, for each strip height in `rows`. Timing is
/// interleaved: each camera's scene is drawn A B A B ... `rounds` times;
/// a round's time is its sum over the cameras.
pub fn measure(
    grid: usize,
    cameras: usize,
    size: (u32, u32),
    rows: &[u32],
    rounds: usize,
) -> Result<Vec<OcclusionRow>, String> {
    use crate::render::{render, DepthKind, Occlusion, RenderOptions};
    let spots = crate::bench_scenes::SpotGrid::load()?;
    let (w, h) = size;
    let mut out = Vec::new();
    for &r in rows {
        let opts = |occlusion| RenderOptions {
            width: w,
            height: h,
            cull: microraster::CullMode::Back,
            detail: 0,
            depth: DepthKind::U16,
            subpixel: 8,
            threads: 1,
            strip_rows: r.min(h).max(1),
            tile_width: 0,
            ids: false,
            mode: microraster::RasterMode::Clipping,
            inv_w: false,
            occlusion,
        };
        let mut totals = vec![[0.0f64; 2]; rounds.max(1)];
        // Submitted, culled_object, culled_occlusion, stored without and with.
        let mut sums = [0.0f64; 5];
        let mut identical = true;
        for k in 0..cameras {
            let (eye, target) = crate::bench_scenes::spots_camera(k, cameras, grid);
            let scene = spots.scene(grid, eye, target, 60.0, w as f32 / h as f32, false)?;
            let base = render(&scene, &opts(Occlusion::Off))?;
            let mut stats = [base.stats; 2];
            for total in totals.iter_mut() {
                for (m, occ) in [Occlusion::Strips, Occlusion::On].into_iter().enumerate() {
                    let t = std::time::Instant::now();
                    let img = render(&scene, &opts(occ))?;
                    total[m] += t.elapsed().as_secs_f64() * 1e3;
                    identical &= img.rgb == base.rgb && img.depth == base.depth;
                    stats[m] = img.stats;
                }
            }
            let [a, b] = stats;
            sums[0] += b.submitted as f64;
            sums[1] += b.culled_object as f64;
            sums[2] += b.culled_occlusion as f64;
            sums[3] += a.stored as f64;
            sums[4] += b.stored as f64;
        }
        let n = cameras.max(1) as f64;
        let spread = |m: usize| {
            let mut v: Vec<f64> = totals.iter().map(|t| t[m] / n).collect();
            v.sort_by(f64::total_cmp);
            [v[v.len() / 2], v[0], v[v.len() - 1]]
        };
        out.push(OcclusionRow {
            rows: r.min(h),
            submitted: sums[0] / n,
            culled_object: sums[1] / n,
            culled_occlusion: sums[2] / n,
            stored: [sums[3] / n, sums[4] / n],
            frame_ms: [spread(0), spread(1)],
            identical,
        });
    }
    Ok(out)
}

/// The occlusion table as Markdown.
pub fn markdown(rows: &[OcclusionRow], grid: usize, cameras: usize, size: (u32, u32)) -> String {
    let mut t = format!(
        "### spots: {grid}x{grid} Spots, {cameras} cameras at eye height, {}x{}, 1 thread, u16 depth\n\n",
        size.0,
        size.1
    );
    t += "| strip rows | submitted / frame | outside frustum | hidden (occlusion) | set up, plain | set up, occlusion | frame ms, strips | frame ms, occlusion | speed-up | identical |\n";
    t += "|---:|---:|---:|---:|---:|---:|---:|---:|---:|:---:|\n";
    for r in rows {
        let pct = |v: f64| 100.0 * v / r.submitted.max(1.0);
        let ms = |m: [f64; 3]| format!("{:.2} ({:.2}-{:.2})", m[0], m[1], m[2]);
        t += &format!(
            "| {} | {:.0} | {:.1} % | {:.1} % | {:.0} | {:.0} | {} | {} | {:.2}x | {} |\n",
            r.rows,
            r.submitted,
            pct(r.culled_object),
            pct(r.culled_occlusion),
            r.stored[0],
            r.stored[1],
            ms(r.frame_ms[0]),
            ms(r.frame_ms[1]),
            r.frame_ms[0][0] / r.frame_ms[1][0],
            if r.identical { "yes" } else { "NO" }
        );
    }
    t
}
