//! Recording events for later replay. DEF'd nodes, PROTO declarations, PROTO instances,
//! Switch choices and interface defaults are kept as their events in one arena
//! ([`Recording::arena`]), never as trees; a [`Recorder`] marks where each recording under
//! way started and how many nodes are open inside it, and it ends when that returns to zero.
//! Names in recorded events are shared through an [`Interner`], so recording a PROTO
//! instance allocates no string per event. Entries below [`Recording::pinned`] belong to
//! DEFs and PROTOs and stay; the rest is released once an instance or choice is done. A file
//! read for its PROTOs while something is recorded is kept out of that recording
//! ([`Recording::set_aside`], [`Recording::resume`]).

use std::ops::Range;
use std::rc::Rc;

use hashbrown::HashSet;

use crate::source::Pos;
use crate::vrml::lower::build::open::Name;
use crate::vrml::syntax::{Event, OwnedEvent};

/// An event in the arena: as written, or a USE already resolved to the recording it names.
#[derive(Clone, Debug)]
pub(in crate::vrml::lower) enum Rec {
    Ev(OwnedEvent),
    /// A USE resolved when it was recorded (later redefinitions do not change what it means).
    Used {
        range: Range<usize>,
        at: Pos,
    },
}

/// What an active recording is for.
#[derive(Debug)]
pub(in crate::vrml::lower) enum RecKind {
    Def(Rc<str>),
    ProtoDecl,
    /// A node inside a Switch's `choice`: kept for replay when the Switch closes.
    Choice,
    /// A PROTO instance: expanded when it closes.
    Instance,
}

#[derive(Debug)]
pub(in crate::vrml::lower) struct Recorder {
    pub(in crate::vrml::lower) start: usize,
    /// Open nodes (or PROTOs for a ProtoDecl) inside the recording; it ends when this returns to 0.
    pub(in crate::vrml::lower) depth: u32,
    pub(in crate::vrml::lower) kind: RecKind,
}

/// Recordings set aside while another file is read (see [`Recording::set_aside`]).
pub(in crate::vrml::lower) struct SetAside {
    recorders: Vec<Recorder>,
    /// The arena's length when they were set aside.
    from: usize,
}

/// Recordings that ended at one event, with the arena range each recorded.
pub(in crate::vrml::lower) type Done = Vec<(RecKind, Range<usize>)>;

/// Slots of [`Interner::recent`].
const RECENT_NAMES: usize = 16;

/// Shared copies of node type and field names (DEF names are not kept here).
#[derive(Default)]
pub(in crate::vrml::lower) struct Interner {
    names: HashSet<Rc<str>>,
    /// The last name met in each slot of a small cache in front of `names`.
    recent: [Option<Rc<str>>; RECENT_NAMES],
}

impl Interner {
    /// A shared copy of `name`.
    pub(in crate::vrml::lower) fn rc(&mut self, name: &str) -> Rc<str> {
        // The same few names come back in turn (one PROTO instance after another): a small
        // direct-mapped cache answers most of them without hashing.
        let b = name.as_bytes();
        let slot = (b.len() ^ (usize::from(b.first().copied().unwrap_or(0)) * 3)) % RECENT_NAMES;
        if let Some(n) = &self.recent[slot] {
            if n.as_bytes() == b {
                return n.clone();
            }
        }
        let n = match self.names.get(name) {
            Some(n) => n.clone(),
            None => {
                let n: Rc<str> = Rc::from(name);
                self.names.insert(n.clone());
                n
            }
        };
        self.recent[slot] = Some(n.clone());
        n
    }
}

/// The event arena and the recordings under way.
#[derive(Default)]
pub(in crate::vrml::lower) struct Recording {
    pub(in crate::vrml::lower) arena: Vec<Rec>,
    /// Arena entries below this are referenced by DEFs or PROTOs and must stay.
    pub(in crate::vrml::lower) pinned: usize,
    pub(in crate::vrml::lower) recorders: Vec<Recorder>,
    /// Open PROTO declarations being recorded (their contents are neither lowered nor checked).
    pub(in crate::vrml::lower) proto_decls: u32,
    /// Node type and field names of recorded events, shared (no allocation per recorded event).
    pub(in crate::vrml::lower) names: Interner,
    /// A buffer for the recordings that end at one event (see `end_slow`).
    done_buf: Done,
    /// A PROTO instance is being read into its template (`direct`): its events go there.
    pub(in crate::vrml::lower) direct: bool,
}

