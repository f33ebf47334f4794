//! Where a light's single-scattering integrand along a camera ray is not smooth because of one
//! shadower (docs/model.md section 3). Along `x(t) = o + t d`, the light ray from `x(t)` crosses the
//! shadower `j` over a length `l_j(t)` that is smooth in `t` except where
//! - the light ray becomes tangent to the sphere: the camera ray crosses its shadow boundary, a
//!   cylinder along `L` (directional light) or a cone with apex `P` (point light); `l_j` behaves
//!   like a square root there. A point light exactly on the surface makes the cone a plane (the
//!   tangent plane at `P`), where `l_j` has a corner;
//! - `x(t)` crosses the sphere's surface (the chord changes form).
//!
//! A dense gas shadower (optical depth `tau_j` along its diameter far above 1) makes the
//! integrand `exp(-sigma_j l_j)` fall from 1 to `exp(-tau_j)` within a thin rim of its shadow,
//! far narrower than the shadow itself. The rim is resolved by more breakpoints: the shadow
//! boundaries of the concentric spheres on which the light ray's optical depth through `j` is
//! 2, 8, 32, ... (a chord `2 sqrt(r^2 - h^2)` has depth `tau` at `h^2 = r^2 (1 - (tau/tau_j)^2)`;
//! for a profiled shadower, docs/model.md section 6, the chord's depth `sigma0 r J(h / r)` is
//! solved for `h` by bisection, as `J` falls monotonically with `h`).
//!
//! Extra breakpoints cost a little work and never accuracy, so roots are kept without deciding
//! on which side of the sphere a tangency lies, or which nappe of a cone it is on.

use glam::{DAffine3, DVec3};

use super::lights::LightKind;
use crate::accel::Prim;
use crate::geom::sphere_roots;
use crate::scene::Profile;

/// Gas shadowers of at least this optical depth along a diameter get rim breakpoints.
const RIM_MIN_DEPTH: f64 = 6.0;

/// Roots of `qa t^2 + qb t + qc = 0` (stable form; a linear or empty equation handled).
fn quadratic(qa: f64, qb: f64, qc: f64, mut push: impl FnMut(f64)) {
    if qa == 0.0 {
        if qb != 0.0 {
            push(-qc / qb);
        }
        return;
    }
    let disc = qb * qb - 4.0 * qa * qc;
    if disc.is_nan() || disc < 0.0 {
        return;
    }
    let q = -0.5 * (qb + disc.sqrt().copysign(qb));
    push(q / qa);
    if q != 0.0 {
        push(qc / q);
    }
}

/// The camera line's crossings of the shadow boundary of the ball `(c, r)` (object frame of the
/// shadower: `o`, `d`, the light mapped alike).
fn boundary(o: DVec3, d: DVec3, c: DVec3, r: f64, light: Light, push: &mut impl FnMut(f64)) {
    match light {
        Light::Along(l) => {
            // Cylinder around the axis through c along L: a circle in the plane normal to L.
            let perp = |v: DVec3| v - v.dot(l) * l;
            if let Some((t0, t1)) = sphere_roots(perp(o - c), perp(d), DVec3::ZERO, r) {
                push(t0);
                push(t1);
            }
        }
        Light::At(pp) => {
            // Cone with apex P tangent to the ball: ((x-P).u)^2 = cos^2(alpha) |x-P|^2.
            let axis = c - pp;
            let dist2 = axis.length_squared();
            if dist2 == 0.0 {
                return;
            }
            let u = axis / dist2.sqrt();
            let g = o - pp;
            if dist2 <= r * r * (1.0 + 1e-6) {
                // P on (or within rounding of) the surface: the cone opens into the tangent
                // plane at P, where the chord has a corner. (Inside, no boundary at all; the
                // root is then merely an extra breakpoint.)
                let du = d.dot(u);
                if du != 0.0 {
                    push(-g.dot(u) / du);
                }
            }
            if dist2 > r * r {
                let k = 1.0 - r * r / dist2;
                let (gu, du) = (g.dot(u), d.dot(u));
                quadratic(
                    du * du - k * d.dot(d),
                    2.0 * (gu * du - k * g.dot(d)),
                    gu * gu - k * g.dot(g),
                    &mut *push,
                );
            }
        }
    }
}

