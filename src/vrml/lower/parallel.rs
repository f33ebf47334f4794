//! Reading one large file on several threads, with the result one reader would give.
//!
//! A scan ([`crate::vrml::split`]) cuts the text into a prefix, a region of whole sibling
//! nodes cut into chunks, and the rest. The main thread lowers the prefix; each chunk is
//! lowered on a worker thread by a lowerer that reads the prefix first (so it starts in the
//! state the file is in there) and hands back what the chunk added: spheres, surfaces,
//! lights, viewpoints, its material table, counts. The main thread puts the chunks' results
//! in place in file order (the enclosing grouping nodes, still open, then move and scope them
//! as they close; the materials the tables repeat, the prefix's among them, are merged like
//! any duplicates) and reads the rest.
//!
//! What a chunk reads that depends on an earlier chunk is checked, not assumed. The result is
//! thrown away and the file read again by one reader (the same answer, slower) when:
//! - a chunk warns, notes, fails, reads another file (Inline), or meets invalid UTF-8: its
//!   messages would need positions and text from outside it, so one reader says them;
//! - a chunk USEs a name the prefix DEF'd that an earlier chunk DEF'd again, or the rest of
//!   the file USEs or ROUTEs a name any chunk DEF'd;
//! - the nodes counted might have passed `max_nodes` somewhere (checked against the bytes
//!   before each node, which one reader has always read);
//! - the main thread fails after the chunks (its message is one reader's to give).

use std::collections::BTreeMap;
use std::io::{Cursor, Read};
use std::path::Path;
use std::rc::Rc;
use std::sync::mpsc::{channel, sync_channel, Receiver, Sender, SyncSender};
use std::sync::{Arc, Mutex};

use glam::{DAffine3, DVec3};
use hashbrown::HashSet;

use super::open::{Kind, Marks};
use super::Lowerer;
use crate::error::Error;
use crate::scene::{EllipsoidId, Light, LightScope, MaterialTable, Sphere, Surface, Viewpoint};
use crate::source::SourceWindow;
use crate::vrml::parse::{Parser, Run};
use crate::vrml::split::{Piece, Splitter};

/// How much text a chunk holds (at least), unless the options say otherwise.
pub const CHUNK_BYTES: u64 = 4 << 20;
/// The longest prefix (text before the region) that every chunk's reader reads again.
const PREFIX_MAX: u64 = 1 << 20;
/// Blocks the scan reads (small, so that little text follows a chunk's end when it is cut:
/// that text is copied to start the next one).
const BLOCK: usize = 256 << 10;

/// Watching a chunk's lowering (set on a worker's lowerer once its prefix is read).
pub(super) struct Watch {
    /// Arena position where the chunk began: DEFs recorded before it are the prefix's.
    pub(super) arena_mark: usize,
    /// File-scope names the chunk USEd or ROUTEd from the prefix's DEFs.
    pub(super) imports: Vec<String>,
    /// Nodes counted when the chunk began, and the most that nodes counted since ran ahead
    /// of the chunk's bytes read (see [`Lowerer::add_nodes`]).
    pub(super) nodes_at_start: u64,
    pub(super) excess: i64,
}

/// What a chunk added, moved to the main thread.
struct Delta {
    spheres: Vec<Sphere>,
    ellipsoids: Vec<DAffine3>,
    surfaces: Vec<Surface>,
    /// The worker's materials, which `spheres` and `surfaces` index, and their hashes (if
    /// the worker knew them all).
    materials: MaterialTable,
    hashes: Vec<u64>,
    lights: Vec<Light>,
    views: Vec<Viewpoint>,
    /// Where the worker's own counts began: its spheres, surfaces, ellipsoids, lights
    /// before the chunk.
    base: Marks,
    ellipsoid_base: usize,
    /// DirectionalLights among the region's siblings (indices into `lights`): scoped by the
    /// group the region is in, when it closes.
    dirlights: Vec<usize>,
    skipped: BTreeMap<String, u64>,
    nodes: u64,
    excess: i64,
    mesh_spheres: u64,
    point_spheres: u64,
    headlight: Option<bool>,
    background: Option<DVec3>,
    exports: Vec<String>,
    imports: Vec<String>,
    line_starts: Vec<u64>,
}

type Outcome = Result<Box<Delta>, String>;

/// A chunk for a worker: its number, its offset, its text, and the prefix to read first.
type Job = (usize, u64, Vec<u8>, Arc<[u8]>);

/// What the main thread's text channel carries.
enum Msg {
    Text(Vec<u8>),
    PrefixEnd,
    RegionEnd { end: u64 },
    Eof,
    Failed(std::io::Error),
}

