//! Diagnostics: the warnings (repeats folded), notes and skipped node types met while
//! loading, and errors made at a position, each turned into `file:line:col` in the file the
//! position is in (the file being read, or a file read for its PROTOs).

use std::collections::BTreeMap;
use std::rc::Rc;
use std::sync::Arc;

// hashbrown's default hasher (foldhash), not SipHash: every lookup in lowering is on names and
// offsets from the scene text, hashed once per node or field of each PROTO instance.
use hashbrown::HashMap;

use crate::diag::{Diagnostic, Severity};
use crate::error::Error;
use crate::source::{Pos, SourceWindow};

/// Warnings (repeats folded) and the node types counted as skipped.
#[derive(Default)]
pub(super) struct Diags {
    pub(super) warnings: Vec<Diagnostic>,
    /// Where each (file, message) is in `warnings`.
    pub(super) index: HashMap<(Arc<str>, String), usize>,
    pub(super) skipped: BTreeMap<String, u64>,
    pub(super) notes: Vec<Diagnostic>,
    /// The files read for their PROTOs (EXTERNPROTO), by index in `Scene::files`: positions
    /// tagged with one of them point into it, not into the file being read (see
    /// [`Pos::tagged`]).
    pub(super) sources: HashMap<u32, Rc<SourceWindow>>,
}

impl Diags {
    /// The source that position `at` is in, and its offset there: `src` (the file being read)
    /// unless `at` is tagged with a file read for its PROTOs.
    pub(super) fn locate<'a>(&'a self, src: &'a SourceWindow, at: Pos) -> (&'a SourceWindow, u64) {
        match at.file() {
            Some(file) => (self.sources.get(&file).map_or(src, |s| &**s), at.offset()),
            None => (src, at.offset()),
        }
    }

    /// A note: not a problem (`--strict` does not refuse it), a choice the user should see.
    pub(super) fn note(&mut self, src: &SourceWindow, at: Pos, msg: impl Into<String>) {
        let (src, at) = self.locate(src, at);
        let d = src.diagnostic(Severity::Note, at, msg.into());
        // Repeats (a PROTO of points instanced many times) are folded, as warnings are.
        if let Some(first) = self
            .notes
            .iter_mut()
            .find(|n| n.message == d.message && n.file == d.file)
        {
            first.repeats += 1;
            return;
        }
        self.notes.push(d);
    }

    /// A warning; repeats of the same message in the same file are folded into the first.
    pub(super) fn warn(&mut self, src: &SourceWindow, at: Pos, msg: impl Into<String>) {
        let (src, at) = self.locate(src, at);
        let msg = msg.into();
        let key = (src.name.clone(), msg);
        if let Some(&i) = self.index.get(&key) {
            self.warnings[i].repeats += 1;
            return;
        }
        let d = src.diagnostic(Severity::Warning, at, key.1.clone());
        self.index.insert(key, self.warnings.len());
        self.warnings.push(d);
    }

    /// An error at `at` (in `src`, or in the file `at` is tagged with).
    pub(super) fn error(&self, src: &SourceWindow, at: Pos, msg: impl Into<String>) -> Error {
        let (src, at) = self.locate(src, at);
        Error::Diag(Box::new(src.diagnostic(Severity::Error, at, msg.into())))
    }

    /// Counts one more instance of a node type that is not lowered.
    pub(super) fn skip(&mut self, ty: &str) {
        *self.skipped.entry(ty.to_string()).or_default() += 1;
    }
}
