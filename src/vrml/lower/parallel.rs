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
use std::io::Read;
use std::path::Path;
use std::rc::Rc;
use std::sync::mpsc::{channel, sync_channel, Receiver, Sender, SyncSender};
use std::sync::{Arc, Mutex};

use hashbrown::HashSet;

use super::chunk::{lower_chunk, Outcome};
use super::Lowerer;
use crate::error::Error;
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