/// What the results channel carries.
enum Done {
    Chunk(usize, Outcome),
    Total(usize),
}

/// The main reader's text: the channel's text, with an end at the prefix's end and at the
/// file's.
#[derive(Clone)]
struct ChannelReader(Rc<std::cell::RefCell<Inner>>);

struct Inner {
    rx: Receiver<Msg>,
    text: Vec<u8>,
    at: usize,
    /// Where the text stopped: the prefix's end, the region's end, or the file's.
    stopped: Option<Msg>,
}

impl Read for ChannelReader {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        let mut s = self.0.borrow_mut();
        loop {
            if s.at < s.text.len() {
                let n = buf.len().min(s.text.len() - s.at);
                buf[..n].copy_from_slice(&s.text[s.at..s.at + n]);
                s.at += n;
                return Ok(n);
            }
            if s.stopped.is_some() {
                return Ok(0);
            }
            match s.rx.recv() {
                Ok(Msg::Text(t)) => {
                    s.text = t;
                    s.at = 0;
                }
                Ok(Msg::Failed(e)) => return Err(e),
                Ok(m) => s.stopped = Some(m),
                Err(_) => s.stopped = Some(Msg::Eof),
            }
        }
    }
}

impl ChannelReader {
    /// Where the text stopped, and reading may go on past it.
    fn take_stop(&self) -> Option<Msg> {
        self.0.borrow_mut().stopped.take()
    }
}

/// Why a file was read by one reader after all, or how many chunks it was read in.
pub(super) enum Parallel {
    Chunks(usize),
    Fallback(String),
}

/// Reads `reader` (the decompressed text of `path`) as [`super::load_source`] would, on
/// `threads` worker threads, into `low`. On `Fallback`, `low` must be thrown away.
pub(super) fn load(
    low: &mut Lowerer,
    name: Arc<str>,
    path: &Path,
    reader: Box<dyn Read + Send>,
    threads: usize,
    chunk_bytes: u64,
) -> Result<Parallel, Error> {
    let (text_tx, text_rx) = sync_channel::<Msg>(16);
    let (chunk_tx, chunk_rx) = sync_channel::<Job>(threads);
    let (done_tx, done_rx) = channel::<Done>();
    // Only the workers hold the chunks' receiver: when they stop, the scan does too.
    let chunk_rx = Arc::new(Mutex::new(chunk_rx));
    let worker_rx: Vec<_> = (0..threads).map(|_| chunk_rx.clone()).collect();
    drop(chunk_rx);
    let opts = low.opts.clone();
    std::thread::scope(|scope| {
        let splitter_done = done_tx.clone();
        scope.spawn(move || split(reader, chunk_bytes, text_tx, chunk_tx, splitter_done));
        for rx in worker_rx {
            let tx = done_tx.clone();
            let (opts, name) = (opts.clone(), name.clone());
            scope.spawn(move || loop {
                let job = rx.lock().map_or(None, |r| r.recv().ok());
                let Some((k, start, text, prefix)) = job else {
                    return;
                };
                let out = lower_chunk(&opts, &name, path, &prefix, start, text);
                if tx.send(Done::Chunk(k, out)).is_err() {
                    return;
                }
            });
        }
        drop(done_tx);
        let reader = ChannelReader(Rc::new(std::cell::RefCell::new(Inner {
            rx: text_rx,
            text: Vec::new(),
            at: 0,
            stopped: None,
        })));
        let r = main_reader(low, name.clone(), path, reader, &done_rx);
        // Dropping the receivers ends the other threads if they are still going.
        drop(done_rx);
        r
    })
}

