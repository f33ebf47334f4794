//! What a random scene is, as the generator describes it: a tree of VRML grouping nodes,
//! shapes and lights, a camera and the headlight. The VRML writer (`vrml.rs`) prints it for
//! the library; the reference (`world.rs`, `reference.rs`) works from this description, not
//! from the library's IR, so a lowering defect shows up as a difference too.

use glam::DVec3;

pub type Rgb = [f64; 3];

/// A gas sphere's density profile (docs/model.md section 6).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Profile {
    Constant,
    Linear,
    Quadratic,
    /// Width s in (0, 1].
    Gaussian(f64),
}

impl Profile {
    /// f(u), u = distance from the centre over the radius, in [0, 1].
    pub fn f(self, u: f64) -> f64 {
        match self {
            Profile::Constant => 1.0,
            Profile::Linear => 1.0 - u,
            Profile::Quadratic => 1.0 - u * u,
            Profile::Gaussian(s) => (-u * u / (2.0 * s * s)).exp(),
        }
    }

    /// I_f = integral of f over [0, 1], by quadrature (the reference does not take the
    /// table's closed forms on trust: the gaussian's needs erf).
    pub fn mean(self) -> f64 {
        super::quad::scalar(|u| self.f(u), 0.0, 1.0, 1e-15)
    }

    /// The name the `GasParticle` PROTO takes.
    pub fn name(self) -> &'static str {
        match self {
            Profile::Constant => "constant",
            Profile::Linear => "linear",
            Profile::Quadratic => "quadratic",
            Profile::Gaussian(_) => "gaussian",
        }
    }
}

/// A VRML97 Material with every field; `profile` is given through a `GasParticle` instance
/// (which sets only diffuse, emissive and transparency, so a profiled material keeps VRML's
/// defaults for the rest).
#[derive(Clone, Copy, Debug)]
pub struct Material {
    pub diffuse: Rgb,
    pub emissive: Rgb,
    pub specular: Rgb,
    pub shininess: f64,
    pub ambient: f64,
    pub transparency: f64,
    pub profile: Profile,
}

/// Geometry in the shape's own coordinates (VRML's definitions).
#[derive(Clone, Copy, Debug)]
pub enum Geometry {
    Sphere {
        r: f64,
    },
    Box {
        size: DVec3,
    },
    Cylinder {
        r: f64,
        h: f64,
    },
    Cone {
        r: f64,
        h: f64,
    },
    /// One IndexedFaceSet triangle, `solid FALSE` (seen from both sides).
    Triangle {
        p: [DVec3; 3],
    },
}

#[derive(Clone, Copy, Debug)]
pub struct PointLight {
    pub on: bool,
    pub location: DVec3,
    pub color: Rgb,
    pub intensity: f64,
    pub ambient: f64,
    pub attenuation: DVec3,
    pub radius: f64,
}

#[derive(Clone, Copy, Debug)]
pub struct DirectionalLight {
    pub on: bool,
    pub direction: DVec3,
    pub color: Rgb,
    pub intensity: f64,
    pub ambient: f64,
}

/// A Transform's fields: translation, rotation (unit axis, angle), uniform scale.
#[derive(Clone, Copy, Debug)]
pub struct Xf {
    pub translation: DVec3,
    pub axis: DVec3,
    pub angle: f64,
    pub scale: f64,
}

#[derive(Clone, Debug)]
pub enum Node {
    /// `material: None` is a Shape without Appearance: unlit white.
    Shape {
        geometry: Geometry,
        material: Option<Material>,
    },
    Point(PointLight),
    Directional(DirectionalLight),
    /// A `Transform` (with `Some`) or a `Group`.
    Group {
        xf: Option<Xf>,
        children: Vec<Node>,
    },
}

/// The first Viewpoint: position, orientation (unit axis, angle), fieldOfView; `ortho` is
/// the world height of the smaller image side when the render is orthographic.
#[derive(Clone, Copy, Debug)]
pub struct Viewpoint {
    pub position: DVec3,
    pub axis: DVec3,
    pub angle: f64,
    pub fov: f64,
    pub ortho: Option<f64>,
}

#[derive(Clone, Debug)]
pub struct SceneDesc {
    pub seed: u64,
    pub nodes: Vec<Node>,
    pub viewpoint: Viewpoint,
    pub headlight: bool,
    pub background: Rgb,
    pub width: u32,
    pub height: u32,
}
