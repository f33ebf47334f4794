//! EXTERNPROTO (VRML97 4.9): the PROTO an EXTERNPROTO names is read from a local file, by
//! the rules of Inline (see `inline`: local paths relative to the declaring file only, never
//! a network URL or an absolute path; at most [`crate::vrml::lower::LoadOptions::max_inline_depth`] files
//! deep; a file that is being read is a cycle, an error). `"file.wrl#Name"` names the PROTO
//! `Name` declared at the top level of that file, `"file.wrl"` the first PROTO declared
//! there. The urls are tried in order; when none leads to a PROTO, the EXTERNPROTO stays a
//! declaration without a body (its instances are counted and skipped), with one warning
//! that says what was tried.
//!
//! A file is read once per scene (by canonical path) and only for its PROTO declarations: it
//! is parsed into the lowering under a quiet root frame, in a file namespace of its own, so
//! its top-level nodes are read (their DEFs serve its PROTOs' defaults) but not lowered, and
//! none of its DEFs or PROTOs leaks into the including file. The EXTERNPROTO then becomes
//! that PROTO (its body, its interface and defaults), expanded like a local one under the
//! PROTOs of its own file ([`ProtoDecl::home`]); the EXTERNPROTO's interface says which
//! fields instances may set ([`ProtoDecl::public`]): a field it declares that the PROTO lacks,
//! or declares with another access or type, is a warning at that declaration and cannot be
//! set.
//!
//! **Positions.** A PROTO read from another file is expanded while some other file is being
//! read. So that its messages, and the IR items it makes, still point into its own file,
//! every position recorded from that file is *tagged* with the file's index in
//! `Scene::files`, in the top bits, as [`crate::scene::Origin`] packs them (see
//! [`crate::source::Pos`]); `Diags` keeps the file's line index to turn tagged positions
//! into `file:line:col`, and `Expander::origin` turns them into origins in that file.

use std::path::{Path, PathBuf};
use std::rc::Rc;

use hashbrown::HashMap;

use super::inline::{local_path, Admit};
use super::proto::{InterfaceField, ProtoDecl, Protos};
use super::record::Rec;
use super::{Expander, Lent};
use crate::error::Error;
use crate::source::{Pos, SourceWindow};
use crate::vrml::lower::build::open::Name;
use crate::vrml::lower::build::Builder;
use crate::vrml::lower::context::Ctx;
use crate::vrml::parse::Parser;
use crate::vrml::syntax::OwnedEvent;

/// The position a recorded event stands at.
fn position_mut(rec: &mut Rec) -> &mut Pos {
    match rec {
        Rec::Used { at, .. } => at,
        Rec::Ev(ev) => match ev {
            OwnedEvent::NodeStart { at, .. }
            | OwnedEvent::NodeEnd { at }
            | OwnedEvent::Field { at, .. }
            | OwnedEvent::NodesStart { at, .. }
            | OwnedEvent::NodesEnd { at }
            | OwnedEvent::Use { at, .. }
            | OwnedEvent::Null { at }
            | OwnedEvent::Decl { at, .. }
            | OwnedEvent::ProtoStart { at, .. }
            | OwnedEvent::ProtoBody { at }
            | OwnedEvent::ProtoEnd { at, .. }
            | OwnedEvent::Route { at, .. } => at,
        },
    }
}

/// Tags the positions of recorded events with the file they were read from.
fn tag_all(recs: &mut [Rec], file: u32) {
    for r in recs {
        let at = position_mut(r);
        *at = at.tagged(file);
    }
}

/// A PROTO declared in file `file`, with its positions tagged (its interface defaults are in
/// the arena, tagged there).
fn tagged(decl: &ProtoDecl, file: u32) -> ProtoDecl {
    let mut events = decl.body_events.to_vec();
    tag_all(&mut events, file);
    let mut d = decl.clone();
    d.body_events = events.into();
    // (Its template's positions would be untagged; a PROTO of another file is replayed.)
    d.sphere = None;
    for f in &mut d.fields {
        f.at = f.at.tagged(file);
    }
    d
}

/// What is kept of a file read for its PROTOs, to place its positions: its name, its line
/// index and its last window (the line shown under a message), not its reader.
fn kept(src: SourceWindow) -> SourceWindow {
    let mut k = SourceWindow::new(src.name.clone(), Box::new(std::io::empty()));
    k.lines = src.lines;
    k.buf = src.buf;
    k.base = src.base;
    k.eof = true;
    k
}

