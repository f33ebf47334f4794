//! The directions an occluding sphere blocks: a spherical cap, exactly (docs/model.md
//! section 11).

use glam::DVec3;

/// A cap of the unit sphere of directions: the unit vectors `w` with `axis . w >= cos`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Cap {
    /// The cap's centre, a unit vector.
    pub axis: DVec3,
    /// The cosine of its angular radius, in `[0, 1)`.
    pub cos: f64,
}

/// How far inside a sphere, relative to its radius, a point is still on its surface.
const ON_SURFACE: f64 = 1e-10;

/// What one sphere does to the directions from a point.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Blocked {
    /// No direction: the sphere is beyond the reach.
    Nothing,
    /// The directions of a cap.
    Cap(Cap),
    /// Every direction: the point is inside the sphere.
    Everything,
}

/// The directions from `p` whose rays meet the ball of centre `c` and radius `r` at a
/// distance of at most `reach` (`f64::INFINITY`: any distance).
///
/// Seen from a distance `d > r`, the ball fills the cap of angular radius `asin(r / d)`
/// about the direction to its centre. A ray within that cone meets the sphere first at a
/// distance that grows with its angle from the axis, so a reach shorter than the tangent
/// length `sqrt(d^2 - r^2)` keeps the directions whose first hit is within it: again a cap
/// about the same axis, whose boundary rays meet the sphere at exactly `reach`, which gives
/// `cos = (d^2 + reach^2 - r^2) / (2 d reach)`. A point on the sphere (`d = r`) sees a
/// hemisphere blocked; so does a point within `1e-10 r` inside it, which is on its surface
/// to the rounding of a ray's hit point.
pub fn blocked_by_ball(p: DVec3, c: DVec3, r: f64, reach: f64) -> Blocked {
    let v = c - p;
    let d = v.length();
    if d < r * (1.0 - ON_SURFACE) {
        return Blocked::Everything;
    }
    if d - r >= reach || d == 0.0 {
        return Blocked::Nothing;
    }
    // (d - r)(d + r) rather than d^2 - r^2: a point near the surface keeps its digits.
    let tangent2 = ((d - r) * (d + r)).max(0.0);
    let cos = if reach * reach >= tangent2 {
        tangent2.sqrt() / d
    } else {
        (tangent2 + reach * reach) / (2.0 * d * reach)
    };
    Blocked::Cap(Cap {
        axis: v / d,
        cos: cos.clamp(0.0, 1.0),
    })
}

/// The cosine-weighted fraction of the hemisphere about a unit normal that one cap covers,
/// the cap's axis at angle θ from the normal (`x = cos θ`, `st = sin θ >= 0`) and its angular
/// radius α (`c = cos α`): the sphere form factor (Snyder 1996; Lagarde and de Rousiers 2014).
/// With `D = sin²α - cos²θ` the formula's inverse cosine and tangent are written as `atan2`s
/// of `√D`, which keep their digits where the cap's edge grazes the horizon (`D` near 0).
pub fn form_factor(x: f64, st: f64, c: f64) -> f64 {
    let sin2 = (1.0 - c) * (1.0 + c);
    // D as a product of differences, from whichever pair is better conditioned.
    let d = if x.abs() < 0.7 {
        (sin2.sqrt() - x.abs()) * (sin2.sqrt() + x.abs())
    } else {
        (st - c) * (st + c)
    };
    if d <= 0.0 {
        // Wholly above the horizon, or wholly below it.
        return (x * sin2).max(0.0);
    }
    let rd = d.sqrt();
    (x * sin2 * rd.atan2(-c * x) - c * rd + rd.atan2(c)) / std::f64::consts::PI
}

impl Cap {
    /// The cosine-weighted fraction of the hemisphere about the unit normal `n` that this cap
    /// covers ([`form_factor`]).
    pub fn form_factor(&self, n: DVec3) -> f64 {
        form_factor(self.axis.dot(n), self.axis.cross(n).length(), self.cos)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Whether the ray from `p` along `w` meets the ball within `reach`, by the quadratic.
    fn ray_meets(p: DVec3, w: DVec3, c: DVec3, r: f64, reach: f64) -> bool {
        let v = c - p;
        let b = v.dot(w);
        let disc = b * b - (v.length_squared() - r * r);
        disc >= 0.0 && b - disc.sqrt() <= reach && b + disc.sqrt() > 0.0
    }

    #[test]
    fn the_cap_is_the_set_of_rays_that_meet_the_ball_within_reach() {
        // Directions sampled around the cap's boundary: just inside it a ray meets the ball
        // within the reach, just outside it does not.
        let p = DVec3::new(0.3, -0.2, 0.1);
        for (c, r, reach) in [
            (DVec3::new(3.0, 1.0, 0.5), 1.0, f64::INFINITY),
            (DVec3::new(3.0, 1.0, 0.5), 1.0, 2.9),
            (DVec3::new(3.0, 1.0, 0.5), 1.0, 2.3),
            (DVec3::new(0.3, 2.3, 0.1), 2.0, 0.8),
        ] {
            let Blocked::Cap(cap) = blocked_by_ball(p, c, r, reach) else {
                panic!("a cap for {c} {r} {reach}");
            };
            let (e1, e2) = cap.axis.any_orthonormal_pair();
            let sin = (1.0 - cap.cos * cap.cos).sqrt();
            for k in 0..16 {
                let phi = f64::from(k) * 0.39;
                let side = e1 * phi.cos() + e2 * phi.sin();
                for (eps, inside) in [(-1e-7, true), (1e-7, false)] {
                    let (c2, s2) = (cap.cos - eps, sin + eps * cap.cos / sin);
                    let w = (cap.axis * c2 + side * s2).normalize();
                    assert_eq!(ray_meets(p, w, c, r, reach), inside, "{c} {r} {reach} {k}");
                }
            }
        }
    }

    #[test]
    fn beyond_reach_inside_and_on_the_sphere() {
        let c = DVec3::new(0.0, 0.0, 3.0);
        assert_eq!(blocked_by_ball(DVec3::ZERO, c, 1.0, 2.0), Blocked::Nothing);
        assert_eq!(
            blocked_by_ball(DVec3::ZERO, c, 3.5, 1.0),
            Blocked::Everything
        );
        let Blocked::Cap(on) = blocked_by_ball(DVec3::ZERO, c, 3.0, 1.0) else {
            panic!("a hemisphere")
        };
        assert_eq!((on.axis, on.cos), (DVec3::Z, 0.0));
    }
}
