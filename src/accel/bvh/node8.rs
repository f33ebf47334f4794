//! The nodes rays walk: the CWBVH's nodes decoded to plain f32 boxes, eight children a node,
//! and a walk over them that visits the children a ray meets nearest first and drops a
//! waiting child once the closest hit lies before it.
//!
//! Why decode. The CWBVH stores each child box as bytes on a per-node grid (80 bytes a
//! node); testing a node meant turning 48 bytes into floats, scaling them and decoding the
//! child order, about 130 instructions with the traversal's bookkeeping, and its traversal
//! order is the octant's, not the distances'. A decoded node (224 bytes) is tested with 12
//! subtractions and multiplications, 8 minima and maxima and one comparison per lane, which
//! the compiler turns into SIMD of the clone's width (see mod.rs), and its child slots say
//! directly which node or primitives each child is. Against walking the CWBVH's own
//! nodes, `bench trace` measured camera rays 1.12-1.22x faster and shadow rays 1.01-1.09x.
//! The tree is built and collapsed by wide.rs (tested against obvhs's own conversion), then
//! decoded here, node for node, and the CWBVH freed. (Walking the CWBVH's
//! byte planes with this walk, 96-byte nodes, measured 8 % slower: decoding costs more than
//! the smaller nodes save.)
//!
//! Why the boxes stay conservative. obvhs decodes a bound as `p + q 2^e` in f32: the
//! product is exact and the sum rounds once, to within half a step of the exact grid value.
//! Each bound here is that moved outward by one f32 step, so it holds the quantised box,
//! which holds the padded primitive boxes (mod.rs says why the padding covers the f32
//! arithmetic of the ray test).

use glam::Vec3A;
use obvhs::cwbvh::node::CwBvhNode;
use obvhs::ray::Ray as Ray32;

/// A node: its eight child boxes (one lane per child) in the scaled f32 frame, and what each
/// child is. An empty lane has the box `+inf..-inf`, which no ray meets.
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C, align(32))]
pub(super) struct Node8 {
    pub lo: [[f32; 8]; 3],
    pub hi: [[f32; 8]; 3],
    /// An inner child: its node index. A leaf child: [`LEAF`] `| (count - 1) << 29 | first`,
    /// its `count` (1 to 3) primitives from index `first` of the chunk.
    pub child: [u32; 8],
}

const LEAF: u32 = 1 << 31;
const FIRST: u32 = (1 << 29) - 1;

/// The most primitives a chunk may hold (a leaf's first index must fit in 29 bits).
pub(super) const MAX_CHUNK_PRIMS: usize = FIRST as usize + 1;

/// Stack entries a walk of a tree `depth` nodes deep needs: at most seven waiting children
/// per level, and room for a node's eight pushes past the top.
#[inline]
pub(super) fn stack_len(depth: usize) -> usize {
    7 * depth + 9
}

/// Entries of the fixed stack; deeper trees (degenerate sets, such as hundreds of concentric
/// spheres) walk with a growable one.
pub(super) const STACK: usize = 128;

/// Whether a reference is a leaf, and its primitives.
#[inline(always)]
pub(super) fn leaf_range(r: u32) -> Option<std::ops::Range<u32>> {
    (r & LEAF != 0).then(|| {
        let first = r & FIRST;
        first..first + ((r >> 29) & 3) + 1
    })
}

/// The decoded nodes of a CWBVH, node for node (same indices, root first).
#[cfg(test)]
pub(super) fn decode(nodes: &[CwBvhNode]) -> Vec<Node8> {
    let mut out = Vec::with_capacity(nodes.len());
    decode_into(nodes, 0, &mut out);
    out
}

/// Appends the decoded nodes of a CWBVH to `out`, node for node, its node indices moved by
/// where it starts in `out` and its primitive indices by `first` (where its primitives start
/// in the chunk).
fn decode_into(nodes: &[CwBvhNode], first: u32, out: &mut Vec<Node8>) {
    let base = out.len() as u32;
    out.extend(nodes.iter().map(|n| {
        let mut out = Node8 {
            lo: [[f32::INFINITY; 8]; 3],
            hi: [[f32::NEG_INFINITY; 8]; 3],
            child: [0; 8],
        };
        for i in 0..8 {
            let meta = n.child_meta[i];
            if meta == 0 {
                continue;
            }
            let b = n.child_aabb(i);
            for a in 0..3 {
                out.lo[a][i] = -next_up(-b.min[a]);
                out.hi[a][i] = next_up(b.max[a]);
            }
            out.child[i] = if (n.imask >> i) & 1 != 0 {
                // Inner children are stored in slot order from `child_base_idx`.
                base + n.child_base_idx + (u32::from(n.imask) & ((1 << i) - 1)).count_ones()
            } else {
                // A leaf's meta: its primitive count in unary in the top three bits, its
                // offset from `primitive_base_idx` in the low five.
                let count = u32::from(meta >> 5).count_ones();
                let at = first + n.primitive_base_idx + u32::from(meta & 0x1f);
                debug_assert!((1..=3).contains(&count) && at <= FIRST);
                LEAF | (count - 1) << 29 | at
            };
        }
        out
    }));
}

