//! Queries: the chunks a ray reaches (f64 slab test), each chunk's nodes walked (node8.rs),
//! and the closest-hit, any-hit and region queries on top, with an all-hits query for the
//! tests (every primitive test in f64 by the caller's closure).

use glam::{DVec3, Vec3A};
use obvhs::ray::Ray as Ray32;

use super::node8::{self, leaf_range, stack_len, Step, STACK};
use super::{Chunk, Hit, Prim, SphereBvh, ALL_CHUNKS, BACKUP};

/// One axis of the slab test: `(t0, t1)` clipped to where `o + t d` lies between the planes
/// `lo` and `hi` of that axis (`inv = 1 / d`). `d == 0` gives +-inf (or NaN when `o` is on a
/// face; then the axis does not clip).
#[inline(always)]
fn clip(lo: f64, hi: f64, o: f64, inv: f64, (t0, t1): (f64, f64)) -> (f64, f64) {
    let (a, b) = ((lo - o) * inv, (hi - o) * inv);
    let (a, b) = if a > b { (b, a) } else { (a, b) };
    (if a > t0 { a } else { t0 }, if b < t1 { b } else { t1 })
}

/// The parameter interval where `o + t d` is inside the box `lo..hi`, clipped to
/// `[tmin, tmax]` (f64 slab test; `inv` is `1 / d` componentwise).
#[inline(always)]
fn slab(lo: DVec3, hi: DVec3, o: DVec3, inv: DVec3, tmin: f64, tmax: f64) -> Option<(f64, f64)> {
    let (t0, t1) = (0..3).fold((tmin, tmax), |t, a| clip(lo[a], hi[a], o[a], inv[a], t));
    (t0 <= t1).then_some((t0, t1))
}

/// Walks chunk `c` along `ray` (see [`node8::walk`]).
#[inline(always)]
pub(super) fn walk<const ORDERED: bool>(
    c: &Chunk,
    ray: &Ray32,
    leaf: impl FnMut(u32) -> Step,
) -> bool {
    if stack_len(c.depth) <= STACK {
        node8::walk::<ORDERED>(&c.nodes, ray, &mut [(0, 0.0); STACK], leaf)
    } else {
        node8::walk::<ORDERED>(&c.nodes, ray, &mut vec![(0, 0.0); stack_len(c.depth)], leaf)
    }
}

impl SphereBvh {
    /// The f32 ray for chunk `c` over `[t0, t1]` (already clipped to the chunk's box), in the
    /// chunk's frame: it starts at the entry point, so its f32 origin lies inside the chunk.
    #[inline]
    pub(super) fn ray32(c: &Chunk, o: DVec3, d: DVec3, t0: f64, t1: f64) -> Ray32 {
        // `+ 0.0` turns -0.0 into +0.0. (obvhs's node test, used until 2026-12-04, picked the
        // near planes from `d < 0` but divided by the signed zero; ours picks them from the sign
        // of `1/d` itself, so either zero is safe.)
        let dir = d.as_vec3a() + Vec3A::ZERO;
        let start = ((o + t0 * d - c.origin) * c.scale).as_vec3a() - BACKUP * dir;
        // Widen the f32 range: the f32 exit must not fall short of the f64 one.
        let len = (((t1 - t0) * c.scale) as f32 + BACKUP) * (1.0 + 4.0 * f32::EPSILON)
            + f32::MIN_POSITIVE;
        Ray32::new(start, dir, 0.0, len)
    }

    /// The f32 ray parameter of world parameter `t` on a ray from [`SphereBvh::ray32`] for
    /// chunk `c` that started at `t0`, rounded up so that no closer box is culled.
    #[inline]
    pub(super) fn t32_above(c: &Chunk, t: f64, t0: f64) -> f32 {
        let r = ((t - t0) * c.scale) as f32 + BACKUP;
        r + r.abs() * 4.0 * f32::EPSILON + f32::MIN_POSITIVE
    }