/// A file read for its PROTOs.
struct Library {
    /// Its top-level PROTOs and EXTERNPROTOs, positions tagged.
    protos: Rc<Protos>,
    /// The first PROTO (not EXTERNPROTO) declared at its top level: what a url without
    /// `#Name` names.
    first: Option<Rc<str>>,
}

/// Why a file an EXTERNPROTO's url names gives no PROTOs.
enum Unread {
    /// It cannot be read: the reason, for the warning.
    Why(String),
    /// Its PROTOs are being read (it is the declaring file, or one that names it).
    Pending,
}

/// The files read for their PROTOs.
#[derive(Default)]
pub(in crate::vrml::lower) struct Externs {
    /// By canonical path: each file is read once per scene.
    libraries: HashMap<PathBuf, Rc<Library>>,
    /// The path of each, by its index in `Scene::files` (the folder of its relative urls).
    paths: HashMap<u32, PathBuf>,
    /// For each file being read for its PROTOs (innermost last), the first PROTO declared.
    reading: Vec<Option<Rc<str>>>,
    /// Their canonical paths, in the same order.
    reading_paths: Vec<PathBuf>,
    /// EXTERNPROTOs of a file read for its PROTOs left unloaded because they name a file
    /// whose PROTOs were being read (by that file's canonical path and their name): what
    /// needs one of them needs itself.
    pending: Vec<(PathBuf, Rc<str>)>,
}

impl Externs {
    /// The path of the file read for its PROTOs that has index `file` in `Scene::files`.
    pub(in crate::vrml::lower) fn path_of(&self, file: u32) -> Option<&Path> {
        self.paths.get(&file).map(PathBuf::as_path)
    }

    /// A PROTO was declared: the first one at the top level of a file read for its PROTOs
    /// is what a url without `#Name` names. (While such a file is read nothing is expanded,
    /// so every declaration then is at its top level.)
    pub(in crate::vrml::lower) fn declared(&mut self, name: &Rc<str>) {
        if let Some(first @ None) = self.reading.last_mut() {
            *first = Some(name.clone());
        }
    }
}

/// A url with the PROTO it names split off: `file.wrl#Name` -> (`file.wrl`, `Some("Name")`).
fn split_url(url: &str) -> (&str, Option<&str>) {
    match url.split_once('#') {
        Some((file, name)) if !name.is_empty() => (file, Some(name)),
        Some((file, _)) => (file, None),
        None => (url, None),
    }
}

impl Expander {
    /// What the EXTERNPROTO `name` (interface `iface`, declared at `at`) becomes: the PROTO
    /// named by the first of `urls` that leads to one; `None` (and a warning that lists what
    /// was tried) if none does, or when other files are not read (`LoadOptions::inline`).
    // (Its own arguments, and the context and builder lent to the expander.)
    #[allow(clippy::too_many_arguments)]
    pub(in crate::vrml::lower) fn import_proto(
        &mut self,
        cx: &mut Ctx,
        b: &mut Builder,
        src: &SourceWindow,
        name: &Rc<str>,
        iface: &[InterfaceField],
        urls: &[String],
        at: Pos,
    ) -> Result<Option<ProtoDecl>, Error> {
        if !cx.opts.inline {
            return Ok(None);
        }
        let base = self.base_dir(at);
        let mut tried = Vec::new();
        let mut pending = false;
        for url in urls {
            let (file, wanted) = split_url(url);
            let (lib, canon) = match self.library(cx, b, src, name, at, &base, url, file)? {
                Ok(lib) => lib,
                Err(Unread::Pending) => {
                    pending = true;
                    continue;
                }
                Err(Unread::Why(why)) => {
                    tried.push(why);
                    continue;
                }
            };
            let found = match wanted {
                Some(n) => lib.protos.get(n),
                None => lib.first.as_ref().and_then(|n| lib.protos.get(n)),
            };
            match found {
                Some(ext) if ext.body.is_some() => {
                    let ext = ext.clone();
                    return Ok(Some(self.adopt(cx, src, name, iface, &ext, &lib, url)));
                }
                Some(ext) if self.externs.pending.contains(&(canon, ext.name.clone())) => {
                    let msg = format!(
                        "EXTERNPROTO {name}: '{url}' names an EXTERNPROTO that needs a file \
                         whose PROTOs are being read: it needs itself (a cycle)"
                    );
                    return Err(cx.diags.error(src, at, msg));
                }
                Some(ext) => tried.push(format!(
                    "'{url}' (its {} is an EXTERNPROTO that was not loaded)",
                    ext.name
                )),
                None => tried.push(match wanted {
                    Some(n) => format!("'{url}' (no PROTO {n} at its top level)"),
                    None => format!("'{url}' (no PROTO at its top level)"),
                }),
            }
        }
        // Declared in a file whose PROTOs are being read, naming one of those files: unused
        // while declarations are read, so not worth a warning; noted, for what needs it.
        if pending && tried.is_empty() {
            if let Some(reading) = self.externs.reading_paths.last() {
                self.externs.pending.push((reading.clone(), name.clone()));
            }
            return Ok(None);
        }
        let what = if tried.is_empty() {
            "no url".to_string()
        } else {
            tried.join(", ")
        };
        cx.diags
            .warn(src, at, format!("EXTERNPROTO {name} not loaded: {what}"));
        Ok(None)
    }