/// The light in a shadower's object frame.
#[derive(Clone, Copy)]
enum Light {
    /// Unit direction towards a directional light.
    Along(DVec3),
    /// Position of a point light.
    At(DVec3),
}

/// Appends to `out` the breakpoints in `(ta, tb)` that shadower `p` causes along `o + t d` for
/// `light`. Ellipsoids are handled in their object space (an affine map keeps `t`). Rim
/// breakpoints go up to optical depth `rim_cap` (deeper ones are never needed: a piece that
/// dark is bounded, not integrated).
#[allow(clippy::too_many_arguments)]
pub fn breakpoints(
    p: &Prim,
    to_object: &[DAffine3],
    o: DVec3,
    d: DVec3,
    light: &LightKind,
    (ta, tb): (f64, f64),
    rim_cap: f64,
    out: &mut Vec<f64>,
) {
    let mut push = |t: f64| {
        if t > ta && t < tb {
            out.push(t);
        }
    };
    // The sphere in its own frame: centre c, radius r; o, d, light mapped alike. `scale` is
    // world length per object length along the light (ellipsoids; roughly, for point lights).
    let (m, c, r) = match p.ellipsoid {
        None => (None, p.center, p.radius),
        Some(e) => (Some(&to_object[e.index()]), DVec3::ZERO, 1.0),
    };
    let point = |x: DVec3| m.map_or(x, |m| m.transform_point3(x));
    let vector = |x: DVec3| m.map_or(x, |m| m.transform_vector3(x));
    let (o, d) = (point(o), vector(d));
    if let Some((t0, t1)) = sphere_roots(o, d, c, r) {
        push(t0);
        push(t1);
    }
    let (lt, world_per_object) = match *light {
        LightKind::Directional { to_light, .. } => {
            let v = vector(to_light);
            (Light::Along(v.normalize()), 1.0 / v.length())
        }
        LightKind::Point { position, .. } => {
            let v = vector(p.center - position);
            let w = (p.center - position).length();
            (
                Light::At(point(position)),
                if v.length() > 0.0 {
                    w / v.length()
                } else {
                    1.0
                },
            )
        }
    };
    boundary(o, d, c, r, lt, &mut push);
    if p.is_gas() {
        // The optical depth along a diameter, and the distance from the centre (in radii) at
        // which a full chord has `tau` of it.
        let depth = 2.0 * p.sigma * r * world_per_object * p.profile.integral();
        if depth >= RIM_MIN_DEPTH {
            let mut tau = 2.0;
            while tau < depth && tau <= rim_cap {
                let q = tau / depth;
                let beta = if p.is_profiled() {
                    profiled_contour(p.profile, q)
                } else {
                    ((1.0 - q) * (1.0 + q)).sqrt()
                };
                boundary(o, d, c, r * beta, lt, &mut push);
                tau *= 4.0;
            }
        }
    }
}

