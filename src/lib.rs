//! gtsphere: a ground-truth renderer for particle data drawn as spheres.
//!
//! This crate is the library; the `gtsphere` command is the workspace crate `cli/` (package
//! `gtsphere-cli`), which turns its arguments into the options these modules take and prints
//! what they return. Data flows one way:
//!
//! 1. Text: bytes ([`input`], gzip sniffed) -> a window of source text ([`source`]) -> syntax
//!    events ([`vrml::lex`], [`vrml::parse`]: node types, fields, values and byte spans,
//!    nothing about what a Sphere means).
//! 2. Scene IR: [`vrml::lower`] (DEF/USE, PROTO, the transform stack, light scopes, warnings)
//!    builds a [`scene::Scene`]: spheres, ellipsoids, materials, lights, viewpoints. `scene`
//!    knows nothing of VRML; [`vrml::write`] writes a Scene back out.
//! 3. Acceleration: [`render::prepare`] builds the [`accel::bvh`] (f32 padded boxes around
//!    spheres tested exactly in f64 by [`geom`]), the camera and the lights.
//! 4. Integrators: [`render::tiles`] traces tiles in parallel, each pixel's samples through
//!    one of [`render::integrators`] (surface, exact, march, mc), into a film (samples summed
//!    in f64, stored as f32 unless `RenderOptions::film_f64`).
//! 5. File: [`output`] writes PNG, EXR or PFM through a temporary file and a rename.
//!
//! Beside the flow: [`particles`] streams a particle table row by row to VRML (no Scene);
//! [`vrml::number`] is the one rule both VRML writers format numbers by; [`compare`] holds
//! image metrics; [`scenes`] generates the benchmark scenes that `gtsphere bench`,
//! `cargo bench` and the tests share. README.md ("How the code is laid out") says where the
//! layout differs from the tree suggested in ../shared/STYLE.md, and why.

pub mod accel;
pub mod compare;
pub mod diag;
pub mod error;
pub mod geom;
pub mod input;
pub mod output;
pub mod particles;
pub mod render;
pub mod scene;
pub mod scenes;
pub mod source;
#[cfg(test)]
mod testing;
pub mod vrml;

pub use error::Error;
