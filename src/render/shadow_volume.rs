//! The region of space that light rays from a piece of a camera ray sweep on their way to a
//! light, and the spheres that meet it (MODEL.md section 3).
//!
//! For light `i`, the points `x(t)` of the segment `[A, B]` send light rays towards the light:
//! along `L` for a directional light (they sweep a half-infinite strip), to the point `P` for a
//! point light (they sweep the triangle `A B P`). Only spheres that meet that region can shadow
//! any point of the segment: those are the segment's **shadowers**.
//!
//! The region is cut into **depth bands** along the light rays (distance `s` along `L`, or the
//! fraction `lambda` of the way to `P`), so that the far bands need only be searched for the
//! parts of the segment that the near ones leave lit (`render::light_pieces`). A band is a
//! convex planar quadrilateral; the BVH is searched with the exact distance of each node's
//! bounding ball to it (`SphereBvh::near_region`), so the nodes visited are those near the
//! quadrilateral, not those in an axis-aligned box around it (for a diagonal light, a large part
//! of the scene).

use glam::{DVec3, UVec2};

use super::lights::LightKind;
use crate::accel::SphereBvh;
/// Distance from `c` to the segment `[a, b]`.
fn to_segment(c: DVec3, a: DVec3, b: DVec3) -> f64 {
    let ab = b - a;
    let len2 = ab.length_squared();
    let u = if len2 > 0.0 {
        ((c - a).dot(ab) / len2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (a + u * ab - c).length()
}

/// Distance from `p` to the triangle `a b c` (Ericson, Real-Time Collision Detection 5.1.5).
fn to_triangle(p: DVec3, a: DVec3, b: DVec3, c: DVec3) -> f64 {
    let (ab, ac, ap) = (b - a, c - a, p - a);
    let (d1, d2) = (ab.dot(ap), ac.dot(ap));
    if d1 <= 0.0 && d2 <= 0.0 {
        return ap.length();
    }
    let bp = p - b;
    let (d3, d4) = (ab.dot(bp), ac.dot(bp));
    if d3 >= 0.0 && d4 <= d3 {
        return bp.length();
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        return to_segment(p, a, b);
    }
    let cp = p - c;
    let (d5, d6) = (ab.dot(cp), ac.dot(cp));
    if d6 >= 0.0 && d5 <= d6 {
        return cp.length();
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        return to_segment(p, a, c);
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        return to_segment(p, b, c);
    }
    let denom = va + vb + vc;
    if denom == 0.0 || denom.is_nan() {
        // Degenerate triangle: its edges.
        return to_segment(p, a, b)
            .min(to_segment(p, a, c))
            .min(to_segment(p, b, c));
    }
    let v = vb / denom;
    let w = vc / denom;
    (a + ab * v + ac * w - p).length()
}

/// A convex planar quadrilateral `q0 q1 q2 q3` (a triangle when two corners coincide), one
/// depth band of a shadow region.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Region {
    pub q: [DVec3; 4],
    /// Unit normal of its plane (zero when degenerate) and the plane's offset `n . q0`.
    normal: DVec3,
    offset: f64,
    /// A ball around it: centre and radius.
    centre: DVec3,
    reach: f64,
    /// In its plane, the inward unit normals of its four edges and their offsets: a point `y`
    /// of the plane is inside when `e_k . y >= o_k` for every edge (unused when degenerate).
    edges: [(DVec3, f64); 4],
}

impl Region {
    pub fn new(q: [DVec3; 4]) -> Region {
        let n = (q[1] - q[0]).cross(q[3] - q[0]) + (q[3] - q[2]).cross(q[1] - q[2]);
        let scale = q
            .iter()
            .map(|v| (*v - q[0]).length_squared())
            .fold(0.0, f64::max);
        // Below this the plane is not well defined (a zero-length segment, or rays along it).
        let normal = if n.length_squared() > 1e-20 * scale * scale {
            n.normalize()
        } else {
            DVec3::ZERO
        };
        let centre = (q[0] + q[1] + q[2] + q[3]) * 0.25;
        let reach = q.iter().map(|v| (*v - centre).length()).fold(0.0, f64::max);
        let mut edges = [(DVec3::ZERO, f64::NEG_INFINITY); 4];
        // (A skipped edge keeps (0, -inf): no constraint.)
        if normal != DVec3::ZERO {
            for (k, e) in edges.iter_mut().enumerate() {
                let (a, b) = (q[k], q[(k + 1) % 4]);
                // An edge of (nearly) zero length, such as the apex of a band that reaches a
                // point light (two corners equal up to rounding), has no direction: no plane.
                if (b - a).length_squared() <= 1e-20 * scale {
                    continue;
                }
                let inward = normal.cross(b - a).normalize_or_zero();
                // Orient it towards the centre (the quad's corners are in either order).
                let inward = if inward.dot(centre - a) < 0.0 {
                    -inward
                } else {
                    inward
                };
                *e = (inward, inward.dot(a));
            }
        }
        Region {
            q,
            normal,
            offset: normal.dot(q[0]),
            centre,
            reach,
            edges,
        }
    }

    /// The band `[f0, f1]` of the region swept from the segment `[a, b]` towards `light`: `f`
    /// is the distance along `L` (directional) or the fraction of the way to `P` (point).
    pub fn band(light: &LightKind, a: DVec3, b: DVec3, f0: f64, f1: f64) -> Region {
        Region::new(match *light {
            LightKind::Directional { to_light: l, .. } => {
                [a + f0 * l, b + f0 * l, b + f1 * l, a + f1 * l]
            }
            LightKind::Point { position: p, .. } => [
                a + f0 * (p - a),
                b + f0 * (p - b),
                b + f1 * (p - b),
                a + f1 * (p - a),
            ],
        })
    }

    /// Distance from `p` to the region (split along the diagonal `q0 q2` into two triangles).
    #[inline]
    pub fn distance(&self, p: DVec3) -> f64 {
        let [q0, q1, q2, q3] = self.q;
        to_triangle(p, q0, q1, q2).min(to_triangle(p, q0, q2, q3))
    }

    /// Whether the ball `(c, r)` meets the region (exactly, up to rounding).
    #[inline]
    pub fn meets(&self, c: DVec3, r: f64) -> bool {
        self.may_meet(c, r) && self.distance(c) <= r
    }

    /// Whether the ball `(c, r)` may meet the region, from lower bounds of the distance only
    /// (so never false for a ball that meets it): the distance to its plane, to a ball around
    /// it, and, in the plane, the largest violation of the edges' half-planes (a convex
    /// polygon is at least that far from a point).
    #[inline]
    pub fn may_meet(&self, c: DVec3, r: f64) -> bool {
        let above = self.normal.dot(c) - self.offset;
        if above.abs() > r {
            return false;
        }
        if (c - self.centre).length_squared() > (r + self.reach) * (r + self.reach) {
            return false;
        }
        let mut out = 0.0f64;
        for &(e, o) in &self.edges {
            out = out.max(o - e.dot(c));
        }
        above * above + out * out <= r * r
    }

    /// Whether the box `lo..hi` (grown by `slack`) may meet the region: false only when a
    /// plane separates them, among its own plane, the four planes through its edges along
    /// its normal, and the box's faces (the box against a ball around the region).
    #[inline]
    pub fn may_meet_box(&self, lo: DVec3, hi: DVec3, slack: f64) -> bool {
        let c = (lo + hi) * 0.5;
        let e = (hi - lo) * 0.5 + slack;
        // The box's extent along a unit axis n, either side of its centre: sum |n_i| e_i.
        if (self.normal.dot(c) - self.offset).abs() > self.normal.abs().dot(e) {
            return false;
        }
        let gap = ((self.centre - c).abs() - e).max(DVec3::ZERO);
        if gap.length_squared() > self.reach * self.reach {
            return false;
        }
        for &(n, o) in &self.edges {
            if n.dot(c) + n.abs().dot(e) < o {
                return false;
            }
        }
        true
    }
}

/// The band edges along the light rays from the segment `[a, b]`: `0 = f_0 < f_1 < ... = end`,
/// where `end` lies beyond every sphere (directional: the farthest corner of the scene's box
/// along `L`; point: the light, `1`), and `f_1 = base`, then eight times deeper each band (fewer bands cost fewer BVH descents; deeper
/// ones gather more spheres that turn out to lie behind dark pieces).
pub fn band_edges(
    bvh: &SphereBvh,
    light: &LightKind,
    a: DVec3,
    b: DVec3,
    base: f64,
    out: &mut Vec<f64>,
) {
    out.clear();
    out.push(0.0);
    let (end, step) = match *light {
        LightKind::Directional { to_light: l, .. } => {
            // Every box point y reached as x + s L has s = (y - x).L, at most the largest over
            // the corners, which is affine in x and so largest at a or b.
            let (lo, hi) = bvh.bounds();
            let mut end = 0.0f64;
            for k in 0..8 {
                let corner = DVec3::new(
                    if k & 1 == 0 { lo.x } else { hi.x },
                    if k & 2 == 0 { lo.y } else { hi.y },
                    if k & 4 == 0 { lo.z } else { hi.z },
                );
                end = end.max((corner - a).dot(l)).max((corner - b).dot(l));
            }
            (end, base)
        }
        LightKind::Point { position: p, .. } => {
            let near = (p - a).length().min((p - b).length());
            (1.0, if near > 0.0 { base / near } else { 1.0 })
        }
    };
    let mut f = step;
    while f.is_finite() && f > 0.0 && f < end {
        out.push(f);
        f *= 8.0;
    }
    out.push(end.max(0.0));
}

/// Appends to `out` every primitive that meets `region`.
pub fn gather(bvh: &SphereBvh, region: &Region, out: &mut Vec<u32>, stack: &mut Vec<UVec2>) {
    // Rounding of the distance: a few ulps of the coordinates involved.
    let slack = {
        let (lo, hi) = bvh.bounds();
        let big = lo.abs().max(hi.abs()).max_element();
        let q = region
            .q
            .iter()
            .fold(big, |m, v| m.max(v.abs().max_element()));
        64.0 * f64::EPSILON * q
    };
    bvh.near_region(
        |lo, hi| region.may_meet_box(lo, hi, slack),
        |i, p| {
            if region.meets(p.center, p.radius * (1.0 + 1e-9) + slack) {
                out.push(i);
            }
        },
        stack,
    );
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Distances against dense sampling of the regions.
    #[test]
    fn band_and_triangle_distances_against_sampling() {
        let mut state = 99u64;
        let mut rnd = || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (state >> 11) as f64 / (1u64 << 53) as f64 * 4.0 - 2.0
        };
        for k in 0..200 {
            let a = DVec3::new(rnd(), rnd(), rnd());
            let b = DVec3::new(rnd(), rnd(), rnd());
            let q = DVec3::new(rnd(), rnd(), rnd());
            let c = DVec3::new(rnd(), rnd(), rnd());
            let l = DVec3::new(rnd(), rnd(), rnd()).normalize();
            let (f0, f1) = (0.25 * (rnd() + 2.0), 2.0 + rnd() + 2.0);
            let light = if k % 2 == 0 {
                LightKind::Directional {
                    to_light: l,
                    scope: (0, u32::MAX),
                }
            } else {
                LightKind::Point {
                    position: c,
                    attenuation: DVec3::X,
                    radius: 100.0,
                }
            };
            let (f0, f1) = if k % 2 == 0 {
                (f0, f1)
            } else {
                (f0 * 0.25, (f1 * 0.25).min(1.0))
            };
            let band = Region::band(&light, a, b, f0, f1);
            let (mut best_b, mut best_t) = (f64::INFINITY, f64::INFINITY);
            for i in 0..=200 {
                let u = i as f64 / 200.0;
                let x = a + u * (b - a);
                for j in 0..=200 {
                    let f = f0 + (f1 - f0) * j as f64 / 200.0;
                    let y = match light {
                        LightKind::Directional { .. } => x + f * l,
                        LightKind::Point { .. } => x + f * (c - x),
                    };
                    best_b = best_b.min((y - q).length());
                    let v = j as f64 / 200.0 * (1.0 - u);
                    best_t = best_t.min((a + u * (b - a) + v * (c - a) - q).length());
                }
            }
            let db = band.distance(q);
            let dt = to_triangle(q, a, b, c);
            // The cheap tests never reject a ball, or a box around it, that meets the band.
            for r in [0.5 * db, db * (1.0 + 1e-9) + 1e-12, 1.5 * db, db + 1.0] {
                assert_eq!(band.meets(q, r), db <= r, "meets at r {r}, distance {db}");
                assert!(
                    band.may_meet(q, r) || db > r,
                    "may_meet at r {r}, distance {db}"
                );
                let h = DVec3::new(r, 1.5 * r, 2.0 * r); // contains the ball
                assert!(
                    band.may_meet_box(q - h, q + h, 1e-12) || db > r,
                    "may_meet_box at r {r}, distance {db}"
                );
            }
            assert!(
                db <= best_b + 1e-12 && db > best_b - 0.05,
                "band {db} vs {best_b}"
            );
            assert!(
                dt <= best_t + 1e-12 && dt > best_t - 0.05,
                "triangle {dt} vs {best_t}"
            );
        }
    }
}
