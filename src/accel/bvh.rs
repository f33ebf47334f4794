//! The sphere BVH: obvhs's compressed wide BVH (CWBVH) over f32 boxes, with every sphere test
//! done exactly in f64 by the caller's closure (STYLE habit 6: the BVH knows boxes, the caller
//! knows spheres).
//!
//! Why the f32 boxes are safe. Before anything is rounded to f32, coordinates are taken
//! relative to the centre `O` of the scene's f64 bounding box, whose half-diagonal is `R`, and a
//! ray is first clipped in f64 to that (padded) box, so its f32 origin lies within about `R` of
//! `O` and its f32 parameter range is at most about `2R`. Every rounding the traversal makes
//! (the f32 origin and direction, the node's quantised child boxes, obvhs's slab arithmetic and
//! its clamping of `1/d` to `1/f32::EPSILON` for near-axis-parallel rays) moves a box face by
//! at most a few `2^-24 R`. Each primitive box is padded by [`PAD_ULPS`] `* 2^-24 * R`, far
//! beyond that, so a box the exact ray meets is never culled. Padding only costs extra exact
//! tests, never a wrong answer; the f64 closure decides every hit.
//!
//! Why a scaled frame. obvhs's node test clamps a box's entry to at least `1e-4` (an absolute
//! epsilon, `cwbvh::node::EPSILON`), so a box the ray leaves within `1e-4` of its origin is
//! culled: a whole scene smaller than that would vanish, and a shadow ray could miss a thin
//! sliver of a neighbouring sphere. The f32 frame is therefore scaled by a power of two (exact)
//! so that `R` becomes about `2^20`, and every f32 ray starts [`BACKUP`] units before its true
//! start: every box the true segment meets is then left at `t >= BACKUP > 1e-4`.
//!
//! Why chunks. obvhs's build needs about 250 bytes per primitive while it runs (binary nodes,
//! then the CWBVH conversion tables), more than the whole finished structure. The spheres are
//! therefore sorted in Morton order and cut, at Morton cell boundaries where possible, into
//! at most [`MAX_CHUNKS`] spatially compact chunks, each with its own CWBVH, so that the
//! build's peak is paid for one chunk at a time.
//! A ray visits the chunks its f64 box test reaches, nearest first, and stops at the first
//! chunk that starts beyond its closest hit.

use std::ops::Range;
use std::time::{Duration, Instant};

use glam::{DAffine3, DVec3, UVec2, Vec3A};
use obvhs::aabb::Aabb;
use obvhs::bvh2::reinsertion::ReinsertionOptimizer;
use obvhs::cwbvh::bvh2_to_cwbvh::bvh2_to_cwbvh;
use obvhs::cwbvh::CwBvh;
use obvhs::ploc::PlocBuilder;
use obvhs::ray::Ray as Ray32;
use obvhs::{Boundable, BvhBuildParams};

use crate::geom::{ellipsoid_roots, sphere_roots};

/// How far (in scaled f32 units) each f32 ray starts before its true start.
const BACKUP: f32 = 4e-4;

/// At most this many chunks; each holds at least [`MIN_CHUNK`] spheres.
pub const MAX_CHUNKS: usize = 16;
const MIN_CHUNK: usize = 1 << 17;

/// Box padding in units of `2^-24 R` (see the module comment).
const PAD_ULPS: f64 = 64.0;

/// One sphere (or ellipsoid) as the renderer sees it, stored in BVH leaf order.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Prim {
    pub center: DVec3,
    /// Radius; for an ellipsoid, a bounding radius (the exact shape is in `to_object`).
    pub radius: f64,
    /// Index into `Scene::materials`.
    pub material: u32,
    /// Index of the sphere in `Scene::spheres` (light scopes and the `id` channel use it).
    pub sphere: u32,
    /// Its map in [`SphereBvh::to_object`]; `None` for a true sphere.
    pub ellipsoid: Option<crate::scene::EllipsoidId>,
    /// Gas (a participating medium), not an opaque surface.
    pub gas: bool,
    /// Extinction of a gas primitive (MODEL.md section 1); 0 for opaque ones.
    pub sigma: f64,
}

