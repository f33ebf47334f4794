//! Where the state of a light can change along a camera ray: the samples, the shadow
//! boundaries of surfaces and the breakpoints the reference integrates between.

use super::*;

impl World {
    /// A sphere holding primitive `k` (for where its shadow can fall).
    pub(super) fn bounding_sphere(&self, k: usize) -> (DVec3, f64) {
        match self.prims[k].solid {
            Solid::Sphere { c, r } => (c, r),
            Solid::Surface { shape, to_world } => {
                let (c, r) = match shape {
                    RefShape::Cylinder { r, h } | RefShape::Cone { r, h } => {
                        (DVec3::ZERO, (r * r + 0.25 * h * h).sqrt())
                    }
                    RefShape::Cuboid { size } => (DVec3::ZERO, 0.5 * size.length()),
                    RefShape::Triangle { p } => {
                        let c = (p[0] + p[1] + p[2]) / 3.0;
                        (c, p.iter().map(|q| (*q - c).length()).fold(0.0, f64::max))
                    }
                };
                let m = to_world.matrix3;
                let scale = m
                    .x_axis
                    .length()
                    .max(m.y_axis.length())
                    .max(m.z_axis.length());
                (
                    to_world.transform_point3(c),
                    r * scale * (1.0 + 1e-9) + 1e-12,
                )
            }
        }
    }

    /// Parameters in [a, b] of the camera ray `o + t w` where light `li`'s state can change
    /// faster than the grid sees: inside the interval where the light's line from the ray meets
    /// a primitive's bounding sphere (a shadow narrower than the grid's step lies in it), and
    /// the ray's closest approach to a point light (its radius and attenuation corner are
    /// spheres around it, which the ray may cross twice within one grid step).
    pub(super) fn extra_samples(
        &self,
        li: usize,
        o: DVec3,
        w: DVec3,
        a: f64,
        b: f64,
        out: &mut Vec<f64>,
    ) {
        let kind = &self.lights[li].kind;
        let point = match *kind {
            LightKind::Point(p) if !p.on => return,
            LightKind::Directional(d) if !d.on => return,
            LightKind::Head if self.head_viewer_carried => return,
            LightKind::Point(p) => Some(p.location),
            _ => None,
        };
        if let Some(lp) = point {
            let tc = (lp - o).dot(w);
            if tc > a && tc < b {
                out.push(tc);
            }
        }
        let dir = match *kind {
            LightKind::Directional(d) => -d.direction,
            LightKind::Head => -self.eye.forward,
            LightKind::Point(_) => DVec3::ZERO,
        };
        for k in 0..self.prims.len() {
            // A triangle edge-on to the light casts a shadow far narrower than its bounding
            // sphere's: which side of each edge the light's line from x(t) passes (the sign of
            // the volume of x(t), the edge and the light's line) and which side of the plane
            // x(t) is are affine in t; one sample between each two of their roots.
            if let Solid::Surface {
                shape: RefShape::Triangle { p },
                to_world,
            } = self.prims[k].solid
            {
                let p = p.map(|q| to_world.transform_point3(q));
                let vol = |t: f64, i: usize| -> f64 {
                    let x = o + t * w;
                    let d = match point {
                        Some(lp) => lp - x,
                        None => dir,
                    };
                    (p[i] - x).cross(p[(i + 1) % 3] - x).dot(d)
                };
                let nrm = (p[1] - p[0]).cross(p[2] - p[0]);
                let side = |t: f64| (o + t * w - p[0]).dot(nrm);
                let mut roots = vec![a, b];
                for f in [
                    &(|t| vol(t, 0)) as &dyn Fn(f64) -> f64,
                    &|t| vol(t, 1),
                    &|t| vol(t, 2),
                    &side,
                ] {
                    let (fa, fb) = (f(a), f(b));
                    if fa != fb {
                        let t = a + (b - a) * fa / (fa - fb);
                        if t > a && t < b {
                            roots.push(t);
                        }
                    }
                }
                roots.sort_by(f64::total_cmp);
                for seg in roots.windows(2) {
                    out.push(0.5 * (seg[0] + seg[1]));
                }
            }
            if let Some(t) = self.inside_shadow(k, o, w, point, dir) {
                if t > a && t < b {
                    out.push(t);
                }
            }
            let (c, r) = self.bounding_sphere(k);
            // Quadratic q(t) = A t^2 + B t + C whose sign says whether the light's line from
            // x(t) meets the sphere (<= 0 for a cylinder, >= 0 for a cone about the point light).
            let (qa, qb, qc) = match point {
                None => {
                    let p0 = (o - c) - (o - c).dot(dir) * dir;
                    let q = w - w.dot(dir) * dir;
                    (
                        q.length_squared(),
                        2.0 * p0.dot(q),
                        p0.length_squared() - r * r,
                    )
                }
                Some(lp) => {
                    let d = c - lp;
                    let dl = d.length();
                    if dl <= r {
                        // The light inside the bounding sphere: anywhere.
                        (0.0, 0.0, -1.0)
                    } else {
                        let u = d / dl;
                        let cos2 = 1.0 - (r / dl) * (r / dl);
                        let y0 = o - lp;
                        let (yu, wu) = (y0.dot(u), w.dot(u));
                        (
                            -(wu * wu - cos2),
                            -2.0 * (yu * wu - cos2 * y0.dot(w)),
                            -(yu * yu - cos2 * y0.length_squared()),
                        )
                    }
                }
            };
            // Split [a, b] at the roots; sample the parts where q <= 0.
            let mut cuts = vec![a, b];
            if qa != 0.0 {
                let disc = qb * qb - 4.0 * qa * qc;
                if disc >= 0.0 {
                    let sq = disc.sqrt();
                    for t in [(-qb - sq) / (2.0 * qa), (-qb + sq) / (2.0 * qa)] {
                        if t > a && t < b {
                            cuts.push(t);
                        }
                    }
                }
            } else if qb != 0.0 {
                let t = -qc / qb;
                if t > a && t < b {
                    cuts.push(t);
                }
            }
            // Where the ray itself crosses the bounding sphere: for a sphere, its light state
            // changes only there and at the roots above, so a sample just beside each cut
            // sees every state, however thin (a light ray from just outside an opaque sphere
            // that misses it).
            if let Some(roots) = sphere_roots(c, r, o, w) {
                for t in [roots.0, roots.1] {
                    if t > a && t < b {
                        cuts.push(t);
                    }
                }
            }
            cuts.sort_by(f64::total_cmp);
            for &t in &cuts[1..cuts.len() - 1] {
                let d = 1e-12 * t.abs().max(1.0);
                out.extend([t - d, t + d].into_iter().filter(|s| *s > a && *s < b));
            }
            for seg in cuts.windows(2) {
                let (s0, s1) = (seg[0], seg[1]);
                let m = 0.5 * (s0 + s1);
                if s1 > s0 && (qa * m + qb) * m + qc <= 0.0 {
                    for n in 0..=EXTRA {
                        let t = s0 + (s1 - s0) * (n as f64 + 0.5) / (EXTRA as f64 + 1.0);
                        out.push(t);
                    }
                }
            }
        }
    }

