//! The expander: it takes the parser's events and turns what VRML builds by reference into
//! plain nodes for the scene builder ([`Builder`]). DEF'd nodes and PROTO declarations are
//! recorded as events in an arena and replayed for USE and PROTO instances (with `IS`
//! substituted); Inline files and the files EXTERNPROTOs name are read in place; ROUTEs are
//! checked. It knows nothing of the [`crate::scene::Scene`]: every node it lets through goes
//! to the builder, which it is lent for each call with the shared [`Ctx`].
//!
//! Its parts: `dispatch` (the one fast path for common events, and the general handler),
//! `record` (the event arena and the recordings under way), `replay` (USE and Switch
//! choices, and the one depth guard), `scope` (DEF and PROTO namespaces), `declare` (PROTO
//! declarations), `proto` (what a declaration holds), `instance` (PROTO instances and `IS`),
//! `template` (an instance whose body is one sphere, lowered by its values) and `direct` (one
//! read straight from the text), `gas_particle` (the profile a `GasParticle` instance gives),
//! `start` and `close` (where a starting or closing node goes), `inline` (files and Inline),
//! `extern_proto` (the files EXTERNPROTOs name, and positions tagged with the file they are
//! in) and `route` (ROUTE checks).

mod close;
mod declare;
mod direct;
mod dispatch;
mod extern_proto;
mod gas_particle;
mod inline;
mod instance;
mod proto;
mod record;
mod replay;
mod route;
mod scope;
mod start;
mod template;

use std::rc::Rc;

use crate::error::Error;
use crate::source::{Pos, SourceWindow};
use crate::vrml::lower::build::Builder;
use crate::vrml::lower::context::Ctx;
use crate::vrml::sphere_node::read_sphere_node;
use crate::vrml::syntax::{Event, Sink};

use extern_proto::Externs;
use inline::Files;
use instance::Expansions;
use proto::ProtoDecl;
use record::Recording;
use replay::Replay;
use scope::Scopes;

pub(in crate::vrml::lower) use record::Rec;

/// What expanding a scene holds between events: recordings, namespaces, the expansions and
/// files under way.
#[derive(Default)]
pub(in crate::vrml::lower) struct Expander {
    /// PROTO instances lowered by a sphere template (`template`).
    pub(in crate::vrml::lower) templated: u64,
    /// The PROTO instance read straight into its template (`direct`).
    direct: direct::Direct,
    /// The PROTO instances whose frames are open, with their depth in the open frames
    /// (`start`).
    instances: Vec<(usize, Rc<ProtoDecl>)>,
    /// Recorded events and the recordings under way (`record`).
    pub(in crate::vrml::lower) rec: Recording,
    /// How deep replays nest, and whether DEFs are being read again (`replay`).
    replay: Replay,
    /// DEF and PROTO namespaces (`scope`).
    pub(in crate::vrml::lower) scopes: Scopes,
    /// The PROTO expansions under way (`instance`).
    expansions: Expansions,
    /// The file being read and the chain of Inlines to it (`inline`).
    pub(in crate::vrml::lower) files: Files,
    /// The files read for their PROTOs (`extern_proto`).
    externs: Externs,
    /// A chunk being read on its own (`lower::parallel`).
    pub(in crate::vrml::lower) watch: Option<Watch>,
    /// Names chunks read on their own DEF'd: the main reader may not use them.
    pub(in crate::vrml::lower) poison: Option<hashbrown::HashSet<String>>,
    /// Why what was read in pieces must be read again by one reader.
    pub(in crate::vrml::lower) fallback: Option<String>,
}

/// Watching a chunk's lowering (set on a worker's lowerer once its prefix is read).
pub(in crate::vrml::lower) struct Watch {
    /// Arena position where the chunk began: DEFs recorded before it are the prefix's.
    pub(in crate::vrml::lower) arena_mark: usize,
    /// File-scope names the chunk USEd or ROUTEd from the prefix's DEFs.
    pub(in crate::vrml::lower) imports: Vec<String>,
    /// Nodes counted when the chunk began (the budget spent is watched in
    /// [`Ctx::headroom`]).
    pub(in crate::vrml::lower) nodes_at_start: u64,
    /// PROTO instances lowered by a template when the chunk began.
    pub(in crate::vrml::lower) templated_at_start: u64,
    /// Sphere nodes read whole when the chunk began.
    pub(in crate::vrml::lower) whole_at_start: u64,
    /// The chunk declared a PROTO or EXTERNPROTO in the file's scope, which the chunks after
    /// it and the main reader would not know.
    pub(in crate::vrml::lower) declared: bool,
}

/// The expander with the builder and context lent to it: what the parser's events go to
/// (the scene file's, and those of the files it reads in place).
pub(in crate::vrml::lower) struct Lent<'a> {
    pub(in crate::vrml::lower) x: &'a mut Expander,
    pub(in crate::vrml::lower) cx: &'a mut Ctx,
    pub(in crate::vrml::lower) b: &'a mut Builder,
}

impl Sink for Lent<'_> {
    #[inline(always)]
    fn event(&mut self, src: &SourceWindow, ev: Event<'_>) -> Result<(), Error> {
        self.x.dispatch(self.cx, self.b, src, ev)
    }

    /// Plain sphere nodes ([`crate::vrml::sphere_node`]) are taken whole.
    fn whole_node(
        &mut self,
        src: &SourceWindow,
        at: Pos,
        text: &str,
    ) -> Result<Option<usize>, Error> {
        if !text.starts_with('T') {
            return Ok(None);
        }
        let mut node = self.b.sphere_text.take().unwrap_or_default();
        let taken = read_sphere_node(text, &mut node)
            && self.x.whole_sphere_node(self.cx, self.b, src, at, &node)?;
        let len = node.len;
        self.b.sphere_text = Some(node);
        Ok(taken.then_some(len))
    }

    fn flat_node(
        &mut self,
        src: &SourceWindow,
        at: Pos,
        text: &str,
        node: &crate::vrml::parse::flat::FlatNode,
    ) -> Result<bool, Error> {
        self.x.whole_instance(self.cx, self.b, src, at, text, node)
    }
}

impl Expander {
    /// Looks a DEF name up in the innermost namespace, noting (in the file's namespace) a
    /// chunk's use of the prefix's DEFs and the main reader's use of names chunks DEF'd.
    pub(in crate::vrml::lower) fn lookup_def(&mut self, name: &str) -> Option<scope::DefEntry> {
        let d = self.scopes.def(name).cloned();
        if self.scopes.depth() == 1 {
            if let Some(w) = &mut self.watch {
                if d.as_ref().is_some_and(|d| d.range.start < w.arena_mark) {
                    w.imports.push(name.to_string());
                }
            }
            if self.poison.as_ref().is_some_and(|p| p.contains(name)) {
                self.fallback
                    .get_or_insert_with(|| format!("'{name}' is used after a chunk DEF'd it"));
                // The pieces' result cannot stand: not found, so that the main reader stops
                // here (a USE of an unknown name is an error) rather than read on to the end
                // for nothing (copies of a Jmol export, 1e6 atoms, two threads: 3.66 s, then
                // about one reader's time).
                return None;
            }
        }
        d
    }
}