/// The scan's thread: reads the text and hands it out.
fn split(
    mut reader: Box<dyn Read + Send>,
    chunk_bytes: u64,
    text: SyncSender<Msg>,
    chunks: SyncSender<Job>,
    done: Sender<Done>,
) {
    let mut s = Splitter::new(chunk_bytes, PREFIX_MAX);
    let mut prefix: Option<Arc<[u8]>> = None;
    let mut k = 0;
    // False once a receiver is gone (the main reader stopped): then the scan stops too.
    let ok = std::cell::Cell::new(true);
    let mut hand = |p: Piece| {
        if !ok.get() {
            return;
        }
        let sent = match p {
            Piece::Text(t) => text.send(Msg::Text(t)).is_ok(),
            Piece::Prefix(p) => {
                prefix = Some(p);
                true
            }
            Piece::Chunk { start, text: t } => {
                let first = k == 0 && text.send(Msg::PrefixEnd).is_err();
                let p = prefix.clone().unwrap_or_else(|| Arc::from(&[][..]));
                k += 1;
                !first && chunks.send((k - 1, start, t, p)).is_ok()
            }
            Piece::RegionEnd { chunks: n, end } => {
                done.send(Done::Total(n)).is_ok() && text.send(Msg::RegionEnd { end }).is_ok()
            }
        };
        ok.set(sent);
    };
    loop {
        match s.read_from(&mut reader, BLOCK, &mut hand) {
            Ok(0) => break,
            Ok(_) if !ok.get() => return,
            Ok(_) => {}
            Err(e) if e.kind() == std::io::ErrorKind::Interrupted => continue,
            Err(e) => {
                s.finish(&mut hand);
                let _ = text.send(Msg::Failed(e));
                return;
            }
        }
    }
    s.finish(&mut hand);
    let _ = text.send(Msg::Eof);
}

/// The main thread: the prefix, the chunks' results in order, the rest.
fn main_reader(
    low: &mut Lowerer,
    name: Arc<str>,
    path: &Path,
    reader: ChannelReader,
    done: &Receiver<Done>,
) -> Result<Parallel, Error> {
    let src = SourceWindow::new(name, Box::new(reader.clone()));
    let mut opened = low.open_file(&src, path);
    let mut parser = Parser::new(src);
    parser.pause_at_end = true;
    let r = parser.begin().and_then(|()| parser.resume(low));
    if !matches!(reader.take_stop(), Some(Msg::PrefixEnd)) {
        // No region: this was one reader all along, and its result stands.
        low.resume_outside(&mut opened);
        r?;
        parser.end()?;
        low.close_file(opened, &parser.src)?;
        return Ok(Parallel::Chunks(0));
    }
    // From here on, a failure's message is one reader's to give.
    let outcome = (|| -> Result<usize, String> {
        r.map_err(|e| e.to_string())?;
        let chunks = put_chunks_in_place(low, &mut parser.src, done)?;
        let end = match reader.0.borrow().rx.recv() {
            Ok(Msg::RegionEnd { end }) => end,
            _ => return Err("the scan stopped before the region's end".into()),
        };
        parser.src.jump(end, Box::new(reader.clone()));
        let run = parser.resume(low).map_err(|e| e.to_string())?;
        debug_assert_eq!(run, Run::Paused);
        if !matches!(reader.take_stop(), Some(Msg::Eof) | None) {
            return Err("the text stopped early".into());
        }
        parser.end().map_err(|e| e.to_string())?;
        Ok(chunks)
    })();
    low.resume_outside(&mut opened);
    let chunks = match outcome {
        Ok(n) => n,
        Err(why) => return Ok(Parallel::Fallback(why)),
    };
    if let Err(e) = low.close_file(opened, &parser.src) {
        return Ok(Parallel::Fallback(e.to_string()));
    }
    Ok(match low.fallback.take() {
        Some(why) => Parallel::Fallback(why),
        None => Parallel::Chunks(chunks),
    })
}

/// Receives the chunks' results and puts them in place in file order; returns how many
/// there were, or why the file must be read by one reader.
fn put_chunks_in_place(
    low: &mut Lowerer,
    src: &mut SourceWindow,
    done: &Receiver<Done>,
) -> Result<usize, String> {
    let mut waiting = BTreeMap::new();
    let mut next = 0;
    let mut total = None;
    // Names the chunks put in place so far DEF'd.
    let mut defined: HashSet<String> = HashSet::new();
    while total != Some(next) {
        match done.recv() {
            Ok(Done::Total(n)) => total = Some(n),
            Ok(Done::Chunk(k, out)) => {
                waiting.insert(k, out);
            }
            Err(_) => return Err("a reading thread stopped".into()),
        }
        while let Some(out) = waiting.remove(&next) {
            let d = out.map_err(|why| format!("chunk {next}: {why}"))?;
            if let Some(n) = d.imports.iter().find(|n| defined.contains(*n)) {
                return Err(format!(
                    "chunk {next} USEs '{n}', which an earlier chunk DEF'd again"
                ));
            }
            if low.nodes as i64 + d.excess > low.opts.max_nodes as i64 {
                return Err("the nodes counted may pass the limit".into());
            }
            defined.extend(d.exports.iter().cloned());
            low.put_in_place(*d, src)?;
            next += 1;
        }
    }
    if !defined.is_empty() {
        low.poison = Some(defined);
    }
    Ok(next)
}

