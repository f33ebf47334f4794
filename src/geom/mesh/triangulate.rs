//! Polygons to triangles: a fan for triangles and convex quads, ear clipping in the plane of
//! the Newell normal otherwise.

use glam::{DVec2, DVec3};

/// The Newell normal of `polygon` (indices into `points`): `sum (p_i - p_0) x (p_i+1 - p_0)`,
/// twice the polygon's vector area, not normalised; it points where the polygon turns
/// counter-clockwise. Zero for fewer than 3 corners or an index out of range.
pub fn newell_normal(points: &[DVec3], polygon: &[u32]) -> DVec3 {
    if polygon.len() < 3 || polygon.iter().any(|&i| i as usize >= points.len()) {
        return DVec3::ZERO;
    }
    let o = points[polygon[0] as usize];
    let mut prev = DVec3::ZERO;
    let mut n = DVec3::ZERO;
    for &i in &polygon[1..] {
        let q = points[i as usize] - o;
        n += prev.cross(q);
        prev = q;
    }
    n
}

/// The Newell normal of `polygon` and its extent (largest coordinate offset from the first
/// corner), or `None` when the area is zero up to rounding, a point is not finite or an index
/// is out of range (as [`triangulate`] and [`super::crease_normals`] decide zero area).
pub(crate) fn area_normal(points: &[DVec3], polygon: &[u32]) -> Option<(DVec3, f64)> {
    let n = polygon.len();
    if n < 3 || polygon.iter().any(|&i| i as usize >= points.len()) {
        return None;
    }
    let o = points[polygon[0] as usize];
    let mut extent = 0.0f64;
    for &i in polygon {
        let d = points[i as usize] - o;
        if !d.is_finite() {
            return None;
        }
        extent = extent.max(d.abs().max_element());
    }
    let normal = newell_normal(points, polygon);
    // Each cross product is off by a few eps extent^2; n of them are summed.
    let noise = 8.0 * n as f64 * f64::EPSILON * extent * extent;
    (normal.is_finite() && normal.length() > noise).then_some((normal, extent))
}

/// Appends triangles covering `polygon` (indices into `points`) to `out` and returns how
/// many. Triangle corners are positions in `polygon` (`0..polygon.len()`), so a caller can
/// look up per-corner data. Every triangle turns as the polygon does (its normal along
/// [`newell_normal`]).
///
/// - A triangle gives itself; a strictly convex quad the fan `[0, 1, 2], [0, 2, 3]`.
/// - Otherwise, ears are clipped in the plane of the Newell normal (each ear tested against
///   the reflex corners near it; O(n^2) at worst). A corner whose neighbours are collinear with it (a repeated vertex, a
///   straight corner, a spike) is removed without a triangle, so such polygons give fewer
///   than `n - 2`. If no ear can be found (a self-intersecting polygon), the most convex
///   corner is clipped anyway; no triangle of the opposite orientation is ever emitted.
/// - Zero area (the Newell normal within rounding of 0), fewer than 3 corners, an index out
///   of range or a non-finite point: no triangles.
pub fn triangulate(points: &[DVec3], polygon: &[u32], out: &mut Vec<[u32; 3]>) -> usize {
    let Some((normal, extent)) = area_normal(points, polygon) else {
        return 0;
    };
    let n = polygon.len();
    let p = |k: usize| points[polygon[k] as usize];
    let o = p(0);
    if n == 3 {
        out.push([0, 1, 2]);
        return 1;
    }
    if n == 4 {
        let convex = (0..4).all(|k| {
            let (a, b, c) = (p((k + 3) % 4), p(k), p((k + 1) % 4));
            (b - a).cross(c - b).dot(normal) > 0.0
        });
        if convex {
            out.extend([[0, 1, 2], [0, 2, 3]]);
            return 2;
        }
    }
    // Coordinates in the plane: e1 x e2 = the unit normal, so the polygon turns positively.
    let w = normal.normalize();
    let e1 = w.any_orthonormal_vector();
    let e2 = w.cross(e1);
    let q: Vec<DVec2> = (0..n)
        .map(|k| {
            let d = p(k) - o;
            DVec2::new(d.dot(e1), d.dot(e2))
        })
        .collect();
    ear_clip(&q, extent, out)
}

