//! Opaque surfaces other than spheres (docs/model.md section 2): VRML97 Box, Cylinder and Cone,
//! exact in their own object space under an affine map, and the triangles of
//! IndexedFaceSets, exactly as the file gives them. They take the lighting equation with the
//! same lights and scopes as spheres; they are never gas.

use glam::{DAffine3, DMat3, DVec3};

use super::Origin;
use crate::geom::shapes::Solid;

/// An opaque surface in world space.
#[derive(Clone, Debug, PartialEq)]
pub struct Surface {
    /// Its geometry, in world space or with the map there.
    pub shape: SurfaceShape,
    /// Its diffuse colour (a triangle's corner colours replace it where it has them).
    pub color: super::Color,
    /// Index of its material's record in `Scene::materials`.
    pub material: u32,
    /// Where in the input it was defined.
    pub origin: Origin,
}

/// The geometry of a [`Surface`].
#[derive(Clone, Debug, PartialEq)]
pub enum SurfaceShape {
    /// A Box, Cylinder or Cone in its VRML object space, and the map from there to the
    /// world (an invertible affine map: rays are intersected in object space, where they keep
    /// their parameters).
    Solid {
        /// The primitive, in its object space.
        solid: Solid,
        /// The map from its object space to the world.
        to_world: DAffine3,
    },
    /// One triangle of an IndexedFaceSet (boxed: most scenes have none, and a Surface stays
    /// small for the solids).
    Triangle(Box<Triangle>),
}

/// A triangle in world space. Its front is the side from which `p[0], p[1], p[2]` run
/// counter-clockwise (the lowering applies `ccw` and mirroring Transforms by reordering).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Triangle {
    /// Its corners, in world space.
    pub p: [DVec3; 3],
    /// Unit shading normals at the corners (the front side's), interpolated across the face;
    /// `None`: flat, the geometric normal.
    pub n: Option<[DVec3; 3]>,
    /// Colours at the corners (a `Color` node: replaces the Material's diffuseColor, or is the
    /// colour itself without a Material); `None`: the Material's.
    pub color: Option<[DVec3; 3]>,
    /// VRML `solid`: seen from behind, the triangle is culled (it still casts shadows).
    pub solid: bool,
}

/// An affine map (world from local) as surfaces take it: with its normal matrix (the inverse
/// transpose) and whether it mirrors, worked out once for all the surfaces it moves.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Mapping {
    /// The map from local coordinates to the world.
    pub map: DAffine3,
    /// The inverse transpose of `map`'s linear part, which maps normals (not normalised).
    pub normals: DMat3,
    /// Whether `map` mirrors (its linear part has a negative determinant).
    pub mirrors: bool,
}

impl Mapping {
    /// The mapping of `map`; `map` must be invertible for `normals` to be finite.
    pub fn new(map: &DAffine3) -> Mapping {
        Mapping {
            map: *map,
            normals: map.matrix3.inverse().transpose(),
            mirrors: map.matrix3.determinant() < 0.0,
        }
    }
}

impl Triangle {
    /// Applies `m`: points moved, normals by the inverse transpose, and the corners
    /// reordered under a mirroring map so that the front stays the front.
    pub(crate) fn transform(&mut self, m: &Mapping) {
        for p in &mut self.p {
            *p = m.map.transform_point3(*p);
        }
        if let Some(n) = &mut self.n {
            for v in n.iter_mut() {
                *v = (m.normals * *v).normalize_or_zero();
            }
        }
        if m.mirrors {
            self.p.swap(1, 2);
            if let Some(n) = &mut self.n {
                n.swap(1, 2);
            }
            if let Some(c) = &mut self.color {
                c.swap(1, 2);
            }
        }
    }

    /// The unnormalised geometric normal (front side).
    #[inline]
    pub fn face_normal(&self) -> DVec3 {
        (self.p[1] - self.p[0]).cross(self.p[2] - self.p[0])
    }
}

impl Surface {
    /// What it refers to in `Scene::materials`.
    #[inline]
    pub fn paint(&self) -> super::Paint {
        super::Paint {
            material: self.material,
            color: self.color,
        }
    }

    /// World-space bounding box (conservative for the solids: the box of their object box's
    /// corners).
    pub fn bounds(&self) -> (DVec3, DVec3) {
        match &self.shape {
            SurfaceShape::Solid { solid, to_world } => {
                let (a, b) = solid.bounds();
                let (mut lo, mut hi) = (DVec3::INFINITY, DVec3::NEG_INFINITY);
                for k in 0..8 {
                    let c = DVec3::new(
                        if k & 1 == 0 { a.x } else { b.x },
                        if k & 2 == 0 { a.y } else { b.y },
                        if k & 4 == 0 { a.z } else { b.z },
                    );
                    let w = to_world.transform_point3(c);
                    lo = lo.min(w);
                    hi = hi.max(w);
                }
                (lo, hi)
            }
            SurfaceShape::Triangle(t) => (
                t.p[0].min(t.p[1]).min(t.p[2]),
                t.p[0].max(t.p[1]).max(t.p[2]),
            ),
        }
    }

    /// A ball holding the surface: the centre of its bounds and their half diagonal.
    pub fn bounding_ball(&self) -> (DVec3, f64) {
        let (lo, hi) = self.bounds();
        (0.5 * lo + 0.5 * hi, 0.5 * (hi - lo).length())
    }

    /// Applies `m` to the surface.
    pub(crate) fn transform(&mut self, m: &Mapping) {
        match &mut self.shape {
            SurfaceShape::Solid { to_world, .. } => *to_world = m.map * *to_world,
            SurfaceShape::Triangle(t) => t.transform(m),
        }
    }

    /// Whether every coordinate is finite and a solid's map invertible (after Transforms).
    pub fn is_sound(&self) -> bool {
        match &self.shape {
            SurfaceShape::Solid { to_world, .. } => {
                let det = to_world.matrix3.determinant();
                to_world.is_finite() && det != 0.0 && det.is_finite()
            }
            SurfaceShape::Triangle(t) => t.p.iter().all(|p| p.is_finite()),
        }
    }
}

/// How many surfaces of each kind (for `info`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize)]
pub struct SurfaceCounts {
    /// VRML Boxes.
    pub boxes: usize,
    /// VRML Cylinders.
    pub cylinders: usize,
    /// VRML Cones.
    pub cones: usize,
    /// Triangles of IndexedFaceSets.
    pub triangles: usize,
}

impl SurfaceCounts {
    /// Counts the surfaces of `surfaces` by kind.
    pub fn of(surfaces: &[Surface]) -> SurfaceCounts {
        let mut c = SurfaceCounts::default();
        for s in surfaces {
            match &s.shape {
                SurfaceShape::Solid { solid, .. } => match solid {
                    Solid::Cuboid { .. } => c.boxes += 1,
                    Solid::Cylinder { .. } => c.cylinders += 1,
                    Solid::Cone { .. } => c.cones += 1,
                },
                SurfaceShape::Triangle(_) => c.triangles += 1,
            }
        }
        c
    }
}
