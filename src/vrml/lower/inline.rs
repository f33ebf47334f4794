//! Files: the scene file and the files its Inline nodes name. Each file is parsed straight
//! into the lowering, in a namespace of its own, under a root frame that groups its
//! top-level nodes (the scope of top-level DirectionalLights); an Inline's file is read when
//! the Inline closes, inside the Inline's group, so its Transforms apply. Only local relative
//! paths to VRML97 files are read (never a network URL); an Inline that includes itself is an
//! error, and so is one nested deeper than [`super::LoadOptions::max_inline_depth`] files.
//! The files EXTERNPROTOs name follow the same rules ([`local_path`], [`Lowerer::admit`]).

use std::path::{Path, PathBuf};

use super::build::open::Name;
use super::build::open::{Frame, Kind};
use super::build::transform::Marks;
use super::expand::Subst;
use super::record::SetAside;
use super::Lowerer;
use crate::error::Error;
use crate::source::{Pos, SourceWindow};
use crate::vrml::parse::Parser;

/// The file being read and the chain of files that include it.
#[derive(Default)]
pub(super) struct Files {
    /// The path of the scene file, then of each Inline'd file (or file read for its
    /// PROTOs) being read, innermost last.
    pub(super) stack: Vec<PathBuf>,
    /// Source bytes read (decompressed), over all files.
    pub(super) bytes: u64,
}

/// What entering a file put aside ([`Lowerer::open_file`]).
pub(super) struct Opened {
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
pub(super) fn local_path(base: &Path, url: &str) -> Result<(PathBuf, PathBuf), &'static str> {
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
pub(super) enum Admit {
    Yes,
    /// It is being read: reading it again would never end.
    Cycle,
    /// It would nest deeper than [`super::LoadOptions::max_inline_depth`] files.
    TooDeep,
    /// It is not VRML97 (X3D, 3DS, VRML 1.0): reported, not fatal.
    NotVrml97,
}

impl Lowerer {
    pub(super) fn load_file(&mut self, path: &Path) -> Result<(), Error> {
        let src = crate::input::open(path, self.cx.opts.inflate_ratio())?;
        self.load_source(src, path)
    }

    /// Parses and lowers one file, its Inlines included.
    pub(super) fn load_source(&mut self, src: SourceWindow, path: &Path) -> Result<(), Error> {
        let mut opened = self.open_file(&src, path);
        let mut parser = Parser::new(src);
        let r = parser.run(self);
        self.resume_outside(&mut opened);
        r?;
        self.close_file(opened, &parser.src)
    }

    /// Enters a file: its namespace, its root frame, and no recording or substitution of the
    /// includer's. Then its events; then [`Self::resume_outside`] and [`Self::close_file`].
    pub(super) fn open_file(&mut self, src: &SourceWindow, path: &Path) -> Opened {
        let saved_file = self.cx.file;
        self.cx.file = self.build.scene.files.len() as u32;
        self.build.scene.files.push(src.name.to_string());
        self.files.stack.push(path.to_path_buf());
        self.scopes.push_file();
        // The file's root groups its top-level nodes (scope of top-level DirectionalLights).
        let root = Kind::Group {
            transform: None,
            marks: Marks::of(&self.build.scene),
            dirlights: None,
            inline_urls: None,
        };
        self.build
            .open
            .push(Name::Static("<file>"), None, root, Pos::at(0));
        let depth = self.build.open.frames.len();
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
    pub(super) fn resume_outside(&mut self, opened: &mut Opened) {
        if let Some(aside) = opened.aside.take() {
            self.rec.resume(aside);
        }
        self.replay.reusing = opened.reusing;
        if let Some(substs) = opened.substs.take() {
            self.expansions.substs = substs;
        }
    }

    /// Leaves a file whose events were all read: its warnings, its root frame, its namespace.
    pub(super) fn close_file(&mut self, opened: Opened, src: &SourceWindow) -> Result<(), Error> {
        if let Some(at) = src.bad_utf8 {
            self.cx
                .diags
                .warn(src, Pos::at(at), "invalid UTF-8 (bytes replaced by '?')");
        }
        debug_assert_eq!(self.build.open.frames.len(), opened.depth);
        let root = self.build.open.frames.pop().expect("file root frame");
        self.build
            .close_group_like(&mut self.cx, src, root.kind, Pos::at(0))?;
        self.scopes.pop();
        self.files.stack.pop();
        self.files.bytes += src.bytes_read;
        self.cx.file = opened.saved_file;
        Ok(())
    }

    /// Closes an Inline: loads the file it names inside its group, then closes the group
    /// over what it lowered.
    pub(super) fn close_inline(&mut self, src: &SourceWindow, frame: Frame) -> Result<(), Error> {
        let at = frame.at;
        let urls = match &frame.kind {
            Kind::Group {
                inline_urls: Some(urls),
                ..
            } => urls.clone(),
            _ => Box::default(),
        };
        self.build.open.frames.push(frame);
        self.load_inline(src, at, &urls)?;
        let frame = self.build.open.frames.pop().expect("inline frame");
        self.build
            .close_group_like(&mut self.cx, src, frame.kind, at)
    }

    /// The folder the relative urls of a node at `at` are resolved in: that of the file it
    /// was written in (the file being read, or the file an external PROTO's body came from).
    pub(super) fn base_dir(&self, at: Pos) -> PathBuf {
        let file = match at.file() {
            Some(tag) => self.externs.path_of(tag),
            None => self.files.stack.last().map(PathBuf::as_path),
        };
        file.and_then(Path::parent)
            .map(Path::to_path_buf)
            .unwrap_or_default()
    }

    /// Whether the local file at `path` (canonically `canon`) may be read now.
    pub(super) fn admit(&self, path: &Path, canon: &Path) -> Admit {
        if self
            .files
            .stack
            .iter()
            .any(|p| p.canonicalize().is_ok_and(|c| c == canon))
        {
            return Admit::Cycle;
        }
        self.admit_file(path)
    }

    /// [`Self::admit`] but for cycles: whether the file nests too deep or is not VRML97.
    pub(super) fn admit_file(&self, path: &Path) -> Admit {
        // The stack holds the scene file and the files being read inside it: this one
        // would be number `stack.len()` down from the scene file.
        if self.files.stack.len() > self.cx.opts.max_inline_depth {
            return Admit::TooDeep;
        }
        let mut head = [0u8; 16];
        let n = crate::input::open(path, self.cx.opts.inflate_ratio())
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
    fn load_inline(&mut self, src: &SourceWindow, at: Pos, urls: &[String]) -> Result<(), Error> {
        if !self.cx.opts.inline {
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
            match self.admit(&path, &canon) {
                Admit::Yes => return self.load_file(&path),
                Admit::Cycle => {
                    let msg = format!("Inline '{url}' includes itself (a cycle)");
                    return Err(self.cx.diags.error(src, at, msg));
                }
                Admit::TooDeep => {
                    let max = self.cx.opts.max_inline_depth;
                    let msg = format!("Inline '{url}' nests deeper than {max} files");
                    return Err(self.cx.diags.error(src, at, msg));
                }
                Admit::NotVrml97 => tried.push(format!("'{url}' (not a VRML97 file)")),
            }
        }
        let what = if tried.is_empty() {
            "no url".to_string()
        } else {
            tried.join(", ")
        };
        self.cx
            .diags
            .warn(src, at, format!("Inline not loaded: {what}"));
        Ok(())
    }
}
