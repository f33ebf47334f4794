//! gtsphere: a ground-truth renderer for particle data drawn as spheres.
//!
//! This crate is the library; the `gtsphere` command is the workspace crate `cli/` (package
//! `gtsphere-cli`), which turns its arguments into the options these modules take and prints
//! what they return. What a program uses:
//!
//! - [`vrml`]: a VRML97 scene read ([`vrml::load_path`], [`vrml::load_bytes`],
//!   [`vrml::load_str`], as [`vrml::LoadOptions`] say, with a [`vrml::LoadReport`] of
//!   warnings and counts) and written back ([`vrml::write_scene`]).
//! - [`scene`]: the scene IR, [`scene::Scene`]: spheres, ellipsoids, other surfaces,
//!   materials, lights, viewpoints. A scene can also be built in code:
//!   [`scene::Scene::from_arrays`] (validated, every bad value named by array and index) and
//!   the lights' `Default`s (VRML's).
//! - [`particles`]: particle tables (CSV, TSV, XYZ) streamed row by row to VRML.
//! - [`render`]: [`render::prepare`] validates a scene and builds a [`render::Prepared`]
//!   (the BVH, materials and lights, once for any number of cameras); [`render::render`]
//!   traces it from a [`render::Camera`] as [`render::RenderOptions`] say (in parallel,
//!   with progress and cancellation) into a [`render::Film`] (f64 RGB, alpha, extra
//!   channels).
//! - [`output`]: pictures written as PNG, EXR, PFM or NPY through a temporary file and a
//!   rename, and read back; [`compare`]: image metrics and error heat maps.
//! - [`input`]: plain or gzip-compressed streams; [`Error`] and [`diag`]: what fails, and
//!   positioned diagnostics.
//!
//! Inside, data flows one way (docs/internals.md follows it module by module):
//!
//! 1. Text: bytes (`input`, gzip sniffed) -> a window of source text (`source`) -> syntax
//!    events (`vrml::lex`, `vrml::parse`: node types, fields, values and byte spans,
//!    nothing about what a Sphere means).
//! 2. Scene IR: `vrml::lower` (DEF/USE, PROTO, the transform stack, light scopes, warnings)
//!    builds a `scene::Scene`; `scene` knows nothing of VRML; `vrml::write` writes a Scene
//!    back out.
//! 3. Acceleration: `render::prepare` builds the `accel::bvh` (f32 padded boxes around
//!    spheres tested exactly in f64 by `geom`).
//! 4. Integrators: `render::tiles` traces each pixel's samples through one of
//!    `render::integrators` (surface, exact, march, mc) into the film.
//! 5. File: `output`.
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
//! Beside the flow: `particles` streams a particle table row by row to VRML (no Scene);
//! `vrml::number` is the one rule both VRML writers format numbers by; `bench` holds the
//! generated benchmark scenes that `gtsphere bench`, `cargo bench` and the tests share.

#![warn(missing_docs)]

pub(crate) mod accel;
#[doc(hidden)]
pub mod bench;
pub mod compare;
pub mod diag;
pub mod error;
pub(crate) mod geom;
pub mod input;
pub mod output;
pub mod particles;
pub mod render;
pub mod scene;
pub(crate) mod source;
#[cfg(test)]
mod testing;
// The test helpers name the library `gtsphere`, as the integration tests that share them do.
#[cfg(test)]
extern crate self as gtsphere;
pub mod vrml;

pub use error::Error;
