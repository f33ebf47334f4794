//! Where the single-scattering integrand along a camera segment is not smooth, and which
//! spheres it depends on (MODEL.md section 3).
//!
//! For light `i`, points `x(t)` of the segment `[A, B]` send light rays towards the light: along
//! `L` for a directional light (they sweep a half-infinite strip), to the point `P` for a point
//! light (they sweep the triangle `A B P`). Only spheres that meet that region can shadow any
//! point of the segment: those are the **candidates** (found through the BVH with the region's
//! box, then kept if their distance to the region is at most their radius). The integrand
//! `E_i(x(t))` is smooth in `t` except where
//! - the light ray from `x(t)` becomes tangent to a candidate: the camera ray crosses its shadow
//!   boundary, a cylinder (directional light) or a cone with apex `P` (point light); the path
//!   length through the sphere behaves like a square root there;
//! - `x(t)` crosses a candidate's surface (its own chord changes form);
//! - `x(t)` crosses the point light's `radius` sphere (a jump).
//!
//! Those parameters are the **breakpoints**. Extra breakpoints cost a little work and never
//! accuracy, so the cylinder and cone roots are kept without deciding on which side of the
//! sphere the tangency lies.

use glam::{DAffine3, DVec3};

use super::lights::{LightKind, LightSource};
use crate::accel::{Prim, SphereBvh};
use crate::geom::sphere_roots;
use crate::scene::NO_ELLIPSOID;

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

/// Distance from `c` to the ray `a + s l`, `s >= 0` (`l` unit).
fn to_ray(c: DVec3, a: DVec3, l: DVec3) -> f64 {
    let s = (c - a).dot(l).max(0.0);
    (a + s * l - c).length()
}

