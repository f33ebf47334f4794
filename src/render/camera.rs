//! Cameras: a [`Camera`] is where the eye is, where it looks and its lens, independent of the
//! image size; [`Camera::image_plane`] turns it into the rays of a `width x height` picture.
//! Cameras come from a VRML Viewpoint, from a look-at in code, from framing a scene, or from
//! what the command line asks of a scene ([`Camera::for_scene`]).
//!
//! Image-plane coordinates: `(u, v)` in `[0,1]^2`, `u` to the right, `v` downwards (row 0 at
//! the top); pixel `(i, j)`'s centre is `((i + 0.5) / W, (j + 0.5) / H)`.

use std::f64::consts::FRAC_PI_4;

use glam::{DQuat, DVec3};

use crate::scene::Viewpoint;
use crate::Error;

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

/// The projection asked for on the command line.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Projection {
    /// Perspective; a Viewpoint's `fieldOfView` is the angle across the `fov_across` side of
    /// the image (VRML97: the smaller one, [`Projection::PERSPECTIVE`]).
    Perspective {
        /// The image side the field of view spans.
        fov_across: FovAcross,
    },
    /// Orthographic; `height` = world size of the smaller image side (None: fit the scene).
    Ortho {
        /// World size of the smaller image side, positive; `None` fits the scene.
        height: Option<f64>,
    },
}

impl Projection {
    /// Perspective, a Viewpoint's `fieldOfView` across the smaller image side (VRML97).
    pub const PERSPECTIVE: Projection = Projection::Perspective {
        fov_across: FovAcross::Smaller,
    };
}

/// Which side of the image a Viewpoint's `fieldOfView` spans. VRML97 defines it as the angle
/// across the smaller side, and that is how gtsphere reads it by default; some tools write
/// another side's angle (PyMOL's VRML export writes the width's: [`pymol_export`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum FovAcross {
    /// The smaller side (VRML97).
    #[default]
    Smaller,
    /// The image width.
    Width,
    /// The image height.
    Height,
}

impl FovAcross {
    /// The angle across the smaller side of a `width x height` image whose `self` side spans
    /// `fov` (radians, `0 < fov < pi`): `2 atan(tan(fov / 2) * min(W, H) / S)`, with `S` the
    /// length of that side; `fov` itself when that side is the smaller one. The result is in
    /// `(0, fov]`, so a valid angle stays valid.
    ///
    /// ```
    /// use gtsphere::render::FovAcross;
    /// // 90 degrees across the width of a 4:3 image: tan(h / 2) = 3/4 across the height.
    /// let h = FovAcross::Width.smaller_side_fov(std::f64::consts::FRAC_PI_2, 640, 480);
    /// assert!((h - 2.0 * 0.75f64.atan()).abs() < 1e-15);
    /// ```
    pub fn smaller_side_fov(self, fov: f64, width: u32, height: u32) -> f64 {
        let side = match self {
            FovAcross::Smaller => return fov,
            FovAcross::Width => width,
            FovAcross::Height => height,
        };
        let smaller = width.min(height);
        if side == smaller {
            return fov;
        }
        2.0 * ((0.5 * fov).tan() * f64::from(smaller) / f64::from(side)).atan()
    }

    /// The side's name, as the command line spells it.
    pub fn name(self) -> &'static str {
        match self {
            FovAcross::Smaller => "smaller",
            FovAcross::Width => "width",
            FovAcross::Height => "height",
        }
    }
}

/// Whether `viewpoints` are those of a PyMOL VRML export, whose `fieldOfView` is the angle
/// across the image width (PyMOL writes `pi * fov * W / (180 * H)` from its vertical field of
/// view `fov` in degrees and its window's `W x H`) rather than VRML97's smaller side.
///
/// PyMOL writes no comment or WorldInfo naming itself; what marks its files is the one
/// Viewpoint it writes, always the same but for the distance and the angle: no DEF name,
/// `description "Z view"`, `orientation 1 0 0 0` and `position 0 0 Z` with `Z > 0`. This
/// checks exactly that (after reading, so the file's layout does not matter).
pub fn pymol_export(viewpoints: &[Viewpoint]) -> bool {
    let [vp] = viewpoints else { return false };
    vp.name.is_none()
        && vp.description == "Z view"
        && vp.position.x == 0.0
        && vp.position.y == 0.0
        && vp.position.z > 0.0
        && vp.orientation.abs_diff_eq(DQuat::IDENTITY, 1e-12)
}

