//! An independent reference for the non-sphere surfaces, written for the tests from the
//! textbook forms (not from `gtsphere::geom::shapes`): ray against a cylinder, cone, box or
//! triangle in the object space of an affine map, with the outward normal and a margin that
//! says how far the hit is from an edge (pixels whose margin is tiny are left out of
//! comparisons: there the answer is decided by rounding, in either code).

use glam::{DAffine3, DVec3};

/// A VRML primitive in its own object space.
#[derive(Clone, Copy, Debug)]
pub enum RefShape {
    /// VRML Cylinder (axis y), radius and full height.
    Cylinder { r: f64, h: f64 },
    /// VRML Cone (apex at +h/2), bottom radius and full height.
    Cone { r: f64, h: f64 },
    /// VRML Box, full size.
    Cuboid { size: DVec3 },
    /// A triangle in world space (two-sided).
    Triangle { p: [DVec3; 3] },
}

/// A hit: parameter, world unit normal facing the ray, margin to the nearest edge (object
/// units, relative for caps and sides).
#[derive(Clone, Copy, Debug)]
pub struct RefHit {
    pub t: f64,
    pub n: DVec3,
    pub margin: f64,
}

/// Roots of `a t^2 + b t + c` in increasing order (textbook formula; benign cases only).
fn roots(a: f64, b: f64, c: f64) -> Option<(f64, f64, f64)> {
    let disc = b * b - 4.0 * a * c;
    if disc < 0.0 || a == 0.0 {
        return None;
    }
    let s = disc.sqrt();
    let (t0, t1) = ((-b - s) / (2.0 * a), (-b + s) / (2.0 * a));
    // The margin of a tangent hit is how far from tangency it is.
    let m = disc / (b * b + (4.0 * a * c).abs() + 1e-300);
    Some((t0.min(t1), t0.max(t1), m))
}

/// All crossings of `o + t d` (object space) with the primitive, `t > 0`, with object normals.
fn object_hits(s: &RefShape, o: DVec3, d: DVec3) -> Vec<RefHit> {
    let mut out = Vec::new();
    match *s {
        RefShape::Cylinder { r, h } => {
            let hh = h / 2.0;
            let a = d.x * d.x + d.z * d.z;
            let b = 2.0 * (o.x * d.x + o.z * d.z);
            let c = o.x * o.x + o.z * o.z - r * r;
            if let Some((t0, t1, m)) = roots(a, b, c) {
                for t in [t0, t1] {
                    let p = o + t * d;
                    if p.y.abs() <= hh {
                        out.push(RefHit {
                            t,
                            n: DVec3::new(p.x, 0.0, p.z) / r,
                            margin: m.min((hh - p.y.abs()) / hh),
                        });
                    }
                }
            }
            for (y, ny) in [(hh, 1.0), (-hh, -1.0)] {
                if d.y != 0.0 {
                    let t = (y - o.y) / d.y;
                    let p = o + t * d;
                    let q = p.x * p.x + p.z * p.z;
                    if q <= r * r {
                        out.push(RefHit {
                            t,
                            n: DVec3::new(0.0, ny, 0.0),
                            margin: (r * r - q) / (r * r),
                        });
                    }
                }
            }
        }
        RefShape::Cone { r, h } => {
            let hh = h / 2.0;
            // x^2 + z^2 = k^2 (hh - y)^2, k = r / h.
            let k = r / h;
            let (k2, w) = (k * k, hh - o.y);
            let a = d.x * d.x + d.z * d.z - k2 * d.y * d.y;
            let b = 2.0 * (o.x * d.x + o.z * d.z + k2 * w * d.y);
            let c = o.x * o.x + o.z * o.z - k2 * w * w;
            if let Some((t0, t1, m)) = roots(a, b, c) {
                for t in [t0, t1] {
                    let p = o + t * d;
                    if p.y >= -hh && p.y <= hh {
                        // Gradient of x^2 + z^2 - k^2 (hh - y)^2.
                        let n = DVec3::new(p.x, k2 * (hh - p.y), p.z).normalize();
                        out.push(RefHit {
                            t,
                            n,
                            margin: m.min((p.y + hh) / h).min((hh - p.y) / h),
                        });
                    }
                }
            }
            if d.y != 0.0 {
                let t = (-hh - o.y) / d.y;
                let p = o + t * d;
                let q = p.x * p.x + p.z * p.z;
                if q <= r * r {
                    out.push(RefHit {
                        t,
                        n: -DVec3::Y,
                        margin: (r * r - q) / (r * r),
                    });
                }
            }
        }
        RefShape::Cuboid { size } => {
            let half = size / 2.0;
            for axis in 0..3 {
                for sign in [-1.0, 1.0] {
                    if d[axis] == 0.0 {
                        continue;
                    }
                    let t = (sign * half[axis] - o[axis]) / d[axis];
                    let p = o + t * d;
                    let mut margin = f64::INFINITY;
                    let mut inside = true;
                    for k in 0..3 {
                        if k != axis {
                            let m = (half[k] - p[k].abs()) / half[k];
                            inside &= m >= 0.0;
                            margin = margin.min(m);
                        }
                    }
                    if inside {
                        let mut n = DVec3::ZERO;
                        n[axis] = sign;
                        out.push(RefHit { t, n, margin });
                    }
                }
            }
        }
        RefShape::Triangle { p } => {
            // Moller-Trumbore.
            let (e1, e2) = (p[1] - p[0], p[2] - p[0]);
            let q = d.cross(e2);
            let det = e1.dot(q);
            if det.abs() > 1e-300 {
                let s = o - p[0];
                let u = s.dot(q) / det;
                let r = s.cross(e1);
                let v = d.dot(r) / det;
                let t = e2.dot(r) / det;
                if u >= 0.0 && v >= 0.0 && u + v <= 1.0 {
                    out.push(RefHit {
                        t,
                        n: e1.cross(e2).normalize(),
                        margin: u.min(v).min(1.0 - u - v),
                    });
                }
            }
        }
    }
    out.retain(|h| h.t > 0.0);
    out
}

