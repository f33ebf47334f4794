//! A [`SceneDesc`] flattened to world space for the reference: every primitive with its
//! world geometry and material, every light with the primitives it lights (VRML scoping of
//! DirectionalLight: the siblings of its grouping node and their descendants), and the
//! camera's rays through pixel centres, written from the Viewpoint's definition.

use glam::{DAffine3, DQuat, DVec3};

use super::scenes::{
    DirectionalLight, Geometry, Material, Node, PointLight, Profile, Rgb, SceneDesc,
};
use crate::surface_reference::RefShape;

/// A primitive in world space.
#[derive(Clone, Copy, Debug)]
pub enum Solid {
    Sphere {
        c: DVec3,
        r: f64,
    },
    /// A Box, Cylinder or Cone in its object space with its object-to-world map, or a
    /// triangle in world space (identity map).
    Surface {
        shape: RefShape,
        to_world: DAffine3,
    },
}

#[derive(Clone, Copy, Debug)]
pub struct Prim {
    pub solid: Solid,
    /// `None`: unlit white.
    pub material: Option<Material>,
    /// The gas this primitive is, if it is.
    gas: Option<Gas>,
}

impl Prim {
    fn new(solid: Solid, material: Option<Material>) -> Prim {
        let mut p = Prim {
            solid,
            material,
            gas: None,
        };
        p.gas = p.make_gas();
        p
    }

    /// Gas: a sphere whose transparency is above 0.
    pub fn gas(&self) -> Option<Gas> {
        self.gas
    }

    fn make_gas(&self) -> Option<Gas> {
        match (self.solid, self.material) {
            (Solid::Sphere { c, r }, Some(m)) if m.transparency > 0.0 => {
                let sigma0 = -m.transparency.ln() / (2.0 * r * m.profile.mean());
                Some(Gas { c, r, sigma0, m })
            }
            _ => None,
        }
    }
}

/// A gas sphere: centre, radius, extinction at the centre and its material.
#[derive(Clone, Copy, Debug)]
pub struct Gas {
    pub c: DVec3,
    pub r: f64,
    pub sigma0: f64,
    pub m: Material,
}

impl Gas {
    /// The line `x + s l` (`l` unit) as this sphere sees it, for [`Gas::sigma_on`].
    pub fn line(&self, x: DVec3, l: DVec3) -> Line {
        let sc = (self.c - x).dot(l);
        let d2 = (x + sc * l - self.c).length_squared();
        Line { sc, d2 }
    }

    /// Extinction at parameter `s` of `line`. Written in `r^2 - |x - c|^2 = (r^2 - d^2) -
    /// (s - sc)^2`, so that it is a smooth function of `s` without cancellation near the rim
    /// (a quadrature of a density evaluated point by point sees rounding noise there).
    pub fn sigma_on(&self, line: &Line, s: f64) -> f64 {
        let v = s - line.sc;
        let r2 = self.r * self.r;
        let rem = (r2 - line.d2) - v * v;
        if rem <= 0.0 {
            return 0.0;
        }
        let e = rem / r2; // 1 - u^2
        let f = match self.m.profile {
            Profile::Constant => 1.0,
            Profile::Linear => e / (1.0 + (1.0 - e).max(0.0).sqrt()),
            Profile::Quadratic => e,
            Profile::Gaussian(w) => (-(line.d2 + v * v) / r2 / (2.0 * w * w)).exp(),
        };
        self.sigma0 * f
    }
}

/// A line's closest approach to a sphere's centre: parameter `sc` and squared distance `d2`.
#[derive(Clone, Copy, Debug)]
pub struct Line {
    pub sc: f64,
    pub d2: f64,
}

/// A light in world space.
#[derive(Clone, Copy, Debug)]
pub enum LightKind {
    Point(PointLight),
    /// `direction` is the unit direction the light travels.
    Directional(DirectionalLight),
    /// The headlight, along the camera's forward axis.
    Head,
}

#[derive(Clone, Debug)]
pub struct Light {
    pub kind: LightKind,
    /// `scope[k]`: whether this light lights primitive k.
    pub scope: Vec<bool>,
}

/// The camera, from the Viewpoint: position, frame, lens.
#[derive(Clone, Copy, Debug)]
pub struct Eye {
    pub position: DVec3,
    pub right: DVec3,
    pub up: DVec3,
    pub forward: DVec3,
    /// Half the extent of the image's smaller side: tan(fov/2) (perspective) or world units.
    pub half: f64,
    pub ortho: bool,
    pub width: u32,
    pub height: u32,
}

