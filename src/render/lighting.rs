//! The VRML97 lighting equation with shadows (MODEL.md section 2):
//!
//! ```text
//! I = O_E + sum_i on_i att_i C_i ( Ia_i O_D O_a
//!                                  + V_i(x) I_i ( O_D max(N.L_i, 0) + O_S max(N.H_i, 0)^(128 s) ) )
//! ```

use glam::DVec3;

use super::integrators::surface::Opaque;
use super::lights::{in_scope, in_surface_scope, towards, LightSource};
use super::visibility::{visible_two, Blockers};
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

/// One light's share at a point, before its shadow ray: direction and distance to it, its
/// attenuation, N.L, and whether its direct term needs a shadow ray (false where the surface
/// shadows itself or the light has no direct part).
#[derive(Clone, Copy)]
struct Term {
    dir: DVec3,
    dist: f64,
    att: f64,
    ndotl: f64,
    ray: bool,
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
pub fn shade(
    prep: &View,
    m: &Material,
    sp: &SurfacePoint,
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
    // Each light's terms in the lights' order; the shadow rays of two lights at a time are
    // traced together (`visible_two`), which gives each the same answer sooner.
    let term = |k: usize| -> Option<Term> {
        let l = &prep.lights[k];
        if !lights(l, sp.on, index) {
            return None;
        }
        let (dir, dist, att) = towards(l, sp.x)?;
        // A convex surface shadows itself exactly where N.L <= 0; then V_i = 0 and the whole
        // direct term (diffuse and specular) vanishes. A face lit from behind its geometric
        // normal is in its own shadow, whatever its shading normal says.
        let ndotl = sp.n.dot(dir);
        let ray = ndotl > 0.0 && geometric.dot(dir) > 0.0 && l.direct != DVec3::ZERO;
        Some(Term {
            dir,
            dist,
            att,
            ndotl,
            ray,
        })
    };
    let mut sum = m.emissive;
    for k in (0..prep.lights.len()).step_by(2) {
        let terms = [
            term(k),
            (k + 1 < prep.lights.len()).then(|| term(k + 1)).flatten(),
        ];
        let rays = terms.map(|t| t.filter(|t| t.ray).map(|t| (t.dir, t.dist)));
        let vis = visible_two(prep, sp.x, Some(sp.on), k, rays, blockers);
        for (j, t) in terms.into_iter().enumerate() {
            let Some(t) = t else {
                continue;
            };
            let l = &prep.lights[k + j];
            sum += t.att * l.ambient * m.ambient_intensity * diffuse;
            if !t.ray {
                continue;
            }
            counters.shadow_rays += 1;
            if vis[j] == 0.0 {
                continue;
            }
            let h = (t.dir + sp.v).normalize_or_zero();
            let spec = sp.n.dot(h).max(0.0).powf(128.0 * m.shininess);
            sum += t.att * vis[j] * l.direct * (diffuse * t.ndotl + m.specular * spec);
        }
    }
    sum
}
