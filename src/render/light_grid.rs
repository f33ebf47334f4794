//! The scene as each light sees it: a grid over the light's frame in which every sphere is
//! listed in the cells its silhouette covers, sorted by its distance along the light rays (the
//! "light buffer" of Haines and Greenberg, 1986, with exact lists instead of a depth map).
//!
//! Why. The light rays from a piece `[A, B]` of a camera ray sweep a planar region (a strip
//! towards a directional light, the triangle `A B P` towards a point light,
//! `render::shadow_volume`). Seen from the light, that region is a line: the strip projects
//! along `L` onto the segment from `A` to `B`, and the triangle, seen from `P`, onto the arc of
//! directions from `A` to `B`. So the spheres that can meet a band of the region are among
//! those listed in the few cells that line crosses, within the band's range of distances: a
//! binary search per cell, then only spheres near the region. A 3D BVH walked with the region
//! visits every node near a long, thin, slanted quadrilateral instead (measured: about 230 box
//! tests per band query in a million-sphere cloud).
//!
//! The frame. A directional light's frame is the plane normal to `L`, with coordinates
//! `(x . e1, x . e2)` and distance `x . L`. A point light's frame is the cube of directions
//! around `P`: six faces, each with gnomonic coordinates `(w1 / w0, w2 / w0)` of `w = x - P`
//! (`w0` the face's axis), in which great circles, and so the directions from `P` to a
//! straight segment, are straight lines; the distance is `|x - P|`.
//!
//! What a sphere covers. Along `L` a ball `(c, r)` projects to a disc of radius `r`. From `P`
//! it fills the cone of half-angle `alpha`, `sin alpha = r / D`, around `a = (c - P) / D`; on a
//! face whose axis makes `A = a . e0 > sin alpha`, the cone's `u = w1 / w0` ranges over
//! `(A B +- s sqrt(A^2 + B^2 - s^2)) / (A^2 - s^2)` (`B = a . e1`, `s = sin alpha`): the planes
//! `w1 = u w0` tangent to the cone. A sphere wider than 14.5 degrees from `P` (`s > 1/4`), or
//! containing `P`, is listed apart and returned by every query; with `s <= 1/4`, a cone that
//! meets a face (within 54.7 degrees of its axis) has `A >= cos 69.2 > s`, so the formula holds.
//!
//! Rounding. Every sphere is listed in the cells of its silhouette's bounding rectangle grown
//! by a rounding allowance, and a query visits every cell within the same allowance of its
//! line; the lists are a superset of the spheres that meet the region, and the caller decides
//! each one with the exact test (`shadow_volume::touches`). Distances are stored as f32 and
//! searched with a margin far above their rounding.

use glam::{DVec2, DVec3};
use rayon::prelude::*;

use super::lights::LightKind;
use crate::accel::Ball;

mod face;
use face::Face;

/// Spheres wider than this (`sin alpha`) from a point light are listed apart.
const WIDE: f64 = 0.25;
/// A sphere whose silhouette covers more cells than this is listed apart.
const MAX_CELLS: usize = 256;
/// Gnomonic coordinates are within [-1, 1]; their rounding allowance. A query's directions
/// are at least 1e-6 of its length from the light, so their projections are good to about
/// 1e-9 (2^-52 times 1e6, twice); ten times that is allowed on each side.
const UV_PAD: f64 = 1e-8;

/// The grid of one light (see the module comment).
#[derive(Debug)]
pub struct LightGrid {
    frame: Frame,
    faces: Vec<Face>,
    /// Spheres returned by every query (wide or containing a point light).
    always: Vec<u32>,
}

/// How a light sees the scene (the module comment's "frame"): along `l` onto the plane of
/// `e1`, `e2` (directional), or from `p` onto the cube of directions (point).
#[derive(Clone, Copy, Debug)]
enum Frame {
    Along { e1: DVec3, e2: DVec3, l: DVec3 },
    From { p: DVec3 },
}

/// A sphere's silhouette on one face: the rectangle `lo..hi`.
#[derive(Clone, Copy, Debug)]
struct Footprint {
    lo: DVec2,
    hi: DVec2,
}

/// Pass 1's result: per face, the bounding rectangle and a sample of widths.
struct Sketch([(DVec2, DVec2); 6], [Vec<f64>; 6]);

impl Sketch {
    fn new() -> Sketch {
        Sketch(
            [(DVec2::splat(f64::INFINITY), DVec2::splat(f64::NEG_INFINITY)); 6],
            Default::default(),
        )
    }
}

/// A sphere's cells `cover` (columns `i0..=i1`, rows `j0..=j1`) on one face, or listed apart.
#[derive(Clone, Copy, Debug)]
struct Placed {
    key: f32,
    reach: f32,
    prim: u32,
    face: u8,
    cover: [u16; 4],
}

