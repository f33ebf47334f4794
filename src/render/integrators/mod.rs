//! Integrators, one per file, each answering `radiance(ray) -> Estimate`. The set is closed and
//! chosen by name (an enum, not trait objects in the hot loop).
//!
//! - [`surface`]: opaque spheres and surfaces only (the whole answer when the scene has no gas).
//! - [`exact`]: gas emission and absorption in closed form, single scattering by adaptive
//!   quadrature between breakpoints, to `--tol` (the default).
//! - [`march`]: fixed-step ray marching with midpoint samples (an approximation, by name only).
//! - [`mc`]: unbiased Monte Carlo: expected-value emission, one sampled scattering point per
//!   segment.

pub mod exact;
pub mod march;
pub mod mc;
pub mod surface;

use glam::DVec3;

use super::lighting::shade;
use super::sampler::Rng;
use super::segments::{Interval, Member, Segment};
use super::{Counters, Integrator, View};
use surface::OpaqueHit;

/// What one camera ray returns.
#[derive(Clone, Copy, Debug, Default)]
pub struct Estimate {
    /// Radiance (linear RGB).
    pub value: DVec3,
    /// Estimated absolute error of `value` (0 where the answer is exact up to rounding).
    pub error: f64,
    /// Whether the ray hit an opaque sphere or passed through gas (pixel coverage, alpha).
    pub covered: bool,
}

/// Reusable buffers of one worker (no allocation per ray once they have grown).
#[derive(Default)]
pub struct Scratch {
    /// The camera ray's intervals inside gas spheres, before they are cut into segments.
    pub intervals: Vec<Interval>,
    /// The sweep's own buffers.
    pub sweep: super::segments::SweepBuffers,
    /// The camera ray's gas segments, in order along it.
    pub segments: Vec<Segment>,
    /// The constant-density gas spheres of the segments (primitive indices), each segment's in
    /// one run that it indexes.
    pub members: Vec<u32>,
    /// The segments' profiled members.
    pub profiled: Vec<Member>,
    /// Kinks of profiled densities within one segment (the exact integrator's breakpoints).
    pub kinks: Vec<f64>,
    /// The exact integrator's: shadow pieces of one segment and light, the lit pieces of the
    /// whole ray with their shadowers, and the quadrature's buffers.
    pub light: super::light_pieces::Buffers,
    /// The exact integrator's pieces `(t0, t1)` of the ray, one integrand each.
    pub pieces: Vec<(f64, f64)>,
    /// What each of `pieces` integrates.
    pub meta: Vec<exact::PieceMeta>,
    /// The lit pieces' active gas shadowers, whole (the integrand reads them in a row).
    pub active: Vec<crate::accel::Prim>,
    /// The quadrature's buffers.
    pub quad: super::quadrature::QuadScratch,
    /// The exact integrator's unshadowed scattering bound of each segment.
    pub unshadowed_by_segment: Vec<f64>,
    /// The spheres that last blocked each light's shadow rays (opaque scenes).
    pub blockers: super::visibility::Blockers,
}

/// The camera ray's radiance with the chosen integrator. Scenes without gas always take the
/// surface integrator: every integrator reduces to it there.
///
/// Ambient occlusion is a picture of its own, not a way to integrate gas: the tile loop
/// shades it (`render::ao::radiance_of_hit`), and this function panics when asked for it.
pub fn radiance(
    view: &View,
    o: DVec3,
    d: DVec3,
    rng: &mut Rng,
    scratch: &mut Scratch,
    counters: &mut Counters,
) -> Estimate {
    assert!(
        !matches!(view.integrator, Integrator::Ao(_)),
        "ambient occlusion is shaded by render::ao, not by an integrator"
    );
    if view.gas_spheres == 0 {
        return surface::radiance(view, o, d, &mut scratch.blockers, counters);
    }
    match view.integrator {
        Integrator::Exact => exact::radiance(view, o, d, scratch, counters),
        Integrator::March { step } => march::radiance(view, o, d, step, scratch, counters),
        Integrator::Mc => mc::radiance(view, o, d, rng, scratch, counters),
        Integrator::Ao(_) => unreachable!("refused above"),
    }
}

