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
    visible_after(prep, x, l, dist, own, &mut None)
}

/// The opaque spheres that last blocked a shadow ray towards each of the first
/// [`Blockers::LIGHTS`] lights (by index in the view), to be tried before the BVH: a shadow ray
/// from a point next to the last one is often blocked by the same sphere, and then one exact
/// sphere test answers it. Speed only: [`visible_after`] answers exactly what [`visible`]
/// does, whatever the slots hold (any sphere index, of any scene, or none).
#[derive(Clone, Copy, Debug, Default)]
pub struct Blockers([Option<u32>; Blockers::LIGHTS]);

impl Blockers {
    /// Lights with a slot; the others' rays go straight to the BVH.
    pub const LIGHTS: usize = 8;

    /// Light `k`'s slot, if it has one.
    #[inline]
    pub fn slot(&mut self, k: usize) -> Option<&mut Option<u32>> {
        self.0.get_mut(k)
    }
}

/// [`visible`], first trying the sphere in `last` (the one that blocked the previous ray
/// towards the same light), and leaving in it the opaque sphere that blocked this one, if the
/// BVH found one. The answer is [`visible`]'s, bit for bit: an opaque sphere that `last` names
/// and that blocks this ray is one the BVH's any-hit query could have stopped at.
#[inline]
pub fn visible_after(
    prep: &Prepared,
    x: DVec3,
    l: DVec3,
    dist: f64,
    own: Option<Opaque>,
    last: &mut Option<u32>,
) -> f64 {
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
    visible_through_spheres(&prep.bvh, x, l, dist, own_sphere, last)
}

/// [`visible_after`] against the spheres alone.
/// (A ray entry point: compiled again for AVX2, see `accel::bvh`.)
#[multiversion::multiversion(targets("x86_64+avx+avx2+fma+bmi1+bmi2+lzcnt+popcnt"))]
pub fn visible_through_spheres(
    bvh: &SphereBvh,
    x: DVec3,
    l: DVec3,
    dist: f64,
    own: Option<u32>,
    last: &mut Option<u32>,
) -> f64 {
    // The last blocker first, with the test the traversal's closure makes below (never the
    // point's own sphere, which the traversal skips; never gas, whose depth only adds up).
    if let Some(i) = last.filter(|&i| Some(i) != own && (i as usize) < bvh.len()) {
        if !bvh.packed()[i as usize].is_gas() {
            if let Some((t0, _)) = bvh.roots_of(i, x, l) {
                if t0 > 0.0 && t0 < dist {
                    return 0.0;
                }
            }
        }
    }
    let mut tau = 0.0;
    let mut blocker = None;
    let blocked = bvh.any_except(x, l, 0.0, dist, own, |i, p, (t0, t1)| {
        if p.is_gas() {
            let (a, b) = (t0.max(0.0), t1.min(dist));
            if b > a {
                tau += super::density::part_depth(bvh, p, x, l, (a, b));
            }
            // Past this, exp(-tau) is 0 in f64 whatever else the ray meets: stop (exactly the
            // same answer, for less work through dense gas).
            tau > 746.0
        } else {
            let blocks = t0 > 0.0 && t0 < dist;
            if blocks {
                blocker = Some(i);
            }
            blocks
        }
    });
    if blocker.is_some() {
        *last = blocker;
    }
    if blocked {
        0.0
    } else {
        (-tau).exp()
    }
}
