//! Light visibility `V_i(x)` (MODEL.md sections 2 and 3): 0 if an opaque sphere or another
//! opaque surface lies between `x` and the light, otherwise the transmittance `exp(-sum_j sigma_j chord_j)` of every gas
//! sphere the light ray crosses.

use glam::DVec3;

use super::integrators::surface::Opaque;
use super::Prepared;
use crate::accel::SphereBvh;

/// Visibility from `x` towards a light at unit direction `l`, distance `dist` (infinite for a
/// directional light). `own` is what `x` lies on, if anything: its own shadow is exact
/// from the sign of `N.L` (a sphere, a solid or a triangle is convex), so the caller decides
/// it and it is skipped here. The ray stops at the first opaque blocker, or once the optical depth
/// makes the transmittance underflow to 0.
///
/// Spheres are solid (one-sided, MODEL.md section 2): an opaque sphere blocks when the light
/// ray enters it, at its first root, between `x` and the light; a ray that starts inside an
/// opaque sphere and leaves it is not blocked by it, as a camera inside a sphere does not see
/// it. A gas sphere attenuates over the part of `[0, dist]` inside it.
#[inline]
pub fn visible(prep: &Prepared, x: DVec3, l: DVec3, dist: f64, own: Option<Opaque>) -> f64 {
    if !prep.surfaces.is_empty() {
        let own_surface = match own {
            Some(Opaque::Surface(i)) => Some(i),
            _ => None,
        };
        // Rounding of the hit point cannot make a neighbouring triangle (a shared edge) block
        // its own point's light ray further than this.
        let tmin = 256.0 * f64::EPSILON * x.abs().max_element();
        if prep.surfaces.blocks(x, l, tmin, dist, own_surface) {
            return 0.0;
        }
    }
    let own_sphere = match own {
        Some(Opaque::Sphere(p)) => Some(p),
        _ => None,
    };
    visible_through_spheres(&prep.bvh, x, l, dist, own_sphere)
}

/// [`visible`] against the spheres alone.
/// (A ray entry point: compiled again for AVX2, see `accel::bvh`.)
#[multiversion::multiversion(targets("x86_64+avx+avx2+fma+bmi1+bmi2+lzcnt+popcnt"))]
pub fn visible_through_spheres(
    bvh: &SphereBvh,
    x: DVec3,
    l: DVec3,
    dist: f64,
    own: Option<u32>,
) -> f64 {
    let mut tau = 0.0;
    let blocked = bvh.any_except(x, l, 0.0, dist, own, |_, p, (t0, t1)| {
        if p.is_gas() {
            let (a, b) = (t0.max(0.0), t1.min(dist));
            if b > a {
                tau += super::density::part_depth(bvh, p, x, l, (a, b));
            }
            // Past this, exp(-tau) is 0 in f64 whatever else the ray meets: stop (exactly the
            // same answer, for less work through dense gas).
            tau > 746.0
        } else {
            t0 > 0.0 && t0 < dist
        }
    });
    if blocked {
        0.0
    } else {
        (-tau).exp()
    }
}
