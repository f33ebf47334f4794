//! The exact gas integrator (docs/model.md sections 3 and 5): emission and absorption in closed form
//! over the segments, single scattering by adaptive Gauss-Kronrod quadrature between the
//! breakpoints of each light's integrand, to `tol` relative to the ray's value (absolute floor
//! `tol * 1e-3`).
//!
//! "Exact up to the requested tolerance" is the contract, and three truncations keep the cost
//! to what can change the value within it. Each is bounded rigorously and its bound is added to
//! the reported error, so the error stays an upper estimate:
//! The ray is integrated front to back, segment by segment. Every term is non-negative, so the
//! value so far is a lower bound of the final value, and "the tolerance" at each step is `tol`
//! times the value so far (floor `1e-3`): never more than the final tolerance.
//! - **The camera ray stops** at the first point where the transmittance `T` so far times
//!   `View::rest_bound` (the most any gas, surface or background could send) is below
//!   [`CAMERA_SHARE`] of the tolerance; `T * rest_bound` is the bound. The point is a
//!   segment's start, or inside a segment (`camera_stop`), whose scattering is then
//!   integrated up to it (its emission is closed form and counted whole).
//! - **Dark pieces are not integrated**: `U_seg`, the scattering a segment would get with
//!   every shadow removed, is known in closed form, and so is `U`, the sum over the ray. The
//!   segment's share `b` of the light budget ([`LIGHT_SHARE`] of the tolerance) is half an
//!   even split between the ray's segments and half its part `U_seg / U`, so the shares sum
//!   to at most 1. A piece whose optical depth to the light is provably at least
//!   `tau_cut = ln(U_seg / b)` all over (`render::light_pieces`) adds at most its unshadowed
//!   integral times `exp(-depth)`, so the segment's dark pieces together at most `b`. If
//!   `tau_cut <= 0`, the segment's scattering is not integrated at all and `U_seg` is the
//!   bound.
//! - **A light ray stops** adding optical depth past `tau_cut +` [`NODE_MARGIN`]; such nodes
//!   can move the segment's value by at most `U_seg exp(-tau_cut - NODE_MARGIN)`.
//!
//! Each bound is reported times [`BOUND_MARGIN`], never level with the amount it bounds.
//!
//! Each segment's quadrature is asked for its share `U_seg / U` of [`QUAD_SHARE`] of the
//! tolerance. Its pieces are cut where the segment's own optical depth reaches 4, 8, 16, ...
//! (`depth_cuts`), so that no piece's camera transmittance falls by many orders.
//!
//! **Profiled gas** (docs/model.md section 6). A segment with profiled members has closed-form
//! optical depths but a source that varies along it. Its emission is still closed form when
//! every member has the same colour (`Segment::emitted`); otherwise it is integrated between
//! the linear profile's kinks, for the segment's part (its bound `T(0, ta) C_max F` over all
//! such bounds) of [`EMIT_SHARE`] of the tolerance, taken from the quadrature's share
//! ([`PROFILED_QUAD_SHARE`] is left for the scattering) in scenes with profiled gas only, so
//! that constant gas renders as before. Its scattering integrand takes the scatter weight
//! and the camera transmittance at each node; its unshadowed bound uses
//! `sum sigma_j a_j <= a_max sigma_t`, whose integral against `T` is closed form.

use glam::DVec3;

use crate::accel::Prim;

use super::{behind, gas_along, scatter_at, scatter_for, Estimate, Scratch, PHASE};
use crate::render::density::gas_depth;
use crate::render::light_pieces::{resolve, Class};
use crate::render::lights::{attenuation, towards, LightKind, LightSource};
use crate::render::quadrature::integrate;
use crate::render::segments::{Member, Segment};
use crate::render::{Counters, View};

/// Sub-intervals the quadrature may use per camera ray before it reports what it has.
const MAX_INTERVALS: usize = 4000;

