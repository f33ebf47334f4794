//! One light's single-scattering integrand over one camera segment, cut into smooth pieces,
//! each either integrated, bounded, or exactly zero (docs/model.md sections 3 and 5).
//!
//! Along the segment `[ta, tb]` of `x(t) = o + t d`, the light arriving at `x(t)` is
//! `exp(-sum_j sigma_j l_j(t))` (or 0 behind an opaque shadower), where `l_j(t)` is the length
//! of the light ray from `x(t)` inside shadower `j`. Between consecutive breakpoints
//! (`render::breakpoints`) every `l_j` keeps one form, and it is either 0 throughout or positive
//! throughout, so each piece has a fixed list of **active** shadowers.
//!
//! **Dark pieces.** On a piece, the optical depth `od(t) = sum_j sigma_j l_j(t)` of the active
//! shadowers takes its minimum at an end of the piece, because it is concave in a monotone
//! parameter of the piece:
//! - directional light: the full chord `2 sqrt(r^2 - rho(t)^2)` (`rho^2` is a convex quadratic
//!   in `t`) and the exit distance from inside (a linear function plus such a root) are
//!   concave in `t` (for an ellipsoid, in its object space, where `t` is the same);
//! - point light: the light rays from a straight camera ray lie in one plane through `P`; let
//!   `phi` be their angle in that plane, monotone in `t`. The full chord through a sphere at
//!   distance `D` is `2 sqrt(g)`, `g = c + k cos^2(phi - phi_j)` with `c = r^2 - D^2 < 0` and
//!   `k = D^2 A^2` (`A` the length of the direction to the centre projected on the plane).
//!   With `s = c + k/2`, `(sqrt g)'' <= 0` wherever `g > 0` reduces to
//!   `k^2 C^2 + 4 k s C + k^2 > 0` for `C = cos 2(phi - phi_j)`, true when `|s| < k/2`, i.e.
//!   `-k < c < 0`, which holds whenever the plane meets the sphere at all. From inside a
//!   shadower, with the light inside it, or for an ellipsoid, no such argument is made, and
//!   those shadowers are left out of the bound (their depth is at least 0).
//!
//! So `od_lower = min(od(t0), od(t1))` (over the shadowers the argument covers) bounds the
//! piece's optical depth from below, and its integrand is at most the unshadowed integrand
//! times `exp(-od_lower)`. A piece with `od_lower >= tau_cut` is **dark**: it is not
//! integrated, and that bound goes into the reported error.
//!
//! **Depth bands.** The shadowers are searched band by band along the light rays
//! (`render::shadow_volume`): after each band, the pieces already dark are dropped, and only
//! the lit parts of the segment are searched in the next band. A sub-piece of a dark piece stays
//! dark (the same shadowers' depth is concave on it too, with a minimum no smaller, and more
//! shadowers only add depth), so no shadower found later can make it lit.
//! In a thick cloud a few bands make nearly every piece dark, whatever lies beyond.

use glam::DVec3;

use super::breakpoints::breakpoints;
use super::density::{gas_chord, gas_depth};
use super::light_grid::LightGrid;
use super::lights::{opaque_reach, path_to, towards, LightKind, LightSource};
use super::shadow_volume::{band_edges, path_end, BandCache};
use super::Prepared;
use crate::accel::Prim;

/// What a piece's integrand is.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Class {
    /// Lit: integrate, with the active gas shadowers `active[a.0 .. a.1]`.
    Lit((u32, u32)),
    /// Dark: the optical depth to the light is at least this all over the piece.
    Dark(f64),
    /// Exactly zero: behind an opaque shadower, or out of the light's reach.
    Zero,
}

/// A part `[t0, t1]` of a segment over which one light's integrand is of one class.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Piece {
    /// Its start, a parameter along the camera ray.
    pub t0: f64,
    /// Its end, at least `t0`.
    pub t1: f64,
    /// What its integrand is.
    pub class: Class,
}

