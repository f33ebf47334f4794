//! The binary BVH that obvhs's PLOC builds, collapsed into the compressed 8-wide BVH (CWBVH)
//! that obvhs's traversal walks.
//!
//! The collapse is the one of Ylitie, Karras and Laine, "Efficient Incoherent Ray Traversal on
//! GPUs Through Compressed Wide BVHs" (HPG 2017): a dynamic programme over the binary tree
//! gives, for every node and every number `i + 1` (1 to 7) of wide subtrees it may turn
//! into, the cheapest SAH cost and how to get it (make the node a leaf, make it a wide node,
//! or hand the budget on to its two children); a top-down pass then reads the choices off.
//! Children are put in the slots their centres point to, so that the traversal visits them
//! nearest first for every ray octant, and their boxes are quantised to 8 bits per plane.
//!
//! obvhs has this conversion too (`bvh2_to_cwbvh`), with the same costs; ours was written for
//! speed and memory, which mattered at 1e6 spheres and up (the conversion was more
//! than half of the BVH build):
//! - the tables are kept for internal nodes only, in post order, 40 bytes each (obvhs keeps
//!   7 decisions of 8 bytes for every node, leaves included: 112 bytes per primitive), and a
//!   node's children's tables are found from the subtree sizes, with no index array;
//! - both passes walk with explicit stacks, so a degenerate, very deep binary tree (hundreds
//!   of concentric spheres) cannot overflow the thread's stack;
//! - the quantised boxes are computed exactly in f64 (floor and ceiling of exact quotients by
//!   a power of two), so a decoded child box always holds the child's f32 box;
//! - the wide tree's depth comes out of the top-down pass.

use glam::{Vec3, Vec3A};
use obvhs::aabb::Aabb;
use obvhs::bvh2::node::Bvh2Node;
use obvhs::bvh2::Bvh2;
use obvhs::cwbvh::node::CwBvhNode;
use obvhs::cwbvh::CwBvh;

/// SAH cost of testing one primitive, relative to testing one wide node's boxes (the value
/// the paper and obvhs use).
const PRIM_COST: f32 = 0.3;

/// What a node becomes with a budget of `i + 1` subtrees, packed in a byte: the kind in the
/// top two bits, then the budgets (`0..=6`, meaning one to seven subtrees) handed to the left
/// and the right child.
const LEAF: u8 = 0 << 6;
const INTERNAL: u8 = 1 << 6;
const DISTRIBUTE: u8 = 2 << 6;
const KIND: u8 = 3 << 6;

#[inline]
fn pick(kind: u8, left: usize, right: usize) -> u8 {
    kind | (left as u8) << 3 | right as u8
}

/// The dynamic programme's row for one internal node of the binary tree.
#[derive(Clone, Copy)]
struct Table {
    /// Cheapest cost with at most `i + 1` subtrees.
    cost: [f32; 7],
    /// How it is reached (see [`LEAF`]).
    pick: [u8; 7],
    /// Primitives in the subtree.
    prims: u32,
}

#[inline]
fn half_area(b: &Aabb) -> f32 {
    let d = b.max - b.min;
    (d.x + d.y) * d.z + d.x * d.y
}