/// How a camera projects, for the smaller side of the image.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Lens {
    /// Perspective with this field of view (radians, `0 < fov < pi`) across the smaller side.
    Perspective {
        /// Field of view across the smaller side, in radians, `0 < fov < pi`.
        fov: f64,
    },
    /// Orthographic; `height` is the world size of the smaller side (`> 0`).
    Orthographic {
        /// World size of the smaller side, positive and finite.
        height: f64,
    },
}

impl Default for Lens {
    /// VRML's default fieldOfView, pi/4.
    fn default() -> Self {
        Lens::Perspective { fov: FRAC_PI_4 }
    }
}

/// A camera: position, an orthonormal frame (`right`, `up`, `forward`) and a lens. The image
/// size is not part of it, so one camera renders at any resolution.
///
/// ```
/// use gtsphere::render::{Camera, Lens};
/// use glam::DVec3;
/// let cam = Camera::look_at(DVec3::new(0.0, 0.0, 5.0), DVec3::ZERO, DVec3::Y, Lens::default())
///     .unwrap();
/// assert_eq!(cam.forward, DVec3::NEG_Z);
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Camera {
    /// The eye, in world space.
    pub position: DVec3,
    /// Unit vector towards the image's right edge.
    pub right: DVec3,
    /// Unit vector towards the image's top edge.
    pub up: DVec3,
    /// Unit viewing direction, at right angles to `right` and `up`.
    pub forward: DVec3,
    /// How it projects.
    pub lens: Lens,
}

/// The rays of one picture: a camera at a given image size.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ImagePlane {
    /// The eye, in world space.
    pub position: DVec3,
    /// Unit vector towards the image's right edge.
    pub right: DVec3,
    /// Unit vector towards the image's top edge.
    pub up: DVec3,
    /// Unit viewing direction, at right angles to `right` and `up`.
    pub forward: DVec3,
    /// Half extents of the image plane: tangents of the half angles (perspective) or world
    /// half sizes (orthographic).
    pub half_w: f64,
    /// Half height of the image plane, in the same units as `half_w`.
    pub half_h: f64,
    /// Whether the projection is orthographic (parallel rays) rather than perspective.
    pub ortho: bool,
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

fn invalid(m: String) -> Error {
    Error::Invalid(m)
}

fn check_vec(what: &str, v: DVec3) -> Result<(), Error> {
    if v.is_finite() {
        Ok(())
    } else {
        Err(invalid(format!(
            "the camera's {what} ({}, {}, {}) is not finite",
            v.x, v.y, v.z
        )))
    }
}

impl Lens {
    /// Checks the field of view or height.
    pub fn validate(self) -> Result<Lens, Error> {
        match self {
            Lens::Perspective { fov } if !(fov > 0.0 && fov < std::f64::consts::PI) => {
                Err(invalid(format!(
                    "the camera's field of view {fov} is not between 0 and pi"
                )))
            }
            Lens::Orthographic { height } if !(height > 0.0 && height.is_finite()) => Err(invalid(
                format!("the orthographic height {height} is not positive and finite"),
            )),
            l => Ok(l),
        }
    }
}

impl Camera {
    /// The camera of a VRML Viewpoint: at `position`, `orientation` applied to VRML's
    /// default view (looking down -z with +y up), perspective with its fieldOfView.
    pub fn from_viewpoint(vp: &Viewpoint) -> Result<Camera, Error> {
        Camera::oriented(
            vp.position,
            vp.orientation,
            Lens::Perspective {
                fov: vp.field_of_view,
            },
        )
    }

    /// The camera of a VRML Viewpoint whose `fieldOfView` spans the `across` side of a
    /// `width x height` image ([`FovAcross::smaller_side_fov`]); with [`FovAcross::Smaller`],
    /// [`Camera::from_viewpoint`] at any size.
    pub fn from_viewpoint_across(
        vp: &Viewpoint,
        across: FovAcross,
        width: u32,
        height: u32,
    ) -> Result<Camera, Error> {
        Camera::oriented(
            vp.position,
            vp.orientation,
            Lens::Perspective {
                fov: across.smaller_side_fov(vp.field_of_view, width, height),
            },
        )
    }

