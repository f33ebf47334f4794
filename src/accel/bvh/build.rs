//! Building the BVH: the primitives in Morton order, cut into at most [`MAX_CHUNKS`] chunks at
//! Morton cell boundaries, each chunk's padded f32 boxes built into a CWBVH by obvhs (PLOC,
//! with clusters of equal Morton codes built apart (clusters.rs), reinsertion, conversion),
//! the chunks side by side on the worker threads.

use std::ops::Range;
use std::time::Instant;

use glam::{DAffine3, DVec3, Vec3A};
use obvhs::aabb::Aabb;
use obvhs::bvh2::reinsertion::ReinsertionOptimizer;
use obvhs::cwbvh::node::CwBvhNode;
use obvhs::BvhBuildParams;
use rayon::prelude::*;

use super::{
    Chunk, Packed, PaddedBox, Prim, SphereBvh, FRAME_FLOOR, MAX_CHUNKS, MAX_PIECES, MIN_CHUNK,
    OUTLIER_CHUNKS, PAD_ULPS, PIECE,
};
use crate::scene::{EllipsoidId, Profile};

mod clusters;

/// What [`SphereBvh::build_packed`] asks of a primitive: its ellipsoid map (when
/// [`Packed::is_ellipsoid`]), its extinction and its density profile (when [`Packed::is_gas`]).
pub type Side<'a> = dyn Fn(&Packed) -> (Option<EllipsoidId>, f64, Profile) + Sync + 'a;

/// Reorders `v` so that `v_new[i] = v_old[order[i]]`, following the permutation's cycles
/// with one bit of bookkeeping per element.
fn permute_in_place<T: Copy>(v: &mut [T], order: &[u32]) {
    debug_assert_eq!(v.len(), order.len());
    let mut done = vec![0u64; v.len().div_ceil(64)];
    for start in 0..v.len() {
        if done[start / 64] >> (start % 64) & 1 != 0 {
            continue;
        }
        // Walk the cycle start -> order[start] -> ..., pulling each element into place.
        let first = v[start];
        let mut i = start;
        loop {
            done[i / 64] |= 1 << (i % 64);
            let src = order[i] as usize;
            if src == start {
                v[i] = first;
                break;
            }
            v[i] = v[src];
            i = src;
        }
    }
}

/// Orders `prims` by the Morton code (21 bits per axis) of their centres in the box `lo..hi`
/// as far as the chunks and their pieces need, and returns the chunks to cut that order into
/// (see [`chunk_ranges`]), each with its pieces (see [`piece_ranges`]). Within a run of at
/// most `piece` the order is left as it is: a run is one Morton cell, which the cuts never
/// split, and each piece's PLOC build sorts its primitives by its own Morton codes anyway.
/// (Sorting on down to single cells was 7 % of a whole `render` of 1e6 spheres,
/// 2026-12-03; one 8-bit pass is enough for even scenes.)
fn morton_sort(
    prims: &mut [Packed],
    lo: DVec3,
    hi: DVec3,
    (per_chunk, piece): (usize, usize),
) -> Vec<(Range<usize>, Vec<Range<usize>>)> {
    fn spread(mut x: u64) -> u64 {
        x &= 0x1f_ffff;
        x = (x | x << 32) & 0x1f_0000_0000_ffff;
        x = (x | x << 16) & 0x1f_0000_ff00_00ff;
        x = (x | x << 8) & 0x100f_00f0_0f00_f00f;
        x = (x | x << 4) & 0x10c3_0c30_c30c_30c3;
        (x | x << 2) & 0x1249_2492_4924_9249
    }
    let scale = DVec3::splat(2_097_151.0) / (hi - lo).max(DVec3::splat(f64::MIN_POSITIVE));
    let mut codes: Vec<u64> = prims
        .par_iter()
        .map(|p| {
            let q = ((p.center - lo) * scale).clamp(DVec3::ZERO, DVec3::splat(2_097_151.0));
            spread(q.x as u64) | spread(q.y as u64) << 1 | spread(q.z as u64) << 2
        })
        .collect();
    let chunks = sort_and_cut(prims, &mut codes, per_chunk);
    // Each chunk sorted on as far as its pieces need, side by side.
    let mut parts = Vec::with_capacity(chunks.len());
    let (mut p, mut c) = (&mut prims[..], &mut codes[..]);
    for range in &chunks {
        let (ph, pt) = p.split_at_mut(range.len());
        let (ch, ct) = c.split_at_mut(range.len());
        parts.push((range.clone(), ph, ch));
        (p, c) = (pt, ct);
    }
    parts
        .into_par_iter()
        .map(|(range, p, c)| {
            let piece = piece.max(range.len().div_ceil(MAX_PIECES));
            if range.len() > piece {
                radix_sort(p, c, 56, piece);
            }
            (range, piece_ranges(c, piece))
        })
        .collect()
}

