//! A declared PROTO as the lowering keeps it: its interface, its body's events, and what is
//! compiled from it once, when it is declared (a sphere template, a `GasParticle`'s profile
//! fields). Only the data: `declare` fills it, `template` and `gas_particle` compile it,
//! `instance` and `direct` use it.

use std::ops::Range;
use std::rc::Rc;

use hashbrown::HashMap;

use super::record::Rec;
use crate::source::Pos;
use crate::vrml::lower::build::sphere::MaterialField;
use crate::vrml::schema::{Access, FieldType};

/// One member of a PROTO's interface.
#[derive(Clone, Debug)]
pub(in crate::vrml::lower) struct InterfaceField {
    pub(in crate::vrml::lower) access: Access,
    pub(in crate::vrml::lower) ty: FieldType,
    pub(in crate::vrml::lower) name: Rc<str>,
    /// The default value's events (one Field event, or NodesStart .. NodesEnd).
    pub(in crate::vrml::lower) default: Option<Range<usize>>,
    /// Where it is declared (for the EXTERNPROTO interface checks).
    pub(in crate::vrml::lower) at: Pos,
}

/// A declared PROTO or EXTERNPROTO.
#[derive(Clone, Debug)]
pub(in crate::vrml::lower) struct ProtoDecl {
    pub(in crate::vrml::lower) name: Rc<str>,
    pub(in crate::vrml::lower) fields: Vec<InterfaceField>,
    /// Body events (PROTO only); None for EXTERNPROTO.
    pub(in crate::vrml::lower) body: Option<Range<usize>>,
    /// A copy of the body's events, replayed for each instance without cloning each event
    /// out of the arena (USEs in it still name arena ranges, which stay pinned).
    pub(in crate::vrml::lower) body_events: Rc<[Rec]>,
    /// For each body event `field IS target` outside nested PROTO declarations, the index of
    /// `target` among `fields` (`u32::MAX` for other events), so that instances do not look IS
    /// targets up by name (shared with the EXTERNPROTOs that name this PROTO).
    pub(in crate::vrml::lower) body_is: Rc<[u32]>,
    /// How many body events an instance replays: up to the end of the body's first node
    /// (earlier PROTO declarations included).
    pub(in crate::vrml::lower) first_end: usize,
    /// The body's first node compiled, when it is one sphere (see `template`).
    pub(in crate::vrml::lower) sphere: Option<Rc<SphereTemplate>>,
    /// A `GasParticle` PROTO's profile fields (see `gas_particle`).
    pub(in crate::vrml::lower) gas: Option<GasFields>,
    /// A PROTO reached through an EXTERNPROTO: which of `fields` an instance may set (those
    /// the EXTERNPROTO declares with the same access and type); `None`: all of them.
    pub(in crate::vrml::lower) public: Option<Rc<[bool]>>,
    /// A PROTO reached through an EXTERNPROTO: the PROTOs of the file it was declared in,
    /// which its body sees instead of those around the instance (VRML97 4.9).
    pub(in crate::vrml::lower) home: Option<Rc<Protos>>,
}

impl ProtoDecl {
    pub(in crate::vrml::lower) fn field(&self, name: &str) -> Option<&InterfaceField> {
        self.fields.iter().find(|f| &*f.name == name)
    }
    /// The index of the first interface field of this name (what `IS` in the body names).
    pub(in crate::vrml::lower) fn field_index(&self, name: &str) -> Option<usize> {
        self.fields.iter().position(|f| &*f.name == name)
    }
    /// [`Self::field_index`] if an instance may set that field (see [`Self::public`]).
    pub(in crate::vrml::lower) fn public_index(&self, name: &str) -> Option<usize> {
        self.field_index(name)
            .filter(|&i| self.public.as_ref().is_none_or(|p| p[i]))
    }
    /// The interface field an instance (or a ROUTE) may use by this name.
    fn public_field(&self, name: &str) -> Option<&InterfaceField> {
        self.public_index(name).map(|i| &self.fields[i])
    }
    /// Resolves `set_x` and `x_changed` of an exposedField `x`, like the standard tables do.
    pub(in crate::vrml::lower) fn event(&self, name: &str) -> Option<(&InterfaceField, Access)> {
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
pub(in crate::vrml::lower) type Protos = HashMap<Rc<str>, Rc<ProtoDecl>>;

/// A PROTO body whose first node is a Transform (translation only) holding one Shape whose
/// geometry is a Sphere; see the module's comment.
#[derive(Clone, Debug)]
pub(in crate::vrml::lower) struct SphereTemplate {
    /// Where the body's Transform and Sphere start (what replaying reports and records).
    pub(in crate::vrml::lower) transform_at: Pos,
    pub(in crate::vrml::lower) sphere_at: Pos,
    pub(in crate::vrml::lower) translation: Option<Slot>,
    /// `None`: no Appearance, or an Appearance without Material (the unlit material).
    pub(in crate::vrml::lower) material: Option<Vec<(MaterialField, Slot)>>,
    pub(in crate::vrml::lower) radius: Option<Slot>,
    /// Nodes of the first node (what replaying counts).
    pub(in crate::vrml::lower) nodes: u64,
    /// What replaying spends of the expansion budget (see `Expander::spend`).
    pub(in crate::vrml::lower) spent: u64,
}

/// Where one value of the template comes from.
#[derive(Clone, Debug)]
pub(in crate::vrml::lower) enum Slot {
    /// Written in the body (checked against its field's type when compiled).
    Given([f64; 3]),
    /// `IS` this interface field: the instance's value, or the field's default.
    Is(u32),
}

/// Where a recognised `GasParticle` PROTO keeps its profile and width.
#[derive(Clone, Copy, Debug)]
pub(in crate::vrml::lower) struct GasFields {
    pub(in crate::vrml::lower) profile: usize,
    pub(in crate::vrml::lower) width: Option<usize>,
}
