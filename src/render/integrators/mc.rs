//! Unbiased Monte Carlo (`--integrator mc`): one path per camera sample. A free-path length is
//! drawn in the piecewise-constant medium (optical depth `tau* = -ln(1 - xi)`); if the path
//! collides at `x` in a segment of extinction `sigma`, it scores `emit / sigma` plus the
//! single-scattered light `p sum_i (scatter / sigma) E_i(x)` with one shadow ray per light (light
//! sampling); if it gets through, it scores the surface or background behind. The pixel's
//! error estimate is the standard error of its samples' mean.

use glam::DVec3;

use super::{behind, gas_along, lights_at, scatter_for, Estimate, Scratch};
use crate::render::sampler::Rng;

use crate::render::{Counters, Prepared};

pub fn radiance(
    prep: &Prepared,
    o: DVec3,
    d: DVec3,
    rng: &mut Rng,
    s: &mut Scratch,
    counters: &mut Counters,
) -> Estimate {
    let hit = gas_along(prep, o, d, s, counters);
    let covered = hit.is_some() || !s.segments.is_empty();
    // 1 - xi is in (0, 1]: -ln of it is finite.
    let mut left = -(1.0 - rng.next_f64()).ln();
    for seg in &s.segments {
        let tau = seg.sigma * (seg.tb - seg.ta);
        if left < tau {
            let t = seg.ta + left / seg.sigma;
            let x = o + t * d;
            let light = lights_at(
                prep,
                x,
                |i| scatter_for(prep, seg, &s.members, i) / seg.sigma,
                counters,
            );
            return Estimate {
                value: seg.emit / seg.sigma + light,
                error: 0.0,
                covered,
            };
        }
        left -= tau;
    }
    Estimate {
        value: behind(prep, o, d, hit, counters),
        error: 0.0,
        covered,
    }
}
