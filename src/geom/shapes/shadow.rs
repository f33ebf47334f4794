//! Where one primitive's shadow can begin or end along a camera ray.
//!
//! The shadowed set of a surface `S` is `{x : the light ray from x meets S}`: `S` swept away
//! from the light. Its boundary lies on
//! - `S` itself (the light ray's start `s = 0` crosses `S`): the camera ray's crossings of the
//!   whole unbounded surfaces (infinite cylinder, double cone, every face plane), class
//!   [`SURFACE`]. A plane also covers a light that grazes it, where the plane is the boundary;
//! - the sweep of the silhouette, light rays tangent to a curved part, class [`TANGENT`]:
//!   the two planes parallel to the cylinder's axis, tangent to it and containing the light
//!   direction (directional) or the light point (point light); the two planes through the cone's
//!   apex tangent to it and containing the light direction or point;
//! - the sweep of the boundary curves, class [`BOUNDARY`]: the planes through a box or
//!   triangle edge and the light direction or point (they also cover the vertices); for a rim
//!   circle, the oblique cylinder (directional) or cone (point light) over the circle, a
//!   quadric crossed at the roots of a quadratic in `t`.
//!
//! A point light's end of the light ray (`s = 1`) does not move with `t`. Degenerate views
//! need nothing more: a light along the cylinder's axis has no tangent planes, and its
//! boundary is the infinite cylinder (class [`SURFACE`]; the rim quadrics degenerate to it
//! too); a point light inside the infinite cylinder has no tangents either; a camera ray
//! parallel to a plane never crosses it.
//!
//! Candidates are kept without asking which side of a tangency, which nappe or which part of a
//! plane they are on: extra candidates only cost work.

use glam::DVec3;

use super::quadrics::{conic, roots};
use super::triangle_hit;
use super::{ShadowLight, Shape, Solid};

/// Candidate classes, for tests that leave one out: the surfaces themselves.
pub(super) const SURFACE: u8 = 1;
/// Silhouette sweeps of curved parts.
pub(super) const TANGENT: u8 = 2;
/// Sweeps of rims and edges.
pub(super) const BOUNDARY: u8 = 4;
pub(super) const ALL: u8 = SURFACE | TANGENT | BOUNDARY;

/// Whether the light ray from x crosses the surface (of the solid: `Solid::blocks` over the
/// light ray's parameter range; for a triangle, `triangle_hit`).
pub fn shadowed(shape: &Shape, x: DVec3, light: &ShadowLight) -> bool {
    let (dir, smax) = match *light {
        ShadowLight::Directional { to_light } => (to_light, f64::INFINITY),
        ShadowLight::Point { position } => (position - x, 1.0),
    };
    match *shape {
        Shape::Solid(s) => s.blocks(x, dir, 0.0, smax),
        Shape::Triangle(p) => triangle_hit(p, x, dir, 0.0, smax).is_some(),
    }
}

/// Candidate parameters t in the open interval (ta, tb) of the camera ray o + t d such that,
/// between any two consecutive candidates (with ta and tb added),
/// `shadowed(shape, o + t d, light)` is constant, except possibly on a set of measure zero.
/// Appended to `out`, unsorted; duplicates and extra candidates are allowed (they cost only
/// work), a MISSING candidate is a bug.
///
/// Pushes at most 18 values for a cuboid (6 faces, 12 edges), 10 for a cylinder, 9 for a
/// cone, 4 for a triangle.
pub fn shadow_breaks(
    shape: &Shape,
    o: DVec3,
    d: DVec3,
    light: &ShadowLight,
    range: (f64, f64),
    out: &mut Vec<f64>,
) {
    breaks(shape, o, d, light, range, ALL, out);
}