impl Prim {
    #[inline]
    pub fn is_gas(&self) -> bool {
        self.gas
    }
}

/// A closest hit: ray parameter and the primitive's index in [`SphereBvh::prims`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hit {
    pub t: f64,
    pub prim: u32,
}

/// A primitive's f32 box, as obvhs builds from.
struct PaddedBox(Aabb);

impl Boundable for PaddedBox {
    fn aabb(&self) -> Aabb {
        self.0
    }
}

/// One chunk: a CWBVH over `prims[base..base + len]`, and its padded f64 box.
struct Chunk {
    bvh: CwBvh,
    /// Deeper than obvhs's fixed 32-entry traversal stack (which silently overwrites its top
    /// entry when full): traverse with a growable stack instead. Happens only for degenerate
    /// sets, such as hundreds of concentric or coincident spheres.
    deep: bool,
    base: u32,
    lo: DVec3,
    hi: DVec3,
}

pub struct SphereBvh {
    chunks: Vec<Chunk>,
    /// Primitives, chunk after chunk, each chunk in its BVH's leaf order: traversal index `i`
    /// of chunk `c` is `prims[c.base + i]`.
    pub prims: Vec<Prim>,
    /// World-to-object maps of the ellipsoids (object space: the unit sphere).
    pub to_object: Vec<DAffine3>,
    /// Centre of the f32 frame.
    origin: DVec3,
    /// f32 coordinates are `(x - origin) * scale`, a power of two making `R` about `2^20`.
    scale: f64,
    /// The padding of every primitive box (world units).
    pad: f64,
    /// The f64 scene box, padded like the primitive boxes, for clipping rays.
    lo: DVec3,
    hi: DVec3,
    /// Wall time of the build (Morton sort, obvhs builds, reordering).
    pub build_time: Duration,
}

/// The parameter interval where `o + t d` is inside the box `lo..hi`, clipped to
/// `[tmin, tmax]` (f64 slab test; `inv` is `1 / d` componentwise).
#[inline(always)]
fn slab(lo: DVec3, hi: DVec3, o: DVec3, inv: DVec3, tmin: f64, tmax: f64) -> Option<(f64, f64)> {
    let a = (lo - o) * inv;
    let b = (hi - o) * inv;
    let (mut t0, mut t1) = (tmin, tmax);
    for (a, b) in [(a.x, b.x), (a.y, b.y), (a.z, b.z)] {
        let (a, b) = if a > b { (b, a) } else { (a, b) };
        // d[k] == 0 gives +-inf (or NaN when o is on a face; then the axis does not clip).
        if a > t0 {
            t0 = a;
        }
        if b < t1 {
            t1 = b;
        }
    }
    (t0 <= t1).then_some((t0, t1))
}

/// Depth of a CWBVH in nodes (internal children of a node sit contiguously at
/// `child_base_idx`, one per set bit of `imask`).
fn cwbvh_depth(bvh: &CwBvh) -> usize {
    if bvh.nodes.is_empty() {
        return 0;
    }
    let mut deepest = 0;
    let mut stack = vec![(0u32, 1usize)];
    while let Some((n, depth)) = stack.pop() {
        deepest = deepest.max(depth);
        let node = &bvh.nodes[n as usize];
        for k in 0..node.imask.count_ones() {
            stack.push((node.child_base_idx + k, depth + 1));
        }
    }
    deepest
}

/// What a leaf visit tells the traversal.
enum Step {
    Go,
    /// Go on, with the ray's f32 `tmax` lowered to this.
    Shrink(f32),
    Stop,
}

/// Traversal state for `obvhs::traverse!` with a stack of our choosing.
struct Walk<S> {
    stack: S,
    current_group: UVec2,
    primitive_group: UVec2,
    oct_inv4: u32,
    primitive_id: u32,
    hitmask: u32,
}

