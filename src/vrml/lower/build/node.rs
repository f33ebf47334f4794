//! The node table and what a node opens as: what each standard node type is lowered to
//! ([`Lowered`], one entry per [`schema::NODES`] entry, built at compile time so that no node
//! type is matched by string), and the frame a modelled node opens, of its [`Kind`] with the
//! VRML97 defaults of its fields; a node not modelled opens a frame that suppresses what it
//! holds.

use glam::DVec3;

use super::meshes::{Grid, MeshKind};
use super::open::{Frame, Kind, Leaf, Name};
use super::transform::Marks;
use super::Builder;
use crate::error::Error;
use crate::geom::shapes::Solid;
use crate::scene::{DirectionalLight, LightScope, Material, PointLight, Viewpoint};
use crate::source::{Pos, SourceWindow};
use crate::vrml::lower::context::Ctx;
use crate::vrml::schema;
/// What a standard node type lowers to.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Lowered {
    Group,
    Transform,
    Inline,
    Switch,
    Lod,
    Shape,
    Appearance,
    Material,
    Sphere,
    Cuboid,
    Cylinder,
    Cone,
    IndexedFaceSet,
    PointSet,
    ElevationGrid,
    Extrusion,
    Coordinate,
    PointLight,
    DirectionalLight,
    Viewpoint,
    NavigationInfo,
    Background,
    /// Not modelled: counted and skipped.
    Skipped,
}

const fn same_str(a: &str, b: &str) -> bool {
    let (a, b) = (a.as_bytes(), b.as_bytes());
    if a.len() != b.len() {
        return false;
    }
    let mut i = 0;
    while i < a.len() {
        if a[i] != b[i] {
            return false;
        }
        i += 1;
    }
    true
}

const fn lowered_as(name: &str) -> Lowered {
    const MODELLED: [(&str, Lowered); 25] = [
        ("Group", Lowered::Group),
        ("Anchor", Lowered::Group),
        ("Billboard", Lowered::Group),
        ("Collision", Lowered::Group),
        ("Transform", Lowered::Transform),
        ("Inline", Lowered::Inline),
        ("Switch", Lowered::Switch),
        ("LOD", Lowered::Lod),
        ("Shape", Lowered::Shape),
        ("Appearance", Lowered::Appearance),
        ("Material", Lowered::Material),
        ("Sphere", Lowered::Sphere),
        ("Box", Lowered::Cuboid),
        ("Cylinder", Lowered::Cylinder),
        ("Cone", Lowered::Cone),
        ("IndexedFaceSet", Lowered::IndexedFaceSet),
        ("PointSet", Lowered::PointSet),
        ("ElevationGrid", Lowered::ElevationGrid),
        ("Extrusion", Lowered::Extrusion),
        ("Coordinate", Lowered::Coordinate),
        ("PointLight", Lowered::PointLight),
        ("DirectionalLight", Lowered::DirectionalLight),
        ("Viewpoint", Lowered::Viewpoint),
        ("NavigationInfo", Lowered::NavigationInfo),
        ("Background", Lowered::Background),
    ];
    let mut i = 0;
    while i < MODELLED.len() {
        if same_str(MODELLED[i].0, name) {
            return MODELLED[i].1;
        }
        i += 1;
    }
    Lowered::Skipped
}

/// [`Lowered`] for each entry of [`schema::NODES`], by index (no string matching per node).
static LOWERED: [Lowered; schema::NODES.len()] = {
    let mut t = [Lowered::Skipped; schema::NODES.len()];
    let mut i = 0;
    while i < t.len() {
        t[i] = lowered_as(schema::NODES[i].name);
        i += 1;
    }
    t
};