/// Cuts a chunk's Morton codes, sorted down to runs of at most `piece`, into at most
/// [`MAX_PIECES`] runs of at most `piece` at Morton cell boundaries (as [`chunk_ranges`] cuts
/// chunks), or, when the cells give more, at fixed counts, which may cut a run whose order
/// was left as it was: those pieces are less compact, which costs speed, never a hit.
fn piece_ranges(codes: &[u64], piece: usize) -> Vec<Range<usize>> {
    let cells = cells(codes, piece);
    if cells.len() <= MAX_PIECES {
        return cells;
    }
    let (n, per) = (codes.len(), codes.len().div_ceil(MAX_PIECES));
    (0..n)
        .step_by(per)
        .map(|at| at..(at + per).min(n))
        .collect()
}

/// [`radix_sort`] as far as [`chunk_ranges`] needs, then the chunks: those a full sort gives.
/// Where the cells give too many chunks and [`chunk_ranges`] falls back to fixed counts,
/// which cut inside cells, the sort is finished first.
fn sort_and_cut(prims: &mut [Packed], codes: &mut [u64], per_chunk: usize) -> Vec<Range<usize>> {
    radix_sort(prims, codes, 56, per_chunk);
    cell_ranges(codes, per_chunk).unwrap_or_else(|| {
        radix_sort(prims, codes, 56, 1);
        chunk_ranges(codes, per_chunk)
    })
}

/// Sorts `prims` and their `codes` together by the codes' bits below `shift + 8`, in place:
/// one American-flag pass on bits `shift..shift + 8` (each element is swapped straight into
/// its bucket, which keeps 256 sequential write streams instead of the random accesses of
/// following a permutation's cycles: 2.4 s of a 6.5 s build at 1e7 spheres), then the buckets
/// side by side on the next 8 bits, down to small runs sorted by insertion (stable), or
/// stopping at runs of at most `enough` (1 for a full sort), which keep their order. The
/// result depends on nothing but the input (no thread count): equal codes keep an order fixed
/// by the passes.
fn radix_sort(prims: &mut [Packed], codes: &mut [u64], shift: u32, enough: usize) {
    debug_assert_eq!(prims.len(), codes.len());
    if prims.len() <= enough {
        return;
    }
    if prims.len() <= 32 {
        for i in 1..prims.len() {
            let mut j = i;
            while j > 0 && codes[j - 1] > codes[j] {
                codes.swap(j - 1, j);
                prims.swap(j - 1, j);
                j -= 1;
            }
        }
        return;
    }
    let bucket = |c: u64| (c >> shift & 0xff) as usize;
    let mut counts = [0usize; 256];
    for &c in codes.iter() {
        counts[bucket(c)] += 1;
    }
    let mut heads = [0usize; 256];
    let mut ends = [0usize; 256];
    let mut at = 0;
    for b in 0..256 {
        heads[b] = at;
        at += counts[b];
        ends[b] = at;
    }
    for b in 0..256 {
        while heads[b] < ends[b] {
            let i = heads[b];
            let c = bucket(codes[i]);
            if c == b {
                heads[b] += 1;
            } else {
                let j = heads[c];
                codes.swap(i, j);
                prims.swap(i, j);
                heads[c] += 1;
            }
        }
    }
    if shift == 0 {
        return;
    }
    // The buckets, disjoint runs, on the next 8 bits.
    let mut runs = Vec::with_capacity(256);
    let (mut p, mut c) = (prims, codes);
    for &n in &counts {
        let (ph, pt) = p.split_at_mut(n);
        let (ch, ct) = c.split_at_mut(n);
        if n > 1 {
            runs.push((ph, ch));
        }
        p = pt;
        c = ct;
    }
    let next = shift.saturating_sub(8);
    runs.into_par_iter()
        .for_each(|(p, c)| radix_sort(p, c, next, enough));
}