impl<S> Walk<S> {
    /// The state at chunk `c`'s root, children ordered for `direction`. (obvhs's
    /// `new_traversal` would also build, and zero, a stack of its own that we do not use.)
    #[inline(always)]
    fn start(c: &Chunk, direction: Vec3A, stack: S) -> Walk<S> {
        // obvhs's `ray_get_octant_inv4` (private there).
        let oct_inv4 = (if direction.x < 0.0 { 0 } else { 0x0404_0404 })
            | (if direction.y < 0.0 { 0 } else { 0x0202_0202 })
            | (if direction.z < 0.0 { 0 } else { 0x0101_0101 });
        Walk {
            stack,
            current_group: if c.bvh.nodes.is_empty() {
                UVec2::ZERO
            } else {
                UVec2::new(0, 0x8000_0000)
            },
            primitive_group: UVec2::ZERO,
            oct_inv4,
            primitive_id: 0,
            hitmask: 0,
        }
    }
}

/// Walks chunk `c` along `ray`, calling `leaf(primitive index in the chunk)` for every
/// primitive in a leaf the ray reaches.
#[inline(always)]
fn walk_with<S: obvhs::faststack::FastStack<UVec2>>(
    c: &Chunk,
    stack: S,
    mut ray: Ray32,
    mut leaf: impl FnMut(u32) -> Step,
) {
    let mut state = Walk::start(c, ray.direction, stack);
    let mut node;
    'done: {
        obvhs::traverse!(
            c.bvh,
            node,
            state,
            node.intersect_ray(&ray, state.oct_inv4),
            {
                match leaf(state.primitive_id) {
                    Step::Go => {}
                    Step::Shrink(t) => ray.tmax = ray.tmax.min(t),
                    Step::Stop => break 'done,
                }
            }
        );
    }
}

#[inline(always)]
fn walk(c: &Chunk, ray: Ray32, leaf: impl FnMut(u32) -> Step) {
    if c.deep {
        walk_with(c, Vec::with_capacity(64), ray, leaf);
    } else {
        walk_with(
            c,
            obvhs::faststack::StackStack::<UVec2, 32>::default(),
            ray,
            leaf,
        );
    }
}

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

/// Sorts `prims` by the Morton code (21 bits per axis) of their centres in the box `lo..hi`,
/// and returns the chunks to cut the sorted order into (see [`chunk_ranges`]).
fn morton_sort(prims: &mut [Prim], lo: DVec3, hi: DVec3, per_chunk: usize) -> Vec<Range<usize>> {
    fn spread(mut x: u64) -> u64 {
        x &= 0x1f_ffff;
        x = (x | x << 32) & 0x1f_0000_0000_ffff;
        x = (x | x << 16) & 0x1f_0000_ff00_00ff;
        x = (x | x << 8) & 0x100f_00f0_0f00_f00f;
        x = (x | x << 4) & 0x10c3_0c30_c30c_30c3;
        (x | x << 2) & 0x1249_2492_4924_9249
    }
    let scale = DVec3::splat(2_097_151.0) / (hi - lo).max(DVec3::splat(f64::MIN_POSITIVE));
    let mut keys: Vec<(u64, u32)> = prims
        .iter()
        .enumerate()
        .map(|(i, p)| {
            let q = ((p.center - lo) * scale).clamp(DVec3::ZERO, DVec3::splat(2_097_151.0));
            let code = spread(q.x as u64) | spread(q.y as u64) << 1 | spread(q.z as u64) << 2;
            (code, i as u32)
        })
        .collect();
    keys.sort_unstable();
    let ranges = chunk_ranges(&keys, per_chunk);
    let order: Vec<u32> = keys.iter().map(|k| k.1).collect();
    drop(keys);
    permute_in_place(prims, &order);
    ranges
}