/// The tables of every internal node of `bvh2`, in post order (left subtree, right subtree,
/// node), so that an internal node's right child's table comes just before its own, and its
/// left child's table `prims(right child)` places before it. Every leaf must hold one
/// primitive (PLOC's output).
#[inline(never)]
fn tables(nodes: &[Bvh2Node], max_leaf: u32) -> Vec<Table> {
    let mut out: Vec<Table> = Vec::with_capacity(nodes.len() / 2 + 1);
    if nodes.is_empty() || nodes[0].is_leaf() {
        return out;
    }
    // A leaf child: one primitive, the same cost for every budget.
    let leaf = |b: &Aabb| [half_area(b) * PRIM_COST; 7];
    let mut stack: Vec<(u32, bool)> = vec![(0, false)];
    while let Some((n, expanded)) = stack.pop() {
        let node = &nodes[n as usize];
        let (l, r) = (node.first_index as usize, node.first_index as usize + 1);
        if !expanded {
            stack.push((n, true));
            for c in [r, l] {
                if !nodes[c].is_leaf() {
                    stack.push((c as u32, false));
                }
            }
            continue;
        }
        let len = out.len();
        let (cr, nr) = if nodes[r].is_leaf() {
            assert_eq!(nodes[r].prim_count, 1, "one primitive per binary leaf");
            (leaf(&nodes[r].aabb), 1)
        } else {
            (out[len - 1].cost, out[len - 1].prims)
        };
        let (cl, nl) = if nodes[l].is_leaf() {
            assert_eq!(nodes[l].prim_count, 1, "one primitive per binary leaf");
            (leaf(&nodes[l].aabb), 1)
        } else {
            let t = &out[len - nr as usize];
            (t.cost, t.prims)
        };
        let area = half_area(&node.aabb);
        let prims = nl + nr;
        if nodes[l].is_leaf() && nodes[r].is_leaf() {
            // Two primitives: every split of a budget costs the same, so the rounds below
            // come to this (the first split where any is cheaper, else as with one fewer).
            // (A fifth of this pass's instructions, callgrind at 2e5 spheres.)
            let two = cl[0] + cr[0];
            let as_node = two + area;
            let as_leaf = if max_leaf >= 2 {
                2.0 * area * PRIM_COST
            } else {
                f32::INFINITY
            };
            let first = if as_leaf < as_node {
                (as_leaf, pick(LEAF, 0, 6))
            } else {
                (as_node, pick(INTERNAL, 0, 6))
            };
            let rest = if two < first.0 {
                (two, pick(DISTRIBUTE, 0, 0))
            } else {
                first
            };
            let mut t = Table {
                cost: [rest.0; 7],
                pick: [rest.1; 7],
                prims,
            };
            (t.cost[0], t.pick[0]) = first;
            out.push(t);
            continue;
        }
        let mut t = Table {
            cost: [0.0; 7],
            pick: [0; 7],
            prims,
        };
        // One subtree: a leaf, or a wide node whose (up to 8) children the two sides share.
        let (mut best, mut k0) = (cl[0] + cr[6], 0);
        for k in 1..7 {
            let c = cl[k] + cr[6 - k];
            (best, k0) = if c < best { (c, k) } else { (best, k0) };
        }
        let as_node = best + area;
        let as_leaf = if prims <= max_leaf {
            prims as f32 * area * PRIM_COST
        } else {
            f32::INFINITY
        };
        (t.cost[0], t.pick[0]) = if as_leaf < as_node {
            (as_leaf, pick(LEAF, k0, 6 - k0))
        } else {
            (as_node, pick(INTERNAL, k0, 6 - k0))
        };
        // More subtrees: as with one fewer, or shared between the two sides.
        for i in 1..7 {
            let (mut c, mut p) = (t.cost[i - 1], t.pick[i - 1]);
            for k in 0..i {
                let s = cl[k] + cr[i - 1 - k];
                (c, p) = if s < c {
                    (s, pick(DISTRIBUTE, k, i - 1 - k))
                } else {
                    (c, p)
                };
            }
            (t.cost[i], t.pick[i]) = (c, p);
        }
        out.push(t);
    }
    out
}

/// A binary node on its way into a wide node: its index, and its table's (for internal ones).
#[derive(Clone, Copy)]
struct Part {
    node: u32,
    table: u32,
}

/// The binary subtrees that become the children of the wide node made from internal node
/// `at`, with budget `i` (0 for a wide node's own children), appended to `out`.
fn children(nodes: &[Bvh2Node], tables: &[Table], at: Part, i: usize, out: &mut Vec<Part>) {
    let node = &nodes[at.node as usize];
    let p = tables[at.table as usize].pick[i];
    let (budget_l, budget_r) = (usize::from(p >> 3 & 7), usize::from(p & 7));
    let (l, r) = (node.first_index, node.first_index + 1);
    let right_prims = if nodes[r as usize].is_leaf() {
        1
    } else {
        tables[at.table as usize - 1].prims
    };
    let sides = [
        (l, at.table.wrapping_sub(right_prims), budget_l),
        (r, at.table.wrapping_sub(1), budget_r),
    ];
    for (c, table, budget) in sides {
        let part = Part { node: c, table };
        if !nodes[c as usize].is_leaf() && tables[table as usize].pick[budget] & KIND == DISTRIBUTE
        {
            children(nodes, tables, part, budget, out);
        } else {
            out.push(part);
        }
    }
}

