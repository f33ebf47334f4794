//! Ambient occlusion, exact for opaque spheres (docs/model.md section 11): at a surface point,
//! the fraction of the hemisphere about its normal (cosine-weighted or uniform) whose rays
//! meet no other sphere within the reach.
//!
//! - `cap`: what one sphere blocks, a cap of directions;
//! - `union`: the measure of the caps' union, in closed form;
//! - `sky`: which directions the caps found so far block whole, to leave out occluders
//!   hidden behind them;
//! - [`methods`]: the approximations real-time tools use, by name, to compare with it.
//!
//! The spheres that can block are those whose nearest point is within the reach and whose
//! box rises above the point's tangent plane; the BVH finds them (`SphereBvh::near_region`),
//! so the cost of a point grows with the spheres within its reach, not with the scene. With
//! no reach (`f64::INFINITY`), every sphere above the tangent plane not hidden by nearer ones
//! is a candidate: a cost that grows with the scene, for each pixel.

pub(crate) mod cap;
pub mod methods;
pub(crate) mod sky;
pub(crate) mod union;

use glam::DVec3;

use super::integrators::surface::{material_of, surface_point, OpaqueHit};
use super::integrators::Estimate;
use super::sampler::Rng;
use super::{Counters, Prepared, View};
use crate::accel::SphereBvh;
use cap::{blocked_by_ball, Blocked, Cap};
pub use methods::AoMethod;
use sky::Sky;
pub use union::Weighting;
use union::{covered_fraction, UnionScratch};

/// How ambient occlusion is computed and shown.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AoSettings {
    /// The distance within which a sphere occludes (`f64::INFINITY`: any distance).
    pub reach: f64,
    /// How directions are weighted.
    pub weighting: Weighting,
    /// The picture is the unoccluded fraction times each surface's diffuse colour (`true`) or
    /// on white (`false`).
    pub colours: bool,
    /// How the unoccluded fraction is computed: exactly, or by a named approximation.
    pub method: AoMethod,
}

impl Default for AoSettings {
    fn default() -> Self {
        AoSettings {
            reach: f64::INFINITY,
            weighting: Weighting::Cosine,
            colours: false,
            method: AoMethod::Exact,
        }
    }
}

/// Reusable buffers of one worker.
#[derive(Default)]
pub struct AoScratch {
    caps: Vec<Cap>,
    stack: Vec<u32>,
    union: UnionScratch,
    sky: Option<Sky>,
    methods: methods::MethodScratch,
}

/// Occluders whose nearest point is within this many typical radii (the median radius) of
/// the shading point are gathered first; beyond it, only those the sky they leave open can
/// show (see [`sky`]).
const NEAR_RADII: f64 = 4.0;

/// More caps than this are pruned by the sky before their union is measured.
const PRUNE: usize = 16;

/// Refuses a reach that is not a positive distance (infinite is any distance).
pub(crate) fn check_reach(reach: f64) -> Result<(), String> {
    if reach.is_nan() || reach <= 0.0 {
        return Err(format!(
            "reach = {reach}: the AO reach must be positive (or infinite)"
        ));
    }
    Ok(())
}

/// The unoccluded fraction at `x` on a surface of unit normal `n`: one minus the fraction of
/// the hemisphere about `n`, weighted by `w`, covered by the opaque spheres of `prep` within
/// `reach`, the sphere `own` (the one `x` is on) left out. 0 if `x` is inside a sphere; a
/// point on a sphere's surface to rounding (within 1e-10 of its radius) is on it.
///
/// The spheres near `x` are gathered first. When the reach goes beyond them, their caps,
/// largest first, mark the cells of the sky they hold whole (a cap inside cells already
/// marked is dropped), and the rest of the scene is searched only where the sky is open:
/// a BVH box or a sphere whose directions all fall in marked cells is left out. What is left
/// out lies within the union of the caps kept, so the union is the same.
pub fn unoccluded(
    prep: &Prepared,
    x: DVec3,
    n: DVec3,
    own: Option<u32>,
    (reach, w): (f64, Weighting),
    s: &mut AoScratch,
) -> f64 {
    let near = (NEAR_RADII * prep.typical_radius).min(reach);
    s.caps.clear();
    let around = Around { x, n, own, reach };
    if around.gather(&prep.bvh, (0.0, near), None, &mut s.caps, &mut s.stack) {
        return 0.0;
    }
    if near < reach || s.caps.len() > PRUNE {
        s.caps.sort_unstable_by(|a, b| a.cos.total_cmp(&b.cos));
        let sky = s.sky.insert(Sky::new(n));
        s.caps.retain(|c| {
            let alpha = c.cos.acos();
            if sky.hides(c.axis, alpha) {
                return false;
            }
            sky.cover(c.axis, alpha);
            true
        });
        if near < reach {
            around.gather(
                &prep.bvh,
                (near, reach),
                Some(sky),
                &mut s.caps,
                &mut s.stack,
            );
        }
    }
    1.0 - covered_fraction(n, &s.caps, w, &mut s.union)
}

