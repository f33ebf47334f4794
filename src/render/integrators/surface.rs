//! Opaque surfaces: closest hit among spheres and the other surfaces, then the VRML97
//! lighting equation with hard shadows (docs/model.md section 2). Exact up to rounding, so the
//! error estimate is 0.

use glam::DVec3;

use super::Estimate;
use crate::accel::PacketStack;
use crate::geom::ellipsoid_normal;
use crate::render::lighting::{shade, SurfacePoint};
use crate::render::visibility::Blockers;
pub use crate::render::visibility::Opaque;
use crate::render::{Counters, Prepared, View};

/// An opaque hit: ray parameter and what was hit.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct OpaqueHit {
    /// Its parameter along the ray.
    pub t: f64,
    /// What was hit.
    pub on: Opaque,
}

/// The first opaque sphere along `o + t d` (`t > tmin`), seen from outside: a sphere whose
/// first root is behind the origin is culled (docs/model.md: spheres are solid).
/// (A ray entry point: compiled again for AVX2, see `accel::bvh`.)
#[multiversion::multiversion(targets("x86_64+avx+avx2+fma+bmi1+bmi2+lzcnt+popcnt"))]
fn first_sphere(prep: &Prepared, o: DVec3, d: DVec3, tmin: f64) -> Option<crate::accel::Hit> {
    prep.bvh
        .closest(o, d, tmin, f64::INFINITY, |_, p, (t0, _)| {
            (!p.is_gas() && t0 > tmin).then_some(t0)
        })
}

/// [`first_sphere`] of up to [`crate::accel::PACKET`] rays at once (`rays[k] = (o, d)`, all
/// with `t > tmin`), written to `hits[k]`: the same hits, the rays walked as one packet.
#[multiversion::multiversion(targets("x86_64+avx+avx2+fma+bmi1+bmi2+lzcnt+popcnt"))]
fn first_spheres(
    prep: &Prepared,
    rays: &[(DVec3, DVec3)],
    tmin: f64,
    hits: &mut [Option<crate::accel::Hit>],
    stack: &mut PacketStack,
) {
    prep.bvh.closest_packet(
        rays,
        tmin,
        f64::INFINITY,
        hits,
        stack,
        |_, _, p, (t0, _)| (!p.is_gas() && t0 > tmin).then_some(t0),
    )
}

/// [`first_hit`] of up to [`crate::accel::PACKET`] coherent rays (a camera tile's
/// neighbouring pixels) at once, written to `hits[k]`: the same hits as one ray at a time.
pub fn first_hits(
    prep: &Prepared,
    rays: &[(DVec3, DVec3)],
    tmin: f64,
    hits: &mut [Option<OpaqueHit>],
    stack: &mut PacketStack,
) {
    let mut spheres = [None; crate::accel::PACKET];
    first_spheres(prep, rays, tmin, &mut spheres, stack);
    for (k, &(o, d)) in rays.iter().enumerate() {
        let sphere = spheres[k].map(|h| OpaqueHit {
            t: h.t,
            on: Opaque::Sphere(h.prim),
        });
        hits[k] = nearer_surface(prep, o, d, tmin, sphere);
    }
}

/// The first opaque surface along `o + t d` (`t > tmin`): a sphere, or a surface in front of it.
#[inline]
pub fn first_hit(prep: &Prepared, o: DVec3, d: DVec3, tmin: f64) -> Option<OpaqueHit> {
    let sphere = first_sphere(prep, o, d, tmin).map(|h| OpaqueHit {
        t: h.t,
        on: Opaque::Sphere(h.prim),
    });
    nearer_surface(prep, o, d, tmin, sphere)
}

/// `hit`, or the first surface in front of it.
#[inline]
pub fn nearer_surface(
    prep: &Prepared,
    o: DVec3,
    d: DVec3,
    tmin: f64,
    hit: Option<OpaqueHit>,
) -> Option<OpaqueHit> {
    let tmax = hit.map_or(f64::INFINITY, |h| h.t);
    match prep.surfaces.closest(o, d, tmin, tmax) {
        Some((t, i)) if t < tmax => Some(OpaqueHit {
            t,
            on: Opaque::Surface(i),
        }),
        _ => hit,
    }
}

/// The surface point of a hit.
#[inline]
pub fn surface_point(prep: &Prepared, o: DVec3, d: DVec3, hit: OpaqueHit) -> SurfacePoint {
    let x = o + hit.t * d;
    match hit.on {
        Opaque::Sphere(prim) => {
            let p = &prep.bvh.prim(prim);
            let n = match p.ellipsoid {
                // o - c first: for a small sphere far from the origin this keeps the normal's
                // direction to the precision of the hit parameter.
                None => ((o - p.center) + hit.t * d).normalize(),
                Some(e) => ellipsoid_normal(x, &prep.bvh.to_object[e.index()]),
            };
            SurfacePoint {
                x,
                n,
                v: -d,
                on: hit.on,
            }
        }
        Opaque::Surface(i) => SurfacePoint {
            x,
            n: prep.surfaces.shading_normal(i, o, d, hit.t),
            v: -d,
            on: hit.on,
        },
    }
}

/// The material of what a hit is on.
#[inline]
pub fn material_of(prep: &Prepared, on: Opaque) -> crate::scene::Material {
    let (m, c) = match on {
        Opaque::Sphere(prim) => {
            let p = prep.bvh.prim(prim);
            (p.material, p.color)
        }
        Opaque::Surface(i) => {
            let p = prep.surfaces.paints[i as usize];
            (p.material, p.color)
        }
    };
    prep.materials.get(m, c)
}

/// `blockers`: see `lighting::shade` (kept from pixel to pixel by the caller).
pub fn radiance(
    prep: &View,
    o: DVec3,
    d: DVec3,
    blockers: &mut Blockers,
    counters: &mut Counters,
) -> Estimate {
    radiance_of_hit(prep, o, d, first_hit(prep, o, d, 0.0), blockers, counters)
}

/// [`radiance`] of a camera ray whose first hit is already known (traced in a packet).
pub fn radiance_of_hit(
    prep: &View,
    o: DVec3,
    d: DVec3,
    hit: Option<OpaqueHit>,
    blockers: &mut Blockers,
    counters: &mut Counters,
) -> Estimate {
    counters.camera_rays += 1;
    match hit {
        None => Estimate {
            value: prep.background,
            error: 0.0,
            covered: false,
        },
        Some(hit) => {
            let sp = surface_point(prep, o, d, hit);
            Estimate {
                value: shade(
                    prep,
                    &material_of(prep, hit.on),
                    &sp,
                    1.0,
                    blockers,
                    counters,
                ),
                error: 0.0,
                covered: true,
            }
        }
    }
}
