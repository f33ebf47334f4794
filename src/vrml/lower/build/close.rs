//! Closing nodes: what a node's frame becomes at its `}`. Leaves (Shape, Appearance,
//! Material, Sphere: most nodes of a particle file) are closed in place without moving their
//! frame out; grouping nodes apply their matrix and light scope to what was lowered inside
//! them; and a closed node hands its result ([`Result_`]) to the field it stands in.

use glam::{DAffine3, DVec3};

use super::meshes::Geom;
use super::open::{Frame, Kind, Leaf, Result_};
use super::Builder;
use crate::error::Error;
use crate::geom::shapes::Solid;
use crate::scene::{Paint, Sphere, Surface, SurfaceShape};
use crate::source::{Pos, SourceWindow};
use crate::vrml::lower::context::Ctx;

/// The first NavigationInfo and Background are bound; later ones are ignored.
#[derive(Default)]
pub(in crate::vrml::lower) struct Bound {
    pub(in crate::vrml::lower) navigation_info: bool,
    pub(in crate::vrml::lower) background: bool,
}

impl Builder {
    /// Hands a closed node's result to the field it stands in.
    pub(in crate::vrml::lower) fn deliver(&mut self, result: Result_) {
        let Some(ctx) = self.open.fields.last() else {
            return;
        };
        let frame = &mut self.open.frames[ctx.frame];
        match (&mut frame.kind, &*ctx.name, result) {
            (Kind::Leaf(Leaf::Shape { appearance, .. }), "appearance", Result_::Appearance(m)) => {
                *appearance = Some(m)
            }
            (Kind::Leaf(Leaf::Shape { geometry, .. }), "geometry", Result_::Geometry(g)) => {
                *geometry = Some(g)
            }
            (Kind::Leaf(Leaf::Appearance { material }), "material", Result_::Material(m)) => {
                *material = Some(m)
            }
            // (Coordinate frames open only in an IndexedFaceSet's `coord`.)
            (Kind::Mesh(m), _, Result_::MeshArray(which, slot)) => {
                Builder::take_array(m, which, slot)
            }
            _ => {}
        }
    }

    /// Closes the innermost node in place if it is a leaf: what `close` does for it, without
    /// moving the frame out (these are most nodes).
    #[inline(always)]
    pub(in crate::vrml::lower) fn close_top_leaf(&mut self, cx: &mut Ctx) -> Option<Result_> {
        let frame = self.open.frames.last()?;
        let Kind::Leaf(leaf) = frame.kind else {
            return None;
        };
        let at = frame.at;
        self.open.frames.truncate(self.open.frames.len() - 1);
        Some(self.close_leaf(cx, leaf, at))
    }

    /// What a leaf node lowers to when it closes (a Shape: a sphere, if its geometry is one).
    #[inline(always)]
    fn close_leaf(&mut self, cx: &mut Ctx, leaf: Leaf, at: Pos) -> Result_ {
        match leaf {
            Leaf::Shape {
                appearance,
                geometry,
            } => {
                self.shape_geometry(cx, appearance, geometry);
                Result_::Nothing
            }
            Leaf::Appearance { material } => Result_::Appearance(material),
            Leaf::Material => Result_::Material(self.close_material()),
            Leaf::Sphere { radius } => Result_::Geometry(Geom::Sphere(radius, at)),
            Leaf::Solid(s) => Result_::Geometry(Geom::Solid(s, at)),
        }
    }

    /// What a node lowers to when it closes. (An Inline, and a Switch with a choice to show,
    /// are the expander's: they read a file or replay a recording first.)
    pub(in crate::vrml::lower) fn close(
        &mut self,
        cx: &mut Ctx,
        src: &SourceWindow,
        frame: Frame,
    ) -> Result<Result_, Error> {
        let at = frame.at;
        Ok(match frame.kind {
            Kind::Switch {
                which, ref choices, ..
            } => {
                let n = choices.len();
                if which >= 0 && which as usize >= n {
                    cx.diags.warn(
                        src,
                        at,
                        format!(
                            "Switch whichChoice {which} is out of range (0..{n}): nothing shown"
                        ),
                    );
                }
                self.close_group_like(cx, src, frame.kind, at)?;
                Result_::Nothing
            }
            k @ (Kind::Group { .. } | Kind::Lod { .. }) => {
                self.close_group_like(cx, src, k, at)?;
                Result_::Nothing
            }
            Kind::Leaf(leaf) => self.close_leaf(cx, leaf, at),
            Kind::Mesh(m) => self.close_mesh(cx, src, &m, at)?,
            Kind::MeshArray(which, slot) => Result_::MeshArray(which, slot),
            Kind::PointLight(l) => {
                self.close_point_light(*l);
                Result_::Nothing
            }
            Kind::DirectionalLight(l) => {
                self.close_directional_light(cx, src, *l, at);
                Result_::Nothing
            }
            Kind::Viewpoint(v) => {
                self.scene.viewpoints.push(*v);
                Result_::Nothing
            }
            Kind::NavigationInfo { headlight } => {
                if !self.bound.navigation_info {
                    self.scene.headlight = headlight.unwrap_or(true);
                    self.bound.navigation_info = true;
                }
                Result_::Nothing
            }
            Kind::Background { sky } => {
                if !self.bound.background {
                    self.scene.background = sky.unwrap_or(DVec3::ZERO);
                    self.bound.background = true;
                }
                Result_::Nothing
            }
            Kind::Skip | Kind::Quiet => Result_::Nothing,
        })
    }

