//! Finding where a large scene file can be read in pieces at once (see
//! `lower::parallel`): a scan of the text's brackets, strings and comments up to where the
//! pieces start, then guessed cuts, no parsing.
//!
//! The pieces are runs of whole sibling nodes of one list, the *region*: the top level of
//! the file, or the `children` of a grouping node (Group, Transform, Anchor, Billboard,
//! Collision) that is itself such a sibling all the way up, with no DEF on the way (a DEF'd
//! node is recorded for its USEs, so its contents must be read where it is). Such nodes'
//! children are lowered in their parent's coordinates and moved when the parent closes, so
//! lowering them apart and putting the results in place gives what one reader would.
//!
//! The text splits into a *prefix* (read first, by the main reader and again by every piece's
//! reader, so that each starts in the state the file is in there: the PROTOs declared, the
//! DEFs made, the grouping nodes open) and *chunks*, to the end of the file. The scan reads
//! the text until a list has `chunk_bytes` of siblings after its first cut (just after the
//! end of the line on which a sibling's `}` ends), or `prefix_max` if that is less and no
//! list it is in has a cut (no other list could be the region then): the prefix ends at that
//! first cut (within `prefix_max` bytes), and the first chunk at a cut the scan found. An
//! EXTERNPROTO in the prefix, or a word the scan cannot be sure of where it matters, leaves
//! the whole file to one reader.
//!
//! From there on nothing is scanned (at two threads the scan cost as much as a quarter of
//! the reading): each further cut is a guess, at the first line after `chunk_bytes` that
//! starts as the region's first sibling's did (see [`Splitter::cut_ahead`]). The guess may be
//! wrong (a nested node written at the same indentation, a string across lines), and the
//! region ends somewhere in the last chunks: the readers check every chunk (it must end, with
//! nothing declared, exactly between two siblings of the region, or at the region's end), and
//! the main reader reads on by itself from the first chunk that fails the check (or from the
//! region's end). Each chunk that passes shows that the next starts where a sibling does.
//!
//! For a plain file, the scan stops once the region is found ([`Splitter::region_at`]) and
//! the rest is cut in the file the same way ([`crate::vrml::cut_file`]).

use std::sync::Arc;

mod scan;

/// What the scan hands on, in file order.
#[derive(Debug)]
pub enum Piece {
    /// Text for the main reader.
    Text(Vec<u8>),
    /// The prefix has been handed on as `Text`; this is it again, for the chunks' readers.
    Prefix(Arc<[u8]>),
    /// A run of whole siblings of the region, starting at offset `start`.
    Chunk { start: u64, text: Vec<u8> },
    /// The same, left in the file (bytes `start..end`) for the chunk's reader to read (see
    /// [`crate::vrml::cut_file`]).
    Range { start: u64, end: u64 },
    /// The region ends at `end`, after `chunks` chunks; the main reader's text goes on from
    /// there.
    RegionEnd { chunks: usize, end: u64 },
}

/// The grouping nodes whose `children` a region may be.
const GROUPING: [&str; 5] = ["Group", "Transform", "Anchor", "Billboard", "Collision"];

