//! The sphere BVH: a wide BVH over f32 boxes, built with obvhs and collapsed into its
//! compressed wide format (CWBVH), then decoded into plain f32 eight-wide nodes that rays walk
//! (node8.rs says why); every sphere test is done exactly in f64 by the caller's closure
//! (the BVH knows boxes, the caller knows spheres).
//!
//! Why the f32 boxes are safe. Each chunk (below) has its own f32 frame. Before anything is
//! rounded to f32, coordinates are taken relative to the centre `O_c` of the chunk's f64
//! bounding box, whose half-diagonal `R_c` is floored at `FRAME_FLOOR` (`2^-20`) times the
//! larger of the scene's half-diagonal and its centre's largest coordinate. A ray entering
//! a chunk is first clipped in f64 to the chunk's (padded) box and expressed in the chunk's
//! frame from its f64 entry point, so its f32 origin lies within about `R_c` of `O_c` and its
//! f32 parameter range is at most about `2R_c`. Every rounding the traversal makes (the f32
//! origin and direction, the quantised child boxes, the slab arithmetic, and obvhs's clamping
//! of `1/d` to `1/f32::EPSILON` for near-axis-parallel rays) moves a box face by at most a
//! few `2^-24 R_c`; the f64 entry point and the f64 clipping are off by a few `2^-53 X`,
//! where `X` is the larger of the ray origin's coordinates and its distance to the chunk,
//! which the floor keeps below `2^-24 R_c` for any ray starting within about `2^7` scene
//! sizes (or `2^7` times the scene's distance from the world origin) of the scene. Each
//! primitive box is padded by `PAD_ULPS` `* 2^-24 * R_c` (chunk boxes by twice that), far
//! beyond all of these, so a box the exact ray meets is never culled. Padding only costs
//! extra exact tests, never a wrong answer; the f64 closure decides every hit.
//!
//! Why a frame per chunk, and outliers apart. A frame's padding and rounding scale with its
//! `R_c`, so a single frame for a scene whose extent dwarfs its detail (one atom of a
//! molecule scaled by 2e9) would pad every box beyond its neighbours, and each ray would test
//! nearly every primitive exactly. Before the Morton chunks are cut, primitives whose boxes
//! do not fit in the bulk's box (per axis the 1st to 99th percentile of the boxes' faces,
//! grown by four times its half-diagonal) go to a chunk of their own, and the outliers of
//! those to the next, up to `OUTLIER_CHUNKS` such chunks, whatever the scene's size.
//! Measured 2026-12-05: `gtsphere render jmol_edit.wrl --width 64 --height 48 --spp 1
//! --stats` (a Jmol export of 20 088 triangles with one atom scaled by 2e9) takes render
//! seconds 0.80-0.86 with one frame, 0.003-0.015 with a frame per chunk (0.002-0.003 without
//! the atom); `bench trace --spheres 1000000 --runs 3 --threads 1`, five and six runs side by
//! side on a loaded machine (medians): camera 5.07 and shadow 3.86 Mrays/s with one frame,
//! 4.95 and 3.87 with a frame per chunk, within the runs' spread (camera 4.4-5.6 either way).
//!
//! Why a scaled frame. Each f32 frame is scaled by a power of two (exact) so that `R_c` becomes
//! about `2^20`, whatever the scene's size: the node test clamps a box's entry at 0, and every
//! f32 ray starts `BACKUP` units before its true start, so that the rounding of its f32
//! origin cannot put a box the true segment meets behind it.
//!
//! Why chunks. The build needs well over 100 bytes per primitive while it runs (obvhs's
//! binary nodes, then the conversion's tables), more than the whole finished structure. The
//! spheres are therefore sorted in Morton order and cut, at Morton cell boundaries where
//! possible, into at most [`MAX_CHUNKS`] spatially compact chunks (besides the outliers'),
//! each with its own tree and frame, so
//! that the build's peak is paid for one chunk at a time.
//! A ray visits the chunks its f64 box test reaches, nearest first, and stops at the first
//! chunk that starts beyond its closest hit. Sixteen chunks at most: measured 2026-12-05 at
//! 1e7 spheres (`bench trace --spheres 10000000 --size 512 --threads 1`), 32 chunks lower
//! the peak from 89-90 to 79-80 bytes per sphere and the build from 2.3 to 2.0 s, but trace
//! camera and shadow rays 8-10 % slower.
//!
//! Why pieces. A chunk of more than [`PIECE`] spheres (a scene of more than two million) is
//! cut, at Morton cells, into at most [`MAX_PIECES`] pieces, each built on its own in the
//! chunk's frame, and the pieces' trees are joined under one new root as soon as the last
//! is built (then decoded, and their compressed form freed): the build's temporary memory
//! is then a piece's, while a ray still visits at most sixteen chunks and pays one more node
//! per chunk. Measured 2026-12-05 on particles with a colour each (`render FILE --spp 1
//! --width 512 --height 512 --threads 2` on `bench parse --layout continuous`'s file at
//! 1e7 and `bench scale`'s at 1e8, runs alternating with the build of whole chunks decoded
//! at the end, the same pictures): at 1e7 a peak of 764-772 MB against 875-966 MB and the
//! BVH build 2.6 s against 2.9 s; at 1e8 7.67 GB against 8.34 GB.
//! `bench trace --spheres 10000000 --size 512 --runs 1 --threads 2`, two runs each: build
//! 4.4-4.6 s against 5.0-5.2 s, camera rays 2.47-2.49 against 2.40-2.44 Mrays/s/core,
//! shadow rays 2.85-2.89 against 2.58-2.81.
//!
//! Why the ray entry points are compiled twice. The build must run on any x86-64, whose
//! baseline (SSE2) has no 8-wide vectors, no fused multiply-add and no `popcnt` or `tzcnt`.
//! The functions that trace rays through this BVH (`first_sphere`, `first_spheres`,
//! `visible_through_spheres`, `segments::gather`) are therefore `#[multiversion]`: compiled
//! once more for AVX2 + FMA + BMI, and chosen at run time by the CPU (one cached atomic load
//! per call). The walks (node8.rs, packet.rs), their node tests and the leaf closures are
//! inlined into them (`#[inline(always)]`), so that they are compiled for the same
//! instruction set; the sphere test's careful path
//! (`geom::sphere`), too large to inline, is dispatched the same way on its own. Nothing
//! changes in the results: the f32 node test is the same arithmetic in both (the compiler
//! never fuses a multiply and an add by itself), and every sphere test is exact in f64
//! whatever the culling. (Compiling the whole program for this machine's AVX-512 measured no
//! faster than the AVX2 clones, 2026-12-04.)
//!
//! Layout: this file holds the types and what both sides use; `build.rs` the Morton chunks
//! and the obvhs builds, `wide.rs` the collapse of obvhs's binary tree into the CWBVH,
//! `node8.rs` the decoded nodes, their ray test and the walk, `packet.rs` the walk of a packet
//! of coherent rays, `query.rs` the queries on top (closest hit, any hit, a region),
//! `packet_query.rs` the closest hits of a packet.

