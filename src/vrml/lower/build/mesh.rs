//! IndexedFaceSet and PointSet while they are read: their fields are gathered leniently and
//! without a table (a value of another type is ignored, as for a skipped node), with the
//! `coord`, `color` and `normal` arrays of their Coordinate, Color and Normal children. What
//! a closed one becomes (spheres, triangles, particles) is decided in `mesh_shape`. What a
//! DEF'd one lowered to is cached at its first USE ([`Meshes::cache`]), so later USEs of a
//! Jmol atom or bond cost a lookup, not a replay of its events.

use glam::DVec3;

use super::meshes::{Array, Geom, MeshCache, MeshKind, MeshParts, MeshState, Meshes};
use super::open::Name;
use super::open::{Kind, Result_};
use super::Builder;
use crate::error::Error;
use crate::source::{Pos, SourceWindow};
use crate::vrml::lower::context::Ctx;
use crate::vrml::syntax::Value;

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
pub(in crate::vrml::lower) fn mesh_field(
    kind: &mut Kind,
    name: &str,
    value: &Value,
    meshes: &mut Meshes,
) {
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

impl Builder {
    /// An IndexedFaceSet or PointSet: its fields are read leniently (see `mesh_field`), with
    /// no table: as for a skipped node, none of them is checked or warned about.
    #[cold]
    #[inline(never)]
    pub(in crate::vrml::lower) fn open_mesh(
        &mut self,
        cx: &mut Ctx,
        ty: Name,
        at: Pos,
        kind: MeshKind,
    ) {
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
            nodes_before: cx.nodes - 1,
        }));
        self.open.push(ty, None, kind, at);
    }

    /// A node inside a mesh: its Coordinate, Color and Normal are read; other nodes are
    /// neither lowered nor counted (as when the mesh was skipped whole).
    #[cold]
    #[inline(never)]
    pub(in crate::vrml::lower) fn mesh_child(&mut self, ty: Name, at: Pos) {
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
    pub(in crate::vrml::lower) fn take_array(m: &mut MeshState, which: Array, slot: u32) {
        match which {
            Array::Coord => m.coord = Some(slot),
            Array::Color => m.color = Some(slot),
            Array::Normal => m.normal = Some(slot),
        }
    }

    /// A closed mesh: what it lowers to (see `mesh_shape`), kept for the Shape that draws it.
    pub(in crate::vrml::lower) fn close_mesh(
        &mut self,
        cx: &mut Ctx,
        src: &SourceWindow,
        m: &MeshState,
        at: Pos,
    ) -> Result<Result_, Error> {
        // (Only a Shape's geometry is drawn: elsewhere it counts as skipped.)
        let drawable = !m.malformed
            && match &m.kind {
                MeshKind::ElevationGrid(g) => g.x_dimension >= 2.0 && g.z_dimension >= 2.0,
                MeshKind::Extrusion(_) => true,
                _ => !self.meshes.array(m.coord).is_empty(),
            };
        let geom = if self.open.in_shape_geometry() && drawable {
            let parts = self.mesh_parts(cx, src, m, at)?;
            let i = self.meshes.parts.len() as u32;
            self.meshes.parts.push(Some(parts));
            Geom::Mesh(i, at)
        } else {
            cx.diags.skip(m.kind.name());
            Geom::Other
        };
        self.meshes.arrays.clear();
        self.meshes.last = Some(MeshCache {
            geom,
            nodes: cx.nodes - m.nodes_before,
        });
        Ok(Result_::Geometry(geom))
    }

    /// The parts of mesh `i` for a Shape: taken, unless the cache still needs them.
    pub(in crate::vrml::lower) fn mesh_parts_for_shape(&mut self, i: u32) -> Option<MeshParts> {
        let slot = self.meshes.parts.get_mut(i as usize)?;
        if self.meshes.kept.contains(&i) {
            slot.clone()
        } else {
            slot.take()
        }
    }

    /// A USE of the mesh recorded at `start`, if what it lowers to is known: counted and
    /// delivered without replaying it. Says whether it was.
    pub(in crate::vrml::lower) fn reuse_mesh(
        &mut self,
        cx: &mut Ctx,
        src: &SourceWindow,
        start: usize,
        at: Pos,
    ) -> Result<bool, Error> {
        if let Some(c) = self.meshes.cache.get(&start).copied() {
            cx.add_nodes(c.nodes, src, at)?;
            if let Geom::Mesh(i, _) = c.geom {
                if let Some(Some(p)) = self.meshes.parts.get(i as usize) {
                    let (spheres, points) = (p.mesh_spheres(), p.point_spheres());
                    // The copies of its spheres and triangles the Shape will add.
                    let items = (p.spheres.len() + p.triangles.len()) as u64;
                    cx.spend(items, src, at, "USE of a mesh")?;
                    self.meshes.spheres += spheres;
                    self.meshes.point_spheres += points;
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
    pub(in crate::vrml::lower) fn remember_mesh(&mut self, start: usize) {
        if let Some(c) = self.meshes.last.take() {
            if let Geom::Mesh(i, _) = c.geom {
                self.meshes.kept.insert(i);
            }
            self.meshes.cache.insert(start, c);
        }
    }
}
