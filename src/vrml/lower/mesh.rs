//! IndexedFaceSet and PointSet while they are read: their fields are gathered leniently and
//! without a table (a value of another type is ignored, as for a skipped node), with the
//! `coord`, `color` and `normal` arrays of their Coordinate, Color and Normal children. What
//! a closed one becomes (spheres, triangles, particles) is decided in `mesh_shape`. What a
//! DEF'd one lowered to is cached at its first USE ([`Meshes::cache`]), so later USEs of a
//! Jmol atom or bond cost a lookup, not a replay of its events.

use glam::DVec3;
use hashbrown::{HashMap, HashSet};

use super::mesh_shape::MeshParts;
use super::open::{Geom, Kind, Name, Result_};
use super::record::Rec;
use super::Lowerer;
use crate::error::Error;
use crate::source::SourceWindow;
use crate::vrml::syntax::{OwnedEvent, Value};

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
    nodes_before: u64,
}

/// What a DEF'd mesh lowered to, replayed for each USE without its events.
#[derive(Clone, Copy, Debug)]
pub(super) struct MeshCache {
    geom: Geom,
    /// Nodes its events lower (the mesh and the nodes inside).
    nodes: u64,
}

/// The meshes met so far.
#[derive(Default)]
pub(super) struct Meshes {
    /// The arrays of the Coordinate, Color and Normal nodes of the open mesh.
    arrays: Vec<Vec<DVec3>>,
    /// What closed meshes lowered to ([`Geom::Mesh`] indexes this); taken by the Shape that
    /// draws it unless cached for later USEs.
    pub(super) parts: Vec<Option<MeshParts>>,
    /// Entries of `parts` that the cache refers to (kept after their Shape).
    kept: HashSet<u32>,
    /// The Box, Cylinder and Cone nodes read and not yet drawn ([`Geom::Solid`] and
    /// `Leaf::Solid` index this).
    pub(super) solids: Vec<crate::geom::shapes::Solid>,
    /// Spheres found in meshes (tessellated spheres, USEs included).
    pub(super) spheres: u64,
    /// Spheres made of points (PointSets and face-less IndexedFaceSets).
    pub(super) point_spheres: u64,
    /// What each DEF'd mesh lowered to, by the start of its recording.
    cache: HashMap<usize, MeshCache>,
    /// The last mesh closed (for `cache`).
    last: Option<MeshCache>,
}

impl Meshes {
    /// The array in `slot`, or an empty one.
    pub(super) fn array(&self, slot: Option<u32>) -> &[DVec3] {
        slot.and_then(|s| self.arrays.get(s as usize))
            .map_or(&[], Vec::as_slice)
    }
}

fn triples(values: &[f64]) -> Vec<DVec3> {
    values
        .chunks_exact(3)
        .map(|c| DVec3::new(c[0], c[1], c[2]))
        .collect()
}

fn integers(values: &[f64]) -> Vec<i64> {
    values.iter().map(|&v| v as i64).collect()
}

/// Reads a field of a mesh or of one of its arrays, leniently: a value of another type is
/// ignored (the node was skipped whole before it was modelled).
pub(super) fn mesh_field(kind: &mut Kind, name: &str, value: &Value, meshes: &mut Meshes) {
    if let (Kind::Mesh(m), Value::Numbers { values, .. }) = (&mut *kind, value) {
        if let MeshKind::Extrusion(e) = &mut m.kind {
            let pairs = || {
                values
                    .chunks_exact(2)
                    .map(|c| glam::DVec2::new(c[0], c[1]))
                    .collect()
            };
            match name {
                "crossSection" => return e.cross_section = pairs(),
                "scale" => return e.scale = pairs(),
                "spine" => return e.spine = triples(values),
                "orientation" => {
                    return e.orientation = values
                        .chunks_exact(4)
                        .map(|c| super::transform::quat([c[0], c[1], c[2], c[3]]))
                        .collect()
                }
                _ => {}
            }
        }
        if let MeshKind::ElevationGrid(g) = &mut m.kind {
            let first = values.first().copied().unwrap_or(0.0);
            match name {
                "xDimension" => return g.x_dimension = first,
                "zDimension" => return g.z_dimension = first,
                "xSpacing" => return g.x_spacing = first,
                "zSpacing" => return g.z_spacing = first,
                "height" => return g.height = values.to_vec(),
                _ => {}
            }
        }
    }
    match (kind, value) {
        (Kind::MeshArray(which, slot), Value::Numbers { values, .. }) => {
            let wanted = match which {
                Array::Coord => "point",
                Array::Color => "color",
                Array::Normal => "vector",
            };
            if name == wanted {
                meshes.arrays[*slot as usize] = triples(values);
            }
        }
        (
            Kind::Mesh(m),
            Value::Numbers {
                values,
                integer: true,
                ..
            },
        ) => match name {
            "coordIndex" => m.coord_index = integers(values),
            "colorIndex" => m.color_index = integers(values),
            "normalIndex" => m.normal_index = integers(values),
            "creaseAngle" => m.crease_angle = values.first().copied().unwrap_or(0.0),
            _ => {}
        },
        (Kind::Mesh(m), Value::Numbers { values, .. }) => match name {
            "creaseAngle" => m.crease_angle = values.first().copied().unwrap_or(0.0),
            "coordIndex" | "colorIndex" | "normalIndex" => m.malformed = true,
            _ => {}
        },
        (Kind::Mesh(m), Value::Bools { values, .. }) => {
            let b = values.first().copied().unwrap_or(true);
            if let MeshKind::Extrusion(e) = &mut m.kind {
                match name {
                    "beginCap" => e.begin_cap = b,
                    "endCap" => e.end_cap = b,
                    _ => {}
                }
            }
            match name {
                "ccw" => m.ccw = b,
                "solid" => m.solid = b,
                "colorPerVertex" => m.color_per_vertex = b,
                "normalPerVertex" => m.normal_per_vertex = b,
                _ => {}
            }
        }
        _ => {}
    }
}