mod build;
mod node8;
mod packet;
mod packet_query;
pub use packet::{PacketStack, PACKET};
mod query;
mod wide;

use std::time::Duration;

use glam::{DAffine3, DVec3};
use obvhs::aabb::Aabb;
use obvhs::Boundable;

use crate::geom::{ellipsoid_roots, enters_between, sphere_roots};
use crate::scene::Profile;

/// How far (in scaled f32 units) each f32 ray starts before its true start.
const BACKUP: f32 = 4e-4;

/// At most this many chunks of the bulk; each holds at least `MIN_CHUNK` spheres.
pub const MAX_CHUNKS: usize = 16;
/// At most this many chunks of outliers (see the module comment), after the bulk's.
const OUTLIER_CHUNKS: usize = 4;
/// At most this many chunks in all.
const ALL_CHUNKS: usize = MAX_CHUNKS + OUTLIER_CHUNKS;
const MIN_CHUNK: usize = 1 << 17;
/// A chunk larger than this is built in pieces of about this many spheres, at most
/// [`MAX_PIECES`], joined under one root (see the module comment).
const PIECE: usize = 1 << 17;
/// At most this many pieces to a chunk: the children of its root.
const MAX_PIECES: usize = 8;

/// Box padding in units of `2^-24 R_c` (see the module comment).
const PAD_ULPS: f64 = 64.0;