/// The nodes of a chunk whose primitives were built into trees in pieces: each piece's
/// CWBVH, with the index in the chunk of its first primitive. One piece is decoded as it is;
/// several are decoded one after another under a new root whose children are their roots
/// (at most eight pieces). Returns the nodes and the depth added (0 or 1).
pub(super) fn join(pieces: &[(u32, Vec<CwBvhNode>)]) -> (Vec<Node8>, usize) {
    debug_assert!(pieces.len() <= 8);
    let total: usize = pieces.iter().map(|(_, p)| p.len()).sum();
    let mut out = Vec::with_capacity(total + usize::from(pieces.len() > 1));
    if let [(first, nodes)] = pieces {
        decode_into(nodes, *first, &mut out);
        return (out, 0);
    }
    out.push(Node8 {
        lo: [[f32::INFINITY; 8]; 3],
        hi: [[f32::NEG_INFINITY; 8]; 3],
        child: [0; 8],
    });
    for (lane, (first, nodes)) in pieces.iter().enumerate() {
        let at = out.len();
        decode_into(nodes, *first, &mut out);
        // The piece's root box: the union of its children's (each already rounded outward).
        let root = out[at];
        for a in 0..3 {
            out[0].lo[a][lane] = root.lo[a].iter().copied().fold(f32::INFINITY, f32::min);
            out[0].hi[a][lane] = root.hi[a].iter().copied().fold(f32::NEG_INFINITY, f32::max);
        }
        out[0].child[lane] = at as u32;
    }
    (out, 1)
}

/// The least f32 above `x` (`f32::next_up`, which needs Rust 1.86).
fn next_up(x: f32) -> f32 {
    if x.is_nan() || x == f32::INFINITY {
        x
    } else if x == 0.0 {
        f32::from_bits(1)
    } else if x > 0.0 {
        f32::from_bits(x.to_bits() + 1)
    } else {
        f32::from_bits(x.to_bits() - 1)
    }
}

/// What a leaf visit tells the walk.
pub(super) enum Step {
    Go,
    /// Go on, with the ray's f32 `tmax` lowered to this.
    Shrink(f32),
    Stop,
}

/// A ray as the node test takes it (the f32 ray of `SphereBvh::ray32`).
#[derive(Clone, Copy)]
struct Probe {
    origin: Vec3A,
    inv: Vec3A,
    negative: [bool; 3],
}

impl Probe {
    #[inline(always)]
    fn new(ray: &Ray32) -> Probe {
        let inv = ray.inv_direction;
        Probe {
            origin: ray.origin,
            inv,
            negative: [inv.x < 0.0, inv.y < 0.0, inv.z < 0.0],
        }
    }

