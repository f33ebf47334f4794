//! The region of space that light rays from a piece of a camera ray sweep on their way to a
//! light, and the spheres that meet it (docs/model.md section 3).
//!
//! For light `i`, the points `x(t)` of the segment `[A, B]` send light rays towards the light:
//! along `L` for a directional light (they sweep a half-infinite strip), to the point `P` for a
//! point light (they sweep the triangle `A B P`). Only spheres that meet that region can shadow
//! any point of the segment: those are the segment's **shadowers**.
//!
//! The region is cut into **depth bands** along the light rays (distance `s` along `L`, or the
//! fraction `lambda` of the way to `P`), so that the far bands need only be searched for the
//! parts of the segment that the near ones leave lit (`render::light_pieces`). A band is a
//! convex planar quadrilateral. Its spheres come from the light's grid when the render has one
//! (`render::light_grid`: the scene as the light sees it, where the band is a line, so a query
//! visits the few cells that line crosses), and otherwise from the BVH, searched with the exact
//! distance of each node's bounding ball to the quadrilateral (`SphereBvh::near_region`), so the
//! nodes visited are those near it, not those in an axis-aligned box around it. Either way each
//! candidate is decided by the same exact distance test (`touches`).
//!
//! Without a grid, the segments of one camera ray share the descents ([`BandCache`]): a band's
//! search covers the asking segment and the ray up to the band's depth beyond it, and the
//! segments that follow take their own shadowers from that list, pruned by where along the ray
//! each sphere can shadow at all ([`reach_on_ray`]) and then by the same exact test. Measured on
//! cloud-N (N = 1e4 to 1e6), it changes the time by less than this machine's noise (about 15 %):
//! the descents it saves are offset by the larger regions they search. Measured with grids
//! (2026-12-02, cloud-N at N = 1e3 to 1e6), sharing made queries 10-15 % slower, so a grid
//! query is always the span's own.

use glam::DVec3;

use super::light_grid::LightGrid;
use super::lights::LightKind;
use crate::accel::{Ball, SphereBvh};
use crate::geom::distance_to_segment as to_segment;

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

/// How far along the light rays from the segment `[a, b]` everything in `bvh` lies: beyond
/// it no light ray meets a primitive (directional: the farthest corner of the BVH's box along
/// `L`; point: the light itself, `1`). In the units of [`Region::band`].
pub fn path_end(bvh: &SphereBvh, light: &LightKind, a: DVec3, b: DVec3) -> f64 {
    match *light {
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
            end
        }
        LightKind::Point { .. } => 1.0,
    }
}

/// The band edges along the light rays from the segment `[a, b]`: `0 = f_0 < f_1 < ... = end`,
/// where `end` is [`path_end`], and `f_1 = base`, then eight times deeper each band (fewer
/// bands cost fewer BVH descents; deeper ones gather more spheres that turn out to lie
/// behind dark pieces).
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
    let end = path_end(bvh, light, a, b);
    let step = match *light {
        LightKind::Directional { .. } => base,
        LightKind::Point { position: p, .. } => {
            let near = (p - a).length().min((p - b).length());
            if near > 0.0 {
                base / near
            } else {
                1.0
            }
        }
    };
    let mut f = step;
    while f.is_finite() && f > 0.0 && f < end {
        out.push(f);
        f *= 8.0;
    }
    out.push(end.max(0.0));
}

/// Rounding allowance of the distance tests against `region`: a few ulps of the coordinates
/// involved.
fn slack(bvh: &SphereBvh, region: &Region) -> f64 {
    let (lo, hi) = bvh.bounds();
    let big = lo.abs().max(hi.abs()).max_element();
    let q = region
        .q
        .iter()
        .fold(big, |m, v| m.max(v.abs().max_element()));
    64.0 * f64::EPSILON * q
}

/// Whether primitive `p`'s ball meets `region` (allowing `slack` for rounding).
#[inline]
fn touches(region: &Region, p: &impl Ball, slack: f64) -> bool {
    region.meets(p.center(), p.radius() * (1.0 + 1e-9) + slack)
}