/// Cuts Morton-sorted `(code, index)` keys into at most [`MAX_CHUNKS`] ranges of at most `per_chunk`.
///
/// Cuts fall on Morton cell boundaries where possible: the order is split at its octree
/// cells (halving one axis per code bit) until each piece fits, and neighbouring pieces are
/// then merged while they fit. A chunk is then a cell or a few sibling cells, with a compact
/// box: cutting at fixed counts instead (1M random spheres in chunks of 2^17 against octants
/// of ~125,000) gives chunks that straddle two cells, whose boxes overlap their neighbours'
/// and which a ray therefore has to walk for nothing. Falls back to fixed counts if the
/// cells give too many chunks (very uneven scenes).
fn chunk_ranges(codes: &[(u64, u32)], per_chunk: usize) -> Vec<Range<usize>> {
    fn split(
        codes: &[(u64, u32)],
        base: usize,
        bit: i32,
        per_chunk: usize,
        out: &mut Vec<Range<usize>>,
    ) {
        if codes.len() <= per_chunk {
            if !codes.is_empty() {
                out.push(base..base + codes.len());
            }
        } else if bit < 0 {
            // Equal codes (coincident centres): fixed counts.
            for at in (0..codes.len()).step_by(per_chunk) {
                out.push(base + at..base + (at + per_chunk).min(codes.len()));
            }
        } else {
            // Within a cell the higher bits are equal, so `bit` is sorted: zeros first.
            let m = codes.partition_point(|c| c.0 >> bit & 1 == 0);
            split(&codes[..m], base, bit - 1, per_chunk, out);
            split(&codes[m..], base + m, bit - 1, per_chunk, out);
        }
    }
    let mut pieces = Vec::new();
    split(codes, 0, 62, per_chunk, &mut pieces);
    let mut merged: Vec<Range<usize>> = Vec::new();
    for p in pieces {
        match merged.last_mut() {
            Some(last) if p.end - last.start <= per_chunk => last.end = p.end,
            _ => merged.push(p),
        }
    }
    if merged.len() > MAX_CHUNKS {
        let n = codes.len();
        merged = (0..n)
            .step_by(per_chunk)
            .map(|at| at..(at + per_chunk).min(n))
            .collect();
    }
    merged
}

