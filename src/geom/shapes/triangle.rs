//! Watertight ray/triangle intersection after Woop, Benthin and Wald, "Watertight
//! Ray/Triangle Intersection" (JCGT 2(1), 2013), in f64.
//!
//! The ray is turned into the +z axis of a sheared frame: the largest component of `d` is
//! the z axis (`kz`), and the vertices, taken relative to `o`, are sheared so that `d` becomes
//! `(0, 0, 1)`. The hit test is then 2D: is the origin inside the projected triangle? The
//! three edge functions `U, V, W` are 2x2 determinants of the sheared vertices. A vertex's
//! sheared coordinates depend only on the vertex and the ray, so triangles that share an edge
//! compute that edge's function from the same two rounded products, with opposite signs
//! (IEEE subtraction is sign-symmetric). When a function rounds to exactly 0, it is
//! recomputed from the products' exact low parts (the paper falls back to double precision
//! instead): the sign of every edge function is then the exact sign for the sheared vertices,
//! and the projected mesh has no gaps or overlaps of the origin. Hence a ray through a shared
//! edge or vertex hits at least one of the triangles that share it.

use glam::DVec3;

use super::TriHit;

/// Watertight ray/triangle intersection (Woop, Benthin, Wald 2013, "Watertight Ray/Triangle
/// Intersection", in f64): a ray through a shared edge or vertex of a closed mesh hits at least
/// one of the triangles that share it; a hit with t in (tmin, tmax), both sides of the triangle.
///
/// Degenerate triangles never hit: collinear points (exactly collinear f64 points always
/// count), and slivers whose edges meet at an angle below ~1e-14 rad (the computed cross
/// product of the edges is then within rounding of 0).
pub fn triangle_hit(p: &[DVec3; 3], o: DVec3, d: DVec3, tmin: f64, tmax: f64) -> Option<TriHit> {
    if !(o.is_finite() && d.is_finite() && p.iter().all(|v| v.is_finite())) {
        return None;
    }
    let (e1, e2) = (p[1] - p[0], p[2] - p[0]);
    // |e1 x e2| rounds with an error of a few eps |e1| |e2|; 32 eps is safely above it.
    const SLIVER: f64 = 32.0 * f64::EPSILON;
    let n2 = e1.cross(e2).length_squared();
    if n2.is_nan() || n2 <= SLIVER * SLIVER * e1.length_squared() * e2.length_squared() {
        return None;
    }

    // Axis permutation: kz the largest |d_k|; kx, ky swapped for d_kz < 0 to keep the winding.
    let ad = d.abs();
    let kz = if ad.x >= ad.y && ad.x >= ad.z {
        0
    } else if ad.y >= ad.z {
        1
    } else {
        2
    };
    let (mut kx, mut ky) = ((kz + 1) % 3, (kz + 2) % 3);
    if d[kz] < 0.0 {
        std::mem::swap(&mut kx, &mut ky);
    }
    // Shear taking d to (0, 0, 1).
    let sz = 1.0 / d[kz];
    let (sx, sy) = (d[kx] * sz, d[ky] * sz);
    let shear = |v: DVec3| {
        let w = v - o;
        (w[kx] - sx * w[kz], w[ky] - sy * w[kz], sz * w[kz])
    };
    let (a, b, c) = (shear(p[0]), shear(p[1]), shear(p[2]));

    let u = edge(c.0, b.1, c.1, b.0);
    let v = edge(a.0, c.1, a.1, c.0);
    let w = edge(b.0, a.1, b.1, a.0);
    if (u < 0.0 || v < 0.0 || w < 0.0) && (u > 0.0 || v > 0.0 || w > 0.0) {
        return None;
    }
    let det = u + v + w;
    if det == 0.0 || !det.is_finite() {
        return None;
    }
    // t = (U az + V bz + W cz) / det: the scaled depths interpolated with the edge functions.
    let t = (u * a.2 + v * b.2 + w * c.2) / det;
    if !(tmin < t && t < tmax) {
        return None;
    }
    Some(TriHit {
        t,
        b1: v / det,
        b2: w / det,
    })
}

/// `p * q - r * s`, with the sign exact whenever the rounded result is 0: then the rounded
/// products are equal, and the difference is that of their (exact, Dekker) rounding errors.
#[inline]
fn edge(p: f64, q: f64, r: f64, s: f64) -> f64 {
    let (x, y) = (p * q, r * s);
    let e = x - y;
    if e != 0.0 {
        return e;
    }
    two_prod_err(p, q, x) - two_prod_err(r, s, y)
}

/// The exact error `p q - fl(p q)` by Dekker's splitting (no fused multiply-add: without an
/// FMA target feature `f64::mul_add` is a slow library call). Exact unless an operand is
/// above ~2^996 or the product underflows.
#[inline]
fn two_prod_err(p: f64, q: f64, pq: f64) -> f64 {
    let (ph, pl) = split(p);
    let (qh, ql) = split(q);
    ((ph * qh - pq) + ph * ql + pl * qh) + pl * ql
}

/// `a = hi + lo` with `hi` of 26 significant bits (Veltkamp's splitting).
#[inline]
fn split(a: f64) -> (f64, f64) {
    let c = 134_217_729.0 * a; // 2^27 + 1
    let hi = c - (c - a);
    (hi, a - hi)
}
