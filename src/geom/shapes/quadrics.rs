//! Cylinder and cone crossings.
//!
//! Each solid is a convex "infinite" part cut by planes: the infinite cylinder
//! `x^2 + z^2 <= r^2` cut to the slab `|y| <= h`, or the lower nappe of the cone cut by the
//! base plane `y = -h`. The line meets the infinite part in a parameter span `[k0, k1]` and
//! the slab (or half-space) in `[h0, h1]` (ends may be infinite). A side root, or a cap's
//! plane parameter, is a crossing when it is an end of the intersection of the two spans.
//! Deciding by comparing these parameters, rather than by testing `|y| <= h` or
//! `x^2 + z^2 <= r^2` again at each point, makes a closed solid watertight at its rims and
//! apex: entry and exit always come as a pair, whatever the rounding.
//!
//! Both side surfaces are zero sets of `X^2 + Z^2 - r2 M^2` along `v = v0 + t v1` with
//! `v = (X, Z, M)` ([`conic`]): `(x, z, 1)` and `r2 = r^2` for the cylinder, `(x, z, h - y)`
//! (apex frame) and `r2 = (r / 2h)^2` for the cone.

use glam::DVec3;

use super::Sink;

const INF: f64 = f64::INFINITY;

/// A span `[lo, hi]` of the line parameter; either end may be infinite.
type Span = (f64, f64);

/// Coefficients `(a, b, c, disc)` of `a t^2 + 2 b t + c`, the form `X^2 + Z^2 - r2 M^2` along
/// `v0 + t v1` (components `(X, Z, M)` stored as `x, y, z`), and its discriminant
/// `b^2 - a c`.
///
/// The discriminant comes from the Lagrange identity `b^2 - a c = -sum g_i g_j (v0 x v1)_k^2`
/// (metric `g = (1, 1, -r2)`): three squares of 2x2 minors, ~`|v0| |v1|` each, instead of the
/// difference of `b^2` and `a c`, which are ~`|v0|^2 |v1|^2` and cancel for small or distant
/// surfaces. It is exact 0 for a line through the apex (`v0 x v1 = 0`).
#[inline]
pub(super) fn conic(v0: DVec3, v1: DVec3, r2: f64) -> (f64, f64, f64, f64) {
    let a = v1.x * v1.x + v1.y * v1.y - r2 * (v1.z * v1.z);
    let b = v0.x * v1.x + v0.y * v1.y - r2 * (v0.z * v1.z);
    let c = v0.x * v0.x + v0.y * v0.y - r2 * (v0.z * v0.z);
    let mx = v0.x * v1.z - v0.z * v1.x;
    let mz = v0.y * v1.z - v0.z * v1.y;
    let mxz = v0.x * v1.y - v0.y * v1.x;
    let disc = r2 * (mx * mx + mz * mz) - mxz * mxz;
    (a, b, c, disc)
}

/// Sorted roots of `a t^2 + 2 b t + c` for `a != 0` and `disc = b^2 - a c >= 0`, in the stable
/// form: `q = -(b + sign(b) sqrt(disc))` adds terms of one sign, roots `q / a` and `c / q`.
#[inline]
pub(super) fn roots(a: f64, b: f64, c: f64, disc: f64) -> (f64, f64) {
    let q = -(b + disc.sqrt().copysign(b));
    if q == 0.0 {
        // b = disc = 0: the double root -b/a = 0.
        return (0.0, 0.0);
    }
    let (t0, t1) = (q / a, c / q);
    if t0 <= t1 {
        (t0, t1)
    } else {
        (t1, t0)
    }
}

/// The ends of the infinite part's span `k` that are crossings of that part cut to `h`: the
/// ends of `k` that are ends of the non-empty intersection `[max(k0, h0), min(k1, h1)]`.
/// The complementary test for a plane parameter `p` is `k0 < p < k1` (see [`cylinder`]);
/// ties go to the side, and an intersection of one point yields nothing.
#[inline]
fn side_ends((k0, k1): Span, (h0, h1): Span) -> [f64; 2] {
    let open = k0 < k1;
    let nan = f64::NAN; // dropped by Sink::push
    [
        if open && h0 <= k0 && k0 < h1 { k0 } else { nan },
        if open && h0 < k1 && k1 <= h1 { k1 } else { nan },
    ]
}

