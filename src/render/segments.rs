//! Gas along a camera ray: every gas-sphere interval up to the first opaque hit, gathered in
//! one BVH traversal, and the sweep that cuts them into segments of constant extinction and
//! source (MODEL.md section 3).

use glam::DVec3;

use super::gas::emission_albedo;
use super::integrators::surface::{nearer_surface, Opaque, OpaqueHit};
use super::Prepared;

/// One gas sphere's interval along the ray, clipped to `t >= 0`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Interval {
    pub t0: f64,
    pub t1: f64,
    pub prim: u32,
}

/// A piece of the ray where the same gas spheres overlap: `sigma = sum sigma_j`,
/// `emit = sum sigma_j C_j`, `scatter = sum sigma_j a_j`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Segment {
    /// The gas spheres present: `members[m.0 .. m.0 + m.1]` of [`sweep`]'s member list, as
    /// primitive indices.
    pub members: (u32, u32),
    pub ta: f64,
    pub tb: f64,
    pub sigma: f64,
    pub emit: DVec3,
    pub scatter: DVec3,
}

/// The first opaque hit along `o + t d` (`t > 0`, spheres seen from outside, or a surface in
/// front of them) and, in the same traversal, every gas interval in front of the spheres. Intervals are not yet clipped at the hit.
pub fn gather(prep: &Prepared, o: DVec3, d: DVec3, out: &mut Vec<Interval>) -> Option<OpaqueHit> {
    out.clear();
    let sphere = prep
        .bvh
        .closest(o, d, 0.0, f64::INFINITY, |i, p, (t0, t1)| {
            if p.is_gas() {
                if t1 > 0.0 && t1 > t0 {
                    out.push(Interval {
                        t0: t0.max(0.0),
                        t1,
                        prim: i,
                    });
                }
                None
            } else {
                (t0 > 0.0).then_some(t0)
            }
        })
        .map(|h| OpaqueHit {
            t: h.t,
            on: Opaque::Sphere(h.prim),
        });
    nearer_surface(prep, o, d, 0.0, sphere)
}

/// Cuts the intervals (clipped to `[0, t_end]`) into segments. The sums are recomputed from
/// the active set at every event rather than updated by adding and subtracting, so that a gap
/// is exactly empty and a thin gas inside a dense one keeps its own sigma.
pub fn sweep(
    prep: &Prepared,
    intervals: &[Interval],
    t_end: f64,
    events: &mut Vec<(f64, u32)>,
    out: &mut Vec<Segment>,
    members: &mut Vec<u32>,
    active: &mut Vec<u32>,
) {
    out.clear();
    events.clear();
    members.clear();
    active.clear();
    for (k, iv) in intervals.iter().enumerate() {
        let t1 = iv.t1.min(t_end);
        if t1 > iv.t0 {
            // Even codes enter, odd codes leave.
            events.push((iv.t0, 2 * k as u32));
            events.push((t1, 2 * k as u32 + 1));
        }
    }
    events.sort_unstable_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
    let mut e = 0;
    while e < events.len() {
        let t = events[e].0;
        while e < events.len() && events[e].0 == t {
            let k = events[e].1 / 2;
            if events[e].1 % 2 == 0 {
                active.push(k);
            } else if let Some(pos) = active.iter().position(|&a| a == k) {
                active.swap_remove(pos);
            }
            e += 1;
        }
        if e < events.len() && !active.is_empty() {
            let tb = events[e].0;
            let (mut sigma, mut emit, mut scatter) = (0.0, DVec3::ZERO, DVec3::ZERO);
            let start = members.len() as u32;
            for &k in active.iter() {
                members.push(intervals[k as usize].prim);
                let p = &prep.bvh.prim(intervals[k as usize].prim);
                let (c, a) = emission_albedo(&prep.materials, p);
                sigma += p.sigma;
                emit += p.sigma * c;
                scatter += p.sigma * a;
            }
            out.push(Segment {
                members: (start, active.len() as u32),
                ta: t,
                tb,
                sigma,
                emit,
                scatter,
            });
        }
    }
}

impl Segment {
    /// What the segment emits towards its start, `(emit / sigma) (1 - exp(-sigma (tb - ta)))`,
    /// with `-expm1` so that tiny optical depths keep full relative precision (0 for gas of
    /// no extinction, which emits nothing).
    #[inline]
    pub fn emitted(&self) -> DVec3 {
        if self.sigma > 0.0 {
            // emit / sigma is a sigma-weighted mean of the C_j: no 0/0 as sigma > 0 here.
            (self.emit / self.sigma) * -(-self.sigma * (self.tb - self.ta)).exp_m1()
        } else {
            DVec3::ZERO
        }
    }
}

/// Emission and absorption in closed form over the segments, and the transmittance through
/// all of them: each segment adds `T(0, t_a) (emit / sigma) (1 - exp(-sigma (t_b - t_a)))`,
/// with `-expm1` so that optical depths down to 1e-300 keep full relative precision, and
/// `T -> 0` without NaN at optical depths far beyond 1e4.
pub fn emission_absorption(segments: &[Segment]) -> (DVec3, f64) {
    let mut tau = 0.0f64;
    let mut l = DVec3::ZERO;
    for s in segments {
        l += (-tau).exp() * s.emitted();
        tau += s.sigma * (s.tb - s.ta);
    }
    (l, (-tau).exp())
}