/// World-space f64 box of a primitive.
fn prim_box(p: &Prim, to_world: Option<&DAffine3>) -> (DVec3, DVec3) {
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

impl SphereBvh {
    /// Builds the BVH. `ellipsoids` are the unit-sphere-to-world maps of `Scene::ellipsoids`.
    pub fn build(prims: Vec<Prim>, ellipsoids: &[DAffine3]) -> SphereBvh {
        let per_chunk = MIN_CHUNK.max(prims.len().div_ceil(MAX_CHUNKS));
        Self::build_chunked(prims, ellipsoids, per_chunk)
    }

    /// [`SphereBvh::build`] with a chosen chunk size (at least `len / MAX_CHUNKS`); tests use
    /// it to exercise many chunks on small scenes.
    pub fn build_chunked(prims: Vec<Prim>, ellipsoids: &[DAffine3], per_chunk: usize) -> SphereBvh {
        let per_chunk = per_chunk.max(prims.len().div_ceil(MAX_CHUNKS)).max(1);
        let to_world = |p: &Prim| p.ellipsoid.map(|e| &ellipsoids[e.index()]);
        let (mut lo, mut hi) = (DVec3::INFINITY, DVec3::NEG_INFINITY);
        for p in &prims {
            let (a, b) = prim_box(p, to_world(p));
            lo = lo.min(a);
            hi = hi.max(b);
        }
        if prims.is_empty() {
            (lo, hi) = (DVec3::ZERO, DVec3::ZERO);
        }
        let origin = (lo + hi) * 0.5;
        let half = ((hi - lo) * 0.5).length().max(f64::MIN_POSITIVE);
        let pad = PAD_ULPS * half * f64::from(f32::EPSILON) * 0.5;
        let scale = 2f64.powi(20 - half.log2().ceil().clamp(-1000.0, 1000.0) as i32);
        let pad32 = (pad * scale) as f32;
        let start = Instant::now();
        let mut prims = prims;
        let ranges = morton_sort(&mut prims, lo, hi, per_chunk);
        let mut chunks = Vec::new();
        for range in ranges {
            let base = range.start;
            let part = &mut prims[range];
            let (mut clo, mut chi) = (DVec3::INFINITY, DVec3::NEG_INFINITY);
            let boxes: Vec<PaddedBox> = part
                .iter()
                .map(|p| {
                    let (a, b) = prim_box(p, to_world(p));
                    clo = clo.min(a);
                    chi = chi.max(b);
                    let a = ((a - origin) * scale).as_vec3a() - Vec3A::splat(pad32);
                    let b = ((b - origin) * scale).as_vec3a() + Vec3A::splat(pad32);
                    PaddedBox(Aabb::new(a, b))
                })
                .collect();
            // obvhs's build_cwbvh, step by step: its debug-build validation asserts a depth
            // below 32, which degenerate sets (concentric spheres) exceed; we handle those
            // (`Chunk::deep`) instead.
            let params = BvhBuildParams::fast_build();
            let mut bvh2 = PlocBuilder::with_capacity(boxes.len()).build(
                params.ploc_search_distance,
                &boxes,
                (0..boxes.len() as u32).collect::<Vec<_>>(),
                params.sort_precision,
                params.search_depth_threshold,
            );
            ReinsertionOptimizer::default().run(&mut bvh2, params.reinsertion_batch_ratio, None);
            let mut bvh = bvh2_to_cwbvh(&bvh2, params.max_prims_per_leaf.clamp(1, 3), true, false);
            drop(bvh2);
            drop(boxes);
            // Leaf order: the traversal reports positions in `primitive_indices`, so the
            // chunk's spheres are permuted into that order in place and the list is freed.
            permute_in_place(part, &bvh.primitive_indices);
            bvh.primitive_indices = Vec::new();
            let deep = cwbvh_depth(&bvh) >= 30;
            chunks.push(Chunk {
                deep,
                bvh,
                base: base as u32,
                lo: clo - pad * 2.0,
                hi: chi + pad * 2.0,
            });
        }
        let build_time = start.elapsed();
        let to_object = ellipsoids.iter().map(|m| m.inverse()).collect();
        SphereBvh {
            prims,
            to_object,
            chunks,
            origin,
            scale,
            pad,
            lo: lo - pad * 2.0,
            hi: hi + pad * 2.0,
            build_time,
        }
    }

    /// The padded world box of every primitive.
    pub fn bounds(&self) -> (DVec3, DVec3) {
        (self.lo, self.hi)
    }

    /// Bytes held by the BVH and the primitive arrays.
    pub fn heap_bytes(&self) -> usize {
        self.chunks
            .iter()
            .map(|c| c.bvh.nodes.capacity() * std::mem::size_of::<obvhs::cwbvh::node::CwBvhNode>())
            .sum::<usize>()
            + self.prims.capacity() * std::mem::size_of::<Prim>()
            + self.to_object.capacity() * std::mem::size_of::<DAffine3>()
    }

    /// Both roots of the line `o + t d` against primitive `p` (sphere or ellipsoid), in `t`.
    #[inline]
    pub fn roots(&self, p: &Prim, o: DVec3, d: DVec3) -> Option<(f64, f64)> {
        match p.ellipsoid {
            None => sphere_roots(o, d, p.center, p.radius),
            Some(e) => ellipsoid_roots(o, d, &self.to_object[e.index()]),
        }
    }

    /// The f32 ray for chunk `c` over `[t0, t1]` (already clipped to the chunk's box): it
    /// starts at the entry point, so its f32 origin lies inside the scene.
    #[inline]
    fn ray32(&self, o: DVec3, d: DVec3, t0: f64, t1: f64) -> Ray32 {
        // `+ 0.0` turns -0.0 into +0.0: obvhs picks a node's near planes from the sign test
        // `d < 0` but divides by the signed zero, so a -0.0 component would invert the slab.
        let dir = d.as_vec3a() + Vec3A::ZERO;
        let start = ((o + t0 * d - self.origin) * self.scale).as_vec3a() - BACKUP * dir;
        // Widen the f32 range: the f32 exit must not fall short of the f64 one.
        let len = (((t1 - t0) * self.scale) as f32 + BACKUP) * (1.0 + 4.0 * f32::EPSILON)
            + f32::MIN_POSITIVE;
        Ray32::new(start, dir, 0.0, len)
    }

    /// The f32 ray parameter of world parameter `t` on a ray from [`SphereBvh::ray32`] that
    /// started at `t0`, rounded up so that no closer box is culled.
    #[inline]
    fn t32_above(&self, t: f64, t0: f64) -> f32 {
        let r = ((t - t0) * self.scale) as f32 + BACKUP;
        r + r.abs() * 4.0 * f32::EPSILON + f32::MIN_POSITIVE
    }

    /// The chunks the segment reaches, with their entry and exit parameters, nearest first,
    /// written to the front of `list`; returns how many. (Filled in place, not returned:
    /// returning the array copied it on every ray.)
    #[inline(always)]
    fn chunks_on(
        &self,
        o: DVec3,
        d: DVec3,
        tmin: f64,
        tmax: f64,
        list: &mut [(f64, f64, u32); MAX_CHUNKS],
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
        let mut n = 0;
        for (k, c) in self.chunks.iter().enumerate() {
            if let Some((t0, t1)) = slab(c.lo, c.hi, o, inv, tmin, tmax) {
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
    #[inline]
    pub fn closest(
        &self,
        o: DVec3,
        d: DVec3,
        tmin: f64,
        tmax: f64,
        mut test: impl FnMut(u32, &Prim, (f64, f64)) -> Option<f64>,
    ) -> Option<Hit> {
        let mut best: Option<Hit> = None;
        let mut list = [(0.0, 0.0, 0u32); MAX_CHUNKS];
        let n = self.chunks_on(o, d, tmin, tmax, &mut list);
        for &(t0, t1, k) in &list[..n] {
            let best_t = best.map_or(tmax, |h| h.t);
            if t0 > best_t {
                break;
            }
            let c = &self.chunks[k as usize];
            let ray = self.ray32(o, d, t0, t1.min(best_t));
            walk(c, ray, |i| {
                let i = c.base + i;
                let p = &self.prims[i as usize];
                if let Some(roots) = self.roots(p, o, d) {
                    if let Some(t) = test(i, p, roots) {
                        // Ties (coincident spheres) go to the earlier sphere in the
                        // scene, whatever the traversal order.
                        let better = match best {
                            None => t <= tmax,
                            Some(b) => {
                                t < b.t
                                    || (t == b.t && p.sphere < self.prims[b.prim as usize].sphere)
                            }
                        };
                        if t > tmin && better {
                            best = Some(Hit { t, prim: i });
                            return Step::Shrink(self.t32_above(t, t0));
                        }
                    }
                }
                Step::Go
            });
        }
        best
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
    #[inline]
    pub fn any_except(
        &self,
        o: DVec3,
        d: DVec3,
        tmin: f64,
        tmax: f64,
        skip: Option<u32>,
        mut blocks: impl FnMut(u32, &Prim, (f64, f64)) -> bool,
    ) -> bool {
        let mut list = [(0.0, 0.0, 0u32); MAX_CHUNKS];
        let n = self.chunks_on(o, d, tmin, tmax, &mut list);
        let mut blocked = false;
        for &(t0, t1, k) in &list[..n] {
            let c = &self.chunks[k as usize];
            walk(c, self.ray32(o, d, t0, t1), |i| {
                let i = c.base + i;
                if Some(i) == skip {
                    return Step::Go;
                }
                let p = &self.prims[i as usize];
                match self.roots(p, o, d) {
                    Some(roots) if blocks(i, p, roots) => {
                        blocked = true;
                        Step::Stop
                    }
                    _ => Step::Go,
                }
            });
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
        stack: &mut Vec<UVec2>,
    ) {
        let inv = 1.0 / self.scale;
        let pad = DVec3::splat(2.0 * self.pad);
        for c in &self.chunks {
            if c.bvh.nodes.is_empty() || !near(c.lo, c.hi) {
                continue;
            }
            stack.clear();
            let mut state = Walk::start(c, Vec3A::X, std::mem::take(stack));
            let mut node: &obvhs::cwbvh::node::CwBvhNode;
            obvhs::traverse!(
                c.bvh,
                node,
                state,
                {
                    let (bits, index) = node.get_child_and_index_bits(state.oct_inv4);
                    let mut mask = 0u32;
                    for child in 0..8 {
                        if node.is_child_empty(child) {
                            continue;
                        }
                        // The child box in world space, padded again for the f32 rounding of
                        // its decoding.
                        let b = node.child_aabb(child);
                        let lo = b.min.as_dvec3() * inv + self.origin - pad;
                        let hi = b.max.as_dvec3() * inv + self.origin + pad;
                        if near(lo, hi) {
                            mask |= obvhs::cwbvh::node::extract_byte64(bits, child)
                                << obvhs::cwbvh::node::extract_byte64(index, child);
                        }
                    }
                    mask
                },
                {
                    let i = c.base + state.primitive_id;
                    visit(i, &self.prims[i as usize]);
                }
            );
            *stack = state.stack;
        }
    }

    /// Calls `visit(prim_index, prim, roots)` for every primitive the line meets whose box the
    /// ray segment `[tmin, tmax]` reaches (order unspecified).
    pub fn all(
        &self,
        o: DVec3,
        d: DVec3,
        tmin: f64,
        tmax: f64,
        mut visit: impl FnMut(u32, &Prim, (f64, f64)),
    ) {
        let mut list = [(0.0, 0.0, 0u32); MAX_CHUNKS];
        let n = self.chunks_on(o, d, tmin, tmax, &mut list);
        for &(t0, t1, k) in &list[..n] {
            let c = &self.chunks[k as usize];
            walk(c, self.ray32(o, d, t0, t1), |i| {
                let i = c.base + i;
                let p = &self.prims[i as usize];
                if let Some(roots) = self.roots(p, o, d) {
                    visit(i, p, roots);
                }
                Step::Go
            });
        }
    }
}

#[cfg(test)]
mod tests {
    use super::{chunk_ranges, permute_in_place, MAX_CHUNKS};
    use crate::testing::Rng;

    #[test]
    fn chunks_follow_morton_cells_and_cover_everything() {
        let mut rng = Rng::new(7);
        // Uniform codes: 8 octants of about n / 8 each, and room for n / 7.5 per chunk.
        let n = 8000;
        let mut keys: Vec<(u64, u32)> = (0..n).map(|i| (rng.u64() >> 1, i)).collect();
        keys.sort_unstable();
        let ranges = chunk_ranges(&keys, n as usize * 2 / 15);
        assert_eq!(ranges.len(), 8);
        for r in &ranges {
            let top = |k: &(u64, u32)| k.0 >> 60;
            assert!(keys[r.clone()]
                .iter()
                .all(|k| top(k) == top(&keys[r.start])));
        }
        // Any sizes: contiguous cover, each within the limit, at most MAX_CHUNKS.
        for (n, per) in [
            (0, 1),
            (1, 1),
            (100, 7),
            (1000, 63),
            (1000, 1000),
            (5000, 313),
        ] {
            let mut keys: Vec<(u64, u32)> =
                (0..n).map(|i| (rng.u64() >> (1 + i % 50), i)).collect();
            keys.sort_unstable();
            let ranges = chunk_ranges(&keys, per);
            assert!(ranges.len() <= MAX_CHUNKS.max(n.div_ceil(per as u32) as usize));
            let mut at = 0;
            for r in ranges {
                assert_eq!(r.start, at);
                assert!(r.end > r.start && r.end - r.start <= per);
                at = r.end;
            }
            assert_eq!(at, n as usize);
        }
        // Equal codes: fixed counts.
        let keys = vec![(5u64, 0u32); 100];
        assert_eq!(chunk_ranges(&keys, 30).len(), 4);
    }

    #[test]
    fn permutation_in_place_matches_a_copy() {
        let mut rng = Rng::new(12345);
        for n in [0usize, 1, 2, 3, 10, 100, 1000] {
            // A random permutation by Fisher-Yates.
            let mut order: Vec<u32> = (0..n as u32).collect();
            for k in (1..n).rev() {
                order.swap(k, rng.below(k + 1));
            }
            let v: Vec<u64> = (0..n as u64).map(|x| x * 7 + 1).collect();
            let want: Vec<u64> = order.iter().map(|&i| v[i as usize]).collect();
            let mut got = v.clone();
            permute_in_place(&mut got, &order);
            assert_eq!(got, want);
        }
    }
}
