//! The directions a flat convex polygon blocks, exactly (docs/model.md section 11): a
//! triangle, or a face of a Box, as a region of the sphere of directions that is the
//! intersection of caps.
//!
//! Seen from a point `x` off its plane, a convex polygon of corners `p_i` fills a spherical
//! polygon: the directions `w` on the polygon's side of each plane through `x` and an edge,
//! `s (a_i × a_{i+1}) . w >= 0` with `a_i = p_i - x` and `s` the side of the plane `x` is on,
//! a cap of angular radius 90 degrees (a great circle) per edge. A ray along such a direction
//! meets the plane at `t = h / (m . w)`, `h` the distance from `x` to the plane and `m` the
//! unit normal towards it, so within a reach `D` it keeps the directions with
//! `m . w >= h / D`: one more cap, needed only when a corner is farther than `D`.
//!
//! Two polygons that share an edge compute its plane through `x` from the same two corners,
//! in one order or the other: the cross products are exactly opposite, so their great
//! circles come out exactly equal or exactly opposite, and the union decides them as shared
//! circles (`union`). A point within `1e-10` of the farthest corner's distance from the
//! plane is in it: the polygon is edge-on and blocks nothing.

use glam::{DAffine3, DVec3};

use super::cap::Cap;
use super::union::{Cone, Regions};

/// How near its plane, relative to the distance to its farthest corner, a point sees a
/// polygon edge-on.
pub const EDGE_ON: f64 = 1e-10;

/// Whether the triangle `p` is too thin to be hit: the renderer's rule (`triangle_hit`),
/// its edges' cross product within rounding of 0.
pub fn is_sliver(p: &[DVec3; 3]) -> bool {
    const SLIVER: f64 = 32.0 * f64::EPSILON;
    let (e1, e2) = (p[1] - p[0], p[2] - p[0]);
    let n2 = e1.cross(e2).length_squared();
    let floor = SLIVER * SLIVER * e1.length_squared() * e2.length_squared();
    // (Not finite: a sliver too.)
    n2.partial_cmp(&floor) != Some(std::cmp::Ordering::Greater)
}

/// Adds to `out` the region of directions from `x` whose rays meet the convex polygon
/// `corners` (in order round it, in one plane, at least 3) at a distance of at most `reach`
/// (`f64::INFINITY`: any distance), if it reaches above the horizon of the unit normal `n`;
/// whether it did. The polygon's plane is the one through its first three corners.
pub fn blocked_by_polygon(
    x: DVec3,
    n: DVec3,
    corners: &[DVec3],
    reach: f64,
    out: &mut Regions,
) -> bool {
    region(x, n, corners, reach, None, out)
}

/// [`blocked_by_polygon`] of a triangle seen from a point `x` of another triangle, `own`,
/// whose plane has the unit normal `n`. The corners of `own` are taken in the tangent plane
/// of `x` (projected onto it), and an edge the two share (the same corners) spans with `x`
/// the plane of `own`, whose great circle is the horizon itself: not the plane through the
/// rounded `x`, which within `d` of the edge turns by the rounding of `x` over `d` and would
/// show a sliver of the neighbour above the horizon that a point of `own` does not see.
pub fn blocked_by_triangle(
    x: DVec3,
    n: DVec3,
    p: &[DVec3; 3],
    reach: f64,
    own: Option<&[DVec3; 3]>,
    out: &mut Regions,
) -> bool {
    region(x, n, p, reach, own, out)
}