impl Recording {
    /// Nothing is being recorded, no PROTO declaration is open and no instance is read into
    /// its template: events of plain scene text may take the fast path (see `dispatch`).
    #[inline(always)]
    pub(in crate::vrml::lower) fn idle(&self) -> bool {
        self.recorders.is_empty() && self.proto_decls == 0 && !self.direct
    }

    /// Appends `ev` to the arena if anything is recording.
    pub(in crate::vrml::lower) fn record(&mut self, ev: &Event) {
        if self.recorders.is_empty() {
            return;
        }
        let owned = match *ev {
            Event::NodeStart { def: None, ty, at } => OwnedEvent::NodeStart {
                def: None,
                ty: self.names.rc(ty),
                at,
            },
            Event::Field { name, at, value } => OwnedEvent::Field {
                name: self.names.rc(name),
                at,
                value: value.to_owned_value(),
            },
            Event::NodesStart { name, at } => OwnedEvent::NodesStart {
                name: self.names.rc(name),
                at,
            },
            _ => ev.to_owned_event(),
        };
        self.arena.push(Rec::Ev(owned));
    }

    /// Called after an event has been handled: closes recorders whose node (or PROTO) ended.
    #[inline]
    pub(in crate::vrml::lower) fn end(&mut self, ev: &Event) -> Done {
        if self.recorders.is_empty() {
            return Vec::new();
        }
        self.end_slow(ev)
    }

    /// [`Self::end`] when something is recording.
    pub(in crate::vrml::lower) fn end_slow(&mut self, ev: &Event) -> Done {
        let mut done = Vec::new();
        let (open, close) = match ev {
            Event::NodeStart { .. } => (true, false),
            Event::NodeEnd { .. } => (false, true),
            Event::ProtoStart { .. } => (true, false),
            Event::ProtoEnd { .. } => (false, true),
            _ => (false, false),
        };
        if !open && !close {
            return done;
        }
        for r in self.recorders.iter_mut() {
            if open {
                r.depth += 1;
            } else {
                r.depth -= 1;
            }
        }
        // A recorder that began at this very event started with depth 0 before the increment.
        while let Some(r) = self.recorders.last() {
            if r.depth == 0 {
                let r = self.recorders.pop().expect("recorder");
                if done.capacity() == 0 {
                    // (One per PROTO instance: `hand_back` returns the buffer.)
                    done = std::mem::take(&mut self.done_buf);
                }
                done.push((r.kind, r.start..self.arena.len()));
            } else {
                break;
            }
        }
        done
    }

    /// Takes back the (emptied) buffer that [`Self::end`] handed out, for the next time.
    pub(in crate::vrml::lower) fn hand_back(&mut self, done: Done) {
        if done.capacity() > 0 {
            self.done_buf = done;
        }
    }

    /// Drops arena entries that nothing refers to (after a PROTO instance or Switch choice).
    pub(in crate::vrml::lower) fn release(&mut self, from: usize) {
        if self.recorders.is_empty() {
            let keep = from.max(self.pinned);
            if keep < self.arena.len() {
                self.arena.truncate(keep);
            }
        }
    }

    /// Starts recording a DEF'd node whose NodeStart is being handled (and was recorded just
    /// before, if anything was recording).
    pub(in crate::vrml::lower) fn start_def(&mut self, def: &Rc<str>, ty: &str, at: Pos) {
        let start = if self.recorders.is_empty() {
            self.arena.push(Rec::Ev(OwnedEvent::NodeStart {
                def: Some(def.clone()),
                ty: ty.into(),
                at,
            }));
            self.arena.len() - 1
        } else {
            self.arena.len() - 1
        };
        self.recorders.push(Recorder {
            start,
            depth: 0,
            kind: RecKind::Def(def.clone()),
        });
    }