/// The primitives of a small subtree, left to right.
fn leaf_prims(bvh2: &Bvh2, n: u32, out: &mut Vec<u32>) {
    let node = &bvh2.nodes[n as usize];
    if node.is_leaf() {
        out.push(bvh2.primitive_indices[node.first_index as usize]);
    } else {
        leaf_prims(bvh2, node.first_index, out);
        leaf_prims(bvh2, node.first_index + 1, out);
    }
}

/// Child `c` (of `count`) goes to slot `slot[c]`: the children's centres, seen from the
/// node's, against the 8 octant directions, assigned greedily cheapest first (the paper's
/// auction, simplified as obvhs and others do). Slot `s` is the octant whose direction has
/// a negative x for bit 4, y for bit 2, z for bit 1: the order the traversal's `oct_inv4`
/// expects.
fn slots(centre: Vec3A, child_centres: &[Vec3A]) -> [usize; 8] {
    let count = child_centres.len();
    let mut cost = [[0f32; 8]; 8];
    for (c, &cc) in child_centres.iter().enumerate() {
        let v = cc - centre;
        for (s, cost) in cost[c].iter_mut().enumerate() {
            let sx = if s & 4 != 0 { -v.x } else { v.x };
            let sy = if s & 2 != 0 { -v.y } else { v.y };
            let sz = if s & 1 != 0 { -v.z } else { v.z };
            *cost = sx + sy + sz;
        }
    }
    // Child c's cheapest free slot (the first on a tie), kept until that slot is taken.
    let cheapest = |row: &[f32; 8], free: u8| {
        let mut best = free.trailing_zeros() as usize;
        for s in best + 1..8 {
            if free >> s & 1 != 0 && row[s] < row[best] {
                best = s;
            }
        }
        best
    };
    let mut best = [0usize; 8];
    let mut least = [f32::INFINITY; 8];
    for c in 0..count {
        best[c] = cheapest(&cost[c], 0xff);
        least[c] = cost[c][best[c]];
    }
    // Greedy rounds: the cheapest pair left, the first in (child, slot) order on a tie,
    // whose child and slot then leave; the children whose cheapest slot that was look again.
    let mut slot = [usize::MAX; 8];
    let (mut free, mut left) = (0xffu8, (1u16 << count) - 1);
    while left != 0 {
        let mut c = left.trailing_zeros() as usize;
        for k in c + 1..count {
            if left >> k & 1 != 0 && least[k] < least[c] {
                c = k;
            }
        }
        let s = best[c];
        slot[c] = s;
        free &= !(1 << s);
        left &= !(1 << c);
        for k in 0..count {
            if left >> k & 1 != 0 && best[k] == s {
                best[k] = cheapest(&cost[k], free);
                least[k] = cost[k][best[k]];
            }
        }
    }
    slot
}

/// `2^k` as an f64, for `k` in -1022..=1023.
#[inline]
fn pow2(k: i32) -> f64 {
    f64::from_bits(((k + 1023) as u64) << 52)
}

/// The quantisation of a node's box on one axis: the biased f32 exponent of the grid step
/// `2^k`, the smallest power of two with `255 * 2^k` at least the box's extent (at least
/// `2^-126`, so that it is a normal f32), and the step's inverse `2^-k`.
#[inline]
fn exponent(lo: f32, hi: f32) -> (u8, f64) {
    let extent = f64::from(hi) - f64::from(lo);
    // A first guess from the extent's exponent (255 < 2^8), then exact comparisons.
    let mut k = if extent > 0.0 {
        (((extent.to_bits() >> 52) & 0x7ff) as i32 - 1023 - 8).clamp(-126, 127)
    } else {
        -126
    };
    while k < 127 && 255.0 * pow2(k) < extent {
        k += 1;
    }
    while k > -126 && 255.0 * pow2(k - 1) >= extent {
        k -= 1;
    }
    ((k + 127) as u8, pow2(-k))
}