#[derive(Clone, Copy, Debug)]
struct Frame {
    /// `[` (a list), or `{` (a node or a PROTO body).
    list: bool,
    /// A list: may be the region. A node: a grouping node whose `children` may be.
    split: bool,
    /// A list: its first cut, where a region in it would start.
    first_cut: Option<u64>,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Lex {
    Code,
    String,
    Escape,
    Comment,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Mode {
    /// Looking for a region.
    Seeking,
    /// In the region, from its first chunk on: cutting without scanning, where a line looks
    /// like the start of a sibling (see [`Splitter::cut_ahead`]).
    Region,
    /// Handing everything on to the main reader.
    Through,
}

/// The PROTO statement at the top level, if one is being read.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Proto {
    None,
    Interface,
    /// Between the interface's `]` and the body's `{`.
    AfterInterface,
    Body,
}

/// The scan's state between blocks of text.
pub struct Splitter {
    chunk_bytes: u64,
    prefix_max: u64,
    /// Text not yet handed on; `hold[0]` is at offset `base`.
    hold: Vec<u8>,
    base: u64,
    /// Where in `hold` the scan is.
    at: usize,
    lex: Lex,
    mode: Mode,
    /// Open brackets and braces below the top level (the top level is an implicit list).
    stack: Vec<Frame>,
    top_first_cut: Option<u64>,
    proto: Proto,
    /// A PROTO has a grouping node's name: those names may not be trusted.
    grouping_shadowed: bool,
    /// Where the words before the next bracket start (after the last structural byte), and
    /// whether a string or comment came since (then they are not read).
    span: usize,
    dirty: bool,
    /// After a sibling's `}`: looking for the end of its line (a cut), before anything but
    /// white space and a comment.
    after_close: bool,
    /// The comment being read began where only white space followed the last structural
    /// byte: the words after it can be read as if it were not there.
    clean_comment: bool,
    /// Where the next `[`, `]` or `#` is in `hold` (`usize::MAX`: none), and how much of
    /// `hold` was searched for it, if known.
    next_rare: Option<(usize, usize)>,
    /// In the region: `\n` and the start of its first sibling's line (its indentation and
    /// first word), the mark of a likely cut; and how many chunks were handed on.
    sibling: Vec<u8>,
    chunks: usize,
    /// Chunks' texts given back to be filled again (see [`Splitter::give_back`]).
    spare: Vec<Vec<u8>>,
}

/// Where the region's cutting has got to, for cutting the rest of it in the file itself (see
/// [`crate::vrml::cut_file`]): the offset after the last chunk handed on, the mark of a likely
/// cut (see [`Splitter::cut_ahead`]), and the chunks handed on.
pub struct RegionAt {
    pub base: u64,
    pub sibling: Vec<u8>,
    pub chunks: usize,
}

/// Bytes that the scan stops at.
const STRUCTURAL: [bool; 256] = {
    let mut t = [false; 256];
    t[b'{' as usize] = true;
    t[b'}' as usize] = true;
    t[b'[' as usize] = true;
    t[b']' as usize] = true;
    t[b'"' as usize] = true;
    t[b'#' as usize] = true;
    t
};

fn is_ws(b: u8) -> bool {
    matches!(b, b' ' | b'\t' | b'\r' | b'\n' | b',')
}

pub(crate) fn is_word(b: u8) -> bool {
    !is_ws(b) && !STRUCTURAL[b as usize] && b != b'\'' && b > b' '
}

/// A few words before a bracket, nearest first (no allocation: the scan asks at every
/// sibling's brace).
struct Words<'a> {
    words: [&'a [u8]; 3],
    len: usize,
}

impl<'a> Words<'a> {
    fn get(&self, j: usize) -> Option<&&'a [u8]> {
        self.words[..self.len].get(j)
    }
    fn first(&self) -> Option<&&'a [u8]> {
        self.get(0)
    }
}

/// `\n` and the indentation and first word of the first line of `text` that has a word
/// (blank lines and comment lines skipped), or just `\n` if there is none.
fn sibling_mark(text: &[u8]) -> Vec<u8> {
    let mut mark = vec![b'\n'];
    for line in text.split(|&b| b == b'\n') {
        let indent = line
            .iter()
            .take_while(|&&b| b == b' ' || b == b'\t')
            .count();
        let word = line[indent..].iter().take_while(|&&b| is_word(b)).count();
        if word > 0 {
            mark.extend_from_slice(&line[..indent + word]);
            break;
        }
        if line[indent..]
            .first()
            .is_some_and(|&b| b != b'#' && b != b'\r')
        {
            // A line that starts with something else (a bracket, a string): no mark.
            break;
        }
    }
    mark
}

impl Splitter {
    pub fn new(chunk_bytes: u64, prefix_max: u64) -> Self {
        Splitter {
            chunk_bytes: chunk_bytes.max(1),
            prefix_max,
            hold: Vec::new(),
            base: 0,
            at: 0,
            lex: Lex::Code,
            mode: Mode::Seeking,
            stack: Vec::new(),
            top_first_cut: None,
            proto: Proto::None,
            grouping_shadowed: false,
            span: 0,
            dirty: false,
            after_close: false,
            clean_comment: false,
            next_rare: None,
            sibling: Vec::new(),
            chunks: 0,
            spare: Vec::new(),
        }
    }

