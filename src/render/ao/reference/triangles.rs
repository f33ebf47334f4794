//! The reference among triangles (see the parent's comment, "Triangles"): each triangle met
//! along each meridian, from the triangle itself.

use super::*;

/// [`covered_with_stats`] of the union of `caps` and of the directions whose rays meet one of
/// `triangles` (corners relative to the shading point) at a distance of at most `reach`.
/// With each triangle, which of its corners lie in the point's tangent plane (corners of the
/// triangle the point is on): their heights are taken as 0, not as rounding leaves them.
pub fn covered_with_triangles(
    n: V3,
    caps: &[(V3, f64)],
    triangles: &[([V3; 3], [bool; 3])],
    reach: f64,
    weight: Weight,
) -> (f64, Stats) {
    let n = normalize(n);
    let (e1, e2) = basis(n);
    let stats = Stats::default();
    let frame = |axis: V3, c: f64| {
        let axis = normalize(axis);
        Cap {
            axis,
            a1: dot(axis, e1),
            a2: dot(axis, e2),
            a3: dot(axis, n),
            c,
            s: ((1.0 - c) * (1.0 + c)).sqrt(),
        }
    };
    let cs: Vec<Cap> = caps
        .iter()
        .map(|&(axis, c)| {
            assert!((0.0..1.0).contains(&c), "cap cosine {c} outside [0, 1)");
            frame(axis, c)
        })
        .filter(|cap| cap.a3 > -cap.s)
        .collect();
    // Triangles with a corner above the horizon.
    let (tris, flats): (Vec<[V3; 3]>, Vec<[bool; 3]>) = triangles
        .iter()
        .copied()
        .filter(|(t, flat)| (0..3).any(|i| !flat[i] && dot(t[i], n) > 0.0))
        .unzip();
    if cs.is_empty() && tris.is_empty() {
        return (0.0, stats);
    }
    // More circles for the breakpoints: each triangle's edge planes and its reach circle,
    // with the cones within which each occluder's boundary lies.
    let mut circles: Vec<(Cap, Option<usize>, bool)> =
        cs.iter().map(|&c| (c, None, false)).collect();
    let mut extra: Vec<f64> = Vec::new();
    for (t, tri) in tris.iter().enumerate() {
        for i in 0..3 {
            let e = cross(tri[i], tri[(i + 1) % 3]);
            if dot(e, e) > 0.0 {
                circles.push((frame(e, 0.0), Some(t), true));
            }
            extra.push(dot(tri[i], e2).atan2(dot(tri[i], e1)));
        }
        let normal = cross(
            add(tri[1], scale(tri[0], -1.0)),
            add(tri[2], scale(tri[0], -1.0)),
        );
        if dot(normal, normal) > 0.0 && reach.is_finite() {
            let normal = normalize(normal);
            let h = dot(normal, tri[0]);
            if h != 0.0 && h.abs() < reach {
                let m = scale(normal, h.signum());
                circles.push((frame(m, h.abs() / reach), Some(t), false));
            }
        }
    }
    for (cap, _, _) in &circles {
        // The azimuths where a circle passes nearest to, or farthest from, the normal.
        let phi = cap.a2.atan2(cap.a1);
        extra.push(phi);
        extra.push(phi + PI);
    }
    let on_boundary = |x: V3, of: Option<usize>| match of {
        None => true,
        Some(t) => {
            let tri = &tris[t];
            (0..3).all(|i| {
                let e = cross(tri[i], tri[(i + 1) % 3]);
                let side = dot(e, tri[(i + 2) % 3]).signum();
                side * dot(e, x) >= -1e-6 * dot(e, e).sqrt()
            })
        }
    };
    let bps = breakpoints_of(n, e1, e2, &circles, &extra, on_boundary);
    let mut eval = Integrand {
        caps: &cs,
        tris: &tris,
        flats: &flats,
        reach,
        n,
        e1,
        e2,
        weight,
        buf: Vec::with_capacity(cs.len() + tris.len()),
    };
    integrate_azimuth(&bps, &mut eval, weight, stats)
}

