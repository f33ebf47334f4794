//! What happens at a node's `}`. Recordings that end there are registered (a DEF's name now
//! means its events), a Switch choice is kept for its Switch and a PROTO instance is
//! expanded; an Inline reads its file and a Switch replays its choice; otherwise the scene
//! builder closes the node's frame (`build::close`).

use super::build::meshes::Geom;
use super::build::open::{Frame, Kind, Result_};
use super::record::{Done, Rec, RecKind};
use super::scope::DefEntry;
use super::Lowerer;
use crate::error::Error;
use crate::source::SourceWindow;
use crate::vrml::syntax::OwnedEvent;

impl Lowerer {
    /// A node's `}`; `done` are the recordings that ended with it.
    pub(super) fn node_end(&mut self, src: &SourceWindow, done: Done) -> Result<(), Error> {
        if done.is_empty() && self.build.open.quiet == 0 {
            if let Some(result) = self.build.close_top_leaf(&mut self.cx) {
                self.build.deliver(result);
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
        let depth = self.build.open.frames.len();
        let frame = self.build.open.pop_closing();
        if let Some(range) = choice {
            if let Some(Frame {
                kind: Kind::Switch { choices, .. },
                ..
            }) = self.build.open.frames.last_mut()
            {
                choices.push(range);
            }
            return Ok(());
        }
        if let Some(range) = instance {
            if let Some(proto) = self.instance_proto(depth) {
                self.expand(src, proto, range.clone(), frame.at)?;
                // The instance's recording is no longer needed unless a DEF refers into it.
                self.rec.release(range.start);
            }
            return Ok(());
        }
        if self.build.open.quiet > 0 || matches!(frame.kind, Kind::Quiet | Kind::Skip) {
            let result = if matches!(frame.kind, Kind::Skip) && self.build.open.quiet == 0 {
                Result_::Geometry(Geom::Other)
            } else {
                Result_::Nothing
            };
            self.build.deliver(result);
            return Ok(());
        }
        let at = frame.at;
        match frame.kind {
            Kind::Group {
                inline_urls: Some(_),
                ..
            } => self.close_inline(src, frame)?,
            Kind::Switch {
                which, ref choices, ..
            } if usize::try_from(which).is_ok_and(|w| w < choices.len()) => {
                let range = choices[which as usize].clone();
                self.build.open.frames.push(frame);
                self.replay_reused(src, range, at, "Switch choice")?;
                let frame = self.build.open.frames.pop().expect("switch frame");
                self.build
                    .close_group_like(&mut self.cx, src, frame.kind, at)?;
            }
            _ => {
                let result = self.build.close(&mut self.cx, src, frame)?;
                self.build.deliver(result);
            }
        }
        Ok(())
    }
}
