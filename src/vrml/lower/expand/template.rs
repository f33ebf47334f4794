//! Sphere templates: a PROTO whose body's first node is one sphere, the form `convert` writes
//! (`Transform { translation IS position children Shape { appearance Appearance { material
//! Material { diffuseColor IS color ... } } geometry Sphere { radius IS radius } } }`), is
//! compiled when it is declared into a [`SphereTemplate`]: where each value comes from (a
//! constant of the body or an interface field). An instance of it is then lowered by reading
//! its values and doing what replaying the body would do (the same node count, material
//! table, sphere and Transform, through the same functions), without replaying the body's
//! events one by one. Anything replaying would warn about or refuse (a transparency outside
//! [0, 1], a bad radius, a node limit or replay depth reached, a place where the body's
//! Transform would be out of place, an instance value that is itself an `IS`) sends the
//! instance down the replay instead, so the result is the replay's in every case
//! (`src/vrml/tests/proto_template.rs` compares the two). With [`super::direct`] it reads
//! `convert`'s files 4.0x (8-bit colours) to 4.2x (a colour per particle) as fast as replaying
//! (`gtsphere bench parse --layout proto --layout continuous`, with and without the hidden
//! `--replay-every-instance`).

use std::ops::Range;

use glam::DVec3;

use super::proto::{ProtoDecl, Slot, SphereTemplate};
use super::record::Rec;
use super::replay::MAX_REPLAY_DEPTH;
use super::Expander;
use crate::error::Error;
use crate::scene::Material;
use crate::source::{Pos, SourceWindow};
use crate::vrml::lower::build::sphere::{
    in_range, padded3, radius_ok, Inputs, MaterialField, Placed,
};
use crate::vrml::lower::build::Builder;
use crate::vrml::lower::context::Ctx;
use crate::vrml::sphere_node::SphereNode;
use crate::vrml::syntax::{OwnedEvent, OwnedValue};

/// Reads the body's first node as a template, if it is one.
pub(in crate::vrml::lower) fn compile(decl: &ProtoDecl) -> Option<SphereTemplate> {
    let n = decl.first_end;
    let events = &decl.body_events[..n];
    let mut m = Matcher {
        events,
        is: &decl.body_is[..n],
        k: 0,
        draft: Draft::default(),
    };
    let transform_at = m.node("Transform", Matcher::transform_member)?;
    let d = m.draft;
    if m.k != n {
        return None;
    }
    // Replaying counts each node as it starts.
    let nodes = events
        .iter()
        .filter(|r| matches!(r, Rec::Ev(OwnedEvent::NodeStart { .. })))
        .count() as u64;
    // And spends of the expansion budget: each node as it starts, each event (with the
    // numbers written in it), and each IS value (one, and the numbers of its slot).
    let written: u64 = events
        .iter()
        .map(|r| match r {
            Rec::Ev(ev) => crate::vrml::lower::event_cost(ev),
            Rec::Used { .. } => 0,
        })
        .sum();
    let slots = (d.translation.iter().map(|s| (s, 3)))
        .chain(d.radius.iter().map(|s| (s, 1)))
        .chain(d.material.iter().flatten().map(|(f, s)| (s, f.arity())));
    let is_values: u64 = slots
        .filter(|(s, _)| matches!(s, Slot::Is(_)))
        .map(|(_, arity)| 1 + arity as u64)
        .sum();
    Some(SphereTemplate {
        transform_at,
        sphere_at: d.sphere_at?,
        translation: d.translation,
        material: d.material,
        radius: d.radius,
        nodes,
        spent: nodes + written + is_values,
    })
}

/// What the matcher has found so far.
#[derive(Default)]
struct Draft {
    translation: Option<Slot>,
    /// Whether the Transform's Shape and the Shape's Appearance were met (each at most once).
    shape: bool,
    appearance: bool,
    material: Option<Vec<(MaterialField, Slot)>>,
    sphere_at: Option<Pos>,
    radius: Option<Slot>,
}

/// A cursor over the first node's events, and what it found.
struct Matcher<'a> {
    events: &'a [Rec],
    is: &'a [u32],
    k: usize,
    draft: Draft,
}