/// The grid cells, at the step whose inverse is `inv` from `p`, of `lo..hi`, rounded
/// outwards: exact, since the differences of f32s and products with powers of two are exact
/// in f64, and a non-negative number's truncation is its floor. (`f64::floor` is a call into
/// libm on plain x86-64.)
#[inline]
fn quantise(p: f32, inv: f64, lo: f32, hi: f32) -> (u8, u8) {
    let a = ((f64::from(lo) - f64::from(p)) * inv).clamp(0.0, 255.0);
    let b = ((f64::from(hi) - f64::from(p)) * inv).clamp(0.0, 255.0);
    let (fa, fb) = (a as u8, b as u8);
    (fa, if f64::from(fb) < b { fb + 1 } else { fb })
}

/// The compressed wide BVH of `bvh2` (leaves of one primitive), with at most `max_leaf`
/// (1 to 3) primitives per wide leaf, and its depth in wide nodes.
#[inline(never)]
pub(super) fn collapse(bvh2: &Bvh2, max_leaf: u32) -> (CwBvh, usize) {
    let nodes = &bvh2.nodes;
    if nodes.is_empty() {
        return (CwBvh::default(), 0);
    }
    let max_leaf = max_leaf.clamp(1, 3);
    let tables = tables(nodes, max_leaf);
    let mut wide: Vec<CwBvhNode> = Vec::with_capacity(tables.len() / 4 + 1);
    wide.push(CwBvhNode::default());
    let mut prims: Vec<u32> = Vec::with_capacity(bvh2.primitive_indices.len());
    let mut depth = 1;
    // (wide node, binary node it is made from, its depth)
    let mut stack: Vec<(u32, Part, usize)> = Vec::new();
    let root = Part {
        node: 0,
        table: (tables.len() as u32).wrapping_sub(1),
    };
    stack.push((0, root, 1));
    let mut kids: Vec<Part> = Vec::with_capacity(8);
    let mut centres: Vec<Vec3A> = Vec::with_capacity(8);
    while let Some((w, at, d)) = stack.pop() {
        depth = depth.max(d);
        kids.clear();
        if nodes[at.node as usize].is_leaf() {
            // A whole tree of one primitive.
            kids.push(at);
        } else {
            children(nodes, &tables, at, 0, &mut kids);
        }
        let b = &nodes[at.node as usize].aabb;
        centres.clear();
        centres.extend(kids.iter().map(|k| nodes[k.node as usize].aabb.center()));
        let slot = slots(b.center(), &centres);
        let mut node = CwBvhNode {
            p: Vec3::from(b.min),
            ..CwBvhNode::default()
        };
        let axes = [
            exponent(b.min.x, b.max.x),
            exponent(b.min.y, b.max.y),
            exponent(b.min.z, b.max.z),
        ];
        node.e = [axes[0].0, axes[1].0, axes[2].0];
        node.primitive_base_idx = prims.len() as u32;
        node.child_base_idx = wide.len() as u32;
        // Children in slot order, as the leaves' primitives are listed.
        let mut by_slot = [None; 8];
        for (k, part) in kids.iter().enumerate() {
            by_slot[slot[k]] = Some(*part);
        }
        for (s, part) in by_slot.iter().enumerate() {
            let Some(part) = part else { continue };
            let c = &nodes[part.node as usize].aabb;
            (node.child_min_x[s], node.child_max_x[s]) =
                quantise(b.min.x, axes[0].1, c.min.x, c.max.x);
            (node.child_min_y[s], node.child_max_y[s]) =
                quantise(b.min.y, axes[1].1, c.min.y, c.max.y);
            (node.child_min_z[s], node.child_max_z[s]) =
                quantise(b.min.z, axes[2].1, c.min.z, c.max.z);
            let is_leaf = nodes[part.node as usize].is_leaf()
                || tables[part.table as usize].pick[0] & KIND == LEAF;
            if is_leaf {
                let first = prims.len() - node.primitive_base_idx as usize;
                leaf_prims(bvh2, part.node, &mut prims);
                let count = prims.len() - node.primitive_base_idx as usize - first;
                debug_assert!((1..=3).contains(&count) && first + count <= 24);
                // The count in unary in the top three bits, the offset in the low five.
                node.child_meta[s] = first as u8 | ((1u8 << count) - 1) << 5;
            } else {
                node.imask |= 1 << s;
                node.child_meta[s] = (24 + s as u8) | 0b0010_0000;
            }
        }
        // The internal children's wide nodes sit in slot order; they are built depth first,
        // first slot first (obvhs's layout), so they are pushed in reverse.
        wide.resize(
            wide.len() + node.imask.count_ones() as usize,
            CwBvhNode::default(),
        );
        wide[w as usize] = node;
        for s in (0..8).rev() {
            if node.imask >> s & 1 != 0 {
                if let Some(part) = by_slot[s] {
                    let j = (node.imask & ((1u16 << s) - 1) as u8).count_ones();
                    stack.push((node.child_base_idx + j, part, d + 1));
                }
            }
        }
    }
    let bvh = CwBvh {
        nodes: wide,
        primitive_indices: prims,
        total_aabb: nodes[0].aabb,
        exact_node_aabbs: None,
        uses_spatial_splits: false,
    };
    (bvh, depth)
}

