//! Pure f64 ray/sphere math: roots of a line against a sphere or an ellipsoid, chord lengths
//! and normals. Depends on nothing else in the crate; see `sphere.rs` for the numerics.

mod ellipsoid;
mod sphere;

pub use ellipsoid::{ellipsoid_normal, ellipsoid_roots};
pub use sphere::{segment_chord, sphere_roots};
