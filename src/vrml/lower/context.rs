//! What every part of lowering shares: the load options, the nodes counted, the expansion
//! budget spent, the diagnostics and the file being read. The budget is what copies may
//! create (see [`LoadOptions::max_expansion`]); the file being read is the one IR origins
//! name unless a position is tagged with another. The parts borrow it for a call; none owns
//! it.

use crate::error::Error;
use crate::scene::Origin;
use crate::source::{Pos, SourceWindow};

use super::diags::Diags;
use super::LoadOptions;

/// Loading's shared state (see the module comment).
pub(super) struct Ctx {
    pub(super) opts: LoadOptions,
    /// Nodes lowered, USE and PROTO expansions included.
    pub(super) nodes: u64,
    /// The expansion budget spent: nodes and what copies create (see [`Self::spend`]).
    pub(super) spent: u64,
    /// Warnings, notes and skipped node types.
    pub(super) diags: Diags,
    /// The file being read, by index in `Scene::files` (positions not tagged with another
    /// file are in it).
    pub(super) file: u32,
    /// Set while a chunk is read on its own (`chunk`): how far its spending ran ahead.
    pub(super) headroom: Option<Headroom>,
}

/// How far the budget spent in a chunk read on its own ran ahead of what the bytes before the
/// cursor allow (checked when the chunk is put in place, against the text before it).
pub(super) struct Headroom {
    /// The budget spent when the chunk began.
    pub(super) spent_at_start: u64,
    /// The most that the budget spent since ran ahead of the bytes before the cursor.
    pub(super) excess: i64,
}

impl Ctx {
    pub(super) fn new(opts: LoadOptions) -> Self {
        Ctx {
            opts,
            nodes: 0,
            spent: 0,
            diags: Diags::default(),
            file: 0,
            headroom: None,
        }
    }

    /// Where an IR item made at `at` comes from: the file being read, or the file a PROTO
    /// body was read from (a tagged position, see [`Pos::tagged`]): the one conversion of
    /// positions to origins.
    #[inline]
    pub(super) fn origin(&self, at: Pos) -> Origin {
        Origin::new(at.file().unwrap_or(self.file), at.offset())
    }

    /// Counts `n` more lowered nodes, which spend as much of the expansion budget.
    #[inline]
    pub(super) fn add_nodes(&mut self, n: u64, src: &SourceWindow, at: Pos) -> Result<(), Error> {
        self.nodes += n;
        self.spend(n, src, at, "node")
    }

    /// The expansion budget once `bytes` of text are read: `expansion_base` plus
    /// `max_expansion` per byte. A blow-up through USE or PROTO grows far faster than the
    /// text, while a file of a hundred million particles (5e8 nodes from 13 GB of PROTO
    /// instances) is text all the way.
    #[inline(always)]
    pub(super) fn budget(&self, bytes: u64) -> u64 {
        self.opts
            .expansion_base
            .saturating_add(self.opts.max_expansion.saturating_mul(bytes))
    }

    /// Whether `n` more units fit the budget at the text read so far.
    #[inline(always)]
    pub(super) fn fits(&self, n: u64, src: &SourceWindow) -> bool {
        self.spent.saturating_add(n) <= self.budget(src.bytes_read)
    }

    /// Spends `n` units of the expansion budget on `what` at `at`, before what they stand for
    /// is made; an error there once the budget is exceeded.
    #[inline]
    pub(super) fn spend(
        &mut self,
        n: u64,
        src: &SourceWindow,
        at: Pos,
        what: &str,
    ) -> Result<(), Error> {
        self.spent = self.spent.saturating_add(n);
        self.watch_nodes(src.offset());
        let limit = self.budget(src.bytes_read);
        if self.spent > limit {
            return Err(self.diags.error(
                src,
                at,
                format!(
                    "this {what} takes the scene past its expansion limit: {limit} nodes and \
                     values ({} plus {} per byte of text read), as USE, PROTO or IS copies \
                     multiply; `--max-expansion` (Python: `max_expansion`) raises the {} \
                     per byte",
                    self.opts.expansion_base, self.opts.max_expansion, self.opts.max_expansion
                ),
            ));
        }
        Ok(())
    }

    /// Notes how far the budget spent in a chunk ran ahead of what the bytes before the
    /// cursor allow.
    #[inline]
    pub(super) fn watch_nodes(&mut self, cursor: u64) {
        if let Some(w) = &mut self.headroom {
            let allowed = self.opts.max_expansion.saturating_mul(cursor);
            let e = (self.spent - w.spent_at_start) as i64 - allowed.min(i64::MAX as u64) as i64;
            w.excess = w.excess.max(e);
        }
    }
}