    /// Reads up to `block` bytes of `reader` straight into the text held (no copy on the
    /// way) and scans them; `out` takes the pieces that completes. Returns how many were
    /// read (0: the end).
    pub fn read_from(
        &mut self,
        reader: &mut dyn std::io::Read,
        block: usize,
        out: &mut impl FnMut(Piece),
    ) -> std::io::Result<usize> {
        use std::io::Read;
        if self.mode == Mode::Through {
            let mut text = Vec::with_capacity(block);
            let n = reader.take(block as u64).read_to_end(&mut text)?;
            if n > 0 {
                out(Piece::Text(text));
            }
            return Ok(n);
        }
        if self.hold.capacity() == 0 && self.mode == Mode::Seeking {
            // Room at once for what is usually held before the region is found: grown by
            // doubling, the text was copied at each step and faulted in twice over (a third
            // of the time to the first chunk, which the other threads wait for).
            let usual = self.prefix_max + self.chunk_bytes + 2 * block as u64;
            self.hold.reserve_exact(usual.min(64 << 20) as usize);
        }
        self.hold.reserve(block);
        let n = reader.take(block as u64).read_to_end(&mut self.hold)?;
        if self.mode == Mode::Seeking {
            self.scan(out);
            // Nothing may pile up without bound: a prefix too long.
            if self.mode == Mode::Seeking
                && self.hold.len() as u64 > self.prefix_max + 4 * self.chunk_bytes
            {
                self.give_up(out);
            }
        }
        if self.mode == Mode::Region {
            self.cut_ahead(out);
        }
        Ok(n)
    }

    /// A chunk's text, done with, to hold the text of another: a buffer whose pages are
    /// already mapped (a fresh one of a few MB is mapped and faulted in page by page, then
    /// unmapped when freed: at two reading threads, that was most of the system time).
    pub fn give_back(&mut self, text: Vec<u8>) {
        if self.spare.len() < 4 {
            self.spare.push(text);
        }
    }

    /// Once in the region: where its cutting has got to, the text held after that dropped
    /// (the rest is cut in the file).
    pub fn region_at(&mut self) -> Option<RegionAt> {
        (self.mode == Mode::Region).then(|| {
            self.hold.clear();
            RegionAt {
                base: self.base,
                sibling: self.sibling.clone(),
                chunks: self.chunks,
            }
        })
    }

    /// The end of the text.
    pub fn finish(mut self, out: &mut impl FnMut(Piece)) {
        match self.mode {
            Mode::Region => {
                if !self.hold.is_empty() {
                    self.chunk(self.base + self.hold.len() as u64, out);
                }
                out(Piece::RegionEnd {
                    chunks: self.chunks,
                    end: self.base,
                });
            }
            Mode::Seeking => self.give_up(out),
            Mode::Through => {}
        }
    }

    /// Cuts the region's text held into chunks of at least `chunk_bytes`, each ending where a
    /// line starts as the region's first sibling's did (its indentation and first word,
    /// `sibling`) and that word ends: a likely cut, not a certain one (strings, comments and
    /// brackets are not scanned any more), which the chunks' readers check (each must end
    /// between two siblings of the region, or the main reader reads on from its start). With
    /// no such line in `8 * chunk_bytes`, the text held up to its last line's start is cut
    /// anyway (the check then fails): what is held stays bounded.
    fn cut_ahead(&mut self, out: &mut impl FnMut(Piece)) {
        let want = self.chunk_bytes as usize;
        let cap = 8 * want.max(1 << 20);
        loop {
            let from = self.at.max(want.saturating_sub(1));
            if from >= self.hold.len() {
                return;
            }
            let found = memchr::memmem::find(&self.hold[from..], &self.sibling);
            match found.map(|i| from + i) {
                Some(i) => {
                    let after = i + self.sibling.len();
                    let Some(&b) = self.hold.get(after) else {
                        // The line's word may go on: wait for more text.
                        self.at = i;
                        return;
                    };
                    if self.sibling.len() > 1 && is_word(b) {
                        self.at = i + 1;
                        continue;
                    }
                    self.chunk(self.base + i as u64 + 1, out);
                    self.at = 0;
                }
                None if self.hold.len() > cap => {
                    let end = memchr::memrchr(b'\n', &self.hold).map_or(self.hold.len(), |k| k + 1);
                    self.chunk(self.base + end as u64, out);
                    self.at = 0;
                }
                None => {
                    // Search again from where a match could still start.
                    self.at = self.hold.len().saturating_sub(self.sibling.len());
                    return;
                }
            }
        }
    }