/// Ear clipping of the positively turning polygon `q` (see [`triangulate`]).
///
/// Only a corner that is not strictly convex (reflex, or straight within rounding) can lie in
/// an ear of a simple polygon without one such corner lying in it too, so an ear is tested
/// against those alone, found through a grid ([`Reflex`]; a clipped ear's neighbours may turn
/// convex, no corner turns reflex). Polygons of 100 000 corners written with six decimals
/// (`gtsphere info`): a circle 13.0 s testing every remaining corner, 6.0 s testing the
/// reflex ones from a list, 2.8 s through the grid; a star of alternating radii 8.4, 5.0 and
/// 2.5 s. What is left is quadratic: clipping grows fans whose triangles cover much of the
/// polygon while many reflex corners remain.
fn ear_clip(q: &[DVec2], extent: f64, out: &mut Vec<[u32; 3]>) -> usize {
    let n = q.len();
    let mut next: Vec<usize> = (1..=n).map(|k| k % n).collect();
    let mut prev: Vec<usize> = (0..n).map(|k| (k + n - 1) % n).collect();
    let turn = |a: usize, b: usize, c: usize| (q[b] - q[a]).perp_dot(q[c] - q[b]);
    // A turn this small is rounding: the corner is straight (or a spike, or repeated).
    let straight = |a: usize, b: usize, c: usize| {
        let t = turn(a, b, c);
        t.abs() <= 8.0 * f64::EPSILON * extent * ((q[b] - q[a]).length() + (q[c] - q[b]).length())
    };
    let not_convex = |a: usize, b: usize, c: usize| turn(a, b, c) <= 0.0 || straight(a, b, c);
    let mut reflex = Reflex::new(
        q,
        (0..n)
            .filter(|&k| not_convex(prev[k], k, next[k]))
            .collect(),
    );
    let mut emitted = 0;
    let mut left = n;
    let mut cur = 0;
    'clip: while left > 3 {
        let mut i = cur;
        let corners = left;
        for _ in 0..corners {
            let (a, c) = (prev[i], next[i]);
            let ear = straight(a, i, c) || (turn(a, i, c) > 0.0 && !reflex.blocks(q, a, i, c));
            if ear {
                if !straight(a, i, c) {
                    out.push([a as u32, i as u32, c as u32]);
                    emitted += 1;
                }
                next[a] = c;
                prev[c] = a;
                reflex.leave(i);
                // Its neighbours may have turned convex: they leave the grid.
                for v in [a, c] {
                    if !not_convex(prev[v], v, next[v]) {
                        reflex.leave(v);
                    }
                }
                left -= 1;
                cur = a;
                continue 'clip;
            }
            i = c;
        }
        // No ear (self-intersection or rounding): clip the most convex corner, if any.
        let (mut best, mut best_turn) = (usize::MAX, 0.0);
        for _ in 0..left {
            let t = turn(prev[i], i, next[i]);
            if t > best_turn {
                (best, best_turn) = (i, t);
            }
            i = next[i];
        }
        if best == usize::MAX {
            return emitted;
        }
        let (a, c) = (prev[best], next[best]);
        out.push([a as u32, best as u32, c as u32]);
        emitted += 1;
        next[a] = c;
        prev[c] = a;
        reflex.leave(best);
        left -= 1;
        cur = a;
    }
    let (a, b, c) = (prev[cur], cur, next[cur]);
    if !straight(a, b, c) && turn(a, b, c) > 0.0 {
        out.push([a as u32, b as u32, c as u32]);
        emitted += 1;
    }
    emitted
}

/// The corners not strictly convex when clipping began, in a uniform grid of about one
/// per cell (so that an ear, a small triangle, meets a few), and which have left: clipped,
/// or turned convex.
struct Reflex {
    /// Every one of them not yet clipped (pruned as it is scanned), for triangles that cover
    /// more cells than it holds corners.
    live: Vec<u32>,
    cells: Vec<Vec<u32>>,
    side: usize,
    lo: DVec2,
    per_unit: DVec2,
    /// By corner: in the grid and not left.
    member: Vec<bool>,
    /// How many are.
    count: usize,
}

