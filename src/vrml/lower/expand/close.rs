//! What happens at a node's `}`. Recordings that end there are registered (a DEF's name now
//! means its events), a Switch choice is kept for its Switch and a PROTO instance is
//! expanded; an Inline reads its file and a Switch replays its choice; otherwise the scene
//! builder closes the node's frame (`build::close`).

use super::record::{Done, Rec, RecKind};
use super::scope::DefEntry;
use super::Expander;
use crate::error::Error;
use crate::source::SourceWindow;
use crate::vrml::lower::build::meshes::Geom;
use crate::vrml::lower::build::open::{Frame, Kind, Result_};
use crate::vrml::lower::build::Builder;
use crate::vrml::lower::context::Ctx;
use crate::vrml::syntax::OwnedEvent;

impl Expander {
    /// A node's `}`; `done` are the recordings that ended with it.
    pub(in crate::vrml::lower) fn node_end(
        &mut self,
        cx: &mut Ctx,
        b: &mut Builder,
        src: &SourceWindow,
        done: Done,
    ) -> Result<(), Error> {
        if done.is_empty() && b.open.quiet == 0 {
            if let Some(result) = b.close_top_leaf(cx) {
                b.deliver(result);
                return Ok(());
            }
        }
        // Register DEFs first: the node is complete.
        let mut instance = None;
        let mut choice = None;
        let mut done = done;
        for (kind, range) in done.drain(..) {
            match kind {
                RecKind::Def(name) if self.rec.proto_decls == 0 => {
                    let ty = match &self.rec.arena[range.start] {
                        Rec::Ev(OwnedEvent::NodeStart { ty, .. }) => ty.clone(),
                        _ => std::rc::Rc::from("?"),
                    };
                    let end = range.end;
                    self.scopes.define(name, DefEntry { range, ty });
                    self.rec.pinned = self.rec.pinned.max(end);
                }
                RecKind::Instance => instance = Some(range),
                RecKind::Choice => choice = Some(range),
                _ => {}
            }
        }
        self.rec.hand_back(done);
        let depth = b.open.frames.len();
        let frame = b.open.pop_closing();
        if let Some(range) = choice {
            if let Some(Frame {
                kind: Kind::Switch { choices, .. },
                ..
            }) = b.open.frames.last_mut()
            {
                choices.push(range);
            }
            return Ok(());
        }
        if let Some(range) = instance {
            if let Some(proto) = self.instance_proto(depth) {
                self.expand(cx, b, src, proto, range.clone(), frame.at)?;
                // The instance's recording is no longer needed unless a DEF refers into it.
                self.rec.release(range.start);
            }
            return Ok(());
        }
        if b.open.quiet > 0 || matches!(frame.kind, Kind::Quiet | Kind::Skip) {
            let result = if matches!(frame.kind, Kind::Skip) && b.open.quiet == 0 {
                Result_::Geometry(Geom::Other)
            } else {
                Result_::Nothing
            };
            b.deliver(result);
            return Ok(());
        }
        let at = frame.at;
        match frame.kind {
            Kind::Group {
                inline_urls: Some(_),
                ..
            } => self.close_inline(cx, b, src, frame)?,
            Kind::Switch {
                which, ref choices, ..
            } if usize::try_from(which).is_ok_and(|w| w < choices.len()) => {
                let range = choices[which as usize].clone();
                b.open.frames.push(frame);
                self.replay_reused(cx, b, src, range, at, "Switch choice")?;
                let frame = b.open.frames.pop().expect("switch frame");
                b.close_group_like(cx, src, frame.kind, at)?;
            }
            _ => {
                let result = b.close(cx, src, frame)?;
                b.deliver(result);
            }
        }
        Ok(())
    }
}
