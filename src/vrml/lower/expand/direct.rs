//! PROTO instances read straight into their sphere template. An instance of a PROTO with a
//! [`SphereTemplate`] is normally recorded while it is read (each field as an event in the
//! arena, its name shared, its value copied) and expanded when it closes. Where nothing
//! else is recording, its plain numeric field values are instead kept by interface field as
//! they come, and the template lowers them when the instance closes: what `instance` and
//! `expand_by_template` do with the recording, without making it.
//!
//! Anything else in the instance (a field the PROTO does not have or whose value does not
//! fit, a node, `IS`, `USE`, a bracketed list) makes the instance recorded after all: the
//! fields kept so far are recorded as they would have been, and the event goes on as usual
//! ([`Expander::record_direct`]). An instance the template refuses when it closes (see
//! `template`) is recorded the same way and replayed. So warnings, errors and the scene are
//! the recording's in every case (`src/vrml/tests/proto_template.rs` compares them with replaying
//! every instance).
//!
//! An instance the parser read whole, because its fields all hold plain numbers
//! ([`crate::vrml::parse::flat::FlatNode`]), takes the same checks without any events
//! ([`Expander::whole_instance`]); one that fails them is given to the events after all.

use std::rc::Rc;

use super::proto::{ProtoDecl, SphereTemplate};
use super::record::{Rec, RecKind};
use super::Expander;
use crate::error::Error;
use crate::source::{Pos, SourceWindow};
use crate::vrml::lower::build::fields::is_event;
use crate::vrml::lower::build::open::Name;
use crate::vrml::lower::build::Builder;
use crate::vrml::lower::context::Ctx;
use crate::vrml::schema;
use crate::vrml::syntax::{Event, Nums, OwnedEvent, OwnedValue, Value};

use super::template::Given;
use crate::vrml::lower::build::sphere::padded3;
use crate::vrml::parse::flat::FlatNode;

/// One field value an instance gave, as written (the last of a name counts).
#[derive(Clone, Copy, Debug)]
struct GivenField {
    /// Interface field index.
    fi: u32,
    len: u8,
    integer: bool,
    at: Pos,
    numbers: [f64; 3],
}

/// The instance being read into its template.
struct Reading {
    proto: Rc<ProtoDecl>,
    ty: Name,
    at: Pos,
}

/// The instance read into its template, if any, and the buffer of its values.
#[derive(Default)]
pub(in crate::vrml::lower) struct Direct {
    reading: Option<Reading>,
    given: Vec<GivenField>,
    memo: FieldMemo,
}

/// The interface fields the last instance read whole gave, in its order, and what value each
/// takes: the next instance of the same PROTO (a file of a million instances writes the same
/// fields in the same order) tries them first, with one name comparison, before the search
/// by name and the type check of [`given_field`].
#[derive(Default)]
struct FieldMemo {
    proto: Option<Rc<ProtoDecl>>,
    order: Vec<Fits>,
}

/// An interface field and the plain numbers its type takes (what [`schema::check_value`]
/// accepts of an unbracketed value): `len` of them, integers where `integer`.
#[derive(Clone, Copy)]
struct Fits {
    fi: u32,
    len: u8,
    integer: bool,
}

impl FieldMemo {
    /// The field at `k` in the instance, if the last instance of `proto` gave `name` there
    /// and `values` fit it: what [`given_field`] would return (the first interface field of
    /// that name, which an instance may set, and a value of its type).
    #[inline(always)]
    fn given(
        &self,
        proto: &ProtoDecl,
        k: usize,
        name: &str,
        at: Pos,
        values: &[f64],
        integer: bool,
    ) -> Option<GivenField> {
        let m = *self.order.get(k)?;
        let f = &proto.fields[m.fi as usize];
        if values.len() != usize::from(m.len)
            || (m.integer && !integer)
            || !schema::same_bytes(f.name.as_bytes(), name.as_bytes())
        {
            return None;
        }
        Some(GivenField {
            fi: m.fi,
            len: m.len,
            integer,
            at,
            numbers: padded3(values),
        })
    }

    /// Remembers that the instance gave field `fi` at `k` (`proto`'s instances from now on).
    fn learn(&mut self, proto: &Rc<ProtoDecl>, k: usize, fi: u32) {
        if !self.proto.as_ref().is_some_and(|p| Rc::ptr_eq(p, proto)) {
            self.proto = Some(proto.clone());
            self.order.clear();
        }
        let ty = proto.fields[fi as usize].ty;
        let fits = ty.arity().filter(|&n| n <= 3).map(|n| Fits {
            fi,
            len: n as u8,
            integer: ty.is_integer(),
        });
        self.order.truncate(k);
        if let (Some(m), true) = (fits, self.order.len() == k) {
            self.order.push(m);
        }
    }
}