/// Lowers one chunk after its prefix, on a worker thread.
fn lower_chunk(
    opts: &super::LoadOptions,
    name: &Arc<str>,
    path: &Path,
    prefix: &Arc<[u8]>,
    start: u64,
    text: Vec<u8>,
) -> Outcome {
    let mut low = Lowerer::new(opts.clone());
    let src = SourceWindow::new(name.clone(), Box::new(Cursor::new(prefix.clone())));
    let mut opened = low.open_file(&src, path);
    let mut parser = Parser::new(src);
    parser.pause_at_end = true;
    let r = parser.begin().and_then(|()| parser.resume(&mut low));
    let d = r
        .map_err(|e| format!("its prefix: {}", reason(&e)))
        .and_then(|_| chunk_delta(&mut low, &mut parser, start, text));
    low.resume_outside(&mut opened);
    d
}

/// `v[from..]`, taken (without a copy when that is all of `v`).
fn tail<T>(v: &mut Vec<T>, from: usize) -> Vec<T> {
    if from == 0 {
        std::mem::take(v)
    } else {
        v.split_off(from)
    }
}

/// What went wrong, without a position (a chunk's reader counts lines from its own start).
fn reason(e: &Error) -> String {
    match e {
        Error::Diag(d) => d.message.clone(),
        e => e.to_string(),
    }
}

/// The number of messages in `d`, repeats included.
fn said(d: &[crate::diag::Diagnostic]) -> u64 {
    d.iter().map(|d| 1 + d.repeats).sum()
}

fn chunk_delta(low: &mut Lowerer, parser: &mut Parser, start: u64, text: Vec<u8>) -> Outcome {
    let base = Marks::of(&low.scene);
    let ellipsoid_base = low.scene.ellipsoids.len();
    let said_before = (said(&low.diags.warnings), said(&low.diags.notes));
    let skipped_before = low.diags.skipped.clone();
    let meshes_before = (low.meshes.spheres, low.meshes.point_spheres);
    let bound_before = (low.bound.navigation_info, low.bound.background);
    let utf8_before = parser.src.bad_utf8.is_some();
    let files_before = low.scene.files.len();
    let arena_mark = low.rec.arena.len();
    low.rec.pinned = low.rec.pinned.max(arena_mark);
    low.watch = Some(Watch {
        arena_mark,
        imports: Vec::new(),
        nodes_at_start: low.nodes,
        excess: i64::MIN,
    });
    parser.src.jump_to_text(start, text);
    parser.resume(low).map_err(|e| reason(&e))?;
    if (said(&low.diags.warnings), said(&low.diags.notes)) != said_before {
        return Err("it has warnings or notes".into());
    }
    if low.scene.files.len() != files_before {
        return Err("it reads another file".into());
    }
    if !utf8_before && parser.src.bad_utf8.is_some() {
        return Err("it has invalid UTF-8".into());
    }
    if let Some(why) = low.fallback.take() {
        return Err(why);
    }
    let watch = low.watch.take().expect("watching the chunk");
    let dirlights = match low.open.innermost_group() {
        Some(
            Kind::Group { dirlights, .. }
            | Kind::Switch { dirlights, .. }
            | Kind::Lod { dirlights, .. },
        ) => dirlights
            .iter()
            .flat_map(|d| d.iter())
            .filter(|&&i| i >= base.lights)
            .map(|&i| i - base.lights)
            .collect(),
        _ => Vec::new(),
    };
    let mut skipped = low.diags.skipped.clone();
    for (ty, n) in &skipped_before {
        if let Some(m) = skipped.get_mut(ty) {
            *m -= n;
        }
    }
    skipped.retain(|_, n| *n > 0);
    let hashes = low
        .materials
        .recent
        .hashes(low.scene.materials.len())
        .to_vec();
    let scene = &mut low.scene;
    Ok(Box::new(Delta {
        spheres: tail(&mut scene.spheres, base.spheres),
        ellipsoids: tail(&mut scene.ellipsoids, ellipsoid_base),
        surfaces: tail(&mut scene.surfaces, base.surfaces),
        materials: std::mem::take(&mut scene.materials),
        hashes,
        lights: tail(&mut scene.lights, base.lights),
        views: tail(&mut scene.viewpoints, base.views),
        base,
        ellipsoid_base,
        dirlights,
        skipped,
        nodes: low.nodes - watch.nodes_at_start,
        excess: watch.excess,
        mesh_spheres: low.meshes.spheres - meshes_before.0,
        point_spheres: low.meshes.point_spheres - meshes_before.1,
        headlight: (!bound_before.0 && low.bound.navigation_info).then_some(scene.headlight),
        background: (!bound_before.1 && low.bound.background).then_some(scene.background),
        exports: low.scopes.file_defs_since(arena_mark),
        imports: watch.imports,
        line_starts: parser.src.lines.starts_after(start).collect(),
    }))
}

