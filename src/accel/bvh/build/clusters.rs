//! The binary BVH of one chunk: obvhs's PLOC over primitives of distinct Morton codes, with
//! every cluster of primitives that share a code built apart by median splits.
//!
//! Why clusters are built apart. PLOC with its smallest search radius merges a node with its
//! neighbour in Morton order only where the cost of merging (the half area of their union)
//! is a local minimum of the sequence: two nodes merge when each prefers the other. Equal
//! boxes (coincident spheres) give equal costs, where every node prefers its right neighbour
//! and only the last of a run of equal boxes is preferred back: one merge per run per pass,
//! so a run of `m` needs `m` passes over the whole chunk (524,287 spheres at 19 centres:
//! 54-100 s). Boxes that share a Morton code but differ otherwise (concentric spheres of
//! different radii, or a scene whose box is so large that its 21 bits per axis put most
//! primitives in one cell) come in an order the codes do not fix, with costs that may rise
//! steadily the same way. Each run of equal codes (the codes PLOC computes, from the same
//! boxes) is therefore built here by splits at the median of the centres along their widest
//! axis (at the median size when the centres coincide), a tree `ceil(log2 m)` deep built in
//! `O(m log m)`, and PLOC gets one box per run. A chunk whose codes are all distinct, as
//! random scenes' are, goes to PLOC as it is, and gets the same tree.
//!
//! Measured 2026-12-05 (2 shared cores, `render --width 64 --height 48 --spp 1 --stats`):
//! 524,287 spheres at 19 centres (nested DEF/USE), BVH build 102.8 s against 0.18 s with
//! the runs built apart; a Jmol peptide of 20,088 triangles with one atom scaled by 2e9,
//! 0.08 s against 0.01 s. `bench trace --spheres 1000000 --runs 3 --threads 1`, four runs
//! each: build 0.31-0.45 s (median 0.34) against 0.22-0.46 s (median 0.38), within the
//! machine's noise; the codes and their sort are the cost added to a chunk of distinct codes.

use glam::Vec3A;
use obvhs::aabb::Aabb;
use obvhs::bvh2::node::Bvh2Node;
use obvhs::bvh2::Bvh2;
use obvhs::ploc::morton::morton_encode_u64_unorm;
use obvhs::ploc::PlocBuilder;
use obvhs::BvhBuildParams;

use super::PaddedBox;

/// The binary BVH over `boxes` (one primitive per leaf, `primitive_indices` into `boxes`),
/// built with `params`' PLOC settings, runs of equal Morton codes built apart.
pub(super) fn build(boxes: &[PaddedBox], params: &BvhBuildParams) -> Bvh2 {
    let ploc = |boxes: &[PaddedBox]| {
        PlocBuilder::with_capacity(boxes.len()).build(
            params.ploc_search_distance,
            boxes,
            (0..boxes.len() as u32).collect::<Vec<_>>(),
            params.sort_precision,
            params.search_depth_threshold,
        )
    };
    let runs = runs_of_equal_codes(boxes);
    if runs.is_empty() {
        return ploc(boxes);
    }
    // One item per run or lone primitive: the primitives of item `k` are
    // `members[starts[k]..starts[k + 1]]`.
    let (members, starts) = items(boxes.len(), runs);
    let item_boxes: Vec<PaddedBox> = starts
        .windows(2)
        .map(|w| PaddedBox(union(boxes, &members[w[0]..w[1]])))
        .collect();
    let mut bvh2 = ploc(&item_boxes);
    drop(item_boxes);
    let mut members = members;
    let mut prims = Vec::with_capacity(boxes.len());
    let mut deepest = 0;
    for slot in 0..bvh2.nodes.len() {
        let node = bvh2.nodes[slot];
        if !node.is_leaf() {
            continue;
        }
        let k = bvh2.primitive_indices[node.first_index as usize] as usize;
        let run = &mut members[starts[k]..starts[k + 1]];
        deepest = deepest.max(split(boxes, run, slot, &mut bvh2.nodes, &mut prims));
    }
    bvh2.primitive_indices = prims;
    bvh2.max_depth += deepest;
    bvh2
}

