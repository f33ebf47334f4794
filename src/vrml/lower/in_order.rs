//! The chunks of a file read in pieces (see [`super::parallel`]) as the main reader takes
//! them: each chunk's lowering on any thread ([`Lowering`]), their results in file order
//! ([`InOrder`], which lowers a waiting chunk itself while the next result is not ready),
//! and their texts, for the main reader reading on by itself ([`ChunkTexts`]).

use std::collections::BTreeMap;
use std::io::Read;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::{Receiver, Sender, SyncSender};
use std::sync::{Arc, Mutex};

use super::chunk::{lower_chunk, ChunkText, Outcome};
use crate::scene::Sphere;

/// A chunk for a worker: its number, its offset, its text, and the prefix to read first.
pub(super) type Job = (usize, u64, ChunkText, Arc<[u8]>);

/// The chunks' receiver, shared by their readers.
pub(super) type Jobs = Arc<Mutex<Receiver<Job>>>;

/// A chunk's offset, outcome and text (see [`lower_chunk`]).
pub(super) struct ChunkResult {
    pub(super) start: u64,
    /// The chunk's length in bytes.
    pub(super) len: u64,
    pub(super) out: Outcome,
    pub(super) text: Option<Vec<u8>>,
}

/// What the results channel carries.
pub(super) enum Done {
    /// A chunk's number and result.
    Chunk(usize, ChunkResult),
    /// The region (the rest of the file) was cut into this many chunks and ends here.
    Total(usize, u64),
    /// The text could not be read to its end.
    Failed,
}

/// The chunks' results in file order.
pub(super) struct InOrder {
    pub(super) rx: Receiver<Done>,
    pub(super) waiting: BTreeMap<usize, ChunkResult>,
    pub(super) next: usize,
    /// The number of chunks and the file's end, once the scan is done.
    pub(super) total: Option<(usize, u64)>,
    pub(super) credits: SyncSender<()>,
    pub(super) spare: Sender<Vec<u8>>,
    /// Chunks' lists of spheres, emptied, for the workers to fill again.
    pub(super) spheres: Spare,
    /// The chunks' receiver, when the main thread lowers chunks too while the next to be put
    /// in place is not ready; with what it lowers them with.
    pub(super) help: Option<(Jobs, Lowering, String)>,
}

/// What a chunk is lowered with, on any thread.
#[derive(Clone)]
pub(super) struct Lowering {
    pub(super) opts: super::LoadOptions,
    pub(super) name: Arc<str>,
    pub(super) path: std::path::PathBuf,
    pub(super) spheres: Spare,
    pub(super) stop: Arc<AtomicBool>,
}

impl Lowering {
    /// Lowers a chunk (see [`lower_chunk`]), unless the main thread reads on by itself.
    pub(super) fn lower(
        &self,
        (k, start, text, prefix): Job,
        window: &mut String,
    ) -> (usize, ChunkResult) {
        let len = match &text {
            ChunkText::Held(t) => t.len() as u64,
            ChunkText::InFile(r) => r.end.saturating_sub(r.at),
        };
        let (out, text) = if self.stop.load(Ordering::Relaxed) {
            let text = match text {
                ChunkText::Held(t) => Some(t),
                ChunkText::InFile(_) => None,
            };
            (Err("not read".into()), text)
        } else {
            let list = self.spheres.lock().ok().and_then(|mut s| s.pop());
            lower_chunk(
                &self.opts,
                (&self.name, &self.path),
                &prefix,
                start,
                text,
                (list.unwrap_or_default(), window),
            )
        };
        (
            k,
            ChunkResult {
                start,
                len,
                out,
                text,
            },
        )
    }
}

/// Emptied lists of spheres, passed from the main thread back to the workers.
pub(super) type Spare = Arc<Mutex<Vec<Vec<Sphere>>>>;

impl InOrder {
    /// The next chunk's offset, outcome and text, or None after the last.
    pub(super) fn next(&mut self) -> Result<Option<ChunkResult>, String> {
        loop {
            if let Some(r) = self.waiting.remove(&self.next) {
                self.next += 1;
                let _ = self.credits.try_send(());
                return Ok(Some(r));
            }
            if self.total.is_some_and(|(n, _)| n == self.next) {
                return Ok(None);
            }
            let done = match self.rx.try_recv() {
                Ok(d) => Ok(d),
                Err(_) => {
                    // Nothing to put in place: lower a chunk that waits for a reader, if any.
                    if let Some((rx, ctx, window)) = &mut self.help {
                        let job = rx.try_lock().ok().and_then(|r| r.try_recv().ok());
                        if let Some(job) = job {
                            let (k, r) = ctx.lower(job, window);
                            self.waiting.insert(k, r);
                            continue;
                        }
                    }
                    self.rx.recv()
                }
            };
            match done {
                Ok(Done::Chunk(k, r)) => {
                    self.waiting.insert(k, r);
                }
                Ok(Done::Total(n, end)) => self.total = Some((n, end)),
                Ok(Done::Failed) => return Err("the text could not be read".into()),
                Err(_) => return Err("a reading thread stopped".into()),
            }
        }
    }
}

/// The text of the chunks from one on, for the main reader reading on by itself.
pub(super) struct ChunkTexts {
    pub(super) text: Vec<u8>,
    pub(super) at: usize,
    pub(super) rest: InOrder,
}

impl Read for ChunkTexts {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        while self.at == self.text.len() {
            match self.rest.next() {
                Ok(Some(ChunkResult {
                    text: Some(text), ..
                })) => {
                    self.text = text;
                    self.at = 0;
                }
                Ok(None) => return Ok(0),
                Ok(Some(ChunkResult { text: None, .. })) => {
                    return Err(std::io::Error::other("a piece's text was not handed back"))
                }
                Err(why) => return Err(std::io::Error::other(why)),
            }
        }
        let n = buf.len().min(self.text.len() - self.at);
        buf[..n].copy_from_slice(&self.text[self.at..self.at + n]);
        self.at += n;
        Ok(n)
    }
}
