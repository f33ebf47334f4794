//! Light visibility `V_i(x)` (MODEL.md section 2): 0 if an opaque sphere lies between `x` and
//! the light. (Transmittance through gas joins here with the gas integrators.)

use glam::DVec3;

use crate::accel::SphereBvh;

/// Visibility from `x` towards a light at unit direction `l`, distance `dist` (infinite for a
/// directional light). `own` is the primitive `x` lies on: its own shadow is exact from the
/// sign of `N.L` (a sphere is convex), so the caller decides it and it is skipped here.
///
/// Spheres are solid (one-sided, MODEL.md section 2): a sphere blocks when the shadow ray
/// enters it, at its first root, between `x` and the light; a ray that starts inside a sphere
/// and leaves it is not blocked by it, as a camera inside a sphere does not see it.
#[inline]
pub fn visible(bvh: &SphereBvh, x: DVec3, l: DVec3, dist: f64, own: u32) -> f64 {
    let blocked = bvh.any(x, l, 0.0, dist, |i, p, (t0, _)| {
        i != own && !p.is_gas() && t0 > 0.0 && t0 < dist
    });
    if blocked {
        0.0
    } else {
        1.0
    }
}