impl Expander {
    /// Starts reading a PROTO instance (its NodeStart is being handled) into its template
    /// when it may be; false: record it.
    pub(in crate::vrml::lower) fn start_direct(
        &mut self,
        cx: &mut Ctx,
        proto: &Rc<ProtoDecl>,
        ty: &Name,
        def: Option<&str>,
        at: Pos,
    ) -> bool {
        let may = def.is_none() && self.template_may_read(cx, proto);
        if may {
            self.direct.reading = Some(Reading {
                proto: proto.clone(),
                ty: ty.clone(),
                at,
            });
            self.direct.given.clear();
            self.rec.direct = true;
        }
        may
    }

    /// Whether an instance of `proto` starting here may be read into its template: it has
    /// one (and is neither a GasParticle nor another file's PROTO), the option allows it,
    /// and nothing records, declares a PROTO or is being read into a template.
    fn template_may_read(&self, cx: &Ctx, proto: &ProtoDecl) -> bool {
        proto.sphere.is_some()
            && proto.gas.is_none()
            && proto.home.is_none()
            && !cx.opts.replay_every_instance
            && self.rec.idle()
    }

    /// A node of plain numbers read whole from the text (see
    /// [`crate::vrml::parse::flat::flat_node`]) at `at`: lowered at once if it is an
    /// instance that [`Self::start_direct`] would read into its template and that template
    /// takes, with what its events would have done (the instance's node counted, its values
    /// checked as `instance` checks them). False: its events follow.
    pub(in crate::vrml::lower) fn whole_instance(
        &mut self,
        cx: &mut Ctx,
        b: &mut Builder,
        src: &SourceWindow,
        at: Pos,
        text: &str,
        node: &FlatNode,
    ) -> Result<bool, Error> {
        let ty = node.ty(text);
        if schema::node_index(ty).is_some() && !self.scopes.proto_shadows_standard {
            return Ok(false);
        }
        let Some(proto) = self.scopes.proto_memo(ty) else {
            return Ok(false);
        };
        if !self.template_may_read(cx, &proto) {
            return Ok(false);
        }
        let Some(tpl) = proto.sphere.clone() else {
            return Ok(false);
        };
        self.whole_instance_with(cx, b, src, at, text, node, &proto, &tpl)
    }

    // (Its own arguments, and the context and builder lent to the expander.)
    #[allow(clippy::too_many_arguments)]
    fn whole_instance_with(
        &mut self,
        cx: &mut Ctx,
        b: &mut Builder,
        src: &SourceWindow,
        at: Pos,
        text: &str,
        node: &FlatNode,
        proto: &Rc<ProtoDecl>,
        tpl: &SphereTemplate,
    ) -> Result<bool, Error> {
        // (No instance is being read into its template here: the buffer is free.)
        self.direct.given.clear();
        let memo = &mut self.direct.memo;
        let known = memo.proto.as_ref().is_some_and(|p| Rc::ptr_eq(p, proto));
        for (k, f) in node.fields().iter().enumerate() {
            let (at, name) = (at + u64::from(f.at), f.name(text));
            let fast = known
                .then(|| memo.given(proto, k, name, at, f.numbers(), f.integer))
                .flatten();
            let g = match fast {
                Some(g) => g,
                None => match given_field(proto, name, at, f.numbers(), f.integer) {
                    Some(g) => {
                        memo.learn(proto, k, g.fi);
                        g
                    }
                    None => return Ok(false),
                },
            };
            self.direct.given.push(g);
        }
        let given = &self.direct.given;
        // The instance's own node is counted before the template's.
        if !cx.fits(1 + tpl.spent, src) {
            return Ok(false);
        }
        let lookup = |fi: usize| last_given(given, fi);
        let Some(inputs) = self.template_inputs(cx, b, src, proto, tpl, lookup) else {
            return Ok(false);
        };
        cx.nodes += 1;
        cx.spent += 1;
        cx.watch_nodes(src.offset());
        self.lower_template(cx, b, src, tpl, inputs)?;
        Ok(true)
    }

