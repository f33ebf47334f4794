//! Gas along a camera ray: every gas-sphere interval up to the first opaque hit, gathered in
//! one BVH traversal, and the sweep that cuts them into segments of constant extinction and
//! source (docs/model.md section 3), or, where profiled gas is present (section 6), segments
//! between sphere events whose profiled members are listed with their closed-form depths.

use glam::DVec3;

use super::density::Along;
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

/// A piece of the ray where the same gas spheres overlap. Over its constant-density members
/// `sigma = sum sigma_j`, `emit = sum sigma_j C_j`, `scatter = sum sigma_j a_j`; its profiled
/// members (docs/model.md section 6), whose densities vary along it, are listed apart.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Segment {
    /// The constant gas spheres present: `members[m.0 .. m.0 + m.1]` of [`sweep`]'s member
    /// list, as primitive indices.
    pub members: (u32, u32),
    /// The profiled ones: `profiled[p.0 .. p.0 + p.1]` of [`sweep`]'s profiled list.
    pub profiled: (u32, u32),
    pub ta: f64,
    pub tb: f64,
    pub sigma: f64,
    pub emit: DVec3,
    pub scatter: DVec3,
    /// The optical depth of the whole segment (`sigma (tb - ta)` without profiled members).
    pub depth: f64,
    /// The emission colour `C` of every member, when they all have the same one: then the
    /// emission has a closed form whatever the profiles ([`Segment::emitted`]).
    pub colour: Option<DVec3>,
    /// The largest channel of any member's `C` and of any member's `a` (bounds).
    pub emit_max: f64,
    pub albedo_max: f64,
}

/// A profiled gas sphere present in a segment: where it lies along the camera ray, its
/// colours and its index in the scene (light scopes).
#[derive(Clone, Copy, Debug)]
pub struct Member {
    pub along: Along,
    pub emit: DVec3,
    pub albedo: DVec3,
    pub sphere: u32,
}

/// [`sweep`]'s buffers.
#[derive(Default)]
pub struct SweepBuffers {
    pub events: Vec<(f64, u32)>,
    /// The sweep's set of gas spheres present.
    pub active: Vec<u32>,
    /// Per interval, its profiled primitive along the ray (when profiled).
    pub alongs: Vec<Option<Along>>,
}

/// The first opaque hit along `o + t d` (`t > 0`, spheres seen from outside, or a surface in
/// front of them) and, in the same traversal, every gas interval in front of the spheres.
/// Intervals are not yet clipped at the hit. (A ray entry point: compiled again for AVX2, see
/// `accel::bvh`.)
#[multiversion::multiversion(targets("x86_64+avx+avx2+fma+bmi1+bmi2+lzcnt+popcnt"))]
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

/// Cuts the intervals (clipped to `[0, t_end]`) into segments of the ray `o + t d`. The sums
/// are recomputed from the active set at every event rather than updated by adding and
/// subtracting, so that a gap is exactly empty and a thin gas inside a dense one keeps its
/// own sigma.
#[allow(clippy::too_many_arguments)]
pub fn sweep(
    prep: &Prepared,
    (o, d): (DVec3, DVec3),
    intervals: &[Interval],
    t_end: f64,
    b: &mut SweepBuffers,
    out: &mut Vec<Segment>,
    members: &mut Vec<u32>,
    profiled: &mut Vec<Member>,
) {
    out.clear();
    members.clear();
    profiled.clear();
    let SweepBuffers {
        events,
        active,
        alongs,
    } = b;
    events.clear();
    active.clear();
    alongs.clear();
    let any_profiled = prep.bvh.has_profiles();
    for (k, iv) in intervals.iter().enumerate() {
        let t1 = iv.t1.min(t_end);
        if t1 > iv.t0 {
            // Even codes enter, odd codes leave.
            events.push((iv.t0, 2 * k as u32));
            events.push((t1, 2 * k as u32 + 1));
        }
        if any_profiled {
            let p = prep.bvh.prim(iv.prim);
            alongs.push(p.is_profiled().then(|| Along::new(&prep.bvh, &p, o, d)));
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
            let pstart = profiled.len() as u32;
            let mut colour = None;
            let mut one_colour = true;
            let (mut emit_max, mut albedo_max) = (0.0f64, 0.0f64);
            for &k in active.iter() {
                let prim = intervals[k as usize].prim;
                let p = &prep.bvh.prim(prim);
                let (c, a) = emission_albedo(&prep.materials, p);
                match alongs.get(k as usize).copied().flatten() {
                    Some(along) => profiled.push(Member {
                        along,
                        emit: c,
                        albedo: a,
                        sphere: p.sphere,
                    }),
                    None => {
                        members.push(prim);
                        sigma += p.sigma;
                        emit += p.sigma * c;
                        scatter += p.sigma * a;
                    }
                }
                if any_profiled {
                    one_colour &= colour.is_none_or(|x| x == c);
                    colour = Some(c);
                    emit_max = emit_max.max(c.max_element());
                    albedo_max = albedo_max.max(a.max_element());
                }
            }
            let np = profiled.len() as u32 - pstart;
            let mut depth = sigma * (tb - t);
            for m in &profiled[pstart as usize..] {
                depth += m.along.depth(t, tb);
            }
            out.push(Segment {
                members: (start, members.len() as u32 - start),
                profiled: (pstart, np),
                ta: t,
                tb,
                sigma,
                emit,
                scatter,
                depth,
                colour: colour.filter(|_| one_colour),
                emit_max,
                albedo_max,
            });
        }
    }
}

