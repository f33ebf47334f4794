//! The meshes being read, as data: which node an open mesh is and the arrays and indices it
//! holds, what closed meshes and other geometry nodes lowered to, and the cache of DEF'd
//! meshes. `mesh` reads their fields, `mesh_shape` turns them into spheres and triangles.

use glam::DVec3;
use hashbrown::{HashMap, HashSet};

use crate::scene::Triangle;
use crate::source::Pos;

/// Which array a child node of a mesh fills.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(in crate::vrml::lower) enum Array {
    Coord,
    Color,
    Normal,
}

/// Which node a mesh is.
#[derive(Clone, Debug)]
pub(in crate::vrml::lower) enum MeshKind {
    IndexedFaceSet,
    PointSet,
    /// An ElevationGrid: its points and faces are made from these when it closes.
    ElevationGrid(Grid),
    /// An Extrusion: likewise.
    Extrusion(Box<crate::geom::mesh::Extrusion>),
}

/// An ElevationGrid's own fields (VRML97 6.18, with its defaults).
#[derive(Clone, Debug, Default)]
pub(in crate::vrml::lower) struct Grid {
    pub(in crate::vrml::lower) x_dimension: f64,
    pub(in crate::vrml::lower) z_dimension: f64,
    pub(in crate::vrml::lower) x_spacing: f64,
    pub(in crate::vrml::lower) z_spacing: f64,
    pub(in crate::vrml::lower) height: Vec<f64>,
}

impl MeshKind {
    /// The node type, for messages and counts.
    pub(in crate::vrml::lower) fn name(&self) -> &'static str {
        match self {
            MeshKind::IndexedFaceSet => "IndexedFaceSet",
            MeshKind::PointSet => "PointSet",
            MeshKind::ElevationGrid(_) => "ElevationGrid",
            MeshKind::Extrusion(_) => "Extrusion",
        }
    }
}

/// An open IndexedFaceSet, PointSet or ElevationGrid (rare: boxed in [`Kind::Mesh`]). Arrays
/// are slots of [`Meshes::arrays`].
#[derive(Clone, Debug)]
pub(in crate::vrml::lower) struct MeshState {
    pub(in crate::vrml::lower) kind: MeshKind,
    pub(in crate::vrml::lower) coord: Option<u32>,
    pub(in crate::vrml::lower) color: Option<u32>,
    pub(in crate::vrml::lower) normal: Option<u32>,
    pub(in crate::vrml::lower) coord_index: Vec<i64>,
    pub(in crate::vrml::lower) color_index: Vec<i64>,
    pub(in crate::vrml::lower) normal_index: Vec<i64>,
    pub(in crate::vrml::lower) ccw: bool,
    pub(in crate::vrml::lower) solid: bool,
    pub(in crate::vrml::lower) color_per_vertex: bool,
    pub(in crate::vrml::lower) normal_per_vertex: bool,
    pub(in crate::vrml::lower) crease_angle: f64,
    /// An index field was given values that are not integers: nothing is drawn.
    pub(in crate::vrml::lower) malformed: bool,
    /// `Ctx::nodes` before this node started (to cache the node count of a DEF).
    pub(in crate::vrml::lower) nodes_before: u64,
}

/// What a DEF'd mesh lowered to, replayed for each USE without its events.
#[derive(Clone, Copy, Debug)]
pub(in crate::vrml::lower) struct MeshCache {
    pub(in crate::vrml::lower) geom: Geom,
    /// Nodes its events lower (the mesh and the nodes inside).
    pub(in crate::vrml::lower) nodes: u64,
}

/// The meshes met so far.
#[derive(Default)]
pub(in crate::vrml::lower) struct Meshes {
    /// The arrays of the Coordinate, Color and Normal nodes of the open mesh.
    pub(in crate::vrml::lower) arrays: Vec<Vec<DVec3>>,
    /// What closed meshes lowered to ([`Geom::Mesh`] indexes this); taken by the Shape that
    /// draws it unless cached for later USEs.
    pub(in crate::vrml::lower) parts: Vec<Option<MeshParts>>,
    /// Entries of `parts` that the cache refers to (kept after their Shape).
    pub(in crate::vrml::lower) kept: HashSet<u32>,
    /// The Box, Cylinder and Cone nodes read and not yet drawn ([`Geom::Solid`] and
    /// `Leaf::Solid` index this).
    pub(in crate::vrml::lower) solids: Vec<crate::geom::shapes::Solid>,
    /// Spheres found in meshes (tessellated spheres, USEs included).
    pub(in crate::vrml::lower) spheres: u64,
    /// Spheres made of points (PointSets and face-less IndexedFaceSets).
    pub(in crate::vrml::lower) point_spheres: u64,
    /// What each DEF'd mesh lowered to, by the start of its recording.
    pub(in crate::vrml::lower) cache: HashMap<usize, MeshCache>,
    /// The last mesh closed (for `cache`).
    pub(in crate::vrml::lower) last: Option<MeshCache>,
}

impl Meshes {
    /// The array in `slot`, or an empty one.
    pub(in crate::vrml::lower) fn array(&self, slot: Option<u32>) -> &[DVec3] {
        slot.and_then(|s| self.arrays.get(s as usize))
            .map_or(&[], Vec::as_slice)
    }
}

/// One sphere of a mesh: centre, radius and its colour if the mesh gave one.
pub(in crate::vrml::lower) type MeshSphere = (DVec3, f64, Option<DVec3>);

/// What a mesh lowers to, in its own coordinates.
#[derive(Clone, Debug, Default)]
pub(in crate::vrml::lower) struct MeshParts {
    pub(in crate::vrml::lower) spheres: Vec<MeshSphere>,
    pub(in crate::vrml::lower) triangles: Vec<Triangle>,
    /// The spheres are particles made of points.
    pub(in crate::vrml::lower) points: bool,
}

impl MeshParts {
    pub(in crate::vrml::lower) fn mesh_spheres(&self) -> u64 {
        if self.points {
            0
        } else {
            self.spheres.len() as u64
        }
    }
    pub(in crate::vrml::lower) fn point_spheres(&self) -> u64 {
        if self.points {
            self.spheres.len() as u64
        } else {
            0
        }
    }
}

/// What a closed geometry node is.
#[derive(Clone, Copy, Debug)]
pub(in crate::vrml::lower) enum Geom {
    Sphere(f64, Pos),
    /// A Box, Cylinder or Cone: index into `Meshes::solids`, node position.
    Solid(u32, Pos),
    /// An IndexedFaceSet or PointSet: index into `Meshes::parts`, node position.
    Mesh(u32, Pos),
    Other,
}
