//! Pure f64 geometry: roots of a line against a sphere or an ellipsoid, chord lengths and
//! normals; the sphere through a tessellated sphere's vertices (`fit.rs`); polygon meshes
//! (`mesh/`: faces, components, triangles, normals); nearest-neighbour spacing
//! (`nearest.rs`). Depends on nothing else in the crate; see `sphere.rs` for the numerics.

pub(crate) mod eft;
use glam::DVec3;

mod ellipsoid;
mod fit;
pub mod mesh;
pub mod nearest;
pub mod shapes;
mod sphere;

pub use ellipsoid::{ellipsoid_normal, ellipsoid_roots};
pub use fit::sphere_fit;
pub use sphere::{enters_between, sphere_roots};

/// Distance from `c` to the segment `[a, b]`.
pub fn distance_to_segment(c: DVec3, a: DVec3, b: DVec3) -> f64 {
    let ab = b - a;
    let len2 = ab.length_squared();
    let u = if len2 > 0.0 {
        ((c - a).dot(ab) / len2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (a + u * ab - c).length()
}

#[cfg(test)]
mod tests;