impl Placed {
    const APART: u8 = u8::MAX;

    fn apart(i: usize) -> Placed {
        Placed {
            key: f32::NEG_INFINITY,
            reach: 0.0,
            prim: i as u32,
            face: Placed::APART,
            cover: [0; 4],
        }
    }
}

impl Frame {
    fn faces(&self) -> usize {
        match self {
            Frame::Along { .. } => 1,
            Frame::From { .. } => 6,
        }
    }

    /// The face axes of point-light face `f`: axis, sign, the two others.
    fn axes(f: usize) -> (usize, f64, usize, usize) {
        let k = f / 2;
        let sign = if f % 2 == 0 { 1.0 } else { -1.0 };
        (k, sign, (k + 1) % 3, (k + 2) % 3)
    }

    /// The distance key of a sphere centred at `c`.
    fn key(&self, c: DVec3) -> f64 {
        match *self {
            Frame::Along { l, .. } => c.dot(l),
            Frame::From { p } => (c - p).length(),
        }
    }

    /// Where `p` lies on each face (`out[f]`, `None` where it does not); false when it must
    /// be listed apart instead.
    fn footprints(&self, p: &impl Ball, pad: f64, out: &mut [Option<Footprint>; 6]) -> bool {
        *out = [None; 6];
        match *self {
            Frame::Along { e1, e2, .. } => {
                let c = DVec2::new(p.center().dot(e1), p.center().dot(e2));
                let r = DVec2::splat(p.radius() + pad);
                out[0] = Some(Footprint {
                    lo: c - r,
                    hi: c + r,
                });
                true
            }
            Frame::From { p: light } => {
                let w = p.center() - light;
                let dist = w.length();
                let s = p.radius() / dist * (1.0 + 1e-9) + 1e-15;
                // (Also for NaN: a degenerate sphere is listed apart.)
                if s.is_nan() || s > WIDE {
                    return false;
                }
                let a = w / dist;
                for (f, slot) in out.iter_mut().enumerate() {
                    let (k, sign, k1, k2) = Frame::axes(f);
                    let big = sign * a[k];
                    // The cone must reach the face's pyramid: within its four half-spaces
                    // sign w_k >= +-w_m (unit normals (sign e_k -+ e_m) / sqrt 2).
                    let reach = -s * std::f64::consts::SQRT_2;
                    if big <= s
                        || big - a[k1] < reach
                        || big + a[k1] < reach
                        || big - a[k2] < reach
                        || big + a[k2] < reach
                    {
                        continue;
                    }
                    let range = |b: f64| {
                        let den = big * big - s * s;
                        let root = s * (big * big + b * b - s * s).max(0.0).sqrt();
                        let (u0, u1) = ((big * b - root) / den, (big * b + root) / den);
                        let pad = UV_PAD * (1.0 + u0.abs().max(u1.abs()));
                        (u0 - pad, u1 + pad)
                    };
                    let (u0, u1) = range(a[k1]);
                    let (v0, v1) = range(a[k2]);
                    let edge = 1.0 + UV_PAD;
                    if u0 > edge || u1 < -edge || v0 > edge || v1 < -edge {
                        continue;
                    }
                    let clip = |x: f64| x.clamp(-edge, edge);
                    *slot = Some(Footprint {
                        lo: DVec2::new(clip(u0), clip(v0)),
                        hi: DVec2::new(clip(u1), clip(v1)),
                    });
                }
                true
            }
        }
    }
}

