//! The opaque surfaces other than spheres, ready to trace: a second [`SphereBvh`] over their
//! bounding balls (each primitive's `sphere` is the surface's index), whose closures do the
//! exact f64 test of the surface itself (`geom::shapes`). Two structures rather than one:
//! a scene of spheres only then pays nothing but one emptiness test per query, and the
//! sphere BVH's hot loop keeps its one kind of primitive.
//!
//! Visibility rules (docs/model.md section 2): Box, Cylinder and Cone are solid (seen from
//! inside, culled); a triangle is seen from both sides unless its IndexedFaceSet is `solid`.
//! Any crossing of a surface, from either side, blocks a light ray.

use glam::{DAffine3, DMat3, DVec3};

use crate::accel::{Prim, SphereBvh};
use crate::geom::shapes::{shadow_breaks, shadowed, triangle_hit, ShadowLight, Shape, Solid};
use crate::scene::{Paint, Surface, SurfaceShape, Triangle};

use super::copies::{hash, LastSeen};
use super::lights::LightKind;

/// A surface as the renderer sees it.
#[derive(Clone, Debug)]
pub enum Traced {
    /// A Box, Cylinder or Cone, traced in its object space.
    Solid {
        /// The primitive, in its object space.
        solid: Solid,
        /// The map from the world to its object space.
        to_object: DAffine3,
        /// Object-space normals to world-space ones: the inverse transpose of the surface's
        /// map from object space to the world.
        normal_to_world: DMat3,
    },
    /// A triangle, in world space.
    Triangle(Triangle),
}

impl Traced {
    fn of(shape: SurfaceShape) -> Traced {
        match shape {
            SurfaceShape::Solid { solid, to_world } => Traced::Solid {
                solid,
                to_object: to_world.inverse(),
                normal_to_world: to_world.matrix3.inverse().transpose(),
            },
            SurfaceShape::Triangle(t) => Traced::Triangle(*t),
        }
    }
}

/// Per surface, whether it is not a copy of the surface last seen in its hash slot (the same
/// shape, colour and material; see `render::copies`), from the balls bounding them.
fn first_copies(surfaces: &[Surface], balls: &[(DVec3, f64)]) -> Vec<bool> {
    let mut seen = LastSeen::new();
    let same = |&a: &usize, &b: &usize| {
        let (a, b) = (&surfaces[a], &surfaces[b]);
        a.shape == b.shape && a.color == b.color && a.material == b.material
    };
    (surfaces.iter().zip(balls).enumerate())
        .map(|(i, (s, &(c, r)))| {
            let key = [c.x, c.y, c.z, r].map(f64::to_bits);
            let h = hash(
                key.into_iter()
                    .chain([s.color.to_bits(), u64::from(s.material)]),
            );
            !seen.copy(h, i, same)
        })
        .collect()
}

/// The surfaces of a scene and their BVH.
pub struct Surfaces {
    /// A BVH over balls bounding the items (copies of an earlier item left out), each [`Prim`]'s
    /// `sphere` the item's index.
    pub bvh: SphereBvh,
    /// The surfaces, in the scene's order.
    pub items: Vec<Traced>,
    /// What each item refers to in `Scene::materials`.
    pub paints: Vec<Paint>,
    /// The median radius of the balls bounding the items in the BVH (0 without any): the
    /// near distance of ambient occlusion in a scene without spheres.
    pub typical_radius: f64,
}

impl Surfaces {
    /// The surfaces made ready to trace; a copy of an earlier surface (same shape, colour and
    /// material) keeps its index but stays out of the BVH.
    pub fn build(surfaces: Vec<Surface>) -> Surfaces {
        let balls: Vec<(DVec3, f64)> = surfaces.iter().map(Surface::bounding_ball).collect();
        let first = first_copies(&surfaces, &balls);
        let mut items = Vec::with_capacity(surfaces.len());
        let mut paints = Vec::with_capacity(surfaces.len());
        let mut prims = Vec::with_capacity(surfaces.len());
        for (i, (s, (center, radius))) in surfaces.into_iter().zip(balls).enumerate() {
            // A copy keeps its index (and id) but is left out of the BVH.
            if !first[i] {
                paints.push(s.paint());
                items.push(Traced::of(s.shape));
                continue;
            }
            prims.push(Prim {
                center,
                // Never zero: a degenerate triangle still needs a box.
                radius: radius.max(f64::MIN_POSITIVE) * (1.0 + 1e-12),
                color: s.color,
                material: s.material,
                sphere: i as u32,
                ellipsoid: None,
                gas: false,
                sigma: 0.0,
                profile: crate::scene::Profile::Constant,
            });
            paints.push(s.paint());
            items.push(Traced::of(s.shape));
        }
        let typical_radius = super::sampled_median(prims.iter().map(|p| p.radius));
        Surfaces {
            bvh: SphereBvh::build(prims, &[]),
            items,
            paints,
            typical_radius,
        }
    }