/// The polar angles `[t0, t1]` (within `[0, pi/2]`) of the directions of the meridian of
/// azimuth `p` (`u = u(p)`) whose rays meet the triangle `tri` (corners relative to the
/// point) within `reach`.
pub(super) fn triangle_on_meridian(
    tri: &[V3; 3],
    flat: [bool; 3],
    n: V3,
    u: V3,
    reach: f64,
) -> Option<(f64, f64)> {
    // The plane of the meridian has the normal v; the triangle meets it where the corners'
    // signed distances change sign. Each corner in the meridian's frame: (distance from
    // the plane, height along n, distance along u), all linear along an edge; a corner in
    // the point's tangent plane has height 0.
    let v = cross(n, u);
    let c: [(f64, f64, f64); 3] = std::array::from_fn(|i| {
        let height = if flat[i] { 0.0 } else { dot(n, tri[i]) };
        (dot(v, tri[i]), height, dot(u, tri[i]))
    });
    let mut pts: Vec<(f64, f64)> = Vec::with_capacity(3);
    for i in 0..3 {
        let j = (i + 1) % 3;
        if c[i].0 == 0.0 {
            pts.push((c[i].1, c[i].2));
        } else if c[i].0 * c[j].0 < 0.0 {
            let f = c[i].0 / (c[i].0 - c[j].0);
            pts.push((
                c[i].1 + f * (c[j].1 - c[i].1),
                c[i].2 + f * (c[j].2 - c[i].2),
            ));
        }
    }
    // The segment: the two points farthest apart.
    let (mut a2, mut b2, mut far) = ((0.0, 0.0), (0.0, 0.0), -1.0);
    for i in 0..pts.len() {
        for j in i + 1..pts.len() {
            let d = (pts[i].0 - pts[j].0).hypot(pts[i].1 - pts[j].1);
            if d > far {
                (a2, b2, far) = (pts[i], pts[j], d);
            }
        }
    }
    if far <= 0.0 {
        return None;
    }
    // Seen edge-on: the segment's line through the point.
    let turn = a2.0 * b2.1 - a2.1 * b2.0;
    if turn.abs() <= 1e-12 * a2.0.hypot(a2.1) * b2.0.hypot(b2.1) {
        return None;
    }
    let d = (b2.0 - a2.0, b2.1 - a2.1);
    // Clip s in [0, 1] to the meridian's side (distance along u >= 0) and to the ball.
    let (mut s0, mut s1) = (0.0f64, 1.0f64);
    if d.1 == 0.0 {
        if a2.1 < 0.0 {
            return None;
        }
    } else {
        let s = -a2.1 / d.1;
        if d.1 > 0.0 {
            s0 = s0.max(s);
        } else {
            s1 = s1.min(s);
        }
    }
    if reach.is_finite() {
        let qa = d.0 * d.0 + d.1 * d.1;
        let qb = a2.0 * d.0 + a2.1 * d.1;
        let qc = (a2.0 * a2.0 + a2.1 * a2.1) - reach * reach;
        let disc = qb * qb - qa * qc;
        if disc < 0.0 {
            return None;
        }
        // The roots of qa s^2 + 2 qb s + qc, without cancellation.
        let q = -(qb + qb.signum() * disc.sqrt());
        let (r0, r1) = if q == 0.0 {
            (0.0, 0.0)
        } else {
            (q / qa, qc / q)
        };
        s0 = s0.max(r0.min(r1));
        s1 = s1.min(r0.max(r1));
    }
    if s0 >= s1 {
        return None;
    }
    // (Distance along u at least 0, also where rounding puts the clipped end below it: an
    // end on the axis below the point is at pi, not -pi.)
    let angle = |s: f64| (a2.1 + s * d.1).max(0.0).atan2(a2.0 + s * d.0);
    let (t0, t1) = (angle(s0), angle(s1));
    let (lo, hi) = (t0.min(t1).max(0.0), t0.max(t1).min(FRAC_PI_2));
    (lo < hi).then_some((lo, hi))
}
