//! Pure f64 geometry: roots of a line against a sphere or an ellipsoid, chord lengths and
//! normals; the sphere through a tessellated sphere's vertices (`fit.rs`); polygon meshes
//! (`mesh/`: faces, components, triangles, normals); nearest-neighbour spacing
//! (`nearest.rs`). Depends on nothing else in the crate; see `sphere.rs` for the numerics.

pub(crate) mod eft;
mod ellipsoid;
mod fit;
pub mod mesh;
pub mod nearest;
pub mod shapes;
mod sphere;

pub use ellipsoid::{ellipsoid_normal, ellipsoid_roots};
pub use fit::{sphere_fit, sphere_through, MIN_POINTS, MIN_REACH, RADIUS_TOLERANCE};
pub use mesh::{
    components, crease_normals, faces, first_bad_index, newell_normal, triangulate, Component,
};
pub use nearest::median_nearest_distance;
pub use sphere::{enters_between, segment_chord, sphere_roots};
