//! Ambient occlusion as the sum of each sphere's own occlusion, clamped at 1: the analytic
//! per-occluder term of shaders, which treat every sphere as if it were alone.
//!
//! One sphere seen from a point blocks a cap of directions, whose cosine-weighted share of
//! the hemisphere is the sphere's form factor, in closed form with the horizon clipping it
//! (J. Snyder, "Area Light Sources for Real-Time Graphics", Microsoft Research
//! MSR-TR-96-11, 1996; S. Lagarde and C. de Rousiers, "Moving Frostbite to Physically Based
//! Rendering", SIGGRAPH 2014 course notes, sphere lights; the case above the horizon,
//! `cos θ (r / d)²`, in I. Quílez, "Sphere ambient occlusion",
//! <https://iquilezles.org/articles/sphereao/>). Shaders add these terms over the occluders
//! and clamp, `occlusion = min(1, Σ_j F_j)`, as M. Bunnell's dynamic ambient occlusion adds
//! its elements' ("Dynamic Ambient Occlusion and Indirect Lighting", GPU Gems 2, chapter 14,
//! 2005, which names the double counting of overlapping occluders and damps it with a
//! second pass; not done here). Where caps overlap, the overlap is counted twice, so the sum
//! overestimates occlusion; with one occluder it is exact.
//!
//! Parameters: none but the reach. Each `F_j` is the form factor of the cap sphere `j`
//! blocks within the reach (`blocked_by_ball`, the exact method's caps), over the spheres
//! the exact method considers (the BVH's region query), the sphere the point is on left out;
//! `Cap::form_factor` is the closed form. Shaders
//! that fade occluders with distance instead of cutting them at a reach are not modelled.

use glam::DVec3;

use super::super::cap::{blocked_by_ball, Blocked};
use crate::accel::SphereBvh;

/// The unoccluded fraction at `x` (unit normal `n`, on the BVH's primitive `own`):
/// `1 - min(1, Σ_j F_j)` over the opaque spheres within `reach`; 0 inside a sphere.
pub fn unoccluded(
    bvh: &SphereBvh,
    (x, n, own): (DVec3, DVec3, Option<u32>),
    reach: f64,
    stack: &mut Vec<u32>,
) -> f64 {
    let (mut total, mut everything) = (0.0, false);
    let reach2 = reach * reach;
    bvh.near_region(
        |lo, hi| {
            let below = (lo - x).max(DVec3::ZERO) + (x - hi).max(DVec3::ZERO);
            // The box's corner farthest along the normal.
            let top = DVec3::select(n.cmpge(DVec3::ZERO), hi, lo);
            below.length_squared() <= reach2 && (top - x).dot(n) > 0.0
        },
        |i, p| {
            if Some(i) == own || p.is_gas() || everything {
                return;
            }
            match blocked_by_ball(x, p.center, p.radius, reach) {
                Blocked::Nothing => {}
                Blocked::Cap(c) => total += c.form_factor(n),
                Blocked::Everything => everything = true,
            }
        },
        stack,
    );
    if everything {
        0.0
    } else {
        1.0 - total.min(1.0)
    }
}
