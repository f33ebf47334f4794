//! Cameras: VRML Viewpoints (perspective), the framing camera used when a scene has no
//! Viewpoint, and an orthographic camera.
//!
//! Image-plane coordinates: `(u, v)` in `[0,1]^2`, `u` to the right, `v` downwards (row 0 at
//! the top); pixel `(i, j)`'s centre is `((i + 0.5) / W, (j + 0.5) / H)`.

use std::f64::consts::FRAC_PI_4;

use glam::{DQuat, DVec3};

use crate::scene::Scene;

/// Which camera to use, as the user asked.
#[derive(Clone, Debug, Default, PartialEq)]
pub enum CameraChoice {
    /// The first Viewpoint in file order; without one, a camera looking down -z placed to
    /// frame the scene's bounds.
    #[default]
    Auto,
    /// A Viewpoint by DEF name or description.
    Named(String),
    /// VRML's fixed default: (0,0,10) looking down -z, fieldOfView pi/4.
    VrmlDefault,
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Projection {
    /// Perspective; the Viewpoint's `fieldOfView` is the angle of the smaller image side.
    Perspective,
    /// Orthographic; `height` = world size of the smaller image side (None: fit the scene).
    Ortho { height: Option<f64> },
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Camera {
    pub position: DVec3,
    pub right: DVec3,
    pub up: DVec3,
    pub forward: DVec3,
    /// Half extents of the image plane: tangents of the half angles (perspective) or world
    /// half sizes (orthographic).
    pub half_w: f64,
    pub half_h: f64,
    pub ortho: bool,
}

/// What the camera is and where it came from, for `info`/`render` to say.
#[derive(Clone, Debug, PartialEq)]
pub struct CameraSetup {
    pub camera: Camera,
    pub description: String,
}

/// Half sizes `(w, h)` of the image plane for the smaller side spanning `2 * s`.
fn halves(s: f64, width: u32, height: u32) -> (f64, f64) {
    let aspect = f64::from(width) / f64::from(height);
    if width >= height {
        (s * aspect, s)
    } else {
        (s, s / aspect)
    }
}

/// Sets up the camera for `scene` at `width x height`, or says why it cannot.
pub fn setup(
    scene: &Scene,
    choice: &CameraChoice,
    projection: Projection,
    width: u32,
    height: u32,
) -> Result<CameraSetup, String> {
    let named = |vp: &crate::scene::Viewpoint| match &vp.name {
        Some(n) => format!("Viewpoint {n}"),
        None if !vp.description.is_empty() => format!("Viewpoint \"{}\"", vp.description),
        None => "the first Viewpoint".to_string(),
    };
    let (position, orientation, fov, description) = match choice {
        CameraChoice::Named(want) => {
            let vp = scene
                .viewpoints
                .iter()
                .find(|v| v.name.as_deref() == Some(want.as_str()))
                .or_else(|| scene.viewpoints.iter().find(|v| v.description == *want))
                .ok_or_else(|| {
                    let mut names: Vec<String> = scene
                        .viewpoints
                        .iter()
                        .map(|v| v.name.clone().unwrap_or_else(|| v.description.clone()))
                        .filter(|n| !n.is_empty())
                        .collect();
                    names.dedup();
                    if names.is_empty() {
                        format!("no Viewpoint named \"{want}\": the scene has no named Viewpoints")
                    } else {
                        format!(
                            "no Viewpoint named \"{want}\"; the scene has: {}",
                            names.join(", ")
                        )
                    }
                })?;
            (vp.position, vp.orientation, vp.field_of_view, named(vp))
        }
        CameraChoice::Auto if !scene.viewpoints.is_empty() => {
            let vp = &scene.viewpoints[0];
            (vp.position, vp.orientation, vp.field_of_view, named(vp))
        }
        CameraChoice::Auto => match scene.bounding_ball() {
            Some((c, r)) => (
                crate::scene::framing_position(c, r).ok_or_else(|| {
                    "no Viewpoint, and a camera framing the scene would stand beyond the \
                     range of f64: give the scene a Viewpoint"
                        .to_string()
                })?,
                DQuat::IDENTITY,
                crate::scene::FRAMING_FOV,
                "no Viewpoint in the scene: looking down -z, placed to frame the scene's bounds"
                    .to_string(),
            ),
            None => (
                DVec3::new(0.0, 0.0, 10.0),
                DQuat::IDENTITY,
                FRAC_PI_4,
                "no Viewpoint and no spheres: VRML's default camera at (0,0,10)".to_string(),
            ),
        },
        CameraChoice::VrmlDefault => (
            DVec3::new(0.0, 0.0, 10.0),
            DQuat::IDENTITY,
            FRAC_PI_4,
            "VRML's default camera at (0,0,10) looking down -z".to_string(),
        ),
    };
    let orientation = orientation.normalize();
    let right = orientation * DVec3::X;
    let up = orientation * DVec3::Y;
    let forward = orientation * DVec3::NEG_Z;
    let (half_w, half_h, ortho) = match projection {
        Projection::Perspective => {
            if !(fov > 0.0 && fov < std::f64::consts::PI) {
                return Err(format!(
                    "the camera's fieldOfView {fov} is not between 0 and pi"
                ));
            }
            let (w, h) = halves((0.5 * fov).tan(), width, height);
            (w, h, false)
        }
        Projection::Ortho { height: Some(hgt) } => {
            let (w, h) = halves(0.5 * hgt, width, height);
            (w, h, true)
        }
        Projection::Ortho { height: None } => {
            // Fit the scene box's corners as seen along the view axis.
            let (mut ew, mut eh) = (0.0f64, 0.0f64);
            if let Some(b) = scene.bounds() {
                for k in 0..8 {
                    let p = DVec3::new(
                        if k & 1 == 0 { b.min[0] } else { b.max[0] },
                        if k & 2 == 0 { b.min[1] } else { b.max[1] },
                        if k & 4 == 0 { b.min[2] } else { b.max[2] },
                    ) - position;
                    ew = ew.max(p.dot(right).abs());
                    eh = eh.max(p.dot(up).abs());
                }
            }
            let aspect = f64::from(width) / f64::from(height);
            // Smallest half height showing both extents, with a 2 % margin.
            let half_h = eh.max(ew / aspect).max(f64::MIN_POSITIVE) * 1.02;
            (half_h * aspect, half_h, true)
        }
    };
    Ok(CameraSetup {
        camera: Camera {
            position,
            right,
            up,
            forward,
            half_w,
            half_h,
            ortho,
        },
        description: if ortho {
            format!("{description} (orthographic)")
        } else {
            description
        },
    })
}

impl Camera {
    /// The ray through image-plane point `(u, v)`: origin and unit direction.
    #[inline]
    pub fn ray(&self, u: f64, v: f64) -> (DVec3, DVec3) {
        let x = (2.0 * u - 1.0) * self.half_w;
        let y = (1.0 - 2.0 * v) * self.half_h;
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