/// The runs (at least two long) of equal Morton codes among `boxes`' centres, as obvhs's PLOC
/// computes them (21 bits per axis over the boxes' union): for each, its primitives.
fn runs_of_equal_codes(boxes: &[PaddedBox]) -> Vec<Vec<u32>> {
    let mut total = Aabb::empty();
    for b in boxes {
        total.extend(b.0.min);
        total.extend(b.0.max);
    }
    let scale = 1.0 / total.diagonal().as_dvec3();
    let offset = -total.min.as_dvec3() * scale;
    let mut keyed: Vec<(u64, u32)> = boxes
        .iter()
        .enumerate()
        .map(|(i, b)| {
            let code = morton_encode_u64_unorm(b.0.center().as_dvec3() * scale + offset);
            (code, i as u32)
        })
        .collect();
    keyed.sort_unstable();
    keyed
        .chunk_by(|a, b| a.0 == b.0)
        .filter(|run| run.len() > 1)
        .map(|run| run.iter().map(|&(_, i)| i).collect())
        .collect()
}

/// The items PLOC builds from: each run, then each primitive in no run, as a list of
/// primitives and the start of each item in it (with the end last).
fn items(n: usize, runs: Vec<Vec<u32>>) -> (Vec<u32>, Vec<usize>) {
    let mut in_run = vec![false; n];
    let mut members = Vec::with_capacity(n);
    let mut starts = Vec::with_capacity(n + 1);
    for run in runs {
        starts.push(members.len());
        for &i in &run {
            in_run[i as usize] = true;
        }
        members.extend(run);
    }
    for (i, _) in in_run.iter().enumerate().filter(|(_, &r)| !r) {
        starts.push(members.len());
        members.push(i as u32);
    }
    starts.push(members.len());
    (members, starts)
}

fn union(boxes: &[PaddedBox], run: &[u32]) -> Aabb {
    let mut b = Aabb::empty();
    for &i in run {
        b = b.union(&boxes[i as usize].0);
    }
    b
}

/// Builds the tree of `run` into `nodes[slot]`, its children appended to `nodes` and its
/// primitives to `prims`: halves at the median centre along the axis where the centres
/// spread most, or at the median size (half diagonal) where they coincide, ties by index.
/// Returns the tree's depth below `slot`, at most `ceil(log2(run.len()))`.
fn split(
    boxes: &[PaddedBox],
    run: &mut [u32],
    slot: usize,
    nodes: &mut Vec<Bvh2Node>,
    prims: &mut Vec<u32>,
) -> usize {
    let aabb = union(boxes, run);
    if let [only] = run {
        nodes[slot] = Bvh2Node::new(aabb, 1, prims.len() as u32);
        prims.push(*only);
        return 0;
    }
    let center = |i: &u32| boxes[*i as usize].0.center();
    let (mut lo, mut hi) = (Vec3A::INFINITY, Vec3A::NEG_INFINITY);
    for i in run.iter() {
        lo = lo.min(center(i));
        hi = hi.max(center(i));
    }
    let spread = hi - lo;
    let axis = if spread.x >= spread.y && spread.x >= spread.z {
        0
    } else if spread.y >= spread.z {
        1
    } else {
        2
    };
    let mid = run.len() / 2;
    if spread[axis] > 0.0 {
        run.select_nth_unstable_by(mid, |a, b| {
            center(a)[axis].total_cmp(&center(b)[axis]).then(a.cmp(b))
        });
    } else {
        let size = |i: &u32| boxes[*i as usize].0.diagonal().element_sum();
        run.select_nth_unstable_by(mid, |a, b| size(a).total_cmp(&size(b)).then(a.cmp(b)));
    }
    let first = nodes.len();
    nodes.push(Bvh2Node::default());
    nodes.push(Bvh2Node::default());
    nodes[slot] = Bvh2Node::new(aabb, 0, first as u32);
    let (left, right) = run.split_at_mut(mid);
    let l = split(boxes, left, first, nodes, prims);
    let r = split(boxes, right, first + 1, nodes, prims);
    1 + l.max(r)
}
