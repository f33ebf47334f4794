//! Ambient occlusion, exact for opaque spheres, triangles and boxes, and to a tolerance among
//! cylinders and cones and through gas (docs/model.md section 11): at a surface point, the
//! fraction of the hemisphere about its normal (cosine-weighted or uniform) whose rays meet no
//! other occluder within the reach, each ray seen through the gas on its way.
//!
//! - `cap`: what one sphere blocks, a cap of directions;
//! - `polygon`: what a triangle or a face of a Box blocks, an intersection of caps;
//! - `bracket`: a Cylinder or a Cone, between the polyhedra inscribed in it and about it;
//! - `gas`: what gas spheres take from the opaque occluders' AO, by nested quadrature;
//! - `supported`: which scenes exact AO takes;
//! - `union`: the measure of the union of those regions, in closed form;
//! - `sky`: which directions the regions found so far block whole, to leave out occluders
//!   hidden behind them;
//! - [`methods`]: the approximations real-time tools use, by name, to compare with it.
//!
//! The occluders that can block are those whose nearest point is within the reach and whose
//! box rises above the point's tangent plane; the BVHs find them (`SphereBvh::near_region`,
//! over the spheres and over the other surfaces), so the cost of a point grows with the
//! occluders within its reach, not with the scene. With no reach (`f64::INFINITY`), every
//! occluder above the tangent plane not hidden by nearer ones is a candidate: a cost that
//! grows with the scene, for each pixel.

pub(crate) mod bracket;
pub(crate) mod cap;
pub(crate) mod gas;
pub mod methods;
pub(crate) mod polygon;
pub(crate) mod sky;
mod supported;
pub(crate) mod union;

use glam::DVec3;

use super::integrators::surface::{material_of, surface_point, OpaqueHit};
use super::integrators::Estimate;
use super::lighting::SurfacePoint;
use super::sampler::Rng;
use super::surfaces::{Surfaces, Traced};
use super::visibility::Opaque;
use super::{Counters, Prepared, View};
use crate::accel::SphereBvh;
use crate::geom::shapes::Solid;
use bracket::{blocked_by_round, Fit};
use cap::{blocked_by_ball, Blocked, Cap};
pub use methods::AoMethod;
use polygon::{blocked_by_box, blocked_by_triangle, coplanar, is_sliver, BoxBlocks};
use sky::Sky;
pub(crate) use supported::unsupported;
pub use union::Weighting;
use union::{
    covered_fraction, covered_fraction_of_regions, Cone, RegionScratch, Regions, UnionScratch,
};

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
    regions: Regions,
    /// The Cylinders and Cones that may block (`bracket`): index in `Surfaces::items`, and
    /// the cone of directions that holds the ball about it.
    rounds: Vec<(u32, Cone)>,
    /// A polyhedron's ring of corners (`bracket`).
    ring: Vec<DVec3>,
    stack: Vec<u32>,
    union: UnionScratch,
    general: RegionScratch,
    sky: Option<Sky>,
    gas: gas::GasScratch,
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