    /// A parameter `t` where the light's line from `o + t w` meets the surface `k` (not a
    /// sphere), if one exists: however thin its shadow along the ray, the grid then holds a
    /// point of it. Every light line from the camera ray lies in one plane (through the ray and
    /// the light's direction or point); a convex surface meets that plane iff its extreme
    /// points along the plane's normal (closed forms: [`support`]) lie on both sides, and the
    /// segment between them, inside the surface, crosses the plane at a point on the light line
    /// of one `t`. (A surface's shadow along a ray is one interval, the shadowed set of a
    /// convex body being convex, so one point of it is enough for the bisection.)
    pub(super) fn inside_shadow(
        &self,
        k: usize,
        o: DVec3,
        w: DVec3,
        point: Option<DVec3>,
        dir: DVec3,
    ) -> Option<f64> {
        let Solid::Surface { shape, to_world } = self.prims[k].solid else {
            return None;
        };
        let across = match point {
            Some(lp) => lp - o,
            None => dir,
        };
        let n = w.cross(across);
        if n.length_squared() < 1e-24 * across.length_squared() {
            return None;
        }
        let (hi, lo) = (
            support(&shape, &to_world, n),
            support(&shape, &to_world, -n),
        );
        let (fh, fl) = (n.dot(hi - o), n.dot(lo - o));
        if fh < 0.0 || fl > 0.0 {
            return None;
        }
        let y = if fh > fl {
            lo + (hi - lo) * (-fl / (fh - fl))
        } else {
            hi
        };
        // y - base = alpha w + beta e in the plane, by the 2x2 normal equations.
        let (base, e) = match point {
            Some(lp) => (lp, o - lp),
            None => (o, dir),
        };
        let q = y - base;
        let (ww, we, ee) = (w.dot(w), w.dot(e), e.dot(e));
        let det = ww * ee - we * we;
        let (qw, qe) = (q.dot(w), q.dot(e));
        let alpha = (qw * ee - qe * we) / det;
        let beta = (qe * ww - qw * we) / det;
        match point {
            // y = o + alpha w + beta dir: on the light line of t = alpha if beta >= 0.
            None => (beta >= 0.0).then_some(alpha),
            // y = lp + beta (o - lp) + alpha w = lp + beta (x(t) - lp) with t = alpha / beta,
            // between x(t) and the light if 0 < beta <= 1.
            Some(_) => (beta > 0.0 && beta <= 1.0).then(|| alpha / beta),
        }
    }

