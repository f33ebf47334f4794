//! Polygon meshes (VRML97 IndexedFaceSet): faces of a `coordIndex`, connected components (the
//! particles of a merged glyph mesh), triangulation and crease-angle normals, and the
//! Extrusion's points and faces. Pure f64.

mod components;
mod extrusion;
mod faces;
mod normals;
mod triangulate;

pub use components::components;
pub use extrusion::{extrusion_mesh, Extrusion};
pub use faces::{faces, first_bad_index};
pub use normals::crease_normals;
pub use triangulate::triangulate;

#[cfg(test)]
pub(crate) use components::tests as tests_support;
