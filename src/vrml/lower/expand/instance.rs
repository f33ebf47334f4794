//! PROTO expansion. An instance is recorded while it is read and expanded when it closes:
//! its field values are checked against the PROTO's interface and kept by interface field
//! ([`Subst`]), then the body is replayed up to the end of its first node (the one that is
//! drawn: VRML97 4.8.3), in a namespace of its own. A body field `name IS target` is
//! replaced by the instance's value of `target`, or by the interface default; that value is
//! emitted in the instance's own scope, with the substitutions of the next expansion out.
//! A PROTO read from another file for an EXTERNPROTO expands the same way, its body under
//! the PROTOs of its own file (its home); an instance may set only the fields its
//! EXTERNPROTO declares alike ([`ProtoDecl::public_index`]).

use std::ops::Range;
use std::rc::Rc;

use super::proto::ProtoDecl;
use super::record::{value_end, Rec};
use super::Expander;
use crate::error::Error;
use crate::source::{Pos, SourceWindow};
use crate::vrml::lower::build::fields::is_event;
use crate::vrml::lower::build::Builder;
use crate::vrml::lower::context::Ctx;
use crate::vrml::schema;
use crate::vrml::syntax::{Event, OwnedEvent, OwnedValue};

/// The values an instance gives its PROTO's interface fields.
#[derive(Debug)]
pub(in crate::vrml::lower) struct Subst {
    proto: Rc<ProtoDecl>,
    /// By interface field index (the first field of a name, as [`ProtoDecl::field`] finds).
    values: Vec<Option<Range<usize>>>,
    /// How many namespaces were in effect around the instance (see `Scopes::take_above`).
    scope_depth: usize,
}

/// The PROTO expansions under way.
#[derive(Default)]
pub(in crate::vrml::lower) struct Expansions {
    /// IS substitutions of the expansions under way (innermost last).
    pub(in crate::vrml::lower) substs: Vec<Subst>,
    /// Emptied `Subst::values` of finished expansions, reused (one per nesting level).
    spare_values: Vec<Vec<Option<Range<usize>>>>,
}

impl Expander {
    /// Replaces `field IS target` by the PROTO instance's value (or the interface default).
    pub(in crate::vrml::lower) fn substitute(
        &mut self,
        cx: &mut Ctx,
        b: &mut Builder,
        src: &SourceWindow,
        name: &str,
        target: &str,
        at: Pos,
    ) -> Result<(), Error> {
        let Some(sub) = self.expansions.substs.last() else {
            return Err(cx.diags.error(
                src,
                at,
                format!("'{name} IS {target}' outside a PROTO body"),
            ));
        };
        let Some(fi) = sub.proto.field_index(target) else {
            let msg = format!(
                "'IS {target}': PROTO {} has no interface field '{target}'",
                sub.proto.name
            );
            return Err(cx.diags.error(src, at, msg));
        };
        self.substitute_field(cx, b, src, name, fi, at)
    }

