//! Packets: up to [`PACKET`] coherent rays (a camera tile's neighbouring pixels) walking one
//! chunk together. Each node is tested once for the whole packet, against the interval hull
//! of its rays (Wald et al., "Ray tracing deformable scenes using dynamic bounding volume
//! hierarchies", 2007: interval arithmetic over the packet's origins and inverse
//! directions), so its cost is shared by every ray; a leaf the hull reaches is then tested
//! ray by ray, first against the leaf's f32 box (the single-ray walk's test, node8.rs) and
//! only then, for the rays that meet the box, sphere by sphere in f64.
//!
//! Why nothing is missed. Every ray of the packet is expressed in one frame: its f32 origin
//! is its point at the packet's common start parameter and its f32 parameter is the world
//! parameter less that start, scaled (query.rs). A ray's own box test is then
//! `(plane - origin) * inv` per axis, each operation rounded once. The hull's bound uses the
//! extreme origin and inverse direction of the rays; since rounding is monotonic, its
//! rounded entry is at most every ray's rounded entry and its rounded exit at least every
//! ray's rounded exit, so whenever one ray's f32 test meets a box, the hull's meets it too.
//! The leaves a ray's single walk would reach are therefore all reached, and each is given
//! the same f32 test and then the exact f64 test.
//!
//! Why the shared frame is safe. A ray's f32 origin is its point at the packet's start, the
//! earliest entry into the chunk among its rays, so it may lie before the ray's own entry.
//! Rays entering more than the chunk's diagonal after the start walk alone (packet_query.rs),
//! so every f32 origin lies within about three half-diagonals `R_c` of the chunk's centre,
//! where the single walk's lie within one: the roundings of the box test grow to a few
//! `2^-24 3R_c`, still far inside the boxes' padding of 64 `2^-24 R_c` (mod.rs).

use obvhs::ray::Ray as Ray32;

use super::node8::{leaf_range, Node8};

/// The most rays a packet holds.
pub const PACKET: usize = 16;

/// A packet's rays in the chunk's f32 frame, one array per coordinate (lane `k` is ray `k`;
/// lanes past the packet's count have `tmax = -inf`, which no box test passes).
pub(super) struct Rays {
    pub origin: [[f32; PACKET]; 3],
    pub inv: [[f32; PACKET]; 3],
    pub tmax: [f32; PACKET],
    pub count: usize,
}

impl Rays {
    pub fn new() -> Rays {
        Rays {
            origin: [[0.0; PACKET]; 3],
            inv: [[1.0; PACKET]; 3],
            tmax: [f32::NEG_INFINITY; PACKET],
            count: 0,
        }
    }

    /// Adds a ray (the caller holds at most [`PACKET`]).
    pub fn push(&mut self, ray: &Ray32) {
        let k = self.count;
        for a in 0..3 {
            self.origin[a][k] = ray.origin[a];
            self.inv[a][k] = ray.inv_direction[a];
        }
        self.tmax[k] = ray.tmax;
        self.count += 1;
    }

    /// The sign of each axis's inverse direction, when the packet holds rays and every ray
    /// has the same.
    pub fn common_signs(&self) -> Option<[bool; 3]> {
        if self.count == 0 {
            return None;
        }
        let mut neg = [false; 3];
        for (a, n) in neg.iter_mut().enumerate() {
            let inv = &self.inv[a][..self.count];
            *n = inv[0] < 0.0;
            if inv.iter().any(|&i| (i < 0.0) != *n) {
                return None;
            }
        }
        Some(neg)
    }
}

/// The hull of a packet: per axis, the least and greatest origin and inverse direction.
struct Hull {
    negative: [bool; 3],
    o_lo: [f32; 3],
    o_hi: [f32; 3],
    i_lo: [f32; 3],
    i_hi: [f32; 3],
}

impl Hull {
    fn of(rays: &Rays, negative: [bool; 3]) -> Hull {
        let n = rays.count;
        let lo = |v: &[f32]| v.iter().fold(f32::INFINITY, |m, &x| m.min(x));
        let hi = |v: &[f32]| v.iter().fold(f32::NEG_INFINITY, |m, &x| m.max(x));
        let mut h = Hull {
            negative,
            o_lo: [0.0; 3],
            o_hi: [0.0; 3],
            i_lo: [0.0; 3],
            i_hi: [0.0; 3],
        };
        for a in 0..3 {
            h.o_lo[a] = lo(&rays.origin[a][..n]);
            h.o_hi[a] = hi(&rays.origin[a][..n]);
            h.i_lo[a] = lo(&rays.inv[a][..n]);
            h.i_hi[a] = hi(&rays.inv[a][..n]);
        }
        h
    }

