//! Where each event goes. The parser's events (through [`super::Lent`]) enter at
//! [`Expander::dispatch`], the replayed events of PROTO bodies at
//! [`Expander::dispatch_recorded`]: while nothing is recorded and no PROTO declaration is
//! open, the common events (node start and end, field, node-valued field start and end) take
//! one fast path, the `fast_*` handlers below, whichever form they come in; everything else
//! takes [`Expander::handle`], which also records events, substitutes `IS`, resolves `USE`,
//! and opens and closes PROTO declarations. The fast path is only a shortcut: `handle` does
//! the same for those events.

use super::record::{Rec, RecKind};
use super::Expander;
use crate::error::Error;
use crate::source::{Pos, SourceWindow};
use crate::vrml::lower::build::Builder;
use crate::vrml::lower::context::Ctx;
use crate::vrml::schema::{Access, FieldType};
use crate::vrml::syntax::{Event, OwnedEvent, OwnedValue, Value};

impl Expander {
    /// Handles one event of the scene text.
    #[inline(always)]
    pub(in crate::vrml::lower) fn dispatch(
        &mut self,
        cx: &mut Ctx,
        b: &mut Builder,
        src: &SourceWindow,
        ev: Event<'_>,
    ) -> Result<(), Error> {
        // The common events of plain scene text (nothing recorded, no PROTO declaration open)
        // go straight to their handlers; this is what `handle` does for them.
        if self.rec.idle() {
            match ev {
                Event::NodeStart { def: None, ty, at } => {
                    return self.fast_node_start(cx, b, src, ty, at)
                }
                Event::NodeEnd { .. } => return self.fast_node_end(cx, b, src),
                Event::Field { name, at, value } if !matches!(value, Value::Is(_)) => {
                    return b.field(cx, src, name, at, value)
                }
                Event::NodesStart { name, at } => return b.nodes_start(cx, src, name, at),
                Event::NodesEnd { .. } => return self.fast_nodes_end(b),
                _ => {}
            }
        }
        self.handle(cx, b, src, ev)
    }

    /// [`Self::dispatch`] for a recorded event (of a PROTO body): the same fast path, taken
    /// without building an [`Event`] first (converting each event costs 2.5 % more
    /// instructions on a file of PROTO instances).
    #[inline(always)]
    pub(in crate::vrml::lower) fn dispatch_recorded(
        &mut self,
        cx: &mut Ctx,
        b: &mut Builder,
        src: &SourceWindow,
        ev: &OwnedEvent,
    ) -> Result<(), Error> {
        if self.rec.idle() {
            match ev {
                OwnedEvent::NodeStart { def: None, ty, at } => {
                    return self.fast_node_start(cx, b, src, ty, *at)
                }
                OwnedEvent::NodeEnd { .. } => return self.fast_node_end(cx, b, src),
                OwnedEvent::Field { name, at, value } if !matches!(value, OwnedValue::Is(_)) => {
                    return b.field(cx, src, name, *at, value.as_value())
                }
                OwnedEvent::NodesStart { name, at } => return b.nodes_start(cx, src, name, *at),
                OwnedEvent::NodesEnd { .. } => return self.fast_nodes_end(b),
                _ => {}
            }
        }
        self.handle(cx, b, src, ev.as_event())
    }

    /// The fast path's NodeStart (without DEF): `handle` without recording.
    #[inline(always)]
    fn fast_node_start(
        &mut self,
        cx: &mut Ctx,
        b: &mut Builder,
        src: &SourceWindow,
        ty: &str,
        at: Pos,
    ) -> Result<(), Error> {
        self.node_start(cx, b, src, None, ty, at)?;
        // (A Switch choice or PROTO instance starts recording at this event.)
        if !self.rec.recorders.is_empty() {
            let done = self.rec.end_slow(&Event::NodeStart { def: None, ty, at });
            debug_assert!(done.is_empty());
        }
        Ok(())
    }

    /// The fast path's NodeEnd: a leaf closes in place, other nodes through `node_end`.
    #[inline(always)]
    fn fast_node_end(
        &mut self,
        cx: &mut Ctx,
        b: &mut Builder,
        src: &SourceWindow,
    ) -> Result<(), Error> {
        if b.open.quiet == 0 {
            if let Some(result) = b.close_top_leaf(cx) {
                b.deliver(result);
                return Ok(());
            }
        }
        self.node_end(cx, b, src, Vec::new())
    }

