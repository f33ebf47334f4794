//! Pure f64 ray geometry for the opaque VRML97 primitives other than Sphere: Box, Cylinder and
//! Cone in their own object space (`quadrics.rs`, `cuboid.rs`), triangles (`triangle.rs`), and
//! the parameters along a camera ray where one primitive's shadow can begin or end
//! (`shadow.rs`).
//!
//! A ray is the line `o + t d` in object space. The caller maps world rays into object space
//! with an affine map, which keeps `t`, so `d` is any non-zero vector, not a unit one.
//! Nothing here allocates (`shadow_breaks` only pushes to the caller's `Vec`) or panics:
//! non-finite input, `d = 0` or a degenerate shape (a size of 0) give no crossings.

mod cuboid;
mod quadrics;
mod shadow;
mod triangle;

#[cfg(test)]
mod tests;

use glam::DVec3;

pub use shadow::{shadow_breaks, shadowed};
pub use triangle::triangle_hit;

/// An opaque VRML97 primitive in its object space (y up).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Solid {
    /// VRML Box: centred at the origin, half extents `half` (all > 0).
    Cuboid {
        /// Half its extent along x, y and z, each positive.
        half: DVec3,
    },
    /// VRML Cylinder: axis y, from y = -half_height to +half_height, radius `radius`; which
    /// parts exist (VRML fields bottom, side, top).
    Cylinder {
        /// Radius of the side and caps, positive.
        radius: f64,
        /// Half its height along y, positive.
        half_height: f64,
        /// Whether the bottom cap (at y = -half_height) exists.
        bottom: bool,
        /// Whether the curved side exists.
        side: bool,
        /// Whether the top cap (at y = +half_height) exists.
        top: bool,
    },
    /// VRML Cone: axis y, apex at y = +half_height, base disc of radius `radius` at
    /// y = -half_height; parts side, bottom.
    Cone {
        /// Radius of the base disc, positive.
        radius: f64,
        /// Half its height along y, positive.
        half_height: f64,
        /// Whether the slanted side exists.
        side: bool,
        /// Whether the base disc exists.
        bottom: bool,
    },
}

/// One crossing of the line o + t d with the surface: parameter and the OUTWARD object-space
/// normal there (unit length; for caps +-y, for faces +-axis).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Crossing {
    /// Its parameter on the line `o + t d`.
    pub t: f64,
    /// The outward unit normal there, in object space.
    pub normal: DVec3,
}

/// A triangle hit: the parameter and the barycentric weights of `p[1]` and `p[2]`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TriHit {
    /// Its parameter on the line `o + t d`.
    pub t: f64,
    /// Barycentric weight of `p[1]`.
    pub b1: f64,
    /// Barycentric weight of `p[2]`.
    pub b2: f64,
}

/// A light as seen from object space.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ShadowLight {
    /// A direction towards the light (not necessarily unit): the light ray from x is
    /// x + s w, s > 0.
    Directional {
        /// The direction `w` towards the light, non-zero.
        to_light: DVec3,
    },
    /// A point light at `position`: the light ray from x is x + s (position - x), s in (0, 1).
    Point {
        /// The light's position, in object space.
        position: DVec3,
    },
}

/// What casts a shadow: a solid, or one triangle of a mesh.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Shape<'a> {
    /// A VRML Box, Cylinder or Cone in its object space.
    Solid(&'a Solid),
    /// A triangle's three corners, in the same space as the ray.
    Triangle(&'a [DVec3; 3]),
}

impl Solid {
    /// Every crossing with t in the open interval (tmin, tmax), sorted by t, written to `out`;
    /// returns the count (at most 4: cylinder side 2 + two caps; cone side 2 + base;
    /// cuboid 2).
    ///
    /// A closed solid (every part present) is watertight: any line meets it in 0 or 2
    /// crossings over the whole line, an entry (`d . normal < 0`) and then an exit, also
    /// through rims, edges and the apex. A tangent line gives none.
    pub fn crossings(
        &self,
        o: DVec3,
        d: DVec3,
        tmin: f64,
        tmax: f64,
        out: &mut [Crossing; 4],
    ) -> usize {
        let mut sink = Sink {
            out,
            n: 0,
            tmin,
            tmax,
        };
        if o.is_finite() && d.is_finite() && d != DVec3::ZERO {
            match *self {
                Solid::Cuboid { half } => cuboid::crossings(half, o, d, &mut sink),
                Solid::Cylinder {
                    radius,
                    half_height,
                    bottom,
                    side,
                    top,
                } => quadrics::cylinder(radius, half_height, [bottom, side, top], o, d, &mut sink),
                Solid::Cone {
                    radius,
                    half_height,
                    side,
                    bottom,
                } => quadrics::cone(radius, half_height, side, bottom, o, d, &mut sink),
            }
        }
        sink.n
    }

    /// The first crossing in (tmin, tmax) where the surface faces the ray (d . normal < 0) if
    /// `front_only`, else the first crossing of any side.
    pub fn first_crossing(
        &self,
        o: DVec3,
        d: DVec3,
        tmin: f64,
        tmax: f64,
        front_only: bool,
    ) -> Option<Crossing> {
        let mut out = [NO_CROSSING; 4];
        let n = self.crossings(o, d, tmin, tmax, &mut out);
        out[..n]
            .iter()
            .find(|c| !front_only || d.dot(c.normal) < 0.0)
            .copied()
    }

    /// Whether the line crosses the surface anywhere in (tmin, tmax) (shadow rays).
    pub fn blocks(&self, o: DVec3, d: DVec3, tmin: f64, tmax: f64) -> bool {
        let mut out = [NO_CROSSING; 4];
        self.crossings(o, d, tmin, tmax, &mut out) > 0
    }

    /// Object-space bounding box (lo, hi).
    pub fn bounds(&self) -> (DVec3, DVec3) {
        let hi = match *self {
            Solid::Cuboid { half } => half,
            Solid::Cylinder {
                radius,
                half_height,
                ..
            }
            | Solid::Cone {
                radius,
                half_height,
                ..
            } => DVec3::new(radius, half_height, radius),
        };
        (-hi, hi)
    }
}

const NO_CROSSING: Crossing = Crossing {
    t: 0.0,
    normal: DVec3::ZERO,
};

/// Collects crossings in `(tmin, tmax)`, sorted by insertion.
struct Sink<'a> {
    out: &'a mut [Crossing; 4],
    n: usize,
    tmin: f64,
    tmax: f64,
}

impl Sink<'_> {
    /// Keeps `t` if it lies in `(tmin, tmax)`: never NaN or infinite (the comparisons are
    /// strict), so rejected roots can be passed as NaN.
    #[inline]
    fn push(&mut self, t: f64, normal: impl FnOnce(f64) -> DVec3) {
        if !(self.tmin < t && t < self.tmax) || self.n == self.out.len() {
            return;
        }
        let mut i = self.n;
        while i > 0 && self.out[i - 1].t > t {
            self.out[i] = self.out[i - 1];
            i -= 1;
        }
        self.out[i] = Crossing {
            t,
            normal: normal(t),
        };
        self.n += 1;
    }
}