/// The unoccluded fraction at `x` on a surface of unit normal `n`, and a bound of its error:
/// one minus the fraction of the hemisphere about `n`, weighted by `w`, covered by the opaque
/// spheres, triangles, Boxes, Cylinders and Cones of `prep` within `reach`, what `x` is on
/// (`own`) left out. 0 if `x` is inside a sphere or a solid; a point on a sphere's surface to
/// rounding (within 1e-10 of its radius) is on it. Exact up to rounding (the error is 0)
/// without Cylinders, Cones or gas near `x`; with Cylinders or Cones, bracketed to within
/// `tol` (`bracket`); with gas spheres, less what they take, to about `tol` ([`gas`]).
///
/// The occluders near `x` are gathered first. When the reach goes beyond them, the caps of
/// the spheres, largest first, and then the triangles' and faces' regions mark the cells of
/// the sky they hold whole (one inside cells already marked is dropped), and the rest of the
/// scene is searched only where the sky is open: a BVH box or an occluder whose directions
/// all fall in marked cells is left out. What is left out lies within the union of the
/// regions kept, so the union is the same. Without triangles or Boxes near `x` the union is
/// that of caps alone (`union::covered_fraction`), as for a scene of spheres.
pub(crate) fn unoccluded_to(
    prep: &Prepared,
    x: DVec3,
    n: DVec3,
    own: Option<Opaque>,
    (reach, w): (f64, Weighting),
    tol: f64,
    s: &mut AoScratch,
) -> (f64, f64) {
    let surfaces = !prep.surfaces.is_empty();
    let typical = if prep.typical_radius > 0.0 || !surfaces {
        prep.typical_radius
    } else {
        prep.surfaces.typical_radius
    };
    let near = (NEAR_RADII * typical).min(reach);
    s.caps.clear();
    s.regions.clear();
    s.rounds.clear();
    let own_triangle = match own {
        Some(Opaque::Surface(i)) => match &prep.surfaces.items[i as usize] {
            Traced::Triangle(t) => Some(t.p),
            Traced::Solid { .. } => None,
        },
        _ => None,
    };
    let around = Around {
        x,
        n,
        own,
        own_triangle,
        reach,
    };
    if around.gather(&prep.bvh, (0.0, near), None, &mut s.caps, &mut s.stack) {
        return (0.0, 0.0);
    }
    if surfaces
        && around.gather_surfaces(
            &prep.surfaces,
            (0.0, near),
            None,
            (&mut s.regions, &mut s.rounds),
            &mut s.stack,
        )
    {
        return (0.0, 0.0);
    }
    let pruned = near < reach || s.caps.len() + s.regions.len() > PRUNE;
    if pruned {
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
        // (A round solid whose ball the sky hides is hidden whole: what its polyhedra block
        // beyond it is left out of both bounds, which keeps each a bound.)
        s.rounds
            .retain(|(_, cone)| !sky.hides(cone.axis, cone.angle));
        s.regions.retain(|caps, cone| {
            if sky.hides(cone.axis, cone.angle) {
                return false;
            }
            sky.cover_all(caps);
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
            if surfaces
                && around.gather_surfaces(
                    &prep.surfaces,
                    (near, reach),
                    Some(sky),
                    (&mut s.regions, &mut s.rounds),
                    &mut s.stack,
                )
            {
                return (0.0, 0.0);
            }
        }
    }
    s.gas.clear();
    if prep.gas_spheres > 0 {
        let sky = if pruned { s.sky.as_ref() } else { None };
        around.gather_gas(&prep.bvh, sky, &mut s.gas, &mut s.stack);
    }
    if !s.rounds.is_empty() {
        debug_assert!(
            s.gas.is_empty(),
            "`unsupported` refuses gas beside round solids"
        );
        return bracketed(prep, (x, n), (reach, w), tol, s);
    }
    let v = if s.regions.is_empty() {
        1.0 - covered_fraction(n, &s.caps, w, &mut s.union)
    } else {
        1.0 - covered_fraction_of_regions(n, &s.caps, &s.regions, w, &mut s.general)
    };
    if s.gas.is_empty() {
        return (v, 0.0);
    }
    let (loss, error) = gas::gas_loss(
        prep,
        (x, n),
        (reach, w),
        tol,
        (&s.caps, &s.regions),
        &mut s.gas,
    );
    ((v - loss).max(0.0), error)
}

/// The end of [`unoccluded_to`] with the round solids `s.rounds` among the occluders: the
/// unoccluded fractions among their inner and their outer polyhedra, with more sides until
/// they are within `2 tol` (`bracket`); their mean and half their gap.
fn bracketed(
    prep: &Prepared,
    (x, n): (DVec3, DVec3),
    (reach, w): (f64, Weighting),
    tol: f64,
    s: &mut AoScratch,
) -> (f64, f64) {
    let base = s.regions.len();
    let mut sides = bracket::FIRST_SIDES;
    loop {
        let mut bounds = [0.0; 2];
        for (bound, fit) in bounds.iter_mut().zip([Fit::Inner, Fit::Outer]) {
            s.regions.truncate(base);
            let mut everything = false;
            for &(i, _) in &s.rounds {
                let Traced::Solid {
                    solid, to_object, ..
                } = &prep.surfaces.items[i as usize]
                else {
                    continue;
                };
                let to_world = to_object.inverse();
                let maps = (to_object, &to_world);
                let blocks = blocked_by_round(
                    (x, n),
                    solid,
                    maps,
                    sides,
                    fit,
                    reach,
                    &mut s.ring,
                    &mut s.regions,
                );
                if blocks == BoxBlocks::Everything {
                    everything = true;
                    break;
                }
            }
            *bound = if everything {
                0.0
            } else if s.regions.is_empty() {
                1.0 - covered_fraction(n, &s.caps, w, &mut s.union)
            } else {
                1.0 - covered_fraction_of_regions(n, &s.caps, &s.regions, w, &mut s.general)
            };
        }
        // (Rounding may leave the outer bound a hair above the inner one.)
        let [upper, lower] = bounds;
        let gap = (upper - lower).max(0.0);
        if gap <= 2.0 * tol || sides >= bracket::MAX_SIDES {
            return (0.5 * (upper + lower), 0.5 * gap);
        }
        sides *= 2;
    }
}

/// [`unoccluded`] at a camera ray's hit: about the sphere's normal, or a triangle's or
/// Box's geometric normal on the side the ray came from (not a mesh's interpolated shading
/// normal: the hemisphere a flat face sees), what the hit is on left out.
pub(crate) fn at_hit(
    prep: &Prepared,
    sp: &SurfacePoint,
    reach: (f64, Weighting),
    tol: f64,
    s: &mut AoScratch,
) -> (f64, f64) {
    let n = geometric_normal(prep, sp);
    unoccluded_to(prep, sp.x, n, Some(sp.on), reach, tol, s)
}

/// The normal AO is taken about at a surface point: see [`at_hit`].
fn geometric_normal(prep: &Prepared, sp: &SurfacePoint) -> DVec3 {
    match sp.on {
        Opaque::Sphere(_) => sp.n,
        Opaque::Surface(i) => prep.surfaces.look(i, sp.x, sp.v, sp.n).0,
    }
}

/// A shading point and what may occlude it.
struct Around {
    x: DVec3,
    n: DVec3,
    own: Option<Opaque>,
    /// The triangle `x` is on, if it is on one: triangles in its plane are edge-on.
    own_triangle: Option<[DVec3; 3]>,
    reach: f64,
}

impl Around {
    /// Whether a BVH box `lo..hi` may hold an occluder whose nearest point is at a distance
    /// in `from..to` and that rises above the horizon, outside what the `sky` hides.
    fn may_hold(
        &self,
        (lo, hi): (DVec3, DVec3),
        (from, to): (f64, f64),
        sky: Option<&Sky>,
    ) -> bool {
        let (x, n) = (self.x, self.n);
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
    }

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
        let Around { x, reach, .. } = *self;
        let own = self.own.and_then(Opaque::sphere);
        let mut everything = false;
        bvh.near_region(
            |lo, hi| self.may_hold((lo, hi), (from, to), sky),
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

    /// Takes into `gas` the gas spheres whose nearest point is within the reach and that rise
    /// above the horizon, leaving out those the `sky` (of opaque occluders) hides.
    fn gather_gas(
        &self,
        bvh: &SphereBvh,
        sky: Option<&Sky>,
        gas: &mut gas::GasScratch,
        stack: &mut Vec<u32>,
    ) {
        let Around { x, n, reach, .. } = *self;
        // (A gas sphere's own surface point, for the per-particle table, does not see it.)
        let own = self.own.and_then(Opaque::sphere);
        bvh.near_region(
            |lo, hi| self.may_hold((lo, hi), (0.0, reach), sky),
            |i, p| {
                if !p.is_gas() || Some(i) == own {
                    return;
                }
                let v = p.center - x;
                let d = v.length();
                if d - p.radius >= reach
                    || sky
                        .is_some_and(|sky| d > p.radius && sky.hides(v / d, (p.radius / d).asin()))
                {
                    return;
                }
                gas.add(*p, x, n, reach);
            },
            stack,
        );
    }

    /// Adds to `regions` those of the triangles and Boxes whose bounding balls' nearest
    /// points are at a distance in `from..to`, and to `rounds` the Cylinders and Cones,
    /// leaving out those the `sky` hides; whether `x` is inside a solid.
    fn gather_surfaces(
        &self,
        surfaces: &Surfaces,
        (from, to): (f64, f64),
        sky: Option<&Sky>,
        (regions, rounds): (&mut Regions, &mut Vec<(u32, Cone)>),
        stack: &mut Vec<u32>,
    ) -> bool {
        let Around { x, n, reach, .. } = *self;
        let own = match self.own {
            Some(Opaque::Surface(i)) => Some(i),
            _ => None,
        };
        let mut everything = false;
        surfaces.bvh.near_region(
            |lo, hi| self.may_hold((lo, hi), (from, to), sky),
            |_, p| {
                let i = p.sphere;
                if Some(i) == own || everything {
                    return;
                }
                let d = (p.center - x).length();
                let gap = d - p.radius;
                if gap >= to || (from > 0.0 && gap < from) {
                    return;
                }
                if sky.is_some_and(|sky| {
                    d > p.radius && sky.hides((p.center - x) / d, (p.radius / d).asin())
                }) {
                    return;
                }
                let before = regions.len();
                match &surfaces.items[i as usize] {
                    Traced::Triangle(t) => {
                        if is_sliver(&t.p) || self.own_triangle.is_some_and(|o| coplanar(&o, &t.p))
                        {
                            return;
                        }
                        blocked_by_triangle(x, n, &t.p, reach, self.own_triangle.as_ref(), regions);
                    }
                    Traced::Solid {
                        solid: Solid::Cuboid { half },
                        to_object,
                        ..
                    } => {
                        if blocked_by_box(x, n, *half, to_object, reach, regions)
                            == BoxBlocks::Everything
                        {
                            everything = true;
                            return;
                        }
                    }
                    // A Cylinder or a Cone: bracketed at the end (`bracketed`); open ones are
                    // refused by `unsupported`.
                    Traced::Solid {
                        solid, to_object, ..
                    } => {
                        if bracket::inside(solid, to_object.transform_point3(x)) {
                            everything = true;
                        } else {
                            // The directions of its bounding ball (all from inside it).
                            let ball = if d > p.radius {
                                Cone {
                                    axis: (p.center - x) / d,
                                    angle: (p.radius / d).asin(),
                                }
                            } else {
                                Cone {
                                    axis: n,
                                    angle: std::f64::consts::PI,
                                }
                            };
                            rounds.push((i, ball));
                        }
                        return;
                    }
                }
                if let Some(sky) = sky {
                    // Those the sky hides, of the ones just added.
                    let mut k = regions.len();
                    while k > before {
                        k -= 1;
                        let cone = regions.bound(k);
                        if sky.hides(cone.axis, cone.angle) {
                            regions.remove(k);
                        }
                    }
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
    let (v, error) = match ao.method {
        AoMethod::Exact => at_hit(view, &sp, (ao.reach, ao.weighting), view.tol, s),
        // (Spheres only: the approximations refuse other surfaces.)
        _ => {
            let at = (sp.x, sp.n, hit.on.sphere());
            methods::unoccluded(view, ao, at, rng, &mut s.methods, counters)
        }
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

#[cfg(test)]
mod bracket_tests;
#[cfg(test)]
mod gas_tests;
#[cfg(test)]
mod reference;
#[cfg(test)]
mod surface_tests;
#[cfg(test)]
mod tests;