/// A shadower of the segment and the part `[lo, hi]` of the segment it shadows (empty when
/// `lo > hi`); by convexity of the set of points it shadows, that part is one interval.
#[derive(Clone, Copy, Debug)]
struct Shadower {
    /// Its index in the BVH (read by the tests through [`Buffers::shadowers`]).
    #[cfg(test)]
    prim: u32,
    lo: f64,
    hi: f64,
    /// The primitive itself: the pieces read it in a row, not through the BVH's arrays.
    whole: Prim,
}

/// Reusable buffers (one set per worker).
#[derive(Default)]
pub struct Buffers {
    shadowers: Vec<Shadower>,
    seen: Vec<u32>,
    found: Vec<u32>,
    breaks: Vec<f64>,
    own: Vec<f64>,
    spans: Vec<(f64, f64)>,
    order: Vec<u32>,
    live: Vec<u32>,
    stack: Vec<u32>,
    pieces: Vec<Piece>,
    /// Surfaces (not spheres) that may shadow the segment, and the sorted, disjoint parts
    /// of the segment they block.
    surface_found: Vec<u32>,
    blocked: Vec<(f64, f64)>,
    /// The camera ray `(o, d)` and its part that may ask (see [`Buffers::start_ray`]) and,
    /// per light, its band edges and band searches.
    ray: (DVec3, DVec3),
    range: (f64, f64),
    lights: Vec<LightCache>,
}

/// One light's band edges for the current camera ray and its searches, one per band.
#[derive(Default)]
struct LightCache {
    ready: bool,
    edges: Vec<f64>,
    bands: Vec<BandCache>,
}

impl Buffers {
    /// A new camera ray, whose segments will ask [`resolve`] for parts of `[t0, t1]`, front to
    /// back: the band edges are then the same for all its segments, and one BVH descent per
    /// band serves the segments that follow within the band's depth.
    pub fn start_ray(&mut self, o: DVec3, d: DVec3, (t0, t1): (f64, f64)) {
        self.ray = (o, d);
        self.range = (t0, t1);
        for l in &mut self.lights {
            l.ready = false;
        }
    }

    /// The shadowers the last [`resolve`] found (primitive indices).
    #[cfg(test)]
    pub fn shadowers(&self) -> impl Iterator<Item = u32> + '_ {
        self.shadowers.iter().map(|s| s.prim)
    }
}

/// The light ray from `x` (unit `dir`, length `dist`) against shadower `p`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Chord {
    /// Gas: the length inside it (0 when missed).
    Gas(f64),
    /// Opaque and entered before the light.
    Blocked,
}

/// The light ray from `x` (unit `dir`, `dist` long) against shadower `p`: its length inside
/// gas, or [`Chord::Blocked`] when an opaque `p` is entered before the light.
#[inline]
pub fn chord(prep: &Prepared, p: &Prim, x: DVec3, dir: DVec3, dist: f64) -> Chord {
    if p.is_gas() {
        return Chord::Gas(gas_chord(prep, p, x, dir, dist));
    }
    match prep.bvh.roots(p, x, dir) {
        Some((t0, _)) if t0 > 0.0 && t0 < opaque_reach(dist) => Chord::Blocked,
        _ => Chord::Gas(0.0),
    }
}