#[cfg(test)]
pub(in crate::accel::bvh) mod tests {
    use super::collapse;
    use crate::testing::Rng;
    use glam::Vec3A;
    use obvhs::aabb::Aabb;
    use obvhs::bvh2::reinsertion::ReinsertionOptimizer;
    use obvhs::bvh2::Bvh2;
    use obvhs::cwbvh::bvh2_to_cwbvh::bvh2_to_cwbvh;
    use obvhs::cwbvh::CwBvh;
    use obvhs::ploc::PlocBuilder;
    use obvhs::BvhBuildParams;

    /// The binary tree the renderer builds (build.rs: PLOC, then reinsertion).
    pub(in crate::accel::bvh) fn bvh2(boxes: &[Aabb]) -> Bvh2 {
        let params = BvhBuildParams::very_fast_build();
        let mut bvh2 = PlocBuilder::with_capacity(boxes.len()).build(
            params.ploc_search_distance,
            boxes,
            (0..boxes.len() as u32).collect::<Vec<_>>(),
            params.sort_precision,
            params.search_depth_threshold,
        );
        ReinsertionOptimizer::default().run(&mut bvh2, params.reinsertion_batch_ratio, None);
        bvh2
    }

    /// Walks the wide tree and checks, in f64, that every primitive's box lies inside the
    /// decoded box of each slot above it, that leaves hold 1 to 3 primitives and every
    /// primitive appears once; returns the depth.
    fn check_boxes(bvh: &CwBvh, boxes: &[Aabb]) -> usize {
        let mut seen = vec![false; boxes.len()];
        // (node, boxes of the slots above it, depth)
        let mut stack = vec![(0usize, Vec::<[f64; 6]>::new(), 1usize)];
        let mut deepest = 0;
        let decode = |n: &obvhs::cwbvh::node::CwBvhNode, s: usize| {
            let step = |e: u8| 2f64.powi(i32::from(e) - 127);
            let (sx, sy, sz) = (step(n.e[0]), step(n.e[1]), step(n.e[2]));
            let p = n.p.as_dvec3();
            [
                p.x + f64::from(n.child_min_x[s]) * sx,
                p.y + f64::from(n.child_min_y[s]) * sy,
                p.z + f64::from(n.child_min_z[s]) * sz,
                p.x + f64::from(n.child_max_x[s]) * sx,
                p.y + f64::from(n.child_max_y[s]) * sy,
                p.z + f64::from(n.child_max_z[s]) * sz,
            ]
        };
        let inside = |b: &Aabb, q: &[f64; 6]| {
            let (lo, hi) = (b.min.as_dvec3(), b.max.as_dvec3());
            lo.x >= q[0]
                && lo.y >= q[1]
                && lo.z >= q[2]
                && hi.x <= q[3]
                && hi.y <= q[4]
                && hi.z <= q[5]
        };
        while let Some((at, above, depth)) = stack.pop() {
            deepest = deepest.max(depth);
            let n = &bvh.nodes[at];
            let mut inner = 0;
            for s in 0..8 {
                let meta = n.child_meta[s];
                if meta == 0 {
                    continue;
                }
                let q = decode(n, s);
                let mut chain = above.clone();
                chain.push(q);
                if n.imask >> s & 1 != 0 {
                    stack.push((n.child_base_idx as usize + inner, chain, depth + 1));
                    inner += 1;
                } else {
                    let count = (meta >> 5).count_ones() as usize;
                    assert!((1..=3).contains(&count) && meta >> 5 == (1 << count) - 1);
                    let first = n.primitive_base_idx as usize + usize::from(meta & 31);
                    for &prim in &bvh.primitive_indices[first..first + count] {
                        let b = &boxes[prim as usize];
                        assert!(!seen[prim as usize], "primitive {prim} twice");
                        seen[prim as usize] = true;
                        for q in &chain {
                            assert!(inside(b, q), "primitive {prim} {b:?} outside {q:?}");
                        }
                    }
                }
            }
            assert_eq!(inner, n.imask.count_ones() as usize);
        }
        assert!(seen.iter().all(|&s| s), "a primitive is missing");
        deepest
    }