    /// The file `file` (of `url`) read for its PROTOs: from the cache, or read now. Why not
    /// if it cannot be read (not a local relative path, no such file, not VRML97), or that
    /// its PROTOs are being read; an error at `at` if it would nest too deep.
    // (Its own arguments, and the context and builder lent to the expander.)
    #[allow(clippy::too_many_arguments)]
    fn library(
        &mut self,
        cx: &mut Ctx,
        b: &mut Builder,
        src: &SourceWindow,
        name: &str,
        at: Pos,
        base: &Path,
        url: &str,
        file: &str,
    ) -> Result<Result<(Rc<Library>, PathBuf), Unread>, Error> {
        let (path, canon) = match local_path(base, file) {
            Ok(p) => p,
            Err(why) => return Ok(Err(Unread::Why(format!("'{url}' ({why})")))),
        };
        if let Some(lib) = self.externs.libraries.get(&canon) {
            return Ok(Ok((lib.clone(), canon)));
        }
        // A file read for its PROTOs names itself, or a file whose PROTOs are being read:
        // those PROTOs are not all declared yet. Nothing needs them while declarations are
        // read; an instance of this EXTERNPROTO is then skipped like any not loaded.
        if self.externs.reading_paths.contains(&canon) {
            return Ok(Err(Unread::Pending));
        }
        // A file being read as a scene (the very file of this EXTERNPROTO, or one that
        // Inlines it) is read again for its PROTO declarations only, not its scene: no cycle.
        let admitted = match self.admit(cx, &path, &canon) {
            Admit::Cycle => self.admit_file(cx, &path),
            other => other,
        };
        match admitted {
            Admit::Yes => {}
            Admit::Cycle => {
                let msg = format!("EXTERNPROTO {name}: '{url}' names a file being read (a cycle)");
                return Err(cx.diags.error(src, at, msg));
            }
            Admit::TooDeep => {
                let max = cx.opts.max_inline_depth;
                let msg = format!("EXTERNPROTO {name}: '{url}' nests deeper than {max} files");
                return Err(cx.diags.error(src, at, msg));
            }
            Admit::NotVrml97 => {
                return Ok(Err(Unread::Why(format!("'{url}' (not a VRML97 file)"))))
            }
        }
        self.externs.reading_paths.push(canon.clone());
        let lib = self.read_library(cx, b, &path);
        self.externs.reading_paths.pop();
        let lib = Rc::new(lib?);
        self.externs.libraries.insert(canon.clone(), lib.clone());
        Ok(Ok((lib, canon)))
    }

