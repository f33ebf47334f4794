//! Files: the scene file and the files its Inline nodes name. Each file is parsed straight
//! into the lowering, in a namespace of its own, under a root frame that groups its
//! top-level nodes (the scope of top-level DirectionalLights); an Inline's file is read when
//! the Inline closes, inside the Inline's group, so its Transforms apply. Only local relative
//! paths to VRML97 files are read (never a network URL); an Inline that includes itself is an
//! error, and so is one nested deeper than [`crate::vrml::lower::LoadOptions::max_inline_depth`] files.
//! The files EXTERNPROTOs name follow the same rules ([`local_path`], [`Expander::admit`]).

use std::path::{Path, PathBuf};

use super::instance::Subst;
use super::record::SetAside;
use super::{Expander, Lent};
use crate::error::Error;
use crate::source::{Pos, SourceWindow};
use crate::vrml::lower::build::open::{Frame, Kind};
use crate::vrml::lower::build::Builder;
use crate::vrml::lower::context::Ctx;
use crate::vrml::parse::Parser;

/// The file being read and the chain of files that include it.
#[derive(Default)]
pub(in crate::vrml::lower) struct Files {
    /// The path of the scene file, then of each Inline'd file (or file read for its
    /// PROTOs) being read, innermost last.
    pub(in crate::vrml::lower) stack: Vec<PathBuf>,
    /// Source bytes read (decompressed), over all files.
    pub(in crate::vrml::lower) bytes: u64,
}

/// What entering a file put aside ([`Expander::open_file`]).
pub(in crate::vrml::lower) struct Opened {
    saved_file: u32,
    depth: usize,
    reusing: u32,
    substs: Option<Vec<Subst>>,
    aside: Option<SetAside>,
}

/// Whether an Inline's (or EXTERNPROTO's) url names a local file relative to the including one.
fn is_local_relative(url: &str) -> bool {
    let lower = url.to_ascii_lowercase();
    let has_scheme = lower.find(':').is_some_and(|k| {
        k > 1
            && lower[..k]
                .chars()
                .all(|c| c.is_ascii_alphanumeric() || "+-.".contains(c))
    });
    !has_scheme && !url.starts_with('/') && !url.starts_with('\\') && !url.is_empty()
}

/// The local file `url` names in the folder `base`, and its canonical path; otherwise why
/// not (for the warning that lists the urls tried).
pub(in crate::vrml::lower) fn local_path(
    base: &Path,
    url: &str,
) -> Result<(PathBuf, PathBuf), &'static str> {
    if !is_local_relative(url) {
        return Err("not a local relative path");
    }
    let path = base.join(url);
    if !path.is_file() {
        return Err("no such file");
    }
    let canon = path.canonicalize().unwrap_or(path.clone());
    Ok((path, canon))
}

/// Whether a local file may be read now (the same rules for Inline and EXTERNPROTO).
pub(in crate::vrml::lower) enum Admit {
    Yes,
    /// It is being read: reading it again would never end.
    Cycle,
    /// It would nest deeper than [`crate::vrml::lower::LoadOptions::max_inline_depth`] files.
    TooDeep,
    /// It is not VRML97 (X3D, 3DS, VRML 1.0): reported, not fatal.
    NotVrml97,
}

impl Expander {
    pub(in crate::vrml::lower) fn load_file(
        &mut self,
        cx: &mut Ctx,
        b: &mut Builder,
        path: &Path,
    ) -> Result<(), Error> {
        let src = crate::input::open(path, cx.opts.inflate_ratio())?;
        self.load_source(cx, b, src, path)
    }

    /// Parses and lowers one file, its Inlines included.
    pub(in crate::vrml::lower) fn load_source(
        &mut self,
        cx: &mut Ctx,
        b: &mut Builder,
        src: SourceWindow,
        path: &Path,
    ) -> Result<(), Error> {
        let mut opened = self.open_file(cx, b, &src, path);
        let mut parser = Parser::new(src);
        let r = parser.run(&mut Lent { x: self, cx, b });
        self.resume_outside(&mut opened);
        r?;
        self.close_file(cx, b, opened, &parser.src)
    }

    /// Enters a file: its namespace, its root frame, and no recording or substitution of the
    /// includer's. Then its events; then [`Self::resume_outside`] and [`Self::close_file`].
    pub(in crate::vrml::lower) fn open_file(
        &mut self,
        cx: &mut Ctx,
        b: &mut Builder,
        src: &SourceWindow,
        path: &Path,
    ) -> Opened {
        let saved_file = cx.file;
        cx.file = b.add_file(&src.name) as u32;
        self.files.stack.push(path.to_path_buf());
        self.scopes.push_file();
        b.open_file_root();
        let depth = b.open.frames.len();
        // A new file is a new namespace, even when reached again through a USE'd Inline.
        let reusing = std::mem::replace(&mut self.replay.reusing, 0);
        let substs = std::mem::take(&mut self.expansions.substs);
        // A DEF being recorded around the Inline records the Inline node, not the file's
        // events: a USE of it reads the file again (replaying them too drew it twice).
        let aside = self.rec.set_aside();
        Opened {
            saved_file,
            depth,
            reusing,
            substs: Some(substs),
            aside: Some(aside),
        }
    }