/// A chunk's frame half-size `R_c` is at least this times the larger of the scene's
/// half-diagonal and its centre's largest coordinate (see the module comment).
const FRAME_FLOOR: f64 = 1.0 / (1u64 << 20) as f64;

/// One sphere (or ellipsoid) as the renderer sees it: what [`SphereBvh::prim`] returns, and what
/// [`SphereBvh::build`] takes. The BVH stores it as a 40-byte [`Packed`] record plus side arrays.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Prim {
    /// Its centre, in world space.
    pub center: DVec3,
    /// Radius; for an ellipsoid, a bounding radius (the exact shape is in `to_object`).
    pub radius: f64,
    /// Its diffuse colour.
    pub color: crate::scene::Color,
    /// Index of its material's record in `Scene::materials`.
    pub material: u32,
    /// Index of the sphere in `Scene::spheres` (light scopes and the `id` channel use it).
    pub sphere: u32,
    /// Its map in [`SphereBvh::to_object`]; `None` for a true sphere.
    pub ellipsoid: Option<crate::scene::EllipsoidId>,
    /// Gas (a participating medium), not an opaque surface.
    pub gas: bool,
    /// Extinction of a gas primitive (docs/model.md section 1); 0 for opaque ones. With a density
    /// profile other than constant, the extinction at the centre, `sigma0` (docs/model.md section 6).
    pub sigma: f64,
    /// The gas's radial density profile (constant for opaque primitives).
    pub profile: Profile,
}

impl Prim {
    /// Whether it is gas (a participating medium) rather than an opaque surface.
    #[inline]
    pub fn is_gas(&self) -> bool {
        self.gas
    }

    /// Gas of a density profile other than constant.
    #[inline]
    pub fn is_profiled(&self) -> bool {
        self.profile != Profile::Constant
    }
}

/// A primitive as stored in leaf order: 48 bytes, so that a scene's 56-byte IR spheres turn
/// into them in place and 1e8 of them fit beside everything else. The extinction
/// and the ellipsoid map, which most scenes do not need, live in side arrays of the BVH that
/// are empty unless some primitive has them; the top bits of `tagged` say which.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Packed {
    /// Its centre, in world space.
    pub center: DVec3,
    /// Its radius; for an ellipsoid, a bounding radius.
    pub radius: f64,
    /// Its diffuse colour.
    pub color: crate::scene::Color,
    /// Material record index, with [`GAS`] and [`ELLIPSOID`] in the top bits.
    tagged: u32,
    /// Index of the sphere in `Scene::spheres` (or, inside a build, its position in the input).
    pub sphere: u32,
}

const GAS: u32 = 1 << 31;
const ELLIPSOID: u32 = 1 << 30;

/// The most materials a packed primitive can index.
pub const MAX_MATERIALS: usize = ELLIPSOID as usize;

impl Packed {
    /// Panics when `material` is not below [`MAX_MATERIALS`] (`prepare` refuses such scenes
    /// with an error first).
    #[inline]
    pub fn new(
        center: DVec3,
        radius: f64,
        (material, color): (u32, crate::scene::Color),
        sphere: u32,
        gas: bool,
        ellipsoid: bool,
    ) -> Packed {
        assert!(
            (material as usize) < MAX_MATERIALS,
            "material index {material} too large"
        );
        let tagged = material | if gas { GAS } else { 0 } | if ellipsoid { ELLIPSOID } else { 0 };
        Packed {
            center,
            radius,
            color,
            tagged,
            sphere,
        }
    }
    /// Index of its material's record in `Scene::materials`.
    #[inline]
    pub fn material(&self) -> u32 {
        self.tagged & (ELLIPSOID - 1)
    }
    /// Whether it is gas rather than an opaque surface.
    #[inline]
    pub fn is_gas(&self) -> bool {
        self.tagged & GAS != 0
    }
    /// Whether it is an ellipsoid, its map in [`SphereBvh::to_object`].
    #[inline]
    pub fn is_ellipsoid(&self) -> bool {
        self.tagged & ELLIPSOID != 0
    }
}