impl Reflex {
    fn new(q: &[DVec2], corners: Vec<usize>) -> Reflex {
        let side = ((corners.len() as f64).sqrt().ceil() as usize).clamp(1, 1024);
        let (lo, hi) = corners.iter().fold(
            (DVec2::splat(f64::INFINITY), DVec2::splat(f64::NEG_INFINITY)),
            |(lo, hi), &k| (lo.min(q[k]), hi.max(q[k])),
        );
        let span = (hi - lo).max(DVec2::splat(f64::MIN_POSITIVE));
        let mut reflex = Reflex {
            live: corners.iter().map(|&k| k as u32).collect(),
            cells: vec![Vec::new(); side * side],
            side,
            lo,
            per_unit: DVec2::splat(side as f64) / span,
            member: vec![false; q.len()],
            count: corners.len(),
        };
        for k in corners {
            let (i, j) = reflex.cell(q[k]);
            reflex.cells[j * side + i].push(k as u32);
            reflex.member[k] = true;
        }
        reflex
    }

    /// Corner `k` leaves (clipped, or turned convex); its entries go when next met.
    fn leave(&mut self, k: usize) {
        if std::mem::take(&mut self.member[k]) {
            self.count -= 1;
        }
    }

    /// The cell holding `x` (clamped to the grid).
    fn cell(&self, x: DVec2) -> (usize, usize) {
        let c = ((x - self.lo) * self.per_unit).floor();
        let max = (self.side - 1) as f64;
        (c.x.clamp(0.0, max) as usize, c.y.clamp(0.0, max) as usize)
    }