/// Cuts sorted Morton codes into at most [`MAX_CHUNKS`] ranges of at most `per_chunk`.
///
/// Cuts fall on Morton cell boundaries where possible: the order is split at its octree
/// cells (halving one axis per code bit) until each piece fits, and neighbouring pieces are
/// then merged while they fit. A chunk is then a cell or a few sibling cells, with a compact
/// box: cutting at fixed counts instead (1M random spheres in chunks of 2^17 against octants
/// of ~125,000) gives chunks that straddle two cells, whose boxes overlap their neighbours'
/// and which a ray therefore has to walk for nothing. Falls back to fixed counts if the
/// cells give too many chunks (very uneven scenes).
fn chunk_ranges(codes: &[u64], per_chunk: usize) -> Vec<Range<usize>> {
    cell_ranges(codes, per_chunk).unwrap_or_else(|| {
        let n = codes.len();
        (0..n)
            .step_by(per_chunk)
            .map(|at| at..(at + per_chunk).min(n))
            .collect()
    })
}

/// [`chunk_ranges`] at cell boundaries, or `None` when that gives more than [`MAX_CHUNKS`].
fn cell_ranges(codes: &[u64], per_chunk: usize) -> Option<Vec<Range<usize>>> {
    let merged = cells(codes, per_chunk);
    (merged.len() <= MAX_CHUNKS).then_some(merged)
}

/// Sorted Morton codes cut at cell boundaries into runs of at most `per`: the order is split
/// at its octree cells (halving one axis per code bit) until each piece fits, and
/// neighbouring pieces are then merged while they fit.
fn cells(codes: &[u64], per: usize) -> Vec<Range<usize>> {
    fn split(codes: &[u64], base: usize, bit: i32, per: usize, out: &mut Vec<Range<usize>>) {
        if codes.len() <= per {
            if !codes.is_empty() {
                out.push(base..base + codes.len());
            }
        } else if bit < 0 {
            // Equal codes (coincident centres): fixed counts.
            for at in (0..codes.len()).step_by(per) {
                out.push(base + at..base + (at + per).min(codes.len()));
            }
        } else {
            // Within a cell the higher bits are equal, so `bit` is sorted: zeros first.
            let m = codes.partition_point(|c| c >> bit & 1 == 0);
            split(&codes[..m], base, bit - 1, per, out);
            split(&codes[m..], base + m, bit - 1, per, out);
        }
    }
    let mut pieces = Vec::new();
    split(codes, 0, 62, per, &mut pieces);
    let mut merged: Vec<Range<usize>> = Vec::new();
    for p in pieces {
        match merged.last_mut() {
            Some(last) if p.end - last.start <= per => last.end = p.end,
            _ => merged.push(p),
        }
    }
    merged
}

/// World-space f64 box of a primitive.
fn prim_box(p: &Packed, to_world: Option<&DAffine3>) -> (DVec3, DVec3) {
    match to_world {
        None => (p.center - p.radius, p.center + p.radius),
        Some(m) => {
            // The unit sphere under x -> A x + t spans t +- (|row_i(A)|)_i: exact half extents.
            let a = m.matrix3;
            let h = DVec3::new(a.row(0).length(), a.row(1).length(), a.row(2).length());
            (m.translation - h, m.translation + h)
        }
    }
}

/// The f32 frame of a chunk whose f64 box is `lo..hi`: its centre, its scale (a power of two
/// making the half-size `R_c` about `2^20`) and its padding `PAD_ULPS * 2^-24 * R_c`
/// (world units), where `R_c` is the box's half-diagonal, but at least `floor` (see the
/// module comment).
fn frame(lo: DVec3, hi: DVec3, floor: f64) -> (DVec3, f64, f64) {
    let origin = (lo + hi) * 0.5;
    let half = ((hi - lo) * 0.5).length().max(floor).max(f64::MIN_POSITIVE);
    let pad = PAD_ULPS * half * f64::from(f32::EPSILON) * 0.5;
    let scale = 2f64.powi(20 - half.log2().ceil().clamp(-1000.0, 1000.0) as i32);
    (origin, scale, pad)
}