    /// The chunks the segment reaches, with their entry and exit parameters, nearest first,
    /// written to the front of `list`; returns how many. (Filled in place, not returned:
    /// returning the array copied it on every ray.)
    #[inline(always)]
    pub(super) fn chunks_on(
        &self,
        o: DVec3,
        d: DVec3,
        tmin: f64,
        tmax: f64,
        list: &mut [(f64, f64, u32); ALL_CHUNKS],
    ) -> usize {
        let inv = d.recip();
        let Some(whole) = slab(self.lo, self.hi, o, inv, tmin, tmax) else {
            return 0;
        };
        if let [c] = &self.chunks[..] {
            // One chunk: its box is the scene's box, up to padding.
            return match slab(c.lo, c.hi, o, inv, whole.0, whole.1) {
                Some((t0, t1)) => {
                    list[0] = (t0, t1, 0);
                    1
                }
                None => 0,
            };
        }
        // Every chunk's slab test, four chunks at a time (one AVX2 pass in the ray entry
        // points' clones; `bench trace`: camera rays +2 % against one `slab` per chunk), then
        // the met chunks inserted by entry parameter.
        let b = &self.chunk_boxes;
        let count = self.chunks.len();
        let mut t0s = [0f64; ALL_CHUNKS];
        let mut t1s = [0f64; ALL_CHUNKS];
        let mut met = [false; ALL_CHUNKS];
        for g in (0..count).step_by(4) {
            for k in g..g + 4 {
                let (t0, t1) = (0..3).fold((tmin, tmax), |t, a| {
                    clip(b.lo[a][k], b.hi[a][k], o[a], inv[a], t)
                });
                t0s[k] = t0;
                t1s[k] = t1;
                met[k] = t0 <= t1;
            }
        }
        let mut n = 0;
        for k in 0..count {
            if met[k] {
                let (t0, t1) = (t0s[k], t1s[k]);
                // Insertion by entry parameter.
                let mut at = n;
                while at > 0 && list[at - 1].0 > t0 {
                    list[at] = list[at - 1];
                    at -= 1;
                }
                list[at] = (t0, t1, k as u32);
                n += 1;
            }
        }
        n
    }

    /// The closest primitive whose `test` accepts the ray: `test(index, prim, roots) -> Some(t)` for a
    /// hit at `t` in `(tmin, tmax]`. Returns the smallest such `t`.
    #[inline(always)]
    pub fn closest(
        &self,
        o: DVec3,
        d: DVec3,
        tmin: f64,
        tmax: f64,
        mut test: impl FnMut(u32, &Prim, (f64, f64)) -> Option<f64>,
    ) -> Option<Hit> {
        let mut best: Option<Hit> = None;
        let mut list = [(0.0, 0.0, 0u32); ALL_CHUNKS];
        let n = self.chunks_on(o, d, tmin, tmax, &mut list);
        for &(t0, t1, k) in &list[..n] {
            let best_t = best.map_or(tmax, |h| h.t);
            if t0 > best_t {
                break;
            }
            self.closest_in(
                k as usize,
                (o, d),
                (tmin, tmax),
                (t0, t1.min(best_t)),
                &mut best,
                &mut test,
            );
        }
        best
    }

    /// Whether a hit at `t` on `p` beats `best` (ties, between coincident spheres, go to the
    /// earlier sphere in the scene, whatever the traversal order).
    #[inline(always)]
    pub(super) fn better(&self, t: f64, p: &Prim, best: Option<Hit>, tmax: f64) -> bool {
        match best {
            None => t <= tmax,
            Some(b) => t < b.t || (t == b.t && p.sphere < self.packed[b.prim as usize].sphere),
        }
    }

    /// The closest hit of one ray in chunk `c`, entered at `t0` and walked to `t1`, lowering
    /// `best`.
    /// (Every closure inlined by hand: left to itself the compiler stopped inlining the leaf
    /// closure once it gathered packed primitives, and camera rays lost 5 %, `bench trace`,
    /// 2026-12-02.)
    #[inline(always)]
    pub(super) fn closest_in(
        &self,
        c: usize,
        (o, d): (DVec3, DVec3),
        (tmin, tmax): (f64, f64),
        (t0, t1): (f64, f64),
        best: &mut Option<Hit>,
        mut test: impl FnMut(u32, &Prim, (f64, f64)) -> Option<f64>,
    ) {
        let c = &self.chunks[c];
        walk::<true>(
            c,
            &Self::ray32(c, o, d, t0, t1),
            #[inline(always)]
            |i| {
                let i = c.base + i;
                if let Some(roots) = self.roots_of(i, o, d) {
                    let p = &self.prim(i);
                    if let Some(t) = test(i, p, roots) {
                        if t > tmin && self.better(t, p, *best, tmax) {
                            *best = Some(Hit { t, prim: i });
                            return Step::Shrink(Self::t32_above(c, t, t0));
                        }
                    }
                }
                Step::Go
            },
        );
    }

    /// Whether any primitive `blocks(prim_index, prim, roots)` along the ray in `[tmin, tmax]`;
    /// stops at the first.
    #[inline]
    pub fn any(
        &self,
        o: DVec3,
        d: DVec3,
        tmin: f64,
        tmax: f64,
        blocks: impl FnMut(u32, &Prim, (f64, f64)) -> bool,
    ) -> bool {
        self.any_except(o, d, tmin, tmax, None, blocks)
    }

