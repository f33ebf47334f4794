//! A declared PROTO as the lowering keeps it: its interface, its body's events, and what is
//! compiled from it once, when it is declared (a sphere template, a `GasParticle`'s profile
//! fields). Only the data: `declare` fills it, `template` and `gas_particle` compile it,
//! `expand` and `direct` use it.

use std::ops::Range;
use std::rc::Rc;

use hashbrown::HashMap;

use super::build::sphere::MaterialField;
use super::record::Rec;
use crate::source::Pos;
use crate::vrml::schema::{Access, FieldType};

/// One member of a PROTO's interface.
#[derive(Clone, Debug)]
pub(super) struct InterfaceField {
    pub(super) access: Access,
    pub(super) ty: FieldType,
    pub(super) name: Rc<str>,
    /// The default value's events (one Field event, or NodesStart .. NodesEnd).
    pub(super) default: Option<Range<usize>>,
    /// Where it is declared (for the EXTERNPROTO interface checks).
    pub(super) at: Pos,
}

/// A declared PROTO or EXTERNPROTO.
#[derive(Clone, Debug)]
pub(super) struct ProtoDecl {
    pub(super) name: Rc<str>,
    pub(super) fields: Vec<InterfaceField>,
    /// Body events (PROTO only); None for EXTERNPROTO.
    pub(super) body: Option<Range<usize>>,
    /// A copy of the body's events, replayed for each instance without cloning each event
    /// out of the arena (USEs in it still name arena ranges, which stay pinned).
    pub(super) body_events: Rc<[Rec]>,
    /// For each body event `field IS target` outside nested PROTO declarations, the index of
    /// `target` among `fields` (`u32::MAX` for other events), so that instances do not look IS
    /// targets up by name (shared with the EXTERNPROTOs that name this PROTO).
    pub(super) body_is: Rc<[u32]>,
    /// How many body events an instance replays: up to the end of the body's first node
    /// (earlier PROTO declarations included).
    pub(super) first_end: usize,
    /// The body's first node compiled, when it is one sphere (see `template`).
    pub(super) sphere: Option<Rc<SphereTemplate>>,
    /// A `GasParticle` PROTO's profile fields (see `gas_particle`).
    pub(super) gas: Option<GasFields>,
    /// A PROTO reached through an EXTERNPROTO: which of `fields` an instance may set (those
    /// the EXTERNPROTO declares with the same access and type); `None`: all of them.
    pub(super) public: Option<Rc<[bool]>>,
    /// A PROTO reached through an EXTERNPROTO: the PROTOs of the file it was declared in,
    /// which its body sees instead of those around the instance (VRML97 4.9).
    pub(super) home: Option<Rc<Protos>>,
}

impl ProtoDecl {
    pub(super) fn field(&self, name: &str) -> Option<&InterfaceField> {
        self.fields.iter().find(|f| &*f.name == name)
    }
    /// The index of the first interface field of this name (what `IS` in the body names).
    pub(super) fn field_index(&self, name: &str) -> Option<usize> {
        self.fields.iter().position(|f| &*f.name == name)
    }
    /// [`Self::field_index`] if an instance may set that field (see [`Self::public`]).
    pub(super) fn public_index(&self, name: &str) -> Option<usize> {
        self.field_index(name)
            .filter(|&i| self.public.as_ref().is_none_or(|p| p[i]))
    }
    /// The interface field an instance (or a ROUTE) may use by this name.
    fn public_field(&self, name: &str) -> Option<&InterfaceField> {
        self.public_index(name).map(|i| &self.fields[i])
    }
    /// Resolves `set_x` and `x_changed` of an exposedField `x`, like the standard tables do.
    pub(super) fn event(&self, name: &str) -> Option<(&InterfaceField, Access)> {
        if let Some(f) = self.public_field(name) {
            return Some((f, f.access));
        }
        if let Some(base) = name.strip_prefix("set_") {
            if let Some(f) = self
                .public_field(base)
                .filter(|f| f.access == Access::ExposedField)
            {
                return Some((f, Access::EventIn));
            }
        }
        if let Some(base) = name.strip_suffix("_changed") {
            if let Some(f) = self
                .public_field(base)
                .filter(|f| f.access == Access::ExposedField)
            {
                return Some((f, Access::EventOut));
            }
        }
        None
    }
}

/// PROTO names and their declarations.
pub(super) type Protos = HashMap<Rc<str>, Rc<ProtoDecl>>;

/// A PROTO body whose first node is a Transform (translation only) holding one Shape whose
/// geometry is a Sphere; see the module's comment.
#[derive(Clone, Debug)]
pub(super) struct SphereTemplate {
    /// Where the body's Transform and Sphere start (what replaying reports and records).
    pub(super) transform_at: Pos,
    pub(super) sphere_at: Pos,
    pub(super) translation: Option<Slot>,
    /// `None`: no Appearance, or an Appearance without Material (the unlit material).
    pub(super) material: Option<Vec<(MaterialField, Slot)>>,
    pub(super) radius: Option<Slot>,
    /// Nodes of the first node (what replaying counts).
    pub(super) nodes: u64,
    /// What replaying spends of the expansion budget (see `Lowerer::spend`).
    pub(super) spent: u64,
}

/// Where one value of the template comes from.
#[derive(Clone, Debug)]
pub(super) enum Slot {
    /// Written in the body (checked against its field's type when compiled).
    Given([f64; 3]),
    /// `IS` this interface field: the instance's value, or the field's default.
    Is(u32),
}

/// Where a recognised `GasParticle` PROTO keeps its profile and width.
#[derive(Clone, Copy, Debug)]
pub(super) struct GasFields {
    pub(super) profile: usize,
    pub(super) width: Option<usize>,
}