/// Counts the camera ray, finds its first opaque hit and cuts the gas in front of it into
/// `s.segments` (one traversal, then the sweep).
pub fn gas_along(
    view: &View,
    o: DVec3,
    d: DVec3,
    s: &mut Scratch,
    counters: &mut Counters,
) -> Option<OpaqueHit> {
    counters.camera_rays += 1;
    let hit = super::segments::gather(view, o, d, &mut s.intervals);
    let t_end = hit.map_or(f64::INFINITY, |h| h.t);
    super::segments::sweep(
        view,
        (o, d),
        &s.intervals,
        t_end,
        &mut s.sweep,
        &mut s.segments,
        &mut s.members,
        &mut s.profiled,
    );
    hit
}

/// Radiance of the opaque surface `hit` (or the background), as seen along `d` through gas
/// of transmittance `seen_through` (which the caller applies; the carried headlight reaches
/// the surface through it too).
pub fn behind(
    view: &View,
    o: DVec3,
    d: DVec3,
    hit: Option<OpaqueHit>,
    seen_through: f64,
    c: &mut Counters,
) -> DVec3 {
    match hit {
        None => view.background,
        Some(h) => {
            let sp = surface::surface_point(view, o, d, h);
            // (No blockers kept: behind gas, the shading is a small part of the work.)
            let mut blockers = super::visibility::Blockers::default();
            shade(
                view,
                &surface::material_of(view, h.on),
                &sp,
                seen_through,
                &mut blockers,
                c,
            )
        }
    }
}

/// `p * sum_i E_i(x)`-style light sum at a point in gas, through the BVH (march and mc):
/// per light, the scatter weights of the gas present (`scatter(i)`, light scoping applied by
/// the caller) times the light arriving. `seen_through` is the camera ray's transmittance up
/// to `x`: the carried headlight's visibility there.
pub fn lights_at(
    view: &View,
    x: DVec3,
    mut scatter: impl FnMut(usize) -> DVec3,
    seen_through: f64,
    c: &mut Counters,
) -> DVec3 {
    let mut sum = DVec3::ZERO;
    for (i, l) in view.lights.iter().enumerate() {
        if l.direct == DVec3::ZERO {
            continue;
        }
        let Some((dir, dist, att)) = super::lights::towards(l, x) else {
            continue;
        };
        let a = scatter(i);
        if a == DVec3::ZERO {
            continue;
        }
        let v = if l.carried {
            seen_through
        } else {
            c.shadow_rays += 1;
            super::visibility::visible(view, x, dir, dist, None)
        };
        sum += a * l.direct * (att * v);
    }
    sum * PHASE
}

/// The isotropic phase function, `1 / (4 pi)`.
pub const PHASE: f64 = 0.25 * std::f64::consts::FRAC_1_PI;

/// The scatter weight `sum sigma_j(t) a_j` at `t` of a segment for light `i`: its constant
/// members' ([`scatter_for`]) and its profiled members' (`profiled`: the sweep's list), each
/// counted where light `i` may light it.
pub fn scatter_at(
    view: &View,
    seg: &Segment,
    members: &[u32],
    profiled: &[Member],
    i: usize,
    t: f64,
) -> DVec3 {
    let l = &view.lights[i];
    let mut sum = scatter_for(view, seg, members, i);
    for m in seg.members_profiled(profiled) {
        if m.albedo != DVec3::ZERO && super::lights::in_scope(l, m.sphere) {
            sum += m.along.density(t) * m.albedo;
        }
    }
    sum
}

/// Scatter weight `sum sigma_j a_j` of a segment's constant members for light `i`, over the
/// members light `i` may light (VRML scoping of DirectionalLights applies to gas spheres as
/// to surfaces).
pub fn scatter_for(view: &View, seg: &Segment, members: &[u32], i: usize) -> DVec3 {
    let l = &view.lights[i];
    match l.kind {
        super::lights::LightKind::Directional {
            scope: crate::scene::LightScope::Range { .. },
            ..
        } => {
            let ms = &members[seg.members.0 as usize..(seg.members.0 + seg.members.1) as usize];
            ms.iter()
                .map(|&k| {
                    let p = &view.bvh.prim(k);
                    if super::lights::in_scope(l, p.sphere) {
                        p.sigma * super::gas::emission_albedo(&view.materials, p).1
                    } else {
                        DVec3::ZERO
                    }
                })
                .sum()
        }
        _ => seg.scatter,
    }
}