/// The tolerance's share for truncating the camera ray; the shares of camera-ray truncation,
/// dark pieces and quadrature sum to 1.
pub const CAMERA_SHARE: f64 = 0.125;
/// The tolerance's share for the dark pieces, those left unintegrated because their optical
/// depth to the light is at least `tau_cut`.
pub const LIGHT_SHARE: f64 = 0.125;
/// The tolerance's share for the quadrature of single scattering.
pub const QUAD_SHARE: f64 = 0.75;
/// In scenes with profiled gas, the quadrature's share is split: [`PROFILED_QUAD_SHARE`] for
/// the scattering, [`EMIT_SHARE`] for the emission of segments whose members differ in colour
/// (the only emission without a closed form).
pub const PROFILED_QUAD_SHARE: f64 = 0.5;
/// The tolerance's share for the quadrature of emission, in scenes with profiled gas.
pub const EMIT_SHARE: f64 = 0.25;
/// How far past `tau_cut` a light ray's optical depth is followed at a quadrature node.
pub const NODE_MARGIN: f64 = 5.0;
/// Every truncation bound is reported times this: a bound is computed in floating point, and
/// where it is tight (an unshadowed segment left out whole, a faint ray stopped early) the
/// amount it bounds can equal it to the last digits. The margin keeps the reported error
/// above the true one there instead of level with it.
pub const BOUND_MARGIN: f64 = 1.0625;

/// One lit piece of one light's scattering integrand.
#[derive(Clone, Copy, Debug)]
pub struct PieceMeta {
    /// Segment start and extinction: the integrand carries `exp(-sigma (t - ta))`.
    ta: f64,
    sigma: f64,
    /// `T(0, ta) p sum sigma_j a_j C_i I_i` (per channel); for a segment with profiled
    /// members, `T(0, ta) p C_i I_i`, the scatter weight being taken at each node.
    coeff: DVec3,
    light: u32,
    /// The piece's active gas shadowers: `active[a.0 .. a.1]`.
    active: (u32, u32),
    /// The segment's index, when it has profiled members.
    profiled: Option<u32>,
    /// For the carried headlight, the camera ray's optical depth to `ta`: the light arriving
    /// is the camera ray's transmittance, not a shadow ray's.
    carried: Option<f64>,
}

/// `integral over [t0, t1] of exp(-sigma (t - ta))`, without cancellation for small depths.
fn decay_integral(sigma: f64, ta: f64, t0: f64, t1: f64) -> f64 {
    if sigma > 0.0 {
        (-sigma * (t0 - ta)).exp() * -(-sigma * (t1 - t0)).exp_m1() / sigma
    } else {
        t1 - t0
    }
}

/// The largest attenuation of `light` over the points `o + t d`, `t` in `[t0, t1]` (`d` unit).
fn attenuation_max(light: &LightSource, o: DVec3, d: DVec3, t0: f64, t1: f64) -> f64 {
    match light.kind {
        LightKind::Directional { .. } => 1.0,
        LightKind::Point {
            position,
            attenuation: a,
            ..
        } => {
            let tc = (position - o).dot(d).clamp(t0, t1);
            attenuation(a, (o + tc * d - position).length())
        }
    }
}