/// The first hit seen from outside (solids: their front faces; a triangle: either side),
/// `to_world` mapping object space to the world (identity for triangles), normal in world
/// space facing the ray.
pub fn first_hit(s: &RefShape, to_world: &DAffine3, o: DVec3, d: DVec3) -> Option<RefHit> {
    let inv = to_world.inverse();
    let (oo, dd) = (inv.transform_point3(o), inv.transform_vector3(d));
    let nm = to_world.matrix3.inverse().transpose();
    let two_sided = matches!(s, RefShape::Triangle { .. });
    object_hits(s, oo, dd)
        .into_iter()
        .filter(|h| two_sided || h.n.dot(dd) < 0.0)
        .min_by(|a, b| a.t.total_cmp(&b.t))
        .map(|h| {
            let mut n = (nm * h.n).normalize();
            if n.dot(d) > 0.0 {
                n = -n;
            }
            RefHit { n, ..h }
        })
}

/// Whether the segment `x + s w`, `s` in `(eps, smax)`, crosses the primitive.
pub fn blocks(s: &RefShape, to_world: &DAffine3, x: DVec3, w: DVec3, smax: f64) -> bool {
    blocks_from(s, to_world, x, w, 1e-9, smax)
}

/// [`blocks`] for crossings at `smin < s < smax` (0 for a point in space, not on a surface).
pub fn blocks_from(
    s: &RefShape,
    to_world: &DAffine3,
    x: DVec3,
    w: DVec3,
    smin: f64,
    smax: f64,
) -> bool {
    let inv = to_world.inverse();
    let (oo, dd) = (inv.transform_point3(x), inv.transform_vector3(w));
    object_hits(s, oo, dd)
        .iter()
        .any(|h| h.t > smin && h.t < smax)
}

/// VRML Transform `T R S` (translation, rotation about a unit axis, scale), as the test
/// writes it into the file.
pub fn trs(t: DVec3, axis: DVec3, angle: f64, s: DVec3) -> DAffine3 {
    DAffine3::from_translation(t)
        * DAffine3::from_axis_angle(axis.normalize(), angle)
        * DAffine3::from_scale(s)
}