fn region(
    x: DVec3,
    n: DVec3,
    corners: &[DVec3],
    reach: f64,
    own: Option<&[DVec3; 3]>,
    out: &mut Regions,
) -> bool {
    let k = corners.len();
    debug_assert!(k >= 3);
    // The corners relative to x, and the edges' great circles' axes. (A triangle's or a
    // face of a Box's on the stack; a polyhedron's larger faces', `bracket`, on the heap.)
    let (mut small, mut large);
    let buffer: &mut [DVec3] = if k <= 4 {
        small = [DVec3::ZERO; 8];
        &mut small[..2 * k]
    } else {
        large = vec![DVec3::ZERO; 2 * k];
        &mut large
    };
    let (a, axes) = buffer.split_at_mut(k);
    // Those of `own` lie in its plane, through x: in the tangent plane of x (projected onto
    // it), and the polygon is the one through them.
    let mut flattened = false;
    for (ai, &p) in a.iter_mut().zip(corners) {
        let v = p - x;
        *ai = if own.is_some_and(|o| o.contains(&p)) {
            flattened = true;
            v - n * v.dot(n)
        } else {
            v
        };
    }
    let a = &*a;
    let normal = if flattened {
        (a[1] - a[0]).cross(a[2] - a[0])
    } else {
        (corners[1] - corners[0]).cross(corners[2] - corners[0])
    }
    .normalize_or_zero();
    let h = normal.dot(a[0]);
    let far = a.iter().map(|v| v.length()).fold(0.0, f64::max);
    // Edge-on (or degenerate, or not finite), beyond the reach, or below the horizon.
    // (Not finite: nothing either.)
    let edge_on = h.abs().partial_cmp(&(EDGE_ON * far)) != Some(std::cmp::Ordering::Greater);
    if edge_on || h.abs() >= reach || a.iter().all(|v| v.dot(n) <= 0.0) {
        return false;
    }
    let s = h.signum();
    for i in 0..k {
        let j = (i + 1) % k;
        let shared = own.is_some_and(|o| o.contains(&corners[i]) && o.contains(&corners[j]));
        let axis = if shared {
            // The horizon, on the side of the corners off the edge.
            let side: f64 = a.iter().map(|v| v.dot(n)).sum();
            if side == 0.0 {
                return false;
            }
            n * side.signum()
        } else {
            let e = a[i].cross(a[j]);
            let len = e.length();
            if !(len > 0.0 && len.is_finite()) {
                return false;
            }
            e * (s / len)
        };
        axes[i] = axis;
    }
    let edges = (0..k).map(|i| {
        let edge = [a[i], a[(i + 1) % k]];
        (
            Cap {
                axis: axes[i],
                cos: 0.0,
            },
            Some(edge),
        )
    });
    // Towards the plane, and the cone about it that holds the corners (the spherical polygon
    // is their convex hull, inside any cap of at most 90 degrees that holds them).
    let m = normal * s;
    let units = a.iter().map(|v| *v / v.length());
    let to_m = units
        .clone()
        .map(|u| u.cross(m).length().atan2(u.dot(m)))
        .fold(0.0, f64::max);
    let mut bound = Cone {
        axis: m,
        angle: to_m,
    };
    let sum: DVec3 = units.clone().sum();
    if sum.length() > 1e-3 {
        let axis = sum.normalize();
        let angle = units
            .map(|u| u.cross(axis).length().atan2(u.dot(axis)))
            .fold(0.0, f64::max);
        if angle < bound.angle {
            bound = Cone { axis, angle };
        }
    }
    let mut reach_cap = None;
    if far > reach {
        let cos = h.abs() / reach;
        reach_cap = Some((Cap { axis: m, cos }, None));
        let angle = ((1.0 - cos) * (1.0 + cos)).sqrt().atan2(cos);
        if angle < bound.angle {
            bound = Cone { axis: m, angle };
        }
    }
    // A margin for the rounding of the angles; past 90 degrees a cap bounds nothing.
    bound.angle = if bound.angle + 1e-9 < std::f64::consts::FRAC_PI_2 {
        bound.angle + 1e-9
    } else {
        std::f64::consts::PI
    };
    out.push(edges.chain(reach_cap), bound);
    true
}

/// What a Box does to the directions from a point.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BoxBlocks {
    /// Its faces that face the point, as regions (maybe none).
    Faces,
    /// Every direction: the point is inside it.
    Everything,
}

/// The corners of a Box's faces (bit 0 of a corner's index is its x side, bit 1 its y, bit
/// 2 its z; a set bit is the + side), each in counter-clockwise order seen from outside, so
/// that two faces run through their shared edge in opposite directions.
const FACES: [[usize; 4]; 6] = [
    [0, 4, 6, 2],
    [1, 3, 7, 5],
    [0, 1, 5, 4],
    [2, 6, 7, 3],
    [0, 2, 3, 1],
    [4, 5, 7, 6],
];

/// Adds to `out` the regions of directions from `x` (in the world) whose rays meet the Box
/// of half extents `half`, mapped from the world to its object space by `to_object`, within
/// `reach`: those of the faces that face `x`, for a ray from outside a convex solid meets a
/// face that faces it first. A point within `1e-10` of a half extent inside a face is on it,
/// outside the Box.
pub fn blocked_by_box(
    x: DVec3,
    n: DVec3,
    half: DVec3,
    to_object: &DAffine3,
    reach: f64,
    out: &mut Regions,
) -> BoxBlocks {
    let xo = to_object.transform_point3(x);
    // Per face, how far outside its plane the point is (object space; < 0 inside).
    let beyond = |f: usize| {
        let axis = f / 2;
        if f % 2 == 0 {
            -half[axis] - xo[axis]
        } else {
            xo[axis] - half[axis]
        }
    };
    let slack = |f: usize| 1e-10 * half[f / 2];
    if (0..6).all(|f| beyond(f) < -slack(f)) {
        return BoxBlocks::Everything;
    }
    if (0..6).all(|f| beyond(f) <= 0.0) {
        return BoxBlocks::Faces;
    }
    let to_world = to_object.inverse();
    let corners: [DVec3; 8] = std::array::from_fn(|b| {
        let sign = |bit: usize| if b >> bit & 1 == 1 { 1.0 } else { -1.0 };
        to_world.transform_point3(DVec3::new(
            sign(0) * half.x,
            sign(1) * half.y,
            sign(2) * half.z,
        ))
    });
    for (f, face) in FACES.iter().enumerate() {
        if beyond(f) > 0.0 {
            let quad = face.map(|c| corners[c]);
            blocked_by_polygon(x, n, &quad, reach, out);
        }
    }
    BoxBlocks::Faces
}

/// Whether the triangle `t` lies in the plane of the triangle `own` (within `1e-12` of their
/// size): seen from a point of `own`, it is edge-on whatever the rounding of the point.
pub fn coplanar(own: &[DVec3; 3], t: &[DVec3; 3]) -> bool {
    let normal = (own[1] - own[0]).cross(own[2] - own[0]).normalize_or_zero();
    if normal == DVec3::ZERO {
        return false;
    }
    let size = t
        .iter()
        .chain(own)
        .map(|p| (*p - own[0]).length())
        .fold(0.0, f64::max);
    t.iter()
        .all(|p| normal.dot(*p - own[0]).abs() <= 1e-12 * size)
}