/// Crossings of the cylinder of radius `r`, `|y| <= h`, with parts `[bottom, side, top]`.
pub(super) fn cylinder(r: f64, h: f64, parts: [bool; 3], o: DVec3, d: DVec3, sink: &mut Sink) {
    if !(r > 0.0 && h > 0.0 && r < INF && h < INF) {
        return;
    }
    // Cap planes: the same two quotients decide the slab and the cap crossings.
    let t_bottom = (-h - o.y) / d.y;
    let t_top = (h - o.y) / d.y;
    let slab = if d.y > 0.0 {
        (t_bottom, t_top)
    } else if d.y < 0.0 {
        (t_top, t_bottom)
    } else if o.y.abs() <= h {
        (-INF, INF)
    } else {
        return;
    };
    let (a, b, c, disc) = conic(DVec3::new(o.x, o.z, 1.0), DVec3::new(d.x, d.z, 0.0), r * r);
    let tube = if a > 0.0 {
        if disc.is_nan() || disc < 0.0 {
            return;
        }
        roots(a, b, c, disc)
    } else if c <= 0.0 {
        // Parallel to the axis, inside the infinite cylinder.
        (-INF, INF)
    } else {
        return;
    };
    if parts[1] {
        for t in side_ends(tube, slab) {
            sink.push(t, |t| {
                let p = o + t * d;
                let rho = p.x.hypot(p.z);
                if rho > 0.0 && rho < INF {
                    DVec3::new(p.x / rho, 0.0, p.z / rho)
                } else {
                    DVec3::X // only if r underflows next to |o|
                }
            });
        }
    }
    if d.y != 0.0 {
        for (present, t, ny) in [(parts[0], t_bottom, -1.0), (parts[2], t_top, 1.0)] {
            if present && tube.0 < t && t < tube.1 {
                sink.push(t, |_| DVec3::new(0.0, ny, 0.0));
            }
        }
    }
}

/// Crossings of the cone with apex `(0, h, 0)` and base disc of radius `r` at `y = -h`.
pub(super) fn cone(r: f64, h: f64, side: bool, bottom: bool, o: DVec3, d: DVec3, sink: &mut Sink) {
    let k = r / (2.0 * h);
    let k2 = k * k;
    if !(r > 0.0 && h > 0.0 && h < INF && k2 > 0.0 && k2 < INF) {
        return;
    }
    let Some(nappe) = nappe_span(k2, h, o, d) else {
        return;
    };
    // Half-space y >= -h (the base side of the base plane).
    let t_base = (-h - o.y) / d.y;
    let above = if d.y > 0.0 {
        (t_base, INF)
    } else if d.y < 0.0 {
        (-INF, t_base)
    } else if o.y >= -h {
        (-INF, INF)
    } else {
        return;
    };
    if side {
        // Outward normal (r_hat, k) / sqrt(1 + k^2), r_hat the radial unit vector: the
        // gradient of sqrt(x^2 + z^2) - k (h - y). Within rounding of the axis (the apex, which
        // has no normal) r_hat is noise; there r_hat = -+ d_xz / |d_xz| for an entry / exit
        // gives d . normal = (-+|d_xz| + k d_y) / sqrt(1 + k^2), of the right sign for every
        // line through the apex that enters or leaves the solid there.
        let scale = 1.0 / (1.0 + k2).sqrt();
        let fuzz = 4.0 * f64::EPSILON * o.abs().max_element();
        let dxz = d.x.hypot(d.z);
        for (exit, t) in side_ends(nappe, above).into_iter().enumerate() {
            sink.push(t, |t| {
                let p = o + t * d;
                let rho = p.x.hypot(p.z);
                let (x, z) = if rho > fuzz + 4.0 * f64::EPSILON * (t * d).abs().max_element() {
                    (p.x / rho, p.z / rho)
                } else if dxz > 0.0 {
                    let s = if exit == 1 { 1.0 } else { -1.0 };
                    (s * d.x / dxz, s * d.z / dxz)
                } else {
                    (1.0, 0.0)
                };
                DVec3::new(x, k, z) * scale
            });
        }
    }
    if bottom && d.y != 0.0 && nappe.0 < t_base && t_base < nappe.1 {
        sink.push(t_base, |_| DVec3::NEG_Y);
    }
}

/// The span where the line is inside the lower nappe `x^2 + z^2 <= k2 u^2, u = h - y >= 0`
/// (unbounded below), or `None`.
///
/// The nappe is chosen from exact data where rounding could mislead: a line whose direction
/// is inside the cone (`a < 0`) meets each nappe once, and enters the lower one going down
/// (`u` increasing), so the sign of `d.y` picks the root, even for a line through the apex.
fn nappe_span(k2: f64, h: f64, o: DVec3, d: DVec3) -> Option<Span> {
    let (uo, du) = (h - o.y, -d.y);
    let (a, b, c, disc) = conic(DVec3::new(o.x, o.z, uo), DVec3::new(d.x, d.z, du), k2);
    if a > 0.0 {
        // Both roots on one nappe (a chord of a convex cone): the one its midpoint is in.
        if disc.is_nan() || disc < 0.0 {
            return None;
        }
        let (t0, t1) = roots(a, b, c, disc);
        (uo + (-b / a) * du >= 0.0).then_some((t0, t1))
    } else if a < 0.0 {
        // disc >= 0 holds exactly here (a < 0 implies a real root on each nappe).
        let (t0, t1) = roots(a, b, c, disc.max(0.0));
        Some(if du > 0.0 { (t1, INF) } else { (-INF, t0) })
    } else if b != 0.0 {
        // Parallel to a generator: 2 b t + c <= 0 is a half-line, in the lower nappe when it
        // runs towards u = +inf.
        let t = -c / (2.0 * b);
        match (b < 0.0, du > 0.0) {
            (true, true) => Some((t, INF)),
            (false, false) => Some((-INF, t)),
            _ => None,
        }
    } else {
        None
    }
}
