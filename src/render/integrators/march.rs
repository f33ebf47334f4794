//! Fixed-step ray marching with midpoint samples, as real-time renderers do (a named
//! approximation, `--integrator march --step H`): along each camera ray, steps of length `H`
//! (the last one shorter) from the camera to the first opaque hit or the end of the gas; at
//! each step's midpoint the extinction, emission and light (one shadow ray per light) are
//! sampled, `L += T * source * dt` and `T *= exp(-sigma * dt)`. Profiled gas (docs/model.md
//! section 6) is sampled at its density at the midpoint, as a real-time renderer would.

use glam::DVec3;

use super::{behind, gas_along, lights_at, scatter_at, Estimate, Scratch};

use crate::render::{Counters, View};

/// The radiance along the camera ray `o + t d`, marched in steps of length `step`.
pub fn radiance(
    view: &View,
    o: DVec3,
    d: DVec3,
    step: f64,
    s: &mut Scratch,
    counters: &mut Counters,
) -> Estimate {
    let hit = gas_along(view, o, d, s, counters);
    let end = s.segments.last().map_or(0.0, |g| g.tb);
    let mut l = DVec3::ZERO;
    let mut transmittance = 1.0;
    let mut t = 0.0;
    let mut k = 0; // current segment
    while t < end {
        let dt = step.min(end - t);
        let mid = t + 0.5 * dt;
        while k < s.segments.len() && s.segments[k].tb <= mid {
            k += 1;
        }
        if k < s.segments.len() && s.segments[k].ta <= mid {
            let seg = s.segments[k];
            let x = o + mid * d;
            // Profiled members at their density at the midpoint.
            let (sigma, emit) = seg.source_at(&s.profiled, mid);
            let light = lights_at(
                view,
                x,
                |i| scatter_at(view, &seg, &s.members, &s.profiled, i, mid),
                transmittance * (-0.5 * sigma * dt).exp(),
                counters,
            );
            l += transmittance * (emit + light) * dt;
            transmittance *= (-sigma * dt).exp();
        }
        t += dt;
    }
    let surface = behind(view, o, d, hit, transmittance, counters);
    Estimate {
        value: l + transmittance * surface,
        error: 0.0,
        covered: hit.is_some() || !s.segments.is_empty(),
    }
}