/// Cuts light `light`'s integrand over the segment `[ta, tb]` of `o + t d` into pieces; the
/// lit pieces' active shadowers are appended to `active`. `slot` is the light's index (its
/// band searches are kept per camera ray, see [`Buffers::start_ray`]). Returns the pieces (in
/// `b`) and the number of shadowers found. `grid` is the light's [`LightGrid`] (the BVH is
/// searched without one). `tau_cut` is the optical depth from which a piece is dark; the
/// rim breakpoints of dense shadowers go up to `4 tau_cut` (deeper ones could only split dark
/// pieces).
#[allow(clippy::too_many_arguments)]
pub fn resolve<'b>(
    prep: &Prepared,
    o: DVec3,
    d: DVec3,
    (ta, tb): (f64, f64),
    (slot, light, grid): (usize, &LightSource, Option<&LightGrid>),
    tau_cut: f64,
    b: &'b mut Buffers,
    active: &mut Vec<Prim>,
) -> (&'b [Piece], usize) {
    b.shadowers.clear();
    b.seen.clear();
    b.breaks.clear();
    b.breaks.extend([ta, tb]);
    if let LightKind::Point {
        position,
        radius,
        attenuation: a,
    } = light.kind
    {
        // The light's reach (a jump) and the corner of 1 / max(a0 + a1 r + a2 r^2, 1) where
        // the quadratic reaches 1.
        let mut spheres = [radius, -1.0];
        if a.x < 1.0 && (a.y > 0.0 || a.z > 0.0) {
            let (qa, qb, qc) = (a.z, a.y, a.x - 1.0);
            spheres[1] = if qa > 0.0 {
                let disc = (qb * qb - 4.0 * qa * qc).max(0.0).sqrt();
                // The positive root without cancellation: 2 c' / (-b - sqrt(disc)), c' < 0.
                2.0 * -qc / (qb + disc)
            } else {
                -qc / qb
            };
        }
        for r in spheres {
            if r > 0.0 {
                if let Some((r0, r1)) = crate::geom::sphere_roots(o, d, position, r) {
                    b.breaks
                        .extend([r0, r1].into_iter().filter(|t| *t > ta && *t < tb));
                }
            }
        }
    }
    surface_shadows(prep, o, d, (ta, tb), light, b);
    let rim_cap = 4.0 * tau_cut.max(1.0);
    if b.ray != (o, d) || !(b.range.0 <= ta && tb <= b.range.1) {
        // Not announced by start_ray: this segment alone.
        b.start_ray(o, d, (ta, tb));
    }
    if b.lights.len() <= slot {
        b.lights.resize_with(slot + 1, LightCache::default);
    }
    let cache = &mut b.lights[slot];
    if !cache.ready {
        let (xa, xb) = (o + b.range.0 * d, o + b.range.1 * d);
        let base = 8.0 * prep.typical_radius;
        band_edges(&prep.bvh, &light.kind, xa, xb, base, &mut cache.edges);
        if cache.bands.len() < cache.edges.len() {
            cache
                .bands
                .resize_with(cache.edges.len(), BandCache::default);
        }
        for band in &mut cache.bands {
            band.clear();
        }
        cache.ready = true;
    }
    b.spans.clear();
    b.spans.push((ta, tb));
    let bands = b.lights[slot].edges.len() - 1;
    for band in 0..bands {
        let cache = &mut b.lights[slot];
        let f = (cache.edges[band], cache.edges[band + 1]);
        b.found.clear();
        for &span in &b.spans {
            cache.bands[band].query(
                &prep.bvh,
                grid,
                &light.kind,
                (o, d),
                f,
                span,
                b.range.1,
                &mut b.found,
                &mut b.stack,
            );
        }
        b.found.sort_unstable();
        b.found.dedup();
        for &i in &b.found {
            if b.seen.binary_search(&i).is_ok() {
                continue;
            }
            let p = &prep.bvh.prim(i);
            let s = shadowed_part(prep, p, o, d, light, (ta, tb), rim_cap, &mut b.own);
            b.breaks.extend_from_slice(&b.own);
            b.shadowers.push(Shadower {
                #[cfg(test)]
                prim: i,
                ..s
            });
        }
        // Keep `seen` sorted for the next band's look-ups.
        b.seen.extend(b.found.iter().copied());
        b.seen.sort_unstable();
        b.seen.dedup();
        let last = band + 1 == bands;
        let mark = active.len();
        classify(prep, o, d, light, tau_cut, b, active);
        if last {
            break;
        }
        // The lit parts, merged, are what the next band searches; drop this round's lists.
        active.truncate(mark);
        b.spans.clear();
        for p in &b.pieces {
            if matches!(p.class, Class::Lit(_)) {
                match b.spans.last_mut() {
                    Some(s) if s.1 == p.t0 => s.1 = p.t1,
                    _ => b.spans.push((p.t0, p.t1)),
                }
            }
        }
        if b.spans.is_empty() {
            break;
        }
    }
    (&b.pieces, b.shadowers.len())
}

