//! Ambient occlusion from a fixed set of directions over the whole sphere, as ChimeraX's
//! multishadow lighting computes it.
//!
//! ChimeraX's `lighting multiShadow K` casts shadows from K directions (64 in its `soft` and
//! `full` presets, 0 by default;
//! <https://www.cgl.ucsf.edu/chimerax/docs/user/commands/lighting.html>).
//!
//! ChimeraX renders one depth (shadow) map along each of K directions spread over the
//! sphere, `sphere_points(K)` of its geometry bundle (`src/bundles/geometry/src/sphere.py`):
//! Bauer's spiral, `φ_i = acos(-1 + (2i + 1) / K)`, `θ_i = sqrt(K π) φ_i` (R. Bauer,
//! "Distribution of Points on a Sphere with Application to Star Catalogs", Journal of
//! Guidance, Control, and Dynamics 23(1), 2000, 130-137). Its fragment shader
//! (`src/bundles/graphics/src/fragmentShader.txt`, `USE_MULTISHADOW`) adds, for each
//! direction, `max(n . l, 0)` times whether the point is lit along it, and divides by
//! `0.25 K` (the mean of `max(n . l, 0)` over the sphere).
//!
//! Here each direction above the point's horizon is a ray traced within the reach against
//! the other opaque spheres, standing for the shadow map's depth test, and the sum is
//! divided by the sum of the cosines of the directions above the horizon (their count with
//! the uniform weighting), so that an unoccluded point is exactly 1 whatever K; ChimeraX's
//! `0.25 K` differs from that sum by the set's quadrature error. A shadow map has a finite
//! resolution (`msMapSize`, 1024 by default) and a depth bias (`msDepthBias`, 0.01 of the
//! scene's depth), and sees the whole scene: none of these is modelled, the rays are exact
//! and stop at the reach. The directions are the same for every point, which is what makes
//! the method deterministic, and what gives its banding. A point with no direction above its
//! horizon (possible for a handful of directions only) gets 0, as in ChimeraX.

use glam::DVec3;

use super::mc::blocked;
use super::Weighting;
use crate::accel::SphereBvh;

/// Writes to `out` the `k` directions of ChimeraX's `sphere_points(k)`, Bauer's spiral (see
/// the module comment), from the south pole up.
pub fn spiral(k: u32, out: &mut Vec<DVec3>) {
    out.clear();
    let kf = f64::from(k);
    let turn = (kf * std::f64::consts::PI).sqrt();
    out.extend((0..k).map(|i| {
        let phi = (-1.0 + f64::from(2 * i + 1) / kf).clamp(-1.0, 1.0).acos();
        let theta = turn * phi;
        let (s, c) = phi.sin_cos();
        DVec3::new(s * theta.cos(), s * theta.sin(), c)
    }));
}

/// The unoccluded fraction at `x` (unit normal `n`, on the BVH's primitive `own`) from the
/// directions `dirs` above its horizon, weighted by `w`, each traced within `reach`; and the
/// number of rays traced.
pub fn unoccluded(
    bvh: &SphereBvh,
    (x, n, own): (DVec3, DVec3, Option<u32>),
    (reach, w): (f64, Weighting),
    dirs: &[DVec3],
) -> (f64, u64) {
    let (mut open, mut all, mut rays) = (0.0, 0.0, 0);
    for &d in dirs {
        let c = n.dot(d);
        if c <= 0.0 {
            continue;
        }
        let weight = match w {
            Weighting::Cosine => c,
            Weighting::Uniform => 1.0,
        };
        all += weight;
        rays += 1;
        if !blocked(bvh, x, d, own, reach) {
            open += weight;
        }
    }
    (if all > 0.0 { open / all } else { 0.0 }, rays)
}
