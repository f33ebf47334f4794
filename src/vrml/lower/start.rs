//! The node table and `node_start`: what each standard node type is lowered to
//! ([`Lowered`], one entry per [`schema::NODES`] entry, built at compile time so that no node
//! type is matched by string), and where a starting node goes: a DEF starts a recording, a
//! node inside a PROTO declaration, a skipped node or a Switch choice opens a quiet frame, a
//! PROTO instance is recorded for expansion when it closes, and a modelled node opens a frame
//! of its [`Kind`] with the VRML97 defaults of its fields.

use glam::DVec3;

use super::meshes::{Grid, MeshKind};
use super::open::{Frame, Kind, Leaf};
use super::record::{Name, RecKind};
use super::transform::Marks;
use super::Lowerer;
use crate::error::Error;
use crate::geom::shapes::Solid;
use crate::scene::{DirectionalLight, LightScope, Material, PointLight, Viewpoint};
use crate::source::{Pos, SourceWindow};
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

impl Lowerer {
    pub(super) fn node_start(
        &mut self,
        src: &SourceWindow,
        def: Option<&str>,
        ty: &str,
        at: Pos,
    ) -> Result<(), Error> {
        let def_rc: Option<std::rc::Rc<str>> = def.map(std::rc::Rc::from);
        if self.rec.proto_decls > 0 {
            return Ok(());
        }
        if let (Some(d), 0) = (&def_rc, self.replay.reusing) {
            // Record the DEF'd node (this NodeStart was pushed just before, if recording).
            self.rec.start_def(d, ty, at);
            self.scopes.open_def(d);
        }
        self.cx.add_nodes(1, src, at)?;
        let index = schema::node_index(ty);
        let spec = index.map(|i| &schema::NODES[i]);
        // A standard type was found by this very name.
        let ty_rc = match spec {
            Some(s) => Name::Static(s.name),
            None => Name::Shared(self.rec.names.rc(ty)),
        };
        if self.open.quiet > 0 {
            // Not lowered; a frame keeps the nesting.
            self.open.push(ty_rc, None, Kind::Quiet, at);
            return Ok(());
        }
        self.check_child(src, ty, at);
        // Where does this node stand? (A Switch choice, an LOD level after the first, or a
        // Collision proxy is recorded or ignored, not lowered.)
        let (in_choice, ignored_level) = match self.open.fields.last() {
            None => (false, false),
            Some(ctx) => match &mut self.open.frames[ctx.frame].kind {
                Kind::Switch { .. } => (&*ctx.name == "choice", false),
                Kind::Lod { levels, .. } if &*ctx.name == "level" => {
                    let ignored = *levels > 0;
                    *levels += 1;
                    (false, ignored)
                }
                Kind::Group { .. } => (false, &*ctx.name == "proxy"),
                Kind::Mesh(_) => {
                    self.mesh_child(ty_rc, at);
                    return Ok(());
                }
                _ => (false, false),
            },
        };
        if in_choice || ignored_level {
            if in_choice && !self.rec.in_choice() {
                self.rec.start_here(&ty_rc, def, at, RecKind::Choice);
            }
            self.open.push_quiet(ty_rc, at);
            return Ok(());
        }
        let proto = if index.is_none() || self.scopes.proto_shadows_standard {
            self.scopes.proto(ty)
        } else {
            None
        };
        if let Some(proto) = proto {
            if proto.body.is_some() {
                // Read the instance into its template, or record it and expand it when it
                // closes.
                if !self.start_direct(&proto, &ty_rc, def, at) {
                    self.rec.start_here(&ty_rc, def, at, RecKind::Instance);
                }
            } else {
                self.cx.diags.skip(ty);
                self.cx.diags.warn(
                    src,
                    at,
                    format!(
                        "EXTERNPROTO {ty} is not available (none of its urls was loaded): skipped"
                    ),
                );
            }
            self.open.push_suppressing(Frame {
                ty: ty_rc,
                spec: None,
                proto: Some(proto),
                kind: Kind::Quiet,
                at,
                quiet: true,
            });
            return Ok(());
        }
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
                self.open_mesh(ty_rc, at, kind);
                return Ok(());
            }
            Lowered::PointLight => Kind::PointLight(Box::new(PointLight {
                origin: self.cx.origin(at),
                ..PointLight::default()
            })),
            // The scope is set when the light's grouping node closes.
            Lowered::DirectionalLight => Kind::DirectionalLight(Box::new(DirectionalLight {
                scope: LightScope::Range { start: 0, end: 0 },
                surface_scope: LightScope::Range { start: 0, end: 0 },
                origin: self.cx.origin(at),
                ..DirectionalLight::default()
            })),
            Lowered::Viewpoint => Kind::Viewpoint(Box::new(Viewpoint {
                name: def.map(str::to_string),
                origin: self.cx.origin(at),
                ..Viewpoint::default()
            })),
            Lowered::NavigationInfo => Kind::NavigationInfo { headlight: None },
            Lowered::Background => Kind::Background { sky: None },
            // A Coordinate is read only in an IndexedFaceSet's `coord` (see `mesh_child`).
            Lowered::Skipped | Lowered::Coordinate => {
                // Standard nodes we do not model are counted in the report, not warned about:
                // they are valid VRML, and `--strict` is about validity.
                if spec.is_none() {
                    self.cx
                        .diags
                        .warn(src, at, format!("unknown node type '{ty}': skipped"));
                }
                self.cx.diags.skip(ty);
                self.open.push_suppressing(Frame {
                    ty: ty_rc,
                    spec,
                    proto: None,
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

    /// Warns when a node type does not belong in the field it stands in.
    #[inline(always)]
    pub(super) fn check_child(&mut self, src: &SourceWindow, ty: &str, at: Pos) {
        let Some(ctx) = self.open.fields.last() else {
            return;
        };
        let parent = &self.open.frames[ctx.frame];
        let allowed: &[&str] = match (&parent.kind, &*ctx.name) {
            (Kind::Leaf(Leaf::Shape { .. }), "appearance") => &["Appearance"],
            (Kind::Leaf(Leaf::Appearance { .. }), "material") => &["Material"],
            _ => return,
        };
        if !allowed.contains(&ty) && self.scopes.proto(ty).is_none() {
            let msg = format!(
                "{ty} is not allowed in field '{}' of {}: ignored",
                ctx.name, parent.ty
            );
            self.cx.diags.warn(src, at, msg);
        }
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