/// Appends to `out` every primitive that meets `region`.
pub fn gather(bvh: &SphereBvh, region: &Region, out: &mut Vec<u32>, stack: &mut Vec<u32>) {
    let slack = slack(bvh, region);
    bvh.near_region(
        |lo, hi| region.may_meet_box(lo, hi, slack),
        |i, p| {
            if touches(region, p, slack) {
                out.push(i);
            }
        },
        stack,
    );
}

/// Appends to `out` every primitive that meets `region`, the band `f` swept from `[a, b]`,
/// from the light's grid's candidates; false (nothing appended) where the grid cannot answer.
fn gather_from_grid(
    grid: &LightGrid,
    bvh: &SphereBvh,
    region: &Region,
    (a, b): (DVec3, DVec3),
    f: (f64, f64),
    out: &mut Vec<u32>,
) -> bool {
    let mark = out.len();
    if !grid.candidates(a, b, f, out) {
        return false;
    }
    out[mark..].sort_unstable();
    let slack = slack(bvh, region);
    let mut keep = mark;
    let mut last = u32::MAX;
    for k in mark..out.len() {
        let i = out[k];
        if i == last {
            continue;
        }
        last = i;
        if touches(region, &bvh.packed()[i as usize], slack) {
            out[keep] = i;
            keep += 1;
        }
    }
    out.truncate(keep);
    true
}

/// A conservative interval of the camera-ray parameters `t` from which the light ray of the
/// point `o + t d` (`d` unit) can meet the ball `(c, r)`: outside it, no light ray does.
/// Infinite where no useful interval is known (a ray along the light's direction, a point
/// light inside or near the ball).
pub fn reach_on_ray(light: &LightKind, o: DVec3, d: DVec3, c: DVec3, r: f64) -> (f64, f64) {
    const ALL: (f64, f64) = (f64::NEG_INFINITY, f64::INFINITY);
    // A wider ball: rounding below cannot lose a ball the light ray meets.
    let r = r * (1.0 + 1e-6) + 64.0 * f64::EPSILON * (c.abs().max_element() + r);
    let (t0, t1) = match *light {
        LightKind::Directional { to_light: l, .. } => {
            // Along L the ball and the line through o + t d project to a disc of radius r
            // and a line; the light ray meets the ball only where the line is within r of the
            // disc's centre: |t - t_c| <= r / |d_perp|.
            let dp = d - d.dot(l) * l;
            let m = dp.length_squared();
            if m < 1e-12 {
                return ALL;
            }
            let w = c - o;
            let wp = w - w.dot(l) * l;
            let tc = wp.dot(dp) / m;
            let half = r / m.sqrt();
            (tc - half, tc + half)
        }
        LightKind::Point { position: p, .. } => {
            // From P the ball fills a cone of half-angle alpha around a; the light ray of x
            // meets the ball only if x - P lies in that cone: (w.a)^2 >= cos^2(alpha) |w|^2
            // for w = e + t d, a quadratic in t that is negative for large |t| when the
            // camera ray is not inside the cone's directions.
            let axis = c - p;
            let dist = axis.length();
            if dist <= 1.01 * r {
                return ALL;
            }
            let a = axis / dist;
            let cos2 = 1.0 - (r / dist) * (r / dist);
            let e = o - p;
            let (p0, p1) = (e.dot(a), d.dot(a));
            let qa = p1 * p1 - cos2;
            if qa > -1e-9 {
                return ALL;
            }
            let qb = p0 * p1 - cos2 * e.dot(d);
            let qc = p0 * p0 - cos2 * e.length_squared();
            let disc = qb * qb - qa * qc;
            if disc < 0.0 {
                // The whole line is outside the (widened) cone.
                return (f64::INFINITY, f64::NEG_INFINITY);
            }
            let root = disc.sqrt();
            // qa < 0: q >= 0 between the roots.
            let (ra, rb) = ((-qb + root) / qa, (-qb - root) / qa);
            (ra.min(rb), ra.max(rb))
        }
    };
    let pad = 1e-9 * (t0.abs().max(t1.abs()) + r);
    (t0 - pad, t1 + pad)
}

