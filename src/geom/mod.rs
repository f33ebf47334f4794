//! Pure f64 ray/sphere math: roots of a line against a sphere or an ellipsoid, chord lengths
//! and normals, and the sphere through a tessellated sphere's vertices (`fit.rs`). Depends on
//! nothing else in the crate; see `sphere.rs` for the numerics.

mod ellipsoid;
mod fit;
mod sphere;

pub use ellipsoid::{ellipsoid_normal, ellipsoid_roots};
pub use fit::sphere_through;
pub use sphere::{segment_chord, sphere_roots};