    /// An event inside the instance being read into its template.
    pub(in crate::vrml::lower) fn direct_event(
        &mut self,
        cx: &mut Ctx,
        b: &mut Builder,
        src: &SourceWindow,
        ev: Event<'_>,
    ) -> Result<(), Error> {
        match ev {
            Event::Field {
                name,
                at,
                value:
                    Value::Numbers {
                        values,
                        integer,
                        bracketed: false,
                    },
            } => {
                let proto = self.direct.reading.as_ref().map(|r| &*r.proto);
                if let Some(g) = proto.and_then(|p| given_field(p, name, at, values, integer)) {
                    self.direct.given.push(g);
                    return Ok(());
                }
            }
            Event::NodeEnd { .. } => return self.finish_direct(cx, b, src),
            _ => {}
        }
        self.record_direct();
        self.handle(cx, b, src, ev)
    }

    /// Turns the instance being read into its template into a recorded one: its recorder
    /// starts at its NodeStart, and the fields kept so far are recorded, as `handle` would
    /// have done.
    fn record_direct(&mut self) {
        self.rec.direct = false;
        let Some(r) = self.direct.reading.take() else {
            return;
        };
        self.rec.start_here(&r.ty, None, r.at, RecKind::Instance);
        // (The recorder counts the instance's own node, as after its NodeStart.)
        let start_event = Event::NodeStart {
            def: None,
            ty: &r.ty,
            at: r.at,
        };
        let done = self.rec.end_slow(&start_event);
        debug_assert!(done.is_empty());
        self.record_given(&r.proto);
    }

    /// Records the fields kept so far as `handle` records fields; returns where they are.
    fn record_given(&mut self, proto: &ProtoDecl) -> std::ops::Range<usize> {
        let first = self.rec.arena.len();
        for g in &self.direct.given {
            let name = self.rec.names.rc(&proto.fields[g.fi as usize].name);
            self.rec.arena.push(Rec::Ev(OwnedEvent::Field {
                name,
                at: g.at,
                value: OwnedValue::Numbers {
                    values: Nums::new(&g.numbers[..usize::from(g.len)]),
                    integer: g.integer,
                    bracketed: false,
                },
            }));
        }
        first..self.rec.arena.len()
    }

    /// The instance's `}`: closes its frame, as `node_end` does, and lowers it by its
    /// template, or records and replays it where the template refuses.
    fn finish_direct(
        &mut self,
        cx: &mut Ctx,
        b: &mut Builder,
        src: &SourceWindow,
    ) -> Result<(), Error> {
        let frame = b.open.pop_closing();
        self.rec.direct = false;
        let Some(Reading { proto, .. }) = self.direct.reading.take() else {
            return Ok(());
        };
        let Some(tpl) = proto.sphere.clone() else {
            return Ok(());
        };
        let given = &self.direct.given;
        let lookup = |fi: usize| last_given(given, fi);
        if let Some(inputs) = self.template_inputs(cx, b, src, &proto, &tpl, lookup) {
            return self.lower_template(cx, b, src, &tpl, inputs);
        }
        // Replayed: the values recorded first, where expand finds an instance's.
        let fields = self.record_given(&proto);
        let mut values = vec![None; proto.fields.len()];
        for (g, i) in self.direct.given.iter().zip(fields.clone()) {
            values[g.fi as usize] = Some(i..i + 1);
        }
        let r = self.replay_body(cx, b, src, proto, values, frame.at);
        self.rec.release(fields.start);
        r
    }
}

/// A field value the template can take: an interface field of the PROTO's that is not an
/// event nor node-valued, with a value of its type (what `instance` checks).
fn given_field(
    proto: &ProtoDecl,
    name: &str,
    at: Pos,
    values: &[f64],
    integer: bool,
) -> Option<GivenField> {
    let fi = proto.public_index(name)?;
    let f = &proto.fields[fi];
    if values.len() > 3 || f.ty.is_node() || is_event(f.access) {
        return None;
    }
    let value = Value::Numbers {
        values,
        integer,
        bracketed: false,
    };
    schema::check_value(f.ty, &value).ok()?;
    Some(GivenField {
        fi: fi as u32,
        len: values.len() as u8,
        integer,
        at,
        numbers: padded3(values),
    })
}

/// What the instance gave interface field `fi`: its last value, if any.
fn last_given(given: &[GivenField], fi: usize) -> Given<'_> {
    match given.iter().rev().find(|g| g.fi as usize == fi) {
        Some(g) => Given::Numbers(&g.numbers[..usize::from(g.len)]),
        None => Given::Absent,
    }
}