/// Distance from `c` to the half-infinite strip `{a + u (b - a) + s l : u in [0,1], s >= 0}`.
fn to_strip(c: DVec3, a: DVec3, b: DVec3, l: DVec3) -> f64 {
    let dv = b - a;
    let w = c - a;
    // Unconstrained minimiser of |a + u dv + s l - c|^2 (l unit).
    let (dd, dl) = (dv.dot(dv), dv.dot(l));
    let det = dd - dl * dl;
    if det > 1e-12 * dd {
        let (wd, wl) = (w.dot(dv), w.dot(l));
        let u = (wd - dl * wl) / det;
        let s = (wl * dd - dl * wd) / det;
        if (0.0..=1.0).contains(&u) && s >= 0.0 {
            return (a + u * dv + s * l - c).length();
        }
    }
    // Otherwise the nearest point is on an edge.
    to_ray(c, a, l)
        .min(to_ray(c, b, l))
        .min(to_segment(c, a, b))
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

/// Where the ray `o + s l` leaves the box `lo..hi` (0 if it starts outside and misses).
fn exit_along(o: DVec3, l: DVec3, lo: DVec3, hi: DVec3) -> f64 {
    let mut s1 = f64::INFINITY;
    for k in 0..3 {
        if l[k] > 0.0 {
            s1 = s1.min((hi[k] - o[k]) / l[k]);
        } else if l[k] < 0.0 {
            s1 = s1.min((lo[k] - o[k]) / l[k]);
        }
    }
    s1.max(0.0)
}

/// Every primitive that the light rays from the segment `[a, b]` towards `light` can meet.
pub fn candidates(bvh: &SphereBvh, a: DVec3, b: DVec3, light: &LightSource, out: &mut Vec<u32>) {
    out.clear();
    let (lo, hi) = bvh.bounds();
    match light.kind {
        LightKind::Directional { to_light: l, .. } => {
            let (ea, eb) = (
                a + exit_along(a, l, lo, hi) * l,
                b + exit_along(b, l, lo, hi) * l,
            );
            let qlo = a.min(b).min(ea).min(eb);
            let qhi = a.max(b).max(ea).max(eb);
            bvh.overlapping(qlo, qhi, |i, p| {
                let r = p.radius * (1.0 + 1e-9);
                if to_strip(p.center, a, b, l) <= r {
                    out.push(i);
                }
            });
        }
        LightKind::Point { position, .. } => {
            let qlo = a.min(b).min(position).max(lo);
            let qhi = a.max(b).max(position).min(hi);
            if qlo.cmpgt(qhi).any() {
                return;
            }
            bvh.overlapping(qlo, qhi, |i, p| {
                let r = p.radius * (1.0 + 1e-9);
                if to_triangle(p.center, a, b, position) <= r {
                    out.push(i);
                }
            });
        }
    }
}

/// Roots of `qa t^2 + qb t + qc = 0` (stable form; a linear or empty equation handled).
fn quadratic(qa: f64, qb: f64, qc: f64, out: &mut Vec<f64>) {
    if qa == 0.0 {
        if qb != 0.0 {
            out.push(-qc / qb);
        }
        return;
    }
    let disc = qb * qb - 4.0 * qa * qc;
    if disc.is_nan() || disc < 0.0 {
        return;
    }
    let q = -0.5 * (qb + disc.sqrt().copysign(qb));
    out.push(q / qa);
    if q != 0.0 {
        out.push(qc / q);
    }
}

/// Appends to `out` the breakpoints in `(ta, tb)` that candidate `p` causes along `o + t d`
/// for `light`. Ellipsoids are handled in their object space (an affine map keeps `t`).
pub fn breakpoints(
    p: &Prim,
    to_object: &[DAffine3],
    o: DVec3,
    d: DVec3,
    light: &LightSource,
    (ta, tb): (f64, f64),
    out: &mut Vec<f64>,
) {
    let mut roots = Vec::new();
    // The sphere in its own frame: centre c, radius r; o, d, light mapped alike.
    let (m, c, r) = if p.ellipsoid == NO_ELLIPSOID {
        (None, p.center, p.radius)
    } else {
        (Some(&to_object[p.ellipsoid as usize]), DVec3::ZERO, 1.0)
    };
    let point = |x: DVec3| m.map_or(x, |m| m.transform_point3(x));
    let vector = |x: DVec3| m.map_or(x, |m| m.transform_vector3(x));
    let (o, d) = (point(o), vector(d));
    if let Some((t0, t1)) = sphere_roots(o, d, c, r) {
        roots.extend([t0, t1]);
    }
    match light.kind {
        LightKind::Directional { to_light, .. } => {
            // Cylinder around the axis through c along L: a circle in the plane normal to L.
            let l = vector(to_light).normalize();
            let perp = |v: DVec3| v - v.dot(l) * l;
            if let Some((t0, t1)) = sphere_roots(perp(o - c), perp(d), DVec3::ZERO, r) {
                roots.extend([t0, t1]);
            }
        }
        LightKind::Point { position, .. } => {
            // Cone with apex P tangent to the sphere: ((x-P).u)^2 = cos^2(alpha) |x-P|^2.
            let pp = point(position);
            let axis = c - pp;
            let dist2 = axis.length_squared();
            if dist2 > r * r {
                let u = axis / dist2.sqrt();
                let k = 1.0 - r * r / dist2;
                let g = o - pp;
                let (gu, du) = (g.dot(u), d.dot(u));
                quadratic(
                    du * du - k * d.dot(d),
                    2.0 * (gu * du - k * g.dot(d)),
                    gu * gu - k * g.dot(g),
                    &mut roots,
                );
            }
        }
    }
    out.extend(roots.into_iter().filter(|t| *t > ta && *t < tb));
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Distances against dense sampling of the regions.
    #[test]
    fn strip_and_triangle_distances_against_sampling() {
        let mut state = 99u64;
        let mut rnd = || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (state >> 11) as f64 / (1u64 << 53) as f64 * 4.0 - 2.0
        };
        for _ in 0..200 {
            let a = DVec3::new(rnd(), rnd(), rnd());
            let b = DVec3::new(rnd(), rnd(), rnd());
            let q = DVec3::new(rnd(), rnd(), rnd());
            let c = DVec3::new(rnd(), rnd(), rnd());
            let l = DVec3::new(rnd(), rnd(), rnd()).normalize();
            let (mut best_s, mut best_t) = (f64::INFINITY, f64::INFINITY);
            for i in 0..=200 {
                let u = i as f64 / 200.0;
                for j in 0..=400 {
                    let s = j as f64 / 40.0;
                    best_s = best_s.min((a + u * (b - a) + s * l - q).length());
                }
                for j in 0..=200 {
                    let v = j as f64 / 200.0 * (1.0 - u);
                    best_t = best_t.min((a + u * (b - a) + v * (c - a) - q).length());
                }
            }
            let ds = to_strip(q, a, b, l);
            let dt = to_triangle(q, a, b, c);
            assert!(
                ds <= best_s + 1e-12 && ds > best_s - 0.05,
                "strip {ds} vs {best_s}"
            );
            assert!(
                dt <= best_t + 1e-12 && dt > best_t - 0.05,
                "triangle {dt} vs {best_t}"
            );
        }
    }
}