/// A shading point and what may occlude it.
struct Around {
    x: DVec3,
    n: DVec3,
    own: Option<u32>,
    reach: f64,
}

impl Around {
    /// Adds to `caps` the caps of the opaque spheres whose nearest point is at a distance in
    /// `from..to` and rises above the horizon, leaving out those the `sky` hides; whether `x`
    /// is inside one of them.
    fn gather(
        &self,
        bvh: &SphereBvh,
        (from, to): (f64, f64),
        sky: Option<&Sky>,
        caps: &mut Vec<Cap>,
        stack: &mut Vec<u32>,
    ) -> bool {
        let Around { x, n, own, reach } = *self;
        let mut everything = false;
        bvh.near_region(
            |lo, hi| {
                let below = (lo - x).max(DVec3::ZERO) + (x - hi).max(DVec3::ZERO);
                let beyond = (lo - x).abs().max((hi - x).abs());
                // The box's corner farthest along the normal.
                let top = DVec3::select(n.cmpge(DVec3::ZERO), hi, lo);
                below.length_squared() < to * to
                    && beyond.length_squared() >= from * from
                    && (top - x).dot(n) > 0.0
                    && !sky.is_some_and(|sky| {
                        let (centre, radius) = (0.5 * (lo + hi), 0.5 * (hi - lo).length());
                        let d = (centre - x).length();
                        d > radius && sky.hides((centre - x) / d, (radius / d).asin())
                    })
            },
            |i, p| {
                if Some(i) == own || p.is_gas() || everything {
                    return;
                }
                let gap = (p.center - x).length() - p.radius;
                // (Nearer than `from == 0`: inside or cutting the shading point's sphere.)
                if gap >= to || (from > 0.0 && gap < from) {
                    return;
                }
                match blocked_by_ball(x, p.center, p.radius, reach) {
                    Blocked::Nothing => {}
                    Blocked::Cap(c) => {
                        if !sky.is_some_and(|sky| sky.hides(c.axis, c.cos.acos())) {
                            caps.push(c);
                        }
                    }
                    Blocked::Everything => everything = true,
                }
            },
            stack,
        );
        everything
    }
}

/// The AO picture's radiance along a camera ray whose first opaque hit is `hit`: the
/// unoccluded fraction there, on white or on the surface's diffuse colour; the background
/// where the ray meets nothing. Exact up to rounding with the exact method (the error
/// estimate is 0); the approximations' estimates are their own ([`methods::unoccluded`]).
pub(crate) fn radiance_of_hit(
    view: &View,
    ao: &AoSettings,
    (o, d): (DVec3, DVec3),
    hit: Option<OpaqueHit>,
    s: &mut AoScratch,
    rng: &mut Rng,
    counters: &mut Counters,
) -> Estimate {
    counters.camera_rays += 1;
    let Some(hit) = hit else {
        return Estimate {
            value: view.background,
            error: 0.0,
            covered: false,
        };
    };
    let sp = surface_point(view, o, d, hit);
    let own = hit.on.sphere();
    let (v, error) = match ao.method {
        AoMethod::Exact => {
            let reach = (ao.reach, ao.weighting);
            (unoccluded(view, sp.x, sp.n, own, reach, s), 0.0)
        }
        _ => methods::unoccluded(view, ao, (sp.x, sp.n, own), rng, &mut s.methods, counters),
    };
    let colour = if ao.colours {
        material_of(view, hit.on).diffuse
    } else {
        DVec3::ONE
    };
    Estimate {
        value: colour * v,
        error: colour.max_element() * error,
        covered: true,
    }
}

/// Why `prep` cannot be rendered with exact AO, if it cannot: the occluders exact AO knows
/// are opaque spheres.
pub(crate) fn unsupported(prep: &Prepared) -> Option<String> {
    let ellipsoids = prep
        .bvh
        .packed()
        .iter()
        .filter(|q| q.is_ellipsoid())
        .count();
    let what = [
        (prep.gas_spheres, "gas spheres"),
        (ellipsoids, "ellipsoids (spheres under a non-uniform scale)"),
        (prep.surfaces.items.len(), "surfaces other than spheres"),
    ];
    let found: Vec<String> = what
        .iter()
        .filter(|(k, _)| *k > 0)
        .map(|(k, w)| format!("{k} {w}"))
        .collect();
    (!found.is_empty()).then(|| {
        format!(
            "ambient occlusion is exact for opaque spheres only, and this scene has {}",
            found.join(", ")
        )
    })
}

#[cfg(test)]
mod reference;
#[cfg(test)]
mod tests;
