//! Light visibility `V_i(x)` (docs/model.md sections 2 and 3): 0 if an opaque sphere or another
//! opaque surface lies between `x` and the light, otherwise the transmittance `exp(-sum_j sigma_j chord_j)` of every gas
//! sphere the light ray crosses.

use glam::DVec3;

use super::lights::opaque_reach;
use super::Prepared;
use crate::accel::SphereBvh;

/// What an opaque hit is on.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Opaque {
    /// A primitive of the sphere BVH (its index, see `SphereBvh::prim`).
    Sphere(u32),
    /// A surface (an index into `Prepared::surfaces.items`, the same as into `Scene::surfaces`).
    Surface(u32),
}

impl Opaque {
    /// The sphere primitive the hit is on, if it is on one.
    pub fn sphere(self) -> Option<u32> {
        match self {
            Opaque::Sphere(prim) => Some(prim),
            Opaque::Surface(_) => None,
        }
    }
}

/// Visibility from `x` towards a light at unit direction `l`, distance `dist` (infinite for a
/// directional light). `own` is what `x` lies on, if anything: its own shadow is exact
/// from the sign of `N.L` (a sphere, a solid or a triangle is convex), so the caller decides
/// it and it is skipped here. The ray stops at the first opaque blocker, or once the optical depth
/// makes the transmittance underflow to 0.
///
/// Spheres are solid (one-sided, docs/model.md section 2): an opaque sphere blocks when the light
/// ray enters it, at its first root, between `x` and the light; a ray that starts inside an
/// opaque sphere and leaves it is not blocked by it, as a camera inside a sphere does not see
/// it. A gas sphere attenuates over the part of `[0, dist]` inside it. Opaque primitives
/// block up to [`opaque_reach`]`(dist)`: a light on an opaque surface lights the side its
/// tangent plane faces.
#[inline]
pub fn visible(prep: &Prepared, x: DVec3, l: DVec3, dist: f64, own: Option<Opaque>) -> f64 {
    visible_after(prep, x, l, dist, own, &mut None)
}

/// The opaque spheres that last blocked a shadow ray towards each light, to be tried before
/// the BVH: a shadow ray from a point next to the last one is often blocked by the same
/// sphere, and then one exact sphere test answers it. Light `k` has slot `k %`
/// [`Blockers::SLOTS`] (lights beyond that share). Speed only: [`visible_after`] answers
/// exactly what [`visible`] does, whatever a slot holds (any sphere index, of any scene, or
/// none).
#[derive(Clone, Copy, Debug, Default)]
pub struct Blockers([Option<u32>; Blockers::SLOTS]);

impl Blockers {
    /// Number of slots: lights `k` and `k + SLOTS` share one.
    pub const SLOTS: usize = 8;

    /// Light `k`'s slot.
    #[inline]
    pub fn slot(&mut self, k: usize) -> &mut Option<u32> {
        &mut self.0[k % Self::SLOTS]
    }
}

/// [`visible`], first trying the sphere in `last` (the one that blocked the previous ray
/// towards the same light), and leaving in it the opaque sphere that blocked this one, if the
/// BVH found one. The answer is [`visible`]'s, bit for bit: an opaque sphere that `last` names
/// and that blocks this ray is one the BVH's any-hit query could have stopped at.
#[inline]
pub fn visible_after(
    prep: &Prepared,
    x: DVec3,
    l: DVec3,
    dist: f64,
    own: Option<Opaque>,
    last: &mut Option<u32>,
) -> f64 {
    if !prep.surfaces.is_empty() {
        let own_surface = match own {
            Some(Opaque::Surface(i)) => Some(i),
            _ => None,
        };
        // Rounding of the hit point cannot make a neighbouring triangle (a shared edge) block
        // its own point's light ray further than this.
        let tmin = 256.0 * f64::EPSILON * x.abs().max_element();
        if prep
            .surfaces
            .blocks(x, l, tmin, opaque_reach(dist), own_surface)
        {
            return 0.0;
        }
    }
    visible_through_spheres(&prep.bvh, x, l, dist, own_sphere(own), last)
}

