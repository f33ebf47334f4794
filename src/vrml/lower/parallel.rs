//! Reading one large file on several threads, with the result one reader would give.
//!
//! A scan ([`crate::vrml::split`]) cuts the text into a prefix and chunks of whole sibling
//! nodes of one list (the region), the later cuts guessed. The main thread lowers the prefix;
//! each chunk is lowered on a worker thread (or on the main thread, while the next chunk to be
//! put in place is not ready; there is one worker fewer than threads) by a lowerer that reads
//! the prefix first (so it starts in the state the file is in there) and hands back what the
//! chunk added: spheres, surfaces, lights, viewpoints, its material table, counts; and its
//! text. The main thread puts the chunks' results in place in file order (the enclosing
//! grouping nodes, still open, then move and scope them as they close; the materials the
//! tables repeat, the prefix's among them, are merged like any duplicates) until a chunk's
//! result may not stand, and from that chunk's start reads the rest itself, from the chunks'
//! texts.
//!
//! A plain file on disk is read so only until the region is found: the rest of the region
//! is cut in the file ([`crate::vrml::cut_file`]), each chunk's reader reads its bytes from
//! the file itself, and the main reader reads on from the file. (Text passed from the scan
//! to the readers was copied by the kernel into buffers of a few MiB, then read again on
//! another core: about 20 ms of CPU per million particles and 25 MB of memory.)
//!
//! When the region's list ends in a chunk (the rest of the file follows), what the chunk read
//! before the list's end stands, and the main reader reads on from there. A chunk's result
//! does not stand (and the main reader reads on from its start) when:
//! - it does not end exactly between two siblings of the region (a guessed cut was wrong);
//! - it declares a PROTO or EXTERNPROTO (which later text may instance);
//! - it warns, notes, fails, reads another file (Inline), or meets invalid UTF-8: its
//!   messages would need positions and text from outside it, so one reader says them.
//!
//! What a chunk reads that depends on an earlier chunk is checked, not assumed. The result is
//! thrown away and the file read again by one reader (the same answer, slower) when:
//! - a chunk USEs a name the prefix DEF'd that an earlier chunk DEF'd again, or the rest of
//!   the file USEs or ROUTEs a name any chunk DEF'd;
//! - the expansion budget spent might have passed its limit somewhere (checked against the
//!   bytes before each node, which one reader has always read);
//! - the main thread fails after the chunks (its message is one reader's to give).
//!
//! What it gains on two threads over one reader (`gtsphere bench parse`, 1e6 particles,
//! medians of 5 runs taking turns, 2026-12-05): 1.81x on top-level sphere nodes and in one
//! Group, 1.80x on `convert`'s PROTO instances with 8-bit colours and 1.79x with a colour per
//! particle; 0.94-1.07x on copies of PyMOL, VTK and Jmol exports, which it leaves to one
//! reader or gives up on early.

use std::collections::BTreeMap;
use std::io::Read;
use std::path::Path;
use std::rc::Rc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::{channel, sync_channel, Receiver, Sender, SyncSender};
use std::sync::{Arc, Mutex};

use hashbrown::HashSet;

use super::chunk::ChunkText;
use super::in_order::{ChunkResult, ChunkTexts, Done, InOrder, Job, Lowering, Spare};
use super::Lowerer;
use crate::error::Error;
use crate::input::{open_plain, read_at, FileRange};
use crate::source::SourceWindow;
use crate::vrml::cut_file::cut_in_file;
use crate::vrml::parse::{Parser, Run};
use crate::vrml::split::{Piece, Splitter};

/// How much text a chunk holds (at least), unless the options say otherwise.
pub const CHUNK_BYTES: u64 = 4 << 20;
/// The longest prefix (text before the region) that every chunk's reader reads again.
const PREFIX_MAX: u64 = 1 << 20;
/// Blocks the scan reads (small, so that little text follows a chunk's end when it is cut:
/// that text is copied to start the next one).
const BLOCK: usize = 256 << 10;

/// What the main thread's text channel carries.
enum Msg {
    Text(Vec<u8>),
    PrefixEnd,
    Eof,
    Failed(std::io::Error),
}

/// The main reader's text: the channel's text, with an end at the prefix's end and at the
/// file's.
#[derive(Clone)]
struct ChannelReader(Rc<std::cell::RefCell<Inner>>);