impl Lowerer {
    /// Looks a DEF name up in the innermost namespace, noting (in the file's namespace) a
    /// chunk's use of the prefix's DEFs and the main reader's use of names chunks DEF'd.
    pub(super) fn lookup_def(&mut self, name: &str) -> Option<super::scope::DefEntry> {
        let d = self.scopes.def(name).cloned();
        if self.scopes.depth() == 1 {
            if let Some(w) = &mut self.watch {
                if d.as_ref().is_some_and(|d| d.range.start < w.arena_mark) {
                    w.imports.push(name.to_string());
                }
            }
            if self.poison.as_ref().is_some_and(|p| p.contains(name)) {
                self.fallback
                    .get_or_insert_with(|| format!("'{name}' is used after a chunk DEF'd it"));
            }
        }
        d
    }

    /// Notes how far the nodes counted in a chunk ran ahead of the bytes before the cursor.
    #[inline]
    pub(super) fn watch_nodes(&mut self, cursor: u64) {
        if let Some(w) = &mut self.watch {
            let e = (self.nodes - w.nodes_at_start) as i64 - cursor as i64;
            w.excess = w.excess.max(e);
        }
    }

    /// Puts a chunk's result in place, as if its text had been lowered here.
    fn put_in_place(&mut self, d: Delta, src: &mut SourceWindow) -> Result<(), String> {
        // Stored as they come (their duplicates are merged like any the cache lets through).
        let first = self.scene.materials.len() as u32;
        self.scene.materials.append(&d.materials);
        let stored = self.scene.materials.len();
        self.materials
            .recent
            .stored_unchecked(&d.hashes, first as usize, stored);
        let scene = &mut self.scene;
        let (s0, f0, l0) = (
            scene.spheres.len(),
            scene.surfaces.len(),
            scene.lights.len(),
        );
        let e0 = scene.ellipsoids.len();
        scene.ellipsoids.extend(d.ellipsoids);
        scene.spheres.reserve(d.spheres.len());
        for mut s in d.spheres {
            s.material += first;
            if let Some(id) = s.ellipsoid {
                let i = id.index();
                if i < d.ellipsoid_base {
                    return Err("a sphere of the chunk is an ellipsoid of its prefix".into());
                }
                s.ellipsoid = EllipsoidId::new(i - d.ellipsoid_base + e0);
            }
            scene.spheres.push(s);
        }
        for mut s in d.surfaces {
            s.material += first;
            scene.surfaces.push(s);
        }
        let shift = |r: &mut LightScope, from: usize, to: usize| {
            if let LightScope::Range { start, end } = r {
                *start = (*start as usize - from + to) as u32;
                *end = (*end as usize - from + to) as u32;
            }
        };
        for (i, mut l) in d.lights.into_iter().enumerate() {
            // (The scopes of the region's own DirectionalLights are set when its group closes.)
            let pending = d.dirlights.contains(&i);
            if let (Light::Directional(dl), false) = (&mut l, pending) {
                shift(&mut dl.scope, d.base.spheres, s0);
                shift(&mut dl.surface_scope, d.base.surfaces, f0);
            }
            scene.lights.push(l);
        }
        scene.viewpoints.extend(d.views);
        if !d.dirlights.is_empty() {
            if let Some(
                Kind::Group { dirlights, .. }
                | Kind::Switch { dirlights, .. }
                | Kind::Lod { dirlights, .. },
            ) = self.open.innermost_group()
            {
                let list = dirlights.get_or_insert_with(Box::default);
                list.extend(d.dirlights.iter().map(|i| i + l0));
            }
        }
        if let (Some(h), false) = (d.headlight, self.bound.navigation_info) {
            self.scene.headlight = h;
            self.bound.navigation_info = true;
        }
        if let (Some(b), false) = (d.background, self.bound.background) {
            self.scene.background = b;
            self.bound.background = true;
        }
        for (ty, n) in d.skipped {
            *self.diags.skipped.entry(ty).or_default() += n;
        }
        self.nodes += d.nodes;
        self.meshes.spheres += d.mesh_spheres;
        self.meshes.point_spheres += d.point_spheres;
        src.lines_skipped(d.line_starts);
        if self.materials.recent.wants_merge(&self.scene.materials) {
            self.merge_materials(0);
        }
        Ok(())
    }
}