impl Lowerer {
    /// An IndexedFaceSet or PointSet: its fields are read leniently (see `mesh_field`), with
    /// no table: as for a skipped node, none of them is checked or warned about.
    #[cold]
    #[inline(never)]
    pub(super) fn open_mesh(&mut self, ty: Name, at: u64, kind: MeshKind) {
        let kind = Kind::Mesh(Box::new(MeshState {
            kind,
            coord: None,
            color: None,
            normal: None,
            coord_index: Vec::new(),
            color_index: Vec::new(),
            normal_index: Vec::new(),
            ccw: true,
            solid: true,
            color_per_vertex: true,
            normal_per_vertex: true,
            crease_angle: 0.0,
            malformed: false,
            nodes_before: self.nodes - 1,
        }));
        self.open.push(ty, None, kind, at);
    }

    /// A node inside a mesh: its Coordinate, Color and Normal are read; other nodes are
    /// neither lowered nor counted (as when the mesh was skipped whole).
    #[cold]
    #[inline(never)]
    pub(super) fn mesh_child(&mut self, ty: Name, at: u64) {
        let Some(ctx) = self.open.fields.last() else {
            return;
        };
        let which = match (&*ctx.name, &*ty) {
            ("coord", "Coordinate") => Some(Array::Coord),
            ("color", "Color") => Some(Array::Color),
            ("normal", "Normal") => Some(Array::Normal),
            _ => None,
        };
        match which {
            Some(which) => {
                let slot = self.meshes.arrays.len() as u32;
                self.meshes.arrays.push(Vec::new());
                self.open.push(ty, None, Kind::MeshArray(which, slot), at);
            }
            None => self.open.push_quiet(ty, at),
        }
    }

    /// An array node closed inside a mesh: the mesh takes it.
    pub(super) fn take_array(m: &mut MeshState, which: Array, slot: u32) {
        match which {
            Array::Coord => m.coord = Some(slot),
            Array::Color => m.color = Some(slot),
            Array::Normal => m.normal = Some(slot),
        }
    }

    /// A closed mesh: what it lowers to (see `mesh_shape`), kept for the Shape that draws it.
    pub(super) fn close_mesh(
        &mut self,
        src: &SourceWindow,
        m: &MeshState,
        at: u64,
    ) -> Result<Result_, Error> {
        // (Only a Shape's geometry is drawn: elsewhere it counts as skipped.)
        let drawable = !m.malformed
            && match &m.kind {
                MeshKind::ElevationGrid(g) => g.x_dimension >= 2.0 && g.z_dimension >= 2.0,
                MeshKind::Extrusion(_) => true,
                _ => !self.meshes.array(m.coord).is_empty(),
            };
        let geom = if self.open.in_shape_geometry() && drawable {
            let parts = self.mesh_parts(src, m, at)?;
            let i = self.meshes.parts.len() as u32;
            self.meshes.parts.push(Some(parts));
            Geom::Mesh(i, at)
        } else {
            self.diags.skip(m.kind.name());
            Geom::Other
        };
        self.meshes.arrays.clear();
        self.meshes.last = Some(MeshCache {
            geom,
            nodes: self.nodes - m.nodes_before,
        });
        Ok(Result_::Geometry(geom))
    }

    /// The parts of mesh `i` for a Shape: taken, unless the cache still needs them.
    pub(super) fn mesh_parts_for_shape(&mut self, i: u32) -> Option<MeshParts> {
        let slot = self.meshes.parts.get_mut(i as usize)?;
        if self.meshes.kept.contains(&i) {
            slot.clone()
        } else {
            slot.take()
        }
    }

    /// Whether a USE of the recording at `start` is of a mesh as a Shape's geometry (lowered
    /// once, then looked up).
    pub(super) fn is_mesh_use(&self, start: usize) -> bool {
        self.open.in_shape_geometry()
            && matches!(&self.rec.arena[start],
                Rec::Ev(OwnedEvent::NodeStart { ty, .. })
                    if matches!(&**ty, "IndexedFaceSet" | "PointSet" | "ElevationGrid" | "Extrusion"))
    }

    /// A USE of the mesh recorded at `start`, if what it lowers to is known: counted and
    /// delivered without replaying it. Says whether it was.
    pub(super) fn reuse_mesh(
        &mut self,
        src: &SourceWindow,
        start: usize,
        at: u64,
    ) -> Result<bool, Error> {
        if let Some(c) = self.meshes.cache.get(&start).copied() {
            self.add_nodes(c.nodes, src, at)?;
            if let Geom::Mesh(i, _) = c.geom {
                if let Some(Some(p)) = self.meshes.parts.get(i as usize) {
                    self.meshes.spheres += p.mesh_spheres();
                    self.meshes.point_spheres += p.point_spheres();
                }
            }
            self.deliver(Result_::Geometry(c.geom));
            return Ok(true);
        }
        self.meshes.last = None;
        Ok(false)
    }

    /// After the first USE of the mesh recorded at `start` was replayed: keeps what it lowered
    /// to for the next USEs.
    pub(super) fn remember_mesh(&mut self, start: usize) {
        if let Some(c) = self.meshes.last.take() {
            if let Geom::Mesh(i, _) = c.geom {
                self.meshes.kept.insert(i);
            }
            self.meshes.cache.insert(start, c);
        }
    }
}