impl LightGrid {
    /// The grid of `light` over `prims`; `None` for an empty scene, or one with coordinates
    /// beyond 1e30 (the BVH serves those).
    pub fn build<P: Ball + Sync>(light: &LightKind, prims: &[P]) -> Option<LightGrid> {
        if prims.is_empty() {
            return None;
        }
        let frame = match *light {
            LightKind::Directional { to_light: l, .. } => {
                let e1 = l.any_orthonormal_vector();
                Frame::Along {
                    e1,
                    e2: l.cross(e1),
                    l,
                }
            }
            LightKind::Point { position, .. } => Frame::From { p: position },
        };
        // The largest coordinate anywhere, for the rounding allowance of projections.
        let big = prims
            .iter()
            .map(|p| p.center().abs().max_element() + p.radius())
            .fold(0.0f64, f64::max);
        if big > 1e30 {
            // Distances are stored as f32: such a scene is searched through the BVH.
            return None;
        }
        let pad = match frame {
            Frame::Along { .. } => 64.0 * f64::EPSILON * big,
            Frame::From { p } => 64.0 * f64::EPSILON * (big + p.abs().max_element()),
        };
        let nf = frame.faces();
        let face_pad = match frame {
            Frame::Along { .. } => pad,
            Frame::From { .. } => UV_PAD,
        };
        // Pass 1: each face's bounding rectangle, and a sample of silhouette widths.
        let stride = (prims.len() / 65536).max(1);
        let Sketch(rects, mut widths) = prims
            .par_iter()
            .enumerate()
            .fold(Sketch::new, |mut acc, (i, p)| {
                let mut fp = [None; 6];
                if frame.footprints(p, pad, &mut fp) {
                    for (f, q) in fp.iter().enumerate().take(nf) {
                        if let Some(q) = q {
                            acc.0[f].0 = acc.0[f].0.min(q.lo);
                            acc.0[f].1 = acc.0[f].1.max(q.hi);
                            if i % stride == 0 {
                                acc.1[f].push((q.hi - q.lo).max_element());
                            }
                        }
                    }
                }
                acc
            })
            .reduce(Sketch::new, |mut x, y| {
                for f in 0..6 {
                    x.0[f] = (x.0[f].0.min(y.0[f].0), x.0[f].1.max(y.0[f].1));
                    x.1[f].extend_from_slice(&y.1[f]);
                }
                x
            });
        // A face holding spheres none of which the stride sampled (few, in a large scene):
        // sample them all, so that every face with spheres gets cells.
        for f in 0..nf {
            if widths[f].is_empty() && rects[f].0.x <= rects[f].1.x {
                let mut fp = [None; 6];
                for p in prims {
                    if frame.footprints(p, pad, &mut fp) {
                        if let Some(q) = fp[f] {
                            widths[f].push((q.hi - q.lo).max_element());
                        }
                    }
                }
            }
        }
        let mut faces: Vec<Face> = (0..nf)
            .map(|f| {
                let axis = match frame {
                    Frame::Along { .. } => (0, 1.0, 1, 2),
                    Frame::From { .. } => Frame::axes(f),
                };
                Face::sized(axis, rects[f], &mut widths[f], prims.len(), face_pad)
            })
            .collect();
        // Pass 2: every sphere's cells on every face (or listed apart).
        let place = |(i, p): (usize, &P), out: &mut Vec<Placed>| {
            let mut fp = [None; 6];
            if !frame.footprints(p, pad, &mut fp) {
                out.push(Placed::apart(i));
                return;
            }
            let key = frame.key(p.center()) as f32;
            let reach = (p.radius() * (1.0 + 1e-6)) as f32;
            let mark = out.len();
            for f in 0..nf {
                if let Some(q) = fp[f] {
                    let (i0, i1, j0, j1) = faces[f].cover(q.lo, q.hi);
                    if (i1 - i0 + 1) * (j1 - j0 + 1) > MAX_CELLS {
                        out.truncate(mark);
                        out.push(Placed::apart(i));
                        return;
                    }
                    out.push(Placed {
                        key,
                        reach,
                        prim: i as u32,
                        face: f as u8,
                        cover: [i0 as u16, i1 as u16, j0 as u16, j1 as u16],
                    });
                }
            }
        };
        const CHUNK: usize = 1 << 14;
        let placed: Vec<Vec<Placed>> = prims
            .par_chunks(CHUNK)
            .enumerate()
            .map(|(c, chunk)| {
                let mut out = Vec::with_capacity(chunk.len());
                for (k, p) in chunk.iter().enumerate() {
                    place((c * CHUNK + k, p), &mut out);
                }
                out
            })
            .collect();
        let placed = || placed.iter().flatten();
        // Pass 3: count, fill, and sort each cell by distance.
        let mut always = Vec::new();
        for q in placed() {
            if q.face == Placed::APART {
                always.push(q.prim);
                continue;
            }
            let face = &mut faces[q.face as usize];
            let [i0, i1, j0, j1] = q.cover.map(usize::from);
            for j in j0..=j1 {
                for c in i0..=i1 {
                    face.start[j * face.n.0 + c + 1] += 1;
                }
            }
        }
        let mut next: Vec<Vec<u32>> = Vec::with_capacity(nf);
        for face in &mut faces {
            for k in 0..face.cells() {
                face.start[k + 1] += face.start[k];
            }
            face.entries = vec![(0.0, 0); face.start[face.cells()] as usize];
            next.push(face.start[..face.cells()].to_vec());
        }
        for q in placed() {
            if q.face == Placed::APART {
                continue;
            }
            let f = q.face as usize;
            let face = &mut faces[f];
            let [i0, i1, j0, j1] = q.cover.map(usize::from);
            for j in j0..=j1 {
                for c in i0..=i1 {
                    let cell = j * face.n.0 + c;
                    face.entries[next[f][cell] as usize] = (q.key, q.prim);
                    next[f][cell] += 1;
                    face.reach[cell] = face.reach[cell].max(q.reach);
                }
            }
        }
        for face in &mut faces {
            let mut cells = Vec::with_capacity(face.cells());
            let mut rest = &mut face.entries[..];
            for w in face.start.windows(2) {
                let (cell, tail) = rest.split_at_mut((w[1] - w[0]) as usize);
                cells.push(cell);
                rest = tail;
            }
            cells
                .into_par_iter()
                .for_each(|c| c.sort_unstable_by(|x, y| x.0.total_cmp(&y.0)));
        }
        always.sort_unstable();
        always.dedup();
        Some(LightGrid {
            frame,
            faces,
            always,
        })
    }