impl<'a> Matcher<'a> {
    fn next(&mut self) -> Option<&'a OwnedEvent> {
        let r = match self.events.get(self.k)? {
            Rec::Ev(ev) => ev,
            Rec::Used { .. } => return None,
        };
        self.k += 1;
        Some(r)
    }

    /// A node of type `ty` without DEF, to its end, each of its members read by `member`:
    /// its position. `None` if it is not one, or `member` refuses a member.
    fn node(
        &mut self,
        ty: &str,
        member: impl Fn(&mut Self, &'a OwnedEvent) -> Option<()>,
    ) -> Option<Pos> {
        let at = match self.next()? {
            OwnedEvent::NodeStart {
                def: None,
                ty: t,
                at,
            } if &**t == ty => *at,
            _ => return None,
        };
        loop {
            match self.next()? {
                OwnedEvent::NodeEnd { .. } => return Some(at),
                ev => member(self, ev)?,
            }
        }
    }

    /// The rest of a node-valued field (its NodesStart was read) holding exactly one node,
    /// read by `inner`.
    fn holding<T>(&mut self, inner: impl FnOnce(&mut Self) -> Option<T>) -> Option<T> {
        let t = inner(self)?;
        match self.next()? {
            OwnedEvent::NodesEnd { .. } => Some(t),
            _ => None,
        }
    }

    /// The value of the Field event just read, `arity` numbers.
    fn slot(&self, value: &OwnedValue, arity: usize) -> Option<Slot> {
        match value {
            OwnedValue::Is(_) => {
                let fi = self.is[self.k - 1];
                (fi != u32::MAX).then_some(Slot::Is(fi))
            }
            OwnedValue::Numbers {
                values, bracketed, ..
            } if !bracketed && values.len() == arity => Some(Slot::Given(padded3(values))),
            _ => None,
        }
    }

    /// A member of the Transform: `translation`, and `children` holding one Shape.
    fn transform_member(&mut self, ev: &'a OwnedEvent) -> Option<()> {
        match ev {
            OwnedEvent::Field { name, value, .. }
                if &**name == "translation" && self.draft.translation.is_none() =>
            {
                self.draft.translation = Some(self.slot(value, 3)?);
            }
            OwnedEvent::NodesStart { name, .. } if &**name == "children" && !self.draft.shape => {
                self.draft.shape = true;
                self.holding(|m| m.node("Shape", Self::shape_member))?;
            }
            _ => return None,
        }
        Some(())
    }

    /// A member of the Shape: `appearance` holding an Appearance, `geometry` a Sphere (which
    /// it must have).
    fn shape_member(&mut self, ev: &'a OwnedEvent) -> Option<()> {
        match ev {
            OwnedEvent::NodesStart { name, .. }
                if &**name == "appearance" && !self.draft.appearance =>
            {
                self.draft.appearance = true;
                self.holding(|m| m.node("Appearance", Self::appearance_member))?;
            }
            OwnedEvent::NodesStart { name, .. }
                if &**name == "geometry" && self.draft.sphere_at.is_none() =>
            {
                let at = self.holding(|m| m.node("Sphere", Self::sphere_member))?;
                self.draft.sphere_at = Some(at);
            }
            _ => return None,
        }
        Some(())
    }

    /// A member of the Appearance: `material` holding a Material.
    fn appearance_member(&mut self, ev: &'a OwnedEvent) -> Option<()> {
        match ev {
            OwnedEvent::NodesStart { name, .. }
                if &**name == "material" && self.draft.material.is_none() =>
            {
                self.draft.material = Some(Vec::new());
                self.holding(|m| m.node("Material", Self::material_member))?;
            }
            _ => return None,
        }
        Some(())
    }

    /// A field of the Material (any of its six).
    fn material_member(&mut self, ev: &'a OwnedEvent) -> Option<()> {
        let OwnedEvent::Field { name, value, .. } = ev else {
            return None;
        };
        let f = MaterialField::of(name)?;
        let s = self.slot(value, f.arity())?;
        if let Slot::Given(v) = &s {
            // (Replaying would warn about a value outside [0, 1].)
            if !in_range(f, &v[..f.arity()]) {
                return None;
            }
        }
        self.draft.material.as_mut()?.push((f, s));
        Some(())
    }

    /// The Sphere's `radius`.
    fn sphere_member(&mut self, ev: &'a OwnedEvent) -> Option<()> {
        match ev {
            OwnedEvent::Field { name, value, .. }
                if &**name == "radius" && self.draft.radius.is_none() =>
            {
                let s = self.slot(value, 1)?;
                if let Slot::Given(v) = s {
                    if !radius_ok(v[0]) {
                        return None;
                    }
                }
                self.draft.radius = Some(s);
            }
            _ => return None,
        }
        Some(())
    }
}

/// The value of a template slot with `arity` numbers: written in the body, or the instance's
/// (`given(fi)`), or the interface default's; `None` where the template cannot take it.
/// Inlined: called out of line, its result went back through memory and reading it stalled
/// (a quarter of the time of reading a PROTO instance whole, on the continuous-colour bench
/// file; `perf annotate`).
#[inline(always)]
fn slot_value<'a>(
    s: &Slot,
    arity: usize,
    given: &impl Fn(usize) -> Given<'a>,
    proto: &ProtoDecl,
    arena: &'a [Rec],
) -> Option<[f64; 3]> {
    let numbers = match *s {
        Slot::Given(v) => return Some(v),
        Slot::Is(fi) => match given(fi as usize) {
            Given::Numbers(v) => v,
            Given::Other => return None,
            Given::Absent => {
                let range = proto.fields.get(fi as usize)?.default.clone()?;
                match arena.get(range.start)? {
                    Rec::Ev(OwnedEvent::Field {
                        value:
                            OwnedValue::Numbers {
                                values,
                                bracketed: false,
                                ..
                            },
                        ..
                    }) => values,
                    _ => return None,
                }
            }
        },
    };
    if numbers.len() != arity {
        return None;
    }
    Some(padded3(numbers))
}