    /// Tests node `n`'s children within `[0, tmax]`. When the ray meets some, returns the
    /// nearest (with `ORDERED`) or the first, and pushes the rest on `stack[..*sp]`, the
    /// nearest on top (with `ORDERED`).
    #[inline(always)]
    fn children<const ORDERED: bool>(
        &self,
        n: &Node8,
        tmax: f32,
        stack: &mut [(u32, f32)],
        sp: &mut usize,
    ) -> Option<u32> {
        let (o, inv) = (self.origin, self.inv);
        // The near and far planes of each axis, by the sign of the ray's direction.
        let pick = |a: usize| {
            if self.negative[a] {
                (&n.hi[a], &n.lo[a])
            } else {
                (&n.lo[a], &n.hi[a])
            }
        };
        let ((nx, fx), (ny, fy), (nz, fz)) = (pick(0), pick(1), pick(2));
        // `a > b ? a : b` is one maxps; no NaN arises (obvhs keeps 1/d finite and non-zero, so
        // even an empty lane's infinities give infinities).
        let max = |a: f32, b: f32| if a > b { a } else { b };
        let min = |a: f32, b: f32| if a < b { a } else { b };
        let mut entry = [0f32; 8];
        let mut lanes = [0u32; 8];
        for i in 0..8 {
            let near = max(
                max((nx[i] - o.x) * inv.x, (ny[i] - o.y) * inv.y),
                max((nz[i] - o.z) * inv.z, 0.0),
            );
            let far = min(
                min((fx[i] - o.x) * inv.x, (fy[i] - o.y) * inv.y),
                min((fz[i] - o.z) * inv.z, tmax),
            );
            entry[i] = near;
            lanes[i] = if near <= far { 1 << i } else { 0 };
        }
        let mut mask = lanes.iter().fold(0, |m, &l| m | l);
        if mask == 0 {
            return None;
        }
        let first = mask.trailing_zeros() as usize;
        mask &= mask - 1;
        if mask == 0 {
            return Some(n.child[first]);
        }
        let base = *sp;
        let mut top = base;
        stack[top] = (n.child[first], entry[first]);
        top += 1;
        while mask != 0 {
            let i = mask.trailing_zeros() as usize;
            mask &= mask - 1;
            let item = (n.child[i], entry[i]);
            let mut at = top;
            if ORDERED {
                // Insertion by entry, the nearest on top.
                while at > base && stack[at - 1].1 < item.1 {
                    stack[at] = stack[at - 1];
                    at -= 1;
                }
            }
            stack[at] = item;
            top += 1;
        }
        top -= 1;
        *sp = top;
        Some(stack[top].0)
    }
}

/// The next waiting child on `stack[..*sp]` that still starts within `tmax`.
#[inline(always)]
fn pop(stack: &[(u32, f32)], sp: &mut usize, tmax: f32) -> Option<u32> {
    while *sp > 0 {
        *sp -= 1;
        let (r, entry) = stack[*sp];
        if entry <= tmax {
            return Some(r);
        }
    }
    None
}

