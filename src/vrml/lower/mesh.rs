//! Tessellated spheres: an IndexedFaceSet lowered as the sphere through its vertices (see
//! "Tessellated spheres" in the module documentation). Its fields are read leniently and
//! without a table, as for a skipped node: only `coordIndex`, the `coord` Coordinate's
//! `point`s and whether a `color` node is given decide. The sphere through the points is
//! fitted when the Coordinate's `point` is read ([`Meshes::fits`]); when the IndexedFaceSet
//! closes as a Shape's geometry and its index uses every point, it is that sphere. What a
//! DEF'd IndexedFaceSet lowered to is cached at its first USE ([`Meshes::cache`]), so later
//! USEs of a Jmol atom cost a lookup, not a replay of its events.

use glam::DVec3;
use hashbrown::HashMap;

use super::open::{Geom, Kind, Name, Result_};
use super::record::Rec;
use super::Lowerer;
use crate::error::Error;
use crate::source::SourceWindow;
use crate::vrml::syntax::{OwnedEvent, Value};

/// An open IndexedFaceSet (rare: boxed in [`Kind::Mesh`]).
#[derive(Debug, Default)]
pub(super) struct MeshState {
    /// From the `coord` Coordinate: point count and the sphere through the points, if any.
    pub(super) coord: Option<CoordFit>,
    /// `coordIndex`, if given as integers.
    index: Option<Vec<f64>>,
    /// A `color` node was given.
    colored: bool,
    /// `Lowerer::nodes` before this node started (to cache the node count of a DEF).
    nodes_before: u64,
}

/// A Coordinate's point count and the sphere through its points (index into
/// [`Meshes::fits`]), if any. Small and `Copy`, so [`Result_`] needs no drop.
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct CoordFit {
    points: usize,
    sphere: Option<u32>,
}

/// What a DEF'd IndexedFaceSet lowered to, replayed for each USE without its events.
#[derive(Clone, Copy, Debug)]
pub(super) struct MeshCache {
    geom: Geom,
    /// Nodes its events lower (the IndexedFaceSet and the nodes inside).
    nodes: u64,
}

/// The tessellated spheres found so far.
#[derive(Default)]
pub(super) struct Meshes {
    /// Spheres through the points of Coordinates in IndexedFaceSets ([`CoordFit`] and
    /// [`Geom::Mesh`] index this).
    pub(super) fits: Vec<(DVec3, f64)>,
    /// IndexedFaceSet instances lowered as spheres (USEs included).
    pub(super) spheres: u64,
    /// What each DEF'd IndexedFaceSet lowered to, by the start of its recording.
    cache: HashMap<usize, MeshCache>,
    /// The last IndexedFaceSet closed (for `cache`).
    last: Option<MeshCache>,
}

/// Reads the fields of an IndexedFaceSet or its Coordinate that decide whether it is a sphere.
/// Leniently: a value of another type makes it no sphere rather than an error (the node was
/// skipped whole before it could be one).
pub(super) fn mesh_field(kind: &mut Kind, name: &str, value: &Value, fits: &mut Vec<(DVec3, f64)>) {
    match (kind, name, value) {
        (
            Kind::Mesh(m),
            "coordIndex",
            Value::Numbers {
                values,
                integer: true,
                ..
            },
        ) => m.index = Some(values.to_vec()),
        (Kind::Coord(c), "point", Value::Numbers { values, .. }) => {
            let sphere = crate::geom::sphere_through(values).map(|f| {
                fits.push(f);
                fits.len() as u32 - 1
            });
            *c = CoordFit {
                points: values.len() / 3,
                sphere,
            }
        }
        _ => {}
    }
}

/// Whether `coordIndex` refers only to existing points (or is -1, the face separator) and
/// uses every one of them: a mesh over all its vertices, not a piece of the sphere.
fn uses_all(index: &[f64], points: usize) -> bool {
    let mut seen = vec![false; points];
    for &i in index {
        if i == -1.0 {
            continue;
        }
        if !(i >= 0.0 && i < points as f64) {
            return false;
        }
        seen[i as usize] = true;
    }
    seen.iter().all(|&s| s)
}