    /// Whether a remaining corner of the grid other than `a`, `b`, `c` lies in or on the
    /// triangle `a b c` (positively turning); corners at the same position as one of the
    /// three do not count.
    fn blocks(&mut self, q: &[DVec2], a: usize, b: usize, c: usize) -> bool {
        let (qa, qb, qc) = (q[a], q[b], q[c]);
        let lo = qa.min(qb).min(qc);
        let hi = qa.max(qb).max(qc);
        let inside = |k: u32| {
            let (k, x) = (k as usize, q[k as usize]);
            k != a
                && k != b
                && k != c
                && x.cmpge(lo).all()
                && x.cmple(hi).all()
                && x != qa
                && x != qb
                && x != qc
                && (qb - qa).perp_dot(x - qa) >= 0.0
                && (qc - qb).perp_dot(x - qb) >= 0.0
                && (qa - qc).perp_dot(x - qc) >= 0.0
        };
        let ((i0, j0), (i1, j1)) = (self.cell(lo), self.cell(hi));
        let member = &self.member;
        if (i1 - i0 + 1) * (j1 - j0 + 1) > self.count {
            self.live.retain(|&k| member[k as usize]);
            return self.live.iter().any(|&k| inside(k));
        }
        for j in j0..=j1 {
            for i in i0..=i1 {
                let cell = &mut self.cells[j * self.side + i];
                cell.retain(|&k| member[k as usize]);
                if cell.iter().any(|&k| inside(k)) {
                    return true;
                }
            }
        }
        false
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::testing::Rng;
    use std::f64::consts::TAU;

    /// A random orthonormal frame (e1, e2, e1 x e2).
    fn frame(rng: &mut Rng) -> (DVec3, DVec3, DVec3) {
        let v = DVec3::new(
            rng.range(-1.0, 1.0),
            rng.range(-1.0, 1.0),
            rng.range(-1.0, 1.0),
        );
        let w = v.normalize();
        let e1 = w.any_orthonormal_vector();
        let e1 = (e1 * rng.range(-1.0, 1.0) + w.cross(e1) * rng.range(-1.0, 1.0)).normalize();
        (e1, w.cross(e1), w)
    }

    fn shoelace(q: &[DVec2]) -> f64 {
        (0..q.len())
            .map(|i| q[i].perp_dot(q[(i + 1) % q.len()]))
            .sum::<f64>()
            / 2.0
    }

    /// Winding number of `q` around `x`, nonzero inside.
    fn inside(q: &[DVec2], x: DVec2) -> bool {
        let mut w = 0;
        for i in 0..q.len() {
            let (a, b) = (q[i], q[(i + 1) % q.len()]);
            let side = (b - a).perp_dot(x - a);
            if a.y <= x.y && b.y > x.y && side > 0.0 {
                w += 1;
            } else if a.y > x.y && b.y <= x.y && side < 0.0 {
                w -= 1;
            }
        }
        w != 0
    }

    #[test]
    fn random_star_polygons() {
        let mut rng = Rng::new(0x7a1);
        let mut out = Vec::new();
        let mut tested = [0; 2];
        for case in 0..4000 {
            let n = 3 + rng.below(48);
            let convex = case % 3 == 0;
            // Star-shaped about 0: increasing angles, radius 1 (convex) or random (concave).
            let mut ang: Vec<f64> = (0..n).map(|_| rng.range(0.0, TAU)).collect();
            ang.sort_by(f64::total_cmp);
            // Simple only if 0 is inside: every angular gap below pi.
            let wrap = ang[0] + TAU - ang[n - 1];
            if ang.windows(2).any(|w| w[1] - w[0] > 3.0) || wrap > 3.0 {
                continue;
            }
            if case % 2 == 1 {
                ang.reverse(); // clockwise
            }
            let q: Vec<DVec2> = ang
                .iter()
                .map(|&a| {
                    let r = if convex { 1.0 } else { rng.range(0.1, 1.0) };
                    r * DVec2::new(a.cos(), a.sin())
                })
                .collect();
            let area = shoelace(&q);
            let scale = rng.log10(-3.0, 3.0);
            let (e1, e2, w) = frame(&mut rng);
            let o = scale
                * DVec3::new(
                    rng.range(-5.0, 5.0),
                    rng.range(-5.0, 5.0),
                    rng.range(-5.0, 5.0),
                );
            let points: Vec<DVec3> = q
                .iter()
                .map(|p| o + scale * (p.x * e1 + p.y * e2))
                .collect();
            // Points in a random order, the polygon through them.
            let mut perm: Vec<u32> = (0..n as u32).collect();
            crate::geom::mesh::tests_support::shuffle(&mut rng, &mut perm);
            let mut shuffled = vec![DVec3::ZERO; n];
            for (k, &i) in perm.iter().enumerate() {
                shuffled[i as usize] = points[k];
            }
            let polygon = perm.clone();

            let nn = newell_normal(&shuffled, &polygon);
            let want_n = 2.0 * area * scale * scale * w;
            assert!(
                (nn - want_n).length() <= 1e-12 * want_n.length(),
                "{nn} {want_n}"
            );

            out.clear();
            let count = triangulate(&shuffled, &polygon, &mut out);
            assert_eq!((count, out.len()), (n - 2, n - 2), "case {case}");
            tested[convex as usize] += 1;
            let mut total = 0.0;
            for t in &out {
                assert!(t.iter().all(|&k| (k as usize) < n));
                let [a, b, c] = t.map(|k| points[k as usize]);
                let cr = (b - a).cross(c - a);
                // Same orientation as the polygon: along +w for counter-clockwise.
                assert!(cr.dot(w) * area.signum() > 0.0, "case {case}: {t:?}");
                total += cr.length() / 2.0;
                let [a, b, c] = t.map(|k| q[k as usize]);
                assert!(
                    inside(&q, (a + b + c) / 3.0),
                    "case {case}: centroid outside"
                );
            }
            let want = area.abs() * scale * scale;
            assert!(
                (total - want).abs() <= 1e-12 * want,
                "case {case}: {total} vs {want}"
            );
        }
        assert!(tested[0] > 1500 && tested[1] > 800, "{tested:?}");
    }

    fn tri(points: &[DVec3], polygon: &[u32]) -> (Vec<[u32; 3]>, f64) {
        let mut out = vec![[7, 7, 7]];
        let count = triangulate(points, polygon, &mut out);
        assert_eq!(out.remove(0), [7, 7, 7], "appends");
        assert_eq!(count, out.len());
        let normal = newell_normal(points, polygon);
        let mut area = 0.0;
        for t in &out {
            let [a, b, c] = t.map(|k| points[polygon[k as usize] as usize]);
            let cr = (b - a).cross(c - a);
            assert!(cr.dot(normal) > 0.0, "{t:?} against {normal}");
            area += cr.length() / 2.0;
        }
        (out, area)
    }

    const NONE: &[[u32; 3]] = &[];

    fn xy(v: &[(f64, f64)]) -> Vec<DVec3> {
        v.iter().map(|&(x, y)| DVec3::new(x, y, 0.0)).collect()
    }

    #[test]
    fn special_polygons() {
        let square = xy(&[(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)]);
        assert_eq!(
            tri(&square, &[0, 1, 2, 3]),
            (vec![[0, 1, 2], [0, 2, 3]], 1.0)
        );
        // Concave quad (a dart): the reflex corner 3 must be a fan's centre.
        let dart = xy(&[(0.0, 0.0), (2.0, 1.0), (0.0, 2.0), (0.5, 1.0)]);
        let (t, a) = tri(&dart, &[0, 1, 2, 3]);
        assert_eq!((t.len(), a), (2, 1.5));
        // Square with its edge midpoints: straight corners give no triangles of their own.
        let mids = xy(&[
            (0.0, 0.0),
            (0.5, 0.0),
            (1.0, 0.0),
            (1.0, 0.5),
            (1.0, 1.0),
            (0.5, 1.0),
            (0.0, 1.0),
            (0.0, 0.5),
        ]);
        let (t, a) = tri(&mids, &[0, 1, 2, 3, 4, 5, 6, 7]);
        assert!(t.len() <= 6 && (a - 1.0).abs() < 1e-15, "{t:?} {a}");
        // Collinear quad (a triangle with a vertex on an edge).
        let (t, a) = tri(&mids, &[0, 1, 2, 4]);
        assert!(t.len() <= 2 && (a - 0.5).abs() < 1e-15, "{t:?} {a}");
        // Repeated vertices, consecutive and not.
        let (t, a) = tri(&square, &[0, 0, 1, 2, 2, 3, 0]);
        assert!(t.len() <= 5 && (a - 1.0).abs() < 1e-15, "{t:?} {a}");
        // Two squares touching at a corner (a bow-tie of one outline, not crossing).
        let two = xy(&[
            (0.0, 0.0),
            (1.0, 0.0),
            (1.0, 1.0),
            (2.0, 1.0),
            (2.0, 2.0),
            (1.0, 2.0),
            (1.0, 1.0),
            (0.0, 1.0),
        ]);
        let (t, a) = tri(&two, &[0, 1, 2, 3, 4, 5, 6, 7]);
        assert!(t.len() <= 6 && (a - 2.0).abs() < 1e-15, "{t:?} {a}");
        // Zero area: collinear, one point, a there-and-back path, a crossing figure eight.
        let line = xy(&[(0.0, 0.0), (1.0, 0.0), (2.0, 0.0), (3.0, 0.0)]);
        assert_eq!(tri(&line, &[0, 1, 2, 3]).0, NONE);
        assert_eq!(tri(&line, &[0, 2, 1]).0, NONE);
        assert_eq!(tri(&line, &[1, 1, 1, 1, 1]).0, NONE);
        assert_eq!(tri(&line, &[0, 3, 0, 3]).0, NONE);
        let eight = xy(&[(0.0, 0.0), (1.0, 1.0), (1.0, 0.0), (0.0, 1.0)]);
        assert_eq!(tri(&eight, &[0, 1, 2, 3]).0, NONE);
        // A crossing polygon with net area: triangles, all of its orientation, no panic.
        let crossed = xy(&[(0.0, 0.0), (3.0, 0.0), (3.0, 2.0), (1.0, -1.0), (0.0, 2.0)]);
        tri(&crossed, &[0, 1, 2, 3, 4]);
        // Bad input.
        assert_eq!(tri(&square, &[]).0, NONE);
        assert_eq!(tri(&square, &[0, 1]).0, NONE);
        assert_eq!(tri(&square, &[0, 1, 9]).0, NONE);
        assert_eq!(newell_normal(&square, &[0, 1, 9]), DVec3::ZERO);
        let mut bad = square.clone();
        bad[2].x = f64::NAN;
        assert_eq!(tri(&bad, &[0, 1, 2, 3]).0, NONE);
        bad[2].x = f64::INFINITY;
        assert_eq!(tri(&bad, &[0, 1, 2]).0, NONE);
    }

    #[test]
    fn random_degenerate_polygons_do_not_panic() {
        // Points on a few lattice lines: many collinear and repeated vertices.
        let mut rng = Rng::new(3);
        let mut out = Vec::new();
        for _ in 0..3000 {
            let n = 3 + rng.below(20);
            let pts: Vec<DVec3> = (0..n)
                .map(|_| DVec3::new(rng.below(3) as f64, rng.below(3) as f64, 0.0))
                .collect();
            let polygon: Vec<u32> = (0..n as u32).collect();
            out.clear();
            let count = triangulate(&pts, &polygon, &mut out);
            assert!(count <= n - 2);
            let normal = newell_normal(&pts, &polygon);
            for t in &out {
                let [a, b, c] = t.map(|k| pts[k as usize]);
                assert!((b - a).cross(c - a).dot(normal) > 0.0);
            }
        }
    }
}