/// The distance `beta` from the centre (in radii) at which a full chord through a ball of
/// profile `profile` has the part `q` in (0, 1) of the diameter's optical depth, to about
/// 1e-4 (a breakpoint need not lie exactly on the contour: it only helps the quadrature): the
/// chord's depth falls monotonically as `beta` grows.
fn profiled_contour(profile: Profile, q: f64) -> f64 {
    let full = |beta: f64| profile.line_integral(beta, -1.0, 1.0);
    let target = q * full(0.0);
    let (mut lo, mut hi) = (0.0f64, 1.0f64);
    for _ in 0..14 {
        let mid = 0.5 * (lo + hi);
        if full(mid) > target {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    0.5 * (lo + hi)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The unit ball at the origin, gas of extinction `sigma` (opaque for 0).
    fn unit_ball(sigma: f64) -> Prim {
        Prim {
            center: DVec3::ZERO,
            radius: 1.0,
            color: crate::scene::Color::default(),
            material: 0,
            sphere: 0,
            ellipsoid: None,
            gas: sigma > 0.0,
            sigma,
            profile: crate::scene::Profile::Constant,
        }
    }

    /// The degenerate cone of a point light on the surface gives the tangent-plane crossing.
    #[test]
    fn light_on_the_surface_gives_the_tangent_plane() {
        let p = unit_ball(0.0);
        let light = LightKind::Point {
            position: DVec3::new(0.0, 1.0, 0.0),
            attenuation: DVec3::X,
            radius: 100.0,
        };
        // A camera line parallel to y through x = 3 crosses the plane y = 1 at t = 1.
        let mut out = Vec::new();
        breakpoints(
            &p,
            &[],
            DVec3::new(3.0, 0.0, 0.0),
            DVec3::Y,
            &light,
            (-10.0, 10.0),
            100.0,
            &mut out,
        );
        assert!(out.iter().any(|t| (t - 1.0).abs() < 1e-12), "{out:?}");
    }

    /// `p`'s breakpoints along the camera line `y = 0, z = -5` (along x from x = -3, so that
    /// `t - 3` is the offset from the centre) for a directional light along +z, every rim
    /// contour included.
    fn rim_breakpoints(p: &Prim) -> Vec<f64> {
        let light = LightKind::Directional {
            to_light: DVec3::Z,
            scope: crate::scene::LightScope::All,
            surface_scope: crate::scene::LightScope::All,
        };
        let mut out = Vec::new();
        breakpoints(
            p,
            &[],
            DVec3::new(-3.0, 0.0, -5.0),
            DVec3::X,
            &light,
            (-10.0, 10.0),
            1e9,
            &mut out,
        );
        out
    }

    /// A dense gaussian shadower's rim breakpoints lie on its own depth contours (where a
    /// full chord has depth 2, 8, 32, ...), not on a constant sphere's.
    #[test]
    fn profiled_rim_breakpoints_sit_on_the_profiles_contours() {
        let mut p = unit_ball(0.0);
        p.gas = true;
        p.profile = Profile::Gaussian { width: 0.3 };
        p.sigma = 400.0; // depth 2 sigma0 I_f, about 300, along the diameter
        let out = rim_breakpoints(&p);
        // The chord at offset |x| from the centre, by Simpson's rule (not the closed form).
        let depth = |x: f64| {
            let h = (1.0 - x * x).max(0.0).sqrt();
            let n = 2000;
            let f = |v: f64| (-(x * x + v * v) / (2.0 * 0.09)).exp();
            let step = 2.0 * h / n as f64;
            p.sigma
                * (0..n)
                    .map(|k| {
                        let a = -h + k as f64 * step;
                        step / 6.0 * (f(a) + 4.0 * f(a + 0.5 * step) + f(a + step))
                    })
                    .sum::<f64>()
        };
        for tau in [2.0, 8.0, 32.0, 128.0] {
            let found = out
                .iter()
                .any(|&t| (depth(t - 3.0) - tau).abs() < 2e-3 * tau);
            assert!(found, "no breakpoint at depth {tau}: {out:?}");
        }
    }

    /// Rim breakpoints of a dense gas shadower lie where its optical depth is 2, 8, 32, ...
    #[test]
    fn rim_breakpoints_sit_on_the_depth_contours() {
        let sigma = 350.0; // depth 700 along the diameter of the unit ball
        let p = unit_ball(sigma);
        // The chord at offset |x| from the centre is 2 sqrt(1 - x^2).
        let out = rim_breakpoints(&p);
        for tau in [2.0, 8.0, 32.0, 128.0, 512.0] {
            let found = out.iter().any(|&t| {
                let x: f64 = t - 3.0;
                let chord = 2.0 * (1.0 - x * x).max(0.0).sqrt();
                (sigma * chord - tau).abs() < 1e-6 * tau
            });
            assert!(found, "no breakpoint at depth {tau}: {out:?}");
        }
    }
}
