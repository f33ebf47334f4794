//! The VRML97 lighting equation with shadows (MODEL.md section 2):
//!
//! ```text
//! I = O_E + sum_i on_i att_i C_i ( Ia_i O_D O_a
//!                                  + V_i(x) I_i ( O_D max(N.L_i, 0) + O_S max(N.H_i, 0)^(128 s) ) )
//! ```

use glam::DVec3;

use super::lights::{in_scope, towards, LightSource};
use super::visibility::visible;
use super::Counters;
use crate::accel::SphereBvh;
use crate::scene::Material;

/// Where and what was hit.
#[derive(Clone, Copy, Debug)]
pub struct SurfacePoint {
    pub x: DVec3,
    /// Outward unit normal.
    pub n: DVec3,
    /// Unit vector towards the viewer.
    pub v: DVec3,
    /// Primitive index in the BVH (skipped by its own shadow rays).
    pub prim: u32,
    /// Sphere index in the scene (light scopes).
    pub sphere: u32,
}

/// Radiance leaving `sp` towards the viewer.
pub fn shade(
    bvh: &SphereBvh,
    lights: &[LightSource],
    m: &Material,
    sp: &SurfacePoint,
    counters: &mut Counters,
) -> DVec3 {
    if m.unlit {
        // VRML 4.14.2: no Material means unlit white, lights ignored.
        return DVec3::ONE;
    }
    let mut sum = m.emissive;
    for l in lights {
        if !in_scope(l, sp.sphere) {
            continue;
        }
        let Some((dir, dist, att)) = towards(l, sp.x) else {
            continue;
        };
        sum += att * l.ambient * m.ambient_intensity * m.diffuse;
        // A convex surface shadows itself exactly where N.L <= 0; then V_i = 0 and the whole
        // direct term (diffuse and specular) vanishes.
        let ndotl = sp.n.dot(dir);
        if ndotl <= 0.0 || l.direct == DVec3::ZERO {
            continue;
        }
        counters.shadow_rays += 1;
        let vis = visible(bvh, sp.x, dir, dist, Some(sp.prim));
        if vis == 0.0 {
            continue;
        }
        let h = (dir + sp.v).normalize_or_zero();
        let spec = sp.n.dot(h).max(0.0).powf(128.0 * m.shininess);
        sum += att * vis * l.direct * (m.diffuse * ndotl + m.specular * spec);
    }
    sum
}
