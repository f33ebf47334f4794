//! `node_start`: where a starting node goes. A DEF starts a recording, a node inside a PROTO
//! declaration, a skipped node or a Switch choice opens a quiet frame, a PROTO instance is
//! recorded for expansion when it closes (or read into its template), and any other node is
//! the scene builder's to open (`build::node`).

use std::rc::Rc;

use super::proto::ProtoDecl;
use super::record::RecKind;
use super::Expander;
use crate::error::Error;
use crate::source::{Pos, SourceWindow};
use crate::vrml::lower::build::open::{Kind, Leaf, Name};
use crate::vrml::lower::build::Builder;
use crate::vrml::lower::context::Ctx;
use crate::vrml::schema;

impl Expander {
    pub(in crate::vrml::lower) fn node_start(
        &mut self,
        cx: &mut Ctx,
        b: &mut Builder,
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
        cx.add_nodes(1, src, at)?;
        let index = schema::node_index(ty);
        let spec = index.map(|i| &schema::NODES[i]);
        // A standard type was found by this very name.
        let ty_rc = match spec {
            Some(s) => Name::Static(s.name),
            None => Name::Shared(self.rec.names.rc(ty)),
        };
        if b.open.quiet > 0 {
            // Not lowered; a frame keeps the nesting.
            b.open.push(ty_rc, None, Kind::Quiet, at);
            return Ok(());
        }
        self.check_child(cx, b, src, ty, at);
        // Where does this node stand? (A Switch choice, an LOD level after the first, or a
        // Collision proxy is recorded or ignored, not lowered.)
        let (in_choice, ignored_level) = match b.open.fields.last() {
            None => (false, false),
            Some(ctx) => match &mut b.open.frames[ctx.frame].kind {
                Kind::Switch { .. } => (&*ctx.name == "choice", false),
                Kind::Lod { levels, .. } if &*ctx.name == "level" => {
                    let ignored = *levels > 0;
                    *levels += 1;
                    (false, ignored)
                }
                Kind::Group { .. } => (false, &*ctx.name == "proxy"),
                Kind::Mesh(_) => {
                    b.mesh_child(ty_rc, at);
                    return Ok(());
                }
                _ => (false, false),
            },
        };
        if in_choice || ignored_level {
            if in_choice && !self.rec.in_choice() {
                self.rec.start_here(&ty_rc, def, at, RecKind::Choice);
            }
            b.open.push_quiet(ty_rc, at);
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
                if !self.start_direct(cx, &proto, &ty_rc, def, at) {
                    self.rec.start_here(&ty_rc, def, at, RecKind::Instance);
                }
            } else {
                cx.diags.skip(ty);
                cx.diags.warn(
                    src,
                    at,
                    format!(
                        "EXTERNPROTO {ty} is not available (none of its urls was loaded): skipped"
                    ),
                );
            }
            b.open.push_quiet(ty_rc, at);
            self.open_instance(b.open.frames.len(), proto);
            return Ok(());
        }
        b.open_node(cx, src, (index, ty_rc), def, at)
    }

    /// Notes that the frame opened at depth `depth` (the frame count once it is pushed) is an
    /// instance of `proto`, to be expanded when it closes.
    fn open_instance(&mut self, depth: usize, proto: Rc<ProtoDecl>) {
        while self.instances.last().is_some_and(|(d, _)| *d >= depth) {
            self.instances.pop();
        }
        self.instances.push((depth, proto));
    }

    /// The PROTO of the instance whose frame, at depth `depth`, closes now.
    pub(in crate::vrml::lower) fn instance_proto(&mut self, depth: usize) -> Option<Rc<ProtoDecl>> {
        while let Some((d, proto)) = self.instances.pop() {
            if d == depth {
                return Some(proto);
            }
            if d < depth {
                self.instances.push((d, proto));
                break;
            }
        }
        None
    }

    /// Warns when a node type does not belong in the field it stands in.
    #[inline(always)]
    pub(in crate::vrml::lower) fn check_child(
        &mut self,
        cx: &mut Ctx,
        b: &mut Builder,
        src: &SourceWindow,
        ty: &str,
        at: Pos,
    ) {
        let Some(ctx) = b.open.fields.last() else {
            return;
        };
        let parent = &b.open.frames[ctx.frame];
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
            cx.diags.warn(src, at, msg);
        }
    }
}
