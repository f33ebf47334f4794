//! The VRML97 lighting equation with shadows (docs/model.md section 2):
//!
//! ```text
//! I = O_E + sum_i on_i att_i C_i ( Ia_i O_D O_a
//!                                  + V_i(x) I_i ( O_D max(N.L_i, 0) + O_S max(N.H_i, 0)^(128 s) ) )
//! ```

use glam::DVec3;

use super::lights::{in_scope, in_surface_scope, towards, LightSource};
use super::visibility::Opaque;
use super::visibility::{visible_after, Blockers};
use super::{Counters, Prepared, View};
use crate::scene::Material;

/// Where and what was hit. As small as a sphere hit needs (the bench's and the AOVs' lists
/// of hits hold it): what only a triangle has, its geometric normal and its colours, is
/// looked up from `on` and `x` when shading.
#[derive(Clone, Copy, Debug)]
pub struct SurfacePoint {
    pub x: DVec3,
    /// Unit shading normal, on the side the viewer sees.
    pub n: DVec3,
    /// Unit vector towards the viewer.
    pub v: DVec3,
    /// What was hit (skipped by its own shadow rays).
    pub on: Opaque,
}

impl SurfacePoint {
    /// Its index in the scene: a sphere's in `Scene::spheres`, a surface's in
    /// `Scene::surfaces` (light scopes, the `id` channel).
    #[inline]
    pub fn scene_index(&self, prep: &Prepared) -> u32 {
        match self.on {
            Opaque::Sphere(p) => prep.bvh.prim(p).sphere,
            Opaque::Surface(i) => i,
        }
    }
}

/// Whether light `l` may light what the point is on (VRML scoping of DirectionalLights).
#[inline]
fn lights(l: &LightSource, on: Opaque, index: u32) -> bool {
    match on {
        Opaque::Sphere(_) => in_scope(l, index),
        Opaque::Surface(_) => in_surface_scope(l, index),
    }
}

/// Radiance leaving `sp` towards the viewer.
/// `blockers` holds the spheres that last blocked each light's rays (see
/// [`Blockers`]): the neighbouring pixel's, when the caller keeps it from pixel to pixel.
/// `seen_through` is the camera ray's transmittance up to `sp` (1 without gas): the carried
/// headlight's visibility there.
pub fn shade(
    prep: &View,
    m: &Material,
    sp: &SurfacePoint,
    seen_through: f64,
    blockers: &mut Blockers,
    counters: &mut Counters,
) -> DVec3 {
    // A triangle's geometric normal and Color there; a sphere's or a solid's normal is both.
    let (geometric, color) = match sp.on {
        Opaque::Sphere(_) => (sp.n, None),
        Opaque::Surface(i) => prep.surfaces.look(i, sp.x, sp.v, sp.n),
    };
    let index = sp.scene_index(prep);
    let diffuse = color.unwrap_or(m.diffuse);
    if m.unlit {
        // VRML 4.14.2: no Material means unlit, lights ignored: white, or the Color node's.
        return diffuse;
    }
    let mut sum = m.emissive;
    for (k, l) in prep.lights.iter().enumerate() {
        if !lights(l, sp.on, index) {
            continue;
        }
        let Some((dir, dist, att)) = towards(l, sp.x) else {
            continue;
        };
        sum += att * l.ambient * m.ambient_intensity * diffuse;
        // A convex surface shadows itself exactly where N.L <= 0; then V_i = 0 and the whole
        // direct term (diffuse and specular) vanishes. A face lit from behind its geometric
        // normal is in its own shadow, whatever its shading normal says.
        let ndotl = sp.n.dot(dir);
        if ndotl <= 0.0 || geometric.dot(dir) <= 0.0 || l.direct == DVec3::ZERO {
            continue;
        }
        let vis = if l.carried {
            seen_through
        } else {
            counters.shadow_rays += 1;
            visible_after(prep, sp.x, dir, dist, Some(sp.on), blockers.slot(k))
        };
        if vis == 0.0 {
            continue;
        }
        let h = (dir + sp.v).normalize_or_zero();
        let spec = sp.n.dot(h).max(0.0).powf(128.0 * m.shininess);
        sum += att * vis * l.direct * (diffuse * ndotl + m.specular * spec);
    }
    sum
}