/// Walks `nodes` along `ray`, calling `leaf(primitive in the chunk)` for every primitive of
/// a leaf box the ray reaches within its (shrinking) `tmax`; returns whether `leaf` said
/// stop. With `ORDERED`, the children a node's test keeps are visited nearest entry first
/// (for closest hits); without, in slot order (for any hit, where sorting costs and the
/// order does not matter). `stack` needs [`stack_len`] of the tree's depth.
#[inline(always)]
pub(super) fn walk<const ORDERED: bool>(
    nodes: &[Node8],
    ray: &Ray32,
    stack: &mut [(u32, f32)],
    mut leaf: impl FnMut(u32) -> Step,
) -> bool {
    if nodes.is_empty() {
        return false;
    }
    let probe = Probe::new(ray);
    let mut tmax = ray.tmax;
    let mut sp = 0;
    let mut cur = 0;
    loop {
        let next = match leaf_range(cur) {
            None => {
                let before = sp;
                let next = probe.children::<ORDERED>(&nodes[cur as usize], tmax, stack, &mut sp);
                if !ORDERED {
                    // Touch the waiting inner children now, so that their loads overlap
                    // with the walk of the first.
                    for &(r, _) in &stack[before..sp] {
                        if r & LEAF == 0 {
                            std::hint::black_box(nodes[r as usize].lo[0][0]);
                        }
                    }
                }
                next
            }
            Some(prims) => {
                for p in prims {
                    match leaf(p) {
                        Step::Go => {}
                        Step::Shrink(t) => tmax = tmax.min(t),
                        Step::Stop => return true,
                    }
                }
                None
            }
        };
        match next.or_else(|| pop(stack, &mut sp, tmax)) {
            Some(r) => cur = r,
            None => return false,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::accel::bvh::wide::collapse;
    use crate::accel::bvh::wide::tests::{bvh2, random_boxes};
    use crate::testing::Rng;
    use glam::vec3a;
    use obvhs::aabb::Aabb;

    /// `next_up` steps to the adjacent f32, through zero and the subnormals.
    #[test]
    fn next_up_is_one_step() {
        assert_eq!(next_up(1.0), 1.0 + f32::EPSILON);
        assert_eq!(next_up(-1.0), -1.0 + f32::EPSILON / 2.0);
        assert_eq!(next_up(0.0), f32::from_bits(1));
        assert_eq!(next_up(-0.0), f32::from_bits(1));
        assert_eq!(next_up(-f32::from_bits(1)), -0.0);
        assert_eq!(next_up(f32::MAX), f32::INFINITY);
        assert_eq!(next_up(f32::NEG_INFINITY), -f32::MAX);
        assert_eq!(next_up(f32::INFINITY), f32::INFINITY);
    }

    /// The sets the tests use: random boxes over six decades of size, coincident ones, ones
    /// far from the origin, points; and nested boxes, a tree deeper than the fixed stack.
    fn trees(rng: &mut Rng) -> Vec<Vec<Aabb>> {
        let mut sets: Vec<Vec<Aabb>> = [
            (1, 0),
            (2, 0),
            (9, 0),
            (5000, 0),
            (300, 1),
            (2000, 2),
            (500, 3),
        ]
        .into_iter()
        .map(|(n, kind)| random_boxes(rng, n, kind))
        .collect();
        sets.push(
            (1..=400)
                .map(|k| Aabb::new(Vec3A::splat(-(k as f32)), Vec3A::splat(k as f32)))
                .collect(),
        );
        sets
    }

    /// Decoding keeps the tree: the leaves hold every primitive position once, each
    /// primitive's box lies in its leaf's lane, and each inner child's lanes in the parent's.
    #[test]
    fn decoded_nodes_partition_the_primitives_and_hold_their_boxes() {
        let mut rng = Rng::new(41);
        for boxes in trees(&mut rng) {
            let (cw, _) = collapse(&bvh2(&boxes), 3);
            let nodes = decode(&cw.nodes);
            assert_eq!(nodes.len(), cw.nodes.len());
            let lane = |n: &Node8, i: usize| {
                (
                    vec3a(n.lo[0][i], n.lo[1][i], n.lo[2][i]),
                    vec3a(n.hi[0][i], n.hi[1][i], n.hi[2][i]),
                )
            };
            // The primitives under a child reference.
            fn under(nodes: &[Node8], r: u32, out: &mut Vec<u32>) {
                match leaf_range(r) {
                    Some(prims) => out.extend(prims),
                    None => {
                        let n = &nodes[r as usize];
                        for i in 0..8 {
                            if n.lo[0][i] <= n.hi[0][i] {
                                under(nodes, n.child[i], out);
                            }
                        }
                    }
                }
            }
            let mut seen = vec![0u32; boxes.len()];
            let mut inner_refs = 0;
            let mut below = Vec::new();
            for n in &nodes {
                for i in 0..8 {
                    let (lo, hi) = lane(n, i);
                    if lo.x > hi.x {
                        continue;
                    }
                    if let Some(prims) = leaf_range(n.child[i]) {
                        seen.iter_mut()
                            .skip(prims.start as usize)
                            .take(prims.len())
                            .for_each(|s| *s += 1);
                    } else {
                        inner_refs += 1;
                    }
                    below.clear();
                    under(&nodes, n.child[i], &mut below);
                    for &p in &below {
                        let b = boxes[cw.primitive_indices[p as usize] as usize];
                        assert!(lo.cmple(b.min).all() && b.max.cmple(hi).all());
                    }
                }
            }
            assert!(seen.iter().all(|&s| s == 1), "{seen:?}");
            // Every node but the root is some node's child.
            assert_eq!(inner_refs, nodes.len() - 1);
        }
    }

    /// Both walks offer every primitive whose box the ray meets with some margin (an f64 slab
    /// test on the box shrunk by a millionth of the scene's reach: brute force), each once;
    /// the ordered walk, lowering `tmax` to each box's entry as a closest-hit query does,
    /// still finds the nearest box. The stack is exactly [`stack_len`] long, so a walk that
    /// needed more would panic.
    #[test]
    fn walks_reach_every_box_the_ray_meets() {
        let mut rng = Rng::new(42);
        let (mut met, mut rays) = (0, 0);
        for (boxes, pieces) in trees(&mut rng)
            .into_iter()
            .flat_map(|b| [(b.clone(), 1), (b, 5)])
        {
            // The tree of all the boxes, or of five runs of them joined under one root; the
            // primitive each leaf index stands for.
            let n = boxes.len();
            let (nodes, depth, prim_of) = if pieces == 1 || n < pieces {
                let (cw, depth) = collapse(&bvh2(&boxes), 3);
                let prim_of: Vec<usize> =
                    cw.primitive_indices.iter().map(|&i| i as usize).collect();
                (decode(&cw.nodes), depth, prim_of)
            } else {
                let (mut parts, mut prim_of, mut depth) = (Vec::new(), Vec::new(), 0);
                for k in 0..pieces {
                    let r = k * n / pieces..(k + 1) * n / pieces;
                    let (cw, d) = collapse(&bvh2(&boxes[r.clone()]), 3);
                    prim_of.extend(cw.primitive_indices.iter().map(|&i| r.start + i as usize));
                    parts.push((r.start as u32, cw.nodes));
                    depth = depth.max(d);
                }
                let (nodes, joined) = join(&parts);
                assert_eq!(joined, 1);
                (nodes, depth + joined, prim_of)
            };
            let (lo, hi) = boxes.iter().fold(
                (Vec3A::splat(f32::INFINITY), Vec3A::splat(f32::NEG_INFINITY)),
                |(lo, hi), b| (lo.min(b.min), hi.max(b.max)),
            );
            let reach = f64::from(lo.abs().max(hi.abs()).max_element()).max(1e-3);
            let margin = 1e-6 * reach;
            for _ in 0..300 {
                let mut next = || rng.f() as f32;
                let origin = lo + (hi - lo) * vec3a(next(), next(), next()) * 1.4 - (hi - lo) * 0.2;
                let target = boxes[(next() * boxes.len() as f32) as usize % boxes.len()].center();
                let dir = match (next() * 4.0) as u32 {
                    0 => vec3a(next() - 0.5, next() - 0.5, next() - 0.5),
                    1 => vec3a(target.x - origin.x, 0.0, 0.0),
                    _ => target - origin,
                };
                if dir.length() == 0.0 {
                    continue;
                }
                let tmax = if next() < 0.5 {
                    f32::INFINITY
                } else {
                    next() * 2.0 * (hi - lo).max_element()
                };
                let ray = Ray32::new(origin, dir.normalize(), 0.0, tmax);
                rays += 1;
                // Brute force: the entry parameter of each box the ray meets with margin.
                let (o, d) = (ray.origin.as_dvec3(), ray.direction.as_dvec3());
                let entry = |b: &Aabb| -> Option<f64> {
                    let (bl, bh) = (b.min.as_dvec3() + margin, b.max.as_dvec3() - margin);
                    let (mut t0, mut t1) = (0.0f64, f64::from(tmax) * (1.0 - 1e-6));
                    for a in 0..3 {
                        if d[a] == 0.0 {
                            if o[a] < bl[a] || o[a] > bh[a] {
                                return None;
                            }
                            continue;
                        }
                        let (u, v) = ((bl[a] - o[a]) / d[a], (bh[a] - o[a]) / d[a]);
                        t0 = t0.max(u.min(v));
                        t1 = t1.min(u.max(v));
                    }
                    (bl.cmple(bh).all() && t0 <= t1).then_some(t0)
                };
                let want: Vec<Option<f64>> = (0..boxes.len())
                    .map(|p| entry(&boxes[prim_of[p]]))
                    .collect();
                met += want.iter().flatten().count();
                for ordered in [false, true] {
                    let mut stack = vec![(0u32, 0f32); stack_len(depth)];
                    let mut offered = vec![0u32; boxes.len()];
                    let leaf = |p: u32| {
                        offered[p as usize] += 1;
                        Step::Go
                    };
                    if ordered {
                        walk::<true>(&nodes, &ray, &mut stack, leaf);
                    } else {
                        walk::<false>(&nodes, &ray, &mut stack, leaf);
                    }
                    for (p, w) in want.iter().enumerate() {
                        assert!(offered[p] <= 1);
                        assert!(w.is_none() || offered[p] == 1, "{p} {w:?} {ray:?}");
                    }
                }
                // Closest: lower tmax to each met box's entry (rounded up) as it is offered.
                let mut best: Option<f64> = None;
                let mut stack = vec![(0u32, 0f32); stack_len(depth)];
                walk::<true>(&nodes, &ray, &mut stack, |p| match want[p as usize] {
                    Some(t) if best.is_none_or(|b| t < b) => {
                        best = Some(t);
                        Step::Shrink(next_up(t as f32))
                    }
                    _ => Step::Go,
                });
                let nearest = want.iter().flatten().copied().reduce(f64::min);
                assert_eq!(best, nearest, "{ray:?}");
            }
        }
        assert!(met > 1000 && rays > 2000, "{met} boxes met on {rays} rays");
    }
}