impl Lowerer {
    /// An IndexedFaceSet: its fields are read leniently (see `field`), with no table: as for a
    /// skipped node, none of them is checked or warned about.
    #[cold]
    #[inline(never)]
    pub(super) fn open_mesh(&mut self, ty: Name, at: u64) {
        let kind = Kind::Mesh(Box::new(MeshState {
            nodes_before: self.nodes - 1,
            ..MeshState::default()
        }));
        self.open.push(ty, None, kind, at);
    }

    /// A node inside an IndexedFaceSet: only the `coord` Coordinate is read; other nodes are
    /// neither lowered nor counted (as when the IndexedFaceSet was skipped whole).
    #[cold]
    #[inline(never)]
    pub(super) fn mesh_child(&mut self, ty: Name, at: u64) {
        let Some(ctx) = self.open.fields.last() else {
            return;
        };
        let coord = &*ctx.name == "coord" && &*ty == "Coordinate";
        if let Kind::Mesh(m) = &mut self.open.frames[ctx.frame].kind {
            m.colored |= &*ctx.name == "color";
        }
        if coord {
            self.open
                .push(ty, None, Kind::Coord(CoordFit::default()), at);
        } else {
            self.open.push_quiet(ty, at);
        }
    }

    /// A closed IndexedFaceSet: a sphere (see "Tessellated spheres") or other geometry.
    pub(super) fn close_mesh(&mut self, m: &MeshState, at: u64) -> Result_ {
        let geom = self.mesh_geom(m, at);
        self.meshes.last = Some(MeshCache {
            geom,
            nodes: self.nodes - m.nodes_before,
        });
        Result_::Geometry(geom)
    }

    /// What a closed IndexedFaceSet is: a sphere (see "Tessellated spheres") or other geometry.
    fn mesh_geom(&mut self, m: &MeshState, at: u64) -> Geom {
        // (Only a Shape's geometry is drawn: elsewhere it counts as skipped.)
        let shape = self.open.in_shape_geometry();
        let fit = m.coord.and_then(|c| {
            let used = m.index.as_deref().is_some_and(|ix| uses_all(ix, c.points));
            c.sphere.filter(|_| shape && used && !m.colored)
        });
        let geom = match fit {
            Some(i) => Geom::Mesh(i, at),
            None => Geom::Other,
        };
        self.count_mesh(geom);
        geom
    }

    fn count_mesh(&mut self, geom: Geom) {
        if let Geom::Mesh(..) = geom {
            self.meshes.spheres += 1;
        } else {
            self.diags.skip("IndexedFaceSet");
        }
    }

    /// Whether a USE of the recording at `start` is of an IndexedFaceSet as a Shape's
    /// geometry (lowered once, then looked up).
    pub(super) fn is_mesh_use(&self, start: usize) -> bool {
        self.open.in_shape_geometry()
            && matches!(&self.rec.arena[start],
                Rec::Ev(OwnedEvent::NodeStart { ty, .. }) if &**ty == "IndexedFaceSet")
    }

    /// A USE of the IndexedFaceSet recorded at `start`, if what it lowers to is known: counted
    /// and delivered without replaying it. Says whether it was.
    pub(super) fn reuse_mesh(
        &mut self,
        src: &SourceWindow,
        start: usize,
        at: u64,
    ) -> Result<bool, Error> {
        if let Some(c) = self.meshes.cache.get(&start).copied() {
            self.add_nodes(c.nodes, src, at)?;
            self.count_mesh(c.geom);
            self.deliver(Result_::Geometry(c.geom));
            return Ok(true);
        }
        self.meshes.last = None;
        Ok(false)
    }

    /// After the first USE of the IndexedFaceSet recorded at `start` was replayed: keeps
    /// what it lowered to for the next USEs.
    pub(super) fn remember_mesh(&mut self, start: usize) {
        if let Some(c) = self.meshes.last.take() {
            self.meshes.cache.insert(start, c);
        }
    }
}