    /// Reads the file at `path` for its PROTO declarations: parsed into the lowering like any
    /// file, in a namespace of its own, but under a quiet root (its nodes are read, not
    /// lowered nor counted) and apart from whatever is under way around it (recordings,
    /// expansions, open node-valued fields).
    fn read_library(
        &mut self,
        cx: &mut Ctx,
        b: &mut Builder,
        path: &Path,
    ) -> Result<Library, Error> {
        let src = crate::input::open(path, cx.opts.inflate_ratio())?;
        let file = u32::try_from(b.add_file(&src.name)).unwrap_or(u32::MAX);
        self.externs.paths.insert(file, path.to_path_buf());
        self.files.stack.push(path.to_path_buf());
        let current = std::mem::replace(&mut cx.file, file);
        let aside = self.rec.set_aside();
        let fields = std::mem::take(&mut b.open.fields);
        let substs = std::mem::take(&mut self.expansions.substs);
        let reusing = std::mem::replace(&mut self.replay.reusing, 0);
        let (nodes, spent) = (cx.nodes, cx.spent);
        let from = self.rec.arena.len();
        self.scopes.push_file();
        b.open.push_quiet(Name::Static("<file>"), Pos::at(0));
        let depth = b.open.frames.len();
        self.externs.reading.push(None);
        let mut parser = Parser::new(src);
        let r = parser.run(&mut Lent { x: self, cx, b });
        let first = self.externs.reading.pop().flatten();
        debug_assert!(r.is_err() || b.open.frames.len() == depth);
        b.open.frames.truncate(depth - 1);
        b.open.quiet -= 1;
        let protos = self.scopes.pop_protos();
        // Its positions point into it from now on.
        tag_all(&mut self.rec.arena[from..], file);
        (cx.nodes, cx.spent) = (nodes, spent);
        self.replay.reusing = reusing;
        self.expansions.substs = substs;
        b.open.fields = fields;
        self.rec.resume(aside);
        cx.file = current;
        self.files.stack.pop();
        r?;
        let src = parser.src;
        if let Some(at) = src.bad_utf8 {
            cx.diags
                .warn(&src, Pos::at(at), "invalid UTF-8 (bytes replaced by '?')");
        }
        self.files.bytes += src.bytes_read;
        cx.diags.sources.insert(file, Rc::new(kept(src)));
        // Its own PROTOs get tagged positions; its EXTERNPROTOs already point elsewhere.
        let protos = protos
            .into_iter()
            .map(|(n, d)| match d.home {
                Some(_) => (n, d),
                None => (n, Rc::new(tagged(&d, file))),
            })
            .collect();
        Ok(Library {
            protos: Rc::new(protos),
            first,
        })
    }

    /// The EXTERNPROTO `name` as the PROTO `ext` of `lib` that `url` names: its body, its
    /// interface and defaults, expanded under its file's PROTOs; an instance may set the
    /// fields `iface` declares with the same access and type as `ext` (warnings for others).
    // (Its own arguments, and the context and builder lent to the expander.)
    #[allow(clippy::too_many_arguments)]
    fn adopt(
        &mut self,
        cx: &mut Ctx,
        src: &SourceWindow,
        name: &Rc<str>,
        iface: &[InterfaceField],
        ext: &ProtoDecl,
        lib: &Library,
        url: &str,
    ) -> ProtoDecl {
        let mut public = vec![false; ext.fields.len()];
        for f in iface {
            // (A field `ext`'s own EXTERNPROTO hides is not there for this one either.)
            let Some(i) = ext.public_index(&f.name) else {
                let msg = format!(
                    "EXTERNPROTO {name} declares '{}', which PROTO {} in '{url}' does not have: it cannot be set",
                    f.name, ext.name
                );
                cx.diags.warn(src, f.at, msg);
                continue;
            };
            let e = &ext.fields[i];
            if e.access == f.access && e.ty == f.ty {
                public[i] = true;
                continue;
            }
            let msg = format!(
                "EXTERNPROTO {name} declares {} {} {}, but PROTO {} in '{url}' has {} {} {}: it cannot be set",
                f.access.keyword(),
                f.ty.name(),
                f.name,
                ext.name,
                e.access.keyword(),
                e.ty.name(),
                e.name
            );
            cx.diags.warn(src, f.at, msg);
        }
        ProtoDecl {
            name: name.clone(),
            public: Some(public.into()),
            // A PROTO that file has through an EXTERNPROTO of its own lives in yet another.
            home: Some(ext.home.clone().unwrap_or_else(|| lib.protos.clone())),
            ..ext.clone()
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn urls_name_a_file_and_maybe_a_proto() {
        assert_eq!(split_url("a.wrl#Ball"), ("a.wrl", Some("Ball")));
        assert_eq!(split_url("a.wrl"), ("a.wrl", None));
        assert_eq!(split_url("a.wrl#"), ("a.wrl", None));
        assert_eq!(split_url("#Ball"), ("", Some("Ball")));
    }
}