/// Moves the primitives whose boxes reach far outside the bulk of `prims` to its end and
/// returns how many stay in front. The bulk's box is, per axis, the 1st percentile of the
/// boxes' low faces to the 99th of their high faces (over a sample of at most about 4096),
/// grown on every side by four times its half-diagonal; a primitive whose box does not fit
/// in it (an outsized sphere, or one far from the rest) is an outlier. Fewer than 64
/// primitives have none.
fn split_outliers(
    prims: &mut [Packed],
    boxes_of: &(impl Fn(&Packed) -> (DVec3, DVec3) + Sync),
) -> usize {
    let n = prims.len();
    if n < 64 {
        return n;
    }
    let sample: Vec<(DVec3, DVec3)> = prims
        .iter()
        .step_by((n / 4096).max(1))
        .map(boxes_of)
        .collect();
    let m = sample.len();
    let (low, high) = (m / 100, m - 1 - m / 100);
    let (mut lo, mut hi) = (DVec3::ZERO, DVec3::ZERO);
    for a in 0..3 {
        let mut v: Vec<f64> = sample.iter().map(|b| b.0[a]).collect();
        lo[a] = *v.select_nth_unstable_by(low, f64::total_cmp).1;
        let mut v: Vec<f64> = sample.iter().map(|b| b.1[a]).collect();
        hi[a] = *v.select_nth_unstable_by(high, f64::total_cmp).1;
    }
    let grow = 4.0 * ((hi - lo) * 0.5).length();
    let (lo, hi) = (lo - grow, hi + grow);
    let inside = |p: &Packed| {
        let (a, b) = boxes_of(p);
        a.cmpge(lo).all() && b.cmple(hi).all()
    };
    if prims.par_iter().all(inside) {
        return n;
    }
    let mut k = 0;
    for i in 0..n {
        if inside(&prims[i]) {
            prims.swap(k, i);
            k += 1;
        }
    }
    k
}

/// Builds the tree of one piece (a run of a chunk's primitives) in the chunk's f32 frame
/// `(origin, scale, pad)`, permutes the run into the tree's leaf order, and returns the
/// compressed tree and its depth.
fn build_piece(
    run: &mut [Packed],
    (origin, scale, pad): (DVec3, f64, f64),
    boxes_of: &(impl Fn(&Packed) -> (DVec3, DVec3) + Sync),
) -> (Vec<CwBvhNode>, usize) {
    let pad32 = (pad * scale) as f32;
    let boxes: Vec<PaddedBox> = run
        .iter()
        .map(|p| {
            let (a, b) = boxes_of(p);
            let a = ((a - origin) * scale).as_vec3a() - Vec3A::splat(pad32);
            let b = ((b - origin) * scale).as_vec3a() + Vec3A::splat(pad32);
            PaddedBox(Aabb::new(a, b))
        })
        .collect();
    // obvhs's build_cwbvh, step by step: its debug-build validation asserts a depth below 32,
    // which degenerate sets (concentric spheres) exceed; our walks size their stacks by
    // `Chunk::depth` instead.
    // obvhs's very fast preset (PLOC's smallest search radius, little reinsertion): measured
    // 2026-12-02 against `fast_build`, builds 13 % faster at 1e7 spheres and traces `bench
    // trace`'s rays 7 % faster (camera rays 2.71 against 2.35 M/s/core), the same pictures.
    let params = BvhBuildParams::very_fast_build();
    let mut bvh2 = clusters::build(&boxes, &params);
    ReinsertionOptimizer::default().run(&mut bvh2, params.reinsertion_batch_ratio, None);
    // The boxes are in the BVH2 now: free them before the conversion's peak.
    drop(boxes);
    let (mut bvh, depth) = super::wide::collapse(&bvh2, params.max_prims_per_leaf);
    drop(bvh2);
    // Leaf order: the traversal reports positions in `primitive_indices`, so the piece's
    // spheres are permuted into that order in place and the list is freed.
    permute_in_place(run, &bvh.primitive_indices);
    bvh.nodes.shrink_to_fit();
    (bvh.nodes, depth)
}

impl SphereBvh {
    /// Builds the BVH. `ellipsoids` are the unit-sphere-to-world maps of `Scene::ellipsoids`.
    pub fn build(prims: Vec<Prim>, ellipsoids: &[DAffine3]) -> SphereBvh {
        Self::build_chunked(prims, ellipsoids, (MIN_CHUNK, PIECE))
    }