/// A ball in world space: what the light grids need of a primitive.
pub trait Ball {
    /// The ball's centre, in world space.
    fn center(&self) -> DVec3;
    /// The ball's radius, in world units.
    fn radius(&self) -> f64;
}

impl Ball for Prim {
    #[inline]
    fn center(&self) -> DVec3 {
        self.center
    }
    #[inline]
    fn radius(&self) -> f64 {
        self.radius
    }
}

impl Ball for Packed {
    #[inline]
    fn center(&self) -> DVec3 {
        self.center
    }
    #[inline]
    fn radius(&self) -> f64 {
        self.radius
    }
}

/// A closest hit: ray parameter and the primitive's index (see [`SphereBvh::prim`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hit {
    /// Its parameter along the ray.
    pub t: f64,
    /// The primitive's index in leaf order, for [`SphereBvh::prim`].
    pub prim: u32,
}

/// A primitive's f32 box, as obvhs builds from.
struct PaddedBox(Aabb);

impl Boundable for PaddedBox {
    fn aabb(&self) -> Aabb {
        self.0
    }
}

/// One chunk: the decoded CWBVH over `prims[base..base + len]` (see node8.rs), its f32 frame
/// and its padded f64 box.
struct Chunk {
    nodes: Vec<node8::Node8>,
    /// The tree's depth in nodes, for the size of a walk's stack.
    depth: usize,
    base: u32,
    /// Centre of the chunk's f32 frame.
    origin: DVec3,
    /// f32 coordinates are `(x - origin) * scale`, a power of two making the frame's
    /// half-size `R_c` about `2^20`.
    scale: f64,
    /// The padding of every primitive box of the chunk (world units).
    pad: f64,
    lo: DVec3,
    hi: DVec3,
}

/// Chunk boxes as arrays per axis, so that the slab tests of four chunks are one SIMD pass.
#[derive(Clone, Copy, Debug, Default)]
struct ChunkBoxes {
    lo: [[f64; ALL_CHUNKS]; 3],
    hi: [[f64; ALL_CHUNKS]; 3],
}

impl ChunkBoxes {
    fn of(chunks: &[Chunk]) -> ChunkBoxes {
        let mut b = ChunkBoxes::default();
        for (k, c) in chunks.iter().enumerate() {
            for a in 0..3 {
                b.lo[a][k] = c.lo[a];
                b.hi[a][k] = c.hi[a];
            }
        }
        b
    }
}

/// The spheres and ellipsoids of a scene in a BVH of f32 boxes, cut into at most
/// [`MAX_CHUNKS`] chunks; its queries (closest hit, any hit, a region) test exactly, in f64,
/// the primitives whose padded boxes a ray meets.
pub struct SphereBvh {
    chunks: Vec<Chunk>,
    /// The chunks' boxes again, axis by axis (lane `k` is chunk `k`), for testing them all
    /// at once.
    chunk_boxes: ChunkBoxes,
    /// Primitives, chunk after chunk, each chunk in its BVH's leaf order: traversal index `i`
    /// of chunk `c` is `packed[c.base + i]`.
    packed: Vec<Packed>,
    /// Extinction per primitive (leaf order); empty when no primitive is gas.
    sigmas: Vec<f64>,
    /// Density profile per primitive (leaf order); empty when every gas primitive is of
    /// constant density.
    profiles: Vec<Profile>,
    /// Ellipsoid map per primitive (leaf order); empty when no primitive is an ellipsoid.
    ellipsoids: Vec<Option<crate::scene::EllipsoidId>>,
    /// World-to-object maps of the ellipsoids (object space: the unit sphere).
    pub to_object: Vec<DAffine3>,
    /// The f64 scene box, the union of the chunks' padded boxes, for clipping rays.
    lo: DVec3,
    hi: DVec3,
    /// Wall time of the build (Morton sort, obvhs builds, reordering).
    pub build_time: Duration,
}

