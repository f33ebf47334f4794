//! Opaque spheres: closest hit, then the VRML97 lighting equation with hard shadows
//! (MODEL.md section 2). Exact up to rounding, so the error estimate is 0.

use glam::DVec3;

use super::Estimate;
use crate::accel::Hit;
use crate::geom::ellipsoid_normal;
use crate::render::lighting::{shade, SurfacePoint};
use crate::render::{Counters, Prepared};

/// The first opaque surface along `o + t d` (`t > tmin`), seen from outside: a sphere whose
/// first root is behind the origin is culled (MODEL.md: spheres are solid).
#[inline]
pub fn first_hit(prep: &Prepared, o: DVec3, d: DVec3, tmin: f64) -> Option<Hit> {
    prep.bvh
        .closest(o, d, tmin, f64::INFINITY, |_, p, (t0, _)| {
            (!p.is_gas() && t0 > tmin).then_some(t0)
        })
}

/// The surface point of a hit.
#[inline]
pub fn surface_point(prep: &Prepared, o: DVec3, d: DVec3, hit: Hit) -> SurfacePoint {
    let p = &prep.bvh.prims[hit.prim as usize];
    let x = o + hit.t * d;
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
        prim: hit.prim,
        sphere: p.sphere,
    }
}

pub fn radiance(prep: &Prepared, o: DVec3, d: DVec3, counters: &mut Counters) -> Estimate {
    counters.camera_rays += 1;
    match first_hit(prep, o, d, 0.0) {
        None => Estimate {
            value: prep.background,
            error: 0.0,
            covered: false,
        },
        Some(hit) => {
            let sp = surface_point(prep, o, d, hit);
            let m = &prep.materials[prep.bvh.prims[hit.prim as usize].material as usize];
            Estimate {
                value: shade(&prep.bvh, &prep.lights, m, &sp, counters),
                error: 0.0,
                covered: true,
            }
        }
    }
}