    /// Closes a grouping node: its matrix applies to everything lowered since it opened, and
    /// its DirectionalLights light exactly that range.
    pub(in crate::vrml::lower) fn close_group_like(
        &mut self,
        cx: &mut Ctx,
        src: &SourceWindow,
        kind: Kind,
        at: Pos,
    ) -> Result<(), Error> {
        let (transform, marks, dirlights) = match kind {
            Kind::Group {
                transform,
                marks,
                dirlights,
                ..
            } => (transform, marks, dirlights),
            Kind::Switch {
                marks, dirlights, ..
            }
            | Kind::Lod {
                marks, dirlights, ..
            } => (None, marks, dirlights),
            _ => return Ok(()),
        };
        self.scope_lights(marks, dirlights);
        let Some(t) = transform else {
            return Ok(());
        };
        let result = self.close_transform(cx, src, &t, marks, at);
        self.transforms.give_back(t);
        result
    }

    /// A closed Shape: a sphere if its geometry is one, in the object space of its Transforms.
    #[inline(always)]
    fn shape_geometry(
        &mut self,
        cx: &mut Ctx,
        appearance: Option<Option<Paint>>,
        geometry: Option<Geom>,
    ) {
        let paint = match appearance {
            Some(Some(m)) => m,
            _ => self.materials.unlit,
        };
        let (center, radius, sat) = match geometry {
            Some(Geom::Sphere(radius, sat)) => (DVec3::ZERO, radius, sat),
            Some(Geom::Solid(solid, sat)) => return self.shape_solid(cx, solid, paint, sat),
            Some(Geom::Mesh(i, sat)) => return self.shape_mesh(cx, i, paint, sat),
            _ => return,
        };
        self.scene.spheres.push(Sphere {
            center,
            radius,
            color: paint.color,
            material: paint.material,
            ellipsoid: None,
            origin: cx.origin(sat),
        });
    }

    /// A Shape whose geometry is a Box, Cylinder or Cone.
    #[cold]
    #[inline(never)]
    fn shape_solid(&mut self, cx: &mut Ctx, i: u32, paint: Paint, at: Pos) {
        let Some(&solid) = self.meshes.solids.get(i as usize) else {
            return;
        };
        if i as usize + 1 == self.meshes.solids.len() {
            // Read and drawn: the common case keeps the list short.
            self.meshes.solids.pop();
        }
        if cx.opts.spheres_only {
            cx.diags.skip(match solid {
                Solid::Cuboid { .. } => "Box",
                Solid::Cylinder { .. } => "Cylinder",
                Solid::Cone { .. } => "Cone",
            });
            return;
        }
        self.scene.surfaces.push(Surface {
            shape: SurfaceShape::Solid {
                solid,
                to_world: DAffine3::IDENTITY,
            },
            color: paint.color,
            material: paint.material,
            origin: cx.origin(at),
        });
    }

    /// A Shape whose geometry is a mesh: its spheres (coloured by the mesh where it gives
    /// colours) and its triangles.
    #[cold]
    #[inline(never)]
    fn shape_mesh(&mut self, cx: &mut Ctx, i: u32, paint: Paint, at: Pos) {
        let Some(parts) = self.mesh_parts_for_shape(i) else {
            return;
        };
        let origin = cx.origin(at);
        for &(center, radius, colour) in &parts.spheres {
            let color = match colour {
                Some(c) => self.scene.materials.add_color(c),
                None => paint.color,
            };
            self.scene.spheres.push(Sphere {
                center,
                radius,
                color,
                material: paint.material,
                ellipsoid: None,
                origin,
            });
        }
        self.scene
            .surfaces
            .extend(parts.triangles.into_iter().map(|t| Surface {
                shape: SurfaceShape::Triangle(Box::new(t)),
                color: paint.color,
                material: paint.material,
                origin,
            }));
    }
}