    /// `n` boxes: uniform in `[0, 100]^3` (`kind` 0), coincident (1), far from the origin at
    /// f32's coarse spacing (2), or points (3); radii over six decades.
    pub(in crate::accel::bvh) fn random_boxes(rng: &mut Rng, n: usize, kind: u32) -> Vec<Aabb> {
        (0..n)
            .map(|_| {
                let c = match kind {
                    // Coincident.
                    1 => Vec3A::splat(0.25),
                    // Far from the origin, at f32's coarse spacing there.
                    2 => {
                        Vec3A::new(3e6, -2e6, 1e6)
                            + Vec3A::new(rng.f() as f32, rng.f() as f32, rng.f() as f32) * 10.0
                    }
                    _ => Vec3A::new(rng.f() as f32, rng.f() as f32, rng.f() as f32) * 100.0,
                };
                // Radii over six decades, and points.
                let r = if kind == 3 {
                    0.0
                } else {
                    10f32.powf(rng.range(-5.0, 1.0) as f32)
                };
                Aabb::new(c - r, c + r)
            })
            .collect()
    }

    /// Against obvhs's own conversion (an independent implementation of the same paper with
    /// the same costs and child order): the same tree, node for node, with grid steps no
    /// coarser than obvhs's; and, checked in f64 on our own, every primitive inside the
    /// decoded boxes above it.
    #[test]
    fn collapse_matches_obvhs_and_its_boxes_hold_their_primitives() {
        let mut rng = Rng::new(20_261_203);
        for (n, kind) in [
            (1, 0),
            (2, 0),
            (3, 0),
            (4, 0),
            (9, 0),
            (100, 0),
            (5000, 0),
            (300, 1),
            (2000, 2),
            (500, 3),
        ] {
            let boxes = random_boxes(&mut rng, n, kind);
            let bvh2 = bvh2(&boxes);
            let (ours, depth) = collapse(&bvh2, 3);
            let theirs = bvh2_to_cwbvh(&bvh2, 3, true, false);
            assert_eq!(
                ours.primitive_indices, theirs.primitive_indices,
                "n {n} kind {kind}"
            );
            assert_eq!(ours.nodes.len(), theirs.nodes.len());
            for (a, b) in ours.nodes.iter().zip(&theirs.nodes) {
                assert_eq!(
                    (
                        a.p,
                        a.imask,
                        a.child_base_idx,
                        a.primitive_base_idx,
                        a.child_meta
                    ),
                    (
                        b.p,
                        b.imask,
                        b.child_base_idx,
                        b.primitive_base_idx,
                        b.child_meta
                    ),
                    "n {n} kind {kind}"
                );
                for k in 0..3 {
                    assert!(
                        a.e[k] <= b.e[k],
                        "n {n} kind {kind}: step {} > {}",
                        a.e[k],
                        b.e[k]
                    );
                }
            }
            assert_eq!(depth, check_boxes(&ours, &boxes), "n {n} kind {kind}");
        }
    }
}
