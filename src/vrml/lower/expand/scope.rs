//! DEF and PROTO namespaces. Each file has one, and so has each PROTO body expansion (VRML97
//! 4.6.3 and 4.8.3); a [`Scope`] maps DEF names to their recorded events and PROTO names to
//! their declarations. DEF lookups see only the innermost scope; PROTO lookups go outwards
//! through enclosing PROTO bodies but stop at the file (an Inline'd file does not see the
//! PROTOs of the file that includes it). The body of a PROTO read from another file for an
//! EXTERNPROTO is expanded under a file scope holding that file's PROTOs (its home), so it
//! sees those and not the ones around the instance. [`Scopes`] also remembers whether a PROTO
//! was given a standard node type's name, since standard types must then be looked up among
//! PROTOs too.

use std::ops::Range;
use std::rc::Rc;

use hashbrown::HashMap;

use super::proto::{ProtoDecl, Protos};
use crate::vrml::schema::same_bytes;

/// A DEF: the arena range of its node's events, and its node type.
#[derive(Clone, Debug)]
pub(in crate::vrml::lower) struct DefEntry {
    pub(in crate::vrml::lower) range: Range<usize>,
    pub(in crate::vrml::lower) ty: Rc<str>,
}

/// A DEF and PROTO namespace: one per file, one per PROTO body expansion.
#[derive(Default)]
pub(in crate::vrml::lower) struct Scope {
    defs: HashMap<Rc<str>, DefEntry>,
    protos: Protos,
    /// The PROTOs of another file, shared: the home of an external PROTO's body.
    home: Option<Rc<Protos>>,
    /// Names whose DEF'd node is still open (a Script may USE itself).
    open_defs: Vec<Rc<str>>,
    /// File scopes stop PROTO lookups from reaching the including file.
    file_root: bool,
}

/// The namespaces in effect, innermost last.
#[derive(Default)]
pub(in crate::vrml::lower) struct Scopes {
    stack: Vec<Scope>,
    /// A PROTO was declared with a standard node type's name: standard types must then be
    /// looked up among the PROTOs too (otherwise they cannot name one).
    pub(in crate::vrml::lower) proto_shadows_standard: bool,
    /// The last name [`Self::proto_memo`] looked up and what it found (a file of a million
    /// instances names the same PROTO a million times). Forgotten whenever the namespaces
    /// change.
    memo: Option<(String, Rc<ProtoDecl>)>,
}

impl Scopes {
    /// Enters a file's namespace.
    pub(in crate::vrml::lower) fn push_file(&mut self) {
        self.memo = None;
        self.stack.push(Scope {
            file_root: true,
            ..Scope::default()
        });
    }

    /// Enters a PROTO body expansion's namespace.
    pub(in crate::vrml::lower) fn push_body(&mut self) {
        self.memo = None;
        self.stack.push(Scope::default());
    }

    /// Enters the file scope of an external PROTO's body: the PROTOs of its file, and none
    /// of those around the instance.
    pub(in crate::vrml::lower) fn push_home(&mut self, home: Rc<Protos>) {
        self.memo = None;
        self.stack.push(Scope {
            file_root: true,
            home: Some(home),
            ..Scope::default()
        });
    }

    pub(in crate::vrml::lower) fn pop(&mut self) {
        self.memo = None;
        self.stack.pop();
    }

    /// Leaves a file's namespace, keeping the PROTOs it declared.
    pub(in crate::vrml::lower) fn pop_protos(&mut self) -> Protos {
        self.memo = None;
        self.stack.pop().map(|s| s.protos).unwrap_or_default()
    }

    /// How many namespaces are in effect (for [`Self::take_above`]).
    pub(in crate::vrml::lower) fn depth(&self) -> usize {
        self.stack.len()
    }

    /// Takes away the namespaces entered since there were `depth` (to be put back by
    /// [`Self::restore`]): an instance's value is read in the instance's namespace, not in
    /// the namespaces of the body it is substituted into.
    pub(in crate::vrml::lower) fn take_above(&mut self, depth: usize) -> Vec<Scope> {
        self.memo = None;
        self.stack.split_off(depth.min(self.stack.len()))
    }

    /// Leaves the namespaces entered since there were `depth`.
    pub(in crate::vrml::lower) fn leave_to(&mut self, depth: usize) {
        self.memo = None;
        self.stack.truncate(depth);
    }

    /// Puts back the namespaces [`Self::take_above`] took.
    pub(in crate::vrml::lower) fn restore(&mut self, scopes: Vec<Scope>) {
        self.memo = None;
        self.stack.extend(scopes);
    }

    pub(in crate::vrml::lower) fn def(&self, name: &str) -> Option<&DefEntry> {
        self.stack.last().and_then(|s| s.defs.get(name))
    }

    pub(in crate::vrml::lower) fn proto(&self, name: &str) -> Option<Rc<ProtoDecl>> {
        for s in self.stack.iter().rev() {
            if let Some(p) = s.protos.get(name) {
                return Some(p.clone());
            }
            if let Some(p) = s.home.as_ref().and_then(|h| h.get(name)) {
                return Some(p.clone());
            }
            if s.file_root {
                break;
            }
        }
        None
    }

    /// [`Self::proto`], remembering the last name looked up while the namespaces stay the same.
    pub(in crate::vrml::lower) fn proto_memo(&mut self, name: &str) -> Option<Rc<ProtoDecl>> {
        if let Some((n, p)) = &self.memo {
            if same_bytes(n.as_bytes(), name.as_bytes()) {
                return Some(p.clone());
            }
        }
        let p = self.proto(name)?;
        let mut n = self.memo.take().map(|(n, _)| n).unwrap_or_default();
        n.clear();
        n.push_str(name);
        self.memo = Some((n, p.clone()));
        Some(p)
    }

    /// The names the file's namespace has defined from arena position `mark` on.
    pub(in crate::vrml::lower) fn file_defs_since(&self, mark: usize) -> Vec<String> {
        self.stack.first().map_or_else(Vec::new, |s| {
            s.defs
                .iter()
                .filter(|(_, d)| d.range.start >= mark)
                .map(|(n, _)| n.to_string())
                .collect()
        })
    }

    /// A DEF'd node of this name has started and not yet ended.
    pub(in crate::vrml::lower) fn open_def(&mut self, name: &Rc<str>) {
        if let Some(s) = self.stack.last_mut() {
            s.open_defs.push(name.clone());
        }
    }

    /// Whether the DEF'd node of this name is still open (a USE of it is inside it).
    pub(in crate::vrml::lower) fn is_open(&self, name: &str) -> bool {
        self.stack
            .last()
            .is_some_and(|s| s.open_defs.iter().any(|n| &**n == name))
    }

    /// A DEF'd node has ended: its name now means its events.
    pub(in crate::vrml::lower) fn define(&mut self, name: Rc<str>, def: DefEntry) {
        if let Some(s) = self.stack.last_mut() {
            s.open_defs.retain(|n| *n != name);
            s.defs.insert(name, def);
        }
    }

    /// A PROTO declaration has ended: its name now means it.
    pub(in crate::vrml::lower) fn declare(
        &mut self,
        name: Rc<str>,
        decl: Rc<ProtoDecl>,
        standard_name: bool,
    ) {
        self.memo = None;
        self.proto_shadows_standard |= standard_name;
        if let Some(s) = self.stack.last_mut() {
            s.protos.insert(name, decl);
        }
    }
}
