//! gtsphere: a ground-truth renderer for particle data drawn as spheres.
//!
//! This crate is the library; the `gtsphere` command is the workspace crate `cli/` (package
//! `gtsphere-cli`), which turns its arguments into the options these modules take and prints
//! what they return. Data flows one way:
//!
//! 1. Text: bytes ([`input`], gzip sniffed) -> a window of source text ([`source`]) -> syntax
//!    events ([`vrml::lex`], `vrml::parse`: node types, fields, values and byte spans,
//!    nothing about what a Sphere means).
//! 2. Scene IR: [`vrml::lower`] (DEF/USE, PROTO, the transform stack, light scopes, warnings)
//!    builds a [`scene::Scene`]: spheres, ellipsoids, materials, lights, viewpoints. `scene`
//!    knows nothing of VRML; [`vrml::write`] writes a Scene back out.
//!    A scene can also be built in code: [`scene::Scene::from_arrays`] (validated, every bad
//!    value named by array and index) and the lights' `Default`s (VRML's).
//! 3. Acceleration: [`render::prepare`] validates the scene and builds a [`render::Prepared`]:
//!    the [`accel::bvh`] (f32 padded boxes around spheres tested exactly in f64 by [`geom`]),
//!    materials and lights, once for any number of cameras.
//! 4. Integrators: [`render::render`] takes the prepared scene, a [`render::Camera`] and
//!    [`render::RenderOptions`], traces tiles in parallel ([`render::tiles`], with progress
//!    and cancellation), each pixel's samples through one of [`render::integrators`]
//!    (surface, exact, march, mc), into a [`render::Film`] (f64 RGB, alpha, extra channels).
//! 5. File: [`output`] writes PNG, EXR, PFM or NPY through a temporary file and a rename.
//!
//! ```
//! use gtsphere::render::{self, Camera, Lens, PrepareOptions, RenderOptions};
//! use gtsphere::scene::{PointLight, Light, Radii, Scene, SphereArrays};
//! use glam::DVec3;
//!
//! let centers = [0.0, 0.0, 0.0, 1.2, 0.3, -0.5];
//! let mut scene = Scene::from_arrays(&SphereArrays::new(&centers, Radii::Each(&[0.5, 0.3])))?;
//! scene.headlight = false;
//! scene.lights.push(Light::Point(PointLight {
//!     location: DVec3::new(3.0, 3.0, 3.0),
//!     ..PointLight::default()
//! }));
//! let prepared = render::prepare(scene, &PrepareOptions::default())?;
//! let camera = Camera::look_at(DVec3::new(0.0, 0.0, 5.0), DVec3::ZERO, DVec3::Y, Lens::default())?;
//! let opts = RenderOptions { width: 64, height: 48, spp: 4, ..RenderOptions::default() };
//! let film = render::render(&prepared, &camera, &opts, &())?;
//! assert!(film.rgb[24 * 64 + 32][0] > 0.0); // the centre pixel sees the lit sphere
//! # Ok::<(), gtsphere::Error>(())
//! ```
//!
//! Beside the flow: [`particles`] streams a particle table row by row to VRML (no Scene);
//! [`vrml::number`] is the one rule both VRML writers format numbers by; [`compare`] holds
//! image metrics; `bench` holds the generated benchmark scenes that `gtsphere bench`,
//! `cargo bench` and the tests share. docs/internals.md follows the data flow module by
//! module.

#![warn(missing_docs)]

pub mod accel;
#[doc(hidden)]
pub mod bench;
pub mod compare;
pub mod diag;
pub mod error;
pub mod geom;
pub mod input;
pub mod output;
pub mod particles;
pub mod render;
pub mod scene;
pub mod source;
#[cfg(test)]
mod testing;
pub mod vrml;

pub use error::Error;