    /// Whether there are no surfaces.
    pub fn is_empty(&self) -> bool {
        self.items.is_empty()
    }

    /// The first surface seen along `o + t d` in `(tmin, tmax)`: its parameter and index.
    #[inline]
    pub fn closest(&self, o: DVec3, d: DVec3, tmin: f64, tmax: f64) -> Option<(f64, u32)> {
        if self.is_empty() {
            return None;
        }
        self.bvh
            .closest(o, d, tmin, tmax, |_, p, _| {
                self.items[p.sphere as usize].seen_at(o, d, tmin, tmax)
            })
            .map(|h| (h.t, self.bvh.prim(h.prim).sphere))
    }

    /// Whether a surface other than `own` crosses `o + t d` for `t` in `(tmin, tmax)`.
    #[inline]
    pub fn blocks(&self, o: DVec3, d: DVec3, tmin: f64, tmax: f64, own: Option<u32>) -> bool {
        if self.is_empty() {
            return false;
        }
        self.bvh.any(o, d, tmin, tmax, |_, p, _| {
            Some(p.sphere) != own && self.items[p.sphere as usize].crosses(o, d, tmin, tmax)
        })
    }

    /// The unit shading normal of surface `i` at `o + t d` (a hit found by
    /// [`Surfaces::closest`]), on the side the ray came from.
    pub fn shading_normal(&self, i: u32, o: DVec3, d: DVec3, t: f64) -> DVec3 {
        match &self.items[i as usize] {
            Traced::Solid {
                solid,
                to_object,
                normal_to_world,
            } => {
                let (oo, dd) = (
                    to_object.transform_point3(o),
                    to_object.transform_vector3(d),
                );
                // The crossing nearest to t (the one that was hit).
                let mut out = [crate::geom::shapes::Crossing {
                    t: 0.0,
                    normal: DVec3::Y,
                }; 4];
                let n = solid.crossings(oo, dd, f64::NEG_INFINITY, f64::INFINITY, &mut out);
                let c = out[..n]
                    .iter()
                    .min_by(|a, b| (a.t - t).abs().total_cmp(&(b.t - t).abs()))
                    .copied()
                    .unwrap_or(out[0]);
                let g = (*normal_to_world * c.normal).normalize_or_zero();
                if g.dot(d) > 0.0 {
                    -g
                } else {
                    g
                }
            }
            Traced::Triangle(tri) => {
                let (b1, b2) = barycentric(&tri.p, o + t * d);
                let g = tri.face_normal().normalize_or_zero();
                let mut s = match tri.n {
                    Some(n) => ((1.0 - b1 - b2) * n[0] + b1 * n[1] + b2 * n[2]).normalize_or_zero(),
                    None => g,
                };
                if s == DVec3::ZERO || s.dot(g) < 0.0 {
                    // A shading normal on the other side than the face's own: the face's.
                    s = g;
                }
                // Seen from behind (not solid): the normal faces the viewer.
                if g.dot(d) > 0.0 {
                    -s
                } else {
                    s
                }
            }
        }
    }

    /// What shading needs of surface `i` at `x` beyond the shading normal `n` (seen from
    /// `v`): the unit geometric normal on the viewer's side, and the Color there, if any.
    /// A solid's geometric normal is `n`.
    #[inline]
    pub fn look(&self, i: u32, x: DVec3, v: DVec3, n: DVec3) -> (DVec3, Option<DVec3>) {
        match &self.items[i as usize] {
            Traced::Solid { .. } => (n, None),
            Traced::Triangle(tri) => {
                let g = tri.face_normal().normalize_or_zero();
                let g = if g.dot(v) < 0.0 { -g } else { g };
                let color = tri.color.map(|c| {
                    let (b1, b2) = barycentric(&tri.p, x);
                    (1.0 - b1 - b2) * c[0] + b1 * c[1] + b2 * c[2]
                });
                (g, color)
            }
        }
    }

