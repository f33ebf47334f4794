//! The open nodes: a stack of [`Frame`]s, one per node whose `}` has not been read, and a
//! stack of the node-valued fields being filled ([`FieldCtx`]). A frame's [`Kind`] is what the
//! node is being lowered to, holding the field values read so far; grouping kinds remember
//! the [`Marks`] of the IR when they opened, so that their matrix and light scope apply to
//! what was lowered since. Frames are pushed and popped for every node, so they are kept
//! within 128 bytes (large, rare payloads are boxed) and names borrow the standard tables'
//! strings when they can ([`Name`]).

use std::ops::Range;
use std::rc::Rc;

use glam::DVec3;

use super::lights::DirLights;
use super::meshes::{Array, Geom, MeshState};
use super::transform::{Marks, TransformFields};
use crate::scene::{DirectionalLight, Paint, PointLight, Viewpoint};
use crate::source::Pos;
use crate::vrml::schema;

/// A node type or field name held while its node is open: the standard tables' own string
/// when there is one (no allocation per node), a shared copy otherwise.
#[derive(Clone, Debug)]
pub(in crate::vrml::lower) enum Name {
    Static(&'static str),
    Shared(Rc<str>),
}

impl std::ops::Deref for Name {
    type Target = str;
    #[inline]
    fn deref(&self) -> &str {
        match self {
            Name::Static(s) => s,
            Name::Shared(s) => s,
        }
    }
}

impl std::fmt::Display for Name {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self)
    }
}

/// The nodes that are closed in place, without moving their frame out (most nodes of a
/// particle file: see `close`). Small and `Copy`.
#[derive(Clone, Copy, Debug)]
pub(in crate::vrml::lower) enum Leaf {
    Shape {
        appearance: Option<Option<Paint>>,
        geometry: Option<Geom>,
    },
    Appearance {
        material: Option<Paint>,
    },
    /// Its fields are the top of `Materials::open`.
    Material,
    Sphere {
        radius: f64,
    },
    /// Box, Cylinder, Cone: its fields are `Meshes::solids[i]` (frames stay small).
    Solid(u32),
}

/// What an open node is lowered to. Large, rare payloads are boxed and a Material's fields
/// live on `Materials::open`, so that a [`Frame`] stays within 128 bytes.
#[derive(Debug)]
pub(in crate::vrml::lower) enum Kind {
    /// Group, Transform, Anchor, Billboard, Collision, Inline, and each file's root.
    Group {
        transform: Option<Box<TransformFields>>,
        marks: Marks,
        dirlights: DirLights,
        inline_urls: Option<Box<[String]>>,
    },
    Switch {
        which: i64,
        choices: Vec<Range<usize>>,
        marks: Marks,
        dirlights: DirLights,
    },
    Lod {
        levels: u32,
        marks: Marks,
        dirlights: DirLights,
    },
    /// Shape, Appearance, Material, Sphere.
    Leaf(Leaf),
    /// An IndexedFaceSet or PointSet (see `mesh_shape`).
    Mesh(Box<MeshState>),
    /// A Coordinate, Color or Normal in a mesh's field: the slot of `Meshes::arrays` it fills.
    MeshArray(Array, u32),
    PointLight(Box<PointLight>),
    DirectionalLight(Box<DirectionalLight>),
    Viewpoint(Box<Viewpoint>),
    NavigationInfo {
        headlight: Option<bool>,
    },
    Background {
        sky: Option<DVec3>,
    },
    /// Not modelled: its contents are read (DEFs inside stay usable) but not lowered.
    Skip,
    /// Recorded, not lowered (PROTO instance, Switch choice, ignored LOD level or proxy).
    Quiet,
}

