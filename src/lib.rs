//! gtsphere: a ground-truth renderer for particle data drawn as spheres.
//!
//! Data flows one way: bytes ([`input`]) -> source text ([`source`]) -> syntax events
//! ([`vrml::parse`]) -> scene IR ([`vrml::lower`] into [`scene::Scene`]).

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
