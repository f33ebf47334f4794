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
}

impl Region {
    /// The band `[f0, f1]` of the region swept from the segment `[a, b]` towards `light`: `f`
    /// is the distance along `L` (directional) or the fraction of the way to `P` (point).
    pub fn band(light: &LightKind, a: DVec3, b: DVec3, f0: f64, f1: f64) -> Region {
        match *light {
            LightKind::Directional { to_light: l, .. } => Region {
                q: [a + f0 * l, b + f0 * l, b + f1 * l, a + f1 * l],
            },
            LightKind::Point { position: p, .. } => Region {
                q: [a + f0 * (p - a), b + f0 * (p - b), b + f1 * (p - b), a + f1 * (p - a)],
            },
        }
    }

    /// Distance from `p` to the region (split along the diagonal `q0 q2` into two triangles).
    #[inline]
    pub fn distance(&self, p: DVec3) -> f64 {
        let [q0, q1, q2, q3] = self.q;
        to_triangle(p, q0, q1, q2).min(to_triangle(p, q0, q2, q3))
    }
}

/// The band edges along the light rays from the segment `[a, b]`: `0 = f_0 < f_1 < ... = end`,
/// where `end` lies beyond every sphere (directional: the farthest corner of the scene's box
/// along `L`; point: the light, `1`), and `f_1 = base`, then four times deeper each band.
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
        f *= 4.0;
    }
    out.push(end.max(0.0));
}

/// Appends to `out` every primitive that meets `region`.
pub fn gather(bvh: &SphereBvh, region: &Region, out: &mut Vec<u32>, stack: &mut Vec<UVec2>) {
    // Rounding of the distance: a few ulps of the coordinates involved.
    let slack = {
        let (lo, hi) = bvh.bounds();
        let big = lo.abs().max(hi.abs()).max_element();
        let q = region.q.iter().fold(big, |m, v| m.max(v.abs().max_element()));
        64.0 * f64::EPSILON * q
    };
    bvh.near_region(
        |c, r| region.distance(c) <= r + slack,
        |i, p| {
            if region.distance(p.center) <= p.radius * (1.0 + 1e-9) + slack {
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
