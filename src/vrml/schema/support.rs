//! What gtsphere does with each standard node type and each member of its interface, as data
//! next to the interfaces themselves: [`SUPPORT`] has one [`NodeSupport`] per entry of
//! [`NODES`], in the same order, and each node that gtsphere reads lists every member of its
//! interface in declaration order with its VRML97 default and what becomes of a value
//! ([`FieldRole`]). [`support_markdown`] turns the two tables into the page `docs/vrml.md`;
//! a test (`vrml/tests/vrml_support.rs`) fails when that file differs from it, and the tests
//! below fail when a node or member of [`NODES`] is not classified here. Built only for the
//! tests: the reader itself does not consult the tables.
//!
//! The tables describe the lowering (`crate::vrml::lower`): which node types it models and
//! which fields it stores. `vrml/tests/vrml_support.rs` checks them against it by loading
//! scenes: skipped nodes are counted as skipped, unknown names and events warn where the table says,
//! a default given explicitly changes nothing, and an ignored field changes nothing either.

use std::fmt::Write as _;

use super::{NodeSpec, NODES};

/// How gtsphere reads a standard node type.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum NodeRole {
    /// Lowered into the scene (drawn, or used for the camera, the lights or the background),
    /// its fields checked against its interface: an unknown name or a value given to an event
    /// is a warning, a value of the wrong type an error.
    Used,
    /// Drawn as a Shape's geometry, its fields read leniently without the interface: an
    /// unknown name, an event or a value of another type is passed over without a warning
    /// (IndexedFaceSet, PointSet, ElevationGrid, Extrusion).
    Mesh,
    /// Read, leniently, only in the field of a mesh that takes it (Coordinate, Color,
    /// Normal); anywhere else skipped.
    MeshPart,
    /// Not modelled: counted in the load report's `skipped`, without a warning; nothing in it
    /// is drawn and its fields are not read.
    Skipped,
}

/// What gtsphere does with a member of a node's interface.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum FieldRole {
    /// The value goes into the scene.
    Used,
    /// Read and checked against the field's type, then dropped without a warning.
    Ignored,
    /// Passed over: no type check, no warning.
    NotRead,
    /// An eventIn or eventOut: it takes no value in a file. A value given to one is a
    /// warning where the node's fields are checked ([`NodeRole::Used`]), passed over
    /// otherwise; ROUTEs to and from it are checked, not run.
    Event,
}

/// What gtsphere does with one member of a node's interface.
#[derive(Debug)]
pub struct FieldSupport {
    /// The member's name, as in the node's [`NodeSpec`].
    pub name: &'static str,
    /// What becomes of a value.
    pub role: FieldRole,
    /// The VRML97 default as written in a file (`0 0 1 0`, `[]`, `NULL`); empty for events.
    pub default: &'static str,
    /// More about what happens (limits, warnings, refusals); empty or whole sentences.
    pub note: &'static str,
}

/// What gtsphere does with one standard node type.
#[derive(Debug)]
pub struct NodeSupport {
    /// The node type's name, as in [`NODES`].
    pub name: &'static str,
    /// How it is read.
    pub role: NodeRole,
    /// What it becomes, in whole sentences.
    pub summary: &'static str,
    /// Every member of its interface in declaration order; empty for a
    /// [`NodeRole::Skipped`] node, whose fields are not read.
    pub fields: &'static [FieldSupport],
}

impl NodeSupport {
    /// The node's interface ([`NODES`] entry of the same name).
    pub fn spec(&self) -> Option<&'static NodeSpec> {
        super::node_spec(self.name)
    }

    /// What happens to the member `name` of this node: its entry's role, [`FieldRole::NotRead`]
    /// for any member of a skipped node; None for a name the node's interface lacks.
    pub fn field_role(&self, name: &str) -> Option<FieldRole> {
        let spec = self.spec()?.field(name)?;
        match self.role {
            NodeRole::Skipped => Some(FieldRole::NotRead),
            _ => self
                .fields
                .iter()
                .find(|f| f.name == spec.name)
                .map(|f| f.role),
        }
    }
}

/// The entry of the standard node type named `name`.
pub fn node_support(name: &str) -> Option<&'static NodeSupport> {
    super::node_index(name).map(|i| &SUPPORT[i])
}

const fn used(name: &'static str, default: &'static str, note: &'static str) -> FieldSupport {
    FieldSupport {
        name,
        role: FieldRole::Used,
        default,
        note,
    }
}

const fn ignored(name: &'static str, default: &'static str, note: &'static str) -> FieldSupport {
    FieldSupport {
        name,
        role: FieldRole::Ignored,
        default,
        note,
    }
}

const fn not_read(name: &'static str, default: &'static str, note: &'static str) -> FieldSupport {
    FieldSupport {
        name,
        role: FieldRole::NotRead,
        default,
        note,
    }
}

const fn event(name: &'static str, note: &'static str) -> FieldSupport {
    FieldSupport {
        name,
        role: FieldRole::Event,
        default: "",
        note,
    }
}

const fn node(
    name: &'static str,
    role: NodeRole,
    summary: &'static str,
    fields: &'static [FieldSupport],
) -> NodeSupport {
    NodeSupport {
        name,
        role,
        summary,
        fields,
    }
}

const fn skipped(name: &'static str, summary: &'static str) -> NodeSupport {
    node(name, NodeRole::Skipped, summary, &[])
}

mod markdown;
mod table;
pub use markdown::support_markdown;
pub use table::SUPPORT;

#[cfg(test)]
mod tests;