    /// Starts a recorder of `kind` whose first event is the NodeStart just handled.
    pub(in crate::vrml::lower) fn start_here(
        &mut self,
        ty: &Name,
        def: Option<&str>,
        at: Pos,
        kind: RecKind,
    ) {
        let start = if self.recorders.is_empty() {
            let ty = match ty {
                Name::Shared(rc) => rc.clone(),
                Name::Static(s) => self.names.rc(s),
            };
            self.arena.push(Rec::Ev(OwnedEvent::NodeStart {
                def: def.map(Rc::from),
                ty,
                at,
            }));
            self.arena.len() - 1
        } else {
            // Already recorded by the enclosing recorder; a DEF recorder may have started here too.
            self.recorders
                .last()
                .filter(|r| r.depth == 0)
                .map(|r| r.start)
                .unwrap_or(self.arena.len() - 1)
        };
        self.recorders.push(Recorder {
            start,
            depth: 0,
            kind,
        });
    }

    /// Starts recording a PROTO declaration at its ProtoStart event (outside any other).
    pub(in crate::vrml::lower) fn start_proto_decl(&mut self, ev: &Event) {
        self.recorders.push(Recorder {
            start: self.arena.len() - usize::from(!self.recorders.is_empty()),
            depth: 0,
            kind: RecKind::ProtoDecl,
        });
        if self.recorders.len() == 1 {
            self.arena.push(Rec::Ev(ev.to_owned_event()));
        }
    }

    /// Sets the recordings under way aside while another file is read inside them (an
    /// external PROTO's file): its events are its own, not theirs.
    pub(in crate::vrml::lower) fn set_aside(&mut self) -> SetAside {
        SetAside {
            recorders: std::mem::take(&mut self.recorders),
            from: self.arena.len(),
        }
    }

    /// Resumes the recordings [`Self::set_aside`] set aside. What the other file left in the
    /// arena meanwhile is not theirs, and each recording must stay one range: the part they
    /// had recorded is copied after it, and they go on from the copy (the earlier copy stays,
    /// for what already refers into it).
    pub(in crate::vrml::lower) fn resume(&mut self, aside: SetAside) {
        let mut recorders = aside.recorders;
        if let Some(first) = recorders.iter().map(|r| r.start).min() {
            if self.arena.len() > aside.from {
                let to = self.arena.len();
                self.arena.extend_from_within(first..aside.from);
                for r in &mut recorders {
                    r.start = to + (r.start - first);
                }
            }
        }
        self.recorders = recorders;
    }

    /// Whether a Switch choice is being recorded (a node inside it is part of that choice).
    pub(in crate::vrml::lower) fn in_choice(&self) -> bool {
        self.recorders
            .iter()
            .any(|r| matches!(r.kind, RecKind::Choice))
    }
}

/// The end (exclusive) of the value that starts at `i`: one Field, or NodesStart .. NodesEnd.
pub(in crate::vrml::lower) fn value_end(arena: &[Rec], i: usize) -> usize {
    match arena.get(i) {
        Some(Rec::Ev(OwnedEvent::NodesStart { .. })) => {
            let mut depth = 0;
            let mut k = i;
            while k < arena.len() {
                match &arena[k] {
                    Rec::Ev(OwnedEvent::NodesStart { .. }) => depth += 1,
                    Rec::Ev(OwnedEvent::NodesEnd { .. }) => {
                        depth -= 1;
                        if depth == 0 {
                            return k + 1;
                        }
                    }
                    _ => {}
                }
                k += 1;
            }
            arena.len()
        }
        _ => i + 1,
    }
}

#[cfg(test)]
mod tests {
    use super::Rec;
    use crate::vrml::syntax::OwnedEvent;

    #[test]
    fn recorded_events_stay_small() {
        // The arena holds one per recorded event (a large PROTO library, DEF'd meshes): a
        // position is one word, and a resolved USE fits in an event's room.
        assert_eq!(std::mem::size_of::<OwnedEvent>(), 80);
        assert_eq!(std::mem::size_of::<Rec>(), 80);
    }
}