/// The parts of `[ta, tb]` that the scene's surfaces (not spheres) block from `light`, into
/// `b.blocked`, their ends into `b.breaks`. Opaque, they make those parts exactly zero; the
/// candidates come from one region query over the whole light path of the segment.
fn surface_shadows(
    prep: &Prepared,
    o: DVec3,
    d: DVec3,
    (ta, tb): (f64, f64),
    light: &LightSource,
    b: &mut Buffers,
) {
    b.blocked.clear();
    if prep.surfaces.is_empty() {
        return;
    }
    let (xa, xb) = (o + ta * d, o + tb * d);
    let end = path_end(&prep.surfaces.bvh, &light.kind, xa, xb).max(0.0);
    let region = super::shadow_volume::Region::band(&light.kind, xa, xb, 0.0, end);
    b.surface_found.clear();
    super::shadow_volume::gather(
        &prep.surfaces.bvh,
        &region,
        &mut b.surface_found,
        &mut b.stack,
    );
    // The BVH's primitive indices, as surface indices.
    for i in &mut b.surface_found {
        *i = prep.surfaces.bvh.prim(*i).sphere;
    }
    prep.surfaces.shadowed_parts(
        &b.surface_found,
        o,
        d,
        &light.kind,
        (ta, tb),
        &mut b.own,
        &mut b.blocked,
    );
    for &(lo, hi) in &b.blocked {
        b.breaks
            .extend([lo, hi].into_iter().filter(|t| *t > ta && *t < tb));
    }
}

/// Whether `t` lies in one of the sorted, disjoint intervals `blocked`.
#[inline]
fn in_blocked(blocked: &[(f64, f64)], t: f64) -> bool {
    let k = blocked.partition_point(|iv| iv.1 <= t);
    blocked.get(k).is_some_and(|iv| iv.0 <= t)
}

/// Shadower `p`'s breakpoints in `(ta, tb)` (into `own`, sorted) and the part of the segment it
/// shadows (`lo > hi` if none).
#[allow(clippy::too_many_arguments)]
fn shadowed_part(
    prep: &Prepared,
    p: &Prim,
    o: DVec3,
    d: DVec3,
    light: &LightSource,
    (ta, tb): (f64, f64),
    rim_cap: f64,
    own: &mut Vec<f64>,
) -> Shadower {
    own.clear();
    breakpoints(
        p,
        &prep.bvh.to_object,
        o,
        d,
        &light.kind,
        (ta, tb),
        rim_cap,
        own,
    );
    own.sort_unstable_by(f64::total_cmp);
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    let mut prev = ta;
    for k in 0..=own.len() {
        let next = own.get(k).copied().unwrap_or(tb);
        if next > prev {
            let x = o + (0.5 * (prev + next)) * d;
            // The light's geometry, not its reach: a sub-interval may straddle a point
            // light's radius, and its part inside the radius is shadowed as its middle is.
            if let Some((dir, dist)) = path_to(light, x) {
                let on = match chord(prep, p, x, dir, dist) {
                    Chord::Gas(l) => l > 0.0,
                    Chord::Blocked => true,
                };
                if on {
                    lo = lo.min(prev);
                    hi = hi.max(next);
                }
            }
        }
        prev = next;
    }
    Shadower {
        #[cfg(test)]
        prim: 0,
        lo,
        hi,
        whole: *p,
    }
}