    /// The fast path's NodesEnd: the node-valued field is complete.
    #[inline(always)]
    fn fast_nodes_end(&mut self, b: &mut Builder) -> Result<(), Error> {
        b.open.fields.pop();
        Ok(())
    }

    /// Handles any event: records it if something is recording, then lowers it.
    pub(in crate::vrml::lower) fn handle(
        &mut self,
        cx: &mut Ctx,
        b: &mut Builder,
        src: &SourceWindow,
        ev: Event<'_>,
    ) -> Result<(), Error> {
        if self.rec.direct {
            return self.direct_event(cx, b, src, ev);
        }
        // IS inside a PROTO expansion is replaced by the instance's value before anything else.
        if let Event::Field {
            name,
            at,
            value: Value::Is(target),
        } = ev
        {
            if self.rec.proto_decls == 0 {
                return self.substitute(cx, b, src, name, target, at);
            }
        }
        if let Event::Use { name, at } = ev {
            if self.rec.proto_decls == 0 {
                return self.on_use(cx, b, src, name, at);
            }
        }
        self.rec.record(&ev);
        match ev {
            Event::NodeStart { def, ty, at } => self.node_start(cx, b, src, def, ty, at)?,
            Event::NodeEnd { .. } => {
                let done = self.rec.end(&ev);
                if self.rec.proto_decls > 0 {
                    // Inside a PROTO declaration nodes are only recorded (no frames were opened).
                    return Ok(());
                }
                self.node_end(cx, b, src, done)?;
                return Ok(());
            }
            Event::Field { name, at, value } => b.field(cx, src, name, at, value)?,
            Event::NodesStart { name, at } => b.nodes_start(cx, src, name, at)?,
            Event::NodesEnd { .. } => {
                b.open.fields.pop();
            }
            Event::Use { .. } => {}
            Event::Null { .. } => {}
            Event::Decl { access, ty, at, .. } => {
                if self.rec.proto_decls == 0 {
                    if Access::from_keyword(access).is_none() {
                        return Err(cx.diags.error(
                            src,
                            at,
                            format!("unknown access type '{access}'"),
                        ));
                    }
                    if FieldType::from_name(ty).is_none() {
                        return Err(cx
                            .diags
                            .error(src, at, format!("unknown field type '{ty}'")));
                    }
                    if let Some(f) = b.open.frames.last() {
                        if &*f.ty == "Script" && access == "exposedField" {
                            cx.diags
                                .warn(src, at, "a Script may not declare an exposedField");
                        }
                    }
                }
            }
            Event::ProtoStart { .. } => {
                if self.rec.proto_decls == 0 {
                    // Start recording the declaration (including this event).
                    self.rec.start_proto_decl(&ev);
                }
                self.rec.proto_decls += 1;
                b.open.quiet += 1;
            }
            Event::ProtoBody { .. } => {}
            Event::ProtoEnd { .. } => {
                self.rec.proto_decls -= 1;
                b.open.quiet -= 1;
                let done = self.rec.end(&ev);
                for (kind, range) in done {
                    if let RecKind::ProtoDecl = kind {
                        self.declare_proto(cx, b, src, range)?;
                    }
                }
                return Ok(());
            }
            Event::Route {
                from_node,
                from_field,
                to_node,
                to_field,
                at,
            } => {
                if self.rec.proto_decls == 0 {
                    self.check_route(cx, src, from_node, from_field, to_node, to_field, at);
                }
            }
        }
        if !self.rec.recorders.is_empty() {
            let done = self.rec.end_slow(&ev);
            debug_assert!(done.is_empty());
        }
        Ok(())
    }

    /// `USE name`: replays the DEF'd node's events (or records the USE).
    fn on_use(
        &mut self,
        cx: &mut Ctx,
        b: &mut Builder,
        src: &SourceWindow,
        name: &str,
        at: Pos,
    ) -> Result<(), Error> {
        let Some(d) = self.lookup_def(name) else {
            let open = self.scopes.is_open(name);
            if open && b.open.quiet > 0 {
                // A Script that refers to itself: fine, it is not lowered.
                if !self.rec.recorders.is_empty() {
                    self.rec.arena.push(Rec::Ev(OwnedEvent::Use {
                        name: name.into(),
                        at,
                    }));
                }
                return Ok(());
            }
            let msg = if open {
                format!("USE of '{name}' inside its own definition")
            } else {
                format!("USE of undefined name '{name}'")
            };
            return Err(cx.diags.error(src, at, msg));
        };
        self.check_child(cx, b, src, &d.ty, at);
        self.use_range(cx, b, src, d.range, at)
    }
}