impl Eye {
    /// The ray through the centre of pixel (i, j), row 0 at the top: origin and unit
    /// direction. Perspective rays start at the eye; orthographic ones on the plane through
    /// it, perpendicular to the view axis.
    pub fn ray(&self, i: u32, j: u32) -> (DVec3, DVec3) {
        let (w, h) = (f64::from(self.width), f64::from(self.height));
        let m = w.min(h);
        let x = (2.0 * (f64::from(i) + 0.5) / w - 1.0) * self.half * w / m;
        let y = (1.0 - 2.0 * (f64::from(j) + 0.5) / h) * self.half * h / m;
        if self.ortho {
            (self.position + x * self.right + y * self.up, self.forward)
        } else {
            (
                self.position,
                (self.forward + x * self.right + y * self.up).normalize(),
            )
        }
    }
}

pub struct World {
    pub prims: Vec<Prim>,
    pub lights: Vec<Light>,
    pub eye: Eye,
    pub background: Rgb,
    /// Whether the headlight is carried by the viewer (no shadows; in gas the camera ray's
    /// transmittance) or a strict DirectionalLight along the view axis.
    pub head_viewer_carried: bool,
}

fn xf_affine(xf: &super::scenes::Xf) -> DAffine3 {
    DAffine3::from_translation(xf.translation)
        * DAffine3::from_axis_angle(xf.axis.normalize(), xf.angle)
        * DAffine3::from_scale(DVec3::splat(xf.scale))
}

/// Walks `nodes` under `m`: pushes primitives, and lights with the range of primitives their
/// scope covers (patched into `scope` once every primitive is known).
fn walk(
    nodes: &[Node],
    m: DAffine3,
    prims: &mut Vec<Prim>,
    lights: &mut Vec<(LightKind, Option<(usize, usize)>)>,
) {
    let first = prims.len();
    let mut scoped = Vec::new();
    for n in nodes {
        match n {
            Node::Shape { geometry, material } => {
                let solid = match *geometry {
                    Geometry::Sphere { r } => Solid::Sphere {
                        c: m.transform_point3(DVec3::ZERO),
                        r: r * m.matrix3.x_axis.length(),
                    },
                    Geometry::Box { size } => Solid::Surface {
                        shape: RefShape::Cuboid { size },
                        to_world: m,
                    },
                    Geometry::Cylinder { r, h } => Solid::Surface {
                        shape: RefShape::Cylinder { r, h },
                        to_world: m,
                    },
                    Geometry::Cone { r, h } => Solid::Surface {
                        shape: RefShape::Cone { r, h },
                        to_world: m,
                    },
                    Geometry::Triangle { p } => Solid::Surface {
                        shape: RefShape::Triangle {
                            p: p.map(|q| m.transform_point3(q)),
                        },
                        to_world: DAffine3::IDENTITY,
                    },
                };
                prims.push(Prim::new(solid, *material));
            }
            Node::Point(l) => {
                let mut l = *l;
                l.location = m.transform_point3(l.location);
                lights.push((LightKind::Point(l), None));
            }
            Node::Directional(l) => {
                let mut l = *l;
                l.direction = m.transform_vector3(l.direction).normalize();
                scoped.push(lights.len());
                lights.push((LightKind::Directional(l), None));
            }
            Node::Group { xf, children } => {
                let inner = xf.as_ref().map_or(m, |x| m * xf_affine(x));
                walk(children, inner, prims, lights);
            }
        }
    }
    for k in scoped {
        lights[k].1 = Some((first, prims.len()));
    }
}

impl World {
    pub fn new(s: &SceneDesc, head_viewer_carried: bool) -> World {
        let mut prims = Vec::new();
        let mut raw = Vec::new();
        walk(&s.nodes, DAffine3::IDENTITY, &mut prims, &mut raw);
        let n = prims.len();
        let mut lights: Vec<Light> = raw
            .into_iter()
            .map(|(kind, range)| Light {
                kind,
                scope: (0..n)
                    .map(|k| range.is_none_or(|(a, b)| k >= a && k < b))
                    .collect(),
            })
            .collect();
        if s.headlight {
            lights.push(Light {
                kind: LightKind::Head,
                scope: vec![true; n],
            });
        }
        let v = &s.viewpoint;
        let q = DQuat::from_axis_angle(v.axis.normalize(), v.angle);
        let eye = Eye {
            position: v.position,
            right: q * DVec3::X,
            up: q * DVec3::Y,
            forward: q * DVec3::NEG_Z,
            half: v.ortho.map_or((v.fov / 2.0).tan(), |h| h / 2.0),
            ortho: v.ortho.is_some(),
            width: s.width,
            height: s.height,
        };
        World {
            prims,
            lights,
            eye,
            background: s.background,
            head_viewer_carried,
        }
    }
}