    /// Puts back the includer's recording and substitutions (once the file's events are
    /// read, whether or not they failed).
    pub(in crate::vrml::lower) fn resume_outside(&mut self, opened: &mut Opened) {
        if let Some(aside) = opened.aside.take() {
            self.rec.resume(aside);
        }
        self.replay.reusing = opened.reusing;
        if let Some(substs) = opened.substs.take() {
            self.expansions.substs = substs;
        }
    }

    /// Leaves a file whose events were all read: its warnings, its root frame, its namespace.
    pub(in crate::vrml::lower) fn close_file(
        &mut self,
        cx: &mut Ctx,
        b: &mut Builder,
        opened: Opened,
        src: &SourceWindow,
    ) -> Result<(), Error> {
        if let Some(at) = src.bad_utf8 {
            cx.diags
                .warn(src, Pos::at(at), "invalid UTF-8 (bytes replaced by '?')");
        }
        debug_assert_eq!(b.open.frames.len(), opened.depth);
        let root = b.open.frames.pop().expect("file root frame");
        b.close_group_like(cx, src, root.kind, Pos::at(0))?;
        self.scopes.pop();
        self.files.stack.pop();
        self.files.bytes += src.bytes_read;
        cx.file = opened.saved_file;
        Ok(())
    }

    /// Closes an Inline: loads the file it names inside its group, then closes the group
    /// over what it lowered.
    pub(in crate::vrml::lower) fn close_inline(
        &mut self,
        cx: &mut Ctx,
        b: &mut Builder,
        src: &SourceWindow,
        frame: Frame,
    ) -> Result<(), Error> {
        let at = frame.at;
        let urls = match &frame.kind {
            Kind::Group {
                inline_urls: Some(urls),
                ..
            } => urls.clone(),
            _ => Box::default(),
        };
        b.open.frames.push(frame);
        self.load_inline(cx, b, src, at, &urls)?;
        let frame = b.open.frames.pop().expect("inline frame");
        b.close_group_like(cx, src, frame.kind, at)
    }

    /// The folder the relative urls of a node at `at` are resolved in: that of the file it
    /// was written in (the file being read, or the file an external PROTO's body came from).
    pub(in crate::vrml::lower) fn base_dir(&self, at: Pos) -> PathBuf {
        let file = match at.file() {
            Some(tag) => self.externs.path_of(tag),
            None => self.files.stack.last().map(PathBuf::as_path),
        };
        file.and_then(Path::parent)
            .map(Path::to_path_buf)
            .unwrap_or_default()
    }

    /// Whether the local file at `path` (canonically `canon`) may be read now.
    pub(in crate::vrml::lower) fn admit(&self, cx: &Ctx, path: &Path, canon: &Path) -> Admit {
        if self
            .files
            .stack
            .iter()
            .any(|p| p.canonicalize().is_ok_and(|c| c == canon))
        {
            return Admit::Cycle;
        }
        self.admit_file(cx, path)
    }

    /// [`Self::admit`] but for cycles: whether the file nests too deep or is not VRML97.
    pub(in crate::vrml::lower) fn admit_file(&self, cx: &Ctx, path: &Path) -> Admit {
        // The stack holds the scene file and the files being read inside it: this one
        // would be number `stack.len()` down from the scene file.
        if self.files.stack.len() > cx.opts.max_inline_depth {
            return Admit::TooDeep;
        }
        let mut head = [0u8; 16];
        let n = crate::input::open(path, cx.opts.inflate_ratio())
            .ok()
            .map(|mut w| {
                let _ = w.fill(16);
                let b = w.rest().as_bytes();
                let k = b.len().min(16);
                head[..k].copy_from_slice(&b[..k]);
                k
            })
            .unwrap_or(0);
        if !head[..n].starts_with(b"#VRML V2.0") {
            return Admit::NotVrml97;
        }
        Admit::Yes
    }

    /// Loads the first of `urls` that is a local VRML97 file; a warning if none is.
    fn load_inline(
        &mut self,
        cx: &mut Ctx,
        b: &mut Builder,
        src: &SourceWindow,
        at: Pos,
        urls: &[String],
    ) -> Result<(), Error> {
        if !cx.opts.inline {
            return Ok(());
        }
        let base = self.base_dir(at);
        let mut tried = Vec::new();
        for url in urls {
            let (path, canon) = match local_path(&base, url) {
                Ok(p) => p,
                Err(why) => {
                    tried.push(format!("'{url}' ({why})"));
                    continue;
                }
            };
            match self.admit(cx, &path, &canon) {
                Admit::Yes => return self.load_file(cx, b, &path),
                Admit::Cycle => {
                    let msg = format!("Inline '{url}' includes itself (a cycle)");
                    return Err(cx.diags.error(src, at, msg));
                }
                Admit::TooDeep => {
                    let max = cx.opts.max_inline_depth;
                    let msg = format!("Inline '{url}' nests deeper than {max} files");
                    return Err(cx.diags.error(src, at, msg));
                }
                Admit::NotVrml97 => tried.push(format!("'{url}' (not a VRML97 file)")),
            }
        }
        let what = if tried.is_empty() {
            "no url".to_string()
        } else {
            tried.join(", ")
        };
        cx.diags.warn(src, at, format!("Inline not loaded: {what}"));
        Ok(())
    }
}
