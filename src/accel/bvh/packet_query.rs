//! The closest hits of a packet of up to [`PACKET`] coherent rays (a camera tile's
//! neighbouring pixels): each chunk the rays reach is walked once for all of them
//! (packet.rs), with the answers of one ray at a time.

use glam::DVec3;

use super::packet::{self, PacketStack, Rays, PACKET};
use super::{Hit, Prim, SphereBvh, ALL_CHUNKS};

impl SphereBvh {
    /// [`SphereBvh::closest`] for up to [`PACKET`] rays at once (`rays[k] = (o, d)`: `o + t d`, all over
    /// `[tmin, tmax]`), each ray's answer written to `best[k]`: the same answers as one ray at
    /// a time, found by walking each chunk once for all the rays that reach it (packet.rs).
    /// `test(ray, index, prim, roots)` is as `closest`'s. Rays whose directions differ in sign
    /// on some axis, or whose entries into a chunk lie far apart, walk that chunk one at a
    /// time.
    #[inline(always)]
    pub fn closest_packet(
        &self,
        rays: &[(DVec3, DVec3)],
        tmin: f64,
        tmax: f64,
        best: &mut [Option<Hit>],
        stack: &mut PacketStack,
        mut test: impl FnMut(usize, u32, &Prim, (f64, f64)) -> Option<f64>,
    ) {
        let n = rays.len();
        assert!(n <= PACKET && best.len() >= n);
        let o: [DVec3; PACKET] = std::array::from_fn(|k| rays.get(k).map_or(DVec3::ZERO, |r| r.0));
        let d: [DVec3; PACKET] = std::array::from_fn(|k| rays.get(k).map_or(DVec3::X, |r| r.1));
        best[..n].fill(None);
        // Each chunk's entry and exit per ray (NaN where the ray does not reach it).
        let mut enter = [[f64::NAN; PACKET]; ALL_CHUNKS];
        let mut leave = [[f64::NAN; PACKET]; ALL_CHUNKS];
        let mut first = [f64::INFINITY; ALL_CHUNKS];
        let mut list = [(0.0, 0.0, 0u32); ALL_CHUNKS];
        for k in 0..n {
            let m = self.chunks_on(o[k], d[k], tmin, tmax, &mut list);
            for &(t0, t1, c) in &list[..m] {
                let c = c as usize;
                enter[c][k] = t0;
                leave[c][k] = t1;
                first[c] = first[c].min(t0);
            }
        }
        let mut order: [usize; ALL_CHUNKS] = std::array::from_fn(|c| c);
        let count = self.chunks.len();
        order[..count].sort_unstable_by(|&a, &b| first[a].total_cmp(&first[b]));
        for &c in &order[..count] {
            if first[c] == f64::INFINITY {
                break;
            }
            let chunk = &self.chunks[c];
            // The rays still looking in this chunk: they reach it before their closest hit.
            let mut slots = [0usize; PACKET];
            let mut active = 0;
            let mut start = f64::INFINITY;
            for k in 0..n {
                let t0 = enter[c][k];
                if t0 <= best[k].map_or(tmax, |h| h.t) {
                    slots[active] = k;
                    active += 1;
                    start = start.min(t0);
                }
            }
            // One frame for the packet: the chunk's, parameters from `start`. A ray entering
            // the chunk further than the chunk's size after `start` (in distance) would put its
            // f32 origin far outside the chunk; it walks alone.
            let size = (chunk.hi - chunk.lo).length();
            let mut packet = Rays::new();
            let mut members = [0usize; PACKET];
            let mut alone = [0usize; PACKET];
            let mut lone = 0;
            for &k in &slots[..active] {
                if active > 1 && (enter[c][k] - start) * d[k].length() <= size {
                    let t1 = leave[c][k].min(best[k].map_or(tmax, |h| h.t));
                    members[packet.count] = k;
                    packet.push(&Self::ray32(chunk, o[k], d[k], start, t1));
                } else {
                    alone[lone] = k;
                    lone += 1;
                }
            }
            let negative = packet.common_signs();
            if negative.is_none() {
                // Mixed signs: every ray alone.
                alone[lone..lone + packet.count].copy_from_slice(&members[..packet.count]);
                lone += packet.count;
            }
            for &k in &alone[..lone] {
                let t1 = leave[c][k].min(best[k].map_or(tmax, |h| h.t));
                self.closest_in(
                    c,
                    (o[k], d[k]),
                    (tmin, tmax),
                    (enter[c][k], t1),
                    &mut best[k],
                    |i, p, r| test(k, i, p, r),
                );
            }
            let Some(negative) = negative else {
                continue;
            };
            packet::walk(&chunk.nodes, &mut packet, negative, stack, |slot, i| {
                let k = members[slot];
                let i = chunk.base + i;
                let roots = self.roots_of(i, o[k], d[k])?;
                let p = &self.prim(i);
                let t = test(k, i, p, roots)?;
                if t > tmin && self.better(t, p, best[k], tmax) {
                    best[k] = Some(Hit { t, prim: i });
                    return Some(Self::t32_above(chunk, t, start));
                }
                None
            });
        }
    }
}