    /// [`SphereBvh::any`], passing over primitive `skip` without a test: a shadow ray's own
    /// sphere, which its line always meets (so its roots would always be computed, for
    /// nothing).
    #[inline(always)]
    pub fn any_except(
        &self,
        o: DVec3,
        d: DVec3,
        tmin: f64,
        tmax: f64,
        skip: Option<u32>,
        mut blocks: impl FnMut(u32, &Prim, (f64, f64)) -> bool,
    ) -> bool {
        self.any_prim_except(
            (o, d),
            (tmin, tmax),
            skip,
            #[inline(always)]
            |i| match self.roots_of(i, o, d) {
                Some(roots) => blocks(i, &self.prim(i), roots),
                None => false,
            },
        )
    }

    /// Whether `blocks(prim_index)` holds for any primitive whose box the ray segment
    /// `[tmin, tmax]` reaches, other than `skip`; stops at the first. `blocks` makes its own
    /// test of the primitive (shadow rays ask [`SphereBvh::enters_between`] of an opaque one,
    /// which needs no roots).
    #[inline(always)]
    pub(crate) fn any_prim_except(
        &self,
        (o, d): (DVec3, DVec3),
        (tmin, tmax): (f64, f64),
        skip: Option<u32>,
        mut blocks: impl FnMut(u32) -> bool,
    ) -> bool {
        let mut list = [(0.0, 0.0, 0u32); ALL_CHUNKS];
        let n = self.chunks_on(o, d, tmin, tmax, &mut list);
        let mut blocked = false;
        for &(t0, t1, k) in &list[..n] {
            let c = &self.chunks[k as usize];
            walk::<false>(
                c,
                &Self::ray32(c, o, d, t0, t1),
                // Inlined by hand, as in `closest`: this is the shadow rays' leaf test, and
                // left out of line it was not compiled for the caller's instruction set
                // (see mod.rs, "Why the ray entry points are compiled twice").
                #[inline(always)]
                |i| {
                    let i = c.base + i;
                    if Some(i) != skip && blocks(i) {
                        blocked = true;
                        Step::Stop
                    } else {
                        Step::Go
                    }
                },
            );
            if blocked {
                return true;
            }
        }
        false
    }

    /// Calls `visit(prim_index, prim)` for every primitive whose (padded) box may meet a
    /// region of space, as judged by `near(lo, hi)`: whether the world box `lo..hi` may meet
    /// the region (it may answer true for boxes that do not; it must never answer false for
    /// one that does). Each child box of a node is tested, so only the nodes whose boxes come
    /// near the region are visited: the cost follows the region, not an enclosing
    /// axis-aligned box (a diagonal shadow strip, say). `visit` still does the exact test.
    pub fn near_region(
        &self,
        near: impl Fn(DVec3, DVec3) -> bool,
        mut visit: impl FnMut(u32, &Prim),
        stack: &mut Vec<u32>,
    ) {
        for c in &self.chunks {
            if c.nodes.is_empty() || !near(c.lo, c.hi) {
                continue;
            }
            let (inv, pad) = (1.0 / c.scale, DVec3::splat(2.0 * c.pad));
            stack.clear();
            stack.push(0);
            while let Some(index) = stack.pop() {
                let node = &c.nodes[index as usize];
                for child in 0..8 {
                    let f32_box = |b: &[[f32; 8]; 3]| {
                        DVec3::new(b[0][child].into(), b[1][child].into(), b[2][child].into())
                    };
                    let (lo, hi) = (f32_box(&node.lo), f32_box(&node.hi));
                    if !(lo.cmple(hi).all()) {
                        // An empty lane.
                        continue;
                    }
                    // The child box in world space, padded again for the f32 rounding of its
                    // decoding.
                    if !near(lo * inv + c.origin - pad, hi * inv + c.origin + pad) {
                        continue;
                    }
                    let r = node.child[child];
                    match leaf_range(r) {
                        None => stack.push(r),
                        Some(prims) => {
                            for i in prims {
                                let i = c.base + i;
                                visit(i, &self.prim(i));
                            }
                        }
                    }
                }
            }
        }
    }

    /// Calls `visit(prim_index, prim, roots)` for every primitive the line meets whose box the
    /// ray segment `[tmin, tmax]` reaches (order unspecified).
    #[cfg(test)]
    pub fn all(
        &self,
        o: DVec3,
        d: DVec3,
        tmin: f64,
        tmax: f64,
        mut visit: impl FnMut(u32, &Prim, (f64, f64)),
    ) {
        let mut list = [(0.0, 0.0, 0u32); ALL_CHUNKS];
        let n = self.chunks_on(o, d, tmin, tmax, &mut list);
        for &(t0, t1, k) in &list[..n] {
            let c = &self.chunks[k as usize];
            walk::<false>(c, &Self::ray32(c, o, d, t0, t1), |i| {
                let i = c.base + i;
                if let Some(roots) = self.roots_of(i, o, d) {
                    visit(i, &self.prim(i), roots);
                }
                Step::Go
            });
        }
    }
}