/// What an instance gives one interface field (see [`Expander::template_inputs`]).
pub(in crate::vrml::lower) enum Given<'a> {
    /// Plain numbers, not bracketed.
    Numbers(&'a [f64]),
    /// Anything else: the template cannot take it.
    Other,
    /// Not given: the field's default.
    Absent,
}

impl Expander {
    /// Lowers a PROTO instance by its body's template: `values` are the instance's values
    /// (arena ranges by interface field, as `instance` found them). `None`: replay the body
    /// instead (nothing was changed).
    pub(in crate::vrml::lower) fn expand_by_template(
        &mut self,
        cx: &mut Ctx,
        b: &mut Builder,
        src: &SourceWindow,
        proto: &ProtoDecl,
        tpl: &SphereTemplate,
        values: &[Option<Range<usize>>],
    ) -> Option<Result<(), Error>> {
        let arena = &self.rec.arena;
        let given = |fi: usize| match values.get(fi).cloned().flatten() {
            None => Given::Absent,
            Some(range) => match arena.get(range.start) {
                Some(Rec::Ev(OwnedEvent::Field {
                    value:
                        OwnedValue::Numbers {
                            values,
                            bracketed: false,
                            ..
                        },
                    ..
                })) => Given::Numbers(values),
                _ => Given::Other,
            },
        };
        let inputs = self.template_inputs(cx, b, src, proto, tpl, given)?;
        Some(self.lower_template(cx, b, src, tpl, inputs))
    }

    /// The instance's values for the template, `given(fi)` by interface field; `None` where
    /// replaying would do more than lower the sphere (see the module's comment).
    pub(in crate::vrml::lower) fn template_inputs<'a>(
        &'a self,
        cx: &Ctx,
        b: &Builder,
        src: &SourceWindow,
        proto: &ProtoDecl,
        tpl: &SphereTemplate,
        given: impl Fn(usize) -> Given<'a>,
    ) -> Option<Inputs> {
        // An external PROTO's body sees other PROTOs.
        if proto.home.is_some() || !self.sphere_fits_here(cx, b, src, tpl.spent) {
            return None;
        }
        let arena = &self.rec.arena[..];
        let translation = match &tpl.translation {
            Some(s) => Some(DVec3::from_array(slot_value(s, 3, &given, proto, arena)?)),
            None => None,
        };
        let material = match &tpl.material {
            None => None,
            Some(fields) => {
                let mut m = Material::default();
                for &(f, ref s) in fields {
                    let v = slot_value(s, f.arity(), &given, proto, arena)?;
                    f.set(&mut m, &v[..f.arity()])?;
                }
                Some(m)
            }
        };
        let radius = match &tpl.radius {
            Some(s) => slot_value(s, 1, &given, proto, arena)?[0],
            None => 1.0,
        };
        if !radius_ok(radius) {
            return None;
        }
        Some(Inputs {
            translation,
            material,
            radius,
        })
    }

    /// Whether a sphere's `nodes` nodes lowered at once here are what lowering them one by
    /// one would give: not where a PROTO named like a standard node may stand for one of
    /// them, nor too deep in replays, nor where the builder would not lower them so
    /// ([`crate::vrml::lower::build::Builder::sphere_fits_here`]).
    #[inline]
    fn sphere_fits_here(&self, cx: &Ctx, b: &Builder, src: &SourceWindow, nodes: u64) -> bool {
        !self.scopes.proto_shadows_standard
            && self.replay.depth < MAX_REPLAY_DEPTH
            && b.sphere_fits_here(cx, src, nodes)
    }

    /// A plain sphere node read whole from the text (see [`crate::vrml::sphere_node`]) at
    /// `at`: lowered as its events would be, if nothing is recorded and its values are ones
    /// that lower without a message. False: its events follow.
    pub(in crate::vrml::lower) fn whole_sphere_node(
        &mut self,
        cx: &mut Ctx,
        b: &mut Builder,
        src: &SourceWindow,
        at: Pos,
        node: &SphereNode,
    ) -> Result<bool, Error> {
        if cx.opts.replay_every_instance
            || !self.rec.idle()
            || !self.sphere_fits_here(cx, b, src, node.nodes)
        {
            return Ok(false);
        }
        b.whole_sphere_node(cx, src, at, node)
    }

    /// Lowers the template's sphere with the instance's `inputs`.
    pub(in crate::vrml::lower) fn lower_template(
        &mut self,
        cx: &mut Ctx,
        b: &mut Builder,
        src: &SourceWindow,
        tpl: &SphereTemplate,
        inputs: Inputs,
    ) -> Result<(), Error> {
        let placed = Placed {
            nodes: tpl.nodes,
            spent: tpl.spent,
            transform_at: tpl.transform_at,
            sphere_at: tpl.sphere_at,
        };
        self.templated += 1;
        b.lower_sphere(cx, src, placed, inputs)
    }
}