impl SphereBvh {
    /// The padded world box of every primitive.
    pub fn bounds(&self) -> (DVec3, DVec3) {
        (self.lo, self.hi)
    }

    /// Bytes held by the BVH and the primitive arrays.
    pub fn heap_bytes(&self) -> usize {
        self.chunks
            .iter()
            .map(|c| c.nodes.capacity() * std::mem::size_of::<node8::Node8>())
            .sum::<usize>()
            + self.packed.capacity() * std::mem::size_of::<Packed>()
            + self.sigmas.capacity() * std::mem::size_of::<f64>()
            + self.profiles.capacity() * std::mem::size_of::<Profile>()
            + self.ellipsoids.capacity() * std::mem::size_of::<Option<crate::scene::EllipsoidId>>()
            + self.to_object.capacity() * std::mem::size_of::<DAffine3>()
    }

    /// Depth in nodes of the deepest chunk's tree (0 when empty): what a walk's stack holds,
    /// and a measure of the build's work, which grows with it.
    #[cfg(test)]
    pub fn depth(&self) -> usize {
        self.chunks.iter().map(|c| c.depth).max().unwrap_or(0)
    }

    /// Number of primitives.
    #[inline]
    pub fn len(&self) -> usize {
        self.packed.len()
    }

    /// The primitives as stored, in leaf order.
    #[inline]
    pub fn packed(&self) -> &[Packed] {
        &self.packed
    }

    /// Whether some gas primitive has a density profile other than constant.
    #[inline]
    pub fn has_profiles(&self) -> bool {
        !self.profiles.is_empty()
    }

    /// Primitive `i` (leaf order) whole.
    #[inline(always)]
    pub fn prim(&self, i: u32) -> Prim {
        let q = &self.packed[i as usize];
        let gas = q.is_gas();
        Prim {
            center: q.center,
            radius: q.radius,
            color: q.color,
            material: q.material(),
            sphere: q.sphere,
            ellipsoid: if q.is_ellipsoid() {
                self.ellipsoids.get(i as usize).copied().flatten()
            } else {
                None
            },
            gas,
            sigma: if gas {
                self.sigmas.get(i as usize).copied().unwrap_or(0.0)
            } else {
                0.0
            },
            profile: self
                .profiles
                .get(i as usize)
                .copied()
                .unwrap_or(Profile::Constant),
        }
    }

    /// [`SphereBvh::roots`] of primitive `i`, read from its packed record (the whole
    /// primitive is gathered only for an ellipsoid): the traversal's test, most often a miss.
    #[inline(always)]
    pub(crate) fn roots_of(&self, i: u32, o: DVec3, d: DVec3) -> Option<(f64, f64)> {
        let q = &self.packed[i as usize];
        if q.is_ellipsoid() {
            self.roots(&self.prim(i), o, d)
        } else {
            sphere_roots(o, d, q.center, q.radius)
        }
    }

    /// Whether the line `o + t d` enters primitive `i` strictly between `t = 0` and `dist`:
    /// the roots' answer ([`crate::geom::enters_between`] for a sphere, which computes its
    /// careful roots only when the answer is close to call).
    #[inline(always)]
    pub(crate) fn enters_between(&self, i: u32, o: DVec3, d: DVec3, dist: f64) -> bool {
        let q = &self.packed[i as usize];
        if q.is_ellipsoid() {
            matches!(self.roots(&self.prim(i), o, d), Some((t0, _)) if t0 > 0.0 && t0 < dist)
        } else {
            enters_between(o, d, q.center, q.radius, dist)
        }
    }

    /// Both roots of the line `o + t d` against primitive `p` (sphere or ellipsoid), in `t`.
    #[inline]
    pub fn roots(&self, p: &Prim, o: DVec3, d: DVec3) -> Option<(f64, f64)> {
        match p.ellipsoid {
            None => sphere_roots(o, d, p.center, p.radius),
            Some(e) => ellipsoid_roots(o, d, &self.to_object[e.index()]),
        }
    }
}