/// An open node.
#[derive(Debug)]
pub(in crate::vrml::lower) struct Frame {
    pub(in crate::vrml::lower) ty: Name,
    pub(in crate::vrml::lower) spec: Option<&'static schema::NodeSpec>,
    pub(in crate::vrml::lower) kind: Kind,
    pub(in crate::vrml::lower) at: Pos,
    /// This frame started a suppression (contents are not lowered).
    pub(in crate::vrml::lower) quiet: bool,
}

/// What a closed node hands to the field it stands in.
pub(in crate::vrml::lower) enum Result_ {
    Nothing,
    Material(Paint),
    Appearance(Option<Paint>),
    Geometry(Geom),
    MeshArray(Array, u32),
}

/// The node-valued field being filled, with the frame index that owns it.
#[derive(Debug)]
pub(in crate::vrml::lower) struct FieldCtx {
    pub(in crate::vrml::lower) name: Name,
    pub(in crate::vrml::lower) frame: usize,
}

/// The open nodes and node-valued fields, innermost last.
#[derive(Default)]
pub(in crate::vrml::lower) struct Open {
    pub(in crate::vrml::lower) frames: Vec<Frame>,
    pub(in crate::vrml::lower) fields: Vec<FieldCtx>,
    /// Open frames that suppress lowering (Skip / Quiet frames, PROTO declarations).
    pub(in crate::vrml::lower) quiet: u32,
}

impl Open {
    /// Pushes a frame of `kind` for a node of type `ty` (lowered, not suppressing).
    #[inline(always)]
    pub(in crate::vrml::lower) fn push(
        &mut self,
        ty: Name,
        spec: Option<&'static schema::NodeSpec>,
        kind: Kind,
        at: Pos,
    ) {
        self.frames.push(Frame {
            ty,
            spec,
            kind,
            at,
            quiet: false,
        });
    }

    /// Pushes a frame that suppresses lowering of its contents (`frame.quiet` is set).
    pub(in crate::vrml::lower) fn push_suppressing(&mut self, frame: Frame) {
        debug_assert!(frame.quiet);
        self.frames.push(frame);
        self.quiet += 1;
    }

    /// Pops the innermost frame as its node closes, undoing what [`Self::push_suppressing`]
    /// counted.
    pub(in crate::vrml::lower) fn pop_closing(&mut self) -> Frame {
        let frame = self.frames.pop().expect("a node closes while one is open");
        if frame.quiet {
            self.quiet -= 1;
        }
        frame
    }

    /// Pushes a frame whose contents are recorded or ignored, not lowered.
    pub(in crate::vrml::lower) fn push_quiet(&mut self, ty: Name, at: Pos) {
        self.push_suppressing(Frame {
            ty,
            spec: None,
            kind: Kind::Quiet,
            at,
            quiet: true,
        });
    }

    /// The type of the innermost open node (for messages).
    pub(in crate::vrml::lower) fn open_type(&self) -> Name {
        self.frames
            .last()
            .map_or(Name::Static(""), |f| f.ty.clone())
    }

    /// Whether the node starting now stands in a Shape's `geometry` field.
    pub(in crate::vrml::lower) fn in_shape_geometry(&self) -> bool {
        self.fields.last().is_some_and(|ctx| {
            &*ctx.name == "geometry"
                && matches!(self.frames[ctx.frame].kind, Kind::Leaf(Leaf::Shape { .. }))
        })
    }

    /// The DirectionalLights of the innermost open grouping node (the scope of a
    /// DirectionalLight closing now).
    pub(in crate::vrml::lower) fn innermost_dirlights(&mut self) -> Option<&mut DirLights> {
        self.frames
            .iter_mut()
            .rev()
            .find_map(|f| match &mut f.kind {
                Kind::Group { dirlights, .. }
                | Kind::Switch { dirlights, .. }
                | Kind::Lod { dirlights, .. } => Some(dirlights),
                _ => None,
            })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn open_node_frames_stay_small() {
        // Frames are pushed and popped for every node; up to 128 bytes they are moved inline.
        assert!(std::mem::size_of::<Frame>() <= 128);
    }
}
