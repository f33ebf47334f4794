//! Two any-hit queries walked together, one step of each in turn.
//!
//! A single ray's walk is one long chain of dependent work: a node's children are tested, the
//! next node's address follows from the test, and that node must be loaded before anything
//! else can happen (`perf annotate` of `bench trace` puts most of the traversal's time on
//! the node loads and on the hit mask the next address waits for). Two rays have two
//! independent chains, and a core can run one while the other waits, as long as both are in
//! its instruction window: so each ray's walk here is a [`Walker`] that does one step (a
//! leaf's primitives, then one node) per call, and the two are called in turn.
//!
//! The steps are those of `obvhs::traverse!` (the same children in the same order, the same
//! node test), so each ray meets the same primitives as [`SphereBvh::any_except`] would, and
//! the answers are the same.

use glam::{DVec3, UVec2};
use obvhs::cwbvh::node::CwBvhNode;
use obvhs::faststack::{FastStack, StackStack};
use obvhs::ray::Ray as Ray32;

use super::node_test::{child_hits, octant_inv4};
use super::query::root_group;
use super::{Chunk, Prim, SphereBvh, MAX_CHUNKS};

/// One ray's walk through one chunk's CWBVH, a step at a time.
struct Walker<'a> {
    nodes: &'a [CwBvhNode],
    /// Index of the chunk's first primitive.
    base: u32,
    ray: Ray32,
    oct_inv4: u32,
    /// The node group being visited and the primitives waiting, as in `obvhs::traverse!`.
    group: UVec2,
    prims: UVec2,
    stack: StackStack<UVec2, 32>,
}

impl<'a> Walker<'a> {
    #[inline(always)]
    fn new(c: &'a Chunk, ray: Ray32) -> Walker<'a> {
        Walker {
            nodes: &c.bvh.nodes,
            base: c.base,
            oct_inv4: octant_inv4(ray.direction),
            ray,
            group: root_group(c),
            prims: UVec2::ZERO,
            stack: StackStack::default(),
        }
    }

    /// Offers the waiting primitives to `blocks` (by index in the BVH), then visits one node.
    /// Returns `Some(true)` when `blocks` said yes, `Some(false)` when the chunk is done.
    #[inline(always)]
    fn step(&mut self, mut blocks: impl FnMut(u32) -> bool) -> Option<bool> {
        while self.prims.y != 0 {
            let k = 31 - self.prims.y.leading_zeros();
            self.prims.y &= !(1u32 << k);
            if blocks(self.base + self.prims.x + k) {
                return Some(true);
            }
        }
        if self.group.y & 0xff00_0000 != 0 {
            let hits = self.group.y;
            let offset = 31 - hits.leading_zeros();
            self.group.y &= !(1u32 << offset);
            if self.group.y & 0xff00_0000 != 0 {
                self.stack.push(self.group);
            }
            let slot = (offset - 24) ^ (self.oct_inv4 & 0xff);
            let index = self.group.x + (hits & !(0xffff_ffffu32 << slot)).count_ones();
            let node = &self.nodes[index as usize];
            let mask = child_hits(node, &self.ray, self.oct_inv4);
            self.group = UVec2::new(
                node.child_base_idx,
                (mask & 0xff00_0000) | u32::from(node.imask),
            );
            self.prims = UVec2::new(node.primitive_base_idx, mask & 0x00ff_ffff);
        } else {
            self.group = UVec2::ZERO;
        }
        if self.prims.y == 0 && self.group.y & 0xff00_0000 == 0 {
            if self.stack.is_empty() {
                return Some(false);
            }
            self.group = self.stack.pop_fast();
        }
        None
    }
}

/// One ray of a pair: the chunks it reaches, and its walk through the current one.
struct Side<'a> {
    o: DVec3,
    d: DVec3,
    skip: Option<u32>,
    chunks: [(f64, f64, u32); MAX_CHUNKS],
    count: usize,
    next: usize,
    walker: Option<Walker<'a>>,
}

/// One any-hit query of a pair: origin, direction, `tmin`, `tmax`, and the primitive to pass
/// over (see [`SphereBvh::any_except`]).
pub type AnyRay = (DVec3, DVec3, f64, f64, Option<u32>);

impl SphereBvh {
    /// [`SphereBvh::any_except`] of two rays, walked together: `blocks(k, index, prim, roots)`
    /// is asked about ray `k`'s primitives. Returns whether each was blocked.
    #[inline(always)]
    pub fn any_except_pair(
        &self,
        rays: [AnyRay; 2],
        mut blocks: impl FnMut(usize, u32, &Prim, (f64, f64)) -> bool,
    ) -> [bool; 2] {
        if self.chunks.iter().any(|c| c.deep) {
            // (Trees deeper than the walker's fixed stack: one ray after the other.)
            let [(o, d, t0, t1, s), (p, e, u0, u1, z)] = rays;
            return [
                self.any_except(o, d, t0, t1, s, |i, q, r| blocks(0, i, q, r)),
                self.any_except(p, e, u0, u1, z, |i, q, r| blocks(1, i, q, r)),
            ];
        }
        let side = |(o, d, tmin, tmax, skip): AnyRay| {
            let mut chunks = [(0.0, 0.0, 0u32); MAX_CHUNKS];
            let count = self.chunks_on(o, d, tmin, tmax, &mut chunks);
            Side {
                o,
                d,
                skip,
                chunks,
                count,
                next: 0,
                walker: None,
            }
        };
        let mut sides = [side(rays[0]), side(rays[1])];
        let mut blocked = [false; 2];
        let mut live = [true; 2];
        while live[0] || live[1] {
            for k in 0..2 {
                if !live[k] {
                    continue;
                }
                let s = &mut sides[k];
                let (o, d, skip) = (s.o, s.d, s.skip);
                let walker = match &mut s.walker {
                    Some(w) => w,
                    None if s.next == s.count => {
                        live[k] = false;
                        continue;
                    }
                    None => {
                        let (t0, t1, c) = s.chunks[s.next];
                        s.next += 1;
                        let ray = self.ray32(o, d, t0, t1);
                        s.walker.insert(Walker::new(&self.chunks[c as usize], ray))
                    }
                };
                let step = walker.step(
                    #[inline(always)]
                    |i| {
                        Some(i) != skip
                            && self
                                .roots_of(i, o, d)
                                .is_some_and(|roots| blocks(k, i, &self.prim(i), roots))
                    },
                );
                match step {
                    Some(true) => {
                        blocked[k] = true;
                        live[k] = false;
                    }
                    Some(false) => s.walker = None,
                    None => {}
                }
            }
        }
        blocked
    }
}