/// A primitive found near a band, with [`reach_on_ray`] of it.
#[derive(Clone, Copy, Debug)]
struct Near {
    prim: u32,
    t0: f64,
    t1: f64,
}

/// One band's search, shared by the segments of a camera ray: the primitives that meet the
/// band swept from the part `cover` of the ray, found by one BVH descent. A segment whose span
/// lies in `cover` takes from that list the primitives that meet its own band (first by their
/// [`reach_on_ray`], then by the same distance test as [`gather`]), which are exactly those a
/// descent for its own band would find: its band lies inside the cached one, and every ball
/// within reach of its band is within reach of the larger one.
#[derive(Debug, Default)]
pub struct BandCache {
    f: (f64, f64),
    cover: (f64, f64),
    near: Vec<Near>,
    found: Vec<u32>,
}

impl BandCache {
    /// Forget what was found (a new camera ray).
    pub fn clear(&mut self) {
        self.cover = (f64::INFINITY, f64::NEG_INFINITY);
        self.near.clear();
    }

    /// Appends to `out` every primitive that meets the band `f` swept from the span
    /// `[u0, u1]` of `o + t d` (`d` unit) towards `light`. A new descent covers the span and
    /// what follows it, up to the band's own depth or four times the span, whichever is less
    /// (and at most up to `t_end`, the end of the camera ray's part that may ask), so that the
    /// next segments can use it.
    #[allow(clippy::too_many_arguments)]
    pub fn query(
        &mut self,
        bvh: &SphereBvh,
        grid: Option<&LightGrid>,
        light: &LightKind,
        (o, d): (DVec3, DVec3),
        f: (f64, f64),
        (u0, u1): (f64, f64),
        t_end: f64,
        out: &mut Vec<u32>,
        stack: &mut Vec<u32>,
    ) {
        if let Some(g) = grid {
            // A grid query costs what the span's own band holds: no descent to share.
            let (a, b) = (o + u0 * d, o + u1 * d);
            let region = Region::band(light, a, b, f.0, f.1);
            if gather_from_grid(g, bvh, &region, (a, b), f, out) {
                return;
            }
        }
        if self.f != f || !(self.cover.0 <= u0 && u1 <= self.cover.1) {
            let depth = match *light {
                LightKind::Directional { .. } => f.1 - f.0,
                LightKind::Point { position, .. } => {
                    (f.1 - f.0) * (position - (o + u0 * d)).length()
                }
            };
            // At most four times the span: a deep band's depth can reach across the cloud,
            // and a descent that far gathers thousands of spheres no segment asks for (measured:
            // uncapped, the thick cloud at N = 1e6 took 2.3 times as long).
            let end = (u0 + depth.min(4.0 * (u1 - u0))).min(t_end).max(u1);
            self.f = f;
            self.cover = (u0, end);
            self.near.clear();
            self.found.clear();
            let region = Region::band(light, o + u0 * d, o + end * d, f.0, f.1);
            gather(bvh, &region, &mut self.found, stack);
            // The same rounding allowance as the distance tests (the cover's, at least any
            // span's inside it).
            let pad = slack(bvh, &region);
            for &i in &self.found {
                let p = &bvh.packed()[i as usize];
                let (t0, t1) = reach_on_ray(light, o, d, p.center, p.radius + pad);
                self.near.push(Near { prim: i, t0, t1 });
            }
        }
        let region = Region::band(light, o + u0 * d, o + u1 * d, f.0, f.1);
        let slack = slack(bvh, &region);
        for n in &self.near {
            if n.t1 < u0 || n.t0 > u1 {
                continue;
            }
            if touches(&region, &bvh.packed()[n.prim as usize], slack) {
                out.push(n.prim);
            }
        }
    }
}

#[cfg(test)]
mod tests;
