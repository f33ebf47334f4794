//! The exact gas integrator (MODEL.md section 3): emission and absorption in closed form over
//! the segments, single scattering by adaptive Gauss-Kronrod quadrature between the
//! breakpoints of each light's integrand, to `tol` relative to the ray's value.

use glam::DVec3;

use super::{behind, gas_along, scatter_for, Estimate, Scratch, PHASE};
use crate::render::lights::{towards, LightKind};
use crate::render::quadrature::integrate;
use crate::render::segments::emission_absorption;
use crate::render::shadow_volume::{breakpoints, candidates};
use crate::render::{Counters, Prepared};

/// Sub-intervals the quadrature may use per camera ray before it reports what it has.
const MAX_INTERVALS: usize = 4000;

/// One smooth piece of one light's scattering integrand.
struct Piece {
    /// Segment start and extinction: the integrand carries `exp(-sigma (t - ta))`.
    ta: f64,
    sigma: f64,
    /// `T(0, ta) p sum sigma_j a_j C_i I_i` (per channel).
    coeff: DVec3,
    light: usize,
    /// The light's candidate spheres: `cands[c.0 .. c.1]`.
    cands: (usize, usize),
}

pub fn radiance(
    prep: &Prepared,
    o: DVec3,
    d: DVec3,
    s: &mut Scratch,
    counters: &mut Counters,
) -> Estimate {
    let hit = gas_along(prep, o, d, s, counters);
    let (emitted, transmittance) = emission_absorption(&s.segments);
    let surface = behind(prep, o, d, hit, counters);
    let known = emitted + transmittance * surface;

    // Pieces of every light's scattering integrand over every segment.
    let mut pieces: Vec<(f64, f64)> = Vec::new();
    let mut meta: Vec<Piece> = Vec::new();
    let mut cands: Vec<u32> = Vec::new();
    let mut tau = 0.0f64;
    for seg in &s.segments {
        let t_a = (-tau).exp();
        tau += seg.sigma * (seg.tb - seg.ta);
        if seg.scatter == DVec3::ZERO || t_a == 0.0 {
            continue;
        }
        let (xa, xb) = (o + seg.ta * d, o + seg.tb * d);
        for (i, l) in prep.lights.iter().enumerate() {
            if l.direct == DVec3::ZERO {
                continue;
            }
            let a = scatter_for(prep, seg, &s.members, i);
            if a == DVec3::ZERO {
                continue;
            }
            candidates(&prep.bvh, xa, xb, l, &mut s.candidates);
            counters.shadow_candidates += s.candidates.len() as u64;
            let c0 = cands.len();
            cands.extend_from_slice(&s.candidates);
            s.breaks.clear();
            s.breaks.push(seg.ta);
            s.breaks.push(seg.tb);
            for &k in &s.candidates {
                let p = &prep.bvh.prims[k as usize];
                breakpoints(
                    p,
                    &prep.bvh.to_object,
                    o,
                    d,
                    l,
                    (seg.ta, seg.tb),
                    &mut s.breaks,
                );
            }
            if let LightKind::Point {
                position, radius, ..
            } = l.kind
            {
                if let Some((r0, r1)) = crate::geom::sphere_roots(o, d, position, radius) {
                    s.breaks
                        .extend([r0, r1].into_iter().filter(|t| *t > seg.ta && *t < seg.tb));
                }
            }
            s.breaks.sort_unstable_by(f64::total_cmp);
            s.breaks.dedup();
            for w in s.breaks.windows(2) {
                pieces.push((w[0], w[1]));
                meta.push(Piece {
                    ta: seg.ta,
                    sigma: seg.sigma,
                    coeff: t_a * PHASE * a * l.direct,
                    light: i,
                    cands: (c0, cands.len()),
                });
            }
        }
    }
    if pieces.is_empty() {
        return Estimate {
            value: known,
            error: 0.0,
            covered: hit.is_some() || !s.segments.is_empty(),
        };
    }
    let bvh = &prep.bvh;
    let tol = prep.tol;
    let q = integrate(
        &pieces,
        |k, t| {
            let m = &meta[k];
            let x = o + t * d;
            let l = &prep.lights[m.light];
            let Some((dir, dist, att)) = towards(l, x) else {
                return DVec3::ZERO;
            };
            // V_i(x) from the candidates alone: every sphere a light ray from this segment
            // can meet is among them.
            let mut od = 0.0;
            for &c in &cands[m.cands.0..m.cands.1] {
                let p = &bvh.prims[c as usize];
                if let Some((t0, t1)) = bvh.roots(p, x, dir) {
                    if p.is_gas() {
                        let overlap = t1.min(dist) - t0.max(0.0);
                        if overlap > 0.0 {
                            od += p.sigma * overlap;
                        }
                    } else if t0 > 0.0 && t0 < dist {
                        return DVec3::ZERO;
                    }
                }
            }
            m.coeff * (att * (-(m.sigma * (t - m.ta) + od)).exp())
        },
        |v| tol * (known + v).abs().max_element().max(1e-3),
        MAX_INTERVALS,
        &mut crate::render::quadrature::QuadScratch::default(),
    );
    counters.quadrature_nodes += q.evals;
    Estimate {
        value: known + q.value,
        error: q.error,
        covered: true,
    }
}