    /// [`Self::substitute`] for interface field `fi` of the innermost expansion's PROTO.
    fn substitute_field(
        &mut self,
        cx: &mut Ctx,
        b: &mut Builder,
        src: &SourceWindow,
        name: &str,
        fi: usize,
        at: Pos,
    ) -> Result<(), Error> {
        let Some(sub) = self.expansions.substs.last() else {
            return Err(Error::Internal("IS outside a PROTO expansion".into()));
        };
        let given = sub.values[fi].clone();
        // An external PROTO's body sees its own file's PROTOs; the instance's value is read
        // among those around the instance (a local PROTO's body namespace lets both through).
        let around = (given.is_some() && sub.proto.home.is_some()).then_some(sub.scope_depth);
        let range = given.or_else(|| sub.proto.fields[fi].default.clone());
        let Some(range) = range else {
            // An event (eventIn/eventOut) has no value to substitute.
            return Ok(());
        };
        // A plain value with nothing recording (nor an instance read into its template, which
        // takes it through `dispatch`): lowered at once, as written in scene text.
        if let Rec::Ev(OwnedEvent::Field { value, at: vat, .. }) = &self.rec.arena[range.start] {
            if !matches!(value, OwnedValue::Is(_)) && self.rec.idle() {
                let (v, vat) = (value.clone(), *vat);
                cx.spend(1 + v.len() as u64, src, at, "IS value")?;
                return b.field(cx, src, name, vat, v.as_value());
            }
        }
        // The instance's substitutions are set aside while its value is emitted: the value is
        // resolved in the instance's scope, with the IS substitutions of the next one out.
        let Some(sub) = self.expansions.substs.pop() else {
            return Ok(());
        };
        let body_scopes = around.map(|depth| self.scopes.take_above(depth));
        // Emit the value under this field's own name.
        let r = match &self.rec.arena[range.start] {
            Rec::Ev(OwnedEvent::Field { value, at: vat, .. }) => {
                let (v, vat) = (value.clone(), *vat);
                cx.spend(1 + v.len() as u64, src, at, "IS value")?;
                self.dispatch(
                    cx,
                    b,
                    src,
                    Event::Field {
                        name,
                        at: vat,
                        value: v.as_value(),
                    },
                )
            }
            Rec::Ev(OwnedEvent::NodesStart { at: vat, .. }) => {
                let vat = *vat;
                self.handle(cx, b, src, Event::NodesStart { name, at: vat })
                    .and_then(|_| {
                        self.replay(cx, b, src, range.start + 1..range.end - 1, at, "IS value")
                    })
                    .and_then(|_| self.handle(cx, b, src, Event::NodesEnd { at: vat }))
            }
            _ => Ok(()),
        };
        if let Some(scopes) = body_scopes {
            self.scopes.restore(scopes);
        }
        self.expansions.substs.push(sub);
        r
    }

    /// Expands a recorded PROTO instance: its field values replace `IS` in the body's first node.
    pub(in crate::vrml::lower) fn expand(
        &mut self,
        cx: &mut Ctx,
        b: &mut Builder,
        src: &SourceWindow,
        proto: Rc<ProtoDecl>,
        inst: Range<usize>,
        at: Pos,
    ) -> Result<(), Error> {
        // The instance's fields (skip its NodeStart and NodeEnd).
        let mut values = self.expansions.spare_values.pop().unwrap_or_default();
        values.resize(proto.fields.len(), None);
        let mut i = inst.start + 1;
        while i + 1 < inst.end {
            let end = value_end(&self.rec.arena, i);
            let (fname, fat) = match &self.rec.arena[i] {
                Rec::Ev(OwnedEvent::Field { name, at, .. })
                | Rec::Ev(OwnedEvent::NodesStart { name, at }) => (name.clone(), *at),
                _ => {
                    i = end;
                    continue;
                }
            };
            match proto.public_index(&fname) {
                None => cx.diags.warn(
                    src,
                    fat,
                    format!("unknown field '{fname}' of PROTO {}: ignored", proto.name),
                ),
                Some(fi) => {
                    let f = &proto.fields[fi];
                    if let Rec::Ev(OwnedEvent::Field { value, .. }) = &self.rec.arena[i] {
                        if f.ty.is_node() {
                            if *value != OwnedValue::Empty {
                                return Err(cx.diags.error(
                                    src,
                                    fat,
                                    format!(
                                        "field '{fname}' of PROTO {} expects {}",
                                        proto.name,
                                        f.ty.name()
                                    ),
                                ));
                            }
                        } else if let Err(e) = schema::check_value(f.ty, &value.as_value()) {
                            return Err(cx.diags.error(
                                src,
                                fat,
                                format!("field '{fname}' of PROTO {} {e}", proto.name),
                            ));
                        }
                    } else if !f.ty.is_node() {
                        return Err(cx.diags.error(
                            src,
                            fat,
                            format!(
                                "field '{fname}' of PROTO {} expects {}, found a node",
                                proto.name,
                                f.ty.name()
                            ),
                        ));
                    }
                    if is_event(f.access) {
                        cx.diags.warn(
                            src,
                            fat,
                            format!(
                                "'{fname}' of PROTO {} is an {}, not a field: ignored",
                                proto.name,
                                f.access.keyword()
                            ),
                        );
                    } else {
                        values[fi] = Some(i..end);
                    }
                }
            }
            i = end;
        }
        // A GasParticle's Materials take its profile (checked here, at the instance's values).
        let outer_profile = b.gas_profile;
        if let Some(gas) = proto.gas {
            b.gas_profile = Some(self.instance_profile(cx, src, &proto, gas, &values, at)?);
        }
        let by_template = match (&proto.sphere, cx.opts.replay_every_instance) {
            (Some(tpl), false) => self.expand_by_template(cx, b, src, &proto, tpl, &values),
            _ => None,
        };
        let r = match by_template {
            Some(r) => {
                values.clear();
                self.expansions.spare_values.push(values);
                r
            }
            None => self.replay_body(cx, b, src, proto, values, at),
        };
        b.gas_profile = outer_profile;
        r
    }