    /// Hands everything on to the main reader from here.
    fn give_up(&mut self, out: &mut impl FnMut(Piece)) {
        self.mode = Mode::Through;
        if !self.hold.is_empty() {
            out(Piece::Text(std::mem::take(&mut self.hold)));
        }
    }

    /// Takes the text before offset `end` out of `hold` (copying only what follows it,
    /// usually less), and moves the scan's indices with it.
    fn take_head(&mut self, end: u64) -> Vec<u8> {
        let n = (end - self.base) as usize;
        // Room for the next chunk and the blocks read past its end, so that the text held
        // is not moved again while it grows.
        let room = (self.chunk_bytes as usize)
            .saturating_add(2 << 20)
            .max(self.hold.len() - n);
        let mut rest = match self.spare.pop() {
            Some(mut v) if v.capacity() >= room => {
                v.clear();
                v
            }
            _ => Vec::with_capacity(room),
        };
        rest.extend_from_slice(&self.hold[n..]);
        self.hold.truncate(n);
        self.head_taken(end);
        std::mem::replace(&mut self.hold, rest)
    }

    /// Takes the text before offset `end` (the prefix, at most `prefix_max` bytes) out of
    /// `hold` by copying it and moving the rest down in place, and moves the scan's indices
    /// with it. ([`Self::take_head`] would copy the rest, the first chunk's whole text, into
    /// a fresh buffer: at the start, when nothing else runs, that copy and its page faults
    /// cost a third as long as the scan before it.)
    fn split_off_prefix(&mut self, end: u64) -> Vec<u8> {
        let n = (end - self.base) as usize;
        let prefix = self.hold[..n].to_vec();
        self.hold.drain(..n);
        self.head_taken(end);
        prefix
    }

    /// The scan's indices into `hold`, once the text before offset `end` has left it.
    fn head_taken(&mut self, end: u64) {
        let n = (end - self.base) as usize;
        self.next_rare = None;
        self.base = end;
        self.at = self.at.saturating_sub(n);
        self.span = self.span.saturating_sub(n);
    }

    /// Hands on the region's text up to `end` as a chunk.
    fn chunk(&mut self, end: u64, out: &mut impl FnMut(Piece)) {
        let start = self.base;
        let text = self.take_head(end);
        out(Piece::Chunk { start, text });
        self.chunks += 1;
    }

    /// The next structural byte at or after `at`: braces and quotes are common, brackets and
    /// comments rare, so the next rare one is looked for once and remembered.
    fn next_structural(&mut self) -> Option<usize> {
        let at = self.at;
        let len = self.hold.len();
        let stale = match self.next_rare {
            None => true,
            // Passed, or none was found in what `hold` held then.
            Some((r, upto)) => r < at || (r == usize::MAX && upto < len),
        };
        if stale {
            let from = match self.next_rare {
                Some((usize::MAX, upto)) => upto.max(at),
                _ => at,
            };
            let r = memchr::memchr3(b'[', b']', b'#', &self.hold[from..])
                .map_or(usize::MAX, |k| from + k);
            self.next_rare = Some((r, len));
        }
        let rare = self.next_rare.map_or(usize::MAX, |r| r.0);
        let end = rare.min(len);
        match memchr::memchr3(b'{', b'}', b'"', &self.hold[at..end]) {
            Some(k) => Some(at + k),
            None => (rare < len).then_some(rare),
        }
    }
}

#[cfg(test)]
mod tests;