/// The sphere (primitive index) a point lies on, if it lies on one.
#[inline]
fn own_sphere(own: Option<Opaque>) -> Option<u32> {
    match own {
        Some(Opaque::Sphere(p)) => Some(p),
        _ => None,
    }
}

/// [`visible_after`] against the spheres alone.
/// (A ray entry point: compiled again for AVX2, see `accel::bvh`.)
#[multiversion::multiversion(targets("x86_64+avx+avx2+fma+bmi1+bmi2+lzcnt+popcnt"))]
pub fn visible_through_spheres(
    bvh: &SphereBvh,
    x: DVec3,
    l: DVec3,
    dist: f64,
    own: Option<u32>,
    last: &mut Option<u32>,
) -> f64 {
    if blocked_by_last(bvh, x, l, dist, own, *last) {
        return 0.0;
    }
    let mut along = Along::default();
    let blocked = bvh.any_prim_except(
        (x, l),
        (0.0, dist),
        own,
        // (Inlined by hand: left out of line, the closure was compiled for plain x86-64.)
        #[inline(always)]
        |i| along.meets(bvh, i, x, l, dist),
    );
    along.finish(blocked, last)
}

/// Whether `last` names an opaque sphere, other than the point's own, that blocks the ray:
/// the test the traversal's closure makes ([`Along::meets`]). Never the own sphere, which the
/// traversal skips; never gas, whose depth only adds up.
#[inline(always)]
fn blocked_by_last(
    bvh: &SphereBvh,
    x: DVec3,
    l: DVec3,
    dist: f64,
    own: Option<u32>,
    last: Option<u32>,
) -> bool {
    // No closures: left out of line, they were compiled for plain x86-64 rather than for
    // the caller's clone (`perf`: 3 % of `bench trace`'s time in one of them).
    let Some(i) = last else {
        return false;
    };
    if Some(i) == own || i as usize >= bvh.len() || bvh.packed()[i as usize].is_gas() {
        return false;
    }
    bvh.enters_between(i, x, l, opaque_reach(dist))
}

/// What a shadow ray has met so far: the optical depth of the gas, and the opaque sphere that
/// blocked it.
#[derive(Default)]
struct Along {
    tau: f64,
    blocker: Option<u32>,
}

impl Along {
    /// Takes in primitive `i`, whose box the ray reaches; true when the ray need go no
    /// further. A gas sphere's chord needs its roots; an opaque one asks only whether the ray
    /// enters it before the light ([`SphereBvh::enters_between`]).
    #[inline(always)]
    fn meets(&mut self, bvh: &SphereBvh, i: u32, x: DVec3, l: DVec3, dist: f64) -> bool {
        if bvh.packed()[i as usize].is_gas() {
            let Some((t0, t1)) = bvh.roots_of(i, x, l) else {
                return false;
            };
            let (a, b) = (t0.max(0.0), t1.min(dist));
            if b > a {
                self.tau += super::density::part_depth(bvh, &bvh.prim(i), x, l, (a, b));
            }
            // Past this, exp(-tau) is 0 in f64 whatever else the ray meets: stop (exactly the
            // same answer, for less work through dense gas).
            self.tau > 746.0
        } else {
            let blocks = bvh.enters_between(i, x, l, opaque_reach(dist));
            if blocks {
                self.blocker = Some(i);
            }
            blocks
        }
    }

    /// The visibility, once the walk is over (`blocked`: it stopped early); the blocker, if
    /// any, goes into `last`.
    #[inline(always)]
    fn finish(self, blocked: bool, last: &mut Option<u32>) -> f64 {
        if self.blocker.is_some() {
            *last = self.blocker;
        }
        if blocked {
            0.0
        } else {
            (-self.tau).exp()
        }
    }
}