    /// The children of `n` the hull meets within `[0, tmax]`, as a mask, with a lower bound
    /// of each one's entry (every ray's own entry is at least this).
    #[inline(always)]
    fn children(&self, n: &Node8, tmax: f32) -> (u32, [f32; 8]) {
        let max = |a: f32, b: f32| if a > b { a } else { b };
        let min = |a: f32, b: f32| if a < b { a } else { b };
        let mut near = [0f32; 8];
        let mut far = [tmax; 8];
        for a in 0..3 {
            // For a positive inverse direction the entry `(lo - o) * i` is least for the
            // greatest origin, the exit `(hi - o) * i` greatest for the least; the product's
            // extreme over the inverse directions is at one of their ends.
            let (np, fp, no, fo) = if self.negative[a] {
                (&n.hi[a], &n.lo[a], self.o_lo[a], self.o_hi[a])
            } else {
                (&n.lo[a], &n.hi[a], self.o_hi[a], self.o_lo[a])
            };
            let (il, ih) = (self.i_lo[a], self.i_hi[a]);
            for i in 0..8 {
                let num = np[i] - no;
                near[i] = max(near[i], min(num * il, num * ih));
                let num = fp[i] - fo;
                far[i] = min(far[i], max(num * il, num * ih));
            }
        }
        let mut mask = 0;
        for i in 0..8 {
            mask |= u32::from(near[i] <= far[i]) << i;
        }
        (mask, near)
    }
}

/// Which rays of the packet meet lane `lane` of node `n` (the single-ray walk's test, ray by
/// ray), as a mask.
#[inline(always)]
fn rays_meeting(rays: &Rays, negative: [bool; 3], n: &Node8, lane: usize) -> u32 {
    let max = |a: f32, b: f32| if a > b { a } else { b };
    let min = |a: f32, b: f32| if a < b { a } else { b };
    let mut near = [0f32; PACKET];
    let mut far = rays.tmax;
    for (a, &neg) in negative.iter().enumerate() {
        let (np, fp) = if neg {
            (n.hi[a][lane], n.lo[a][lane])
        } else {
            (n.lo[a][lane], n.hi[a][lane])
        };
        for k in 0..PACKET {
            let (o, i) = (rays.origin[a][k], rays.inv[a][k]);
            near[k] = max(near[k], (np - o) * i);
            far[k] = min(far[k], (fp - o) * i);
        }
    }
    let mut mask = 0;
    for k in 0..PACKET {
        mask |= u32::from(near[k] <= far[k]) << k;
    }
    mask
}

/// A packet walk's stack (kept by the caller from packet to packet): waiting children as
/// (child reference, its node `<< 3 |` lane, the hull's entry).
#[derive(Debug, Default)]
pub struct PacketStack(Vec<(u32, u32, f32)>);

/// Walks `nodes` with the packet `rays` (whose inverse directions have the signs
/// `negative`), calling `leaf(ray, primitive in the chunk)` for every primitive of a leaf box
/// a ray meets within its (shrinking) `tmax`; `leaf` returns the ray's new f32 `tmax` when
/// it found a closer hit. Children are visited by the hull's entry, nearest first, and a
/// waiting child is dropped once every ray's closest hit lies before it.
#[inline(always)]
pub(super) fn walk(
    nodes: &[Node8],
    rays: &mut Rays,
    negative: [bool; 3],
    stack: &mut PacketStack,
    mut leaf: impl FnMut(usize, u32) -> Option<f32>,
) {
    if nodes.is_empty() || rays.count == 0 {
        return;
    }
    let hull = Hull::of(rays, negative);
    let mut tmax = rays.tmax.iter().fold(f32::NEG_INFINITY, |m, &t| m.max(t));
    let stack = &mut stack.0;
    stack.clear();
    stack.push((0, 0, 0.0));
    while let Some((r, at, entry)) = stack.pop() {
        if entry > tmax {
            continue;
        }
        match leaf_range(r) {
            None => {
                let node = &nodes[r as usize];
                let (mut mask, near) = hull.children(node, tmax);
                let base = stack.len();
                while mask != 0 {
                    let i = mask.trailing_zeros() as usize;
                    mask &= mask - 1;
                    let item = (node.child[i], r << 3 | i as u32, near[i]);
                    // Insertion by entry, the nearest on top.
                    stack.push(item);
                    let mut k = stack.len() - 1;
                    while k > base && stack[k - 1].2 < item.2 {
                        stack[k] = stack[k - 1];
                        k -= 1;
                    }
                    stack[k] = item;
                }
            }
            Some(prims) => {
                let node = &nodes[(at >> 3) as usize];
                let mut meet = rays_meeting(rays, negative, node, (at & 7) as usize);
                if meet == 0 {
                    continue;
                }
                while meet != 0 {
                    let k = meet.trailing_zeros() as usize;
                    meet &= meet - 1;
                    for p in prims.clone() {
                        if let Some(t) = leaf(k, p) {
                            rays.tmax[k] = rays.tmax[k].min(t);
                        }
                    }
                }
                tmax = rays.tmax.iter().fold(f32::NEG_INFINITY, |m, &t| m.max(t));
            }
        }
    }
}