/// Cuts `[ta, tb]` at every breakpoint and classifies the pieces into `b.pieces`; the active
/// gas shadowers of lit pieces are appended to `active`.
fn classify(
    prep: &Prepared,
    o: DVec3,
    d: DVec3,
    light: &LightSource,
    tau_cut: f64,
    b: &mut Buffers,
    active: &mut Vec<Prim>,
) {
    b.breaks.sort_unstable_by(f64::total_cmp);
    b.breaks.dedup();
    b.pieces.clear();
    // Shadowers in order of where their shadow starts; `live` holds the ones started and not
    // yet ended (indices into `shadowers`).
    b.order.clear();
    b.order.extend((0..b.shadowers.len() as u32).filter(|&k| {
        let s = &b.shadowers[k as usize];
        s.lo <= s.hi
    }));
    b.order.sort_unstable_by(|&x, &y| {
        b.shadowers[x as usize]
            .lo
            .total_cmp(&b.shadowers[y as usize].lo)
    });
    b.live.clear();
    let mut next = 0;
    for w in 0..b.breaks.len().saturating_sub(1) {
        let (t0, t1) = (b.breaks[w], b.breaks[w + 1]);
        // Every shadow interval's ends are breakpoints: active on [t0, t1] iff lo <= t0 < hi.
        while next < b.order.len() && b.shadowers[b.order[next] as usize].lo <= t0 {
            b.live.push(b.order[next]);
            next += 1;
        }
        let sh = &b.shadowers;
        b.live.retain(|&k| sh[k as usize].hi > t0);
        let xm = o + (0.5 * (t0 + t1)) * d;
        if in_blocked(&b.blocked, 0.5 * (t0 + t1)) {
            // Behind a surface: exactly zero.
            b.pieces.push(Piece {
                t0,
                t1,
                class: Class::Zero,
            });
            continue;
        }
        let Some((dm, distm, _)) = towards(light, xm) else {
            b.pieces.push(Piece {
                t0,
                t1,
                class: Class::Zero,
            });
            continue;
        };
        let (x0, x1) = (o + t0 * d, o + t1 * d);
        let ends = (towards(light, x0), towards(light, x1));
        let mark = active.len();
        let (mut od0, mut od1) = (0.0, 0.0);
        let mut blocked = false;
        for &k in &b.live {
            let p = &sh[k as usize].whole;
            if !p.is_gas() {
                // The blocking status is constant on a piece; decide it at the middle.
                if chord(prep, p, xm, dm, distm) == Chord::Blocked {
                    blocked = true;
                    break;
                }
                continue;
            }
            active.push(*p);
            if bounded_at_ends(prep, p, light, xm) {
                let at = |x: DVec3, e: Option<(DVec3, f64, f64)>| match e {
                    Some((dir, dist, _)) => gas_depth(prep, p, x, dir, dist),
                    // At the light itself (the end of a piece): no bound from this end.
                    None => 0.0,
                };
                od0 += at(x0, ends.0);
                od1 += at(x1, ends.1);
            }
        }
        let od = od0.min(od1);
        let class = if blocked {
            active.truncate(mark);
            Class::Zero
        } else if od >= tau_cut {
            active.truncate(mark);
            Class::Dark(od)
        } else {
            Class::Lit((mark as u32, active.len() as u32))
        };
        b.pieces.push(Piece { t0, t1, class });
    }
}

/// Whether the gas shadower `p`'s optical depth to `light` over a piece (through `xm`, its
/// middle) takes its minimum at an end of the piece (the module comment), so that it may
/// count in the dark-piece bound.
///
/// Constant gas: the chord's concavity. A profiled shadower's depth along a full chord is
/// `sigma0 r J(beta)`, and `J` falls as `beta`, the chord's distance from the centre, grows
/// (`f` falls outwards, and the chord shortens); along the piece `beta` is largest at an end
/// exactly where the constant chord is shortest there (the same convexity). That holds for
/// full chords only, so `xm` must lie outside the shadower (and the light too).
#[inline]
fn bounded_at_ends(prep: &Prepared, p: &Prim, light: &LightSource, xm: DVec3) -> bool {
    let point_light = matches!(light.kind, LightKind::Point { .. });
    let outside_sphere = || (xm - p.center).length_squared() > p.radius * p.radius;
    if !p.is_profiled() {
        return !point_light
            || (p.ellipsoid.is_none() && outside_sphere() && light_outside(light, p));
    }
    match p.ellipsoid {
        // In object space a directional light stays one direction, and `t` is kept.
        Some(e) => {
            !point_light
                && prep.bvh.to_object[e.index()]
                    .transform_point3(xm)
                    .length_squared()
                    > 1.0
        }
        None => outside_sphere() && light_outside(light, p),
    }
}

fn light_outside(light: &LightSource, p: &Prim) -> bool {
    match light.kind {
        LightKind::Point { position, .. } => {
            (position - p.center).length_squared() > p.radius * p.radius
        }
        LightKind::Directional { .. } => true,
    }
}