/// The radiance along the camera ray `o + t d`, to `view.tol`: gas emission and absorption
/// in closed form, single scattering by adaptive quadrature, then what lies behind the gas.
pub fn radiance(
    view: &View,
    o: DVec3,
    d: DVec3,
    s: &mut Scratch,
    counters: &mut Counters,
) -> Estimate {
    let hit = gas_along(view, o, d, s, counters);
    let covered = hit.is_some() || !s.segments.is_empty();
    let tol = view.tol;
    let Scratch {
        segments,
        members,
        profiled,
        kinks,
        light: buffers,
        pieces,
        meta,
        active,
        quad,
        unshadowed_by_segment,
        ..
    } = s;
    let quad_share = if view.bvh.has_profiles() {
        PROFILED_QUAD_SHARE
    } else {
        QUAD_SHARE
    };

    // The scattering every light would add along the whole ray with no shadows at all
    // (attenuation <= 1): the tolerance is shared out between segments in proportion to it.
    // Likewise the emission of segments that have no closed form, bounded by their largest
    // colour.
    unshadowed_by_segment.clear();
    let mut tau = 0.0f64;
    let mut emission_bound = 0.0;
    for seg in segments.iter() {
        let t_a = (-tau).exp();
        unshadowed_by_segment.push(segment_unshadowed(view, seg, members, t_a));
        if seg.emitted().is_none() {
            emission_bound += t_a * seg.emit_max * seg.opacity();
        }
        tau += seg.depth;
    }
    let unshadowed: f64 = unshadowed_by_segment.iter().sum();
    if let (Some(first), Some(last)) = (segments.first(), segments.last()) {
        buffers.start_ray(o, d, (first.ta, last.tb));
    }

    // Front to back: the value so far is a lower bound of the final one (every term is
    // non-negative), so the tolerance each step may use grows as the ray goes on.
    let mut value = DVec3::ZERO;
    let mut error = 0.0;
    let mut tau = 0.0f64;
    let allowed = |v: DVec3| tol * v.abs().max_element().max(1e-3);
    // Where the camera ray stopped: the bound on all that lies behind.
    let mut stopped = None;
    for (k, seg) in segments.iter().enumerate() {
        if stopped.is_some() {
            break;
        }
        let t_a = (-tau).exp();
        let rest = t_a * view.rest_bound;
        if rest <= CAMERA_SHARE * allowed(value) {
            stopped = Some(rest);
            break;
        }
        // Where the camera ray stops inside this segment (see `camera_stop`): the scattering
        // is integrated up to `t_end` only, and the ray ends with this segment.
        let stop = camera_stop(seg, profiled, tau, view.rest_bound, allowed(value));
        stopped = stop.map(|(_, bound)| bound);
        let t_end = stop.map_or(seg.tb, |(t, _)| t);
        kinks.clear();
        if seg.is_profiled() {
            kinks.push(seg.ta);
            seg.kinks(profiled, kinks);
            kinks.push(seg.tb);
        }
        depth_cuts(seg, profiled, t_end, kinks);
        kinks.sort_unstable_by(f64::total_cmp);
        match seg.emitted() {
            Some(e) => value += t_a * e,
            None => {
                // Members of different colours and profiles: no closed form. Integrated
                // between the kinks, for its part of the emission's share.
                // (A bound of 0 means it emits exactly nothing in f64.)
                let bound = t_a * seg.emit_max * seg.opacity();
                if bound > 0.0 {
                    let share = bound / emission_bound;
                    pieces.clear();
                    pieces.extend(kinks.windows(2).map(|w| (w[0], w[1])));
                    let so_far = value;
                    let q = integrate(
                        pieces,
                        |_, t| {
                            let (_, emit) = seg.source_at(profiled, t);
                            t_a * (-seg.depth_to(profiled, t)).exp() * emit
                        },
                        |v| EMIT_SHARE * share * allowed(so_far + v),
                        MAX_INTERVALS,
                        quad,
                    );
                    counters.quadrature_nodes += q.evals;
                    value += q.value;
                    error += q.error;
                }
            }
        }
        let tau_a = tau;
        tau += seg.depth;
        let u_seg = unshadowed_by_segment[k];
        if u_seg == 0.0 {
            continue;
        }
        // This segment's shares. Its dark pieces may add up to `share` of the light budget:
        // half of it split evenly between the segments (the least total work for a given
        // sum of bounds u exp(-tau) is at equal bounds), half in proportion to `u_seg`. Its
        // quadrature gets its part `u_seg / unshadowed` of the quadrature's share.
        let weight = u_seg / unshadowed;
        let share = 0.5 * (weight + 1.0 / segments.len() as f64);
        let tau_cut = (u_seg / (share * LIGHT_SHARE * allowed(value))).ln();
        if tau_cut <= 0.0 {
            error += BOUND_MARGIN * u_seg;
            continue;
        }
        pieces.clear();
        meta.clear();
        active.clear();
        for (i, l) in view.lights.iter().enumerate() {
            if l.direct == DVec3::ZERO {
                continue;
            }
            let (coeff, bound) = if seg.is_profiled() {
                if seg.albedo_max == 0.0 {
                    continue;
                }
                // The scatter weight varies along the segment: taken at each node.
                let c = t_a * PHASE * l.direct;
                (c, c.max_element() * seg.albedo_max)
            } else {
                let a = scatter_for(view, seg, members, i);
                if a == DVec3::ZERO {
                    continue;
                }
                let c = t_a * PHASE * a * l.direct;
                (c, c.max_element())
            };
            if l.carried {
                // No shadow: one lit piece, cut at the kinks of profiled densities.
                let m = PieceMeta {
                    ta: seg.ta,
                    sigma: seg.sigma,
                    coeff,
                    light: i as u32,
                    active: (0, 0),
                    profiled: seg.is_profiled().then_some(k as u32),
                    carried: Some(tau_a),
                };
                push_cut(pieces, meta, m, (seg.ta, t_end), kinks);
                continue;
            }
            let (found, n) = resolve(
                view,
                o,
                d,
                (seg.ta, t_end),
                (i, l, view.grids[i].as_ref()),
                tau_cut,
                buffers,
                active,
            );
            counters.shadow_candidates += n as u64;
            for p in found {
                match p.class {
                    Class::Lit(range) => {
                        let m = PieceMeta {
                            ta: seg.ta,
                            sigma: seg.sigma,
                            coeff,
                            light: i as u32,
                            active: range,
                            profiled: seg.is_profiled().then_some(k as u32),
                            carried: None,
                        };
                        push_cut(pieces, meta, m, (p.t0, p.t1), kinks);
                    }
                    Class::Dark(depth) => {
                        // The unshadowed integral of the piece: `decay_integral` times the
                        // constant scatter weight, or with profiled members at most the
                        // largest albedo times `T(ta, t0) - T(ta, t1)` (the integral of
                        // `sigma_t T`).
                        let unshadowed = if seg.is_profiled() {
                            let d0 = seg.depth_to(profiled, p.t0);
                            let d1 = seg.depth_to(profiled, p.t1);
                            (-d0).exp() * -(d0 - d1).exp_m1()
                        } else {
                            decay_integral(seg.sigma, seg.ta, p.t0, p.t1)
                        };
                        error += BOUND_MARGIN
                            * bound
                            * attenuation_max(l, o, d, p.t0, p.t1)
                            * (-depth).exp()
                            * unshadowed;
                    }
                    Class::Zero => {}
                }
            }
        }
        if pieces.is_empty() {
            continue;
        }
        let limit = tau_cut + NODE_MARGIN;
        let mut deep = false;
        let so_far = value;
        let gas = RayGas {
            segments,
            members,
            profiled,
        };
        let q = integrate(
            pieces,
            |k, t| scattered(view, &gas, &meta[k], active, o + t * d, t, limit, &mut deep),
            |v| quad_share * weight * allowed(so_far + v),
            MAX_INTERVALS,
            quad,
        );
        counters.quadrature_nodes += q.evals;
        value += q.value;
        error += q.error;
        if deep {
            error += BOUND_MARGIN * u_seg * (-limit).exp();
        }
    }
    if let Some(bound) = stopped {
        // What lies behind cannot change the value within its share of the tolerance.
        return Estimate {
            value,
            error: error + BOUND_MARGIN * bound,
            covered,
        };
    }
    let seen_through = (-tau).exp();
    let surface = behind(view, o, d, hit, seen_through, counters);
    Estimate {
        value: value + seen_through * surface,
        error,
        covered,
    }
}