    /// The light-state breakpoints inside [a, b] for gas points of the ray: the states are
    /// sampled on a grid of [`GRID`] steps plus [`World::extra_samples`], and every change
    /// between neighbouring samples is bisected, as often as the states still differ (two
    /// changes between two samples are both found). Each breakpoint comes with whether a light's
    /// line grazes a gas sphere there: the (light, gas sphere) pairs (see [`World::graded`]).
    pub(super) fn breakpoints(
        &self,
        o: DVec3,
        w: DVec3,
        a: f64,
        b: f64,
    ) -> Vec<(f64, Vec<(usize, usize)>)> {
        let sig = |t: f64| {
            let mut s = Vec::new();
            for li in 0..self.lights.len() {
                self.signature(li, o + t * w, &mut s);
            }
            s
        };
        let mut samples: Vec<f64> = (0..=GRID)
            .map(|g| {
                if g == GRID {
                    b
                } else {
                    a + (b - a) * g as f64 / GRID as f64
                }
            })
            .collect();
        for li in 0..self.lights.len() {
            self.extra_samples(li, o, w, a, b, &mut samples);
        }
        samples.sort_by(f64::total_cmp);
        samples.dedup();
        let mut out = vec![(a, Vec::new())];
        let mut prev = (a, sig(a));
        for &t in &samples[1..] {
            let s = sig(t);
            while s != prev.1 {
                let (mut lo, mut hi) = (prev.0, t);
                while hi - lo > BISECT * hi.abs().max(1.0) {
                    let mid = 0.5 * (lo + hi);
                    if mid <= lo || mid >= hi {
                        break;
                    }
                    if sig(mid) == prev.1 {
                        lo = mid;
                    } else {
                        hi = mid;
                    }
                }
                let (glo, ghi) = (
                    self.gas_signature(o + lo * w),
                    self.gas_signature(o + hi * w),
                );
                // The pairs on one side only.
                let grazes = glo
                    .iter()
                    .filter(|p| !ghi.contains(p))
                    .chain(ghi.iter().filter(|p| !glo.contains(p)))
                    .copied()
                    .collect();
                out.push((0.5 * (lo + hi), grazes));
                if hi >= t {
                    break;
                }
                prev = (hi, sig(hi));
            }
            prev = (t, s);
        }
        out.push((b, Vec::new()));
        out
    }
}

/// A point of the surface `shape` (placed by `to_world`) farthest along `n`: VRML's shapes
/// in their object space, where the farthest point along `m = A^T n` is a corner, a rim point
/// or the apex.
fn support(shape: &RefShape, to_world: &glam::DAffine3, n: DVec3) -> DVec3 {
    let m = to_world.matrix3.transpose() * n;
    let sign = |x: f64| if x < 0.0 { -1.0 } else { 1.0 };
    let rim = |r: f64, y: f64| {
        let len = m.x.hypot(m.z);
        if len > 0.0 {
            DVec3::new(r * m.x / len, y, r * m.z / len)
        } else {
            DVec3::new(r, y, 0.0)
        }
    };
    let object = match *shape {
        RefShape::Cuboid { size } => 0.5 * size * DVec3::new(sign(m.x), sign(m.y), sign(m.z)),
        RefShape::Cylinder { r, h } => rim(r, 0.5 * h * sign(m.y)),
        RefShape::Cone { r, h } => {
            let (apex, base) = (DVec3::new(0.0, 0.5 * h, 0.0), rim(r, -0.5 * h));
            if m.dot(apex) >= m.dot(base) {
                apex
            } else {
                base
            }
        }
        RefShape::Triangle { p } => {
            let mut best = p[0];
            for q in &p[1..] {
                if n.dot(*q) > n.dot(best) {
                    best = *q;
                }
            }
            return best;
        }
    };
    to_world.transform_point3(object)
}
