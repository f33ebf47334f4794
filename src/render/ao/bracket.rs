//! Cylinders and Cones as occluders, to a tolerance (docs/model.md section 11): the directions
//! a round solid blocks are not bounded by circles of the sphere, so they are bracketed.
//!
//! A closed Cylinder or Cone is convex and lies between two polyhedra with `k` sides: the
//! prism or pyramid over the `k`-gon inscribed in its end discs, and the one over the
//! `k`-gon circumscribed about them. Seen from a point, what the inner one blocks within the
//! reach is inside what the solid blocks, which is inside what the outer one blocks, and the
//! union with the other occluders keeps that order; so the unoccluded fraction among the
//! inner polyhedra is an upper bound of the true one, and among the outer ones a lower
//! bound, both exact (`polygon`, `union`). Their mean is the value and half their gap the
//! error, a bound and not an estimate; `k` doubles from [`FIRST_SIDES`] until the gap is
//! within twice the tolerance or `k` reaches [`MAX_SIDES`], where the gap is reported as it
//! is. The gap falls as `1/k²`: the outer polygon's corners are `1/cos(π/k)` times the radius
//! out. Near a round solid's own surface (a sphere touching a cylinder), the point may lie
//! within the outer polyhedron: there the lower bound is 0 and the error is what `k` =
//! [`MAX_SIDES`] leaves, on a band of width about `5 r / k²` round the solid.
//!
//! The polyhedra are convex, so, as for a Box, their faces that face the point block what they
//! block; each ring of corners is computed once, so that faces sharing an edge share its
//! corners to the bit (`union` decides such edges as shared circles).

use glam::{DAffine3, DVec3};

use super::polygon::{blocked_by_polygon, BoxBlocks};
use super::union::Regions;
use crate::geom::shapes::Solid;

/// The sides of the first pair of polyhedra.
pub const FIRST_SIDES: usize = 8;
/// The most sides a polyhedron is given.
pub const MAX_SIDES: usize = 1024;

/// Which of the two polyhedra about a round solid.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Fit {
    /// Inscribed: inside the solid.
    Inner,
    /// Circumscribed: holding the solid.
    Outer,
}

/// Whether `solid` is a round solid with all its parts, which this module brackets: a
/// Cylinder with its side and both caps, or a Cone with its side and base.
pub fn is_closed_round(solid: &Solid) -> bool {
    match *solid {
        Solid::Cylinder {
            bottom, side, top, ..
        } => bottom && side && top,
        Solid::Cone { side, bottom, .. } => side && bottom,
        Solid::Cuboid { .. } => false,
    }
}

/// Whether `solid` is a Cylinder or a Cone (closed or not).
pub fn is_round(solid: &Solid) -> bool {
    !matches!(solid, Solid::Cuboid { .. })
}

/// Whether the point `xo` (object space) is inside the closed round `solid`, more than
/// `1e-10` of its size from its surface.
pub fn inside(solid: &Solid, xo: DVec3) -> bool {
    match *solid {
        Solid::Cylinder {
            radius,
            half_height,
            ..
        } => xo.y.abs() < half_height * (1.0 - 1e-10) && xo.x.hypot(xo.z) < radius * (1.0 - 1e-10),
        Solid::Cone {
            radius,
            half_height,
            ..
        } => {
            // The radius at height y, from the base's (y = -h) to 0 at the apex (y = h).
            let at = radius * (half_height - xo.y) / (2.0 * half_height);
            xo.y > -half_height * (1.0 - 1e-10) && xo.x.hypot(xo.z) < at * (1.0 - 1e-10)
        }
        Solid::Cuboid { .. } => false,
    }
}

/// Adds to `out` the regions of directions from `x` whose rays meet, within `reach`, the
/// polyhedron with `sides` sides that `fit` names about the closed round `solid` (mapped
/// from the world to its object space by `to_object`, and back by `to_world`): those of its
/// faces that face `x`. Everything when `x` is inside the polyhedron.
#[allow(clippy::too_many_arguments)]
pub fn blocked_by_round(
    (x, n): (DVec3, DVec3),
    solid: &Solid,
    (to_object, to_world): (&DAffine3, &DAffine3),
    sides: usize,
    fit: Fit,
    reach: f64,
    ring: &mut Vec<DVec3>,
    out: &mut Regions,
) -> BoxBlocks {
    let (radius, half_height, cone) = match *solid {
        Solid::Cylinder {
            radius,
            half_height,
            ..
        } => (radius, half_height, false),
        Solid::Cone {
            radius,
            half_height,
            ..
        } => (radius, half_height, true),
        Solid::Cuboid { .. } => return BoxBlocks::Faces,
    };
    let half_turn = std::f64::consts::PI / sides as f64;
    // The polygon's corners lie on the circle of this radius; its sides touch the circle of
    // `radius` (outer) or are chords of it (inner).
    let rho = match fit {
        Fit::Inner => radius,
        Fit::Outer => radius / half_turn.cos(),
    };
    let apothem = rho * half_turn.cos();
    let xo = to_object.transform_point3(x);
    let (h, slack) = (half_height, 1e-10 * half_height.max(radius));
    // Per face, how far outside its plane the point is (object space; < 0 inside): the
    // sides, then the base (y = -h), then the top (y = +h, a Cylinder's).
    let angle = |k: usize| 2.0 * half_turn * k as f64;
    let side_beyond = |k: usize| {
        // The side's outward direction across the axis, at the middle of its edge.
        let (s, c) = (angle(k) + half_turn).sin_cos();
        let radial = xo.x * c + xo.z * s;
        if cone {
            // The plane through the apex (0, h, 0) and the base edge at distance `apothem`
            // from the axis: normal (2h c, apothem, 2h s), unnormalised.
            let normal = DVec3::new(2.0 * h * c, apothem, 2.0 * h * s);
            (radial * 2.0 * h + (xo.y - h) * apothem) / normal.length()
        } else {
            radial - apothem
        }
    };
    let base_beyond = -h - xo.y;
    let top_beyond = xo.y - h;
    let inside_all = (0..sides).all(|k| side_beyond(k) < -slack)
        && base_beyond < -slack
        && (cone || top_beyond < -slack);
    if inside_all {
        return BoxBlocks::Everything;
    }
    // The rings of corners, in the world: the base's, then (a Cylinder's) the top's.
    ring.clear();
    let corner = |k: usize, y: f64| {
        let (s, c) = angle(k).sin_cos();
        to_world.transform_point3(DVec3::new(rho * c, y, rho * s))
    };
    ring.extend((0..sides).map(|k| corner(k, -h)));
    if !cone {
        ring.extend((0..sides).map(|k| corner(k, h)));
    }
    let apex = to_world.transform_point3(DVec3::new(0.0, h, 0.0));
    for k in 0..sides {
        if side_beyond(k) <= 0.0 {
            continue;
        }
        let j = (k + 1) % sides;
        if cone {
            blocked_by_polygon(x, n, &[ring[k], ring[j], apex], reach, out);
        } else {
            let quad = [ring[k], ring[j], ring[sides + j], ring[sides + k]];
            blocked_by_polygon(x, n, &quad, reach, out);
        }
    }
    if base_beyond > 0.0 {
        blocked_by_polygon(x, n, &ring[..sides], reach, out);
    }
    if !cone && top_beyond > 0.0 {
        blocked_by_polygon(x, n, &ring[sides..], reach, out);
    }
    BoxBlocks::Faces
}