    /// Replays an instance's body with its `values` (by interface field), in a namespace of
    /// its own.
    pub(in crate::vrml::lower) fn replay_body(
        &mut self,
        cx: &mut Ctx,
        b: &mut Builder,
        src: &SourceWindow,
        proto: Rc<ProtoDecl>,
        values: Vec<Option<Range<usize>>>,
        at: Pos,
    ) -> Result<(), Error> {
        // The body runs in a namespace of its own (under its file's PROTOs if it came from
        // another file), with this instance's substitutions.
        let scope_depth = self.scopes.depth();
        if let Some(home) = &proto.home {
            self.scopes.push_home(home.clone());
        }
        self.scopes.push_body();
        self.expansions.substs.push(Subst {
            proto: proto.clone(),
            values,
            scope_depth,
        });
        let saved = std::mem::take(&mut self.rec.recorders);
        let reusing = std::mem::replace(&mut self.replay.reusing, 0);
        let n = proto.first_end;
        let r =
            self.replay_first_node(cx, b, src, &proto.body_events[..n], &proto.body_is[..n], at);
        self.replay.reusing = reusing;
        self.rec.recorders = saved;
        if let Some(mut sub) = self.expansions.substs.pop() {
            sub.values.clear();
            self.expansions.spare_values.push(sub.values);
        }
        self.scopes.leave_to(scope_depth);
        r
    }

    /// Replays a PROTO body up to the end of its first node (earlier PROTO declarations
    /// included): `events` and `is` are cut at [`ProtoDecl::first_end`]. The common events
    /// take the same fast path as scene text (see `dispatch`).
    fn replay_first_node(
        &mut self,
        cx: &mut Ctx,
        b: &mut Builder,
        src: &SourceWindow,
        events: &[Rec],
        is: &[u32],
        at: Pos,
    ) -> Result<(), Error> {
        for (rec, &is) in events.iter().zip(is) {
            match rec {
                Rec::Ev(ev) => {
                    cx.spend(
                        crate::vrml::lower::event_cost(ev),
                        src,
                        at,
                        "PROTO instance",
                    )?;
                    self.enter_replay(cx, src, at, "PROTO expansions")?;
                    let r = match ev {
                        // `field IS target` of this body: the instance's value, found by index.
                        OwnedEvent::Field { name, at, .. }
                            if is != u32::MAX && self.rec.proto_decls == 0 =>
                        {
                            self.substitute_field(cx, b, src, name, is as usize, *at)
                        }
                        _ => self.dispatch_recorded(cx, b, src, ev),
                    };
                    self.replay.depth -= 1;
                    r?;
                }
                Rec::Used { range, at } => self.use_range(cx, b, src, range.clone(), *at)?,
            }
        }
        Ok(())
    }
}