struct Inner {
    rx: Receiver<Msg>,
    text: Vec<u8>,
    at: usize,
    /// Where the text stopped: the prefix's end, or the file's.
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
    /// Read in this many chunks, then by the main reader from where and why it says.
    Chunks(usize, Option<String>),
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
    (chunk_bytes, size): (u64, u64),
    on_disk: bool,
) -> Result<Parallel, Error> {
    // A plain file on disk: the region's chunks are left in it for their readers.
    let in_file = if on_disk {
        open_plain(path).map(Arc::new)
    } else {
        None
    };
    let (text_tx, text_rx) = sync_channel::<Msg>(16);
    let (chunk_tx, chunk_rx) = sync_channel::<Job>(threads);
    let (done_tx, done_rx) = channel::<Done>();
    // The scan hands on a chunk for each credit, and the main thread gives one back for each
    // chunk it is done with: what is held (texts, results) stays bounded however far the
    // scan could run ahead (as when the main thread reads on by itself).
    let ahead = 2 * threads + 2;
    let (credit_tx, credit_rx) = sync_channel::<()>(ahead);
    for _ in 0..ahead {
        let _ = credit_tx.try_send(());
    }
    // Set when the main thread reads on by itself: the chunks still coming are not lowered.
    let stop = Arc::new(AtomicBool::new(false));
    // Only the readers of chunks hold the chunks' receiver: when they stop, the scan does too.
    // The main thread is one of them (it lowers a chunk whenever the next to be put in place
    // is not ready: with a worker thread fewer, a chunk's spheres are copied from the core that
    // made them more often, and the main thread no longer wakes to take a worker's core).
    let chunk_rx = Arc::new(Mutex::new(chunk_rx));
    let worker_rx: Vec<_> = (1..threads.max(2)).map(|_| chunk_rx.clone()).collect();
    let opts = low.cx.opts.clone();
    std::thread::scope(|scope| {
        let splitter_done = done_tx.clone();
        let (spare_tx, spare_rx) = channel();
        let hands = Hands {
            text: text_tx,
            chunks: chunk_tx,
            done: splitter_done,
            credits: credit_rx,
            spare: spare_rx,
        };
        let scan_file = in_file.clone();
        scope.spawn(move || split(reader, (chunk_bytes, scan_file), hands));
        let ctx = Lowering {
            opts: opts.clone(),
            name: name.clone(),
            path: path.to_path_buf(),
            spheres: Spare::default(),
            stop: stop.clone(),
        };
        for rx in worker_rx {
            let tx = done_tx.clone();
            let ctx = ctx.clone();
            scope.spawn(move || {
                // (See `lower_chunk`.)
                let mut window = String::new();
                loop {
                    let job = rx.lock().map_or(None, |r| r.recv().ok());
                    let Some(job) = job else {
                        return;
                    };
                    let (k, r) = ctx.lower(job, &mut window);
                    if tx.send(Done::Chunk(k, r)).is_err() {
                        return;
                    }
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
        let results = InOrder {
            rx: done_rx,
            waiting: BTreeMap::new(),
            next: 0,
            total: None,
            credits: credit_tx,
            spare: spare_tx,
            spheres: ctx.spheres.clone(),
            help: Some((chunk_rx, ctx, String::new())),
        };
        // Dropping the receivers (in `results`) ends the other threads if they are still
        // going.
        let sizes = (size, in_file);
        main_reader(low, (name.clone(), path), reader, results, &stop, sizes)
    })
}

/// Where the scan's thread hands things on.
struct Hands {
    text: SyncSender<Msg>,
    chunks: SyncSender<Job>,
    done: Sender<Done>,
    credits: Receiver<()>,
    /// Chunks' texts given back (see [`Splitter::give_back`]).
    spare: Receiver<Vec<u8>>,
}

/// The scan's thread: reads the text and hands it out; or, given the file (plain text, on
/// disk), reads it until the region is found and cuts the rest in the file (see
/// [`crate::vrml::cut_file`]).
fn split(
    mut reader: Box<dyn Read + Send>,
    (chunk_bytes, in_file): (u64, Option<Arc<std::fs::File>>),
    to: Hands,
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
            Piece::Text(t) => to.text.send(Msg::Text(t)).is_ok(),
            Piece::Prefix(p) => {
                prefix = Some(p);
                true
            }
            Piece::Chunk { start, text: t } => {
                hand_chunk(&to, &mut k, &prefix, start, ChunkText::Held(t))
            }
            Piece::Range { start, end } => {
                // (Ranges come only from cutting in the file.)
                let Some(file) = in_file.clone() else {
                    return ok.set(false);
                };
                let range = FileRange {
                    file,
                    at: start,
                    end,
                };
                hand_chunk(&to, &mut k, &prefix, start, ChunkText::InFile(range))
            }
            Piece::RegionEnd { chunks: n, end } => to.done.send(Done::Total(n, end)).is_ok(),
        };
        ok.set(sent);
    };
    loop {
        while let Ok(t) = to.spare.try_recv() {
            s.give_back(t);
        }
        match s.read_from(&mut reader, BLOCK, &mut hand) {
            Ok(0) => break,
            Ok(_) if !ok.get() => return,
            Ok(_) => {
                let Some(file) = &in_file else { continue };
                let Some(at) = s.region_at() else { continue };
                let mut read_at = |buf: &mut [u8], offset: u64| read_at(file, buf, offset);
                let cut = cut_in_file(at, &mut read_at, chunk_bytes, &mut |p| {
                    hand(p);
                    ok.get()
                });
                if let Err(e) = cut {
                    // (As below: the file is read again by one reader, which meets it.)
                    let _ = to.done.send(Done::Failed);
                    let _ = to.text.send(Msg::Failed(e));
                    return;
                }
                let _ = to.text.send(Msg::Eof);
                return;
            }
            Err(e) if e.kind() == std::io::ErrorKind::Interrupted => continue,
            Err(e) => {
                // Before the region, the main reader meets the error; in it, the file is read
                // again by one reader, which meets it.
                let _ = to.done.send(Done::Failed);
                let _ = to.text.send(Msg::Failed(e));
                return;
            }
        }
    }
    s.finish(&mut hand);
    let _ = to.text.send(Msg::Eof);
}

/// Hands chunk `k` (counted here) to the workers, once a credit allows; the first ends the
/// main reader's text (the prefix). False if the receivers are gone.
fn hand_chunk(
    to: &Hands,
    k: &mut usize,
    prefix: &Option<Arc<[u8]>>,
    start: u64,
    text: ChunkText,
) -> bool {
    let first = *k == 0 && to.text.send(Msg::PrefixEnd).is_err();
    let p = prefix.clone().unwrap_or_else(|| Arc::from(&[][..]));
    *k += 1;
    !first && to.credits.recv().is_ok() && to.chunks.send((*k - 1, start, text, p)).is_ok()
}

/// The main thread: the prefix, the chunks' results in order, the rest.
fn main_reader(
    low: &mut Lowerer,
    (name, path): (Arc<str>, &Path),
    reader: ChannelReader,
    results: InOrder,
    stop: &AtomicBool,
    (size, in_file): (u64, Option<Arc<std::fs::File>>),
) -> Result<Parallel, Error> {
    let src = SourceWindow::new(name, Box::new(reader.clone()));
    let mut opened = low
        .expand
        .open_file(&mut low.cx, &mut low.build, &src, path);
    let mut parser = Parser::new(src);
    parser.pause_at_end = true;
    let r = parser.begin().and_then(|()| parser.resume(&mut low.lent()));
    if !matches!(reader.take_stop(), Some(Msg::PrefixEnd)) {
        // No region: this was one reader all along, and its result stands.
        low.expand.resume_outside(&mut opened);
        r?;
        parser.end()?;
        low.expand
            .close_file(&mut low.cx, &mut low.build, opened, &parser.src)?;
        return Ok(Parallel::Chunks(0, None));
    }
    // From here on, a failure's message is one reader's to give.
    let outcome = (|| -> Result<(usize, Option<String>), String> {
        r.map_err(|e| e.to_string())?;
        let placed = put_chunks_in_place(low, &mut parser.src, results, (size, in_file))?;
        // The rest: from the first chunk whose result did not stand (or the file's end).
        stop.store(true, Ordering::Relaxed);
        parser.src.jump(placed.from, Box::new(placed.rest));
        let run = parser.resume(&mut low.lent()).map_err(|e| e.to_string())?;
        debug_assert_eq!(run, Run::Paused);
        parser.end().map_err(|e| e.to_string())?;
        Ok((placed.count, placed.why))
    })();
    low.expand.resume_outside(&mut opened);
    let (chunks, why) = match outcome {
        Ok(r) => r,
        Err(why) => {
            return Ok(Parallel::Fallback(
                low.expand.fallback.take().unwrap_or(why),
            ))
        }
    };
    if let Err(e) = low
        .expand
        .close_file(&mut low.cx, &mut low.build, opened, &parser.src)
    {
        return Ok(Parallel::Fallback(e.to_string()));
    }
    Ok(match low.expand.fallback.take() {
        Some(why) => Parallel::Fallback(why),
        None => Parallel::Chunks(chunks, why),
    })
}

/// Room for what the rest of the file (`ahead` bytes) will add, at the density of the first
/// chunk (`len` bytes, which `added` spheres and lines), at once: grown chunk by chunk, each
/// list was copied (and faulted in) again at every doubling, the other growing lists in the
/// way. Only address space is taken beyond what is used; the spheres are shrunk to fit when
/// the file is read. Bounded, and asked for without aborting on failure: it is only a hint.
fn reserve_ahead(
    low: &mut Lowerer,
    src: &mut SourceWindow,
    [spheres, lines]: [usize; 2],
    (ahead, len): (u64, u64),
) {
    let ahead = ahead as f64;
    let more = |n: usize, most: f64| (1.02 * n as f64 / len.max(1) as f64 * ahead).min(most);
    let _ = (low.build.scene.spheres).try_reserve_exact(more(spheres, ahead / 8.0) as usize);
    src.lines.try_reserve(more(lines, ahead / 2.0) as usize);
}

/// The chunks put in place, and where the main reader reads on.
struct Placed {
    count: usize,
    /// Why it reads on by itself before the file's end (with where), if it does.
    why: Option<String>,
    /// Where it reads on, and the text from there.
    from: u64,
    rest: Box<dyn Read>,
}

/// Puts the chunks' results in place in file order, up to the first that may not stand (its
/// cuts were wrong, it warns...) or the one the region's list ends in (up to that end); or
/// says why the file must be read again by one reader. `size` is the file's (a hint: for the
/// lists to come); `in_file`, the file, when the chunks' texts were left in it (the main
/// reader then reads on from it).
fn put_chunks_in_place(
    low: &mut Lowerer,
    src: &mut SourceWindow,
    mut results: InOrder,
    (size, in_file): (u64, Option<Arc<std::fs::File>>),
) -> Result<Placed, String> {
    let mut why = None;
    let mut placed = 0;
    // Names the chunks put in place so far DEF'd.
    let mut defined: HashSet<String> = HashSet::new();
    // The text the main reader reads on in, from `skip` bytes into chunk `k`'s (none when the
    // chunks were left in the file: it reads on from the file).
    let read_on = |text: Option<Vec<u8>>, k: usize, skip: u64| match text {
        Some(mut t) => {
            t.drain(..t.len().min(skip as usize));
            Ok(t)
        }
        None if in_file.is_some() => Ok(Vec::new()),
        None => Err(format!("chunk {k}: its text was not handed back")),
    };
    let (from, text) = loop {
        let Some(ChunkResult {
            start,
            len,
            out,
            text,
        }) = results.next()?
        else {
            let end = results.total.map_or(0, |t| t.1);
            break (end, Vec::new());
        };
        let (d, text) = match out {
            Ok(d) if d.end.is_some() => (d, text),
            Ok(d) => {
                if let Some(t) = text {
                    let _ = results.spare.send(t);
                }
                (d, None)
            }
            Err(e) => {
                let text = read_on(text, placed, 0)?;
                why = Some(format!("from piece {placed} at byte {start}: {e}"));
                break (start, text);
            }
        };
        if let Some(n) = d.imports.iter().find(|n| defined.contains(*n)) {
            return Err(format!(
                "chunk {placed} USEs '{n}', which an earlier chunk DEF'd again"
            ));
        }
        if low.cx.spent as i64 + d.excess > low.cx.opts.expansion_base.min(i64::MAX as u64) as i64 {
            return Err("the budget spent may pass the expansion limit".into());
        }
        defined.extend(d.exports.iter().cloned());
        let end = d.end;
        let lines = d.lines();
        let before = low.build.scene.spheres.len();
        let emptied = low.put_in_place(*d, src)?;
        if placed == 0 {
            let added = [low.build.scene.spheres.len() - before, lines];
            reserve_ahead(low, src, added, (size.saturating_sub(start + len), len));
        }
        if let Ok(mut spare) = results.spheres.lock() {
            if spare.len() < 4 {
                spare.push(emptied);
            }
        }
        placed += 1;
        if let Some(end) = end {
            // The region's list ends in this chunk (counted as put in place): the main reader
            // reads on from its end.
            let k = placed - 1;
            let text = read_on(text, k, end - start)?;
            why = Some(format!(
                "from byte {end}, where the region's list ends (in piece {k})"
            ));
            break (end, text);
        }
    };
    if !defined.is_empty() {
        low.expand.poison = Some(defined);
    }
    let rest: Box<dyn Read> = match in_file {
        // (The chunks still coming are not waited for: dropping `results` stops them.)
        Some(file) => Box::new(FileRange {
            file,
            at: from,
            end: u64::MAX,
        }),
        None => Box::new(ChunkTexts {
            text,
            at: 0,
            rest: InOrder {
                help: None,
                ..results
            },
        }),
    };
    Ok(Placed {
        count: placed,
        why,
        from,
        rest,
    })
}