impl Segment {
    /// What the segment emits towards its start, `(emit / sigma) (1 - exp(-sigma (tb - ta)))`,
    /// with `-expm1` so that tiny optical depths keep full relative precision (0 for gas of
    /// no extinction, which emits nothing).
    ///
    /// With profiled members the same holds when every member has the same colour `C`: the
    /// source is `sigma_t(t) C`, the derivative of `-C T`, so the segment sends
    /// `C (1 - exp(-depth))`. With colours that differ there is no closed form (`None`: the
    /// integrator integrates it).
    #[inline]
    pub fn emitted(&self) -> Option<DVec3> {
        if self.profiled.1 > 0 {
            return self.colour.map(|c| c * self.opacity());
        }
        Some(if self.sigma > 0.0 {
            // emit / sigma is a sigma-weighted mean of the C_j: no 0/0 as sigma > 0 here.
            (self.emit / self.sigma) * -(-self.sigma * (self.tb - self.ta)).exp_m1()
        } else {
            DVec3::ZERO
        })
    }

    /// `1 - exp(-depth)`, the part of the light entering the segment that it absorbs (by
    /// `expm1`, so that tiny depths keep full relative precision).
    #[inline]
    pub fn opacity(&self) -> f64 {
        -(-self.depth).exp_m1()
    }

    /// Whether some member is profiled.
    #[inline]
    pub fn is_profiled(&self) -> bool {
        self.profiled.1 > 0
    }

    /// Its profiled members, from [`sweep`]'s list.
    #[inline]
    pub fn members_profiled<'m>(&self, all: &'m [Member]) -> &'m [Member] {
        &all[self.profiled.0 as usize..(self.profiled.0 + self.profiled.1) as usize]
    }

    /// The optical depth of `[ta, t]`.
    #[inline]
    pub fn depth_to(&self, all: &[Member], t: f64) -> f64 {
        let mut tau = self.sigma * (t - self.ta);
        for m in self.members_profiled(all) {
            tau += m.along.depth(self.ta, t);
        }
        tau
    }

    /// `(sigma_t, sum sigma_j C_j)` at `t`.
    #[inline]
    pub fn source_at(&self, all: &[Member], t: f64) -> (f64, DVec3) {
        let (mut sigma, mut emit) = (self.sigma, self.emit);
        for m in self.members_profiled(all) {
            let s = m.along.density(t);
            sigma += s;
            emit += s * m.emit;
        }
        (sigma, emit)
    }

    /// The kinks of the profiled members' densities inside the segment, appended to `out`.
    pub fn kinks(&self, all: &[Member], out: &mut Vec<f64>) {
        for m in self.members_profiled(all) {
            if let Some(t) = m.along.kink().filter(|&t| t > self.ta && t < self.tb) {
                out.push(t);
            }
        }
    }
}

/// Emission and absorption in closed form over the segments, and the transmittance through
/// all of them: each segment adds `T(0, t_a) (emit / sigma) (1 - exp(-sigma (t_b - t_a)))`,
/// with `-expm1` so that optical depths down to 1e-300 keep full relative precision, and
/// `T -> 0` without NaN at optical depths far beyond 1e4.
///
/// Segments whose emission has no closed form ([`Segment::emitted`]) add only their
/// absorption; the caller integrates their emission.
pub fn emission_absorption(segments: &[Segment]) -> (DVec3, f64) {
    let mut tau = 0.0f64;
    let mut l = DVec3::ZERO;
    for s in segments {
        if let Some(e) = s.emitted() {
            l += (-tau).exp() * e;
        }
        tau += s.depth;
    }
    (l, (-tau).exp())
}
