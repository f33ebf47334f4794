//! Profiled gas along a line (docs/model.md section 6): where a gas primitive's density
//! `sigma0 f(u)` lies along `o + t d`, its density at `t`, and the optical depth of any part
//! of the line in closed form ([`Profile::line_integral`]). The integrators use it for camera
//! rays and light rays alike; constant gas keeps its own, older arithmetic (section 3) so
//! that its pictures do not change by a bit.
//!
//! A primitive's object space is its unit ball: `(x - c) / r` for a sphere, the inverse of
//! the Transform for an ellipsoid (then `u` is measured there, and the density follows the
//! ellipsoid's shape). The line maps to `q(t) = q0 + t e`; with `k = |e|`, its closest
//! approach to the centre is at `t_c = -q0.e / k^2`, at `beta = |q(t_c)|`, and
//! `u(t)^2 = beta^2 + v^2` with `v = k (t - t_c)`. So the optical depth of `[t0, t1]` is
//! `sigma0 J(beta, v0, v1) / k` (for a sphere `1 / k = r |d|^-1`).

use glam::DVec3;

use super::profile::Profile;
use super::Prepared;
use crate::accel::{Prim, SphereBvh};

/// A profiled gas primitive along one line.
#[derive(Clone, Copy, Debug)]
pub struct Along {
    /// The closest approach to the centre (line parameter).
    pub tc: f64,
    /// Its distance from the centre, in radii (object space).
    pub beta: f64,
    /// `v` (radii) per unit of the line parameter.
    pub k: f64,
    pub sigma0: f64,
    pub profile: Profile,
}

impl Along {
    /// Primitive `p` along `o + t d` (`d` need not be a unit vector).
    #[inline]
    pub fn new(bvh: &SphereBvh, p: &Prim, o: DVec3, d: DVec3) -> Along {
        let (q0, e) = match p.ellipsoid {
            None => ((o - p.center) / p.radius, d / p.radius),
            Some(m) => {
                let m = &bvh.to_object[m.index()];
                (m.transform_point3(o), m.transform_vector3(d))
            }
        };
        let k2 = e.length_squared();
        let tc = -q0.dot(e) / k2;
        Along {
            tc,
            beta: (q0 + tc * e).length(),
            k: k2.sqrt(),
            sigma0: p.sigma,
            profile: p.profile,
        }
    }

    /// The optical depth of `[t0, t1]` (0 where the line misses the ball; infinite ends
    /// allowed).
    #[inline]
    pub fn depth(&self, t0: f64, t1: f64) -> f64 {
        if t1 <= t0 {
            return 0.0;
        }
        let j =
            self.profile
                .line_integral(self.beta, self.k * (t0 - self.tc), self.k * (t1 - self.tc));
        self.sigma0 * j / self.k
    }

    /// The extinction at `t`: `sigma0 f(u(t))`, 0 outside the ball.
    #[inline]
    pub fn density(&self, t: f64) -> f64 {
        let v = self.k * (t - self.tc);
        self.sigma0 * self.profile.f((self.beta * self.beta + v * v).sqrt())
    }

    /// Where the density is not smooth along the line inside the ball: the linear profile's
    /// kink at the closest approach to the centre (`f = 1 - sqrt(beta^2 + v^2)` bends there,
    /// sharply when `beta` is small).
    #[inline]
    pub fn kink(&self) -> Option<f64> {
        (self.profile == Profile::Linear && self.beta < 1.0).then_some(self.tc)
    }
}

/// The length of the light ray `x + s dir`, `s` in `[0, dist]` (`dir` unit), inside the gas
/// shadower `p`. For a sphere, in plain f64: the offset `v` of the centre from the line is
/// formed directly (not as a difference of squares), the half chord is
/// `sqrt((r - |v|)(r + |v|))`, and a chord wholly inside `[0, dist]` is twice that rather than
/// a difference of two roots. Near a tangency the absolute error is about
/// `eps |x - c| r / chord`, negligible against the chord except within ~1e-13 of the
/// tangency, where the chord's contribution is itself below rounding. (The careful roots of
/// `geom::sphere_roots` decide hits to 1e-15; here every call is on a shadower known to be
/// active, so that care buys nothing and costs a third of the integrand.)
#[inline]
pub fn gas_chord(prep: &Prepared, p: &Prim, x: DVec3, dir: DVec3, dist: f64) -> f64 {
    if p.ellipsoid.is_some() {
        return match prep.bvh.roots(p, x, dir) {
            Some((t0, t1)) => (t1.min(dist) - t0.max(0.0)).max(0.0),
            None => 0.0,
        };
    }
    let f = x - p.center;
    let b = f.dot(dir);
    let h = (f - b * dir).length();
    // Also false for NaN.
    if h.partial_cmp(&p.radius) != Some(std::cmp::Ordering::Less) {
        return 0.0;
    }
    let half = ((p.radius - h) * (p.radius + h)).sqrt();
    let (t0, t1) = (-b - half, -b + half);
    if t0 >= 0.0 && t1 <= dist {
        2.0 * half
    } else {
        (t1.min(dist) - t0.max(0.0)).max(0.0)
    }
}

/// The optical depth of the light ray `x + s dir`, `s` in `[0, dist]` (`dir` a unit vector),
/// through the gas primitive `p`, whatever its profile. Constant gas: `sigma` times the chord
/// ([`gas_chord`]). (Always inlined, the profiled part never: the
/// constant case is the quadrature's innermost loop, and inlining the closed forms into it
/// kept the whole from being inlined there, 5 % of constant gas's time.)
#[inline(always)]
pub fn gas_depth(prep: &Prepared, p: &Prim, x: DVec3, dir: DVec3, dist: f64) -> f64 {
    if p.is_profiled() {
        profiled_depth(&prep.bvh, p, x, dir, (0.0, dist))
    } else {
        p.sigma * gas_chord(prep, p, x, dir, dist)
    }
}

/// [`gas_depth`] of the part `[t0, t1]` (known to lie inside the primitive, as the BVH's
/// roots give it) of the line `x + s dir`; constant gas: `sigma (t1 - t0)`.
#[inline(always)]
pub fn part_depth(bvh: &SphereBvh, p: &Prim, x: DVec3, dir: DVec3, (t0, t1): (f64, f64)) -> f64 {
    if p.is_profiled() {
        profiled_depth(bvh, p, x, dir, (t0, t1))
    } else {
        p.sigma * (t1 - t0)
    }
}

#[inline(never)]
fn profiled_depth(bvh: &SphereBvh, p: &Prim, x: DVec3, dir: DVec3, (t0, t1): (f64, f64)) -> f64 {
    Along::new(bvh, p, x, dir).depth(t0, t1)
}
