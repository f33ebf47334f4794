//! The meshes being read, as data: which node an open mesh is and the arrays and indices it
//! holds, what closed meshes and other geometry nodes lowered to, and the cache of DEF'd
//! meshes. `mesh` reads their fields, `mesh_shape` turns them into spheres and triangles.

use glam::DVec3;
use hashbrown::{HashMap, HashSet};

use crate::scene::Triangle;
use crate::source::Pos;

/// Which array a child node of a mesh fills.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Array {
    Coord,
    Color,
    Normal,
}

/// Which node a mesh is.
#[derive(Clone, Debug)]
pub(super) enum MeshKind {
    IndexedFaceSet,
    PointSet,
    /// An ElevationGrid: its points and faces are made from these when it closes.
    ElevationGrid(Grid),
    /// An Extrusion: likewise.
    Extrusion(Box<crate::geom::mesh::Extrusion>),
}

/// An ElevationGrid's own fields (VRML97 6.18, with its defaults).
#[derive(Clone, Debug, Default)]
pub(super) struct Grid {
    pub(super) x_dimension: f64,
    pub(super) z_dimension: f64,
    pub(super) x_spacing: f64,
    pub(super) z_spacing: f64,
    pub(super) height: Vec<f64>,
}

impl MeshKind {
    /// The node type, for messages and counts.
    pub(super) fn name(&self) -> &'static str {
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
pub(super) struct MeshState {
    pub(super) kind: MeshKind,
    pub(super) coord: Option<u32>,
    pub(super) color: Option<u32>,
    pub(super) normal: Option<u32>,
    pub(super) coord_index: Vec<i64>,
    pub(super) color_index: Vec<i64>,
    pub(super) normal_index: Vec<i64>,
    pub(super) ccw: bool,
    pub(super) solid: bool,
    pub(super) color_per_vertex: bool,
    pub(super) normal_per_vertex: bool,
    pub(super) crease_angle: f64,
    /// An index field was given values that are not integers: nothing is drawn.
    pub(super) malformed: bool,
    /// `Lowerer::nodes` before this node started (to cache the node count of a DEF).
    pub(super) nodes_before: u64,
}

/// What a DEF'd mesh lowered to, replayed for each USE without its events.
#[derive(Clone, Copy, Debug)]
pub(super) struct MeshCache {
    pub(super) geom: Geom,
    /// Nodes its events lower (the mesh and the nodes inside).
    pub(super) nodes: u64,
}

/// The meshes met so far.
#[derive(Default)]
pub(super) struct Meshes {
    /// The arrays of the Coordinate, Color and Normal nodes of the open mesh.
    pub(super) arrays: Vec<Vec<DVec3>>,
    /// What closed meshes lowered to ([`Geom::Mesh`] indexes this); taken by the Shape that
    /// draws it unless cached for later USEs.
    pub(super) parts: Vec<Option<MeshParts>>,
    /// Entries of `parts` that the cache refers to (kept after their Shape).
    pub(super) kept: HashSet<u32>,
    /// The Box, Cylinder and Cone nodes read and not yet drawn ([`Geom::Solid`] and
    /// `Leaf::Solid` index this).
    pub(super) solids: Vec<crate::geom::shapes::Solid>,
    /// Spheres found in meshes (tessellated spheres, USEs included).
    pub(super) spheres: u64,
    /// Spheres made of points (PointSets and face-less IndexedFaceSets).
    pub(super) point_spheres: u64,
    /// What each DEF'd mesh lowered to, by the start of its recording.
    pub(super) cache: HashMap<usize, MeshCache>,
    /// The last mesh closed (for `cache`).
    pub(super) last: Option<MeshCache>,
}

impl Meshes {
    /// The array in `slot`, or an empty one.
    pub(super) fn array(&self, slot: Option<u32>) -> &[DVec3] {
        slot.and_then(|s| self.arrays.get(s as usize))
            .map_or(&[], Vec::as_slice)
    }
}

/// One sphere of a mesh: centre, radius and its colour if the mesh gave one.
pub(super) type MeshSphere = (DVec3, f64, Option<DVec3>);

/// What a mesh lowers to, in its own coordinates.
#[derive(Clone, Debug, Default)]
pub(super) struct MeshParts {
    pub(super) spheres: Vec<MeshSphere>,
    pub(super) triangles: Vec<Triangle>,
    /// The spheres are particles made of points.
    pub(super) points: bool,
}

impl MeshParts {
    pub(super) fn mesh_spheres(&self) -> u64 {
        if self.points {
            0
        } else {
            self.spheres.len() as u64
        }
    }
    pub(super) fn point_spheres(&self) -> u64 {
        if self.points {
            self.spheres.len() as u64
        } else {
            0
        }
    }
}

/// What a closed geometry node is.
#[derive(Clone, Copy, Debug)]
pub(super) enum Geom {
    Sphere(f64, Pos),
    /// A Box, Cylinder or Cone: index into `Meshes::solids`, node position.
    Solid(u32, Pos),
    /// An IndexedFaceSet or PointSet: index into `Meshes::parts`, node position.
    Mesh(u32, Pos),
    Other,
}