/// Where the camera ray may stop inside `seg`, which starts at the ray's optical depth `tau_a`:
/// the first point `t` where everything behind it, at most `T(0, t) rest_bound`, is below
/// [`CAMERA_SHARE`] of `allowed`, with that bound (`None`: not inside this segment). Only a
/// segment deep enough to hold the point has one; the segment-start test of [`radiance`] covers
/// the rest.
fn camera_stop(
    seg: &Segment,
    profiled: &[Member],
    tau_a: f64,
    rest_bound: f64,
    allowed: f64,
) -> Option<(f64, f64)> {
    let level = (rest_bound / (CAMERA_SHARE * allowed)).ln() - tau_a;
    if !(level > 0.0 && level < seg.depth) {
        return None;
    }
    let t = at_depth(seg, profiled, level);
    // The bound from the depth actually reached (at least `level`).
    let depth = seg.depth_to(profiled, t).max(level);
    Some((t, (-(tau_a + depth)).exp() * rest_bound))
}

/// A point of `seg` where its optical depth from the start is at least `level` (and within a
/// few parts in 1e4 of the segment past the exact point), `level < seg.depth`.
fn at_depth(seg: &Segment, profiled: &[Member], level: f64) -> f64 {
    if !seg.is_profiled() {
        return (seg.ta + level / seg.sigma).min(seg.tb);
    }
    // The depth grows monotonically along the segment: bisection, keeping the far end.
    let (mut lo, mut hi) = (seg.ta, seg.tb);
    for _ in 0..13 {
        let mid = 0.5 * (lo + hi);
        if seg.depth_to(profiled, mid) >= level {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    hi
}

/// Cuts a segment's scattering where its own optical depth (from the start) reaches 4, 8,
/// 16, ... before `t_end`: in optically thick gas the camera ray's transmittance falls by many
/// orders along one piece, and a 15-point rule over it can see agreement of its two estimates
/// where both are wrong (a thick quadratic profile lit along the view direction was 3 % low
/// with an error estimate of 2e-4 of the value). On the piece from depth `L` to `2 L` the
/// transmittance falls by `e^-L`, while the piece holds less than `e^-L` of the integral; a
/// fall by `e^-4` on the first piece is resolved by the rule's nodes. Measured on the thick
/// gas clouds (cloud-thick-1e3 and 1e4, 128 x 128): quadrature nodes within 0.4 % of no cuts
/// (starting at depth 1 instead cost 25 % more nodes and 9 % more time). Appended to `out`
/// (unsorted); none in a segment thinner than 4.
fn depth_cuts(seg: &Segment, profiled: &[Member], t_end: f64, out: &mut Vec<f64>) {
    let mut level = 4.0;
    while level < seg.depth {
        let t = at_depth(seg, profiled, level);
        if t >= t_end {
            break;
        }
        out.push(t);
        level *= 2.0;
    }
}

/// Appends the lit piece `[t0, t1]` with `m`, cut at the kinks of profiled densities (none
/// for constant gas).
fn push_cut(
    pieces: &mut Vec<(f64, f64)>,
    meta: &mut Vec<PieceMeta>,
    m: PieceMeta,
    (t0, t1): (f64, f64),
    kinks: &[f64],
) {
    let mut from = t0;
    for &t in kinks.iter().filter(|&&t| t > t0 && t < t1) {
        pieces.push((from, t));
        meta.push(m);
        from = t;
    }
    pieces.push((from, t1));
    meta.push(m);
}

/// The segment's scattering with every shadow removed (a bound: attenuation <= 1), largest
/// channel, summed over the lights; `t_a` is the transmittance to its start.
fn segment_unshadowed(view: &View, seg: &Segment, members: &[u32], t_a: f64) -> f64 {
    let mut u = 0.0;
    for (i, l) in view.lights.iter().enumerate() {
        if l.direct == DVec3::ZERO {
            continue;
        }
        if seg.is_profiled() {
            // sum sigma_j(t) a_j <= albedo_max sigma_t(t), whose integral against the
            // transmittance is 1 - exp(-depth).
            u += t_a * PHASE * l.direct.max_element() * seg.albedo_max * seg.opacity();
            continue;
        }
        let a = scatter_for(view, seg, members, i);
        u += (t_a * PHASE * a * l.direct).max_element()
            * decay_integral(seg.sigma, seg.ta, seg.ta, seg.tb);
    }
    u
}

/// The camera ray's segments and their members, for the integrand of a profiled segment.
struct RayGas<'a> {
    segments: &'a [Segment],
    members: &'a [u32],
    profiled: &'a [Member],
}

/// The integrand of a lit piece at `x = o + t d`. A light ray whose optical depth passes
/// `limit` stops there and counts as dark (`deep` is set; the caller bounds it).
#[inline]
#[allow(clippy::too_many_arguments)]
fn scattered(
    view: &View,
    gas: &RayGas,
    m: &PieceMeta,
    active: &[Prim],
    x: DVec3,
    t: f64,
    limit: f64,
    deep: &mut bool,
) -> DVec3 {
    let l = &view.lights[m.light as usize];
    let Some((dir, dist, att)) = towards(l, x) else {
        return DVec3::ZERO;
    };
    if let Some(tau_a) = m.carried {
        // The carried headlight arrives through the gas in front along the camera ray.
        return match m.profiled {
            None => m.coeff * (-(2.0 * m.sigma * (t - m.ta) + tau_a)).exp(),
            Some(k) => {
                let seg = &gas.segments[k as usize];
                let a = scatter_at(view, seg, gas.members, gas.profiled, m.light as usize, t);
                m.coeff * a * (-(2.0 * seg.depth_to(gas.profiled, t) + tau_a)).exp()
            }
        };
    }
    // V_i(x) from the piece's active shadowers alone: no other sphere meets a light ray from
    // this piece, and no opaque one does.
    let mut od = 0.0;
    for p in &active[m.active.0 as usize..m.active.1 as usize] {
        od += gas_depth(view, p, x, dir, dist);
        if od > limit {
            *deep = true;
            return DVec3::ZERO;
        }
    }
    match m.profiled {
        None => m.coeff * (att * (-(m.sigma * (t - m.ta) + od)).exp()),
        Some(k) => {
            let seg = &gas.segments[k as usize];
            let a = scatter_at(view, seg, gas.members, gas.profiled, m.light as usize, t);
            m.coeff * a * (att * (-(seg.depth_to(gas.profiled, t) + od)).exp())
        }
    }
}