/// [`shadow_breaks`] restricted to the candidate classes in `classes`.
pub(super) fn breaks(
    shape: &Shape,
    o: DVec3,
    d: DVec3,
    light: &ShadowLight,
    (ta, tb): (f64, f64),
    classes: u8,
    out: &mut Vec<f64>,
) {
    let start = out.len();
    let lit = match *light {
        ShadowLight::Directional { to_light } => to_light.is_finite(),
        ShadowLight::Point { position } => position.is_finite(),
    };
    if lit && o.is_finite() && d.is_finite() && d != DVec3::ZERO {
        let mut c = Cands {
            o,
            d,
            light: *light,
            out: &mut *out,
        };
        let want = |class: u8| classes & class != 0;
        match *shape {
            Shape::Solid(&Solid::Cuboid { half }) => c.cuboid(half, want),
            Shape::Solid(&Solid::Cylinder {
                radius,
                half_height,
                ..
            }) => c.cylinder(radius, half_height, want),
            Shape::Solid(&Solid::Cone {
                radius,
                half_height,
                ..
            }) => c.cone(radius, half_height, want),
            Shape::Triangle(p) => c.triangle(p, want),
        }
    }
    // Keep the new candidates inside (ta, tb): drops NaN and infinities too.
    let mut i = start;
    while i < out.len() {
        if ta < out[i] && out[i] < tb {
            i += 1;
        } else {
            out.swap_remove(i);
        }
    }
}

/// The camera ray, the light and the candidate list.
struct Cands<'a> {
    o: DVec3,
    d: DVec3,
    light: ShadowLight,
    out: &'a mut Vec<f64>,
}