impl Builder {
    /// Opens a frame for a node of type `ty` (the standard node `index` of
    /// [`schema::NODES`], if it is one) that is lowered here: not a PROTO instance and not
    /// inside a node that is not lowered.
    pub(in crate::vrml::lower) fn open_node(
        &mut self,
        cx: &mut Ctx,
        src: &SourceWindow,
        (index, ty_rc): (Option<usize>, Name),
        def: Option<&str>,
        at: Pos,
    ) -> Result<(), Error> {
        let ty: &str = &ty_rc;
        let spec = index.map(|i| &schema::NODES[i]);
        let m = Marks::of(&self.scene);
        let group = |transform| Kind::Group {
            transform,
            marks: m,
            dirlights: None,
            inline_urls: None,
        };
        let lowered = index.map_or(Lowered::Skipped, |i| LOWERED[i]);
        let kind = match lowered {
            Lowered::Group => group(None),
            Lowered::Transform => group(Some(self.transforms.take())),
            Lowered::Inline => Kind::Group {
                transform: None,
                marks: m,
                dirlights: None,
                inline_urls: Some(Box::default()),
            },
            Lowered::Switch => Kind::Switch {
                which: -1,
                choices: Vec::new(),
                marks: m,
                dirlights: None,
            },
            Lowered::Lod => Kind::Lod {
                levels: 0,
                marks: m,
                dirlights: None,
            },
            Lowered::Shape => Kind::Leaf(Leaf::Shape {
                appearance: None,
                geometry: None,
            }),
            Lowered::Appearance => Kind::Leaf(Leaf::Appearance { material: None }),
            Lowered::Material => {
                self.materials.open.push(Material::default());
                Kind::Leaf(Leaf::Material)
            }
            Lowered::Sphere => Kind::Leaf(Leaf::Sphere { radius: 1.0 }),
            Lowered::Cuboid => self.open_solid(Solid::Cuboid { half: DVec3::ONE }),
            Lowered::Cylinder => self.open_solid(Solid::Cylinder {
                radius: 1.0,
                half_height: 1.0,
                bottom: true,
                side: true,
                top: true,
            }),
            Lowered::Cone => self.open_solid(Solid::Cone {
                radius: 1.0,
                half_height: 1.0,
                side: true,
                bottom: true,
            }),
            Lowered::IndexedFaceSet
            | Lowered::PointSet
            | Lowered::ElevationGrid
            | Lowered::Extrusion => {
                let kind = match lowered {
                    Lowered::PointSet => MeshKind::PointSet,
                    Lowered::ElevationGrid => MeshKind::ElevationGrid(Grid {
                        x_spacing: 1.0,
                        z_spacing: 1.0,
                        ..Grid::default()
                    }),
                    Lowered::Extrusion => MeshKind::Extrusion(Box::default()),
                    _ => MeshKind::IndexedFaceSet,
                };
                self.open_mesh(cx, ty_rc, at, kind);
                return Ok(());
            }
            Lowered::PointLight => Kind::PointLight(Box::new(PointLight {
                origin: cx.origin(at),
                ..PointLight::default()
            })),
            // The scope is set when the light's grouping node closes.
            Lowered::DirectionalLight => Kind::DirectionalLight(Box::new(DirectionalLight {
                scope: LightScope::Range { start: 0, end: 0 },
                surface_scope: LightScope::Range { start: 0, end: 0 },
                origin: cx.origin(at),
                ..DirectionalLight::default()
            })),
            Lowered::Viewpoint => Kind::Viewpoint(Box::new(Viewpoint {
                name: def.map(str::to_string),
                origin: cx.origin(at),
                ..Viewpoint::default()
            })),
            Lowered::NavigationInfo => Kind::NavigationInfo { headlight: None },
            Lowered::Background => Kind::Background { sky: None },
            // A Coordinate is read only in an IndexedFaceSet's `coord` (see `mesh_child`).
            Lowered::Skipped | Lowered::Coordinate => {
                // Standard nodes we do not model are counted in the report, not warned about:
                // they are valid VRML, and `--strict` is about validity.
                if spec.is_none() {
                    cx.diags
                        .warn(src, at, format!("unknown node type '{ty}': skipped"));
                }
                cx.diags.skip(ty);
                self.open.push_suppressing(Frame {
                    ty: ty_rc,
                    spec,
                    kind: Kind::Skip,
                    at,
                    quiet: true,
                });
                return Ok(());
            }
        };
        self.open.push(ty_rc, spec, kind, at);
        Ok(())
    }

    /// A Box, Cylinder or Cone with VRML's defaults: its fields live in `Meshes::solids`.
    #[cold]
    #[inline(never)]
    fn open_solid(&mut self, s: Solid) -> Kind {
        self.meshes.solids.push(s);
        Kind::Leaf(Leaf::Solid(self.meshes.solids.len() as u32 - 1))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_modelled_type_is_a_standard_node() {
        let modelled: Vec<_> = schema::NODES
            .iter()
            .zip(LOWERED)
            .filter(|(_, l)| *l != Lowered::Skipped)
            .map(|(n, _)| n.name)
            .collect();
        assert_eq!(modelled.len(), 25, "{modelled:?}");
        assert_eq!(LOWERED[schema::node_index("LOD").unwrap()], Lowered::Lod);
        assert_eq!(LOWERED[schema::node_index("Box").unwrap()], Lowered::Cuboid);
        assert_eq!(
            LOWERED[schema::node_index("Text").unwrap()],
            Lowered::Skipped
        );
    }
}