    /// [`SphereBvh::build`] with a chosen chunk size (at least `len / MAX_CHUNKS`) and piece
    /// size (at least a chunk's size over [`MAX_PIECES`]); tests use it to exercise many
    /// chunks and pieces on small scenes.
    pub fn build_chunked(
        prims: Vec<Prim>,
        ellipsoids: &[DAffine3],
        sizes: (usize, usize),
    ) -> SphereBvh {
        let packed = prims
            .iter()
            .enumerate()
            .map(|(j, p)| {
                Packed::new(
                    p.center,
                    p.radius,
                    (p.material, p.color),
                    j as u32,
                    p.gas,
                    p.ellipsoid.is_some(),
                )
            })
            .collect();
        let profiled = prims.iter().any(|p| p.is_gas() && p.is_profiled());
        let side = |q: &Packed| {
            let p = &prims[q.sphere as usize];
            (p.ellipsoid, p.sigma, p.profile)
        };
        let mut bvh = Self::build_packed_chunked(packed, ellipsoids, sizes, &side, profiled);
        for q in &mut bvh.packed {
            q.sphere = prims[q.sphere as usize].sphere;
        }
        bvh
    }

    /// Builds the BVH over packed primitives whose `sphere` is their position in `packed`
    /// (as [`crate::render::prepare`] makes them from the scene's spheres, in place).
    /// `side(q)` gives a primitive's ellipsoid map (when [`Packed::is_ellipsoid`]), extinction
    /// and profile (when [`Packed::is_gas`]); `profiled` says whether some gas primitive's
    /// profile may be other than constant (else the profiles are not asked for).
    pub fn build_packed(
        packed: Vec<Packed>,
        ellipsoids: &[DAffine3],
        side: &Side<'_>,
        profiled: bool,
    ) -> SphereBvh {
        Self::build_packed_chunked(packed, ellipsoids, (MIN_CHUNK, PIECE), side, profiled)
    }