    /// The parts of `[ta, tb]` of `o + t d` where some surface blocks `light` (merged, sorted,
    /// appended to `out`): exact up to rounding, from each candidate surface's own shadow
    /// breakpoints and a test between consecutive ones. `candidates` are the surfaces that
    /// may shadow the segment (a superset).
    #[allow(clippy::too_many_arguments)]
    pub fn shadowed_parts(
        &self,
        candidates: &[u32],
        o: DVec3,
        d: DVec3,
        light: &LightKind,
        (ta, tb): (f64, f64),
        breaks: &mut Vec<f64>,
        out: &mut Vec<(f64, f64)>,
    ) {
        let start = out.len();
        for &i in candidates {
            breaks.clear();
            let item = &self.items[i as usize];
            let (oo, dd, l) = in_object_space(item, o, d, light);
            let shape = shape_of(item);
            shadow_breaks(&shape, oo, dd, &l, (ta, tb), breaks);
            breaks.retain(|t| *t > ta && *t < tb);
            breaks.push(ta);
            breaks.push(tb);
            breaks.sort_unstable_by(f64::total_cmp);
            breaks.dedup();
            for w in breaks.windows(2) {
                let (t0, t1) = (w[0], w[1]);
                if t1 <= t0 {
                    continue;
                }
                if shadowed(&shape, oo + (0.5 * (t0 + t1)) * dd, &l) {
                    match out[start..].last_mut() {
                        Some(last) if last.1 == t0 => last.1 = t1,
                        _ => out.push((t0, t1)),
                    }
                }
            }
        }
        // Merge the surfaces' intervals.
        out[start..].sort_unstable_by(|a, b| a.0.total_cmp(&b.0));
        let mut w = start;
        for r in start..out.len() {
            let iv = out[r];
            if w > start && iv.0 <= out[w - 1].1 {
                out[w - 1].1 = out[w - 1].1.max(iv.1);
            } else {
                out[w] = iv;
                w += 1;
            }
        }
        out.truncate(w);
    }
}

/// Barycentric weights of corners 1 and 2 of the triangle `p` at the point `x` of its plane.
#[inline]
fn barycentric(p: &[DVec3; 3], x: DVec3) -> (f64, f64) {
    let (e1, e2) = (p[1] - p[0], p[2] - p[0]);
    let n = e1.cross(e2);
    let nn = n.length_squared();
    if nn == 0.0 {
        return (1.0 / 3.0, 1.0 / 3.0);
    }
    let q = x - p[0];
    (q.cross(e2).dot(n) / nn, e1.cross(q).dot(n) / nn)
}

fn shape_of(item: &Traced) -> Shape<'_> {
    match item {
        Traced::Solid { solid, .. } => Shape::Solid(solid),
        Traced::Triangle(t) => Shape::Triangle(&t.p),
    }
}

/// The camera ray and the light in the item's own space (object space for a solid).
fn in_object_space(
    item: &Traced,
    o: DVec3,
    d: DVec3,
    light: &LightKind,
) -> (DVec3, DVec3, ShadowLight) {
    let world = |l: &LightKind| match *l {
        LightKind::Directional { to_light, .. } => ShadowLight::Directional { to_light },
        LightKind::Point { position, .. } => ShadowLight::Point { position },
    };
    match item {
        Traced::Solid { to_object, .. } => (
            to_object.transform_point3(o),
            to_object.transform_vector3(d),
            match *light {
                LightKind::Directional { to_light, .. } => ShadowLight::Directional {
                    to_light: to_object.transform_vector3(to_light),
                },
                LightKind::Point { position, .. } => ShadowLight::Point {
                    position: to_object.transform_point3(position),
                },
            },
        ),
        Traced::Triangle(_) => (o, d, world(light)),
    }
}

impl Traced {
    /// Where a camera ray sees it in `(tmin, tmax)` (culling back faces of solid ones).
    #[inline]
    pub fn seen_at(&self, o: DVec3, d: DVec3, tmin: f64, tmax: f64) -> Option<f64> {
        match self {
            Traced::Solid {
                solid, to_object, ..
            } => solid
                .first_crossing(
                    to_object.transform_point3(o),
                    to_object.transform_vector3(d),
                    tmin,
                    tmax,
                    true,
                )
                .map(|c| c.t),
            Traced::Triangle(tri) => {
                let h = triangle_hit(&tri.p, o, d, tmin, tmax)?;
                (!tri.solid || tri.face_normal().dot(d) < 0.0).then_some(h.t)
            }
        }
    }

    /// Whether it crosses `o + t d` for `t` in `(tmin, tmax)`, from either side.
    #[inline]
    pub fn crosses(&self, o: DVec3, d: DVec3, tmin: f64, tmax: f64) -> bool {
        match self {
            Traced::Solid {
                solid, to_object, ..
            } => solid.blocks(
                to_object.transform_point3(o),
                to_object.transform_vector3(d),
                tmin,
                tmax,
            ),
            Traced::Triangle(tri) => triangle_hit(&tri.p, o, d, tmin, tmax).is_some(),
        }
    }
}

#[cfg(test)]
mod tests {
    /// 50 000 copies of one triangle (same shape, colour and material) in front of a sphere:
    /// one primitive in the surfaces' BVH, every copy keeping its index.
    #[test]
    fn copies_of_a_triangle_are_traced_once() {
        let scene = crate::testing::triangles(50_000);
        let prep = crate::testing::prepare(scene);
        assert_eq!(prep.surfaces.bvh.len(), 1);
    }
}
