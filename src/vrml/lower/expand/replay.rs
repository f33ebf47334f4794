//! Replaying recorded events: a USE replays its DEF's events, a Switch replays its chosen
//! choice, and a PROTO instance replays its body (in `instance`). Replays nest (a USE inside a
//! DEF, an instance inside a body), and every level costs stack, so one depth counter guards
//! them all: at most [`MAX_REPLAY_DEPTH`] replays may be under way at once, and the next one
//! is an error at the USE or instance that would start it. While a USE or choice is
//! replayed, the DEFs inside it are not registered again (they were when first read).

use std::ops::Range;

use super::record::Rec;
use super::Expander;
use crate::error::Error;
use crate::source::{Pos, SourceWindow};
use crate::vrml::lower::build::open::{Frame, Kind};
use crate::vrml::lower::build::Builder;
use crate::vrml::lower::context::Ctx;
use crate::vrml::syntax::OwnedEvent;

/// How many USE, Switch choice and PROTO body replays may nest (each level is a few stack
/// frames of the event handlers, well within a 2 MiB thread stack).
pub(in crate::vrml::lower) const MAX_REPLAY_DEPTH: u32 = 200;

/// The replays under way.
#[derive(Default)]
pub(in crate::vrml::lower) struct Replay {
    /// Replays nested now (bounded by [`MAX_REPLAY_DEPTH`]).
    pub(in crate::vrml::lower) depth: u32,
    /// Replaying a USE or a Switch choice: DEFs inside were registered when first read.
    pub(in crate::vrml::lower) reusing: u32,
}

impl Expander {
    /// Enters one more level of replay; an error at `at` if that would make more than
    /// [`MAX_REPLAY_DEPTH`]. `what` names the replays in the message.
    #[inline(always)]
    pub(in crate::vrml::lower) fn enter_replay(
        &mut self,
        cx: &mut Ctx,
        src: &SourceWindow,
        at: Pos,
        what: &str,
    ) -> Result<(), Error> {
        if self.replay.depth >= MAX_REPLAY_DEPTH {
            return Err(cx.diags.error(
                src,
                at,
                format!("{what} nest deeper than {MAX_REPLAY_DEPTH}"),
            ));
        }
        self.replay.depth += 1;
        Ok(())
    }

    /// Replays the arena's events in `range` (a DEF'd node, a Switch choice or an `IS`
    /// value) for the `what` at `at`, each spending its cost of the expansion budget.
    pub(in crate::vrml::lower) fn replay(
        &mut self,
        cx: &mut Ctx,
        b: &mut Builder,
        src: &SourceWindow,
        range: Range<usize>,
        at: Pos,
        what: &str,
    ) -> Result<(), Error> {
        self.enter_replay(cx, src, at, "USE and PROTO expansions")?;
        let mut i = range.start;
        while i < range.end {
            let rec = self.rec.arena[i].clone();
            match rec {
                Rec::Ev(ev) => {
                    cx.spend(crate::vrml::lower::event_cost(&ev), src, at, what)?;
                    self.handle(cx, b, src, ev.as_event())?
                }
                Rec::Used { range, at } => self.use_range(cx, b, src, range, at)?,
            }
            i += 1;
        }
        self.replay.depth -= 1;
        Ok(())
    }

    /// Replays a recording that was read before (a USE or a Switch choice): nothing is
    /// recorded again and the DEFs inside are not registered again.
    pub(in crate::vrml::lower) fn replay_reused(
        &mut self,
        cx: &mut Ctx,
        b: &mut Builder,
        src: &SourceWindow,
        range: Range<usize>,
        at: Pos,
        what: &str,
    ) -> Result<(), Error> {
        // Replaying must not record the replayed events again into the same recorders: they
        // already hold what stands for them (a `Used` entry, or the Switch's own events).
        let saved = std::mem::take(&mut self.rec.recorders);
        self.replay.reusing += 1;
        let r = self.replay(cx, b, src, range, at, what);
        self.replay.reusing -= 1;
        self.rec.recorders = saved;
        r
    }

    /// A resolved USE: recorded as such if recording, replayed if lowering.
    pub(in crate::vrml::lower) fn use_range(
        &mut self,
        cx: &mut Ctx,
        b: &mut Builder,
        src: &SourceWindow,
        range: Range<usize>,
        at: Pos,
    ) -> Result<(), Error> {
        if !self.rec.recorders.is_empty() {
            self.rec.arena.push(Rec::Used {
                range: range.clone(),
                at,
            });
        }
        if b.open.quiet == 0 {
            // A USE'd IndexedFaceSet as a Shape's geometry: lowered once, then looked up.
            let mesh = self.is_mesh_use(b, range.start);
            if mesh && b.reuse_mesh(cx, src, range.start, at)? {
                return Ok(());
            }
            self.replay_reused(cx, b, src, range.clone(), at, "USE")?;
            if mesh {
                b.remember_mesh(range.start);
            }
        } else if let Some(Frame {
            kind: Kind::Switch { choices, .. },
            ..
        }) = b.open.frames.last_mut()
        {
            // A USE among a Switch's choices is a choice of its own.
            choices.push(range);
        }
        Ok(())
    }
    /// Whether a USE of the recording at `start` is of a mesh as a Shape's geometry (lowered
    /// once, then looked up).
    pub(in crate::vrml::lower) fn is_mesh_use(&self, b: &Builder, start: usize) -> bool {
        b.open.in_shape_geometry()
            && matches!(&self.rec.arena[start],
                Rec::Ev(OwnedEvent::NodeStart { ty, .. })
                    if matches!(&**ty, "IndexedFaceSet" | "PointSet" | "ElevationGrid" | "Extrusion"))
    }
}