    /// Bytes held.
    pub fn heap_bytes(&self) -> usize {
        self.faces
            .iter()
            .map(|f| f.start.capacity() * 4 + f.reach.capacity() * 4 + f.entries.capacity() * 8)
            .sum::<usize>()
            + self.always.capacity() * 4
    }

    /// Appends to `out` (with repeats) a superset of the primitives that meet the band
    /// `[f0, f1]` of the region swept from the segment `[a, b]` towards the light (the units of
    /// `shadow_volume::Region::band`). Returns false, having appended nothing, where the grid
    /// cannot answer (a segment through a point light): search the BVH instead.
    pub fn candidates(&self, a: DVec3, b: DVec3, (f0, f1): (f64, f64), out: &mut Vec<u32>) -> bool {
        let mark = out.len();
        match self.frame {
            Frame::Along { e1, e2, l } => {
                let face = &self.faces[0];
                let (pa, pb) = (
                    DVec2::new(a.dot(e1), a.dot(e2)),
                    DVec2::new(b.dot(e1), b.dot(e2)),
                );
                let (sa, sb) = (a.dot(l), b.dot(l));
                let keys = (sa.min(sb) + f0, sa.max(sb) + f1);
                // The query's own rounding, beyond what the face allows for.
                let grow = 64.0 * f64::EPSILON * a.abs().max(b.abs()).max_element();
                let keys = (keys.0 - grow, keys.1 + grow);
                if face.cells() > 0 {
                    face.walk(pa, pb, face.pad.max(grow), |cell| {
                        face.scan(cell, keys, out)
                    });
                }
            }
            Frame::From { p } => {
                let (wa, wb) = (a - p, b - p);
                let near = crate::geom::distance_to_segment(p, a, b);
                let far = wa.length().max(wb.length());
                // Within 1e-6 of its length from the light, the segment's directions turn
                // too fast for the projection's rounding: the BVH answers instead.
                if near.is_nan() || near <= 1e-6 * far {
                    return false;
                }
                let keys = ((1.0 - f1).max(0.0) * near, (1.0 - f0) * far);
                let grow = 1e-9 * far;
                let keys = (keys.0 - grow, keys.1 + grow);
                let dw = wb - wa;
                for face in &self.faces {
                    if face.cells() == 0 {
                        continue;
                    }
                    let (k, sign, k1, k2) = face.axis;
                    // The part of the segment whose directions lie in the face's pyramid
                    // (grown by a little, so neighbouring faces overlap): sign w_k >= |w_k1|,
                    // |w_k2|, four conditions linear in the segment parameter.
                    let (mut s0, mut s1) = (0.0f64, 1.0f64);
                    // Far below |w| >= near, so sign w_k > 0 stays true in the grown pyramid.
                    let slack = 1e-12 * far;
                    for (m, e) in [(k1, 1.0), (k1, -1.0), (k2, 1.0), (k2, -1.0)] {
                        let g0 = sign * wa[k] - e * wa[m] + slack;
                        let g1 = sign * dw[k] - e * dw[m];
                        // g0 + s g1 >= 0
                        if g1 == 0.0 {
                            if g0 < 0.0 {
                                s0 = 1.0;
                                s1 = 0.0;
                            }
                        } else if g1 > 0.0 {
                            s0 = s0.max(-g0 / g1);
                        } else {
                            s1 = s1.min(-g0 / g1);
                        }
                    }
                    if s0 > s1 {
                        continue;
                    }
                    let uv = |s: f64| {
                        let w = wa + s * dw;
                        DVec2::new(w[k1], w[k2]) / (sign * w[k])
                    };
                    let (pa, pb) = (uv(s0), uv(s1));
                    if !(pa.is_finite() && pb.is_finite()) {
                        out.truncate(mark);
                        return false;
                    }
                    face.walk(pa, pb, face.pad, |cell| face.scan(cell, keys, out));
                }
            }
        }
        out.extend_from_slice(&self.always);
        true
    }
}