    fn build_packed_chunked(
        prims: Vec<Packed>,
        ellipsoids: &[DAffine3],
        (per_chunk, piece): (usize, usize),
        side: &Side<'_>,
        profiled: bool,
    ) -> SphereBvh {
        let per_chunk = per_chunk.max(prims.len().div_ceil(MAX_CHUNKS)).max(1);
        let piece = piece.max(1);
        let to_world = |p: &Packed| {
            if p.is_ellipsoid() {
                side(p).0.map(|e| &ellipsoids[e.index()])
            } else {
                None
            }
        };
        let boxes_of = |p: &Packed| prim_box(p, to_world(p));
        let (mut lo, mut hi) = (DVec3::INFINITY, DVec3::NEG_INFINITY);
        for p in &prims {
            let (a, b) = boxes_of(p);
            lo = lo.min(a);
            hi = hi.max(b);
        }
        // The least frame half-size (see the module comment, "Why the f32 boxes are safe").
        let floor = (((hi - lo) * 0.5).length())
            .max(((lo + hi) * 0.5).abs().max_element())
            .max(0.0)
            * FRAME_FLOOR;
        let start = Instant::now();
        let mut prims = prims;
        // The outliers' chunks at the end, each level the outliers of the level before.
        let n = prims.len();
        let bulk = split_outliers(&mut prims, &boxes_of);
        let mut tails = Vec::new();
        let mut at = bulk;
        while at < n {
            let k = at + split_outliers(&mut prims[at..], &boxes_of);
            if k == at || tails.len() + 1 == OUTLIER_CHUNKS {
                tails.push(at..n);
                break;
            }
            tails.push(at..k);
            at = k;
        }
        let (mut blo, mut bhi) = (DVec3::INFINITY, DVec3::NEG_INFINITY);
        for p in &prims[..bulk] {
            blo = blo.min(p.center);
            bhi = bhi.max(p.center);
        }
        let mut chunks = morton_sort(&mut prims[..bulk], blo, bhi, (per_chunk, piece));
        chunks.extend(tails.into_iter().map(|r| {
            let whole = std::iter::once(0..r.len()).collect();
            (r, whole)
        }));
        // Each chunk's f32 frame, from its f64 box.
        let frames: Vec<((DVec3, f64, f64), DVec3, DVec3)> = chunks
            .par_iter()
            .map(|(range, _)| {
                let (mut clo, mut chi) = (DVec3::INFINITY, DVec3::NEG_INFINITY);
                for p in &prims[range.clone()] {
                    let (a, b) = boxes_of(p);
                    clo = clo.min(a);
                    chi = chi.max(b);
                }
                let (origin, scale, pad) = frame(clo, chi, floor);
                ((origin, scale, pad), clo - pad * 2.0, chi + pad * 2.0)
            })
            .collect();
        // The chunks, and the pieces in each, are disjoint runs of `prims`, built side by side
        // (each alone, so the result does not depend on the number of threads; each build's
        // temporary peak is paid once per thread at work), each piece in its chunk's frame.
        let mut parts = Vec::with_capacity(chunks.len());
        let mut rest = &mut prims[..];
        for ((range, pieces), frame) in chunks.into_iter().zip(frames) {
            let (part, tail) = rest.split_at_mut(range.len());
            parts.push((range, pieces, frame, part));
            rest = tail;
        }
        let chunks: Vec<Chunk> = parts
            .into_par_iter()
            .map(|(range, pieces, ((origin, scale, pad), lo, hi), part)| {
                let mut runs = Vec::with_capacity(pieces.len());
                let mut rest = part;
                for piece in &pieces {
                    let (run, tail) = rest.split_at_mut(piece.len());
                    runs.push((piece.start as u32, run));
                    rest = tail;
                }
                let built: Vec<(u32, Vec<CwBvhNode>, usize)> = runs
                    .into_par_iter()
                    .map(|(first, run)| {
                        let (nodes, depth) = build_piece(run, (origin, scale, pad), &boxes_of);
                        (first, nodes, depth)
                    })
                    .collect();
                // Decoded as soon as the chunk's pieces are built (the decoded nodes are 2.8
                // times the compressed ones), and the compressed nodes freed: the peak is
                // the finished trees plus the pieces under way, not plus every compressed
                // tree.
                let depth = built.iter().map(|b| b.2).max().unwrap_or(0);
                let pieces: Vec<(u32, Vec<CwBvhNode>)> = built
                    .into_iter()
                    .map(|(first, nodes, _)| (first, nodes))
                    .collect();
                // (A chunk holds at most 2^17 or a sixteenth of the primitives, fewer than 2^32.)
                debug_assert!(range.len() <= super::node8::MAX_CHUNK_PRIMS);
                let (nodes, joined) = super::node8::join(&pieces);
                drop(pieces);
                Chunk {
                    nodes,
                    depth: depth + joined,
                    base: range.start as u32,
                    origin,
                    scale,
                    pad,
                    lo,
                    hi,
                }
            })
            .collect();
        // The scene's box: the union of the chunks' padded boxes.
        let (mut lo, mut hi) = (DVec3::INFINITY, DVec3::NEG_INFINITY);
        for c in &chunks {
            lo = lo.min(c.lo);
            hi = hi.max(c.hi);
        }
        if chunks.is_empty() {
            (lo, hi) = (DVec3::ZERO, DVec3::ZERO);
        }
        // The side arrays, in leaf order, only when some primitive needs them.
        let sigmas = if prims.iter().any(Packed::is_gas) {
            prims
                .par_iter()
                .map(|q| if q.is_gas() { side(q).1 } else { 0.0 })
                .collect()
        } else {
            Vec::new()
        };
        let profile = |q: &Packed| {
            if q.is_gas() {
                side(q).2
            } else {
                Profile::Constant
            }
        };
        let profiles = if profiled {
            prims.par_iter().map(profile).collect()
        } else {
            Vec::new()
        };
        let ellipsoid_maps = if prims.iter().any(Packed::is_ellipsoid) {
            prims
                .par_iter()
                .map(|q| if q.is_ellipsoid() { side(q).0 } else { None })
                .collect()
        } else {
            Vec::new()
        };
        let build_time = start.elapsed();
        let to_object = ellipsoids.iter().map(|m| m.inverse()).collect();
        SphereBvh {
            packed: prims,
            sigmas,
            profiles,
            ellipsoids: ellipsoid_maps,
            to_object,
            chunk_boxes: super::ChunkBoxes::of(&chunks),
            chunks,
            lo,
            hi,
            build_time,
        }
    }
}

#[cfg(test)]
mod tests;