impl Cands<'_> {
    /// Where the camera ray meets the plane `n . (x - p) = 0` (NaN or infinite if parallel).
    fn plane(&mut self, n: DVec3, p: DVec3) {
        self.out.push(n.dot(p - self.o) / n.dot(self.d));
    }

    /// The plane through the line `p + s e` and the light (its direction, or its point).
    fn edge_plane(&mut self, p: DVec3, e: DVec3) {
        let to_light = match self.light {
            ShadowLight::Directional { to_light } => to_light,
            ShadowLight::Point { position } => position - p,
        };
        self.plane(e.cross(to_light), p);
    }

    /// Roots of the quadratic [`conic`] along `v0 + t v1`: both real roots; if the
    /// discriminant rounds below 0, the vertex of the parabola (where a pair of roots of a
    /// nearly tangent crossing would be); the single root of a linear equation.
    fn conic(&mut self, v0: DVec3, v1: DVec3, r2: f64) {
        let (a, b, c, disc) = conic(v0, v1, r2);
        if a == 0.0 {
            self.out.push(-c / (2.0 * b));
        } else if disc >= 0.0 {
            let (t0, t1) = roots(a, b, c, disc);
            self.out.extend([t0, t1]);
        } else {
            self.out.push(-b / a);
        }
    }

    /// The camera ray's crossings of the sweep of the circle `x^2 + z^2 = r^2, y = yc` along the
    /// light rays.
    ///
    /// The light ray from `x` meets the plane `y = yc` at `x + s (l - x)` (point light `l`) with
    /// `s = (yc - x_y) / (l_y - x_y)`; times `m = l_y - x_y` that point is
    /// `(l_y - yc) x_xz + (yc - x_y) l_xz`, linear in `t` like `m`, so the condition
    /// `|point|^2 = r^2 m^2` is a quadric, a cone with apex `l`. For a directional light `w`,
    /// `m = w_y` and the point is `w_y x_xz + (yc - x_y) w_xz`: an oblique cylinder. Homogeneous
    /// forms: no division by `m`, so a light nearly in the plane gives no overflow.
    fn rim(&mut self, yc: f64, r: f64) {
        let (o, d) = (self.o, self.d);
        let (v0, v1) = match self.light {
            ShadowLight::Directional { to_light: w } => (
                DVec3::new(
                    w.y * o.x + (yc - o.y) * w.x,
                    w.y * o.z + (yc - o.y) * w.z,
                    w.y,
                ),
                DVec3::new(w.y * d.x - d.y * w.x, w.y * d.z - d.y * w.z, 0.0),
            ),
            ShadowLight::Point { position: l } => {
                let e = l.y - yc;
                (
                    DVec3::new(
                        e * o.x + (yc - o.y) * l.x,
                        e * o.z + (yc - o.y) * l.z,
                        l.y - o.y,
                    ),
                    DVec3::new(e * d.x - d.y * l.x, e * d.z - d.y * l.z, -d.y),
                )
            }
        };
        self.conic(v0, v1, r * r);
    }

    fn cuboid(&mut self, half: DVec3, want: impl Fn(u8) -> bool) {
        for i in 0..3 {
            let mut axis = DVec3::ZERO;
            axis[i] = 1.0;
            if want(SURFACE) {
                self.plane(axis, half * axis);
                self.plane(axis, -half * axis);
            }
            if want(BOUNDARY) {
                // The four edges along axis i, from their corner at x_i = -half_i.
                let (j, k) = ((i + 1) % 3, (i + 2) % 3);
                for (sj, sk) in [(1.0, 1.0), (1.0, -1.0), (-1.0, 1.0), (-1.0, -1.0)] {
                    let mut p = -half * axis;
                    (p[j], p[k]) = (sj * half[j], sk * half[k]);
                    self.edge_plane(p, 2.0 * half * axis);
                }
            }
        }
    }

    fn cylinder(&mut self, r: f64, h: f64, want: impl Fn(u8) -> bool) {
        let (o, d) = (self.o, self.d);
        if want(SURFACE) {
            self.conic(DVec3::new(o.x, o.z, 1.0), DVec3::new(d.x, d.z, 0.0), r * r);
            self.plane(DVec3::Y, DVec3::new(0.0, h, 0.0));
            self.plane(DVec3::Y, DVec3::new(0.0, -h, 0.0));
        }
        if want(TANGENT) {
            match self.light {
                ShadowLight::Directional { to_light: w } => {
                    // Planes n . x = +-r |n| with n = y x w (horizontal, across w).
                    let n = DVec3::new(w.z, 0.0, -w.x);
                    let at = n * (r / w.x.hypot(w.z));
                    self.plane(n, at);
                    self.plane(n, -at);
                }
                ShadowLight::Point { position: l } => {
                    // Tangents from l_xz to the circle: lines n . x = r |l|^2 through l with
                    // n = r l_xz +- sqrt(|l|^2 - r^2) l_xz^perp (|n| = |l|^2). Clamped at 0,
                    // so a light on or just inside the surface still gets its tangent plane.
                    let s = ((l.x * l.x + l.z * l.z) - r * r).max(0.0).sqrt();
                    for s in [s, -s] {
                        let n = DVec3::new(r * l.x - s * l.z, 0.0, r * l.z + s * l.x);
                        self.plane(n, l);
                    }
                }
            }
        }
        if want(BOUNDARY) {
            self.rim(h, r);
            self.rim(-h, r);
        }
    }

    fn cone(&mut self, r: f64, h: f64, want: impl Fn(u8) -> bool) {
        let (o, d) = (self.o, self.d);
        let k = r / (2.0 * h);
        let apex = DVec3::new(0.0, h, 0.0);
        if want(SURFACE) {
            let v0 = DVec3::new(o.x, o.z, h - o.y);
            self.conic(v0, DVec3::new(d.x, d.z, -d.y), k * k);
            self.plane(DVec3::Y, -apex);
            self.plane(DVec3::Y, apex);
        }
        if want(TANGENT) {
            // In the apex frame (x, z, u = h - y) the cone is |v_xz| = k u, and the tangent
            // plane along the generator of radial direction c_hat has normal (c_hat, -k). It
            // contains the light direction w (point light: l - apex) when
            // c_hat . w_xz = k w_u: c_hat |w_xz|^2 = k w_u w_xz +- sqrt(|w_xz|^2 - k^2 w_u^2)
            // w_xz^perp. Clamped at 0: a light along a generator gets its one plane. Also the
            // plane through the axis and w, an extra candidate.
            let w = match self.light {
                ShadowLight::Directional { to_light } => to_light,
                ShadowLight::Point { position } => position - apex,
            };
            let (wx, wz, wu) = (w.x, w.z, -w.y);
            let om2 = wx * wx + wz * wz;
            let s = (om2 - (k * wu) * (k * wu)).max(0.0).sqrt();
            for s in [s, -s] {
                let (nx, nz) = (k * wu * wx - s * wz, k * wu * wz + s * wx);
                // n_u = -k om2 on u = h - y is +k om2 on y.
                self.plane(DVec3::new(nx, k * om2, nz), apex);
            }
            self.plane(DVec3::new(wz, 0.0, -wx), apex);
        }
        if want(BOUNDARY) {
            self.rim(-h, r);
        }
    }

    fn triangle(&mut self, p: &[DVec3; 3], want: impl Fn(u8) -> bool) {
        if want(SURFACE) {
            self.plane((p[1] - p[0]).cross(p[2] - p[0]), p[0]);
        }
        if want(BOUNDARY) {
            for i in 0..3 {
                let j = (i + 1) % 3;
                self.edge_plane(p[i], p[j] - p[i]);
            }
        }
    }
}