    /// At `position`, looking along `orientation * (0,0,-1)` with `orientation * (0,1,0)` up.
    pub fn oriented(position: DVec3, orientation: DQuat, lens: Lens) -> Result<Camera, Error> {
        check_vec("position", position)?;
        if !orientation.is_finite() || orientation.length_squared() == 0.0 {
            return Err(invalid("the camera's orientation is not a rotation".into()));
        }
        let q = orientation.normalize();
        Ok(Camera {
            position,
            right: q * DVec3::X,
            up: q * DVec3::Y,
            forward: q * DVec3::NEG_Z,
            lens: lens.validate()?,
        })
    }

    /// At `eye`, looking at `target`, with `up` projected to be perpendicular to the view.
    /// Errors when `eye == target` or `up` is parallel to the view direction.
    pub fn look_at(eye: DVec3, target: DVec3, up: DVec3, lens: Lens) -> Result<Camera, Error> {
        check_vec("position", eye)?;
        check_vec("target", target)?;
        check_vec("up vector", up)?;
        let forward = (target - eye).normalize_or_zero();
        if forward == DVec3::ZERO {
            return Err(invalid(
                "the camera's target is its own position: no direction to look in".into(),
            ));
        }
        let right = forward.cross(up).normalize_or_zero();
        if right == DVec3::ZERO {
            return Err(invalid(format!(
                "the up vector ({}, {}, {}) is parallel to the view direction",
                up.x, up.y, up.z
            )));
        }
        Ok(Camera {
            position: eye,
            right,
            up: right.cross(forward),
            forward,
            lens: lens.validate()?,
        })
    }

    /// A camera looking along `direction` (with `up`) that sees the ball `(centre, radius)`
    /// whole across the smaller image side, with `margin` (0.02: 2 %) of room: far enough for
    /// a perspective lens (whose `fov` is kept), or an orthographic height of the ball's
    /// diameter (the lens's height is replaced).
    pub fn frame(
        ball: (DVec3, f64),
        direction: DVec3,
        up: DVec3,
        lens: Lens,
        margin: f64,
    ) -> Result<Camera, Error> {
        let (centre, radius) = ball;
        if !(margin >= 0.0 && margin.is_finite()) {
            return Err(invalid(format!("the framing margin {margin} is not >= 0")));
        }
        let radius = radius.max(f64::MIN_POSITIVE) * (1.0 + margin);
        let dir = direction.normalize_or_zero();
        if dir == DVec3::ZERO || !dir.is_finite() {
            return Err(invalid(
                "the framing direction is zero or not finite".into(),
            ));
        }
        let (distance, lens) = match lens.validate()? {
            Lens::Perspective { fov } => (radius / (0.5 * fov).sin(), lens),
            Lens::Orthographic { .. } => (
                2.0 * radius,
                Lens::Orthographic {
                    height: 2.0 * radius,
                },
            ),
        };
        let eye = centre - distance * dir;
        if !eye.is_finite() {
            return Err(invalid(
                "a camera framing the scene would stand beyond the range of f64".into(),
            ));
        }
        Camera::look_at(eye, centre, up, lens)
    }

    /// The camera the command line uses for a scene with these `viewpoints` and bounds
    /// (`bounds` = (min, max) corners, `ball` = a bounding ball), as `choice` and `projection`
    /// ask, at `width x height` (an orthographic lens fitted to the scene depends on the
    /// aspect), with a sentence saying which camera it is. A perspective [`Projection`] says
    /// which image side a Viewpoint's `fieldOfView` spans ([`FovAcross::smaller_side_fov`]);
    /// that changes nothing for the other cameras (VRML's default, one framing the scene).
    pub(crate) fn for_scene(
        viewpoints: &[Viewpoint],
        bounds: Option<(DVec3, DVec3)>,
        ball: Option<(DVec3, f64)>,
        choice: &CameraChoice,
        projection: Projection,
        width: u32,
        height: u32,
    ) -> Result<(Camera, String), Error> {
        let across = match projection {
            Projection::Perspective { fov_across } => fov_across,
            Projection::Ortho { .. } => FovAcross::Smaller,
        };
        let named = |vp: &Viewpoint| match &vp.name {
            Some(n) => format!("Viewpoint {n}"),
            None if !vp.description.is_empty() => format!("Viewpoint \"{}\"", vp.description),
            None => "the first Viewpoint".to_string(),
        };
        let from_file = |vp: &Viewpoint| {
            (
                across.smaller_side_fov(vp.field_of_view, width, height),
                if across == FovAcross::Smaller {
                    named(vp)
                } else {
                    format!(
                        "{} (fieldOfView across the image {})",
                        named(vp),
                        across.name()
                    )
                },
            )
        };
        let (position, orientation, fov, description) = match choice {
            CameraChoice::Named(want) => {
                let vp = viewpoints
                    .iter()
                    .find(|v| v.name.as_deref() == Some(want.as_str()))
                    .or_else(|| viewpoints.iter().find(|v| v.description == *want))
                    .ok_or_else(|| {
                        let mut names: Vec<String> = viewpoints
                            .iter()
                            .map(|v| v.name.clone().unwrap_or_else(|| v.description.clone()))
                            .filter(|n| !n.is_empty())
                            .collect();
                        names.dedup();
                        invalid(if names.is_empty() {
                            format!(
                                "no Viewpoint named \"{want}\": the scene has no named Viewpoints"
                            )
                        } else {
                            format!(
                                "no Viewpoint named \"{want}\"; the scene has: {}",
                                names.join(", ")
                            )
                        })
                    })?;
                let (fov, description) = from_file(vp);
                (vp.position, vp.orientation, fov, description)
            }
            CameraChoice::Auto if !viewpoints.is_empty() => {
                let (fov, description) = from_file(&viewpoints[0]);
                (
                    viewpoints[0].position,
                    viewpoints[0].orientation,
                    fov,
                    description,
                )
            }
            CameraChoice::Auto => match ball {
                Some((c, r)) => (
                    crate::scene::framing_position(c, r).ok_or_else(|| {
                        invalid(
                            "no Viewpoint, and a camera framing the scene would stand beyond \
                             the range of f64: give the scene a Viewpoint"
                                .to_string(),
                        )
                    })?,
                    DQuat::IDENTITY,
                    crate::scene::FRAMING_FOV,
                    "no Viewpoint in the scene: looking down -z, placed to frame the scene's \
                     bounds"
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
        let mut cam = Camera::oriented(position, orientation, Lens::Perspective { fov })?;
        match projection {
            Projection::Perspective { .. } => Ok((cam, description)),
            Projection::Ortho { height: Some(h) } => {
                cam.lens = Lens::Orthographic { height: h }.validate()?;
                Ok((cam, format!("{description} (orthographic)")))
            }
            Projection::Ortho { height: None } => {
                // Fit the scene box's corners as seen along the view axis.
                let (mut ew, mut eh) = (0.0f64, 0.0f64);
                if let Some((lo, hi)) = bounds {
                    for k in 0..8 {
                        let p = DVec3::new(
                            if k & 1 == 0 { lo.x } else { hi.x },
                            if k & 2 == 0 { lo.y } else { hi.y },
                            if k & 4 == 0 { lo.z } else { hi.z },
                        ) - position;
                        ew = ew.max(p.dot(cam.right).abs());
                        eh = eh.max(p.dot(cam.up).abs());
                    }
                }
                let aspect = f64::from(width) / f64::from(height);
                // Smallest half height showing both extents, with a 2 % margin, as the
                // world size of the smaller side.
                let half_h = eh.max(ew / aspect).max(f64::MIN_POSITIVE) * 1.02;
                let (hw, hh) = (half_h * aspect, half_h);
                cam.lens = Lens::Orthographic {
                    height: 2.0 * hw.min(hh),
                }
                .validate()?;
                Ok((cam, format!("{description} (orthographic)")))
            }
        }
    }

    /// The rays of a `width x height` picture taken with this camera.
    pub fn image_plane(&self, width: u32, height: u32) -> ImagePlane {
        let (half_w, half_h, ortho) = match self.lens {
            Lens::Perspective { fov } => {
                let (w, h) = halves((0.5 * fov).tan(), width, height);
                (w, h, false)
            }
            Lens::Orthographic { height: hgt } => {
                let (w, h) = halves(0.5 * hgt, width, height);
                (w, h, true)
            }
        };
        ImagePlane {
            position: self.position,
            right: self.right,
            up: self.up,
            forward: self.forward,
            half_w,
            half_h,
            ortho,
        }
    }
}

impl ImagePlane {
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

#[cfg(test)]
mod tests;
